"""The hands' performance of a kit part: each hand's motion over its joints, and what became of each note.

:func:`play_hands` takes a kit part's notes (times, pieces, levels; the limbs assigned or given) and
plays each hand's share. A hand's notes, in time order, fall into runs on one piece; each run is
planned by the one-stick planner (:func:`~drumstroke.design.planner.plan_stick`) on that piece's
:class:`~drumstroke.design.Setup` (its h, so its surface at θ_max = −asin(h/x), its c): the notes of a
run bounce on, or are caught and thrown again, as the planner decides, and the run's last note is
caught at its ready height. Between two runs the hand moves: its positioning joints (``yaw``, and
``lift`` on the shipped kit) from the last piece's place to the next's, and θ, the stick's angle to
the horizontal (one angle over every piece, each piece's surface at its own θ_max), from where the
stick was caught to where the next run's first stroke is thrown from — all joints together, as one
time-optimal, jerk-limited, synchronised move (:func:`~drumstroke.palette.motion.synchronised_move`),
then held there until the throw. When the move does not fit after the catch (at the rebound's apex), the
hand leaves earlier, on the rise after the last impact (:data:`DEPARTURES`): the move takes the stick
over from its flight at the flight's angle and speed.

The stick stays clear of every surface it passes over. What lies under it is told by the yaw: a piece's
footprint is its place's yaw ± a half-width (``footprint``), and while the yaw is within it the stick
stays ``clearance`` rad above that piece's surface (θ ≥ θ_max + clearance) — except where the
positioning joints are exactly at a piece's place, where the stick plays that piece and only its
surface is below it (θ ≥ θ_max), as in the planner. The lift joint does not enter: a raised cymbal
counts as a surface at its own θ_max. A move is checked on a grid of :data:`CHECK_STEP` s and at
each joint's extremes; when the direct move passes too low, the hand lifts the stick first (to the
clearance above every footprint it sweeps), then moves across (and down to the throw), or moves across
at that height and then lowers it: two or three synchronised moves.
When that does not fit in the time before the next stroke's release, the run is planned again with
the planner's shorter throws onto its first note (:data:`~drumstroke.design.planner.LEADS`): the
move gets their time; when none fits, that note is left out and reported, with the time the move
needs and the time there is — never a jump — and the run's other notes are planned again.

Examples
--------
>>> from drumstroke.kit.limbs import KitNote
>>> from drumstroke.kit.pieces import default_kit
>>> notes = [KitNote(0.5, "snare"), KitNote(1.0, "floor-tom"), KitNote(1.5, "snare")]
>>> part = play_hands(notes, default_kit(), velocities=[100, 90, 100], limbs=["right"] * 3)
>>> [(o.piece, round(o.impact, 9), o.played) for o in part.outcomes]
[('snare', 0.5, True), ('floor-tom', 1.0, True), ('snare', 1.5, True)]
>>> right = part.hands["right"]
>>> right.joints
('yaw', 'lift', 'theta')
>>> positions, _ = right.curve(np.array([1.0]))     # at the floor tom's impact: over it, on its surface
>>> positions.round(4).tolist()
[[-0.8, 0.0, -0.3008]]
"""

import itertools
import math
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

from .._checks import check_real, check_vector, shown
from ..curve import Curve, Segment, placed
from ..design import Unreachable
from ..design.chain import LEAD, MIN_GAP
from ..design.planner import LEADS, Problem, Target, plan_stick
from ..design.setup import Setup
from ..dynamics import CEILING_DB, FLOOR_DB, velocity_to_foot_level, velocity_to_level
from ..errors import ParameterError
from ..palette.motion import plan_return, synchronised_move
from ..trajectory import DEFAULT_RATE
from .limbs import Assignment, KitNote, assign_limbs
from .pedal import MIN_GAP as PEDAL_GAP
from .pedal import Pedal, design_pedal
from .pieces import FEET, YAW, Kit

THETA = "theta"
"""The name of a hand's last joint: the stick's angle to the horizontal (rad), common to every piece."""

CLEARANCE = 0.05
"""Default: rad the stick stays above a surface it passes over (1.35 cm at the paper stick's tip, x = 0.27 m)."""

FOOTPRINT = 0.25
"""Default: rad of yaw either side of a piece's place over which the stick is above it (a 14-inch drum's
radius, 0.18 m, seen from the shoulder at about 0.7 m)."""

CHECK_STEP = 1e-4
"""s: the grid a move is checked for clearance on (with each joint's extremes)."""

DEPARTURES = (0.75, 0.5, 0.3, 0.15, 0.05)
"""Where, as shares of the time from a stroke's last impact to its catch, a hand that cannot reach its next piece
from the catch tries leaving instead (the move takes the stick over on its rise)."""

_AT_PLACE = 1e-9  # rad: positioning joints this near a piece's place are at it (the stick plays that piece)


class Hit(NamedTuple):
    """One impact of a hand's stick: when (s), on which piece, at what level (dB re 1 m/s), and the note's index."""

    t: float
    piece: str
    level: float
    note: int


@dataclass(frozen=True)
class Outcome:
    """What became of one note a hand was to play (or no limb could).

    Attributes
    ----------
    index : int
        The note's index in the part.
    note : KitNote
    limb : str or None
        The hand that plays it; None when no limb was assigned.
    level : float
        dB re 1 m/s tip speed: the level asked for.
    impact : float or None
        s: when its impact lands (None when not played).
    impact_level : float or None
        dB: the impact's level (None when not played).
    problem : Problem or None
        Why it is not played: the reason, the nearest time (s) and level (dB) reachable where known.
    """

    index: int
    note: KitNote
    limb: str | None
    level: float
    impact: float | None = None
    impact_level: float | None = None
    problem: Problem | None = None

    @property
    def played(self):
        """Whether the note is played."""
        return self.problem is None

    @property
    def piece(self):
        """The piece's name."""
        return self.note.piece


