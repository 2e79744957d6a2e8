"""Profiles: values, pieces (the solver's step boundaries), sums and sample files."""

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
