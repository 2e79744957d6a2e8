"""The live performer: notes in as they come, setpoints out at the control rate.

A :class:`Performer` keeps, for each stick, the motion planned so far as a chain of pieces on one
clock (s): designed strokes (:mod:`drumstroke.design`), jerk-limited moves and holds. A note that
arrives now is heard ``latency`` s later (or at the time it names); the planner designs its stroke
from where the stick will be a little after now (``guard`` s: nothing already sent, or about to be,
changes), in this order of preference:

1. **a bounce** from the stick's last planned impact, when that impact is still to come: the stroke
   goes on through the new note, as a drummer's hand lets a stick bounce into the next note;
2. **from the rebound in flight**, when the last impact is past but the stick still rises from it;
3. **a throw** from where the stick rests (caught at the apex of its last rebound, or held);
4. **a move and a throw**: a time-optimal jerk-limited move to the height of a quick throw, then the
   throw.

The piece the new stroke replaces is cut where it starts; what came before is kept sample for sample.
A note that cannot be played in time (too soon, too loud for the time left, before a note already
planned on its stick) is dropped and logged with its reason; the motion never jumps.

Samples are evaluated when asked for (:meth:`Performer.setpoints`), exactly as an offline run of the
same notes at the same arrival times gives them: the planner's decisions depend on the notes and the
times they arrived only, so :meth:`Performer.replay` reproduces a session from its log.

Examples
--------
>>> clock = ManualClock()
>>> performer = Performer(clock=clock)
>>> performer.note("right", 100).planned                   # heard 50 ms from now
True
>>> clock.set(0.2)
>>> chunk = performer.setpoints(0.2)
>>> chunk.t.shape, chunk.theta.shape
((201,), (201, 2))
"""

import gc
import json
import math
import threading
import time
from dataclasses import dataclass, replace

import numpy as np

from .._checks import check_real, shown
from ..curve import Curve, Segment, placed
from ..design import Design, Setup, Start, Unreachable, next_stroke
from ..design.buzz import DENSITY, buzz_times
from ..dynamics import velocity_to_level
from ..errors import ParameterError
from ..formats.json import _plain, json_text
from ..palette.motion import Limits, plan_return, return_time
from ..trajectory import DEFAULT_RATE

LATENCY = 0.05
"""Default lookahead (s): a note arriving now is heard this much later."""

GUARD = 0.006
"""Default time (s) after a note arrives from which it may change the motion: its planning's budget (setpoints
may be given up to a little before that ahead of their time)."""

CLOSEST = 0.03
"""Default shortest time (s) between two notes of one stick: closer ones are dropped before any planning."""

HORIZON = 4.0
"""Default horizon (s): a note heard further ahead of its arrival is dropped (at least the latency): one note an hour
ahead would otherwise hold its stick, refusing every earlier note, for that hour."""

ROWS = 20_000
"""The rows of a performer's log from which it keeps no dropped note (it counts them, :attr:`Performer.unrecorded`);
planned notes are always kept, as a replay needs them (a stick plays at most one note every ``closest`` s). A full
log is a record of about 6-8 MB, written in about a second when a session ends."""

RECORD_BYTES = 40 * 2**20
"""The bytes of the notes' rows of a performer's log (as the record's JSON writes them) from which it plans no more
notes: each later note is dropped, saying the record is full. Planned notes must all be kept for a replay, and with
the dropped notes' :data:`ROWS` and the problems the record stays within the 64 MiB a JSON file may be to be read
again (:func:`drumstroke.live.replay_session`): some 130,000 notes of some 320 bytes (a buzz's row, with its many
impacts, more), half an hour of two sticks each playing as fast as they may (a note every 30 ms), hours of a
dense part."""

STILL = 1e-5
"""rad/s: the largest speed at which a stick is still enough to be held where it is when the performer closes."""

_WARM = set()  # the models a performer of this process has warmed up

AUTO = "auto"
"""The stick a note names when the performer chooses it."""

BUZZ = 0.25
"""Default length (s) of a live buzz note (it cannot know the stick's next note)."""

STROKES = ("auto", "buzz")
"""The strokes a live note may ask for."""


class SystemClock:
    """Seconds since the clock was made (or restarted), from the monotonic clock."""

    def __init__(self):
        self._zero = time.monotonic()

    def now(self):
        return time.monotonic() - self._zero

    def restart(self):
        """Start again from 0 (before anything was stamped with it)."""
        self._zero = time.monotonic()


