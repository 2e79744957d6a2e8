"""Profiles: values, pieces (the solver's step boundaries), sums and sample files."""

import math

import numpy as np
import pytest

from drumstroke import Constant, ParameterError, PiecewiseLinear, Pulses, Samples, Sum
from drumstroke.profiles import profile_from_dict


def test_piecewise_linear_is_linear_between_points_and_constant_beyond():
    p = PiecewiseLinear([(0.5, 10.0), (1.0, 20.0), (2.0, 0.0)])
    assert p([0.0, 0.5, 0.75, 1.0, 1.5, 2.0, 9.0]).tolist() == [10.0, 10.0, 15.0, 20.0, 10.0, 0.0, 0.0]


def test_pulses_follow_amplitude_period_duty_phase_and_base():
    p = Pulses(amplitude=100.0, period=0.4, duty=0.25, phase=0.1, base=5.0)
    t = np.array([0.0, 0.099, 0.1, 0.19, 0.2, 0.49, 0.5, 0.6])
    assert p(t).tolist() == [5.0, 5.0, 105.0, 105.0, 5.0, 5.0, 105.0, 5.0]


def test_pulse_edges_are_piece_edges_with_the_right_values():
    pieces = Pulses(amplitude=189.0, period=0.4, duty=0.05, phase=0.08).pieces(1.0)
    expected = [0.0, 0.08, 0.1, 0.48, 0.5, 0.88, 0.9, 1.0]
    assert np.allclose(pieces.edges, expected, atol=1e-15)
    assert pieces.values.tolist() == [0.0, 189.0, 0.0, 189.0, 0.0, 189.0, 0.0]
    assert not pieces.slopes.any()


def test_pieces_reproduce_the_profile_between_edges():
    profile = Sum([PiecewiseLinear([(0.0, 0.0), (1.0, 100.0), (3.0, 40.0)]),
                   Pulses(amplitude=50.0, period=0.7, duty=0.3, phase=0.2), Constant(-3.0)])
    pieces = profile.pieces(4.0)
    rng = np.random.default_rng(7)
    for i in range(len(pieces)):
        left, right = pieces.edges[i], pieces.edges[i + 1]
        t = rng.uniform(left, right, 5)
        assert np.allclose(pieces.values[i] + pieces.slopes[i] * (t - left), profile(t), atol=1e-9)


def test_sum_is_the_sum_of_its_parts():
    a, b = PiecewiseLinear([(0.0, 1.0), (1.0, 3.0)]), Pulses(amplitude=2.0, period=0.5, duty=0.5)
    t = np.linspace(0.0, 2.0, 41)
    assert np.array_equal((a + b)(t), a(t) + b(t))


def test_samples_file_with_header_and_comments(tmp_path):
    path = tmp_path / "thumb.csv"
    path.write_text("# thumb sensor, m/s^2\nt,value\n0.0,0.0\n0.5,100.0\n1.0,50.0\n")
    samples = Samples(path)
    assert samples([0.25, 0.75, 2.0]).tolist() == [50.0, 75.0, 50.0]
    assert samples.to_dict() == {"kind": "samples", "file": str(path)}


def test_profile_tables_round_trip():
    for profile in [Constant(9.8), PiecewiseLinear([(0.0, 1.0), (2.0, 3.0)]),
                    Pulses(amplitude=1.0, period=0.3, duty=0.2, phase=0.1, base=0.5),
                    Sum([Constant(1.0), Pulses(amplitude=1.0, period=0.3, duty=0.2)])]:
        assert profile_from_dict(profile.to_dict()) == profile


def test_too_many_pieces_is_refused_not_slow():
    with pytest.raises(ParameterError, match="pieces"):
        Pulses(amplitude=1.0, period=0.001, duty=0.5).pieces(3600.0)


def test_samples_file_written_by_a_spreadsheet_with_a_byte_order_mark(tmp_path):
    path = tmp_path / "excel.csv"
    path.write_bytes("\ufefft,value\r\n0,1\r\n1,3\r\n".encode("utf-8"))
    assert Samples(path)(0.5) == 2.0


