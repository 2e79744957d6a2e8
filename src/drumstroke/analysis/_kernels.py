"""The onset detector's compiled loops (:mod:`.onsets`): each computes what the numpy, scipy (or librosa) code it
replaced did, in the same order, except where its docstring says otherwise (a product numpy gave to BLAS, a
solve to LAPACK, a filter to scipy's C: added in order here, the same to rounding).

They are a module of their own so that importing :mod:`drumstroke.analysis` does not import numba
(:mod:`drumstroke._jit`); :mod:`.onsets` imports them where it runs them.
"""

import math

import numpy as np

from .._jit import jit
from ._modes import five_window_sums, largest_magnitude_of, largest_of, trial_dots, upsampled_peak


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
def change_points(x, peaks, width):
    """:func:`aic` of ``x`` from ``4 width`` before each of ``peaks`` to ``2 width`` after: the change points (samples of ``x``)."""
    out = np.empty(len(peaks), dtype=np.int64)
    for i in range(len(peaks)):
        low = max(0, peaks[i] - 4 * width)
        out[i] = low + aic(x[low:peaks[i] + 2 * width])
    return out


@jit
def unpredicted(x, coefficients, start, stop):
    """``x[start:stop]`` less its prediction by the error filter ``coefficients`` from the samples before ``start``
    (each predicted sample predicting the next); as it is when ``start`` is within the filter's order."""
    order = len(coefficients) - 1
    out = np.empty(stop - start)
    for j in range(stop - start):
        out[j] = x[start + j]
    if start < order:
        return out
    past = np.empty(order + stop - start)
    for j in range(order):
        past[j] = x[start - order + j]
    for j in range(stop - start):
        total = 0.0  # the taps, oldest first, times the past
        for k in range(order):
            total += -coefficients[order - k] * past[j + k]
        past[order + j] = total
        out[j] -= total
    return out



@jit(inline="always")
def biquad(v, b0, b1, b2, a1, a2, z0, z1):
    """``v`` through a second-order section as scipy's ``sosfilt`` runs it: its output and new states."""
    y = b0 * v + z0
    return y, b1 * v - a1 * y + z1, b2 * v - a2 * y


@jit
def unit_numerators(sos):
    """Whether ``sos``'s sections after the first have the numerator (1, 2, 1) (a Butterworth low-pass's, its zeros at
    Nyquist, as scipy designs them)."""
    for s in range(1, len(sos)):
        if sos[s, 0] != 1.0 or sos[s, 1] != 2.0 or sos[s, 2] != 1.0:
            return False
    return True


@jit(inline="always")
def numerators(sos, s, unit):
    """Section ``s``'s numerator: the constants (1, 2, 1) when ``unit`` (compiled in: the products 1 v and 2 v are then
    v and v + v, exactly as multiplied), else its coefficients."""
    if unit:
        return 1.0, 2.0, 1.0
    return sos[s, 0], sos[s, 1], sos[s, 2]


@jit
def low_pass_every(sos, x, q):
    """``scipy.signal.sosfilt(sos, x)[::q]`` for 4 second-order sections (an 8th-order filter): the same
    operations, each section's state in registers, only the samples kept stored."""
    if unit_numerators(sos):
        return low_pass_loop(sos, x, q, True)
    return low_pass_loop(sos, x, q, False)