class ManualClock:
    """A clock that stands still until told: for tests and for replaying a session faster than real time."""

    def __init__(self, t=0.0):
        self._t = float(t)

    def now(self):
        return self._t

    def set(self, t):
        """Move the clock to ``t`` (s), never back."""
        t = check_real("t", t, low=self._t, unit="s (not before the clock's time)")
        self._t = t


@dataclass(frozen=True, slots=True)
class LiveNote:
    """A note as it arrived: when (s, the performer's clock), on which stick, how loud, when it is heard.

    ``stick`` is the stick that plays it (the one chosen, for a note that named none; on a kit, the
    limb); ``cut`` the time from which the planner changed the motion for it (s); ``piece`` the kit's
    piece it is played on and ``key`` the MIDI key it came as (None: the snare, no key).
    """

    arrived: float
    stick: str
    velocity: float
    at: float
    stroke: str = "auto"
    duration: float | None = None
    cut: float = math.nan
    piece: str | None = None
    key: int | None = None


@dataclass(frozen=True, slots=True)
class Outcome:
    """What became of a live note: planned or dropped (with the reason), its stroke, how long planning took (s).

    ``impacts`` are the designed stroke's impacts on its notes, (t s, level dB) each; ``design`` is the
    :class:`~drumstroke.design.Design` itself in the outcome :meth:`Performer.note` returns, and None in
    the performer's log (which a long session would otherwise fill with strokes). ``move`` is a kit
    hand's move to the note's piece (:class:`~drumstroke.live.kit.KitPerformer`): from and to which
    piece, its start and end (s) and each joint's angles there (rad); None when the hand did not move.
    """

    note: LiveNote
    planned: bool
    reason: str = ""
    design: object = None
    compute: float = 0.0
    impacts: tuple = ()
    move: dict | None = None

    def to_dict(self):
        """The outcome as plain values (a session log's row; a kit's note adds its piece, key and move)."""
        note = self.note
        row = {"arrived": note.arrived, "stick": note.stick, "velocity": note.velocity, "at": note.at,
               "stroke": note.stroke, "duration": note.duration, "cut": note.cut, "planned": self.planned,
               "reason": self.reason, "compute": self.compute}
        if note.piece is not None:
            row |= {"piece": note.piece, "key": note.key, "move": self.move}
        if self.planned:
            row["impacts"] = [list(impact) for impact in self.impacts]
        return {key: (None if isinstance(value, float) and not math.isfinite(value) else value)
                for key, value in row.items()}


@dataclass(frozen=True, repr=False)
class Chunk:
    """Setpoints of every stick at consecutive control periods.

    Attributes
    ----------
    t : ndarray [shape=(n,)]
        s, on the performer's clock, k/rate.
    theta, omega, alpha : ndarray [shape=(n, sticks)]
        rad, rad/s, rad/s² (α is the flight acceleration dω/dt, impacts excluded).
    sticks : tuple of str
        The columns' names: the sticks', or on a kit every joint's, ``LIMB.JOINT`` (``right.yaw``).
    impacts : tuple of ndarray
        Each column's impact times (s) in the steps up to its setpoints, from the one before the first (a
        positioning joint's: none); the validation leaves the steps across them unbounded in acceleration
        and jerk (:func:`drumstroke.robot.validate.impact_steps`).
    """

    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    sticks: tuple
    impacts: tuple = ()

    def __len__(self):
        return len(self.t)

    def __repr__(self):
        span = f"{self.t[0]:.6g}-{self.t[-1]:.6g} s" if len(self.t) else "empty"
        return f"Chunk({len(self.t)} setpoints of {', '.join(self.sticks)}, {span})"


@dataclass
class _Stick:
    """One stick's planned motion (a Curve whose last segment holds on forever); how many notes changed it."""

    motion: Curve
    last_note: float = -math.inf
    version: int = 0


