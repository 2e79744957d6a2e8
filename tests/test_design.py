"""Inverse design: the force that plays given notes, checked by the solver and against exact flights.

Oracles: docs/model.md's closed form of a flight under constant forcing (scipy's elliptic integrals,
independent of drumstroke's compiled ones); the notes themselves (every design is simulated and
its impacts compared); strokes simulated from random recipes, whose audible impacts must come back.
"""

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, assume, event, given, settings
from hypothesis import strategies as st
from scipy.special import ellipk, ellipkinc

import drumstroke
from drumstroke.design import ForceRange, Setup, Start, Unreachable, buzz, design

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from reference import reference_flight

from drumstroke.dynamics import velocity_to_level
from drumstroke.model import coefficients

STICK = drumstroke.Stick()
HEAD = STICK.theta_max
X = STICK.pivot_to_tip
WIDE = ForceRange(-1.0e4, 1.0e5)  # un-natural forces allowed: the round trip tests the inverse, not the limits

ROUND_TRIP = settings(max_examples=60, deadline=None, derandomize=True, database=None, report_multiple_bugs=False,
                      phases=(Phase.explicit, Phase.generate, Phase.shrink), suppress_health_check=[HealthCheck.too_slow])


def level(speed):
    return 20.0 * math.log10(speed * X)


def oracle_flight(u, c):
    """The duration of a flight launched from the head at u under constant C, by scipy."""
    sh = math.sin(HEAD)
    apex = sh + u * u / (2.0 * c)
    m = (1.0 + apex) / 2.0
    psi = math.asin(math.sqrt((1.0 + sh) / (1.0 + apex)))
    return 2.0 * (ellipk(m) - ellipkinc(psi, m)) / math.sqrt(c)


@pytest.mark.parametrize("model", drumstroke.MODELS)
@pytest.mark.parametrize("force", [0.0, 60.0, 240.0, 900.0])
def test_a_bounce_that_loses_only_the_impact_is_one_constant_force_found_exactly(model, force):
    """Notes v and c·v apart by the closed-form flight of C: the design's flight has C up and down."""
    co = coefficients(model, STICK)
    c = co.torque_rate(9.8, force)
    v = 3.0
    duration = oracle_flight(0.86 * v, c)
    designed = design([0.2, 0.2 + duration], [level(v), level(0.86 * v)], setup=Setup(model=model))
    rise, fall = [p for p in designed.pieces if p.phase in ("rise", "fall")]
    assert rise.force == pytest.approx(force, abs=1e-7 * max(1.0, force))
    assert fall.force == pytest.approx(force, abs=1e-7 * max(1.0, force))
    assert designed.impacts.t[:2] == pytest.approx([0.2, 0.2 + duration], abs=1e-8)


@pytest.mark.parametrize("model", drumstroke.MODELS)
@pytest.mark.parametrize("gap", [0.060, 0.090, 0.125])
@pytest.mark.parametrize("second", [0.0, 3.0])
def test_diddles_are_two_notes_as_a_drummer_plays_them(model, gap, second):
    """60-125 ms apart, the second as loud as the first or louder: energy is added on the way down."""
    first = velocity_to_level(100)
    designed = design([0.5, 0.5 + gap], [first, first + second], setup=Setup(model=model))
    assert len(designed.impacts) == 2  # caught: nothing after the second note
    assert designed.impacts.t == pytest.approx([0.5, 0.5 + gap], abs=1e-8)
    assert designed.impacts.level_db == pytest.approx([first, first + second], abs=1e-6)
    fall = next(p for p in designed.pieces if p.phase == "fall")
    rise = next(p for p in designed.pieces if p.phase == "rise")
    assert fall.force > rise.force  # the push on the way down
    theta, omega = designed.state(designed.t_end)
    assert theta > HEAD and omega == pytest.approx(0.0, abs=1e-6)  # caught at the apex


