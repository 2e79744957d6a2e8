"""Playing a reference on the simulated joint: the reference at the control rate, the run, what was played.

Examples
--------
>>> import drumstroke
>>> from drumstroke.robot.controllers import controller
>>> ref = reference(drumstroke.simulate("finger-pulses"))
>>> played = track(ref, controller("impedance"))
>>> played.controller, len(played.reference.t)
('impedance', 5001)
"""

from dataclasses import dataclass

import numpy as np

from .._checks import check_real
from ..errors import ParameterError
from ..recipe import DEFAULT_COR
from ..stroke import as_trajectory
from ..trajectory import DEFAULT_RATE, Trajectory
from .kernel import run_loop
from .plant import Plant, contact_gains

_DIFF = 1e-6  # s, the step of the acceleration's central difference on the exact path


@dataclass(frozen=True)
class Reference:
    """What the robot is asked to play, at the control rate.

    Attributes
    ----------
    t, theta, omega, alpha : ndarray [shape=(n,)]
        s; rad; rad/s; the flight acceleration (rad/s²) — impacts excluded.
    impact_t, impact_speed : ndarray [shape=(m,)]
        The reference's impacts: times (s) and tip speeds (m/s).
    rate : float
        Hz.
    name, model : str
    head : float
        θ_max (rad).
    cor : float
        The coefficient of restitution the reference was made with (the head's).
    trajectory : Trajectory
        The curve it samples.
    """

    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    impact_t: np.ndarray
    impact_speed: np.ndarray
    rate: float
    name: str
    model: str
    head: float
    cor: float
    trajectory: object = None


def reference(source, rate=DEFAULT_RATE, *, cor=None):
    """A :class:`Reference` from a Stroke or Trajectory sampled at ``rate`` (Hz).

    ``cor`` (the head's coefficient of restitution) defaults to the recipe's.
    """
    rate = check_real("rate", rate, low=10.0, high=1e5, unit="Hz")
    trajectory = as_trajectory(source)
    if cor is None:
        cor = trajectory.recipe.cor if trajectory.recipe is not None else DEFAULT_COR
    cor = check_real("cor", cor, low=0.0, high=1.0)
    t, theta, omega = trajectory.sample(rate)
    alpha = _flight_acceleration(trajectory, t)
    impacts = trajectory.impacts
    return Reference(t, theta, omega, alpha, impacts.t.copy(), impacts.tip_speed.copy(), rate, trajectory.name,
                     trajectory.model, trajectory.theta_max, cor, trajectory)


def trajectory_from_samples(t, theta, omega, *, head, tip_distance, name="trajectory", model="unknown"):
    """A :class:`~drumstroke.palette.Trajectory` through samples (a CSV) with its impacts found in them.

    An impact lies between samples k and k+1 where ω turns from down to up within
    two periods' travel of the head; its time is where sample k's motion reaches
    the head, t_k + (θ_k − θ_head)/|ω_k| (to a small fraction of a period).
    """
    t = np.asarray(t, dtype=float)
    return Trajectory.from_samples(t - t[0], theta, omega, theta_max=head, tip_distance=tip_distance, name=name,
                                   model=model)