class Performer:
    """Notes in, setpoints out: the live runtime on one clock (see the module's description).

    ``note`` and ``setpoints`` may be called from different threads: a note is planned on a copy of
    its stick's motion, outside the lock the setpoints are given under, and committed only if
    nothing it changes has been given meanwhile (else it is dropped, "planned too late").

    Parameters
    ----------
    sticks : sequence of str
        The sticks' names (default right and left).
    setup : Setup, optional
        The model, c, the thumb accelerations the planner may use (m/s²) and the joint's limits, which
        the strokes and the moves both keep (default ``Setup(moves=Limits())``: a strong drumming
        joint, as live moves must be quick; a setup whose moves differ from its limits is refused).
    rate : float in [10, 1e5]
        The control rate (Hz).
    latency : float in (0, 10]
        s between a note's arrival and when it is heard, unless it names its time.
    guard : float in (0, latency)
        s after now from which a new note may change the motion: setpoints up to then may be given
        ahead of their time.
    rest : float
        rad, where the sticks wait before the first note and after :meth:`close` (default 0: level).
    closest : float in [0, 1]
        s, the shortest time between two notes of one stick (default 0.03; closer notes are dropped
        unplanned: a flood costs nothing).
    horizon : float in [latency, 60], optional
        s: a note heard further ahead of its arrival is dropped (default :data:`HORIZON`, or the latency
        if that is longer).
    clock : object with ``now()``, optional
        Default a :class:`SystemClock`; a :class:`ManualClock` runs faster than real time.
    """

    def __init__(self, *, sticks=("right", "left"), setup=None, rate=DEFAULT_RATE, latency=LATENCY, guard=GUARD,
                 rest=0.0, closest=CLOSEST, horizon=None, clock=None):
        setup = Setup(moves=Limits()) if setup is None else setup
        if not isinstance(setup, Setup):
            raise ParameterError(f"setup must be a drumstroke.design.Setup, got {setup!r}")
        if setup.moves != setup.limits:
            raise ParameterError(f"setup.moves must be setup.limits live (a note heard {LATENCY:g} s after it arrives "
                                 f"leaves no time for gentler moves), got {setup.moves!r}")
        sticks = tuple(sticks)
        if not sticks or len(set(sticks)) != len(sticks) or not all(isinstance(s, str) and s for s in sticks) \
                or "auto" in sticks:
            raise ParameterError(f"sticks must be distinct non-empty names other than 'auto', got {sticks!r}")
        self.sticks = sticks
        self.setup = setup
        self.model, self.limits, self.head = setup.model, setup.limits, setup.head
        self.rate = check_real("rate", rate, low=10.0, high=1e5, unit="Hz")
        self.latency = check_real("latency", latency, low=0.0, high=10.0, low_open=True, unit="s")
        self.guard = check_real("guard", guard, low=0.0, high=self.latency, low_open=True, high_open=True, unit="s")
        self.closest = check_real("closest", closest, low=0.0, high=1.0, unit="s")
        horizon = max(HORIZON, self.latency) if horizon is None else horizon
        self.horizon = check_real("horizon", horizon, low=self.latency, high=60.0, unit="s (at least the latency)")
        self.rest = check_real("rest", rest, low=self.head, high=self.limits.theta_high, low_open=True, unit="rad")
        self.clock = clock or SystemClock()
        self.log = []
        self.unrecorded = 0  # dropped notes past the log's ROWS
        self.recorded = 0  # bytes of the log's rows, as the record's JSON writes them
        self.given_up = 0  # planned notes not yet begun when the performer closed
        self.closed = None
        self._sticks = {name: _Stick(Curve.hold(self.rest)) for name in sticks}
        self._next = 0  # the index k of the next setpoint to give, at k/rate
        self._lock = threading.Lock()

    def warm_up(self):
        """Plan a short phrase on a scratch performer with these options: compiled code loaded, caches filled.

        The first stroke a process designs loads the compiled solver (most of a second); a live host
        does this before its clock starts. The phrase is played once per process and model; then the
        process's objects are settled out of the garbage collector's way (:func:`settle`).
        """
        self._rehearse()
        settle()

    def _rehearse(self):
        """The scratch phrase of :meth:`warm_up`, once per process and model."""
        if self.model in _WARM:
            return
        scratch = Performer(sticks=self.sticks[:1], setup=self.setup, rate=self.rate, latency=self.latency,
                            guard=self.guard, rest=self.rest, closest=self.closest, horizon=self.horizon,
                            clock=ManualClock())
        stick = self.sticks[0]
        for arrived, velocity, stroke in ((0.0, 100, "auto"), (0.02, 60, "auto"), (0.3, 127, "auto"),
                                          (0.6, 30, "auto"), (1.0, 90, "buzz")):
            scratch.clock.set(arrived)
            scratch.setpoints(arrived)
            scratch.note(stick, velocity, stroke=stroke)
        scratch.close()
        scratch.setpoints(scratch.done)
        _WARM.add(self.model)

    # --- notes in --------------------------------------------------------------------------------------------------

    def note(self, stick, velocity, *, at=None, stroke="auto", duration=None, arrived=None, cut=None, piece=None,
             key=None):
        """Plan a note heard at ``at`` (s, the clock; default arrival + latency) on ``stick``; return its :class:`Outcome`.

        Parameters
        ----------
        stick : str or None
            One of the performer's sticks, or "auto" (or None): the stick that has waited longest and
            can play it.
        velocity : float in [1, 127]
        at : float, optional
            s on the performer's clock.
        stroke : {"auto", "buzz"}
        duration : float in (0, 10], optional
            s, a buzz's length (default :data:`BUZZ`).
        arrived : float, optional
            s, when the note arrived (default now): a host that queues notes stamps them as they come.
        cut : float, optional
            s: change the motion from this time (a replay gives the logged one); default arrival + guard,
            or the first setpoint not yet given if that is later.
        piece : str, optional
            The piece it is played on: this performer plays the snare (None or "snare"); a
            :class:`~drumstroke.live.kit.KitPerformer` any of its kit's.
        key : int in [0, 127], optional
            The MIDI key it came as (recorded; on a kit, the hi-hat's key says open or closed).
        """
        started = time.perf_counter()
        arrived = self.clock.now() if arrived is None else check_real("arrived", arrived, low=-1e9, high=1e9, unit="s")
        if cut is not None:
            cut = check_real("cut", cut, low=-1e9, high=1e9, unit="s")
        outcome = self._note(arrived, stick, velocity, at, stroke, duration, cut, piece, key)
        impacts = () if outcome.design is None else _heard(outcome.design)
        # made directly, not by dataclasses.replace, which costs a few times as much, at every note
        compute = time.perf_counter() - started
        logged = Outcome(outcome.note, outcome.planned, outcome.reason, None, compute, impacts, outcome.move)
        outcome = Outcome(outcome.note, outcome.planned, outcome.reason, outcome.design, compute, impacts, outcome.move)
        with self._lock:
            if outcome.planned or len(self.log) < ROWS:
                self.log.append(logged)
                self.recorded += _row_bytes(logged)
            else:
                self.unrecorded += 1
        return outcome

    def _note(self, arrived, stick, velocity, at, stroke, duration, cut, piece, key):
        with self._lock:
            given = self._next / self.rate
        cut = max(arrived + self.guard, given) if cut is None else cut
        named = AUTO if stick is None else stick
        note = LiveNote(arrived, named, velocity, arrived + self.latency if at is None else at, stroke, duration, cut,
                        piece, key)
        reason = self._refusal(note)
        if reason:
            return Outcome(note, False, reason)
        if type(velocity) is not float or type(note.at) is not float:  # (made again only to change them)
            note = LiveNote(arrived, named, float(velocity), float(note.at), stroke, duration, cut, piece, key)
        if self.closed is not None:
            return Outcome(note, False, f"the performer closed at {self.closed:.6g} s")
        if self.recorded >= RECORD_BYTES:
            return Outcome(note, False, f"the record is full: its notes take {RECORD_BYTES / 2**20:g} MiB, the most a "
                                        "session keeps (start another session to play on)")
        failure = None
        for name in self._choices(note):
            outcome = self._note_on(note if name == note.stick else replace(note, stick=name))
            if outcome.planned:
                return outcome
            failure = failure or outcome
        return failure

    def _choices(self, note):
        """The sticks to try for a note: the one named, or every stick, the one free longest first."""
        if note.stick != AUTO:
            return [note.stick]
        return sorted(self.sticks, key=lambda name: (self._sticks[name].last_note, self.sticks.index(name)))

    def _note_on(self, note):
        """Plan ``note`` on its stick and commit it, or say why not.

        If the stick's motion changed while it was planned (another note), or the setpoints from its cut
        were given meanwhile (a busy host, a long buzz), it is planned again, from the first setpoint not
        given plus the guard and twice the time planning took.
        """
        stick = self._sticks[note.stick]
        for _ in range(4):
            motion, version, last_note = stick.motion, stick.version, stick.last_note
            if note.at < last_note + max(self.closest, 1e-3):
                when = "not after" if note.at <= last_note else f"less than {self.closest:g} s after"
                return Outcome(note, False, f"heard at {note.at:.6g} s, {when} the {note.stick} stick's last note "
                                            f"at {last_note:.6g} s")
            began = time.perf_counter()
            try:
                new, made, move = self._plan(motion, note)
            except (Unreachable, ParameterError) as error:
                return Outcome(note, False, str(error))
            took = time.perf_counter() - began
            with self._lock:
                if self.closed is not None:
                    return Outcome(note, False, f"the performer closed at {self.closed:.6g} s")
                if stick.version != version:
                    continue
                given = self._next / self.rate
                if given > new.start:
                    late = replace(note, cut=given + self.guard + 2.0 * took)  # room to plan it again
                    if late.at < late.cut + 1e-3:  # the record says the cut it would have needed
                        return Outcome(late, False, f"planned too late: the setpoints up to {given:.6g} s had been "
                                                    "given")
                    note = late
                    continue
                stick.motion = stick.motion.spliced(new)
                stick.last_note = float(made.times[-1])
                stick.version += 1
            return Outcome(note, True, design=made, move=move)
        return Outcome(note, False, "the stick's motion or the setpoints given kept changing while this note was "
                                    "planned")

    def _refusal(self, note):
        """Why a note cannot be taken as given (its values), or ''."""
        reason = self.stick_refusal(note.stick)
        if reason:
            return reason
        if note.stroke not in STROKES:
            return f"stroke must be one of {', '.join(STROKES)}, got {shown(note.stroke)}"
        if note.key is not None and (isinstance(note.key, bool) or not isinstance(note.key, int)
                                     or not 0 <= note.key <= 127):
            return f"key must be a MIDI key, an integer in [0, 127], got {shown(note.key)}"
        reason = self._piece_refusal(note)
        if reason:
            return reason
        velocity, at = note.velocity, note.at
        if not ((type(velocity) is float or type(velocity) is int) and 1.0 <= velocity <= 127.0  # the usual note
                and type(at) is float and -1e9 <= at <= 1e9 and note.duration is None):
            for name, value, low, high in (("velocity", velocity, 1.0, 127.0), ("at", at, -1e9, 1e9),
                                           ("duration", note.duration, 0.0, 10.0)):
                if value is None and name == "duration":
                    continue
                if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                        or not low <= value <= high or (name == "duration" and value == 0.0):
                    return f"{name} must be a finite number in [{low:g}, {high:g}], got {value!r}"
        if note.duration is not None and note.stroke != "buzz":
            return "only a buzz has a duration"
        if note.at > note.arrived + self.horizon:
            return (f"heard at {note.at:.6g} s, {note.at - note.arrived:.6g} s after it arrived: further ahead than "
                    f"the horizon, {self.horizon:g} s")
        if note.at < note.cut + 1e-3:
            return f"heard at {note.at:.6g} s, too soon: the motion may change from {note.cut:.6g} s"
        return ""

    def stick_refusal(self, stick):
        """Why ``stick`` is not one this performer's notes may name (its sticks, or "auto"), or ''."""
        if not isinstance(stick, str) or (stick not in self._sticks and stick != AUTO):
            return f"stick must be one of {', '.join(self.sticks + (AUTO,))}, got {shown(stick)}"
        return ""

    def _piece_refusal(self, note):
        """Why the note's piece is not this performer's (it plays the snare), or ''."""
        if note.piece not in (None, "snare"):
            return (f"piece must be snare: this performer plays the snare (drumstroke live --kit plays a kit's "
                    f"pieces), got {shown(note.piece)}")
        return ""

    def _plan(self, motion, note):
        """The motion that plays ``note`` from its cut on (a Curve), the design and the move to its piece (None);
        raises Unreachable when none can."""
        made, start, moves = self._stroke(note, self.setup, motion.last(Design), motion.state)
        return _played(made, start, moves), made, None

    def _stroke(self, note, setup, last, state):
        """The stroke that plays ``note`` on ``setup``'s surface after the stroke segment ``last`` (or None), the
        stick's θ and ω at a time being ``state(t)``: (design, when its motion starts (s), the moves before it)."""
        times = self._times(note)
        level = velocity_to_level(note.velocity)
        levels = np.full(len(times), level) if len(times) > 1 else np.array([level])  # (np.full costs more)
        cut, running = note.cut, None
        if last is not None:
            made = last.source
            n = len(made.times)
            # the design's impacts on the notes' timeline (Design.impacts makes them all afresh at each use)
            impacts = made.stroke.impacts
            heard = float(impacts.t[n - 1] + made.release)
            if heard >= cut:  # its last planned impact is still to come: bounce on from it
                running = Start(heard, setup.head, setup.cor * float(-impacts.omega[n - 1]))
            else:
                theta, omega = state(cut)
                if omega > 1e-9:  # its rebound still rises
                    running = Start(cut, theta, omega)
        free = max(cut, last.end if last is not None and math.isfinite(last.end) else cut)
        theta, omega = state(free)
        made, moves = next_stroke(times, levels, setup, free=free, theta=theta, omega=omega, running=running)
        start = running.t if running is not None and made.release <= running.t + 1e-9 else free
        return made, start, moves

    @staticmethod
    def _times(note):
        """The impact times (s) a note asks for: one, or a buzz's bounces."""
        if note.stroke == "buzz":
            return buzz_times(note.at, note.at + (note.duration or BUZZ), DENSITY)
        return np.array([note.at])

    # --- the end ---------------------------------------------------------------------------------------------------

    def close(self, cut=None):
        """Take no more notes and stop soon: each stick finishes the stroke in progress up to the apex of its next
        rebound (or where it is still), the notes not yet begun given up (:attr:`given_up` counts them), then moves
        to ``rest``. Returns when all rest (s).

        ``cut`` (s) is when the performer closed (default now + guard, or the first setpoint not yet
        given if later; a replay gives the logged one).
        """
        if cut is not None:
            cut = check_real("cut", cut, low=-1e9, high=1e9, unit="s")
        with self._lock:
            given = self._next / self.rate
            cut = max(self.clock.now() + self.guard, given) if cut is None else cut
            if self.closed is not None:
                return self.done
            held = {}
            for name, stick in self._sticks.items():
                held[name] = _still_from(stick.motion, cut)
                motion = stick.motion.spliced(Segment.hold(stick.motion.state(held[name])[0], held[name]))
                home = self._home(name, motion, held[name])
                stick.motion = motion if home is None else motion.spliced(home)
            self.given_up = sum(o.planned and o.note.at > held[o.note.stick] for o in self.log)
            self.closed = cut  # last: a thread that sees it closed sees the moves to rest
            return self.done

    def _home(self, stick, motion, start):
        """The motion (a Curve) that takes ``stick`` from ``start`` (s, where it finished) to rest, or None if it is there."""
        theta, omega = motion.state(start)
        target = (self.rest, 0.0)
        window = return_time((theta, omega), target, self.head, self.limits)
        moves = plan_return((theta, omega), target, window, self.head, self.limits) if window > 0 else []
        if not moves:
            return None
        home = Curve.sequence(moves, start)
        return home.spliced(Segment.hold(self.rest, home.end))

    @property
    def done(self):
        """s: from when every stick holds still (its last piece's start)."""
        return max(stick.motion.segments[-1].start for stick in list(self._sticks.values()))

    # --- setpoints out ---------------------------------------------------------------------------------------------

    def setpoints(self, until=None):
        """Every setpoint from the last one given up to ``until`` (s, the clock; default now), as a :class:`Chunk`.

        ``until`` may be up to ``guard`` ahead of now: no note changes those any more.
        """
        until = self.clock.now() if until is None else check_real("until", until, low=-1e9, high=1e9, unit="s")
        with self._lock:
            stop = math.floor(float(until) * self.rate + 1e-9) + 1
            k = np.arange(self._next, max(stop, self._next))
            self._next = max(stop, self._next)
            snapshot = [self._sticks[name].motion for name in self.sticks]
            sent = self.sent
            for stick in self._sticks.values():  # what is given no longer changes: forget it
                stick.motion = stick.motion.since(sent)
        t = k / self.rate
        columns = [motion.evaluate(t) for motion in snapshot]  # a kit's hand gives every joint of it at once
        return Chunk(t, *(np.column_stack([c[i] for c in columns]) if len(t) else np.empty((0, len(self.columns)))
                          for i in range(3)), self.columns, self._strikes(snapshot, t))

    def _strikes(self, motions, t):
        """Each column's impact times (s) from one period before ``t[0]`` to ``t[-1]``: here a stick's, its motion's."""
        if not len(t):
            return tuple(np.empty(0) for _ in self.columns)
        low, high = t[0] - 1.0 / self.rate, t[-1]
        return tuple(times[(times >= low) & (times <= high)] for times in (motion.impacts for motion in motions))

    @property
    def columns(self):
        """The setpoints' columns (a :class:`Chunk`'s ``sticks``): here the sticks' names."""
        return self.sticks

    def checks(self):
        """Each column's (head, Limits) that its setpoints are validated against (rad; the runtime checks them)."""
        return [(self.head, self.limits)] * len(self.sticks)

    def options(self):
        """The performer's options as plain values (a session's record; :func:`~drumstroke.live.replay_session`
        makes the performer again from them)."""
        forces = self.setup.forces
        return {"model": self.model, "rate": self.rate, "latency": self.latency, "guard": self.guard,
                "closest": self.closest, "horizon": self.horizon, "sticks": list(self.sticks), "rest": self.rest, "cor": self.setup.cor,
                "forces": {"low": forces.low, "high": forces.high}, "limits": self.limits.to_dict()}

    @property
    def sent(self):
        """s: the time of the last setpoint given (−1/rate before the first)."""
        return (self._next - 1) / self.rate

    # --- replay ----------------------------------------------------------------------------------------------------

    @classmethod
    def replay(cls, log, *, until, closed=None, **options):
        """The setpoints an offline performer gives for the notes of ``log`` (a session's), up to ``until`` (s).

        Every note planned in the session is given again at the time it arrived, on the stick that
        played it and with the cut it was planned from (the notes dropped changed nothing); ``closed``
        is when the session closed, if it did. The setpoints equal those of the session, sample for sample.
        """
        clock = ManualClock()
        performer = cls(clock=clock, **options)
        for outcome in sorted((o for o in log if o.planned), key=lambda o: o.note.arrived):
            note = outcome.note
            clock.set(max(note.arrived, clock.now()))
            again = performer.note(note.stick, note.velocity, at=note.at, stroke=note.stroke, duration=note.duration,
                                   cut=note.cut, piece=note.piece, key=note.key)
            if not again.planned:
                raise ParameterError(f"the log's note at {note.at:.6g} s on {note.stick} was planned in the session "
                                     f"but not in its replay: {again.reason} (a log of other options?)")
        if closed is not None:
            performer.close(closed)
        return performer.setpoints(until)


