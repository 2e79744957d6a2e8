"""The closed loop, compiled: controller at the control rate, joint integrated in substeps, contacts logged.

One function runs every control law (see :mod:`drumstroke.robot.controllers`)
so a whole stroke — thousands of control periods, tens of substeps each — runs
without returning to Python.

Laws (``law``) and their ``gains``:

OPEN        τ = torque[k] (the drop test)
PI          τ = Kp·e + Ki·∫e                                      gains: Kp, Ki
PID_FF      τ = J·α_ref + m g k cos θ_ref + Kp·e + Ki·∫e + Kd·ė     gains: Kp, Ki, Kd
IMPEDANCE   τ = J·α_ref + m g k cos θ_ref + s·(Kp·e + Kd·ė)        gains: Kp, Kd, band, floor
            with s = floor + (1 − floor)·min(1, (θ_ref − θ_head)/band): a stiff arm in the
            air and a soft one near the head, so the contact bounces the stick, not the motor.

e = θ_ref − θ̂, ė = ω_ref − ω̂, with θ̂ the encoder reading and ω̂ the estimate of
:func:`estimate_speed` (with :data:`SPEED_FILTER` = 1, the encoder's difference over one
period). The integral is clamped so Ki·∫e stays within the torque limit (anti-windup).
The impedance controller's ``lead`` acts on the reference, before the loop
(:func:`drumstroke.robot.track.lead_in_contact`).
"""

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

OPEN, PI, PID_FF, IMPEDANCE = 0, 1, 2, 3

SPEED_FILTER = 1.0
"""How much of each new encoder difference the speed estimate takes (1: the raw difference over one period)."""


@dataclass(frozen=True)
class Log:
    """What the joint did: per control period θ (rad), ω (rad/s), torque (N·m); contacts with the head.

    Attributes
    ----------
    theta, omega, torque : ndarray [shape=(n,)]
        At the start of each control period; the torque applied over it.
    onsets : ndarray [shape=(m,)]
        Times the stick touched the head (s).
    onset_speed : ndarray [shape=(m,)]
        ω then (rad/s, ≤ 0).
    release, release_speed : ndarray [shape=(m,)]
        When it left the head (s) and ω then (rad/s); NaN if still on it at the end.
    """

    theta: np.ndarray
    omega: np.ndarray
    torque: np.ndarray
    onsets: np.ndarray
    onset_speed: np.ndarray
    release: np.ndarray
    release_speed: np.ndarray


def run_plant(plant, stiffness, damping, torque, rate, *, theta0=0.0, omega0=0.0):
    """Drive the joint open loop with ``torque`` (N·m, one per control period at ``rate`` Hz)."""
    n = len(torque)
    zeros = np.zeros(n)
    return run_loop(plant, stiffness, damping, OPEN, np.zeros(4), zeros, zeros, zeros, rate,
                    theta0=theta0, omega0=omega0, torque=np.asarray(torque, dtype=float))


def run_loop(plant, stiffness, damping, law, gains, ref_theta, ref_omega, ref_alpha, rate, *, theta0, omega0,
             torque=None):
    """Run the closed loop over the reference (arrays at ``rate`` Hz); return the :class:`Log`."""
    n = len(ref_theta)
    torque = np.zeros(n) if torque is None else torque
    out = _loop(law, np.asarray(gains, dtype=float), ref_theta, ref_omega, ref_alpha, torque, float(rate),
                int(plant.substeps), plant.inertia, plant.gravity_torque, plant.viscous, plant.coulomb,
                plant.max_torque, plant.max_speed, plant.resolution, plant.head, float(stiffness), float(damping),
                float(theta0), float(omega0))
    theta, omega, applied, events, count = out
    events = events[:count]
    return Log(theta, omega, applied, events[:, 0].copy(), events[:, 1].copy(), events[:, 2].copy(),
               events[:, 3].copy())


@njit(cache=True)
def _accel(theta, omega, tau, J, mgk, b, tc, head, K, B):
    friction = b * omega + tc * math.tanh(omega / 1e-3)
    delta = head - theta
    contact = 0.0
    if delta > 0.0:
        contact = max(0.0, K * delta - B * omega)
    return (tau - mgk * math.cos(theta) - friction + contact) / J


def limit_torque(tau, omega, tau_max, w_max):
    """The DC motor's torque–speed line: the torque (N·m) it gives for ``tau``, less the faster it already turns that way."""
    if tau * omega > 0.0:
        top = tau_max * max(0.0, 1.0 - abs(omega) / w_max)
    else:
        top = tau_max
    return min(max(tau, -top), top)


