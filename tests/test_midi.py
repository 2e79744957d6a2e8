"""MIDI: impacts written as percussion and checked by two independent readers; scores read back in seconds.

Written files are read with mido (messages, delta ticks and tempo changes turned into seconds here, by
hand) and with pretty_midi; score files are built with mido here and their note times worked out by hand;
the real files of tests/data/midi (made by others) are checked against mido's and pretty_midi's readings.
"""

import inspect
import math
import os
import re
import tracemalloc
from collections import Counter
from pathlib import Path

import mido
import numpy as np
import pretty_midi
import pytest

import drumstroke
import drumstroke._atomic
from _midi import read_with_mido
from drumstroke import ParameterError
from drumstroke.dynamics import CEILING_DB, FLOOR_DB, level_to_velocity
from drumstroke.formats import midi
from drumstroke.formats.midi import TempoMap, Track

HALF_MS = 0.5e-3
DATA = Path(__file__).resolve().parent / "data" / "midi"
TYPE_0 = DATA / "d6caebd1964d9e4a3c5ea59525230e2a.mid"  # drums on channel 10 among 8 other channels, 65 tempi
TYPE_1 = DATA / "d8faddb8596fff7abb24d78666f73e4e.mid"  # 18 tracks, drums on channel 10 in 'Track 9'
TEMPO_TRACK = DATA / "1390.mid"  # a tempo track with 68 changes, then 'piano' (channel 1) and 'melody' (channel 2)
REAL_FILES = [TYPE_0, TYPE_1, TEMPO_TRACK]


def pretty_midi_notes(path):
    """(start s, key, velocity, channel-10-ness) of every note, as pretty_midi reads the file, in time order."""
    return sorted((note.start, note.pitch, note.velocity, instrument.is_drum)
                  for instrument in pretty_midi.PrettyMIDI(str(path)).instruments for note in instrument.notes)


def audible(levels):
    return np.asarray(levels) >= FLOOR_DB


def keys_of(count):
    """A stroke's keys: 38 for its first impact, 40 for the rest."""
    return np.where(np.arange(count) == 0, 38, 40)


@pytest.fixture(scope="module")
def stroke():
    return drumstroke.simulate("free-bounce")


@pytest.fixture
def stroke_file(stroke, tmp_path):
    path = tmp_path / "free-bounce.mid"
    t, level = stroke.impacts.t, stroke.impacts.level_db
    written = midi.write_midi(path, [Track("free-bounce", t, level, keys_of(t.size))], title="free-bounce (paper)")
    return path, written


# ---------------------------------------------------------------- writing, read back by mido and pretty_midi


def test_a_simulated_stroke_reads_back_with_mido(stroke, stroke_file):
    path, (written,) = stroke_file
    t, level = stroke.impacts.t, stroke.impacts.level_db
    keep = audible(level)
    assert 0 < keep.sum() < len(t), "free-bounce should have both audible and too-quiet impacts"

    file, names, tempo_map, meters, notes = read_with_mido(path)
    assert file.type == 1 and file.ticks_per_beat == midi.TICKS_PER_BEAT and len(file.tracks) == 2
    assert names == ["free-bounce (paper)", "free-bounce"] and tempo_map == [(0, 500_000)] and meters == [(0, 4, 4)]
    assert {note["track"] for note in notes} == {1}
    assert len(notes) == len(written) == keep.sum()
    times = np.array([note["time"] for note in notes])
    assert np.max(np.abs(times - t[keep])) <= 0.5 * 500_000e-6 / midi.TICKS_PER_BEAT + 1e-12
    assert [note["note"] for note in notes] == keys_of(t.size)[keep].tolist() and notes[0]["note"] == 38
    assert {note["channel"] for note in notes} == {9}
    assert [note["velocity"] for note in notes] == level_to_velocity(level[keep]).tolist()
    assert [(n.note, n.velocity, n.track) for n in written] == [(n["note"], n["velocity"], 1) for n in notes]
    np.testing.assert_allclose([note.time for note in written], times, rtol=0, atol=1e-12)


def test_a_simulated_stroke_reads_back_with_pretty_midi(stroke, stroke_file):
    path, _ = stroke_file
    keep = audible(stroke.impacts.level_db)
    (instrument,) = pretty_midi.PrettyMIDI(str(path)).instruments
    assert instrument.is_drum and instrument.name == "free-bounce"
    starts = np.array([note.start for note in instrument.notes])
    assert len(starts) == keep.sum()
    assert np.max(np.abs(starts - stroke.impacts.t[keep])) < HALF_MS
    assert [note.pitch for note in instrument.notes] == keys_of(keep.size)[keep].tolist()
    assert [note.velocity for note in instrument.notes] == level_to_velocity(stroke.impacts.level_db[keep]).tolist()
    lengths = np.array([note.end - note.start for note in instrument.notes])
    assert np.all(lengths > 0) and np.all(lengths <= midi.NOTE_LENGTH + HALF_MS)


