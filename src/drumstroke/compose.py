"""Composition: a score becomes one continuous motor-angle trajectory per stick (SPEC §4).

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

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ._checks import check_real
from .design import Target, assign_sticks, plan_stick
from .dynamics import level_to_velocity, velocity_to_level
from .errors import ParameterError
from .formats.midi import TempoMap
from .model import Stick
from .palette.motion import RETURN_LIMITS, assemble, plan_return, return_time
from .palette.transforms import compress, compress_limit, trim
from .recipe import T_END_LIMIT
from .score import PLANNED, Score, ScoreNote
from .trajectory import DEFAULT_RATE, Trajectory

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


def compose(notes, library=None, *, rate=None, limits=None, progress=None, model="paper", sticks=2, forces=None,
            joint=None):
    """Compose ``notes`` into one trajectory per stick: library strokes placed, ``auto`` and ``buzz`` notes designed.

    Parameters
    ----------
    notes : Score or sequence of ScoreNote
        At least one note. A note's stroke is a library stroke's name, or ``"auto"``/``"buzz"``
        for the planner (:mod:`drumstroke.design`); a note whose stick is None gets one from the
        planner (:func:`~drumstroke.design.assign_sticks`). A :class:`~drumstroke.score.Score`
        (what :func:`~drumstroke.score.read_score` returns) brings its tempo map along.
    library : drumstroke.palette.library.Library or None
        Needed for notes that name library strokes.
    rate : float in [1, 100000] or None
        Control rate (Hz) of the result; default the library's (without one, 1000).
    limits : Limits or None
        Bounds on the moves between strokes (default :data:`~drumstroke.palette.motion.RETURN_LIMITS`).
    progress : callable or None
        Called with the fraction done (0 to 1) as the notes are placed and the sticks assembled.
    model : {"paper", "geometry"}
        The model the planner designs with.
    sticks : {1, 2}
        How many sticks the planner may give the notes without one.
    forces : drumstroke.design.ForceRange or None
        The thumb accelerations the planner may use (default 0 to 3000 m/s²).
    joint : Limits or None
        The joint's limits the designed strokes keep (default ``Limits()``).

    Returns
    -------
    Composition
    """
    limits = limits or RETURN_LIMITS
    tempo_map = notes.tempo_map if isinstance(notes, Score) else TempoMap()
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
    default_rate = library.rate if library is not None else DEFAULT_RATE
    rate = default_rate if rate is None else check_real("rate", rate, low=1.0, high=1e5, unit="Hz")
    notes.sort(key=lambda n: n.time)
    if notes[-1].time > T_END_LIMIT:  # found before any work: a song too long to compose fails at once
        raise ParameterError(f"{notes[-1].source or 'note'}: time must be at most {T_END_LIMIT:g} s (a composition "
                             f"lasts at most an hour), got {notes[-1].time:.6g} s")
    notes = _with_sticks(notes, sticks)
    problems = []
    variants = {}
    for note in notes:
        key = (note.stroke, note.velocity)
        if note.stroke not in PLANNED and key not in variants:
            variants[key] = _Variant(*_at_velocity(library[note.stroke].trajectory, note, problems, limits))
    placed = [n for n in notes if n.stroke not in PLANNED]
    head = library[placed[0].stroke].trajectory.theta_max if placed else Stick().theta_max
    by_stick = {}
    for note in notes:
        by_stick.setdefault(note.stick, []).append(note)
    done = 0

    def advance(count):  # placing a note is one step, assembling it into its stick another
        nonlocal done
        done += count
        if progress is not None:
            progress(done / (2 * len(notes)))

    designed = {}
    for stick, stick_notes in by_stick.items():
        wanted = [n for n in stick_notes if n.stroke in PLANNED]
        if wanted:
            targets = [Target.from_velocity(n.time, n.velocity, kind=n.stroke, duration=n.duration, key=k)
                       for k, n in enumerate(wanted)]
            designed[stick] = (wanted, plan_stick(targets, model=model, forces=forces, limits=joint, moves=limits))
            advance(len(wanted))
    offset = _offset(placed, variants, head, limits, rate, designed)
    plans = {stick: _place([n for n in stick_notes if n.stroke not in PLANNED], variants, offset, head, limits,
                           problems, advance) for stick, stick_notes in by_stick.items()}
    placements = []
    for stick, (wanted, plan) in designed.items():
        placements += _designed_placements(wanted, plan, offset, problems)
        plans[stick] = _clear_of(plans[stick], plan, offset, head, limits, problems)
    for plan in plans.values():
        _report_cuts(plan, library, problems)
    ends = [_finish(plan, head, limits) for plan in plans.values() if any(p.played for p, _ in plan)]
    ends += [offset + plan.designs[-1].t_end for _, plan in designed.values() if plan.designs]
    if not ends:
        raise ParameterError("no note could be played: " + "; ".join(problems[:3]))
    end = max(ends) + HOLD_AFTER
    if not math.isfinite(end):
        raise ParameterError(f"the last stroke cannot return to its start angle within {limits}")
    assembled = {}
    for stick in by_stick:
        played = [(p.start, trim(v.stroke, 0.0, p.cut) if p.cut is not None else v.stroke)
                  for p, v in plans[stick] if p.played]
        plan = designed[stick][1] if stick in designed else None
        if plan is not None:
            played += [(offset + d.release, Trajectory.from_stroke(d.stroke, rate=rate, name="designed"))
                       for d in plan.designs]
        if not played:
            continue
        played.sort(key=lambda item: item[0])
        assembled[stick] = assemble([piece for _, piece in played], [start for start, _ in played], limits=limits,
                                    end=end, name=f"composition ({stick} stick)", home=plan is None).sample(rate)
        advance(len(plans[stick]))
    placements = sorted(placements + [p for plan in plans.values() for p, _ in plan], key=lambda p: p.note.time)
    trajectory = Trajectory.from_sticks(assembled, name=f"composition of {len(placements)} notes",
                                        history=(f"compose {len(placements)} notes",))
    designs = tuple((stick, d) for stick, (_, plan) in designed.items() for d in plan.designs)
    return Composition(trajectory, offset, tuple(placements), tuple(problems), tempo_map, designs)


def _report_cuts(plan, library, problems):
    """A problem for each played library stroke cut before one of its hits (see :data:`HITS`)."""
    for placement, variant in plan:
        if not placement.played or placement.cut is None:
            continue
        note = placement.note
        hits = variant.stroke.impacts.t[:HITS.get(library[note.stroke].category, 0)]
        lost = int(np.sum(hits > placement.cut))
        if lost:
            problems.append(f"{note.source or 'note'}: {note.stroke!r} on the {note.stick} stick is cut "
                            f"{placement.cut:.3f} s into it for the next note: {lost} of its {len(hits)} hits not "
                            "played")


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


def _designed_placements(notes, plan, offset, problems):
    """The placements of a stick's planned notes: each played note on its design, the others left out."""
    played = {}
    for design, keys in zip(plan.designs, plan.keys):
        for key in keys:
            played[key] = design
    for problem in plan.problems:
        problems.append(f"{notes[problem.key].source or 'note'}: {problem.reason}; left out")
    return [Placement(note, True, offset + played[k].release, offset + note.time, 1.0) if k in played
            else Placement(note, False, factor=1.0) for k, note in enumerate(notes)]


