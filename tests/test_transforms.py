"""Transforms of trajectories (the paper's Section 3.5): stretch, compress, reverse, trim, catch, concat.

Oracles: the simulated stroke itself (``Stroke.state``, exact), read at the times each transform's
map sends a time to; exact identities (reverse∘reverse, stretch(f)∘stretch(1/f)); the physics of a
free flight (symmetric about its apex); and invariants every transformed trajectory must keep
(θ = θ_max at each impact, never below the head or past upright, ω ≤ 0 ≤ ω⁺ at impacts and the
curve's velocity jump agreeing with the impact table).

Tolerances (measured on this machine, each bound stated with its margin):

- identities of exact trajectories: θ, ω within 1e-12 (measured ≤ 3e-15 rad, ≤ 4e-14 rad/s);
- the Hermite curve through 1 kHz samples against the exact stroke at random times: θ within
  1e-10 rad (measured 3.0e-11 free-bounce, 5.4e-11 high-low, 1.0e-12 finger-pulses);
- a sampled trajectory stretched by f then 1/f and read at 777 Hz (off the sample grid) against the
  exact stroke: θ within 1e-10 rad, ω within 1e-6 rad/s (measured 5.5e-12 rad, 1.6e-8 rad/s).
"""

import math
import re

import numpy as np
import pytest

import drumstroke
from drumstroke import ParameterError
from drumstroke.palette.motion import RETURN_LIMITS, Limits, concat
from drumstroke.palette.transforms import (
    apply_steps,
    catch,
    compress,
    compress_limit,
    reverse,
    stretch,
    trim,
)
from drumstroke.trajectory import THETA_TOP, Trajectory

PRESETS = ("free-bounce", "finger-pulses", "high-low", "reversed-gravity", "low-high", "constant",
           "rising-gravity", "superhuman-press")
IDENTITY_TOL = 1e-12  # rad, rad/s, s
HERMITE_TOL = 1e-10  # rad
AT_HEAD_TOL = 1e-9  # rad: θ at an impact time
COR = 0.86  # the presets' coefficient of restitution


@pytest.fixture(scope="module")
def strokes():
    return {name: drumstroke.simulate(name) for name in PRESETS}


@pytest.fixture(scope="module")
def exact(strokes):
    return {name: Trajectory.from_stroke(stroke) for name, stroke in strokes.items()}


def from_samples(stroke, rate=1000.0):
    """A trajectory through the stroke's samples at ``rate`` (Hz), as a library file holds it."""
    t, theta, omega = stroke.sample(rate)
    return Trajectory.from_samples(t, theta, omega, stroke.impacts, -stroke.recipe.cor * stroke.impacts.omega,
                                   theta_max=stroke.recipe.theta_max, name=stroke.recipe.name)


def random_times(rng, t_end, n=10_000):
    return rng.uniform(0.0, t_end, n)


def stroke_from(theta0, omega0, force, t_end=1.5, **recipe):
    """A stroke under a constant thumb force (m/s^2), from θ0 (rad) and ω0 (rad/s)."""
    return drumstroke.simulate(drumstroke.Recipe(force=drumstroke.Constant(force), theta0=theta0, omega0=omega0,
                                                 t_end=t_end, **recipe))


def assert_same_trajectory(a, b, times, tol=IDENTITY_TOL):
    """θ, ω at ``times`` and at 1 kHz, the impacts and ω after them agree within ``tol``."""
    assert abs(a.t_end - b.t_end) <= tol
    for x, y in ((a.state(times), b.state(times)), (a.sample(1000.0).columns()[1:], b.sample(1000.0).columns()[1:])):
        np.testing.assert_allclose(x[0], y[0], rtol=0, atol=tol)
        np.testing.assert_allclose(x[1], y[1], rtol=0, atol=tol)
    assert len(a.impacts) == len(b.impacts)
    np.testing.assert_allclose(a.impacts.t, b.impacts.t, rtol=0, atol=tol)
    np.testing.assert_allclose(a.impacts.omega, b.impacts.omega, rtol=0, atol=tol)
    np.testing.assert_allclose(a.omega_after, b.omega_after, rtol=0, atol=tol)


