"""MIDI: impacts written as percussion and checked by two independent readers; scores read back in seconds.

Written files are read with mido (messages, delta ticks and tempo turned into seconds here, by hand)
and with pretty_midi; score files are built with mido here and their note times worked out by hand.
"""

import math
import os
import re

import mido
import numpy as np
import pretty_midi
import pytest

import drumstroke
import drumstroke._atomic
from drumstroke import ParameterError
from drumstroke.dynamics import CEILING_DB, FLOOR_DB, level_to_velocity
from drumstroke.formats import midi

HALF_MS = 0.5e-3


def tick_seconds(tick, tempo_map, ticks_per_beat):
    """Seconds at absolute ``tick`` given ``tempo_map``, a sorted list of (tick, µs per beat) starting at tick 0."""
    seconds = 0.0
    for (start, tempo), (end, _) in zip(tempo_map, tempo_map[1:] + [(math.inf, None)]):
        if tick <= start:
            break
        seconds += (min(tick, end) - start) * tempo / (1e6 * ticks_per_beat)
    return seconds


def read_with_mido(path, charset="latin1"):
    """Notes (dicts with start/end ticks and seconds) and meta of a MIDI file, by walking its delta ticks here."""
    file = mido.MidiFile(path, charset=charset)
    tempo_map = {0: 500_000}
    names, events = [], []
    for number, track in enumerate(file.tracks):
        tick = 0
        for order, message in enumerate(track):
            tick += message.time
            if message.type == "set_tempo":
                tempo_map[tick] = message.tempo
            elif message.type == "track_name":
                names.append(message.name)
            elif message.type in ("note_on", "note_off"):
                events.append((tick, number, order, message))
    tempo_map = sorted(tempo_map.items())
    notes, sounding = [], {}
    for tick, _, _, message in sorted(events, key=lambda event: event[:3]):
        key = (message.channel, message.note)
        if message.type == "note_off" or message.velocity == 0:
            if key in sounding:
                sounding.pop(key)["end_tick"] = tick
            continue
        note = {"tick": tick, "note": message.note, "velocity": message.velocity, "channel": message.channel}
        sounding[key] = note
        notes.append(note)
    for note in notes:
        note["time"] = tick_seconds(note["tick"], tempo_map, file.ticks_per_beat)
        note["end"] = tick_seconds(note.get("end_tick", math.inf), tempo_map, file.ticks_per_beat)
    return file, names, tempo_map, notes


def audible(levels):
    return np.asarray(levels) >= FLOOR_DB


@pytest.fixture(scope="module")
def stroke():
    return drumstroke.simulate("free-bounce")


@pytest.fixture
def stroke_file(stroke, tmp_path):
    path = tmp_path / "free-bounce.mid"
    written = midi.write_midi(path, stroke.impacts.t, stroke.impacts.level_db, title="free-bounce (model: paper)")
    return path, written


# ---------------------------------------------------------------- writing, read back by mido and pretty_midi


def test_a_simulated_stroke_reads_back_with_mido(stroke, stroke_file):
    path, written = stroke_file
    t, level = stroke.impacts.t, stroke.impacts.level_db
    keep = audible(level)
    assert 0 < keep.sum() < len(t), "free-bounce should have both audible and too-quiet impacts"

    file, names, tempo_map, notes = read_with_mido(path)
    assert file.type == 0 and file.ticks_per_beat == midi.TICKS_PER_BEAT
    assert names == ["free-bounce (model: paper)"] and tempo_map == [(0, 500_000)]
    assert len(notes) == len(written) == keep.sum()
    times = np.array([note["time"] for note in notes])
    assert np.max(np.abs(times - t[keep])) < HALF_MS
    assert np.max(np.abs(times - t[keep])) <= 0.5 * 500_000e-6 / midi.TICKS_PER_BEAT + 1e-12
    assert {note["note"] for note in notes} == {38} and {note["channel"] for note in notes} == {9}
    assert [note["velocity"] for note in notes] == level_to_velocity(level[keep]).tolist()
    assert [note.velocity for note in written] == [note["velocity"] for note in notes]
    np.testing.assert_allclose([note.time for note in written], times, rtol=0, atol=1e-12)


