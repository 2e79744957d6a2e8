"""The one control loop: a whole run is many steps of the stepping code, on either plant.

Oracles: :func:`track` against the same reference stepped by hand through :meth:`ControlLoop.step`,
sample for sample (``np.array_equal``: the same code, so the same floating-point numbers); a run
stopped halfway and resumed against one run over all; the joint's clock against whole periods.
"""

import math

import numpy as np
import pytest

import drumstroke
from drumstroke.errors import ParameterError
from drumstroke.robot.controllers import CONTROLLERS, controller
from drumstroke.robot.loop import ControlLoop, Joint, open_loop
from drumstroke.robot.mujoco_plant import MujocoJoint
from drumstroke.robot.plant import Plant, SimpleJoint, contact_gains, run_plant
from drumstroke.robot.track import reference, track
from drumstroke.trajectory import Trajectory

PLANT = Plant()
BUILT_IN = ("pi", "pid-ff", "impedance")
JOINTS = {"simple": SimpleJoint, "mujoco": MujocoJoint}


@pytest.fixture(scope="module")
def short():
    """The first 0.7 s of free-bounce: two impacts, and the bounce off the second."""
    return reference(drumstroke.simulate("free-bounce", t_end=0.7))


def joint_for(engine, ref, plant=PLANT):
    """The joint ``track`` builds for ``ref`` on ``engine``."""
    start = {"theta0": float(ref.theta[0]), "omega0": float(ref.omega[0]), "start": float(ref.t[0])}
    if engine == "mujoco":
        return MujocoJoint(plant, ref.recipe.cor, rate=ref.rate, **start)
    return SimpleJoint(plant, ref.recipe.cor, **start)


def assert_same_run(log, played):
    assert np.array_equal(log.theta, played.theta)
    assert np.array_equal(log.omega, played.omega)
    assert np.array_equal(log.torque, played.torque)
    assert np.array_equal(log.onsets, played.onsets)
    assert np.array_equal(log.contacts.tip_speed, played.onset_speed)


def test_the_built_in_controllers_are_the_ones_stepped_here():
    assert tuple(CONTROLLERS) == BUILT_IN


@pytest.mark.parametrize("engine", JOINTS)
@pytest.mark.parametrize("name", BUILT_IN)
def test_a_run_stepped_one_period_at_a_time_is_track_sample_for_sample(short, engine, name):
    c = controller(name)
    played = track(short, c, engine=engine)
    loop = ControlLoop(joint_for(engine, short), c, short.rate, capacity=16)  # the log grows on the way
    theta, omega, alpha = c.steer(short)
    for k in range(len(short)):
        loop.step(theta[k], omega[k], alpha[k])
    log = loop.log()
    assert len(loop) == len(short) == len(log.theta)
    assert len(log.onsets) >= 2  # it played the impacts
    assert_same_run(log, played)


@pytest.mark.parametrize("engine", JOINTS)
def test_stepping_can_stop_and_resume(short, engine):
    """Two runs over the halves of the reference, one after the other on one loop, are one run over all of it."""
    c = controller("impedance")
    played = track(short, c, engine=engine)
    theta, omega, alpha = c.steer(short)
    half = len(short) // 2
    loop = ControlLoop(joint_for(engine, short), c, short.rate)
    loop.run(theta[:half], omega[:half], alpha[:half])
    first = loop.log()
    assert np.array_equal(first.theta, played.theta[:half]) and np.array_equal(first.torque, played.torque[:half])
    loop.run(theta[half:], omega[half:], alpha[half:])
    assert_same_run(loop.log(), played)
    assert np.array_equal(first.theta, played.theta[:half])  # a log taken earlier stays as it was