@pytest.mark.parametrize("model", drumstroke.MODELS)
@pytest.mark.parametrize("gap, ratio", [(0.08, 1.0 / 0.86), (0.12, 1.6), (0.3, 0.9)])
def test_a_flights_forces_equal_an_independent_shooting_with_solve_ivp(model, gap, ratio):
    """benchmarks/reference.py's reference_flight: the same two forces found by scipy's DOP853 and fsolve."""
    u = 3.0
    v = ratio * u
    designed = design([0.3, 0.3 + gap], [level(u / 0.86), level(v)], setup=Setup(model=model, forces=WIDE))
    rise, fall = [p.force for p in designed.pieces if p.phase in ("rise", "fall")]
    up, down = reference_flight(gap, u, v, model)
    assert (rise, fall) == pytest.approx((up, down), rel=1e-6, abs=1e-6)


@pytest.mark.parametrize("s0, w0, s1, c", [
    (-0.2593, 5.0, -0.2, 100.0),     # a libration: the orbit turns back below the vertical
    (-0.2593, 10.234, -0.2394, 39.4),  # a rotation: a fast stick under a light force by the head
    (-0.26, 20.0, 0.9, 30.0),         # a rotation over most of the range
])
def test_a_part_of_a_flight_takes_the_time_of_its_integral(s0, w0, s1, c):
    from scipy.integrate import quad

    from drumstroke.design.flight import part_time
    w1 = math.sqrt(w0 * w0 - 2.0 * c * (s1 - s0))
    exact, _ = quad(lambda theta: 1.0 / math.sqrt(w0 * w0 - 2.0 * c * (math.sin(theta) - s0)), math.asin(s0),
                    math.asin(s1), epsabs=0.0, epsrel=1e-13)
    assert part_time(s0, w0, s1, w1, c) == pytest.approx(exact, rel=1e-12)


def test_the_design_is_the_recipe_the_solver_plays():
    """The recipe on its own (written and read back as TOML) makes the notes: the design is no private model."""
    designed = design([0.3, 0.38, 0.46, 0.53], velocities=[110, 90, 90, 120], setup=Setup(model="geometry"))
    stroke = drumstroke.simulate(designed.recipe)
    assert stroke.impacts.t[:4] + designed.release == pytest.approx(designed.times, abs=1e-8)
    assert stroke.impacts.level_db[:4] == pytest.approx([velocity_to_level(v) for v in (110, 90, 90, 120)],
                                                        abs=1e-6)
    assert designed.recipe.force.kind == "piecewise-linear" and designed.model == "geometry"


@pytest.mark.parametrize("model", drumstroke.MODELS)
@pytest.mark.parametrize("density", [15.0, 25.0, 40.0])
def test_long_buzzes_stay_on_their_notes(model, density):
    """Many bounces in a row: errors must not grow from bounce to bounce."""
    designed = buzz(0.0, 3.0, velocity=90, density=density, setup=Setup(model=model))
    n = len(designed.times)
    assert n >= 3.0 * density - 4
    assert designed.impacts.t[:n] == pytest.approx(designed.times, abs=1e-8)
    assert designed.impacts.level_db[:n] == pytest.approx(velocity_to_level(90), abs=1e-5)
    assert np.diff(designed.impacts.t[:n]) == pytest.approx(1.0 / density, abs=1e-8)
    assert designed.stroke.rest_time is not None and designed.t_end <= 3.0


def test_a_buzz_decays_as_asked():
    designed = buzz(1.0, 1.5, level=-6.0, density=30.0, decay=20.0, finish="catch")
    n = len(designed.times)
    assert designed.impacts.level_db[:n] == pytest.approx(-6.0 - 20.0 * (designed.times - 1.0), abs=1e-6)
    assert len(designed.impacts) == n  # caught


def test_the_ends():
    notes = {"times": [0.2, 0.3], "velocities": [90, 90]}
    caught = design(**notes, end="catch")
    pressed = design(**notes, end="press")
    free = design(**notes, end="bounce")
    assert len(caught.impacts) == 2 and caught.stroke.rest_time is None
    for stroke in (pressed, free):
        assert len(stroke.impacts) > 2 and stroke.stroke.rest_time is not None
        assert stroke.impacts.t[:2] == pytest.approx([0.2, 0.3], abs=1e-8)
        assert np.all(np.diff(stroke.impacts.level_db[1:]) < 0)  # after the notes, each bounce softer
    assert pressed.t_end - 0.3 < free.t_end - 0.3  # pressed to rest sooner
    assert design(**notes, end="bounce", tail=0.05).t_end == pytest.approx(0.35)


