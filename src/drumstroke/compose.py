"""Composition: a score becomes one continuous motor-angle trajectory per stick.

For each note the library stroke is set to the note's velocity and placed so
that its first impact lands exactly on the note's time; between strokes the
stick returns smoothly to the next stroke's start angle (quintic moves within
:data:`~drumstroke.palette.motion.RETURN_LIMITS` by default, never below the head); a stroke that
cannot finish before the next one must start is cut at the top of a rebound
(an apex, where the stick stands still), the latest that leaves time for the
return. A note that comes too soon after the previous one on the same stick,
even when that stroke is cut at its first rebound, is left out and reported in
:attr:`Composition.problems` — never dropped silently.

Velocity sets the level of the stroke's first impact: the stroke's excursion
above the head is scaled (:func:`~drumstroke.palette.compress`) by
``10 ** ((velocity_to_level(v) − L₀) / 20)``, where L₀ is the first impact's
level in the library, so the first impact's tip speed is exactly the
velocity's level (:mod:`drumstroke.dynamics`): monotonic in velocity, and a
louder note starts from higher up, as a drummer's does. A velocity whose
stroke would pass upright is played as loud as the stick can go, and reported.

Examples
--------
>>> import tempfile
>>> from drumstroke.palette.library import build_library, read_palette
>>> from drumstroke.score import parse_pattern
>>> library = build_library(tempfile.mkdtemp(), palette=[e for e in read_palette() if e.name == "single"])
>>> piece = compose(parse_pattern("tempo 120\\n0 single 100\\n1 single 64\\n"), library)
>>> [round(float(t - piece.offset), 9) for t in piece.sticks["right"].impacts.t]
[0.0, 0.5]
>>> piece.problems
()
"""

import itertools
import math
from dataclasses import dataclass, field, replace

import numpy as np

from ._checks import check_real
from .budget import check_memory, check_time, csv_seconds, values_bytes
from .design import Setup, Target, assign_sticks, plan_stick
from .design.chain import MIN_GAP
from .dynamics import level_to_velocity, velocity_to_level
from .errors import ParameterError
from .formats.midi import TempoMap
from .palette.motion import assemble, plan_return, return_time
from .palette.transforms import compress, compress_limit, trim
from .recipe import T_END_LIMIT
from .score import PLANNED, Score, ScoreNote
from .trajectory import DEFAULT_RATE, THETA_TOP, Trajectory

HOLD_AFTER = 0.25
"""Time (s) the stick holds still at the end of a composition, after its last return."""

HITS = {"single stroke": 1, "double stroke": 2, "triple stroke": 3}
"""How many of a library stroke's first impacts are its notes, by its category: a double's two, a triple's
three (a buzz's bounces are not notes). A stroke cut before one of them is a problem."""


@dataclass(frozen=True)
class Placement:
    """What became of one note.

    Attributes
    ----------
    note : ScoreNote
    played : bool
        False when it was left out (see the problems).
    start : float
        When its stroke starts on the composition's timeline (s).
    impact : float
        When its first impact lands (s): the note's time plus the offset.
    factor : float
        The compress factor its velocity asked for (1 = as in the library).
    cut : float or None
        Where the stroke was cut (s, its own time), or None if played to its end.
    """

    note: ScoreNote
    played: bool
    start: float = math.nan
    impact: float = math.nan
    factor: float = math.nan
    cut: float | None = None


