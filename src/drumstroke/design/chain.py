"""Inverse design of one stick's notes: the force profile whose stroke plays exactly those impacts.

The notes one stick must play — times (s) and levels (dB re 1 m/s tip speed) — are played
as consecutive bounces of one stroke. The stroke is built from exact flights
(:mod:`.flight`):

- the **approach**: from rest at a height (where the stick was lifted or caught) a constant
  force throws it onto the head so that it arrives at the first note's time and speed; the
  height comes from the start state or, without one, from a fall of ``lead`` seconds;
- one **flight per gap**: after each impact the stick leaves at c times its speed, rises
  under one force to an apex and falls under another, arriving at the next note's time and
  speed; the two equations fix the apex and both forces exactly;
- the **end** after the last note: ``"catch"`` (caught at the apex of the rebound: the
  stroke ends there, at rest), ``"press"`` (pressed into the head with the strongest force:
  the bounces die in a quick buzz and the stick rests) or ``"bounce"`` (let bounce under
  gravity alone until it rests).

The forces form a piecewise-constant a(t), written as a ``piecewise-linear`` profile whose
steps take 2 ns (centred on the switch, so their impulse is the step's). Every design is
simulated forwards by the solver and checked: its impacts up to the last note are exactly
the notes (times within :data:`TIME_TOLERANCE`, levels within :data:`LEVEL_TOLERANCE`;
in practice within a few nanoseconds and 1e-6 dB), with no other impact in between.

A note that cannot be played within the limits raises :class:`Unreachable`, naming the
note, what it needs and the limit, and the nearest time and level that can be reached.

Examples
--------
>>> diddle = design([0.2, 0.3], velocities=[100, 100])        # two equal notes 100 ms apart
>>> [round(float(t), 9) for t in diddle.impacts.t]
[0.2, 0.3]
>>> [round(float(db), 6) for db in diddle.impacts.level_db] == [round(float(db), 6) for db in diddle.levels]
True
>>> diddle.end, diddle.model, diddle.recipe.force.kind
('catch', 'paper', 'piecewise-linear')
"""

import functools
import itertools
import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from .._checks import as_vector, check_choice, check_real, check_vector, shown
from ..dynamics import CEILING_DB, FLOOR_DB, velocity_to_level
from ..errors import ParameterError, SimulationError
from ..palette.motion import Limits
from ..profiles import Constant, PiecewiseLinear
from ..recipe import STANDARD_GRAVITY, Recipe
from ..stroke import simulate
from ..trajectory import LEVEL_REFERENCE, Impacts
from .flight import (
    apex_for_fall,
    flight_time,
    force_to_reach,
    height_time,
    possible_flights,
    settled_flights,
    solve_apex,
    solve_flight,
)
from .setup import FORCE_LIMIT, ForceRange, Setup  # noqa: F401 (FORCE_LIMIT and ForceRange: also drumstroke.design.chain's)
from .throw import one_note

HUMAN_FORCE = 250.0
"""The top of the human thumb's range of a(t) (m/s², paper §3.3: about 10 N on this stick)."""

ENDS = ("catch", "press", "bounce")
"""What may follow the last note: caught at its rebound's apex, pressed to rest, or let bounce."""

LEAD = 0.1
"""Default duration (s) of the approach, the throw from rest onto the first note."""

MIN_GAP = 1e-3
"""Closest two notes of one stick may be (s)."""

TIME_TOLERANCE = 1e-4
"""Largest |impact time − note time| (s) a design is allowed; designs reach about 1e-9."""

LEVEL_TOLERANCE = 0.5
"""Largest |impact level − note level| (dB) a design is allowed; designs reach about 1e-6."""

DRIFT = (1e-6, 1e-3)
"""s and dB: a design whose simulated impacts drift this far from its notes is refused at the note where they do.

A chain of bounces is open-loop: its forces are fixed in time, so an error of one impact changes
the next flight. Most chains shrink such errors; some (long and short flights in turns) enlarge
them from round-off. The planner then starts a new stroke at the chain's longest flight."""

_RAMP = 1e-9
"""Half the time (s) a force step takes in the written profile."""

HIGHEST = 1.25
"""The highest a designed stroke takes the stick (rad, about 72°; a drummer's full stroke, tip 30 cm above the
head, is about 1 rad): lower if the joint's ``theta_high`` is lower. Near the vertical the stick balances."""

_SWITCH = 0.05
"""Where a force changes next to an impact: this fraction of the flight's height above the head."""

_SETTLE_ROUNDS = 30
"""Most rounds of solving each flight with its neighbours' forces (they settle in a handful)."""


@dataclass(frozen=True)
class Start:
    """The stick's state where a design starts.

    Parameters
    ----------
    t : float
        s, on the notes' timeline; before the first note.
    theta : float in [theta_max, pi/2)
        rad. Above the head at rest (``omega = 0``): the stick is held there and released when
        the approach must begin.
    omega : float
        rad/s. Rising (> 0): the first flight rises to an apex and falls onto the first note.
        Falling (< 0): one force brings it down; its arrival time is then fixed.
    """

    t: float
    theta: float
    omega: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "t", check_real("start.t", self.t, low=-1e6, high=1e6, unit="s"))
        object.__setattr__(self, "theta", check_real("start.theta", self.theta, low=-math.pi / 2, high=math.pi / 2,
                                                     high_open=True, unit="rad"))
        object.__setattr__(self, "omega", check_real("start.omega", self.omega, low=-1000.0, high=1000.0,
                                                     unit="rad/s"))