@pytest.mark.parametrize("engine", JOINTS)
def test_a_loop_that_keeps_no_record_plays_the_same_in_constant_memory(short, engine):
    """record=False (a live robot's loop): the same contacts, the same torque each period; no log kept.

    The contacts from the k-th on (``since``) are the last of all of them.
    """
    c = controller("pid-ff")
    played = track(short, c, engine=engine)
    theta, omega, alpha = c.steer(short)
    loop = ControlLoop(joint_for(engine, short), c, short.rate, record=False)
    torque = [loop.step(theta[k], omega[k], alpha[k]) for k in range(len(short))]
    assert len(loop) == len(short) and np.array_equal(torque, played.torque)
    contacts = loop.joint.contacts()
    assert np.array_equal(contacts.t, played.onsets) and len(contacts) >= 2
    later = loop.joint.contacts(1)
    assert np.array_equal(later.t, contacts.t[1:]) and np.array_equal(later.omega, contacts.omega[1:])
    assert len(loop.joint.contacts(len(contacts) + 5)) == 0
    with pytest.raises(ParameterError, match=r"^this loop keeps no log \(it was made with record=False\)"):
        loop.log()
    for bad in (-1, 1.5, True, None):
        with pytest.raises(ParameterError, match=r"^since must be an integer in \[0, inf\)"):
            loop.joint.contacts(bad)


def test_a_loop_that_keeps_no_record_holds_no_memory_per_period():
    """Measured by tracemalloc: what the loop's module still holds after 20,000 periods.

    A loop that records holds 3 × 8 bytes a period (480 kB); one that does not, a few kB whatever
    the length (measured 2.3 kB).
    """
    import tracemalloc

    held = {}
    for record in (False, True):
        loop = ControlLoop(SimpleJoint(PLANT, 0.86, theta0=0.1), controller("pid-ff"), 1000.0, record=record)
        tracemalloc.start()
        try:
            loop.run(np.full(20_000, 0.1), np.zeros(20_000), np.zeros(20_000))
            snapshot = tracemalloc.take_snapshot().filter_traces([tracemalloc.Filter(True, "*robot/loop.py")])
        finally:
            tracemalloc.stop()
        held[record] = sum(stat.size for stat in snapshot.statistics("filename"))
    assert held[False] < 10_000 and held[True] >= 480_000, held


@pytest.mark.parametrize("engine", JOINTS)
def test_both_joints_keep_to_the_plant_interface(short, engine):
    joint = joint_for(engine, short)
    assert isinstance(joint, JOINTS[engine]) and isinstance(joint, Joint)  # plant, theta, omega, advance, contacts
    assert (joint.theta, joint.omega) == (short.theta[0], short.omega[0])
    applied = joint.advance(0.5, 1.0 / short.rate)
    assert 0.0 < applied <= 0.5 and joint.theta != short.theta[0]
    assert len(joint.contacts()) == 0


def test_the_simple_joints_clock_counts_whole_periods():
    """Contacts are timed from the start plus whole periods, not a running sum that drifts."""
    joint = SimpleJoint(PLANT, 0.86, theta0=0.0, start=2.5)
    for _ in range(1000):
        joint.advance(0.0, 1e-3)
    assert joint.time == 2.5 + 1000 * 1e-3
    contacts = joint.contacts()
    free = SimpleJoint(PLANT, 0.86, theta0=0.0)
    for _ in range(1000):
        free.advance(0.0, 1e-3)
    assert len(contacts) >= 2
    assert contacts.t - 2.5 == pytest.approx(free.contacts().t, abs=1e-12)


def test_a_reference_that_starts_later_is_played_on_its_own_clock(short):
    """θ does not depend on the clock; the onsets move with it."""
    t, theta, omega = short.t, short.theta, short.omega
    same = {"theta_max": PLANT.head, "rate": short.rate, "alpha": short.alpha}
    at_zero = Trajectory.from_samples(t, theta, omega, **same)
    later = Trajectory.from_samples(t + 1.0, theta, omega, **same)
    c = controller("pid-ff")
    a, b = track(at_zero, c, cor=0.86), track(later, c, cor=0.86)
    assert np.array_equal(a.theta, b.theta) and len(a.onsets) >= 2
    assert b.onsets - 1.0 == pytest.approx(a.onsets, abs=1e-12)


