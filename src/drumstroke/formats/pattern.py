"""Text patterns, both ways: a tempo, then one note per line.

::

    # a backbeat: comments start with '#'
    tempo 96
    # beat   stroke        velocity   stick (optional)
    0        single        100
    1        tap           40         left

Beats count from 0 in quarter notes at the tempo (beats per minute); the stroke is a name;
the velocity MIDI's 1–127; the stick optional. Reading gives plain rows, each with where it
came from (``NAME line N``) for messages; :mod:`drumstroke.score` makes notes of them.

Examples
--------
>>> tempo, rows = parse_pattern("tempo 120\\n0 single 100\\n0.5 tap 40 left\\n")
>>> tempo, rows[1]
(120.0, PatternRow(beat=0.5, stroke='tap', velocity=40, stick='left', source='pattern line 3'))
>>> print(pattern_text(tempo, rows), end="")
tempo 120
0 single 100
0.5 tap 40 left
"""

import re
from pathlib import Path
from typing import NamedTuple

from .._atomic import write_atomic
from .._checks import check_real
from ..errors import ParameterError


class PatternRow(NamedTuple):
    """One note line: its beat (quarter notes from 0), stroke name, velocity (1–127), stick (or None) and source."""

    beat: float
    stroke: str
    velocity: int
    stick: str | None
    source: str


def read_pattern_file(path):
    """The tempo (bpm) and rows of the pattern file at ``path``; errors name the file and the line."""
    path = Path(path)
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as error:
        reason = error.strerror if isinstance(error, OSError) else "not a UTF-8 text file"
        raise ParameterError(f"pattern {str(path)!r} cannot be read: {reason}") from None
    return parse_pattern(text, name=str(path))


def parse_pattern(text, *, name="pattern"):
    """The tempo (bpm) and rows of a pattern given as text, in file order."""
    tempo, rows = None, []
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
        rows.append(PatternRow(beat, fields[1], velocity, fields[3] if len(fields) == 4 else None, where))
    if tempo is None:
        raise ParameterError(f"{name} is empty: it needs a 'tempo BPM' line and notes")
    if not rows:
        raise ParameterError(f"{name} has a tempo but no notes")
    return tempo, rows


def pattern_text(tempo, rows):
    """The text of a pattern: the tempo line, then one line per row (beat, stroke, velocity[, stick])."""
    lines = [f"tempo {tempo:g}"]
    for row in rows:
        beat, stroke, velocity, stick = row[:4]
        lines.append(f"{beat:.17g} {stroke} {int(velocity)}" + (f" {stick}" if stick else ""))
    return "\n".join(lines) + "\n"


def write_pattern(path, tempo, rows):
    """Write a pattern file, atomically."""
    write_atomic(path, pattern_text(tempo, rows))


def _number(text, where, what):
    try:
        return float(text)
    except ValueError:
        raise ParameterError(f"{where}: {what} must be a number, got {text!r}") from None


def _integer(text, where):
    if not re.fullmatch(r"\d{1,3}", text) or not 1 <= int(text) <= 127:
        raise ParameterError(f"{where}: velocity must be an integer in [1, 127], got {text!r}")
    return int(text)
