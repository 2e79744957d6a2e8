"""Compiled loops written to make the onset detector faster (drumstroke.analysis._templates and its neighbours) against
the numpy code they stand for: to the bit, each computing what that code computed in the same operations."""

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from drumstroke.analysis import _templates


@pytest.fixture
def rng():
    return np.random.default_rng(20261127)


def test_lag_dots_are_numpys_dots_of_each_window(rng):
    """blas_lag_dots gives np.dot's bits (OpenBLAS's ddot, on one thread as the detector runs it) for every length: the
    16 lanes, the products left over, a window count that is no multiple of the lags side by side."""
    with threadpool_limits(1, user_api="blas"):
        for _ in range(600):
            length = int(rng.integers(1, 3000))
            count, first = int(rng.integers(1, 20)), int(rng.integers(0, 9))
            x = rng.standard_normal(first + count + length + 3) * 10.0 ** rng.uniform(-30, 30)
            x[rng.random(len(x)) < 0.05] = 0.0
            y = rng.standard_normal(length + int(rng.integers(0, 5))) * 10.0 ** rng.uniform(-3, 3, 1)
            got = np.full(count + 1, np.nan)
            _templates.blas_lag_dots(x, first, count, y, length, got)
            want = [np.dot(x[first + k:first + k + length], y[:length]) for k in range(count)]
            np.testing.assert_array_equal(got[:count], want)
            assert np.isnan(got[count])  # nothing written past the windows asked for


def test_squares_bound_the_running_sums(rng):
    """_squares sums in its own order: within the few ulps of the exact sum that _surely_least's bounds allow."""
    from numba import njit

    squares = njit(lambda x, first, last: _templates._squares(x, first, last))
    for _ in range(300):
        x = rng.standard_normal(int(rng.integers(1, 2000))) * 10.0 ** rng.uniform(-100, 100)
        first = int(rng.integers(0, len(x)))
        last = int(rng.integers(first, len(x) + 1))
        exact = float(np.sum(np.asarray(x[first:last], dtype=np.longdouble) ** 2))
        assert abs(squares(x, first, last) - exact) <= 4.0 * (last - first + 1) * np.finfo(float).eps * exact
