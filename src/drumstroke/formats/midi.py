"""Standard MIDI Files, both ways: impacts written as General MIDI percussion, notes read from scores.

Needs the ``midi`` extra (mido), imported when a file is read or written.

:func:`write_midi` writes a stroke's impacts as notes whose velocities come from
:func:`drumstroke.dynamics.level_to_velocity`; :func:`read_midi_notes` reads the
notes of a score back, in seconds, for composition.

Examples
--------
>>> import pathlib, tempfile
>>> with tempfile.TemporaryDirectory() as folder:
...     path = pathlib.Path(folder) / "stroke.mid"
...     written = write_midi(path, [0.0, 0.25, 0.5], [0.0, -6.0, -60.0], title="free-bounce (paper)")
...     notes = read_midi_notes(path)
>>> len(written), [note.velocity for note in notes]
(2, [95, 80])
>>> notes[1]
Note(time=0.25, note=38, velocity=80, channel=10)
"""

import io
import math
from dataclasses import dataclass
from numbers import Integral
from pathlib import Path

import numpy as np

from .._atomic import write_atomic
from .._checks import as_vector, check_real, check_vector
from ..dynamics import FLOOR_DB, level_to_velocity
from ..errors import ParameterError

SUFFIXES = (".mid", ".midi")
"""The extensions of the MIDI files written."""

TICKS_PER_BEAT = 1920
"""Resolution of written files (ticks per quarter note): at 120 bpm a tick is 0.26 ms, so a note is
within 0.13 ms of its impact (half a tick, 15.625/tempo ms in general)."""

NOTE_LENGTH = 0.020
"""How long a written note sounds (s), unless the next note on the same key starts sooner."""

SNARE = 38
"""General MIDI percussion key of the acoustic snare."""

PERCUSSION_CHANNEL = 10
"""General MIDI percussion channel, counted from 1 as musicians do (mido's channel 9)."""

_MAX_DELTA = 0x0FFFFFFF  # the largest delta time a variable-length quantity holds (ticks)


@dataclass(frozen=True)
class Note:
    """One note of a score.

    Attributes
    ----------
    time : float >= 0
        Start (s) from the beginning of the file.
    note : int in [0, 127]
        MIDI key (38 is the General MIDI acoustic snare).
    velocity : int in [1, 127]
        MIDI velocity; :func:`drumstroke.dynamics.velocity_to_level` gives its level.
    channel : int in [1, 16]
        MIDI channel counted from 1 (General MIDI percussion is 10).
    """

    time: float
    note: int
    velocity: int
    channel: int

    def __post_init__(self):
        check_real("time", self.time, low=0.0, unit="s")
        _check_int("note", self.note, 0, 127)
        _check_int("velocity", self.velocity, 1, 127)
        _check_int("channel", self.channel, 1, 16)


def write_midi(path, times, levels_db, *, note=SNARE, channel=PERCUSSION_CHANNEL, tempo=120.0, title=""):
    """Write impacts as one-track (type 0) MIDI percussion notes to ``path``, atomically.

    Each impact becomes a note at its time (rounded to the nearest of
    :data:`TICKS_PER_BEAT` ticks per beat) with velocity
    ``level_to_velocity(level)``. Impacts quieter than
    :data:`drumstroke.dynamics.FLOOR_DB` (they would all clip to velocity 1)
    are left out. Impacts that round to the tick of the previous written note
    are merged into it, which keeps the louder velocity. A note sounds
    :data:`NOTE_LENGTH`, or until the next note starts if that is sooner (its
    note-off then comes first on that tick), and at least one tick.

    Parameters
    ----------
    path : str or path-like
        The file to write; its folder is made if missing.
    times : array_like of float >= 0 [shape=(n,)]
        Impact times (s), finite and non-decreasing.
    levels_db : array_like of float [shape=(n,)]
        Impact levels (dB re 1 m/s tip speed, see :attr:`drumstroke.Impacts.level_db`);
        −inf (a zero-speed impact) is allowed, NaN and +inf are not.
    note : int in [0, 127]
        MIDI key of every note (38, the General MIDI acoustic snare, by default).
    channel : int in [1, 16]
        MIDI channel counted from 1 (10, General MIDI percussion, by default).
    tempo : float in (0, 1000]
        Beats per minute written in the file. Times in seconds do not depend on
        it; the timing error, half a tick, is 15.625/tempo ms.
    title : str
        The track name (UTF-8), e.g. the stroke and the model that made it.

    Returns
    -------
    list of Note
        The notes written, in order, with the times they were written at (s);
        ``len()`` of it is the number of notes, at most n.
    """
    times, levels_db = _check_impacts(times, levels_db)
    note = _check_int("note", note, 0, 127)
    channel = _check_int("channel", channel, 1, 16)
    tempo = check_real("tempo", tempo, low=0.0, high=1000.0, low_open=True, unit="bpm")
    if not isinstance(title, str):
        raise ParameterError(f"title must be a str, got {title!r}")

    mido = _mido()
    microseconds_per_beat = mido.bpm2tempo(tempo)
    seconds_per_tick = microseconds_per_beat * 1e-6 / TICKS_PER_BEAT
    ticks = np.rint(times / seconds_per_tick).astype(np.int64)
    too_late = np.flatnonzero(ticks > _MAX_DELTA)
    if too_late.size:
        i = too_late[0]
        latest = _MAX_DELTA * seconds_per_tick
        raise ParameterError(
            f"times[{i}] must be in [0, {latest:g}] s at tempo {tempo:g} bpm (the longest time a MIDI file holds), "
            f"got {float(times[i])!r}"
        )

    starts, velocities = _merge_same_ticks(ticks, levels_db)
    length = max(1, round(NOTE_LENGTH / seconds_per_tick))
    ends = np.minimum(starts + length, np.append(starts[1:], np.iinfo(np.int64).max))

    track = mido.MidiTrack([
        mido.MetaMessage("track_name", name=title),
        mido.MetaMessage("set_tempo", tempo=microseconds_per_beat),
    ])
    previous = 0
    for start, end, velocity in zip(starts.tolist(), ends.tolist(), velocities.tolist()):
        track.append(mido.Message("note_on", channel=channel - 1, note=note, velocity=velocity, time=start - previous))
        track.append(mido.Message("note_off", channel=channel - 1, note=note, velocity=0, time=end - start))
        previous = end
    track.append(mido.MetaMessage("end_of_track"))

    buffer = io.BytesIO()
    mido.MidiFile(type=0, ticks_per_beat=TICKS_PER_BEAT, charset="utf-8", tracks=[track]).save(file=buffer)
    write_atomic(path, buffer.getvalue())
    return [Note(start * seconds_per_tick, note, velocity, channel)
            for start, velocity in zip(starts.tolist(), velocities.tolist())]


