"""The kick pedal's beater (drumstroke.kit.pedal) against oracles worked out here, not by the module.

The oracles: the harmonic closed form written out afresh from the pedal's parameters (κ_eff from
κ, m·g·l_c and the chord of sin φ), scipy's solve_ivp (DOP853, rtol 1e-12) with events for the
hybrid system, the Zeno series summed term by term, and the physics' invariants (energy in flight,
restitution at impacts).
"""

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from drumstroke.design import Unreachable
from drumstroke.errors import ParameterError, SimulationError
from drumstroke.kit.pedal import FootForce, Pedal, beater, design_pedal, simulate_pedal

PEDAL = Pedal()


def stiffness(pedal):
    """κ_eff from the parameters, as the model's equation defines it."""
    chord = (math.sin(pedal.phi_head) - math.sin(pedal.phi_rest)) / (pedal.phi_head - pedal.phi_rest)
    return pedal.spring - pedal.gravity * chord


def rate(pedal):
    return math.sqrt(stiffness(pedal) / pedal.inertia)


def equilibrium(pedal, force):
    return pedal.phi_rest + pedal.arm * force / stiffness(pedal)


def hybrid_ivp(pedal, pieces, t_end, phi0=None, nonlinear=False):
    """The hybrid system integrated by solve_ivp with a head event: impact times, speeds before (rad/s)."""
    k_eff = stiffness(pedal)
    spans = [(a, b, f) for (a, f), (b, _) in zip(pieces, [*pieces[1:], (t_end, 0.0)])]

    def rhs_for(force):
        if nonlinear:  # the spring's preload holds φ_rest against the exact gravity torque
            return lambda t, y: [y[1], (pedal.arm * force - pedal.spring * (y[0] - pedal.phi_rest)
                                        + pedal.gravity * (math.sin(y[0]) - math.sin(pedal.phi_rest))) / pedal.inertia]
        return lambda t, y: [y[1], (pedal.arm * force - k_eff * (y[0] - pedal.phi_rest)) / pedal.inertia]

    def hit(t, y):
        return y[0] - pedal.phi_head

    hit.terminal, hit.direction = True, 1.0
    y = [pedal.phi_rest if phi0 is None else phi0, 0.0]
    times, speeds = [], []
    for a, b, force in spans:
        t = a
        while t < b:
            solution = solve_ivp(rhs_for(force), (t, b), y, method="DOP853", rtol=1e-12, atol=1e-14, events=hit)
            if solution.t_events[0].size:
                t, (phi, omega) = solution.t_events[0][0], solution.y_events[0][0]
                times.append(t)
                speeds.append(omega)
                if len(times) > 100:
                    raise RuntimeError("the oracle met a Zeno sequence: pick forces that do not bury the beater")
                y = [pedal.phi_head, -pedal.cor * omega]
            else:
                t, y = b, list(solution.y[:, -1])
    return np.array(times), np.array(speeds)


# --- the pedal ---------------------------------------------------------------------------------------------------------


def test_beater_numbers_from_masses():
    inertia, gravity = beater(head_mass=0.08, length=0.2, shaft_mass=0.05, shaft_length=0.24)
    assert inertia == pytest.approx(0.08 * 0.2**2 + 0.05 * 0.24**2 / 3, rel=1e-15)
    assert gravity == pytest.approx(9.81 * (0.08 * 0.2 + 0.05 * 0.12), rel=1e-15)
    steel = 7850 * math.pi * 0.006**2 / 4 * 0.21
    assert beater()[0] == pytest.approx(0.07 * 0.19**2 + steel * 0.21**2 / 3, rel=1e-15)
    assert (PEDAL.inertia, PEDAL.gravity) == beater()


def test_defaults_are_a_real_pedal():
    assert 0.1 <= PEDAL.return_time <= 0.2  # s from the head back to rest, foot off
    assert PEDAL.frequency == pytest.approx(rate(PEDAL), rel=1e-15)
    assert PEDAL.stiffness == pytest.approx(stiffness(PEDAL), rel=1e-15)
    assert PEDAL.balance == pytest.approx(stiffness(PEDAL) * 1.0 / PEDAL.arm, rel=1e-15)


