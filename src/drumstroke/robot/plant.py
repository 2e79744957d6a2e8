"""The simulated robot joint: a DC motor and gearbox swinging the stick onto a drumhead.

Joint-side equation of motion, θ the stick's angle (rad) as in the model::

    J·θ̈ = τ_m − m·g·k·cos θ − b·θ̇ − τ_c·sign(θ̇) + τ_h

- J = m·D_geometry (the stick, Eq. 1) + N²·J_rotor (the motor's rotor through the gearbox);
- τ_m, the motor torque at the joint, is limited by the DC motor's torque–speed line:
  at most τ_max·(1 − |θ̇|/ω_max) in the direction of motion (none beyond the no-load
  speed ω_max), τ_max against it;
- b viscous and τ_c Coulomb friction (the Coulomb term fades to zero inside ±1e-3 rad/s);
- the drumhead is a unilateral spring–damper on the penetration δ = θ_head − θ > 0:
  τ_h = max(0, K·δ − B·θ̇). K and B are found (:func:`contact_gains`) so that the
  joint, dropped with the motor off, rebounds with the recipe's coefficient of
  restitution c and stays on the head for ``contact_time`` (3–6 ms for real sticks);
- the controller reads an encoder: θ quantised to 2π/(counts·N) rad.

Defaults are a small joint like the paper's prosthesis (a 20 W class brushless
motor with a 20:1 gearbox); every value can be set in a TOML ``[plant]`` table.

Examples
--------
>>> plant = Plant()
>>> round(plant.inertia, 6), round(plant.resolution, 7)
(0.001083, 3.83e-05)
>>> drop = drop_test(plant, cor=0.86)
>>> round(drop.restitution, 3), 0.003 <= drop.contact_time <= 0.006
(0.86, True)
"""

import math
from dataclasses import asdict, dataclass, field, replace
from functools import lru_cache

import numpy as np

from .._checks import check_int, check_keys, check_real
from ..errors import ParameterError
from ..formats.toml import reading_toml
from ..model import Stick, inertia_ratio
from ..recipe import STANDARD_GRAVITY
from .kernel import advance_joint
from .loop import Contacts, open_loop

GRAVITY = STANDARD_GRAVITY
"""m/s²."""


@dataclass(frozen=True)
class Plant:
    """Parameters of the robot joint (joint side unless said otherwise).

    Parameters
    ----------
    stick : Stick
        Its mass, geometry and head angle.
    rotor_inertia : float in [0, 1e-2]
        Motor rotor inertia (kg·m², motor side).
    gear_ratio : float in [1, 1000]
    max_torque : float in (0, 100]
        Stall torque at the joint (N·m).
    max_speed : float in (0, 1000]
        No-load speed at the joint (rad/s).
    viscous : float in [0, 10]
        b (N·m·s/rad).
    coulomb : float in [0, 10]
        τ_c (N·m).
    encoder_counts : int in [16, 2**24]
        Counts per motor revolution.
    contact_time : float in [0.0005, 0.05]
        How long a dropped stick stays on the head (s).
    substeps : int in [4, 1000]
        Integration steps per control period.
    """

    stick: Stick = field(default_factory=Stick)
    rotor_inertia: float = 1.0e-6
    gear_ratio: float = 20.0
    max_torque: float = 2.0
    max_speed: float = 40.0
    viscous: float = 2.0e-4
    coulomb: float = 2.0e-3
    encoder_counts: int = 8192
    contact_time: float = 0.0035
    substeps: int = 40

    def __post_init__(self):
        if not isinstance(self.stick, Stick):
            raise ParameterError(f"stick must be a drumstroke.Stick, got {self.stick!r}")
        check_real("rotor_inertia", self.rotor_inertia, low=0.0, high=1e-2, unit="kg m^2")
        check_real("gear_ratio", self.gear_ratio, low=1.0, high=1000.0)
        check_real("max_torque", self.max_torque, low=0.0, high=100.0, low_open=True, unit="N m")
        check_real("max_speed", self.max_speed, low=0.0, high=1000.0, low_open=True, unit="rad/s")
        check_real("viscous", self.viscous, low=0.0, high=10.0, unit="N m s/rad")
        check_real("coulomb", self.coulomb, low=0.0, high=10.0, unit="N m")
        check_real("contact_time", self.contact_time, low=5e-4, high=0.05, unit="s")
        check_int("encoder_counts", self.encoder_counts, low=16, high=2**24)
        check_int("substeps", self.substeps, low=4, high=1000)

    @property
    def inertia(self):
        """J, the joint's inertia: the stick (geometry model) plus the reflected rotor (kg·m²)."""
        stick = self.stick
        return stick.mass * inertia_ratio("geometry", stick) + self.gear_ratio**2 * self.rotor_inertia

    @property
    def gravity_torque(self):
        """m·g·k, the stick's gravity torque at level (N·m); at θ it is this times cos θ."""
        return self.stick.mass * GRAVITY * self.stick.pivot_to_com

    @property
    def resolution(self):
        """The encoder's step at the joint (rad)."""
        return 2.0 * math.pi / (self.encoder_counts * self.gear_ratio)

    @property
    def head(self):
        """The head angle θ_max (rad)."""
        return self.stick.theta_max

    @classmethod
    def from_dict(cls, table):
        """A plant from a TOML ``[plant]`` table (``stick`` a sub-table of Stick fields)."""
        if not isinstance(table, dict):
            raise ParameterError(f"plant must be a table, got {table!r}")
        keys = [name for name in cls.__dataclass_fields__]
        check_keys("plant", table, keys)
        values = dict(table)
        if "stick" in values:
            stick = values["stick"]
            if not isinstance(stick, dict):
                raise ParameterError(f"plant.stick must be a table, got {stick!r}")
            check_keys("plant.stick", stick, list(Stick().to_dict()))
            values["stick"] = Stick(**stick)
        return cls(**values)

    @classmethod
    def from_toml(cls, path):
        """A plant from the ``[plant]`` table of a TOML file (other tables are left for their readers)."""
        with reading_toml(path, "robot config") as data:
            return cls.from_dict(data.get("plant", {}))

    def to_dict(self):
        """The parameters as plain data (a ``[plant]`` table)."""
        data = asdict(self)
        data["stick"] = self.stick.to_dict()
        return data


