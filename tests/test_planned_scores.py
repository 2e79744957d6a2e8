"""The planner in composition: the 40 PAS rudiments at the bottom, middle and top of their ranges, and the snare
parts of real songs, every note played on time and level on two sticks, or reported.

Checks are against the notes themselves (the rudiments' data, the MIDI files read by mido here), not against
the planner's own account: each note must have an impact of its stick within 1 ms of its time and 1.5 dB of its
velocity's level; every trajectory must pass the robot's validation with the joint's default limits.
"""

from pathlib import Path

import mido
import numpy as np
import pytest

from drumstroke.compose import compose, rudiment_score
from drumstroke.dynamics import velocity_to_level
from drumstroke.palette.motion import Limits
from drumstroke.palette.rudiments import rudiments
from drumstroke.robot.validate import validate
from drumstroke.score import read_score

DATA = Path(__file__).resolve().parent / "data" / "midi"
SONGS = ["d6caebd1964d9e4a3c5ea59525230e2a.mid", "In Too Deep.mid", "Les Yeux Revolvers.mid"]


def impact_of(piece, note):
    """The impact of ``note``'s stick nearest its time: (time error s, level dB)."""
    impacts = piece.sticks[note.stick].impacts
    target = piece.offset + note.time
    i = int(np.argmin(np.abs(impacts.t - target)))
    return abs(impacts.t[i] - target), impacts.level_db[i]


def assert_played(piece):
    for placement in piece.placements:
        note = placement.note
        assert placement.played, (note.source, piece.problems)
        error, level = impact_of(piece, note)
        assert error < 1e-3, (note.source, error)
        assert abs(level - velocity_to_level(note.velocity)) < 1.5, (note.source, level)
    for stick in piece.trajectory.sticks:  # the joint's default limits, every stick
        validate(piece.trajectory, stick=stick, limits=Limits())


@pytest.mark.parametrize("where", ["bottom", "middle", "top"])
@pytest.mark.parametrize("rudiment", rudiments(), ids=lambda r: f"{r.number:02d}-{r.name}")
def test_every_rudiment_is_played_at_its_tempi(rudiment, where):
    low, high = rudiment.tempo
    tempo = {"bottom": low, "middle": (low + high) / 2, "top": high}[where]
    score, played = rudiment_score(rudiment.name, tempo, bars=2)
    piece = compose(score)
    assert piece.problems == ()
    assert {p.note.stick for p in piece.placements} == {n.stick for n in played.notes}  # the rudiment's sticking kept
    assert_played(piece)
    by_stick = {}
    for placement in piece.placements:
        by_stick.setdefault(placement.note.stick, []).append(placement.note)
    for notes in by_stick.values():  # diddles: two notes of one dynamic on a stick, a diddle's gap apart
        for first, second in zip(notes, notes[1:]):
            if first.stroke == second.stroke == "auto" and first.velocity == second.velocity \
                    and second.time - first.time < 0.13:
                assert abs(impact_of(piece, first)[1] - impact_of(piece, second)[1]) < 1.0


def test_a_buzz_of_a_sixteenth_at_120_bpm_makes_at_least_three_impacts():
    score, played = rudiment_score("multiple-bounce-roll", 120.0, bars=1)
    piece = compose(score)
    assert piece.problems == ()
    buzzes = [n for n in played.notes if n.kind == "buzz"]
    assert len(buzzes) == 16 and all(n.duration == pytest.approx(0.125) for n in buzzes)
    for n in buzzes:
        impacts = piece.sticks[n.stick].impacts.t - piece.offset
        assert np.sum((impacts > n.time - 1e-6) & (impacts < n.time + n.duration)) >= 3


def snare_notes(path):
    """Counted with mido: the channel-10 note_ons on 37, 38 and 40 (time s, velocity)."""
    now, notes = 0.0, []
    for message in mido.MidiFile(path):
        now += message.time
        if message.type == "note_on" and message.velocity and message.channel == 9 and message.note in (37, 38, 40):
            notes.append((now, message.velocity))
    return notes


@pytest.mark.parametrize("name", SONGS)
def test_a_real_songs_snare_part_is_played_on_two_sticks_the_planner_chose(name):
    path = DATA / name
    expected = snare_notes(path)
    tempo_changes = sum(1 for track in mido.MidiFile(path).tracks for m in track if m.type == "set_tempo")
    assert tempo_changes > 1 and len(expected) >= 8
    piece = compose(read_score(path))
    assert [p.note.velocity for p in piece.placements] == [velocity for _, velocity in expected]
    assert [p.note.time for p in piece.placements] == pytest.approx([time for time, _ in expected], abs=1e-9)
    left_out = [p for p in piece.placements if not p.played]
    assert len(left_out) == sum("left out" in problem for problem in piece.problems)  # each one reported
    assert not left_out
    assert_played(piece)
