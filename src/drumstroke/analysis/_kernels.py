"""The onset detector's compiled loops (:mod:`.onsets`): each computes what the numpy code it replaced did, in the same order.

They are a module of their own so that importing :mod:`drumstroke.analysis` does not import numba
(:mod:`drumstroke._jit`); :mod:`.onsets` imports them where it runs them.
"""

import math

import numpy as np

from .._jit import jit


@jit
def jump_at(x, i, width):
    """:func:`.onsets._jump_at` at sample ``i``, windows of ``width`` samples: :func:`.onsets._windows`' sums in its order (the same bits)."""
    half = max(1, width // 2)
    low, high = max(0, i - half - 4 * width), min(len(x), i + half + width + 1)
    size = high - low
    if size <= 0:
        return 0.0
    power = np.empty(size + 1)
    power[0] = total = 0.0
    for n in range(size):  # the running sum, as np.cumsum adds
        total += x[low + n] * x[low + n]
        power[n + 1] = total
    best = 0.0
    for k in range(max(i - half, low) - low, min(i + half + 1, high) - low):
        if k < min(4 * width, i):  # a full window before, or the signal's start
            continue
        after = (power[min(k + width, size)] - power[k]) / width
        before = (power[k] - power[max(k - 4 * width, 0)]) / (4 * width)
        best = max(best, math.sqrt(after / max(before, 1e-300 + after * 1e-12)))
    return best


@jit
def pursue(r, centres, lead, basis, solve, gram, head, head_norm, width, tail, jumps, likeness, where, at, amp):
    """:func:`.onsets._pursue`'s loop over the onsets (at samples ``centres``), in time order: ``r`` less each one's fit, in place.

    For each onset: its jump in ``r`` (:func:`jump_at`), then the signature (``basis``: it and its
    derivative; ``solve``: their least-squares operator; ``gram``: their normal equations) fitted at the best
    of five starts, taken off with the room's ``tail`` (empty: none) scaled by it. Fills ``jumps``,
    ``likeness``, ``where``, ``at`` and ``amp``.
    """
    size, count, two = basis.shape[0], head.shape[0], basis.shape[1] > 1
    half = max(1, width // 2)
    for i in range(len(centres)):
        c = centres[i]
        # the jump: the next window's power over the 4 windows before, the largest within half a window
        low, high = max(0, c - half - 4 * width), min(len(r), c + half + width + 1)
        jumps[i] = jump_at(r[low:high], c - low, width) if high - low > width else 0.0
        best, best_cost, w0, w1 = -1, np.inf, 0.0, 0.0
        for start in range(c - lead - 2, c - lead + 3):
            if start < 0 or start + size > len(r):
                continue
            dot = norm = 0.0
            for j in range(count):
                dot += r[start + j] * head[j]
                norm += r[start + j] * r[start + j]
            likeness[i] = max(likeness[i], abs(dot) / (math.sqrt(norm) * head_norm + 1e-300))
            a = b = energy = 0.0
            for j in range(size):
                a += solve[0, j] * r[start + j]
                b += solve[1, j] * r[start + j] if two else 0.0
                energy += r[start + j] * r[start + j]
            fit = a * (a * gram[0, 0] + b * gram[1, 0]) + b * (a * gram[0, 1] + b * gram[1, 1]) if two else a * a * gram[0, 0]
            cost = energy - fit
            if cost < best_cost:
                best, best_cost, w0, w1 = start, cost, a, b
        if best < 0:
            continue
        for j in range(size):
            r[best + j] -= basis[j, 0] * w0 + basis[j, 1] * w1 if two else basis[j, 0] * w0
        for j in range(size, min(len(tail), len(r) - best)):
            r[best + j] -= w0 * tail[j]
        at[i], amp[i] = best, w0
        shift = -w1 / w0 if w0 != 0.0 else 0.0
        where[i] = best + lead + min(max(shift, -1.0), 1.0)


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
