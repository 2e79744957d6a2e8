"""The room echo test's compiled loops (drumstroke.analysis._rooms) against plain Python and numpy.

``echo_novelty``'s oracle runs the same coarse-to-fine search over lags with numpy's dot products and least squares;
``room_echoes``' oracle is the partner search as it stood in :mod:`drumstroke.analysis.onsets` (numpy masks, one
``echo_novelty`` call per attack tried, given the oracle's novelty). Seeded random sounds with repeated notes,
attacks near the signal's ends and levels on the bounds.
"""

import math

import numpy as np
import pytest

from drumstroke.analysis import _rooms


@pytest.fixture
def rng():
    return np.random.default_rng(20261127)


def _novelty_in_numpy(x, at, centres, before, after, reach, step, most_left):
    """echo_novelty by numpy: each window's fit by ``np.linalg.lstsq``, the lags searched as the kernel does."""
    width, start = before + after, at - before
    if start < 0 or start + width > len(x):
        return math.inf
    own = x[start:start + width]
    least, best, scale = math.inf, -1, 0.0
    for centre in centres:
        low = centre - reach - before
        if low < 0 or low + width + 2 * reach > len(x):
            continue
        first, last, coarse = 0, 2 * reach, step
        while True:
            found = -1
            for lag in range(first, last + 1, coarse):
                window = x[low + lag:low + lag + width]
                if window @ window <= 0.0:
                    continue
                fit = np.linalg.lstsq(window[:, None], own, rcond=None)[0][0]
                left = np.sum((own - fit * window) ** 2)
                if left < least:
                    least, best, scale, found = left, low + lag, fit, lag
            if coarse == 1 or found < 0:
                break
            first, last, coarse = max(0, found - step + 1), min(2 * reach, found + step - 1), 1
    if best < 0 or least > most_left * (own @ own):
        return math.inf
    left = own - scale * x[best:best + width]
    return np.mean(left[before:] ** 2) / max(np.mean(left[:before] ** 2), 1e-300)


def _sound(rng, notes, count=30000):
    """White noise 50 dB under ``notes`` (start, scale) of one decaying note, each returned 4000 samples later at a
    tenth of its amplitude."""
    note = np.convolve(rng.standard_normal(2000), np.hanning(16), mode="same") * np.exp(-np.arange(2000) / 400.0)
    x = 3e-3 * rng.standard_normal(count)
    for start, scale in notes:
        for at, gain in ((start, scale), (start + 4000, 0.1 * scale)):
            stop = min(count, at + len(note))
            x[at:stop] += gain * note[:stop - at]
    return x


@pytest.mark.parametrize("seed", range(6))
def test_echo_novelty_is_numpys_coarse_to_fine_least_squares(seed):
    rng = np.random.default_rng(seed)
    x = _sound(rng, [(1000, 1.0), (9000, 0.7), (17000, 0.4)])
    x[24000:25000] = 0.0  # digital silence: windows of no power
    # the first and the third note's returns, fitted by the second's (not by themselves: a window's fit by itself
    # leaves rounding alone, whose ratio is any)
    for at in (4000 + 1000 + 150, 4000 + 17000 + 150 + int(rng.integers(-5, 5)), 100, 29950, 24500):
        centres = np.array([4000 + 9000 + 150 + int(rng.integers(-20, 20)), 50, 29990, 24400, 24500])
        for step in (1, 3, 4):
            got = _rooms.echo_novelty(x, at, centres, 240, 200, 24, step, 0.5)
            want = _novelty_in_numpy(x, at, centres, 240, 200, 24, step, 0.5)
            assert got == pytest.approx(want, rel=1e-9) or got == want == math.inf


def _room_echoes_in_numpy(x, times, levels, clear, tried, attack, which, nearest, farthest, louder, alike, before,
                          after, reach, step, most_left, novel):
    attack = attack.copy()
    for k in tried:
        sources = np.flatnonzero((times[k] - times >= nearest) & (times[k] - times <= farthest)
                                 & (levels >= levels[k] + louder))
        centres = []
        for i in sources:
            delay = times[k] - times[i]
            partners = np.abs(levels - levels[i]) <= alike
            partners[i] = False
            partners &= clear >= delay + before + reach
            centres.extend(times[partners] + delay)
        if centres and _novelty_in_numpy(x, round(times[k]), np.rint(centres).astype(np.int64), before, after, reach,
                                         step, most_left) <= novel:
            attack[which[k]] = False
    return attack


@pytest.mark.parametrize("seed", range(8))
def test_room_echoes_is_the_numpy_partner_search(seed):
    """Notes and their returns (some levels and clear spans on the bounds), a few near the ends; the novelty's
    bounds such that both answers occur."""
    rng = np.random.default_rng(seed)
    starts = np.sort(rng.choice(np.arange(200, 24000, 500), size=10, replace=False))
    x = _sound(rng, [(int(s), float(rng.uniform(0.3, 1.0))) for s in starts])
    times = np.sort(np.concatenate([starts, starts + 4000, [30, 29980]]) + rng.uniform(-0.5, 0.5, 22))
    levels = rng.uniform(-10.0, 0.0, len(times))
    returns = np.isin(np.rint(times), starts + 4000) | (rng.random(len(times)) < 0.2)
    levels[returns] -= 20.0
    levels[3] = levels[2] + 6.0  # within alike on the bound
    clear = rng.uniform(0.0, 12000.0, len(times))  # how long each stays clear: drawn, some on the bound
    clear[[0, 5]] = times[7] - times[[0, 5]] + 240 + 24
    tried = np.flatnonzero(returns).astype(np.int64)
    which = np.sort(rng.choice(40, size=len(times), replace=False)).astype(np.int64)
    attack = np.zeros(40, dtype=bool)
    attack[which] = True
    for novel in (0.5, 2.0, 1e9):
        got = _rooms.room_echoes(x, times, levels, clear, tried, attack, which, 1680.0, 14400.0, 15.0, 6.0, 240, 240,
                                 24, 3, 0.5, novel)
        want = _room_echoes_in_numpy(x, times, levels, clear, tried, attack, which, 1680.0, 14400.0, 15.0, 6.0, 240,
                                     240, 24, 3, 0.5, novel)
        np.testing.assert_array_equal(got, want)
