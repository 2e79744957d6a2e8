"""The performance planner: one stick's notes become designed strokes joined by moves.

Per stick, in time order, the planner decides which notes form one bounce chain and which start
a new stroke:

- a note joins the chain of the note before it when the flight between them is within the force
  limits (:func:`~drumstroke.design.chain.design`'s flights);
- otherwise the chain ends caught at its last rebound's apex, and the next stroke starts, if it
  can, by a throw from where the stick was caught (held there until the throw), else from the
  height of a standard throw (``lead`` s, shorter ones when time is short), reached by a
  time-optimal, jerk-limited move (:func:`~drumstroke.palette.motion.plan_return`);
- a buzz note is bounces at :data:`~drumstroke.design.buzz.DENSITY` per second over its span (by
  default until the stick's next note), chained like notes: into the next note when the flight
  allows (a press roll flows into its release), caught after its last bounce otherwise.

A note that cannot be played within the limits is left out and reported with its reason and the
nearest reachable time and level (:class:`Problem`) — never dropped silently; the rest are played
exactly (times within nanoseconds, levels within 1e-6 dB).

Examples
--------
>>> plan = plan_stick([Target(0.5, -6.0), Target(0.6, -6.0), Target(1.5, 0.0)])
>>> [len(d.times) for d in plan.designs], plan.problems
([2, 1], ())
"""

import math
from dataclasses import dataclass

import numpy as np

from .._checks import check_real
from ..dynamics import velocity_to_level
from ..errors import ParameterError
from ..palette.motion import Limits, assemble, plan_return, return_time
from ..trajectory import DEFAULT_RATE
from .buzz import DENSITY, buzz_times
from .chain import (
    DRIFT,
    LEAD,
    Start,
    Unreachable,
    _Plan,
    _standard_throw,
    catch_height,
    design,
    design_pieces,
    flights_within,
    ready_height,
    standard_throw,
)
from .setup import Setup

KINDS = ("auto", "buzz")
"""What a target asks for: a note the planner designs, or a buzz over a span."""

LEADS = (LEAD, LEAD / 2, LEAD / 4, LEAD / 8)
"""The throws (s) tried, longest first, when a stroke starts from a standard height."""

LONGEST_BOUNCE = 0.2
"""s: notes further apart are played as a caught stroke and a new throw where one fits, not as one bounce.

A drummer lets the stick bounce through diddles, buzzes and fast singles, and stops and throws it
again for slower notes; long bounces in a chain also enlarge its errors (see :data:`~drumstroke.design.chain.DRIFT`)."""



