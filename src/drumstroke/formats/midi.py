"""Standard MIDI Files, both ways: impacts written as General MIDI percussion, notes read from scores.

Needs the ``midi`` extra (mido), imported when a file is read or written.

:func:`write_midi` writes impacts as notes, one track per stick, on the tempo map of
the score they came from, with velocities from :func:`drumstroke.dynamics.level_to_velocity`.
:func:`read_midi` reads a score: its tempo map, its tracks, and its notes in seconds,
streamed in time order across all tracks. A :class:`TempoMap` is the music's time: tempo
changes and time signatures by beat.

Examples
--------
>>> import pathlib, tempfile
>>> with tempfile.TemporaryDirectory() as folder:
...     path = pathlib.Path(folder) / "stroke.mid"
...     written = write_midi(path, [Track("stick", [0.0, 0.25, 0.5], [0.0, -6.0, -60.0], [38, 40, 40])],
...                          tempo_map=TempoMap.constant(96.0, meter=(3, 4)), title="free-bounce (paper)")
...     score = read_midi(path)
...     notes = list(score.notes())
>>> score.track_names, score.tempo_map.tempi, score.tempo_map.meters
(('free-bounce (paper)', 'stick'), ((0.0, 625000.0),), ((0.0, 3, 4),))
>>> [(note.note, note.velocity) for note in notes]
[(38, 95), (40, 80)]
>>> notes[1]
Note(time=0.25, note=40, velocity=80, channel=10, track=1)
"""

import heapq
import io
import math
from bisect import bisect_right
from dataclasses import dataclass, field
from functools import cached_property
from itertools import pairwise
from typing import NamedTuple

import numpy as np

from .._atomic import write_atomic
from .._checks import as_vector, check_int, check_real, check_vector
from ..dynamics import FLOOR_DB, level_to_velocity
from ..errors import ParameterError
from .reading import MIB, read_bytes

SUFFIXES = (".mid", ".midi")
"""The extensions of the MIDI files written."""

MAX_BYTES = 32 * MIB
"""The largest MIDI file read (bytes): some four million notes."""

TICKS_PER_BEAT = 1920
"""The resolution of written files (ticks per quarter note): at 120 bpm a tick is 0.26 ms, so a note is
within 0.13 ms of its impact (half a tick). It is rounded up to a multiple of the resolution the tempo
map was read at (so every tempo change stays on a tick), coarser for a file that would otherwise pass
:data:`MAX_TICKS`, and never so coarse that half a tick passes 0.5 ms at the slowest tempo."""

MAX_TICKS = 10_000_000
"""The most ticks a written file lasts when it can (pretty_midi refuses longer files as "likely corrupt"):
at 1920 ticks a beat, 43 minutes at 120 bpm."""

NOTE_LENGTH = 0.020
"""How long a written note sounds (s), unless the next note of the same key starts sooner."""

PERCUSSION_CHANNEL = 10
"""General MIDI percussion channel, counted from 1 as musicians do (mido's channel 9)."""

GM_PERCUSSION = {
    27: "High Q", 28: "Slap", 29: "Scratch Push", 30: "Scratch Pull", 31: "Sticks", 32: "Square Click",
    33: "Metronome Click", 34: "Metronome Bell",
    35: "Acoustic Bass Drum", 36: "Bass Drum 1", 37: "Side Stick", 38: "Acoustic Snare", 39: "Hand Clap",
    40: "Electric Snare", 41: "Low Floor Tom", 42: "Closed Hi-Hat", 43: "High Floor Tom", 44: "Pedal Hi-Hat",
    45: "Low Tom", 46: "Open Hi-Hat", 47: "Low-Mid Tom", 48: "Hi Mid Tom", 49: "Crash Cymbal 1", 50: "High Tom",
    51: "Ride Cymbal 1", 52: "Chinese Cymbal", 53: "Ride Bell", 54: "Tambourine", 55: "Splash Cymbal", 56: "Cowbell",
    57: "Crash Cymbal 2", 58: "Vibraslap", 59: "Ride Cymbal 2", 60: "Hi Bongo", 61: "Low Bongo", 62: "Mute Hi Conga",
    63: "Open Hi Conga", 64: "Low Conga", 65: "High Timbale", 66: "Low Timbale", 67: "High Agogo", 68: "Low Agogo",
    69: "Cabasa", 70: "Maracas", 71: "Short Whistle", 72: "Long Whistle", 73: "Short Guiro", 74: "Long Guiro",
    75: "Claves", 76: "Hi Wood Block", 77: "Low Wood Block", 78: "Mute Cuica", 79: "Open Cuica", 80: "Mute Triangle",
    81: "Open Triangle",
    82: "Shaker", 83: "Jingle Bell", 84: "Belltree", 85: "Castanets", 86: "Mute Surdo", 87: "Open Surdo",
}
"""The General MIDI percussion key map: key on :data:`PERCUSSION_CHANNEL` → its sound's name.

Keys 35–81 are General MIDI Level 1's (the MMA's names; its "Closed Hi Hat" written "Closed Hi-Hat"
as its pedal and open hi-hats are), 27–34 and 82–87 the ones General MIDI Level 2 adds. Other keys
have no General MIDI name."""