def _heard(made):
    """The impacts of a design (a stroke's, a kit's press) on its notes: (t s, level dB) each (a stroke's as its check
    found them; a press's made once: a design makes them afresh at each use)."""
    if type(made) is Design:
        return made.heard
    impacts, n = made.impacts, len(made.times)
    return tuple(zip(impacts.t[:n].tolist(), impacts.level_db[:n].tolist()))


def _row_bytes(outcome):
    """``_json_bytes(outcome.to_dict())``, the bytes of a log's row, from the row's frame and its values' text.

    At every note: making the row's dict and encoding it cost several times the values' reprs. A row of plain values
    (a snare's note whose fields are floats and strings, its impacts finite) is counted here: json writes a float as
    its repr, a string as ``encode_basestring_ascii`` does, a top-level float that is not finite as null (the row's
    own rule); any other row is made and encoded.
    """
    note, impacts = outcome.note, outcome.impacts
    duration = note.duration
    if note.piece is not None or type(note.stick) is not str or type(note.stroke) is not str \
            or type(outcome.reason) is not str or type(note.arrived) is not float or type(note.velocity) is not float \
            or type(note.at) is not float or type(note.cut) is not float or type(outcome.compute) is not float \
            or (duration is not None and type(duration) is not float):
        return _json_bytes(outcome.to_dict())
    if outcome.planned:  # true, and the impacts' frame
        n = len(impacts)
        total = _FRAME + 4 + (_IMPACTS[0] if n == 0 else _IMPACTS[1] + _IMPACTS[2] * (n - 1))
    else:  # false
        total = _FRAME_DROPPED + 5
    for value in (note.arrived, note.velocity, note.at, note.cut, outcome.compute, duration):
        if value is None:
            total += 4
        else:
            total += len(repr(value)) if value - value == 0.0 else 4  # not finite: null
    total += len(_string(note.stick)) + len(_string(note.stroke)) + len(_string(outcome.reason))
    if outcome.planned:
        for impact in impacts:
            if len(impact) != 2:
                return _json_bytes(outcome.to_dict())
            for value in impact:
                if type(value) is not float or value - value != 0.0:  # json writes NaN, Infinity here
                    return _json_bytes(outcome.to_dict())
                total += len(repr(value))
    return total


