"""The kick drum pedal's beater: an exact hybrid system like the stick's, and its inverse.

The beater is a rigid rod turning about the pedal's axle; φ is its angle from the vertical (rad),
toward the bass drum's head positive. The head is vertical and stops the beater at φ_head; the
pedal's spring holds it back at φ_rest < φ_head with the foot off the board. The foot presses the
footboard with a force F (N), which the chain and the cam turn into a torque ``arm``·F about the axle.
With the gravity torque of the beater, m·g·l_c·sin φ, replaced by its chord between φ_rest and φ_head
(exact at both ends; the error within the swing is :attr:`Pedal.gravity_error`), the motion is

    J·φ̈ = arm·F − κ_eff·(φ − φ_rest),      κ_eff = κ − m·g·l_c·(sin φ_head − sin φ_rest)/(φ_head − φ_rest),

so under a constant force a flight is harmonic about φ_eq = φ_rest + arm·F/κ_eff, with Ω = √(κ_eff/J):

    φ(t) = φ_eq + (φ₀ − φ_eq)·cos Ωt + (ω₀/Ω)·sin Ωt.

An impact (φ reaching φ_head moving toward it) reverses and scales the speed, φ̇⁺ = −c·φ̇⁻. The beater
rests on the head while the net torque presses it in (φ_eq ≥ φ_head) and lifts off the moment it
does not. Between impacts the energy ½J·φ̇² + ½κ_eff·(φ − φ_eq)² is conserved, so a flight that
leaves the head at speed u under one force comes back at u, after

    (2/Ω)·atan2(u/Ω, φ_eq − φ_head);

with the foot pressing (φ_eq > φ_head) and c < 1 the bounces accumulate (Zeno) at the exact sum of
that series, after which the beater rests on the head ("buried").

Joint coordinate: the head is an *upper* bound on φ, and drumstroke's trajectories put the head
below (θ ≥ θ_max, impacts moving down). Curves, impacts and trajectories of the beater therefore use
θ = −φ, the angle measured back from the vertical, away from the head: θ_max = −φ_head, an impact
has ω = −φ̇⁻ < 0, and a beater level is 20·log10(|φ̇⁻|·length / 1 m/s) dB like a stick tip's.

- :class:`Pedal`: the pedal's numbers (validated), and where each comes from.
- :class:`FootForce`: a piecewise-constant foot force.
- :func:`simulate_pedal`: force → the exact motion (:class:`PedalStroke`, a
  :class:`~drumstroke.curve.Curve` and its :class:`~drumstroke.trajectory.Impacts`).
- :func:`design_pedal`: notes → the foot force that plays them (:class:`PedalDesign`), checked by
  simulating it.

Examples
--------
>>> pedal = Pedal()
>>> round(pedal.return_time, 3)                      # s: the spring brings the beater back from the head
0.12
>>> kick = design_pedal([0.3, 0.4], [15.0, 10.0])    # a double kick, 100 ms apart
>>> kick.stroke.impacts.t.round(9).tolist(), kick.stroke.impacts.level_db.round(6).tolist()
([0.3, 0.4], [15.0, 10.0])
>>> [round(piece.force, 1) for piece in kick.pieces]    # N: wait, press, rise, press, return, wait
[0.0, 67.3, 29.1, 96.2, 11.7, 0.0]
>>> trajectory = kick.stroke.sample(1000.0)          # θ = −φ, sampled exactly at 1 kHz
>>> bool(trajectory.theta.min() >= -pedal.phi_head), trajectory.impacts is kick.stroke.impacts
(True, True)
>>> theta, omega = trajectory.state(0.5)                                  # exact between the samples too
>>> bool(abs(-theta - float(kick.stroke.angle(0.5)[0])) == 0.0)
True
"""

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from .._checks import check_choice, check_int, check_real, check_vector, shown
from ..curve import Curve, Segment
from ..design import Unreachable
from ..errors import ParameterError, SimulationError
from ..solver.constants import ZENO_SPEED
from ..trajectory import LEVEL_REFERENCE, Impacts, Trajectory

STANDARD_GRAVITY = 9.81
"""m/s²."""

STEEL_DENSITY = 7850.0
"""kg/m³, of the beater's shaft."""

MAX_IMPACTS = 100_000
"""Most impacts :func:`simulate_pedal` lists by default."""

FORCE_LIMIT = 1.0e4
"""Largest |foot force| (N) a :class:`FootForce` may hold: some ten times a body's weight, beyond any foot."""

ENDS = ("release", "bury")
"""What follows a design's last note: the foot lets the beater back to rest, or keeps it pressed into the head."""

MIN_GAP = 1e-3
"""Closest two notes of one foot may be (s)."""

TIME_TOLERANCE = 1e-9
"""Largest |impact time − note time| (s) a design may show in its forward simulation."""

LEVEL_TOLERANCE = 1e-6
"""Largest |impact level − note level| (dB) a design may show in its forward simulation."""

LEVEL_RANGE = (-60.0, 40.0)
"""dB re 1 m/s: the levels a note may ask for (0.2 mm/s to 100 m/s of beater head speed)."""


# --- the pedal -------------------------------------------------------------------------------------------------------