@dataclass(frozen=True, repr=False)
class HandMotion:
    """One hand's motion over the kit.

    Attributes
    ----------
    hand : str
    joints : tuple of str
        The curve's columns: the hand's positioning joints in the kit's order, then :data:`THETA`.
    curve : Curve or None
        The hand's exact motion, ``curve(t) -> (positions, velocities)`` (rad, rad/s) [shape=t.shape +
        (joints,)]: held before its first stroke and after its last (None for a hand without notes).
    hits : tuple of Hit
        Every impact of its stick, in time order.
    designs : tuple of (str, Design)
        The strokes it plays, each with its piece's name.
    limits : tuple of Limits
        Each joint's limits: the kit's for the positioning joints; for θ the setup's moves (its range from
        the lowest surface the hand plays).
    t_end : float
        s: where its last stroke ends (its stick caught); 0 without notes.
    """

    hand: str
    joints: tuple
    curve: Curve | None
    hits: tuple
    designs: tuple
    limits: tuple
    t_end: float

    def __repr__(self):
        return f"HandMotion({self.hand!r}, {len(self.hits)} hits, {len(self.designs)} strokes)"

    def sample(self, rate=DEFAULT_RATE, t_end=None):
        """The motion at ``rate`` Hz from 0 (or its first release, if earlier) to ``t_end`` s (default its end).

        Returns
        -------
        t : ndarray [shape=(n,)]
            s, multiples of 1/rate.
        positions, velocities : ndarray [shape=(n, joints)]
            rad, rad/s.
        """
        if self.curve is None:
            raise ParameterError(f"the {self.hand} hand plays no note: it has no motion to sample")
        rate = check_real("rate", rate, low=0.0, high=1e6, low_open=True, unit="Hz")
        start = min(0.0, self.curve.start)
        end = self.t_end if t_end is None else check_real("t_end", t_end, low=start, high=1e6, unit="s")
        t = np.arange(math.floor(start * rate), math.floor(end * rate + 1e-9) + 1) / rate
        return (t, *self.curve(t))


class FootNote(NamedTuple):
    """A note a foot plays, passed on as given: its index in the part, the note, the foot, its level (dB)."""

    index: int
    note: KitNote
    limb: str
    level: float


@dataclass(frozen=True, repr=False)
class HandsPerformance:
    """The hands' performance of a kit part.

    Attributes
    ----------
    hands : dict of str to HandMotion
        Each of the kit's hands.
    outcomes : tuple of Outcome
        Every note not a foot's, in the part's order: played (its impact) or not (its problem).
    feet : tuple of FootNote
        The feet's notes, untouched, for the pedals to play.
    """

    hands: dict
    outcomes: tuple
    feet: tuple

    def __repr__(self):
        played = sum(o.played for o in self.outcomes)
        return f"HandsPerformance({played} of {len(self.outcomes)} hand notes played, {len(self.feet)} foot notes)"

    @property
    def problems(self):
        """The problems of the notes not played."""
        return tuple(o.problem for o in self.outcomes if not o.played)


def play_hands(notes, kit, *, levels=None, velocities=None, setup=None, limbs=None, clearance=CLEARANCE,
               footprint=FOOTPRINT):
    """Play the hands' notes of a kit part: each hand's motion, every note played or reported.

    Parameters
    ----------
    notes : sequence of KitNote
        Times (s), pieces, the hi-hat's states; any order.
    kit : Kit
    levels : array_like [shape=(n,)], optional
        dB re 1 m/s tip speed, each in [-35.96, 12.04] (MIDI velocities 1-127). Give these or ``velocities``.
    velocities : array_like [shape=(n,)], optional
        MIDI velocities 1-127.
    setup : Setup, optional
        What every stick is played with (model, forces, joint limits, the moves' budget); each piece's
        :meth:`~drumstroke.kit.pieces.Piece.setup` sets its h and c. Default ``Setup()``.
    limbs : Assignment or sequence of str or None, optional
        The notes' limbs: an :func:`~drumstroke.kit.limbs.assign_limbs` result, or limbs given for some
        notes (None for the others, which are assigned). Default: all assigned.
    clearance : float in [0, 0.5]
        rad the stick stays above each surface it passes over (θ ≥ θ_max + clearance).
    footprint : float in [0, 1] or dict of str to float
        rad of yaw either side of a piece's place over which the stick is above it; one for every piece
        or one per piece name (the pieces not named: :data:`FOOTPRINT`).

    Returns
    -------
    HandsPerformance
    """
    hand_arms = arms(kit, setup, clearance=clearance, footprint=footprint)  # kit, setup and the moves' options checked
    assignment = limbs if isinstance(limbs, Assignment) else assign_limbs(notes, kit, given=limbs)
    notes = _checked(notes, kit, assignment)
    levels = _levels(levels, velocities, len(notes))
    hands = {hand: _Hand(arm).play([i for i, limb in enumerate(assignment.limbs) if limb == hand], notes, levels)
             for hand, arm in hand_arms.items()}
    played = {i: outcome for motion, outcomes in hands.values() for i, outcome in outcomes.items()}
    outcomes, feet = [], []
    for i, (note, limb) in enumerate(zip(notes, assignment.limbs)):
        if limb in FEET:
            feet.append(FootNote(i, note, limb, levels[i]))
        elif limb is None:
            problem = Problem(i, note.time, assignment.reasons[i] or "no limb plays it")
            outcomes.append(Outcome(i, note, None, levels[i], problem=problem))
        else:
            outcomes.append(played[i])
    return HandsPerformance({hand: motion for hand, (motion, _) in hands.items()}, tuple(outcomes), tuple(feet))