def test_written_notes_read_back_equal_with_read_midi(stroke_file):
    path, (written,) = stroke_file
    score = read_midi_or_fail(path)
    notes = list(score.notes())
    assert [(n.note, n.velocity, n.channel, n.track) for n in notes] == \
           [(n.note, n.velocity, n.channel, n.track) for n in written]
    np.testing.assert_allclose([n.time for n in notes], [n.time for n in written], rtol=0, atol=1e-12)
    assert score.track_names == ("free-bounce (paper)", "free-bounce") and score.type == 1


def read_midi_or_fail(path):
    score = midi.read_midi(path)
    assert inspect.isgenerator(score.notes())  # streamed, not a list built up front
    return score


def test_velocities_follow_the_dynamics_map_and_never_fall_as_the_level_rises(tmp_path, rng):
    levels = np.sort(rng.uniform(FLOOR_DB - 3.0, CEILING_DB + 3.0, 200))
    times = np.arange(levels.size) * 0.05
    (written,) = midi.write_midi(tmp_path / "ramp.mid", [Track("ramp", times, levels, 38)])
    keep = audible(levels)
    velocities = np.array([note["velocity"] for note in read_with_mido(tmp_path / "ramp.mid")[4]])
    assert velocities.tolist() == level_to_velocity(levels[keep]).tolist() == [n.velocity for n in written]
    assert np.all(np.diff(velocities) >= 0)
    assert velocities[0] == 1 and velocities[-1] == 127 and len(set(velocities.tolist())) > 100


def test_impacts_quieter_than_the_floor_are_left_out(tmp_path):
    levels = [-math.inf, FLOOR_DB - 1e-9, FLOOR_DB, -80.0, 0.0, FLOOR_DB - 0.1]
    (written,) = midi.write_midi(tmp_path / "quiet.mid", [Track("s", [0.0, 0.1, 0.2, 0.3, 0.4, 0.5], levels, 38)])
    assert [(round(n.time, 9), n.velocity) for n in written] == [(0.2, 1), (0.4, level_to_velocity(0.0))]
    (drum,) = pretty_midi.PrettyMIDI(str(tmp_path / "quiet.mid")).instruments
    assert [(round(n.start, 9), n.velocity) for n in drum.notes] == [(0.2, 1), (0.4, level_to_velocity(0.0))]


def test_all_quiet_impacts_write_a_file_without_notes(tmp_path):
    path = tmp_path / "silent.mid"
    assert midi.write_midi(path, [Track("s", [0.0, 1.0], [-math.inf, -90.0], 38)], title="silent") == [[]]
    _, names, _, _, notes = read_with_mido(path)
    assert notes == [] and names == ["silent", "s"]
    assert list(midi.read_midi(path).notes()) == []


def test_impacts_on_the_same_tick_and_key_merge_into_the_louder(tmp_path):
    tick = 500_000e-6 / midi.TICKS_PER_BEAT
    times = [0.1, 0.1, 0.1 + 0.3 * tick, 0.2, 0.2 + tick, 0.3, 0.3, 0.4, 0.4]
    levels = [-20.0, -5.0, -30.0, -10.0, -12.0, -100.0, -15.0, -20.0, -25.0]
    keys = [38, 38, 38, 38, 38, 38, 38, 38, 40]  # the last two share a tick but not a key: both stay
    (written,) = midi.write_midi(tmp_path / "merge.mid", [Track("s", times, levels, keys)])
    expected = [(0.1, 38, -5.0), (0.2, 38, -10.0), (0.2 + tick, 38, -12.0), (0.3, 38, -15.0), (0.4, 38, -20.0),
                (0.4, 40, -25.0)]
    notes = read_with_mido(tmp_path / "merge.mid")[4]
    for got in (written, [midi.Note(n["time"], n["note"], n["velocity"], n["channel"] + 1, 1) for n in notes]):
        assert [(n.note, n.velocity) for n in got] == [(k, level_to_velocity(v)) for _, k, v in expected]
        np.testing.assert_allclose([n.time for n in got], [t for t, _, _ in expected], rtol=0, atol=0.5 * tick + 1e-12)