def test_a_start_state():
    held = design([1.0], velocities=[120], start=Start(0.0, 0.6))
    assert held.recipe.theta0 == 0.6 and held.hold > 0 and held.release == pytest.approx(held.hold)
    assert held.impacts.t[0] == pytest.approx(1.0, abs=1e-8)
    rising = design([0.4, 0.5], velocities=[80, 80], start=Start(0.1, HEAD, 2.0))
    assert rising.release == 0.1 and rising.recipe.omega0 == 2.0
    assert rising.impacts.t[:2] == pytest.approx([0.4, 0.5], abs=1e-8)
    with pytest.raises(Unreachable, match="only .* s are left") as error:
        design([0.05], velocities=[120], start=Start(0.0, 0.6))
    assert error.value.nearest_time > 0.05


def test_an_accent_20_ms_after_a_note_is_unreachable_with_the_nearest():
    with pytest.raises(Unreachable, match="note 1") as error:
        design([0.2, 0.22], [-10.0, 2.0])
    assert "nearest reachable" in str(error.value) and "force limit 3000" in str(error.value)
    assert error.value.note == 1
    nearest = error.value.nearest_time
    if nearest is not None:  # playing it there works
        assert design([0.2, nearest], [-10.0, 2.0]).impacts.t[1] == pytest.approx(nearest, abs=1e-6)


def test_a_loud_throw_beyond_a_weak_thumb_is_unreachable_with_the_loudest():
    """With at most 50 m/s² the stick must be thrown from above the joint's range: unreachable, and the
    nearest level a throw from the highest angle gives is heard there."""
    weak = ForceRange(0.0, 50.0)
    with pytest.raises(Unreachable, match="needs more than the strongest force 50") as error:
        design([0.095], velocities=[127], setup=Setup(forces=weak))
    loudest = error.value.nearest_level
    assert loudest < velocity_to_level(127)
    made = design([0.5], [loudest - 1e-6], setup=Setup(forces=weak))
    assert made.impacts.level_db[0] == pytest.approx(loudest - 1e-6, abs=1e-6)


@pytest.mark.parametrize("times, levels, match", [
    ([0.2, 0.2], [-3, -3], "increase by at least"),
    ([0.3, 0.2], [-3, -3], "increase by at least"),
    ([0.2, float("nan")], [-3, -3], r"times\[1\] must be a finite number"),
    ([0.2, 0.3], [-3, 30.0], r"levels\[1\] must be .* dB"),
    ([0.2, 0.3], [-3], "one level per note"),
    ([], [], "at least one note"),
])
def test_bad_notes_are_refused(times, levels, match):
    with pytest.raises(drumstroke.ParameterError, match=match):
        design(times, levels)


def test_bad_options_are_refused():
    with pytest.raises(drumstroke.ParameterError, match="give the notes' levels"):
        design([0.2])
    with pytest.raises(drumstroke.ParameterError, match="end must be one of"):
        design([0.2], [-3], end="stop")
    with pytest.raises(drumstroke.ParameterError, match=r"forces.high must be in \(-5"):
        ForceRange(-5.0, -6.0)
    with pytest.raises(drumstroke.ParameterError, match="start.t must be before"):
        design([0.2], [-3], start=Start(0.3, 0.5))
    with pytest.raises(drumstroke.ParameterError, match=r"velocities\[0\] must be"):
        design([0.2], velocities=[0])
    with pytest.raises(drumstroke.ParameterError, match="density"):
        buzz(0.0, 1.0, velocity=90, density=0.0)
    with pytest.raises(drumstroke.ParameterError, match=r"drift must be \(seconds, dB\), two numbers > 0, got \(0.001,\)"):
        design([0.2], [-3], drift=(1e-3,))
    with pytest.raises(drumstroke.ParameterError, match=r"drift\[1\] must be .* \(0, inf\) dB, got -1"):
        design([0.2], [-3], drift=(1e-3, -1.0))


# -- the round trip: strokes from random recipes, their audible impacts designed back ---------------------

def reals(low, high):
    return st.floats(low, high, allow_nan=False, allow_infinity=False)


