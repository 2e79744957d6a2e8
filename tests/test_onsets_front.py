"""The onset detector's front-end kernels (drumstroke.analysis._front) against scipy, numpy and librosa: the same to the
bit where they do the same operations."""

import numpy as np
import pytest
from scipy.signal import butter, sosfilt

from drumstroke.analysis import _front, _kernels


@pytest.fixture
def rng():
    return np.random.default_rng(20261127)


@pytest.mark.parametrize("n", [0, 1, 2, 3, 4, 5, 47, 1000, 48_000])
@pytest.mark.parametrize(("q", "q_other", "q_third"), [(8, 24, 48), (2, 3, 2), (5, 5, 7)])
def test_low_pass_three_is_sosfilt_to_the_bit(rng, n, q, q_other, q_third):
    rate = 48_000
    sos, other, third = (butter(8, 0.8 * rate / each / 2.0, fs=rate, output="sos") for each in (q, q_other, q_third))
    x = rng.standard_normal(n)
    lows = _front.low_pass_three(sos, q, other, q_other, third, q_third, x)
    for low, f, each in zip(lows, (sos, other, third), (q, q_other, q_third), strict=True):
        assert low.tobytes() == (sosfilt(f, x)[::each] if n else np.empty(0)).tobytes()


def test_low_pass_three_any_sections_and_signed_zeros(rng):
    """Sections of any numerators (negative ones make signed zeros), on a signal that starts with silence."""
    sos, other, third = (rng.standard_normal((4, 6)) * 0.3 for _ in range(3))
    sos[:, 3] = other[:, 3] = third[:, 3] = 1.0
    x = np.concatenate((np.zeros(7), -np.zeros(3), rng.standard_normal(200)))
    low, low_other, low_third = _front.low_pass_three(sos, 3, other, 4, third, 5, x)
    assert low.tobytes() == sosfilt(sos, x)[::3].tobytes()
    assert low_other.tobytes() == sosfilt(other, x)[::4].tobytes()
    assert low_third.tobytes() == sosfilt(third, x)[::5].tobytes()


def _lanes_dot(x, y):
    """``x @ y`` added in four lanes (every fourth product, in order; the products left over after the last four in the
    first lane), the lanes summed as (0 + 1) + (2 + 3): numpy's cumulative sums add in order."""
    whole = len(x) - len(x) % 4
    products = x * y
    lanes = [np.cumsum(np.concatenate(([0.0], products[lane:whole:4], products[whole:] if lane == 0 else [])))[-1]
             for lane in range(4)]
    return (lanes[0] + lanes[1]) + (lanes[2] + lanes[3])


def _burg_in_numpy(y, order):
    """librosa.lpc's Burg method (as Marple) in numpy, its sums of products in four lanes."""
    f, b = y[1:].copy(), y[:-1].copy()
    a, a_prev = np.zeros(order + 1), np.zeros(order + 1)
    a[0] = a_prev[0] = 1.0
    den = _lanes_dot(f, f) + _lanes_dot(b, b)
    dot = _lanes_dot(b, f)
    for i in range(order):
        m = len(y) - 1 - i
        reflect = dot * -2
        reflect /= den + np.finfo(np.float64).tiny
        a_prev, a = a, a_prev
        a[1:i + 2] = a_prev[1:i + 2] + reflect * a_prev[i::-1]
        forward = f[i:i + m].copy()
        f[i:i + m] = forward + reflect * b[:m]
        b[:m] = b[:m] + reflect * forward
        dot = _lanes_dot(b[:m - 1], f[i + 1:i + m])
        den = (1.0 - reflect ** 2) * den - b[m - 1] ** 2 - f[i] ** 2
    return a


@pytest.mark.parametrize(("n", "order"), [(n, order) for n in (2, 3, 5, 6, 9, 10, 11, 12, 13, 101, 4_003)
                                           for order in (1, 2, 3, 7, 48) if order < n])
def test_burg_is_librosas_lpc_summed_in_four_lanes(rng, n, order):
    librosa = pytest.importorskip("librosa")
    x = np.cumsum(rng.standard_normal(n)) * 0.1 + rng.standard_normal(n)
    a = _front.burg(x, order)
    assert a.tobytes() == _burg_in_numpy(x, order).tobytes()  # the same operations, in the same order
    np.testing.assert_allclose(a, librosa.lpc(x, order=order), rtol=1e-9, atol=1e-9)


def test_burg_leaves_its_input(rng):
    x = rng.standard_normal(300)
    kept = x.copy()
    _front.burg(x, 12)
    assert x.tobytes() == kept.tobytes()


