"""The compiled numerics the control loop shares: the simple joint's substeps, the motor's line, the encoder.

- :func:`advance_joint` integrates the simple joint over one control period (RK4 substeps,
  the motor's torque–speed line per substep, contacts with the head located within the
  substep), compiled, so the loop (:class:`drumstroke.robot.loop.ControlLoop`) calls it once
  per period;
- :func:`limit_torque`, the DC motor's torque–speed line, applied per substep on both plants;
- :func:`quantize`, the encoder's reading, and :func:`estimate_speed`, the speed estimate the
  controllers see.

The controllers' laws are their own (:mod:`drumstroke.robot.controllers`).

Examples
--------
>>> limit_torque(5.0, 20.0, 2.0, 40.0)  # half the no-load speed: half the stall torque
1.0
>>> quantize(0.10001, 1e-4)
0.1
"""

import math

from .._jit import jit

SPEED_FILTER = 1.0
"""How much of each new encoder difference the speed estimate takes (1: the raw difference over one period)."""


@jit
def _accel(theta, omega, tau, J, mgk, b, tc, head, K, B):
    friction = b * omega + tc * math.tanh(omega / 1e-3)
    delta = head - theta
    contact = 0.0
    if delta > 0.0:
        contact = max(0.0, K * delta - B * omega)
    return (tau - mgk * math.cos(theta) - friction + contact) / J


def limit_torque(tau, omega, tau_max, w_max):
    """The DC motor's torque–speed line: the torque (N·m) it gives for ``tau``, less the faster it already turns that way.

    Parameters
    ----------
    tau : float
        Commanded torque (N·m).
    omega : float
        Joint speed (rad/s).
    tau_max : float > 0
        Stall torque (N·m).
    w_max : float > 0
        No-load speed (rad/s).
    """
    if tau * omega > 0.0:
        top = tau_max * max(0.0, 1.0 - abs(omega) / w_max)
    else:
        top = tau_max
    return min(max(tau, -top), top)


_limit = jit(limit_torque)


@jit
def advance_joint(state, params, events, tau, substeps, h, t0):
    """The simple joint over one control period under the command ``tau`` (N·m): the mean torque applied (N·m).

    ``substeps`` RK4 steps of ``h`` seconds, each with ``tau`` limited by the motor's line at
    the step's starting speed. A contact starts or ends where the step crosses the head,
    interpolated linearly within it; its speed is the one on the free side of the step (the
    head's damping switches on in full at contact).

    Parameters
    ----------
    state : ndarray [shape=(4,)]
        θ (rad), ω (rad/s), on the head (1.0) or not (0.0), contacts logged; updated in place.
    params : ndarray [shape=(9,)]
        J (kg·m²), m·g·k (N·m), b (N·m·s/rad), τ_c (N·m), τ_max (N·m), ω_max (rad/s), θ_head (rad),
        the head's K (N·m/rad) and B (N·m·s/rad).
    events : ndarray [shape=(m, 4)]
        Contacts: onset time (s), ω then (rad/s), release time (s), ω then; filled in place.
        Room for ``substeps`` more rows (one contact per substep at most) is the caller's to make.
    tau : float
        N·m.
    substeps : int
    h : float
        s.
    t0 : float
        The time at the period's start (s).
    """
    theta, omega, in_contact, count = state[0], state[1], state[2] != 0.0, int(state[3])
    inertia, mgk, b, tc, tau_max, w_max = params[0], params[1], params[2], params[3], params[4], params[5]
    head, K, B = params[6], params[7], params[8]
    applied = 0.0
    for j in range(substeps):
        tau_j = _limit(tau, omega, tau_max, w_max)
        applied += tau_j
        k1t, k1w = omega, _accel(theta, omega, tau_j, inertia, mgk, b, tc, head, K, B)
        k2t, k2w = omega + 0.5 * h * k1w, _accel(theta + 0.5 * h * k1t, omega + 0.5 * h * k1w, tau_j, inertia, mgk, b,
                                                 tc, head, K, B)
        k3t, k3w = omega + 0.5 * h * k2w, _accel(theta + 0.5 * h * k2t, omega + 0.5 * h * k2w, tau_j, inertia, mgk, b,
                                                 tc, head, K, B)
        k4t, k4w = omega + h * k3w, _accel(theta + h * k3t, omega + h * k3w, tau_j, inertia, mgk, b, tc, head, K, B)
        theta_new = theta + h / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t)
        omega_new = omega + h / 6.0 * (k1w + 2 * k2w + 2 * k3w + k4w)
        touching = theta_new < head
        if touching != in_contact:
            frac = (theta - head) / (theta - theta_new) if theta != theta_new else 0.0
            when = t0 + (j + frac) * h
            # the speed on the free side of the step: the head's damping switches on in full at contact
            speed = omega if touching else omega_new
            if touching:
                if count == events.shape[0]:
                    raise IndexError("advance_joint: no room left in events for another contact")
                events[count, 0] = when
                events[count, 1] = speed
                count += 1
            elif count > 0:
                events[count - 1, 2] = when
                events[count - 1, 3] = speed
            in_contact = touching
        theta, omega = theta_new, omega_new
    state[0], state[1], state[2], state[3] = theta, omega, 1.0 if in_contact else 0.0, count
    return applied / substeps


def estimate_speed(omega_hat, measured, measured_prev, rate):
    """The speed estimate's update (rad/s): ``SPEED_FILTER`` of the way to the encoder's difference over a period.

    Parameters
    ----------
    omega_hat : float
        The last estimate (rad/s).
    measured, measured_prev : float
        This period's and the last period's encoder readings (rad).
    rate : float
        The control rate (Hz).
    """
    return omega_hat + SPEED_FILTER * ((measured - measured_prev) * rate - omega_hat)


def quantize(theta, resolution):
    """The encoder's reading of θ (rad): the nearest multiple of ``resolution`` (rad)."""
    return math.floor(theta / resolution + 0.5) * resolution
