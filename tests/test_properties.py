"""Invariants of simulate() over random valid recipes, and the solver on extreme recipes.

The hypothesis tests draw recipes from the valid domain: either model; θ₀ on the head, at 0 or in
[θ_max + 1 mrad, 1.3]; ω₀ = 0 or 0.1 ≤ |ω₀| ≤ 20 rad/s; c in [0, 1] (0 and 1 included); t_end in
[1 µs, 10 s]; a(t) constant in [−60, 3000], piecewise-linear (1–6 breakpoints, values in [0, 3000]),
pulses (amplitude [0, 400], period [0.05, 1], duty (0.01, 0.99), phase [0, 1]) or a sum of those;
g(t) = 9.8 three times in four, else piecewise-linear in [−5, 60]. Times, periods and phases are
sometimes round numbers, so that edges of different profiles coincide up to round-off as they do in
recipes people write. Magnitudes below 1e-9 are drawn as 0 and start states within a micro-bounce
of the head are left out: those degenerate inputs have explicit tests at the end of this file.

A recipe may legitimately drive the stick past the vertical (SimulationError mentioning the
vertical); such examples are rejected. Every other exception fails the test.

Runs are derandomized and use no example database: CI sees the same examples every time.
"""

import math
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, assume, given, settings
from hypothesis import strategies as st
from scipy.special import ellipk, ellipkinc

import drumstroke
from drumstroke.model import coefficients
from drumstroke.solver import MAX_IMPACTS, ZENO_SPEED

PROPERTY = settings(
    max_examples=120,
    deadline=None,
    derandomize=True,
    database=None,
    # One shrunk counterexample per test and no explain phase: a failing run stays short.
    report_multiple_bugs=False,
    phases=(Phase.explicit, Phase.generate, Phase.shrink),
    suppress_health_check=[HealthCheck.too_slow],
)

STICK = drumstroke.Stick()
THETA_MAX = STICK.theta_max
RATE = 1000.0  # Hz, the robot's control rate
T_END_MIN = 1e-6  # s, the shortest stroke a recipe allows
BREAKPOINT_SPACING = 1e-9  # s, the closest two breakpoints may be
TINY = 1e-9  # magnitudes below this are drawn as exactly 0
# Starts closer to the head than this (rad), or slower than this (rad/s), make micro-bounces: at c = 1
# millions of impacts too small to hear. They have explicit tests.
MICRO_ANGLE = 1e-3
MICRO_SPEED = 0.1

THETA_TOL = 1e-12  # rad: θ is continuous through an impact
SPEED_RTOL, SPEED_ATOL = 1e-9, 1e-10  # ω⁺ = −c·ω⁻, and c·|ω⁻| is the next return speed
SLOW = 10.0  # s: an extreme recipe that takes longer is crawling, not solving


# -- strategies ------------------------------------------------------------------------


def reals(low, high, **kwargs):
    return st.floats(low, high, allow_nan=False, allow_infinity=False, allow_subnormal=False, **kwargs).map(
        lambda x: 0.0 if abs(x) < TINY else x
    )


def round_numbers(step, high):
    """Multiples of ``step`` in [0, high], as a person types them (0.15, not 3 × 0.05)."""
    return st.integers(0, round(high / step)).map(lambda k: round(k * step, 10))


@st.composite
def piecewise_linear(draw, low, high):
    n = draw(st.integers(1, 6))
    times = sorted(draw(st.lists(st.one_of(reals(0.0, 10.0), round_numbers(0.05, 10.0)), min_size=n, max_size=n)))
    spaced = times[:1]
    for t in times[1:]:
        if t - spaced[-1] >= BREAKPOINT_SPACING:
            spaced.append(t)
    values = draw(st.lists(reals(low, high), min_size=len(spaced), max_size=len(spaced)))
    return drumstroke.PiecewiseLinear(list(zip(spaced, values)))


pulses = st.builds(
    drumstroke.Pulses,
    amplitude=reals(0.0, 400.0),
    period=st.one_of(reals(0.05, 1.0), st.sampled_from((0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.75, 1.0))),
    duty=st.one_of(reals(0.01, 0.99, exclude_min=True, exclude_max=True), st.sampled_from((0.05, 0.25, 0.5, 0.75))),
    phase=st.one_of(reals(0.0, 1.0), round_numbers(0.05, 1.0)),
)

