"""The robot joint on its own: drumhead contact, energy, gravity, motor limits, encoder, parameters.

Oracles are closed forms of the joint equation J·θ̈ = τ − m·g·k·cos θ − b·θ̇ − τ_c·sign θ̇ + τ_h:
free fall from level reaches the head at √(2·m·g·k·(−sin θ_head)/J); with no friction and no contact
½·J·ω² + m·g·k·sin θ is constant; the motor's torque–speed line with no load gives
ω = ω_max·(1 − exp(−t·τ_max/(J·ω_max))); an undamped contact pressed by a weight W lasts (π + 2·atan(W/(J·ω_n·v)))/ω_n.
"""

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from drumstroke.errors import ParameterError
from drumstroke.model import Stick
from drumstroke.robot.kernel import quantize
from drumstroke.robot.plant import Plant, contact_gains, drop_test, run_plant

RATE = 1000.0
CORS = (0.3, 0.6, 0.86, 0.95)
PLANTS = {
    "default": Plant(),
    "longer stick": Plant(stick=Stick(pivot_to_tip=0.3)),
    "heavier rotor": Plant(rotor_inertia=1e-5),
}


def frictionless(plant):
    return dataclasses.replace(plant, viscous=0.0, coulomb=0.0)


def energy(plant, theta, omega):
    """½·J·ω² + m·g·k·sin θ (J)."""
    return 0.5 * plant.inertia * omega**2 + plant.gravity_torque * np.sin(theta)


def landing_speed(plant, theta0=0.0):
    """|ω| at the head after falling from rest at theta0 with no friction (rad/s): energy conservation."""
    return math.sqrt(2.0 * plant.gravity_torque * (math.sin(theta0) - math.sin(plant.head)) / plant.inertia)


# --- the parameters' closed forms -----------------------------------------------------------------------------------

@pytest.mark.parametrize("plant", PLANTS.values(), ids=PLANTS.keys())
def test_inertia_gravity_and_encoder_step_are_their_closed_forms(plant):
    s = plant.stick
    x, length = s.pivot_to_tip, s.length
    stick = s.mass * (3 * x**2 - 3 * x * length + length**2) / 3  # paper Eq. 1 times m
    assert plant.inertia == pytest.approx(stick + plant.gear_ratio**2 * plant.rotor_inertia, rel=1e-12)
    assert plant.gravity_torque == pytest.approx(s.mass * 9.8 * s.pivot_to_com, rel=1e-12)
    assert plant.head == pytest.approx(-math.asin(s.pivot_height / x), rel=1e-12)
    assert plant.resolution == pytest.approx(2 * math.pi / (plant.encoder_counts * plant.gear_ratio), rel=1e-12)


def test_the_default_joint_has_the_documented_inertia_and_encoder_step():
    plant = Plant()
    # 0.0373 kg · 0.0183 m² (Table 1 stick, Eq. 1) + 20² · 1e-6 kg·m² rotor
    assert plant.inertia == pytest.approx(0.0373 * (3 * 0.27**2 - 3 * 0.27 * 0.39 + 0.39**2) / 3 + 400e-6, rel=1e-12)
    assert plant.resolution == pytest.approx(2 * math.pi / (8192 * 20), rel=1e-12)
    assert Plant(encoder_counts=1024, gear_ratio=50.0).resolution == pytest.approx(2 * math.pi / 51200, rel=1e-12)


@pytest.mark.parametrize("theta", [0.1, -0.2, 1.23456, 7e-5])
def test_the_encoder_reads_the_nearest_step(theta):
    step = Plant().resolution
    reading = quantize(theta, step)
    assert abs(reading - theta) <= step / 2 * (1 + 1e-9)
    assert reading / step == pytest.approx(round(reading / step), abs=1e-9)  # a whole number of steps


