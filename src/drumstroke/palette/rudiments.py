"""The 40 PAS International Drum Rudiments as notes for two sticks.

The rudiments are data, :data:`RUDIMENTS_FILE` (``rudiments.toml`` next to this module), written from
the Percussive Arts Society's standard sheet: per rudiment the notes of one cycle — their beats,
sticks, dynamics, grace notes and buzzes — and a tempo range. :func:`rudiment` finds one by name or
number, :meth:`Rudiment.notes_at` plays it at a tempo as timed notes on the sticks ``right`` and
``left``, and :meth:`Rudiment.pattern_text` writes the same notes as a text pattern whose strokes the
planner designs (``auto``, ``buzz``).

The data names dynamics; :data:`DYNAMICS` turns them into MIDI velocities, here and nowhere else.
``docs/rudiments.md`` gives the table of the 40, why the velocities, grace offsets and tempo ranges
are what they are, and the data format.

Examples
--------
>>> flam_tap = rudiment("flam-tap")
>>> flam_tap
Rudiment(22, 'flam-tap', flam, 60-150 bpm, 6 notes in 1 beat)
>>> flam_tap.sticking
'lR> R rL> L'
>>> played = flam_tap.notes_at(120, bars=1, beats_per_bar=1)
>>> [(round(n.time, 3), n.stick, n.velocity) for n in played.notes]
[(0.47, 'left', 69), (0.5, 'right', 116), (0.625, 'right', 84), (0.72, 'right', 69), (0.75, 'left', 116), (0.875, 'left', 84)]
>>> print(flam_tap.pattern_text(120, bars=1, beats_per_bar=1), end="")
# PAS 22, Flam Tap: 1 bar of 1 beat at 120 bpm, after a lead-in of 1 beat for the grace notes
tempo 120
0.94 auto 69 left
1 auto 116 right
1.25 auto 84 right
1.44 auto 69 right
1.5 auto 116 left
1.75 auto 84 left
"""

import math
import re
from dataclasses import dataclass
from fractions import Fraction
from functools import cache
from numbers import Real
from pathlib import Path
from types import MappingProxyType
from typing import NamedTuple

from .._checks import check_choice, check_int, check_keys, check_real, did_you_mean, shown
from ..errors import ParameterError
from ..formats.toml import reading_toml

RUDIMENTS_FILE = Path(__file__).with_name("rudiments.toml")
"""The shipped data: the 40 PAS rudiments in PAS order."""

DYNAMICS = MappingProxyType({"accent": 116, "normal": 100, "tap": 84, "grace": 69})
"""MIDI velocity of each dynamic the data names.

Stick heights of a rudimental drummer, each half the one above: accent 12 in, normal 6 in, tap 3 in,
grace 1.5 in; at a given stroke time the tip's speed is proportional to the height, so each step is
6 dB, 16 velocity steps of 0.38 dB (:mod:`drumstroke.dynamics`). An accent is 12.2 dB over a tap; a
grace note is 11.8 dB under a normal note and 17.9 dB under an accent, inside the 10-20 dB of a flam
(docs/design.md). Normal is velocity 100 (1.2 m/s at the tip); tap is 84, the shipped ``tap`` stroke's level.
"""

FAMILIES = ("roll", "diddle", "flam", "drag")
"""The four PAS families: I roll, II diddle, III flam, IV drag rudiments."""

KINDS = ("note", "grace", "buzz")
"""What a note of the data is: a plain note, a grace note placed in milliseconds before its main
note, or a buzz (a multiple-bounce stroke) lasting a number of beats."""

TEMPO_LIMITS = (1.0, 400.0)
"""The tempos (beats per minute) :meth:`Rudiment.notes_at` plays at all; a rudiment's own range is narrower."""

GRACE_OFFSETS_MS = (-100.0, -15.0)
"""The grace offsets (ms before the main note) the data may use: a flam's is -15 to -50 ms (a human flam's),
a drag's first grace note is earlier."""