one_force = st.one_of(st.builds(drumstroke.Constant, reals(-60.0, 3000.0)), piecewise_linear(0.0, 3000.0), pulses)
forces = st.one_of(one_force, st.lists(one_force, min_size=1, max_size=3).map(drumstroke.Sum))


@st.composite
def _gravity(draw):
    if draw(st.integers(0, 3)) == 0:
        return draw(piecewise_linear(-5.0, 60.0))
    return drumstroke.Constant(9.8)


gravities = _gravity()


@st.composite
def recipes(draw, force=forces, gravity=gravities):
    return drumstroke.Recipe(
        force=draw(force),
        gravity=draw(gravity),
        model=draw(st.sampled_from(drumstroke.MODELS)),
        theta0=draw(st.one_of(st.just(THETA_MAX), st.just(0.0), reals(THETA_MAX + MICRO_ANGLE, 1.3))),
        omega0=draw(st.one_of(st.just(0.0), reals(-20.0, -MICRO_SPEED), reals(MICRO_SPEED, 20.0))),
        cor=draw(st.one_of(st.just(0.0), st.just(1.0), reals(0.0, 1.0))),
        t_end=draw(reals(T_END_MIN, 10.0)),
    )


constant_recipes = recipes(
    force=st.builds(drumstroke.Constant, reals(-60.0, 3000.0)),
    gravity=st.just(drumstroke.Constant(9.8)),
)


def simulate(recipe, **options):
    """The stroke, or a rejected example if the recipe legitimately drives the stick past the vertical."""
    try:
        return drumstroke.simulate(recipe, **options)
    except drumstroke.SimulationError as error:
        if "vertical" not in str(error):
            raise
        assume(False)


def constant_forcing(recipe, t0, t1):
    """Whether C(t) is one constant over each [t0, t1] (no profile edge inside, no slope), and C there."""
    a, g = recipe.force.pieces(recipe.t_end), recipe.gravity.pieces(recipe.t_end)
    edges = np.union1d(a.edges, g.edges)
    inside = np.searchsorted(edges, t1, side="left") - np.searchsorted(edges, t0, side="right")
    middle = 0.5 * (t0 + t1)
    ia = np.searchsorted(a.edges, middle, side="right") - 1
    ig = np.searchsorted(g.edges, middle, side="right") - 1
    flat = (inside == 0) & (a.slopes[ia] == 0.0) & (g.slopes[ig] == 0.0)
    c = coefficients(recipe.model, recipe.stick).torque_rate(recipe.gravity(middle), recipe.force(middle))
    return flat, c


# -- properties ------------------------------------------------------------------------


@PROPERTY
@given(recipes())
def test_every_output_is_finite(recipe):
    stroke = simulate(recipe)
    impacts = stroke.impacts
    for name in ("t", "omega", "tip_speed", "level_db"):
        values = np.asarray(getattr(impacts, name))
        assert values.shape == (len(impacts),), name
        assert np.all(np.isfinite(values)), f"impacts.{name} is not finite: {values[~np.isfinite(values)]}"
    t, theta, omega = stroke.sample(RATE)
    assert np.all(np.isfinite(t))
    assert np.all(np.isfinite(theta)), f"theta is not finite at t = {t[~np.isfinite(theta)][:3]}"
    assert np.all(np.isfinite(omega)), f"omega is not finite at t = {t[~np.isfinite(omega)][:3]}"
    assert stroke.rest_time is None or math.isfinite(stroke.rest_time)
    assert np.all(np.isfinite(stroke.rests))


@PROPERTY
@given(recipes())
def test_samples_are_at_the_control_rate(recipe):
    t, theta, omega = simulate(recipe).sample(RATE)
    assert t.shape == theta.shape == omega.shape
    assert t[0] == 0.0
    assert np.all(np.diff(t) > 0.0)
    assert t[-1] <= recipe.t_end < t[-1] + 1.0 / RATE + 1e-12 * recipe.t_end
    np.testing.assert_array_equal(t, np.minimum(np.arange(len(t)) / RATE, recipe.t_end))


@PROPERTY
@given(recipes())
def test_impact_times_strictly_increase_within_the_stroke(recipe):
    impacts = simulate(recipe).impacts
    if len(impacts):
        assert impacts.t[0] >= 0.0
        assert impacts.t[-1] <= recipe.t_end
        assert np.all(np.diff(impacts.t) > 0.0), "impact times are not strictly increasing"
        assert np.all(impacts.omega <= 0.0), "an impact moving up"