# --- the dropped stick ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("plant", PLANTS.values(), ids=PLANTS.keys())
@pytest.mark.parametrize("cor", CORS)
def test_a_dropped_stick_rebounds_with_the_configured_restitution(plant, cor):
    """Measured: restitution within 0.4 %, contact time within 0.4 %; the logged landing speed is up to
    0.6 % below free fall (c = 0.3) because the substep that crosses into the head already feels the damper."""
    drop = drop_test(plant, cor)
    assert drop.restitution == pytest.approx(cor, rel=0.02)
    assert drop.speed_in == pytest.approx(landing_speed(plant), rel=0.01)  # free fall from level
    assert 0.003 <= drop.contact_time <= 0.006
    assert drop.contact_time == pytest.approx(plant.contact_time, rel=0.02)


@pytest.mark.parametrize("plant", PLANTS.values(), ids=PLANTS.keys())
@pytest.mark.parametrize("cor", CORS)
def test_run_plant_with_no_torque_bounces_with_the_configured_restitution(plant, cor):
    free = frictionless(plant)
    stiffness, damping = contact_gains(free, cor)
    log = run_plant(free, stiffness, damping, np.zeros(1500), RATE, theta0=0.0)
    assert len(log.onsets) >= 2
    out = log.release_speed[0]
    assert out / -log.onset_speed[0] == pytest.approx(cor, rel=0.02)
    assert log.release[0] - log.onsets[0] == pytest.approx(plant.contact_time, rel=0.02)
    # the flight after the bounce is a free one: its apex is where ½·J·ω² turns into height, and it
    # lands at the speed it left with
    t = np.arange(1500) / RATE
    flight = (t > log.release[0]) & (t < log.onsets[1])
    apex = math.asin(math.sin(plant.head) + free.inertia * out**2 / (2 * free.gravity_torque))
    assert log.theta[flight].max() == pytest.approx(apex, abs=1e-4)
    assert -log.onset_speed[1] == pytest.approx(out, rel=0.01)
    assert log.onsets[1] > log.release[0]


def test_every_contact_loses_energy_and_the_bounces_die_away():
    plant = Plant()
    stiffness, damping = contact_gains(plant, 0.86)
    log = run_plant(plant, stiffness, damping, np.zeros(3000), RATE, theta0=0.0)
    done = np.isfinite(log.release)
    assert done.sum() >= 5
    assert np.all(log.release_speed[done] < -log.onset_speed[done])  # an impact never adds energy
    assert np.all(np.diff(-log.onset_speed) < 0)  # each landing slower than the one before
    assert np.all(np.diff(log.onsets) > 0) and np.all(log.release[done] > log.onsets[done])


# --- flight: energy and gravity -------------------------------------------------------------------------------------

def test_energy_is_conserved_in_a_frictionless_flight():
    """Measured: relative drift ≈ 1e-14 over 0.47 s at 40 RK4 substeps per 1 ms (the tolerance is 1e-10)."""
    free = frictionless(Plant())
    stiffness, damping = contact_gains(free, 0.86)
    log = run_plant(free, stiffness, damping, np.zeros(600), RATE, theta0=1.2)
    t = np.arange(600) / RATE
    flight = t < log.onsets[0]  # before it reaches the head
    assert flight.sum() > 400 and log.theta[flight].min() < 0.0  # a real fall, most of the way down
    e0 = free.gravity_torque * math.sin(1.2)
    drift = np.abs(energy(free, log.theta[flight], log.omega[flight]) - e0).max() / e0
    assert drift < 1e-10
    # with friction the same fall loses energy at every step
    rubbing = Plant()
    log = run_plant(rubbing, stiffness, damping, np.zeros(400), RATE, theta0=1.2)
    e = energy(rubbing, log.theta, log.omega)
    assert np.all(np.diff(e) < 0)


@pytest.mark.parametrize("theta", [-0.2, 0.0, 0.5, 1.0, 1.4])
def test_gravity_alone_accelerates_the_joint_by_mgk_cos_theta_over_j(theta):
    """From rest, ω after one 1 ms period over the period is the initial θ̈ (measured error ≤ 4.2e-6)."""
    free = frictionless(Plant())
    stiffness, damping = contact_gains(free, 0.86)
    log = run_plant(free, stiffness, damping, np.zeros(2), RATE, theta0=theta)
    expected = -free.gravity_torque * math.cos(theta) / free.inertia
    assert log.omega[1] * RATE == pytest.approx(expected, rel=1e-4)