STICKS = MappingProxyType({"R": "right", "L": "left"})
"""The data's hands and the sticks they play, as the rest of drumstroke names sticks."""

_OTHER = {"R": "L", "L": "R"}
_NAME = re.compile(r"^[a-z0-9]+(-[a-z0-9]+)*$")
_KEYS = ("number", "name", "title", "family", "tempo", "cycle", "notes")


class Note(NamedTuple):
    """One note of a rudiment's cycle, as the data gives it.

    Attributes
    ----------
    beat : Fraction in [0, cycle)
        Quarter notes from the start of the cycle; a grace note has its main note's beat.
    stick : {"R", "L"}
    dynamic : str
        A key of :data:`DYNAMICS`.
    kind : {"note", "grace", "buzz"}
    value : float or Fraction or None
        A grace note's offset (ms, < 0), a buzz's length (beats), None for a plain note.
    """

    beat: Fraction
    stick: str
    dynamic: str
    kind: str = "note"
    value: float | Fraction | None = None


class PlayedNote(NamedTuple):
    """One note at a tempo, for the composer.

    Attributes
    ----------
    time : float
        s from 0: the first note, or the start of a lead-in (:attr:`RudimentNotes.downbeat`) before it.
    stick : {"right", "left"}
    velocity : int in [1, 127]
    kind : {"auto", "buzz"}
        ``auto``: one impact, its stroke designed by the planner; ``buzz``: a multiple-bounce stroke.
    duration : float
        A buzz's length (s); 0 for ``auto``.
    """

    time: float
    stick: str
    velocity: int
    kind: str
    duration: float


@dataclass(frozen=True)
class RudimentNotes:
    """A rudiment played at a tempo: its notes in time order, and whether the tempo is in its range.

    Attributes
    ----------
    rudiment : str
        The rudiment's name.
    tempo : float
        Beats per minute.
    tempo_range : tuple of float
        The rudiment's range (bpm): bottom, top.
    notes : tuple of PlayedNote
        Sorted by time.
    downbeat : float
        When the cycle's beat 0 falls (s): 0, or a lead-in of whole beats that makes room for grace notes
        before the first note.
    """

    rudiment: str
    tempo: float
    tempo_range: tuple
    notes: tuple
    downbeat: float

    def __post_init__(self):
        check_real("tempo", self.tempo, low=TEMPO_LIMITS[0], high=TEMPO_LIMITS[1], unit="beats per minute")
        times = [note.time for note in self.notes]
        if times != sorted(times):
            raise ParameterError(f"{self.rudiment}: notes must be in time order")

    @property
    def in_range(self):
        """True if the tempo is within the rudiment's range."""
        return self.tempo_range[0] <= self.tempo <= self.tempo_range[1]

    @property
    def warning(self):
        """None in range; else one line saying the tempo is outside the rudiment's range (for the CLI to print)."""
        if self.in_range:
            return None
        low, high = self.tempo_range
        side = "below" if self.tempo < low else "above"
        return f"{self.tempo:g} bpm is {side} the range of {self.rudiment}, {low:g}-{high:g} bpm"


