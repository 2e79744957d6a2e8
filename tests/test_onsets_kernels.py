"""The onset detector's compiled kernels against the numpy and scipy code they stand for (drumstroke.analysis._kernels).

Filters and sliding correlations must agree to the bit (the same operations in the same order); sums
the kernels add in another order (the upsampled peak, the 2-by-2 solves, Parseval's energies, the prediction
error filter) to 1e-12 relative. Signals are seeded, with silences and 60-dB level changes where the bounds of a kernel rely on them.
"""

import numpy as np
import pytest
from numpy.lib.stride_tricks import sliding_window_view
from scipy.signal import butter, lfilter, sosfilt, upfirdn

from _recordings import uneven_noise
from drumstroke.analysis import _front, _kernels
from drumstroke.analysis.onsets import _interpolator, _low_pass


@pytest.fixture
def rng():
    return np.random.default_rng(20261127)


@pytest.mark.parametrize("q", [1, 3, 8, 24, 45])
def test_decimating_low_pass_is_scipys_sosfilt(rng, q):
    x = uneven_noise(rng, 20001)
    sos, _ = _low_pass(0.8 * 48000 / max(q, 2) / 2.0, 48000)
    np.testing.assert_array_equal(_kernels.low_pass_every(sos, x, q), sosfilt(sos, x)[::q])


@pytest.mark.parametrize(("q", "q_other", "q_third"), [(2, 2, 2), (8, 24, 48), (9, 45, 12)])
def test_three_decimating_low_passes_in_one_pass_are_each_scipys_sosfilt(rng, q, q_other, q_third):
    x = uneven_noise(rng, 20001)
    (sos, _), (other, _), (third, _) = (_low_pass(0.8 * 48000 / each / 2.0, 48000) for each in (q, q_other, q_third))
    low, low_other, low_third = _front.low_pass_three(sos, q, other, q_other, third, q_third, x)
    np.testing.assert_array_equal(low, sosfilt(sos, x)[::q])
    np.testing.assert_array_equal(low_other, sosfilt(other, x)[::q_other])
    np.testing.assert_array_equal(low_third, sosfilt(third, x)[::q_third])


def test_high_pass_section_is_scipys_sosfilt(rng):
    x = uneven_noise(rng, 20001)
    sos = butter(2, 60.0, btype="highpass", fs=48000, output="sos")
    np.testing.assert_array_equal(_front.high_pass(sos, x)[0], sosfilt(sos, x))


def test_best_lag_is_the_sliding_correlations_argmax(rng):
    for _ in range(300):
        size, count = int(rng.integers(2, 300)), int(rng.integers(2, 200))
        x, low = uneven_noise(rng, count + size + 10), int(rng.integers(0, 10))
        template = x[low + 3:low + 3 + size].copy() if rng.random() < 0.3 else rng.standard_normal(size)
        windows = sliding_window_view(x[low:low + count + size - 1], size)
        energy = template @ template
        dot = windows @ template
        like = dot / (np.sqrt(np.einsum("ij,ij->i", windows, windows) * energy) + 1e-300)
        k = int(np.argmax(like))
        assert _kernels.best_lag(x, template, low, count, energy) == (k, dot[k], like[k])


def test_upsampled_peak_is_upfirdns(rng):
    h = _interpolator()
    for n in (2, 3, 10, 241):
        x = rng.standard_normal(n)
        assert _kernels.upsampled_peak(h, x) == pytest.approx(np.abs(upfirdn(h, x, 4)).max(), rel=1e-12)


@pytest.mark.parametrize(("n", "taps"), [(1, 1), (5, 49), (600, 1), (1500, 2), (1500, 49), (3000, 25)])
def test_prediction_error_is_scipys_lfilter(rng, n, taps):
    x, a = uneven_noise(rng, n), rng.standard_normal(taps)
    want = lfilter(a, [1.0], x)
    np.testing.assert_allclose(_kernels.prediction_error(a, x), want, rtol=1e-12, atol=1e-12 * np.abs(want).max())


