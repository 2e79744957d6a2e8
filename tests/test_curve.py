"""The one exact motion type: curves of segments, checked against closed forms."""

import math

import numpy as np
import pytest

from drumstroke.curve import STEP, Curve, Segment
from drumstroke.errors import ParameterError


def _parabola(acceleration, theta0=0.0, omega0=0.0):
    """θ = θ0 + ω0 t + a t²/2: its ω is linear, so a central difference gives a exactly (to round-off)."""
    def path(t):
        t = np.asarray(t, dtype=float)
        return theta0 + omega0 * t + 0.5 * acceleration * t * t, omega0 + acceleration * t
    return path


def _bounce(head=-0.25, speed=2.0, gravity=-9.0, cor=0.5):
    """A ball's fall onto ``head`` at local t = 0 (ω = −speed) and its rebound at cor·speed, under constant α."""
    def path(t):
        t = np.asarray(t, dtype=float)
        after = t >= 0.0
        omega0 = np.where(after, cor * speed, -speed)
        return head + omega0 * t + 0.5 * gravity * t * t, omega0 + gravity * t
    return path


def test_a_hold_stays_still_with_no_speed_or_acceleration():
    curve = Curve.hold(0.3, 1.0)
    t = np.linspace(0.0, 5.0, 11)
    theta, omega = curve(t)
    assert np.all(theta == 0.3) and np.all(omega == 0.0)
    assert np.all(curve.acceleration(t) == 0.0)
    assert curve.state(2.0) == (0.3, 0.0)


def test_each_time_is_evaluated_by_the_segment_that_holds_it_on_its_own_clock():
    curve = Curve.sequence([(1.0, _parabola(2.0)), (1.0, _parabola(0.0, 1.0, 2.0))])
    theta, omega = curve(np.array([0.5, 1.0, 1.5]))
    assert theta.tolist() == [0.25, 1.0, 2.0]  # at the boundary the later segment: its local 0
    assert omega.tolist() == [1.0, 2.0, 2.0]


def test_times_outside_the_span_are_clamped_to_it():
    curve = Curve.sequence([(1.0, _parabola(2.0))], start=1.0)
    theta, omega = curve(np.array([0.0, 3.0]))
    assert theta.tolist() == [0.0, 1.0] and omega.tolist() == [0.0, 2.0]


def test_unsorted_times_give_what_sorted_times_give(rng):
    curve = Curve.sequence([(0.3, _parabola(2.0)), (0.5, _parabola(-1.0, 0.09, 0.6)), (1.0, _parabola(0.0, 0.5))])
    t = rng.uniform(-0.1, 2.0, 200)
    order = np.argsort(t)
    theta, omega = curve(t)
    sorted_theta, sorted_omega = curve(t[order])
    assert np.array_equal(theta[order], sorted_theta) and np.array_equal(omega[order], sorted_omega)
    grid = np.reshape(t, (20, 10))
    assert curve(grid)[0].shape == (20, 10)


def test_acceleration_is_the_flight_acceleration_exactly_for_constant_forcing():
    curve = Curve.sequence([(1.0, _parabola(-7.5, 0.1, 3.0)), (1.0, _parabola(4.0, 0.1, 0.0))])
    t = np.linspace(0.0, 2.0, 2001)
    alpha = curve.acceleration(t)
    expected = np.where(t < 1.0, -7.5, 4.0)
    assert np.abs(alpha - expected).max() < 1e-6 * 7.5  # one-sided at the segments' edges: never across


def test_acceleration_is_one_sided_across_an_impact():
    segment = Segment(0.0, 1.0, _bounce(), offset=0.5, impacts=np.array([0.0]))
    curve = Curve((segment,))
    t = 0.5 + np.array([-STEP / 2, 0.0, STEP / 2, 0.3])
    assert np.abs(curve.acceleration(t) - (-9.0)).max() < 1e-6  # without it: a jump of 3 rad/s over 2 µs
    assert curve.impacts.tolist() == [0.5]


