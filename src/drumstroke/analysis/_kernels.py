"""The onset detector's compiled loops (:mod:`.onsets`): each computes what the numpy (or librosa) code it replaced did, in the same order.

They are a module of their own so that importing :mod:`drumstroke.analysis` does not import numba
(:mod:`drumstroke._jit`); :mod:`.onsets` imports them where it runs them.
"""

import math

import numpy as np

from .._jit import jit


@jit
def aic(x):
    """Akaike's change point of ``x``: the first sample of its second, louder-or-quieter segment."""
    n = len(x)
    power = np.cumsum(x * x)
    total = power[-1]
    tiny = total / n * 1e-12 + 1e-300
    edge = max(2, n // 50)
    best, at = np.inf, 0
    for k in range(max(1, edge + 1), n - edge):  # the first and last ``edge`` splits are not considered
        before = power[k - 1] / k
        after = (total - power[k - 1]) / (n - k)
        aic = k * math.log(before + tiny) + (n - k - 1) * math.log(after + tiny)
        if aic < best:
            best, at = aic, k - 1
    return at + 1


@jit
def waited(candidates, gap, first):
    """The ``candidates`` (sorted) each more than ``gap`` after the last kept, greedily; sample 0 first when ``first``."""
    kept = np.empty(len(candidates) + 1, dtype=np.int64)
    count, last = 0, -gap - 1
    if first:
        kept[0], count, last = 0, 1, 0
    for n in candidates:
        if n > last + gap:
            kept[count] = n
            count += 1
            last = n
    return kept[:count].copy()


@jit
def jump_at(x, positions, width):
    """:func:`.onsets._jump_at`: :func:`jump_near` each of ``positions`` (int)."""
    out = np.zeros(len(positions))
    for n in range(len(positions)):
        out[n] = jump_near(x, positions[n], width)
    return out


@jit
def jump_near(x, i, width):
    """The largest RMS jump of ``x`` (the next ``width`` samples over the 4 ``width`` before) within half a window of
    sample ``i``, over the slice of ``x`` the numpy code cut around it (the power summed in order from its start)."""
    half = max(1, width // 2)
    low, high = max(0, i - half - 4 * width), min(len(x), i + half + width + 1)
    power = np.zeros(high - low + 1)
    for j in range(low, high):
        power[j - low + 1] = power[j - low] + x[j] * x[j]
    count = high - low
    best = 0.0
    for k in range(max(i - half, low) - low, min(i + half + 1, high) - low):
        if k < min(4 * width, i):  # a full window before, or the signal's start
            continue
        after = (power[min(k + width, count)] - power[k]) / width
        before = (power[k] - power[max(k - 4 * width, 0)]) / (4 * width)
        best = max(best, math.sqrt(after / max(before, 1e-300 + after * 1e-12)))
    return best


@jit
def row_dots(a, b):
    """``np.einsum("ij,ij->i", a, b)`` summed as numpy sums it (its loop for rows contiguous along j, in
    the x86-64 baseline's 2-lane vectors): lane by lane, 4 vectors a step from the last, the lanes added at the end."""
    out = np.empty(a.shape[0])
    n = a.shape[1]
    for i in range(a.shape[0]):
        even, odd = 0.0, 0.0
        j = 0
        while n - j >= 8:
            e = a[i, j + 6] * b[i, j + 6] + even
            o = a[i, j + 7] * b[i, j + 7] + odd
            e = a[i, j + 4] * b[i, j + 4] + e
            o = a[i, j + 5] * b[i, j + 5] + o
            e = a[i, j + 2] * b[i, j + 2] + e
            o = a[i, j + 3] * b[i, j + 3] + o
            even = a[i, j] * b[i, j] + e
            odd = a[i, j + 1] * b[i, j + 1] + o
            j += 8
        while j < n:
            even = a[i, j] * b[i, j] + even
            if j + 1 < n:
                odd = a[i, j + 1] * b[i, j + 1] + odd
            j += 2
        out[i] = even + odd
    return out


@jit
def jump_profile(x, width):
    """The RMS jump of ``x`` at each sample (:func:`.onsets._windows`' next ``width`` samples over the 4 ``width``
    before, the power summed in order from ``x[0]``), 0 over the first 4 ``width``."""
    count = len(x)
    power = np.zeros(count + 1)
    for j in range(count):
        power[j + 1] = power[j] + x[j] * x[j]
    out = np.zeros(count)
    for k in range(4 * width, count):
        after = (power[min(k + width, count)] - power[k]) / width
        before = (power[k] - power[max(k - 4 * width, 0)]) / (4 * width)
        out[k] = math.sqrt(after / max(before, 1e-300 + after * 1e-12))
    return out


@jit
def peak_pick(x, gap):
    """:func:`.onsets._peak_pick`: the samples that are the largest from ``gap`` before to ``gap - 1`` after, at
    least their predecessor's and their mean, more than ``gap`` after the last kept (greedily)."""
    count = len(x)
    size = 2 * gap  # x[n - gap:n + gap], -inf past the ends (as scipy's maximum_filter1d of that size)
    padded = np.full(count + 2 * size, -np.inf)
    padded[gap:gap + count] = x
    prefix = padded.copy()  # the largest from each block's start of ``size`` samples, and to its end (van Herk)
    suffix = padded.copy()
    for start in range(0, len(padded), size):
        stop = min(len(padded), start + size)
        for j in range(start + 1, stop):
            prefix[j] = max(prefix[j - 1], padded[j])
        for j in range(stop - 2, start - 1, -1):
            suffix[j] = max(suffix[j + 1], padded[j])
    largest = np.empty(count)
    for n in range(count):
        largest[n] = max(suffix[n], prefix[n + size - 1])
    candidates = np.empty(count, dtype=np.int64)
    found = 0
    for n in range(1, count):
        if x[n] == largest[n] and x[n] >= (x[n - 1] + x[n]) / 2.0:
            candidates[found] = n
            found += 1
    first = True
    for n in range(min(gap, count)):
        if x[n] > x[0]:
            first = False
    return waited(candidates[:found], gap, first)


@jit
def burg(y, order):
    """``librosa.lpc(y, order=order)`` for a 1-D ``y`` (Burg's method, as Marple): the same operations in the same
    order, each order's update of the prediction errors done in place, one pass."""
    tiny = np.finfo(np.float64).tiny
    n = len(y)
    f = y[1:].copy()  # f[i:] is the forward error at order i, b[:n - 1 - i] the backward one
    b = y[:-1].copy()
    a = np.zeros(order + 1)
    a_prev = np.zeros(order + 1)
    a[0] = a_prev[0] = 1.0
    den = 0.0
    for k in range(n - 1):
        den += f[k] ** 2 + b[k] ** 2
    dot = 0.0
    for k in range(n - 1):
        dot += b[k] * f[k]
    for i in range(order):
        m = n - 1 - i  # the errors' length at this order
        reflect = dot * -2
        reflect /= den + tiny
        a_prev, a = a, a_prev
        for j in range(1, i + 2):
            a[j] = a_prev[j] + reflect * a_prev[i - j + 1]
        dot = 0.0  # the next order's numerator: its b[k] (this one's new b[k]) times its f[k] (this one's new f[k + 1])
        for k in range(m):
            old = f[i + k]
            f[i + k] = old + reflect * b[k]
            b[k] = b[k] + reflect * old
            if k > 0:
                dot += b[k - 1] * f[i + k]
        q = 1.0 - reflect ** 2
        den = q * den - b[m - 1] ** 2 - f[i] ** 2
    return a


@jit
def weighted_lags(x, weight, start, stop, order):
    """Rows ``x[n], x[n - 1], …, x[n - order]`` times ``weight[n]``, for ``n`` from ``start`` to ``stop`` (a new array)."""
    rows = np.empty((stop - start, order + 1))
    for n in range(start, stop):
        for j in range(order + 1):
            rows[n - start, j] = x[n - j] * weight[n]
    return rows
