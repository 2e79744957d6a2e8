"""The compiled R_F, as F(φ|m) = sin φ·R_F(cos²φ, 1 − m·sin²φ, 1), against scipy's ellipkinc and mpmath."""

import mpmath
import numpy as np
from scipy.special import ellipkinc

from drumstroke.solver.carlson import rf


def ellipf(phi, m):
    s, c = np.sin(phi), np.cos(phi)
    return s * rf(c * c, 1.0 - m * s * s, 1.0)


def test_rf_closed_forms():
    # R_F(0, 1, 1) = π/2 and R_F(x, x, x) = 1/√x (DLMF 19.20.1)
    assert abs(rf(0.0, 1.0, 1.0) - np.pi / 2) < 4e-16
    assert abs(rf(4.0, 4.0, 4.0) - 0.5) < 1e-16


def test_ellipf_matches_scipy_over_the_solvers_range(rng):
    phi = rng.uniform(0.0, np.pi / 2, 20_000)
    m = rng.uniform(0.0, 1.0 - 1e-9, 20_000)
    ours = np.array([ellipf(p, q) for p, q in zip(phi, m)])
    assert np.max(np.abs(ours - ellipkinc(phi, m)) / np.maximum(ellipkinc(phi, m), 1e-300)) < 5e-15


def test_ellipf_matches_mpmath_at_small_angles_and_near_m_1():
    mpmath.mp.dps = 30
    for phi, m in [(1e-12, 0.4), (1e-6, 0.99), (0.3, 0.999999), (np.pi / 2, 0.9999999), (0.7, 0.0)]:
        exact = float(mpmath.ellipf(phi, m))
        assert abs(ellipf(phi, m) - exact) <= 4e-15 * exact
