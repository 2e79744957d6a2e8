"""Scores: text patterns, MIDI note mappings and MIDI files become ScoreNotes; bad input is named by line.

Oracles: note times worked out by hand (beat · 60 / tempo with values chosen to be exact in binary),
the documented default mapping written out, the notes of real MIDI files counted here with mido, and the
General MIDI percussion names by pretty_midi's table.
"""

import collections
import re
from pathlib import Path

import mido
import pretty_midi
import pytest

from drumstroke.errors import ParameterError
from drumstroke.formats.midi import GM_PERCUSSION, TempoMap
from drumstroke.score import (
    BOUNCE_NOTE,
    DEFAULT_STICK,
    DRUM_MAP,
    FIRST_IMPACT_NOTE,
    ScoreNote,
    default_mapping,
    parse_pattern,
    read_mapping,
    read_pattern,
    read_score,
)

DATA = Path(__file__).resolve().parent / "data" / "midi"


def summary(notes):
    return [(n.time, n.stroke, n.velocity, n.stick, n.source) for n in notes]


# --- patterns ------------------------------------------------------------------------------------------------------

def test_pattern_times_are_beats_at_the_tempo_with_comments_blanks_default_stick_and_sorting():
    text = ("# a groove\n"
            "\n"
            "   tempo 96   # bpm\n"
            "2.75  double  80   left\n"
            "\t\n"
            "0     single  100\n"
            "# 1 tap 10\n"
            "1.5   tap     7    stick_2   # ghost\n"
            "0.5   single  127  right\n")
    notes = parse_pattern(text, name="groove")
    # at 96 bpm a beat is 0.625 s: 0 → 0, 0.5 → 0.3125, 1.5 → 0.9375, 2.75 → 1.71875 (all exact in binary)
    assert summary(notes) == [
        (0.0, "single", 100, "right", "groove line 6"),
        (0.3125, "single", 127, "right", "groove line 9"),
        (0.9375, "tap", 7, "stick_2", "groove line 8"),
        (1.71875, "double", 80, "left", "groove line 4"),
    ]
    assert DEFAULT_STICK == "right"
    assert all(isinstance(n, ScoreNote) and isinstance(n.velocity, int) for n in notes)


@pytest.mark.parametrize("tempo, beat", [(7.0, 1.0), (133.0, 3.3), (1000.0, 12345.5), (0.5, 0.25)])
def test_pattern_time_is_beat_times_60_over_tempo(tempo, beat):
    (note,) = parse_pattern(f"tempo {tempo!r}\n{beat!r} single 64\n")
    assert note.time == beat * 60.0 / tempo


def test_notes_at_the_same_time_keep_the_file_order():
    notes = parse_pattern("tempo 60\n1 tap 10 a\n0 single 5\n1 tap 20 b\n1 tap 30 c\n")
    assert [(n.time, n.stick) for n in notes] == [(0.0, "right"), (1.0, "a"), (1.0, "b"), (1.0, "c")]