class Unreachable(ParameterError):
    """A note that cannot be played within the limits.

    Attributes
    ----------
    note : int
        Its index among the notes (0 first).
    nearest_time : float or None
        The nearest time (s) it can be played at, at its level (None if none).
    nearest_level : float or None
        The nearest level (dB) it can be played at, at its time (None if none).
    drift : bool
        The note is reachable, but not in the same open-loop chain as the notes before it (see :data:`DRIFT`).
    """

    def __init__(self, message, *, note, nearest_time=None, nearest_level=None, nearest=None, drift=False):
        super().__init__(message)
        self.note = note
        self.drift = drift
        self._nearest = (nearest_time, nearest_level) if nearest is None else None
        self._find = nearest  # worked out when asked for: a planner catches most of these and needs none

    @property
    def nearest_time(self):
        return self.nearest[0]

    @property
    def nearest_level(self):
        return self.nearest[1]

    @property
    def nearest(self):
        """(nearest time, nearest level)."""
        if self._nearest is None:
            self._nearest = self._find()
        return self._nearest

    def __str__(self):
        if self._find is None:
            return super().__str__()
        nearest_time, nearest_level = self.nearest
        near = []
        if nearest_time is not None:
            near.append(f"t = {nearest_time:.6g} s at its level")
        if nearest_level is not None:
            near.append(f"{nearest_level:.2f} dB at its time")
        return super().__str__() + (f"; nearest reachable: {' or '.join(near)}" if near
                                    else "; nothing near it is reachable")


class Piece(NamedTuple):
    """One constant force of a design (a named tuple: a design makes several, and a frozen dataclass costs more to
    make than the force to work out).

    Attributes
    ----------
    start, end : float
        s, on the recipe's clock (0 at the release).
    force : float
        a (m/s²).
    phase : str
        ``"approach"``, ``"rise"`` (after note ``note`` to the apex), ``"fall"`` (from the apex to note
        ``note + 1``) or ``"end"``.
    note : int
        The note the piece leaves from (−1 for the approach).
    """

    start: float
    end: float
    force: float
    phase: str
    note: int


@dataclass(frozen=True, repr=False)
class Design:
    """A designed stroke: the recipe that plays the notes, placed on the notes' timeline, and its check.

    Attributes
    ----------
    recipe : Recipe
        Its t = 0 is the release, at ``release`` on the notes' timeline.
    release : float
        s: when the stroke starts (the stick leaves the start state or the height it was held at).
    times, levels : ndarray [shape=(n,)]
        The notes: s and dB re 1 m/s tip speed.
    end : str
        One of :data:`ENDS`.
    pieces : tuple of Piece
    stroke : Stroke
        The recipe simulated by the solver (checked against the notes).
    hold : float
        s the stick was held still at the start before the release (0 without a resting start).
    """

    recipe: object
    release: float
    times: np.ndarray
    levels: np.ndarray
    end: str
    pieces: tuple
    stroke: object
    hold: float = 0.0
    _errors: tuple = field(default=(0.0, 0.0), compare=False)
    _heard: tuple | None = field(default=None, compare=False)

    def __repr__(self):
        return (f"Design({len(self.times)} notes {self.times[0]:.6g}-{self.times[-1]:.6g} s, model={self.model!r}, "
                f"end={self.end!r}, forces {self.min_force:.4g}-{self.max_force:.4g} m/s^2)")

    @property
    def model(self):
        """The model that made the stroke."""
        return self.recipe.model

    @property
    def impacts(self):
        """Every impact of the stroke on the notes' timeline (the notes first, then what the end makes)."""
        impacts = self.stroke.impacts
        return Impacts(impacts.t + self.release, impacts.omega, impacts.tip_distance)

    @property
    def heard(self):
        """The impacts on the notes: (t s, level dB) each, as floats (the check's own, kept: a live note logs them)."""
        if self._heard is None:
            impacts, n = self.impacts, len(self.times)
            return tuple(zip(impacts.t[:n].tolist(), impacts.level_db[:n].tolist()))
        return self._heard

    @property
    def t_end(self):
        """s, on the notes' timeline: where the stroke ends (the catch's apex, or its rest)."""
        return float(self.release + self.recipe.t_end)

    @property
    def max_force(self):
        """The strongest a(t) the design uses (m/s²)."""
        return max(piece.force for piece in self.pieces)

    @property
    def min_force(self):
        """The weakest a(t) the design uses (m/s²)."""
        return min(piece.force for piece in self.pieces)

    @property
    def beyond_human(self):
        """Whether the design needs a thumb outside the human range, 0–:data:`HUMAN_FORCE` m/s²."""
        return self.max_force > HUMAN_FORCE or self.min_force < 0.0

    @property
    def time_error(self):
        """Largest |impact time − note time| of the forward simulation (s)."""
        return self._errors[0]

    @property
    def level_error(self):
        """Largest |impact level − note level| of the forward simulation (dB)."""
        return self._errors[1]

    @property
    def ends(self):
        """The stick's state at the release and at ``t_end``: ((θ rad, ω rad/s), (θ rad, ω rad/s)), as floats.

        Evaluated once, in one call of the solver's arcs: the planner asks where each stroke ends (the
        next is thrown from there), and the moves that join the strokes start and end at these states.
        (Kept in the design's ``__dict__`` by hand: functools' cached property takes a lock at each first use.)
        """
        ends = self.__dict__.get("_ends")
        if ends is None:
            theta, omega = self.stroke.arcs.evaluate(np.array([0.0, self.recipe.t_end]))
            ends = self.__dict__["_ends"] = (float(theta[0]), float(omega[0])), (float(theta[1]), float(omega[1]))
        return ends

    def state(self, t):
        """θ (rad) and ω (rad/s) at times ``t`` (s, notes' timeline) within [release, t_end], exact."""
        local = np.asarray(t, dtype=float) - self.release
        # t_end itself may land a rounding past the recipe's end on the recipe's clock
        return self.stroke.state(np.where(np.abs(local - self.recipe.t_end) < 1e-12, self.recipe.t_end, local))


