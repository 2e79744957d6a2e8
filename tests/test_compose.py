"""Composition: a score becomes one continuous trajectory per stick, its first impacts on the notes.

Oracles are the note times written here (beats at a tempo, MIDI ticks through a tempo change, both worked
out by hand), the library strokes' own paths (apexes found here with brentq), the documented velocity map
written out by hand (127 is 4 m/s, 48 dB down to velocity 1, linear in dB), and invariants: θ between the
head and upright, returns within the speed and acceleration limits, one time grid for every stick.
"""

import collections
import json
import math
import re
from pathlib import Path

import mido
import numpy as np
import pretty_midi
import pytest
from scipy.optimize import brentq

from _cli import assert_one_line_error, run
from _midi import read_with_mido
from drumstroke.compose import compose
from drumstroke.design import Setup
from drumstroke.dynamics import FLOOR_DB, level_to_velocity, velocity_to_level
from drumstroke.errors import ParameterError
from drumstroke.formats.midi import GM_PERCUSSION, TempoMap
from drumstroke.palette.library import Entry, build_library, load_library, make_stroke, palette_library, read_palette
from drumstroke.palette.motion import RETURN_LIMITS, Limits
from drumstroke.recipe import Recipe
from drumstroke.render.outputs import write_composition_outputs
from drumstroke.score import Score, ScoreNote, parse_pattern, read_score

STROKES = ("single", "tap", "double", "triple", "press-roll")  # in the shipped palette's order
TIP = 0.27  # pivot to tip (m) of the paper's stick, which every shipped stroke uses
UPRIGHT = math.pi / 2

PATTERN = """\
# two sticks, every kind of stroke in the small library
tempo 120

0     single      100
0.5   tap         30    left
1     double      80          # a diddle on the right
2     triple      64    left
3     press-roll  127
4     single      45    left
4.5   tap         90
6     single      110
"""
# beat · 60 / 120 bpm, by hand: (time s, stick)
PATTERN_NOTES = [(0.0, "right"), (0.25, "left"), (0.5, "right"), (1.0, "left"), (1.5, "right"), (2.0, "left"),
                 (2.25, "right"), (3.0, "right")]

# A type 1 MIDI score: 480 ticks a beat, 120 bpm (0.5 s a beat) until tick 960, then 60 bpm (1 s a beat).
# (tick, note, velocity) on channel 10: 38 and 40 → single, 37 → tap (the drum map); 42 (a hi-hat) is not in it.
MIDI_EVENTS = [(0, 38, 100), (240, 42, 70), (480, 37, 40), (960, 40, 90), (1920, 38, 120), (2400, 37, 64)]
# seconds by hand: tick·0.5/480 up to tick 960 (1.0 s), then 1.0 + (tick − 960)·1.0/480
MIDI_NOTES = [(0.0, "right"), (0.5, "right"), (1.0, "right"), (3.0, "right"), (4.0, "right")]
LIBRARY_MAPPING = {38: ("single", "right"), 40: ("single", "right"), 37: ("tap", "right")}



@pytest.fixture(scope="module")
def library(tmp_path_factory):
    return build_library(tmp_path_factory.mktemp("lib"), palette=[e for e in read_palette() if e.name in STROKES])


@pytest.fixture(scope="module")
def loaded(library):
    """The same library read back from its files (Hermite curves through the samples), as the CLI uses it."""
    return load_library(library.path)


def write_score_midi(path):
    tempo = mido.MidiTrack([mido.MetaMessage("set_tempo", tempo=500_000, time=0),
                            mido.MetaMessage("set_tempo", tempo=1_000_000, time=960),
                            mido.MetaMessage("end_of_track", time=0)])
    messages = []
    for i, (tick, note, velocity) in enumerate(MIDI_EVENTS):
        messages.append((tick, 1, mido.Message("note_on", channel=9, note=note, velocity=velocity)))
        # alternate the two ways of ending a note: note_off, and note_on with velocity 0
        end = mido.Message("note_off", channel=9, note=note, velocity=64) if i % 2 else \
            mido.Message("note_on", channel=9, note=note, velocity=0)
        messages.append((tick + 60, 0, end))
    notes, now = mido.MidiTrack(), 0
    for tick, _, message in sorted(messages, key=lambda m: (m[0], m[1])):
        notes.append(message.copy(time=tick - now))
        now = tick
    notes.append(mido.MetaMessage("end_of_track", time=0))
    mido.MidiFile(type=1, ticks_per_beat=480, tracks=[tempo, notes]).save(path)


def score(kind, library, tmp_path):
    """(notes, [(time s, stick)] written by hand) for a text pattern or a MIDI file."""
    if kind == "pattern":
        return parse_pattern(PATTERN), PATTERN_NOTES
    path = tmp_path / "score.mid"
    write_score_midi(path)
    score = read_score(path, mapping=LIBRARY_MAPPING)  # the library's strokes (the drum map's are the planner's)
    assert score.report.counts == {("played", 10): 5, ("unmapped", 10): 1}
    assert [n.stroke for n in score.notes] == ["single", "tap", "single", "single", "tap"]
    assert score.tempo_map.tempi == ((0.0, 500_000), (2.0, 1_000_000))
    return score, MIDI_NOTES


def head_of(library):
    return library["single"].trajectory.theta_max


# --- first impacts on the notes ------------------------------------------------------------------------------------