def _jump_profile_in_numpy(x, width):
    """The RMS of ``x`` over the next ``width`` samples over that of the ``4 width`` before (the running power added in
    order, the windows cut at the end), 0 over the first ``4 width``: the profile as numpy's cumsum builds it."""
    power = np.concatenate(([0.0], np.cumsum(x * x)))
    k = np.arange(4 * width, len(x))
    after = (power[np.minimum(k + width, len(x))] - power[k]) / width
    before = (power[k] - power[k - 4 * width]) / (4 * width)
    out = np.zeros(len(x))
    out[k] = np.sqrt(after / np.maximum(before, 1e-300 + after * 1e-12))
    return out


@pytest.mark.parametrize("width", [12, 13, 48])
@pytest.mark.parametrize("n", [1, 3, 5, 47, 48, 61, 63, 64, 65, 241, 243, 244, 1_003, 20_000])
def test_low_pass_three_and_jumps_is_sosfilt_and_the_jump_profile(rng, width, n):
    rate = 48_000
    sos = butter(8, 0.8 * rate / 8 / 2.0, fs=rate, output="sos")
    other = butter(8, 0.8 * rate / 24 / 2.0, fs=rate, output="sos")
    third = butter(8, 0.8 * rate / 45 / 2.0, fs=rate, output="sos")
    x = rng.standard_normal(n)
    rise = np.diff(x, prepend=x[0]) * rng.random(n) ** 4  # loud and quiet stretches
    low, low_other, low_third, jumps = _front.low_pass_three_and_jumps(sos, 8, other, 24, third, 45, x, rise, width)
    assert low.tobytes() == sosfilt(sos, x)[::8].tobytes()
    assert low_other.tobytes() == sosfilt(other, x)[::24].tobytes()
    assert low_third.tobytes() == sosfilt(third, x)[::45].tobytes()
    assert jumps.tobytes() == _jump_profile_in_numpy(rise, width).tobytes()