def _checked(notes, kit, assignment):
    """The notes as KitNotes, each on a piece of ``kit`` and its limb (the assignment's) one that plays it."""
    if isinstance(notes, (str, bytes)) or not hasattr(notes, "__len__"):
        raise ParameterError(f"notes must be a sequence of KitNote, got {shown(notes)}")
    notes = tuple(note if isinstance(note, KitNote) else KitNote(*note) for note in notes)
    if len(assignment.limbs) != len(notes):
        raise ParameterError(f"limbs must hold a limb for each of the {len(notes)} notes, got {len(assignment.limbs)}")
    for i, (note, limb) in enumerate(zip(notes, assignment.limbs)):
        check_real(f"notes[{i}].time", note.time, low=0.0, high=1e6, unit="s")
        can = kit.piece(note.piece).limbs_for(note.state)
        if limb is not None and limb not in can:
            raise ParameterError(f"limbs[{i}] must be a limb that plays {note.piece!r} ({', '.join(can)}), "
                                 f"got {shown(limb)}")
    return notes


def _levels(levels, velocities, count):
    """The notes' levels (dB), from ``levels`` or ``velocities``, one per note."""
    if (levels is None) == (velocities is None):
        raise ParameterError("give the notes' levels (dB) or their velocities (MIDI 1-127), one of the two")
    if levels is None:
        velocities = check_vector("velocities", velocities, low=1.0, high=127.0)
        levels = [velocity_to_level(v) for v in velocities]
    levels = check_vector("levels", levels, low=FLOOR_DB - 1e-9, high=CEILING_DB + 1e-9, unit="dB")
    if len(levels) != count:
        raise ParameterError(f"levels (or velocities) must hold one per note ({count}), got {len(levels)}")
    return [float(level) for level in levels]


@dataclass(frozen=True)
class _Surface:
    """A piece a hand plays, as the moves see it: its place, its surface's θ_max (rad) and its footprint's
    half-width (rad of yaw), and the setup it is played with."""

    name: str
    place: dict
    head: float
    footprint: float
    setup: Setup = field(repr=False)


def _surfaces(kit, setup, footprint):
    """Every piece a hand plays, by name, as a :class:`_Surface`."""
    named = footprint if isinstance(footprint, dict) else {}
    hands = [piece for piece in kit.pieces if piece.hands]
    for name in named:
        if name not in [piece.name for piece in hands]:
            raise ParameterError(f"footprint names {shown(name)}, not a piece a hand plays "
                                 f"({', '.join(piece.name for piece in hands)})")
    default = FOOTPRINT if isinstance(footprint, dict) else footprint
    surfaces = {}
    for piece in hands:
        width = check_real(f"footprint[{piece.name!r}]" if piece.name in named else "footprint",
                           named.get(piece.name, default), low=0.0, high=1.0, unit="rad")
        played = piece.setup(setup)
        surfaces[piece.name] = _Surface(piece.name, piece.place, played.head, width, played)
    return surfaces


def _states(kit, setup, surfaces):
    """Every piece a hand plays in each of its states (the hi-hat's: closed, half, open), by (name, state): its
    surface with the state's own c and h; (name, None) the piece's own."""
    states = {}
    for name, surface in surfaces.items():
        piece = kit.piece(name)
        for state in (None, *piece.surfaces):
            played = piece.setup(setup, state)
            states[name, state] = replace(surface, head=played.head, setup=played)
    return states


