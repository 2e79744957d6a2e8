"""The compiled loop of the onset detector's test for a room's echo (:func:`.onsets._room_echoes`).

A module of its own (as :mod:`._kernels`) so that importing :mod:`drumstroke.analysis` does not import numba;
:mod:`.onsets` imports it where it runs it.
"""

import math

import numpy as np

from .._jit import jit
from ._kernels import window_dots


@jit
def room_echoes(x, times, levels, clear, tried, attack, which, nearest, farthest, louder, alike, before, after, reach,
                step, most_left, novel):
    """:func:`.onsets._room_echoes`' loop: ``attack`` (a copy) less each of ``tried`` (indices of ``times``, full-rate
    samples, and ``levels``, dB) whose :func:`echo_novelty` is ``novel`` or less, the centres tried those at the same
    delay after each attack as loud (within ``alike`` dB; ``clear`` samples or more clear of the next one) as each
    attack ``louder`` dB or more louder ``nearest`` to ``farthest`` samples before it; ``which`` maps ``times`` to
    ``attack``."""
    attack = attack.copy()
    centres = np.empty(0)
    for k in tried:
        count = 0
        for i in range(len(times)):
            if not (times[k] - times[i] >= nearest and times[k] - times[i] <= farthest
                    and levels[i] >= levels[k] + louder):
                continue
            delay = times[k] - times[i]
            for j in range(len(times)):
                if j != i and abs(levels[j] - levels[i]) <= alike and clear[j] >= delay + before + reach:
                    if count == len(centres):
                        grown = np.empty(max(16, 2 * count))
                        grown[:count] = centres[:count]
                        centres = grown
                    centres[count] = times[j] + delay
                    count += 1
        at = int(np.rint(times[k]))
        if count and echo_novelty(x, at, np.rint(centres[:count]).astype(np.int64), before, after, reach, step,
                                  most_left) <= novel:
            attack[which[k]] = False
    return attack


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
        # the window's products with those at every lag, each summed in order (as a loop over the lags tried: the
        # same to the bit), all lags a term at a time: the lags tried are read from them
        crosses = window_dots(x, low, x[start:start + width], 2 * reach + 1)
        first, last, coarse = 0, 2 * reach, step
        while True:
            found = -1
            for lag in range(first, last + 1, coarse):
                cross = crosses[lag]
                if power[lag] <= 0.0:
                    continue
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


@jit
def layer_echoes(x, times, levels, clear, tried, attack, which, nearest, farthest, before, after, reach, most_left,
                 novel, partners, beyond=None, same=-1.0):
    """:func:`.onsets._layer_echoes`' loop: ``attack`` (a copy) less each of ``tried`` (indices of ``times``, full-rate
    samples, and ``levels``, dB) whose :func:`joint_novelty` is ``novel`` or less: for each attack as loud or louder
    ``nearest`` to ``farthest`` samples before it, the window at the same delay after one of the ``partners`` other
    attacks nearest it in level (``clear`` samples or more clear of the next one, or ``beyond`` samples clear of the
    one after where the next one lies within ``same`` samples of that delay: its own return there; -1, the default:
    none may) that fits it best alone (:func:`_best_window`); ``which`` maps ``times`` to ``attack``."""
    attack = attack.copy()
    if beyond is None:
        far = clear
    else:
        far = beyond
    for k in tried:
        at = int(np.rint(times[k]))
        starts = np.empty(len(times), np.int64)
        count = 0
        for i in range(len(times)):
            delay = times[k] - times[i]
            if not (nearest <= delay <= farthest and levels[i] >= levels[k]):
                continue
            others = np.empty(len(times), np.int64)
            n = 0
            for j in range(len(times)):
                need = delay + after + reach
                if j != i and j != k and (clear[j] >= need or (
                        same >= 0.0 and abs(clear[j] - delay) <= same and far[j] >= need)):
                    others[n] = j
                    n += 1
            others = others[:n][np.argsort(np.abs(levels[others[:n]] - levels[i]), kind="mergesort")[:partners]]
            best = _best_window(x, at, np.rint(times[others] + delay).astype(np.int64), before, after, reach)
            if best >= 0:
                starts[count] = best
                count += 1
        if count and joint_novelty(x, at, starts[:count], before, after, most_left) <= novel:
            attack[which[k]] = False
    return attack


@jit
def _best_window(x, at, centres, before, after, reach):
    """The start of the window (``before + after`` samples) about one of ``centres``, moved by up to ``reach`` samples
    either way, that fits ``x[at - before:at + after]`` best alone (least squares); -1 where none lies within ``x``."""
    width = before + after
    start = at - before
    if start < 0 or start + width > len(x):
        return -1
    own = x[start:start + width]
    energy = np.dot(own, own)
    least, best = math.inf, -1
    for i in range(len(centres)):
        low = centres[i] - reach - before
        if low < 0 or low + width + 2 * reach > len(x):
            continue
        for lag in range(2 * reach + 1):
            other = x[low + lag:low + lag + width]
            cross, power = np.dot(own, other), np.dot(other, other)
            if power > 0.0 and energy - cross * cross / power < least:
                least, best = energy - cross * cross / power, low + lag
    return best


@jit
def joint_novelty(x, at, starts, before, after, most_left):
    """How much more of ``x`` around ``at`` is new after it than before it once the windows at ``starts`` explain it
    together: ``x[at - before:at + after]`` fitted by least squares by the sum of the same-length windows of ``x`` from
    each of ``starts``; the mean power the fit leaves over the ``after`` samples over that over the ``before`` samples.
    ``inf`` where the window does not lie within ``x`` or the fit leaves more than ``most_left`` of its energy."""
    width = before + after
    start = at - before
    if start < 0 or start + width > len(x):
        return math.inf
    m = len(starts)
    own = x[start:start + width]
    # the normal equations (each product one dot of two windows of x), solved by least squares: the same windows
    # chosen for two notes make them singular
    gram, cross = np.empty((m, m)), np.empty(m)
    for i in range(m):
        cross[i] = np.dot(x[starts[i]:starts[i] + width], own)
        for j in range(i + 1):
            gram[i, j] = gram[j, i] = np.dot(x[starts[i]:starts[i] + width], x[starts[j]:starts[j] + width])
    scales = np.linalg.lstsq(gram, cross)[0]
    left = own.copy()
    for j in range(m):
        left -= scales[j] * x[starts[j]:starts[j] + width]
    early, late = 0.0, 0.0
    for k in range(width):
        if k < before:
            early += left[k] * left[k]
        else:
            late += left[k] * left[k]
    if early + late > most_left * (own @ own):
        return math.inf
    return (late / after) / max(early / before, 1e-300)
