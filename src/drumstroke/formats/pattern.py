"""Text patterns, both ways: a tempo, optionally a meter, then one note per line (:data:`FORMAT`).

Reading gives plain rows, each with where it came from (``NAME line N``) for messages;
:mod:`drumstroke.score` makes notes of them.

Examples
--------
>>> pattern = parse_pattern("tempo 120\\nmeter 3/4\\n0 single 100\\n0.5 tap 40 left\\n")
>>> pattern.tempo, pattern.meter, pattern.rows[1]
(120.0, (3, 4), PatternRow(beat=0.5, stroke='tap', velocity=40, stick='left', source='pattern line 4', beats=None, piece=None, state=None))
>>> print(pattern_text(*pattern), end="")
tempo 120
meter 3/4
0 single 100
0.5 tap 40 left
"""

import math
import re
from typing import NamedTuple

import numpy as np

from .._atomic import write_atomic
from .._checks import check_real
from ..errors import ParameterError
from .reading import MIB, read_text

_PIECE = re.compile(r"^([a-z][a-z0-9_-]{0,31})(?::([a-z]{1,32}))?$")  # a kit piece's name (a letter first: never a
# number), and a state of it (the hi-hat's) after a colon

MAX_BYTES = 16 * MIB
"""The largest pattern file read (bytes): some 800,000 notes."""

FORMAT = """\
A text pattern is UTF-8 text, one item a line; '#' starts a comment, and blank
lines are skipped:

  tempo BPM      the first line: quarter notes a minute, in (0, 1000]
  meter N/D      optional, before the first note: the time signature (N in
                 [1, 255], D a power of two up to 128; default 4/4); it changes
                 no time, and is written into MIDI files
  BEAT STROKE VELOCITY [STICK [BEATS] [PIECE]]
                 a note: its time in quarter notes from 0 (a number in [0, 1e6];
                 0.5 is the second eighth note); its stroke; a MIDI velocity
                 1-127 (the level of its impact); the stick that plays it (1-32
                 of a-z, 0-9, '_', '-'; default right; auto: the planner picks
                 one), one trajectory per stick; on a kit (compose --kit) a
                 limb: right, left, right-foot, left-foot or auto; then the
                 kit's piece it is played on (default snare; compose --kit
                 reads it, the snare-only compose plays every note on the
                 snare), and after a colon the hi-hat's state: hihat:closed
                 (the default), hihat:half, hihat:open, hihat:pedal (the foot).
                 Notes may come in any order.
                 The stroke is one of:
                   auto    the planner designs the stroke that plays the note
                           (a diddle, a flam, a drag, an accent or a tap is just
                           notes and velocities on sticks)
                   buzz    a multiple-bounce stroke from the note's time for
                           BEATS quarter notes (the fifth field; default: until
                           the stick's next note)
                   NAME    a stroke of the library, played as it is stored
                           (without one, of the shipped palette: 'drumstroke
                           presets' lists them)

For example:

  # a backbeat, and a flam and a buzz the planner designs
  tempo 96
  0      single   100
  0.5    tap      40     left
  1      double   90
  1.95   auto     50     left      # the flam's grace note, 31 ms early
  2      auto     110    right
  3      buzz     80     auto  0.5
  3.5    auto     90     auto  ride     # on the kit: the ride
  3.75   auto     70     auto  hihat:open
"""
"""The text pattern format, complete: what ``drumstroke compose --help`` prints."""


class Pattern(NamedTuple):
    """A pattern read: its tempo (bpm), its rows in file order and its meter (numerator, denominator)."""

    tempo: float
    rows: list
    meter: tuple = (4, 4)


class PatternRow(NamedTuple):
    """One note line: its beat (quarter notes from 0), stroke name, velocity (1–127), stick (or None), source,
    a buzz's length in beats (or None), the kit's piece it names (or None) and the piece's state (or None)."""

    beat: float
    stroke: str
    velocity: int
    stick: str | None
    source: str
    beats: float | None = None
    piece: str | None = None
    state: str | None = None


def read_pattern_file(path):
    """The :class:`Pattern` in the file at ``path``; errors name the file and the line."""
    return parse_pattern(read_text(path, "pattern", limit=MAX_BYTES), name=str(path))


