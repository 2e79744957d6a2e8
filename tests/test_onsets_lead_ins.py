"""The learned lead-in's statistics (drumstroke.analysis.onsets._median_and_spread) against numpy's median and
percentiles: the same bits, on seeded random leads of 1 to 40 values, with ties, integers and a constant."""

import numpy as np
import pytest

from drumstroke.analysis.onsets import _median_and_spread


def _cases():
    rng = np.random.default_rng(20261127)
    for count in range(1, 41):
        yield rng.normal(48.0, 5.0, count)
        yield np.round(rng.normal(48.0, 5.0, count))  # ties
        yield rng.uniform(-1e-3, 1e6, count)
    yield np.full(7, 47.25)


@pytest.mark.parametrize("leads", list(_cases()))
def test_median_and_spread_are_numpys(leads):
    middle, spread = _median_and_spread(leads)
    assert middle == np.median(leads)
    assert spread == np.subtract(*np.percentile(leads, [75, 25]))