@pytest.mark.parametrize("rest, head", [(-1.0, 0.0), (-0.6, 0.1), (-1.4, -0.2), (-0.3, 0.4)])
def test_gravity_error_is_the_chords_largest_error(rest, head):
    pedal = Pedal(phi_rest=rest, phi_head=head)
    phi = np.linspace(rest, head, 200_001)
    chord = (math.sin(head) - math.sin(rest)) / (head - rest)
    error = pedal.gravity * np.abs(np.sin(phi) - math.sin(rest) - chord * (phi - rest))
    assert pedal.gravity_error == pytest.approx(error.max(), rel=1e-9)


@pytest.mark.parametrize("changes, match", [
    ({"cor": 1.5}, r"cor must be in \[0, 1\], got 1.5"),
    ({"cor": -0.1}, r"cor must be in \[0, 1\]"),
    ({"cor": float("nan")}, r"cor must be a finite number"),
    ({"inertia": -1.0}, r"inertia must be in \(0, 0.1\] kg m\^2, got -1.0"),
    ({"phi_rest": 0.1}, r"phi_rest must be in \(-1.5708, 0\) rad, got 0.1"),
    ({"spring": 0.1}, r"spring must be in \(0.15\d*, 100\] N m/rad .* got 0.1"),
    ({"length": 0.0}, r"length must be in \(0, 0.5\] m"),
    ({"max_force": "a lot"}, r"max_force must be a number"),
])
def test_pedal_refuses_bad_numbers(changes, match):
    with pytest.raises(ParameterError, match=match):
        dataclasses.replace(PEDAL, **changes)


# --- the forward simulation against the closed form and solve_ivp -------------------------------------------------------


@pytest.mark.parametrize("force", [15.0, 40.0, 100.0, 280.0])
def test_first_impact_under_constant_force_is_the_closed_form(force):
    omega = rate(PEDAL)
    e = equilibrium(PEDAL, force)
    amplitude = e - PEDAL.phi_rest  # from rest: φ(t) = e − A·cos Ωt
    t_star = math.acos((e - PEDAL.phi_head) / amplitude) / omega
    speed = omega * math.sqrt(amplitude**2 - (e - PEDAL.phi_head) ** 2)
    stroke = simulate_pedal(force, t_end=t_star + 1e-3)
    assert stroke.impacts.t[0] == pytest.approx(t_star, abs=1e-12)
    assert -stroke.impacts.omega[0] == pytest.approx(speed, rel=1e-12)
    assert stroke.levels[0] == pytest.approx(20 * math.log10(speed * PEDAL.length), abs=1e-10)
    # before it, the motion is the cosine, exactly, at any time
    t = np.linspace(0.0, t_star, 1001)[:-1]
    phi, phidot = stroke.angle(t)
    np.testing.assert_allclose(phi, e - amplitude * np.cos(omega * t), rtol=0, atol=1e-14)
    np.testing.assert_allclose(phidot, amplitude * omega * np.sin(omega * t), rtol=0, atol=1e-12)


def test_a_weak_press_never_reaches_the_head():
    force = 0.49 * PEDAL.balance  # φ_eq short of midway: the swing turns back before the head
    stroke = simulate_pedal(force, t_end=2.0)
    assert len(stroke.impacts) == 0
    phi, _ = stroke.angle(np.linspace(0, 2, 4001))
    e = equilibrium(PEDAL, force)
    assert phi.max() == pytest.approx(2 * e - PEDAL.phi_rest, abs=1e-6)


PIECES = [(0.0, 18.0), (0.3, 13.0), (0.52, 20.0), (0.75, 15.0), (0.9, 19.0)]
"""Forces under the balance (22 N): the beater reaches the head and is pulled off it, no Zeno tail."""


