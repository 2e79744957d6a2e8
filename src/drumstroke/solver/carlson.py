"""Carlson's symmetric elliptic integral R_F in compiled code.

scipy.special's ``ellipkinc`` cannot be called from numba, so the compiled
solver writes F(φ|m) = sin φ · R_F(cos²φ, 1 − m·sin²φ, 1) for φ in [0, π/2]
(DLMF 19.25.5), with R_F by the duplication theorem (Carlson, 1995, Numer.
Algorithms 10; DLMF 19.36.1), iterated until the series' error term is below
double-precision round-off.
"""

import math

from .._jit import jit

_Q_FACTOR = (3.0 * 2.0**-53) ** (-1.0 / 6.0)  # the series' relative error is then below 2⁻⁵³


@jit
def rf(x, y, z):
    """Carlson's symmetric integral R_F(x, y, z) for x, y, z ≥ 0, at most one of them 0.

    Carlson's algorithm (1995, §2): duplicate until 4⁻ⁿ·Q < Aₙ, then a series of order 5.
    """
    a0 = (x + y + z) / 3.0
    q = _Q_FACTOR * max(abs(a0 - x), abs(a0 - y), abs(a0 - z))
    x0, y0 = x, y
    a, scale = a0, 1.0
    for _ in range(100):
        if q * scale < abs(a):
            break
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * sy + sy * sz + sz * sx
        x, y, z, a = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam), 0.25 * (a + lam)
        scale *= 0.25
    dx = (a0 - x0) * scale / a
    dy = (a0 - y0) * scale / a
    dz = -(dx + dy)
    e2 = dx * dy - dz * dz
    e3 = dx * dy * dz
    return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / math.sqrt(a)