@dataclass(frozen=True)
class Rudiment:
    """One PAS rudiment: the notes of a cycle and the tempos it is played at.

    Attributes
    ----------
    number : int >= 1
        PAS's number, 1 to 40.
    name : str
        Kebab-case, unique: ``double-stroke-open-roll``.
    title : str
        PAS's name: ``Double Stroke Open Roll``.
    family : {"roll", "diddle", "flam", "drag"}
    tempo : tuple of float
        (bottom, top) beats per minute, a quarter note a beat, within :data:`TEMPO_LIMITS`.
    cycle : Fraction > 0
        Beats in one repetition of the notes.
    notes : tuple of Note
        The cycle's notes, in time order (normalised on construction).
    """

    number: int
    name: str
    title: str
    family: str
    tempo: tuple
    cycle: Fraction
    notes: tuple

    def __post_init__(self):
        check_int("rudiment number", self.number, low=1, high=999)
        if not isinstance(self.name, str) or not _NAME.match(self.name):
            raise ParameterError(f"rudiment {self.number}: name must be kebab-case (a-z, 0-9, words joined by '-'), "
                                 f"got {self.name!r}")
        where = f"rudiment {self.number} ({self.name})"
        if not isinstance(self.title, str) or not self.title.strip() or "\n" in self.title:
            raise ParameterError(f"{where}: title must be one line of text, got {self.title!r}")
        check_choice(f"{where}: family", self.family, FAMILIES)
        object.__setattr__(self, "tempo", _tempo_range(self.tempo, where))
        cycle = _fraction(self.cycle, f"{where}: cycle")
        if cycle <= 0:
            raise ParameterError(f"{where}: cycle must be > 0 beats, got {cycle}")
        object.__setattr__(self, "cycle", cycle)
        if not isinstance(self.notes, (tuple, list)) or not self.notes:
            raise ParameterError(f"{where}: notes must be a non-empty sequence of notes, got {self.notes!r}")
        notes = [_note(note, cycle, f"{where}: notes[{i}]") for i, note in enumerate(self.notes)]
        _check_ornaments(notes, cycle, where)
        object.__setattr__(self, "notes", tuple(sorted(notes, key=_cycle_order)))

    def __repr__(self):
        beats = "beat" if self.cycle == 1 else "beats"
        return (f"Rudiment({self.number}, {self.name!r}, {self.family}, {self.tempo[0]:g}-{self.tempo[1]:g} bpm, "
                f"{len(self.notes)} notes in {self.cycle} {beats})")

    @property
    def sticking(self):
        """The cycle as a drummer writes it: R/L main notes, ``>`` an accent, ``z`` a buzz, l/r grace notes before."""
        words, graces = [], ""
        for note in self.notes:
            if note.kind == "grace":
                graces += note.stick.lower()
                continue
            mark = (">" if note.dynamic == "accent" else "") + ("z" if note.kind == "buzz" else "")
            words.append(graces + note.stick + mark)
            graces = ""
        return " ".join(words)

    def notes_at(self, tempo, *, bars=2, beats_per_bar=None):
        """The rudiment played at ``tempo``: its notes with times (s), sticks and velocities.

        Parameters
        ----------
        tempo : float in [1, 400]
            Beats (quarter notes) per minute. Outside the rudiment's range it still plays;
            :attr:`RudimentNotes.warning` then says so.
        bars : int >= 1
        beats_per_bar : float > 0 or None
            Beats in a bar; None: whole cycles, at least 4 beats. Notes past the last bar are left out,
            a note's grace notes with it.

        Returns
        -------
        RudimentNotes
            Grace notes at their offsets before their main notes; when they would fall before 0, the
            whole rudiment starts a whole number of beats later (``downbeat``).
        """
        events, lead, _ = self._events(tempo, bars, beats_per_bar)
        notes = tuple(PlayedNote(event.time, STICKS[event.note.stick], DYNAMICS[event.note.dynamic],
                                 "buzz" if event.note.kind == "buzz" else "auto", event.length) for event in events)
        return RudimentNotes(self.name, float(tempo), self.tempo, notes, lead * 60.0 / tempo)

    def pattern_text(self, tempo, *, bars=2, beats_per_bar=None):
        """The notes of :meth:`notes_at` as a text pattern: ``tempo BPM``, then ``beat auto velocity stick``
        lines, and ``beat buzz velocity stick BEATS`` for a buzz (its length in beats as a fifth field).

        Beats count from the pattern's start (the lead-in included), so they give the same times (to 12 digits).
        """
        events, lead, span = self._events(tempo, bars, beats_per_bar)
        tempo = float(tempo)
        bar = span / bars
        head = f"# PAS {self.number}, {self.title}: {_count(bars, 'bar')} of {_count(bar, 'beat')} at {tempo:g} bpm"
        if lead:
            head += f", after a lead-in of {_count(lead, 'beat')} for the grace notes"
        lines = [head]
        if not self.tempo[0] <= tempo <= self.tempo[1]:
            lines.append(f"# {self.tempo[0]:g}-{self.tempo[1]:g} bpm is this rudiment's range")
        lines.append(f"tempo {tempo:g}")
        for event in events:
            buzz = event.note.kind == "buzz"
            line = (f"{_text(event.beat)} {'buzz' if buzz else 'auto'} {DYNAMICS[event.note.dynamic]} "
                    f"{STICKS[event.note.stick]}")
            lines.append(f"{line} {_text(event.length_beats)}" if buzz else line)
        return "\n".join(lines) + "\n"

    def _events(self, tempo, bars, beats_per_bar):
        """The notes placed over the bars, in time order; the lead-in (beats) and the span played (beats)."""
        tempo = check_real("tempo", tempo, low=TEMPO_LIMITS[0], high=TEMPO_LIMITS[1], unit="beats per minute")
        check_int("bars", bars, low=1, high=10_000)
        span = _span(self.cycle, bars, beats_per_bar)
        seconds_per_beat = 60.0 / tempo
        placed = []
        for repeat in range(math.ceil(span / self.cycle)):
            for note in self.notes:
                beat = repeat * self.cycle + note.beat
                if beat < span:
                    offset = note.value / 1000.0 if note.kind == "grace" else 0.0
                    placed.append((float(beat) + offset / seconds_per_beat, note))
        earliest = min(beat for beat, _ in placed)
        lead = math.ceil(-earliest) if earliest < 0 else 0
        events = []
        for beat, note in placed:
            length = float(note.value) if note.kind == "buzz" else 0.0
            events.append(_Event((beat + lead) * seconds_per_beat, beat + lead, note, length * seconds_per_beat, length))
        events.sort(key=lambda event: (event.time, event.note.stick))
        return events, lead, span