@pytest.mark.parametrize("cor", [0.0, 0.2, 0.6])
def test_forced_run_matches_solve_ivp(cor):
    pedal = dataclasses.replace(PEDAL, cor=cor)
    times, speeds = hybrid_ivp(pedal, PIECES, 1.2)
    stroke = simulate_pedal(PIECES, pedal, t_end=1.2)
    assert len(times) >= 2
    assert len(stroke.impacts) == len(times)
    np.testing.assert_allclose(stroke.impacts.t, times, rtol=0, atol=1e-9)
    np.testing.assert_allclose(-stroke.impacts.omega, speeds, rtol=1e-8)


def test_samples_are_exact_at_the_control_rate():
    force = 60.0
    stroke = simulate_pedal(force, t_end=0.06)  # before the first impact (0.0676 s)
    trajectory = stroke.sample(1000.0)
    e, omega = equilibrium(PEDAL, force), rate(PEDAL)
    t = np.arange(61) / 1000.0
    np.testing.assert_array_equal(trajectory.t, t)
    np.testing.assert_allclose(trajectory.theta, -(e - (e - PEDAL.phi_rest) * np.cos(omega * t)), rtol=0, atol=1e-14)
    np.testing.assert_allclose(trajectory.omega, -(e - PEDAL.phi_rest) * omega * np.sin(omega * t), rtol=0,
                               atol=1e-12)


def test_trajectory_conventions():
    stroke = simulate_pedal(PIECES, t_end=1.2)
    trajectory = stroke.sample(2000.0)
    assert trajectory.theta_max == -PEDAL.phi_head
    assert np.all(trajectory.theta >= trajectory.theta_max)  # the head is a lower bound on θ = −φ
    assert np.all(trajectory.impacts.omega < 0) and np.all(trajectory.omega_after >= 0)
    np.testing.assert_allclose(trajectory.impacts.level_db,
                               20 * np.log10(-trajectory.impacts.omega * PEDAL.length), rtol=0, atol=1e-12)
    theta, omega = trajectory.state(stroke.impacts.t)  # just after each impact: on the head, leaving
    np.testing.assert_allclose(theta, -PEDAL.phi_head, atol=1e-14)
    np.testing.assert_allclose(omega, trajectory.omega_after, rtol=1e-12)


# --- invariants ----------------------------------------------------------------------------------------------------------


def harmonic_energy(pedal, phi, phidot, force):
    return 0.5 * pedal.inertia * phidot**2 + 0.5 * stiffness(pedal) * (phi - equilibrium(pedal, force)) ** 2


def test_energy_is_conserved_in_flight_and_never_gained_at_impacts():
    pedal = dataclasses.replace(PEDAL, cor=0.6)
    stroke = simulate_pedal(PIECES, pedal, t_end=1.2)
    edges = [t for t, _ in PIECES] + [1.2]
    cuts = np.unique(np.concatenate([edges, stroke.impacts.t]))
    force = FootForce(PIECES)
    for a, b in zip(cuts[:-1], cuts[1:]):
        t = np.linspace(a, b, 50)[1:-1]
        energy = harmonic_energy(pedal, *stroke.angle(t), force(t))
        assert np.ptp(energy) <= 1e-12 * max(energy.max(), 1e-3)
    for t, omega, after in zip(stroke.impacts.t, stroke.impacts.omega, stroke.omega_after):
        f = force(t)
        before = harmonic_energy(pedal, pedal.phi_head, -omega, f)
        later = harmonic_energy(pedal, pedal.phi_head, after, f)
        assert later <= before
        assert after / -omega == pytest.approx(0.6, rel=1e-15)  # ω⁺ = −c·ω⁻, exactly