def design(times, levels=None, *, velocities=None, start=None, end="catch", setup=None, lead=LEAD, tail=None,
           catch_at=None, highest=HIGHEST, drift=DRIFT):
    """Design the stroke that plays ``times`` at ``levels`` on one stick, and check it by simulating it.

    Parameters
    ----------
    times : array_like [shape=(n,)]
        s; strictly increasing, at least :data:`MIN_GAP` apart, n ≥ 1.
    levels : array_like [shape=(n,)], optional
        dB re 1 m/s tip speed, within the MIDI map [:data:`~drumstroke.dynamics.FLOOR_DB`,
        :data:`~drumstroke.dynamics.CEILING_DB`] (−35.96 to 12.04 dB). Give these or ``velocities``.
    velocities : array_like [shape=(n,)], optional
        MIDI velocities 1–127, through :func:`drumstroke.dynamics.velocity_to_level`.
    start : Start, optional
        The stick's state before the first note. Default: held at rest at the height from
        which a throw of ``lead`` s plays the first note (lower if that needs more force
        than ``forces.high``, higher if less than ``forces.low``).
    end : {"catch", "press", "bounce"}
        What follows the last note (see :data:`ENDS`).
    setup : Setup, optional
        The model, c, the stick, the thumb accelerations allowed (m/s²) and the joint's range
        (the stick's highest angle), speed and acceleration (default ``Setup()``: the paper's
        model and stick, c = 0.86, 0 to :data:`FORCE_LIMIT` m/s², ``Limits()``).
    lead : float in (0, 10]
        s, the approach's duration when no ``start`` is given.
    tail : float in (0, 60], optional
        s after the last note for ``end="bounce"`` (default: until the stick rests).
    catch_at : float, optional
        rad: for ``end="catch"``, the height to catch the last rebound at (the force after the
        last note follows from it). Default: the grip of the stroke's last rise.
    highest : float in (theta_max, pi/2)
        rad, the highest the design may take the stick (default :data:`HIGHEST`; lower if the
        joint's ``limits.theta_high`` is).
    drift : (float, float)
        s and dB: how far the simulated impacts may drift from the notes before the design is refused
        (default :data:`DRIFT`; a fit to a recording, which measures its own errors, allows more).

    Returns
    -------
    Design

    Raises
    ------
    Unreachable
        A note cannot be played within the limits; it names the note, the need, the limit and
        the nearest reachable time and level.
    """
    if drift is not DRIFT and (not isinstance(drift, (tuple, list)) or len(drift) != 2):
        raise ParameterError(f"drift must be (seconds, dB), two numbers > 0, got {shown(drift)}")
    drift = DRIFT if drift is DRIFT else tuple(check_real(f"drift[{i}]", x, low=0.0, low_open=True, unit=unit)
                  for i, (x, unit) in enumerate(zip(drift, ("s", "dB"))))
    plan = _Plan.of(times, levels, velocities, start=start, end=end, setup=setup, lead=lead, tail=tail,
                    catch_at=catch_at, highest=highest)
    return plan.build(drift)


def design_pieces(times, levels, *, start=None, end="catch", setup=None, lead=LEAD, highest=HIGHEST):
    """The constant forces of :func:`design`'s stroke for these notes, without simulating it.

    What a search over many candidate notes needs (a fit tries levels and c until the forces are the
    simplest): the same pieces :func:`design` builds, a thousand times cheaper than checking each by
    the solver. The design finally chosen is then made, and checked, by :func:`design`.

    Parameters are :func:`design`'s (levels in dB re 1 m/s).

    Returns
    -------
    pieces : tuple of Piece
        On the recipe's clock (0 at the release).
    release : float
        s, on the notes' timeline.

    Raises
    ------
    Unreachable
        As :func:`design`.
    """
    plan = _Plan.of(times, levels, None, start=start, end=end, setup=setup, lead=lead, tail=None, highest=highest)
    pieces, release, _, _ = plan.pieces()
    return tuple(pieces), release


def standard_throw(time, level, *, setup=None, lead=LEAD):
    """Where :func:`design` without a start throws the stick from onto a note, without simulating it.

    Parameters
    ----------
    time : float
        s, the note's time.
    level : float
        dB re 1 m/s tip speed.
    setup : Setup, optional
    lead : float in (0, 10]
        s, the throw's duration (shorter when it needs more force than the setup's range).

    Returns
    -------
    release : float
        s: when the stick leaves its rest.
    theta : float
        rad: the height it rests at before the release.

    Raises
    ------
    Unreachable
        As :func:`design` for its first note.
    """
    setup = Setup() if setup is None else setup
    if not isinstance(setup, Setup):
        raise ParameterError(f"setup must be a drumstroke.design.Setup, got {setup!r}")
    time = check_real("time", time, low=-1e6, high=1e6, unit="s")
    level = check_real("level", level, low=FLOOR_DB - 1e-9, high=CEILING_DB + 1e-9, unit="dB")  # as design's
    speed = 10.0 ** (level / 20.0) * LEVEL_REFERENCE / setup.stick.pivot_to_tip
    if speed > setup.limits.max_speed:  # the full checks say why
        _Plan.of([time], [level], None, start=None, end="catch", setup=setup, lead=lead, tail=None)
    return _standard_throw(setup, time, level, lead)


def _standard_throw(setup, time, level, lead):
    """:func:`standard_throw` of a time (s) and level (dB) it has checked: a planner tries several leads for one note."""
    duration, theta = _throw(setup, float(lead), level)
    return time - duration, theta


@functools.lru_cache(maxsize=1024)
def _throw(setup, lead, level):
    """The throw's duration (s) and its rest height (rad) onto a note at ``level`` (dB).

    Cached: a planner asks for the same throws again and again (the live performer at each lead it
    tries, for notes at one of 127 velocities).
    """
    speed = 10.0 ** (level / 20.0) * LEVEL_REFERENCE / setup.stick.pivot_to_tip
    plan = _throw_plan(setup, lead)
    _, height = plan.throw(speed)
    return height_time(height, plan.head) / speed, math.asin(height)


@functools.lru_cache(maxsize=64)
def _throw_plan(setup, lead):
    """The plan of a throw of ``lead`` s: a planner asks for many throws of one setup, its plan checked once."""
    return _Plan.of([0.0], [0.0], None, start=None, end="catch", setup=setup, lead=lead, tail=None)


@functools.lru_cache(maxsize=64)
def _base_recipe(setup):
    """The recipe every design with ``setup`` is made from: made once, its coefficients worked out once."""
    return Recipe(force=Constant(0.0), model=setup.model, cor=setup.cor, stick=setup.stick)