_string = json.encoder.encode_basestring_ascii
"""A string as json's encoder writes it (ASCII, escaped, quoted)."""

_ROW = ("arrived", "stick", "velocity", "at", "stroke", "duration", "cut", "planned", "reason", "compute")
"""A snare note's row's keys (:meth:`Outcome.to_dict`), in order; a planned one's impacts follow."""

_FRAME = len(json_text(dict.fromkeys(_ROW + ("impacts",), 0))) - len(_ROW) - 1
"""The characters of a planned row's text (json_text's) other than its values' (each 0 in the frame)."""

_FRAME_DROPPED = len(json_text(dict.fromkeys(_ROW, 0))) - len(_ROW)
"""The same of a dropped note's row, which has no impacts."""


def _impacts_frame(n):
    """The characters of the text of ``n`` impacts in a row (json_text's, nested at the row's depth) other than the
    numbers' (each 0 in the frame)."""
    return len(json_text({"impacts": [[0, 0]] * n})) - len(json_text({"impacts": 0})) + 1 - 2 * n


_IMPACTS = _impacts_frame(0), _impacts_frame(1), _impacts_frame(2) - _impacts_frame(1)
"""The frame of no impacts ("[]"), of one, and what each further one adds (the text grows by the same for each)."""


def _json_bytes(row):
    """``len(json_text(row))``, the bytes of a log's row as the record's JSON writes it, from json's compiled encoder.

    ``json_text`` indents, which json does in Python only, with closures that refer to each other: some 30
    objects a note that only the garbage collector frees. The indentation is counted instead.
    """
    return len(_COMPACT.encode(row)) + 1 + _indents(row, 1)