def contact_gains(plant, cor):
    """K (N·m/rad) and B (N·m·s/rad) of the head so a dropped joint rebounds with ``cor`` after ``contact_time``.

    Calibrated on the joint dropped from level with the motor off: starting from
    the linear spring–damper's closed forms (c = exp(−ζπ/√(1−ζ²)), contact =
    π/ω_d), ζ and ω_n are corrected by simulating that contact, because the
    unilateral clamp ends it early and gravity acts during it.
    """
    cor = check_real("cor", cor, low=0.0, high=1.0)
    weight = plant.gravity_torque * math.cos(plant.head)
    speed = math.sqrt(2.0 * plant.gravity_torque * (0.0 - math.sin(plant.head)) / plant.inertia)
    return _contact_gains(plant.inertia, plant.contact_time, cor, weight, speed)


@lru_cache(maxsize=256)
def _contact_gains(inertia, contact_time, cor, weight, speed):
    from scipy.optimize import brentq

    def gains(zeta, period):
        omega_n = math.pi / (period * math.sqrt(1.0 - zeta**2))
        return inertia * omega_n**2, 2.0 * zeta * omega_n * inertia

    def rebound(zeta, period):
        return _contact(inertia, *gains(zeta, period), weight, speed)

    period, zeta = contact_time, 0.0
    for _ in range(4):  # alternately: ζ for the restitution, the period for the contact time
        deadest = rebound(0.9999, period)[0]
        if cor < deadest:
            raise ParameterError(f"cor must be at least {deadest:.3g} for this plant's head (a spring-damper "
                                 f"that lets go after {contact_time * 1e3:.3g} ms), got {cor!r}")
        zeta = brentq(lambda z, p=period: rebound(z, p)[0] - cor, 0.0, 0.9999, xtol=1e-13)
        period *= contact_time / rebound(zeta, period)[1]
    return gains(zeta, period)


def _contact(inertia, k, b, weight, speed):
    """Rebound ratio and duration of a contact entered at ``speed`` (rad/s) with ``weight`` (N·m) pressing down."""
    omega_n = math.sqrt(k / inertia)
    dt = 1e-3 / omega_n
    delta, rate, t = 0.0, speed, 0.0  # penetration (rad) and its rate (rad/s)
    while True:
        force = max(0.0, k * delta + b * rate)
        rate += (weight - force) / inertia * dt
        delta += rate * dt
        t += dt
        if delta <= 0.0:
            return -rate / speed, t