@pytest.mark.parametrize(
    "text, match",
    [
        ("", r"pattern is empty"),
        ("# only a comment\n\n", r"pattern is empty"),
        ("0 single 100\n", r"pattern line 1: the first line must be 'tempo BPM', got '0 single 100'"),
        ("# c\n\nbpm 120\n0 single 100\n", r"pattern line 3: the first line must be 'tempo BPM'"),
        ("tempo\n0 single 100\n", r"pattern line 1: the first line must be 'tempo BPM'"),
        ("tempo 0\n0 single 100\n", r"pattern line 1: tempo must be in \(0, 1000\] beats per minute, got 0.0"),
        ("tempo -60\n0 single 100\n", r"pattern line 1: tempo must be in \(0, 1000\].*got -60.0"),
        ("tempo nan\n0 single 100\n", r"pattern line 1: tempo must be a finite number.*got nan"),
        ("tempo fast\n0 single 100\n", r"pattern line 1: tempo must be a number, got 'fast'"),
        ("tempo 120\n0 single 0\n", r"pattern line 2: velocity must be an integer in \[1, 127\], got '0'"),
        ("tempo 120\n0 single 128\n", r"pattern line 2: velocity must be an integer in \[1, 127\], got '128'"),
        ("tempo 120\n0 single loud\n", r"pattern line 2: velocity must be an integer in \[1, 127\], got 'loud'"),
        ("tempo 120\n0 single 1.5\n", r"pattern line 2: velocity must be an integer in \[1, 127\], got '1.5'"),
        ("tempo 120\n0 single -5\n", r"pattern line 2: velocity .* got '-5'"),
        ("tempo 120\n\n0 single\n", r"pattern line 3: a note is 'beat stroke velocity \[stick \[beats\] \[piece\]\]', got '0 single'"),
        ("tempo 120\n0 single 100 left 2\n", r"pattern line 2: only a buzz takes a length \(the fifth field\)"),
        ("tempo 120\n0 buzz 100 left 2 ride more\n", r"pattern line 2: a note is 'beat stroke velocity \[stick \[beats\] \[piece\]\]'"),
        ("tempo 120\n0 buzz 100 left 2 3\n", r"pattern line 2: a note is 'beat stroke velocity \[stick \[beats\] \[piece\]\]'"),
        ("tempo 120\n0 buzz 100 left 0\n", r"pattern line 2: buzz length must be in \(0, 1e\+06\] beats, got 0.0"),
        ("tempo 120\n-1 single 100\n", r"pattern line 2: beat must be in \[0, 1e\+06\], got -1.0"),
        ("tempo 120\nsoon single 100\n", r"pattern line 2: beat must be a number, got 'soon'"),
        ("tempo 120\ninf single 100\n", r"pattern line 2: beat must be a finite number"),
        ("tempo 120\n0 single 100\n1 single 100 Left\n", r"pattern line 3: stick must be 1-32 of a-z.*got 'Left'"),
        ("tempo 120\n0 single 100 l.h\n", r"pattern line 2: stick must be .*got 'l.h'"),
        ("tempo 120\n# no notes\n", r"pattern has a tempo but no notes"),
        ("tempo 120\nmeter 3/5\n0 single 100\n", (r"pattern line 2: meter must be N/D with N in \[1, 255\] and D a "
                                                   r"power of two in \[1, 128\], got '3/5'")),
        ("tempo 120\nmeter 0/4\n0 single 100\n", r"pattern line 2: meter must be N/D .* got '0/4'"),
        ("tempo 120\nmeter 3:4\n0 single 100\n", r"pattern line 2: meter must be N/D .* got '3:4'"),
        ("tempo 120\n0 single 100\nmeter 3/4\n", r"pattern line 3: a meter is one 'meter N/D' line before the notes"),
        ("tempo 120\nmeter 3 4\n0 single 100\n", r"pattern line 2: a meter is one 'meter N/D' line before the notes"),
    ],
)
def test_bad_patterns_are_named_by_line(text, match):
    with pytest.raises(ParameterError, match=match):
        parse_pattern(text)


def test_read_pattern_reads_a_file_and_names_it(tmp_path):
    path = tmp_path / "beat.pattern"
    path.write_text("tempo 150\n0 single 90\n1 tap 40 left\n", encoding="utf-8")
    notes = read_pattern(path)
    assert summary(notes) == [(0.0, "single", 90, "right", f"{path} line 2"),
                              (0.4, "tap", 40, "left", f"{path} line 3")]
    path.write_text("tempo 150\n0 single 90\n1 tap 400 left\n")
    with pytest.raises(ParameterError, match=rf"{path} line 3: velocity must be"):
        read_pattern(path)


def test_read_pattern_refuses_a_file_that_is_not_utf8(tmp_path):
    path = tmp_path / "latin.pattern"
    path.write_bytes(b"tempo 120\n0 single 100 # caf\xe9\n")
    with pytest.raises(ParameterError, match=r"latin.pattern' cannot be read: not a UTF-8 text file"):
        read_pattern(path)


def test_read_pattern_names_a_missing_file(tmp_path):
    with pytest.raises(ParameterError, match=r"nowhere.pattern' cannot be read: No such file"):
        read_pattern(tmp_path / "nowhere.pattern")


