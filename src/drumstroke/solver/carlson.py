"""Incomplete elliptic integrals of the first kind in compiled code (Carlson's R_F).

scipy.special's ``ellipkinc`` cannot be called from numba, so the batch
kernels use F(φ|m) = sin φ · R_F(cos²φ, 1 − m·sin²φ, 1) for φ in [0, π/2]
(DLMF 19.25.5), with R_F by the duplication theorem (Carlson, 1995, Numer.
Algorithms 10; DLMF 19.36.1), iterated until the series' error term is below
double-precision round-off.
"""

import math

from numba import njit


@njit(cache=True)
def rf(x, y, z):
    """Carlson's symmetric integral R_F(x, y, z) for x, y, z ≥ 0, at most one of them 0."""
    for _ in range(100):
        mu = (x + y + z) / 3.0
        dx, dy, dz = 1.0 - x / mu, 1.0 - y / mu, 1.0 - z / mu
        if max(abs(dx), abs(dy), abs(dz)) < 1e-4:  # the series error is then below 1e-20
            e2 = dx * dy - dz * dz
            e3 = dx * dy * dz
            return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / math.sqrt(mu)
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * sy + sy * sz + sz * sx
        x, y, z = (x + lam) / 4.0, (y + lam) / 4.0, (z + lam) / 4.0
    return math.nan


@njit(cache=True)
def ellipf(phi, m):
    """F(φ|m) for φ in [0, π/2] and m in [0, 1)."""
    s = math.sin(phi)
    c = math.cos(phi)
    return s * rf(c * c, 1.0 - m * s * s, 1.0)
