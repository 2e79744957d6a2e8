"""Scores: what to play, when, how loud and with which stick — from a text pattern or MIDI notes.

A text pattern is the tempo, then one note per line::

    # a backbeat: comments start with '#'
    tempo 96
    # beat   stroke        velocity   stick (optional, default right)
    0        single        100
    1        tap           40         left
    1.5      double        80         left
    2        single        110

Beats count from 0 in quarter notes at the tempo (beats per minute); stroke
names are the library's; velocity is MIDI's 1–127; the stick is any name
(a-z, 0-9, ``_``, ``-``), one trajectory per stick. A MIDI score's notes
(read with :func:`drumstroke.render.midi.read_midi_notes`) become score notes
through a note mapping (:func:`read_mapping`): a TOML file ::

    [notes]
    38 = "single"                                # acoustic snare
    40 = { stroke = "press-roll", stick = "left" }

Without one, :func:`default_mapping` maps 38 (acoustic snare) to ``single``,
37 (side stick) to ``tap``, 40 (electric snare) to ``press-roll``, and note
60 + i to the library's i-th stroke (the order of ``drumstroke library list``).

Examples
--------
>>> notes = parse_pattern("tempo 120\\n0 single 100\\n0.5 tap 40 left\\n")
>>> [(n.time, n.stroke, n.velocity, n.stick) for n in notes]
[(0.0, 'single', 100, 'right'), (0.25, 'tap', 40, 'left')]
"""

import re
from dataclasses import dataclass
from pathlib import Path

from ._checks import check_keys, check_real, read_toml
from .errors import ParameterError

DEFAULT_STICK = "right"
_STICK = re.compile(r"^[a-z0-9_-]{1,32}$")
_GM_NAMES = {38: "single", 37: "tap", 40: "press-roll"}
FIRST_LIBRARY_NOTE = 60
"""MIDI note of the library's first stroke in the default mapping (C4); the i-th stroke is 60 + i."""


@dataclass(frozen=True)
class ScoreNote:
    """One note to play.

    Attributes
    ----------
    time : float
        When its first impact should land (s from the score's start).
    stroke : str
        A library stroke's name.
    velocity : int in [1, 127]
        Sets the first impact's level (see :mod:`drumstroke.dynamics`).
    stick : str
    source : str
        Where it came from ("line 4", "MIDI note 38 at 1.5 s"), for messages.
    """

    time: float
    stroke: str
    velocity: int
    stick: str = DEFAULT_STICK
    source: str = ""

    def __post_init__(self):
        where = self.source or "note"
        check_real(f"{where}: time", self.time, low=0.0, high=1e6, unit="s")
        if isinstance(self.velocity, bool) or not isinstance(self.velocity, int) or not 1 <= self.velocity <= 127:
            raise ParameterError(f"{where}: velocity must be an integer in [1, 127], got {self.velocity!r}")
        if not isinstance(self.stroke, str) or not self.stroke:
            raise ParameterError(f"{where}: stroke must be a stroke name, got {self.stroke!r}")
        if not isinstance(self.stick, str) or not _STICK.match(self.stick):
            raise ParameterError(f"{where}: stick must be 1-32 of a-z, 0-9, '_', '-', got {self.stick!r}")


def read_pattern(path):
    """The notes of a text pattern file (see the module docstring), in time order."""
    path = Path(path)
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as error:
        reason = error.strerror if isinstance(error, OSError) else "not a UTF-8 text file"
        raise ParameterError(f"pattern {str(path)!r} cannot be read: {reason}") from None
    return parse_pattern(text, name=str(path))