def parse_pattern(text, *, name="pattern"):
    """The :class:`Pattern` given as text: its tempo (bpm), its rows in file order and its meter."""
    tempo, rows, meter = None, [], (4, 4)
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
            if not math.isfinite(60e6 / tempo):  # a beat longer than any number of µs: no tempo map holds it
                raise ParameterError(f"{where}: tempo {tempo!r} beats per minute is too slow: a beat of 60e6/tempo µs "
                                     "must be a finite number")
            continue
        if fields[0] == "meter":
            if rows or len(fields) != 2:
                raise ParameterError(f"{where}: a meter is one 'meter N/D' line before the notes, got {line.strip()!r}")
            meter = _meter(fields[1], where)
            continue
        if len(fields) not in (3, 4, 5, 6):
            raise ParameterError(f"{where}: a note is 'beat stroke velocity [stick [beats] [piece]]', got "
                                 f"{line.strip()!r}")
        beat = check_real(f"{where}: beat", _number(fields[0], where, "beat"), low=0.0, high=1e6)
        velocity = _integer(fields[2], where)
        beats, piece, state = _beats_and_piece(fields, where, line)
        rows.append(PatternRow(beat, fields[1], velocity, fields[3] if len(fields) >= 4 else None, where, beats,
                               piece, state))
    if tempo is None:
        raise ParameterError(f"{name} is empty: it needs a 'tempo BPM' line and notes")
    if not rows:
        raise ParameterError(f"{name} has a tempo but no notes")
    return Pattern(tempo, rows, meter)


def _beats_and_piece(fields, where, line):
    """A note line's buzz length (beats, or None), piece and its state (each None if not named): the fields after
    its stick."""
    rest = fields[4:]
    beats = None
    if rest and rest[0][:1] in "0123456789.+-":  # a number: a buzz's length
        if fields[1] != "buzz":
            raise ParameterError(f"{where}: only a buzz takes a length (the fifth field), got {line.strip()!r}")
        beats = check_real(f"{where}: buzz length", _number(rest[0], where, "buzz length"), low=0.0, high=1e6,
                           low_open=True, unit="beats")
        rest = rest[1:]
    if len(rest) > 1 or (rest and _PIECE.match(rest[0]) is None):
        raise ParameterError(f"{where}: a note is 'beat stroke velocity [stick [beats] [piece]]', a piece 1-32 of "
                             f"a-z, 0-9, '_', '-' starting with a letter (and a state after a colon: hihat:open), "
                             f"got {line.strip()!r}")
    return (beats, *_PIECE.match(rest[0]).groups()) if rest else (beats, None, None)


def pattern_text(tempo, rows, meter=(4, 4)):
    """The text of a pattern: the tempo line, the meter if not 4/4, then one line per row (beat, stroke, velocity[,
    stick[, a buzz's beats]])."""
    lines = [f"tempo {_shortest(tempo)}"] + ([f"meter {meter[0]}/{meter[1]}"] if tuple(meter) != (4, 4) else [])
    for row in rows:
        beat, stroke, velocity, stick = row[:4]
        beats = row[5] if len(row) > 5 else None
        piece = row[6] if len(row) > 6 else None
        state = row[7] if len(row) > 7 else None
        named = stick or beats is not None or piece
        line = f"{_shortest(beat)} {stroke} {int(velocity)}" + (f" {stick or 'right'}" if named else "")
        lines.append(line + (f" {_shortest(beats)}" if beats is not None else "") + (f" {piece}" if piece else "")
                     + (f":{state}" if piece and state else ""))
    return "\n".join(lines) + "\n"


def _shortest(number):
    """``number`` as the fewest digits that read back as the same float, never in exponent form (0.955, not
    0.95499999999999996; 120, not 120.0)."""
    return np.format_float_positional(float(number), trim="-")


def write_pattern(path, tempo, rows, meter=(4, 4)):
    """Write a pattern file, atomically."""
    write_atomic(path, pattern_text(tempo, rows, meter))


def _number(text, where, what):
    try:
        return float(text)  # a number too large is inf, which the range check refuses
    except ValueError:
        raise ParameterError(f"{where}: {what} must be a number, got {text!r}") from None


def _meter(text, where):
    numerator, _, denominator = text.partition("/")
    if re.fullmatch(r"\d{1,3}", numerator) and re.fullmatch(r"\d{1,3}", denominator):
        numerator, denominator = int(numerator), int(denominator)
        if 1 <= numerator <= 255 and denominator in (1, 2, 4, 8, 16, 32, 64, 128):
            return numerator, denominator
    raise ParameterError(f"{where}: meter must be N/D with N in [1, 255] and D a power of two in [1, 128], "
                         f"got {text!r}")


def _integer(text, where):
    if not re.fullmatch(r"\d{1,3}", text) or not 1 <= int(text) <= 127:
        raise ParameterError(f"{where}: velocity must be an integer in [1, 127], got {text!r}")
    return int(text)
