"""Scores: what to play, when, how loud and with which stick — from a text pattern or a MIDI file.

A text pattern is the tempo, optionally a meter, then one note per line::

    # a backbeat: comments start with '#'
    tempo 96
    meter 4/4
    # beat   stroke        velocity   stick (optional, default right)
    0        single        100
    1        tap           40         left
    1.5      double        80         left
    2        single        110

Beats count from 0 in quarter notes at the tempo (beats per minute); a stroke
is ``auto`` (the planner designs it, :mod:`drumstroke.design`), ``buzz`` (a
multiple-bounce stroke, its length in beats as a fifth field) or a library
stroke's name; velocity is MIDI's 1–127; the stick is any name (a-z, 0-9, ``_``,
``-``), one trajectory per stick, or ``auto`` for the planner to choose.

A MIDI file's notes become score notes through a note mapping: only the
channels chosen (by default 10, General MIDI percussion) and the tracks chosen
(by default all) are read, and on them only the keys the mapping names are
played; every other note is skipped and counted in the :class:`ScoreReport`.
A mapping is a TOML file (:func:`read_mapping`) ::

    [notes]
    38 = "single"                                # acoustic snare
    40 = { stroke = "press-roll", stick = "left" }

Without one, :func:`default_mapping` applies: on channel 10 the drum map
(:data:`DRUM_MAP`: the General MIDI snares, 38 and 40, and 37, side stick, each
a note the planner designs, ``auto``, on a stick it chooses); on any other
channel, where a key is a pitch, also key 60 + i (C4 and up) as the library's
i-th stroke (the order of ``drumstroke library list``).

:func:`read_score` reads either kind of file, by its name's ending, into a :class:`Score`.

Examples
--------
>>> notes = parse_pattern("tempo 120\\n0 single 100\\n0.5 tap 40 left\\n")
>>> [(n.time, n.stroke, n.velocity, n.stick) for n in notes]
[(0.0, 'single', 100, 'right'), (0.25, 'tap', 40, 'left')]
"""

import re
from array import array
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

from ._checks import check_int, check_keys, check_real, shown
from .errors import ParameterError
from .formats.midi import GM_PERCUSSION, PERCUSSION_CHANNEL, TempoMap
from .formats.pattern import parse_pattern as pattern_rows
from .formats.pattern import read_pattern_file
from .formats.toml import reading_toml

DEFAULT_STICK = "right"
_STICK = re.compile(r"^[a-z0-9_-]{1,32}$")


class DrumKey(NamedTuple):
    """A row of the drum map: a General MIDI percussion key, read and written.

    Attributes
    ----------
    name : str
        Its General MIDI percussion name.
    stroke : str
        The library stroke the key is read as, by default, on channel 10.
    written : str or None
        The impacts a written MIDI file puts on the key: "first" (each stroke's first
        impact: the note the score asked for) or "bounce" (its later impacts); None for none.
    """

    name: str
    stroke: str
    written: str | None


DRUM_MAP = {
    37: DrumKey(GM_PERCUSSION[37], "auto", None),
    38: DrumKey(GM_PERCUSSION[38], "auto", "first"),
    40: DrumKey(GM_PERCUSSION[40], "auto", "bounce"),
}
"""The drum map, both ways, in one table: MIDI key on channel 10 → what it is read as and written for.

Read: songs put their snare on either of General MIDI's two snares, 38 and 40, so both
are notes the planner designs (``auto``) at their velocity; so is the side stick (37),
a click on the rim, played on the head at its velocity by a robot without a rim stroke.
The planner chooses each note's stick. Every other key of the percussion channel (kick,
hi-hats, toms, cymbals, and 60–81, the Latin percussion) is not the snare drum, and is
skipped.

Written: every impact is a snare note, so a General MIDI player sounds all of them
on a snare; a stroke's first impact (the note the score asked for) is on 38 and its
bounces on 40, so in a DAW the notes and the bounces sit on two rows of the piano
roll, to select, mute or re-voice apart."""