def read_midi_notes(path):
    """The notes of the standard MIDI file at ``path``, in seconds, sorted by time.

    Type 0 and type 1 files are read; tempo changes in any track apply from
    their tick on (120 bpm until the first). A note_on with velocity 0 ends a
    note, as a note_off does; notes on the same tick keep the file's order.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    list of Note
        Every note started in the file (at least one), with its start (s).

    Raises
    ------
    ParameterError
        If the file is missing, unreadable, truncated or not MIDI, is of type 2
        or times in SMPTE frames, or holds no notes; the message names the file.
    """
    midi = _load(path)
    where = f"MIDI file {str(path)!r}"
    if midi.type not in (0, 1):
        raise ParameterError(f"{where} is of type {midi.type}; only types 0 and 1 (synchronous tracks) can be read")
    if midi.ticks_per_beat <= 0:
        raise ParameterError(f"{where} times in SMPTE frames, which is not supported; only ticks per beat are")

    notes = []
    tick = 0
    tempo = 500_000  # µs per beat: 120 bpm, the standard's default
    tempo_tick, tempo_seconds = 0, 0.0  # where the current tempo took over
    # merge_tracks sorts stably by tick, so notes come out in time order.
    for message in _mido().merge_tracks(midi.tracks, skip_checks=True):
        tick += message.time
        seconds = tempo_seconds + (tick - tempo_tick) * tempo * 1e-6 / midi.ticks_per_beat
        if message.type == "set_tempo":
            tempo, tempo_tick, tempo_seconds = message.tempo, tick, seconds
        elif message.type == "note_on" and message.velocity > 0:
            notes.append(Note(seconds, message.note, message.velocity, message.channel + 1))
    if not notes:
        raise ParameterError(f"{where} has no notes (no note_on with a velocity of 1 or more)")
    return notes


def _load(path):
    """The mido.MidiFile at ``path``; any failure to read it is a ParameterError naming the file."""
    mido = _mido()
    from mido.midifiles.meta import KeySignatureError

    try:
        return mido.MidiFile(Path(path))
    except EOFError:
        reason = "it ends too early (truncated?)"
    except OSError as error:
        reason = error.strerror or str(error)
    except (ValueError, KeyError, IndexError, TypeError, KeySignatureError) as error:
        reason = f"it is not a valid MIDI file ({type(error).__name__}: {error})"
    raise ParameterError(f"MIDI file {str(path)!r} cannot be read: {reason}")


def _merge_same_ticks(ticks, levels_db):
    """Start ticks and velocities of the notes to write: audible impacts, one per tick (the louder)."""
    audible = levels_db >= FLOOR_DB
    ticks = ticks[audible]
    velocities = level_to_velocity(levels_db[audible]).reshape(-1)
    if ticks.size == 0:
        return ticks, velocities
    first = np.flatnonzero(np.diff(ticks, prepend=-1))  # ticks are sorted: each run of equal ticks starts here
    return ticks[first], np.maximum.reduceat(velocities, first)


def _check_impacts(times, levels_db):
    """``times`` and ``levels_db`` as float arrays of equal length, checked entry by entry."""
    times = check_vector("times", times, low=0.0, unit="s")
    levels_db = as_vector("levels_db", levels_db)
    if times.shape != levels_db.shape:
        raise ParameterError(
            f"times and levels_db must have the same length, got {times.size} and {levels_db.size}"
        )
    decreasing = np.flatnonzero(np.diff(times) < 0)
    if decreasing.size:
        i = decreasing[0] + 1
        raise ParameterError(
            f"times must be non-decreasing: times[{i}] = {float(times[i])!r} s comes before "
            f"times[{i - 1}] = {float(times[i - 1])!r} s"
        )
    for i, level in enumerate(levels_db.tolist()):
        if math.isnan(level) or level == math.inf:
            raise ParameterError(f"levels_db[{i}] must be a number in [-inf, inf) dB, got {level!r}")
    return times, levels_db


def _check_int(name, value, low, high):
    """Return ``value`` as an int if it is an integer in [low, high]."""
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise ParameterError(f"{name} must be an integer in [{low}, {high}], got {value!r}")
    if not low <= value <= high:
        raise ParameterError(f"{name} must be in [{low}, {high}], got {value!r}")
    return int(value)


def _mido():
    try:
        import mido
    except ImportError as error:  # pragma: no cover - exercised only without the extra
        raise ImportError("drumstroke MIDI needs mido: pip install 'drumstroke[midi]'") from error
    return mido