def test_a_splice_keeps_the_motion_before_the_cut_and_plays_the_new_one_after():
    first = Curve.sequence([(2.0, _parabola(1.0))])
    later = Curve.sequence([(1.0, _parabola(-1.0, 0.5, 1.0))], start=1.0)
    spliced = first.spliced(later)
    assert [s.start for s in spliced.segments] == [0.0, 1.0] and spliced.segments[0].end == 1.0
    theta, _ = spliced(np.array([0.5, 1.0, 1.5]))
    assert theta.tolist() == [0.125, 0.5, 0.5 + 0.5 - 0.125]
    assert spliced.since(1.5).segments == spliced.segments[1:]


def _one_at_a_time(curve, t):
    """θ, ω and α at each time alone, as the module says, in Python floats: the last segment that starts at or
    before it (the first before the curve starts), on its clock, clamped to its span; α the slope of ω over
    2·STEP, one-sided where the span's end or an impact lies within the step, 0 on a still segment."""
    rows = []
    for time in t.tolist():
        segment = next((s for s in reversed(curve.segments) if s.start <= time), curve.segments[0])
        local = min(max(time, segment.start), segment.end) - segment.offset
        theta, omega = (float(x[0]) for x in segment.path(np.array([local])))
        lo = max(local - STEP, segment.start - segment.offset)
        hi = min(local + STEP, segment.end - segment.offset)
        lo = local if any(lo < i <= local for i in segment.impacts.tolist()) else lo
        hi = local if any(local < i < hi for i in segment.impacts.tolist()) else hi
        slope = (float(segment.path(np.array([hi]))[1][0]) - float(segment.path(np.array([lo]))[1][0])) / (hi - lo)
        rows.append((theta, omega, 0.0 if segment.still or hi == lo else slope))
    return np.array(rows).reshape(-1, 3).T


def test_a_chunk_of_setpoints_is_each_time_evaluated_alone_to_the_bit(rng):
    """The quick paths (increasing times as runs, the clamp skipped within a span, one path call per run for θ,
    ω and both ends of α's step) agree exactly with each time evaluated on its own."""
    curve = Curve.sequence([(0.4, _parabola(1.0, 0.2, 0.5))], start=0.1) \
        .spliced(Segment(0.5, 1.25, _bounce(), offset=1.0, impacts=np.array([0.0, 0.125]))) \
        .spliced(Curve.sequence([(0.25, _parabola(3.0, -0.1, -1.0))], start=1.25)) \
        .spliced(Curve((Segment.hold(0.05, 1.5, 1.75), Segment(1.75, 2.0, _parabola(-2.0), offset=1.75))))
    samples = np.arange(0, 2201) / 1000.0  # before, through and after it: every boundary, the impacts at 1, 1.125 s
    edges = np.array([s.start for s in curve.segments] + [1.0, 1.125])
    near = np.concatenate((edges - STEP / 2, edges, edges + STEP / 2, edges + 3 * STEP))
    for t in (samples, samples[480:530], np.sort(near), rng.uniform(-0.5, 3.0, 300), np.array([1.0])):
        expected = _one_at_a_time(curve, t)
        assert all(np.array_equal(got, want) for got, want in zip(curve.evaluate(t), expected))
        assert all(np.array_equal(got, want) for got, want in zip(curve(t), expected[:2]))
        assert np.array_equal(curve.acceleration(t), expected[2])
    assert [curve.state(time) for time in near.tolist()] == list(zip(*_one_at_a_time(curve, near)[:2].tolist()))


def test_a_splice_and_a_forgetting_make_curves_that_pass_the_checks():
    """Both skip the checks (their segments tile by construction): the curve they make passes them."""
    curve = Curve.hold(0.0)
    for k in range(1, 6):
        curve = curve.spliced(Curve.sequence([(0.3, _parabola(1.0)), (0.2, _parabola(-1.0))], start=0.4 * k))
        curve = curve.since(0.4 * k - 0.3)
        checked = Curve(curve.segments)
        assert [(s.start, s.end) for s in checked.segments] == [(s.start, s.end) for s in curve.segments]
    assert np.allclose([s.start for s in curve.segments], [1.6, 1.9, 2.0, 2.3], rtol=0.0, atol=1e-15)
    with pytest.raises(ParameterError, match="new must be a Segment or a Curve"):
        curve.spliced((1.0, _parabola(0.0)))


