"""The compiled loops of the onset detector's detection stages (:mod:`.onsets`, steps 2-5): each computes what the
Python and numpy code it replaced did, with the same operations in the same order, so its results are the same to
the bit (tests/test_onsets_detect.py holds them against that code).

A module of its own (as :mod:`._kernels`) so that importing :mod:`drumstroke.analysis` does not import numba;
:mod:`.onsets` imports it where it runs it.
"""

import math

import numpy as np

from .._jit import jit


@jit
def normalised(band, peak):
    """``band / peak``, its first difference (``np.diff(.., prepend=its first sample)``) and that difference's magnitude."""
    out, rise, d = np.empty(len(band)), np.empty(len(band)), np.empty(len(band))
    last = band[0] / peak if len(band) else 0.0
    for j in range(len(band)):
        value = band[j] / peak
        out[j], rise[j] = value, value - last
        d[j] = abs(rise[j])
        last = value
    return out, rise, d


@jit
def merge(values, kinds, rises, gap, apart, strong_rise, strong):
    """:func:`.onsets._merge` of the onsets at ``values`` (samples) found as ``kinds`` say (0 broadband, 1 tonal,
    2 deep), sorted by value then kind; ``rises`` are the tonal ones' (read when ``strong``: a group's tonal time
    more than ``apart`` from its broadband one and rising ``strong_rise`` times is taken instead).

    Returns the onsets' times and kinds."""
    times, chosen = np.empty(len(values)), np.empty(len(values), dtype=np.int64)
    count, start = 0, 0
    while start < len(values):  # a group: the onsets closer than gap to its first
        stop = start + 1
        while stop < len(values) and values[stop] - values[start] < gap:
            stop += 1
        s, kind = values[start], kinds[start]
        if stop > start + 1:
            first = start  # the first of the group's least kind (the earliest broadband one, if any)
            for j in range(start + 1, stop):
                if kinds[j] < kinds[first]:
                    first = j
            s, kind = values[first], kinds[first]
            near = -1  # the group's tonal time nearest that choice (the first of equals)
            for j in range(start, stop):
                if kinds[j] == 1 and (near < 0 or abs(values[j] - s) < abs(values[near] - s)):
                    near = j
            if kind == 0 and near >= 0 and strong and abs(values[near] - s) > apart and rises[near] >= strong_rise:
                s, kind = values[near], 1
        if count and s - times[count - 1] < gap / 4:
            if kind < chosen[count - 1]:
                times[count - 1], chosen[count - 1] = s, kind
        else:
            times[count], chosen[count] = s, kind
            count += 1
        start = stop
    return times[:count].copy(), chosen[:count].copy()


@jit
def later_peaks(x, delay, q, times, tried, ahead, gap, width, least):
    """:func:`.onsets._try_later`'s moves: for each of ``tried`` (indices of ``times``, full-rate samples), where the RMS
    jump of ``x`` (the band's remainder at ``1 / q`` the rate, the filter's delay ``delay`` full-rate samples; the next
    ``width`` samples over the ``4 width`` before, as :func:`.onsets._windows` gives) is largest from a sample after
    it to ``ahead`` after it (or ``gap`` before the next onset), when that jump is ``least`` or more.

    Returns the times, those moved there (full-rate samples)."""
    count = len(x)
    power = np.zeros(count + 1)
    power[1:] = np.cumsum(x * x)
    moved = times.copy()
    for i in tried:
        end = times[i] + ahead
        if i + 1 < len(times):
            end = min(end, times[i + 1] - gap)
        low, high = int(np.ceil((times[i] + delay) / q)) + 1, min(int((end + delay) / q), count)
        best, at = -1.0, -1
        for k in range(low, high):
            after = (power[min(k + width, count)] - power[k]) / width
            before = (power[k] - power[max(k - 4 * width, 0)]) / (4 * width)
            jump = math.sqrt(after / max(before, 1e-300 + after * 1e-12))
            if jump > best:
                best, at = jump, k
        if at >= 0 and best >= least:
            moved[i] = at * q - delay
    return moved


@jit
def spiking(e, delay, q, times, which, attack, before, gap, early, late, least):
    """:func:`.onsets._impulsive`'s test: each attack ``which`` (indices of ``times``, full-rate samples) stays one when
    the innovation ``e`` (at ``1 / q`` the rate, the filter's delay ``delay`` full-rate samples) from ``early`` samples
    before it to ``late`` after passes, at some sample, ``least`` times its RMS over the ``before`` samples up to
    ``gap`` before that sample.

    Returns ``attack`` so judged (a copy)."""
    power = np.zeros(len(e) + 1)
    power[1:] = np.cumsum(e * e)
    out = attack.copy()
    for i in which:
        k = int(np.rint((times[i] + delay) / q))
        low, high = max(before + gap, k - early), min(len(e), k + late)
        if high <= low:
            continue
        spike = False
        for n in range(low, high):
            if abs(e[n]) > math.sqrt((power[n - gap] - power[n - gap - before]) / before) * least:
                spike = True
                break
        out[i] = spike
    return out


@jit
def _peak(d, low, high):
    """``d[low:high].max(initial=0.0)`` (``d`` ≥ 0; ``low`` ≥ 0)."""
    peak = 0.0
    for j in range(low, min(high, len(d))):
        peak = max(peak, d[j])
    return peak


@jit
def one_attack_each(d, times, kinds, amplitude, which, width, reach, template_reach, lead, over, start, clear,
                    fitted_lead):
    """:func:`.onsets._one_attack_each`'s pairs of consecutive attacks ``which`` (indices of ``times``, full-rate
    samples): ``width`` and ``reach`` samples, ``template_reach`` samples (a float), ``lead``, ``start`` and ``clear``
    the ratios ``lead_db``, ``start_db``, ``start_clear_db`` and ``fitted_lead_db`` stand for, ``over`` the
    ``start_over``.

    Returns which candidates are kept and their amplitudes (all, a copy)."""
    keep, amplitude = np.ones(len(times), dtype=np.bool_), amplitude.copy()
    for n in range(len(which) - 1):
        i, j = which[n], which[n + 1]
        a, b = int(np.rint(times[i])), int(np.rint(times[j]))
        if keep[i] and kinds[i] == 3 and kinds[j] != 3 and b - a <= template_reach:
            keep[j] = False  # the template's fit of the detection just after it: one attack, the detection's level
            amplitude[i] = amplitude[j]
            continue
        both_fitted = kinds[i] == 3 and kinds[j] == 3
        if not keep[i] or b - a > reach or amplitude[j] < amplitude[i] * (fitted_lead if both_fitted else lead):
            continue
        click = _peak(d, a, a + width)
        prior = _peak(d, max(0, a - reach), max(1, a - width))
        dip = click
        stop = min(max(a + width, b - width // 2), len(d))
        if stop - (a + width) >= width:  # the least of the largest over each window of width between them
            dip = np.inf
            for k in range(a + width, stop - width + 1):
                dip = min(dip, _peak(d, k, k + width))
        louder = _peak(d, b, b + reach)
        onward = dip >= 0.5 * click or prior <= louder * clear
        if click > over * prior and onward and click >= louder * start:
            keep[j] = False
            amplitude[i] = amplitude[j]
        elif louder >= _peak(d, a, max(a + 1, b)) * lead:
            keep[i] = False
    return keep, amplitude