class Arm:
    """One hand's joints over the kit: where each piece puts them, and the moves between pieces that keep the stick
    clear of the surfaces it passes over (see the module's docstring). Made by :func:`arms`.

    Attributes
    ----------
    hand : str
    joints : tuple of str
        Its positioning joints in the kit's order, then :data:`THETA`.
    limits : tuple of Limits
        Each joint's: the kit's for the positioning joints; for θ the setup's moves, its range from the lowest
        surface the hand plays.
    surfaces : dict
        Every piece a hand plays, by name: its place, its surface's θ_max (``head``, rad), its footprint's
        half-width (rad of yaw) and the :class:`~drumstroke.design.Setup` it is played with (``setup``).
    states : dict of (str, str or None) to surface
        The same in each of a piece's states (the hi-hat's closed, half, open: their own c and h), by (name,
        state); (name, None) the piece's own. The moves' clearance is the piece's own surface's.
    places : dict of str to ndarray
        The positioning joints' angles (rad) at each of those pieces.
    clearance : float
        rad the stick stays above a surface it passes over.
    """

    def __init__(self, hand, kit, setup, surfaces, clearance):
        self.hand, self.surfaces, self.clearance = hand, surfaces, clearance
        self.states = _states(kit, setup, surfaces)
        positioning = tuple(kit.limbs[hand])
        self.joints = positioning + (THETA,)
        self.yaw = positioning.index(YAW)
        self.places = {name: np.array([s.place[joint] for joint in positioning]) for name, s in surfaces.items()}
        mine = [s for s in self.states.values() if hand in kit.piece(s.name).hands]
        # no surface it plays lies lower than the lowest of them
        theta = replace(setup.moves, theta_low=min((s.head for s in mine), default=setup.moves.theta_low))
        self.limits = tuple(kit.limbs[hand][joint] for joint in positioning) + (theta,)

    def __repr__(self):
        return f"Arm({self.hand!r}, joints {self.joints})"

    def position(self, piece, theta):
        """Every joint's angle (rad) with the hand at ``piece``'s place (its name) and the stick at ``theta``."""
        return np.append(self.places[piece], theta)

    def on_place(self, piece, path):
        """A path of θ (one joint) as a path of every joint, the positioning joints held at ``piece``'s place."""
        place = self.places[piece]

        def path_of_joints(t):
            theta, omega = path(t)
            shape = np.shape(theta) + place.shape
            return (np.concatenate((np.broadcast_to(place, shape), np.asarray(theta)[..., None]), axis=-1),
                    np.concatenate((np.zeros(shape), np.asarray(omega)[..., None]), axis=-1))

        return path_of_joints


    def crossing(self, start, target, speed=0.0):
        """The moves from ``start`` (every joint's angle, θ moving at ``speed`` rad/s, the others at rest) to
        ``target`` (at rest) that keep the stick clear: the direct synchronised move, else lift then across, else
        lift, across, lower; None when none does."""
        velocities = np.zeros_like(start)
        velocities[-1] = speed
        direct = synchronised_move(start, target, self.limits, velocities=velocities)
        if direct is not None and self.clear(direct):
            return [direct]
        height = self.height_over(start[self.yaw], target[self.yaw])
        lifted = _with_theta(start, max(start[-1], height))
        for stops in ([start, lifted, target], [start, lifted, _with_theta(target, max(target[-1], height)), target]):
            moves = self.legs(stops, velocities)
            if moves is not None:
                return moves
        return None

    def legs(self, stops, velocities):
        """The synchronised moves from stop to stop (the first leaving at ``velocities``), or None when one is not
        clear."""
        moves = []
        for a, b in itertools.pairwise(stops):
            if np.array_equal(a, b) and (moves or not velocities.any()):
                continue
            move = synchronised_move(a, b, self.limits, velocities=None if moves else velocities)
            if move is None or not self.clear(move):
                return None
            moves.append(move)
        return moves

    def height_over(self, a, b):
        """θ (rad) clear of every surface whose footprint the yaw sweeps going from ``a`` to ``b`` (rad)."""
        low, high = min(a, b), max(a, b)
        heads = [s.head for s in self.surfaces.values()
                 if s.place[YAW] + s.footprint >= low and s.place[YAW] - s.footprint <= high]
        return max(heads) + self.clearance

    def clear(self, move):
        """Whether the stick stays clear of the surfaces under it throughout ``move`` (on a grid, and at its
        joints' extremes)."""
        t = np.unique(np.concatenate((np.arange(0.0, move.duration, CHECK_STEP), [move.duration], move.turns)))
        positions, _ = move.path(t)
        return bool(np.all(self.clear_at(positions)))

    def clear_at(self, positions):
        """For each row of every joint's angle (rad), whether the stick is clear of the surfaces under it.

        Where the positioning joints are at a piece's place the stick plays that piece: only its surface is
        below it (θ ≥ θ_max); elsewhere, over every footprint the yaw is in, θ ≥ θ_max + clearance.
        """
        theta, yaw = positions[:, -1], positions[:, self.yaw]
        clear = np.ones(len(positions), bool)
        at_place = np.zeros(len(positions), bool)
        for surface in self.surfaces.values():
            here = np.all(np.abs(positions[:, :-1] - self.places[surface.name]) <= _AT_PLACE, axis=1)
            clear &= ~here | (theta >= surface.head - 1e-12)
            at_place |= here
        for surface in self.surfaces.values():
            over = (np.abs(yaw - surface.place[YAW]) <= surface.footprint) & ~at_place
            clear &= ~over | (theta >= surface.head + self.clearance - 1e-12)
        return clear


def arms(kit, setup=None, *, clearance=CLEARANCE, footprint=FOOTPRINT):
    """Each of ``kit``'s hands as an :class:`Arm`, by name.

    Parameters
    ----------
    kit : Kit
    setup : Setup, optional
        What the sticks are played with; each piece's :meth:`~drumstroke.kit.pieces.Piece.setup` sets its h and c.
        Default ``Setup()``.
    clearance : float in [0, 0.5]
        rad the stick stays above each surface it passes over (θ ≥ θ_max + clearance).
    footprint : float in [0, 1] or dict of str to float
        rad of yaw either side of a piece's place over which the stick is above it; one for every piece or one per
        piece name (the pieces not named: :data:`FOOTPRINT`).
    """
    if not isinstance(kit, Kit):
        raise ParameterError(f"kit must be a drumstroke.kit.pieces.Kit, got {shown(kit)}")
    setup = Setup() if setup is None else setup
    if not isinstance(setup, Setup):
        raise ParameterError(f"setup must be a drumstroke.design.Setup, got {shown(setup)}")
    clearance = check_real("clearance", clearance, low=0.0, high=0.5, unit="rad")
    surfaces = _surfaces(kit, setup, footprint)
    return {hand: Arm(hand, kit, setup, surfaces, clearance) for hand in kit.hands}