@jit(inline="always")
def low_pass_loop(sos, x, q, unit):
    """:func:`low_pass_every`'s loop (sections after the first of numerator (1, 2, 1) when ``unit``)."""
    b00, b01, b02, a01, a02 = sos[0, 0], sos[0, 1], sos[0, 2], sos[0, 4], sos[0, 5]
    (b10, b11, b12), (b20, b21, b22), (b30, b31, b32) = numerators(sos, 1, unit), numerators(sos, 2, unit), \
        numerators(sos, 3, unit)
    a11, a12, a21, a22, a31, a32 = sos[1, 4], sos[1, 5], sos[2, 4], sos[2, 5], sos[3, 4], sos[3, 5]
    z00 = z01 = z10 = z11 = z20 = z21 = z30 = z31 = 0.0
    out = np.empty((len(x) + q - 1) // q)
    skip = 0
    for i in range(len(x)):
        y, z00, z01 = biquad(x[i], b00, b01, b02, a01, a02, z00, z01)
        y, z10, z11 = biquad(y, b10, b11, b12, a11, a12, z10, z11)
        y, z20, z21 = biquad(y, b20, b21, b22, a21, a22, z20, z21)
        y, z30, z31 = biquad(y, b30, b31, b32, a31, a32, z30, z31)
        if skip == 0:
            out[i // q] = y
            skip = q
        skip -= 1
    return out




@jit
def all_pole(a, x):
    """``scipy.signal.lfilter([1.0], a, x)`` (``a[0]`` 1): its direct form II transposed, the same operations in the
    same order (the numerator's zeros too: the same signs of zero)."""
    order = len(a) - 1
    b = np.zeros(order + 1)
    b[0] = 1.0
    z = np.zeros(max(order, 1))
    y = np.empty(len(x))
    for n in range(len(x)):
        v = x[n]
        out = z[0] + b[0] * v
        for k in range(order - 1):
            z[k] = z[k + 1] + v * b[k + 1] - out * a[k + 1]
        z[order - 1] = v * b[order] - out * a[order]
        y[n] = out
    return y


@jit
def tail_free_peaks(e, coefficients, starts, stops, sure, amplitude, h, horizon, interpolator):
    """:func:`.onsets._attack_amplitudes`' loop over the onsets when the room's tails are taken off: each ``sure``
    onset's ``e[starts[i]:stops[i]]`` less the earlier sure onsets' tails ``amplitude[j] * h[lag:]`` (their lag from
    ``horizon`` to ``len(h)``, in order), through the predictor's all-pole response (:func:`all_pole`), its peak
    between samples (:func:`upsampled_peak`, padded by 4 zeros each side); the others' ``amplitude`` as it is."""
    out = amplitude.copy()
    for i in range(len(starts)):
        k, stop = starts[i], stops[i]
        if k < len(coefficients) - 1 or stop <= k or not sure[i]:
            continue
        own = e[k:stop].copy()
        for j in range(i):
            lag = k - starts[j]
            if sure[j] and horizon <= lag < len(h):
                part = h[lag:min(len(h), lag + stop - k)]
                for m in range(len(part)):
                    own[m] -= amplitude[j] * part[m]
        padded = np.zeros(len(own) + 8)
        padded[4:4 + len(own)] = all_pole(coefficients, own)
        out[i] = upsampled_peak(interpolator, padded)
    return out



@jit
def residual_peaks(x, coefficients, starts, stops, h):
    """The peak of each ``x[starts[i]:stops[i]]`` less its linear prediction from the samples before (:func:`unpredicted`),
    between samples (:func:`upsampled_peak`, ``h`` the 4-times upsampling FIR; 0 where the span is empty)."""
    out = np.zeros(len(starts))
    for i in range(len(starts)):
        if stops[i] <= starts[i]:
            continue
        actual = unpredicted(x, coefficients, starts[i], stops[i])
        if len(actual) < 2:
            out[i] = abs(actual[0])
            continue
        padded = np.zeros(len(actual) + 8)  # the new sound starts from nothing
        for j in range(len(actual)):
            padded[4 + j] = actual[j]
        out[i] = upsampled_peak(h, padded)
    return out


@jit
def jump_at(x, positions, width, floor):
    """:func:`.onsets._jump_at`: :func:`jump_near` each of ``positions`` (int)."""
    out = np.zeros(len(positions))
    for n in range(len(positions)):
        out[n] = jump_near(x, positions[n], width, floor)
    return out


@jit
def jump_near(x, i, width, floor):
    """The largest RMS jump of ``x`` (the next ``width`` samples over the 4 ``width`` before) within half a window of
    sample ``i``, over the slice of ``x`` the numpy code cut around it (the power summed in order from its start).

    A mean power under ``floor`` counts as ``floor``: where a fit took a note off to its last bits, what is
    left is rounding, and its "jump" (0 before, a few ulps after) is none."""
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
        best = max(best, math.sqrt(max(after, floor) / max(before, floor, 1e-300 + after * 1e-12)))
    return best


@jit
def row_dots(a, b):
    """``np.einsum("ij,ij->i", a, b)``, each row summed as :func:`pair_dot` sums it."""
    out = np.empty(a.shape[0])
    for i in range(a.shape[0]):
        out[i] = pair_dot(a[i], b[i])
    return out


@jit
def pair_dot(a, b):
    """``np.einsum("i,i->", a, b)`` of two vectors as numpy sums it (its loop for contiguous rows, in the x86-64
    baseline's 2-lane vectors): lane by lane, 4 vectors a step from the last, the lanes added at the end."""
    n = len(a)
    even, odd = 0.0, 0.0
    j = 0
    while n - j >= 8:
        e = a[j + 6] * b[j + 6] + even
        o = a[j + 7] * b[j + 7] + odd
        e = a[j + 4] * b[j + 4] + e
        o = a[j + 5] * b[j + 5] + o
        e = a[j + 2] * b[j + 2] + e
        o = a[j + 3] * b[j + 3] + o
        even = a[j] * b[j] + e
        odd = a[j + 1] * b[j + 1] + o
        j += 8
    while j < n:
        even = a[j] * b[j] + even
        if j + 1 < n:
            odd = a[j + 1] * b[j + 1] + odd
        j += 2
    return even + odd


@jit
def window_dot(x, start, t):
    """``x[start:start + len(t)] @ t`` as numpy's matmul sums a row of a sliding window (not a BLAS call): in order."""
    total = 0.0
    for j in range(len(t)):
        total += x[start + j] * t[j]
    return total


@jit
def likeness_at(x, start, t, energy):
    """The correlation of ``x`` from ``start`` with ``t`` (whose energy is ``energy``) and their dot product, as
    :func:`.onsets._best_lag` computes them."""
    dot = window_dot(x, start, t)
    own = pair_dot(x[start:start + len(t)], x[start:start + len(t)])
    return dot / (math.sqrt(own * energy) + 1e-300), dot


@jit(error_model="numpy")  # (every divisor is 1e-300 or more: numpy's model only lets the bounds' loop be vectorised)
def best_lag(x, template, low, count, energy):
    """:func:`.onsets._best_lag` over the ``count`` windows of ``x`` from ``low``: the best window, its dot product
    with ``template`` and its correlation (the first of the largest), each as :func:`likeness_at` computes it.

    The dot products are summed all windows at a time (:func:`window_dots`). A window's
    energy is first bounded from running sums (their rounding bounded, whatever the windows' levels), which
    bounds its correlation; only the windows whose bound reaches the best lower bound have it summed as
    :func:`likeness_at` sums it, and the best of those is the best of all.
    """
    size = len(template)
    span = count + size - 1
    power = np.zeros(span + 1)
    for j in range(span):
        power[j + 1] = power[j] + x[low + j] * x[low + j]
    slack = 4.0 * (span + 2) * 2.220446049250313e-16 * power[span]  # more than either sum's rounding
    dots = window_dots(x, low, template, count)
    upper, lower = np.empty(count), np.empty(count)
    for k in range(count):  # each window's bounds (in vector instructions), then the best lower bound
        own = power[k + size] - power[k]
        a = dots[k] / (math.sqrt(max(own - slack, 0.0) * energy) + 1e-300)
        b = dots[k] / (math.sqrt((own + slack) * energy) + 1e-300)
        upper[k], lower[k] = max(a, b), min(a, b)
    floor = -np.inf
    for k in range(count):
        floor = max(floor, lower[k])
    best, at = -np.inf, 0
    for k in range(count):
        if upper[k] >= floor:
            own = pair_dot(x[low + k:low + k + size], x[low + k:low + k + size])
            like = dots[k] / (math.sqrt(own * energy) + 1e-300)
            if like > best:
                best, at = like, k
    return at, dots[at], best


@jit
def window_dots(x, low, t, count):
    """:func:`window_dot` of the ``count`` windows of ``x`` from ``low``: each window's products added in order, all the
    windows a term at a time (a loop over the windows, in vector instructions), eight terms a pass (each window's sum
    loaded and stored once for eight products, not each)."""
    dots = np.zeros(count)
    j = 0
    while j + 8 <= len(t):
        v0, v1, v2, v3, v4, v5, v6, v7 = t[j], t[j + 1], t[j + 2], t[j + 3], t[j + 4], t[j + 5], t[j + 6], t[j + 7]
        shifted = x[low + j:low + j + count + 7]  # a slice: indices the compiler sees are ≥ 0
        for k in range(count):
            dots[k] = (((((((dots[k] + shifted[k] * v0) + shifted[k + 1] * v1) + shifted[k + 2] * v2)
                           + shifted[k + 3] * v3) + shifted[k + 4] * v4) + shifted[k + 5] * v5)
                       + shifted[k + 6] * v6) + shifted[k + 7] * v7
        j += 8
    while j < len(t):
        v, shifted = t[j], x[low + j:low + j + count]
        for k in range(count):
            dots[k] += shifted[k] * v
        j += 1
    return dots


@jit
def eight_dots(x, starts, t, out):
    """:func:`window_dot` of the eight windows from ``starts``, into ``out``: eight chains of additions side by side."""
    s0, s1, s2, s3, s4, s5, s6, s7 = starts[0], starts[1], starts[2], starts[3], starts[4], starts[5], starts[6], starts[7]
    d0, d1, d2, d3, d4, d5, d6, d7 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    for j in range(len(t)):
        v = t[j]
        d0 += x[s0 + j] * v
        d1 += x[s1 + j] * v
        d2 += x[s2 + j] * v
        d3 += x[s3 + j] * v
        d4 += x[s4 + j] * v
        d5 += x[s5 + j] * v
        d6 += x[s6 + j] * v
        d7 += x[s7 + j] * v
    out[0], out[1], out[2], out[3], out[4], out[5], out[6], out[7] = d0, d1, d2, d3, d4, d5, d6, d7


@jit
def eight_squares(x, starts, size, out):
    """:func:`pair_dot` of each of the eight windows of ``size`` samples of ``x`` from ``starts`` with itself, into
    ``out``: their two lanes' chains side by side, each added in pair_dot's order."""
    even, odd = np.zeros(8), np.zeros(8)
    j = 0
    while size - j >= 8:
        for step in (6, 4, 2, 0):  # pair_dot's order: the vector's last pair first, into the lanes
            for w in range(8):
                a, b = x[starts[w] + j + step], x[starts[w] + j + step + 1]
                even[w] = a * a + even[w]
                odd[w] = b * b + odd[w]
        j += 8
    while j < size:
        for w in range(8):
            a = x[starts[w] + j]
            even[w] = a * a + even[w]
            if j + 1 < size:
                b = x[starts[w] + j + 1]
                odd[w] = b * b + odd[w]
        j += 2
    for w in range(8):
        out[w] = even[w] + odd[w]


@jit
def pursue(r, positions, centres, basis, gram, solve, head, head_norm, lead, width, tail, floor):
    """:func:`.onsets._pursue`'s loop: ``r`` (the innovation, changed in place) less each onset's fitted signature.

    ``basis`` holds the signature (and its derivative) as columns, ``gram`` its normal equations and ``solve``
    their solution for it; ``centres`` are the rounded ``positions``. Returns the jumps, likenesses, where each
    fits, where each fitted signature starts and its scale. The windows' products are summed as numpy's matmul
    sums a sliding window's rows (in order), their row sums as its einsum; the fit taken off (``basis`` times the
    weights, numpy's BLAS call) in order.
    """
    count, n = len(centres), len(r)
    size, m = basis.shape
    half = max(1, width // 2)
    jumps, likeness = np.zeros(count), np.zeros(count)
    where = positions.copy()
    at, amp = np.zeros(count, dtype=np.int64), np.zeros(count)
    weights, fitted = np.empty((5, m)), np.empty(m)  # each alignment's weights, and one's times gram
    cost, dots, heads, energies, sums = np.empty(5), np.empty(5), np.empty(5), np.empty(5), np.empty(15)
    for i in range(count):
        c = centres[i]
        low, high = max(0, c - half - 4 * width), min(n, c + half + width + 1)
        jumps[i] = jump_near(r, c, width, floor) if high - low > width else 0.0
        first, last = max(c - lead - 2, 0), min(c - lead + 2, n - size)  # the five alignments that fit in r
        if last < first:
            continue
        like = -np.inf
        # each alignment's sums as window_dot and pair_dot add them, the five alignments' side by side
        five_dots(r, first, last, head, dots)
        five_squares(r, first, last, len(head), heads)
        if m == 2 and last == first + 4:  # the five windows in vector lanes (away from the ends)
            five_window_sums(r, first, solve[0], solve[1], size, sums)
            for k in range(5):
                weights[k, 0], weights[k, 1], energies[k] = sums[k], sums[5 + k], sums[10 + k]
        else:
            five_squares(r, first, last, size, energies)
            for q in range(m):
                five_dots(r, first, last, solve[q], weights[:, q])
        for k in range(last - first + 1):
            like = max(like, abs(dots[k]) / (math.sqrt(heads[k]) * head_norm + 1e-300))
            if m == 2:  # the loops below for two columns: the same operations (from 0.0), in registers
                w0, w1 = weights[k, 0], weights[k, 1]
                f0, f1 = (0.0 + w0 * gram[0, 0]) + w1 * gram[1, 0], (0.0 + w0 * gram[0, 1]) + w1 * gram[1, 1]
                cost[k] = energies[k] - ((w0 * f0 + 0.0) + (w1 * f1 + 0.0))
                continue
            fitted[:] = 0.0
            for q in range(m):
                for p in range(m):
                    fitted[q] += weights[k, p] * gram[p, q]
            cost[k] = energies[k] - pair_dot(weights[k], fitted)
        likeness[i] = like
        k = 0  # the first of the least costs
        for j in range(1, last - first + 1):
            if cost[j] < cost[k]:
                k = j
        s = first + k
        if m == 2:
            w0, w1 = weights[k, 0], weights[k, 1]
            for j in range(size):
                r[s + j] -= (0.0 + basis[j, 0] * w0) + basis[j, 1] * w1
        else:
            for j in range(size):
                fit = 0.0
                for q in range(m):
                    fit += basis[j, q] * weights[k, q]
                r[s + j] -= fit
        if len(tail) > size:
            for j in range(s + size, min(n, s + len(tail))):
                r[j] -= weights[k, 0] * tail[j - s]
        at[i], amp[i] = s, weights[k, 0]
        shift = -weights[k, 1] / weights[k, 0] if m > 1 and weights[k, 0] != 0.0 else 0.0
        where[i] = s + lead + min(max(shift, -1.0), 1.0)
    return jumps, likeness, where, at, amp


@jit
def five_dots(x, first, last, t, out):
    """:func:`window_dot` of the windows of ``x`` from ``first`` to ``last`` (five at most) with ``t``, into ``out``:
    five chains of additions side by side (a window past ``last`` is the last one again)."""
    s0, s1, s2 = first, min(first + 1, last), min(first + 2, last)
    s3, s4 = min(first + 3, last), min(first + 4, last)
    d0, d1, d2, d3, d4 = 0.0, 0.0, 0.0, 0.0, 0.0
    for j in range(len(t)):
        v = t[j]
        d0 += x[s0 + j] * v
        d1 += x[s1 + j] * v
        d2 += x[s2 + j] * v
        d3 += x[s3 + j] * v
        d4 += x[s4 + j] * v
    out[0], out[1], out[2], out[3], out[4] = d0, d1, d2, d3, d4


@jit
def five_squares(x, first, last, size, out):
    """:func:`pair_dot` of each window of ``size`` samples of ``x`` from ``first`` to ``last`` (five at most) with
    itself, into ``out``: its two lanes' chains for the five windows side by side (a window past ``last`` is the last
    one again)."""
    s0, s1, s2 = first, min(first + 1, last), min(first + 2, last)
    s3, s4 = min(first + 3, last), min(first + 4, last)
    e0, e1, e2, e3, e4 = 0.0, 0.0, 0.0, 0.0, 0.0  # each window's even and odd lanes
    o0, o1, o2, o3, o4 = 0.0, 0.0, 0.0, 0.0, 0.0
    j = 0
    while size - j >= 8:
        for step in (6, 4, 2, 0):  # pair_dot's order: the vector's last pair first, into the lanes
            a0, a1, a2 = x[s0 + j + step], x[s1 + j + step], x[s2 + j + step]
            a3, a4 = x[s3 + j + step], x[s4 + j + step]
            e0, e1, e2, e3, e4 = a0 * a0 + e0, a1 * a1 + e1, a2 * a2 + e2, a3 * a3 + e3, a4 * a4 + e4
            a0, a1, a2 = x[s0 + j + step + 1], x[s1 + j + step + 1], x[s2 + j + step + 1]
            a3, a4 = x[s3 + j + step + 1], x[s4 + j + step + 1]
            o0, o1, o2, o3, o4 = a0 * a0 + o0, a1 * a1 + o1, a2 * a2 + o2, a3 * a3 + o3, a4 * a4 + o4
        j += 8
    while j < size:
        a0, a1, a2, a3, a4 = x[s0 + j], x[s1 + j], x[s2 + j], x[s3 + j], x[s4 + j]
        e0, e1, e2, e3, e4 = a0 * a0 + e0, a1 * a1 + e1, a2 * a2 + e2, a3 * a3 + e3, a4 * a4 + e4
        if j + 1 < size:
            a0, a1, a2 = x[s0 + j + 1], x[s1 + j + 1], x[s2 + j + 1]
            a3, a4 = x[s3 + j + 1], x[s4 + j + 1]
            o0, o1, o2, o3, o4 = a0 * a0 + o0, a1 * a1 + o1, a2 * a2 + o2, a3 * a3 + o3, a4 * a4 + o4
        j += 2
    out[0], out[1], out[2], out[3], out[4] = e0 + o0, e1 + o1, e2 + o2, e3 + o3, e4 + o4


@jit
def best_trial(y, basis, grams, lags, total):
    """The trial signature that takes off the most of ``y`` (a window of the remainder, ``total`` its energy) with a
    positive scale: its index in ``lags`` (-1 for none), its least-squares weights and the F statistic of its two
    parameters against what is left of ``y`` (``len(y) - 4`` degrees of freedom: the window's own attack's two
    parameters too).

    Each trial is ``basis`` (the signature and its derivative, as columns, C-contiguous) starting ``lags`` samples
    (consecutive) into the window, truncated to it (``grams``: the normal equations of its first rows, cumulated).

    Each trial's 2-by-2 normal equations (ridged by 1e-12 of the first's trace) are solved by Gaussian elimination
    with partial pivoting, as LAPACK's ``gesv`` solves them.
    """
    size = len(y)
    ridge = 1e-12 * (grams[size - lags[0] - 1, 0, 0] + grams[size - lags[0] - 1, 1, 1])
    best, at = -np.inf, -1
    chosen = np.zeros(2)
    # the window from each lag on (zeros past) times each column, in order (the lags: consecutive)
    dots0, dots1 = np.empty(len(lags)), np.empty(len(lags))
    trial_dots(y, basis, lags[0], len(lags), dots0, dots1)
    for k in range(len(lags)):
        lag, b0, b1 = lags[k], dots0[k], dots1[k]
        g = grams[size - lag - 1]
        w0, w1 = solve_2x2(g[0, 0] + ridge, g[0, 1], g[1, 0], g[1, 1] + ridge, b0, b1)
        if not (np.isfinite(w0) and np.isfinite(w1)):
            return -1, chosen, 0.0
        drop = w0 * b0 + w1 * b1 if w0 > 0.0 else -np.inf  # what the trial's fit takes off the window
        if drop > best:
            best, at = drop, k
            chosen[0], chosen[1] = w0, w1
    if at < 0 or not np.isfinite(best):
        return -1, chosen, 0.0
    return at, chosen, (best / 2.0) / max(total - best, 1e-300) * (size - 4)


@jit
def after_louder(residual, basis, grams, at, amplitude, positions, head, head_norm, gap, reach, spike, width, f_least,
                 f_weak, like_weak, ratio_low, ratio_high):
    """:func:`.onsets._after_louder`'s loop over the attacks: where a quiet attack is found in each one's signature.

    ``at`` and ``amplitude`` are each attack's fitted signature's start and scale in ``residual``, ``positions`` its
    sample there. Returns each found attack's place (samples of the band, to a fraction) and its start's likeness to
    the signature's; the products as numpy's (BLAS's).
    """
    size = basis.shape[0]
    found, likes = np.empty(len(at)), np.empty(len(at))
    count = 0
    for i in range(len(at)):
        s, alpha = at[i], amplitude[i]
        if alpha <= 0.0 or s + size > len(residual):
            continue
        stop = positions[i] + reach if i + 1 == len(at) else min(positions[i] + reach, positions[i + 1] - gap)
        lags = np.arange(positions[i] + gap, stop + 1) - spike - s  # where each trial signature starts in the window
        lags = lags[(lags > 0) & (lags < size - 2 * width)]  # two jump windows of it in the window
        if not len(lags):
            continue
        y = residual[s:s + size]
        k, weights, f = best_trial(y, basis, grams, lags, np.dot(y, y))
        if k < 0:
            continue
        ratio = weights[0] / alpha
        start = residual[s + lags[k]:s + lags[k] + len(head)]
        like = abs(np.dot(start, head)) / (np.sqrt(np.dot(start, start)) * head_norm + 1e-300)
        passes = f >= f_least or (f >= f_weak and like >= like_weak)
        if passes and ratio_low <= ratio <= ratio_high:
            found[count] = s + lags[k] + spike + min(max(-weights[1] / weights[0], -1.0), 1.0)
            likes[count] = like
            count += 1
    return found[:count].copy(), likes[:count].copy()


@jit
def soft_likeness(e, spike, widths, bank, offsets, lengths, norms, k):
    """:func:`.onsets._soft_likeness`: the largest correlation (magnitude) of ``e`` at sample ``k`` with each smoothed start
    ``bank[offsets[h]:offsets[h] + lengths[h]]`` (of norm ``norms[h]``, by a contact of ``widths[h]`` samples), tried
    from two samples before its alignment with ``k`` to two and half the contact after; the products as numpy's."""
    best = 0.0
    for h in range(len(widths)):
        head = bank[offsets[h]:offsets[h] + lengths[h]]
        for s in range(max(0, k - spike - 2), min(len(e) - lengths[h], k - spike + 2 + widths[h] // 2) + 1):
            part = e[s:s + lengths[h]]
            best = max(best, abs(np.dot(part, head)) / (np.sqrt(np.dot(part, part)) * norms[h] + 1e-300))
    return best


@jit
def solve_2x2(a00, a01, a10, a11, b0, b1):
    """The solution of ``[[a00, a01], [a10, a11]] w = [b0, b1]`` by Gaussian elimination with partial pivoting (as
    LAPACK's ``gesv``); NaN where the matrix is singular."""
    if abs(a10) > abs(a00):
        a00, a01, a10, a11, b0, b1 = a10, a11, a00, a01, b1, b0
    if a00 == 0.0:
        return np.nan, np.nan
    ratio = a10 / a00
    pivot = a11 - ratio * a01
    if pivot == 0.0:
        return np.nan, np.nan
    w1 = (b1 - ratio * b0) / pivot
    return (b0 - a01 * w1) / a00, w1


@jit
def least_unexplained(part, cross, energy, length):
    """Where a template of ``energy`` leaves the least of ``part``'s windows of ``length`` unexplained, given their
    ``cross`` products with it: ``k`` and the fraction ``(own - cross² / energy) / own`` (``own``: the window's
    energy by running sums from ``part[0]``), as numpy code computed it (the first least, or the first nan)."""
    return least_unexplained_by(running_power(part, len(part)), cross, energy, length)


@jit
def running_power(x, count):
    """The running sums of ``x * x`` over its first ``count`` samples, from 0, in order [shape=(count + 1,)]."""
    power = np.empty(count + 1)
    power[0] = 0.0
    for j in range(count):
        power[j + 1] = power[j] + x[j] * x[j]
    return power


@jit
def least_unexplained_by(power, cross, energy, length):
    """:func:`least_unexplained` given the running sums ``power`` of the part's squares (:func:`running_power`, over as
    many samples as its windows reach or more: the windows' energies are the same)."""
    tiny = np.finfo(np.float64).tiny
    best, at = np.inf, 0
    for k in range(len(cross)):
        own = power[k + length] - power[k]
        unexplained = (own - cross[k] * cross[k] / energy) / max(own, tiny)
        if math.isnan(unexplained):
            return k, unexplained
        if unexplained < best or k == 0:
            best, at = unexplained, k
    return at, best


@jit
def first_transients(d, times, reach, horizon, least, over, clear):
    """:func:`.onsets._first_transients`' times (a new array): each of ``times`` (increasing, full-rate samples) moved
    to the first sample within ``reach`` of it (and half way to its neighbours, the earlier one as moved) where ``d``
    passes ``least`` times its peak over the ``horizon`` after it and ``over`` times its own peak over the ``reach``
    before (scipy's maximum_filter1d there), that earlier peak ``clear`` times the peak at most; less half a sample."""
    out = times.copy()
    # the reach before each sample's peak from blocks of reach samples (van Herk's): the largest from a window's start
    # to its block's end and from the next block's start to the window's end (two passes without branches)
    ahead, behind = np.empty(3 * reach + 1), np.empty(3 * reach + 1)
    for i in range(len(out)):
        c = int(np.rint(out[i]))
        low = max(reach, c - reach, math.ceil((out[i - 1] + c) / 2) if i else 0)
        high = min(len(d), c + reach, int((out[i + 1] + c) / 2) if i + 1 < len(out) else len(d))
        peak = window_largest(d, c, min(len(d), c + horizon), False)
        if high - low < 2 or not peak > 0.0:
            continue
        base = low - reach  # the blocks' start: the first window's
        for start in range(base, high - 1, reach):
            stop = min(start + reach, high - 1)
            largest = ahead[start - base] = d[start]  # from the block's start to each sample
            for j in range(start + 1, stop):
                largest = ahead[j - base] = max(largest, d[j])
            largest = behind[stop - 1 - base] = d[stop - 1]  # from each sample to the block's end
            for j in range(stop - 2, start - 1, -1):
                largest = behind[j - base] = max(largest, d[j])
        for j in range(low, high):  # the window d[j - reach:j]
            prior = max(behind[j - reach - base], ahead[j - 1 - base])
            if d[j] > peak * least and d[j] > over * prior and prior <= peak * clear:
                out[i] = j - 0.5
                break
    return out


@jit
def peaks_around(d, centres, after, before, gap):
    """For each of ``centres`` (samples of ``d``), ``d[c:c + after].max(initial=0.0)`` and
    ``d[max(0, c - before):max(1, c - gap)].max(initial=0.0)``: the peak over the ``after`` samples from it and over
    the ``before`` samples before it, less the ``gap`` samples just before."""
    ahead, prior = np.zeros(len(centres)), np.zeros(len(centres))
    for i in range(len(centres)):
        c = centres[i]
        ahead[i] = window_largest(d, c, min(len(d), c + after), False)
        prior[i] = window_largest(d, max(0, c - before), min(len(d), max(1, c - gap)), False)
    return ahead, prior


@jit(inline="always")
def window_largest(x, low, high, magnitude):
    """The largest of 0.0 and ``x[low:high]`` (their magnitudes, with ``magnitude``) as ``peak = max(peak, v)`` in
    order gives it: sixteen samples at a time in vector lanes (:func:`._modes.largest_of`) from ``low`` ≥ 0."""
    peak, j = 0.0, low
    if low >= 0 and high - low >= 16:
        blocks = (high - low) // 16
        peak = largest_magnitude_of(x, low, blocks) if magnitude else largest_of(x, low, blocks)
        j = low + 16 * blocks
    for k in range(j, high):
        peak = max(peak, abs(x[k]) if magnitude else x[k])
    return peak


@jit
def largest_magnitude(x):
    """``np.max(np.abs(x), initial=0.0)``, without the array of magnitudes (in vector lanes: the largest is the same)."""
    return window_largest(x, 0, len(x), True)


@jit
def window_peaks(x, lows, highs):
    """``np.abs(x[lows[i]:highs[i]]).max(initial=0.0)`` for each ``i`` (``lows`` ≥ 0)."""
    out = np.zeros(len(lows))
    for i in range(len(lows)):
        out[i] = window_largest(x, lows[i], min(len(x), highs[i]), True)
    return out


@jit
def frame_peaks(x, frame, count):
    """``np.abs(x[:count * frame]).reshape(count, frame).max(axis=1)``: each frame's largest magnitude (NaN where it
    holds a NaN, as numpy's maximum gives), without numpy's reduction over short rows' time (1000 frames of 5 samples:
    33 against a few us)."""
    out = np.empty(count)
    for i in range(count):
        peak = abs(x[i * frame])
        for j in range(i * frame + 1, (i + 1) * frame):
            if math.isnan(peak):
                break
            peak = max(peak, abs(x[j])) if not math.isnan(x[j]) else abs(x[j])
        out[i] = peak
    return out


@jit
def first_at_least(d, lows, highs, levels):
    """For each ``i``, the first sample of ``d[lows[i]:highs[i]]`` at least ``levels[i]`` (from ``lows[i]``), or -1."""
    out = np.full(len(lows), -1, dtype=np.int64)
    for i in range(len(lows)):
        for j in range(lows[i], min(len(d), highs[i])):
            if d[j] >= levels[i]:
                out[i] = j - lows[i]
                break
    return out



@jit
def lanes_dot(x, x_start, y, y_start, n):
    """``x[x_start:x_start + n] @ y[y_start:y_start + n]`` added in four lanes (every fourth term), summed at the end."""
    s0 = s1 = s2 = s3 = 0.0
    k = 0
    while k + 4 <= n:
        s0 += x[x_start + k] * y[y_start + k]
        s1 += x[x_start + k + 1] * y[y_start + k + 1]
        s2 += x[x_start + k + 2] * y[y_start + k + 2]
        s3 += x[x_start + k + 3] * y[y_start + k + 3]
        k += 4
    while k < n:
        s0 += x[x_start + k] * y[y_start + k]
        k += 1
    return (s0 + s1) + (s2 + s3)


@jit
def prediction_error(a, x):
    """``scipy.signal.lfilter(a, [1.0], x)``: ``x`` through the FIR ``a`` (each output's taps added from the first, in
    blocks of samples a tap at a time: the same to rounding, in vector instructions)."""
    n, taps = len(x), len(a)
    out = np.empty(n)
    for start in range(0, n, 512):
        stop = min(n, start + 512)
        for j in range(start, stop):
            out[j] = a[0] * x[j]
        for k in range(1, min(taps, stop)):
            low = max(start, k)
            block, past, tap = out[low:stop], x[low - k:stop - k], a[k]  # slices: indices the compiler sees are ≥ 0
            for j in range(stop - low):
                block[j] += tap * past[j]
    return out


@jit
def impulse_correlations(e, at, amp, length):
    """The train of impulses ``amp`` at samples ``at`` (``s``, as long as ``e``; repeated samples add up), correlated
    with itself and with ``e`` at lags 0 to ``length - 1``: ``r_ss[k] = Σ s[n] s[n + k]`` and ``r_se[k] = Σ s[n] e[n +
    k]`` (what :func:`.onsets._room_tail` took from FFTs, here added impulse by impulse: to rounding the same)."""
    n = len(e)
    r_ss, r_se = np.zeros(length), np.zeros(length)
    for i in range(len(at)):
        a = at[i] + n if at[i] < 0 else at[i]  # a negative sample counts from the end, as numpy indexes
        for j in range(len(at)):
            k = (at[j] + n if at[j] < 0 else at[j]) - a
            if 0 <= k < length:
                r_ss[k] += amp[i] * amp[j]
        for k in range(min(length, n - a)):
            r_se[k] += amp[i] * e[a + k]
    return r_ss, r_se