@dataclass(frozen=True, repr=False)
class Composition:
    """A composed piece: one trajectory of all its sticks, and what became of each note.

    Attributes
    ----------
    trajectory : Trajectory
        Every stick on one timeline from 0 to the same end, continuous in θ and ω, at the
        control rate.
    offset : float
        Where the score's time 0 is on the timeline (s): room for the first
        stroke's downstroke before its note.
    placements : tuple of Placement
        One per note, in time order.
    problems : tuple of str
        Notes left out (with why, and the nearest time and level that can be played), velocities out of
        reach, library strokes cut before their hits.
    tempo_map : TempoMap
        The score's tempo changes and time signatures (its MIDI file's, or its pattern's tempo and
        meter; 120 bpm in 4/4 for notes given without one), on the score's time.
    designs : tuple of (str, Design)
        The strokes the planner designed, with their sticks, on the score's time (:mod:`drumstroke.design`).
    """

    trajectory: Trajectory
    offset: float
    placements: tuple
    problems: tuple
    tempo_map: TempoMap = field(default_factory=TempoMap)
    designs: tuple = ()

    def __repr__(self):
        sticks = ", ".join(f"{name} {len(s.impacts)}" for name, s in self.sticks.items())
        played = sum(p.played for p in self.placements)
        return (f"Composition(model={self.model!r}, {played} of {len(self.placements)} notes played, "
                f"{self.t_end:g} s at {self.rate:g} Hz, score time 0 at {self.offset:g} s; impacts: {sticks})")

    @property
    def sticks(self):
        """Each stick's one-stick trajectory, by name: ``{stick: Trajectory}``."""
        return {name: self.trajectory.stick(name) for name in self.trajectory.sticks}

    @property
    def rate(self):
        """The control rate (Hz)."""
        return self.trajectory.rate

    @property
    def model(self):
        """The model that made the strokes ("mixed" if more than one)."""
        return self.trajectory.model

    @property
    def t_end(self):
        """Duration (s)."""
        return self.trajectory.t_end

    def sample(self, rate=None):
        """Times (s) and, per stick, (θ rad, ω rad/s) at ``rate`` (Hz; default the composition's)."""
        trajectory = self.trajectory.sample(rate)
        return trajectory.t, {name: (part.theta, part.omega) for name, part in
                              ((n, trajectory.stick(n)) for n in trajectory.sticks)}

    def impacts(self):
        """All impacts of all sticks in time order: times (s), tip speeds (m/s) and levels (dB re 1 m/s)."""
        motions = self.trajectory.motions
        t, speed, level = (np.concatenate([getattr(m.impacts, key) for m in motions])
                           for key in ("t", "tip_speed", "level_db"))
        order = np.argsort(t, kind="stable")
        return t[order], speed[order], level[order]

    def stick_impacts(self):
        """Each stick's impacts on the score's time, and which of them are a stroke's first impact.

        Returns
        -------
        dict
            ``{stick: (t, level_db, first)}``: times (s from the score's time 0, so a note's first
            impact is at its time), levels (dB re 1 m/s) and booleans [each shape=(n,)].
        """
        result = {}
        for name, stick in self.sticks.items():
            t = np.maximum(stick.impacts.t - self.offset, 0.0)  # round-off below the score's time 0
            first = np.zeros(t.size, dtype=bool)
            landed = np.array([p.impact - self.offset for p in self.placements if p.played and p.note.stick == name])
            if landed.size:  # each played note's first impact is the impact nearest its time
                after = np.minimum(np.searchsorted(t, landed), t.size - 1)
                before = np.maximum(after - 1, 0)
                first[np.where(np.abs(t[before] - landed) <= np.abs(t[after] - landed), before, after)] = True
            result[name] = (t, stick.impacts.level_db, first)
        return result


