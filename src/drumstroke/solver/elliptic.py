"""Exact flights under constant forcing, in Jacobi elliptic functions, compiled.

With C > 0 constant, φ = θ + π/2 turns θ̈ = −C cos θ into a pendulum. A flight
whose energy E = ω²/2 + C sin θ is below C (the stick never reaches the
vertical) is a libration with parameter m = (1 + E/C)/2 ∈ (0, 1). With τ the
time since the apex (negative before it) and v = √C·τ,

    θ(τ) = 2·asin(√m·cd(v | m)) − π/2,      ω(τ) = −2·√(m(1 − m)C)·sd(v | m),

(cd = cn/dn, sd = sn/dn: the apex form of sn(K − v) and cn(K − v), which
needs no K(m)).

The time from the apex to a state follows by inverting it: with
sin ψ = √((1 + sin θ)/(2m)) and cos ψ = |ω|/(2√(mC)), |τ| = (K(m) − F(ψ|m))/√C.
That difference cancels badly near the head of a small bounce, so it is written
as F(χ|m)/√C with tan χ = cos ψ/(√(1 − m)·sin ψ) (the addition theorem
F(ψ) + F(χ) = K for tan ψ·tan χ = 1/√(1 − m)), which keeps full relative
accuracy for flights of any size; on the orbit sin²χ and cos²χ are rational in
sin θ, ω², C and m, so no trigonometric function is needed.

Every function is compiled (numba) and takes floats; scipy's elliptic
functions cannot be called from compiled code, so F comes from Carlson's R_F
(:mod:`.carlson`) and sn, cn, dn from the arithmetic-geometric mean
(:func:`jacobi`). tests/test_elliptic.py holds both to scipy and mpmath.
"""

import math

import numpy as np

from .._jit import jit
from .carlson import rf

_EPS = 1.1102230246251565e-16  # 2⁻⁵³


@jit
def parameter(sin_theta, omega, c):
    """The elliptic parameter m = (1 + sin θ + ω²/(2C))/2 of the orbit through (θ, ω).

    m < 1 means a libration (the flight turns back before the vertical).
    """
    return 0.5 * (1.0 + sin_theta + omega * omega / (2.0 * c))


@jit
def time_from_apex(sin_theta, omega, c, m):
    """|τ|, the time between the apex and the state (θ, ω) on the orbit m (s).

    Parameters
    ----------
    sin_theta : float
        sin θ.
    omega : float
        ω (rad/s); only its magnitude matters.
    c : float > 0
        C (s⁻²).
    m : float in (0, 1)
        From :func:`parameter`.
    """
    # F(χ|m) = sin χ·R_F(cos²χ, 1 − m·sin²χ, 1) (DLMF 19.25.5), where on the orbit
    # sin²χ = ω²/(2mC(1 − sin θ)) and cos²χ = (1 − m)(1 + sin θ)/(m(1 − sin θ)).
    below = 1.0 - sin_theta
    sin2 = omega * omega / (2.0 * m * c * below)
    cos2 = (1.0 - m) * max(1.0 + sin_theta, 0.0) / (m * below)
    return math.sqrt(sin2) * rf(cos2, cos2 + (1.0 - m) * sin2, 1.0) / math.sqrt(c)


@jit
def to_head(sin_theta, omega, c, m, sin_head):
    """From a state (θ, ω) on the orbit m under C = ``c``: the way down to the head.

    Returns
    -------
    to_apex : float
        Time from now to the apex (s), negative if the apex is past.
    apex_to_head : float
        Time from the apex down to the head (s).
    speed : float
        |ω| on reaching the head (rad/s).
    """
    since_apex = time_from_apex(sin_theta, omega, c, m)
    speed = math.sqrt(omega * omega + 2.0 * c * max(sin_theta - sin_head, 0.0))
    return (since_apex if omega > 0.0 else -since_apex), time_from_apex(sin_head, speed, c, m), speed


@jit
def flight_time(launch_speed, c, sin_head):
    """Duration (s) of a flight launched upward from the head at ``launch_speed`` (rad/s), and its m.

    Parameters
    ----------
    launch_speed : float ≥ 0
        ω just after the impact (rad/s).
    c : float > 0
        C (s⁻²).
    sin_head : float
        sin θ_max.
    """
    m = parameter(sin_head, launch_speed, c)
    return 2.0 * time_from_apex(sin_head, launch_speed, c, m), m


@jit
def jacobi(u, m):
    """sn, cn and dn of ``u`` for the parameter m in [0, 1), by the AGM and descending Landen steps.

    The algorithm of Abramowitz & Stegun 16.4 (as in Cephes' ``ellpj``, which
    scipy wraps), accurate to a few units of round-off.
    """
    return jacobi_with(u, m, agm_scratch())


AGM_SIZE = 23
"""An AGM kept for :func:`jacobi_with`: m, its steps i, 2^i, then a_0…a_9 and c_0…c_9."""
_A, _C = 3, 13


