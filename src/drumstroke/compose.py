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
from .dynamics import level_to_velocity, velocity_to_level
from .errors import ParameterError
from .formats.midi import TempoMap
from .palette.motion import RETURN_LIMITS, assemble, plan_return, return_time
from .palette.transforms import compress, compress_limit, trim
from .score import Score, ScoreNote
from .trajectory import Trajectory

HOLD_AFTER = 0.25
"""Time (s) the stick holds still at the end of a composition, after its last return."""


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
        Notes left out, velocities out of reach.
    tempo_map : TempoMap
        The score's tempo changes and time signatures (its MIDI file's, or its pattern's tempo and
        meter; 120 bpm in 4/4 for notes given without one), on the score's time.
    """

    trajectory: Trajectory
    offset: float
    placements: tuple
    problems: tuple
    tempo_map: TempoMap = field(default_factory=TempoMap)

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


def compose(notes, library, *, rate=None, limits=None, progress=None):
    """Compose ``notes`` from ``library`` strokes into one trajectory per stick.

    Parameters
    ----------
    notes : Score or sequence of ScoreNote
        At least one note; their strokes must be in the library. A :class:`~drumstroke.score.Score`
        (what :func:`~drumstroke.score.read_score` returns) brings its tempo map along.
    library : drumstroke.palette.library.Library
    rate : float in [1, 100000] or None
        Control rate (Hz) of the result; default the library's.
    limits : Limits or None
        Bounds on the returns between strokes (default :data:`~drumstroke.palette.motion.RETURN_LIMITS`).
    progress : callable or None
        Called with the fraction done (0 to 1) as the notes are placed and the sticks assembled.

    Returns
    -------
    Composition
    """
    limits = limits or RETURN_LIMITS
    rate = library.rate if rate is None else check_real("rate", rate, low=1.0, high=1e5, unit="Hz")
    tempo_map = notes.tempo_map if isinstance(notes, Score) else TempoMap()
    notes = list(notes.notes if isinstance(notes, Score) else notes)
    if not notes:
        raise ParameterError("notes must hold at least one note")
    for note in notes:
        if not isinstance(note, ScoreNote):
            raise ParameterError(f"notes must be ScoreNote objects, got {note!r}")
    notes.sort(key=lambda n: n.time)
    problems = []
    variants = {}
    for note in notes:
        if note.stroke not in library:
            raise ParameterError(f"{note.source or 'note'}: stroke {note.stroke!r} is not in the library; it has "
                                 f"{', '.join(library)}")
        key = (note.stroke, note.velocity)
        if key not in variants:
            variants[key] = _Variant(*_at_velocity(library[note.stroke].trajectory, note, problems, limits))
    head = library[notes[0].stroke].trajectory.theta_max
    offset = _offset(notes, variants, head, limits, rate)
    by_stick = {}
    for note in notes:
        by_stick.setdefault(note.stick, []).append(note)
    done = 0

    def advance(count):  # placing a note is one step, assembling it into its stick another
        nonlocal done
        done += count
        if progress is not None:
            progress(done / (2 * len(notes)))

    plans = {stick: _place(stick_notes, variants, offset, head, limits, problems, advance)
             for stick, stick_notes in by_stick.items()}
    end = max(_finish(plan, head, limits) for plan in plans.values()) + HOLD_AFTER
    if not math.isfinite(end):
        raise ParameterError(f"the last stroke cannot return to its start angle within {limits}")
    sticks = {}
    for stick, plan in plans.items():
        played = [p for p, _ in plan if p.played]
        pieces = [trim(v.stroke, 0.0, p.cut) if p.cut is not None else v.stroke for p, v in plan if p.played]
        sticks[stick] = assemble(pieces, [p.start for p in played], limits=limits, end=end,
                                 name=f"composition ({stick} stick)").sample(rate)
        advance(len(plan))
    placements = sorted((p for plan in plans.values() for p, _ in plan), key=lambda p: p.note.time)
    trajectory = Trajectory.from_sticks(sticks, name=f"composition of {len(placements)} notes",
                                        history=(f"compose {len(placements)} notes",))
    return Composition(trajectory, offset, tuple(placements), tuple(problems), tempo_map)


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


def _offset(notes, variants, head, limits, rate):
    """The lead (s) before the score's time 0 so every stick's first downstroke fits, on the control grid."""
    need = 0.0
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