FIRST_IMPACT_NOTE = next(key for key, row in DRUM_MAP.items() if row.written == "first")
"""The key of each written stroke's first impact (38, acoustic snare): see :data:`DRUM_MAP`."""

BOUNCE_NOTE = next(key for key, row in DRUM_MAP.items() if row.written == "bounce")
"""The key of each written stroke's later impacts, its bounces (40, electric snare): see :data:`DRUM_MAP`."""

FIRST_LIBRARY_NOTE = 60
"""MIDI key of the library's first stroke in the default mapping off channel 10 (C4); the i-th stroke is 60 + i."""

MIDI_SUFFIXES = (".mid", ".midi")
"""File name endings :func:`read_score` reads as MIDI files; any other file is a text pattern."""

PLANNED = ("auto", "buzz")
"""The strokes the planner designs (:mod:`drumstroke.design`), not a library's: a note, and a buzz over a span."""

AUTO_STICK = "auto"
"""What a pattern or a mapping says for a stick the planner chooses (a note's ``stick`` is then None)."""

SKIP_REASONS = ("track", "channel", "unmapped")
"""Why a MIDI note is skipped, in the order they are tested: its track or its channel was not chosen, or
the mapping has no stroke for its key."""


@dataclass(frozen=True)
class ScoreNote:
    """One note to play.

    Attributes
    ----------
    time : float
        When its first impact should land (s from the score's start).
    stroke : str
        ``"auto"`` (the planner designs it), ``"buzz"`` (a multiple-bounce stroke) or a library stroke's name.
    velocity : int in [1, 127]
        Sets the first impact's level (see :mod:`drumstroke.dynamics`).
    stick : str or None
        None: the planner chooses it.
    source : str
        Where it came from ("song.pattern line 4", "song.mid note 38 at 1.5 s (channel 10, track 2)"),
        for messages.
    duration : float or None
        s, a buzz's span; None: until its stick's next note.
    beat : float or None
        Where it falls in quarter notes from the score's start (for choosing sticks: the lead hand on the beat).
    piece : str or None
        The kit's piece it is played on (a pattern's sixth field, a MIDI key's piece on a kit); None: the snare.
    state : str or None
        The piece's state a pattern names (``hihat:open``: the hi-hat's, one of its states in the kit); None:
        by its key, else the hi-hat closed (a hand) or its pedal (a foot).
    key : int in [0, 127] or None
        The MIDI key it was read from (None for a pattern's note).
    """

    time: float
    stroke: str
    velocity: int
    stick: str | None = DEFAULT_STICK
    source: str = ""
    duration: float | None = None
    beat: float | None = None
    piece: str | None = None
    key: int | None = None
    state: str | None = None

    def __post_init__(self):
        where = self.source or "note"
        if self.piece is not None and (not isinstance(self.piece, str) or not self.piece):
            raise ParameterError(f"{where}: piece must be a kit piece's name or None, got {self.piece!r}")
        if self.state is not None and (self.piece is None or not isinstance(self.state, str) or not self.state):
            raise ParameterError(f"{where}: state must be a state's name on a piece named, or None, got {self.state!r}")
        if self.key is not None:
            check_int(f"{where}: key", self.key, low=0, high=127)
        check_real(f"{where}: time", self.time, low=0.0, high=1e6, unit="s")
        if isinstance(self.velocity, bool) or not isinstance(self.velocity, int) or not 1 <= self.velocity <= 127:
            raise ParameterError(f"{where}: velocity must be an integer in [1, 127], got {self.velocity!r}")
        if not isinstance(self.stroke, str) or not self.stroke:
            raise ParameterError(f"{where}: stroke must be a stroke name, got {self.stroke!r}")
        if self.stick is not None and (not isinstance(self.stick, str) or not _STICK.match(self.stick)
                                       or self.stick == AUTO_STICK):
            raise ParameterError(f"{where}: stick must be 1-32 of a-z, 0-9, '_', '-' (not 'auto'), or None for the "
                                 f"planner to choose, got {self.stick!r}")
        if self.duration is not None:
            if self.stroke != "buzz":
                raise ParameterError(f"{where}: only a buzz has a duration, got {self.duration!r} for {self.stroke!r}")
            check_real(f"{where}: duration", self.duration, low=0.0, high=3600.0, low_open=True, unit="s")
        if self.beat is not None:
            check_real(f"{where}: beat", self.beat, low=0.0, high=1e7, unit="quarter notes")