@jit
def agm_scratch():
    """Room for :func:`jacobi_with`'s AGM, holding none yet [shape=(AGM_SIZE,)]."""
    agm = np.empty(AGM_SIZE)
    agm[0] = math.nan
    return agm


@jit
def jacobi_with(u, m, agm):
    """:func:`jacobi`, the AGM of m (which ``u`` does not change) kept in ``agm`` for the next call with this m.

    ``agm`` is from :func:`agm_scratch`. The numbers are :func:`jacobi`'s whatever it held.
    """
    if m < 1e-9:
        return _near_zero(u, m)
    _agm(m, agm)
    i = int(agm[1])
    phi = agm[2] * agm[_A + i] * u
    previous = phi
    while i > 0:
        previous = phi
        phi = 0.5 * (math.asin(agm[_C + i] * math.sin(phi) / agm[_A + i]) + phi)
        i -= 1
    return _finished(phi, previous, m)


@jit
def jacobi_pair(u, w, m, agm):
    """:func:`jacobi_with` of ``u`` and of ``w`` (sn, cn, dn of each), the same numbers, the two descents
    side by side: each step waits for an asin and a sine of the last, and the other's step fills the wait."""
    if m < 1e-9:
        return _near_zero(u, m) + _near_zero(w, m)
    _agm(m, agm)
    i = int(agm[1])
    phi, psi = agm[2] * agm[_A + i] * u, agm[2] * agm[_A + i] * w
    previous, before = phi, psi
    while i > 0:
        previous, before = phi, psi
        phi = 0.5 * (math.asin(agm[_C + i] * math.sin(phi) / agm[_A + i]) + phi)
        psi = 0.5 * (math.asin(agm[_C + i] * math.sin(psi) / agm[_A + i]) + psi)
        i -= 1
    return _finished(phi, previous, m) + _finished(psi, before, m)


@jit(inline="always")
def _near_zero(u, m):
    s, c = math.sin(u), math.cos(u)
    ai = 0.25 * m * (u - s * c)
    return s - ai * c, c + ai * s, 1.0 - 0.5 * m * s * s


@jit(inline="always")
def _agm(m, agm):
    """The AGM's a_i and c_i of m into ``agm`` (at most 9 steps for m < 1 − 1e-16), unless it holds them."""
    if agm[0] != m:
        agm[_A], agm[_C] = 1.0, math.sqrt(m)
        b = math.sqrt(1.0 - m)
        twon = 1.0
        i = 0
        while abs(agm[_C + i] / agm[_A + i]) > _EPS and i < 9:
            agm[_C + i + 1] = 0.5 * (agm[_A + i] - b)
            agm[_A + i + 1], b = 0.5 * (agm[_A + i] + b), math.sqrt(agm[_A + i] * b)
            twon *= 2.0
            i += 1
        agm[0], agm[1], agm[2] = m, i, twon


@jit(inline="always")
def _finished(phi, previous, m):
    """sn, cn, dn from the descent's last two angles."""
    sn, cn = math.sin(phi), math.cos(phi)
    dn_factor = math.cos(phi - previous)
    if abs(dn_factor) < 0.1:  # the quotient cancels there (DLMF 22.20.5)
        return sn, cn, math.sqrt(1.0 - m * sn * sn)
    return sn, cn, cn / dn_factor


@jit(error_model="numpy")  # (its divisor, 1 − m·sn²·sn_h², is positive for m < 1: no check for zero)
def shift(sn, cn, dn, sn_h, cn_h, dn_h, m):
    """sn, cn, dn of u + h from those of u and of h (the addition theorem, DLMF 22.8.1–3)."""
    d = 1.0 / (1.0 - m * sn * sn * sn_h * sn_h)
    return (
        (sn * cn_h * dn_h + sn_h * cn * dn) * d,
        (cn * cn_h - sn * dn * sn_h * dn_h) * d,
        (dn * dn_h - m * sn * cn * sn_h * cn_h) * d,
    )


@jit
def apex_form(sn, cn, dn, root_m, speed):
    """θ = 2·asin(√m·cd) − π/2 (rad) and ω = −speed·sd (rad/s), given √m and speed = 2√(m(1 − m)C)."""
    inverse = 1.0 / dn
    return 2.0 * math.asin(root_m * cn * inverse) - 0.5 * math.pi, -speed * sn * inverse


@jit
def state(tau, c, m):
    """θ (rad) and ω (rad/s) at time ``tau`` after the apex (s) on the orbit ``m``."""
    return state_with(tau, c, m, agm_scratch())


@jit
def state_with(tau, c, m, agm):
    """:func:`state`, its AGM kept in ``agm`` (from :func:`agm_scratch`) as :func:`jacobi_with` keeps it."""
    sn, cn, dn = jacobi_with(math.sqrt(c) * tau, m, agm)
    return apex_form(sn, cn, dn, math.sqrt(m), 2.0 * math.sqrt(m * (1.0 - m) * c))