def test_read_pattern_refuses_a_pattern_without_notes(tmp_path):
    path = tmp_path / "silence.pattern"
    path.write_text("tempo 120\n")
    with pytest.raises(ParameterError, match=r"silence.pattern has a tempo but no notes"):
        read_pattern(path)


# --- mappings ------------------------------------------------------------------------------------------------------

def test_read_mapping_takes_strings_and_tables_with_a_default_stick(tmp_path):
    path = tmp_path / "map.toml"
    path.write_text('[notes]\n38 = "single"\n40 = { stroke = "press-roll", stick = "left" }\n'
                    '37 = { stroke = "tap" }\n0 = "double"\n127 = "triple"\n')
    assert read_mapping(path) == {38: ("single", "right"), 40: ("press-roll", "left"), 37: ("tap", "right"),
                                  0: ("double", "right"), 127: ("triple", "right")}


@pytest.mark.parametrize(
    "text, match",
    [
        ('[notes]\n128 = "single"\n', r"key must be a MIDI note number 0-127, got '128'"),
        ('[notes]\nx = "single"\n', r"key must be a MIDI note number 0-127, got 'x'"),
        ('[notes]\n-1 = "single"\n', r"key must be a MIDI note number 0-127, got '-1'"),
        ('[notes]\n38 = { stroke = "single", hand = "left" }\n', r"mapping notes.38 has unknown key 'hand'"),
        ('[notes]\n38 = 5\n', r"mapping notes.38 must be a stroke name or a table, got 5"),
        ('[notes]\n38 = ["single"]\n', r"mapping notes.38 must be a stroke name or a table"),
        ('[notes]\n38 = ""\n', r"mapping notes.38.stroke must be a stroke name, auto or buzz, got ''"),
        ('[notes]\n38 = { stick = "left" }\n', r"mapping notes.38.stroke must be a stroke name, auto or buzz, got None"),
        ('[notes]\n38 = { stroke = "single", stick = "Left Hand" }\n', r"notes.38.stick must be 1-32 of a-z"),
        ('notes = 5\n', r"needs a \[notes\] table"),
        ('[notes]\n', r"needs a \[notes\] table"),
        ('[notes]\n38 = "single"\n[extra]\n', r"mapping has unknown key 'extra'"),
        ('[notes\n', r"is not valid TOML"),
    ],
)
def test_bad_mappings_are_named(tmp_path, text, match):
    path = tmp_path / "map.toml"
    path.write_text(text)
    with pytest.raises(ParameterError, match=match):
        read_mapping(path)


def test_default_mapping_on_channel_10_is_the_drum_map_and_elsewhere_also_numbers_the_library_from_60():
    """On channel 10 the snares and the side stick are notes the planner designs, on sticks it chooses (None)."""
    names = ["single", "tap", "double", "triple", "press-roll"]
    drums = {38: ("auto", None), 40: ("auto", None), 37: ("auto", None)}
    assert default_mapping(names, percussion=True) == drums
    assert default_mapping(names) == drums | {60: ("single", "right"), 61: ("tap", "right"), 62: ("double", "right"),
                                              63: ("triple", "right"), 64: ("press-roll", "right")}
    assert default_mapping([], percussion=True) == drums  # no library needed for the drum map


def test_default_mapping_stops_at_note_127():
    names = [f"s{i}" for i in range(80)]
    mapping = default_mapping(names)
    assert sorted(mapping) == sorted(set(range(60, 128)) | {37, 38, 40})
    assert mapping[127] == ("s67", "right")


def test_the_drum_map_is_one_table_read_and_written():
    """Both General MIDI snares and the side stick read as notes the planner designs; written files put each
    stroke's first impact on the acoustic snare and its bounces on the electric snare; nothing else of channel 10."""
    assert {key: (row.name, row.stroke) for key, row in DRUM_MAP.items()} == {
        37: ("Side Stick", "auto"), 38: ("Acoustic Snare", "auto"), 40: ("Electric Snare", "auto")}
    assert (FIRST_IMPACT_NOTE, BOUNCE_NOTE) == (38, 40)
    assert [row.written for row in DRUM_MAP.values()] == [None, "first", "bounce"]