def compose(notes, library=None, *, setup=None, rate=None, sticks=2, progress=None):
    """Compose ``notes`` into one trajectory per stick: library strokes placed, ``auto`` and ``buzz`` notes designed.

    Every note becomes a candidate span on its stick: a library stroke at the note's velocity (with
    the apexes it may be cut at), or a stroke the planner designed (a chain of notes bouncing on,
    caught after its last). One pass places each stick's spans in time order: a span plays when the
    stick can reach its start from the span before it (that one cut at its latest apex that leaves
    time for the move), and is left out, reported, when it cannot.

    Parameters
    ----------
    notes : Score or sequence of ScoreNote
        At least one note. A note's stroke is a library stroke's name, or ``"auto"``/``"buzz"``
        for the planner (:mod:`drumstroke.design`); a note whose stick is None gets one from the
        planner (:func:`~drumstroke.design.assign_sticks`). A :class:`~drumstroke.score.Score`
        (what :func:`~drumstroke.score.read_score` returns) brings its tempo map along.
    library : drumstroke.palette.library.Library or None
        Needed for notes that name library strokes.
    setup : Setup or None
        The model the planner designs with, c, the thumb accelerations it may use (m/s²), the
        joint's limits the designed strokes keep, and the budget of every move between strokes
        (default ``Setup()``: moves within :data:`~drumstroke.palette.motion.RETURN_LIMITS`).
    rate : float in [1, 100000] or None
        Control rate (Hz) of the result; default the library's (without one, 1000).
    sticks : {1, 2}
        How many sticks the planner may give the notes without one.
    progress : callable or None
        Called with the fraction done (0 to 1) as the notes are placed and the sticks assembled.

    Returns
    -------
    Composition
    """
    setup = Setup() if setup is None else setup
    if not isinstance(setup, Setup):
        raise ParameterError(f"setup must be a drumstroke.design.Setup, got {setup!r}")
    tempo_map = notes.tempo_map if isinstance(notes, Score) else TempoMap()
    notes = _checked(notes, library)
    rate = (library.rate if library is not None else DEFAULT_RATE) if rate is None else check_real(
        "rate", rate, low=1.0, high=1e5, unit="Hz")
    notes = _with_sticks(sorted(notes, key=lambda n: n.time), sticks)
    step = _Progress(progress, 2 * len(notes))
    variants, problems = {}, []
    for note in notes:
        key = (note.stroke, note.velocity)
        if note.stroke not in PLANNED and key not in variants:
            stroke, factor, problem = _at_velocity(library[note.stroke].trajectory, note, setup)
            variants[key] = _Variant(stroke, factor)
            problems += [problem] if problem else []
    by_stick = {}
    for note in notes:
        by_stick.setdefault(note.stick, []).append(note)
    spans = {stick: _spans(stick_notes, variants, setup, rate, step) for stick, stick_notes in by_stick.items()}
    for stick_spans in spans.values():
        problems += [problem for span in stick_spans for problem in span.problems]
    offset = _offset(spans, setup, rate)
    placed = {stick: _place(stick_spans, offset, setup) for stick, stick_spans in spans.items()}
    for stick_placed in placed.values():
        problems += [problem for _, problem in stick_placed if problem]
        problems += [problem for span, _ in stick_placed if span.played for problem in _cut_short(span, library)]
    ends = [_finish(stick_placed, setup) for stick_placed in placed.values()
            if any(span.played for span, _ in stick_placed)]
    if not ends:
        raise ParameterError("no note could be played: " + "; ".join(problems[:3]))
    end = max(ends) + HOLD_AFTER
    if not math.isfinite(end):
        raise ParameterError(f"the last stroke cannot return to its start angle within {setup.moves}")
    assembled = {}
    for stick, stick_placed in placed.items():
        played = [span for span, _ in stick_placed if span.played]
        if played:
            pieces = [trim(span.stroke, 0.0, span.cut) if span.cut is not None else span.stroke for span in played]
            assembled[stick] = assemble(pieces, [span.start for span in played], limits=setup.moves, end=end,
                                        name=f"composition ({stick} stick)",
                                        home=played[-1].design is None).sample(rate)
        step(sum(len(span.notes) for span, _ in stick_placed))
    placements = sorted((p for stick_placed in placed.values() for span, _ in stick_placed for p in span.placements()),
                        key=lambda p: p.note.time)
    trajectory = Trajectory.from_sticks(assembled, name=f"composition of {len(placements)} notes",
                                        history=(f"compose {len(placements)} notes",))
    designs = tuple((stick, span.design) for stick, stick_placed in placed.items() for span, _ in stick_placed
                    if span.design is not None and span.played)
    return Composition(trajectory, offset, tuple(placements), tuple(problems), tempo_map, designs)


def rudiment_score(name, tempo, *, bars=2):
    """A PAS rudiment (:mod:`drumstroke.palette.rudiments`) at ``tempo`` bpm for ``bars`` bars, as a Score to compose.

    Its notes are ``auto`` and ``buzz`` notes on the sticks the rudiment names, its tempo map the tempo
    in 4/4; a note's source names the rudiment, the note and its stick.

    Returns
    -------
    Score, RudimentNotes
        The score, and the rudiment's notes at the tempo (with ``in_range`` and ``warning`` for a tempo
        outside the rudiment's range).
    """
    from .palette.rudiments import rudiment
    from .score import ScoreReport

    played = rudiment(name).notes_at(tempo, bars=bars)
    notes = tuple(ScoreNote(n.time, n.kind, n.velocity, n.stick, source=f"{played.rudiment} note {k} ({n.stick})",
                            duration=n.duration if n.kind == "buzz" else None,
                            beat=(n.time - played.downbeat) * tempo / 60.0 if n.time >= played.downbeat else None)
                  for k, n in enumerate(played.notes))
    report = ScoreReport(f"{played.rudiment} at {tempo:g} bpm", {("played", None): len(notes)})
    return Score(notes, TempoMap.constant(tempo), report), played


def _with_sticks(notes, sticks):
    """The notes with a stick each: those without one get the planner's (the others keep theirs)."""
    if all(note.stick is not None for note in notes):
        return notes
    chosen = assign_sticks([n.time for n in notes], beats=[n.beat if n.beat is not None else 0.5 for n in notes],
                           given=[n.stick for n in notes], sticks=sticks)
    return [note if note.stick is not None else replace(note, stick=stick) for note, stick in zip(notes, chosen)]


class _Progress:
    """The fraction done, reported as steps are done: placing a note is one step, assembling it into its stick
    another."""

    def __init__(self, report, total):
        self.report, self.total, self.done = report, total, 0

    def __call__(self, count):
        self.done += count
        if self.report is not None:
            self.report(self.done / self.total)


