"""The onset detector's compiled loops (:mod:`.onsets`): each computes what the numpy code it replaced did, in the same order.

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