def test_a_simulated_stroke_reads_back_with_pretty_midi(stroke, stroke_file):
    path, _ = stroke_file
    keep = audible(stroke.impacts.level_db)
    (instrument,) = pretty_midi.PrettyMIDI(str(path)).instruments
    assert instrument.is_drum and instrument.name == "free-bounce (model: paper)"
    starts = np.array([note.start for note in instrument.notes])
    assert len(starts) == keep.sum()
    assert np.max(np.abs(starts - stroke.impacts.t[keep])) < HALF_MS
    assert {note.pitch for note in instrument.notes} == {38}
    assert [note.velocity for note in instrument.notes] == level_to_velocity(stroke.impacts.level_db[keep]).tolist()
    lengths = np.array([note.end - note.start for note in instrument.notes])
    assert np.all(lengths > 0) and np.all(lengths <= midi.NOTE_LENGTH + HALF_MS)


def test_written_notes_read_back_equal_with_read_midi_notes(stroke_file):
    path, written = stroke_file
    notes = midi.read_midi_notes(path)
    assert [(n.note, n.velocity, n.channel) for n in notes] == [(n.note, n.velocity, n.channel) for n in written]
    np.testing.assert_allclose([n.time for n in notes], [n.time for n in written], rtol=0, atol=1e-12)


def test_velocities_follow_the_dynamics_map_and_never_fall_as_the_level_rises(tmp_path, rng):
    levels = np.sort(rng.uniform(FLOOR_DB - 3.0, CEILING_DB + 3.0, 200))
    times = np.arange(levels.size) * 0.05
    written = midi.write_midi(tmp_path / "ramp.mid", times, levels)
    keep = audible(levels)
    velocities = np.array([note["velocity"] for note in read_with_mido(tmp_path / "ramp.mid")[3]])
    assert velocities.tolist() == level_to_velocity(levels[keep]).tolist() == [n.velocity for n in written]
    assert np.all(np.diff(velocities) >= 0)
    assert velocities[0] == 1 and velocities[-1] == 127 and len(set(velocities.tolist())) > 100


def test_impacts_quieter_than_the_floor_are_left_out_and_the_count_says_so(tmp_path):
    levels = [-math.inf, FLOOR_DB - 1e-9, FLOOR_DB, -80.0, 0.0, FLOOR_DB - 0.1]
    written = midi.write_midi(tmp_path / "quiet.mid", [0.0, 0.1, 0.2, 0.3, 0.4, 0.5], levels)
    assert [(round(n.time, 9), n.velocity) for n in written] == [(0.2, 1), (0.4, level_to_velocity(0.0))]
    starts = [(round(n.start, 9), n.velocity) for n in pretty_midi.PrettyMIDI(str(tmp_path / "quiet.mid")).instruments[0].notes]
    assert starts == [(0.2, 1), (0.4, level_to_velocity(0.0))]


def test_all_quiet_impacts_write_a_file_without_notes(tmp_path):
    assert midi.write_midi(tmp_path / "silent.mid", [0.0, 1.0], [-math.inf, -90.0], title="silent") == []
    _, names, _, notes = read_with_mido(tmp_path / "silent.mid")
    assert notes == [] and names == ["silent"]
    with pytest.raises(ParameterError, match="has no notes"):
        midi.read_midi_notes(tmp_path / "silent.mid")