def _checked(notes, library):
    notes = list(notes.notes if isinstance(notes, Score) else notes)
    if not notes:
        raise ParameterError("notes must hold at least one note")
    for note in notes:
        if not isinstance(note, ScoreNote):
            raise ParameterError(f"notes must be ScoreNote objects, got {note!r}")
        if note.stroke not in PLANNED and (library is None or note.stroke not in library):
            strokes = f"the library has {', '.join(library)}" if library is not None else "no library was given"
            raise ParameterError(f"{note.source or 'note'}: stroke {note.stroke!r} is not auto, buzz or a library "
                                 f"stroke; {strokes}")
    last = max(note.time for note in notes)
    if last > T_END_LIMIT:  # found before any work: a song too long to compose fails at once
        note = max(notes, key=lambda n: n.time)
        raise ParameterError(f"{note.source or 'note'}: time must be at most {T_END_LIMIT:g} s (a composition "
                             f"lasts at most an hour), got {last:.6g} s")
    return notes


class _Span:
    """A candidate on one stick: a library stroke for one note, or a designed stroke for a chain of notes.

    It starts ``lead`` s before ``at`` (s, the score's time: its note's for a library stroke, whose first
    impact is ``lead`` s into it; its release for a design); ``start`` is where it starts on the
    composition's time once placed. ``cuts`` are where the stroke may end (its own time, s, latest
    first), ``cut`` where it was cut (None: played to its end), ``played`` whether it plays.
    """

    def __init__(self, notes, stroke, at, *, lead=0.0, cuts=(), factor=1.0, design=None, problems=()):
        self.notes, self.stroke, self.at, self.lead, self.cuts = notes, stroke, at, lead, list(cuts)
        self.factor, self.design, self.problems = factor, design, tuple(problems)
        self.start, self.cut, self.played = math.nan, None, True
        self._states = {}

    def place(self, offset):
        self.offset, self.start = offset, offset + self.at - self.lead

    @property
    def first(self):
        return self.notes[0]

    def state(self, t):
        """(θ rad, ω rad/s) at ``t`` (s, its own time)."""
        if t not in self._states:
            theta, omega = self.stroke.path(np.array([t]))
            self._states[t] = float(theta[0]), float(omega[0])
        return self._states[t]

    @property
    def length(self):
        """s: how long it plays (to its cut)."""
        return self.cut if self.cut is not None else self.stroke.t_end

    def placements(self):
        if self.design is None:
            note = self.first
            if not self.played:
                return [Placement(note, False, factor=self.factor)]
            return [Placement(note, True, self.start, self.start + self.lead, self.factor, self.cut)]
        return [Placement(note, True, self.start, self.offset + note.time, 1.0) if self.played
                else Placement(note, False, factor=1.0) for note in self.notes]


def _check_apart(wanted):
    """Refuse a stick's planned notes closer than the planner takes, naming the notes (a score's file and line)."""
    for before, note in itertools.pairwise(wanted):
        if note.time - before.time < MIN_GAP:
            raise ParameterError(f"{note.source or 'note'}: a planned note {1e3 * (note.time - before.time):g} ms after "
                                 f"{before.source or 'the note before'} on the same stick; the planner's notes on a "
                                 f"stick must be at least {1e3 * MIN_GAP:g} ms apart")


def _check_one_span_a_note(plan, wanted):
    """Refuse a note the planner played as several strokes (a buzz too quiet to press: its bounces each a stroke of
    their own, with no note of theirs), which a span of the composition cannot hold."""
    held = None
    for keys in plan.keys:
        if keys:
            held = wanted[keys[-1]]
            continue
        note = held or wanted[0]
        strokes = sum(1 for k in plan.keys if not k) + 1
        raise ParameterError(f"{note.source or 'note'}: a {note.stroke} at velocity {note.velocity:g} is played as "
                             f"{strokes} strokes of a bounce each, which a composition cannot place yet: give it a "
                             "higher velocity (a buzz of velocity 60 is one stroke)")


def _spans(notes, variants, setup, rate, step):
    """A stick's candidate spans in time order: library strokes and the planner's designs of its other notes.

    The designs' notes the planner could not play are left out here, with its reasons."""
    spans = []
    for note in notes:
        if note.stroke not in PLANNED:
            variant = variants[(note.stroke, note.velocity)]
            spans.append(_Span([note], variant.stroke, note.time, lead=float(variant.stroke.impacts.t[0]),
                               cuts=variant.cuts, factor=variant.factor))
            step(1)
    wanted = [n for n in notes if n.stroke in PLANNED]
    _check_apart(wanted)
    if wanted:
        targets = [Target.from_velocity(n.time, n.velocity, kind=n.stroke, duration=n.duration, key=k)
                   for k, n in enumerate(wanted)]
        plan = plan_stick(targets, setup=setup)
        step(len(wanted))
        _check_one_span_a_note(plan, wanted)
        for made, keys in zip(plan.designs, plan.keys):
            stroke = Trajectory.from_stroke(made.stroke, rate=rate, name="designed")
            spans.append(_Span([wanted[k] for k in keys], stroke, made.release, cuts=[stroke.t_end], design=made))
        for problem in plan.problems:
            note = wanted[problem.key]
            left_out = _Span([note], None, note.time,
                             problems=[f"{note.source or 'note'}: {problem.reason}; left out"])
            left_out.played = False
            spans.append(left_out)
    return sorted(spans, key=lambda span: span.first.time)


