"""Two strokes compared: against the closed forms of a free bounce, invariants and bad input."""

import json
import math

import numpy as np
import pytest
from scipy.special import ellipk, ellipkinc

import drumstroke
from _cli import assert_one_line_error, run
from drumstroke.analysis import Onsets
from drumstroke.analysis.compare import FLOOR_DB, GRID_POINTS, compare, stroke_onsets
from drumstroke.errors import ParameterError

C_GRAVITY = 0.075 * 9.8 / 0.0714  # paper Eq. 7 with a = 0: C = k·g / D (s⁻²)
THETA_MAX = -math.asin(0.07 / 0.27)  # paper Eq. 5 with Table 1


def free_bounce(cor):
    """A free bounce's onsets from the closed forms of docs/model.md: dropped from θ = 0 at rest under gravity alone.

    Each flight returns at its launch speed, so impact k has speed ω₁·c^k; its flight time is twice the
    rise time [K(m) − F(ψ | m)] / √C.
    """
    omega = math.sqrt(2.0 * C_GRAVITY * (0.0 - math.sin(THETA_MAX)))  # energy from θ0 = 0 down to the head
    first = _fall_time()
    speeds = omega * cor ** np.arange(60)
    flights = [_flight(cor * w) for w in speeds[:-1]]
    t = first + np.concatenate(([0.0], np.cumsum(flights)))
    return t, 20.0 * np.log10(speeds / speeds[0])


def _flight(launch):
    sin_apex = math.sin(THETA_MAX) + launch ** 2 / (2.0 * C_GRAVITY)
    m = (1.0 + sin_apex) / 2.0
    psi = math.asin(math.sqrt((1.0 + math.sin(THETA_MAX)) / (1.0 + sin_apex)))
    return 2.0 * (ellipk(m) - ellipkinc(psi, m)) / math.sqrt(C_GRAVITY)


def _fall_time():
    m = (1.0 + 0.0) / 2.0  # apex at θ = 0
    psi = math.asin(math.sqrt(1.0 + math.sin(THETA_MAX)))
    return (ellipk(m) - ellipkinc(psi, m)) / math.sqrt(C_GRAVITY)


def simulated(cor):
    return Onsets.from_impacts(drumstroke.simulate("free-bounce", cor=cor).impacts, source=f"c = {cor}")


def test_the_closed_forms_are_the_simulated_free_bounce():
    t, level = free_bounce(0.86)
    onsets = simulated(0.86)
    assert np.allclose(onsets.t[:30], t[:30], atol=1e-9, rtol=0)
    assert np.allclose(onsets.level_db[:30], level[:30], atol=1e-9, rtol=0)


@pytest.mark.parametrize("cor_a, cor_b", [(0.86, 0.8), (0.7, 0.9), (0.86, 0.86)])
def test_free_bounces_compared_as_the_closed_forms_say(cor_a, cor_b):
    """Bounces pair as mir_eval matches the closed forms' times; each pair differs as the closed forms say."""
    import mir_eval

    result = compare(simulated(cor_a), simulated(cor_b))
    t_a, level_a = free_bounce(cor_a)
    t_b, level_b = free_bounce(cor_b)
    expected_counts = [int(np.sum(level >= FLOOR_DB)) for level in (level_a, level_b)]
    assert list(result.counts) == expected_counts
    t_a, t_b = t_a[:expected_counts[0]] - t_a[0], t_b[:expected_counts[1]] - t_b[0]
    assert len(result.pairs) == len(mir_eval.util.match_events(t_a, t_b, 0.010))
    if cor_a == cor_b:
        assert result.pairs.tolist() == [[k, k] for k in range(expected_counts[0])]
    i, j = result.pairs.T
    assert np.all(np.diff(i) > 0) and np.all(np.diff(j) > 0) and np.all(np.abs(t_b[j] - t_a[i]) <= 0.010)
    assert np.allclose(result.time_difference, t_b[j] - t_a[i], atol=1e-9, rtol=0)
    assert np.allclose(result.interval_difference, np.diff(t_b[j]) - np.diff(t_a[i]), atol=1e-9, rtol=0)
    # impact k is c^k times the first: B's j-th against A's i-th differ by 20·(j·log10 c_b − i·log10 c_a) dB
    expected_levels = 20.0 * (j * math.log10(cor_b) - i * math.log10(cor_a))
    assert np.allclose(result.level_difference, expected_levels, atol=1e-9, rtol=0)
    assert result.durations == pytest.approx((t_a[-1], t_b[-1]), abs=1e-9)
    summary = result.summary()
    assert summary["count_difference"] == expected_counts[1] - expected_counts[0]
    assert summary["pairs"] == len(i) and summary["intervals_compared"] == len(i) - 1
    assert summary["unmatched_a"] == sorted(set(range(expected_counts[0])) - set(i.tolist()))
    assert summary["unmatched_b"] == sorted(set(range(expected_counts[1])) - set(j.tolist()))
    assert summary["level_difference_max_db"] == pytest.approx(np.max(np.abs(expected_levels)), abs=1e-9)