def test_a_note_lasts_its_length_or_ends_as_the_next_of_its_key_starts_on_any_track(tmp_path):
    tick = 500_000e-6 / midi.TICKS_PER_BEAT
    full = round(midi.NOTE_LENGTH / tick)
    tracks = [Track("right", [0.0, 0.005, 0.005 + tick, 1.0, 2.0], [0.0] * 5, [38, 38, 38, 38, 40]),
              Track("left", [1.010, 2.005], [0.0, 0.0], [38, 38])]
    midi.write_midi(tmp_path / "lengths.mid", tracks)
    notes = read_with_mido(tmp_path / "lengths.mid")[4]
    lengths = {(n["track"], n["tick"]): n["end_tick"] - n["tick"] for n in notes}
    at = {t: round(t / tick) for t in (0.0, 0.005, 0.005 + tick, 1.0, 1.010, 2.0, 2.005)}
    assert lengths == {
        (1, at[0.0]): at[0.005],                 # cut by its own track's next 38
        (1, at[0.005]): 1,                       # a tick before the next 38
        (1, at[0.005 + tick]): full,
        (1, at[1.0]): at[1.010] - at[1.0],       # cut by the left stick's 38, ten milliseconds later
        (2, at[1.010]): full,
        (1, at[2.0]): full,                      # a 40: the left stick's 38 five milliseconds later is another key
        (2, at[2.005]): full,
    }
    assert abs(full * tick - midi.NOTE_LENGTH) <= 0.5 * tick
    file = mido.MidiFile(tmp_path / "lengths.mid")
    assert [m.type for m in file.tracks[1] if not m.is_meta] == ["note_on", "note_off"] * 5  # off first on a tick
    merged, sounding = [], set()  # played on one channel, as a synthesizer merges the tracks: no key overlaps
    for message in mido.merge_tracks(file.tracks):
        if message.type == "note_on":
            assert message.note not in sounding
            sounding.add(message.note)
        elif message.type == "note_off":
            sounding.discard(message.note)
            merged.append(message.note)
    assert len(merged) == 7 and not sounding
    instruments = pretty_midi.PrettyMIDI(str(tmp_path / "lengths.mid")).instruments
    assert [len(i.notes) for i in instruments] == [5, 2] and [i.name for i in instruments] == ["right", "left"]


def test_channel_and_titles_are_honoured(tmp_path, stroke):
    t, level = stroke.impacts.t, stroke.impacts.level_db
    title = "double stroke — model: geometry"
    (written,) = midi.write_midi(tmp_path / "hat.mid", [Track("stick é", t, level, np.int64(42))], channel=1,
                                 title=title)
    _, names, _, _, notes = read_with_mido(tmp_path / "hat.mid", charset="utf-8")
    assert names == [title, "stick é"]
    assert {(n["note"], n["channel"]) for n in notes} == {(42, 0)}
    assert {(n.note, n.channel) for n in written} == {(42, 1)}
    (instrument,) = pretty_midi.PrettyMIDI(str(tmp_path / "hat.mid")).instruments
    assert not instrument.is_drum and {n.pitch for n in instrument.notes} == {42}


@pytest.mark.parametrize("tempo", [31.25, 60.0, 133.7, 1000.0])
def test_timing_error_is_at_most_half_a_tick_at_any_tempo(tmp_path, rng, tempo):
    times = np.cumsum(rng.uniform(0.002, 4.0, 300))  # at least two ticks apart at 31.25 bpm, so none merge
    midi.write_midi(tmp_path / "t.mid", [Track("s", times, np.zeros(times.size), 38)],
                    tempo_map=TempoMap.constant(tempo))
    file, _, tempo_map, _, notes = read_with_mido(tmp_path / "t.mid")
    assert tempo_map == [(0, mido.bpm2tempo(tempo))]
    starts = np.array([n["time"] for n in notes])
    half_tick = 0.5 * mido.bpm2tempo(tempo) * 1e-6 / file.ticks_per_beat
    assert len(starts) == times.size
    assert np.max(np.abs(starts - times)) <= half_tick + 1e-9 and half_tick <= HALF_MS


def test_a_tempo_map_is_written_on_its_ticks_and_every_impact_reads_back_within_half_a_ms(tmp_path, rng):
    """Tempo changes at beats 0, 3.5 (a waltz of 3/4 from beat 6) and so on; impacts anywhere, in seconds.
    mido (walked here) and pretty_midi (its own tempo handling) both give back every impact's time."""
    tempi = ((0.0, 600_000), (3.5, 350_000), (6.0, 1_500_000), (10.25, 428_571))
    tempo_map = TempoMap(tempi=tempi, meters=((0.0, 4, 4), (6.0, 3, 4)))
    end = float(tempo_map.seconds(14.0))
    right = np.sort(rng.uniform(0.0, end, 60))
    left = np.sort(rng.uniform(0.0, end, 40))
    tracks = [Track("right", right, np.zeros(60), keys_of(60)), Track("left", left, np.full(40, -6.0), 40)]
    written = midi.write_midi(tmp_path / "map.mid", tracks, tempo_map=tempo_map, title="a map")
    file, names, got_tempi, meters, notes = read_with_mido(tmp_path / "map.mid")
    resolution = file.ticks_per_beat
    assert resolution % midi.TICKS_PER_BEAT == 0 and 0.5 * 1_500_000e-6 / resolution <= HALF_MS
    assert got_tempi == [(round(beat * resolution), tempo) for beat, tempo in tempi]
    assert meters == [(0, 4, 4), (6 * resolution, 3, 4)] and names == ["a map", "right", "left"]
    for number, times in ((1, right), (2, left)):
        starts = np.array([n["time"] for n in notes if n["track"] == number])
        assert starts.size == times.size and np.max(np.abs(starts - times)) <= HALF_MS
        np.testing.assert_allclose([n.time for n in written[number - 1]], starts, rtol=0, atol=1e-9)
    theirs = pretty_midi.PrettyMIDI(str(tmp_path / "map.mid"))
    assert [i.name for i in theirs.instruments] == ["right", "left"]
    for instrument, times in zip(theirs.instruments, (right, left)):
        assert np.max(np.abs(np.array([n.start for n in instrument.notes]) - times)) <= HALF_MS
    changes, bpm = theirs.get_tempo_changes()
    assert changes == pytest.approx(tempo_map.seconds([beat for beat, _ in tempi]), abs=1e-9)
    assert bpm == pytest.approx([60e6 / tempo for _, tempo in tempi], rel=1e-12)
    assert [(s.numerator, s.denominator) for s in theirs.time_signature_changes] == [(4, 4), (3, 4)]