def test_a_mapping_may_ask_for_the_planner(tmp_path):
    path = tmp_path / "planned.toml"
    path.write_text('[notes]\n38 = "auto"\n40 = { stroke = "buzz", stick = "left" }\n'
                    '37 = { stroke = "single", stick = "auto" }\n')
    assert read_mapping(path) == {38: ("auto", None), 40: ("buzz", "left"), 37: ("single", None)}


def test_a_pattern_asks_for_the_planner_and_buzzes_with_their_length():
    notes = parse_pattern("tempo 120\n0 auto 100 auto\n0.5 buzz 90 left 0.25\n1 buzz 80\n")
    assert [(n.time, n.stroke, n.stick, n.duration, n.beat) for n in notes] == [
        (0.0, "auto", None, None, 0.0), (0.25, "buzz", "left", 0.125, 0.5), (0.5, "buzz", "right", None, 1.0)]


# --- MIDI scores ---------------------------------------------------------------------------------------------------

def midi_file(path, tracks, *, type=1):
    """A MIDI file of ``tracks``: lists of (absolute tick, channel from 1, key, velocity) notes, 480 ticks a beat
    at 120 bpm (a tick is 1/960 s), each note held 10 ticks; a track may start with its name."""
    file = mido.MidiFile(type=type, ticks_per_beat=480)
    for notes in tracks:
        events = [(0, mido.MetaMessage("track_name", name=notes.pop(0)))] if notes and isinstance(notes[0], str) else []
        for tick, channel, key, velocity in notes:
            events += [(tick, mido.Message("note_on", channel=channel - 1, note=key, velocity=velocity)),
                       (tick + 10, mido.Message("note_off", channel=channel - 1, note=key))]
        events.sort(key=lambda event: event[0])
        track, now = mido.MidiTrack(), 0
        for tick, message in events:
            track.append(message.copy(time=tick - now))
            now = tick
        file.tracks.append(track)
    file.save(path)
    return path


SONG = [["drums", (0, 10, 38, 100), (480, 10, 42, 60), (960, 10, 40, 90), (1440, 10, 37, 30), (1920, 10, 61, 70)],
        ["bass", (0, 2, 40, 80), (960, 2, 38, 80)],
        ["melody", (240, 1, 60, 64), (720, 1, 61, 64), (1200, 1, 38, 50)]]
NAMES = ["single", "tap", "double"]


def test_by_default_only_channel_10_is_played_through_the_drum_map(tmp_path):
    path = midi_file(tmp_path / "song.mid", [list(t) for t in SONG])
    score = read_score(path, stroke_names=NAMES)
    assert [(n.time, n.stroke, n.velocity, n.stick, n.beat) for n in score.notes] == [
        (0.0, "auto", 100, None, 0.0), (1.0, "auto", 90, None, 2.0), (1.5, "auto", 30, None, 3.0)]
    assert score.notes[1].source == f"{path} note 40 at 1 s (channel 10, track 0)"
    report = score.report
    assert report.counts == {("played", 10): 3, ("unmapped", 10): 2, ("channel", 2): 2, ("channel", 1): 3}
    assert (report.played, report.skipped, report.count("channel"), report.count(channel=10)) == (3, 7, 5, 5)
    assert report.summary() == (f"{path}: 10 notes on 3 channels, 3 tracks; 3 to play (channel 10: 3); skipped 7: "
                                "5 on channels not chosen (channels) (channel 1: 3, channel 2: 2), "
                                "2 not in the drum map (channel 10: 42 Closed Hi-Hat ×1, 61 Low Bongo ×1)")
    details = list(report.details())
    assert details[0] == (f"{path}: note 40 at 0 s (channel 2, track 1 'bass', velocity 80) skipped: on channels not "
                          "chosen (channels)")
    assert len(details) == 7 and [d.split(" at ")[1].split(" s ")[0] for d in details] == \
           ["0", "0.25", "0.5", "0.75", "1", "1.25", "2"]
    assert score.tempo_map == TempoMap(resolution=480)