# --- the motor's limits ---------------------------------------------------------------------------------------------

def test_an_unloaded_motor_follows_its_torque_speed_line_to_the_no_load_speed():
    """No gravity, no friction, a command 50× the limit: ω = ω_max·(1 − exp(−t/T)), T = J·ω_max/τ_max."""
    plant = Plant(stick=Stick(pivot_to_com=0.0), viscous=0.0, coulomb=0.0)
    stiffness, damping = contact_gains(Plant(), 0.86)
    log = run_plant(plant, stiffness, damping, np.full(300, 100.0), RATE, theta0=0.0)
    t = np.arange(300) / RATE
    T = plant.inertia * plant.max_speed / plant.max_torque
    assert log.omega == pytest.approx(plant.max_speed * (1 - np.exp(-t / T)), abs=1e-3 * plant.max_speed)
    assert log.omega.max() <= plant.max_speed
    assert log.omega[-1] > 0.999 * plant.max_speed
    assert np.all(log.torque <= plant.max_torque) and log.torque[0] > 0.9 * plant.max_torque


def test_a_huge_command_lifting_the_stick_is_held_to_the_torque_and_speed_limits():
    plant = Plant()
    stiffness, damping = contact_gains(plant, 0.86)
    log = run_plant(plant, stiffness, damping, np.full(200, 100.0), RATE, theta0=plant.head)
    lifting = log.theta < math.pi / 2  # gravity against the motor until the stick is upright
    assert lifting.sum() > 50
    assert np.all(np.abs(log.torque) <= plant.max_torque)
    assert log.omega[lifting].max() <= plant.max_speed
    assert log.omega[lifting].max() > 0.9 * plant.max_speed  # it was driven near the limit
    # the average torque over a period is at most the line's value at the speed the period starts with
    line = plant.max_torque * (1 - log.omega[lifting] / plant.max_speed)
    assert np.all(log.torque[lifting] <= line + 1e-12)


def test_braking_against_the_motion_gets_the_full_stall_torque():
    plant = Plant()
    stiffness, damping = contact_gains(plant, 0.86)
    log = run_plant(plant, stiffness, damping, np.full(3, -100.0), RATE, theta0=0.5, omega0=30.0)
    assert np.all(log.omega > 0)  # still moving up over the three periods
    assert log.torque == pytest.approx(np.full(3, -plant.max_torque), rel=1e-12)


# --- the head's gains -----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("plant", PLANTS.values(), ids=PLANTS.keys())
def test_contact_gains_are_positive_and_damping_falls_as_restitution_rises(plant):
    gains = [contact_gains(plant, c) for c in CORS]
    assert all(k > 0 and b > 0 for k, b in gains)
    assert np.all(np.diff([b for _, b in gains]) < 0)


@pytest.mark.parametrize("plant", [*PLANTS.values(), Plant(contact_time=0.005)],
                         ids=[*PLANTS.keys(), "longer contact"])
def test_contact_gains_without_loss_are_the_undamped_springs(plant):
    """c = 1: B → 0 and K = J·ω_n², ω_n from the undamped contact pressed by the stick's weight W = m·g·k·cos θ_head.

    Measured: K within 0.06 % of that form; the plain half period K = J·(π/T)² (no weight) is
    0.5–1.4 % below it, as the weight keeps the stick on the head a little longer.
    """
    J, T = plant.inertia, plant.contact_time
    weight = plant.gravity_torque * math.cos(plant.head)
    v = landing_speed(plant)
    omega_n = brentq(lambda w: (math.pi + 2 * math.atan(weight / (J * w * v))) / w - T, 1.0, 1e6)
    k, b = contact_gains(plant, 1.0)
    assert k == pytest.approx(J * omega_n**2, rel=1e-3)
    assert k == pytest.approx(J * (math.pi / T) ** 2, rel=0.015)
    assert k > J * (math.pi / T) ** 2
    assert 0 <= b / (2 * math.sqrt(k * J)) < 1e-3  # ζ


