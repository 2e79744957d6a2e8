"""The compiled loop of :func:`.onsets._template_search`: attacks found by fitting the recording's own attack.

A module of its own (as :mod:`._kernels`) so that importing :mod:`drumstroke.analysis` does not import numba;
:mod:`.onsets` imports it where it runs it. Its sums run in another order than numpy's (``np.correlate``, ``@``):
the same to rounding.
"""

import math

import numpy as np

from .._jit import jit


@jit(error_model="numpy")
def template_search(remainder, template, head, times, shifts, refused, offset, pre, gap, shortest, fit, bounce,
                    signature, reach, likeness, refused_likeness, ratio_low, ratio_high, least):
    """:func:`.onsets._template_search`'s loop over the attacks at ``times`` (full-rate samples, in order).

    ``remainder`` (the band, changed in place) less each attack's fitted ``template`` (``pre`` samples before its
    attack; ``head`` its start), each at ``times`` less ``shifts`` (rounded: an attack the template timed at its
    fit's sample, ``offset`` the template's attack less its whole sample); ``refused`` the onsets step 4 refused
    (samples, in order); ``gap``, ``shortest`` (the shortest fit), ``fit``, ``bounce``, ``signature`` and
    ``reach`` in samples. Returns the attacks found (their times, in order) and each one's correlation.
    """
    n, size = len(remainder), len(template)
    head_energy = 0.0
    for j in range(len(head)):
        head_energy += head[j] * head[j]
    found, likes, count = np.empty(n // max(gap, 1) + 1), np.empty(n // max(gap, 1) + 1), 0  # each new one gap after
    i, pending = 0, -1.0
    while True:
        if pending >= 0.0:
            c, pending = int(np.rint(pending - offset)), -1.0  # where the template's attack fell
        elif i < len(times):
            c, i = int(np.rint(times[i] - shifts[i])), i + 1
        else:
            break
        following = int(np.rint(times[i] - shifts[i])) if i < len(times) else n
        span = min(max(pre + shortest, min(pre + fit, following - c)), size, n - c + pre)
        if c < pre or span <= pre:
            continue
        scale = _dot(remainder, c - pre, template, span) / _dot(template, 0, template, span)
        for j in range(min(size, n - c + pre)):
            remainder[c - pre + j] -= scale * template[j]
        at, like = -1, 0.0
        if scale > 0.0:
            high = min(following - gap, c + bounce, n - len(head) + pre)
            at, like = _bounce_after(remainder, template, head, head_energy, c + gap, high, following, pre, shortest,
                                     fit, reach, scale, likeness, ratio_low, ratio_high)
        if at < 0:
            at, like = _refused_fit(remainder, template, head, head_energy, refused, c + signature,
                                    min(following - gap, n - len(head) + pre), pre, fit, reach, refused_likeness,
                                    least)
        if at >= 0:
            pending = at + offset
            found[count], likes[count], count = pending, like, count + 1
    return found[:count].copy(), likes[:count].copy()


@jit(error_model="numpy")
def _bounce_after(remainder, template, head, head_energy, low, high, following, pre, shortest, fit, reach, scale,
                  likeness, ratio_low, ratio_high):
    """The first sample in ``[low, high)`` where ``head`` fits ``remainder`` (by ``likeness``, scaled ``ratio_low`` to
    ``ratio_high`` times ``scale``) and the template over ``fit`` samples (up to ``following``) does too, moved to
    the start's best correlation within ``reach`` samples after: (sample, correlation), or (-1, 0)."""
    if high <= low:
        return -1, 0.0
    count = high - low
    own = _energies(remainder, low - pre, count, len(head))
    floor = (ratio_low * scale) ** 2 * head_energy  # the energy a fit so scaled needs (Cauchy-Schwarz)
    if not own.max() >= floor:
        return -1, 0.0
    dots = _correlations(remainder, low - pre, head, count)
    for k in range(count):
        if own[k] < floor:
            continue
        like = dots[k] / math.sqrt(max(own[k] * head_energy, 1e-300))
        ratio = dots[k] / (head_energy * scale)
        if like < likeness or ratio < ratio_low or ratio > ratio_high:
            continue
        at = low + k
        span = min(max(pre + shortest, min(pre + fit, following - at)), len(template), len(remainder) - at + pre)
        whole = _dot(remainder, at - pre, template, span)
        if whole < likeness * math.sqrt(max(_dot(remainder, at - pre, remainder[at - pre:], span)
                                            * _dot(template, 0, template, span), 1e-300)):
            continue  # the start alone is often met in a drum's beating modes
        best = k
        for m in range(k + 1, min(k + reach + 1, count)):
            if dots[m] / math.sqrt(max(own[m] * head_energy, 1e-300)) > dots[best] / math.sqrt(
                    max(own[best] * head_energy, 1e-300)):
                best = m
        return low + best, dots[best] / math.sqrt(max(own[best] * head_energy, 1e-300))
    return -1, 0.0


@jit(error_model="numpy")
def _refused_fit(remainder, template, head, head_energy, refused, low, high, pre, fit, reach, refused_likeness, least):
    """The first of ``refused`` in ``[low, high)`` where the template's first ``fit`` samples, at their best lag within
    ``reach`` samples, correlate by ``refused_likeness`` and scale ``least`` or more, and ``head`` there correlates
    so too: (that lag's sample, the fit's correlation), or (-1, 0)."""
    span = min(pre + fit, len(template))
    energy = _dot(template, 0, template, span)
    lags = 2 * reach + 1
    for r in range(len(refused)):
        if refused[r] < max(low, pre + reach) or refused[r] >= high - reach:
            continue
        c = int(np.rint(refused[r]))
        if c - pre + reach + span > len(remainder):
            continue
        start = c - pre - reach
        own = _energies(remainder, start, lags, len(head))
        dots = _correlations(remainder, start, head, lags)
        starts = np.empty(lags)
        for k in range(lags):
            starts[k] = dots[k] / math.sqrt(max(own[k] * head_energy, 1e-300))
        if not starts.max() >= refused_likeness:
            continue  # the start's correlations first: cheaper, and they seldom pass where no note starts
        whole = _correlations(remainder, start, template[:span], lags)
        wide = _energies(remainder, start, lags, span)
        best, best_like = 0, -np.inf
        for k in range(lags):
            like = whole[k] / math.sqrt(max(wide[k] * energy, 1e-300))
            if like > best_like:
                best, best_like = k, like
        if best_like >= refused_likeness and whole[best] / energy >= least and starts[best] >= refused_likeness:
            return c - reach + best, best_like
    return -1, 0.0


@jit(error_model="numpy")
def _dot(x, start, t, count):
    """``x[start:start + count] @ t[:count]``, summed in order."""
    total = 0.0
    for j in range(count):
        total += x[start + j] * t[j]
    return total


@jit(error_model="numpy")
def _correlations(x, start, t, count):
    """The dot products of ``t`` with the ``count`` windows of ``x`` from ``start`` (one sample apart), each summed in
    order of ``t``'s samples, all windows at once: over a copy of the samples read, which the compiler then knows
    apart from the sums, and so runs in vector instructions."""
    samples = x[start:start + count + len(t) - 1].copy()
    out = np.zeros(count)
    for j in range(len(t)):
        v = t[j]
        window = samples[j:j + count]
        for k in range(count):
            out[k] += window[k] * v
    return out


@jit(error_model="numpy")
def _energies(x, start, count, size):
    """The energies of the ``count`` windows of ``size`` samples of ``x`` from ``start`` (running sums)."""
    out = np.empty(count)
    total = 0.0
    for j in range(size):
        total += x[start + j] * x[start + j]
    out[0] = total
    for k in range(1, count):
        total += x[start + k + size - 1] * x[start + k + size - 1] - x[start + k - 1] * x[start + k - 1]
        out[k] = max(total, 0.0)
    return out