@dataclass(frozen=True, eq=False)
class ScoreReport:
    """What reading a score played and skipped: counts per reason and channel, and each skipped note.

    Attributes
    ----------
    source : str
        The score file.
    counts : dict
        ``{(reason, channel): notes}``: reason "played" or one of :data:`SKIP_REASONS`; channel
        1–16 (None for a text pattern, whose notes are all played).
    track_names : tuple of str
        The MIDI file's track names, by track number (empty for a text pattern).
    mapped : bool
        Whether a mapping was given (notes off it are "not in the mapping", else not in the default one).
    kit : bool
        Whether the keys were read as a kit's (notes off it are "not on the kit").
    """

    source: str
    counts: dict
    track_names: tuple = ()
    mapped: bool = False
    _skipped: tuple = field(default=(), repr=False)  # compact columns: time, key, velocity, channel, track, reason
    kit: bool = False

    def count(self, reason=None, channel=None):
        """How many notes were skipped for ``reason`` ("played" for the others; None: every note), on ``channel``
        (None: every channel)."""
        return sum(n for (r, c), n in self.counts.items()
                   if (reason is None or r == reason) and (channel is None or c == channel))

    @property
    def played(self):
        """How many notes the score gives to play."""
        return self.count("played")

    @property
    def skipped(self):
        """How many notes were skipped, for any reason."""
        return self.count() - self.played

    def summary(self, names=None):
        """One line: the notes read, the notes to play and the skipped ones per reason, with their channels.

        The notes no mapping plays are counted by key, the most frequent first, on the percussion channel
        with the key's General MIDI name (:data:`~drumstroke.formats.midi.GM_PERCUSSION`):
        ``not in the drum map (channel 10: 42 Closed Hi-Hat ×12, 36 Bass Drum 1 ×10)``.

        ``names`` is what the caller calls read_score's ``tracks``, ``channels`` and ``mapping`` (the command
        line: its options), for the reasons; by default, those names.
        """
        if all(channel is None for _, channel in self.counts):  # a text pattern: every note is played
            return f"{self.source}: {self.played} notes"
        channels = sorted({c for _, c in self.counts})
        played = self._by_channel("played")
        line = (f"{self.source}: {self.count()} notes on {len(channels)} channel{'s' * (len(channels) != 1)}, "
                f"{len(self.track_names)} track{'s' * (len(self.track_names) != 1)}; {self.played} to play"
                + (f" ({played})" if played else ""))
        if self.skipped:
            parts = [f"{self.count(reason)} {self._reason_text(reason, names)} "
                     f"({reason == 'unmapped' and self._keys_by_channel() or self._by_channel(reason)})"
                     for reason in SKIP_REASONS if self.count(reason)]
            line += f"; skipped {self.skipped}: " + ", ".join(parts)
        return line

    def details(self, names=None):
        """Each skipped note on a line of its own, in time order: where it is and why it was skipped (``names``: as
        :meth:`summary` takes them)."""
        times, keys, velocities, channels, tracks, reasons = self._skipped or ((),) * 6
        for time, key, velocity, channel, track, reason in zip(times, keys, velocities, channels, tracks, reasons):
            reason = SKIP_REASONS[reason]
            yield (f"{self.source}: note {key} at {time:.6g} s (channel {channel}, track {track} "
                   f"{self.track_names[track]!r}, velocity {velocity}) skipped: {self._reason_text(reason, names)}")

    def _by_channel(self, reason):
        counts = sorted((c, n) for (r, c), n in self.counts.items() if r == reason and n)
        return ", ".join(f"channel {c}: {n}" for c, n in counts)

    def _keys_by_channel(self):
        """The keys of the notes no mapping plays, counted per channel, the most frequent first; on the percussion
        channel with their General MIDI names (``channel 10: 42 Closed Hi-Hat ×12, 36 Bass Drum 1 ×10``)."""
        _, keys, _, channels, _, reasons = self._skipped or ((),) * 6
        unmapped = SKIP_REASONS.index("unmapped")
        counts = Counter((c, k) for k, c, r in zip(keys, channels, reasons) if r == unmapped)
        parts = []
        for channel in sorted({c for c, _ in counts}):
            named = GM_PERCUSSION if channel == PERCUSSION_CHANNEL else {}
            ranked = sorted(((n, k) for (c, k), n in counts.items() if c == channel), key=lambda nk: (-nk[0], nk[1]))
            keys = ", ".join(" ".join(filter(None, (str(k), named.get(k), f"×{n}"))) for n, k in ranked)
            parts.append(f"channel {channel}: {keys}")
        return "; ".join(parts)

    def _reason_text(self, reason, names):
        parameter = {"track": "tracks", "channel": "channels", "unmapped": "mapping"}[reason]
        option = (names or {}).get(parameter, parameter)
        if reason == "unmapped" and self.kit:
            return "not on the kit"
        if reason != "unmapped":
            return f"in tracks not chosen ({option})" if reason == "track" else f"on channels not chosen ({option})"
        if self.mapped:
            return f"not in the mapping ({option})"
        percussion = all(c == PERCUSSION_CHANNEL for (r, c), n in self.counts.items() if r == reason and n)
        return "not in the drum map" if percussion else "not in the default mapping"