@pytest.mark.parametrize("which", ["built", "loaded", "shipped"])
@pytest.mark.parametrize("kind", ["pattern", "midi"])
def test_every_note_first_impact_lands_on_offset_plus_its_time(library, loaded, tmp_path, kind, which):
    lib = {"built": library, "loaded": loaded, "shipped": palette_library()}[which]
    notes, expected = score(kind, lib, tmp_path)
    piece = compose(notes, lib)
    head = head_of(lib)
    assert piece.problems == ()
    assert all(p.played for p in piece.placements)
    assert [p.note.stick for p in piece.placements] == [stick for _, stick in expected]
    assert [p.note.time for p in piece.placements] == pytest.approx([time for time, _ in expected], abs=1e-12)
    assert piece.offset * piece.rate == pytest.approx(round(piece.offset * piece.rate), abs=1e-9)  # on the grid
    t, columns = piece.sample()
    errors = []
    for (time, stick), placement in zip(expected, piece.placements):
        target = piece.offset + time
        impacts = piece.sticks[stick].impacts.t
        nearest = impacts[np.argmin(np.abs(impacts - target))]
        errors.append(abs(nearest - target))
        assert abs(nearest - target) <= 1.0 / piece.rate
        # it is the stroke's first impact: none of this stick's impacts between the stroke's start and the note
        assert not np.any((impacts >= placement.start) & (impacts < target - 1e-9)), (time, stick)
        # the stick is on the head there
        assert piece.sticks[stick].state(np.array([target]))[0][0] == pytest.approx(head, abs=1e-9)
        theta, omega = columns[stick]
        k = round(target * piece.rate)
        assert t[k] == pytest.approx(target, abs=0.5 / piece.rate)
        assert 0.0 <= theta[k] - head <= np.abs(omega).max() / piece.rate
    assert max(errors) <= 1e-9, max(errors)


# --- continuity, bounds, one time grid -----------------------------------------------------------------------------

@pytest.mark.parametrize("rate", [1000.0, 10000.0])
def test_theta_is_continuous_between_head_and_upright_on_one_grid(library, rate):
    """|Δθ| ≤ max|ω|·dt: max|ω| from 100 kHz samples and the impact speeds, +1 % for peaks between samples."""
    piece = compose(parse_pattern(PATTERN), library)
    head = head_of(library)
    assert len({s.t_end for s in piece.sticks.values()}) == 1
    t, columns = piece.sample(rate)
    assert t == pytest.approx(np.arange(len(t)) / rate, abs=1e-12)
    assert piece.t_end - 1.0 / rate < t[-1] <= piece.t_end
    _, fine = piece.sample(100_000.0)
    assert set(columns) == {"left", "right"}
    for stick, (theta, omega) in columns.items():
        assert theta.shape == omega.shape == t.shape
        assert np.all(np.isfinite(theta)) and np.all(np.isfinite(omega))
        top_speed = max(np.abs(fine[stick][1]).max(), np.abs(piece.sticks[stick].impacts.omega).max())
        steps = np.abs(np.diff(theta))
        assert steps.max() <= top_speed / rate * 1.01, (stick, steps.max(), top_speed / rate)
        assert theta.min() >= head - 1e-12
        assert theta.max() <= UPRIGHT
        assert fine[stick][0].min() >= head - 1e-12 and fine[stick][0].max() <= UPRIGHT


def test_theta_and_omega_are_continuous_where_strokes_start_and_end(library):
    piece = compose(parse_pattern(PATTERN), library)
    eps = 1e-9
    for p in piece.placements:
        stick = piece.sticks[p.note.stick]
        length = p.cut if p.cut is not None else library[p.note.stroke].trajectory.t_end
        for junction in (p.start, p.start + length):
            if junction >= stick.t_end - eps:
                continue
            (theta0, theta1), (omega0, omega1) = stick.state(np.array([junction - eps, junction + eps]))
            assert theta1 == pytest.approx(theta0, abs=1e-6), (p.note, junction)
            assert omega1 == pytest.approx(omega0, abs=1e-3), (p.note, junction)


# --- returns within the limits -------------------------------------------------------------------------------------

def returns(piece, library):
    """Per stick, the intervals (s) where the stick is between strokes: lead-in, returns, the way home."""
    out = {}
    for stick in piece.sticks:
        played = sorted((p for p in piece.placements if p.played and p.note.stick == stick), key=lambda p: p.start)
        ends = [p.start + (p.cut if p.cut is not None else library[p.note.stroke].trajectory.t_end) for p in played]
        starts = [p.start for p in played]
        out[stick] = list(zip([0.0, *ends], [*starts, piece.t_end]))
    return out


def return_extremes(piece, library, rate=10_000.0):
    """Largest |ω| and central-difference |α| seen on the returns, sampled at ``rate``; and the lowest θ."""
    t, columns = piece.sample(rate)
    dt = 1.0 / rate
    speed = accel = 0.0
    low = math.inf
    for stick, intervals in returns(piece, library).items():
        theta, omega = columns[stick]
        for a, b in intervals:
            k = np.flatnonzero((t >= a + dt) & (t <= b - dt))  # k − 1 and k + 1 inside too
            if len(k) == 0:
                continue
            speed = max(speed, np.abs(omega[k]).max())
            accel = max(accel, (np.abs(omega[k + 1] - omega[k - 1]) / (2 * dt)).max())
            low = min(low, theta[k].min())
    return speed, accel, low


@pytest.mark.parametrize("limits", [None, Limits(max_speed=5.0, max_acceleration=300.0)])
def test_returns_between_strokes_stay_within_the_limits(library, limits):
    """Speed within 1e-9 relative; acceleration by central differences at 10 kHz within 0.1 %
    (the quintics' jerk makes the difference err by ~1e-5 of the limit)."""
    piece = compose(parse_pattern(PATTERN), library, setup=Setup(moves=limits or RETURN_LIMITS))
    bounds = limits or RETURN_LIMITS
    assert all(p.played for p in piece.placements)
    speed, accel, low = return_extremes(piece, library)
    print(f"limits {bounds}: max return speed {speed:.4f} rad/s, max return acceleration {accel:.2f} rad/s^2")
    assert speed <= bounds.max_speed * (1 + 1e-9)
    assert accel <= bounds.max_acceleration * (1 + 1e-3)
    assert low >= head_of(library) - 1e-12
    assert speed > 0.0 and accel > 0.0  # there were returns to look at


def test_the_default_limits_are_binding_for_the_tight_ones(library):
    """The check above means something: with the default limits the returns go past 5 rad/s or 300 rad/s²."""
    speed, accel, _ = return_extremes(compose(parse_pattern(PATTERN), library), library)
    assert speed > 5.0 or accel > 300.0


# --- velocity ------------------------------------------------------------------------------------------------------

def hand_tip_speed(velocity):
    """The documented map written out: velocity 127 is 4 m/s, velocity 1 is 48 dB lower, linear in dB."""
    return 4.0 * 10.0 ** (-48.0 * (127 - velocity) / 126.0 / 20.0)


