"""The detection stages' compiled loops (drumstroke.analysis._detect) against the Python and numpy code they replaced.

Each oracle below is that code as it stood in :mod:`drumstroke.analysis.onsets` (the same operations in the same
order): the kernels must give the same bits, on seeded random onsets with ties, near neighbours, onsets at the
signal's ends and digital silence.
"""

import itertools

import numpy as np
import pytest

from _recordings import uneven_noise
from drumstroke.analysis import _detect
from drumstroke.analysis.onsets import _merge, _windows


@pytest.fixture
def rng():
    return np.random.default_rng(20261127)


def _merge_in_python(tonal, broadband, gap, deep=(), strong=None):
    """_merge as it was: ``strong`` a function of (tonal, broadband) samples."""
    def floats(samples):
        return np.asarray(samples, dtype=float).tolist()

    marked = sorted([(s, 1) for s in floats(tonal)] + [(s, 0) for s in floats(broadband)]
                    + [(s, 2) for s in floats(deep)])
    times, kinds = [], []
    start = 0
    while start < len(marked):
        stop = start + 1
        while stop < len(marked) and marked[stop][0] - marked[start][0] < gap:
            stop += 1
        s, kind = marked[start]
        if stop > start + 1:
            group = marked[start:stop]
            s, kind = min(group, key=lambda item: item[1])
            near = min((t for t, k in group if k == 1), key=lambda t: abs(t - s), default=None)
            if kind == 0 and near is not None and strong is not None and strong(near, s):
                s, kind = near, 1
        if times and s - times[-1] < gap / 4:
            if kind < kinds[-1]:
                times[-1], kinds[-1] = s, kind
        else:
            times.append(s)
            kinds.append(kind)
        start = stop
    return np.array(times, dtype=float), np.array(kinds, dtype=np.int64)


def _onsets(rng, count, span):
    """``count`` onsets (samples) over ``span``, some rounded to whole or half samples (ties between the kinds)."""
    t = rng.uniform(0.0, span, count)
    t[::3] = np.round(t[::3])
    t[1::5] = np.round(t[1::5]) - 0.5
    return t


@pytest.mark.parametrize("trial", range(40))
def test_merge_is_the_python_merge(rng, trial):
    gap = float(rng.uniform(10.0, 200.0))
    tonal = _onsets(rng, int(rng.integers(0, 60)), 5000.0).tolist()
    broadband = (_onsets(rng, int(rng.integers(0, 60)), 5000.0)).tolist() + tonal[:3]  # some at a tonal one's time
    deep = _onsets(rng, int(rng.integers(0, 20)), 5000.0)
    rises = rng.uniform(0.0, 20.0, len(tonal))
    apart, least = float(rng.uniform(0.0, 30.0)), 10.0
    by_time = dict(zip(tonal, rises))

    def strong(tonal_at, broadband_at):
        return abs(tonal_at - broadband_at) > apart and by_time[tonal_at] >= least

    rises = np.array([by_time[t] for t in tonal])  # a repeated time's rise is its last one's, as the dict had it
    for got, want in [(_merge(tonal, broadband, gap, deep, strong=(rises, apart, least)),
                       _merge_in_python(tonal, broadband, gap, deep, strong=strong)),
                      (_merge(tonal, broadband, gap), _merge_in_python(tonal, broadband, gap))]:
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])


def test_normalised_is_numpys(rng):
    band = uneven_noise(rng, 30001)
    peak = float(np.abs(band).max())
    got = _detect.normalised(band, peak)
    scaled = band / peak
    rise = np.diff(scaled, prepend=scaled[0])
    for g, w in zip(got, (scaled, rise, np.abs(rise))):
        np.testing.assert_array_equal(g, w)


@pytest.mark.parametrize("trial", range(20))
def test_later_peaks_are_the_python_moves(rng, trial):
    x = uneven_noise(rng, 10000)
    q, delay, rate, width = int(rng.integers(2, 30)), float(rng.uniform(0.0, 40.0)), 2000.0, 4
    times = np.sort(rng.uniform(0.0, len(x) * q, 60))
    tried = np.flatnonzero(rng.random(len(times)) < 0.6)
    ahead, gap, least = float(rng.uniform(0.0, 1000.0)), float(rng.uniform(10.0, 200.0)), float(rng.uniform(1.0, 5.0))
    after, before, used = _windows(x, rate, width)
    profile = np.sqrt(after / np.maximum(before, 1e-300 + after * 1e-12))
    want = times.copy()
    for i in tried:  # _try_later's loop as it was
        end = min(times[i] + ahead, times[i + 1] - gap if i + 1 < len(times) else np.inf)
        low, high = int(np.ceil((times[i] + delay) / q)) + 1, min(int((end + delay) / q), len(profile))
        if high > low:
            k = low + int(np.argmax(profile[low:high]))
            if profile[k] >= least:
                want[i] = k * q - delay
    np.testing.assert_array_equal(_detect.later_peaks(x, delay, q, times, tried, ahead, gap, used, least), want)