def test_several_joints_are_columns_of_one_curve():
    hold = Segment.hold([0.1, -0.2], 0.0, 1.0)
    move = Segment(1.0, math.inf, lambda t: (np.column_stack((0.1 + t, -0.2 - t)), np.column_stack(
        (np.ones(np.shape(t)), -np.ones(np.shape(t))))), offset=1.0)
    curve = Curve((hold, move))
    theta, omega = curve(np.array([0.5, 1.5]))
    assert theta.shape == (2, 2) and theta.tolist() == [[0.1, -0.2], [0.6, -0.7]]
    assert omega.tolist() == [[0.0, 0.0], [1.0, -1.0]]
    assert np.abs(curve.acceleration(np.array([0.5, 1.5]))).max() < 1e-6
    state = curve.state(1.5)
    assert np.allclose(state[0], [0.6, -0.7])


@pytest.mark.parametrize("segments, match", [
    ((), "non-empty"),
    ((Segment.hold(0.0, 0.0, 1.0), Segment.hold(0.0, 1.5)), r"segments\[1\] starts at 1.5"),
])
def test_segments_must_tile_the_span(segments, match):
    with pytest.raises(ParameterError, match=match):
        Curve(segments)


@pytest.mark.parametrize("start, end", [(1.0, 0.5), (math.nan, 1.0), (0.0, math.nan), (math.inf, math.inf)])
def test_a_segment_ends_at_or_after_its_start(start, end):
    with pytest.raises(ParameterError, match="end must be at or after its start"):
        Segment(start, end, _parabola(0.0))


def test_a_curve_cut_and_joined_without_checks_equals_one_checked_from_its_segments():
    """spliced and since trust segments that tile (they are cut from a curve): the result is the curve the checked
    constructor makes of the same segments, at every time."""
    rise = Segment(0.5, 1.0, lambda t: (2.0 * t, np.full(np.shape(t), 2.0)), offset=0.5)
    joined = Curve.hold(0.0).spliced(Curve((rise, Segment.hold(1.0, 1.0))))
    checked = Curve(joined.segments)
    t = np.linspace(-1.0, 3.0, 401)
    for a, b in zip(joined.evaluate(t), checked.evaluate(t)):
        np.testing.assert_array_equal(a, b)
    later = joined.since(0.75)
    assert later.segments == joined.segments[1:]
    np.testing.assert_array_equal(later(t[t >= 0.75])[0], checked(t[t >= 0.75])[0])


def test_evenly_spaced_samples_carry_the_solvers_arcs_and_leave_other_paths_alone():
    """With ``spacing`` the arcs' runs are carried by the addition theorem (within round-off of each sample
    afresh, the closed form); a closure's values are the same to the bit, and so are times clamped to a span."""
    from drumstroke import simulate

    stroke = simulate("free-bounce", t_end=1.0)
    still, rising = (0.4, _parabola(3.0, 0.2, 1.0))
    curve = Curve((Segment.hold(still, 0.0, 0.3), Segment(0.3, 1.3, stroke.arcs.evaluate, 0.3, stroke.impacts.t),
                   Segment(1.3, 2.0, rising, 1.3)))
    t = np.minimum(np.arange(2101) / 1000.0, 2.05)
    fresh, carried = curve(t), curve(t, spacing=1e-3)
    inside = (t > 0.3) & (t < 1.3)
    for a, b in zip(fresh, carried):
        np.testing.assert_array_equal(a[~inside], b[~inside])
        np.testing.assert_allclose(b[inside], a[inside], rtol=0, atol=1e-12)
    assert np.any(fresh[0][inside] != carried[0][inside])  # carried indeed: not each sample afresh