def beater(head_mass=0.07, length=0.19, shaft_mass=None, shaft_length=0.21, shaft_diameter=0.006):
    """The moment of inertia J (kg m²) and gravity torque m·g·l_c (N m) of a beater about the axle.

    A point head of ``head_mass`` (kg) at ``length`` (m, the striking point) and a uniform shaft of
    ``shaft_length`` (m) from the axle up, of ``shaft_mass`` (kg; default a steel rod of
    ``shaft_diameter`` m): J = m_h·l² + m_s·L²/3 and m·g·l_c = g·(m_h·l + m_s·L/2). The head's own
    inertia about its centre (a 3 cm felt cylinder: under 1 % of J) is left out.

    >>> inertia, gravity = beater()
    >>> round(inertia, 6), round(gravity, 4)
    (0.003212, 0.1785)
    """
    head_mass = check_real("head_mass", head_mass, low=0.0, low_open=True, high=1.0, unit="kg")
    length = check_real("length", length, low=0.0, low_open=True, high=0.5, unit="m")
    shaft_length = check_real("shaft_length", shaft_length, low=0.0, high=0.5, unit="m")
    if shaft_mass is None:
        diameter = check_real("shaft_diameter", shaft_diameter, low=0.0, high=0.05, unit="m")
        shaft_mass = STEEL_DENSITY * math.pi * diameter**2 / 4.0 * shaft_length
    shaft_mass = check_real("shaft_mass", shaft_mass, low=0.0, high=1.0, unit="kg")
    inertia = head_mass * length**2 + shaft_mass * shaft_length**2 / 3.0
    gravity = STANDARD_GRAVITY * (head_mass * length + shaft_mass * shaft_length / 2.0)
    return inertia, gravity


_INERTIA, _GRAVITY = beater()


@dataclass(frozen=True)
class Pedal:
    """A bass drum pedal: its beater, spring, head and linkage, and the foot's strongest press.

    The defaults are a felt beater on a chain-drive pedal; see the page on the pedal for where each
    number comes from. Vary one with ``dataclasses.replace``.

    Parameters
    ----------
    inertia : float in (0, 0.1]
        J, kg m²: the beater about the axle (default :func:`beater`'s: a 70 g head 0.19 m up a
        0.21 m, 6 mm steel shaft, 0.00321 kg m²).
    spring : float in (0, 100]
        κ, N m/rad: the spring's stiffness about the axle (default 0.7, assumed: the return from the
        head to rest then takes :attr:`return_time` = 0.12 s, within the 0.1–0.2 s of real pedals).
    gravity : float in [0, 10]
        m·g·l_c, N m: the beater's gravity torque at the horizontal (default :func:`beater`'s, 0.178).
    phi_rest : float in (-pi/2, phi_head)
        rad: where the spring holds the beater with the foot off (default −1.0, 57° back from the
        vertical; pedals set their beater angle between about 30° and 60°).
    phi_head : float in [-0.5, 0.5]
        rad: where the beater meets the vertical head (default 0: the shaft vertical at the strike,
        the usual setting, the beater's face flat on the head).
    cor : float in [0, 1]
        c: restitution of the beater on the head (default 0.2, assumed: a felt beater on a kick drum's
        head returns little; slow-motion video of a hard kick shows about 0.15).
    length : float in (0, 0.5]
        m: axle to the striking point, for the beater head's speed and level (default 0.19).
    arm : float in (0, 0.2]
        m: torque about the axle per newton the foot presses the footboard with: the cam's radius
        (0.035 m) times the footboard's lever from the foot to the chain (0.18/0.25) (default 0.025).
    max_force : float in (0, 2000]
        N: the strongest press a design may ask of the foot (default 300 N, about half a player's
        weight, what a leg pressing down through the ankle gives).
    """

    inertia: float = _INERTIA
    spring: float = 0.7
    gravity: float = _GRAVITY
    phi_rest: float = -1.0
    phi_head: float = 0.0
    cor: float = 0.2
    length: float = 0.19
    arm: float = 0.025
    max_force: float = 300.0

    def __post_init__(self):
        checked = {
            "inertia": check_real("inertia", self.inertia, low=0.0, low_open=True, high=0.1, unit="kg m^2"),
            "spring": check_real("spring", self.spring, low=0.0, low_open=True, high=100.0, unit="N m/rad"),
            "gravity": check_real("gravity", self.gravity, low=0.0, high=10.0, unit="N m"),
            "phi_head": check_real("phi_head", self.phi_head, low=-0.5, high=0.5, unit="rad"),
            "cor": check_real("cor", self.cor, low=0.0, high=1.0),
            "length": check_real("length", self.length, low=0.0, low_open=True, high=0.5, unit="m"),
            "arm": check_real("arm", self.arm, low=0.0, low_open=True, high=0.2, unit="m"),
            "max_force": check_real("max_force", self.max_force, low=0.0, low_open=True, high=2000.0, unit="N"),
        }
        checked["phi_rest"] = check_real("phi_rest", self.phi_rest, low=-math.pi / 2, high=checked["phi_head"],
                                         low_open=True, high_open=True, unit="rad")
        for name, value in checked.items():
            object.__setattr__(self, name, value)
        least = self.gravity * self.chord
        if not self.spring > least:
            allowed = f"({least:g}, 100] N m/rad"
            raise ParameterError(f"spring must be in {allowed} (stiffer than gravity tips the beater over its swing), "
                                 f"got {self.spring!r}", parameter="spring", value=self.spring, allowed=allowed)

    @property
    def chord(self):
        """The slope of sin φ's chord from φ_rest to φ_head: gravity's linear part is gravity·chord·φ."""
        return (math.sin(self.phi_head) - math.sin(self.phi_rest)) / (self.phi_head - self.phi_rest)

    @property
    def stiffness(self):
        """κ_eff = κ − m·g·l_c·chord (N m/rad): the spring less gravity's pull away from the vertical."""
        return self.spring - self.gravity * self.chord

    @property
    def frequency(self):
        """Ω = √(κ_eff/J) (rad/s): the beater's natural angular frequency."""
        return math.sqrt(self.stiffness / self.inertia)

    @property
    def return_time(self):
        """π/(2Ω) (s): a beater let go at the head with the foot off is back at rest after this, moving."""
        return math.pi / (2.0 * self.frequency)

    @property
    def travel(self):
        """φ_head − φ_rest (rad): the beater's swing from rest to the head."""
        return self.phi_head - self.phi_rest

    @property
    def gravity_error(self):
        """The largest error (N m) of the chord for the gravity torque within the swing [φ_rest, φ_head].

        |m·g·l_c·(sin φ − sin φ_rest − chord·(φ − φ_rest))| is largest where cos φ = chord (0.011 N m for
        the defaults: 1.5 % of the spring's torque over the swing, κ·(φ_head − φ_rest)).
        """
        sign = 1.0 if self.phi_rest + self.phi_head < 0.0 else -1.0  # the side of 0 the swing mostly lies on
        where = min(max(-sign * math.acos(min(self.chord, 1.0)), self.phi_rest), self.phi_head)
        return self.gravity * abs(math.sin(where) - math.sin(self.phi_rest) - self.chord * (where - self.phi_rest))

    def equilibrium(self, force):
        """φ_eq (rad) under a constant foot ``force`` (N): φ_rest + arm·F/κ_eff."""
        return self.phi_rest + self.arm * force / self.stiffness

    def force_for(self, equilibrium):
        """The foot force (N) whose equilibrium is ``equilibrium`` (rad): the inverse of :meth:`equilibrium`."""
        return self.stiffness * (equilibrium - self.phi_rest) / self.arm

    @property
    def balance(self):
        """The foot force (N) that holds the beater against the head without pressing it in: κ_eff·travel/arm."""
        return self.force_for(self.phi_head)

    def energy(self, phi, omega, force):
        """½J·φ̇² + ½κ_eff·(φ − φ_eq)² (J) at angles ``phi`` (rad) and speeds ``omega`` (rad/s) under ``force`` (N)."""
        phi, omega = np.asarray(phi, dtype=float), np.asarray(omega, dtype=float)
        return 0.5 * self.inertia * omega**2 + 0.5 * self.stiffness * (phi - self.equilibrium(force))**2

    def level(self, speed):
        """20·log10(|speed|·length / 1 m/s) (dB) of the beater arriving at ``speed`` (rad/s)."""
        with np.errstate(divide="ignore"):
            return 20.0 * np.log10(np.abs(np.asarray(speed, dtype=float)) * self.length / LEVEL_REFERENCE)

    def speed(self, level):
        """The angular speed (rad/s) of an impact at ``level`` (dB re 1 m/s beater head speed)."""
        return 10.0 ** (np.asarray(level, dtype=float) / 20.0) * LEVEL_REFERENCE / self.length


