"""The compiled loop of the onset detector's test for a room's echo (:func:`.onsets._room_echoes`).

A module of its own (as :mod:`._kernels`) so that importing :mod:`drumstroke.analysis` does not import numba;
:mod:`.onsets` imports it where it runs it.
"""

import math

from .._jit import jit


@jit
def echo_novelty(x, at, centres, before, after, reach):
    """How much more of ``x`` around ``at`` is new after it than before it, once the sound around another time explains
    it: the window ``x[at - before:at + after]`` is fitted by least squares by the same window around each of
    ``centres`` moved by up to ``reach`` samples either way; where the fit leaves least, the mean power it leaves
    over the ``after`` samples over that over the ``before`` samples. ``inf`` where no window lies within ``x``."""
    width = before + after
    start = at - before
    own = 0.0
    for k in range(width):
        own += x[start + k] * x[start + k]
    least, novelty = math.inf, math.inf
    for i in range(len(centres)):
        for lag in range(-reach, reach + 1):
            other = centres[i] + lag - before
            if other < 0 or other + width > len(x) or start < 0 or start + width > len(x):
                continue
            cross, power = 0.0, 0.0
            for k in range(width):
                cross += x[start + k] * x[other + k]
                power += x[other + k] * x[other + k]
            if power <= 0.0:
                continue
            left = own - cross * cross / power
            if left < least:
                scale = cross / power
                early, late = 0.0, 0.0
                for k in range(before):
                    r = x[start + k] - scale * x[other + k]
                    early += r * r
                for k in range(before, width):
                    r = x[start + k] - scale * x[other + k]
                    late += r * r
                least = left
                novelty = (late / after) / max(early / before, 1e-300)
    return novelty