def test_velocity_sets_the_first_impact_level_monotonically(library):
    velocities = [1, 20, 64, 100, 127]
    notes = [ScoreNote(2.0 * i, "single", v, source=f"note {i}") for i, v in enumerate(velocities)]
    piece = compose(notes, library)
    assert piece.problems == ()
    impacts = piece.sticks["right"].impacts
    speeds, starts = [], []
    for note, placement in zip(notes, piece.placements):
        k = np.flatnonzero(np.abs(impacts.t - (piece.offset + note.time)) < 1e-9)
        assert len(k) == 1
        speed = abs(impacts.omega[k[0]]) * TIP
        assert speed == pytest.approx(hand_tip_speed(note.velocity), rel=1e-9)
        assert level_to_velocity(20 * math.log10(speed)) == note.velocity
        assert level_to_velocity(impacts.level_db[k[0]]) == note.velocity
        speeds.append(speed)
        starts.append(piece.sticks["right"].state(np.array([placement.start]))[0][0])
    assert np.all(np.diff(speeds) > 0)
    assert np.all(np.diff(starts) > 0)  # a louder note starts from higher up


def drop_library(folder, omega0):
    """A one-stroke library: the stick dropped from 1.3 rad (near upright), caught after its first bounce."""
    recipe = Recipe.from_dict({"theta0": 1.3, "omega0": omega0, "t_end": 2.0,
                               "force": {"kind": "constant", "value": 0.0}}, name="drop")
    return build_library(folder, palette=[Entry("drop", "test", "a drop from near upright", recipe,
                                                ({"catch": 1},))])


def test_a_velocity_out_of_reach_is_played_as_loud_as_it_can_go_and_reported(tmp_path):
    lib = drop_library(tmp_path, 0.0)
    drop = lib["drop"].trajectory
    head = drop.theta_max
    top = (UPRIGHT - head) / (1.3 - head)  # the drop's highest point is its start
    loudest = abs(drop.impacts.omega[0]) * TIP * top
    assert loudest < hand_tip_speed(127)  # so 127 is out of reach
    piece = compose([ScoreNote(0.0, "drop", 127, source="line 7"), ScoreNote(3.0, "drop", 30)], lib)
    assert all(p.played for p in piece.placements)
    (problem,) = piece.problems
    reached = level_to_velocity(20 * math.log10(loudest))
    assert problem.startswith("line 7: velocity 127") and "past upright" in problem
    assert f"played at velocity {reached}," in problem
    impacts = piece.sticks["right"].impacts
    assert abs(impacts.omega[0]) * TIP == pytest.approx(loudest, rel=1e-9)
    assert abs(impacts.omega[1]) * TIP == pytest.approx(hand_tip_speed(30), rel=1e-9)
    _, columns = piece.sample(10_000.0)
    assert columns["right"][0].max() <= UPRIGHT
    assert columns["right"][0].max() == pytest.approx(UPRIGHT, abs=1e-9)


def test_a_loud_note_on_a_stroke_falling_from_near_upright_is_reported_not_a_crash(tmp_path):
    """The same drop thrown down at 1 rad/s: played as loud as it can go and reported (compose's docstring).

    Exposes a bug: the velocity is clamped to compress_limit, which puts the stroke's start at exactly
    upright moving down; no lead-in can wind up into that, return_time is inf and compose._offset does
    math.ceil(inf) → OverflowError (not even a ParameterError)."""
    lib = drop_library(tmp_path, -1.0)
    piece = compose([ScoreNote(0.0, "drop", 127, source="line 3")], lib)
    assert any(p.startswith("line 3:") for p in piece.problems)
    _, columns = piece.sample(10_000.0)
    assert columns["right"][0].max() <= UPRIGHT


# --- cuts ------------------------------------------------------------------------------------------------------------

def apex_between(trajectory, k):
    """The time (s) where ω turns from up to down between impacts k and k + 1 (0-based), by brentq on ω."""
    a, b = trajectory.impacts.t[k], trajectory.impacts.t[k + 1]
    grid = np.linspace(a, b, 2001)[1:-1]
    omega = trajectory.path(grid)[1]
    i = np.flatnonzero((omega[:-1] >= 0) & (omega[1:] < 0))[0]
    return brentq(lambda s: float(trajectory.path(np.array([s]))[1][0]), grid[i], grid[i + 1], xtol=1e-14)


@pytest.mark.parametrize("stroke, gap, kept", [("double", 0.45, 1), ("triple", 0.75, 2)])
def test_a_stroke_too_long_for_the_next_note_is_cut_at_its_latest_possible_apex(library, stroke, gap, kept):
    """double: impacts at +0 and +0.309 s, 0.442 s long after its note; a single starts 0.095 s before its own.
    triple: impacts at +0, +0.309, +0.576 s, 0.690 s long. Cut after ``kept`` impacts at the apex there, and the
    hits lost with the cut are a problem."""
    source = library[stroke].trajectory
    piece = compose([ScoreNote(0.0, stroke, 100), ScoreNote(gap, "single", 100)], library)
    assert all(p.played for p in piece.placements)
    (problem,) = piece.problems
    hits = {"double": 2, "triple": 3}[stroke]
    assert f"{stroke!r} on the right stick is cut" in problem and f"{hits - kept} of its {hits} hits not played" in problem
    first = piece.placements[0]
    apex = apex_between(source, kept - 1)
    assert first.cut is not None
    assert first.cut == pytest.approx(apex, abs=1e-9)
    stick = piece.sticks["right"]
    assert stick.state(np.array([first.start + first.cut]))[1][0] == pytest.approx(0.0, abs=1e-6)
    expected = [piece.offset + t - source.impacts.t[0] for t in source.impacts.t[:kept]] + [piece.offset + gap]
    assert stick.impacts.t == pytest.approx(expected, abs=1e-9)
    # between the last kept impact and the single's, the stick stays off the head
    t, columns = piece.sample(10_000.0)
    between = (t > expected[-2] + 1e-3) & (t < expected[-1] - 1e-3)
    assert columns["right"][0][between].min() > source.theta_max + 1e-6


