"""The kit played live: each note on its piece, by the limb a drummer would use, every joint streamed.

A :class:`KitPerformer` is a :class:`~drumstroke.live.performer.Performer` whose "sticks" are the kit's
limbs: each hand a motion of all its joints (its positioning joints, ``yaw`` and ``lift`` on the shipped
kit, then ``theta``, the stick's angle), each foot its pedal's beater (``theta`` = −φ, as
:mod:`drumstroke.kit.pedal` has it). Its setpoints have a column per joint, named ``LIMB.JOINT`` as a
composed kit's CSV names them (``right.yaw``, ``right.theta``, ``right-foot.theta``).

A note names its piece (default the snare) and, optionally, its limb. A note that names none gets
one as it arrives (notes come one at a time: a rule, not the offline assignment's optimisation): the
limbs that play the piece (:meth:`~drumstroke.kit.pieces.Piece.limbs_for`: the hi-hat's pedal a foot,
its cymbals a hand), the hand already over the piece first, then the hand the piece's role asks for
(the lead hand keeps time on the hi-hat and the ride, the other plays the backbeat on the snare),
then the hand that leaves the hands uncrossed (the right not left of the left), then the nearer
(:func:`~drumstroke.kit.limbs.move_time`), then the one free longest; the other hand is tried when
the first cannot play it.

A hand's note is planned as the stick performer plans one, on its piece's own
:class:`~drumstroke.design.Setup` (:meth:`~drumstroke.kit.pieces.Piece.setup`: its surface's θ_max, its
c), when the hand is over that piece. On another piece the hand moves first: from where its stick was
caught, all its joints together, to the piece's place and the height of a throw onto the note, in one
time-optimal jerk-limited synchronised move (:func:`~drumstroke.palette.motion.synchronised_move`,
within the kit's joints' limits), or, when that would pass too low over a surface on the way, two or
three (the stick raised ``clearance`` rad above every surface whose footprint the yaw sweeps, moved
across, lowered), as the offline kit moves (:meth:`~drumstroke.kit.play.Arm.crossing`); the throws tried are the planner's (:data:`~drumstroke.design.planner.LEADS`, longest first).
A note no move reaches in time is dropped with what the move needs and the time there is: the motion
never jumps. A foot's note is a press from rest (:func:`~drumstroke.kit.pedal.design_pedal`), once its
beater is back at rest after its last note.

Examples
--------
>>> from drumstroke.live import ManualClock
>>> performer = KitPerformer(clock=ManualClock())
>>> performer.columns[:3], performer.columns[-1]
(('right.yaw', 'right.lift', 'right.theta'), 'left-foot.theta')
>>> outcome = performer.note("auto", 100, at=0.3, piece="floor-tom")
>>> outcome.note.stick, outcome.move["from"], outcome.move["to"]
('right', 'hihat', 'floor-tom')
>>> performer.note("auto", 90, piece="tabla").reason
"piece must be one of the kit's pieces (snare, kick, hihat, tom1, tom2, floor-tom, ride, ride-bell, crash), got 'tabla'"
"""

import math
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from .._checks import check_choice, check_real, shown
from ..curve import Curve, Segment, placed
from ..design import Design, Unreachable, design
from ..design.chain import standard_throw
from ..design.planner import LEADS
from ..dynamics import velocity_to_foot_level, velocity_to_level
from ..errors import ParameterError
from ..kit.limbs import move_time
from ..kit.pedal import design_pedal
from ..kit.pieces import FEET, PEDAL_STATE, YAW, Kit, default_kit
from ..kit.play import CLEARANCE, FOOTPRINT, THETA, arms, kit_pedals
from ..palette.motion import Limits, plan_return, return_time
from ..trajectory import DEFAULT_RATE
from .performer import _WARM, AUTO, CLOSEST, GUARD, LATENCY, ManualClock, Performer, _played, _Stick