_COMPACT = json.JSONEncoder(separators=(",", ": "), default=_plain)
"""json's compiled encoder writing json_text's tokens without its indentation."""


def _indents(value, depth):
    """The characters one-space indentation puts in ``value``'s JSON at ``depth``: a newline and ``depth`` spaces
    before each member of a non-empty list or object, a newline and ``depth`` − 1 spaces before its close."""
    if isinstance(value, dict):
        members = value.values()
    elif isinstance(value, (list, tuple)):
        members = value
    elif isinstance(value, _SCALARS) or not hasattr(value, "tolist"):
        return 0
    else:  # numpy's values, as json_text writes them
        return _indents(value.tolist(), depth)
    if not members:
        return 0
    total = len(members) * (1 + depth) + depth
    for member in members:  # a loop, not a generator: at every note
        if not isinstance(member, _SCALARS):
            total += _indents(member, depth + 1)
    return total


_SCALARS = (str, int, float, type(None))


def settle():
    """Collect the process's garbage, then freeze every object left out of later collections (``gc.freeze``).

    A full collection scans every object of the process: with numba's and numpy's loaded, 35-50 ms, which
    falls in whichever note it interrupts. Frozen before a performance, those objects are never scanned
    again; the collector's pauses are then those of the objects the performance makes. A live host calls
    it (through :meth:`Performer.warm_up`, and :class:`~drumstroke.live.Runtime` as it starts) before its
    clock starts.
    """
    gc.collect()
    gc.freeze()


