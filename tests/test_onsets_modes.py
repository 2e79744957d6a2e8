"""The modes' band's and the level band's compiled loops (drumstroke.analysis._modes) against the numpy code they replaced.

The normal equations of the reweighted predictor must be numpy's to the bit where numpy's BLAS is OpenBLAS's
fused-multiply-add kernel (its Haswell kernel, on Intel and AMD processors since 2013: the product the detector
ran), and within rounding of numpy's one product of all the lagged rows anywhere.
"""

import numpy as np
import pytest
from numpy.lib.stride_tricks import sliding_window_view

from _recordings import uneven_noise
from drumstroke.analysis import _modes


@pytest.fixture
def rng():
    return np.random.default_rng(20261127)


def _lagged(x, order, weight):
    """Rows (x[n], x[n - 1], …, x[n - order]) weight[n] for n from order on, in numpy."""
    return sliding_window_view(x, order + 1)[:, ::-1] * weight[order:, None]


def _blas_kernel():
    """numpy's BLAS and the processor kind its kernels are for (threadpoolctl's names), or None without threadpoolctl."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    for library in threadpoolctl.threadpool_info():
        if library["user_api"] == "blas" and "numpy" in library["filepath"]:
            return library["internal_api"], library.get("architecture")
    return None


_CASES = [(10_000, 40), (5_000, 24), (2 * 256 + 40 + 1, 40), (300, 40), (64, 3), (50, 1), (700, 2), (900, 8), (600, 47),
          (2_000, 100)]


@pytest.mark.parametrize(("n", "order"), _CASES)
def test_weighted_gram_is_the_lagged_rows_product(rng, n, order):
    x, weight = uneven_noise(rng, n), rng.random(n) + 0.1
    rows = _lagged(x, order, weight)
    want = rows.T @ rows
    got = _modes.weighted_gram(x, weight, order, 256)
    assert got.shape == (order + 1, order + 1)
    np.testing.assert_array_equal(got, got.T)
    np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-13 * np.max(np.abs(want)) * np.sqrt(n))


@pytest.mark.parametrize(("n", "order"), _CASES)
@pytest.mark.parametrize("block", [256, 37])
def test_weighted_gram_is_numpys_block_products_to_the_bit(rng, n, order, block):
    """To the bit where numpy's BLAS is OpenBLAS's Haswell kernel (the order of fused multiply-adds the kernel keeps:
    the detector's outputs before it); with another BLAS, whose sums are in another order, within their rounding."""
    x, weight = uneven_noise(rng, n), rng.random(n) + 0.1
    rows = _lagged(x, order, weight)
    want = np.zeros((order + 1, order + 1))
    buffer = np.empty((block, order + 1))  # each block as the detector multiplied it: one buffer, rows.T @ rows
    for start in range(0, len(rows), block):
        part = buffer[:min(len(rows), start + block) - start]
        part[:] = rows[start:start + len(part)]
        want += part.T @ part
    got = _modes.weighted_gram(x, weight, order, block)
    if _blas_kernel() == ("openblas", "Haswell"):
        np.testing.assert_array_equal(got, want)
    else:
        np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-13 * np.max(np.abs(want)) * np.sqrt(n))


def test_weighted_gram_of_too_short_a_signal_is_zero(rng):
    x = rng.standard_normal(5)
    np.testing.assert_array_equal(_modes.weighted_gram(x, np.ones(5), 5, 256), np.zeros((6, 6)))


def _in_order(a, b):
    """Σ a[j] b[j], added one product at a time in Python's floats (IEEE doubles): the order the chains keep."""
    total = 0.0
    for u, v in zip(a.tolist(), b.tolist()):
        total += u * v
    return total


def test_five_window_sums_are_each_windows_sums(rng):
    for size in list(range(1, 34)) + [101, 102, 103]:
        x = uneven_noise(rng, size + 60)
        t0, t1 = rng.standard_normal(size + 2), rng.standard_normal(size)
        first = int(rng.integers(0, len(x) - size - 4))
        out = np.full(15, np.nan)
        _modes.five_window_sums(x, first, t0, t1, size, out)
        for k in range(5):
            window = x[first + k:first + k + size]
            assert out[k] == _in_order(window, t0[:size])
            assert out[5 + k] == _in_order(window, t1)
            assert out[10 + k] == np.einsum("i,i->", window, window)  # numpy's pairs of lanes