def test_the_envelope_and_the_rate_are_linear_between_onsets_and_midpoints():
    a = Onsets([0.0, 0.2, 0.3, 0.35], [0.0, -6.0, -9.0, -12.0])
    b = Onsets([0.0, 0.1, 0.3, 0.4], [0.0, -2.0, -4.0, -20.0])
    result = compare(a, b)
    assert len(result.envelope_t) == GRID_POINTS and result.envelope_t[-1] == pytest.approx(0.35)
    k = np.searchsorted(result.envelope_t, 0.15)
    t = result.envelope_t[k]
    assert result.envelope_a[k] == pytest.approx(-6.0 * t / 0.2)
    assert result.envelope_b[k] == pytest.approx(-2.0 - 2.0 * (t - 0.1) / 0.2)
    # A's rates: 5 Hz at 0.1 s, 10 Hz at 0.25 s, 20 Hz at 0.325 s; B's 10 Hz at 0.05 s, 5 Hz at 0.2 s, 10 Hz at 0.35 s
    assert result.rate_a[k] == pytest.approx(5.0 + 5.0 * (t - 0.1) / 0.15)
    assert result.rate_b[k] == pytest.approx(10.0 - 5.0 * (t - 0.05) / 0.15)
    assert result.rate_a[0] == pytest.approx(5.0) and result.rate_a[-1] == pytest.approx(20.0)  # held beyond
    assert result.rate_b[0] == pytest.approx(10.0) and result.rate_b[-1] == pytest.approx(10.0)


def test_a_stroke_compared_with_itself_later_shows_no_difference():
    a = simulated(0.86)
    later = Onsets(a.t + 1.2345, a.level_db, source="later")
    summary = compare(a, later).summary()
    assert summary["count_difference"] == 0
    assert summary["interval_difference_max_s"] < 1e-12 and summary["level_difference_max_db"] == 0.0
    assert summary["envelope_difference_rms_db"] < 1e-9 and summary["rate_difference_rms_hz"] < 1e-6


def test_a_detection_threshold_counts_both_strokes_above_it():
    detected = Onsets([0.0, 0.1, 0.19], [0.0, -10.0, -25.0], threshold_db=-30.0, source="recording")
    result = compare(detected, simulated(0.86))
    assert result.threshold_db == -30.0
    assert result.counts[1] == int(np.sum(free_bounce(0.86)[1] >= -30.0)) == 23
    assert result.b.t[0] == 0.0 and result.b.source == "c = 0.86"


def test_strokes_with_too_few_onsets_compare_without_envelopes():
    one = Onsets([0.5], [0.0])
    result = compare(one, simulated(0.86))
    assert result.counts[0] == 1 and len(result.interval_difference) == 0 and len(result.envelope_t) == 0
    summary = result.summary()
    assert summary["interval_difference_median_s"] is None and summary["duration_a_s"] == 0.0
    assert compare(Onsets([], []), Onsets([], [])).counts == (0, 0)


@pytest.mark.parametrize("threshold", [math.nan, 1.0, -201.0, math.inf])
def test_a_bad_threshold_is_refused_by_name(threshold):
    with pytest.raises(ParameterError, match="threshold_db"):
        compare(simulated(0.86), simulated(0.8), threshold_db=threshold)


def test_only_onsets_are_compared():
    with pytest.raises(ParameterError, match="b must be Onsets"):
        compare(simulated(0.86), [0.1, 0.2])


def test_compare_recipes_from_the_command_line(tmp_path):
    drumstroke.simulate("free-bounce").recipe.to_toml(tmp_path / "human.toml")
    drumstroke.simulate("free-bounce", cor=0.8).recipe.to_toml(tmp_path / "robot.toml")
    result = run("compare", tmp_path / "human.toml", tmp_path / "robot.toml", "--json", tmp_path / "c.json",
                 "--plot", tmp_path / "c.png")
    assert result.returncode == 0, result.stderr
    assert "A 37, B 25 (-12)" in result.stdout and "simulated on the paper model" in result.stdout
    data = json.loads((tmp_path / "c.json").read_text())
    t_a, _ = free_bounce(0.86)
    assert data["comparison"]["duration_a_s"] == pytest.approx(t_a[36] - t_a[0], abs=1e-9)
    assert len(data["b"]["t_s"]) == 25
    assert (tmp_path / "c.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_stroke_onsets_of_a_recipe_name_their_model(tmp_path):
    drumstroke.simulate("constant", model="geometry").recipe.to_toml(tmp_path / "g.toml")
    onsets = stroke_onsets(tmp_path / "g.toml")
    assert onsets.info["model"] == "geometry" and onsets.source == "g.toml" and onsets.level_db.max() == 0.0


@pytest.mark.parametrize("args, needle", [
    (("--threshold", "nan"), "--threshold"),
    (("--plot", "c.bmp"), "--plot"),
])
def test_bad_compare_options_are_one_line(tmp_path, args, needle):
    drumstroke.simulate("free-bounce").recipe.to_toml(tmp_path / "a.toml")
    assert_one_line_error(run("compare", tmp_path / "a.toml", tmp_path / "a.toml", *args, cwd=tmp_path), needle)


def test_a_corrupt_recipe_is_one_line(tmp_path):
    (tmp_path / "bad.toml").write_text("force = [[[")
    assert_one_line_error(run("compare", tmp_path / "bad.toml", tmp_path / "bad.toml"), "bad.toml")


def test_the_bounce_rate_is_one_over_each_interval_at_its_midpoint():
    midpoints, rate = Onsets(np.array([0.0, 0.1, 0.15, 0.175]), np.array([0.0, -1.0, -2.0, -3.0])).bounce_rate()
    assert midpoints == pytest.approx([0.05, 0.125, 0.1625], abs=1e-15)
    assert rate == pytest.approx([10.0, 20.0, 40.0], rel=1e-12)
    assert [len(a) for a in Onsets(np.array([0.2]), np.array([0.0])).bounce_rate()] == [0, 0]