@functools.lru_cache(maxsize=64)
def _bounds(setup, highest):
    """sin θ at the head and at the highest a design may go, and the force range's torque rates (s⁻²).

    Asked for at every flight and check of every design: worked out once per setup.
    """
    recipe = _base_recipe(setup)
    rate = recipe.coefficients.torque_rate
    return (math.sin(recipe.theta_max), math.sin(min(setup.limits.theta_high, highest)),
            (rate(STANDARD_GRAVITY, setup.forces.low), rate(STANDARD_GRAVITY, setup.forces.high)))


@dataclass
class _Plan:
    """What a design is worked out from, in the solver's units (sin θ, rad/s, torque rates C)."""

    times: np.ndarray
    levels: np.ndarray
    speeds: np.ndarray
    start: Start | None
    end: str
    setup: Setup
    recipe: Recipe
    forces: ForceRange
    limits: Limits
    lead: float
    tail: float | None
    catch_at: float | None = None
    highest: float = HIGHEST

    @classmethod
    def of(cls, times, levels, velocities, *, start, end, setup, lead, tail, catch_at=None, highest=HIGHEST):
        setup = Setup() if setup is None else setup
        if not isinstance(setup, Setup):
            raise ParameterError(f"setup must be a drumstroke.design.Setup, got {setup!r}")
        check_choice("end", end, ENDS)
        stick, forces, limits = setup.stick, setup.forces, setup.limits
        if start is not None and not isinstance(start, Start):
            raise ParameterError(f"start must be a drumstroke.design.Start or None, got {start!r}")
        lead = check_real("lead", lead, low=0.0, high=10.0, low_open=True, unit="s")
        if tail is not None:
            tail = check_real("tail", tail, low=0.0, high=60.0, low_open=True, unit="s")
        times, levels = check_notes(times, levels, velocities)
        _check_placed(start, times, stick)
        speeds = 10.0 ** (levels / 20.0) * LEVEL_REFERENCE / stick.pivot_to_tip
        if max(speeds.tolist()) > limits.max_speed:
            i = int(np.argmax(speeds > limits.max_speed))
            loudest = 20.0 * math.log10(limits.max_speed * stick.pivot_to_tip / LEVEL_REFERENCE)
            raise Unreachable(f"note {i} ({levels[i]:.2f} dB) needs the stick at {speeds[i]:.4g} rad/s, over the "
                              f"joint's max_speed {limits.max_speed:g} rad/s; the loudest reachable is {loudest:.2f} dB",
                              note=i, nearest_level=loudest)
        recipe = _base_recipe(setup)
        highest = check_real("highest", highest, low=stick.theta_max, high=math.pi / 2, low_open=True,
                             high_open=True, unit="rad")
        if catch_at is not None:
            if end != "catch":
                raise ParameterError(f"catch_at is for end='catch', got end={end!r}")
            catch_at = check_real("catch_at", catch_at, low=stick.theta_max, high=min(limits.theta_high, highest),
                                  low_open=True, unit="rad")
        return cls(times, levels, speeds, start, end, setup, recipe, forces, limits, lead, tail, catch_at, highest)

    def moved(self, start, lead):
        """This plan's notes (checked) from another ``start`` and ``lead``, only those checked: :func:`next_stroke`
        tries several starts for the same notes."""
        if start is not None and not isinstance(start, Start):
            raise ParameterError(f"start must be a drumstroke.design.Start or None, got {start!r}")
        lead = check_real("lead", lead, low=0.0, high=10.0, low_open=True, unit="s")
        _check_placed(start, self.times, self.setup.stick)
        return _Plan(self.times, self.levels, self.speeds, start, self.end, self.setup, self.recipe, self.forces,
                     self.limits, lead, self.tail, self.catch_at, self.highest)

    # The model in torque rates: C = (k·g + k′·a)/D presses the stick toward the head.
    def rate_of(self, force):
        return self.coefficients.torque_rate(STANDARD_GRAVITY, force)

    def force_of(self, rate):
        co = self.coefficients
        return (rate * co.inertia_ratio - co.k * STANDARD_GRAVITY) / co.k_thumb

    def __post_init__(self):
        # sin θ at the head and the top, the force range's torque rates (s⁻²): a plan's fields are not changed
        self.head, self.top, self.rates = _bounds(self.setup, self.highest)
        self.coefficients = self.recipe.coefficients
        # the notes' times (s) and speeds (rad/s) as Python floats: a design's arithmetic on a few notes costs several
        # times as much on numpy's scalars (the same operations on the same doubles)
        self.note_times, self.note_speeds = self.times.tolist(), self.speeds.tolist()

    def build(self, drift):
        pieces, release, hold, theta0 = self.pieces()
        base = self.recipe
        recipe = base._varied(_profile(pieces), pieces[-1].end, theta0,
                              self.start.omega if self.start is not None else 0.0, "designed")
        stroke = simulate(recipe)
        errors, heard = self.check(stroke, release, drift)
        return Design(recipe, release, self.times, self.levels, self.end, tuple(pieces), stroke, hold, errors, heard)

    def pieces(self):
        """The constant-force pieces on the recipe's clock, the release (notes' timeline), the hold (s) and θ₀."""
        if len(self.note_times) == 1 and self.end == "catch" and (self.start is None or self.start.omega == 0.0):
            thrown = self.one_note()
            if thrown is not None:
                return thrown
        return self.pieces_in_python()

    def one_note(self):
        """:meth:`pieces` of one note thrown from rest and caught, in one compiled call (:mod:`.throw`); None where it
        refuses them (the Python path says why)."""
        start, co, (low, high) = self.start, self.coefficients, self.rates
        held = start is not None
        duration, force, release, height, t_last, end, caught = one_note(
            self.note_speeds[0], self.note_times[0], held, math.sin(start.theta) if held else 0.0,
            start.t if held else 0.0, math.nan if self.catch_at is None else math.sin(self.catch_at), self.lead,
            self.recipe.cor, self.head, self.top, low, high, co.k, STANDARD_GRAVITY, co.k_thumb, co.inertia_ratio)
        if math.isnan(duration):
            return None
        pieces = [Piece(0.0, duration, force, "approach", -1), Piece(t_last, end, caught, "end", 0)]
        if held:
            return pieces, release, max(release - start.t, 0.0), start.theta
        return pieces, release, 0.0, math.asin(height)

    def pieces_in_python(self):
        """:meth:`pieces` step by step: any notes, starts and ends, and the refusals that say why."""
        pieces, release, hold, theta0 = self.approach()
        times = [t - release for t in self.note_times]
        for i, flight in enumerate(self.flights()):
            t = times[i]
            if flight.first is not None:
                pieces.append(Piece(t, t + flight.t_rise, self.force_of(flight.first), "rise", i))
            pieces.append(Piece(t + flight.t_rise, t + flight.t_apex, self.force_of(flight.rise), "rise", i))
            pieces.append(Piece(t + flight.t_apex, t + flight.t_last, self.force_of(flight.fall), "fall", i))
            if flight.last is not None:
                pieces.append(Piece(t + flight.t_last, times[i + 1], self.force_of(flight.last), "fall", i))
        pieces.append(self.ending(self.recipe.cor * self.note_speeds[-1], times[-1], pieces))
        return pieces, release, hold, theta0

    def flights(self):
        """The flights between the notes, with no change of force at any impact between two of them.

        A force that changes at an impact would make the chain unstable: an impact a little early or
        late meets the other force for that little time, and the error grows from bounce to bounce
        (about twice per bounce in a buzz). So the change is moved a little off the impact, to the
        side where it steadies the chain instead: a weaker force takes over just before the impact
        (a late stick then arrives slower and its next flight is shorter), a stronger one just after
        it. The flights are solved first as if the force changed at the impacts, to know which side
        each change goes to, then again with those short parts, each flight with its neighbours'
        forces, until the forces settle.
        """
        n = len(self.times)
        if n < 2:
            return []
        settled = settled_flights(self.times, self.speeds, cor=self.recipe.cor, sh=self.head, top=self.top,
                                  rates=self.rates, theta_max=self.recipe.theta_max,
                                  max_acceleration=self.limits.max_acceleration, switch=_SWITCH,
                                  rounds=_SETTLE_ROUNDS)
        # a flight fails (or needs a quadrature): the same rounds one flight at a time, which say where and why
        return settled if settled is not None else self.flights_one_by_one()

    def flights_one_by_one(self):
        """:meth:`flights` in Python, each flight checked as it is solved: raises :class:`Unreachable` at the first
        that fails."""
        n = len(self.times)
        plain = [self.bounce(i) for i in range(n - 1)]
        # each change happens in the flight it is part of, near its end or its start
        heights = [self.head + _SWITCH * (flight.apex - self.head) for flight in plain]
        # at impact i (between flight i − 1 and flight i): the weaker force takes over before it, a stronger after
        before = [False] + [plain[i].rise < plain[i - 1].fall for i in range(1, n - 1)]
        flights = plain
        for _ in range(_SETTLE_ROUNDS):
            settled = []
            for i in range(n - 1):
                first = (flights[i - 1].fall, heights[i]) if i > 0 and not before[i] else None
                last = (flights[i + 1].rise, heights[i]) if i + 1 < n - 1 and before[i + 1] else None
                settled.append(self.bounce(i, first=first, last=last))
            change = max(abs(a.fall - b.fall) + abs(a.rise - b.rise) for a, b in zip(settled, flights))
            flights = settled
            if change <= 1e-13 * max(flight.fall for flight in flights):
                break
        return flights

    def approach(self):
        """The pieces down to the first note, the release time, the hold and the start angle."""
        v, t1, head = self.note_speeds[0], self.note_times[0], self.head
        start = self.start
        if start is None:
            rate, height = self.throw(v)
            duration = height_time(height, head) / v
            return [Piece(0.0, duration, self.force_of(rate), "approach", -1)], t1 - duration, 0.0, math.asin(height)
        s0 = math.sin(start.theta)
        if start.omega == 0.0:
            thrown = self.held_throw()
            if isinstance(thrown, Unreachable):
                raise thrown
            rate, duration, release = thrown
            return ([Piece(0.0, duration, self.force_of(rate), "approach", -1)], release, max(release - start.t, 0.0),
                    start.theta)
        duration = t1 - start.t
        if start.omega < 0.0:
            return [self.falling_start(s0, v, duration)], start.t, 0.0, start.theta
        apex = solve_apex(duration, u=start.omega, v=v, s0=s0, sh=head, top=self.top)
        if apex is None:
            raise Unreachable(f"note 0 (t = {t1:.6g} s) cannot be reached from the rising start in {duration:.6g} s "
                              "below the joint's highest angle", note=0)
        rise_rate, fall_rate = force_to_reach(start.omega, apex - s0), force_to_reach(v, apex - head)
        self.check_rate(0, rise_rate, "the rise from the start")
        self.check_rate(0, fall_rate, "the fall onto it")
        rise = height_time(apex, s0) / start.omega
        return ([Piece(0.0, rise, self.force_of(rise_rate), "approach", -1),
                 Piece(rise, duration, self.force_of(fall_rate), "approach", -1)], start.t, 0.0, start.theta)

    def held_throw(self, *, why=True):
        """The throw from a start held at rest: (torque rate s⁻², duration s, release s), or the :class:`Unreachable`
        that refuses it, returned, not raised (:func:`next_stroke` tries this start first, and most are refused);
        with ``why`` False, None instead (the caller asks again if it must say why: most never do)."""
        v, t1, head, start = self.note_speeds[0], self.note_times[0], self.head, self.start
        s0 = math.sin(start.theta)
        if s0 <= head:
            return Unreachable("note 0: the start is at rest on the head; the stick must be lifted first (a move)",
                               note=0) if why else None
        rate = force_to_reach(v, s0 - head)
        if not self.within(rate):
            return self.rate_refusal(0, rate, "the throw from the start") if why else None
        duration = height_time(s0, head) / v
        release = t1 - duration
        if release < start.t - 1e-9:  # a throw planned to fit exactly may land a rounding early
            if not why:
                return None
            return Unreachable(f"note 0 (t = {t1:.6g} s) needs a throw of {duration:.6g} s from the start at "
                               f"{start.theta:.4g} rad, but only {t1 - start.t:.6g} s are left; nearest reachable "
                               f"time {start.t + duration:.6g} s", note=0, nearest_time=start.t + duration)
        return rate, duration, release

    def falling_start(self, s0, v, duration):
        from ..solver.elliptic import parameter, to_head

        start, head = self.start, self.head
        if s0 <= head or v * v <= start.omega**2:
            raise Unreachable(f"note 0 needs {v:.4g} rad/s at the head, but the stick already falls at "
                              f"{-start.omega:.4g} rad/s from {start.theta:.4g} rad", note=0)
        rate = (v * v - start.omega**2) / (2.0 * (s0 - head))
        self.check_rate(0, rate, "the fall from the start")
        to_apex, apex_to_head, _ = to_head(s0, start.omega, rate, parameter(s0, start.omega, rate), head)
        arrival = to_apex + apex_to_head
        if abs(arrival - duration) > TIME_TOLERANCE / 10:
            raise Unreachable(f"note 0 (t = {self.times[0]:.6g} s): falling from the start, the stick reaches the "
                              f"head at {start.t + arrival:.6g} s at that level", note=0,
                              nearest_time=start.t + arrival)
        return Piece(0.0, duration, self.force_of(rate), "approach", -1)

    def throw(self, v):
        """The torque rate and rest height (sin θ) of the default approach onto a note at speed ``v``."""
        head, top = self.head, self.top
        low, high = self.rates
        height = apex_for_fall(self.lead, v=v, sh=head, top=top)
        rate = force_to_reach(v, (top if height is None else height) - head)
        if rate > high:
            rate = high
        elif rate < low:
            rate = low
        if rate <= 0.0 or head + force_to_reach(v, rate) > top + 1e-12:
            raise Unreachable(f"note 0 ({self.level_of(v):.2f} dB) needs more than the strongest force "
                              f"{self.forces.high:g} m/s^2 from the joint's highest angle", note=0,
                              nearest_level=self.level_of(math.sqrt(2.0 * high * (top - head))) if high > 0 else None)
        return rate, head + force_to_reach(v, rate)

    def bounce(self, i, *, first=None, last=None):
        """The flight from note ``i`` to note ``i + 1`` (see :func:`~drumstroke.design.flight.solve_flight`)."""
        u, v = self.recipe.cor * self.note_speeds[i], self.note_speeds[i + 1]
        flight = solve_flight(self.note_times[i + 1] - self.note_times[i], u=u, v=v, sh=self.head, top=self.top, first=first,
                              last=last)
        if flight is None:
            self.unreachable(i + 1, u, "the bounce would rise above the joint's highest angle")
        for rate, what in ((flight.rise, "on the way up"), (flight.fall, "on the way down")):
            if not self.within(rate):
                limit = self.forces.high if rate > self.rate_of(self.forces.high) else self.forces.low
                self.unreachable(i + 1, u, f"the flight from note {i} needs a = {self.force_of(rate):.5g} m/s^2 "
                                           f"{what}, beyond the force limit {limit:g} m/s^2")
        self.check_acceleration(i + 1, max(flight.rise, flight.fall), flight.apex)
        return flight

    def ending(self, u, t_last, pieces):
        """The last piece: after the last note, to the catch, the rest or the end of the free bounce.

        A catch keeps the grip of the stroke's last rise (or of its throw), so a single note's rebound
        mirrors its throw; only if that would carry the stick above the joint's range is it held harder.
        """
        head, top, last = self.head, self.top, len(self.times) - 1
        low, high = self.rates
        if self.end == "catch" and self.catch_at is not None:
            apex = math.sin(self.catch_at)
            rate = force_to_reach(u, apex - head) if apex > head else math.inf
            self.check_rate(last, rate, f"the catch at {self.catch_at:.4g} rad")
            return Piece(t_last, t_last + height_time(apex, head) / u, self.force_of(rate), "end", last)
        if self.end == "catch":
            grip = self.rate_of(next(piece.force for piece in reversed(pieces) if piece.phase != "fall"))
            rate = max(grip, force_to_reach(u, top - head), 1e-12)
            apex = head + force_to_reach(u, rate)
            return Piece(t_last, t_last + height_time(apex, head) / u, self.force_of(rate), "end", last)
        rate = high if self.end == "press" else max(low, self.rate_of(0.0))
        if rate <= 0.0:
            raise ParameterError(f"end {self.end!r} needs a force that presses the stick down; forces.high = "
                                 f"{self.forces.high:g} m/s^2 does not")
        if self.end == "bounce" and self.tail is not None:
            duration = self.tail
        else:
            if head + force_to_reach(u, rate) >= top:
                raise Unreachable(f"after the last note the stick would rise above the joint's highest angle under "
                                  f"a = {self.force_of(rate):.5g} m/s^2", note=last)
            duration = _accumulation(u, rate, head, self.recipe.cor) + 1e-3
        return Piece(t_last, t_last + duration, self.force_of(rate), "end", last)

    def within(self, rate):
        """Whether the torque rate is within the force range (to round-off: designs land on its ends exactly)."""
        low, high = self.rates
        slack = 1e-9 * max(abs(low), abs(high))
        return low - slack <= rate <= high + slack

    def check_rate(self, note, rate, what):
        if not self.within(rate):
            raise self.rate_refusal(note, rate, what)

    def rate_refusal(self, note, rate, what):
        """The :class:`Unreachable` of a torque rate out of the force range."""
        limit = self.forces.high if rate > self.rate_of(self.forces.high) else self.forces.low
        return Unreachable(f"note {note} ({self.times[note]:.6g} s, {self.levels[note]:.2f} dB): {what} needs "
                           f"a = {self.force_of(rate):.5g} m/s^2, beyond the force limit {limit:g} m/s^2", note=note)

    def check_acceleration(self, note, rate, apex):
        # |dω/dt| = C·cos θ, largest where θ is nearest 0 along the flight
        lowest_cos = max(math.cos(self.recipe.theta_max), math.sqrt(max(0.0, 1.0 - apex * apex)))
        peak = rate * (1.0 if apex >= 0.0 else lowest_cos)
        if peak > self.limits.max_acceleration:
            raise Unreachable(f"note {note}: its flight accelerates the stick at {peak:.5g} rad/s^2, over the "
                              f"joint's max_acceleration {self.limits.max_acceleration:g} rad/s^2", note=note)

    def unreachable(self, note, u, reason):
        raise Unreachable(f"note {note} (t = {self.times[note]:.6g} s, {self.levels[note]:.2f} dB): {reason}",
                          note=note, nearest=lambda: self.nearest(note, u))

    def nearest(self, note, u):
        """The nearest time at the note's level, and the nearest level at its time, of the flight into ``note``."""
        head, top = self.head, self.top
        low = max(self.rate_of(self.forces.low), 1e-12)
        high = self.rate_of(self.forces.high)
        if high <= 0.0:
            return None, None
        # apexes the rise allows: C_up = u²/(2(a − head)) within [low, high]
        a_low, a_high = head + force_to_reach(u, high), min(top, head + force_to_reach(u, low))
        previous = self.times[note - 1]

        def feasible(v):  # apexes where the fall onto the note at v is within the forces too
            lo, hi = max(a_low, head + force_to_reach(v, high)), min(a_high, head + force_to_reach(v, low))
            return (lo, hi) if lo <= hi else None

        nearest_time = None
        window = feasible(self.speeds[note])
        if window is not None:
            spans = [previous + flight_time(a, u=u, v=self.speeds[note], s0=head, sh=head) for a in window]
            nearest_time = float(np.clip(self.times[note], *spans))
        levels = np.linspace(FLOOR_DB, CEILING_DB, 97)  # half-dB steps
        reachable = []
        for level in levels:
            v = 10.0 ** (level / 20.0) * LEVEL_REFERENCE / self.recipe.stick.pivot_to_tip
            window = feasible(v)
            if window is not None:
                spans = [previous + flight_time(a, u=u, v=v, s0=head, sh=head) for a in window]
                if spans[0] <= self.times[note] <= spans[1]:
                    reachable.append(level)
        nearest_level = min(reachable, key=lambda x: abs(x - self.levels[note])) if reachable else None
        return nearest_time, nearest_level

    def level_of(self, speed):
        return 20.0 * math.log10(speed * self.recipe.stick.pivot_to_tip / LEVEL_REFERENCE)

    def check(self, stroke, release, drift):
        """Hold the simulated stroke to the notes; return its largest time and level errors, and its impacts on the
        notes ((t s, level dB) each: :attr:`Design.heard`)."""
        n = len(self.times)
        impacts = stroke.impacts
        if len(impacts) < n:
            raise SimulationError(f"the designed stroke made {len(impacts)} impacts for {n} notes (a bug: please "
                                  "report it with the notes)")
        # in plain Python but the logarithm, numpy's as before (numpy's calls on a note or two cost more than the
        # arithmetic): Impacts.level_db of the notes' impacts, without its error state (a listed impact's ω is never 0)
        heard_t = [t + release for t in impacts.t[:n].tolist()]
        tip = impacts.tip_distance
        heard_levels = [20.0 * x for x in np.log10([abs(w) * tip / LEVEL_REFERENCE
                                                    for w in impacts.omega[:n].tolist()]).tolist()]
        # the errors of a few notes in plain Python (numpy's calls cost more than the arithmetic)
        time_errors = [abs(t - note) for t, note in zip(heard_t, self.note_times)]
        level_errors = [abs(level - note) for level, note in zip(heard_levels, self.levels.tolist())]
        worst = max(time_errors), max(level_errors)
        if worst[0] > drift[0] or worst[1] > drift[1]:
            k = next(k for k in range(n) if time_errors[k] > drift[0] or level_errors[k] > drift[1])
            raise Unreachable(f"note {k} (t = {self.times[k]:.6g} s): the bounces before it drift, {time_errors[k]:.3g} s "
                              f"and {level_errors[k]:.3g} dB off by the solver (a long chain of flights that enlarges "
                              "small errors); play it as a new stroke", note=k, drift=True)
        return worst, tuple(zip(heard_t, heard_levels))