@dataclass(frozen=True)
class Score:
    """A score read: its notes, its musical time, and what reading it played and skipped.

    Attributes
    ----------
    notes : tuple of ScoreNote
        In time order.
    tempo_map : TempoMap
        The MIDI file's tempo changes and time signatures, or the pattern's tempo and meter.
    report : ScoreReport
    """

    notes: tuple
    tempo_map: TempoMap
    report: ScoreReport


def read_pattern(path):
    """The notes of a text pattern file (see the module docstring), in time order."""
    return _notes(read_pattern_file(path))


def parse_pattern(text, *, name="pattern"):
    """The notes of a text pattern given as a string, in time order."""
    return _notes(pattern_rows(text, name=name))


def _notes(pattern):
    notes = [ScoreNote(row.beat * 60.0 / pattern.tempo, row.stroke, row.velocity, _stick(row.stick or DEFAULT_STICK),
                       source=row.source, duration=None if row.beats is None else row.beats * 60.0 / pattern.tempo,
                       beat=row.beat, piece=row.piece, state=row.state) for row in pattern.rows]
    return sorted(notes, key=lambda n: n.time)


def _stick(name):
    """A stick as a note holds it: None for ``auto`` (the planner chooses)."""
    return None if name == AUTO_STICK else name


def default_mapping(stroke_names, *, percussion=False):
    """The default MIDI key → (stroke, stick) mapping for a library with ``stroke_names`` (in order).

    Parameters
    ----------
    stroke_names : sequence of str
        The library's strokes, in its order.
    percussion : bool
        For the General MIDI percussion channel (10): the drum map's keys only
        (:data:`DRUM_MAP`). Otherwise, where keys are pitches, also 60 + i for the i-th stroke.
    """
    mapping = {} if percussion else {FIRST_LIBRARY_NOTE + i: (name, DEFAULT_STICK) for i, name in
                                     enumerate(stroke_names) if FIRST_LIBRARY_NOTE + i <= 127}
    mapping.update({key: (row.stroke, None) for key, row in DRUM_MAP.items()})
    return mapping