class _Hand:
    """One hand's notes played: runs planned on their pieces, moves between them (see the module's docstring)."""

    def __init__(self, arm):
        self.arm, self.hand = arm, arm.hand
        self.segments, self.hits, self.designs = [], [], []
        self.outcomes = {}
        self.last = None  # (surface, Design, index of its segment): the hand's last stroke

    def play(self, indices, notes, levels):
        """(HandMotion, {note index: Outcome}) of the notes ``indices`` of the part."""
        self.notes, self.levels = notes, levels
        for run in self.runs(sorted(indices, key=lambda i: notes[i].time)):
            first = notes[run[0]]
            self.run(self.arm.states[first.piece, first.state], run)
        curve, t_end = None, 0.0
        if self.last is not None:
            surface, stroke, _ = self.last
            t_end = stroke.t_end
            self.segments.append(Segment.hold(self.arm.position(surface.name, _caught(stroke)), t_end))
            curve = Curve(tuple(self.segments))
        motion = HandMotion(self.hand, self.arm.joints, curve, tuple(sorted(self.hits)),
                            tuple(self.designs), self.arm.limits, t_end)
        return motion, self.outcomes

    def runs(self, order):
        """The notes in time order as runs on one surface (a piece, in one state); a note too close to the one before
        is left out."""
        runs, last = [], None
        for i in order:
            note = self.notes[i]
            if last is not None and note.time - self.notes[last].time < MIN_GAP:
                self.leave_out(i, f"the {self.hand} hand plays note {last} {note.time - self.notes[last].time:.3g} "
                                  f"s before it; its stick's notes must be at least {MIN_GAP:g} s apart")
                continue
            before = self.notes[runs[-1][-1]] if runs else None
            if before is not None and (before.piece, before.state) == (note.piece, note.state):  # one surface
                runs[-1].append(i)
            else:
                runs.append([i])
            last = i
        return runs

    def run(self, surface, run):
        """Plan one run on ``surface``, its first throw the planner's or, when the hand cannot get there in time,
        a shorter one; when none gives the time, the first note is left out and the rest planned again."""
        pending = list(run)
        while pending:
            targets = [Target(self.notes[i].time, self.levels[i], key=i) for i in pending]
            attempt = None
            for lead in LEADS if self.last is not None else (LEAD,):
                plan = plan_stick(targets, setup=surface.setup, lead=lead)
                if not plan.designs:
                    if attempt is None:  # the planner's own throw plays none of them: its reasons
                        self.report(plan.problems)
                        return
                    continue
                moves, leave, need, available = self.arrive(surface, plan.designs[0])
                if moves is not None:
                    self.keep(surface, plan, moves, leave)
                    return
                attempt = (plan.keys[0][0], leave, need, available)
            key, leave, need, available = attempt
            nearest = self.notes[key].time + need - available if math.isfinite(need) else None
            self.leave_out(key, self.too_slow(surface, leave, need, available), nearest)
            pending.remove(key)

    def arrive(self, surface, first):
        """The moves that take the hand from its last stroke to ``first``'s throw on ``surface`` (none for its
        first stroke), when they leave (s), the time they need and the time there is (s); the moves None when no
        departure fits.

        The hand leaves where its last stroke's stick is caught when the move fits from there; else earlier, on
        the rise after the stroke's last impact (:func:`departures`): the move then takes the stick over from its
        flight, at its angle and speed. Without a fit, the need and time reported are the departure's that came
        closest."""
        if self.last is None:
            return [], 0.0, 0.0, math.inf
        before, last, _ = self.last
        target = self.arm.position(surface.name, _thrown(first))
        closest = None
        for leave in departures(last):
            theta, omega = last.state(np.array([leave]))
            moves = self.arm.crossing(self.arm.position(before.name, float(theta[0])), target, float(omega[0]))
            need = math.inf if moves is None else sum(move.duration for move in moves)
            available = first.release - leave
            if need <= available:
                return moves, leave, need, available
            if closest is None or need - available < closest[1] - closest[2]:
                closest = (leave, need, available)
        return (None, *closest)

    def keep(self, surface, plan, moves, leave):
        """Add the run's strokes (the first after ``moves``, which leave at ``leave`` s) and the planner's moves
        between them."""
        designs, made = plan.designs, plan.designs[0]
        held = self.arm.position(surface.name, _thrown(made))
        if self.last is None:
            self.segments.append(Segment.hold(held, min(0.0, made.release), made.release))
        else:
            flight = self.last[2]  # the last stroke's segment: its flight ends where the move takes the stick over
            self.segments[flight] = replace(self.segments[flight], end=leave)
            self.segments += placed([(move.duration, move.path) for move in moves], leave)
            self.segments.append(Segment.hold(held, leave + sum(move.duration for move in moves), made.release))
        for k, stroke in enumerate(designs):
            if k:
                self.between(surface, designs[k - 1], stroke)
            self.stroke(surface, stroke, plan.keys[k])
        self.last = (surface, designs[-1], len(self.segments) - 1)
        self.report(plan.problems)

    def between(self, surface, before, after):
        """The planner's move of θ on one piece, from where ``before`` is caught to ``after``'s release."""
        theta = _caught(before)
        moves = plan_return((theta, 0.0), (float(after.recipe.theta0), 0.0), after.release - before.t_end,
                            surface.head, surface.setup.moves)
        if moves is None:  # the planner fitted this move when it made the strokes
            raise RuntimeError(f"no move from {theta:.6g} rad to the stroke at {after.release:.6g} s")
        self.segments += placed([(d, self.arm.on_place(surface.name, path)) for d, path in moves], before.t_end)

    def stroke(self, surface, made, keys):
        """One designed stroke on ``surface``: its segment, its impacts, its notes' outcomes."""
        stroke = made.stroke
        self.segments.append(Segment(made.release, made.t_end, self.arm.on_place(surface.name, stroke.arcs.evaluate),
                                     made.release, stroke.impacts.t, made))
        self.designs.append((surface.name, made))
        impacts = made.impacts
        for k, (t, level) in enumerate(zip(impacts.t, impacts.level_db)):
            note = keys[k] if k < len(keys) else -1
            self.hits.append(Hit(float(t), surface.name, float(level), note))
            if note >= 0:
                self.outcomes[note] = Outcome(note, self.notes[note], self.hand, self.levels[note], float(t),
                                              float(level))

    def report(self, problems):
        """The planner's problems, as the notes' outcomes."""
        for problem in problems:
            self.leave_out(problem.key, problem.reason, problem.nearest_time, problem.nearest_level)

    def leave_out(self, i, reason, nearest_time=None, nearest_level=None):
        problem = Problem(i, self.notes[i].time, reason, nearest_time, nearest_level)
        self.outcomes[i] = Outcome(i, self.notes[i], self.hand, self.levels[i], problem=problem)

    def too_slow(self, surface, leave, need, available):
        """Why the hand cannot reach ``surface`` in time (leaving at ``leave`` s, its closest try)."""
        where = f"from {self.last[0].name!r} to {surface.name!r}"
        if not math.isfinite(need):
            return (f"no move of the {self.hand} hand {where} keeps the stick {self.arm.clearance:g} rad above the "
                    f"surfaces it passes within the joints' ranges")
        return (f"the {self.hand} hand's move {where} needs {need:.4g} s, {available:.4g} s available (leaving at "
                f"{leave:.6g} s, its stick's last impact at {self.last[1].impacts.t[-1]:.6g} s, the throw onto the "
                f"note released at {leave + available:.6g} s)")