def test_a_stroke_played_to_its_end_reports_no_cut(library):
    """Placement.cut is 'None if played to its end'. The double (0.548 s, caught at its second apex, so
    still moving at its end) has 1.3 s of room before the single: it is played whole, both impacts.

    Exposes a bug: _place stores the first candidate of _latest_cut — _settle(stroke), which is t_end for a
    stroke still moving at its end — so cut == t_end instead of None for every stroke but the last."""
    source = library["double"].trajectory
    piece = compose([ScoreNote(0.0, "double", 100), ScoreNote(1.5, "single", 100)], library)
    impacts = piece.sticks["right"].impacts.t
    assert len(impacts) == 3  # both of the double's and the single's: nothing was cut
    assert impacts[1] - impacts[0] == pytest.approx(source.impacts.t[1] - source.impacts.t[0], abs=1e-9)
    assert piece.placements[0].cut is None


# --- notes that cannot be played -----------------------------------------------------------------------------------

def test_a_note_too_soon_on_the_same_stick_is_reported_and_left_out(library):
    piece = compose(parse_pattern("tempo 60\n0 single 100\n0.02 single 90\n"), library)
    assert [p.played for p in piece.placements] == [True, False]
    assert math.isnan(piece.placements[1].impact)
    (problem,) = piece.problems
    assert problem.startswith("pattern line 3:") and "too soon" in problem and "left out" in problem
    assert piece.sticks["right"].impacts.t == pytest.approx([piece.offset], abs=1e-12)


def test_the_same_two_notes_on_two_sticks_both_play(library):
    piece = compose(parse_pattern("tempo 60\n0 single 100\n0.02 single 90 left\n"), library)
    assert piece.problems == ()
    assert [p.played for p in piece.placements] == [True, True]
    assert piece.sticks["right"].impacts.t == pytest.approx([piece.offset], abs=1e-9)
    assert piece.sticks["left"].impacts.t == pytest.approx([piece.offset + 0.02], abs=1e-9)


@pytest.mark.parametrize("strict, status", [(True, 3), (False, 0)])
def test_compose_command_warns_and_strict_fails_on_a_note_left_out(library, tmp_path, strict, status):
    pattern = tmp_path / "close.pattern"
    pattern.write_text("tempo 60\n0 single 100\n0.02 single 90\n")
    result = run("compose", pattern, "--library", library.path, *(["--strict"] if strict else []))
    assert result.returncode == status, result
    assert "Traceback" not in result.stderr
    warnings = [line for line in result.stderr.splitlines() if line.startswith("warning:")]
    assert len(warnings) == 1 and "line 3" in warnings[0] and "too soon" in warnings[0]
    assert ("--strict" in result.stderr) == strict
    assert "composed 1 of 2 notes" in result.stdout


@pytest.mark.parametrize("text, problems, count", [
    ("tempo 100\n0 double 90\n1 single 124\n", 1, "1 problem"),  # the double cut short, nothing left out
    ("tempo 100\n0 double 90\n1 single 124\n1.02 single 90\n", 2, "1 note left out, 1 other problem"),
])
def test_compose_command_counts_its_problems_in_one_line(library, tmp_path, text, problems, count):
    """The one warning line without --verbose: "other" only after notes left out, "the first" only of several."""
    pattern = write(tmp_path / "cut.pattern", text)
    found = compose(read_score(pattern), library).problems
    assert len(found) == problems and "cut 0.260 s into it" in found[-1]
    result = run("compose", pattern, "--library", library.path)
    assert result.returncode == 0, result
    first = f": {found[0]}" if problems == 1 else f"; the first: {found[0]}; --verbose lists them all"
    assert result.stderr == f"warning: {count} (velocities out of reach, strokes cut short){first}\n"


def test_compose_command_counts_each_sticks_impacts_in_words(library, tmp_path):
    pattern = write(tmp_path / "one.pattern", "tempo 60\n0 single 100\n")
    sticks = compose(read_score(pattern), library).sticks
    assert {name: len(stick.impacts) for name, stick in sticks.items()} == {"right": 1}  # a single hits once
    result = run("compose", pattern, "--library", library.path)
    assert result.returncode == 0 and result.stdout.splitlines()[1].endswith("sticks: right (1 impact)")


def test_the_shipped_palettes_strokes_are_simulate_s_made_only_when_asked_for(monkeypatch):
    """Without a library, compose plays the shipped palette's strokes as ``drumstroke simulate NAME`` makes them."""
    made = []
    make = Entry.make
    monkeypatch.setattr(Entry, "make", lambda entry, **k: made.append(entry.name) or make(entry, **k))
    shipped = palette_library()
    assert list(shipped) == [entry.name for entry in read_palette()] and made == []
    double = shipped["double"].trajectory
    assert shipped["double"].trajectory is double and made == ["double"]  # simulated once
    assert shipped.get("flam") is None and "flam" not in shipped
    assert np.array_equal(double.impacts.t, make_stroke("double").impacts.t)
    assert shipped.rate == 1000.0 and double.t_end * 1000.0 == pytest.approx(round(double.t_end * 1000.0), abs=1e-6)


def test_compose_command_without_a_library_plays_the_shipped_palette_and_says_so(tmp_path):
    pattern = write(tmp_path / "two.pattern", "tempo 120\n0 single 100\n1 double 90 left\n2 auto 80\n")
    result = run("compose", pattern, "--json", tmp_path / "c.json", "--strict")
    assert result.returncode == 0, result
    assert "strokes from the shipped palette: no --library" in result.stdout.splitlines()[1]
    data = json.loads((tmp_path / "c.json").read_text())
    assert [note["played"] for note in data["notes"]] == [True, True, True]
    built = build_library(tmp_path / "lib", palette=[e for e in read_palette() if e.name in ("single", "double")])
    result = run("compose", pattern, "--library", built.path)
    assert result.returncode == 0 and f"strokes from library {built.path}" in result.stdout
    planned = write(tmp_path / "auto.pattern", "tempo 120\n0 auto 100\n")  # no library stroke: no library named
    assert "strokes from" not in run("compose", planned).stdout
    wrong = write(tmp_path / "wrong.pattern", "tempo 120\n0 singel 100\n")
    assert_one_line_error(run("compose", wrong), "wrong.pattern line 2: stroke 'singel' is not auto, buzz or a "
                                                 "library stroke; the library has single, tap, double")