def test_channels_and_tracks_choose_what_is_played_and_the_report_says_why_the_rest_is_not(tmp_path):
    path = midi_file(tmp_path / "song.mid", [list(t) for t in SONG])
    options = {"channels": "--channel", "tracks": "--track", "mapping": "--mapping"}
    score = read_score(path, stroke_names=NAMES, channels=[1, 10], tracks=["melody", 0])
    # channel 1 is not percussion: key 60 + i is the library's i-th stroke, 38 still the planner's
    assert [(n.time, n.stroke) for n in score.notes] == [
        (0.0, "auto"), (0.25, "single"), (0.75, "tap"), (1.0, "auto"), (1.25, "auto"), (1.5, "auto")]
    assert score.report.counts == {("played", 10): 3, ("played", 1): 3, ("unmapped", 10): 2, ("track", 2): 2}
    assert "2 in tracks not chosen (--track) (channel 2: 2)" in score.report.summary(options)
    assert "2 in tracks not chosen (tracks) (channel 2: 2)" in score.report.summary()
    assert read_score(path, stroke_names=NAMES, tracks=["1"], channels=[2]).report.counts == {
        ("played", 2): 2, ("track", 10): 5, ("track", 1): 3}
    mapping = {42: ("double", "left")}
    score = read_score(path, mapping=mapping, channels=(10,))
    assert [(n.time, n.stroke, n.stick) for n in score.notes] == [(0.5, "double", "left")]
    keys = "channel 10: 37 Side Stick ×1, 38 Acoustic Snare ×1, 40 Electric Snare ×1, 61 Low Bongo ×1"
    assert f"4 not in the mapping (--mapping) ({keys})" in score.report.summary(options)
    assert f"4 not in the mapping (mapping) ({keys})" in score.report.summary()
    # off the percussion channel a key is a pitch: named by its number only, each channel apart
    score = read_score(path, stroke_names=NAMES[:1], channels=[1, 10])
    assert ("3 not in the default mapping (channel 1: 61 ×1; channel 10: 42 Closed Hi-Hat ×1, 61 Low Bongo ×1)"
            in score.report.summary())


@pytest.mark.parametrize(("choice", "value", "match"), [
    ({"channels": [0]}, 0, (r"^--channel \(a MIDI channel, counted from 1; 10 is General MIDI percussion\) must be "
                            r"an integer in \[1, 16\], got 0")),
    ({"channels": [17]}, 17, r"^--channel .* got 17"),
    ({"channels": 10}, 10, r"^--channel must be a non-empty list of MIDI channels, got 10"),
    ({"tracks": ["drum"]}, "drum", (r"^--track 'drum' is not a track of MIDI file '.*song.mid'; its tracks are "
                                    r"0 'drums', 1 'bass', 2 'melody'")),
    ({"tracks": [3]}, 3, r"^--track 3 is not a track"),
    ({"tracks": ["-1"]}, "-1", r"^--track '-1' is not a track"),
])
def test_a_channel_or_track_that_is_not_there_is_refused_naming_the_parameter(tmp_path, choice, value, match):
    """The error names the parameter (and carries it, and the value): a caller words it with its own name for it."""
    path = midi_file(tmp_path / "song.mid", [list(t) for t in SONG])
    with pytest.raises(ParameterError) as raised:
        read_score(path, stroke_names=NAMES, **choice)
    (parameter,) = choice
    option = {"channels": "--channel", "tracks": "--track"}[parameter]
    error = raised.value
    assert (error.parameter, error.value) == (parameter, value)
    assert re.match(match, str(error.renamed(option)))
    assert str(error) == parameter + str(error.renamed(option)).removeprefix(option)


def test_a_pattern_refuses_channels_and_tracks_and_gives_its_tempo_and_meter(tmp_path):
    pattern = tmp_path / "waltz.pattern"
    pattern.write_text("tempo 90\nmeter 3/4\n0 single 100\n1 tap 50 left\n")
    score = read_score(pattern)
    assert score.tempo_map == TempoMap.constant(90.0, meter=(3, 4))
    assert [(n.time, n.stroke) for n in score.notes] == [(0.0, "single"), (60 / 90, "tap")]
    assert score.report.summary() == f"{pattern}: 2 notes" and list(score.report.details()) == []
    for choice in ({"channels": [10]}, {"tracks": [0]}):
        with pytest.raises(ParameterError, match=r"^(channels|tracks) applies to MIDI scores"):
            read_score(pattern, **choice)