# --- Zeno, rest, lift-off ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("cor, force", [(0.2, 60.0), (0.5, 40.0), (0.8, 150.0)])
def test_zeno_accumulation_is_the_series_sum(cor, force):
    """Under a constant force each flight leaving the head at u comes back at u (energy), after
    (2/Ω)·atan(u/(Ω·p)), p = φ_eq − φ_head: the flights after an impact at v sum to Σ_k (2/Ω)·atan(c^k·v/(Ωp))."""
    pedal = dataclasses.replace(PEDAL, cor=cor)
    omega, e = rate(pedal), equilibrium(pedal, force)
    amplitude, p = e - pedal.phi_rest, e - pedal.phi_head
    first = math.acos(p / amplitude) / omega
    speed = omega * math.sqrt(amplitude**2 - p**2)
    terms = []
    u = cor * speed
    while u > 1e-300:
        terms.append(2.0 / omega * math.atan(u / (omega * p)))
        u *= cor
    stroke = simulate_pedal(force, pedal, t_end=1.0)
    assert stroke.rests.tolist()[0][1] == 1.0 and len(stroke.rests) == 1
    assert stroke.rest_time == pytest.approx(first + math.fsum(terms), abs=1e-12)
    # the listed bounces: each speed c times the last, each flight the series' term
    n = len(stroke.impacts)
    np.testing.assert_allclose(stroke.impacts.omega[1:] / stroke.impacts.omega[:-1], cor, rtol=1e-12)
    np.testing.assert_allclose(np.diff(stroke.impacts.t), terms[:n - 1], rtol=1e-9, atol=1e-15)
    assert stroke.omega_after[-1] < 1e-6  # listed down to the Zeno floor


def test_no_restitution_rests_at_once_and_elastic_bounces_forever():
    stroke = simulate_pedal(60.0, dataclasses.replace(PEDAL, cor=0.0), t_end=0.5)
    assert len(stroke.impacts) == 1 and stroke.rest_time == stroke.impacts.t[0]
    elastic = simulate_pedal(60.0, dataclasses.replace(PEDAL, cor=1.0), t_end=0.5)
    e, omega = equilibrium(PEDAL, 60.0), rate(PEDAL)
    speed = -elastic.impacts.omega[0]
    period = 2.0 / omega * math.atan(speed / (omega * (e - PEDAL.phi_head)))
    np.testing.assert_allclose(np.diff(elastic.impacts.t), period, rtol=1e-9)
    np.testing.assert_allclose(elastic.impacts.omega, -speed, rtol=1e-12)
    assert elastic.rest_time is None


def test_rest_then_lift_off_when_the_net_torque_reverses():
    low = 0.5 * PEDAL.balance  # under the spring's pull at the head: the beater leaves it
    stroke = simulate_pedal([(0.0, 80.0), (0.3, low)], t_end=0.3 + 0.9 * 2 * math.pi / rate(PEDAL))
    assert stroke.rests[0, 1] == 0.3  # lifts off exactly when the force drops
    e, omega = equilibrium(PEDAL, low), rate(PEDAL)
    t = np.linspace(0.3, stroke.t_end, 500)
    phi, _ = stroke.angle(t)
    np.testing.assert_allclose(phi, e + (PEDAL.phi_head - e) * np.cos(omega * (t - 0.3)), rtol=0, atol=1e-14)
    # from rest at the head it comes back after a whole period, grazing it at zero speed: no impact
    period = 2 * math.pi / omega
    again = simulate_pedal([(0.0, 80.0), (0.3, low)], t_end=0.3 + 1.5 * period)
    assert again.impacts.t[-1] < 0.3
    phi, phidot = again.angle(0.3 + period)
    assert phi == pytest.approx(PEDAL.phi_head, abs=1e-14) and phidot == pytest.approx(0.0, abs=1e-12)


def test_limits_raise_simulation_errors():
    with pytest.raises(SimulationError, match="past the horizontal"):
        simulate_pedal([(0.0, 100.0), (0.2, 0.0)], t_end=0.6)  # let go at the head: it swings 2 rad back
    with pytest.raises(SimulationError, match="more than max_impacts = 50 impacts"):
        simulate_pedal(60.0, dataclasses.replace(PEDAL, cor=1.0), t_end=20.0, max_impacts=50)