@st.composite
def forcings(draw):
    kind = draw(st.sampled_from(("constant", "piecewise", "pulses")))
    if kind == "constant":
        return drumstroke.Constant(draw(reals(0.0, 600.0)))
    if kind == "piecewise":
        times = sorted({round(t, 4) for t in draw(st.lists(reals(0.0, 3.0), min_size=2, max_size=5))})
        values = draw(st.lists(reals(0.0, 600.0), min_size=len(times), max_size=len(times)))
        return drumstroke.PiecewiseLinear(list(zip(times, values)))
    return drumstroke.Pulses(amplitude=draw(reals(20.0, 300.0)), period=draw(reals(0.1, 0.6)),
                             duty=draw(reals(0.03, 0.5)), phase=draw(reals(0.0, 0.3)))


@ROUND_TRIP
@given(force=forcings(), model=st.sampled_from(drumstroke.MODELS), theta0=reals(0.0, 0.9),
       cor=reals(0.5, 0.95))
def test_the_audible_impacts_of_any_stroke_are_designed_back(force, model, theta0, cor):
    recipe = drumstroke.Recipe(force=force, model=model, theta0=theta0, cor=cor, t_end=3.0)
    try:
        stroke = drumstroke.simulate(recipe)
    except drumstroke.SimulationError:
        assume(False)
    levels = stroke.impacts.level_db
    # the audible impacts: within 30 dB of the loudest and of the MIDI map, each at least 1 ms after the last
    keep = []
    for i, (t, db) in enumerate(zip(stroke.impacts.t, levels)):
        if db < max(levels.max() - 30.0, -35.0) or db > 12.0 or (keep and t - stroke.impacts.t[keep[-1]] < 1e-3):
            break
        keep.append(i)
    assume(len(keep) >= 1)
    event(f"{min(len(keep), 10) // 3 * 3}+ notes")
    times, targets = stroke.impacts.t[keep], levels[keep]
    assume(stroke.sample(1000.0).theta.max() < 1.2)  # clear of the vertical, where the stick balances
    # the design's two forces a flight may need a higher apex than the recipe's own forcing reached
    designed = design(times, targets, setup=Setup(model=model, cor=cor, forces=WIDE), highest=1.5)
    n = len(keep)
    assert designed.impacts.t[:n] == pytest.approx(times, abs=1e-4)  # the tolerance
    assert designed.impacts.level_db[:n] == pytest.approx(targets, abs=0.5)
    assert designed.time_error < 1e-6 and designed.level_error < 1e-3  # what a design guarantees (chain.DRIFT)
    assert len(designed.impacts) == n  # caught: no other impact, before or after


@pytest.mark.parametrize("model", drumstroke.MODELS)
def test_the_compiled_rounds_of_a_chains_flights_are_the_rounds_one_flight_at_a_time_to_the_bit(model, rng):
    """A chain's flights settled in one compiled call equal the same rounds solved and checked flight by flight
    (the code they replace, kept for the chains that fail); where one fails a check, the compiled rounds give
    way (None) and the flight-by-flight rounds raise. The planner's quick test of each flight alone
    (:func:`flights_within`, compiled too) is whether that flight, solved and checked alone, raises."""
    from drumstroke.design.chain import _SETTLE_ROUNDS, _SWITCH, _Plan, flights_within
    from drumstroke.design.flight import settled_flights

    setup = Setup(model=model)
    solved = failed = 0
    for _ in range(200):
        n = int(rng.integers(2, 10))
        times = np.cumsum(rng.uniform(0.05, 0.15, n))
        levels = rng.uniform(-12.0, 4.0, n)
        plan = _Plan.of(times, levels, None, start=None, end="catch", setup=setup, lead=0.1, tail=None)
        compiled = settled_flights(plan.times, plan.speeds, cor=plan.recipe.cor, sh=plan.head, top=plan.top,
                                   rates=plan.rates, theta_max=plan.recipe.theta_max,
                                   max_acceleration=plan.limits.max_acceleration, switch=_SWITCH,
                                   rounds=_SETTLE_ROUNDS)
        assert flights_within(times, levels, setup=setup) == [_passes(plan.bounce, i) for i in range(n - 1)]
        try:
            expected = plan.flights_one_by_one()
        except Unreachable:
            assert compiled is None
            failed += 1
            continue
        assert compiled == expected  # every field, exactly
        solved += 1
    assert solved >= 10 and failed >= 10


def _passes(bounce, i):
    try:
        bounce(i)
    except Unreachable:
        return False
    return True