def test_a_midi_scores_library_keys_play_the_shipped_palette_without_a_library(tmp_path):
    """Off channel 10, key 60 + i is the i-th stroke: of the shipped palette when no library is given."""
    names = [entry.name for entry in read_palette()]
    track = mido.MidiTrack([mido.Message("note_on", channel=0, note=60 + names.index("double"), velocity=90, time=0),
                            mido.Message("note_off", channel=0, note=60 + names.index("double"), time=240)])
    mido.MidiFile(type=0, ticks_per_beat=480, tracks=[track]).save(tmp_path / "one.mid")
    result = run("compose", tmp_path / "one.mid", "--channel", "1", "--json", tmp_path / "one.json")
    assert result.returncode == 0, result
    (note,) = json.loads((tmp_path / "one.json").read_text())["notes"]
    assert note["stroke"] == "double" and note["played"]


def test_a_stroke_not_in_the_library_is_named_with_its_line(library):
    """Exposes a bug: Library.__getitem__ raises ParameterError, not KeyError, so Mapping.__contains__ in
    ``note.stroke not in library`` raises the library's message (no line) instead of answering False."""
    notes = parse_pattern("tempo 100\n0 single 100\n\n1 flam 80\n")
    with pytest.raises(ParameterError, match=r"pattern line 4: stroke 'flam' is not auto, buzz or a library stroke; "
                                             r"the library has single, tap, double, triple, press-roll"):
        compose(notes, library)


def test_a_buzz_too_quiet_to_be_one_stroke_is_refused_with_its_line(library, tmp_path):
    """Found by the studio's fuzz test: a buzz at velocity 1 is designed as many one-bounce strokes with no note of
    their own, and compose raised IndexError on them (the command a traceback). It is refused by its line."""
    notes = parse_pattern("tempo 1\n0 buzz 1 right\n")
    with pytest.raises(ParameterError, match=r"pattern line 2: a buzz at velocity 1 is played as \d+ strokes"):
        compose(notes, library)
    (tmp_path / "quiet.pattern").write_text("tempo 1\n0 buzz 1 right\n")
    assert_one_line_error(run("compose", tmp_path / "quiet.pattern"), "quiet.pattern line 2: a buzz at velocity 1")
    (placed,) = compose(parse_pattern("tempo 1\n0 buzz 60 right\n"), library).placements  # louder: one stroke
    assert placed.played


def test_no_notes_is_refused(library):
    with pytest.raises(ParameterError, match="notes must hold at least one note"):
        compose([], library)


def test_something_else_than_score_notes_is_a_parameter_error(library):
    """Exposes a bug: compose sorts by ``n.time`` before its ScoreNote check, so a tuple is an AttributeError."""
    with pytest.raises(ParameterError, match=r"notes must be ScoreNote objects, got \(0.0, 'single', 100\)"):
        compose([(0.0, "single", 100)], library)


# --- the score's time: tempo map, progress, MIDI out ----------------------------------------------------------------

DATA = Path(__file__).resolve().parent / "data" / "midi"
SONG = DATA / "d6caebd1964d9e4a3c5ea59525230e2a.mid"  # type 0: drums on channel 10 among 8 channels, 65 tempi


def test_a_score_brings_its_tempo_map_and_bare_notes_get_midis_default(library, tmp_path):
    pattern = tmp_path / "waltz.pattern"
    pattern.write_text("tempo 90\nmeter 3/4\n0 single 100\n1 double 80\n")
    score = read_score(pattern)
    assert isinstance(score, Score)
    assert compose(score, library).tempo_map == TempoMap.constant(90, meter=(3, 4))
    assert compose(list(score.notes), library).tempo_map == TempoMap() == TempoMap.constant(120)


def test_progress_rises_to_one_as_notes_are_placed_and_sticks_assembled(library):
    seen = []
    compose(parse_pattern(PATTERN), library, progress=seen.append)
    assert len(seen) == 8 + 2 and seen == sorted(seen) and seen[-1] == 1.0 and seen[0] > 0.0  # notes, then sticks


def test_stick_impacts_are_on_the_score_time_and_mark_each_strokes_first_impact(library):
    piece = compose(parse_pattern(PATTERN), library)
    by_stick = piece.stick_impacts()
    assert sorted(by_stick) == ["left", "right"]
    for stick, (t, level, first) in by_stick.items():
        trajectory = piece.sticks[stick]
        assert t == pytest.approx(trajectory.impacts.t - piece.offset, abs=1e-12)
        assert np.array_equal(level, trajectory.impacts.level_db)
        notes = [time for time, note_stick in PATTERN_NOTES if note_stick == stick]
        assert t[first] == pytest.approx(notes, abs=1e-9)
        strokes = [p.note.stroke for p in piece.placements if p.note.stick == stick]
        bounces = sum(len(library[s].trajectory.impacts) - 1 for s in strokes)
        assert (~first).sum() <= bounces and first.sum() == len(notes)  # cut strokes lose bounces, never notes


def composed_midi(piece, path):
    """Write the composition's --midi and read it with mido: (file, track names, tempo map, meters, notes)."""
    assert write_composition_outputs(piece, title="piece", midi=path) == [path]
    return read_with_mido(path)


def assert_every_impact_reads_back(piece, path, notes, names):
    """Every audible impact of every stick is a note of its stick's track within 1 ms (mido, walked by hand, and
    pretty_midi), at its level's velocity, on 38 when it is a stroke's first impact and 40 otherwise."""
    theirs = {i.name: i for i in pretty_midi.PrettyMIDI(str(path)).instruments}
    assert names == ["piece (model paper)", *piece.sticks] and sorted(theirs) == sorted(piece.sticks)
    worst = 0.0
    for number, (stick, (t, level, first)) in enumerate(piece.stick_impacts().items(), start=1):
        keep = level >= FLOOR_DB
        ours = [n for n in notes if n["track"] == number]
        assert len(ours) == keep.sum() == len(theirs[stick].notes) > 0
        assert [n["note"] for n in ours] == np.where(first[keep], 38, 40).tolist()
        assert [n["velocity"] for n in ours] == level_to_velocity(level[keep]).tolist()
        assert {n["channel"] for n in ours} == {9} and theirs[stick].is_drum
        assert [n.pitch for n in theirs[stick].notes] == [n["note"] for n in ours]
        for starts in ([n["time"] for n in ours], [n.start for n in theirs[stick].notes]):
            worst = max(worst, float(np.max(np.abs(np.array(starts) - t[keep]))))
    assert worst <= 1e-3
    return worst