FASTEST_TEMPO = 60_000
"""The shortest beat a tempo map holds (µs per quarter note): 1000 bpm, as text patterns allow."""

SLOWEST_MIDI_TEMPO = 0xFFFFFF
"""The longest beat a MIDI file can hold (µs per quarter note, 24 bits): 3.58 bpm."""

_MAX_DELTA = 0x0FFFFFFF  # the largest delta time a variable-length quantity holds (ticks)
_MAX_RESOLUTION = 0x7FFF  # the largest ticks per beat a MIDI header holds


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
    track : int >= 0
        The track it is in, counted from 0 in the file's order.
    """

    time: float
    note: int
    velocity: int
    channel: int
    track: int = 0

    def __post_init__(self):
        check_real("time", self.time, low=0.0, unit="s")
        check_int("note", self.note, low=0, high=127)
        check_int("velocity", self.velocity, low=1, high=127)
        check_int("channel", self.channel, low=1, high=16)
        check_int("track", self.track, low=0)


@dataclass(frozen=True)
class TempoMap:
    """The music's time: tempo changes and time signatures, each from a beat (quarter notes from 0).

    Attributes
    ----------
    tempi : tuple of (beat, µs per beat)
        The first at beat 0, beats strictly increasing; each tempo in [:data:`FASTEST_TEMPO`, inf)
        µs per quarter note (60e6 / bpm). Default: 120 bpm throughout, MIDI's default.
    meters : tuple of (beat, numerator, denominator)
        Time signatures, the first at beat 0, beats strictly increasing; numerator in [1, 255],
        denominator a power of two in [1, 128]. Default: 4/4.
    resolution : int or None
        The ticks per beat the beats were read at (a MIDI file's), so a writer can put every
        change on a tick of its own; None when they were not read from ticks.

    Examples
    --------
    >>> waltz = TempoMap(tempi=((0.0, 500_000), (6.0, 1_000_000)), meters=((0.0, 3, 4),))
    >>> waltz.seconds([0.0, 6.0, 7.0]).tolist(), waltz.beats([3.0, 4.0]).tolist()
    ([0.0, 3.0, 4.0], [6.0, 7.0])
    """

    tempi: tuple = ((0.0, 500_000.0),)
    meters: tuple = ((0.0, 4, 4),)
    resolution: int | None = None

    def __post_init__(self):
        tempi = tuple((check_real(f"tempi[{i}] beat", beat, low=0.0),
                       check_real(f"tempi[{i}] tempo", tempo, low=FASTEST_TEMPO, unit="µs per beat"))
                      for i, (beat, tempo) in enumerate(_pairs("tempi", self.tempi, 2)))
        meters = tuple((check_real(f"meters[{i}] beat", beat, low=0.0),
                        check_int(f"meters[{i}] numerator", numerator, low=1, high=255),
                        check_int(f"meters[{i}] denominator", denominator, low=1, high=128))
                       for i, (beat, numerator, denominator) in enumerate(_pairs("meters", self.meters, 3)))
        for i, (_, _, denominator) in enumerate(meters):
            if denominator & (denominator - 1):
                raise ParameterError(f"meters[{i}] denominator must be a power of two in [1, 128], got {denominator}")
        for name, changes in (("tempi", tempi), ("meters", meters)):
            if changes[0][0] != 0.0:
                raise ParameterError(f"{name}[0] must be at beat 0, got beat {changes[0][0]:g}")
            for i in range(1, len(changes)):
                if changes[i][0] <= changes[i - 1][0]:
                    raise ParameterError(f"{name} beats must increase: {name}[{i}] at beat {changes[i][0]:g} comes "
                                         f"after beat {changes[i - 1][0]:g}")
        if self.resolution is not None:
            check_int("resolution", self.resolution, low=1, high=_MAX_RESOLUTION, unit="ticks per beat")
        object.__setattr__(self, "tempi", tempi)
        object.__setattr__(self, "meters", meters)

    @classmethod
    def constant(cls, bpm, *, meter=(4, 4)):
        """One tempo (beats per minute, in (0, 1000]) and one time signature (numerator, denominator)."""
        bpm = check_real("tempo", bpm, low=0.0, high=1000.0, low_open=True, unit="bpm")
        return cls(tempi=((0.0, 60e6 / bpm),), meters=((0.0, *meter),))

    @cached_property
    def _starts(self):
        """Beats and seconds where each tempo starts."""
        beats = np.array([beat for beat, _ in self.tempi])
        per_beat = np.array([tempo * 1e-6 for _, tempo in self.tempi])
        return beats, np.concatenate(([0.0], np.cumsum(np.diff(beats) * per_beat[:-1]))), per_beat

    def seconds(self, beats):
        """Seconds at ``beats`` (quarter notes from 0, >= 0) [shape of beats]."""
        starts, seconds, per_beat = self._starts
        beats = np.asarray(beats, dtype=float)
        i = np.searchsorted(starts, beats, side="right") - 1
        return seconds[i] + (beats - starts[i]) * per_beat[i]

    def beats(self, seconds):
        """Beats at ``seconds`` (s from 0, >= 0): the inverse of :meth:`seconds` [shape of seconds]."""
        starts, at, per_beat = self._starts
        seconds = np.asarray(seconds, dtype=float)
        i = np.searchsorted(at, seconds, side="right") - 1
        return starts[i] + (seconds - at[i]) / per_beat[i]


class Track(NamedTuple):
    """What :func:`write_midi` writes as one track: a stick's impacts as notes.

    Attributes
    ----------
    name : str
        The track's name (e.g. the stick's).
    times : array_like of float >= 0 [shape=(n,)]
        Impact times (s), finite and non-decreasing.
    levels_db : array_like of float [shape=(n,)]
        Impact levels (dB re 1 m/s tip speed, see :attr:`drumstroke.Impacts.level_db`);
        −inf (a zero-speed impact) is allowed, NaN and +inf are not.
    notes : int or array_like of int in [0, 127] [shape=(n,)]
        The key of each impact's note, or one key for all.
    """

    name: str
    times: object
    levels_db: object
    notes: object


def write_midi(path, tracks, *, tempo_map=None, channel=PERCUSSION_CHANNEL, title="", bundle=None):
    """Write impacts as MIDI notes, one track each, to ``path`` (a type-1 Standard MIDI File), atomically.

    Track 0 holds the title, the time signatures and the tempo changes; then one
    track per :class:`Track`. Each impact becomes a note at its time (to half a
    tick, see :data:`TICKS_PER_BEAT`) with velocity ``level_to_velocity(level)``.
    Impacts quieter than :data:`drumstroke.dynamics.FLOOR_DB` (they would all clip
    to velocity 1) are left out; impacts of one track that round to the same tick
    and key merge into the louder. A note sounds :data:`NOTE_LENGTH` (at least one
    tick), or until the next note of the same key starts on any track if that is
    sooner, so notes of one key never overlap on the channel; on a shared tick a
    track's note-off comes before its note-on.

    Parameters
    ----------
    path : str or path-like
        The file to write; its folder is made if missing.
    tracks : sequence of Track
        At least one.
    tempo_map : TempoMap or None
        The tempo changes and time signatures written (default: 120 bpm, 4/4). Times in
        seconds do not depend on it; every tempo must be at most :data:`SLOWEST_MIDI_TEMPO`.
    channel : int in [1, 16]
        MIDI channel counted from 1 (10, General MIDI percussion, by default).
    title : str
        Track 0's name (UTF-8), e.g. the score and the model that made it.
    bundle : Bundle or None
        Put the file in place with this :class:`drumstroke._atomic.Bundle`'s others (default: at once).

    Returns
    -------
    list of list of Note
        Per track, the notes written, in order, with the times they were written at (s);
        ``Note.track`` is the track's number in the file (from 1).
    """
    tempo_map = TempoMap() if tempo_map is None else tempo_map
    if not isinstance(tempo_map, TempoMap):
        raise ParameterError(f"tempo_map must be a TempoMap, got {tempo_map!r}")
    tracks = _check_tracks(tracks)
    channel = check_int("channel", channel, low=1, high=16)
    if not isinstance(title, str):
        raise ParameterError(f"title must be a str, got {title!r}")
    clock = _Clock(tempo_map, max((float(track.times.max()) for track in tracks if track.times.size), default=0.0)
                   + NOTE_LENGTH)

    parts = [_notes_of(track, i, clock) for i, track in enumerate(tracks)]
    ends = _ends(parts, clock)
    mido = _mido()
    conductor = [(0, mido.MetaMessage("track_name", name=title))]
    conductor += [(tick, mido.MetaMessage("time_signature", numerator=numerator, denominator=denominator))
                  for tick, numerator, denominator in clock.meters]
    conductor += [(tick, mido.MetaMessage("set_tempo", tempo=tempo)) for tick, tempo in clock.tempi]
    files_tracks = [_delta_track(mido, sorted(conductor, key=lambda event: event[0]))]
    for track, (starts, keys, velocities), track_ends in zip(tracks, parts, ends):
        events = [(0, 0, mido.MetaMessage("track_name", name=track.name))]
        for start, end, key, velocity in zip(starts.tolist(), track_ends.tolist(), keys.tolist(), velocities.tolist()):
            events.append((start, 1, mido.Message("note_on", channel=channel - 1, note=key, velocity=velocity)))
            events.append((end, 0, mido.Message("note_off", channel=channel - 1, note=key, velocity=0)))
        events.sort(key=lambda event: event[:2])  # stable: on a shared tick, note-offs first
        files_tracks.append(_delta_track(mido, [(tick, message) for tick, _, message in events]))

    buffer = io.BytesIO()
    mido.MidiFile(type=1, ticks_per_beat=clock.resolution, charset="utf-8", tracks=files_tracks).save(file=buffer)
    write_atomic(path, buffer.getvalue(), bundle=bundle)
    return [[Note(time, key, velocity, channel, number)
             for time, key, velocity in zip(clock.seconds(starts).tolist(), keys.tolist(), velocities.tolist())]
            for number, (starts, keys, velocities) in enumerate(parts, start=1)]


@dataclass(frozen=True, eq=False)
class MidiScore:
    """A Standard MIDI File read for its notes: what :func:`read_midi` returns.

    Attributes
    ----------
    path : str
        The file, as given.
    type : int
        0 (one track) or 1 (synchronous tracks).
    track_names : tuple of str
        Each track's name ('' when it has none), in the file's order.
    tempo_map : TempoMap
        Every tempo change and time signature, from any track, by beat; its resolution is the file's.
    """

    path: str
    type: int
    track_names: tuple
    tempo_map: TempoMap
    _file: object = field(repr=False)

    def notes(self):
        """The notes started in the file (note_on with velocity >= 1), in time order, streamed.

        Notes on the same tick come in track order, then file order. Each note's time
        (s) follows the tempo map: 120 bpm until the first tempo change.

        Yields
        ------
        Note
        """
        resolution = self._file.ticks_per_beat
        changes = [(round(beat * resolution), tempo) for beat, tempo in self.tempo_map.tempi]
        ticks = [tick for tick, _ in changes]
        seconds = [0.0]
        for (tick, tempo), (following, _) in pairwise(changes):
            seconds.append(seconds[-1] + (following - tick) * tempo * 1e-6 / resolution)
        streams = [_note_ons(track, number) for number, track in enumerate(self._file.tracks)]
        for tick, number, key, velocity, channel in heapq.merge(*streams):
            i = bisect_right(ticks, tick) - 1
            time = seconds[i] + (tick - ticks[i]) * changes[i][1] * 1e-6 / resolution
            yield Note(time, key, velocity, channel + 1, number)


def read_midi(path):
    """The Standard MIDI File at ``path``, read: its tracks, its tempo map and (streamed) its notes.

    Type 0 and type 1 files are read; tempo changes and time signatures in any
    track apply to every track from their tick on. A note_on with velocity 0 ends
    a note, as a note_off does.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    MidiScore

    Raises
    ------
    ParameterError
        If the file is missing, unreadable, truncated or not MIDI, is of type 2,
        times in SMPTE frames, or holds a tempo outside 3.58–1000 bpm or a time
        signature that is not one; the message names the file.
    """
    file = _load(path)
    where = f"MIDI file {str(path)!r}"
    if file.type not in (0, 1):
        raise ParameterError(f"{where} is of type {file.type}; only types 0 and 1 (synchronous tracks) can be read")
    if file.ticks_per_beat <= 0:
        reason = "0 ticks per beat" if file.ticks_per_beat == 0 else "SMPTE frames, which is not supported"
        raise ParameterError(f"{where} times in {reason}; a file must time in ticks per beat (1 or more)")
    names = tuple(next((m.name for m in track if m.type == "track_name"), "") for track in file.tracks)
    return MidiScore(str(path), file.type, names, _tempo_map(file, where), file)


def _note_ons(track, number):
    """(tick, track number, key, velocity, channel from 0) of each note_on with velocity >= 1 of a track."""
    tick = 0
    for message in track:
        tick += message.time
        if message.type == "note_on" and message.velocity:
            yield tick, number, message.note, message.velocity, message.channel


def _tempo_map(file, where):
    """The tempo changes and time signatures of every track, by beat; a bad value is refused naming where it is."""
    tempi, meters = {0: 500_000}, {0: (4, 4)}
    for events in sorted(_meta_events(file), key=lambda event: event[:2]):  # by tick, then track
        tick, number, message = events
        at = f"{where}, track {number} at tick {tick}"
        if message.type == "set_tempo":
            if not FASTEST_TEMPO <= message.tempo <= SLOWEST_MIDI_TEMPO:
                bpm = f"{60e6 / message.tempo:.6g} bpm" if message.tempo else "an infinite tempo"
                raise ParameterError(f"{at}: tempo must be in [{FASTEST_TEMPO}, {SLOWEST_MIDI_TEMPO}] µs per beat "
                                     f"(3.58-1000 bpm), got {message.tempo} ({bpm})")
            tempi[tick] = message.tempo
        else:
            denominator = message.denominator
            if not 1 <= message.numerator <= 255 or not 1 <= denominator <= 128 or denominator & (denominator - 1):
                raise ParameterError(f"{at}: a time signature must be N/D with N in [1, 255] and D a power of two in "
                                     f"[1, 128], got {message.numerator}/{denominator}")
            meters[tick] = (message.numerator, denominator)
    resolution = file.ticks_per_beat
    return TempoMap(tempi=tuple((tick / resolution, tempo) for tick, tempo in sorted(tempi.items())),
                    meters=tuple((tick / resolution, *meter) for tick, meter in sorted(meters.items())),
                    resolution=resolution)


def _meta_events(file):
    for number, track in enumerate(file.tracks):
        tick = 0
        for message in track:
            tick += message.time
            if message.type in ("set_tempo", "time_signature"):
                yield tick, number, message


def _load(path):
    """The mido.MidiFile at ``path``, read within bounds; any failure to read it is a ParameterError naming the file."""
    mido = _mido()
    from mido.midifiles.meta import KeySignatureError

    data = read_bytes(path, "MIDI file", limit=MAX_BYTES)
    try:
        return mido.MidiFile(file=io.BytesIO(data))
    except EOFError:
        reason = "it ends too early (truncated?)"
    except OSError as error:
        reason = error.strerror or f"it is not a valid MIDI file ({error})"
    except (ValueError, KeyError, IndexError, TypeError, KeySignatureError) as error:
        reason = f"it is not a valid MIDI file ({type(error).__name__}: {error})"
    raise ParameterError(f"MIDI file {str(path)!r} cannot be read: {reason}")


class _Clock:
    """Seconds <-> ticks of a written file that ends at ``end`` (s): its resolution and its tempo map in whole
    ticks and µs."""

    def __init__(self, tempo_map, end):
        slowest = max(tempo for _, tempo in tempo_map.tempi)
        if slowest > SLOWEST_MIDI_TEMPO:
            raise ParameterError(f"tempo_map: a MIDI file holds tempi of 3.58 bpm and faster, got {60e6 / slowest:.6g} "
                                 f"bpm ({slowest:.0f} µs per beat)")
        base = tempo_map.resolution or 1  # a multiple of it puts every change read from a file on a tick
        finest = base * math.ceil(slowest / 1000.0 / base)  # half a tick <= 0.5 ms at the slowest tempo
        resolution = base * math.ceil(TICKS_PER_BEAT / base)
        beats = 1.01 * float(tempo_map.beats(end)) + 1.0  # the last tick's beat, with room for rounding
        if beats * resolution > MAX_TICKS:
            resolution = base * math.floor(MAX_TICKS / beats / base)
        resolution = max(resolution, finest)
        self.resolution = resolution if resolution <= _MAX_RESOLUTION else base
        self.tempi = []
        for beat, tempo in tempo_map.tempi:
            tick, tempo = round(beat * self.resolution), round(tempo)
            if self.tempi and tick == self.tempi[-1][0]:
                self.tempi[-1] = (tick, tempo)
            else:
                self.tempi.append((tick, tempo))
        self.meters = [(round(beat * self.resolution), numerator, denominator)
                       for beat, numerator, denominator in tempo_map.meters]
        self._ticks = np.array([tick for tick, _ in self.tempi], dtype=float)
        self._per_tick = np.array([tempo * 1e-6 / self.resolution for _, tempo in self.tempi])
        self._seconds = np.concatenate(([0.0], np.cumsum(np.diff(self._ticks) * self._per_tick[:-1])))

    def ticks(self, seconds):
        """The nearest tick of each time (s) [int64, shape of seconds]."""
        i = np.searchsorted(self._seconds, seconds, side="right") - 1
        return np.rint(self._ticks[i] + (seconds - self._seconds[i]) / self._per_tick[i]).astype(np.int64)

    def seconds(self, ticks):
        """The time (s) of each tick [shape of ticks]."""
        i = np.searchsorted(self._ticks, ticks, side="right") - 1
        return self._seconds[i] + (ticks - self._ticks[i]) * self._per_tick[i]


def _notes_of(track, number, clock):
    """Start ticks, keys and velocities of one track's audible notes, one per tick and key (the louder)."""
    ticks = clock.ticks(track.times)
    late = np.flatnonzero(ticks > _MAX_DELTA)
    if late.size:
        i = late[0]
        raise ParameterError(f"tracks[{number}].times[{i}] must be at most {float(clock.seconds(_MAX_DELTA)):g} s (the "
                             f"longest time a MIDI file holds on this tempo map), got {float(track.times[i])!r}")
    audible = track.levels_db >= FLOOR_DB
    ticks, keys = ticks[audible], track.notes[audible]
    velocities = level_to_velocity(track.levels_db[audible]).reshape(-1)
    order = np.lexsort((keys, ticks))
    ticks, keys, velocities = ticks[order], keys[order], velocities[order]
    if ticks.size == 0:
        return ticks, keys, velocities
    first = np.flatnonzero(np.diff(ticks, prepend=-1) | np.diff(keys, prepend=-1))  # each run of one tick and key
    return ticks[first], keys[first], np.maximum.reduceat(velocities, first)