# --- reverse∘reverse and stretch(f)∘stretch(1/f) are the identity --------------------------------------------------


@pytest.mark.parametrize("name", ["free-bounce", "finger-pulses", "high-low", "reversed-gravity"])
def test_reverse_twice_is_the_identity(exact, name, rng):
    s = exact[name]
    assert_same_trajectory(reverse(reverse(s)), s, random_times(rng, s.t_end))


def test_reverse_twice_is_the_identity_for_a_sampled_trajectory(strokes, rng):
    s = from_samples(strokes["free-bounce"])
    assert_same_trajectory(reverse(reverse(s)), s, random_times(rng, s.t_end))


@pytest.mark.parametrize("factor", [0.37, 2.5, 7.0])
@pytest.mark.parametrize("name", ["free-bounce", "finger-pulses", "high-low", "reversed-gravity"])
def test_stretch_then_unstretch_is_the_identity(exact, name, factor, rng):
    s = exact[name]
    assert_same_trajectory(stretch(stretch(s, factor), 1.0 / factor), s, random_times(rng, s.t_end))


@pytest.mark.parametrize("factor", [0.37, 2.5, 7.0])
@pytest.mark.parametrize("name", ["free-bounce", "finger-pulses", "high-low"])
def test_stretch_then_unstretch_of_samples_stays_within_sampling_tolerance(strokes, name, factor, rng):
    stroke = strokes[name]
    sampled = from_samples(stroke)
    back = stretch(stretch(sampled, factor), 1.0 / factor)
    # The transforms wrap the curve's time map, never resample: back is the sampled curve itself ...
    assert_same_trajectory(back, sampled, random_times(rng, stroke.t_end))
    # ... and read off the sample grid (777 Hz) it is as close to the physics as the Hermite curve is.
    t, theta, omega = back.sample(777.0)
    theta_exact, omega_exact = stroke.state(np.minimum(t, stroke.t_end))
    np.testing.assert_allclose(theta, theta_exact, rtol=0, atol=HERMITE_TOL)
    np.testing.assert_allclose(omega, omega_exact, rtol=0, atol=1e-6)


# --- stretch -------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("factor", [0.37, 2.5, 7.0])
@pytest.mark.parametrize("name", ["free-bounce", "finger-pulses", "reversed-gravity"])
def test_stretch_scales_times_and_speeds(strokes, exact, name, factor, rng):
    stroke = strokes[name]
    s = stretch(exact[name], factor)
    assert s.t_end == stroke.t_end * factor
    assert np.array_equal(s.impacts.t, stroke.impacts.t * factor)
    assert np.array_equal(s.impacts.omega, stroke.impacts.omega / factor)
    assert np.array_equal(s.omega_after, -COR * stroke.impacts.omega / factor)
    np.testing.assert_allclose(s.impacts.tip_speed, stroke.impacts.tip_speed / factor, rtol=1e-15, atol=0)
    t = random_times(rng, s.t_end)
    theta, omega = s.state(t)
    theta_0, omega_0 = stroke.state(np.minimum(t / factor, stroke.t_end))
    np.testing.assert_allclose(theta, theta_0, rtol=0, atol=1e-13)
    np.testing.assert_allclose(omega, omega_0 / factor, rtol=0, atol=1e-13)