def test_a_stick_curves_strokes_holds_and_moves_sampled_in_one_call_equal_each_segment_alone_to_the_bit():
    """A curve with the solver's arcs evaluates its runs of samples in one compiled call: each run the same to the
    bit as its segment's own path on it (the arcs carried over the run), a closure's run by the closure, a run past
    the curve's end clamped; a jerk-limited move's path is ruckig's own motion (to round-off)."""
    from drumstroke import simulate
    from drumstroke.palette.motion import Limits, plan_move

    first, second = simulate("free-bounce", t_end=0.7), simulate("free-bounce", t_end=0.5, theta0=0.3)
    end = first.arcs.evaluate(np.array([0.7]))[0][0]
    duration, move = plan_move((end, 0.0), (0.3, 0.0), 0.4, theta_max=first.recipe.theta_max, limits=Limits())
    segments = (Segment.hold(0.3, 0.0, 0.25), Segment(0.25, 0.95, first.arcs.evaluate, 0.25, first.impacts.t),
                Segment(0.95, 1.35, move, 0.95), Segment.hold(0.3, 1.35, 1.5),
                Segment(1.5, 2.0, second.arcs.evaluate, 1.5, second.impacts.t),
                Segment(2.0, 2.2, _parabola(3.0, 0.2, 1.0), 2.0))
    curve = Curve(segments)
    t = np.minimum(np.arange(2301) / 1000.0, 2.25)  # the last samples past the end: clamped
    theta, omega = curve(t, spacing=1e-3)
    which = np.maximum(np.searchsorted([s.start for s in segments], t, side="right") - 1, 0)
    for k, segment in enumerate(segments):
        run = t[which == k]
        inside = segment.start <= run[0] and run[-1] <= segment.end
        local = (run if inside else np.minimum(np.maximum(run, segment.start), segment.end)) - segment.offset
        spaced = inside and getattr(segment.path, "__self__", None) is not None
        alone = segment.path(local, spacing=1e-3) if spaced else segment.path(local)
        np.testing.assert_array_equal(theta[which == k], alone[0], err_msg=f"segment {k}")
        np.testing.assert_array_equal(omega[which == k], alone[1], err_msg=f"segment {k}")
    from drumstroke.solver.kernel import ARCS, CUBIC, HOLD, PATH

    assert curve._layout[0].tolist() == [HOLD, ARCS, CUBIC, HOLD, ARCS, PATH]  # the call this test is about
    import ruckig

    parameters = ruckig.InputParameter(1)
    parameters.current_position, parameters.target_position = [end], [0.3]
    parameters.current_velocity = parameters.current_acceleration = [0.0]
    parameters.target_velocity = parameters.target_acceleration = [0.0]
    limits = Limits()
    parameters.max_velocity = [0.98 * limits.max_speed]
    parameters.max_acceleration = [0.98 * limits.max_acceleration]
    parameters.max_jerk = [0.98 * limits.max_jerk]
    parameters.minimum_duration = 0.4
    trajectory = ruckig.Trajectory(1)
    ruckig.Ruckig(1).calculate(parameters, trajectory)
    local = np.linspace(0.0, 0.4, 41)
    expected = np.array([trajectory.at_time(float(x))[:2] for x in local])[:, :, 0]
    np.testing.assert_allclose(np.column_stack(move(local)), expected, rtol=0, atol=1e-12)


def test_the_runs_of_increasing_times_are_numpys_search_of_the_segments_starts(rng):
    """kernel.runs_of (one pass over sorted times) finds the runs numpy's searchsorted finds: each time's segment the
    last starting at or before it (the first before the start), times on a start in the later segment."""
    from drumstroke.solver.kernel import runs_of

    for _ in range(200):
        starts = np.cumsum(rng.choice([0.0, 1e-3, 0.05, 0.3], int(rng.integers(1, 40))))
        t = np.sort(np.concatenate((rng.uniform(-0.1, starts[-1] + 0.1, int(rng.integers(1, 300))),
                                    rng.choice(starts, 5))))
        which = np.maximum(starts.searchsorted(t, side="right") - 1, 0)
        first = np.concatenate(([0], (which[1:] != which[:-1]).nonzero()[0] + 1, [t.size]))
        made_first, made_segment = runs_of(starts, t)
        np.testing.assert_array_equal(made_first, first)
        np.testing.assert_array_equal(made_segment, which[first[:-1]])