@dataclass(frozen=True)
class Target:
    """One note a stick must play.

    Parameters
    ----------
    t : float
        s.
    level : float
        dB re 1 m/s tip speed (see :mod:`drumstroke.dynamics`).
    kind : {"auto", "buzz"}
    duration : float or None
        s, a buzz's span; None: until the stick's next note (or 0.25 s for the last).
    key : object
        The caller's name for the note (an index), used in :class:`Problem` and the placements.
    """

    t: float
    level: float
    kind: str = "auto"
    duration: float | None = None
    key: object = None

    def __post_init__(self):
        object.__setattr__(self, "t", check_real("target.t", self.t, low=-1e6, high=1e6, unit="s"))
        object.__setattr__(self, "level", check_real("target.level", self.level, low=-200.0, high=200.0, unit="dB"))
        if self.kind not in KINDS:
            raise ParameterError(f"target.kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        if self.duration is not None:
            object.__setattr__(self, "duration", check_real("target.duration", self.duration, low=0.0, high=3600.0,
                                                            low_open=True, unit="s"))

    @classmethod
    def from_velocity(cls, t, velocity, **options):
        """A target at MIDI ``velocity`` (1–127)."""
        return cls(t, velocity_to_level(velocity), **options)


@dataclass(frozen=True)
class Problem:
    """A note left out: its key, time, what stood in the way, and the nearest time and level reachable."""

    key: object
    t: float
    reason: str
    nearest_time: float | None = None
    nearest_level: float | None = None

    def __str__(self):
        return f"note {self.key} at {self.t:.6g} s not played: {self.reason}"


@dataclass(frozen=True, repr=False)
class StickPlan:
    """What the planner made of one stick's notes.

    Attributes
    ----------
    designs : tuple of Design
        The strokes, in time order; each plays a chain of notes.
    keys : tuple of tuple
        The keys of the notes each design plays (a buzz: its one note).
    problems : tuple of Problem
    limits : Limits
        The budget of the moves between strokes.
    """

    designs: tuple
    keys: tuple
    problems: tuple
    limits: Limits

    def __repr__(self):
        return f"StickPlan({len(self.designs)} strokes, {sum(map(len, self.keys))} notes, {len(self.problems)} problems)"

    @property
    def release(self):
        """When the first stroke starts (s), or None without strokes."""
        return self.designs[0].release if self.designs else None

    def trajectory(self, *, t_end, rate=DEFAULT_RATE, name="planned"):
        """The stick's motion on [0, ``t_end``] s: held before its first stroke, the strokes, the moves between.

        Parameters
        ----------
        t_end : float
            s, at or after the last stroke's end.
        rate : float
            Hz.
        """
        if not self.designs:
            raise ParameterError("the plan has no strokes to play")
        if self.designs[0].release < 0.0:
            raise ParameterError(f"the first stroke starts at {self.designs[0].release:.6g} s, before 0: shift the "
                                 "notes later")
        from ..trajectory import Trajectory

        pieces = [Trajectory.from_stroke(d.stroke, rate=rate, name=f"designed {len(d.times)}") for d in self.designs]
        return assemble(pieces, np.array([d.release for d in self.designs]), limits=self.limits, name=name,
                        end=max(t_end, self.designs[-1].t_end), home=False, ends=[d.ends for d in self.designs])


def plan_stick(targets, *, setup=None, gap=0.25, lead=LEAD):
    """Plan one stick's notes: chains of bounces, designed; strokes joined; the unplayable reported.

    Parameters
    ----------
    targets : sequence of Target
        In any order; times at least 1 ms apart.
    setup : Setup, optional
        The model, c, the stick, the thumb accelerations allowed (m/s²), the joint's limits the
        strokes keep and the budget of the moves between strokes (default ``Setup()``).
    gap : float
        s, the span of a buzz that is the stick's last note and gives no duration.
    lead : float in (0, 10]
        s, the throw onto the first note, from rest at its standard height (a caller whose stick must
        first get there asks for a shorter one, :data:`LEADS`).

    Returns
    -------
    StickPlan
    """
    setup = Setup() if setup is None else setup
    if not isinstance(setup, Setup):
        raise ParameterError(f"setup must be a drumstroke.design.Setup, got {setup!r}")
    for target in targets:
        if not isinstance(target, Target):
            raise ParameterError(f"targets must be drumstroke.design.Target, got {target!r}")
    targets = sorted(targets, key=lambda target: target.t)
    lead = check_real("lead", lead, low=0.0, high=10.0, low_open=True, unit="s")
    return _Planner(targets, setup, gap, lead).run()


def next_stroke(times, levels, setup, *, free, theta, omega=0.0, running=None, end="catch", catch_at=None):
    """The stroke that takes a stick from where it is to its next notes, and the moves before it.

    The one decision of the offline planner and the live performer. The stick may change its motion
    from ``free`` (s), where it is at ``theta`` (rad) moving at ``omega`` (rad/s); in this order of
    preference:

    1. from ``running``, a state of the motion still under way (an impact still to come, a
       rebound still rising), the stroke bounces on: no move, the motion goes on through the notes;
    2. a throw from where the stick rests (caught at a rebound's apex, or held), held there until it
       is released;
    3. for each lead in :data:`LEADS`, longest first, a throw from that lead's height, reached by a
       time-optimal jerk-limited move within ``setup.moves`` that fits before its release.

    Parameters
    ----------
    times, levels : array_like [shape=(n,)]
        The notes: s and dB re 1 m/s tip speed.
    setup : Setup
    free : float
        s: from when the motion may change.
    theta, omega : float
        rad and rad/s at ``free``: at rest when |omega| < 1e-6 rad/s.
    running : Start, optional
        A state from which the stroke may bounce on (at or after ``free``).
    end, catch_at
        As :func:`~drumstroke.design.chain.design`'s.

    Returns
    -------
    made : Design
    moves : list of (duration s, path)
        The moves from ``free`` to the design's release (empty when it bounces on or is thrown from
        where the stick rests: the stick is held until the release).

    Raises
    ------
    Unreachable
        The first note cannot be reached by any of them (the reason of the first that failed), or a
        later note cannot be chained (``note`` > 0: no other start helps; the chain splits there).
    """
    plan = None

    def designed(start=None, lead=LEAD, *, held=False):
        """:func:`~drumstroke.design.chain.design` of the notes from ``start`` or a throw of ``lead`` s: the notes
        checked at the first design only, the later ones only their start. A ``held`` start (at rest) whose throw
        is refused gives back its plan, which says why (the error its design would raise first) if asked, without a
        design begun."""
        nonlocal plan
        plan = (_Plan.of(times, levels, None, start=start, end=end, setup=setup, lead=lead, tail=None,
                         catch_at=catch_at) if plan is None else plan.moved(start, lead))
        if held and plan.held_throw(why=False) is None:
            return plan
        return plan.build(DRIFT)

    failure = None
    if running is not None:
        try:
            made = designed(running)
        except Unreachable as error:
            if error.note > 0:
                raise
            failure = _kept(error)
        else:
            if made.release >= running.t - 1e-9:
                return made, []
            failure = Unreachable("the stroke would start before the motion may change", note=0)
    if abs(omega) < 1e-6 and theta > setup.head + 1e-9 and free < times[0]:
        try:
            made = designed(Start(free, theta), held=True)
        except Unreachable as error:
            if error.note > 0:
                raise
            failure = failure or _kept(error)
        else:
            if not isinstance(made, _Plan):
                return made, []
            failure, made = failure or made, None  # its refusal, said if raised (most notes are thrown another way)
    first = None  # the first note's time (s) and level (dB), once standard_throw has checked them
    for lead in LEADS:
        try:  # where the throw starts, in closed form: a stroke is designed and simulated only if the move fits
            if first is None:
                release, height = standard_throw(times[0], levels[0], setup=setup, lead=lead)
                first = float(times[0]), float(levels[0])
            else:
                release, height = _standard_throw(setup, *first, lead)
            window = release - free
            if window < 0.0:  # no move needs no time: the throw would start before the stick is free
                failure = failure or Unreachable(
                    f"the stick is free at {free:.6g} s, after a throw of {times[0] - release:.4g} s onto the note at "
                    f"{times[0]:.6g} s would start", note=0)
                continue
            need = return_time((theta, omega), (height, 0.0), setup.head, setup.moves)
            if need > window:
                failure = failure or Unreachable(
                    f"the stick, free at {free:.6g} s, needs {need:.4g} s to reach the height of its next throw, but "
                    f"only {window:.4g} s are left", note=0)
                continue
            made = designed(lead=lead)
        except Unreachable as error:
            if error.note > 0:
                raise
            failure = failure or _kept(error)
            continue
        moves = plan_return((theta, omega), (float(made.recipe.theta0), 0.0), made.release - free, setup.head,
                            setup.moves)
        if moves is not None:
            return made, moves
    if isinstance(failure, _Plan):  # the held throw's refusal, said now
        failure = failure.held_throw()
    try:
        raise failure
    finally:
        failure = None  # the error's traceback holds this frame: no reference cycle through it


def _kept(error):
    """A caught error kept to be raised later, without its traceback: the traceback holds the frame that keeps
    the error, a reference cycle that only the garbage collector frees (a live note's planning pauses for it)."""
    return error.with_traceback(None)


@dataclass(frozen=True)
class _Atom:
    """One impact the planner must make: a note, or one bounce of a buzz (``bounce`` > 0)."""

    t: float
    level: float
    target: Target
    bounce: int = 0
    last: bool = False  # the last bounce of its buzz


class _Planner:
    def __init__(self, targets, setup, gap, lead):
        self.targets, self.setup, self.gap, self.lead = targets, setup, gap, lead
        self.designs, self.keys, self.problems = [], [], []

    def run(self):
        atoms = self.atoms()
        joins = flights_within([a.t for a in atoms], [a.level for a in atoms], setup=self.setup) if len(atoms) > 1 else []
        for k, join in enumerate(joins):  # a long gap is a caught stroke and a new throw, when one fits
            if join and atoms[k + 1].t - atoms[k].t > LONGEST_BOUNCE and self.catchable(atoms[k], atoms[k + 1]):
                joins[k] = False
        i = 0
        while i < len(atoms):
            j = i
            while j + 1 < len(atoms) and joins[j]:
                j += 1
            i = self.chain(atoms, i, j)
        return StickPlan(tuple(self.designs), tuple(self.keys), tuple(self.problems), self.setup.moves)

    def atoms(self):
        """The notes, each buzz spread into its bounces (at :data:`~drumstroke.design.buzz.DENSITY` per second)."""
        atoms = []
        for k, target in enumerate(self.targets):
            if target.kind == "auto":
                atoms.append(_Atom(target.t, target.level, target))
                continue
            following = self.targets[k + 1].t if k + 1 < len(self.targets) else None
            span = target.duration if target.duration is not None else (
                following - target.t if following is not None else self.gap)
            if following is not None:
                span = min(span, following - target.t)
            times = buzz_times(target.t, target.t + span, DENSITY)
            atoms += [_Atom(t, target.level, target, b, b == len(times) - 1) for b, t in enumerate(times)]
        return atoms

    def chain(self, atoms, i, j):
        """Design atoms i..j as one stroke (fewer if a flight fails); return the index of the next atom."""
        while True:
            chain = atoms[i:j + 1]
            end, catch_at = self.ending(chain[-1], atoms[j + 1] if j + 1 < len(atoms) else None)
            try:
                made = self.stroke([a.t for a in chain], [a.level for a in chain], end=end, catch_at=catch_at)
            except Unreachable as error:
                if error.drift:  # a new stroke at the chain's longest flight before the note
                    gaps = np.diff([a.t for a in chain[:error.note + 1]])
                    j = i + int(np.argmax(gaps))
                    continue
                if error.note > 0:  # the chain breaks before that note; it starts the next one
                    j = i + error.note - 1
                    continue
                self.leave_out(atoms[i].target, error)
                return self.skip(atoms, i)
            self.keep(made, [a.target.key for a in chain if a.bounce == 0])
            return j + 1

    def catchable(self, last, following):
        """Whether the stick can be caught after ``last`` where the throw onto ``following`` starts (no move)."""
        height = self.ending(last, following)[1]
        if height is None:
            return False
        try:  # its forces and its timing decide it, in closed form: the stroke itself is designed later
            design_pieces([following.t], [following.level], start=Start(last.t + 1e-9, height), setup=self.setup)
        except Unreachable:
            return False
        return True

    def ending(self, last, following):
        """How a stroke ending on atom ``last`` ends: caught, where the next throw starts if there is a next note.

        A buzz is caught too, not pressed to rest: pressing ends it in a Zeno tail of bounces a fraction of
        a millisecond apart, which no robot joint plays (the impedance controller keeps 82-90 % of a
        pressed multiple-bounce roll's onsets against 98 % of the other rudiments'); caught, it ends at
        its last bounce.
        """
        if following is None:  # the stick's last note: caught at a playing height, not thrown up to its apex
            return "catch", ready_height(last.level, setup=self.setup)
        return "catch", catch_height(last.level, following.level, following.t - last.t, setup=self.setup)

    def skip(self, atoms, i):
        """The next atom after leaving out atom i: a buzz is left out whole if its first bounce is."""
        k = i + 1
        if atoms[i].bounce == 0 and atoms[i].target.kind == "buzz":
            while k < len(atoms) and atoms[k].target is atoms[i].target:
                k += 1
        return k

    def stroke(self, times, levels, *, end, catch_at):
        """The design of the notes from where the stick is: caught and thrown again, or moved to a standard throw."""
        previous = self.designs[-1] if self.designs else None
        if previous is None:
            return design(times, levels, end=end, catch_at=catch_at, setup=self.setup, lead=self.lead)
        theta = previous.ends[1][0]  # caught at its last rebound's apex: at rest
        return next_stroke(times, levels, self.setup, free=previous.t_end, theta=theta, end=end,
                           catch_at=catch_at)[0]

    def keep(self, made, keys):
        self.designs.append(made)
        self.keys.append(tuple(keys))

    def leave_out(self, target, error):
        self.problems.append(Problem(target.key, target.t, str(error), getattr(error, "nearest_time", None),
                                     getattr(error, "nearest_level", None)))


def assign_sticks(times, *, beats=None, given=None, sticks=2, lead="right", other="left", fastest=0.25):
    """The stick for each note of a part that does not name them, as a drummer sticks it.

    The lead hand plays the notes on the beat; off the beat the hands alternate; a note that comes
    sooner than ``fastest`` s after its hand's last note goes to the other hand if that one has been
    free for longer. A stick ``given`` for a note is kept (and keeps its hand busy). With one stick,
    every note without one is the lead's.

    Parameters
    ----------
    times : array_like [shape=(n,)]
        s, in time order.
    beats : array_like [shape=(n,)], optional
        Each note's position in beats; a whole number is on the beat. Default: every note off it.
    given : sequence of str or None [n], optional
        The notes' sticks where the part names them (None where it does not).
    sticks : {1, 2}
    lead, other : str
        The sticks' names.
    fastest : float
        s, the shortest gap one stick takes between two notes before the other stick plays.

    Returns
    -------
    list of str
    """
    times = np.asarray(times, dtype=float)
    given = [None] * len(times) if given is None else list(given)
    if sticks not in (1, 2):
        raise ParameterError(f"sticks must be 1 or 2, got {sticks!r}")
    if len(given) != len(times):
        raise ParameterError(f"given must name a stick (or None) for each of the {len(times)} notes, got {len(given)}")
    if sticks == 1:
        return [stick if stick is not None else lead for stick in given]
    on_beat = (np.zeros(len(times), bool) if beats is None
               else np.abs(np.asarray(beats, dtype=float) - np.round(beats)) < 1e-6)
    chosen, last = [], {lead: -math.inf, other: -math.inf}
    for k, t in enumerate(times):
        if given[k] is not None:
            hand = given[k]
        else:
            hand = lead if on_beat[k] or not chosen else (other if chosen[-1] == lead else lead)
            spare = other if hand == lead else lead
            if t - last[hand] < fastest and last[spare] < last[hand]:  # the hand free for longer takes it
                hand = spare
        chosen.append(hand)
        last[hand] = t
    return chosen