@pytest.mark.parametrize("trial", range(200))
def test_peak_pick_as_librosa(trial):
    librosa = pytest.importorskip("librosa")
    rng = np.random.default_rng(trial)
    n, gap = int(rng.integers(1, 3000)), int(rng.integers(1, 130))
    x = [rng.standard_normal(n) ** 2, np.round(rng.standard_normal(n) * 2), np.round(np.cumsum(rng.standard_normal(n))),
         np.abs(np.sin(np.arange(n) * 0.05)) + np.round(rng.random(n))][trial % 4]
    if trial % 5 == 0:
        x[n // 3:2 * n // 3] = 0.0  # a flat stretch
    want = librosa.util.peak_pick(x, pre_max=gap, post_max=gap, pre_avg=1, post_avg=1, delta=0.0, wait=gap)
    np.testing.assert_array_equal(_front.peak_pick_over(x, gap, -np.inf), want)


def _frame_energy_in_numpy(v):
    """Parseval's energy of a windowed frame ``v`` over its half spectrum's bins, from the sums of its squares and of
    its even and odd samples, each added in four lanes (every fourth sample; those left over, even or odd, in the first
    two) in order: numpy's cumulative sums add in order."""
    whole = len(v) - len(v) % 4
    rest = np.arange(whole, len(v))

    def lanes(terms):
        return [np.cumsum(np.concatenate(([0.0], terms[lane:whole:4], terms[rest[rest % 2 == lane]] if lane < 2 else [])))[-1]
                for lane in range(4)]

    p, t = lanes(v * v), lanes(v)
    power, even, odd = (p[0] + p[2]) + (p[1] + p[3]), t[0] + t[2], t[1] + t[3]
    return (len(v) * power + (even + odd) ** 2 + (even - odd) ** 2) / 2.0


@pytest.mark.parametrize("size", [4, 8, 6, 7, 1024])
@pytest.mark.parametrize("frames", [1, 2, 3, 10])
def test_frame_energies_as_their_lanes_in_numpy_and_the_spectra(rng, size, frames):
    x, window = rng.standard_normal(5_000), np.hanning(size)
    starts = np.sort(rng.integers(0, len(x) - size, frames)).astype(np.int64)
    energies = _front.frame_energies(x, starts, window)
    assert energies.tobytes() == np.array([_frame_energy_in_numpy(x[s:s + size] * window) for s in starts]).tobytes()
    if size % 2 == 0:  # Parseval's over the half spectrum (its last bin Nyquist's)
        spectra = np.fft.rfft(np.stack([x[s:s + size] * window for s in starts]), axis=1)
        np.testing.assert_allclose(energies, (np.abs(spectra) ** 2).sum(axis=1), rtol=1e-10)


@pytest.mark.parametrize("n", [0, 1, 7, 48_000])
def test_high_pass_is_sosfilt_and_its_peak(rng, n):
    sos = butter(2, 20.0, btype="highpass", fs=48_000, output="sos")
    x = rng.standard_normal(n) + 0.3
    band, peak, at = _front.high_pass(sos, x)
    want = sosfilt(sos, x) if n else np.empty(0)
    assert band.tobytes() == want.tobytes()
    assert peak == np.max(np.abs(want), initial=0.0)
    assert at == (np.argmax(np.abs(want)) if n else 0)


def test_high_pass_finds_the_first_of_equal_peaks():
    """A signal whose filtered largest magnitude is reached twice (an impulse, then its negative after the decay):
    the first, as numpy's argmax."""
    sos = np.array([[1.0, 0.0, 0.0, 1.0, 0.0, 0.0]])  # the identity
    x = np.zeros(50)
    x[10], x[30] = 2.0, -2.0
    assert _front.high_pass(sos, x)[1:] == (2.0, 10)


@pytest.mark.parametrize("width", [12, 13, 48])
@pytest.mark.parametrize("n", [0, 1, 47, 48, 60, 64, 65, 241, 244, 245, 1_003, 30_000])
def test_jump_profile_as_numpy(rng, width, n):
    x = rng.standard_normal(n) * rng.random(n) ** 4
    assert _front.jump_profile(x, width).tobytes() == _jump_profile_in_numpy(x, width).tobytes()


@pytest.mark.parametrize("gap", [12, 96, 97, 130])
def test_peak_pick_on_a_jump_profile(rng, gap):
    """A long profile as the detector picks (a noisy signal's RMS ratios, quiet and loud stretches): librosa's peaks."""
    librosa = pytest.importorskip("librosa")
    x = rng.standard_normal(60_000) * np.repeat(rng.random(60) ** 4, 1_000)
    profile = _jump_profile_in_numpy(x, 48)
    want = librosa.util.peak_pick(profile, pre_max=gap, post_max=gap, pre_avg=1, post_avg=1, delta=0.0, wait=gap)
    np.testing.assert_array_equal(_front.peak_pick_over(profile, gap, -np.inf), want)


@pytest.mark.parametrize("taps", [1, 2, 5, 41, 49])
@pytest.mark.parametrize("n", [1, 3, 31, 32, 48, 49, 80, 81, 1_025, 30_000])
def test_prediction_error_is_lfilter_and_the_scalar_kernel(rng, taps, n):
    from scipy.signal import lfilter

    x, a = rng.standard_normal(n), rng.standard_normal(taps)
    a[0] = 1.0
    e = _front.prediction_error(a, x)
    assert e.tobytes() == _kernels.prediction_error(a, x).tobytes()  # each output's taps added in the same order
    np.testing.assert_allclose(e, lfilter(a, [1.0], x), rtol=1e-12, atol=1e-12 * np.sum(np.abs(a)))


def test_vector_reads_take_read_only_arrays_and_refuse_strided_ones(rng):
    window = np.hanning(64)
    window.flags.writeable = False  # as the decimation's cached window
    x = rng.standard_normal(1_000)
    starts = np.array([0, 100, 900], dtype=np.int64)
    np.testing.assert_allclose(_front.frame_energies(x, starts, window),
                               [np.sum(np.abs(np.fft.rfft(x[s:s + 64] * window)) ** 2) for s in starts], rtol=1e-12)
    with pytest.raises(Exception, match="contiguous 1-D array of float64"):
        _front.prediction_error(np.ones(3), x[::2])


def test_level_band_takes_a_guessed_decimation_only_where_it_is_its_own(rng):
    """Step 5's band from a decimation made beforehand (the right one) or not (a wrong one) is the band it makes alone."""
    from drumstroke.analysis.onsets import OnsetConfig, _decimate, _level_band, _level_decimation

    rate, config = 48_000, OnsetConfig()
    band = rng.standard_normal(rate) * np.exp(-np.arange(rate) / 4800.0)
    first = np.array([100.0])
    alone = _level_band(band, rate, 8, first, config)
    q3 = _level_decimation(band, rate, 8, first, config)
    assert alone.q == q3
    for guess in (q3, q3 + 1, q3 - 1):
        guessed = _level_band(band, rate, 8, first, config, _decimate(band, rate, guess))
        assert (guessed.q, guessed.rate, guessed.delay, guessed.floor) == (alone.q, alone.rate, alone.delay, alone.floor)
        assert guessed.x.tobytes() == alone.x.tobytes()
        assert guessed.coefficients.tobytes() == alone.coefficients.tobytes()