def flights_within(times, levels, *, setup=None):
    """For each pair of consecutive notes, whether one flight within the limits plays the second after the first.

    The quick test the planner uses to chain notes (each flight solved once, as if the force changed
    at the impacts; the design itself then settles the forces, rarely breaking a chain further).

    Returns
    -------
    list of bool [len(times) − 1]
    """
    plan = _Plan.of(times, levels, None, start=None, end="catch", setup=setup, lead=LEAD, tail=None)
    return possible_flights(plan.times, plan.speeds, cor=plan.recipe.cor, sh=plan.head, top=plan.top, rates=plan.rates,
                            theta_max=plan.recipe.theta_max, max_acceleration=plan.limits.max_acceleration)


def catch_height(last, following, gap, *, setup=None, lead=LEAD):
    """Where to catch a stroke after its last note so that the next stroke is thrown from there, or None.

    The stick leaves the head at c times the last note's speed, is caught at rest at the height
    returned, held, and thrown from there onto the next note ``gap`` s later: both forces (the
    catch's and the throw's) within ``forces``, the rise and the throw within the gap. Of the
    heights that do, the one nearest the next note's standard throw (``lead`` s) is chosen. When
    none does (a tap after an accent: from any height the accent's rebound reaches, the tap would
    need the thumb to pull), the lowest catch, the quickest: the stick is then moved to the next
    throw's height.

    Parameters
    ----------
    last, following : float
        dB, the levels of the stroke's last note and of the next note.
    gap : float
        s between them.

    Returns
    -------
    float or None
        rad; None when even the strongest force cannot catch the stick below the joint's highest angle.
    """
    setup = Setup() if setup is None else setup
    try:
        return _catch_height(setup, last, following, gap, lead)
    except TypeError:  # an argument that cannot be a cache's key: checked (and refused) uncached
        return _catch_height.__wrapped__(setup, last, following, gap, lead)