def lead_in_contact(ref, lead):
    """θ, ω, α to steer by when the head holds the stick ``lead`` seconds at each impact (arrays like ref's).

    A real head keeps the stick for a few milliseconds where the model's impact is
    instantaneous, so a stick that follows the reference leaves every impact late
    and lands late. Flight by flight (impact i to i+1, duration d > 2·lead), the
    stick is held on the head for ``lead`` and the flight is replayed
    d/(d − lead) times faster: θ_w(t) = θ(t_i + (t − t_i − lead)·d/(d − lead)),
    so it leaves when the head lets go and lands on the reference's next impact.
    Shorter flights are left as they are.
    """
    theta, omega, alpha = ref.theta.copy(), ref.omega.copy(), ref.alpha.copy()
    if lead <= 0.0 or ref.trajectory is None or len(ref.trajectory.impacts) < 2:
        return theta, omega, alpha
    impacts = ref.trajectory.impacts.t
    t = ref.t
    i = np.searchsorted(impacts, t, side="right") - 1
    inside = (i >= 0) & (i < len(impacts) - 1)
    i = np.clip(i, 0, len(impacts) - 2)
    start, d = impacts[i], impacts[i + 1] - impacts[i]
    warp = inside & (d > 2.0 * lead)
    held = warp & (t < start + lead)
    flying = warp & ~held
    speed = np.where(warp, d / np.maximum(d - lead, 1e-12), 1.0)
    source = np.clip(start + (t - start - lead) * speed, 0.0, ref.trajectory.t_end)
    if flying.any():
        th, om = ref.trajectory.path(source[flying])
        theta[flying], omega[flying] = th, om * speed[flying]
        alpha[flying] = _flight_acceleration(ref.trajectory, source[flying]) * speed[flying] ** 2
    theta[held], omega[held], alpha[held] = ref.head, 0.0, 0.0
    return theta, omega, alpha


def _flight_acceleration(trajectory, t):
    """dω/dt away from impacts: a central difference, one-sided where an impact is within the step."""
    lo = np.clip(t - _DIFF, 0.0, trajectory.t_end)
    hi = np.clip(t + _DIFF, 0.0, trajectory.t_end)
    impacts = trajectory.impacts.t
    if len(impacts):
        j = np.searchsorted(impacts, t, side="right")
        before = impacts[np.clip(j - 1, 0, len(impacts) - 1)]
        after = impacts[np.clip(j, 0, len(impacts) - 1)]
        lo = np.where((j > 0) & (before > lo), t, lo)  # an impact just behind: look ahead only
        hi = np.where((j < len(impacts)) & (after < hi), t, hi)
    _, w_hi = trajectory.path(hi)
    _, w_lo = trajectory.path(lo)
    alpha = np.where(hi > lo, (w_hi - w_lo) / np.where(hi > lo, hi - lo, 1.0), 0.0)
    return alpha


@dataclass(frozen=True)
class Played:
    """A reference played by a controller on a plant.

    Attributes
    ----------
    reference : Reference
    controller : str
    theta, omega, torque : ndarray [shape=(n,)]
        The joint at each control period: rad, rad/s, N·m.
    onsets, onset_speed : ndarray [shape=(m,)]
        When the stick touched the head (s) and its tip speed then (m/s).
    max_torque : float
        The plant's torque limit (N·m).
    plant : str
        "simple" or "mujoco".
    """

    reference: Reference
    controller: str
    theta: np.ndarray
    omega: np.ndarray
    torque: np.ndarray
    onsets: np.ndarray
    onset_speed: np.ndarray
    max_torque: float
    plant: str = "simple"


def track(ref, controller, plant=None):
    """Play ``ref`` (a :class:`Reference`) with ``controller`` on ``plant`` (default :class:`Plant`)."""
    plant = plant or Plant()
    if not isinstance(ref, Reference):
        raise ParameterError(f"ref must be a drumstroke.robot.track.Reference, got {ref!r}")
    if abs(plant.head - ref.head) > 1e-9:
        raise ParameterError(f"the reference's head ({ref.head:.6g} rad) is not the plant's ({plant.head:.6g} rad); "
                             "give the plant the stick the reference was made with")
    stiffness, damping = contact_gains(plant, ref.cor)
    theta, omega, alpha = lead_in_contact(ref, getattr(controller, "lead", 0.0))
    log = run_loop(plant, stiffness, damping, controller.law, controller.gains(), theta, omega, alpha,
                   ref.rate, theta0=float(ref.theta[0]), omega0=float(ref.omega[0]))
    tip = plant.stick.pivot_to_tip
    return Played(ref, controller.name, log.theta, log.omega, log.torque, log.onsets, np.abs(log.onset_speed) * tip,
                  plant.max_torque)