# --- the foot's force ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FootForce:
    """A piecewise-constant foot force: each piece's force from its start to the next piece's start.

    Parameters
    ----------
    pieces : sequence of (t_start, force) pairs
        t_start (s) in [0, 3600], strictly increasing; force (N) with |force| ≤ :data:`FORCE_LIMIT`
        (negative: a toe strap pulling the board up). The force is 0 before the first start.

    Examples
    --------
    >>> press = FootForce([(0.1, 80.0), (0.25, 0.0)])
    >>> press([0.0, 0.1, 0.2, 0.3]).tolist()
    [0.0, 80.0, 80.0, 0.0]
    """

    pieces: tuple

    def __post_init__(self):
        try:
            pairs = [tuple(p) for p in self.pieces]
        except TypeError:
            raise ParameterError(f"pieces must be a sequence of (t_start, force) pairs, got {shown(self.pieces)}",
                                 parameter="pieces", value=self.pieces, allowed="(t_start, force) pairs") from None
        if not pairs or any(len(p) != 2 for p in pairs):
            raise ParameterError(f"pieces must be a non-empty sequence of (t_start, force) pairs, got "
                                 f"{shown(self.pieces)}", parameter="pieces", value=self.pieces,
                                 allowed="(t_start, force) pairs")
        starts = [check_real(f"pieces[{i}] start", t, low=0.0, high=3600.0, unit="s") for i, (t, _) in enumerate(pairs)]
        forces = [check_real(f"pieces[{i}] force", f, low=-FORCE_LIMIT, high=FORCE_LIMIT, unit="N")
                  for i, (_, f) in enumerate(pairs)]
        for i in range(1, len(starts)):
            if not starts[i] > starts[i - 1]:
                raise ParameterError(f"pieces[{i}] start must be after pieces[{i - 1}]'s ({starts[i - 1]!r} s), got "
                                     f"{starts[i]!r} s", parameter=f"pieces[{i}] start", value=starts[i],
                                     allowed=f"({starts[i - 1]!r}, 3600] s")
        object.__setattr__(self, "pieces", tuple(zip(starts, forces)))

    @classmethod
    def of(cls, force):
        """``force`` as a FootForce: one already, a number (N, from t = 0 on) or (t_start, force) pairs."""
        if isinstance(force, cls):
            return force
        if isinstance(force, (int, float, np.integer, np.floating)) and not isinstance(force, bool):
            return cls([(0.0, force)])
        return cls(force)

    def __call__(self, t):
        """The force (N) at times ``t`` (s) [any shape]; at a start, the new piece's."""
        starts = np.array([0.0] + [s for s, _ in self.pieces])
        forces = np.array([0.0] + [f for _, f in self.pieces])
        return forces[np.searchsorted(starts, np.asarray(t, dtype=float), side="right") - 1]

    def spans(self, t_end):
        """The constant pieces on [0, t_end] (s): (start, end, force) triples, end to end."""
        starts = [0.0] + [s for s, _ in self.pieces if 0.0 < s < t_end] + [t_end]
        return [(a, b, float(self(a))) for a, b in itertools.pairwise(starts)]