def _offset(spans, setup, rate):
    """The lead (s) before the score's time 0 so every stick's first stroke fits, on the control grid."""
    need = 0.0
    for stick_spans in spans.values():
        first = next((span for span in stick_spans if span.played), None)
        if first is None:
            continue
        theta, omega = first.state(0.0)
        wind = return_time((theta, 0.0), (theta, omega), first.stroke.theta_max, setup.moves) if first.design is None else 0.0
        need = max(need, first.lead + wind - first.at)
    return math.ceil(need * rate - 1e-9) / rate if need > 0 else 0.0


def _place(spans, offset, setup):
    """One stick's spans placed in time order, each played or left out: [(span, problem or '')].

    A span plays when the stick can move from the span before it (cut at its latest apex that leaves time
    for the move) to its start; the last plays on until it settles, or until its latest apex the stick can
    leave for home."""
    placed, previous = [], None
    for span in spans:
        if not span.played:  # the planner could not play it; its problem is its own
            placed.append((span, ""))
            continue
        span.place(offset)
        if previous is not None:
            cut = _latest_cut(previous, span, setup)
            if cut is None:
                need = _earliest_start(previous, span, setup) - span.start
                note, before = span.first, previous.first
                span.played = False
                placed.append((span, (f"{note.source}: {note.stroke!r} on the {note.stick} stick comes "
                                     f"{need * 1e3:.0f} ms too soon after {before.stroke!r} at {before.time:.6g} s; "
                                     "left out")))
                continue
            previous.cut = cut if cut < previous.stroke.t_end else None
        placed.append((span, ""))
        previous = span
    if previous is not None and previous.design is None:
        home = (previous.state(0.0)[0], 0.0)
        head = previous.stroke.theta_max
        cut = next((c for c in previous.cuts if math.isfinite(return_time(previous.state(c), home, head, setup.moves))),
                   previous.cuts[-1])
        previous.cut = cut if cut < previous.stroke.t_end else None
    return placed


def _latest_cut(span, following, setup):
    target = following.state(0.0)
    for cut in span.cuts:
        window = following.start - (span.start + cut)
        if window >= -1e-9 and plan_return(span.state(cut), target, window, span.stroke.theta_max, setup.moves) is not None:
            return cut
    return None


def _earliest_start(span, following, setup):
    cut = span.cuts[-1]
    return span.start + cut + return_time(span.state(cut), following.state(0.0), span.stroke.theta_max, setup.moves)


def _finish(placed, setup):
    """When the stick is done after its last stroke (s): home at its start angle after a library stroke, caught
    after a designed one."""
    last = [span for span, _ in placed if span.played][-1]
    if last.design is not None:
        return last.offset + last.design.t_end
    home = (last.state(0.0)[0], 0.0)
    return last.start + last.length + return_time(last.state(last.length), home, last.stroke.theta_max, setup.moves)


def _cut_short(span, library):
    """A problem if a library stroke was cut before one of its hits (see :data:`HITS`)."""
    if span.design is not None or span.cut is None:
        return []
    note = span.first
    hits = span.stroke.impacts.t[:HITS.get(library[note.stroke].category, 0)]
    lost = int(np.sum(hits > span.cut))
    if not lost:
        return []
    return [(f"{note.source or 'note'}: {note.stroke!r} on the {note.stick} stick is cut {span.cut:.3f} s into it for "
            f"the next note: {lost} of its {len(hits)} hits not played")]


