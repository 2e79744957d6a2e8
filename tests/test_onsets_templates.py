"""The template stages' compiled loops (drumstroke.analysis._templates) against the numpy code they stand for: to the
bit (the same operations in the same order; a median is the same values whatever sorts them, but for the sign of a
zero where +0 and -0 tie, which no peak, product or energy after it sees)."""

import numpy as np
import pytest

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