@PROPERTY
@given(recipes())
def test_stick_never_goes_below_the_head(recipe):
    stroke = simulate(recipe)
    _, theta, _ = stroke.sample(RATE)
    assert np.all(theta >= recipe.theta_max)
    assert np.all(theta < math.pi / 2)


@PROPERTY
@given(st.one_of(recipes(), constant_recipes))
def test_no_impact_adds_energy(recipe):
    stroke = simulate(recipe)
    impacts = stroke.impacts
    if len(impacts) == 0:
        return
    theta_after, omega_after = stroke.state(impacts.t)  # at an impact time: the state just after it
    # θ is continuous through the impact: the stick is on the head just before and just after.
    np.testing.assert_allclose(theta_after, recipe.theta_max, rtol=0.0, atol=THETA_TOL)
    assert np.all(omega_after >= 0.0), "the stick leaves an impact moving down"
    before, after = np.abs(impacts.omega), omega_after
    expected = recipe.cor * before
    matches = np.abs(after - expected) <= SPEED_RTOL * expected + SPEED_ATOL
    # The Zeno tail: bounces launched slower than ZENO_SPEED are summed, the stick put to rest at once.
    summed = (after == 0.0) & (expected <= ZENO_SPEED * (1.0 + 1e-9))
    bad = np.flatnonzero(~(matches | summed))
    assert len(bad) == 0, (
        f"|omega+| != cor |omega-| at t = {impacts.t[bad[0]]!r}: {after[bad[0]]!r} vs {expected[bad[0]]!r}"
    )
    assert np.all(after <= before * (1.0 + SPEED_RTOL) + SPEED_ATOL), "an impact added energy"


@PROPERTY
@given(recipes())
def test_solver_finishes_below_the_impact_limit(recipe):
    assert len(simulate(recipe).impacts) < MAX_IMPACTS


@PROPERTY
@given(st.one_of(recipes(), constant_recipes))
def test_return_speed_decays_while_forcing_is_constant(recipe):
    impacts = simulate(recipe).impacts
    if len(impacts) < 2:
        return
    flat, c = constant_forcing(recipe, impacts.t[:-1], impacts.t[1:])
    chosen = flat & (c > 0.0)
    speed = np.abs(impacts.omega)
    previous, following = speed[:-1][chosen], speed[1:][chosen]
    # Energy is conserved in flight, so the stick comes back at its launch speed c·|ω⁻|.
    assert np.all(following <= previous * (1.0 + SPEED_RTOL) + SPEED_ATOL), "|omega-| grew under constant forcing"
    np.testing.assert_allclose(following, recipe.cor * previous, rtol=SPEED_RTOL, atol=SPEED_ATOL)


@PROPERTY
@given(constant_recipes)
def test_energy_is_conserved_in_flight_under_constant_forcing(recipe):
    """§1: E = ω²/2 + C·sin θ is constant in flight; sampled values are exact, not interpolated."""
    stroke = simulate(recipe)
    c = coefficients(recipe.model, recipe.stick).torque_rate(9.8, recipe.force.value)
    t, theta, omega = stroke.sample(RATE)
    energy = 0.5 * omega**2 + c * np.sin(theta)
    launch = np.concatenate(
        (
            [0.5 * recipe.omega0**2 + c * math.sin(recipe.theta0)],
            0.5 * (recipe.cor * stroke.impacts.omega) ** 2 + c * math.sin(recipe.theta_max),
        )
    )
    flight = np.searchsorted(stroke.impacts.t, t, side="right")
    np.testing.assert_allclose(energy, launch[flight], rtol=1e-9, atol=1e-9 * (1.0 + abs(c)))


@PROPERTY
@given(recipes())
def test_impacts_come_before_the_rest(recipe):
    stroke = simulate(recipe)
    if stroke.rest_time is not None:
        assert np.all(stroke.impacts.t <= stroke.rest_time)
        assert stroke.rests[-1, 1] == recipe.t_end
        t, theta, omega = stroke.sample(RATE)
        resting = t >= stroke.rest_time
        assert np.all(theta[resting] == recipe.theta_max)
        assert np.all(omega[resting] == 0.0)


