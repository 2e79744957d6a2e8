"""The performance planner: one stick's notes become designed strokes and moves, every note played or reported."""

import numpy as np
import pytest

import drumstroke
import drumstroke.dynamics
from drumstroke.design import Problem, Setup, Start, Target, assign_sticks, next_stroke, plan_stick
from drumstroke.design.chain import standard_throw
from drumstroke.palette.motion import RETURN_LIMITS, Limits
from drumstroke.robot.validate import validate


def targets(notes):
    return [Target.from_velocity(t, v, kind=kind, duration=duration, key=k)
            for k, (t, v, kind, duration) in enumerate(notes)]


def check_trajectory(plan, t_end):
    trajectory = plan.trajectory(t_end=t_end)
    validate(trajectory, limits=Limits())  # the default joint's limits: speed, acceleration, jerk, the head
    _t, theta, omega = trajectory
    assert theta.min() >= trajectory.theta_max - 1e-12
    # continuous: no sample farther from the last than the speed allows
    assert np.all(np.abs(np.diff(theta)) <= np.maximum(np.abs(omega[1:]), np.abs(omega[:-1])) / trajectory.rate
                  + 0.5 * 60000.0 / trajectory.rate**2)
    return trajectory


@pytest.mark.parametrize("model", drumstroke.MODELS)
@pytest.mark.parametrize("name, notes", [
    ("eighths at 120 bpm on one stick", [(0.5 + k * 0.25, 100, "auto", None) for k in range(16)]),
    ("sixteenths at 120 bpm on one stick", [(0.5 + k * 0.125, 100, "auto", None) for k in range(16)]),
    ("RR of RRLL in 32nds at 100 bpm", [(0.5 + k * 0.075 + (k // 2) * 0.075, 96, "auto", None) for k in range(16)]),
    ("accents and taps", [(0.5 + k * 0.25, 120 if k % 4 == 0 else 48, "auto", None) for k in range(16)]),
    ("a press roll into its release", [(0.5, 90, "buzz", 1.0), (1.75, 110, "auto", None)]),
    ("quarter notes at 60 bpm", [(0.5 + k, 100, "auto", None) for k in range(5)]),
])
def test_every_note_is_played_on_time_and_level(model, name, notes):
    plan = plan_stick(targets(notes), setup=Setup(model=model))
    assert plan.problems == ()
    assert sorted(k for keys in plan.keys for k in keys) == list(range(len(notes)))
    for design, keys in zip(plan.designs, plan.keys):
        n = len(design.times)
        assert design.impacts.t[:n] == pytest.approx(design.times, abs=1e-8)
        assert design.impacts.level_db[:n] == pytest.approx(design.levels, abs=1e-5)
    impacts = np.concatenate([d.impacts.t[:len(d.times)] for d in plan.designs])
    levels = np.concatenate([d.impacts.level_db[:len(d.times)] for d in plan.designs])
    for t, velocity, _, _ in notes:  # each note's own impact, at its time and its velocity's level
        i = int(np.argmin(np.abs(impacts - t)))
        assert impacts[i] == pytest.approx(t, abs=1e-8)
        assert levels[i] == pytest.approx(drumstroke.dynamics.velocity_to_level(velocity), abs=1e-5)
    check_trajectory(plan, notes[-1][0] + 0.5)


def test_the_first_stroke_chains_and_breaks_as_the_forces_allow():
    plan = plan_stick(targets([(0.5, 100, "auto", None), (0.6, 100, "auto", None), (1.5, 127, "auto", None)]))
    assert [len(k) for k in plan.keys] == [2, 1]  # a diddle, then a new stroke a second later
    assert plan.designs[1].recipe.theta0 > plan.designs[0].recipe.theta0 - 1.0


def test_a_flam_on_one_stick_is_reported_not_dropped():
    """The grace note 30 ms before a note 18 dB louder on the same stick: the main note cannot be thrown in time."""
    plan = plan_stick(targets([(0.5, 40, "auto", None), (0.53, 110, "auto", None), (1.0, 100, "auto", None)]))
    assert [p.key for p in plan.problems] == [1]
    problem = plan.problems[0]
    assert isinstance(problem, Problem) and problem.t == 0.53 and "force limit" in problem.reason
    assert "note 1 at 0.53 s not played" in str(problem)
    assert sorted(k for keys in plan.keys for k in keys) == [0, 2]


def test_buzzes_make_their_bounces():
    """A buzz of a sixteenth at 120 bpm makes at least 3 impacts; its bounces are at the buzz density."""
    plan = plan_stick(targets([(0.5, 90, "buzz", 0.125), (1.0, 90, "buzz", 0.125)]))
    assert plan.problems == ()
    impacts = np.concatenate([d.impacts.t for d in plan.designs])
    for start in (0.5, 1.0):
        assert np.sum((impacts >= start - 1e-9) & (impacts < start + 0.125)) >= 3


def test_the_moves_between_strokes_keep_their_budget():
    plan = plan_stick(targets([(0.5, 127, "auto", None), (0.8, 30, "auto", None), (1.1, 127, "auto", None)]),
                      setup=Setup(moves=RETURN_LIMITS))
    assert plan.problems == ()
    trajectory = check_trajectory(plan, 1.5)
    assert np.abs(trajectory.omega).max() <= Limits().max_speed


def test_bad_targets():
    with pytest.raises(drumstroke.ParameterError, match="target.kind must be one of auto, buzz"):
        Target(0.1, -3.0, kind="flam")
    with pytest.raises(drumstroke.ParameterError, match="target.t must be a finite number"):
        Target(float("nan"), -3.0)
    with pytest.raises(drumstroke.ParameterError, match="targets must be drumstroke.design.Target"):
        plan_stick([(0.1, -3.0)])
    with pytest.raises(drumstroke.ParameterError, match="increase by at least"):
        plan_stick([Target(0.1, -3.0), Target(0.1, -3.0)])


def test_sticking_a_part_that_names_no_stick():
    times = np.arange(8) * 0.125  # sixteenths at 120 bpm: beats at 0, 0.5 s
    beats = times / 0.5
    sticks = assign_sticks(times, beats=beats)
    assert sticks == ["right", "left", "right", "left", "right", "left", "right", "left"]
    # two notes 30 ms apart (a flam): the other hand takes the second
    assert assign_sticks([0.0, 0.03], beats=[0.0, 0.06]) == ["right", "left"]
    # the lead hand on every beat, even after an off-beat right note
    assert assign_sticks([0.0, 0.75, 1.0], beats=[0.0, 1.5, 2.0]) == ["right", "left", "right"]
    assert assign_sticks([0.0, 0.1], sticks=1) == ["right", "right"]
    with pytest.raises(drumstroke.ParameterError, match="sticks must be 1 or 2"):
        assign_sticks([0.0], sticks=3)


def test_next_stroke_throws_from_where_the_stick_rests_when_it_can():
    setup = Setup()
    made, moves = next_stroke([1.0], [0.0], setup, free=0.5, theta=0.0)  # gravity alone is too slow from level
    assert moves == [] and made.release >= 0.5 - 1e-9
    assert float(made.recipe.theta0) == pytest.approx(0.0, abs=1e-12)  # thrown from the height it rests at
    assert made.impacts.t[0] == pytest.approx(1.0, abs=1e-8)


def test_next_stroke_moves_to_a_throw_when_the_stick_cannot_be_thrown_from_where_it_is():
    setup = Setup()
    made, moves = next_stroke([1.0], [-6.0], setup, free=0.5, theta=setup.head)  # resting on the head
    assert moves, "a stick on the head must be lifted first"
    duration = sum(d for d, _ in moves)
    assert duration == pytest.approx(made.release - 0.5, abs=1e-9)  # the moves fill the window to the release
    first, last = moves[0][1](np.array([0.0])), moves[-1][1](np.array([moves[-1][0]]))
    assert first[0][0] == pytest.approx(setup.head, abs=1e-9) and first[1][0] == pytest.approx(0.0, abs=1e-9)
    assert last[0][0] == pytest.approx(float(made.recipe.theta0), abs=1e-9) and abs(last[1][0]) < 1e-6


def test_next_stroke_bounces_on_from_a_running_motion():
    setup = Setup()
    running = Start(0.4, setup.head, 5.0)  # leaving the head at 5 rad/s
    made, moves = next_stroke([0.5], [-6.0], setup, free=0.4, theta=setup.head, omega=5.0, running=running)
    assert moves == [] and made.release == pytest.approx(0.4, abs=1e-12)
    assert made.impacts.t[0] == pytest.approx(0.5, abs=1e-8)


@pytest.mark.parametrize("free, theta, level", [(0.55, -0.25, 12.0),  # too loud a throw from this low
                                                 (0.55, 0.0, -20.0),  # too soft a throw from this high
                                                 (0.55, 0.2, 12.0)])  # too long a throw for the time left
def test_next_stroke_refuses_a_throw_from_rest_as_its_design_does(free, theta, level):
    """A start at rest is refused without its design begun (the planner tries it first): with no other start left
    (no move fits in the time left), next_stroke raises the refusal design raises, message and note."""
    setup = Setup()
    with pytest.raises(drumstroke.design.Unreachable) as designed:
        drumstroke.design.design([0.6], [level], start=Start(free, theta), setup=setup)
    with pytest.raises(drumstroke.design.Unreachable) as planned:
        next_stroke([0.6], [level], setup, free=free, theta=theta)
    assert (str(planned.value), planned.value.note) == (str(designed.value), designed.value.note)


def test_next_stroke_says_why_when_no_start_reaches_the_note():
    with pytest.raises(drumstroke.ParameterError, match=r"needs 0\.1\d+ s to reach the height of its next throw, "
                                                        r"but only 0\.02 s are left"):
        next_stroke([0.62], [-6.0], Setup(), free=0.5, theta=1.3, omega=15.0)  # rising fast: it must stop first
    with pytest.raises(drumstroke.ParameterError, match="free at 0.5 s, after a throw of 0.1 s onto the note at "
                                                        "0.52 s would start"):
        next_stroke([0.52], [-6.0], Setup(), free=0.5, theta=1.3, omega=15.0)


def test_a_setup_names_what_is_wrong():
    with pytest.raises(drumstroke.ParameterError, match=r"cor must be in \[0, 1\)"):
        Setup(cor=1.0)
    with pytest.raises(drumstroke.ParameterError, match="model must be one of"):
        Setup(model="fast")
    with pytest.raises(drumstroke.ParameterError, match="forces must be a drumstroke.design.ForceRange"):
        Setup(forces=(0, 100))
    with pytest.raises(drumstroke.ParameterError, match="setup must be a drumstroke.design.Setup"):
        plan_stick([Target(0.5, -6.0)], setup={"model": "paper"})


@pytest.mark.parametrize("time, level, lead", [(1.0, -6.0, 0.1), (1.0, 5.0, 0.0125), (0.5, -30.0, 0.05),
                                               (2.0, 12.0, 0.1)])
def test_the_standard_throw_in_closed_form_is_where_the_simulated_design_starts(time, level, lead):
    made = drumstroke.design.design([time], [level], lead=lead)
    release, height = standard_throw(time, level, lead=lead)
    assert release == made.release and height == float(made.recipe.theta0)


@pytest.mark.parametrize("lead", [0.1, 0.05, 0.025, 0.0125])
def test_the_first_throw_is_as_long_as_asked_and_the_notes_are_played_the_same(lead):
    targets = [Target(1.0, -3.0), Target(1.09, -3.0), Target(1.6, 0.0)]
    plan = plan_stick(targets, lead=lead)
    release, height = standard_throw(1.0, -3.0, lead=lead)
    first = plan.designs[0]
    assert first.release == pytest.approx(release, abs=1e-9) and float(first.recipe.theta0) == pytest.approx(height)
    assert plan.problems == ()
    impacts = np.concatenate([d.impacts.t[:len(d.times)] for d in plan.designs])
    np.testing.assert_allclose(impacts, [1.0, 1.09, 1.6], atol=1e-8)


def test_a_throw_of_no_time_is_refused():
    with pytest.raises(drumstroke.errors.ParameterError, match=r"lead must be in \(0, 10\] s, got 0.0"):
        plan_stick([Target(1.0, 0.0)], lead=0.0)


def test_a_throw_asked_for_again_at_other_times_is_still_where_the_design_starts():
    """standard_throw keeps a throw's duration and height (by setup, lead and level): the cached answer, shifted to
    another note's time, is what the design at that time finds."""
    for time in (0.25, 1.0, 3.7, 1.0, 1000.3):
        made = drumstroke.design.design([time], [-9.5], lead=0.05)
        assert standard_throw(time, -9.5, lead=0.05) == (made.release, float(made.recipe.theta0))