def test_impacts_on_the_same_tick_merge_into_the_louder(tmp_path):
    tick = 500_000e-6 / midi.TICKS_PER_BEAT
    times = [0.1, 0.1, 0.1 + 0.3 * tick, 0.2, 0.2 + tick, 0.3, 0.3]
    levels = [-20.0, -5.0, -30.0, -10.0, -12.0, -100.0, -15.0]
    written = midi.write_midi(tmp_path / "merge.mid", times, levels)
    expected = [(0.1, level_to_velocity(-5.0)), (0.2, level_to_velocity(-10.0)),
                (0.2 + tick, level_to_velocity(-12.0)), (0.3, level_to_velocity(-15.0))]
    assert len(written) == 4
    notes = read_with_mido(tmp_path / "merge.mid")[3]
    for got in (written, [midi.Note(n["time"], n["note"], n["velocity"], n["channel"] + 1) for n in notes]):
        assert [n.velocity for n in got] == [v for _, v in expected]
        np.testing.assert_allclose([n.time for n in got], [t for t, _ in expected], rtol=0, atol=0.5 * tick + 1e-12)


def test_a_note_lasts_its_length_or_ends_as_the_next_one_starts(tmp_path):
    tick = 500_000e-6 / midi.TICKS_PER_BEAT
    times = [0.0, 0.005, 0.005 + tick, 1.0]
    midi.write_midi(tmp_path / "lengths.mid", times, [0.0] * 4)
    notes = read_with_mido(tmp_path / "lengths.mid")[3]
    ends = [note["end_tick"] - note["tick"] for note in notes]
    full = round(midi.NOTE_LENGTH / tick)
    assert ends == [round(0.005 / tick), 1, full, full]
    assert abs(full * tick - midi.NOTE_LENGTH) <= 0.5 * tick
    track = mido.MidiFile(tmp_path / "lengths.mid").tracks[0]
    kinds = [m.type for m in track if not m.is_meta]
    assert kinds == ["note_on", "note_off"] * 4  # each note-off precedes the next note-on on a shared tick
    pm_notes = pretty_midi.PrettyMIDI(str(tmp_path / "lengths.mid")).instruments[0].notes
    assert len(pm_notes) == 4 and abs(pm_notes[0].end - pm_notes[1].start) < 1e-12


def test_note_channel_tempo_and_title_are_honoured(tmp_path, stroke):
    t, level = stroke.impacts.t, stroke.impacts.level_db
    title = "double stroke — model: geometry"
    written = midi.write_midi(tmp_path / "hat.mid", t, level, note=np.int64(42), channel=1, tempo=90.0, title=title)
    _, names, tempo_map, notes = read_with_mido(tmp_path / "hat.mid", charset="utf-8")
    assert names == [title] and tempo_map == [(0, mido.bpm2tempo(90.0))]
    assert {(n["note"], n["channel"]) for n in notes} == {(42, 0)}
    assert {(n.note, n.channel) for n in written} == {(42, 1)}
    keep = audible(level)
    assert np.max(np.abs(np.array([n["time"] for n in notes]) - t[keep])) <= 0.5 * mido.bpm2tempo(90.0) * 1e-6 / 1920
    (instrument,) = pretty_midi.PrettyMIDI(str(tmp_path / "hat.mid")).instruments
    assert not instrument.is_drum and {n.pitch for n in instrument.notes} == {42}


@pytest.mark.parametrize("tempo", [31.25, 60.0, 133.7, 1000.0])
def test_timing_error_is_at_most_half_a_tick_at_any_tempo(tmp_path, rng, tempo):
    times = np.cumsum(rng.uniform(0.002, 4.0, 300))  # at least two ticks apart at 31.25 bpm, so none merge
    midi.write_midi(tmp_path / "t.mid", times, np.zeros(times.size), tempo=tempo)
    starts = np.array([n["time"] for n in read_with_mido(tmp_path / "t.mid")[3]])
    half_tick = 0.5 * mido.bpm2tempo(tempo) * 1e-6 / midi.TICKS_PER_BEAT
    assert len(starts) == times.size
    assert np.max(np.abs(starts - times)) <= half_tick + 1e-9 and half_tick <= HALF_MS


def test_the_file_is_type_0_with_name_and_tempo_first_and_end_of_track_last(stroke_file):
    file = mido.MidiFile(stroke_file[0])
    (track,) = file.tracks
    assert (file.type, file.ticks_per_beat) == (0, 1920)
    assert [m.type for m in track[:2]] == ["track_name", "set_tempo"] and track[0].time == track[1].time == 0
    assert track[-1].type == "end_of_track"