# --- one flight in closed form ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Flight:
    """The beater's flight under a constant force, from (φ₀, ω₀) at its local time 0.

    φ(τ) = φ_eq + (φ₀ − φ_eq)·cos Ωτ + (ω₀/Ω)·sin Ωτ.

    Attributes
    ----------
    phi0, omega0 : float
        rad, rad/s at τ = 0.
    equilibrium : float
        φ_eq, rad.
    rate : float
        Ω, rad/s.
    """

    phi0: float
    omega0: float
    equilibrium: float
    rate: float

    def state(self, tau):
        """φ (rad) and φ̇ (rad/s) at local times ``tau`` (s)."""
        x, w = self.phi0 - self.equilibrium, self.omega0 / self.rate
        cos, sin = np.cos(self.rate * tau), np.sin(self.rate * tau)
        return self.equilibrium + x * cos + w * sin, self.rate * (w * cos - x * sin)

    def path(self, tau):
        """θ = −φ (rad) and ω = −φ̇ (rad/s) at local times ``tau`` (s): the joint coordinate of a curve."""
        phi, omega = self.state(np.asarray(tau, dtype=float))
        return -phi, -omega

    def arrival(self, head):
        """(τ, speed): the first τ > 0 (s) at which φ reaches ``head`` moving toward it, and φ̇ there (rad/s).

        (inf, 0) if it never does. The speed comes from the conserved energy,
        (φ̇/Ω)² = (φ₀ − head)·(φ₀ + head − 2φ_eq) + (ω₀/Ω)², the time from the phase.
        """
        w = self.omega0 / self.rate
        squared = (self.phi0 - head) * (self.phi0 + head - 2.0 * self.equilibrium) + w * w
        if squared < 0.0:
            return math.inf, 0.0
        reach = math.sqrt(squared)
        if self.phi0 == head:  # leaving the head at −w: back after 2·atan2(−w, φ_eq − head)/Ω
            phase = 2.0 * math.atan2(abs(w), self.equilibrium - head)  # w ≤ 0; abs: atan2(-0.0, -1) is -π
        else:
            start = math.atan2(-w, self.phi0 - self.equilibrium)  # x = R cos(Ωτ + start)
            phase = (-math.atan2(reach, head - self.equilibrium) - start) % (2.0 * math.pi)
            if self.omega0 > 0.0 and phase > math.pi:  # below the head moving in: it is at most π ahead
                phase = 0.0  # (round-off put the start a hair past the crossing)
        return phase / self.rate, self.rate * reach

    def lowest(self, duration):
        """The lowest φ (rad) on [0, ``duration``] s."""
        x, w = self.phi0 - self.equilibrium, self.omega0 / self.rate
        bottom = (math.pi - math.atan2(-w, x)) % (2.0 * math.pi) / self.rate  # where Ωτ + start = π
        if bottom <= duration:
            return self.equilibrium - math.hypot(x, w)
        return min(self.phi0, float(self.state(duration)[0]))


