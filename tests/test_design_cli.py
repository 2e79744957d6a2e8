"""The planner's commands as a user runs them: ``design``, ``rudiment``, and ``compose`` with ``auto`` and ``buzz``."""

import json

import mido
import numpy as np
import pytest

import drumstroke
from _cli import assert_one_line_error, run
from drumstroke.dynamics import velocity_to_level


def test_design_writes_a_recipe_that_plays_the_notes(tmp_path):
    result = run("design", "--times", "0.2,0.29,0.38", "--velocities", "100,100,110", "--model", "geometry",
                 "--out", tmp_path / "d.toml", "--json", tmp_path / "d.json", "--csv", tmp_path / "d.csv")
    assert result.returncode == 0, result.stderr
    assert "designed 3 notes on the geometry model" in result.stdout
    data = json.loads((tmp_path / "d.json").read_text())
    assert data["model"] == "geometry" and data["design"]["notes"] == [0.2, 0.29, 0.38]
    assert data["csv"]["columns"] == ["t", "theta", "omega"]  # the CSV's metadata beside it
    data = data["design"]
    # the recipe alone, read back and simulated, makes the notes (its t = 0 is the release)
    stroke = drumstroke.simulate(drumstroke.Recipe.from_toml(tmp_path / "d.toml"))
    assert stroke.impacts.t[:3] + data["release"] == pytest.approx([0.2, 0.29, 0.38], abs=1e-8)
    assert stroke.impacts.level_db[:3] == pytest.approx([velocity_to_level(v) for v in (100, 100, 110)], abs=1e-5)
    assert (tmp_path / "d.csv").read_text().splitlines()[0] == "t,theta,omega"


def test_design_of_a_buzz(tmp_path):
    result = run("design", "--buzz", "0:0.5", "--velocity", "80", "--density", "30", "--json", tmp_path / "b.json")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "b.json").read_text())["design"]
    assert np.diff(data["notes"]) == pytest.approx(1 / 30, abs=1e-12) and data["end"] == "press"
    assert data["t_end"] <= 0.5


def test_an_unreachable_note_is_one_line_with_the_nearest():
    result = run("design", "--times", "0.2,0.22", "--levels=-10,2")
    assert_one_line_error(result, "note 1", "force limit 3000 m/s^2", "nearest reachable")
    assert_one_line_error(run("design", "--times", "0.2,0.1", "--velocities", "50,60"), "times must increase")
    assert_one_line_error(run("design", "--times", "0.2", "--velocities", "200"), "velocities[0] must be")
    assert_one_line_error(run("design", "--times", "0.2,x", "--velocities", "50,60"), "--times", "numbers")
    assert_one_line_error(run("design"), "--times", "--buzz")


def test_rudiment_list_and_play(tmp_path):
    listed = run("rudiment", "--list")
    assert listed.returncode == 0 and len(listed.stdout.splitlines()) == 40
    assert listed.stdout.splitlines()[15].split()[:2] == ["16", "single-paradiddle"]
    result = run("rudiment", "single-paradiddle", "--tempo", "100", "--midi", tmp_path / "p.mid", "--json",
                 tmp_path / "p.json")
    assert result.returncode == 0, result.stderr
    assert "32 of 32 notes played" in result.stdout  # two bars
    data = json.loads((tmp_path / "p.json").read_text())
    assert {n["stick"] for n in data["notes"]} == {"right", "left"} and all(n["played"] for n in data["notes"])
    assert data["designs"] and all(d["model"] == "paper" for d in data["designs"])
    file = mido.MidiFile(tmp_path / "p.mid")
    firsts = [m for t in file.tracks for m in t if m.type == "note_on" and m.velocity and m.note == 38]
    assert len(firsts) == 32


def test_rudiment_bad_input():
    assert_one_line_error(run("rudiment", "paradidle"), "did you mean")
    from drumstroke.errors import ParameterError
    from drumstroke.palette.rudiments import rudiment

    for name in ("paradiddle", "41", "zzz"):  # the library's message, about NAME and pointing at --list
        with pytest.raises(ParameterError) as raised:
            rudiment(name)
        expected = str(raised.value).replace("rudiment must", "NAME must", 1).replace("rudiments()",
                                                                                   "'drumstroke rudiment --list'")
        result = run("rudiment", name)
        assert result.returncode == 2 and result.stderr == f"drumstroke rudiment: error: {expected}\n"
    assert "(did you mean 'single-paradiddle', 'double-paradiddle' or 'triple-paradiddle'?)" in \
        run("rudiment", "paradiddle").stderr
    assert_one_line_error(run("rudiment", "single-paradiddle", "--tempo", "0"), "--tempo")
    assert_one_line_error(run("rudiment"), "NAME", "--list")


def test_rudiment_list_prints_the_40_by_number_with_their_family_and_tempo_range():
    from drumstroke.palette.rudiments import rudiments

    result = run("rudiment", "--list")
    assert result.returncode == 0 and result.stderr == ""
    rows = [line.split() for line in result.stdout.splitlines()]
    assert [(int(row[0]), row[1], row[2], row[3]) for row in rows] == [
        (r.number, r.name, r.family, f"{r.tempo[0]:g}-{r.tempo[1]:g}") for r in rudiments()]
    assert [row[0] for row in rows] == [str(n) for n in range(1, 41)]


def test_compose_plays_auto_and_buzz_notes_without_a_library(tmp_path):
    pattern = tmp_path / "flam.pattern"
    pattern.write_text("tempo 100\n0 auto 110 right\n0.95 auto 60 left\n1 auto 115 right\n2 buzz 90 auto 0.5\n"
                       "3 auto 100 auto\n")
    result = run("compose", pattern, "--json", tmp_path / "c.json", "--strict")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "c.json").read_text())
    assert all(n["played"] for n in data["notes"]) and data["notes"][1]["stick"] == "left"
    assert data["notes"][3]["stick"] in ("right", "left")  # the planner's choice, recorded
    unreachable = tmp_path / "bad.pattern"
    unreachable.write_text("tempo 100\n0 auto 40 right\n0.05 auto 127 right\n")
    result = run("compose", unreachable, "--strict")
    assert result.returncode == 3 and "left out" in result.stderr
    assert_one_line_error(run("compose", tmp_path / "flam.pattern", "--sticks", "3"), "--sticks")
    named = tmp_path / "named.pattern"
    named.write_text("tempo 100\n0 flam 100\n")  # no --library: the shipped palette's strokes, no flam among them
    assert_one_line_error(run("compose", named), "'flam' is not auto, buzz or a library stroke",
                          "the library has single, tap")