# ---------------------------------------------------------------- reading scores


def write_score(path, tracks, *, type=1, ticks_per_beat=480):
    file = mido.MidiFile(type=type, ticks_per_beat=ticks_per_beat)
    file.tracks.extend(mido.MidiTrack(track) for track in tracks)
    file.save(path)
    return path


def on(note, velocity, time, channel=9):
    return mido.Message("note_on", note=note, velocity=velocity, time=time, channel=channel)


def off(note, time, channel=9):
    return mido.Message("note_off", note=note, time=time, channel=channel)


def tempo(microseconds, time):
    return mido.MetaMessage("set_tempo", tempo=microseconds, time=time)


def by_hand(tick):
    """Seconds of ``tick`` at 480 ticks per beat, 120 bpm to tick 960, 240 bpm to tick 1440, then 60 bpm."""
    if tick <= 960:
        return tick * 0.5 / 480
    if tick <= 1440:
        return 1.0 + (tick - 960) * 0.25 / 480
    return 1.25 + (tick - 1440) * 1.0 / 480


# Absolute ticks, key, velocity, 0-based channel of the notes in the score files below.
SCORE = [(0, 38, 100, 9), (480, 42, 60, 9), (960, 38, 127, 9), (960, 60, 30, 0), (1200, 36, 1, 9),
         (1440, 38, 90, 3), (2000, 38, 64, 9)]
EXPECTED = [midi.Note(by_hand(tick), note, velocity, channel + 1) for tick, note, velocity, channel in SCORE]


def score_events():
    """(absolute tick, message) of SCORE: every note held 100 ticks, ended by note_on velocity 0 or note_off."""
    events = []
    for i, (tick, note, velocity, channel) in enumerate(SCORE):
        events.append((tick, on(note, velocity, 0, channel)))
        events.append((tick + 100, off(note, 0, channel) if i % 2 else on(note, 0, 0, channel)))
    return events


def score_messages():
    return to_delta(score_events())


def to_delta(events):
    """Messages with delta times from (absolute tick, message) pairs; equal ticks keep their order."""
    messages, previous = [], 0
    for tick, message in sorted(events, key=lambda event: event[0]):
        messages.append(message.copy(time=tick - previous))
        previous = tick
    return messages


TEMPI = [(0, tempo(500_000, 0)), (960, tempo(250_000, 0)), (1440, tempo(1_000_000, 0))]


def assert_notes_equal(got, expected, tolerance=1e-9):
    assert [(n.note, n.velocity, n.channel) for n in got] == [(n.note, n.velocity, n.channel) for n in expected]
    np.testing.assert_allclose([n.time for n in got], [n.time for n in expected], rtol=0, atol=tolerance)


def pretty_midi_starts(path):
    notes = [note for instrument in pretty_midi.PrettyMIDI(str(path)).instruments for note in instrument.notes]
    return sorted((note.start, note.pitch, note.velocity) for note in notes)


def test_type_1_score_with_tempo_changes_on_the_tempo_track(tmp_path):
    path = write_score(tmp_path / "score1.mid", [to_delta(TEMPI), score_messages()])
    notes = midi.read_midi_notes(path)
    assert_notes_equal(notes, EXPECTED)
    assert [n.time for n in notes] == sorted(n.time for n in notes)
    expected = sorted((n.time, n.note, n.velocity) for n in EXPECTED)
    for (start, pitch, velocity), (time, note, vel) in zip(pretty_midi_starts(path), expected, strict=True):
        assert (pitch, velocity) == (note, vel) and abs(start - time) < 1e-9


def test_type_0_score_with_tempo_changes_among_the_notes(tmp_path):
    path = write_score(tmp_path / "score0.mid", [to_delta(TEMPI + score_events())], type=0)
    assert mido.MidiFile(path).type == 0
    assert_notes_equal(midi.read_midi_notes(path), EXPECTED)
    assert [s for s, _, _ in pretty_midi_starts(path)] == pytest.approx(sorted(n.time for n in EXPECTED), abs=1e-9)