@PROPERTY
@given(recipes())
def test_stroke_starts_at_the_start_state_exactly(recipe):
    """The state at t = 0, and the first sample, are the recipe's θ₀ and ω₀ as given, not to round-off."""
    stroke = simulate(recipe)
    theta, omega = stroke.state(0.0)
    first = stroke.sample(RATE)
    assert (first.theta[0], first.omega[0]) == (theta, omega)
    assert float(theta) == recipe.theta0
    impacts = stroke.impacts
    if len(impacts) and impacts.t[0] == 0.0:
        expected = -recipe.cor * recipe.omega0  # an impact at t = 0: the state just after it
    elif recipe.theta0 == recipe.theta_max and recipe.omega0 <= 0.0:
        expected = 0.0
    else:
        expected = recipe.omega0
    if float(omega) == 0.0 and 0.0 < expected <= ZENO_SPEED:
        return  # a launch slower than ZENO_SPEED: the summed Zeno tail, the stick put to rest at once
    assert float(omega) == expected


@PROPERTY
@given(recipes())
def test_toml_round_trip(recipe):
    recipe = recipe.replace(name="stroke")  # from_toml names a recipe after its file
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "stroke.toml"
        recipe.to_toml(path)
        data = tomllib.loads(path.read_text())
        again = drumstroke.Recipe.from_toml(path)
    assert data == recipe.to_dict()
    assert drumstroke.Recipe.from_dict(data, name="stroke") == recipe
    assert again == recipe
    first = simulate(recipe)
    second = drumstroke.simulate(again)
    np.testing.assert_array_equal(second.impacts.t, first.impacts.t)
    np.testing.assert_array_equal(second.impacts.omega, first.impacts.omega)
    np.testing.assert_array_equal(second.rests, first.rests)


def test_toml_round_trip_with_a_samples_file(tmp_path):
    """A samples file is written relative to the recipe's folder and found again from there."""
    (tmp_path / "data").mkdir()
    csv = tmp_path / "data" / "thumb.csv"
    csv.write_text("t,value\n0,10\n0.5,180\n1.0,20\n")
    force = drumstroke.Sum([drumstroke.Samples(csv), drumstroke.Pulses(amplitude=50.0, period=0.4, duty=0.1)])
    recipe = drumstroke.Recipe(force=force, gravity=drumstroke.Samples(csv), t_end=2.0, name="stroke")
    path = tmp_path / "recipes" / "stroke.toml"
    path.parent.mkdir()  # writers create no folder
    recipe.to_toml(path)
    data = tomllib.loads(path.read_text())
    assert data["gravity"] == {"kind": "samples", "file": "../data/thumb.csv"}
    again = drumstroke.Recipe.from_toml(path)
    assert again == recipe
    first, second = drumstroke.simulate(recipe), drumstroke.simulate(again)
    np.testing.assert_array_equal(second.impacts.t, first.impacts.t)
    np.testing.assert_array_equal(second.impacts.omega, first.impacts.omega)


@PROPERTY
@given(
    force=st.lists(st.one_of(pulses, st.builds(drumstroke.Constant, reals(0.0, 3000.0))), min_size=1, max_size=3).map(
        drumstroke.Sum
    ),
    model=st.sampled_from(drumstroke.MODELS),
    cor=reals(0.0, 1.0),
    t_end=reals(0.01, 10.0),
)
def test_a_stick_pressed_onto_the_head_stays_there(force, model, cor, t_end):
    """a(t) ≥ 0 and g = 9.8: the forcing never lifts, so a stick lying on the head never moves."""
    stroke = drumstroke.simulate(force=force, model=model, cor=cor, t_end=t_end, theta0=THETA_MAX, omega0=0.0)
    assert len(stroke.impacts) == 0, f"phantom impacts at t = {stroke.impacts.t[:3]}"
    np.testing.assert_array_equal(stroke.rests, [[0.0, t_end]])


# -- the solver on extreme valid recipes: it finishes, quickly, with sensible results ---------


def timed(recipe=None, **options):
    start = time.perf_counter()
    stroke = drumstroke.simulate(recipe, **options)
    elapsed = time.perf_counter() - start
    assert elapsed < SLOW, f"the solver took {elapsed:.1f} s"
    return stroke


