"""Where a planned part leaves the sticks: caught at rest at a playing height, within the joint's range.

A drummer ends a part (and a stick ends its last note) with the stick caught low over the head,
ready to play again, never thrown up to its rebound's apex and held there; a robot's range of
motion is kept by every planned motion: designed strokes, library strokes and the moves between.
"""

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from _cli import run
from drumstroke.compose import HOLD_AFTER, compose, rudiment_score
from drumstroke.design import Setup, design
from drumstroke.design.chain import ready_height
from drumstroke.dynamics import velocity_to_level
from drumstroke.palette.library import build_library, read_palette
from drumstroke.palette.motion import RETURN_LIMITS, Limits
from drumstroke.palette.rudiments import rudiments
from drumstroke.robot.validate import validate
from drumstroke.score import read_score
from drumstroke.trajectory import Trajectory

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

READY_HIGHEST = 0.4625
"""rad: the highest a stick ends a part at with the default setup (the standard throw of velocity 127), as the docs state."""


def _tempi(r):
    low, high = r.tempo
    return low, (low + high) / 2.0, high


def _held_at_the_end(trajectory, k):
    """The stick's angle over the final hold, checked to be one angle at rest."""
    hold = trajectory.t >= trajectory.t[-1] - 0.9 * HOLD_AFTER
    theta, omega = trajectory.theta[hold, k], trajectory.omega[hold, k]
    assert np.ptp(theta) == 0.0 and np.all(omega == 0.0)
    return float(theta[-1])


@pytest.mark.parametrize("r", rudiments(), ids=lambda r: r.name)
def test_every_rudiment_at_three_tempi_ends_each_stick_caught_at_rest_at_the_height_it_would_play_again(r):
    head = Setup().head
    for tempo in _tempi(r):
        score, _ = rudiment_score(r.name, tempo)
        piece = compose(score)
        assert piece.problems == ()
        trajectory = piece.trajectory
        for k, stick in enumerate(trajectory.sticks):
            final = _held_at_the_end(trajectory, k)
            last = max((p for p in piece.placements if p.note.stick == stick), key=lambda p: p.note.time)
            assert final == pytest.approx(ready_height(velocity_to_level(last.note.velocity)), abs=1e-5)  # as simulated: a buzz of dozens of bounces drifts (10 µrad: 4 µm at the tip)
            assert head < final <= READY_HIGHEST
            assert trajectory.theta[:, k].max() <= READY_HIGHEST, (tempo, stick)


@pytest.mark.parametrize("velocity", [5, 20, 40, 64, 80, 90, 110, 120, 127])
def test_the_ready_height_is_the_standard_throw_of_the_note_or_as_high_as_its_free_rebound_rises(velocity):
    """Two independent routes: the height the designer throws the note from by default, and the apex of the
    note's rebound under gravity alone (simulated), the highest a thumb that only presses can catch it."""
    level = velocity_to_level(velocity)
    throw = float(design([1.0], [level]).recipe.theta0)
    bounced = Trajectory.from_stroke(design([1.0], [level], end="bounce").stroke) if velocity <= 80 else None
    free = math.inf if bounced is None else float(bounced.path(np.array([bounced.apexes[0]]))[0][0])
    assert ready_height(level) == pytest.approx(min(throw, free), abs=1e-9)


def test_the_ready_height_rises_with_the_note_and_stays_below_the_stated_height():
    heights = [ready_height(velocity_to_level(v)) for v in range(1, 128)]
    assert np.all(np.diff(heights) > 0.0)
    assert heights[-1] == pytest.approx(READY_HIGHEST, abs=1e-4) and heights[-1] <= READY_HIGHEST


@pytest.fixture(scope="module")
def palette(tmp_path_factory):
    return build_library(tmp_path_factory.mktemp("lib"), palette=list(read_palette()))