def _still_from(motion, cut):
    """The first time (s) from ``cut`` at which ``motion`` may be held where it is, found where it can be still (ω
    within :data:`STILL` of 0): at the cut, at each apex of a designed stroke's rebounds, where a segment ends (a move
    ends at rest, a stroke caught or pressed to rest). Holding there is a catch, as at the end of every stroke."""
    for segment in motion.segments:
        if segment.end < cut:
            continue
        first = max(cut, segment.start)
        times = [first, segment.end]
        if isinstance(segment.source, Design):
            made = segment.source
            times += [made.release + piece.end for piece in made.pieces if piece.phase in ("rise", "end")]
        for t in sorted(t for t in times if first <= t <= segment.end and math.isfinite(t)):
            if np.max(np.abs(motion.state(t)[1])) <= STILL:
                return t
    return max(cut, motion.segments[-1].start)  # the last segment holds still


def _played(made, start, moves):
    """The motion from ``start`` (s): the moves (or the stick held until the release), the designed stroke, then the
    stick held where the stroke caught it."""
    stroke = made.stroke
    lead_in = placed(moves, start) if moves else (
        (Segment.hold(float(made.recipe.theta0), start, made.release),) if made.release > start else ())
    t_end = made.t_end
    played = Segment._of(made.release, t_end, stroke.arcs.evaluate, made.release, stroke.impacts.t, made)
    return Curve((*lead_in, played, Segment.hold(made.ends[1][0], t_end)))