def _clear_of(plan, designed, offset, head, limits, problems):
    """A stick's library strokes that fit between its designed strokes (moves included); the others left out."""
    spans = [(offset + d.release, offset + d.t_end, d) for d in designed.designs]
    kept = []
    for placement, variant in plan:
        if not placement.played:
            kept.append((placement, variant))
            continue
        end = placement.start + (placement.cut if placement.cut is not None else variant.stroke.t_end)
        start_state = variant.state(0.0)
        clash = next((d for s, e, d in spans if not (end + _gap(variant, placement, d, head, limits) <= s
                                                     or placement.start >= e + _gap_after(d, start_state, head,
                                                                                            limits))), None)
        if clash is None:
            kept.append((placement, variant))
            continue
        note = placement.note
        problems.append(f"{note.source or 'note'}: {note.stroke!r} on the {note.stick} stick meets the stroke "
                        f"designed for the notes at {clash.times[0]:.6g}-{clash.times[-1]:.6g} s; left out")
        kept.append((Placement(note, False, factor=variant.factor), variant))
    return kept


def _gap(variant, placement, design, head, limits):
    """The time (s) a library stroke needs after its end to reach a designed stroke's start."""
    end = placement.cut if placement.cut is not None else variant.stroke.t_end
    return return_time(variant.state(end), (float(design.recipe.theta0), 0.0), head, limits)


def _gap_after(design, start_state, head, limits):
    """The time (s) a designed stroke needs after its end to reach a library stroke's start."""
    theta = float(design.state(design.t_end)[0])
    return return_time((theta, 0.0), start_state, head, limits)


def _at_velocity(stroke, note, problems, limits):
    """The stroke compressed so its first impact has the note's velocity level, with the factor."""
    if not len(stroke.impacts):
        raise ParameterError(f"{note.source or 'note'}: stroke {note.stroke!r} has no impact to land on the note")
    first = stroke.impacts.level_db[0]
    factor = 10.0 ** ((velocity_to_level(note.velocity) - first) / 20.0)
    top = compress_limit(stroke)
    wanted = factor
    factor = min(factor, top)
    scaled = stroke if factor == 1.0 else compress(stroke, factor)
    while not _can_wind_up(scaled, limits) and factor > 1e-6:  # a stroke that starts moving needs room above
        factor *= 0.98
        scaled = compress(stroke, factor)
    if factor < wanted:
        reached = level_to_velocity(first + 20.0 * math.log10(factor))
        problems.append(f"{note.source}: velocity {note.velocity} would lift {note.stroke!r} past upright; "
                        f"played at velocity {reached}, the loudest it can go")
    return scaled, factor