def test_a_subnormal_forcing_simulates_without_warnings():
    import drumstroke

    # g and a cancel to within one subnormal: the stick floats; no overflow warning (pytest errors on them)
    stroke = drumstroke.simulate(force=0.0, gravity=5e-324, theta0=0.1, t_end=1.0)
    assert len(stroke.impacts) == 0


def test_a_few_breakpoints_are_cut_into_the_same_pieces_as_by_numpy_to_the_bit(rng, monkeypatch):
    """A short profile's pieces, worked in plain Python, equal those of the numpy code kept for long ones: edges
    (duplicates and clusters closer than the merging tolerance merged into their first), values and slopes."""
    from drumstroke import profiles

    cases = []
    for _ in range(300):
        n = int(rng.integers(1, 40))
        t = np.cumsum(rng.choice([1.5e-9, 3e-9, 1e-3, 0.05, 0.3], n)) + rng.choice([0.0, 0.01])
        points = [(float(a), float(b)) for a, b in zip(t, rng.uniform(-3000.0, 3000.0, n))]
        t_end = float(rng.choice([t[-1], t[-1] + 0.2, t[n // 2], t[0] + 5e-13]))
        cases.append((PiecewiseLinear(points), max(t_end, 1e-6)))
    few = [profile.pieces(t_end) for profile, t_end in cases]
    extra = rng.uniform(0.0, 1.0, 30).tolist()
    edges = [np.array(extra[:k] + extra[:k // 2] + [x + 1e-13 for x in extra[k // 2:k]]) for k in range(1, 30)]
    merged = [profiles.merge_edges(e, 0.7) for e in edges]
    monkeypatch.setattr(profiles, "_FEW", 0)
    for (profile, t_end), pieces in zip(cases, few):
        expected = profile.pieces(t_end)
        for name in ("edges", "values", "slopes"):
            np.testing.assert_array_equal(getattr(pieces, name), getattr(expected, name), err_msg=name)
    for e, made in zip(edges, merged):
        np.testing.assert_array_equal(made, profiles.merge_edges(e, 0.7))


def test_a_pulse_trains_compiled_pieces_equal_the_numpy_codes_to_the_bit(rng):
    """Pulses' pieces (one compiled call) against the base class's steps in numpy: its breaks merged by
    merge_edges (clusters closer than the tolerance into their first edge, long trains by numpy's branch) and its
    __call__ just after each edge; a sum's values against the sum of its parts' __call__."""
    from drumstroke import profiles

    for _ in range(400):
        period = float(rng.choice([1e-3, 0.013, 0.1, 0.4, 2.0]) * rng.uniform(1.0, 1.5))
        duty = float(rng.choice([1e-13, 1e-9, 0.05, rng.uniform(0.0, 1.0), 1.0 - 1e-13]))
        pulse = Pulses(amplitude=float(rng.uniform(-500.0, 500.0)), period=period, duty=max(duty, 1e-15),
                       phase=float(rng.choice([0.0, rng.uniform(0.0, 3.0)])), base=float(rng.uniform(-50.0, 50.0)))
        t_end = float(rng.choice([1e-6, 0.3, 1.0, 5.0, 12.0, pulse.phase + 3 * period]))
        pieces = pulse.pieces(t_end)
        edges = profiles.merge_edges(pulse._breaks(t_end), t_end)
        np.testing.assert_array_equal(pieces.edges, edges)
        np.testing.assert_array_equal(pieces.values, pulse(edges[:-1] + profiles.merge_tolerance(t_end)))
        np.testing.assert_array_equal(pieces.slopes, np.zeros(len(edges) - 1))
        both = Sum([pulse, Pulses(amplitude=3.0, period=0.25, duty=0.5, phase=0.01)])
        summed = both.pieces(t_end)
        left = summed.edges[:-1] + profiles.merge_tolerance(t_end)
        np.testing.assert_array_equal(summed.values, 0 + pulse(left) + both.parts[1](left))


def test_a_piecewise_linear_forcing_made_in_the_compiled_call_equals_its_pieces_to_the_bit(rng):
    """The solver's one call for a piecewise-linear a(t) (a designed stroke's) cuts it as PiecewiseLinear.pieces does
    (its edges merged within the tolerance, few points or many) and makes C = (k·g + k′·a)/D of them as
    Coefficients.torque_rate does: the same edges, C and slopes to the bit."""
    from drumstroke import Stick
    from drumstroke.model import coefficients
    from drumstroke.profiles import merge_tolerance
    from drumstroke.solver.kernel import _linear_forcing

    co = coefficients("paper", Stick())
    for _ in range(300):
        n = int(rng.integers(1, 150))
        t = np.cumsum(rng.choice([1.5e-9, 3e-9, 1e-3, 0.05, 0.3], n)) + rng.choice([0.0, 0.01])
        profile = PiecewiseLinear([(float(a), float(b)) for a, b in zip(t, rng.uniform(-3000.0, 3000.0, n))])
        t_end = max(float(rng.choice([t[-1], t[-1] + 0.2, t[n // 2], t[0] + 5e-13])), 1e-6)
        gravity = float(rng.uniform(0.0, 20.0))
        pieces = profile.pieces(t_end)
        edges, c0, c1 = _linear_forcing(profile._t, profile._v, merge_tolerance(t_end),
                                        np.array((co.k, co.k_thumb, co.inertia_ratio, gravity)), t_end)
        np.testing.assert_array_equal(edges, pieces.edges)
        np.testing.assert_array_equal(c0, co.torque_rate(gravity, pieces.values))
        np.testing.assert_array_equal(c1, co.torque_rate(0.0, pieces.slopes))


@pytest.mark.parametrize("force", [
    PiecewiseLinear([(0.0, 40.0), (0.1, 40.0), (0.1 + 2e-9, 120.0), (0.4, 0.0), (0.9, 60.0)]),
    Pulses(amplitude=189.0, period=0.4, duty=0.05, phase=0.1, base=10.0),
])
def test_a_designed_or_pulsed_stroke_in_one_call_equals_it_simulated_piece_by_piece(force):
    """simulate's one compiled call for a piecewise-linear or pulsed a(t) against the pieces cut in Python and run
    one call at a time (what a progress report makes it do): the same impacts and arcs to the bit."""
    from drumstroke import Recipe, simulate

    recipe = Recipe(force, t_end=1.5, theta0=0.4)
    one, chunked = simulate(recipe), simulate(recipe, progress=lambda done: None)
    assert len(one.impacts) >= 3
    np.testing.assert_array_equal(one.impacts.t, chunked.impacts.t)
    np.testing.assert_array_equal(one.impacts.omega, chunked.impacts.omega)
    np.testing.assert_array_equal(one.arcs.table, chunked.arcs.table)
    np.testing.assert_array_equal(one.rests, chunked.rests)


def test_a_profile_made_of_two_lists_is_the_one_made_of_their_pairs(rng):
    """PiecewiseLinear._of (a designed stroke's steps) makes what PiecewiseLinear of the pairs makes: the same points
    (Python floats), arrays and pieces; pairs that fail the checks fail with the same error."""
    for _ in range(100):
        n = int(rng.integers(1, 30))
        times = np.cumsum(rng.choice([1.5e-9, 1e-3, 0.05], n)).tolist()
        values = [np.float64(x) for x in rng.uniform(-3000.0, 3000.0, n)]  # a design's forces may be numpy's
        made, expected = PiecewiseLinear._of(times, values), PiecewiseLinear(list(zip(times, values)))
        assert made == expected and made.points == expected.points
        assert all(type(x) is float for point in made.points for x in point)
        np.testing.assert_array_equal(made._t, expected._t)
        np.testing.assert_array_equal(made._v, expected._v)
        for name in ("edges", "values", "slopes"):
            np.testing.assert_array_equal(getattr(made.pieces(1.0), name), getattr(expected.pieces(1.0), name))
    for times, values in (([0.0, 0.0], [1.0, 2.0]), ([0.0, 1.0], [1.0, math.nan]), ([-1.0], [1.0])):
        with pytest.raises(ParameterError) as made:
            PiecewiseLinear._of(times, values)
        with pytest.raises(ParameterError) as expected:
            PiecewiseLinear(list(zip(times, values)))
        assert str(made.value) == str(expected.value)
