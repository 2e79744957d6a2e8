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
(read with :func:`drumstroke.formats.midi.read_midi_notes`) become score notes
through a note mapping (:func:`read_mapping`): a TOML file ::

    [notes]
    38 = "single"                                # acoustic snare
    40 = { stroke = "press-roll", stick = "left" }

Without one, :func:`default_mapping` maps 38 (acoustic snare) to ``single``,
37 (side stick) to ``tap``, 40 (electric snare) to ``press-roll``, and note
60 + i to the library's i-th stroke (the order of ``drumstroke library list``).

:func:`read_score` reads either kind of file, by its name's ending.

Examples
--------
>>> notes = parse_pattern("tempo 120\\n0 single 100\\n0.5 tap 40 left\\n")
>>> [(n.time, n.stroke, n.velocity, n.stick) for n in notes]
[(0.0, 'single', 100, 'right'), (0.25, 'tap', 40, 'left')]
"""

import re
from dataclasses import dataclass
from pathlib import Path

from ._checks import check_keys, check_real
from .errors import ParameterError
from .formats.pattern import parse_pattern as pattern_rows
from .formats.pattern import read_pattern_file
from .formats.toml import read_toml

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
    return _notes(*read_pattern_file(path))


def parse_pattern(text, *, name="pattern"):
    """The notes of a text pattern given as a string, in time order."""
    return _notes(*pattern_rows(text, name=name))


def _notes(tempo, rows):
    notes = [ScoreNote(row.beat * 60.0 / tempo, row.stroke, row.velocity, row.stick or DEFAULT_STICK,
                       source=row.source) for row in rows]
    return sorted(notes, key=lambda n: n.time)


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



MIDI_SUFFIXES = (".mid", ".midi")
"""File name endings :func:`read_score` reads as MIDI files; any other file is a text pattern."""


def read_score(path, *, mapping=None, stroke_names=None, mapping_name="mapping"):
    """The notes of a score file: a MIDI file through a note mapping, or a text pattern.

    Parameters
    ----------
    path : str or Path
        A ``.mid``/``.midi`` file (times in s from its ticks and tempo changes) or a text pattern
        (see the module docstring), which names its strokes itself.
    mapping : str, Path, dict or None
        For a MIDI file only: a mapping file (:func:`read_mapping`) or ``{MIDI note: (stroke, stick)}``.
        Default: :func:`default_mapping` of ``stroke_names``.
    stroke_names : sequence of str or None
        The library's stroke names in its order, for the default mapping.
    mapping_name : str
        What the caller calls ``mapping``, for messages (the command line: ``--mapping``).

    Returns
    -------
    notes : list of ScoreNote
        In time order.
    unmapped : dict
        {MIDI note number: how many notes had no mapping}; they are left out. Empty for a pattern.

    Raises
    ------
    ParameterError
        If the file cannot be read, a mapping is given for a text pattern, or a MIDI file comes with
        neither a mapping nor stroke names.
    """
    path = Path(path)
    if path.suffix.lower() not in MIDI_SUFFIXES:
        if mapping is not None:
            raise ParameterError(f"{mapping_name} applies to MIDI scores (.mid, .midi); {str(path)!r} is a text pattern, "
                                 "which names its strokes")
        return read_pattern(path), {}
    from .formats.midi import read_midi_notes

    if mapping is None:
        if stroke_names is None:
            raise ParameterError(f"MIDI score {str(path)!r} needs a mapping or the library's stroke_names")
        mapping = default_mapping(list(stroke_names))
    elif not isinstance(mapping, dict):
        mapping = read_mapping(mapping)
    return from_midi_notes(read_midi_notes(path), mapping)