class KitPerformer(Performer):
    """Notes on a kit's pieces in, every joint of every limb out (see the module's description).

    Parameters
    ----------
    kit : Kit, optional
        Default the shipped :func:`~drumstroke.kit.pieces.default_kit`.
    lead : {"right", "left"}
        The hand that keeps time (the hi-hat, the ride) and starts over the hi-hat; the other starts
        over the snare (each hand over the first piece of that role it plays).
    setup : Setup, optional
        What every stick is played with, as :class:`~drumstroke.live.performer.Performer` takes it;
        each piece's :meth:`~drumstroke.kit.pieces.Piece.setup` sets its h and c.
    clearance : float in [0, 0.5]
        rad the stick stays above a surface it passes over on a move.
    footprint : float in [0, 1]
        rad of yaw either side of a piece's place over which the stick is above it.
    rate, latency, guard, rest, closest, horizon, clock
        As :class:`~drumstroke.live.performer.Performer` takes them; ``rest`` (rad, the sticks' θ before
        the first note and after :meth:`close`) must clear every piece's surface by ``clearance``.
    """

    def __init__(self, kit=None, *, lead="right", setup=None, clearance=CLEARANCE, footprint=FOOTPRINT,
                 rate=DEFAULT_RATE, latency=LATENCY, guard=GUARD, rest=0.0, closest=CLOSEST, horizon=None,
                 clock=None):
        kit = default_kit() if kit is None else kit
        if not isinstance(kit, Kit):
            raise ParameterError(f"kit must be a drumstroke.kit.pieces.Kit, got {shown(kit)}")
        pedals = kit_pedals(None, kit)
        feet = {foot: next(p.pedal for p in kit.pieces if foot in p.feet) for foot in kit.feet
                if any(foot in p.feet for p in kit.pieces)}
        super().__init__(sticks=kit.hands + tuple(feet), setup=setup, rate=rate, latency=latency, guard=guard,
                         rest=rest, closest=closest, horizon=horizon, clock=clock)
        self.kit = kit
        self.lead = check_choice("lead", lead, kit.hands)
        self._arms = arms(kit, self.setup, clearance=clearance,
                          footprint=check_real("footprint", footprint, low=0.0, high=1.0, unit="rad"))
        self.clearance, self.footprint = self._arms[kit.hands[0]].clearance, footprint
        self.pedals = {foot: pedals[name] for foot, name in feet.items()}
        self._setups = {name: surface.setup for name, surface in self._arms[kit.hands[0]].surfaces.items()}
        highest = max(s.head for s in self._setups.values()) + self.clearance
        if self.rest < highest:
            raise ParameterError(f"rest must be at least {highest:.6g} rad on this kit: {self.clearance:g} rad above "
                                 f"its highest surface, got {self.rest!r}")
        self._joints = {hand: arm.joints[:-1] for hand, arm in self._arms.items()}
        self._places = {hand: {name: place for name, place in arm.places.items() if hand in kit.piece(name).hands}
                        for hand, arm in self._arms.items()}
        # what the setpoints are checked against: the kit's joints, θ's range from the lowest surface the hand plays
        self._limits = {hand: arm.limits[:-1] + (replace(self.limits, theta_low=arm.limits[-1].theta_low),)
                        for hand, arm in self._arms.items()}
        self._sticks = {hand: _Stick(Curve.hold(self._position(hand, self._start(hand), self.rest)))
                        for hand in kit.hands}
        self._sticks |= {foot: _Stick(Curve.hold(-pedal.phi_rest)) for foot, pedal in self.pedals.items()}

    def _start(self, hand):
        """The piece ``hand`` starts over: the first of its role it plays (the lead's time, the other's backbeat)."""
        role = "time" if hand == self.lead else "backbeat"
        mine = [p for p in self.kit.pieces if hand in p.hands]
        return next((p.name for p in mine if p.role == role), mine[0].name)

    def _rehearse(self):
        """As :meth:`Performer.warm_up`'s, and a move and a press planned: ruckig and the pedal's code loaded."""
        super()._rehearse()
        if ("kit", self.model) in _WARM:
            return
        scratch = KitPerformer(self.kit, lead=self.lead, setup=self.setup, rate=self.rate, latency=self.latency,
                               guard=self.guard, rest=self.rest, closest=self.closest, horizon=self.horizon,
                               clock=ManualClock())
        for at, piece in ((0.3, None), (0.6, next(p.name for p in self.kit.pieces if p.hands and p.name != "snare")),
                          (0.9, next((p.name for p in self.kit.pieces if p.feet), None))):
            scratch.note("auto", 100, at=at, piece=piece)
        _WARM.add(("kit", self.model))

    # --- the columns --------------------------------------------------------------------------------------------------

    @property
    def columns(self):
        """``LIMB.JOINT`` for every joint of every limb: each hand's positioning joints and ``theta``, each foot's
        ``theta``."""
        return tuple(f"{limb}.{joint}" for limb in self.sticks
                     for joint in (self._joints[limb] + (THETA,) if limb in self._joints else (THETA,)))

    def _strikes(self, motions, t):
        """A limb's impacts are its θ's; its positioning joints strike nothing."""
        limbs = dict(zip(self.sticks, super()._strikes(motions, t)))
        none = np.empty(0)
        return tuple(limbs[limb] if joint == THETA else none
                     for limb, _, joint in (column.partition(".") for column in self.columns))

    def checks(self):
        """Each column's (head, Limits): a positioning joint's the kit's; a hand's θ the lowest surface it plays; a
        beater's its head and the pedal's loudest note, twice (the speed; the acceleration and jerk of its impact
        at the control rate, as :class:`~drumstroke.palette.motion.Limits`' defaults are set)."""
        checks = []
        for limb in self.sticks:
            if limb in self._limits:
                checks += [(limits.theta_low, limits) for limits in self._limits[limb]]
                continue
            pedal = self.pedals[limb]
            speed = 2.0 * pedal.speed(velocity_to_foot_level(127))
            impact = (1.0 + pedal.cor) * speed * self.rate
            checks.append((-pedal.phi_head, Limits(theta_low=-pedal.phi_head, max_speed=speed,
                                                   max_acceleration=impact, max_jerk=impact * self.rate)))
        return checks

    def options(self):
        """:meth:`Performer.options`, and the kit, the lead hand and the columns."""
        return super().options() | {"kit": self.kit.to_dict(), "lead": self.lead, "columns": list(self.columns)}

    # --- notes in -------------------------------------------------------------------------------------------------

    def _note(self, arrived, stick, velocity, at, stroke, duration, cut, piece, key):
        return super()._note(arrived, stick, velocity, at, stroke, duration, cut, "snare" if piece is None else piece,
                             key)

    def _piece_refusal(self, note):
        """Why the note's piece, key or limb is not one of the kit's that go together, or ''."""
        names = [p.name for p in self.kit.pieces]
        if not isinstance(note.piece, str) or note.piece not in names:
            return f"piece must be one of the kit's pieces ({', '.join(names)}), got {shown(note.piece)}"
        piece = self.kit.piece(note.piece)
        if note.key is not None and note.key not in piece.keys:
            return f"key must be one of {piece.name}'s ({', '.join(map(str, piece.keys))}), got {note.key}"
        limbs = self._limbs(note)
        if note.stick != AUTO and note.stick not in limbs:
            return f"stick must be a limb that plays {piece.name} here ({', '.join(limbs)}), got {shown(note.stick)}"
        if note.stroke == "buzz" and limbs[0] in FEET:
            return f"stroke must be auto on {piece.name}'s pedal (a foot presses single notes), got 'buzz'"
        return ""

    def _limbs(self, note):
        """The limbs that may play ``note``: its key's (the hi-hat's pedal key a foot's), or its named limb's kind."""
        piece = self.kit.piece(note.piece)
        if note.key is not None:
            state = piece.state(note.key)
        else:
            state = PEDAL_STATE if note.stick in FEET and PEDAL_STATE in piece.states.values() else None
        return tuple(limb for limb in piece.limbs_for(state) if limb in self._sticks)

    def _choices(self, note):
        """The limbs to try: the one named; else its foot, or its hands, the one over the piece first, then the one
        its role asks for (the lead keeps time, the other plays the backbeat), then the one free longest."""
        if note.stick != AUTO:
            return [note.stick]
        limbs = self._limbs(note)
        piece = self.kit.piece(note.piece)

        if limbs[0] in FEET:
            return list(limbs)
        at = {hand: self._piece_of(hand, self._sticks[hand].motion) for hand in self.kit.hands}

        def rank(hand):
            asked = hand == self.lead if piece.role == "time" else hand != self.lead if piece.role == "backbeat" else False
            return (at[hand] != piece.name, not asked, self._crossed(at | {hand: piece.name}),
                    move_time(self.kit, hand, at[hand], piece), self._sticks[hand].last_note, self.sticks.index(hand))

        return sorted(limbs, key=rank)

    def _crossed(self, at):
        """Whether hands over the pieces ``at`` (hand to piece name) are crossed: the right left of the left."""
        if len(at) < 2:
            return False
        return self.kit.piece(at["right"]).place[YAW] > self.kit.piece(at["left"]).place[YAW]

    def _plan(self, motion, note):
        """The limb's motion that plays ``note`` from its cut on, its design and the hand's move (or None)."""
        limb = note.stick
        if limb in self.pedals:
            return self._press(limb, motion, note)
        here = self._piece_of(limb, motion)
        if here != note.piece:
            return self._travel(limb, here, motion, note)
        made, start, moves = self._stroke(note, self._setups[here], motion.last(Design), _theta_state(motion))
        return self._over_piece(limb, here, _played(made, start, moves)), made, None

    def _piece_of(self, hand, motion):
        """The piece ``hand`` ends over in ``motion`` (its last segment holds it at the piece's place)."""
        position = motion.segments[-1].path(np.zeros(1))[0][0][:-1]
        return next(name for name, place in self._places[hand].items() if np.array_equal(place, position))

    def _travel(self, hand, here, motion, note):
        """Move ``hand`` from piece ``here`` to the note's, then throw onto it: the curve, the design, the move."""
        last = motion.last(Design)
        free = max(note.cut, last.end if last is not None else note.cut)
        start = motion.state(free)[0]  # at rest: the stick caught, or held
        setup = self._setups[note.piece]
        times = self._times(note)
        levels = np.full(len(times), velocity_to_level(note.velocity))
        slow = failure = None
        for lead in LEADS:
            try:
                release, height = standard_throw(times[0], levels[0], setup=setup, lead=lead)
                moves, need = self._crossing(hand, start, self._position(hand, note.piece, height))
                if need <= release - free:
                    made = design(times, levels, setup=setup, lead=lead)
                    held = self._position(hand, note.piece, float(made.recipe.theta0))
                    moves, need = self._crossing(hand, start, held)
                    release = made.release
            except Unreachable as error:
                if error.note > 0:
                    raise
                failure = failure or error.with_traceback(None)  # its frames would hold it: a reference cycle
                continue
            if need > release - free:  # the shortest throw's, the most time, is the one reported
                slow = self._too_slow(hand, here, note.piece, need, release - free, free)
                continue
            segments = [*placed([(m.duration, m.path) for m in moves], free), Segment.hold(held, free + need, release)]
            curve = Curve((*segments, *self._over_piece(hand, note.piece, _played(made, release, [])).segments))
            joints = [f"{hand}.{joint}" for joint in self._joints[hand] + (THETA,)]
            move = {"from": here, "to": note.piece, "start": free, "end": free + need,
                    "joints": {name: [float(a), float(b)] for name, a, b in zip(joints, start, held)}}
            return curve, made, move
        try:
            raise Unreachable(slow, note=0) if slow else failure
        finally:
            failure = None  # the error's traceback holds this frame: no reference cycle through it

    def _crossing(self, hand, start, target):
        """The moves from ``start`` to ``target`` (every joint's angle, at rest) that keep the stick clear
        (:meth:`~drumstroke.kit.play.Arm.crossing`), and their time (s); ([], inf) when none does."""
        moves = self._arms[hand].crossing(start, target)
        return ([], math.inf) if moves is None else (moves, sum(move.duration for move in moves))

    def _too_slow(self, hand, here, piece, need, available, free):
        where = f"from {here!r} to {piece!r}"
        if not math.isfinite(need):
            return (f"no move of the {hand} hand {where} keeps the stick {self.clearance:g} rad above the surfaces "
                    "it passes within the joints' ranges")
        return (f"the {hand} hand's move {where} needs {need:.4g} s, {available:.4g} s available (the hand free at "
                f"{free:.6g} s, the shortest throw onto the note released at {free + available:.6g} s)")

    def _press(self, foot, motion, note):
        """A foot's note: a press from rest once its beater is back at rest; the curve, the press, no move."""
        pedal = self.pedals[foot]
        last = motion.last(_Press)
        free = max(note.cut, last.source.rest if last is not None else note.cut)
        if note.at <= free:
            raise Unreachable(f"the {foot}'s beater is back at rest at {free:.6g} s, not before the note: a live "
                              "foot note is a press from rest", note=0)
        try:
            made = design_pedal([note.at - free], [velocity_to_foot_level(note.velocity)], pedal)
        except Unreachable as error:
            raise Unreachable(f"the {foot} on its pedal, at rest from {free:.6g} s (the times below from then): "
                              f"{error}", note=0) from None
        press, stroke = _Press(made, free), made.stroke
        pressed = Segment(free, free + stroke.t_end, stroke.curve, free, stroke.impacts.t, press)
        return Curve((pressed, Segment.hold(-pedal.phi_rest, free + stroke.t_end))), press, None

    # --- the end ----------------------------------------------------------------------------------------------------

    def _home(self, stick, motion, start):
        """A hand's stick to ``rest`` over the piece it played last; a foot is at rest already (None)."""
        if stick in self.pedals:
            return None
        piece = self._piece_of(stick, motion)
        head, limits = self._setups[piece].head, self._limits[stick][-1]
        theta, omega = _theta_state(motion)(start)
        window = return_time((theta, omega), (self.rest, 0.0), head, limits)
        moves = plan_return((theta, omega), (self.rest, 0.0), window, head, limits) if window > 0 else []
        if not moves:
            return None
        home = Curve.sequence(moves, start)
        return self._over_piece(stick, piece, home.spliced(Segment.hold(self.rest, home.end)))

    # --- joints -----------------------------------------------------------------------------------------------------

    def _position(self, hand, piece, theta):
        """Every joint's angle (rad): ``hand`` at ``piece``'s place, its stick at ``theta``."""
        return self._arms[hand].position(piece, theta)

    def _over_piece(self, hand, piece, curve):
        """A curve of θ as a curve of every joint of ``hand``, its positioning joints held at ``piece``'s place."""
        arm = self._arms[hand]
        return Curve(tuple(Segment(s.start, s.end, arm.on_place(piece, s.path), s.offset, s.impacts, s.source, s.still)
                           for s in curve.segments))


class _Impacts(NamedTuple):
    t: np.ndarray
    level_db: np.ndarray


@dataclass(frozen=True, eq=False)
class _Press:
    """A foot's designed press (a :class:`~drumstroke.kit.pedal.PedalDesign`) from ``start`` (s) on the session's
    clock: its notes' times, its impacts, when its beater is back at rest."""

    design: object
    start: float

    @property
    def times(self):
        return self.design.times + self.start

    @property
    def impacts(self):
        impacts = self.design.stroke.impacts
        return _Impacts(impacts.t + self.start, impacts.level_db)

    @property
    def rest(self):
        """s: the beater back at rest, the foot off (the design's last piece, a wait, starts)."""
        return self.start + self.design.pieces[-1].start


def _theta_state(motion):
    """``state(t)`` of a hand's stick alone: θ (rad) and ω (rad/s) as floats."""
    def state(t):
        positions, velocities = motion.state(t)
        return float(positions[-1]), float(velocities[-1])
    return state
