"""The MuJoCo joint: the simple plant's physics in MuJoCo's terms, and the same strokes played on both."""

import math
from dataclasses import replace

import mujoco
import numpy as np
import pytest

import drumstroke
from drumstroke.errors import ParameterError
from drumstroke.model import Stick
from drumstroke.robot.controllers import controller
from drumstroke.robot.metrics import AUDIBLE_SPEED, match_onsets, metrics
from drumstroke.robot.mujoco_plant import contact_solref, head_gap, mujoco_drop_test, mujoco_model
from drumstroke.robot.plant import Plant, contact_gains, drop_test
from drumstroke.robot.track import reference, track

FREE = replace(Plant(), viscous=0.0, coulomb=0.0)  # no friction: the drop and energy checks


def state(model, theta, omega=0.0):
    """A fresh MjData at θ (rad), ω (rad/s), its derived quantities computed."""
    data = mujoco.MjData(model)
    data.qpos[0], data.qvel[0] = theta, omega
    mujoco.mj_forward(model, data)
    return data


# --- the model: inertia, gravity, geometry, energy ------------------------------------------------------------------

def test_the_joint_inertia_is_the_plants():
    model = mujoco_model(Plant(), 0.86)
    data = state(model, 0.2)
    full = np.zeros((1, 1))
    mujoco.mj_fullM(model, data, full)
    assert full[0, 0] == pytest.approx(Plant().inertia, rel=1e-9)
    assert model.dof_armature[0] == pytest.approx(20.0**2 * 1e-6, rel=1e-12)


def test_a_known_torque_in_zero_gravity_accelerates_it_by_torque_over_inertia():
    model = mujoco_model(FREE, 0.86)
    model.opt.gravity[:] = 0.0
    data = mujoco.MjData(model)
    data.qpos[0], data.ctrl[0] = 0.3, 0.5
    mujoco.mj_forward(model, data)
    assert data.qacc[0] == pytest.approx(0.5 / FREE.inertia, rel=1e-9)


@pytest.mark.parametrize("theta", [1.2, 0.5, 0.0, -0.2, FREE.head + 1e-3])
def test_free_fall_is_the_simple_plants_gravity(theta):
    data = state(mujoco_model(FREE, 0.86), theta)
    assert data.ncon == 0
    assert data.qacc[0] == pytest.approx(-FREE.gravity_torque * math.cos(theta) / FREE.inertia, rel=1e-9)


def test_the_tip_touches_the_head_exactly_at_theta_max_and_the_gap_is_mujocos_distance():
    model = mujoco_model(FREE, 0.86)
    head = FREE.head
    assert state(model, head + 1e-9).ncon == 0
    assert state(model, head - 1e-9).ncon == 1
    for theta in (head - 1e-4, head - 3e-3):
        data = state(model, theta)
        assert data.ncon == 1
        assert data.contact.dist[0] == pytest.approx(head_gap(FREE, theta), rel=1e-9)
    assert head_gap(FREE, head) == pytest.approx(0.0, abs=1e-15)