def parse_pattern(text, *, name="pattern"):
    """The notes of a text pattern given as a string, in time order."""
    tempo, notes = None, []
    for number, line in enumerate(text.splitlines(), start=1):
        fields = line.split("#", 1)[0].split()
        if not fields:
            continue
        where = f"{name} line {number}"
        if tempo is None:
            if len(fields) != 2 or fields[0] != "tempo":
                raise ParameterError(f"{where}: the first line must be 'tempo BPM', got {line.strip()!r}")
            tempo = check_real(f"{where}: tempo", _number(fields[1], where, "tempo"), low=0.0, high=1000.0,
                               low_open=True, unit="beats per minute")
            continue
        if len(fields) not in (3, 4):
            raise ParameterError(f"{where}: a note is 'beat stroke velocity [stick]', got {line.strip()!r}")
        beat = check_real(f"{where}: beat", _number(fields[0], where, "beat"), low=0.0, high=1e6)
        velocity = _integer(fields[2], where)
        stick = fields[3] if len(fields) == 4 else DEFAULT_STICK
        notes.append(ScoreNote(beat * 60.0 / tempo, fields[1], velocity, stick, source=where))
    if tempo is None:
        raise ParameterError(f"{name} is empty: it needs a 'tempo BPM' line and notes")
    if not notes:
        raise ParameterError(f"{name} has a tempo but no notes")
    return sorted(notes, key=lambda n: n.time)


def _number(text, where, what):
    try:
        return float(text)
    except ValueError:
        raise ParameterError(f"{where}: {what} must be a number, got {text!r}") from None


def _integer(text, where):
    if not re.fullmatch(r"\d{1,3}", text) or not 1 <= int(text) <= 127:
        raise ParameterError(f"{where}: velocity must be an integer in [1, 127], got {text!r}")
    return int(text)


def default_mapping(stroke_names):
    """The default MIDI note → (stroke, stick) mapping for a library with ``stroke_names`` (in order)."""
    mapping = {FIRST_LIBRARY_NOTE + i: (name, DEFAULT_STICK) for i, name in enumerate(stroke_names)
               if FIRST_LIBRARY_NOTE + i <= 127}
    mapping.update({note: (name, DEFAULT_STICK) for note, name in _GM_NAMES.items() if name in stroke_names})
    return mapping


def read_mapping(path):
    """A note mapping file: ``{midi note: (stroke, stick)}``."""
    data = read_toml(path, "mapping")
    check_keys("mapping", data, ("notes",))
    table = data.get("notes")
    if not isinstance(table, dict) or not table:
        raise ParameterError(f"mapping {str(path)!r} needs a [notes] table such as 38 = \"single\"")
    mapping = {}
    for key, value in table.items():
        if not re.fullmatch(r"\d{1,3}", key) or int(key) > 127:
            raise ParameterError(f"mapping notes: key must be a MIDI note number 0-127, got {key!r}")
        if isinstance(value, str):
            value = {"stroke": value}
        if not isinstance(value, dict):
            raise ParameterError(f"mapping notes.{key} must be a stroke name or a table, got {value!r}")
        check_keys(f"mapping notes.{key}", value, ("stroke", "stick"))
        stroke, stick = value.get("stroke"), value.get("stick", DEFAULT_STICK)
        if not isinstance(stroke, str) or not stroke:
            raise ParameterError(f"mapping notes.{key}.stroke must be a stroke name, got {stroke!r}")
        if not isinstance(stick, str) or not _STICK.match(stick):
            raise ParameterError(f"mapping notes.{key}.stick must be 1-32 of a-z, 0-9, '_', '-', got {stick!r}")
        mapping[int(key)] = (stroke, stick)
    return mapping


def from_midi_notes(midi_notes, mapping):
    """Score notes from MIDI notes (objects with time s, note, velocity) through ``mapping``.

    Returns
    -------
    notes : list of ScoreNote
        In time order.
    unmapped : dict
        {MIDI note number: how many notes had no mapping}; they are left out.
    """
    notes, unmapped = [], {}
    for note in midi_notes:
        if note.note not in mapping:
            unmapped[note.note] = unmapped.get(note.note, 0) + 1
            continue
        stroke, stick = mapping[note.note]
        source = f"MIDI note {note.note} at {note.time:.6g} s"
        notes.append(ScoreNote(float(note.time), stroke, int(note.velocity), stick, source=source))
    return sorted(notes, key=lambda n: n.time), unmapped