def test_free_bounce_without_losses_for_an_hour_is_periodic():
    stroke = timed(cor=1.0, t_end=3600.0)
    t, omega = stroke.impacts.t, stroke.impacts.omega
    # §1 oracle: the drop from the horizontal at rest (apex θ = 0, m = 1/2) takes [K(m) − F(ψ|m)]/√C.
    c = coefficients("paper", STICK).torque_rate(9.8, 0.0)
    fall = (ellipk(0.5) - ellipkinc(math.asin(math.sqrt(1.0 + math.sin(THETA_MAX))), 0.5)) / math.sqrt(c)
    assert t[0] == pytest.approx(fall, abs=1e-9)
    np.testing.assert_allclose(np.diff(t), 2.0 * fall, rtol=0.0, atol=1e-9)
    np.testing.assert_allclose(omega, omega[0], rtol=1e-9)
    assert len(t) == math.floor((3600.0 - fall) / (2.0 * fall)) + 1
    assert stroke.rest_time is None
    assert len(stroke.rests) == 0


def test_dead_stick_stops_at_its_first_impact():
    stroke = timed(cor=0.0, t_end=3600.0)
    assert len(stroke.impacts) == 1
    assert stroke.rest_time == stroke.impacts.t[0]
    np.testing.assert_array_equal(stroke.rests, [[stroke.impacts.t[0], 3600.0]])
    theta, omega = stroke.state(np.array([stroke.impacts.t[0], 1800.0, 3600.0]))
    np.testing.assert_array_equal(theta, THETA_MAX)
    np.testing.assert_array_equal(omega, 0.0)


def test_finger_pulses_for_an_hour_keep_the_bounce_alive():
    stroke = timed(drumstroke.preset("finger-pulses").replace(t_end=3600.0))
    t = stroke.impacts.t
    assert stroke.rest_time is None
    assert t[-1] > 3600.0 - 1.0, "the bounce died"
    assert np.all(np.diff(t) > 0.0)
    late = t[t > 3000.0]
    # Fig. 7: the bounce settles at the pulse period.
    assert (late[-1] - late[0]) / (len(late) - 1) == pytest.approx(0.4, abs=1e-3)


def test_dead_stick_under_finger_pulses_stops_at_its_first_impact():
    stroke = timed(drumstroke.preset("finger-pulses").replace(t_end=3600.0, cor=0.0))
    assert len(stroke.impacts) == 1
    assert stroke.rest_time == stroke.impacts.t[0]
    np.testing.assert_array_equal(stroke.rests, [[stroke.impacts.t[0], 3600.0]])


def test_a_huge_constant_press_ends_in_a_summed_zeno_tail():
    stroke = timed(force=1e5)
    t, speed = stroke.impacts.t, np.abs(stroke.impacts.omega)
    assert 0 < len(t) < 1000
    assert np.all(np.diff(t) > 0.0)
    np.testing.assert_allclose(speed[1:], 0.86 * speed[:-1], rtol=1e-9)
    assert speed[-1] >= ZENO_SPEED
    assert stroke.rest_time is not None
    assert t[-1] < stroke.rest_time < 0.1
    # After the last listed impact the bounces (launched below ZENO_SPEED) sum to 2·L/(C·cos θ_max·(1 − c)).
    c = coefficients("paper", STICK).torque_rate(9.8, 1e5)
    tail = 2.0 * 0.86 * speed[-1] / (c * math.cos(THETA_MAX) * (1.0 - 0.86))
    assert stroke.rest_time - t[-1] == pytest.approx(tail, rel=1e-6)


def test_a_huge_press_without_losses_bounces_periodically_for_a_minute():
    stroke = timed(force=1e6, cor=1.0, t_end=60.0)
    t = stroke.impacts.t
    assert 1000 < len(t) < MAX_IMPACTS
    intervals = np.diff(t)
    np.testing.assert_allclose(intervals, intervals[0], rtol=0.0, atol=1e-9)
    assert stroke.rest_time is None
    _, theta, _ = stroke.sample(RATE)
    assert np.all(np.isfinite(theta)) and np.all(theta >= THETA_MAX)


# -- degenerate and corner inputs: minimal repros of solver bugs found with the properties above ---


def test_a_resting_stick_under_two_pulse_trains_has_no_phantom_impact():
    """Edges of the two trains coincide up to round-off at t = 2.4 s; a(t) ≥ 0 never lifts the stick."""
    force = drumstroke.Sum(
        [
            drumstroke.Pulses(amplitude=189.0, period=0.1, duty=0.4, phase=1.0),
            drumstroke.Pulses(amplitude=50.0, period=0.6, duty=0.75, phase=0.15),
        ]
    )
    stroke = drumstroke.simulate(force=force, theta0=THETA_MAX, omega0=0.0, t_end=10.0)
    assert len(stroke.impacts) == 0, f"phantom impacts at t = {stroke.impacts.t}"
    np.testing.assert_array_equal(stroke.rests, [[0.0, 10.0]])