def test_contact_gains_refuse_a_restitution_outside_0_1():
    with pytest.raises(ParameterError, match=r"cor must be in \[0, 1\], got 1.2"):
        contact_gains(Plant(), 1.2)


# --- parameters -----------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("changes, pattern", [
    ({"rotor_inertia": -1e-6}, r"^rotor_inertia must be in \[0, 0.01\] kg m\^2, got -1e-06"),
    ({"max_torque": float("nan")}, r"^max_torque must be a finite number"),
    ({"max_speed": 0.0}, r"^max_speed must be in \(0, 1000\]"),
    ({"gear_ratio": 0.5}, r"^gear_ratio must be in \[1, 1000\]"),
    ({"viscous": float("inf")}, r"^viscous must be a finite number"),
    ({"coulomb": "0.1"}, r"^coulomb must be a number"),
    ({"contact_time": 0.1}, r"^contact_time must be in \[0.0005, 0.05\] s"),
    ({"encoder_counts": 3.5}, r"^encoder_counts must be an integer in \[16, 16777216\], got 3.5"),
    ({"encoder_counts": True}, r"^encoder_counts must be an integer"),
    ({"substeps": 2}, r"^substeps must be an integer in \[4, 1000\], got 2"),
    ({"stick": {"length": 0.4}}, r"^stick must be a drumstroke.Stick"),
])
def test_bad_plant_parameters_are_refused_by_name(changes, pattern):
    with pytest.raises(ParameterError, match=pattern):
        Plant(**changes)


def test_a_plant_table_with_an_unknown_key_is_refused_naming_it():
    with pytest.raises(ParameterError, match=r"^plant has unknown key 'torque'; allowed keys: stick, rotor_inertia"):
        Plant.from_dict({"torque": 1.0})
    with pytest.raises(ParameterError, match=r"^plant.stick has unknown key 'weight'"):
        Plant.from_dict({"stick": {"weight": 0.04}})
    with pytest.raises(ParameterError, match=r"^plant.stick must be a table"):
        Plant.from_dict({"stick": 0.3})
    with pytest.raises(ParameterError, match=r"^plant must be a table"):
        Plant.from_dict([("gear_ratio", 10.0)])
    with pytest.raises(ParameterError, match=r"^max_torque must be in"):
        Plant.from_dict({"max_torque": -2.0})


def test_a_plant_is_read_from_the_plant_table_of_a_toml_file_and_round_trips(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text(
        "[plant]\n"
        "gear_ratio = 50.0\n"
        "max_torque = 5.5\n"
        "encoder_counts = 4096\n"
        "contact_time = 0.004\n"
        "[plant.stick]\n"
        "pivot_to_tip = 0.3\n"
        "mass = 0.05\n"
        "[controller.pi]\n"
        "kp = 1.0\n"
    )
    plant = Plant.from_toml(path)
    assert (plant.gear_ratio, plant.max_torque, plant.encoder_counts, plant.contact_time) == (50.0, 5.5, 4096, 0.004)
    assert plant.stick == Stick(pivot_to_tip=0.3, mass=0.05)
    assert plant.rotor_inertia == Plant().rotor_inertia  # unset keys keep their defaults
    assert Plant.from_dict(plant.to_dict()) == plant
    assert plant.to_dict()["stick"] == Stick(pivot_to_tip=0.3, mass=0.05).to_dict()
    empty = tmp_path / "none.toml"
    empty.write_text("[controller.pi]\nkp = 1.0\n")
    assert Plant.from_toml(empty) == Plant()


def test_an_unreadable_robot_config_is_refused_naming_the_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[plant\n")
    with pytest.raises(ParameterError, match=r"^robot config .*bad.toml' is not valid TOML"):
        Plant.from_toml(bad)
    with pytest.raises(ParameterError, match=r"^robot config .*missing.toml' cannot be read"):
        Plant.from_toml(tmp_path / "missing.toml")