def test_trial_dots_are_each_lags_sums_in_order(rng):
    for size in (1, 2, 5, 9, 40, 102):
        y = uneven_noise(rng, size)
        basis = rng.standard_normal((size + 3, 2))
        for first in range(0, size, max(1, size // 7)):
            count = int(rng.integers(0, size - first + 1))
            b0, b1 = np.full(count, np.nan), np.full(count, np.nan)
            _modes.trial_dots(y, basis, first, count, b0, b1)
            for k in range(count):
                window = y[first + k:]
                assert b0[k] == _in_order(window, basis[:len(window), 0])
                assert b1[k] == _in_order(window, basis[:len(window), 1])


def _measured_at_in_numpy(times, found, reach):
    """The numpy code measured_at stands for."""
    nearest = np.clip(np.searchsorted(found, times), 1, len(found)) - 1
    nearer = np.where((nearest + 1 < len(found)) & (np.abs(found[np.minimum(nearest + 1, len(found) - 1)] - times)
                                                    < np.abs(found[nearest] - times)), nearest + 1, nearest)
    near = (found[nearer] >= times) & (found[nearer] - times <= reach)
    near &= (found[nearer] == times) | ~np.isin(found[nearer], times)
    return np.where(near, found[nearer], times)


def test_measured_at_is_the_numpy_code(rng):
    for _ in range(500):
        found = np.unique(rng.integers(0, 400, int(rng.integers(1, 30))) + rng.choice([0.0, 0.5], 1))
        count = int(rng.integers(1, 30))
        times = np.sort(np.concatenate((rng.choice(found, min(count // 3, len(found)), replace=False),
                                        rng.uniform(-20, 420, count))))  # some of them found ones
        reach = float(rng.choice([0.0, 3.0, 48.0]))
        want = _measured_at_in_numpy(times, found, reach)
        np.testing.assert_array_equal(_modes.measured_at(times, found, reach), want)


def test_levinson_is_scipys_solve_toeplitz(rng):
    from scipy.linalg import solve_toeplitz

    for trial in range(300):
        n = int(rng.integers(1, 320))
        # an impulse train's autocorrelation, ridged (as the room's tail's), or a diagonally dominant column
        train = np.zeros(3 * n)
        np.add.at(train, rng.integers(0, len(train), int(rng.integers(1, 60))), rng.standard_normal(60)[:1])
        r = np.array([train[:len(train) - k] @ train[k:] for k in range(n)]) if trial % 2 else rng.standard_normal(n)
        r[0] = abs(r[0]) * 1.01 + (0.0 if trial % 2 else n)
        b = rng.standard_normal(n)
        x, solved = _modes.levinson(r, b)
        assert solved
        np.testing.assert_array_equal(x, solve_toeplitz(r, b))


def test_levinson_says_when_a_principal_minor_is_singular():
    _, solved = _modes.levinson(np.array([0.0, 1.0]), np.ones(2))
    assert not solved
    _, solved = _modes.levinson(np.array([1.0, 1.0, 0.5]), np.ones(3))  # [[1, 1], [1, 1]] leads
    assert not solved


def test_upsampled_peak_sums_each_output_in_order(rng):
    from scipy.signal import upfirdn

    for trial in range(300):
        h = rng.standard_normal(81 if trial % 2 else int(rng.integers(1, 30)))
        x = uneven_noise(rng, int(rng.integers(1, 20)))
        outputs = []
        for n in range((len(x) - 1) * 4 + len(h)):  # each output's products in order of x's samples, in Python's floats
            total = 0.0
            for m in range(max(0, (n - len(h)) // 4 + 1), min(len(x), n // 4 + 1)):
                total += float(x[m]) * float(h[n - 4 * m])
            outputs.append(abs(total))
        assert _modes.upsampled_peak(h, x) == max(outputs, default=0.0)
        assert _modes.upsampled_peak(h, x) == pytest.approx(np.abs(upfirdn(h, x, 4)).max(), rel=1e-12, abs=1e-300)


def _pursued_in_python(r, centres, basis, gram, solve, head, head_norm, lead):
    """The pursuit's fits as its loops were written, in Python's floats (each window's products in order, its squares
    and the cost's last product in numpy's einsum order): likenesses, places, starts, scales; ``r`` less the fits."""
    size, n = len(basis), len(r)
    out = []
    for c in centres:
        first, last = max(c - lead - 2, 0), min(c - lead + 2, n - size)
        like, costs, weights = -np.inf, [], []
        for s in range(first, last + 1):
            window = r[s:s + size]
            dot = _in_order(r[s:s + len(head)], head)
            like = max(like, abs(dot) / (np.sqrt(np.einsum("i,i->", r[s:s + len(head)], r[s:s + len(head)])) * head_norm
                                         + 1e-300))
            w = [_in_order(window, solve[q]) for q in range(2)]
            fitted = [0.0, 0.0]
            for q in range(2):
                for p in range(2):
                    fitted[q] += w[p] * gram[p, q]
            costs.append(np.einsum("i,i->", window, window) - np.einsum("i,i->", np.array(w), np.array(fitted)))
            weights.append(w)
        k = int(np.argmin(costs))  # the first of the least
        s, (w0, w1) = first + k, weights[k]
        for j in range(size):
            fit = 0.0
            for q, w in enumerate((w0, w1)):
                fit += basis[j, q] * w
            r[s + j] -= fit
        shift = -w1 / w0 if w0 != 0.0 else 0.0
        out.append((like, s + lead + min(max(shift, -1.0), 1.0), s, w0))
    return out


def test_pursuit_fits_as_its_loops_in_python(rng):
    from drumstroke.analysis._kernels import pursue

    for trial in range(20):
        e = uneven_noise(rng, 400)
        template = rng.standard_normal(30) * np.exp(-np.arange(30) / 8.0)  # a spike and its decay
        basis = np.column_stack([template, np.gradient(template)])
        gram = basis.T @ basis
        solve = np.ascontiguousarray(np.linalg.solve(gram, basis.T))
        head = template[:8].copy()
        head_norm = float(np.sqrt(head @ head))
        # onsets with five alignments, and fewer at the ends
        centres = rng.choice(np.arange(5, 370), 6, replace=False)
        centres = np.unique(np.concatenate((centres, [2, 374] if trial % 2 else []))).astype(np.int64)
        r, want_r = e.copy(), e.copy()
        _, likeness, where, at, amp = pursue(r, centres.astype(float), centres, basis, gram, solve, head, head_norm, 2,
                                             4, np.empty(0), 0.0)
        want = _pursued_in_python(want_r, centres, basis, gram, solve, head, head_norm, 2)
        np.testing.assert_array_equal(r, want_r)
        np.testing.assert_array_equal(likeness, [w[0] for w in want])
        np.testing.assert_array_equal(where, [w[1] for w in want])
        np.testing.assert_array_equal(at, [w[2] for w in want])
        np.testing.assert_array_equal(amp, [w[3] for w in want])


def test_reweighting_is_scipys_uniform_filter_and_numpys_mean(rng):
    from scipy.ndimage import uniform_filter1d

    for n in (1, 2, 3, 4, 5, 8, 9, 17, 128, 129, 1000, 10_000, 12_345):
        first = uneven_noise(rng, n)
        power = np.maximum(uniform_filter1d(first * first, 9), 0.0)
        np.testing.assert_array_equal(_modes.reweighting(first, 9),
                                      1.0 / np.sqrt(power + 1e-12 * power.mean() + 1e-300))


def test_pairwise_sum_is_numpys(rng):
    for n in [1, 7, 8, 9, 127, 128, 129, 135, 256, 257, 1000, 10_000, 65_537]:
        x = uneven_noise(rng, n)
        assert _modes._pairwise_sum(x) == np.add.reduce(x)