def test_frame_energies_are_the_half_spectrums(rng):
    x, window = uneven_noise(rng, 9000), np.hanning(1024)
    starts = np.arange(0, 9000 - 1024, 512, dtype=np.int64)
    frames = sliding_window_view(x, 1024)[starts] * window
    power = np.abs(np.fft.rfft(frames, axis=1)) ** 2
    np.testing.assert_allclose(_front.frame_energies(x, starts, window), power.sum(axis=1), rtol=1e-12, atol=0.0)


def test_two_by_two_solve_is_numpys(rng):
    for _ in range(200):
        a = rng.standard_normal((2, 2))
        b = rng.standard_normal(2)
        np.testing.assert_allclose(_kernels.solve_2x2(a[0, 0], a[0, 1], a[1, 0], a[1, 1], b[0], b[1]),
                                   np.linalg.solve(a, b), rtol=1e-9, atol=1e-12)
    assert np.all(np.isnan(_kernels.solve_2x2(1.0, 2.0, 2.0, 4.0, 1.0, 1.0)))  # singular


def test_change_points_are_each_peaks_aic(rng):
    x = uneven_noise(rng, 5000)
    peaks = np.array([10, 300, 2500, 4990], dtype=np.int64)
    want = [max(0, p - 48) + _kernels.aic(x[max(0, p - 48):p + 24]) for p in peaks]
    np.testing.assert_array_equal(_kernels.change_points(x, peaks, 12), want)


@pytest.mark.parametrize("n", [30, 241, 20001])
def test_jump_profile_is_the_windows_rms_jump(rng, n):
    from drumstroke.analysis.onsets import _windows

    x = uneven_noise(rng, n)
    after, before, width = _windows(x, 48000)
    jump = np.sqrt(after / np.maximum(before, 1e-300 + after * 1e-12))
    jump[:4 * width] = 0.0
    np.testing.assert_array_equal(_front.jump_profile(x, width), jump)


def test_least_unexplained_is_numpys_argmin(rng):
    for _ in range(300):
        length, count = int(rng.integers(16, 400)), int(rng.integers(1, 30))
        part = uneven_noise(rng, length + count - 1)
        head = part[3:3 + length].copy() if rng.random() < 0.3 and count > 3 else rng.standard_normal(length)
        energy = head @ head
        cross = np.correlate(part, head, "valid")
        power = np.cumsum(np.concatenate([[0.0], part * part]))
        own = power[length:] - power[:-length]
        unexplained = (own - cross * cross / energy) / np.maximum(own, np.finfo(float).tiny)
        k = int(np.argmin(unexplained))
        assert _kernels.least_unexplained(part, cross, energy, length) == (k, unexplained[k])