def _ends(parts, clock):
    """Each note's end tick: NOTE_LENGTH later (at least a tick), or the next start of its key on any track."""
    starts = np.concatenate([ticks for ticks, _, _ in parts])
    keys = np.concatenate([keys for _, keys, _ in parts])
    ends = np.maximum(clock.ticks(clock.seconds(starts) + NOTE_LENGTH), starts + 1)
    order = np.lexsort((starts, keys))
    ordered_starts, ordered_keys = starts[order], keys[order]
    following = np.full(starts.size, np.iinfo(np.int64).max)
    # the next strictly later start of the same key: search each key's run of sorted starts
    for key in np.unique(keys).tolist():
        run = np.flatnonzero(ordered_keys == key)
        run_starts = ordered_starts[run]
        after = np.searchsorted(run_starts, run_starts, side="right")
        following[order[run]] = np.where(after < run.size, run_starts[np.minimum(after, run.size - 1)],
                                         np.iinfo(np.int64).max)
    ends = np.minimum(ends, following)
    return np.split(ends, np.cumsum([ticks.size for ticks, _, _ in parts])[:-1])


def _delta_track(mido, events):
    """A MidiTrack of (absolute tick, message) events in order, with delta times, ended."""
    track, previous = mido.MidiTrack(), 0
    for tick, message in events:
        track.append(message.copy(time=tick - previous))
        previous = tick
    track.append(mido.MetaMessage("end_of_track"))
    return track