class _Event(NamedTuple):
    """A note placed in a performance: time (s) and beat from the start, the note, a buzz's length (s, beats)."""

    time: float
    beat: float
    note: Note
    length: float
    length_beats: float


def read_rudiments(path=None):
    """The rudiments of a rudiments file (default: :data:`RUDIMENTS_FILE`), validated, in file order.

    Raises
    ------
    ParameterError
        Naming the rudiment and the field at fault.
    """
    path = Path(path) if path is not None else RUDIMENTS_FILE
    with reading_toml(path, "rudiments file") as data:
        check_keys(f"rudiments file {str(path)!r}", data, ("rudiment",))
        tables = data.get("rudiment")
        if not isinstance(tables, list) or not tables:
            raise ParameterError(f"rudiments file {str(path)!r} needs at least one [[rudiment]] table")
        found, names = [], set()
        for i, table in enumerate(tables):
            rudiment = _rudiment_from_table(table, f"rudiment[{i}]")
            if found and rudiment.number <= found[-1].number:
                raise ParameterError(f"rudiment {rudiment.number} ({rudiment.name}): numbers must increase through the "
                                     f"file, but it follows rudiment {found[-1].number}")
            if rudiment.name in names:
                raise ParameterError(f"rudiment {rudiment.number}: name {rudiment.name!r} appears twice")
            names.add(rudiment.name)
            found.append(rudiment)
        return tuple(found)


@cache
def rudiments():
    """The 40 PAS rudiments, in PAS order (read once)."""
    return read_rudiments()