def _first_transients_numpy(d, times, reach, horizon, least, over, clear):
    """The numpy and scipy loop first_transients stands for."""
    from scipy.ndimage import maximum_filter1d

    times = times.copy()
    for i in range(len(times)):
        c = round(times[i])
        low = max(reach, c - reach, int(np.ceil((times[i - 1] + c) / 2)) if i else 0)
        high = min(len(d), c + reach, int((times[i + 1] + c) / 2) if i + 1 < len(times) else len(d))
        peak = d[c:min(len(d), c + horizon)].max(initial=0.0)
        if high - low < 2 or not peak > 0.0:
            continue
        prior = maximum_filter1d(d[low - reach:high - 1], reach, origin=-(reach // 2))[:high - low]
        above = np.flatnonzero((d[low:high] > peak * least) & (d[low:high] > over * prior) & (prior <= peak * clear))
        if len(above):
            times[i] = low + above[0] - 0.5
    return times


def test_first_transients_are_the_numpy_loops(rng):
    for _ in range(200):
        n = int(rng.integers(200, 5000))
        d = np.abs(uneven_noise(rng, n))
        count = int(rng.integers(1, 12))
        times = np.sort(rng.choice(n, count, replace=False)) + rng.choice([0.0, 0.5, -0.5], count)
        reach, horizon = int(rng.integers(1, 150)), int(rng.integers(1, 240))
        least, over, clear = 10.0 ** (rng.uniform(-40, 0) / 20.0), rng.uniform(1.0, 4.0), 10.0 ** (rng.uniform(-40, 0) / 20.0)
        np.testing.assert_array_equal(_kernels.first_transients(d, times, reach, horizon, least, over, clear),
                                      _first_transients_numpy(d, times, reach, horizon, least, over, clear))


def test_peaks_around_are_the_slices_maxima(rng):
    d = np.abs(uneven_noise(rng, 3000))
    centres = np.concatenate(([0, 1, 5, 2999], rng.integers(0, 3000, 200)))
    for after, before, gap in [(96, 240, 24), (1, 1, 0), (500, 10, 10), (10, 500, 600)]:
        ahead, prior = _kernels.peaks_around(d, centres, after, before, gap)
        np.testing.assert_array_equal(ahead, [d[c:c + after].max(initial=0.0) for c in centres])
        np.testing.assert_array_equal(prior, [d[max(0, c - before):max(1, c - gap)].max(initial=0.0) for c in centres])


def test_window_peaks_are_the_slices_largest_magnitudes(rng):
    x = uneven_noise(rng, 3000)
    lows = rng.integers(0, 3000, 200)
    highs = lows + rng.integers(-5, 400, 200)  # some empty, some past the end
    want = [np.abs(x[low:high]).max(initial=0.0) for low, high in zip(lows, highs)]
    np.testing.assert_array_equal(_kernels.window_peaks(x, lows, highs), want)


def test_window_largest_is_the_serial_max_in_any_lanes(rng):
    # sixteen samples at a time in vector lanes: the same value as max(peak, v) in order (a NaN passed over, as there)
    x = uneven_noise(rng, 3000)
    x[rng.integers(0, 3000, 30)] = np.nan

    def serial(low, high, magnitude):
        peak = 0.0
        for v in x[low:high]:
            peak = max(peak, abs(v) if magnitude else v)
        return peak

    for low, size in zip(rng.integers(0, 2500, 300), rng.integers(0, 500, 300)):
        for magnitude in (False, True):
            got = _kernels.window_largest(x, low, low + size, magnitude)
            assert got == serial(low, low + size, magnitude) and not np.isnan(got)


def test_first_at_least_is_the_first_nonzero(rng):
    d = np.abs(uneven_noise(rng, 3000))
    lows = rng.integers(0, 3000, 300)
    highs = lows + rng.integers(0, 400, 300)
    levels = rng.uniform(0.0, 3.0, 300) * np.median(d)
    expected = [np.append(np.flatnonzero(d[a:b] >= v), -1)[0] for a, b, v in zip(lows, highs, levels)]
    np.testing.assert_array_equal(_kernels.first_at_least(d, lows, highs, levels), expected)


def test_a_remainder_at_rounding_level_makes_no_jump():
    """A note fitted and taken off to its last bits leaves zeros, then a few ulps: no jump under the floor.

    Without the floor the ratio of a few ulps after to exact zeros before is the cap (1e6); with it, a
    mean power 240 dB under the signal's peak counts as the floor, so the jump is 1 at most; a real sound
    (here 60 dB under the peak) still jumps as before."""
    from drumstroke.analysis._kernels import jump_at
    from drumstroke.analysis.onsets import _rounding_floor

    x = np.zeros(4000)
    x[0] = 1.0  # the signal's peak, long before
    x[2000:] = 1e-17 * np.random.default_rng(3).standard_normal(2000)  # rounding of a note taken off
    floor = _rounding_floor(x)
    assert jump_at(x, np.array([2000]), 12, 0.0)[0] == pytest.approx(1e6)
    assert jump_at(x, np.array([2000]), 12, floor)[0] <= 1.0
    x[2000:2012] += 1e-3
    assert jump_at(x, np.array([2000]), 12, floor)[0] == jump_at(x, np.array([2000]), 12, 0.0)[0] > 100.0