@functools.lru_cache(maxsize=4096)
def _catch_height(setup, last, following, gap, lead):
    """:func:`catch_height`, cached: a planner asks for the same few levels and gaps again and again."""
    plan = _Plan.of([0.0, max(gap, 2 * MIN_GAP)], [last, following], None, start=None, end="catch", setup=setup,
                    lead=lead, tail=None)
    head, top = plan.head, plan.top
    u, v = plan.recipe.cor * plan.speeds[0], plan.speeds[1]
    low, high = plan.rate_of(plan.forces.low), plan.rate_of(plan.forces.high)
    if high <= 0.0 or u == 0.0:
        return None
    slack = 1.0 + 1e-9  # strictly inside the force range, so the designs' own checks pass
    quickest = head + u * u / (2.0 * high) * slack
    if quickest >= top:
        return None
    lowest = head + max(u, v) ** 2 / (2.0 * high) * slack
    highest = min(top, head + min(u, v) ** 2 / (2.0 * low) / slack) if low > 0.0 else top
    if lowest > highest or flight_time(lowest, u=u, v=v, s0=head, sh=head) > gap:
        return math.asin(quickest)
    in_time = solve_apex(gap - 1e-9, u=u, v=v, s0=head, sh=head, top=highest)  # a nanosecond to spare
    ceiling = highest if in_time is None else in_time
    preferred = apex_for_fall(lead, v=v, sh=head, top=top)
    height = min(max(preferred if preferred is not None else top, lowest), ceiling)
    return math.asin(height)