def rudiment(name):
    """The shipped rudiment called ``name``: its name (``flam-tap``), title (``Flam Tap``) or number (22 or ``"22"``).

    A name not found is a ParameterError (``parameter`` "rudiment") suggesting the likeliest names: those
    that contain it, else the closest (:func:`drumstroke._checks.closest`).

    >>> try:
    ...     rudiment("paradiddle")
    ... except ParameterError as error:
    ...     print(error.allowed)
    ...     print(str(error).split(", got ")[1])
    a name, title or number in [1, 40] of the rudiments rudiments() lists
    'paradiddle' (did you mean 'single-paradiddle', 'double-paradiddle' or 'triple-paradiddle'?)
    """
    known = rudiments()
    allowed = f"a name, title or number in [1, {len(known)}] of the rudiments rudiments() lists"
    if isinstance(name, bool) or not isinstance(name, (int, str)):
        raise ParameterError(f"rudiment must be {allowed}, got {shown(name)}", parameter="rudiment", value=name,
                             allowed=allowed)
    if isinstance(name, int) or name.strip().isdigit():
        number = int(name)
        for entry in known:
            if entry.number == number:
                return entry
        raise ParameterError(f"rudiment must be {allowed}, got {shown(name)}", parameter="rudiment", value=name,
                             allowed=allowed)
    key = re.sub(r"[\s_]+", "-", name.strip().lower()).replace("#", "")
    by_name = {entry.name: entry for entry in known}
    if key in by_name:
        return by_name[key]
    raise ParameterError(f"rudiment must be {allowed}, got {shown(name)}{did_you_mean(key, by_name)}",
                         parameter="rudiment", value=name, allowed=allowed)


def _rudiment_from_table(table, where):
    if not isinstance(table, dict):
        raise ParameterError(f"{where} must be a table, got {table!r}")
    check_keys(where, table, _KEYS)
    missing = [key for key in _KEYS if key not in table]
    if "number" in table and "name" in table:
        where = f"rudiment {table['number']} ({table['name']})"
    if missing:
        raise ParameterError(f"{where} needs the key {missing[0]!r}; the keys are {', '.join(_KEYS)}")
    rows = table["notes"]
    if not isinstance(rows, list) or not rows:
        raise ParameterError(f"{where}: notes must be a non-empty list of [beat, stick, dynamic(, kind, value)]")
    notes = [_row_note(row, f"{where}: notes[{j}]") for j, row in enumerate(rows)]
    return Rudiment(table["number"], table["name"], table["title"], table["family"], table["tempo"], table["cycle"],
                    notes)


def _row_note(row, where):
    if not isinstance(row, list) or len(row) not in (3, 5):
        raise ParameterError(f"{where} must be [beat, stick, dynamic] or [beat, stick, dynamic, kind, value], "
                             f"got {row!r}")
    beat = _fraction(row[0], f"{where}: beat")
    if len(row) == 3:
        return Note(beat, row[1], row[2])
    kind, value = row[3], row[4]
    if kind == "buzz":
        value = _fraction(value, f"{where}: buzz length")
    return Note(beat, row[1], row[2], kind, value)


def _note(note, cycle, where):
    """The note with its beat as a Fraction, checked field by field (ornaments are checked together later)."""
    try:
        beat, stick, dynamic, kind, value = Note(*note)
    except TypeError:
        raise ParameterError(f"{where} must be a Note (beat, stick, dynamic[, kind, value]), got {note!r}") from None
    beat = _fraction(beat, f"{where}: beat")
    if not 0 <= beat < cycle:
        raise ParameterError(f"{where}: beat must be in [0, cycle) = [0, {cycle}) beats, got {beat}")
    check_choice(f"{where}: stick", stick, tuple(STICKS))
    check_choice(f"{where}: dynamic", dynamic, tuple(DYNAMICS))
    check_choice(f"{where}: kind", kind, KINDS)
    if kind == "grace":
        if dynamic != "grace":
            raise ParameterError(f"{where}: a grace note's dynamic must be 'grace', got {dynamic!r}")
        value = check_real(f"{where}: grace offset", value, low=GRACE_OFFSETS_MS[0], high=GRACE_OFFSETS_MS[1],
                           unit="ms")
    elif dynamic == "grace":
        raise ParameterError(f"{where}: dynamic 'grace' is for grace notes (kind 'grace'), got kind {kind!r}")
    elif kind == "buzz":
        value = _fraction(value, f"{where}: buzz length")
        if not 0 < value <= cycle:
            raise ParameterError(f"{where}: buzz length must be in (0, cycle] = (0, {cycle}] beats, got {value}")
    elif value is not None:
        raise ParameterError(f"{where}: a plain note takes no value, got {value!r}")
    return Note(beat, stick, dynamic, kind, value)