def _caught(made):
    """θ (rad) where a designed stroke's stick is caught, at rest, at its end."""
    return float(made.state(np.array([made.t_end]))[0][0])


def _thrown(made):
    """θ (rad) a designed stroke's stick is held at, at rest, until its release."""
    return float(made.recipe.theta0)


def departures(made):
    """When (s) a hand may leave the piece it played ``made`` on: where its stick is caught (its end), then earlier
    along the rise after its last impact (:data:`DEPARTURES`, latest first): the earliest a hair after the impact."""
    last = float(made.impacts.t[-1]) if len(made.impacts.t) else made.release
    return [made.t_end] + [last + share * (made.t_end - last) for share in DEPARTURES]


def _with_theta(position, theta):
    """``position`` (every joint's angle, rad) with the stick at ``theta`` instead."""
    return np.concatenate((position[:-1], [theta]))


# --- the whole kit: the hands, and the feet on their pedals --------------------------------------------------------


class KitHit(NamedTuple):
    """One impact of a limb on the kit: when (s), the piece, the MIDI key it sounds as (the hi-hat's says its
    state), the limb, the striking speed (m/s: a stick's tip, a pedal's beater head) and the note's index (−1
    for a stick's bounce after its note)."""

    t: float
    piece: str
    key: int
    limb: str
    speed: float
    note: int


@dataclass(frozen=True, repr=False)
class FootMotion:
    """One foot's motion on its pedal.

    Attributes
    ----------
    foot : str
    pedal : str
        The pedal's name (the kit's pieces name it: "kick", "hihat").
    joints : tuple of str
        ``("theta",)``: the beater's angle θ = −φ (rad), back from the vertical (see :mod:`.pedal`).
    curve : Curve
        The exact motion, ``curve(t) -> (θ, ω)`` (rad, rad/s); at rest at φ_rest before its first press and
        after its design ends.
    design : PedalDesign or None
        The foot force that plays its notes (None for a foot without notes).
    t_end : float
        s: where its design ends, the beater back at rest (0 without notes).
    """

    foot: str
    pedal: str
    joints: tuple
    curve: Curve
    design: object
    t_end: float

    def __repr__(self):
        notes = 0 if self.design is None else len(self.design.times)
        return f"FootMotion({self.foot!r} on the {self.pedal!r} pedal, {notes} notes)"


@dataclass(frozen=True, repr=False)
class KitPerformance:
    """A kit part played: every limb's motion, what became of every note, every impact.

    Attributes
    ----------
    hands : dict of str to HandMotion
        Each of the kit's hands.
    feet : dict of str to FootMotion
        Each of the kit's feet that works a pedal.
    outcomes : tuple of Outcome
        Every note, in the part's order: its limb, played (impact time, s; level, dB re 1 m/s of the tip or the
        beater head) or not (its problem).
    keys : tuple of int
        Every note's MIDI key (the hi-hat's says its state).
    hits : tuple of KitHit
        Every impact of every limb, in time order.
    """

    hands: dict
    feet: dict
    outcomes: tuple
    keys: tuple
    hits: tuple

    def __repr__(self):
        played = sum(o.played for o in self.outcomes)
        return f"KitPerformance({played} of {len(self.outcomes)} notes played, {len(self.hits)} hits)"

    @property
    def problems(self):
        """The problems of the notes not played."""
        return tuple(o.problem for o in self.outcomes if not o.played)

    @property
    def motions(self):
        """Every limb with a motion, in the kit's order: ``{limb: (joints, curve)}`` (hands without notes left out)."""
        hands = {hand: (m.joints, m.curve) for hand, m in self.hands.items() if m.curve is not None}
        return hands | {foot: (m.joints, m.curve) for foot, m in self.feet.items()}

    @property
    def t_end(self):
        """s: when the last limb's motion ends (its stick caught, its beater back at rest)."""
        return max([m.t_end for m in self.hands.values()] + [m.t_end for m in self.feet.values()] + [0.0])


