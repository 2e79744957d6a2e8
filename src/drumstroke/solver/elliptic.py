"""Exact flights under constant forcing, in Jacobi elliptic functions.

With C > 0 constant, φ = θ + π/2 turns θ̈ = −C cos θ into a pendulum. A flight
whose energy E = ω²/2 + C sin θ is below C (the stick never reaches the
vertical) is a libration with parameter m = (1 + E/C)/2 ∈ (0, 1), and with τ the
time since the apex (negative before it), u = K(m) − √C·τ:

    θ(τ) = 2·asin(√m·sn(u | m)) − π/2,      ω(τ) = −2·√(m·C)·cn(u | m).

The time from the apex to a state follows by inverting sn: with
sin ψ = √((1 + sin θ)/(2m)) and cos ψ = |ω|/(2√(mC)), |τ| = (K(m) − F(ψ|m))/√C.
That difference cancels badly near the head of a small bounce, so it is written
as F(χ|m)/√C with tan χ = cos ψ/(√(1 − m)·sin ψ) (the addition theorem
F(ψ) + F(χ) = K for tan ψ·tan χ = 1/√(1 − m)), which keeps full relative
accuracy for flights of any size.

All functions take and return numpy arrays or floats, element-wise.
"""

import numpy as np
from scipy.special import ellipj, ellipk, ellipkinc


def parameter(sin_theta, omega, c):
    """The elliptic parameter m = (1 + sin θ + ω²/(2C))/2 of the orbit through (θ, ω).

    m < 1 means a libration (the flight turns back before the vertical).
    """
    return 0.5 * (1.0 + sin_theta + omega * omega / (2.0 * c))


def time_from_apex(sin_theta, omega, c, m):
    """|τ|, the time between the apex and the state (θ, ω) on the orbit m (s).

    Parameters
    ----------
    sin_theta : float or ndarray
        sin θ.
    omega : float or ndarray
        ω (rad/s); only its magnitude matters.
    c : float > 0
        C (s⁻²).
    m : float or ndarray in (0, 1)
        From :func:`parameter`.
    """
    sin_psi = np.sqrt(np.maximum(1.0 + sin_theta, 0.0) / (2.0 * m))
    cos_psi = np.abs(omega) / (2.0 * np.sqrt(m * c))
    chi = np.arctan2(cos_psi, np.sqrt(1.0 - m) * sin_psi)
    return ellipkinc(chi, m) / np.sqrt(c)


def flight_time(launch_speed, c, sin_head):
    """Duration of a flight launched upward from the head at ``launch_speed`` (s).

    Parameters
    ----------
    launch_speed : float or ndarray ≥ 0
        ω just after the impact (rad/s).
    c : float > 0
        C (s⁻²).
    sin_head : float
        sin θ_max.
    """
    m = parameter(sin_head, launch_speed, c)
    return 2.0 * time_from_apex(sin_head, launch_speed, c, m)


def state(tau, c, m):
    """θ (rad) and ω (rad/s) at time ``tau`` after the apex (s) on the orbit ``m``."""
    u = ellipk(m) - np.sqrt(c) * tau
    sn, cn, _, _ = ellipj(u, m)
    theta = 2.0 * np.arcsin(np.sqrt(m) * sn) - 0.5 * np.pi
    omega = -2.0 * np.sqrt(m * c) * cn
    return theta, omega