def test_compose_midi_is_on_the_patterns_time_its_first_note_on_the_downbeat(library, tmp_path):
    piece = compose(read_score(write(tmp_path / "groove.pattern", "tempo 96\nmeter 3/4\n" + PATTERN.split("tempo 120\n")[1])),
                    library)
    assert piece.offset > 0  # the trajectory starts before the score's time 0; the MIDI file does not
    file, names, tempi, meters, notes = composed_midi(piece, tmp_path / "groove.mid")
    assert file.type == 1 and tempi == [(0, 625_000)] and meters == [(0, 3, 4)]
    assert notes[0]["tick"] == 0 and notes[0]["note"] == 38 and notes[0]["track"] == 1  # beat 0, the right stick
    beats = {n["tick"] / file.ticks_per_beat for n in notes if n["note"] == 38}
    assert beats == {0.0, 0.5, 1.0, 2.0, 3.0, 4.0, 4.5, 6.0}  # every note of the pattern on its beat, exactly
    assert_every_impact_reads_back(piece, tmp_path / "groove.mid", notes, names)


def test_compose_midi_keeps_a_midi_scores_tempo_change(library, tmp_path):
    write_score_midi(tmp_path / "score.mid")
    piece = compose(read_score(tmp_path / "score.mid", stroke_names=list(library)), library)
    file, names, tempi, _, notes = composed_midi(piece, tmp_path / "out.mid")
    assert file.ticks_per_beat % 480 == 0 and tempi == [(0, 500_000), (2 * file.ticks_per_beat, 1_000_000)]
    first = [n["tick"] * 480 // file.ticks_per_beat for n in notes if n["note"] == 38]
    assert first == [tick for tick, key, _ in MIDI_EVENTS if key != 42]  # the score's own ticks
    assert_every_impact_reads_back(piece, tmp_path / "out.mid", notes, names)


def write(path, text):
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def song(library):
    return compose(read_score(SONG, stroke_names=list(library)), library)


def test_a_real_songs_drum_part_is_composed_and_nothing_else(song):
    """Counted here with mido: the channel-10 note_ons of velocity >= 1 whose key is in the drum map, each played by
    the planner on a stick it chose, within 1 ms of its time and 1.5 dB of its velocity's level, or reported."""
    piece = song
    now, expected = 0.0, []
    for message in mido.MidiFile(SONG):  # mido's own clock: seconds per message
        now += message.time
        if message.type == "note_on" and message.velocity and message.channel == 9 and message.note in (37, 38, 40):
            expected.append((now, message.velocity))
    assert len(expected) == 137
    assert [(p.note.stroke, p.note.velocity) for p in piece.placements] == [("auto", v) for _, v in expected]
    assert [p.note.time for p in piece.placements] == pytest.approx([t for t, _ in expected], abs=1e-9)
    played = [p for p in piece.placements if p.played]
    assert len(piece.placements) - len(played) == len(piece.problems)  # each note left out is reported
    assert len(played) >= 130 and {p.note.stick for p in played} == {"right", "left"}
    for p in played:
        stick = piece.sticks[p.note.stick].impacts
        i = int(np.argmin(np.abs(stick.t - (piece.offset + p.note.time))))
        assert abs(stick.t[i] - (piece.offset + p.note.time)) < 1e-3
        assert abs(stick.level_db[i] - velocity_to_level(p.note.velocity)) < 1.5


def test_a_real_songs_composition_writes_its_65_tempo_changes_and_every_impact_within_a_millisecond(song, tmp_path):
    piece = song
    file, names, tempi, _, notes = composed_midi(piece, tmp_path / "song.mid")
    source = mido.MidiFile(SONG)
    factor = file.ticks_per_beat // source.ticks_per_beat
    assert file.ticks_per_beat == factor * source.ticks_per_beat
    source_tempi, tick = {0: 500_000}, 0
    for message in source.tracks[0]:
        tick += message.time
        if message.type == "set_tempo":
            source_tempi[tick] = message.tempo
    assert tempi == [(tick * factor, tempo) for tick, tempo in sorted(source_tempi.items())] and len(tempi) == 65
    worst = assert_every_impact_reads_back(piece, tmp_path / "song.mid", notes, names)
    print(f"round trip of {len(notes)} impacts over 65 tempo changes: worst {worst * 1e3:.2e} ms")
    changes, _ = pretty_midi.PrettyMIDI(str(tmp_path / "song.mid")).get_tempo_changes()
    assert changes == pytest.approx(pretty_midi.PrettyMIDI(str(SONG)).get_tempo_changes()[0], abs=1e-9)


# --- the command on real files -------------------------------------------------------------------------------------

def test_compose_command_prints_one_summary_line_with_the_counts(library, tmp_path):
    result = run("compose", SONG, "--library", library.path, "--midi", tmp_path / "song.mid")
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    counts = {}
    for message in mido.MidiFile(SONG).tracks[0]:
        if message.type == "note_on" and message.velocity:
            kind = (10, message.note in (37, 38, 40)) if message.channel == 9 else (message.channel + 1, None)
            counts[kind] = counts.get(kind, 0) + 1
    played, unmapped = counts[10, True], counts[10, False]
    others = sorted((c, n) for (c, _), n in counts.items() if c != 10)
    skipped = collections.Counter(message.note for message in mido.MidiFile(SONG).tracks[0] if message.type == "note_on"
                                  and message.velocity and message.channel == 9 and message.note not in (37, 38, 40))
    keys = ", ".join(f"{key} {GM_PERCUSSION[key]} ×{n}" for key, n in sorted(skipped.items(), key=lambda kn: (-kn[1], kn[0])))
    assert lines[0] == (f"{SONG}: {sum(counts.values())} notes on 9 channels, 1 track; {played} to play (channel 10: "
                        f"{played}); skipped {sum(counts.values()) - played}: {sum(n for _, n in others)} on channels "
                        f"not chosen (--channel) (" + ", ".join(f"channel {c}: {n}" for c, n in others) +
                        f"), {unmapped} not in the drum map (channel 10: {keys})")
    assert lines[1].startswith(f"composed {played} of {played} notes")  # the planner plays every one, on two sticks
    assert lines[2:] == [f"wrote {tmp_path / 'song.mid'}"]
    assert result.stderr == ""


def test_compose_command_quiet_prints_nothing_and_verbose_lists_every_note(library, tmp_path):
    quiet = run("compose", SONG, "--library", library.path, "--quiet", "--json", tmp_path / "q.json")
    assert quiet.returncode == 0 and quiet.stdout == "" and quiet.stderr == ""
    assert (tmp_path / "q.json").is_file()
    verbose = run("compose", SONG, "--library", library.path, "--verbose")
    assert verbose.returncode == 0
    skipped = [line for line in verbose.stdout.splitlines() if " skipped: " in line]
    assert len(skipped) == 2852 - 137
    assert [line for line in verbose.stderr.splitlines() if line.startswith("warning:")] == []


def test_compose_command_plays_a_chosen_track_and_channel(library, tmp_path):
    melody = DATA / "1390.mid"
    none = run("compose", melody, "--library", library.path)
    assert_one_line_error(none, f"{melody} has no notes to play", "--channel, --track or --mapping")
    mapping = write(tmp_path / "m.toml", "[notes]\n" + "\n".join(f'{k} = "tap"' for k in range(128)))
    result = run("compose", melody, "--library", library.path, "--channel", 2, "--track", "melody", "--mapping", mapping,
                 "--json", tmp_path / "m.json")
    assert result.returncode == 0, result.stderr
    assert "242 to play (channel 2: 242); skipped 705: 705 in tracks not chosen (--track) (channel 1: 705)" in \
           result.stdout.splitlines()[0]
    data = json.loads((tmp_path / "m.json").read_text())
    assert len(data["notes"]) == 242 and {n["stroke"] for n in data["notes"]} == {"tap"}
    bad = run("compose", melody, "--library", library.path, "--track", "drums")
    assert_one_line_error(bad, "--track 'drums' is not a track of MIDI file", "0 '', 1 'piano', 2 'melody'")
    bad = run("compose", melody, "--library", library.path, "--channel", 0)
    assert_one_line_error(bad, "--channel (a MIDI channel, counted from 1", "got 0")


def test_compose_help_describes_the_pattern_format_and_the_drum_map():
    result = run("compose", "--help")
    assert result.returncode == 0 and "README" not in result.stdout
    for needle in ("tempo BPM", "meter N/D", "BEAT STROKE VELOCITY [STICK [BEATS] [PIECE]]", "38  Acoustic Snare", "40  Electric Snare",
                   "37  Side Stick", "--channel N", "--track TRACK", "--quiet", "--verbose"):
        assert needle in result.stdout, needle


# --- a score on the kit --------------------------------------------------------------------------------------------

KIT_SONG = Path(__file__).parent / "data" / "midi" / "d6caebd1964d9e4a3c5ea59525230e2a.mid"


def test_a_pattern_names_its_pieces_and_old_patterns_play_the_snare():
    from drumstroke.compose import compose_kit

    score = parse_pattern("tempo 120\n0 auto 100 auto kick\n0 auto 90 right hihat\n1 single 110\n"
                          "1.5 auto 80 left-foot hihat\n2 buzz 80 auto 0.5 ride\n")
    assert [(n.piece, n.stick) for n in score][3:] == [("hihat", "left-foot"), ("ride", None)]
    piece = compose_kit(score)
    outcomes = piece.performance.outcomes
    assert [(o.piece, o.limb, o.note.state) for o in outcomes] == [
        ("kick", "right-foot", None), ("hihat", "right", "closed"), ("snare", "right", None),
        ("hihat", "left-foot", "pedal"), ("ride", "right", None)]
    assert [o.impact - piece.offset for o in outcomes] == pytest.approx([0.0, 0.0, 0.5, 0.75, 1.0], abs=1e-9)
    _, columns = piece.sample()
    assert list(columns)[:3] == ["right.yaw", "right.lift", "right.theta"]
    assert "right-foot.theta" in columns and "left-foot.theta.velocity" in columns
    with pytest.raises(ParameterError, match="piece 'cowbell' is not a piece of the kit"):
        compose_kit(parse_pattern("tempo 120\n0 auto 100 auto cowbell\n"))
    with pytest.raises(ParameterError, match="only a buzz takes a length"):
        parse_pattern("tempo 120\n0 auto 100 auto 0.5 ride\n")


def test_a_pattern_names_the_hi_hats_state_and_each_hit_carries_its_key():
    """``hihat:half`` and so on: the note is played in that state (its key the state's, on its hits); a hi-hat
    note naming none is closed, or the pedal for a foot; a state the piece does not have is refused by line."""
    from drumstroke.compose import compose_kit
    from drumstroke.formats.pattern import parse_pattern as pattern_rows
    from drumstroke.formats.pattern import pattern_text
    from drumstroke.kit.pieces import default_kit

    text = ("tempo 120\n0 auto 90 right hihat:half\n0.5 auto 90 right hihat:open\n1 auto 90 right hihat\n"
            "1.5 auto 70 auto hihat:pedal\n2 auto 90 right hihat:closed\n2.5 auto 70 left-foot hihat\n")
    score = parse_pattern(text)
    assert [n.state for n in score] == ["half", "open", None, "pedal", "closed", None]
    assert pattern_text(*pattern_rows(text)) == text  # written back as read
    piece = compose_kit(score)
    performance = piece.performance
    states = ["half", "open", "closed", "pedal", "closed", "pedal"]
    assert [(o.note.state, o.played) for o in performance.outcomes] == [(s, True) for s in states]
    hihat = default_kit().piece("hihat")
    assert [hihat.state(k) for k in performance.keys] == states
    for hit in performance.hits:  # a stick's bounces sound as the note they follow: in its state
        if hit.note >= 0:
            assert hihat.state(hit.key) == states[hit.note]
    with pytest.raises(ParameterError, match=r"pattern line 2: state 'open' is not one of pieces\.snare's states "
                                             r"\(none\)"):
        compose_kit(parse_pattern("tempo 120\n0 auto 100 auto snare:open\n"))
    with pytest.raises(ParameterError, match=r"pattern line 2: state 'loose' is not one of pieces\.hihat's states "
                                             r"\(closed, half, open, pedal\)"):
        compose_kit(parse_pattern("tempo 120\n0 auto 100 auto hihat:loose\n"))
    for bad in ("hihat:", "hihat:Open", ":open", "hihat:open:half"):
        with pytest.raises(ParameterError, match=r"pattern line 2: a note is .*a state after a colon"):
            parse_pattern(f"tempo 120\n0 auto 100 auto {bad}\n")


def test_a_song_on_the_kit_reads_every_key_the_kit_answers():
    from drumstroke.compose import compose_kit
    from drumstroke.kit.pieces import default_kit

    kit = default_kit()
    score = read_score(KIT_SONG, kit=kit)
    midi = mido.MidiFile(KIT_SONG)
    drums = [m.note for m in midi if m.type == "note_on" and m.velocity > 0 and m.channel == 9]
    answered = [k for k in drums if k in kit.keys]
    assert len(score.notes) == len(answered) and [n.key for n in score.notes] == answered
    assert "not on the kit (channel 10: 55 Splash Cymbal ×28)" in score.report.summary()
    piece = compose_kit(score, kit, rate=100, pieces=["kick", "snare"])
    assert set(piece.left_out) == {"ride", "tom2", "crash", "tom1", "floor-tom", "hihat"}
    assert len(piece.performance.outcomes) + sum(piece.left_out.values()) == len(answered)


def test_compose_kit_on_a_song_writes_a_column_per_joint_the_notes_and_the_pieces_keys(tmp_path):
    import pandas

    from drumstroke.kit.pieces import default_kit

    kit = default_kit()
    result = run("compose", KIT_SONG, "--kit", "--rate", "100", "--csv", tmp_path / "s.csv", "--json",
                 tmp_path / "n.json", "--midi", tmp_path / "s.mid")
    assert result.returncode == 0, result.stderr
    played, total = map(int, re.search(r"played (\d+) of (\d+) notes on the kit", result.stdout).groups())
    assert "28 not on the kit (channel 10: 55 Splash Cymbal ×28)" in result.stdout
    frame = pandas.read_csv(tmp_path / "s.csv")
    joints = ["right.yaw", "right.lift", "right.theta", "left.yaw", "left.lift", "left.theta", "right-foot.theta",
              "left-foot.theta"]
    assert list(frame.columns) == ["t", *joints, *(f"{j}.velocity" for j in joints)]
    assert np.diff(frame["t"]).max() == pytest.approx(0.01)
    document = json.loads((tmp_path / "n.json").read_text())
    drums = [m.note for m in mido.MidiFile(KIT_SONG) if m.type == "note_on" and m.velocity > 0 and m.channel == 9]
    assert len(document["notes"]) == total == sum(k in kit.keys for k in drums) == 590
    assert sum(n["played"] for n in document["notes"]) == played
    assert all(("impact" in n) == n["played"] == ("reason" not in n) for n in document["notes"])
    assert played / total >= 0.9  # 555 of 590 (94 %) on the shipped kit
    out = mido.MidiFile(tmp_path / "s.mid")
    written = [m for m in out if m.type == "note_on" and m.velocity > 0]
    assert len(written) == len(document["hits"]) and {m.channel for m in written} == {9}
    assert {m.note for m in written} == {h["key"] for h in document["hits"]} <= set(kit.keys)
    # the score's tempo map kept, a track per limb, every hit at its time on the score's clock (to half a tick)
    assert [m.tempo for m in out if m.type == "set_tempo"] == [
        m.tempo for m in mido.MidiFile(KIT_SONG) if m.type == "set_tempo"]
    assert {track.name for track in out.tracks[1:]} == {h["limb"] for h in document["hits"]}
    now, onsets = 0.0, []
    for message in out:  # mido turns ticks into seconds through the tempo map
        now += message.time
        if message.type == "note_on" and message.velocity > 0:
            onsets.append((round(now, 3), message.note))
    expected = sorted((round(h["t"], 3), h["key"]) for h in document["hits"])
    assert len(onsets) == len(expected)
    assert np.abs(np.array(sorted(onsets))[:, 0] - np.array(expected)[:, 0]).max() <= 2e-3


def test_compose_kit_renders_a_pattern_s_audio(tmp_path):
    pattern = tmp_path / "bar.pattern"
    pattern.write_text("tempo 120\n0 auto 110 auto kick\n0 auto 90 auto hihat\n1 auto 100\n1 auto 90 auto hihat\n")
    result = run("compose", pattern, "--kit", "--pieces", "kick,snare", "--audio", tmp_path / "bar.wav")
    assert result.returncode == 0, result.stderr
    assert "played 2 of 2 notes on the kit" in result.stdout and "not chosen (--pieces): hihat ×2" in result.stdout
    assert (tmp_path / "bar.wav").stat().st_size > 1000


def test_compose_kit_puts_the_csv_s_metadata_into_the_json_beside_it_once(tmp_path):
    """--csv s.csv --json s.json: the run's JSON is the CSV's sidecar, holding both the notes and the CSV's
    metadata, written once (not the sidecar overwritten by the notes)."""
    pattern = tmp_path / "bar.pattern"
    pattern.write_text("tempo 120\n0 auto 110 auto kick\n1 auto 100\n")
    result = run("compose", pattern, "--kit", "--csv", tmp_path / "s.csv", "--json", tmp_path / "s.json")
    assert result.returncode == 0, result.stderr
    assert result.stdout.count("wrote") == 2 and "wrote " + str(tmp_path / "s.json") in result.stdout
    document = json.loads((tmp_path / "s.json").read_text())
    assert len(document["notes"]) == 2 and document["csv"]["rate"] == 1000.0 and document["model"] == "paper"
    assert document["csv"]["columns"][0] == "t" and document["csv"]["model"] == "paper"