def test_a_pulse_edge_just_after_a_breakpoint_does_not_lift_a_pressed_stick():
    force = drumstroke.Sum(
        [
            drumstroke.Pulses(amplitude=400.0, period=1.0, duty=0.5, phase=1.0),
            drumstroke.PiecewiseLinear([(0.0, 0.0), (1.0 - 1e-10, 0.0)]),
        ]
    )
    stroke = drumstroke.simulate(force=force, theta0=THETA_MAX, omega0=0.0, t_end=3.0)
    assert len(stroke.impacts) == 0, f"phantom impacts at t = {stroke.impacts.t}"
    np.testing.assert_array_equal(stroke.rests, [[0.0, 3.0]])


@pytest.mark.parametrize(
    ("theta0", "omega0"),
    [(0.5, 0.0), (0.0, 0.0), (THETA_MAX, 0.0)],
    ids=["flying", "from-horizontal", "resting"],
)
@pytest.mark.parametrize("phase", [1e-40, 1e-200])
def test_a_pulse_train_starting_just_after_zero_gives_a_finite_stroke(phase, theta0, omega0):
    """A tiny phase leaves a sliver [0, phase] of forcing; the stroke must come out as without it."""
    pulses = {"amplitude": 142.0, "period": 0.4, "duty": 0.5}
    reference = drumstroke.simulate(force=drumstroke.Pulses(**pulses), theta0=theta0, omega0=omega0, t_end=2.0)
    stroke = drumstroke.simulate(
        force=drumstroke.Pulses(**pulses, phase=phase), theta0=theta0, omega0=omega0, t_end=2.0
    )
    _, theta, omega = stroke.sample(RATE)
    assert np.all(np.isfinite(theta)) and np.all(np.isfinite(omega))
    np.testing.assert_allclose(stroke.impacts.t, reference.impacts.t, rtol=0.0, atol=1e-9)


def test_a_launch_from_the_head_past_the_vertical_is_a_simulation_error():
    """At t = 0 on the head moving down at 6 rad/s with c = 1: the rebound passes the vertical."""
    c = coefficients("paper", STICK).torque_rate(9.8, 0.0)
    assert 0.5 * 6.0**2 + c * math.sin(THETA_MAX) > c  # energy above the vertical's
    with pytest.raises(drumstroke.SimulationError, match="vertical"):
        drumstroke.simulate(theta0=THETA_MAX, omega0=-6.0, cor=1.0, t_end=1.0)


def test_a_weak_lift_off_does_not_stall_at_t0(monkeypatch):
    """g(t) rises from −0.01 to 9.8 m/s²: the stick floats off the head briefly, lands once, rests."""
    # The expected stroke has one impact; a lower limit makes a stalled solver fail in milliseconds.
    monkeypatch.setattr("drumstroke.solver.hybrid.MAX_IMPACTS", 10_000, raising=False)
    gravity = drumstroke.PiecewiseLinear([(0.0, -0.01), (1.0, 9.8)])
    stroke = drumstroke.simulate(gravity=gravity, theta0=THETA_MAX, omega0=0.0, cor=0.0, t_end=2.0)
    assert len(stroke.impacts) == 1
    assert stroke.impacts.t[0] > 0.0 and stroke.impacts.omega[0] < 0.0
    assert stroke.rest_time == stroke.impacts.t[0]


def test_an_impact_always_has_a_speed():
    """A launch at 1e-200 rad/s comes back at that speed; an impact at exactly 0 rad/s has no level."""
    stroke = drumstroke.simulate(theta0=THETA_MAX, omega0=1e-200, cor=0.0, t_end=1.0)
    assert np.all(stroke.impacts.omega < 0.0)
    assert np.all(np.isfinite(stroke.impacts.level_db))


def test_lossless_micro_bounces_do_not_exhaust_the_impact_limit():
    """c = 1 after a tap of 1e-7 rad/s: bounces slower than ZENO_SPEED, which the solver never lists."""
    stroke = timed(theta0=THETA_MAX, omega0=-1e-7, cor=1.0, t_end=5.0)
    later = stroke.impacts.t > 0.0
    assert np.all(np.abs(stroke.impacts.omega[later]) >= ZENO_SPEED)
    _, theta, _ = stroke.sample(RATE)
    np.testing.assert_allclose(theta, THETA_MAX, rtol=0.0, atol=1e-12)
