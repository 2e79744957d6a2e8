"""The moves between strokes are ruckig's own: the calculator kept for a thread (its input's limits set only when
they change) gives each move a fresh ruckig calculator gives, to the bit, and a move's path is that trajectory's."""

import numpy as np
import pytest

from drumstroke.palette.motion import RETURN_LIMITS, Limits, _path_of, _ruckig, _ruckig_joints, plan_move

ruckig = pytest.importorskip("ruckig")

HEAD = Limits().theta_low


def fresh(starts, targets, minimum, limits):
    """ruckig's trajectory from a calculator and input made for this move alone, or None where ruckig finds none."""
    n = len(starts)
    parameters = ruckig.InputParameter(n)
    parameters.current_position = [s[0] for s in starts]
    parameters.current_velocity = [s[1] for s in starts]
    parameters.current_acceleration = [0.0] * n
    parameters.target_position = [s[0] for s in targets]
    parameters.target_velocity = [s[1] for s in targets]
    parameters.target_acceleration = [0.0] * n
    parameters.max_velocity = [0.98 * joint.max_speed for joint in limits]
    parameters.max_acceleration = [0.98 * joint.max_acceleration for joint in limits]
    parameters.max_jerk = [0.98 * joint.max_jerk for joint in limits]
    parameters.synchronization = ruckig.Synchronization.Time
    if minimum > 0.0:
        parameters.minimum_duration = minimum
    trajectory = ruckig.Trajectory(n)
    try:
        result = ruckig.Ruckig(n).calculate(parameters, trajectory)
    except ruckig.RuckigError:
        return None
    return trajectory if result in (ruckig.Result.Working, ruckig.Result.Finished) else None


def assert_same(made, expected, joints):
    """Two ruckig trajectories the same to the bit: duration, every phase's values, states along them."""
    assert (made is None) == (expected is None)
    if made is None:
        return
    assert made.duration == expected.duration
    for mine, theirs in zip(made.profiles[0], expected.profiles[0]):
        for name in ("t", "j", "a", "v", "p"):
            assert getattr(mine, name) == getattr(theirs, name), name
    for t in np.linspace(-0.01, expected.duration + 0.01, 23):
        assert made.at_time(float(t)) == expected.at_time(float(t))


def state(rng):
    """A random (θ rad, ω rad/s): at rest a third of the time (as a return's ends are), moving up to 25 rad/s (past
    RETURN_LIMITS' speed: ruckig brakes first)."""
    theta = float(rng.uniform(HEAD, 1.2))
    return theta, (0.0 if rng.random() < 1 / 3 else float(rng.uniform(-25.0, 25.0)))


def test_a_one_joint_move_is_a_fresh_ruckig_calculators_to_the_bit(rng):
    """Random moves, time-optimal and stretched (some too short to take: none either way; some ruckig cannot stretch:
    none either way), the limits changing between moves as two setups' moves interleave."""
    found = failed = 0
    for k in range(600):
        limits = (Limits(), RETURN_LIMITS)[k % 2]
        start, target = state(rng), state(rng)
        minimum = 0.0 if rng.random() < 0.3 else float(rng.uniform(0.0, 0.3))
        made, expected = _ruckig(start, target, minimum, limits), fresh([start], [target], minimum, [limits])
        assert_same(made, expected, 1)
        found += made is not None
        failed += made is None
    assert found > 300 and failed > 10  # both kinds met


def test_a_move_of_several_joints_is_a_fresh_ruckig_calculators_to_the_bit(rng):
    joints = [Limits(theta_low=-1.0), Limits(theta_low=-1.0, max_speed=8.0, max_acceleration=400.0),
              Limits(theta_low=-1.0, max_jerk=2.0e4)]
    for k in range(200):
        n = 2 + k % 2
        starts = [(float(rng.uniform(-1.0, 1.0)), float(rng.uniform(-2.0, 2.0))) for _ in range(n)]
        targets = [(float(rng.uniform(-1.0, 1.0)), 0.0) for _ in range(n)]
        minimum = 0.0 if k % 3 else float(rng.uniform(0.0, 1.0))
        made = _ruckig_joints(starts, targets, minimum, joints[:n])
        assert_same(made, fresh(starts, targets, minimum, joints[:n]), n)
        _ruckig((0.1, 0.0), (0.2, 0.0), 0.0, RETURN_LIMITS)  # a one-joint move between: its own calculator


def phases_of(profile):
    """A profile's phases laid out as the path reads them, by numpy column by column: start, jerk, acceleration,
    speed, angle."""
    starts = np.concatenate(([0.0], np.cumsum(profile.t[:-1])))
    return np.ascontiguousarray(np.column_stack((starts, profile.j, profile.a[:7], profile.v[:7], profile.p[:7])))


def test_a_moves_path_is_its_trajectorys_phases_and_states(rng):
    """A move's path holds the trajectory's phases to the bit (their starts summed in order) and gives ruckig's states
    along it to round-off; one starting beyond the limits (ruckig brakes first) is ruckig's own states."""
    braked = 0
    for _ in range(300):
        start, target = state(rng), state(rng)
        trajectory = fresh([start], [target], 0.0, [RETURN_LIMITS])
        if trajectory is None:
            continue
        path = _path_of(trajectory)
        profile = trajectory.profiles[0][0]
        t = np.linspace(0.0, trajectory.duration, 31)
        expected = np.array([trajectory.at_time(float(x))[:2] for x in t])[:, :, 0]
        if profile.brake.duration > 0.0 or profile.accel.duration > 0.0:
            braked += 1
            np.testing.assert_array_equal(np.column_stack(path(t)), expected)
            continue
        assert path.phases.flags.c_contiguous and path.phases.shape == (7, 5)
        np.testing.assert_array_equal(path.phases, phases_of(profile))
        scale = max(1.0, abs(start[0]), abs(target[0]), abs(start[1]), abs(target[1]))
        np.testing.assert_allclose(np.column_stack(path(t)), expected, rtol=0, atol=1e-12 * scale)
    assert braked > 10


def test_a_move_ruckig_cannot_stretch_is_its_time_optimal_move_then_the_target_held():
    """ruckig finds no 12.6 ms profile for this 0.205 rad move from rest to rest (its shortest is 8.4 ms), though it
    could take that long: the move is then ruckig's time-optimal one, the stick held at the target after it."""
    start, target, duration = (0.0, 0.0), (-0.20546491343554205, 0.0), 0.012604224090270972
    assert fresh([start], [target], duration, [Limits()]) is None
    optimal = fresh([start], [target], 0.0, [Limits()])
    assert optimal.duration < duration
    took, path = plan_move(start, target, duration, theta_max=HEAD, limits=Limits())
    assert took == duration
    t = np.linspace(0.0, duration, 64)
    theta, omega = path(t)
    moving = t < optimal.duration
    expected = np.array([optimal.at_time(float(x))[:2] for x in t[moving]])[:, :, 0]
    np.testing.assert_allclose(np.column_stack((theta[moving], omega[moving])), expected, rtol=0, atol=1e-12)
    assert np.all(theta[~moving] == target[0]) and np.all(omega[~moving] == 0.0)
