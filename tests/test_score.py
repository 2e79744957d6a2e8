"""Scores: text patterns, MIDI note mappings and MIDI notes become ScoreNotes; bad input is named by line.

Oracles: note times worked out by hand (beat · 60 / tempo with values chosen to be exact in binary),
and the documented default mapping written out.
"""

import pytest

from drumstroke.errors import ParameterError
from drumstroke.formats.midi import Note
from drumstroke.score import (
    DEFAULT_STICK,
    ScoreNote,
    default_mapping,
    from_midi_notes,
    parse_pattern,
    read_mapping,
    read_pattern,
)


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
        ("tempo 120\n\n0 single\n", r"pattern line 3: a note is 'beat stroke velocity \[stick\]', got '0 single'"),
        ("tempo 120\n0 single 100 left extra\n", r"pattern line 2: a note is 'beat stroke velocity \[stick\]'"),
        ("tempo 120\n-1 single 100\n", r"pattern line 2: beat must be in \[0, 1e\+06\], got -1.0"),
        ("tempo 120\nsoon single 100\n", r"pattern line 2: beat must be a number, got 'soon'"),
        ("tempo 120\ninf single 100\n", r"pattern line 2: beat must be a finite number"),
        ("tempo 120\n0 single 100\n1 single 100 Left\n", r"pattern line 3: stick must be 1-32 of a-z.*got 'Left'"),
        ("tempo 120\n0 single 100 l.h\n", r"pattern line 2: stick must be .*got 'l.h'"),
        ("tempo 120\n# no notes\n", r"pattern has a tempo but no notes"),
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
        ('[notes]\n38 = ""\n', r"mapping notes.38.stroke must be a stroke name, got ''"),
        ('[notes]\n38 = { stick = "left" }\n', r"mapping notes.38.stroke must be a stroke name, got None"),
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


def test_default_mapping_names_the_general_midi_snares_and_numbers_the_library_from_60():
    names = ["single", "tap", "double", "triple", "press-roll"]
    assert default_mapping(names) == {38: ("single", "right"), 37: ("tap", "right"), 40: ("press-roll", "right"),
                                      60: ("single", "right"), 61: ("tap", "right"), 62: ("double", "right"),
                                      63: ("triple", "right"), 64: ("press-roll", "right")}
    # a General MIDI note only when the library has its stroke
    assert default_mapping(["double", "tap"]) == {37: ("tap", "right"), 60: ("double", "right"),
                                                  61: ("tap", "right")}


def test_default_mapping_stops_at_note_127():
    names = [f"s{i}" for i in range(80)]
    mapping = default_mapping(names)
    assert sorted(mapping) == list(range(60, 128))
    assert mapping[127] == ("s67", "right")


# --- MIDI notes ----------------------------------------------------------------------------------------------------

def test_from_midi_notes_maps_and_counts_the_unmapped_per_note_number():
    midi_notes = [Note(1.5, 38, 100, 10), Note(0.25, 42, 60, 10), Note(0.5, 40, 90, 10), Note(0.75, 42, 61, 10),
                  Note(0.0, 37, 30, 10), Note(2.0, 49, 127, 10), Note(1.0, 42, 62, 10)]
    mapping = {38: ("single", "right"), 37: ("tap", "left"), 40: ("press-roll", "left")}
    notes, unmapped = from_midi_notes(midi_notes, mapping)
    assert unmapped == {42: 3, 49: 1}
    assert summary(notes) == [
        (0.0, "tap", 30, "left", "MIDI note 37 at 0 s"),
        (0.5, "press-roll", 90, "left", "MIDI note 40 at 0.5 s"),
        (1.5, "single", 100, "right", "MIDI note 38 at 1.5 s"),
    ]
    assert all(type(n.time) is float and type(n.velocity) is int for n in notes)


def test_from_midi_notes_with_nothing_mapped_gives_no_notes():
    notes, unmapped = from_midi_notes([Note(0.0, 42, 60, 10)], {38: ("single", "right")})
    assert notes == [] and unmapped == {42: 1}


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
