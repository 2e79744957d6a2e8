"""Every shipped example does what its comments say, with no warning and no problem reported.

The recipes in examples/ read and simulate; the patterns (examples/ and the demo's groove) compose with every note
played whole; the palette builds the strokes it describes; the robot config holds the defaults it says it does; the
sweeps simulate every point; and each command an example's comments give runs clean, as a user types it.
"""

import csv
import re
import shlex
import shutil
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import drumstroke
from _cli import problem_lines, run
from drumstroke.compose import HITS, compose
from drumstroke.palette.library import DEMO_PATTERN, build_library, load_library, read_palette
from drumstroke.robot.config import RobotConfig
from drumstroke.score import PLANNED, read_pattern

FOLDER = Path(__file__).resolve().parents[1] / "examples"
EXAMPLES = sorted(FOLDER.glob("*.toml"))
PATTERNS = [*sorted(FOLDER.glob("*.pattern")), DEMO_PATTERN]
SWEEPS = sorted((FOLDER / "sweeps").glob("*.toml"))
CATEGORIES = {entry.name: entry.category for entry in read_palette()}  # the shipped palette's


def test_there_are_examples():
    assert len(EXAMPLES) >= 3 and len(PATTERNS) >= 3 and len(SWEEPS) >= 2


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_simulates(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        recipe = drumstroke.Recipe.from_toml(path)
        stroke = drumstroke.simulate(recipe)
        _, theta, _ = stroke.sample(1000.0)
    assert len(stroke.impacts) >= 3
    assert np.all(np.isfinite(theta)) and np.all(theta >= recipe.theta_max)
    assert stroke.to_dict()["model"] == recipe.model and stroke.to_dict()["recipe_name"] == path.stem


def test_the_recorded_thumb_is_read_from_its_file():
    recipe = drumstroke.Recipe.from_toml(EXAMPLES[0].parent / "recorded-thumb.toml")
    assert isinstance(recipe.force, drumstroke.Samples)
    assert recipe.force(1.1) == pytest.approx(140.0, abs=13.0)  # the press's peak, plus tremor
    assert len(recipe.force.points) == 1501


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    """The shipped palette's strokes the patterns name, built once: (the folder, the library)."""
    names = {note.stroke for path in PATTERNS for note in read_pattern(path) if note.stroke not in PLANNED}
    folder = tmp_path_factory.mktemp("examples") / "lib"
    return folder, build_library(folder, palette=[entry for entry in read_palette() if entry.name in names])


@pytest.mark.parametrize("path", PATTERNS, ids=[p.name for p in PATTERNS])
def test_every_pattern_plays_every_note_whole(path, library):
    folder, _ = library
    result = run("compose", path, "--library", folder)
    assert result.returncode == 0, result.stderr
    assert not problem_lines(result.stdout + result.stderr), problem_lines(result.stdout + result.stderr)
    assert re.search(r"composed (\d+) of \1 notes", result.stdout), result.stdout


def test_the_demo_groove_plays_natural_strokes_and_swells_into_its_last_downbeat(library):
    """No stroke of the paper's un-natural kind (a human hand cannot play them); bar 4's promise, a swell into the
    last downbeat, is notes on both sticks each louder than the one before, the downbeat the loudest note."""
    notes = read_pattern(DEMO_PATTERN)
    assert {CATEGORIES[note.stroke] for note in notes} <= set(CATEGORIES.values()) - {"un-natural"}
    piece = compose(notes, library[1])
    swell = [p for p in piece.placements if p.note.beat >= 15]
    assert len(swell) >= 4 and {p.note.stick for p in swell} == {"left", "right"}
    levels = []
    for placement in swell:
        impacts = piece.sticks[placement.note.stick].impacts
        (first,) = np.flatnonzero(np.isclose(impacts.t, placement.impact, atol=1e-9))
        levels.append(impacts.level_db[first])
    loudest = max(stick.impacts.level_db.max() for stick in piece.sticks.values())
    assert np.all(np.diff(levels) > 0) and levels[-1] == loudest


def test_the_small_palette_builds_the_strokes_it_describes(tmp_path):
    result = run("library", "build", tmp_path / "lib", "--palette", FOLDER / "palettes" / "small.toml")
    assert result.returncode == 0 and not problem_lines(result.stdout + result.stderr), result
    strokes = load_library(tmp_path / "lib")
    for name, entry in strokes.items():
        if entry.category in HITS:  # a single, double or triple stroke: that many impacts, then caught
            assert len(entry.trajectory.impacts) == HITS[entry.category], name
    assert strokes["pulsed-press"].trajectory.rest_time is not None  # "an uneven buzz that the press ends"
    # "the free bounce's first three bounces, played at half speed"
    free = drumstroke.simulate("free-bounce").impacts.t[:3]
    assert np.allclose(strokes["slow-ruff"].trajectory.impacts.t, 2.0 * free, atol=1e-9)


def test_the_robot_config_holds_the_defaults_but_the_speed_limit():
    """Its comment: every value is the default but [limits].max_speed, 40 rad/s where the default is 30."""
    config, default = RobotConfig.from_toml(FOLDER / "robot" / "robot.toml"), RobotConfig()
    assert config.plant == default.plant and dict(config.controllers) == dict(default.controllers)
    assert default.limits.max_speed == 30.0 and config.limits == replace(default.limits, max_speed=40.0)


@pytest.mark.parametrize("path", SWEEPS, ids=[p.stem for p in SWEEPS])
def test_every_sweep_point_simulates(path, tmp_path):
    result = run("sweep", path, "--out", tmp_path / "sweep.csv")
    assert result.returncode == 0 and not problem_lines(result.stdout + result.stderr), result
    with open(tmp_path / "sweep.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) >= 200 and all(row["error"] == "" for row in rows)
    assert all(int(row["audible_impacts"]) >= 1 for row in rows)


def _commands_in_comments():
    """The `drumstroke ...` commands the examples' comments give, in backticks or as a comment line of their own;
    one naming alternatives ('track|tune') is a usage line, not a command."""
    found = []
    for path in sorted(FOLDER.rglob("*")):
        if path.suffix not in (".toml", ".pattern"):
            continue
        for line in path.read_text(encoding="utf-8").splitlines():
            comment = line.partition("#")[2]
            found += re.findall(r"`(drumstroke [^`]+)`", comment) or re.findall(r"^\s*(drumstroke .+)$", comment)
    return [command for command in found if "|" not in command]


def test_the_commands_in_the_examples_comments_run_clean(tmp_path, library):
    commands = _commands_in_comments()
    assert any("compose examples/backbeat.pattern" in c for c in commands) and any(" sweep " in c for c in commands)
    shutil.copytree(FOLDER, tmp_path / "examples")
    shutil.copytree(library[0], tmp_path / "lib")
    for command in commands:
        result = run(*shlex.split(command)[1:], cwd=tmp_path)
        assert result.returncode == 0, (command, result.stderr)
        assert not problem_lines(result.stdout + result.stderr), (command, problem_lines(result.stdout + result.stderr))
