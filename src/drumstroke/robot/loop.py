"""The one control loop, over a plant interface: whole runs are many steps of the stepping code.

Each control period :meth:`ControlLoop.step` reads the encoder (θ quantised to the plant's
resolution), updates the speed estimate, runs the controller's law on the reference and
the readings, and advances the plant by one period under the torque; it logs θ and ω at
the period's start and the mean torque applied over it. The plant reports its own
contacts with the head. :func:`drumstroke.robot.track.track` is this loop stepped over a
whole reference; a live runtime steps it as setpoints arrive; the drop tests drive it open
loop (:meth:`ControlLoop.drive`).

The plant is anything that keeps to :class:`Joint`: the simple joint
(:class:`drumstroke.robot.plant.SimpleJoint`, compiled) and MuJoCo's
(:class:`drumstroke.robot.mujoco_plant.MujocoJoint`).

Examples
--------
>>> from drumstroke.robot.controllers import controller
>>> from drumstroke.robot.plant import Plant, SimpleJoint
>>> joint = SimpleJoint(Plant(), cor=0.86, theta0=0.3)
>>> loop = ControlLoop(joint, controller("pid-ff"), rate=1000.0)
>>> for _ in range(500):  # hold θ = 0.3 rad
...     torque = loop.step(0.3, 0.0, 0.0)
>>> log = loop.log()
>>> len(log.theta), bool(abs(log.theta[-1] - 0.3) < 1e-4), len(log.onsets)
(500, True, 0)
"""

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from .._checks import check_real
from ..errors import ParameterError
from .kernel import estimate_speed, quantize


@dataclass(frozen=True, repr=False)
class Contacts:
    """A joint's contacts with the head, in time order.

    Attributes
    ----------
    t : ndarray [shape=(m,)]
        When the stick touched the head (s).
    omega : ndarray [shape=(m,)]
        ω then (rad/s, ≤ 0).
    release : ndarray [shape=(m,)]
        When it left the head (s); NaN while it is still on it.
    omega_after : ndarray [shape=(m,)]
        ω then (rad/s); NaN while it is still on it.
    tip_distance : float
        x, fulcrum to tip (m).
    """

    t: np.ndarray
    omega: np.ndarray
    release: np.ndarray
    omega_after: np.ndarray
    tip_distance: float

    @classmethod
    def from_events(cls, events, tip_distance):
        """From rows of (onset time, ω, release time, ω) [shape=(m, 4)]."""
        events = np.asarray(events, dtype=float).reshape(-1, 4)
        return cls(*(events[:, i].copy() for i in range(4)), float(tip_distance))

    def __len__(self):
        return len(self.t)

    def __repr__(self):
        span = f" over [{self.t[0]:.6g}, {self.t[-1]:.6g}] s" if len(self) else ""
        return f"Contacts({len(self)}{span})"

    @property
    def tip_speed(self):
        """|ω|·x at each touch, the tip's speed (m/s) [shape=(m,)]."""
        return np.abs(self.omega) * self.tip_distance


@runtime_checkable
class Joint(Protocol):
    """What the control loop needs of a plant.

    Attributes
    ----------
    plant : Plant
        Its parameters: the encoder's step, and the model the laws' feedforward uses.
    theta : float
        θ now (rad).
    omega : float
        ω now (rad/s).
    """

    plant: object
    theta: float
    omega: float

    def advance(self, torque, duration):
        """Advance by one control period of ``duration`` (s) under the command ``torque`` (N·m).

        In substeps, each applying ``torque`` limited by the motor's torque–speed line
        (:func:`drumstroke.robot.kernel.limit_torque`) at the substep's starting speed.

        Returns
        -------
        float
            The mean torque applied over the period (N·m).
        """

    def contacts(self, since=0):
        """The :class:`Contacts` so far, from the ``since``-th on (0: all; an integer ≥ 0)."""


@dataclass(frozen=True, repr=False)
class Log:
    """What the joint did: per control period θ (rad), ω (rad/s), torque (N·m); its contacts with the head.

    Attributes
    ----------
    theta, omega, torque : ndarray [shape=(n,)]
        At the start of each control period; the mean torque applied over it.
    contacts : Contacts
    """

    theta: np.ndarray
    omega: np.ndarray
    torque: np.ndarray
    contacts: Contacts

    def __repr__(self):
        return f"Log({len(self.theta)} control periods, {self.contacts!r})"

    @property
    def onsets(self):
        """Times the stick touched the head (s) [shape=(m,)]."""
        return self.contacts.t

    @property
    def onset_speed(self):
        """ω then (rad/s, ≤ 0) [shape=(m,)]."""
        return self.contacts.omega

    @property
    def release(self):
        """When it left the head (s; NaN if still on it at the end) [shape=(m,)]."""
        return self.contacts.release

    @property
    def release_speed(self):
        """ω then (rad/s; NaN if still on it) [shape=(m,)]."""
        return self.contacts.omega_after