def zeno_time(launch, pressing, cor, rate):
    """The time (s) from an impact until the bounces it starts accumulate on the head.

    Each flight under a constant force leaving the head at speed u comes back at u after
    (2/Ω)·atan(u/(Ω·p)), p = φ_eq − φ_head > 0; the launches are u = c^k·``launch``, so the bounces
    end after (2/Ω)·Σ_k atan(c^k·x), x = launch/(Ω·p). Terms are summed while c^k·x > 1e-3, the rest by
    Σ_k atan(c^k·y) = Σ_{m odd} ±y^m/(m·(1 − c^m)) to four terms (the next is below 1e-27·y).

    Parameters
    ----------
    launch : float ≥ 0
        rad/s, the speed the beater leaves the head with after the impact.
    pressing : float > 0
        p = φ_eq − φ_head (rad).
    cor : float in [0, 1)
    rate : float > 0
        Ω (rad/s).
    """
    y, total = launch / (rate * pressing), 0.0
    while y > 1e-3:
        total += math.atan(y)
        y *= cor
    total += sum((-1) ** (k // 2) * y**k / (k * (1.0 - cor**k)) for k in (1, 3, 5, 7))
    return 2.0 * total / rate


# --- the forward simulation ------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class PedalStroke:
    """What :func:`simulate_pedal` found: the beater's exact motion and its impacts.

    Attributes
    ----------
    pedal : Pedal
    force : FootForce
    t_end : float
        s.
    curve : Curve
        The exact motion in the joint coordinate θ = −φ (rad) and ω = −φ̇ (rad/s): one segment per flight
        (a closed-form :class:`Flight`) or rest; at an impact time, the state just after it.
    impacts : Impacts
        Times (s), ω = −φ̇ just before each (rad/s, < 0), tip distance the beater's length.
    omega_after : ndarray [shape=(n,)]
        c·|φ̇⁻| (rad/s, ≥ 0): the speed each impact sends the beater back with.
    rests : ndarray [shape=(k, 2)]
        [start, end] (s) of each time the beater rests on the head; a Zeno accumulation's rest starts at
        its accumulation time, the bounces of its summed tail (under :data:`ZENO_SPEED`) not listed.
    """

    pedal: Pedal
    force: FootForce
    t_end: float
    curve: Curve = field(repr=False)
    impacts: Impacts
    omega_after: np.ndarray = field(repr=False)
    rests: np.ndarray = field(repr=False)

    def angle(self, t):
        """φ (rad) and φ̇ (rad/s) at times ``t`` (s), exact; at an impact time, just after it."""
        theta, omega = self.curve(np.asarray(t, dtype=float))
        return -theta, -omega

    @property
    def levels(self):
        """Each impact's level (dB re 1 m/s beater head speed) [shape=(n,)]."""
        return self.impacts.level_db

    @property
    def rest_time(self):
        """When the beater comes to rest on the head for good (s), or None if it is off the head at t_end."""
        if len(self.rests) and self.rests[-1, 1] >= self.t_end:
            return float(self.rests[-1, 0])
        return None

    def sample(self, rate=1000.0, *, name="kick"):
        """The motion as a :class:`~drumstroke.trajectory.Trajectory` at ``rate`` (Hz), exact at the samples.

        Its stick is called ``name``, its head θ_max = −φ_head, its model ``"pedal"``.
        """
        return Trajectory.single(self.curve, self.impacts, self.omega_after, theta_max=-self.pedal.phi_head,
                                 t_end=self.t_end, rate=rate, stick=name, name=name, model="pedal",
                                 history=(f"simulate the pedal over [0, {self.t_end:g}] s",))


def simulate_pedal(force, pedal=None, *, t_end, phi0=None, omega0=0.0, max_impacts=MAX_IMPACTS):
    """Simulate the beater under a piecewise-constant foot force, exactly.

    Each piece's flights are :class:`Flight` closed forms; impacts are located from the phase of the
    cosine (to round-off, ~1e-16 s), their speeds from the conserved energy. A force pressing the
    beater into the head makes the bounces accumulate (:func:`zeno_time`): they are listed down to
    launches of :data:`ZENO_SPEED`, the rest summed, and the beater rests on the head from the
    accumulation time until a piece's net torque pulls it away (lift-off at that piece's start).

    Parameters
    ----------
    force : FootForce, float or sequence of (t_start, force) pairs
        N on the footboard (see :class:`FootForce`).
    pedal : Pedal, optional
        Default ``Pedal()``.
    t_end : float in [1e-6, 3600]
        s.
    phi0 : float in (-pi/2, phi_head], optional
        rad at t = 0 (default the pedal's rest angle).
    omega0 : float in [-1000, 1000]
        rad/s at t = 0 (toward the head positive).
    max_impacts : int ≥ 1
        Most impacts listed before :class:`~drumstroke.errors.SimulationError` is raised.

    Returns
    -------
    PedalStroke

    Raises
    ------
    SimulationError
        More than ``max_impacts`` impacts, or the beater swung back past the horizontal (φ = −π/2),
        beyond which the model means nothing.

    Examples
    --------
    Press 60 N from rest: the beater strikes, its bounces die on the head (buried); at 0.3 s the foot
    eases to 15 N, under the spring's pull at the head, and the beater lifts off:

    >>> stroke = simulate_pedal([(0.0, 60.0), (0.3, 15.0)], t_end=0.6)
    >>> stroke.impacts.t[:3].round(6).tolist(), stroke.levels[:3].round(2).tolist(), len(stroke.impacts)
    ([0.067628, 0.104257, 0.111721], [14.4, 0.42, -13.56], 11)
    >>> stroke.rests.round(6).tolist()
    [[0.113588, 0.3]]
    """
    pedal = _check_pedal(pedal)
    force = FootForce.of(force)
    t_end = check_real("t_end", t_end, low=1e-6, high=3600.0, unit="s")
    phi = pedal.phi_rest if phi0 is None else check_real("phi0", phi0, low=-math.pi / 2, high=pedal.phi_head,
                                                          low_open=True, unit="rad")
    omega = check_real("omega0", omega0, low=-1000.0, high=1000.0, unit="rad/s")
    run = _Run(pedal, check_int("max_impacts", max_impacts, low=1))
    for start, end, value in force.spans(t_end):
        phi, omega = run.piece(start, end, pedal.equilibrium(value), phi, omega)
    return run.result(force, t_end)


def _check_pedal(pedal):
    if pedal is None:
        return Pedal()
    if not isinstance(pedal, Pedal):
        raise ParameterError(f"pedal must be a drumstroke.kit.pedal.Pedal, got {shown(pedal)}", parameter="pedal",
                             value=pedal, allowed="a Pedal")
    return pedal


class _Run:
    """One simulation's growing record: segments, impacts, rests."""

    def __init__(self, pedal, max_impacts):
        self.pedal, self.max_impacts = pedal, max_impacts
        self.segments, self.times, self.speeds, self.rests = [], [], [], []

    def piece(self, start, end, equilibrium, phi, omega):
        """Run one constant-force piece from (φ, φ̇) at ``start`` to ``end`` (s); the state at ``end``."""
        head, t = self.pedal.phi_head, start
        while True:
            if phi >= head:  # on the head (a boundary's round-off clamped)
                phi = head
                if omega > 0.0:
                    omega, settled = self.impact(t, omega, end, equilibrium)
                    if settled is not None:
                        t, omega = settled, 0.0
                if omega == 0.0 and equilibrium >= head:
                    self.rest(t, end)
                    return head, 0.0
            flight = Flight(phi, omega, equilibrium, self.pedal.frequency)
            duration, speed = flight.arrival(head)
            if t + duration >= end:
                self.fly(flight, t, end)
                phi, omega = flight.state(end - t)
                return min(float(phi), head), float(omega)
            if t + duration == t and omega < 0.0:  # pressed in, bounces shorter than the clock resolves: settled
                self.rest(t, end)
                return head, 0.0
            if t + duration > t:  # (an arrival within round-off of the start is an impact now)
                self.fly(flight, t, t + duration, impact=True)
            t, phi, omega = t + duration, head, speed

    def impact(self, t, speed, end, equilibrium):
        """Record an impact at ``t`` arriving at ``speed`` (rad/s); the launch φ̇ and the rest time if it settles.

        The rest time is the accumulation time of the Zeno tail when the launch is below :data:`ZENO_SPEED`
        under a force pressing into the head and the tail ends within this piece (with c = 1 the
        micro-bounce never ends and never lifts: the beater counts as resting from this launch).
        """
        if len(self.times) >= self.max_impacts:
            raise SimulationError(f"more than max_impacts = {self.max_impacts} impacts before t = {t:.9g} s: raise "
                                  "max_impacts, shorten t_end or press less (c close to 1 bounces long)")
        self.times.append(t)
        self.speeds.append(speed)
        cor, head = self.pedal.cor, self.pedal.phi_head
        launch = cor * speed
        if 0.0 < launch < ZENO_SPEED and equilibrium > head:
            settle = t if cor == 1.0 else t + zeno_time(launch, equilibrium - head, cor, self.pedal.frequency)
            if settle < end:
                self.segments.append(Segment.hold(-head, t, settle))  # the summed tail, within 1e-12 rad of the head
                return 0.0, settle
        return -launch, None

    def fly(self, flight, start, end, impact=False):
        lowest = flight.lowest(end - start)
        if lowest <= -math.pi / 2:
            raise SimulationError(f"the beater swings back past the horizontal (phi = {lowest:.4g} rad < -pi/2) between "
                                  f"t = {start:.6g} and {end:.6g} s: the model covers phi in (-pi/2, phi_head]")
        impacts = np.array([end - start]) if impact else np.empty(0)
        self.segments.append(Segment(start, end, flight.path, start, impacts, source=flight))

    def rest(self, start, end):
        if self.rests and self.rests[-1][1] == start:
            self.rests[-1][1] = end
        else:
            self.rests.append([start, end])
        self.segments.append(Segment.hold(-self.pedal.phi_head, start, end))

    def result(self, force, t_end):
        speeds = np.array(self.speeds)
        impacts = Impacts(np.array(self.times), -speeds, self.pedal.length)
        rests = np.array(self.rests).reshape(-1, 2)
        return PedalStroke(self.pedal, force, t_end, Curve(tuple(self.segments)), impacts, self.pedal.cor * speeds,
                           rests)


# --- the inverse -----------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Swing:
    """One closed-form half-swing between the head and an apex under a constant force.

    From the head at speed ``speed`` back to an apex ``depth`` behind it (or, reversed in time, from
    rest at the apex onto the head at that speed): the equilibrium is midway plus the speed's share,
    φ_eq = φ_head − D/2 + (u/Ω)²/(2D), and it takes (2/Ω)·atan(D·Ω/u).

    Attributes
    ----------
    depth : float > 0
        D = φ_head − φ_apex (rad).
    speed : float ≥ 0
        u, rad/s at the head.
    force : float
        N on the footboard.
    duration : float
        s.
    """

    depth: float
    speed: float
    force: float
    duration: float

    @classmethod
    def of(cls, pedal, depth, speed):
        rate = pedal.frequency
        scaled = speed / rate
        with np.errstate(over="ignore"):  # a press beyond any foot comes out inf, and is refused as such
            equilibrium = pedal.phi_head - depth / 2.0 + scaled**2 / (2.0 * depth)
        return cls(depth, speed, pedal.force_for(equilibrium), 2.0 * math.atan2(depth, scaled) / rate)


def double_depth(gap, launch, arrival, rate):
    """The apex depth D (rad) between two impacts ``gap`` s apart: leaving at ``launch``, arriving at ``arrival``.

    The rise and the fall take (2/Ω)·(atan(D/W) + atan(D/V)) = gap with W, V the speeds over Ω; with
    x = Ω·gap/2 < π, tan of both sides gives sin x·D² + (V + W)·cos x·D − sin x·W·V = 0, whose positive
    root is taken in the form that does not cancel.
    """
    x = rate * gap / 2.0
    w, v = launch / rate, arrival / rate
    q = (v + w) * math.cos(x)
    root = math.sqrt(q * q + 4.0 * math.sin(x) ** 2 * w * v)
    return 2.0 * math.sin(x) * w * v / (q + root) if q > 0.0 else (root - q) / (2.0 * math.sin(x))


@dataclass(frozen=True)
class Piece:
    """One constant foot force of a design.

    Attributes
    ----------
    start, end : float
        s.
    force : float
        N.
    phase : str
        ``"wait"`` (at rest, foot off), ``"press"`` (from an apex or rest onto note ``note``), ``"rise"``
        (after note ``note`` back to an apex), ``"return"`` (after the last note back to rest) or ``"bury"``.
    note : int
        The note the piece plays (press) or leaves from (rise, return, bury); −1 before the first.
    """

    start: float
    end: float
    force: float
    phase: str
    note: int

    def __post_init__(self):
        for name in ("start", "end", "force"):
            object.__setattr__(self, name, float(getattr(self, name)))


@dataclass(frozen=True, eq=False)
class PedalDesign:
    """A designed foot force and its check.

    Attributes
    ----------
    times, levels : ndarray [shape=(n,)]
        The notes: s, dB re 1 m/s beater head speed.
    end : str
        One of :data:`ENDS`.
    pieces : tuple of Piece
    force : FootForce
    stroke : PedalStroke
        The force simulated forwards, its impacts up to the last note the notes.
    """

    times: np.ndarray
    levels: np.ndarray
    end: str
    pieces: tuple
    force: FootForce
    stroke: PedalStroke

    @property
    def max_force(self):
        """The strongest press the design asks of the foot (N)."""
        return max(piece.force for piece in self.pieces)


def design_pedal(times, levels, pedal=None, *, end="release", hold=None, tail=0.3):
    """The foot force that plays the notes ``times`` at ``levels`` on the pedal, checked by simulating it.

    The beater starts at rest at φ_rest, t = 0. Each note is reached by one press: from rest (the first
    note, or one after a gap long enough to let the beater back to rest) or from the apex of the rebound
    of the note before (a double kick): the rebound leaves the head at c times the arrival speed, a first
    force sets the apex it turns back at, a second drives it onto the head at the note's time and speed.
    Every half-swing is a :class:`Swing` in closed form; the apex depth of a gap is
    :func:`double_depth`'s. After the last note, ``end``:

    - ``"release"``: the foot eases off along the rebound with the one force that brings the beater to rest
      exactly at φ_rest, then lets go (0 N);
    - ``"bury"``: the foot keeps pressing with ``hold``; the rebounds die on the head (a Zeno accumulation)
      and the beater stays there.

    Parameters
    ----------
    times : array_like [shape=(n,)]
        s, in [0, 3600], strictly increasing, at least :data:`MIN_GAP` apart.
    levels : array_like [shape=(n,)]
        dB re 1 m/s beater head speed, within :data:`LEVEL_RANGE`.
    pedal : Pedal, optional
        Default ``Pedal()``; its ``max_force`` bounds every press.
    end : {"release", "bury"}
    hold : float in [pedal.balance, pedal.max_force], optional
        N, the press of ``end="bury"``; default the last note's press, at least twice the balance (the force
        that only just holds the beater on the head), at most ``max_force``.
    tail : float in (0, 60]
        s simulated after the beater is back at rest (``"release"``) or after the last note (``"bury"``).

    Returns
    -------
    PedalDesign

    Raises
    ------
    Unreachable
        A note that needs more than the pedal allows: a press stronger than ``max_force``, or (the first) a
        press longer than the time before it. The message names the note, what it needs and the limit.
    """
    pedal = _check_pedal(pedal)
    times = check_vector("times", times, low=0.0, high=3600.0, unit="s")
    levels = check_vector("levels", levels, low=LEVEL_RANGE[0], high=LEVEL_RANGE[1], unit="dB")
    _check_notes(times, levels)
    end = check_choice("end", end, ENDS)
    tail = check_real("tail", tail, low=0.0, low_open=True, high=60.0, unit="s")
    speeds = pedal.speed(levels)
    pieces = _approach(pedal, times[0], speeds[0], levels[0])
    for k in range(1, len(times)):
        pieces += _double(pedal, k, times, speeds, levels)
    pieces += _ending(pedal, end, hold, len(times) - 1, times[-1], speeds[-1], tail)
    force = FootForce([(p.start, p.force) for p in pieces])
    t_end = pieces[-1].end
    stroke = simulate_pedal(force, pedal, t_end=t_end)
    _check_played(stroke, times, levels, end)
    return PedalDesign(times, levels, end, tuple(pieces), force, stroke)


def _check_notes(times, levels):
    if len(times) == 0 or len(times) != len(levels):
        raise ParameterError(f"times and levels must be two arrays of one length >= 1, got {len(times)} times and "
                             f"{len(levels)} levels", parameter="times", value=times, allowed="n >= 1 times")
    gaps = np.diff(times)
    bad = np.flatnonzero(gaps < MIN_GAP)
    if len(bad):
        i = int(bad[0]) + 1
        allowed = f"[{times[i - 1] + MIN_GAP!r}, 3600] s"
        raise ParameterError(f"times[{i}] must be at least {MIN_GAP:g} s after times[{i - 1}] = {times[i - 1]!r} s "
                             f"(times strictly increasing), got {times[i]!r} s", parameter=f"times[{i}]",
                             value=float(times[i]), allowed=allowed)


def _press_limit(pedal, swing, k, time, level, what):
    if swing.force > pedal.max_force:
        raise Unreachable(f"note {k} (t = {time:.6g} s, {level:.4g} dB) needs a press of {swing.force:.4g} N {what}; "
                          f"the pedal's max_force is {pedal.max_force:g} N", note=k)


def _approach(pedal, time, speed, level):
    """The beater at rest, then one press from rest onto the first note."""
    press = Swing.of(pedal, pedal.travel, speed)
    _press_limit(pedal, press, 0, time, level, "from rest")
    begin = time - press.duration
    if begin < 0.0:
        raise Unreachable(f"note 0 (t = {time:.6g} s, {level:.4g} dB) needs a press of {press.duration:.6g} s from rest, "
                          f"which would start at {begin:.6g} s; the beater is at rest from t = 0 (play it at "
                          f"t >= {press.duration:.6g} s)", note=0, nearest_time=press.duration)
    wait = [Piece(0.0, begin, 0.0, "wait", -1)] if begin > 0.0 else []
    return wait + [Piece(begin, time, press.force, "press", 0)]


def _double(pedal, k, times, speeds, levels):
    """The rebound of note k − 1 and the press onto note k: through an apex, or through rest if the gap allows."""
    gap, launch = times[k] - times[k - 1], pedal.cor * speeds[k - 1]
    back, again = Swing.of(pedal, pedal.travel, launch), Swing.of(pedal, pedal.travel, speeds[k])
    if gap >= back.duration + again.duration:  # time enough to come back to rest: a press from rest
        depth = pedal.travel
    else:
        if launch == 0.0 and gap <= math.pi / pedal.frequency:  # no rebound: any swing back takes half a period
            raise Unreachable(f"note {k} (t = {times[k]:.6g} s, {levels[k]:.4g} dB) comes {gap:.6g} s after note "
                              f"{k - 1}; a beater that does not rebound (c = 0) takes half a period, "
                              f"{math.pi / pedal.frequency:.6g} s, to swing back from the head under a constant press",
                              note=k, nearest_time=float(times[k - 1] + math.pi / pedal.frequency))
        depth = double_depth(gap, launch, speeds[k], pedal.frequency)
        if not depth > 1e-12:  # a rebound too slow to turn back within the gap (c nearly 0)
            raise Unreachable(f"note {k} (t = {times[k]:.6g} s, {levels[k]:.4g} dB) comes {gap:.6g} s after note "
                              f"{k - 1}, whose rebound ({launch:.3g} rad/s) is too slow to turn back in time", note=k)
        back, again = Swing.of(pedal, depth, launch), Swing.of(pedal, depth, speeds[k])
    what = "from the rebound" if depth < pedal.travel else "from rest"
    _press_limit(pedal, back, k, times[k], levels[k], f"to turn note {k - 1}'s rebound back")
    _press_limit(pedal, again, k, times[k], levels[k], what)
    top, begin = times[k - 1] + back.duration, times[k] - again.duration
    pieces = [Piece(times[k - 1], top, back.force, "rise", k - 1)]
    if begin > top:
        pieces.append(Piece(top, begin, 0.0, "wait", k - 1))
    return pieces + [Piece(begin, times[k], again.force, "press", k)]


def _ending(pedal, end, hold, k, time, speed, tail):
    """After the last note (note k): eased back to rest, or held on the head."""
    if end == "release":
        back = Swing.of(pedal, pedal.travel, pedal.cor * speed)
        if back.force > pedal.max_force:
            raise Unreachable(f"note {k} (t = {time:.6g} s, the last) needs a press of {back.force:.4g} N to ease the "
                              f"beater back to rest; the pedal's max_force is {pedal.max_force:g} N", note=k)
        rest = time + back.duration
        return [Piece(time, rest, back.force, "return", k), Piece(rest, rest + tail, 0.0, "wait", k)]
    if hold is None:  # the foot keeps its last press, pressed well past the balance
        press = Swing.of(pedal, pedal.travel, speed).force
        hold = min(max(press, 2.0 * pedal.balance), pedal.max_force)
    hold = check_real("hold", hold, low=pedal.balance, high=pedal.max_force, unit="N")
    return [Piece(time, time + tail, hold, "bury", k)]


def _check_played(stroke, times, levels, end):
    """Raise unless the simulated impacts up to the last note are the notes (release: no impact after)."""
    impacts = stroke.impacts
    n = len(times)
    played = impacts.t[:n]
    if len(impacts) < n or (end == "release" and len(impacts) > n):
        raise SimulationError(f"the designed force plays {len(impacts)} impacts for {n} notes")
    time_error = np.abs(played - times).max()
    level_error = np.abs(impacts.level_db[:n] - levels).max()
    if time_error > TIME_TOLERANCE or level_error > LEVEL_TOLERANCE:
        raise SimulationError(f"the designed force plays the notes {time_error:.3g} s and {level_error:.3g} dB off; "
                              f"a design allows {TIME_TOLERANCE:g} s and {LEVEL_TOLERANCE:g} dB")