READY_GAP = 1.0
"""s: after a stick's last note it is caught as if the same note came again this long after (:func:`ready_height`)."""


def ready_height(level, *, setup=None, lead=LEAD):
    """Where a stick is caught after its last note: at a playing height, ready to play that note again.

    A drummer ends a part with the stick caught low over the head, not thrown up to its rebound's
    apex. The height is :func:`catch_height`'s for the same note again :data:`READY_GAP` s later:
    the height of its standard throw (``lead`` s), lower if the catch would need more than
    ``forces.high``. With the default setup it is at most 0.4625 rad (26.5°, the standard throw of
    velocity 127); a quiet note's is a few millimetres above the head.

    Parameters
    ----------
    level : float
        dB re 1 m/s tip speed, the last note's.

    Returns
    -------
    float or None
        rad; None when even the strongest force cannot catch the stick below the joint's highest angle.

    Examples
    --------
    >>> from drumstroke.dynamics import velocity_to_level
    >>> round(ready_height(velocity_to_level(127)), 4)
    0.4625
    """
    return catch_height(level, level, READY_GAP, setup=setup, lead=lead)


def check_notes(times, levels, velocities):
    """The notes' times (s) and levels (dB) as arrays, checked (see :func:`design`)."""
    times = _vector("times", times, low=-1e6, high=1e6, unit="s")
    if len(times) == 0:
        raise ParameterError("times must hold at least one note, got none")
    if (levels is None) == (velocities is None):
        raise ParameterError("give the notes' levels (dB) or their velocities (1-127), not both or neither")
    if velocities is not None:
        velocities = check_vector("velocities", velocities, low=1.0, high=127.0)
        levels = np.array([velocity_to_level(float(v)) for v in velocities])
    else:
        # the map's ends to round-off: velocity_to_level(127) lands a rounding above CEILING_DB
        levels = _vector("levels", levels, low=FLOOR_DB - 1e-9, high=CEILING_DB + 1e-9, unit="dB re 1 m/s")
    if len(levels) != len(times):
        raise ParameterError(f"levels must give one level per note: {len(times)} times, {len(levels)} levels")
    listed = times.tolist()
    for i in range(1, len(listed)):
        if listed[i] - listed[i - 1] < MIN_GAP:
            raise ParameterError(f"times must increase by at least {MIN_GAP:g} s from note to note; note {i} at "
                                 f"{listed[i]!r} s follows {listed[i - 1]!r} s")
    return times, levels


