"""The template stages' compiled loops (drumstroke.analysis._templates) against the numpy code they stand for: to the
bit (the same operations in the same order; a median is the same values whatever sorts them, but for the sign of a
zero where +0 and -0 tie, which no peak, product or energy after it sees)."""

import numpy as np
import pytest
from numpy.lib.stride_tricks import sliding_window_view

from _recordings import uneven_noise
from drumstroke.analysis import _templates


@pytest.fixture
def rng():
    return np.random.default_rng(20261127)


def _layer_median_numpy(x, at, scales, whole, clean):
    """The median by parts with np.median, as onsets._layer_template took it before it was compiled."""
    rows = [x[a:a + n] / s for a, s, n in zip(at, scales, whole)]
    bounds = np.unique(np.concatenate(([0], whole, clean)))
    parts = []
    for low, high in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
        voted = whole >= high
        chosen = voted if np.count_nonzero(voted) >= 3 else clean >= high
        if not chosen.any():
            break
        parts.append(np.median([row[low:high] for row, use in zip(rows, chosen) if use], axis=0))
    return np.concatenate(parts) if parts else np.empty(0)


def test_layer_median_is_numpys_median_by_parts(rng):
    x = uneven_noise(rng, 30000)
    x[1000:1400] = np.round(x[1000:1400], 1)  # ties between the waveforms
    for _ in range(300):
        count = int(rng.integers(1, 13))
        at = rng.integers(0, 20000, count)
        at[rng.random(count) < 0.3] = 1000  # the same samples, ties in every column
        whole = np.minimum(rng.integers(0, 2000, count), len(x) - at)
        whole[rng.random(count) < 0.2] = 0
        clean = np.minimum(whole, rng.integers(0, 2000, count))
        scales = np.exp(rng.standard_normal(count))
        scales[rng.random(count) < 0.3] = 1.0
        got = _templates.layer_median(x, at, scales, whole, clean)
        want = _layer_median_numpy(x, at, scales, whole, clean)
        np.testing.assert_array_equal(got, want, strict=True)


def _next_attack_numpy(x, head, low, high, pre, reach, base, width, energy, rise, likeness, least):
    """The first window that rises, is scaled and correlates, moved to the best correlation within ``reach`` after:
    running sums by np.cumsum (in order), the windows' products and energies as numpy sums sliding windows."""
    count, size = high - base, len(head)
    power = np.concatenate(([0.0], np.cumsum(x[base:high] ** 2)))
    n = np.arange(low, high) - base
    after = (power[np.minimum(n + width, count)] - power[n]) / width
    before = (power[n] - power[np.maximum(n - 4 * width, 0)]) / (4 * width)
    windows = sliding_window_view(x[low - pre:high - pre + size - 1], size)
    dots = windows @ head
    like = dots / (np.sqrt(np.einsum("ij,ij->i", windows, windows) * energy) + 1e-300)
    passing = np.flatnonzero((after >= rise * before) & (dots >= least * energy) & (like >= likeness))
    if not len(passing):
        return -1
    first = passing[0]
    return low + first + int(np.argmax(like[first:min(first + reach + 1, high - low)]))


def test_next_attack_is_the_first_rising_scaled_correlating_window(rng):
    """Onsets in noise, in silence and in what a fit left of itself (zeros, the windows a quiet bound skips)."""
    hits = 0
    for _ in range(400):
        n, size, pre = int(rng.integers(400, 3000)), int(rng.integers(8, 80)), int(rng.integers(1, 8))
        width = int(rng.integers(2, 20))
        x = uneven_noise(rng, n) * 10.0 ** rng.uniform(-4, 1)
        head = rng.standard_normal(size)
        if rng.random() < 0.3:
            x[int(rng.integers(0, n // 2)):][:int(rng.integers(0, n))] = 0.0
        for _ in range(int(rng.integers(0, 4))):  # the head itself, scaled, over the noise
            at = int(rng.integers(pre, n - size))
            x[at - pre:at - pre + size] += head * 10.0 ** rng.uniform(-3, 1)
        low = int(rng.integers(4 * width + pre, n // 2))
        high = int(rng.integers(low, n - size + pre + 1))
        base = max(0, low - 4 * width) if rng.random() < 0.8 else int(rng.integers(0, low - pre + 1))
        energy = head @ head
        args = (x, head, low, high, pre, int(rng.integers(0, 20)), base, width, energy, float(rng.choice([1.0, 4.0])),
                float(rng.choice([0.3, 0.8])), float(rng.choice([1e-3, 0.01, 0.3])))
        want = _next_attack_numpy(*args)
        assert _templates.next_attack(*args) == want
        hits += want >= 0
    assert 50 < hits < 350  # both answers tried


def test_window_dots_sum_each_window_in_order(rng):
    """The template fit's sliding products, eight terms a pass, are numpy's matmul over the sliding windows (its
    loop adds each row's products in order): to the bit, for every length's last terms fewer than eight."""
    from drumstroke.analysis._kernels import window_dots

    for size in list(range(1, 26)) + [504]:
        count = int(rng.integers(1, 300))
        x, low = uneven_noise(rng, count + size + 20), int(rng.integers(0, 20))
        t = rng.standard_normal(size) * 10.0 ** rng.uniform(-3, 3)
        want = sliding_window_view(x[low:low + count + size - 1], size) @ t
        np.testing.assert_array_equal(window_dots(x, low, t, count), want, strict=True)