# --- compress ------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("factor", [0.25, 0.5, 1.7])
@pytest.mark.parametrize("name", ["free-bounce", "high-low", "reversed-gravity"])
def test_compress_scales_the_excursion_and_the_speeds(strokes, exact, name, factor, rng):
    stroke = strokes[name]
    head = stroke.recipe.theta_max
    s = compress(exact[name], factor)
    assert s.t_end == stroke.t_end
    assert np.array_equal(s.impacts.t, stroke.impacts.t)
    assert np.array_equal(s.impacts.omega, stroke.impacts.omega * factor)
    np.testing.assert_allclose(s.impacts.tip_speed, stroke.impacts.tip_speed * factor, rtol=1e-15, atol=0)
    np.testing.assert_allclose(s.impacts.level_db - stroke.impacts.level_db, 20.0 * math.log10(factor),
                               rtol=0, atol=1e-12)
    t = random_times(rng, s.t_end)
    theta, omega = s.state(t)
    theta_0, omega_0 = stroke.state(t)
    np.testing.assert_allclose(theta - head, factor * (theta_0 - head), rtol=0, atol=1e-15)
    np.testing.assert_allclose(omega, factor * omega_0, rtol=1e-15, atol=0)


@pytest.mark.parametrize("name", ["free-bounce", "reversed-gravity", "rising-gravity"])
def test_compress_refuses_a_factor_past_its_limit(exact, name):
    s = exact[name]
    top = compress_limit(s)
    allowed = re.escape(f"factor must be in (0, {top:.6g}]")
    with pytest.raises(ParameterError, match=allowed):
        compress(s, top * (1 + 1e-9))
    for bad in (0.0, -1.0, math.nan):
        with pytest.raises(ParameterError, match=r"^factor must be"):
            compress(s, bad)


def top_of(trajectory):
    """The highest θ (rad): on a 10 kHz grid, at t_end, and at every apex (where ω changes sign)."""
    t = np.append(np.arange(0.0, trajectory.t_end, 1e-4), trajectory.t_end)
    apexes = trajectory.apexes[np.isfinite(trajectory.apexes)]
    return max(trajectory.state(t)[0].max(), trajectory.state(apexes)[0].max(initial=-np.inf))


@pytest.mark.parametrize("name", ["free-bounce", "reversed-gravity", "rising-gravity", "high-drop"])
def test_compress_at_its_limit_reaches_upright_and_never_passes_it(exact, name):
    s = exact.get(name) or Trajectory.from_stroke(stroke_from(0.5, 0.0, 0.0, t_end=6.0), name=name)
    top = top_of(compress(s, compress_limit(s)))
    assert top >= THETA_TOP - 1e-9  # the limit is the largest factor, not a conservative one
    assert top <= THETA_TOP


# --- reverse -------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["free-bounce", "finger-pulses", "reversed-gravity"])
def test_reverse_mirrors_time_and_swaps_speeds(strokes, exact, name, rng):
    stroke = strokes[name]
    r = reverse(exact[name])
    end = stroke.t_end
    assert r.t_end == end
    assert np.array_equal(r.impacts.t, end - stroke.impacts.t[::-1])
    assert np.all(np.diff(r.impacts.t) > 0)
    assert np.array_equal(r.impacts.omega, COR * stroke.impacts.omega[::-1])
    assert np.array_equal(r.omega_after, -stroke.impacts.omega[::-1])
    t = random_times(rng, end)
    theta, omega = r.state(t)
    theta_0, omega_0 = stroke.state(end - t)
    np.testing.assert_allclose(theta, theta_0, rtol=0, atol=1e-13)
    np.testing.assert_allclose(omega, -omega_0, rtol=0, atol=1e-13)


def test_reversed_free_bounce_gains_energy_at_every_impact(exact):
    r = reverse(exact["free-bounce"])
    gain = np.abs(r.omega_after) / np.abs(r.impacts.omega)
    np.testing.assert_allclose(gain, 1.0 / COR, rtol=1e-12, atol=0)
    # The curve agrees: just after each (well separated) reversed impact the stick leaves 1/c faster.
    t = r.impacts.t
    gaps = np.diff(np.concatenate(([0.0], t, [r.t_end])))
    spaced = (gaps[:-1] > 1e-3) & (gaps[1:] > 1e-3)
    assert spaced.sum() >= 20
    _, after = r.state(t[spaced] + 1e-10)
    _, before = r.state(t[spaced] - 1e-10)
    np.testing.assert_allclose(after / -before, 1.0 / COR, rtol=1e-6)