def test_energy_is_conserved_in_a_frictionless_swing_without_the_head():
    """Dropped from level past the vertical and back: ½Jω² + m·g·k·sin θ stays within 1e-12 J over 1 s."""
    model = mujoco_model(FREE, 0.86)
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    data = mujoco.MjData(model)
    energy, peak = [], 0.0
    for _ in range(round(1.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
        theta, omega = data.qpos[0], data.qvel[0]
        energy.append(0.5 * FREE.inertia * omega**2 + FREE.gravity_torque * math.sin(theta))
        peak = max(peak, 0.5 * FREE.inertia * omega**2)
    assert peak > 0.02  # it did swing through (≈ 0.021 J at the bottom)
    assert np.ptp(energy) < 1e-12


# --- the head: drop test -------------------------------------------------------------------------------------------

def first_bounce(model):
    """Drop from level, motor off: (speed in, speed out, contact time) from MuJoCo's own contact list."""
    data = mujoco.MjData(model)
    step = model.opt.timestep
    touching, speed_in, steps = False, None, 0
    for _ in range(round(0.5 / step)):
        before = data.qvel[0]
        mujoco.mj_step(model, data)
        mujoco.mj_forward(model, data)  # the contact list of the state just reached
        if data.ncon and not touching:
            touching, speed_in = True, -before
        if touching:
            if not data.ncon:
                return speed_in, data.qvel[0], steps * step
            steps += 1
    raise AssertionError("no bounce")


@pytest.mark.parametrize("cor", [0.5, 0.86, 0.95])
def test_a_dropped_stick_rebounds_with_the_heads_restitution_after_a_few_ms(cor):
    speed_in, speed_out, contact = first_bounce(mujoco_model(FREE, cor))
    assert speed_out / speed_in == pytest.approx(cor, rel=0.02)
    assert 0.003 <= contact <= 0.006
    assert contact == pytest.approx(FREE.contact_time, abs=2e-4)  # to a few steps of 25 µs
    fall = math.sqrt(2.0 * FREE.gravity_torque * -math.sin(FREE.head) / FREE.inertia)  # energy, level to head
    assert speed_in == pytest.approx(fall, rel=1e-3)
    drop = mujoco_drop_test(FREE, cor)  # the module's own contact log, the meeting located within the step
    assert drop.speed_in == pytest.approx(fall, rel=1e-9)
    assert drop.restitution == pytest.approx(cor, rel=1e-3)
    assert drop.contact_time == pytest.approx(FREE.contact_time, rel=1e-4)
    simple = drop_test(FREE, cor)
    assert drop.restitution == pytest.approx(simple.speed_out / fall, rel=0.01)  # the simple plant's true ratio


def test_the_head_is_a_spring_that_carries_the_motors_push_as_the_simple_plants_does():
    """Pressing with 0.5 N·m, the tip settles δ = (τ + m·g·k·cos θ)/K into the head, K the simple plant's."""
    model = mujoco_model(FREE, 0.86)
    data = mujoco.MjData(model)
    data.qpos[0], data.ctrl[0] = FREE.head, -0.5
    for _ in range(round(0.3 / model.opt.timestep)):  # many contact periods: it rests
        mujoco.mj_step(model, data)
    stiffness, _ = contact_gains(FREE, 0.86)
    expected = (0.5 + FREE.gravity_torque * math.cos(FREE.head)) / stiffness
    assert FREE.head - data.qpos[0] == pytest.approx(expected, rel=0.01)


def test_the_calibration_is_cached_and_independent_of_friction():
    assert contact_solref(FREE, 0.86) is contact_solref(Plant(), 0.86)
    stiffness, damping = (-v for v in contact_solref(FREE, 0.86))
    assert stiffness > 0.0 and damping > 0.0


@pytest.mark.parametrize("cor", [0.02, 0.1])
def test_a_dead_head_takes_more_than_critical_damping_and_still_rebounds_as_asked(cor):
    """The clamped spring lets go with energy left, so c < 0.12 needs ζ > 1 (the simple plant cannot: brentq fails)."""
    drop = mujoco_drop_test(FREE, cor)
    assert drop.restitution == pytest.approx(cor, rel=0.01)
    assert drop.contact_time == pytest.approx(FREE.contact_time, rel=1e-3)


def test_with_no_restitution_the_head_holds_the_stick():
    drop = mujoco_drop_test(FREE, 0.0)
    assert drop.speed_in > 3.0 and drop.speed_out == 0.0 and drop.contact_time == math.inf


# --- the same strokes on both plants -------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def free_bounce():
    return reference(drumstroke.simulate("free-bounce"))


@pytest.fixture(scope="module", params=["impedance", "pi"])
def both(request, free_bounce):
    c = controller(request.param)
    return track(free_bounce, c), track(free_bounce, c, engine="mujoco")


def audible(played):
    return played.onsets[played.onset_speed >= AUDIBLE_SPEED]


def test_the_played_record_is_the_simple_plants_shape(both, free_bounce):
    simple, played = both
    assert played.plant == "mujoco" and simple.plant == "simple"
    assert played.controller == simple.controller
    n = len(free_bounce.t)
    assert played.theta.shape == played.omega.shape == played.torque.shape == (n,)
    assert played.theta[0] == free_bounce.theta[0] and played.omega[0] == free_bounce.omega[0]
    assert np.all(np.diff(played.onsets) > 0) and np.all(played.onset_speed >= 0)
    assert np.abs(played.torque).max() <= played.max_torque


def test_both_plants_play_the_same_onsets_within_half_a_millisecond(both):
    """Audible onsets: as many within 10 % (or 2), 90 % matched within 2 ms, the median under 0.5 ms.

    Measured at the time of writing: impedance 28 and 28, 27 matched, max 0.42 ms; PI (3, 2)
    15 and 15, all matched, max 0.25 ms.
    """
    simple, played = both
    a, b = audible(simple), audible(played)
    assert abs(len(a) - len(b)) <= max(2, round(0.1 * len(a)))
    match = match_onsets(a, b, window=0.002)
    assert np.mean(match >= 0) >= 0.9
    errors = np.abs(b[match[match >= 0]] - a[match >= 0])
    assert np.median(errors) < 0.5e-3 and errors.max() < 2e-3
    assert np.sqrt(np.mean((played.theta - simple.theta) ** 2)) < 2e-3  # rad, over the whole stroke


def test_both_plants_score_the_same(both):
    """Kept fractions within 0.1 (measured: impedance 1.00 and 1.00, PI 0.44 and 0.44), RMS error within 5 %."""
    simple, played = (metrics(p) for p in both)
    assert simple.reference_onsets == played.reference_onsets
    assert played.kept_fraction == pytest.approx(simple.kept_fraction, abs=0.1)
    assert played.rms_error == pytest.approx(simple.rms_error, rel=0.05)


# --- bad input -----------------------------------------------------------------------------------------------------

def test_a_reference_for_another_head_is_refused(free_bounce):
    other = Plant(stick=Stick(pivot_height=0.08))
    with pytest.raises(ParameterError, match=r"the reference's head \(-0\.262255 rad\) is not the plant's"):
        track(free_bounce, controller("impedance"), other, engine="mujoco")


def test_what_is_not_a_reference_is_refused():
    with pytest.raises(ParameterError, match="reference must be a one-stick drumstroke Trajectory"):
        track(drumstroke.simulate("free-bounce"), controller("pi"), engine="mujoco")


@pytest.mark.parametrize("kwargs, message", [
    ({"plant": "plant", "cor": 0.86}, "plant must be a drumstroke.robot.plant.Plant"),
    ({"plant": Plant(), "cor": 1.5}, r"cor must be in \[0, 1\], got 1.5"),
    ({"plant": Plant(), "cor": 0.86, "rate": 5.0}, r"rate must be in \[10, 100000\] Hz, got 5.0"),
])
def test_bad_model_parameters_are_refused(kwargs, message):
    with pytest.raises(ParameterError, match=message):
        mujoco_model(**kwargs)