def _check_ornaments(notes, cycle, where):
    """Grace notes lead to a main note on the other stick; a stick plays one main note a beat; a buzz ends in time."""
    mains = {}
    for i, note in enumerate(notes):
        if note.kind != "grace":
            if (note.beat, note.stick) in mains:
                raise ParameterError(f"{where}: notes[{i}] is a second note on stick {note.stick} at beat {note.beat}")
            mains[note.beat, note.stick] = note
    for i, note in enumerate(notes):
        if note.kind == "grace" and (note.beat, _OTHER[note.stick]) not in mains:
            raise ParameterError(f"{where}: notes[{i}], a grace note on {note.stick} at beat {note.beat}, needs a main "
                                 f"note on {_OTHER[note.stick]} at the same beat")
    for i, note in enumerate(notes):
        if note.kind != "buzz":
            continue
        later = [n.beat + (n.beat <= note.beat) * cycle for n in notes if n.stick == note.stick and n is not note]
        end = min(later, default=note.beat + cycle)
        if note.beat + note.value > end:
            raise ParameterError(f"{where}: notes[{i}], a buzz on {note.stick} at beat {note.beat} lasting "
                                 f"{note.value} beats, runs into the stick's next note at beat {end % cycle}")


def _cycle_order(note):
    return note.beat, (note.value if note.kind == "grace" else 0.0), note.stick


def _tempo_range(tempo, where):
    if not isinstance(tempo, (tuple, list)) or len(tempo) != 2:
        raise ParameterError(f"{where}: tempo must be [bottom, top] beats per minute, got {tempo!r}")
    low = check_real(f"{where}: tempo bottom", tempo[0], low=TEMPO_LIMITS[0], high=TEMPO_LIMITS[1],
                     unit="beats per minute")
    high = check_real(f"{where}: tempo top", tempo[1], low=low, high=TEMPO_LIMITS[1], low_open=True,
                      unit="beats per minute")
    return low, high


def _fraction(value, what):
    """A number or a string such as "1/3" as an exact Fraction (a float by its shortest decimal: 0.1 is 1/10)."""
    if isinstance(value, Fraction) or (isinstance(value, int) and not isinstance(value, bool)):
        return Fraction(value)
    if isinstance(value, Real) and not isinstance(value, bool) and math.isfinite(value):
        return Fraction(repr(float(value)))
    if isinstance(value, str):
        try:
            return Fraction(value.strip())
        except (ValueError, ZeroDivisionError):
            pass
    raise ParameterError(f"{what} must be a finite number or a fraction such as \"1/3\", got {value!r}")


def _span(cycle, bars, beats_per_bar):
    """Beats played: ``bars`` bars of ``beats_per_bar`` (default: whole cycles, at least 4 beats)."""
    if beats_per_bar is None:
        bar = cycle * math.ceil(4 / cycle)
    else:
        bar = _fraction(check_real("beats_per_bar", beats_per_bar, low=0.0, high=1000.0, low_open=True,
                                   unit="beats"), "beats_per_bar")
    return bars * bar


def _count(number, unit):
    """``1 beat``, ``4 beats``, ``4.5 beats``."""
    return f"{_text(float(number))} {unit}" + ("" if number == 1 else "s")


def _text(number):
    """A number to 12 significant digits (a beat read back within 1e-11 of itself, far below a sample)."""
    return f"{float(number):.12g}"