# --- trim ----------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["free-bounce", "finger-pulses", "reversed-gravity"])
def test_trim_keeps_the_impacts_in_the_window_and_shifts_time(strokes, exact, name, rng):
    stroke = strokes[name]
    impact_t = stroke.impacts.t
    windows = [tuple(np.sort(rng.uniform(0.0, stroke.t_end, 2))) for _ in range(3)]
    windows.append((float(impact_t[2]), float(impact_t[5])))  # the ends are impacts: both kept
    for t0, t1 in windows:
        s = trim(exact[name], t0, t1)
        keep = (impact_t >= t0) & (impact_t <= t1)
        assert s.t_end == t1 - t0
        assert np.array_equal(s.impacts.t, impact_t[keep] - t0)
        assert np.array_equal(s.impacts.omega, stroke.impacts.omega[keep])
        assert np.array_equal(s.omega_after, -COR * stroke.impacts.omega[keep])
        t = random_times(rng, s.t_end, 2000)
        theta, omega = s.state(t)
        theta_0, omega_0 = stroke.state(np.minimum(t + t0, stroke.t_end))
        np.testing.assert_allclose(theta, theta_0, rtol=0, atol=1e-13)
        np.testing.assert_allclose(omega, omega_0, rtol=0, atol=1e-12)
    assert len(trim(exact[name], float(impact_t[2]), float(impact_t[5])).impacts) == 4


@pytest.mark.parametrize("t0, t1, name", [
    (math.nan, None, "t0"), (-0.1, None, "t0"), (5.0, None, "t0"), ("0", None, "t0"),
    (1.0, 1.0, "t1"), (1.0, 0.5, "t1"), (0.0, 5.5, "t1"), (0.0, math.nan, "t1"),
])
def test_trim_refuses_a_bad_window(exact, t0, t1, name):
    with pytest.raises(ParameterError, match=rf"^{name} must be"):
        trim(exact["free-bounce"], t0, t1)


# --- catch and apexes ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name, numbers", [("free-bounce", (1, 2, 5, 30)), ("finger-pulses", (1, 2, 12)),
                                           ("high-low", (1, 3, 60)), ("reversed-gravity", (1, 2, 100))])
def test_catch_ends_at_the_apex_after_impact_n(strokes, exact, name, numbers):
    stroke = strokes[name]
    impact_t = stroke.impacts.t
    for n in numbers:
        caught = catch(exact[name], n)
        apex = exact[name].apex_after(n)
        assert caught.t_end == apex
        assert impact_t[n - 1] < apex < impact_t[n]
        assert len(caught.impacts) == n
        assert np.array_equal(caught.impacts.t, impact_t[:n])
        theta, omega = caught.state([caught.t_end])
        assert abs(omega[0]) < 1e-6
        dense = stroke.state(np.linspace(impact_t[n - 1], impact_t[n], 200_001))[0]
        assert abs(theta[0] - dense.max()) < 1e-9


def test_free_bounce_flights_are_symmetric_about_their_apex(strokes, exact):
    # Under constant gravity the flight is time-reversible: the apex is half way between impacts.
    t = strokes["free-bounce"].impacts.t
    for n in (1, 2, 3, 10):
        assert abs(exact["free-bounce"].apex_after(n) - (t[n - 1] + 0.5 * (t[n] - t[n - 1]))) < 1e-9


@pytest.mark.parametrize("n", [0, 99, -1, 1.0, True])
def test_catch_refuses_a_bad_impact_number(exact, n):
    with pytest.raises(ParameterError, match=re.escape("n must be an impact number in [1, 98]")):
        catch(exact["free-bounce"], n)


# --- invariants of every transform and chain of transforms ---------------------------------------------------------