def _at_velocity(stroke, note, setup):
    """The stroke compressed so its first impact has the note's velocity level, the factor, and a problem or ''.

    The stroke is scaled no higher than the joint's highest angle (``setup.limits.theta_high``)."""
    if not len(stroke.impacts):
        raise ParameterError(f"{note.source or 'note'}: stroke {note.stroke!r} has no impact to land on the note")
    first = stroke.impacts.level_db[0]
    factor = 10.0 ** ((velocity_to_level(note.velocity) - first) / 20.0)
    wanted = factor
    top = setup.limits.theta_high
    factor = min(factor, compress_limit(stroke, top))
    scaled = stroke if factor == 1.0 else compress(stroke, factor)
    while not _can_wind_up(scaled, setup.moves) and factor > 1e-6:  # a stroke that starts moving needs room above
        factor *= 0.98
        scaled = compress(stroke, factor)
    if factor >= wanted:
        return scaled, factor, ""
    reached = level_to_velocity(first + 20.0 * math.log10(factor))
    where = "past upright" if top >= THETA_TOP else f"above the joint's highest angle, {top:.4g} rad"
    return scaled, factor, (f"{note.source}: velocity {note.velocity} would lift {note.stroke!r} {where}; "
                            f"played at velocity {reached}, the loudest it can go")


class _Variant:
    """A library stroke at one velocity and where it may be cut, found once: a composition asks again at every note
    that plays it."""

    def __init__(self, stroke, factor):
        self.stroke, self.factor = stroke, factor
        settle = stroke.t_end if stroke.rest_time is None else stroke.rest_time  # at rest for good, or its end
        apexes = stroke.apexes[np.isfinite(stroke.apexes)]
        apexes = apexes[(apexes > stroke.impacts.t[0]) & (apexes < settle)]
        self.cuts = [settle, *apexes[::-1].tolist()]  # where it may be cut (its own time, s), latest first


def _can_wind_up(stroke, moves):
    theta, omega = stroke.path(np.array([0.0]))
    theta, omega = float(theta[0]), float(omega[0])
    return math.isfinite(return_time((theta, 0.0), (theta, omega), stroke.theta_max, moves))


# --- a score on the kit --------------------------------------------------------------------------------------------