class ControlLoop:
    """A controller playing on a joint, one control period per :meth:`step`.

    The speed estimate starts at the joint's ω (the loop starts at rest or where the
    reference starts, known); from the second period on it is
    :func:`~drumstroke.robot.kernel.estimate_speed` of the encoder readings.

    Parameters
    ----------
    joint : Joint
    controller : Controller or None
        Its law (:meth:`~drumstroke.robot.controllers.Controller.law`) gives the torque each
        period; None for a loop only driven open loop (:meth:`drive`).
    rate : float in [10, 1e5]
        The control rate (Hz).
    capacity : int
        Periods to make room for in the log at the start (it grows as needed).
    record : bool
        Keep θ, ω and the torque of every period for :meth:`log` (default). A loop that runs for
        hours and needs only the joint's contacts (a live robot's) keeps none: its own memory stays the
        same (the joint's contacts, a few dozen bytes each, still accumulate).
    """

    def __init__(self, joint, controller, rate, *, capacity=1024, record=True):
        self.rate = check_real("rate", rate, low=10.0, high=1e5, unit="Hz")
        self.period = 1.0 / self.rate
        self.joint = joint
        self._command = None if controller is None else controller.law(joint.plant, self.rate)
        self._resolution = joint.plant.resolution
        self._measured = quantize(joint.theta, self._resolution)
        self._omega_hat = joint.omega
        self._count = 0
        self.record = bool(record)
        capacity = max(int(capacity), 1) if self.record else 0
        self._theta, self._omega, self._torque = np.empty(capacity), np.empty(capacity), np.empty(capacity)

    def __len__(self):
        """Control periods run so far."""
        return self._count

    def step(self, ref_theta, ref_omega, ref_alpha):
        """Run one control period towards the reference θ (rad), ω (rad/s), α (rad/s²): the mean torque (N·m)."""
        if self._command is None:
            raise ParameterError("this loop has no controller: drive it with drive(torque)")
        joint = self.joint
        theta, omega = joint.theta, joint.omega
        measured = self._read(theta)
        return self._apply(theta, omega, self._command(ref_theta, ref_omega, ref_alpha, measured, self._omega_hat))

    def drive(self, torque):
        """Run one control period open loop with the command ``torque`` (N·m; 0: the motor off): the mean torque."""
        joint = self.joint
        theta, omega = joint.theta, joint.omega
        self._read(theta)
        return self._apply(theta, omega, torque)

    def run(self, ref_theta, ref_omega, ref_alpha):
        """:meth:`step` through the reference arrays (rad, rad/s, rad/s² [shape=(n,)])."""
        self._reserve(len(ref_theta))
        step = self.step
        for theta, omega, alpha in zip(np.asarray(ref_theta, dtype=float).tolist(),
                                       np.asarray(ref_omega, dtype=float).tolist(),
                                       np.asarray(ref_alpha, dtype=float).tolist()):
            step(theta, omega, alpha)

    def log(self):
        """The :class:`Log` so far (copies); a loop that keeps no record has none."""
        if not self.record:
            raise ParameterError("this loop keeps no log (it was made with record=False): its joint's contacts() "
                                 "are what it played")
        n = self._count
        return Log(self._theta[:n].copy(), self._omega[:n].copy(), self._torque[:n].copy(), self.joint.contacts())

    def _read(self, theta):
        """The encoder's reading of ``theta`` (rad), updating the speed estimate (rad/s) from the last one."""
        measured = quantize(theta, self._resolution)
        if self._count:
            self._omega_hat = estimate_speed(self._omega_hat, measured, self._measured, self.rate)
        self._measured = measured
        return measured

    def _apply(self, theta, omega, torque):
        """Advance the joint one period under ``torque`` (N·m), logging where it started and what it applied."""
        k = self._count
        applied = self.joint.advance(torque, self.period)
        if self.record:
            if k == len(self._theta):
                self._reserve(1)
            self._theta[k], self._omega[k], self._torque[k] = theta, omega, applied
        self._count = k + 1
        return applied

    def _reserve(self, more):
        """Room in the log for ``more`` periods after those run (at least doubling when it grows); none unrecorded."""
        if not self.record:
            return
        n, need = self._count, self._count + more
        if need > len(self._theta):
            size = max(need, 2 * len(self._theta))
            self._theta, self._omega, self._torque = (np.concatenate((a[:n], np.empty(size - n)))
                                                      for a in (self._theta, self._omega, self._torque))


def open_loop(joint, torque, rate):
    """Drive ``joint`` with the command ``torque`` (N·m, one per control period at ``rate`` Hz): its :class:`Log`.

    Parameters
    ----------
    joint : Joint
    torque : ndarray [shape=(n,)]
    rate : float in [10, 1e5]
        Hz.
    """
    torque = np.asarray(torque, dtype=float)
    loop = ControlLoop(joint, None, rate, capacity=len(torque))
    for tau in torque.tolist():
        loop.drive(tau)
    return loop.log()
