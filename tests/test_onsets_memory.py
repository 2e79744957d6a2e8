"""The detector's stages without their large temporaries, against the numpy, scipy and librosa code they replaced.

:func:`drumstroke.analysis.onsets._robust_innovation` adds its normal equations up over blocks of lagged rows
in one small buffer (it built all the rows at once), and :func:`drumstroke.analysis.onsets._room_tail`
correlates the attacks' impulses by sums over them (it used FFTs of the band's length): the sums' order
changes, so those oracles are held within stated tolerances, relative to the largest entry. The full-rate jump
profile keeps its running power over a ring of its windows' samples and the peak picker its peaks as found: the
same bits, over lengths that cross the ring.
"""

import numpy as np
import pytest
from numpy.lib.stride_tricks import sliding_window_view
from scipy.linalg import solve_toeplitz
from scipy.ndimage import uniform_filter1d

from _recordings import uneven_noise
from drumstroke.analysis import _front, _kernels
from drumstroke.analysis.onsets import _LAG_ROWS, _innovation, _robust_innovation, _room_tail


@pytest.fixture
def rng():
    return np.random.default_rng(20261127)


def _lagged(x, order):
    """Rows x[n], x[n - 1], …, x[n - order] for n from order on, in numpy."""
    return sliding_window_view(x, order + 1)[:, ::-1]


def _robust_in_numpy(x, order):
    """_robust_innovation's coefficients as they were: every lagged row at once, one product, lstsq."""
    _, first = _innovation(x, order)
    power = np.maximum(uniform_filter1d(first * first, 9), 0.0)
    weight = 1.0 / np.sqrt(power + 1e-12 * power.mean() + 1e-300)
    rows = _lagged(x, order) * weight[order:, None]
    gram = rows.T @ rows
    c, *_ = np.linalg.lstsq(gram[1:, 1:], -gram[1:, 0], rcond=None)
    return np.concatenate(([1.0], c))


@pytest.mark.parametrize("n, order", [(10_000, 40), (5_000, 24), (2 * _LAG_ROWS + 40 + 1, 40), (300, 40), (64, 3)])
def test_predictor_as_the_whole_lagged_matrix_gives_it(rng, n, order):
    # ringing (two decaying modes) with attacks and uneven noise: a well-posed fit, as the detector meets it
    t = np.arange(n)
    x = np.sin(0.3 * t) * np.exp(-t / 2000) + 0.5 * np.sin(0.71 * t) + uneven_noise(rng, n) * 1e-2
    x[n // 3:] += np.sin(0.45 * t[:n - n // 3]) * np.exp(-t[:n - n // 3] / 500)
    want = _robust_in_numpy(x, min(order, max(1, n // 8)))
    got, e = _robust_innovation(x, order)
    np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-9 * np.max(np.abs(want)))
    np.testing.assert_allclose(e, np.convolve(x, got)[:n], rtol=0.0, atol=1e-12 * np.max(np.abs(x)) * np.sum(np.abs(got)))


def _correlations_by_fft(e, at, amp, length):
    """The impulses' correlations as _room_tail took them: np.add.at into a train, FFTs of the band's length."""
    s = np.zeros(len(e))
    np.add.at(s, at, amp)
    size = 1 << int(np.ceil(np.log2(len(e) + length)))
    spectrum = np.fft.rfft(s, size)
    return (np.fft.irfft(spectrum * np.conj(spectrum), size)[:length],
            np.fft.irfft(np.conj(spectrum) * np.fft.rfft(e, size), size)[:length])


def test_impulse_correlations_as_ffts_give_them(rng):
    e = rng.standard_normal(3000)
    # repeated samples, neighbours closer than the tail, a negative sample (numpy's: from the end), the last sample
    at = np.array([5, 5, 40, 41, 300, 1700, 1720, 2999, -3], dtype=np.int64)
    amp = rng.standard_normal(len(at))
    for length in (1, 25, 300, 3500):
        got, want = _kernels.impulse_correlations(e, at, amp, length), _correlations_by_fft(e, at, amp, length)
        for g, w in zip(got, want):
            np.testing.assert_allclose(g, w[:length], rtol=0.0, atol=1e-12 * np.max(np.abs(w)))


def test_room_tail_as_ffts_and_scipys_toeplitz_solve_give_it(rng):
    e = uneven_noise(rng, 10_000)
    at = np.sort(rng.choice(len(e) - 10, 50, replace=False)).astype(np.int64)
    amp = rng.standard_normal(50)
    amp[7] = 0.0  # an onset no signature was fitted at: left out
    keep = amp != 0.0
    r_ss, r_se = _correlations_by_fft(e, at[keep], amp[keep], 300)
    r_ss[0] *= 1.01
    want = solve_toeplitz(r_ss, r_se)
    np.testing.assert_allclose(_room_tail(e, at, amp, 300, 0.01), want, rtol=0.0, atol=1e-10 * np.max(np.abs(want)))
    assert _room_tail(e, at[:0], amp[:0], 300, 0.01) is None


def test_jump_profile_over_blocks_as_numpys_cumulative_sums(rng):
    def jump(x, width):  # the mean squares over the next window and the 4 before, as cumulative sums in numpy
        power = np.concatenate(([0.0], np.cumsum(x * x)))
        n = np.arange(len(x))
        after = (power[np.minimum(n + width, len(x))] - power[n]) / width
        before = (power[n] - power[np.maximum(n - 4 * width, 0)]) / (4 * width)
        out = np.sqrt(after / np.maximum(before, 1e-300 + after * 1e-12))
        out[:4 * width] = 0.0
        return out

    for n in (0, 5, 4096 + 4 * 48 - 1, 4096 + 5 * 48, 2 * 4096 + 240, 3 * 4096 + 7, 240_000):
        x = rng.standard_normal(n) * np.exp(rng.standard_normal(n))
        x[n // 3:n // 2] = 0.0  # digital silence
        for width in (4, 12, 48):
            np.testing.assert_array_equal(_front.jump_profile(x, width), jump(x, width)[:n], err_msg=f"n={n}")


def test_peaks_of_long_signals_picked_as_librosa_picks_them(rng):
    import librosa

    for trial in range(12):
        n, gap = int(rng.integers(5_000, 30_000)), int(rng.choice([1, 2, 96, 480]))
        x = rng.standard_normal(n) ** 2
        if trial % 2:
            x = np.round(x, 1)  # ties
        x[n // 4:n // 3] = 0.0  # a flat stretch
        want = librosa.util.peak_pick(x, pre_max=gap, post_max=gap, pre_avg=1, post_avg=1, delta=0.0, wait=gap)
        np.testing.assert_array_equal(_front.peak_pick_over(x, gap, -np.inf), want, err_msg=f"n={n}, gap={gap}")