def _check_placed(start, times, stick):
    """Refuse a start (a Start or None) not before the first note or below the head."""
    if start is not None and not start.t < times[0]:
        raise ParameterError(f"start.t must be before the first note at {times[0]!r} s, got {start.t!r}")
    if start is not None and start.theta < stick.theta_max:
        raise ParameterError(f"start.theta must be at or above the head, theta_max = {stick.theta_max:.6g} rad, "
                             f"got {start.theta!r}")


def _vector(name, values, *, low, high, unit):
    """:func:`~drumstroke._checks.check_vector`'s array, its usual case (every entry in range) checked in plain Python.

    At every design: numpy's reductions cost more than the check on a few notes. An array of doubles already (a
    planner's notes) is taken as it is, as :func:`~drumstroke._checks.as_vector` would.
    """
    is_doubles = type(values) is np.ndarray and values.dtype is _DOUBLE and values.ndim == 1
    vector = values if is_doubles else as_vector(name, values)
    for x in vector.tolist():  # a loop, not a generator: at every design
        if not low <= x <= high:  # NaN fails every comparison
            return check_vector(name, values, low=low, high=high, unit=unit)
    return vector


_DOUBLE = np.dtype(float)


def _accumulation(u, rate, head, cor):
    """When bounces launched at ``u`` (rad/s) under a constant ``rate`` come to rest (s after the first launch).

    The flights' durations, in closed form, until they are a millionth of the first; the rest of the
    series is then geometric (small flights last in proportion to their speed).
    """
    if cor == 0.0:
        return 0.0
    total, speed = 0.0, u
    while speed > 1e-6 * u:
        total += 2.0 * height_time(head + force_to_reach(speed, rate), head) / speed
        speed *= cor
    return total + 2.0 * height_time(head + force_to_reach(speed, rate), head) / speed / (1.0 - cor)


def _profile(pieces):
    """a(t) of constant pieces, each step a 2-ns ramp centred on it (a piecewise-linear profile)."""
    forces = [piece.force for piece in pieces]
    if all(force == forces[0] for force in forces):
        return Constant(forces[0])
    times, values = [0.0], [forces[0]]
    for before, after in itertools.pairwise(pieces):
        if after.force != before.force:
            times += (after.start - _RAMP, after.start + _RAMP)
            values += (before.force, after.force)
    return PiecewiseLinear._of(times, values)
