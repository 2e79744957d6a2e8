"""The compiled loop of the onset detector's test for a room's echo (:func:`.onsets._room_echoes`).

A module of its own (as :mod:`._kernels`) so that importing :mod:`drumstroke.analysis` does not import numba;
:mod:`.onsets` imports it where it runs it.
"""

import math

import numpy as np

from .._jit import jit


@jit
def echo_novelty(x, at, centres, before, after, reach, step, most_left):
    """How much more of ``x`` around ``at`` is new after it than before it, once the sound around another time explains
    it: the window ``x[at - before:at + after]`` is fitted by least squares by the same window around each of
    ``centres`` moved by up to ``reach`` samples either way (every ``step`` samples, then every sample about the
    best); where the fit leaves least, the mean power it leaves over the ``after`` samples over that over the
    ``before`` samples. ``inf`` where no window lies within ``x`` or the best fit leaves more than ``most_left`` of
    the window's energy (that sound does not explain it)."""
    width = before + after
    start = at - before
    if start < 0 or start + width > len(x):
        return math.inf
    own = 0.0
    for k in range(width):
        own += x[start + k] * x[start + k]
    least, best, scale = math.inf, -1, 0.0
    for i in range(len(centres)):
        low = centres[i] - reach - before
        if low < 0 or low + width + 2 * reach > len(x):
            continue
        # the windows' powers at every lag, from one running sum
        power = np.empty(2 * reach + 1)
        total = 0.0
        for k in range(width):
            total += x[low + k] * x[low + k]
        power[0] = total
        for lag in range(1, 2 * reach + 1):
            total += x[low + lag + width - 1] * x[low + lag + width - 1] - x[low + lag - 1] * x[low + lag - 1]
            power[lag] = total
        first, last, coarse = 0, 2 * reach, step
        while True:
            found = -1
            for lag in range(first, last + 1, coarse):
                if power[lag] <= 0.0:
                    continue
                cross = 0.0
                for k in range(width):
                    cross += x[start + k] * x[low + lag + k]
                left = own - cross * cross / power[lag]
                if left < least:
                    least, best, scale, found = left, low + lag, cross / power[lag], lag
            if coarse == 1 or found < 0:
                break
            first, last, coarse = max(0, found - step + 1), min(2 * reach, found + step - 1), 1
    if best < 0 or least > most_left * own:
        return math.inf
    early, late = 0.0, 0.0
    for k in range(width):
        r = x[start + k] - scale * x[best + k]
        if k < before:
            early += r * r
        else:
            late += r * r
    return (late / after) / max(early / before, 1e-300)