class SimpleJoint:
    """The joint of a :class:`Plant` integrated in compiled RK4 substeps: the control loop's simple plant.

    Keeps to :class:`drumstroke.robot.loop.Joint`. Each :meth:`advance` integrates one control
    period in ``plant.substeps`` RK4 steps (:func:`drumstroke.robot.kernel.advance_joint`),
    the motor's torque–speed line applied at each, and logs the contacts with the head.

    Parameters
    ----------
    plant : Plant
    cor : float in [0, 1] or None
        The head's coefficient of restitution: its gains are :func:`contact_gains` of it.
    stiffness, damping : float or None
        Or the head's gains K (N·m/rad) and B (N·m·s/rad) themselves, instead of ``cor``.
    theta0 : float
        θ at the start (rad).
    omega0 : float
        ω at the start (rad/s).
    start : float
        The time at the start (s): contacts are logged on this clock.
    """

    def __init__(self, plant, cor=None, *, stiffness=None, damping=None, theta0=0.0, omega0=0.0, start=0.0):
        if not isinstance(plant, Plant):
            raise ParameterError(f"plant must be a drumstroke.robot.plant.Plant, got {plant!r}")
        if (cor is None) == (stiffness is None or damping is None):
            raise ParameterError("give the head either cor or both stiffness and damping")
        if cor is not None:
            stiffness, damping = contact_gains(plant, cor)
        self.plant = plant
        self.stiffness = check_real("stiffness", stiffness, low=0.0, unit="N m/rad")
        self.damping = check_real("damping", damping, low=0.0, unit="N m s/rad")
        self._params = np.array([plant.inertia, plant.gravity_torque, plant.viscous, plant.coulomb, plant.max_torque,
                                 plant.max_speed, plant.head, self.stiffness, self.damping])
        self._state = np.array([check_real("theta0", theta0, unit="rad"), check_real("omega0", omega0, unit="rad/s"),
                                0.0, 0.0])
        self._state[2] = 1.0 if self._state[0] < plant.head else 0.0
        self._events = np.full((16, 4), np.nan)
        self._substeps = plant.substeps
        self._origin, self._periods, self._period = check_real("start", start, unit="s"), 0, None

    @property
    def theta(self):
        """θ now (rad)."""
        return self._state.item(0)

    @property
    def omega(self):
        """ω now (rad/s)."""
        return self._state.item(1)

    @property
    def time(self):
        """The time now (s)."""
        return self._origin + self._periods * self._period if self._periods else self._origin

    def advance(self, torque, duration):
        """Advance one control period of ``duration`` (s) under the command ``torque`` (N·m): the mean torque applied.

        Times are counted in whole periods from the last change of ``duration``, so the
        clock does not drift by adding periods up.
        """
        if duration != self._period:
            self._origin, self._periods, self._period = self.time, 0, duration
        events = self._events
        if self._state.item(3) + self._substeps > len(events):  # each substep may start one contact
            self._events = events = np.concatenate((events, np.full((len(events) + self._substeps, 4), np.nan)))
        applied = advance_joint(self._state, self._params, events, float(torque), self._substeps,
                                duration / self._substeps, self._origin + self._periods * duration)
        self._periods += 1
        return applied

    def set_head(self, head, stiffness, damping):
        """Put another head under the stick from now: at ``head`` (rad; None: none) with gains K (N·m/rad), B (N·m·s/rad).

        A kit's arm carries the stick from piece to piece (:mod:`drumstroke.robot.kit`): each has its
        surface at its own θ_max, and between them there is none. A stick already below the new head
        starts in contact with it, without an onset.
        """
        head = -math.inf if head is None else check_real("head", head, low=-math.pi / 2, high=math.pi / 2, unit="rad")
        self._params[6] = head
        self._params[7] = check_real("stiffness", stiffness, low=0.0, unit="N m/rad")
        self._params[8] = check_real("damping", damping, low=0.0, unit="N m s/rad")
        self._state[2] = 1.0 if self._state[0] < head else 0.0

    def contacts(self, since=0):
        """The :class:`~drumstroke.robot.loop.Contacts` so far, from the ``since``-th on (0: all)."""
        return Contacts.from_events(self._events[check_int("since", since, low=0):int(self._state.item(3))],
                                    self.plant.stick.pivot_to_tip)


def run_plant(plant, stiffness, damping, torque, rate, *, theta0=0.0, omega0=0.0):
    """Drive the simple joint open loop with ``torque`` (N·m, one per control period at ``rate`` Hz): its Log.

    Parameters
    ----------
    plant : Plant
    stiffness, damping : float
        The head's K (N·m/rad) and B (N·m·s/rad).
    torque : ndarray [shape=(n,)]
    rate : float in [10, 1e5]
        Hz.
    theta0, omega0 : float
        The start (rad, rad/s).
    """
    joint = SimpleJoint(plant, stiffness=stiffness, damping=damping, theta0=theta0, omega0=omega0)
    return open_loop(joint, torque, rate)


@dataclass(frozen=True)
class Drop:
    """A dropped joint, motor off: the first impact's speeds and how long it stayed on the head."""

    speed_in: float
    speed_out: float
    contact_time: float

    @property
    def restitution(self):
        """speed_out / speed_in."""
        return self.speed_out / self.speed_in


def drop_test(plant, cor, *, theta0=0.0):
    """Drop the joint from ``theta0`` (rad) with the motor off and no friction; measure its first bounce."""
    joint = SimpleJoint(replace(plant, viscous=0.0, coulomb=0.0), cor, theta0=theta0)
    log = open_loop(joint, np.zeros(2000), 1000.0)  # 2 s at 1 kHz
    if not len(log.onsets):
        raise ParameterError("the dropped stick never reached the head")
    return Drop(float(-log.onset_speed[0]), float(log.release_speed[0]), float(log.release[0] - log.onsets[0]))