@pytest.mark.parametrize("pattern", ["backbeat.pattern", "rudiments.pattern"])
def test_the_shipped_examples_end_each_stick_at_rest_where_its_last_stroke_started(pattern, palette):
    piece = compose(read_score(EXAMPLES / pattern, stroke_names=list(palette)), palette)
    trajectory = piece.trajectory
    for k, stick in enumerate(trajectory.sticks):
        final = _held_at_the_end(trajectory, k)
        last = max((p for p in piece.placements if p.note.stick == stick and p.played), key=lambda p: p.note.time)
        if last.note.stroke in ("auto", "buzz"):
            assert final == pytest.approx(ready_height(velocity_to_level(last.note.velocity)), abs=1e-5)  # as simulated: a buzz of dozens of bounces drifts (10 µrad: 4 µm at the tip)
        else:  # a library stroke returns home: where it was thrown from
            thrown_from = float(trajectory.stick(stick).path(np.array([last.start]))[0][0])
            assert final == pytest.approx(thrown_from, abs=1e-12)


JOINT = Limits(theta_high=0.1, max_speed=40.0)


@pytest.mark.parametrize("r", rudiments()[::4], ids=lambda r: r.name)
def test_a_joint_s_range_is_kept_by_every_planned_motion_and_nothing_left_out_silently(r):
    piece = compose(rudiment_score(r.name, sum(r.tempo) / 2.0)[0], setup=Setup(limits=JOINT))
    trajectory = piece.trajectory
    assert trajectory.theta.max() <= JOINT.theta_high + 1e-12
    for stick in trajectory.sticks:
        validate(trajectory, stick=stick, limits=JOINT)
    for placement in piece.placements:  # a note the range leaves out is reported, by its source
        assert placement.played or any(placement.note.source in problem for problem in piece.problems)


def test_library_strokes_are_scaled_below_the_joint_s_highest_angle_and_say_so(palette):
    joint = Limits(theta_high=0.15, max_speed=40.0)
    piece = compose(read_score(EXAMPLES / "backbeat.pattern", stroke_names=list(palette)), palette,
                    setup=Setup(limits=joint))
    assert piece.trajectory.theta.max() <= joint.theta_high + 1e-12
    assert any("above the joint's highest angle, 0.15 rad" in problem for problem in piece.problems)
    unlimited = compose(read_score(EXAMPLES / "backbeat.pattern", stroke_names=list(palette)), palette)
    assert unlimited.trajectory.theta.max() > joint.theta_high  # the test means something


def test_the_moves_between_strokes_keep_the_joint_s_range_and_speed():
    setup = Setup(limits=Limits(theta_high=0.1, max_speed=10.0))
    assert setup.moves.theta_high == 0.1 and setup.moves.max_speed == 10.0
    assert setup.moves.max_acceleration == RETURN_LIMITS.max_acceleration
    assert Setup().moves == RETURN_LIMITS
    assert Setup().replace(limits=JOINT).moves.theta_high == JOINT.theta_high
    given = Limits(max_speed=5.0)
    assert Setup(moves=given).replace(limits=JOINT).moves == given  # moves given are kept as given


def test_rudiment_with_a_robot_config_writes_a_part_robot_validate_accepts(tmp_path):
    config = tmp_path / "robot.toml"
    config.write_text("[limits]\ntheta_high = 0.1\nmax_speed = 40.0\n")
    done = run("rudiment", "single-paradiddle", "--tempo", "100", "--config", config, "--csv", tmp_path / "p.csv")
    assert done.returncode == 0, done.stderr
    frame = pd.read_csv(tmp_path / "p.csv")
    assert frame[["theta_right", "theta_left"]].to_numpy().max() <= 0.1 + 1e-9
    for stick in ("right", "left"):
        checked = run("robot", "validate", tmp_path / "p.csv", "--stick", stick, "--config", config)
        assert checked.returncode == 0 and "valid" in checked.stdout, checked.stderr
    plain = run("rudiment", "single-paradiddle", "--tempo", "100", "--csv", tmp_path / "q.csv")
    assert plain.returncode == 0
    assert pd.read_csv(tmp_path / "q.csv")[["theta_right"]].to_numpy().max() > 0.1  # the config changed it