@pytest.mark.parametrize("call, match", [
    (lambda: simulate_pedal(10.0, t_end=-1.0), r"t_end must be in \[1e-06, 3600\] s, got -1.0"),
    (lambda: simulate_pedal(10.0, t_end=float("nan")), r"t_end must be a finite number"),
    (lambda: simulate_pedal(10.0, t_end=1.0, phi0=0.2), r"phi0 must be in \(-1.5708, 0\] rad, got 0.2"),
    (lambda: simulate_pedal(float("nan"), t_end=1.0), r"pieces\[0\] force must be a finite number"),
    (lambda: simulate_pedal([(0.2, 1.0), (0.1, 2.0)], t_end=1.0), r"pieces\[1\] start must be after"),
    (lambda: simulate_pedal([(-0.1, 1.0)], t_end=1.0), r"pieces\[0\] start must be in \[0, 3600\] s"),
    (lambda: simulate_pedal([(0.1, 1.0, 3.0)], t_end=1.0), r"pieces must be a non-empty sequence"),
    (lambda: simulate_pedal(10.0, "pedal", t_end=1.0), r"pedal must be a drumstroke.kit.pedal.Pedal"),
])
def test_simulation_refuses_bad_input(call, match):
    with pytest.raises(ParameterError, match=match):
        call()


# --- the inverse ---------------------------------------------------------------------------------------------------------


def check_design(design, times, levels):
    """The design's force played by solve_ivp hits the notes; forces within the foot's range; end as asked."""
    pieces = [(p.start, p.force) for p in design.pieces]
    t_ivp, speeds = hybrid_ivp(PEDAL, pieces, design.times[-1] + 1e-3)
    np.testing.assert_allclose(t_ivp[:len(times)], times, rtol=0, atol=1e-8)
    np.testing.assert_allclose(20 * np.log10(speeds[:len(times)] * PEDAL.length), levels, atol=1e-6)


def test_single_note_is_the_closed_form():
    design = design_pedal([0.3], [15.0])
    press = design.pieces[1]
    speed = 10 ** (15 / 20) / PEDAL.length
    e = equilibrium(PEDAL, press.force)
    amplitude, p = e - PEDAL.phi_rest, e - PEDAL.phi_head
    assert rate(PEDAL) * math.sqrt(amplitude**2 - p**2) == pytest.approx(speed, rel=1e-12)
    assert press.end - press.start == pytest.approx(math.acos(p / amplitude) / rate(PEDAL), abs=1e-13)
    check_design(design, [0.3], [15.0])


@pytest.mark.parametrize("times, levels", [([0.3, 0.36], [10.0, 10.0]), ([0.3, 0.4], [15.0, 10.0]),
                                           ([0.4, 0.55], [8.0, 14.0]), ([0.3, 0.42, 0.52], [12.0, 10.0, 12.0])])
def test_double_kicks_are_played_by_an_independent_integrator(times, levels):
    design = design_pedal(times, levels)
    check_design(design, times, levels)
    rises = [p for p in design.pieces if p.phase == "rise"]
    assert len(rises) == len(times) - 1


def test_release_rests_at_the_rest_angle_and_bury_on_the_head():
    released = design_pedal([0.3, 0.4], [15.0, 10.0], end="release")
    assert len(released.stroke.impacts) == 2
    phi, phidot = released.stroke.angle(released.stroke.t_end)
    assert phi == pytest.approx(PEDAL.phi_rest, abs=1e-12) and phidot == pytest.approx(0.0, abs=1e-10)
    buried = design_pedal([0.3, 0.4], [15.0, 10.0], end="bury", hold=120.0)
    assert buried.pieces[-1].force == 120.0 and buried.stroke.rest_time is not None
    after = buried.stroke.impacts.level_db[2:]
    np.testing.assert_allclose(np.diff(after), 20 * math.log10(PEDAL.cor), atol=1e-9)  # the buzz dies by c


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(first=st.floats(0.25, 1.5), gap=st.floats(0.06, 0.15), levels=st.lists(st.floats(-5.0, 20.0), min_size=1,
                                                                                  max_size=2),
       end=st.sampled_from(["release", "bury"]), cor=st.floats(0.0, 0.6))