@dataclass(frozen=True, repr=False)
class KitComposition:
    """A score played on a kit: every limb's joints on one timeline, every note's outcome, every hit.

    Attributes
    ----------
    performance : KitPerformance
        Every limb's exact motion, every note's outcome and every hit, on the composition's timeline.
    kit : Kit
    offset : float
        Where the score's time 0 is on the timeline (s): room for the first press or throw before its note.
    rate : float
        The control rate (Hz).
    t_end : float
        s: the last limb's motion ended, held :data:`HOLD_AFTER` s.
    tempo_map : TempoMap
    left_out : dict of str to int
        Notes on pieces not chosen (``pieces``), counted by piece.
    model : str
        The model the sticks' strokes were designed with (the pedals have their own, :mod:`drumstroke.kit.pedal`).
    setup : Setup
        What the sticks were played with (its joint's limits bound every θ).
    pedals : dict of str to Pedal
        Each pedal the kit's pieces name, by name, as played.
    """

    performance: object
    kit: object
    offset: float
    rate: float
    t_end: float
    tempo_map: TempoMap = field(default_factory=TempoMap)
    left_out: dict = field(default_factory=dict)
    model: str = "paper"
    setup: Setup = field(default_factory=Setup)
    pedals: dict = field(default_factory=dict)

    def __repr__(self):
        return f"KitComposition({self.performance!r}, {self.t_end:g} s at {self.rate:g} Hz)"

    def summary(self):
        """One line: the notes played of those given, per piece (most first), what --pieces left out, the span."""
        from collections import Counter

        outcomes = self.performance.outcomes
        played = Counter(o.piece for o in outcomes if o.played)
        counts = ", ".join(f"{name} {played[name]}/{n}" for name, n in Counter(o.piece for o in outcomes).most_common())
        left = (f"; not chosen (--pieces): {', '.join(f'{k} ×{n}' for k, n in self.left_out.items())}"
                if self.left_out else "")
        return (f"played {sum(played.values())} of {len(outcomes)} notes on the kit ({counts}){left}; "
                f"{self.t_end:.3f} s at {self.rate:g} Hz, score time 0 at {self.offset:g} s")

    @property
    def columns(self):
        """The CSV's header after ``t``: ``LIMB.JOINT`` (rad) for every joint of every limb with a motion, then
        ``LIMB.JOINT.velocity`` (rad/s); a hand's joints are its positioning joints and ``theta``, a foot's its
        beater's ``theta`` (θ = −φ)."""
        from .formats.trajectory_csv import kit_column_names

        return kit_column_names({limb: joints for limb, (joints, _) in self.performance.motions.items()})

    def sample(self, rate=None):
        """Times (s, from 0 to :attr:`t_end` at ``rate`` Hz, default the composition's) and ``{column: values}``."""
        rate = self.rate if rate is None else check_real("rate", rate, low=1.0, high=1e5, unit="Hz")
        rows = self._rows(rate)
        # the columns, and the copies samples() and the CSV's text make of them
        check_memory(f"sampling {self.t_end:g} s of the kit's {len(self.columns) // 2} joints at rate = {rate:g} Hz",
                     2 * values_bytes(rows * (1 + len(self.columns))), f"{rows} samples")
        t = np.arange(rows) / rate
        positions, velocities = [], []
        for joints, curve in self.performance.motions.values():
            q, v = curve(t)
            positions += [q] if q.ndim == 1 else [q[:, j] for j in range(len(joints))]
            velocities += [v] if v.ndim == 1 else [v[:, j] for j in range(len(joints))]
        return t, dict(zip(self.columns, positions + velocities, strict=True))

    def samples(self, rate=None):
        """The composition as :class:`~drumstroke.formats.trajectory_csv.KitSamples` at ``rate`` Hz (default its own):
        every joint's samples, each joint's limits and each limb's hits.

        The limits: a hand's positioning joints the kit's; its θ the setup's joint limits over the range from the
        lowest surface the hand plays (its θ's range as played); a foot's beater its pedal's range alone, from the
        head (θ = −φ_head) to rest (θ = −φ_rest), as the pedal's spring and the foot move it, no motor.
        """
        from .formats.trajectory_csv import KitSamples

        t, columns = self.sample(rate)
        motions = self.performance.motions
        joints = self.columns[:len(columns) // 2]
        limits = {}
        for limb, (names, _) in motions.items():
            if limb in self.performance.hands:
                hand = self.performance.hands[limb]
                tables = [joint.to_dict() for joint in hand.limits[:-1]]
                tables.append(replace(self.setup.limits, theta_low=hand.limits[-1].theta_low).to_dict())
            else:
                pedal = self.pedals[self.performance.feet[limb].pedal]
                tables = [{"theta_low": 0.0 - pedal.phi_head, "theta_high": 0.0 - pedal.phi_rest}]  # no -0
            limits |= {f"{limb}.{name}": table for name, table in zip(names, tables, strict=True)}
        hits = {limb: np.array([hit.t for hit in self.performance.hits if hit.limb == limb]) for limb in motions}
        # + 0.0: no -0 (a beater's ω = −φ̇ at rest), so the samples are those a kit CSV reads back, bit for bit
        positions = {j: columns[j] + 0.0 for j in joints}
        velocities = {j: columns[f"{j}.velocity"] + 0.0 for j in joints}
        limbs = {limb: tuple(names) for limb, (names, _) in motions.items()}
        return KitSamples(t, positions, velocities, limbs, float(self.rate if rate is None else rate), self.model,
                          self.offset, limits, hits)

    def write_csv(self, path, *, sidecar=True, bundle=None):
        """Write ``t`` and a column per joint (:attr:`columns`), header first, atomically; the metadata (rate,
        offset, units, each joint's limits and each limb's hits: :meth:`samples`) in the JSON beside it as every
        trajectory CSV does (``sidecar=False``: returned only)."""
        from .formats.trajectory_csv import write_kit

        rows, columns = self._rows(self.rate), 1 + len(self.columns)
        check_time(f"the CSV {str(path)!r}", csv_seconds(rows, columns),
                   f"{rows} rows of {columns} numbers at rate = {self.rate:g} Hz")
        return write_kit(path, self.samples(), sidecar=sidecar, bundle=bundle)

    def _rows(self, rate):
        """Samples from 0 to :attr:`t_end` at ``rate`` Hz."""
        return math.floor(self.t_end * rate + 1e-9) + 1


def compose_kit(notes, kit=None, *, setup=None, rate=None, pieces=None, lead="right", open_handed=False,
                pedals=None):
    """Play a score on a kit: its notes' limbs assigned, the hands' strokes planned, the feet's presses designed.

    Every note is a note on a piece of the kit, at its time and velocity: a MIDI file's notes read with the kit
    (:func:`~drumstroke.score.read_score` with ``kit=``: every key it answers, the hi-hat's state by its key),
    a pattern's on the piece its line names (default the snare; its stroke's name is not used, a note is one
    impact) and in the state it names (``hihat:half``). A note's stick, when it names a limb of the kit, is
    given (``auto``: assigned); a hi-hat note that names no state (nor a key) is closed, or its pedal when a
    foot plays it. :func:`~drumstroke.kit.play.play_kit` plays them.

    Parameters
    ----------
    notes : Score or sequence of ScoreNote
    kit : Kit, optional
        Default the shipped :func:`~drumstroke.kit.pieces.default_kit`.
    setup : Setup, optional
        What the sticks are played with (default ``Setup()``).
    rate : float in [1, 100000], optional
        Control rate (Hz) of the samples; default 1000.
    pieces : sequence of str, optional
        Play only these pieces (the others' notes are counted in ``left_out``); default every piece.
    lead : {"right", "left"}
    open_handed : bool
    pedals : dict of str to Pedal, optional
        As :func:`~drumstroke.kit.play.play_kit` takes them.

    Returns
    -------
    KitComposition

    Examples
    --------
    >>> from drumstroke.score import parse_pattern
    >>> score = parse_pattern("tempo 120\\n0 auto 100 auto kick\\n0 auto 90 auto hihat\\n1 auto 110 auto\\n")
    >>> piece = compose_kit(score)
    >>> [(o.piece, o.limb, o.played) for o in piece.performance.outcomes]
    [('kick', 'right-foot', True), ('hihat', 'right', True), ('snare', 'left', True)]
    >>> piece.columns[:4], piece.offset
    (['right.yaw', 'right.lift', 'right.theta', 'left.yaw'], 0.241)
    """
    from .kit.limbs import KitNote
    from .kit.pieces import Kit, default_kit
    from .kit.play import kit_pedals, play_kit

    kit = default_kit() if kit is None else kit
    if not isinstance(kit, Kit):
        raise ParameterError(f"kit must be a drumstroke.kit.pieces.Kit, got {kit!r}")
    setup = Setup() if setup is None else setup
    if not isinstance(setup, Setup):
        raise ParameterError(f"setup must be a drumstroke.design.Setup, got {setup!r}")
    tempo_map = notes.tempo_map if isinstance(notes, Score) else TempoMap()
    notes = notes.notes if isinstance(notes, Score) else tuple(notes)
    rate = DEFAULT_RATE if rate is None else check_real("rate", rate, low=1.0, high=1e5, unit="Hz")
    names = [piece.name for piece in kit.pieces]
    chosen = names if pieces is None else list(pieces)
    for name in chosen:
        if name not in names:
            raise ParameterError(f"pieces names {name!r}, not a piece of the kit ({', '.join(names)})",
                                 parameter="pieces", value=name, allowed=", ".join(names))
    kept, left_out = [], {}
    for note in notes:
        if not isinstance(note, ScoreNote):
            raise ParameterError(f"notes must be ScoreNotes, got {note!r}")
        piece = note.piece or "snare"
        if piece not in names:
            raise ParameterError(f"{note.source or 'note'}: piece {piece!r} is not a piece of the kit "
                                 f"({', '.join(names)})", parameter="piece", value=piece, allowed=", ".join(names))
        if piece in chosen:
            kept.append(note)
        else:
            left_out[piece] = left_out.get(piece, 0) + 1
    if not kept:
        raise ParameterError(f"no note to play on the pieces chosen ({', '.join(chosen)})")
    # room before the first note for the slowest press from rest (half the pedal's period) and a stick's throw
    pedals = kit_pedals(pedals, kit)
    need = max([LEAD_ROOM] + [math.pi / pedal.frequency for pedal in pedals.values()])
    offset = math.ceil(max(0.0, need - min(n.time for n in kept)) * rate - 1e-9) / rate
    kit_notes, keys, limbs = [], [], []
    for note in kept:
        piece = kit.piece(note.piece or "snare")
        limb = note.stick if note.stick in kit.limbs else None
        state = _kit_state(note, piece, limb)
        key = note.key if note.key is not None else next(k for k in piece.keys if piece.state(k) == state)
        kit_notes.append(KitNote(note.time + offset, piece.name, state,
                                 None if note.beat is None else float(note.beat)))
        keys.append(key)
        limbs.append(limb)
    performance = play_kit(kit_notes, kit, velocities=[n.velocity for n in kept], keys=keys, setup=setup,
                           limbs=limbs, lead=lead, open_handed=open_handed, pedals=pedals)
    return KitComposition(performance, kit, offset, rate, performance.t_end + HOLD_AFTER, tempo_map, left_out,
                          setup.model, setup, pedals)


LEAD_ROOM = 0.1
"""s kept before a composition's first note for a stick's throw onto it (the planner's throw)."""


def _kit_state(note, piece, limb):
    """The state ``note`` is played in on ``piece``: the one it names, its key's, or the hi-hat's default."""
    from .kit.pieces import FEET, PEDAL_STATE

    if note.state is not None:
        states = tuple(dict.fromkeys(piece.states.values()))
        if note.state not in states:
            allowed = ", ".join(states) or "none"
            raise ParameterError(f"{note.source or 'note'}: state {note.state!r} is not one of pieces.{piece.name}'s "
                                 f"states ({allowed})", parameter="state", value=note.state, allowed=allowed)
        return note.state
    if note.key is not None:
        return piece.state(note.key)
    return (PEDAL_STATE if limb in FEET else "closed") if piece.kind == "hihat" else None