def test_a_file_is_written_at_a_multiple_of_the_resolution_its_tempo_map_was_read_at(tmp_path):
    for resolution, written in ((96, 1920), (480, 1920), (1024, 2048), (25_000, 25_000)):
        tempo_map = TempoMap(tempi=((0.0, 500_000), (7 / resolution, 400_000)), resolution=resolution)
        midi.write_midi(tmp_path / "r.mid", [Track("s", [0.5], [0.0], 38)], tempo_map=tempo_map)
        file, _, tempi, _, _ = read_with_mido(tmp_path / "r.mid")
        assert file.ticks_per_beat == written and tempi[1] == (7 * written // resolution, 400_000)


def test_an_hour_long_file_stays_within_the_ticks_pretty_midi_reads_and_within_half_a_millisecond(tmp_path, rng):
    times = np.sort(np.concatenate(([0.0, 3600.0], rng.uniform(0.0, 3600.0, 200))))
    midi.write_midi(tmp_path / "hour.mid", [Track("s", times, np.zeros(times.size), 38)])
    file, _, _, _, notes = read_with_mido(tmp_path / "hour.mid")
    assert 500 <= file.ticks_per_beat < midi.TICKS_PER_BEAT  # coarser, but half a tick is still under 0.5 ms
    assert max(n["end_tick"] for n in notes) <= midi.MAX_TICKS
    for starts in ([n["time"] for n in notes], [n.start for n in pretty_midi.PrettyMIDI(str(tmp_path / "hour.mid"))
                                                .instruments[0].notes]):
        assert np.max(np.abs(np.array(starts) - times)) <= HALF_MS


def test_the_slowest_midi_tempo_is_written_finely_enough_and_a_slower_one_is_refused(tmp_path):
    midi.write_midi(tmp_path / "slow.mid", [Track("s", [0.0, 20.0, 33.3], [0.0] * 3, 38)],
                    tempo_map=TempoMap(tempi=((0.0, midi.SLOWEST_MIDI_TEMPO),)))
    file, _, tempi, _, notes = read_with_mido(tmp_path / "slow.mid")
    assert tempi == [(0, midi.SLOWEST_MIDI_TEMPO)] and 0.5 * midi.SLOWEST_MIDI_TEMPO * 1e-6 / file.ticks_per_beat <= HALF_MS
    assert [n["time"] for n in notes] == pytest.approx([0.0, 20.0, 33.3], abs=HALF_MS)
    with pytest.raises(ParameterError, match=r"tempo_map: a MIDI file holds tempi of 3.58 bpm and faster, got 0.5 bpm"):
        midi.write_midi(tmp_path / "slower.mid", [Track("s", [0.0], [0.0], 38)], tempo_map=TempoMap.constant(0.5))
    assert not (tmp_path / "slower.mid").exists()


# ---------------------------------------------------------------- the tempo map


def test_a_tempo_map_turns_beats_into_seconds_and_back():
    tempo_map = TempoMap(tempi=((0.0, 500_000), (2.0, 250_000), (3.0, 1_000_000)))
    beats = np.array([0.0, 1.0, 2.0, 2.5, 3.0, 4.5])
    seconds = [0.0, 0.5, 1.0, 1.125, 1.25, 2.75]  # 0.5 s a beat, then 0.25, then 1
    assert tempo_map.seconds(beats).tolist() == seconds
    assert tempo_map.beats(seconds) == pytest.approx(beats, abs=1e-15)
    assert TempoMap().tempi == ((0.0, 500_000.0),) and TempoMap().meters == ((0.0, 4, 4),)
    assert TempoMap.constant(96, meter=(7, 8)) == TempoMap(tempi=((0.0, 625_000),), meters=((0.0, 7, 8),))


@pytest.mark.parametrize(("fields", "message"), [
    ({"tempi": ()}, r"tempi must be a non-empty sequence of \(beat, tempo\)"),
    ({"tempi": ((0.0,),)}, r"tempi must be a non-empty sequence of \(beat, tempo\)"),
    ({"tempi": ((1.0, 500_000),)}, r"tempi\[0\] must be at beat 0, got beat 1"),
    ({"tempi": ((0.0, 500_000), (2.0, 400_000), (2.0, 300_000))}, r"tempi beats must increase: tempi\[2\] at beat 2"),
    ({"tempi": ((0.0, 0),)}, r"tempi\[0\] tempo must be in \[60000, inf\) µs per beat, got 0.0"),
    ({"tempi": ((0.0, 59_999),)}, r"tempi\[0\] tempo must be in \[60000, inf\) µs per beat, got 59999.0"),
    ({"tempi": ((0.0, math.nan),)}, r"tempi\[0\] tempo must be a finite number"),
    ({"tempi": ((-1.0, 500_000),)}, r"tempi\[0\] beat must be in \[0, inf\), got -1.0"),
    ({"meters": ((0.0, 0, 4),)}, r"meters\[0\] numerator must be an integer in \[1, 255\], got 0"),
    ({"meters": ((0.0, 3, 6),)}, r"meters\[0\] denominator must be a power of two in \[1, 128\], got 6"),
    ({"meters": ((0.0, 3, 256),)}, r"meters\[0\] denominator must be an integer in \[1, 128\], got 256"),
    ({"meters": ((0.0, 4, 4), (0.0, 3, 4))}, r"meters beats must increase"),
    ({"resolution": 0}, r"resolution must be an integer in \[1, 32767\] ticks per beat, got 0"),
    ({"tempi": (("0", 500_000),)}, r"tempi\[0\] beat must be a number in \[0, inf\), got '0'"),
    ({"meters": ((0.0, 4.0, 4),)}, r"meters\[0\] numerator must be an integer in \[1, 255\], got 4.0"),
])
def test_a_tempo_map_checks_its_fields(fields, message):
    with pytest.raises(ParameterError, match=message):
        TempoMap(**fields)
    with pytest.raises(ParameterError, match=r"tempo must be in \(0, 1000\] bpm, got 0.0"):
        TempoMap.constant(0)


# ---------------------------------------------------------------- reading scores made by hand


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


def expected(track):
    return [midi.Note(by_hand(tick), note, velocity, channel + 1, track) for tick, note, velocity, channel in SCORE]


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
READ_TEMPI = ((0.0, 500_000.0), (2.0, 250_000.0), (3.0, 1_000_000.0))


def assert_notes_equal(got, expected, tolerance=1e-9):
    got = list(got)
    assert [(n.note, n.velocity, n.channel, n.track) for n in got] == \
           [(n.note, n.velocity, n.channel, n.track) for n in expected]
    np.testing.assert_allclose([n.time for n in got], [n.time for n in expected], rtol=0, atol=tolerance)


def test_type_1_score_with_tempo_changes_on_the_tempo_track(tmp_path):
    path = write_score(tmp_path / "score1.mid", [to_delta(TEMPI), score_messages()])
    score = midi.read_midi(path)
    assert score.type == 1 and score.track_names == ("", "") and score.tempo_map.tempi == READ_TEMPI
    assert score.tempo_map.resolution == 480
    notes = list(score.notes())
    assert_notes_equal(notes, expected(1))
    expected_starts = sorted((n.time, n.note, n.velocity, n.channel == 10) for n in expected(1))
    for theirs, ours in zip(pretty_midi_notes(path), expected_starts, strict=True):
        assert theirs[1:] == ours[1:] and abs(theirs[0] - ours[0]) < 1e-9


def test_type_0_score_with_tempo_changes_among_the_notes(tmp_path):
    path = write_score(tmp_path / "score0.mid", [to_delta(TEMPI + score_events())], type=0)
    score = midi.read_midi(path)
    assert score.type == 0 and score.tempo_map.tempi == READ_TEMPI
    assert_notes_equal(score.notes(), expected(0))
    assert [s for s, *_ in pretty_midi_notes(path)] == pytest.approx(sorted(n.time for n in expected(0)), abs=1e-9)


def test_a_tempo_change_in_a_later_track_applies_to_every_track(tmp_path):
    # Not valid for pretty_midi (tempo outside track 0), so only the hand-made times check it.
    path = write_score(tmp_path / "late.mid", [score_messages(), to_delta(TEMPI)])
    assert_notes_equal(midi.read_midi(path).notes(), expected(0))


def test_notes_of_several_tracks_come_in_time_order_then_track_order(tmp_path):
    tracks = [[on(38, 10, 0), on(40, 11, 100)], [on(37, 20, 50), on(38, 21, 50)], [on(36, 30, 0), on(38, 31, 200)]]
    path = write_score(tmp_path / "three.mid", tracks)
    notes = list(midi.read_midi(path).notes())
    assert [(round(n.time * 960), n.velocity, n.track) for n in notes] == [
        (0, 10, 0), (0, 30, 2), (50, 20, 1), (100, 11, 0), (100, 21, 1), (200, 31, 2)]


def test_without_set_tempo_the_tempo_is_120_bpm_and_zero_velocity_is_not_a_note(tmp_path):
    path = write_score(tmp_path / "plain.mid", [[on(38, 0, 0), on(38, 80, 240), on(38, 0, 240), off(38, 0)]],
                       ticks_per_beat=96)
    score = midi.read_midi(path)
    assert list(score.notes()) == [midi.Note(240 * 0.5 / 96, 38, 80, 10, 0)]
    assert score.tempo_map == TempoMap(resolution=96)


def test_time_signatures_are_read_from_any_track(tmp_path):
    signature = mido.MetaMessage("time_signature", numerator=6, denominator=8, time=960)
    path = write_score(tmp_path / "six-eight.mid", [[on(38, 10, 0)], [signature]])
    assert midi.read_midi(path).tempo_map.meters == ((0.0, 4, 4), (2.0, 6, 8))


# ---------------------------------------------------------------- reading real files made by others


def mido_count(path):
    """Independently of drumstroke: every note_on with velocity >= 1, as (channel from 1, key) -> count."""
    counts = {}
    for track in mido.MidiFile(path).tracks:
        for message in track:
            if message.type == "note_on" and message.velocity > 0:
                key = (message.channel + 1, message.note)
                counts[key] = counts.get(key, 0) + 1
    return counts


def never_ended(path):
    """(track, tick, channel from 1, key, velocity) of each note_on that no later note-off of its key on its
    track ends: pretty_midi leaves such notes out (a drum hit needs no end, so drumstroke plays them)."""
    found = []
    for number, track in enumerate(mido.MidiFile(path).tracks):
        tick, open_notes = 0, {}
        for message in track:
            tick += message.time
            if message.type not in ("note_on", "note_off"):
                continue
            key = (message.channel + 1, message.note)
            if message.type == "note_on" and message.velocity > 0:
                open_notes.setdefault(key, []).append((tick, message.velocity))
            else:  # pretty_midi ends every open note of the key, but one started on this very tick
                open_notes[key] = [(start, velocity) for start, velocity in open_notes.get(key, []) if start == tick]
        found += [(number, start, *key, velocity) for key, starts in open_notes.items() for start, velocity in starts]
    return found


def by_kind(notes):
    """Times of (time, key, velocity, percussion) notes, sorted, by (key, velocity, percussion)."""
    kinds = {}
    for time, *kind in notes:
        kinds.setdefault(tuple(kind), []).append(time)
    return {kind: np.sort(times) for kind, times in kinds.items()}


@pytest.mark.parametrize("path", REAL_FILES, ids=[p.name for p in REAL_FILES])
def test_a_real_file_reads_every_note_at_pretty_midis_time_and_its_tempo_map(path):
    """Against pretty_midi's own reading: the same notes (time to 1 µs, key, velocity, percussion or not),
    but for those it leaves out because nothing ends them; the same tempo changes and time signatures."""
    score = midi.read_midi(path)
    notes = list(score.notes())
    assert Counter((note.channel, note.note) for note in notes) == mido_count(path)
    theirs = pretty_midi_notes(path)
    resolution = mido.MidiFile(path).ticks_per_beat
    unended = [(float(score.tempo_map.seconds(tick / resolution)), key, velocity, channel == 10)
               for _, tick, channel, key, velocity in never_ended(path)]
    ours = by_kind([(n.time, n.note, n.velocity, n.channel == 10) for n in notes])
    expected = by_kind(theirs + unended)
    assert len(theirs) > 900 and ours.keys() == expected.keys()
    for kind, times in ours.items():
        assert len(times) == len(expected[kind]) and np.max(np.abs(times - expected[kind])) < 1e-6, kind
    tempo_map = score.tempo_map
    midi_file = pretty_midi.PrettyMIDI(str(path))
    changes, bpm = midi_file.get_tempo_changes()
    assert tempo_map.seconds([beat for beat, _ in tempo_map.tempi]) == pytest.approx(changes, abs=1e-9)
    assert [60e6 / tempo for _, tempo in tempo_map.tempi] == pytest.approx(bpm, rel=1e-12)
    signatures = [(s.time, s.numerator, s.denominator) for s in midi_file.time_signature_changes] or [(0.0, 4, 4)]
    assert [(float(tempo_map.seconds(beat)), n, d) for beat, n, d in tempo_map.meters] == signatures


def test_the_real_files_are_what_their_readme_says():
    type_0, type_1, tempo_track = (midi.read_midi(p) for p in REAL_FILES)
    assert type_0.type == 0 and len(type_0.tempo_map.tempi) == 65
    assert type_1.type == 1 and type_1.track_names == tuple(f"Track {i}" for i in range(18))
    assert tempo_track.type == 1 and tempo_track.track_names == ("", "piano", "melody")
    assert len(tempo_track.tempo_map.tempi) == 68 and tempo_track.tempo_map.resolution == 480
    drums = {key: n for (channel, key), n in mido_count(TYPE_0).items() if channel == 10}
    assert sum(drums.values()) == 618 and drums[40] == 123 and drums[37] == 14 and 38 not in drums


# ---------------------------------------------------------------- streaming


def test_reading_a_long_file_streams_its_notes_in_bounded_memory(tmp_path):
    """60,000 notes over 8 tracks: once the file is loaded (mido's messages), walking all its notes in order
    allocates next to nothing beyond the note in hand (no list of notes, no merged copy of the tracks)."""
    tracks = [[on(36 + k, 90, 30, channel=k) if i % 2 == 0 else off(36 + k, 30, channel=k) for i in range(15_000)]
              for k in range(8)]
    path = write_score(tmp_path / "long.mid", tracks)
    score = midi.read_midi(path)
    tracemalloc.start()  # once loaded: tracing the load would only slow it (what it holds is not measured)
    try:
        count, last = 0, -1.0
        for note in score.notes():
            assert note.time >= last
            count, last = count + 1, note.time
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert count == 60_000 and last == pytest.approx(14_999 * 30 / 960, abs=1e-9)
    assert peak < 200_000, f"walking the notes took {peak} bytes"


# ---------------------------------------------------------------- errors


def names_path(path):
    return re.escape(repr(str(path)))


def test_a_truncated_file_names_the_file(tmp_path, stroke_file):
    data = stroke_file[0].read_bytes()
    path = tmp_path / "half.mid"
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(ParameterError, match=names_path(path) + ".*truncated"):
        midi.read_midi(path)


def test_random_bytes_name_the_file(tmp_path, rng):
    path = tmp_path / "noise.mid"
    path.write_bytes(rng.integers(0, 256, 4096, dtype=np.uint8).tobytes())
    with pytest.raises(ParameterError, match=names_path(path) + ".*not a MIDI file"):
        midi.read_midi(path)


def test_a_missing_file_or_a_folder_names_the_path(tmp_path):
    with pytest.raises(ParameterError, match=names_path(tmp_path / "nowhere.mid") + ".*No such file"):
        midi.read_midi(tmp_path / "nowhere.mid")
    with pytest.raises(ParameterError, match=names_path(tmp_path)):
        midi.read_midi(tmp_path)


def test_type_2_files_are_refused(tmp_path):
    path = write_score(tmp_path / "type2.mid", [score_messages(), score_messages()], type=2)
    with pytest.raises(ParameterError, match=names_path(path) + ".*type 2"):
        midi.read_midi(path)


@pytest.mark.parametrize(("division", "reason"), [(-25 * 256 + 40, "SMPTE"), (0, "0 ticks per beat")])
def test_smpte_time_division_and_zero_ticks_per_beat_are_refused(tmp_path, division, reason):
    path = write_score(tmp_path / "smpte.mid", [score_messages()], ticks_per_beat=division)
    with pytest.raises(ParameterError, match=names_path(path) + f" times in {reason}"):
        midi.read_midi(path)


@pytest.mark.parametrize(("meta", "message"), [
    (tempo(0, 960), (r"track 1 at tick 960: tempo must be in \[60000, 16777215\] µs per beat \(3.58-1000 bpm\), "
                     r"got 0 \(an infinite tempo\)")),
    (tempo(1, 0), r"track 1 at tick 0: tempo must be .* got 1 \(6e\+07 bpm\)"),
    (tempo(59_999, 5), r"track 1 at tick 5: .* got 59999 \(1000.02 bpm\)"),
    (mido.MetaMessage("time_signature", numerator=0, denominator=4, time=10),
     r"track 1 at tick 10: a time signature must be N/D .* got 0/4"),
    (mido.MetaMessage("time_signature", numerator=3, denominator=256), r"track 1 at tick 0: .* got 3/256"),
])
def test_a_tempo_or_time_signature_out_of_range_is_refused_naming_where_it_is(tmp_path, meta, message):
    path = write_score(tmp_path / "absurd.mid", [score_messages(), [meta]])
    with pytest.raises(ParameterError, match=names_path(path) + ", " + message):
        midi.read_midi(path)


def test_a_corrupt_real_world_file_is_named(tmp_path):
    """A data byte above 127 in a controller message, as miditok keeps one among its tests' corrupted files."""
    data = bytearray(TYPE_0.read_bytes())
    controller = data.index(bytes([0xB9]))  # a control change on channel 10
    data[controller + 2] = 168
    path = tmp_path / "corrupt.mid"
    path.write_bytes(bytes(data))
    with pytest.raises(ParameterError, match=names_path(path) + " cannot be read: it is not a valid MIDI file"):
        midi.read_midi(path)


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
            notes = list(midi.read_midi(path).notes())
        except ParameterError as error:
            assert str(path) in str(error)
            outcomes.add("error")
        else:
            assert all(isinstance(note, midi.Note) for note in notes)
            outcomes.add("notes")
    assert outcomes == {"error", "notes"}


BAD_WRITES = [
    pytest.param({"times": [0.0, math.nan]}, r"tracks\[0\]\.times\[1\] must be a finite number in \[0, inf\) s, got nan",
                 id="nan-time"),
    pytest.param({"times": [-0.1, 0.0]}, r"tracks\[0\]\.times\[0\] must be .* got -0.1", id="negative-time"),
    pytest.param({"times": [0.0, math.inf]}, r"times\[1\] .* got inf", id="inf-time"),
    pytest.param({"times": [0.2, 0.1]}, r"non-decreasing: times\[1\] = 0.1 s comes before times\[0\] = 0.2",
                 id="decreasing"),
    pytest.param({"times": [0.0, 1e9]}, r"tracks\[0\]\.times\[1\] must be at most .* s \(the longest time a MIDI file "
                                        r"holds on this tempo map\), got 1000000000.0", id="too-late"),
    pytest.param({"times": [[0.0, 1.0]]}, r"times must be a 1-D array of numbers, got shape \(1, 2\)", id="2-d"),
    pytest.param({"times": ["a", "b"]}, r"times must be a 1-D array of numbers, got \['a', 'b'\]", id="text"),
    pytest.param({"levels_db": [0.0, math.inf]}, r"levels_db\[1\] must be a number in \[-inf, inf\) dB, got inf",
                 id="inf-level"),
    pytest.param({"levels_db": [math.nan, 0.0]}, r"levels_db\[0\] .* got nan", id="nan-level"),
    pytest.param({"levels_db": [0.0]}, r"times and tracks\[0\]\.levels_db must have the same length, got 2 and 1",
                 id="lengths"),
    pytest.param({"notes": 128}, r"tracks\[0\]\.notes must be one MIDI key or one per time.* got 128", id="note-128"),
    pytest.param({"notes": [38, -1]}, r"tracks\[0\]\.notes must be .* got \[38, -1\]", id="note-negative"),
    pytest.param({"notes": [38.0, 40.0]}, r"tracks\[0\]\.notes must be .* got \[38.0, 40.0\]", id="note-float"),
    pytest.param({"notes": [38, 38, 38]}, r"tracks\[0\]\.notes must be one MIDI key or one per time", id="note-count"),
    pytest.param({"name": 7}, r"tracks\[0\]\.name must be a str, got 7", id="name"),
    pytest.param({"channel": 0}, r"channel must be an integer in \[1, 16\], got 0", id="channel-0"),
    pytest.param({"channel": 17}, r"channel must be an integer in \[1, 16\], got 17", id="channel-17"),
    pytest.param({"channel": 10.0}, r"channel must be an integer in \[1, 16\], got 10.0", id="channel-float"),
    pytest.param({"title": 7}, r"title must be a str, got 7", id="title"),
    pytest.param({"tempo_map": 120}, r"tempo_map must be a TempoMap, got 120", id="tempo-map"),
    pytest.param({"tracks": []}, r"tracks must be a non-empty list of Track, got \[\]", id="no-tracks"),
    pytest.param({"tracks": [("s", [0.0], [0.0], 38)]}, r"tracks\[0\] must be a Track\(name, times, levels_db, notes\)",
                 id="tuple-track"),
]


@pytest.mark.parametrize(("change", "message"), BAD_WRITES)
def test_bad_input_to_write_midi_is_refused_and_writes_nothing(tmp_path, change, message):
    fields = {"name": "s", "times": [0.0, 0.5], "levels_db": [0.0, -6.0], "notes": 38}
    options = {key: change.pop(key) for key in ("channel", "title", "tempo_map", "tracks") if key in change}
    tracks = options.pop("tracks", [Track(**(fields | change))])
    with pytest.raises(ParameterError, match=message):
        midi.write_midi(tmp_path / "bad.mid", tracks, **options)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("field", ["time", "note", "velocity", "channel", "track"])
def test_a_note_checks_its_fields(field):
    bad = {"time": -1.0, "note": 128, "velocity": 0, "channel": 17, "track": -1}
    fields = {"time": 0.0, "note": 38, "velocity": 1, "channel": 10, "track": 0} | {field: bad[field]}
    with pytest.raises(ParameterError, match=f"{field} must be .*, got {bad[field]}"):
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
        midi.write_midi(path, [Track("s", [0.0, 1.0], [0.0, 0.0], 38)], title="new")
    assert path.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == [path.name]