def _check_tracks(tracks):
    """``tracks`` as Tracks of float arrays and int keys of equal lengths, checked entry by entry."""
    if isinstance(tracks, Track) or not isinstance(tracks, (list, tuple)) or not tracks:
        raise ParameterError(f"tracks must be a non-empty list of Track, got {tracks!r}")
    checked = []
    for i, track in enumerate(tracks):
        if not isinstance(track, Track):
            raise ParameterError(f"tracks[{i}] must be a Track(name, times, levels_db, notes), got {track!r}")
        if not isinstance(track.name, str):
            raise ParameterError(f"tracks[{i}].name must be a str, got {track.name!r}")
        times, levels = _check_impacts(f"tracks[{i}].", track.times, track.levels_db)
        notes = np.asarray(track.notes)
        if notes.ndim == 0:
            notes = np.full(times.size, notes)
        if notes.shape != times.shape or notes.size and (notes.dtype.kind not in "iu" or notes.min() < 0
                                                         or notes.max() > 127):
            raise ParameterError(f"tracks[{i}].notes must be one MIDI key or one per time, each an integer in "
                                 f"[0, 127], got {track.notes!r}")
        checked.append(Track(track.name, times, levels, notes.astype(np.int64)))
    return checked


def _check_impacts(prefix, times, levels_db):
    """``times`` and ``levels_db`` as float arrays of equal length, checked entry by entry."""
    times = check_vector(f"{prefix}times", times, low=0.0, unit="s")
    levels_db = as_vector(f"{prefix}levels_db", levels_db)
    if times.shape != levels_db.shape:
        raise ParameterError(f"{prefix}times and {prefix}levels_db must have the same length, got {times.size} and "
                             f"{levels_db.size}")
    decreasing = np.flatnonzero(np.diff(times) < 0)
    if decreasing.size:
        i = decreasing[0] + 1
        raise ParameterError(f"{prefix}times must be non-decreasing: times[{i}] = {float(times[i])!r} s comes before "
                             f"times[{i - 1}] = {float(times[i - 1])!r} s")
    bad = np.flatnonzero(np.isnan(levels_db) | (levels_db == math.inf))
    if bad.size:
        i = bad[0]
        raise ParameterError(f"{prefix}levels_db[{i}] must be a number in [-inf, inf) dB, got {float(levels_db[i])!r}")
    return times, levels_db


def _pairs(name, changes, size):
    """``changes`` as a non-empty tuple of tuples of ``size`` items, or a ParameterError naming ``name``."""
    try:
        changes = tuple(tuple(change) for change in changes)
    except TypeError:
        changes = None
    if not changes or any(len(change) != size for change in changes):
        shape = "(beat, tempo)" if size == 2 else "(beat, numerator, denominator)"
        raise ParameterError(f"{name} must be a non-empty sequence of {shape}, got {changes!r}")
    return changes


def _mido():
    try:
        import mido
    except ImportError as error:  # pragma: no cover - exercised only without the extra
        raise ImportError("drumstroke MIDI needs mido: pip install 'drumstroke[midi]'") from error
    return mido