def play_kit(notes, kit, *, levels=None, velocities=None, keys=None, setup=None, limbs=None, lead="right",
             open_handed=False, pedals=None, clearance=CLEARANCE, footprint=FOOTPRINT):
    """Play a kit part: the hands as :func:`play_hands` plays them, each foot's notes on its pedal.

    A foot's notes (the kick's: the right foot; the hi-hat's pedal key: the left, on the shipped kit) are
    designed by :func:`~drumstroke.kit.pedal.design_pedal` on the pedal its piece names (``end="release"``:
    the beater back at rest after its last note). A note the pedal cannot play (a press stronger than its
    ``max_force``, a first press that would start before 0 s, a double too fast for its rebound) is left out
    with the design's reason, and the foot's other notes are designed again; so is a note within 1 ms of the
    foot's note before it.

    Parameters
    ----------
    notes : sequence of KitNote
        Times (s), pieces, the hi-hat's states; any order.
    kit : Kit
    levels : array_like [shape=(n,)], optional
        dB re 1 m/s: a hand's note its tip speed (within a stick's MIDI range, [-35.96, 12.04]); a foot's its
        beater head's speed (within :data:`~drumstroke.kit.pedal.LEVEL_RANGE`). Give these or ``velocities``.
    velocities : array_like [shape=(n,)], optional
        MIDI velocities 1-127: a hand's note through :func:`~drumstroke.dynamics.velocity_to_level`, a foot's
        through :func:`~drumstroke.dynamics.velocity_to_foot_level` (127 is a hard kick, 17 dB).
    keys : sequence of int, optional
        Each note's MIDI key, one of its piece's (a hi-hat's of its state); recorded with its hits. Default the
        piece's first key for the note's state.
    setup : Setup, optional
        As :func:`play_hands` takes it.
    limbs : Assignment or sequence of str or None, optional
        The notes' limbs: an :func:`~drumstroke.kit.limbs.assign_limbs` result, or limbs given for some notes
        (None for the others, assigned with ``lead`` and ``open_handed``).
    lead : {"right", "left"}
    open_handed : bool
    pedals : dict of str to Pedal, optional
        Each pedal the kit's pieces name, by name; default ``Pedal()`` for each. The hi-hat's foot is modelled
        as a kick pedal whose "head" is the closed cymbals: without its own numbers, the defaults.
    clearance, footprint
        As :func:`play_hands` takes them.

    Returns
    -------
    KitPerformance

    Examples
    --------
    >>> from drumstroke.kit.pieces import default_kit
    >>> notes = [KitNote(0.5, "kick"), KitNote(0.5, "hihat", "closed"), KitNote(1.0, "hihat", "pedal")]
    >>> part = play_kit(notes, default_kit(), velocities=[127, 90, 64])
    >>> [(o.limb, round(o.impact, 9), round(o.impact_level, 6)) for o in part.outcomes]
    [('right-foot', 0.5, 17.0), ('right', 0.5, -2.054038), ('left-foot', 1.0, 5.0)]
    >>> [(h.limb, h.key) for h in part.hits if h.note >= 0]
    [('right', 42), ('right-foot', 35), ('left-foot', 44)]
    """
    if not isinstance(kit, Kit):
        raise ParameterError(f"kit must be a drumstroke.kit.pieces.Kit, got {shown(kit)}")
    if isinstance(notes, (str, bytes)) or not hasattr(notes, "__len__"):
        raise ParameterError(f"notes must be a sequence of KitNote, got {shown(notes)}")
    notes = tuple(note if isinstance(note, KitNote) else KitNote(*note) for note in notes)
    assignment = limbs if isinstance(limbs, Assignment) else assign_limbs(
        notes, kit, lead=lead, open_handed=open_handed, given=limbs)
    keys = _keys(notes, kit, keys)
    on_foot = [limb in FEET for limb in assignment.limbs]
    hand_levels, foot_levels = _kit_levels(levels, velocities, on_foot)
    hands = play_hands(notes, kit, levels=hand_levels, setup=setup, limbs=assignment, clearance=clearance,
                       footprint=footprint)
    pedals = kit_pedals(pedals, kit)
    outcomes = {o.index: o for o in hands.outcomes}
    feet = {}
    for foot in kit.feet:
        mine = [_with_level(f, foot_levels[f.index]) for f in hands.feet if f.limb == foot]
        pedal = next((kit.piece(f.note.piece).pedal for f in mine), _pedal_of(kit, foot))
        if pedal is None:
            continue
        feet[foot], played = _play_foot(foot, pedal, pedals[pedal], mine, kit)
        outcomes.update(played)
    outcomes = tuple(outcomes[i] for i in range(len(notes)))
    return KitPerformance(hands.hands, feet, outcomes, keys, _kit_hits(hands.hands, feet, outcomes, keys))


def _with_level(foot_note, level):
    """``foot_note`` with the foot's level (dB re 1 m/s beater head speed)."""
    return foot_note._replace(level=level)


def _keys(notes, kit, keys):
    """Each note's MIDI key: given (one of its piece's, of its state) or the piece's first for the state."""
    if keys is None:
        return tuple(next(k for k in kit.piece(n.piece).keys if kit.piece(n.piece).state(k) == n.state)
                     if n.state else kit.piece(n.piece).keys[0] for n in notes)
    if isinstance(keys, (str, bytes)) or not hasattr(keys, "__len__") or len(keys) != len(notes):
        raise ParameterError(f"keys must hold a MIDI key for each of the {len(notes)} notes, got {shown(keys)}")
    checked = []
    for i, (note, key) in enumerate(zip(notes, keys)):
        piece = kit.piece(note.piece)
        if isinstance(key, bool) or int(key) != key or int(key) not in piece.keys or piece.state(int(key)) != note.state:
            state = f" when {note.state}" if note.state else ""
            raise ParameterError(f"keys[{i}] must be a key of {note.piece!r}{state} "
                                 f"({', '.join(str(k) for k in piece.keys if piece.state(k) == note.state)}), "
                                 f"got {shown(key)}")
        checked.append(int(key))
    return tuple(checked)