class _Variant:
    """A library stroke at one velocity, with where it may be cut and its state at those times, each found once:
    a composition asks for them again at every note that plays it."""

    def __init__(self, stroke, factor):
        self.stroke, self.factor = stroke, factor
        settle = stroke.t_end if stroke.rest_time is None else stroke.rest_time  # at rest for good, or its end
        apexes = stroke.apexes[np.isfinite(stroke.apexes)]
        apexes = apexes[(apexes > stroke.impacts.t[0]) & (apexes < settle)]
        self.cuts = [settle, *apexes[::-1].tolist()]  # where it may be cut (its own time, s), latest first
        self._states = {}

    def state(self, t):
        """(θ rad, ω rad/s) at ``t`` (s, its own time)."""
        if t not in self._states:
            self._states[t] = _state(self.stroke, t)
        return self._states[t]


def _can_wind_up(stroke, limits):
    theta, omega = _state(stroke, 0.0)
    return math.isfinite(return_time((theta, 0.0), (theta, omega), stroke.theta_max, limits))


def _offset(notes, variants, head, limits, rate, designed=None):
    """The lead (s) before the score's time 0 so every stick's first downstroke fits, on the control grid.

    ``designed``: {stick: (notes, StickPlan)}, whose first strokes start (are released) before time 0."""
    need = max([0.0] + [-plan.designs[0].release for _, plan in (designed or {}).values() if plan.designs])
    firsts = {}
    for note in notes:
        firsts.setdefault(note.stick, note)
    for note in firsts.values():
        variant = variants[(note.stroke, note.velocity)]
        theta, omega = variant.state(0.0)
        wind = return_time((theta, 0.0), (theta, omega), head, limits)
        need = max(need, variant.stroke.impacts.t[0] + wind - note.time)
    return math.ceil(need * rate - 1e-9) / rate if need > 0 else 0.0


def _place(notes, variants, offset, head, limits, problems, advance):
    """Placements on one stick: (Placement, _Variant) in time order, cuts chosen; ``advance(1)`` for each note."""
    plan = []
    for note in notes:
        advance(1)
        variant = variants[(note.stroke, note.velocity)]
        start = offset + note.time - variant.stroke.impacts.t[0]
        placed = Placement(note, True, start, offset + note.time, variant.factor)
        previous = next((i for i in range(len(plan) - 1, -1, -1) if plan[i][0].played), None)
        if previous is not None:
            before, before_variant = plan[previous]
            cut = _latest_cut(before_variant, before.start, variant, start, head, limits)
            if cut is None:
                need = _earliest_start(before_variant, before.start, variant, head, limits) - start
                problems.append(
                    f"{note.source}: {note.stroke!r} on the {note.stick} stick comes {need * 1e3:.0f} ms too soon "
                    f"after {before.note.stroke!r} at {before.note.time:.6g} s; left out")
                plan.append((Placement(note, False, factor=variant.factor), variant))
                continue
            cut = cut if cut < before_variant.stroke.t_end else None
            plan[previous] = (replace(before, cut=cut), before_variant)
        plan.append((placed, variant))
    last = next((i for i in range(len(plan) - 1, -1, -1) if plan[i][0].played), None)
    if last is not None:  # the last stroke plays on until it settles, or until its latest apex the stick can leave
        p, v = plan[last]
        home = (v.state(0.0)[0], 0.0)
        cut = next((c for c in v.cuts if math.isfinite(return_time(v.state(c), home, head, limits))), v.cuts[-1])
        plan[last] = (replace(p, cut=cut if cut < v.stroke.t_end else None), v)
    return plan


def _latest_cut(variant, start, following, following_start, head, limits):
    target = following.state(0.0)
    for cut in variant.cuts:
        window = following_start - (start + cut)
        if window >= 0.0 and plan_return(variant.state(cut), target, window, head, limits) is not None:
            return cut
    return None


def _earliest_start(variant, start, following, head, limits):
    cut = variant.cuts[-1]
    return start + cut + return_time(variant.state(cut), following.state(0.0), head, limits)


def _finish(plan, head, limits):
    """When the stick is home after its last stroke (s)."""
    played = [(p, v) for p, v in plan if p.played]
    p, v = played[-1]
    end = p.cut if p.cut is not None else v.stroke.t_end
    return p.start + end + return_time(v.state(end), (v.state(0.0)[0], 0.0), head, limits)


def _state(stroke, t):
    theta, omega = stroke.path(np.array([t]))
    return float(theta[0]), float(omega[0])