def read_mapping(path):
    """A note mapping file: ``{midi note: (stroke, stick)}``."""
    with reading_toml(path, "mapping") as data:
        check_keys("mapping", data, ("notes",))
        table = data.get("notes")
        if not isinstance(table, dict) or not table:
            raise ParameterError(f"mapping {str(path)!r} needs a [notes] table such as 38 = \"single\"")
        mapping = {}
        for key, value in table.items():
            if not re.fullmatch(r"\d{1,3}", key) or int(key) > 127:
                raise ParameterError(f"mapping notes: key must be a MIDI note number 0-127, got {shown(key)}")
            if isinstance(value, str):
                value = {"stroke": value}
            if not isinstance(value, dict):
                raise ParameterError(f"mapping notes.{key} must be a stroke name or a table, got {value!r}")
            check_keys(f"mapping notes.{key}", value, ("stroke", "stick"))
            stroke = value.get("stroke")
            stick = value.get("stick", AUTO_STICK if stroke in PLANNED else DEFAULT_STICK)
            if not isinstance(stroke, str) or not stroke:
                raise ParameterError(f"mapping notes.{key}.stroke must be a stroke name, auto or buzz, got {stroke!r}")
            if not isinstance(stick, str) or not _STICK.match(stick):
                raise ParameterError(f"mapping notes.{key}.stick must be 1-32 of a-z, 0-9, '_', '-', or auto, got "
                                     f"{stick!r}")
            mapping[int(key)] = (stroke, _stick(stick))
        return mapping


def read_score(path, *, mapping=None, stroke_names=None, channels=None, tracks=None, kit=None):
    """The notes of a score file: a MIDI file through a note mapping, or a text pattern.

    Parameters
    ----------
    path : str or Path
        A ``.mid``/``.midi`` file (type 0 or 1; times in s from its ticks and tempo changes) or a text
        pattern (see the module docstring), which names its strokes itself.
    mapping : str, Path, dict or None
        For a MIDI file only: a mapping file (:func:`read_mapping`) or ``{MIDI key: (stroke, stick)}``,
        for every channel chosen. Default: :func:`default_mapping` of ``stroke_names``, per channel.
    stroke_names : sequence of str or None
        The library's stroke names in its order, for the default mapping off channel 10 (none: the
        drum map only).
    channels : sequence of int in [1, 16] or None
        For a MIDI file only: the channels to play, counted from 1 as musicians do.
        Default: 10, General MIDI percussion.
    tracks : sequence of int or str, or None
        For a MIDI file only: the tracks to play, by number (from 0, in the file's order)
        or by name. Default: every track.
    kit : Kit or None
        For a MIDI file only, instead of a mapping: every key the kit answers is a note on its piece (planned,
        ``auto``, its limb assigned later), with its key; the others are skipped as "not on the kit".

    Returns
    -------
    Score
        The notes to play, the tempo map, and a report of every note played or skipped and why.

    Raises
    ------
    ParameterError
        If the file cannot be read, or a mapping, channel or track is given for a text pattern or does
        not exist; its ``parameter`` is ``mapping``, ``channels`` or ``tracks`` when one of them is wrong.
    """
    path = Path(path)
    if path.suffix.lower() not in MIDI_SUFFIXES:
        for key, given in (("mapping", mapping), ("channels", channels), ("tracks", tracks), ("kit", kit)):
            if given is not None:
                raise ParameterError(f"{key} applies to MIDI scores (.mid, .midi); {str(path)!r} is a text pattern, "
                                     "which names its strokes", parameter=key, value=given,
                                     allowed="None for a text pattern")
        pattern = read_pattern_file(path)
        notes = _notes(pattern)
        return Score(tuple(notes), TempoMap.constant(pattern.tempo, meter=pattern.meter),
                     ScoreReport(str(path), {("played", None): len(notes)}))
    channels = _check_channels(channels)
    stroke_names = () if stroke_names is None else stroke_names
    if kit is not None and mapping is not None:
        raise ParameterError("give a mapping or a kit, not both: a kit plays every key it answers", parameter="mapping",
                             value=mapping, allowed="None with a kit")
    if mapping is not None and not isinstance(mapping, dict):
        mapping = read_mapping(mapping)
    pieces = {} if kit is None else {key: piece.name for piece in kit.pieces for key in piece.keys}
    if kit is not None:
        mapping = {key: ("auto", None) for key in pieces}
    from .formats.midi import read_midi

    midi = read_midi(path)
    chosen = _chosen_tracks(tracks, midi)
    mappings = {channel: mapping if mapping is not None else
                default_mapping(list(stroke_names), percussion=channel == PERCUSSION_CHANNEL) for channel in channels}
    notes, counts, skipped = [], Counter(), tuple(array(code) for code in "dBBBHB")
    for note in midi.notes():
        if chosen is not None and note.track not in chosen:
            reason = 0
        elif note.channel not in mappings:
            reason = 1
        elif note.note not in mappings[note.channel]:
            reason = 2
        else:
            stroke, stick = mappings[note.channel][note.note]
            source = f"{path} note {note.note} at {note.time:.6g} s (channel {note.channel}, track {note.track})"
            notes.append(ScoreNote(note.time, stroke, note.velocity, stick, source=source,
                                   beat=float(midi.tempo_map.beats(note.time)), piece=pieces.get(note.note),
                                   key=note.note if kit is not None else None))
            counts["played", note.channel] += 1
            continue
        counts[SKIP_REASONS[reason], note.channel] += 1
        for column, value in zip(skipped, (note.time, note.note, note.velocity, note.channel, note.track, reason)):
            column.append(value)
    report = ScoreReport(str(path), dict(counts), midi.track_names, mapping is not None and kit is None, skipped,
                         kit=kit is not None)
    return Score(tuple(notes), midi.tempo_map, report)