def test_open_loop_driving_is_the_same_loop_with_the_motor_commanded_directly():
    """run_plant and open_loop are one and the same: drive(τ) steps the loop with τ in place of a law."""
    k, b = contact_gains(PLANT, 0.86)
    torque = np.linspace(-0.2, 0.3, 400)
    log = run_plant(PLANT, k, b, torque, 1000.0, theta0=0.2)
    again = open_loop(SimpleJoint(PLANT, stiffness=k, damping=b, theta0=0.2), torque, 1000.0)
    assert np.array_equal(log.theta, again.theta) and np.array_equal(log.torque, again.torque)
    assert np.all(np.abs(log.torque) <= np.abs(torque) + 1e-15)  # what was applied is at most what was asked


def test_the_played_trajectory_is_the_joints_motion_with_its_contacts_as_impacts(short):
    played = track(short, controller("impedance"))
    trajectory = played.trajectory
    assert isinstance(trajectory, Trajectory) and trajectory.rate == short.rate
    assert np.array_equal(trajectory.t, short.t)
    assert np.array_equal(trajectory.theta, played.theta) and np.array_equal(trajectory.omega, played.omega)
    assert np.array_equal(trajectory.impacts.t, played.onsets)
    assert trajectory.impacts.tip_speed == pytest.approx(played.onset_speed, rel=1e-12)
    released = np.isfinite(played.contacts.release)
    assert np.array_equal(trajectory.omega_after[released], played.contacts.omega_after[released])
    assert trajectory.theta_max == short.theta_max and "impedance" in trajectory.name


def test_a_loop_without_a_controller_is_driven_not_stepped():
    loop = ControlLoop(SimpleJoint(PLANT, 0.86, theta0=0.1), None, 1000.0)
    with pytest.raises(ParameterError, match=r"^this loop has no controller"):
        loop.step(0.1, 0.0, 0.0)
    loop.drive(0.0)
    assert len(loop) == 1


def test_the_mujoco_joint_runs_at_the_rate_it_was_built_for():
    joint = MujocoJoint(PLANT, 0.86, rate=1000.0, theta0=0.1)
    with pytest.raises(ParameterError, match=r"^duration must be the control period the model was built for"):
        joint.advance(0.0, 2e-3)


@pytest.mark.parametrize("call, pattern", [
    (lambda ref: track(ref, controller("pi"), engine="gazebo"), r"^engine must be one of simple, mujoco, got 'gazebo'"),
    (lambda ref: track(ref, "pi"), r"^controller must be a drumstroke.robot.controllers.Controller, got 'pi'"),
    (lambda ref: track(ref, controller("pi"), cor=1.5), r"^cor must be in \[0, 1\], got 1.5"),
    (lambda ref: track(ref, controller("pi"), "plant"), r"^plant must be a drumstroke.robot.plant.Plant"),
    (lambda ref: reference(ref, 5.0), r"^rate must be in \[10, 100000\] Hz, got 5.0"),
    (lambda ref: ControlLoop(SimpleJoint(PLANT, 0.86), None, math.inf), r"^rate must be a finite number"),
    (lambda ref: SimpleJoint(PLANT), r"^give the head either cor or both stiffness and damping"),
])
def test_bad_input_is_refused_by_name(short, call, pattern):
    with pytest.raises(ParameterError, match=pattern):
        call(short)


def test_the_heads_restitution_defaults_to_the_recipes_and_can_be_set(short):
    c = controller("pid-ff")
    assert np.array_equal(track(short, c).theta, track(short, c, cor=short.recipe.cor).theta)
    assert not np.array_equal(track(short, c).theta, track(short, c, cor=0.5).theta)


def test_track_reports_its_progress_without_changing_the_run():
    """Every 1000 periods and at the end; the run is the same whether anyone watches."""
    ref = reference(drumstroke.simulate("free-bounce", t_end=2.5))  # 2501 periods
    fractions = []
    watched = track(ref, controller("impedance"), progress=fractions.append)
    assert fractions == [1000 / 2501, 2000 / 2501, 1.0]
    alone = track(ref, controller("impedance"))
    assert np.array_equal(watched.theta, alone.theta) and np.array_equal(watched.torque, alone.torque)
    assert np.array_equal(watched.onsets, alone.onsets)