def test_a_tempo_change_in_a_later_track_applies_to_every_track(tmp_path):
    # Not valid for pretty_midi (tempo outside track 0), so only the hand-made times check it.
    path = write_score(tmp_path / "late.mid", [score_messages(), to_delta(TEMPI)])
    assert_notes_equal(midi.read_midi_notes(path), EXPECTED)


def test_without_set_tempo_the_tempo_is_120_bpm_and_zero_velocity_is_not_a_note(tmp_path):
    path = write_score(tmp_path / "plain.mid", [[on(38, 0, 0), on(38, 80, 240), on(38, 0, 240), off(38, 0)]],
                       ticks_per_beat=96)
    assert midi.read_midi_notes(path) == [midi.Note(240 * 0.5 / 96, 38, 80, 10)]


# ---------------------------------------------------------------- errors


def names_path(path):
    return re.escape(repr(str(path)))


def test_a_truncated_file_names_the_file(tmp_path, stroke_file):
    data = stroke_file[0].read_bytes()
    path = tmp_path / "half.mid"
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(ParameterError, match=names_path(path) + ".*truncated"):
        midi.read_midi_notes(path)


def test_random_bytes_name_the_file(tmp_path, rng):
    path = tmp_path / "noise.mid"
    path.write_bytes(rng.integers(0, 256, 4096, dtype=np.uint8).tobytes())
    with pytest.raises(ParameterError, match=names_path(path) + ".*not a MIDI file"):
        midi.read_midi_notes(path)


def test_a_missing_file_or_a_folder_names_the_path(tmp_path):
    with pytest.raises(ParameterError, match=names_path(tmp_path / "nowhere.mid") + ".*No such file"):
        midi.read_midi_notes(tmp_path / "nowhere.mid")
    with pytest.raises(ParameterError, match=names_path(tmp_path)):
        midi.read_midi_notes(tmp_path)


def test_type_2_files_are_refused(tmp_path):
    path = write_score(tmp_path / "type2.mid", [score_messages(), score_messages()], type=2)
    with pytest.raises(ParameterError, match=names_path(path) + ".*type 2"):
        midi.read_midi_notes(path)


def test_smpte_time_division_is_refused(tmp_path):
    path = write_score(tmp_path / "smpte.mid", [score_messages()], ticks_per_beat=-25 * 256 + 40)
    with pytest.raises(ParameterError, match=names_path(path) + ".*SMPTE"):
        midi.read_midi_notes(path)


def test_a_score_without_notes_is_refused(tmp_path):
    path = write_score(tmp_path / "empty.mid", [to_delta(TEMPI), [on(38, 0, 10), off(38, 10)]])
    with pytest.raises(ParameterError, match=names_path(path) + ".*has no notes"):
        midi.read_midi_notes(path)


def test_damaged_files_give_notes_or_a_parameter_error_never_a_traceback(tmp_path, rng, stroke_file):
    data = stroke_file[0].read_bytes()
    path = tmp_path / "damaged.mid"
    outcomes = set()
    for i in range(300):
        damaged = bytearray(data)
        for position in rng.integers(0, len(damaged), 3):
            damaged[position] = rng.integers(0, 256)
        path.write_bytes(bytes(damaged[: rng.integers(1, len(damaged))] if i % 3 == 0 else damaged))
        try:
            notes = midi.read_midi_notes(path)
        except ParameterError as error:
            assert str(path) in str(error)
            outcomes.add("error")
        else:
            assert notes and all(isinstance(note, midi.Note) for note in notes)
            outcomes.add("notes")
    assert outcomes == {"error", "notes"}