def _kit_levels(levels, velocities, on_foot):
    """The hands' levels (each foot's note 0 dB: play_hands passes them on untouched) and every note's foot level."""
    if (levels is None) == (velocities is None):
        raise ParameterError("give the notes' levels (dB) or their velocities (MIDI 1-127), one of the two")
    if levels is None:
        velocities = check_vector("velocities", velocities, low=1.0, high=127.0)
        if len(velocities) != len(on_foot):
            raise ParameterError(f"velocities must hold one per note ({len(on_foot)}), got {len(velocities)}")
        return ([0.0 if foot else velocity_to_level(v) for v, foot in zip(velocities, on_foot)],
                [velocity_to_foot_level(v) if foot else None for v, foot in zip(velocities, on_foot)])
    levels = check_vector("levels", levels, low=-1e3, high=1e3, unit="dB")
    if len(levels) != len(on_foot):
        raise ParameterError(f"levels must hold one per note ({len(on_foot)}), got {len(levels)}")
    return ([0.0 if foot else float(level) for level, foot in zip(levels, on_foot)],
            [float(level) if foot else None for level, foot in zip(levels, on_foot)])


def kit_pedals(pedals, kit):
    """Every pedal the kit's pieces name, by name: those given in ``pedals`` (checked), the others ``Pedal()`` — with
    the c of the piece it plays when only feet play that piece (the kick's ``cor`` is its beater's on its head; the
    hi-hat's is a stick's on its plates, and its pedal keeps ``Pedal()``'s)."""
    names = sorted({piece.pedal for piece in kit.pieces if piece.pedal is not None})
    pedals = {} if pedals is None else pedals
    if not isinstance(pedals, dict):
        raise ParameterError(f"pedals must be a dict of pedal name to Pedal, got {shown(pedals)}")
    for name, pedal in pedals.items():
        if name not in names:
            raise ParameterError(f"pedals names {shown(name)}, not a pedal of the kit ({', '.join(names)})")
        if not isinstance(pedal, Pedal):
            raise ParameterError(f"pedals[{name!r}] must be a drumstroke.kit.pedal.Pedal, got {shown(pedal)}")
    beaten = {piece.pedal: piece.cor for piece in kit.pieces if piece.pedal is not None and not piece.hands}
    return {name: pedals[name] if name in pedals else replace(Pedal(), cor=beaten.get(name, Pedal().cor))
            for name in names}


def _pedal_of(kit, foot):
    """The pedal ``foot`` works when it plays no note: its first piece's (None if it plays none)."""
    return next((piece.pedal for piece in kit.pieces if foot in piece.feet), None)


def _play_foot(foot, name, pedal, notes, kit):
    """(FootMotion, {note index: Outcome}) of one foot's notes on the pedal ``name``."""
    outcomes, kept = {}, []

    def leave_out(note, reason, nearest_time=None):
        problem = Problem(note.index, note.note.time, reason, nearest_time)
        outcomes[note.index] = Outcome(note.index, note.note, foot, note.level, problem=problem)

    for note in sorted(notes, key=lambda n: n.note.time):
        if kit.piece(note.note.piece).pedal != name:
            leave_out(note, f"the {foot} works the {name!r} pedal; it has no move to another")
        elif kept and note.note.time - kept[-1].note.time < PEDAL_GAP:
            leave_out(note, f"the {foot} plays note {kept[-1].index} {note.note.time - kept[-1].note.time:.3g} s "
                            f"before it; a pedal's notes must be at least {PEDAL_GAP:g} s apart")
        else:
            kept.append(note)
    design = None
    while kept and design is None:
        try:
            design = design_pedal([n.note.time for n in kept], [n.level for n in kept], pedal)
        except Unreachable as error:  # left out, and the foot's other notes designed again
            leave_out(kept.pop(error.note), f"the {foot} on the {name!r} pedal (its note {error.note} there): {error}",
                      error.nearest_time)
    rest = Segment.hold(-pedal.phi_rest, 0.0)
    if design is None:
        return FootMotion(foot, name, (THETA,), Curve((rest,)), None, 0.0), outcomes
    stroke = design.stroke
    for note, t, level in zip(kept, stroke.impacts.t, stroke.impacts.level_db):
        outcomes[note.index] = Outcome(note.index, note.note, foot, note.level, float(t), float(level))
    curve = Curve(stroke.curve.segments + (Segment.hold(-pedal.phi_rest, stroke.t_end),))
    return FootMotion(foot, name, (THETA,), curve, design, stroke.t_end), outcomes


def _kit_hits(hands, feet, outcomes, keys):
    """Every impact, in time order: a stick's bounce sounds as the note it follows (its key, so its state)."""
    hits = []
    for hand, motion in hands.items():
        last = None
        for hit in motion.hits:
            last = hit.note if hit.note >= 0 else last
            hits.append(KitHit(hit.t, hit.piece, keys[last], hand, 10.0 ** (hit.level / 20.0), hit.note))
    for foot, motion in feet.items():
        if motion.design is None:
            continue
        played = [o for o in outcomes if o.limb == foot and o.played]
        impacts = motion.design.stroke.impacts
        for outcome, t, speed in zip(played, impacts.t, impacts.tip_speed):
            hits.append(KitHit(float(t), outcome.piece, keys[outcome.index], foot, float(speed), outcome.index))
    return tuple(sorted(hits, key=lambda h: (h.t, h.limb)))