def test_designs_play_their_notes(first, gap, levels, end, cor):
    pedal = dataclasses.replace(PEDAL, cor=cor)
    times = [first, first + gap][:len(levels)]
    try:
        design = design_pedal(times, levels, pedal, end=end)
    except Unreachable:
        assume(False)
    impacts = design.stroke.impacts
    np.testing.assert_allclose(impacts.t[:len(times)], times, rtol=0, atol=1e-9)
    np.testing.assert_allclose(impacts.level_db[:len(times)], levels, rtol=0, atol=1e-6)
    assert all(0.0 <= p.force <= pedal.max_force for p in design.pieces)
    phi, _ = design.stroke.angle(np.linspace(0.0, design.stroke.t_end, 3001))
    assert phi.min() >= pedal.phi_rest - 1e-12 and phi.max() <= pedal.phi_head  # within the pedal's travel


@pytest.mark.parametrize("times, levels, match", [
    ([0.3], [25.0], r"note 0 \(t = 0.3 s, 25 dB\) needs a press of 57\d.\d N from rest; the pedal's max_force is 300 N"),
    ([0.02], [10.0], r"note 0 \(t = 0.02 s, 10 dB\) needs a press of 0.10\d+ s from rest"),
    ([0.3, 0.36], [5.0, 10.0], r"note 1 \(t = 0.36 s, 10 dB\) needs a press of 36\d.\d N from the rebound"),
])
def test_unreachable_notes_say_what_they_need(times, levels, match):
    with pytest.raises(Unreachable, match=match) as raised:
        design_pedal(times, levels)
    assert raised.value.note == len(times) - 1


def test_a_dead_beater_needs_half_a_period_to_come_back():
    dead = dataclasses.replace(PEDAL, cor=0.0)
    half = math.pi / rate(dead)
    with pytest.raises(Unreachable, match=r"note 1 .* comes 0.1 s after note 0; .*\(c = 0\) takes half a period") as raised:
        design_pedal([0.3, 0.4], [10.0, 10.0], dead)
    assert raised.value.nearest_time == pytest.approx(0.3 + half, rel=1e-12)
    check = design_pedal([0.3, 0.3 + half + 0.05], [10.0, 10.0], dead)
    np.testing.assert_allclose(check.stroke.impacts.t, [0.3, 0.35 + half], atol=1e-9)


@pytest.mark.parametrize("call, match", [
    (lambda: design_pedal([0.3, float("nan")], [1.0, 1.0]), r"times\[1\] must be a finite number"),
    (lambda: design_pedal([0.3, 0.3], [1.0, 1.0]), r"times\[1\] must be at least 0.001 s after times\[0\]"),
    (lambda: design_pedal([0.4, 0.3], [1.0, 1.0]), r"times\[1\] must be at least"),
    (lambda: design_pedal([0.3], [1.0, 2.0]), r"times and levels must be two arrays of one length"),
    (lambda: design_pedal([0.3], [99.0]), r"levels\[0\] must be a finite number in \[-60, 40\] dB"),
    (lambda: design_pedal([0.3], [1.0], end="kick"), r"end must be one of 'release', 'bury'"),
    (lambda: design_pedal([0.3], [1.0], end="bury", hold=1.0), r"hold must be in \[21.99\d*, 300\] N"),
    (lambda: design_pedal([0.3], [1.0], tail=-1.0), r"tail must be in \(0, 60\] s"),
])
def test_design_refuses_bad_input(call, match):
    with pytest.raises(ParameterError, match=match):
        call()


# --- the model's approximation --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("level, late, off", [(5.0, 2e-3, 0.3), (10.0, 6e-4, 0.1), (15.0, 2e-4, 0.03)])
def test_linearised_gravity_costs_little_from_mezzo_forte_up(level, late, off):
    """The exact gravity torque (solve_ivp) against the chord: a designed note lands within ``late`` s, ``off`` dB."""
    design = design_pedal([0.4], [level])
    press = [(p.start, p.force) for p in design.pieces[:2]]  # rest, then the press held on past the note
    times, speeds = hybrid_ivp(PEDAL, press, 0.41, nonlinear=True)
    assert abs(times[0] - 0.4) < late
    assert abs(20 * math.log10(speeds[0] * PEDAL.length) - level) < off