BAD_WRITES = [
    pytest.param({"times": [0.0, math.nan]}, r"times\[1\] must be a finite number in \[0, inf\) s, got nan", id="nan-time"),
    pytest.param({"times": [-0.1, 0.0]}, r"times\[0\] must be .* got -0.1", id="negative-time"),
    pytest.param({"times": [0.0, math.inf]}, r"times\[1\] .* got inf", id="inf-time"),
    pytest.param({"times": [0.2, 0.1]}, r"non-decreasing: times\[1\] = 0.1 s comes before times\[0\] = 0.2", id="decreasing"),
    pytest.param({"times": [0.0, 1e9]}, r"times\[1\] must be in \[0, .*\] s at tempo 120 bpm.* got 1000000000.0", id="too-late"),
    pytest.param({"times": [[0.0, 1.0]]}, r"times must be a 1-D array of numbers, got shape \(1, 2\)", id="2-d"),
    pytest.param({"times": ["a", "b"]}, r"times must be a 1-D array of numbers, got \['a', 'b'\]", id="text"),
    pytest.param({"levels_db": [0.0, math.inf]}, r"levels_db\[1\] must be a number in \[-inf, inf\) dB, got inf", id="inf-level"),
    pytest.param({"levels_db": [math.nan, 0.0]}, r"levels_db\[0\] .* got nan", id="nan-level"),
    pytest.param({"levels_db": [0.0]}, r"times and levels_db must have the same length, got 2 and 1", id="lengths"),
    pytest.param({"channel": 0}, r"channel must be in \[1, 16\], got 0", id="channel-0"),
    pytest.param({"channel": 17}, r"channel must be in \[1, 16\], got 17", id="channel-17"),
    pytest.param({"channel": 10.0}, r"channel must be an integer in \[1, 16\], got 10.0", id="channel-float"),
    pytest.param({"note": 128}, r"note must be in \[0, 127\], got 128", id="note-128"),
    pytest.param({"note": -1}, r"note must be in \[0, 127\], got -1", id="note-negative"),
    pytest.param({"note": True}, r"note must be an integer in \[0, 127\], got True", id="note-bool"),
    pytest.param({"tempo": 0}, r"tempo must be in \(0, 1000\] bpm, got 0.0", id="tempo-0"),
    pytest.param({"tempo": 1000.5}, r"tempo must be in \(0, 1000\] bpm, got 1000.5", id="tempo-high"),
    pytest.param({"tempo": math.nan}, r"tempo must be a finite number in \(0, 1000\] bpm, got nan", id="tempo-nan"),
    pytest.param({"title": 7}, r"title must be a str, got 7", id="title"),
]


@pytest.mark.parametrize(("change", "message"), BAD_WRITES)
def test_bad_input_to_write_midi_is_refused_and_writes_nothing(tmp_path, change, message):
    arguments = {"times": [0.0, 0.5], "levels_db": [0.0, -6.0]} | change
    times, levels = arguments.pop("times"), arguments.pop("levels_db")
    with pytest.raises(ParameterError, match=message):
        midi.write_midi(tmp_path / "bad.mid", times, levels, **arguments)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("field", ["time", "note", "velocity", "channel"])
def test_a_note_checks_its_fields(field):
    bad = {"time": -1.0, "note": 128, "velocity": 0, "channel": 17}
    fields = {"time": 0.0, "note": 38, "velocity": 1, "channel": 10} | {field: bad[field]}
    with pytest.raises(ParameterError, match=f"{field} must be in .*, got {bad[field]}"):
        midi.Note(**fields)


# ---------------------------------------------------------------- atomic writes


def crash(*args, **kwargs):
    raise OSError("disk pulled out")


@pytest.mark.parametrize("where", ["save", "replace"])
def test_a_crash_mid_write_leaves_the_old_file_whole(tmp_path, monkeypatch, stroke_file, where):
    path, _ = stroke_file
    before = path.read_bytes()
    if where == "save":
        monkeypatch.setattr(mido.MidiFile, "save", crash)
    else:
        monkeypatch.setattr(drumstroke._atomic.os, "replace", crash)
    with pytest.raises(OSError, match="disk pulled out"):
        midi.write_midi(path, [0.0, 1.0], [0.0, 0.0], title="new")
    assert path.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == [path.name]