def random_step(s, rng):
    """A random valid transform of ``s`` and its name."""
    op = rng.choice(["stretch", "compress", "reverse", "trim", "catch"])
    if op == "catch" and len(s.impacts) < 2:
        op = "reverse"
    if op == "stretch":
        return stretch(s, float(np.exp(rng.uniform(np.log(0.3), np.log(3.0)))))
    if op == "compress":
        return compress(s, float(rng.uniform(0.2, 0.95) * min(2.0, compress_limit(s))))
    if op == "reverse":
        return reverse(s)
    if op == "trim":
        return trim(s, float(rng.uniform(0.0, 0.4) * s.t_end), float(rng.uniform(0.6, 1.0) * s.t_end))
    return catch(s, int(rng.integers(1, min(len(s.impacts), 6))))


def assert_consistent(s):
    """The impacts lie on the curve, the curve never leaves [θ_max, π/2]."""
    t, omega, after = s.impacts.t, s.impacts.omega, s.omega_after
    assert len(omega) == len(after) == len(t)
    assert np.all(np.diff(t) > 0)
    assert np.all((t > 0.0) & (t < s.t_end))
    assert np.all(omega <= 0.0) and np.all(after >= 0.0)
    theta_at, _ = s.state(t)
    np.testing.assert_allclose(theta_at, s.theta_max, rtol=0, atol=AT_HEAD_TOL)
    _, theta, _ = s.sample(1000.0)
    assert theta.min() >= s.theta_max
    assert theta.max() <= THETA_TOP
    # The curve's velocity jumps at each impact as the table says (impacts well apart from their neighbours).
    gaps = np.diff(np.concatenate(([0.0], t, [s.t_end])))
    spaced = (gaps[:-1] > 1e-5) & (gaps[1:] > 1e-5)
    delta = 1e-9
    _, before = s.state(t[spaced] - delta)
    _, leaving = s.state(t[spaced] + delta)
    np.testing.assert_allclose(before, omega[spaced], rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(leaving, after[spaced], rtol=1e-4, atol=1e-6)


@pytest.mark.parametrize("name", PRESETS)
def test_every_single_transform_keeps_impacts_on_the_curve(exact, name):
    s = exact[name]
    assert_consistent(s)
    for t in (stretch(s, 0.37), stretch(s, 4.0), compress(s, 0.3), compress(s, compress_limit(s) * 0.99),
              reverse(s), trim(s, 0.3, 0.8 * s.t_end), catch(s, 2)):
        assert_consistent(t)


def test_random_chains_of_transforms_keep_impacts_on_the_curve(exact, rng):
    for _ in range(40):
        s = exact[PRESETS[rng.integers(len(PRESETS))]]
        for _ in range(rng.integers(1, 5)):
            s = random_step(s, rng)
        assert_consistent(s)


# --- concat --------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def caught():
    """A single (caught after 1 impact), a double (after 2) and a free bounce caught after its 3rd."""
    single = catch(stroke_from(0.1, -2.0, 200.0, t_end=1.0), 1)
    double = catch(stroke_from(0.1, -2.0, 120.0), 2)
    bounce = catch(drumstroke.simulate("free-bounce"), 3)
    return single, double, bounce


def check_returns(c, pieces, starts, limits):
    """Continuity at each join and the limits in each gap, on a 10 kHz grid."""
    dt = 1e-4
    ends = [s + p.t_end for s, p in zip(starts, pieces)]
    for k, (gap_start, gap_end) in enumerate(zip(ends[:-1], starts[1:])):
        for join in (gap_start, gap_end):
            eps = 1e-9
            (theta_a, theta_b), (omega_a, omega_b) = c.state([join - eps, join + eps])
            assert abs(theta_b - theta_a) <= 2 * eps * limits.max_speed + 1e-12
            assert abs(omega_b - omega_a) <= 2 * eps * limits.max_acceleration + 1e-9
        t = np.append(np.arange(gap_start, gap_end, dt), gap_end)
        theta, omega = c.state(t)
        assert np.abs(omega).max() <= limits.max_speed
        assert (np.abs(np.diff(omega)) / np.diff(t)).max() <= limits.max_acceleration * (1 + 1e-6)
        assert theta.min() >= c.theta_max and theta.max() <= THETA_TOP
    # No jump anywhere: θ moves at most max|ω|·dt between 10 kHz samples.
    theta, omega = c.sample(1.0 / dt).columns()[1:]
    assert np.abs(np.diff(theta)).max() <= np.abs(omega).max() * dt * 1.01


@pytest.mark.parametrize("limits", [RETURN_LIMITS, Limits(max_speed=6.0, max_acceleration=300.0)])
def test_concat_places_strokes_after_their_gaps_and_returns_smoothly(caught, limits):
    single, double, bounce = caught
    pieces, gaps = [single, double, bounce], [0.3, 0.45]
    c = concat(pieces, gaps, limits=limits)
    start_2 = single.t_end + gaps[0]
    start_3 = start_2 + double.t_end + gaps[1]
    assert abs(c.t_end - (start_3 + bounce.t_end)) < 1e-12
    n1, n2 = len(single.impacts), len(double.impacts)
    assert len(c.impacts) == n1 + n2 + len(bounce.impacts)
    assert np.array_equal(c.impacts.t[:n1], single.impacts.t)
    assert np.array_equal(c.impacts.t[n1:n1 + n2], double.impacts.t + start_2)
    np.testing.assert_allclose(c.impacts.t[n1 + n2:], bounce.impacts.t + start_3, rtol=0, atol=1e-12)
    assert np.array_equal(c.impacts.omega, np.concatenate([p.impacts.omega for p in pieces]))
    assert np.array_equal(c.omega_after, np.concatenate([p.omega_after for p in pieces]))
    # Within each stroke the motion is the stroke's own.
    for piece, start in zip(pieces, (0.0, start_2, start_3)):
        t = np.linspace(0.0, piece.t_end, 501)[1:-1]
        np.testing.assert_allclose(c.state(t + start)[0], piece.state(t)[0], rtol=0, atol=1e-12)
    check_returns(c, pieces, [0.0, start_2, start_3], limits)
    assert_consistent(c)


def test_concat_names_a_gap_too_short_and_how_long_it_needs(caught):
    single, double, _ = caught
    with pytest.raises(ParameterError, match=r"^gaps\[0\] = 0.001 s is too short") as error:
        concat([single, single], 0.001)
    need = float(re.search(r"it needs at least ([0-9.e+-]+) s", str(error.value)).group(1))
    assert 0.001 < need < 1.0
    c = concat([single, single], need * 1.001)  # the stated need (to its 4 printed digits) is enough
    check_returns(c, [single, single], [0.0, single.t_end + need * 1.001], RETURN_LIMITS)
    with pytest.raises(ParameterError, match=r"^gaps\[1\] = 0 s is too short.*it needs at least"):
        concat([single, double, single], [0.5, 0.0])


def test_concat_refuses_strokes_of_different_sticks(caught):
    single = caught[0]
    other_head = drumstroke.simulate(drumstroke.Recipe(force=drumstroke.Constant(0.0), model="geometry",
                                                       stick=drumstroke.Stick(pivot_to_tip=0.3)))
    with pytest.raises(ParameterError, match=r"^strokes\[1\] is for a different stick"):
        concat([single, other_head], 1.0)
    # Same head angle (h/x unchanged), twice as long a lever: still another stick.
    longer = drumstroke.Stick(length=0.78, pivot_to_tip=0.54, pivot_height=0.14)
    assert abs(longer.theta_max - single.theta_max) < 1e-12
    other_tip = drumstroke.simulate(drumstroke.Recipe(force=drumstroke.Constant(0.0), stick=longer))
    with pytest.raises(ParameterError, match=r"^strokes\[1\] is for a different stick"):
        concat([single, other_tip], 1.0)


# --- steps as a palette or recipe file writes them -----------------------------------------------------------------


def test_apply_steps_equals_the_direct_calls(strokes, exact, rng):
    steps = [{"catch": 2}, {"stretch": 1.5}, {"reverse": True}, {"trim": [0.1, 0.5]}, {"compress": 0.5}]
    got = apply_steps(strokes["free-bounce"], steps)
    want = compress(trim(reverse(stretch(catch(exact["free-bounce"], 2), 1.5)), 0.1, 0.5), 0.5)
    t = random_times(rng, want.t_end)
    assert got.t_end == want.t_end
    for x, y in zip(got.state(t), want.state(t)):
        assert np.array_equal(x, y)
    assert np.array_equal(got.impacts.t, want.impacts.t)
    assert np.array_equal(got.impacts.omega, want.impacts.omega)
    assert np.array_equal(got.omega_after, want.omega_after)
    assert got.history[1:] == ("catch 2", "stretch 1.5", "reverse", "trim 0.1..0.5", "compress 0.5")


@pytest.mark.parametrize("steps, message", [
    ([{"stretch": 2.0, "reverse": True}], r"^transforms\[0\] must be a one-key table"),
    ([{"stretch": 2.0}, {"flip": True}], r"^transforms\[1\] must be a one-key table"),
    ([{"reverse": False}], r"^transforms\[0\] \(reverse\): reverse must be true"),
    ([{"stretch": 2.0}, {"trim": [1]}], r"^transforms\[1\] \(trim\): trim must be \[start, end\]"),
    ([{"catch": 0}], r"^transforms\[0\] \(catch\): n must be an impact number"),
    ([{"stretch": 1000.0}], r"^transforms\[0\] \(stretch\): factor must be in"),
    ({"stretch": 2.0}, r"^transforms must be a list"),
])
def test_apply_steps_refuses_malformed_steps(exact, steps, message):
    with pytest.raises(ParameterError, match=message):
        apply_steps(exact["free-bounce"], steps)


# --- the Hermite curve through samples -----------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["free-bounce", "high-low", "finger-pulses"])
def test_samples_at_1khz_reproduce_the_exact_trajectory(strokes, name, rng):
    stroke = strokes[name]
    sampled = from_samples(stroke)
    t = rng.uniform(0.0, stroke.t_end, 100_000)
    theta, _ = sampled.state(t)
    assert np.abs(theta - stroke.state(t)[0]).max() < HERMITE_TOL
    grid, theta_grid, omega_grid = stroke.sample(1000.0)
    at_grid = sampled.state(grid)
    assert np.array_equal(at_grid[0], theta_grid)
    assert np.array_equal(at_grid[1], omega_grid)
    impact_theta, _ = sampled.state(stroke.impacts.t)
    assert np.all(impact_theta == stroke.recipe.theta_max)


def test_samples_landing_on_an_impact_keep_the_curve_whole(exact, rng):
    # Trimmed so that the first impact falls on the 1 kHz grid (to round-off): the curve through the
    # samples must still break cleanly there, not divide by a zero-length piece.
    bounce = exact["free-bounce"]
    t0 = float(bounce.impacts.t[0]) - 0.1
    s = trim(bounce, t0, 3.0)
    on_grid = s.impacts.t * 1000.0
    assert abs(on_grid[0] - 100.0) < 1e-9
    t, theta, omega = s.sample(1000.0)
    sampled = Trajectory.from_samples(t, theta, omega, s.impacts, s.omega_after, theta_max=s.theta_max)
    times = np.concatenate((rng.uniform(0.0, s.t_end, 50_000), s.impacts.t[:3] + 1e-7, s.impacts.t[:3] - 1e-7))
    got, want = sampled.state(times), s.state(times)
    assert np.all(np.isfinite(got[0])) and np.all(np.isfinite(got[1]))
    assert np.abs(got[0] - want[0]).max() < HERMITE_TOL
    np.testing.assert_allclose(got[1], want[1], rtol=0, atol=1e-6)