def mido_unmapped_keys(path):
    """Independently, with mido: how many notes each key off the drum map has on channel 10."""
    keys = collections.Counter(message.note for track in mido.MidiFile(path).tracks for message in track
                               if message.type == "note_on" and message.velocity and message.channel == 9)
    return {key: n for key, n in keys.items() if key not in (37, 38, 40)}


def test_the_general_midi_percussion_names_are_pretty_midis_and_level_2s():
    """Keys 35-81 by pretty_midi's General MIDI table (spelling aside: hyphens, spaces, case), 27-87 all named."""
    spelled = lambda name: re.sub(r"[\s-]", "", name.lower())
    assert {key: spelled(GM_PERCUSSION[key]) for key in range(35, 82)} == {
        key: spelled(pretty_midi.note_number_to_drum_name(key)) for key in range(35, 82)}
    assert sorted(GM_PERCUSSION) == list(range(27, 88)) and len(set(GM_PERCUSSION.values())) == 61
    assert {key: row.name for key, row in DRUM_MAP.items()} == {37: "Side Stick", 38: "Acoustic Snare",
                                                                40: "Electric Snare"}


def mido_counts(path):
    """Independently, with mido: (on channel 10 in the drum map, on channel 10 not in it, per other channel)."""
    played = unmapped = 0
    others = {}
    for track in mido.MidiFile(path).tracks:
        for message in track:
            if message.type != "note_on" or message.velocity == 0:
                continue
            if message.channel == 9:
                played, unmapped = (played + 1, unmapped) if message.note in (37, 38, 40) else (played, unmapped + 1)
            else:
                others[message.channel + 1] = others.get(message.channel + 1, 0) + 1
    return played, unmapped, others


@pytest.mark.parametrize("name", ["d6caebd1964d9e4a3c5ea59525230e2a.mid", "d8faddb8596fff7abb24d78666f73e4e.mid",
                                  "1390.mid"])
def test_a_real_song_plays_its_drum_map_notes_on_channel_10_and_counts_the_rest(name):
    path = DATA / name
    played, unmapped, others = mido_counts(path)
    score = read_score(path, stroke_names=["single", "tap", "double"])
    report = score.report
    expected = {("played", 10): played, ("unmapped", 10): unmapped} | {("channel", c): n for c, n in others.items()}
    assert report.counts == {key: n for key, n in expected.items() if n}
    assert len(score.notes) == played and {n.stroke for n in score.notes} <= {"auto"}
    assert len(list(report.details())) == report.skipped == unmapped + sum(others.values())
    summary = report.summary()
    assert f"; {played} to play" in summary and "\n" not in summary
    if unmapped:
        keys = ", ".join(f"{key} {GM_PERCUSSION[key]} ×{n}" for key, n in
                         sorted(mido_unmapped_keys(path).items(), key=lambda kn: (-kn[1], kn[0])))
        assert f"{unmapped} not in the drum map (channel 10: {keys})" in summary
    if others:
        assert f"{sum(others.values())} on channels not chosen" in summary


# --- the note itself -----------------------------------------------------------------------------------------------

@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"time": -0.1}, r"line 9: time must be in \[0, 1e\+06\] s, got -0.1"),
        ({"velocity": 0}, r"line 9: velocity must be an integer in \[1, 127\], got 0"),
        ({"velocity": 64.0}, r"line 9: velocity must be an integer in \[1, 127\], got 64.0"),
        ({"velocity": True}, r"line 9: velocity must be an integer in \[1, 127\], got True"),
        ({"stroke": ""}, r"line 9: stroke must be a stroke name, got ''"),
        ({"stick": "x" * 33}, r"line 9: stick must be 1-32 of a-z"),
    ],
)
def test_score_note_checks_its_fields(kwargs, match):
    fields = {"time": 0.0, "stroke": "single", "velocity": 64, "stick": "right", "source": "line 9"} | kwargs
    with pytest.raises(ParameterError, match=match):
        ScoreNote(**fields)
