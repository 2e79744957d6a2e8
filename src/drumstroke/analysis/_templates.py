"""The compiled loops of the onset detector's template stages (:mod:`.onsets`: the template fit, ``peak_db``'s
templates): each computes what the numpy code it replaced did, in the same order, to the bit.

A module of its own (as :mod:`._kernels`) so that importing :mod:`drumstroke.analysis` does not import numba;
:mod:`.onsets` imports it where it runs it.
"""

import numpy as np

from .._jit import jit


_BLOCK = 256  # samples a time: a dozen notes' waveforms over them stay in the first-level cache


@jit
def layer_median(x, at, scales, whole, clean):
    """:func:`.onsets._layer_template`'s median: note ``i``'s waveform is ``x[at[i]:at[i] + whole[i]] / scales[i]``
    (``at`` ≥ 0, ``at + whole`` ≤ ``len(x)``), clean over its first ``clean[i]`` samples (``clean`` ≤ ``whole``).

    Over each part between the sorted, distinct values of 0, ``whole`` and ``clean``, the waveforms that last past
    it (three or more), else the clean ones that do, are the part's; at each sample the median of theirs (the
    middle one, or the mean of the middle two as ``np.median`` takes it); up to the first part none lasts over.
    """
    count = len(at)
    bounds = np.unique(np.concatenate((np.zeros(1, dtype=np.int64), whole, clean)))
    out = np.empty(bounds[-1])
    chosen, buffer = np.empty(count, dtype=np.int64), np.empty((count, _BLOCK))
    size = 0
    for p in range(len(bounds) - 1):
        low, high = bounds[p], bounds[p + 1]
        voted = 0
        for i in range(count):
            voted += whole[i] >= high
        m = 0
        for i in range(count):
            if (whole[i] >= high) if voted >= 3 else (clean[i] >= high):
                chosen[m] = i
                m += 1
        if m == 0:
            break
        for first in range(low, high, _BLOCK):
            _block_median(x, at, scales, chosen[:m], first, min(first + _BLOCK, high), buffer, out)
        size = high
    return out[:size].copy()


@jit
def _block_median(x, at, scales, chosen, first, last, buffer, out):
    """``out[first:last]``: at each sample the median of the waveforms ``chosen`` (:func:`layer_median`'s), their values
    sorted by an odd-even transposition network (each comparator a pass over the block, in vector instructions)."""
    m, width = len(chosen), last - first
    for r in range(m):
        i = chosen[r]
        row, scale = buffer[r], scales[i]
        for j in range(width):
            row[j] = x[at[i] + first + j] / scale
    for step in range(m):
        for r in range(step % 2, m - 1, 2):
            lower, upper = buffer[r], buffer[r + 1]
            for j in range(width):
                u, v = lower[j], upper[j]
                swap = v < u  # swapped only when out of order: the values are kept, the signs of zero too
                lower[j], upper[j] = (v, u) if swap else (u, v)
    middle = buffer[m // 2]
    if m % 2:
        for j in range(width):
            out[first + j] = middle[j]
    else:
        below = buffer[m // 2 - 1]
        for j in range(width):
            out[first + j] = (below[j] + middle[j]) / 2.0