@pytest.mark.parametrize("trial", range(20))
def test_spiking_is_the_python_test(rng, trial):
    e = uneven_noise(rng, 10000)
    e[rng.integers(0, len(e), 30)] *= 50.0  # spikes
    q, delay = int(rng.integers(2, 30)), float(rng.uniform(0.0, 40.0))
    times = np.sort(rng.uniform(-100.0, len(e) * q + 100.0, 40))
    attack = rng.random(len(times)) < 0.7
    which = np.flatnonzero(attack & (rng.random(len(times)) < 0.8))
    before, gap, early, late = 20, 2, 5, 9
    least = 10.0 ** (float(rng.uniform(0.0, 12.0)) / 20.0)
    power = np.concatenate(([0.0], np.cumsum(e * e)))
    want = attack.copy()
    for i in which:  # _impulsive's loop as it was
        k = round((times[i] + delay) / q)
        near = np.arange(max(before + gap, k - early), min(len(e), k + late))
        if not len(near):
            continue
        prior = np.sqrt((power[near - gap] - power[near - gap - before]) / before)
        want[i] = np.any(np.abs(e[near]) > prior * least)
    np.testing.assert_array_equal(_detect.spiking(e, delay, q, times, which, attack, before, gap, early, late, least),
                                  want)


def _one_attack_each_in_python(d, times, kinds, amplitude, which, width, reach, template_reach, lead, over, start,
                               clear, fitted_lead):
    keep, amplitude = np.ones(len(times), dtype=bool), amplitude.copy()
    for i, j in itertools.pairwise(which):
        a, b = round(times[i]), round(times[j])
        if keep[i] and kinds[i] == 3 != kinds[j] and b - a <= template_reach:
            keep[j] = False
            amplitude[i] = amplitude[j]
            continue
        asked = fitted_lead if kinds[i] == 3 == kinds[j] else lead
        if not keep[i] or b - a > reach or amplitude[j] < amplitude[i] * asked:
            continue
        click = d[a:a + width].max(initial=0.0)
        prior = d[max(0, a - reach):max(1, a - width)].max(initial=0.0)
        between = d[a + width:max(a + width, b - width // 2)]
        dip = (np.lib.stride_tricks.sliding_window_view(between, width).max(axis=1).min()
               if len(between) >= width else click)
        louder = d[b:b + reach].max(initial=0.0)
        onward = dip >= 0.5 * click or prior <= louder * clear
        if click > over * prior and onward and click >= louder * start:
            keep[j] = False
            amplitude[i] = amplitude[j]
        elif louder >= d[a:max(a + 1, b)].max() * lead:
            keep[i] = False
    return keep, amplitude


@pytest.mark.parametrize("trial", range(30))
def test_one_attack_each_is_the_python_loop(rng, trial):
    d = np.abs(uneven_noise(rng, 6000))
    times = np.sort(rng.uniform(0.0, len(d) - 1.0, int(rng.integers(2, 80))))
    times[::4] = np.round(times[::4]) + 0.5  # halves: rounded to even
    kinds = rng.integers(0, 4, len(times))
    amplitude = np.exp(2.0 * rng.standard_normal(len(times)))
    which = np.flatnonzero(rng.random(len(times)) < 0.8)
    fitted_lead = 10.0 ** ((6.0, 3.0, 120.0)[trial % 3] / 20.0)
    args = (which, 12, 240, 120.0, 10.0 ** (6.0 / 20.0), 2.0, 10.0 ** (-40.0 / 20.0), 10.0 ** (-30.0 / 20.0),
            fitted_lead)
    got = _detect.one_attack_each(d, times, kinds, amplitude, *args)
    want = _one_attack_each_in_python(d, times, kinds, amplitude, *args)
    np.testing.assert_array_equal(got[0], want[0])
    np.testing.assert_array_equal(got[1], want[1])