_limit = njit(cache=True)(limit_torque)


@njit(cache=True)
def command(law, gains, ref_theta, ref_omega, ref_alpha, measured, omega_hat, integral, dt, J, mgk, tau_max, head):
    """One control period of ``law``: the torque (N·m) and the updated error integral (rad·s)."""
    e = ref_theta - measured
    de = ref_omega - omega_hat
    ff = J * ref_alpha + mgk * math.cos(ref_theta)
    if law == PI or law == PID_FF:
        ki = gains[1]
        if ki > 0.0:
            integral = min(max(integral + e * dt, -tau_max / ki), tau_max / ki)
        if law == PI:
            return gains[0] * e + ki * integral, integral
        return ff + gains[0] * e + ki * integral + gains[2] * de, integral
    s = gains[3] + (1.0 - gains[3]) * min(1.0, max(0.0, (ref_theta - head) / gains[2]))
    return ff + s * (gains[0] * e + gains[1] * de), integral


def estimate_speed(omega_hat, measured, measured_prev, rate):
    """The speed estimate's update (rad/s): ``SPEED_FILTER`` of the way to the encoder's difference over a period."""
    return omega_hat + SPEED_FILTER * ((measured - measured_prev) * rate - omega_hat)


_estimate_speed = njit(cache=True)(estimate_speed)


def quantize(theta, resolution):
    """The encoder's reading of θ (rad): the nearest multiple of ``resolution`` (rad)."""
    return math.floor(theta / resolution + 0.5) * resolution


_quantize = njit(cache=True)(quantize)


@njit(cache=True)
def _loop(law, gains, ref_theta, ref_omega, ref_alpha, open_torque, rate, substeps, J, mgk, b, tc, tau_max, w_max,
          q, head, K, B, theta0, omega0):
    n = len(ref_theta)
    dt = 1.0 / rate
    h = dt / substeps
    theta_log = np.empty(n)
    omega_log = np.empty(n)
    torque_log = np.empty(n)
    events = np.full((max(16, n), 4), np.nan)
    count = 0
    theta, omega = theta0, omega0
    integral = 0.0
    measured_prev = _quantize(theta0, q)
    omega_hat = omega0
    in_contact = theta < head
    for k in range(n):
        measured = _quantize(theta, q)
        if k > 0:
            omega_hat = _estimate_speed(omega_hat, measured, measured_prev, rate)
        measured_prev = measured
        if law == 0:
            tau = open_torque[k]
        else:
            tau, integral = command(law, gains, ref_theta[k], ref_omega[k], ref_alpha[k], measured, omega_hat,
                                    integral, dt, J, mgk, tau_max, head)
        theta_log[k] = theta
        omega_log[k] = omega
        t0 = k * dt
        applied = 0.0
        for j in range(substeps):
            tau_j = _limit(tau, omega, tau_max, w_max)
            applied += tau_j
            k1t, k1w = omega, _accel(theta, omega, tau_j, J, mgk, b, tc, head, K, B)
            k2t, k2w = omega + 0.5 * h * k1w, _accel(theta + 0.5 * h * k1t, omega + 0.5 * h * k1w, tau_j, J, mgk, b,
                                                     tc, head, K, B)
            k3t, k3w = omega + 0.5 * h * k2w, _accel(theta + 0.5 * h * k2t, omega + 0.5 * h * k2w, tau_j, J, mgk, b,
                                                     tc, head, K, B)
            k4t, k4w = omega + h * k3w, _accel(theta + h * k3t, omega + h * k3w, tau_j, J, mgk, b, tc, head, K, B)
            theta_new = theta + h / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t)
            omega_new = omega + h / 6.0 * (k1w + 2 * k2w + 2 * k3w + k4w)
            touching = theta_new < head
            if touching != in_contact:
                frac = (theta - head) / (theta - theta_new) if theta != theta_new else 0.0
                when = t0 + (j + frac) * h
                # the speed on the free side of the step: the head's damping switches on in full at contact
                speed = omega if touching else omega_new
                if touching:
                    if count == len(events):
                        grown = np.full((2 * count, 4), np.nan)
                        grown[:count] = events
                        events = grown
                    events[count, 0] = when
                    events[count, 1] = speed
                    count += 1
                elif count > 0:
                    events[count - 1, 2] = when
                    events[count - 1, 3] = speed
                in_contact = touching
            theta, omega = theta_new, omega_new
        torque_log[k] = applied / substeps
    return theta_log, omega_log, torque_log, events, count