def _check_channels(channels):
    if channels is None:
        return (PERCUSSION_CHANNEL,)
    if isinstance(channels, (int, str)) or not channels:
        raise ParameterError(f"channels must be a non-empty list of MIDI channels, got {channels!r}",
                             parameter="channels", value=channels, allowed="a non-empty list of MIDI channels")
    checked = []
    for channel in channels:
        try:
            checked.append(check_int("channels", channel, low=1, high=16))
        except ParameterError as error:  # one entry: said what a channel is
            raise ParameterError(f"channels (a MIDI channel, counted from 1; 10 is General MIDI percussion) "
                                 f"{error.reason}", parameter="channels", value=channel, allowed=error.allowed) from None
    return tuple(checked)


def _chosen_tracks(tracks, midi):
    """The track numbers ``tracks`` (numbers from 0 or names) stand for in ``midi``, or None for all."""
    if tracks is None:
        return None
    if isinstance(tracks, (int, str)) or not tracks:
        raise ParameterError(f"tracks must be a non-empty list of track numbers or names, got {tracks!r}",
                             parameter="tracks", value=tracks, allowed="a non-empty list of track numbers or names")
    listed = ", ".join(f"{i} {track!r}" for i, track in enumerate(midi.track_names))
    chosen = set()
    for track in tracks:
        if isinstance(track, str) and track in midi.track_names:
            chosen.update(i for i, known in enumerate(midi.track_names) if known == track)
        elif isinstance(track, str) and re.fullmatch(r"\d+", track) and int(track) < len(midi.track_names):
            chosen.add(int(track))
        elif not isinstance(track, (bool, str)) and isinstance(track, int) and 0 <= track < len(midi.track_names):
            chosen.add(track)
        else:
            raise ParameterError(f"tracks {track!r} is not a track of MIDI file {midi.path!r}; its tracks are "
                                 f"{listed}", parameter="tracks", value=track, allowed=listed)
    return chosen
