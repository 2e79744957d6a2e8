"""Listening-test statistics: the paper's Table 2, Tryon's formulas by hand, TOST, Group B, responses."""

import json
import math

import numpy as np
import pytest
from scipy import stats as scipy_stats

from _cli import assert_one_line_error, run
from drumstroke.errors import ParameterError
from drumstroke.evaluation.stats import (
    Group,
    analyze,
    from_summary,
    parse_responses,
    read_responses,
    simulate_guessing,
    tryon,
    tryon_with,
)

HEADER = "subject,pair,robot,answer,confidence,similarity\n"


def test_table_2_gives_the_papers_rg():
    """Table 2's means and SDs, SE = SD/√22 and exact t values: Rg = 20.974 %, within 0.05 pp of 20.99 %."""
    result = from_summary(4.227, 2.654, 4.999, 1.564, 22, pairs=10)
    assert result.rg_percent == pytest.approx(20.99, abs=0.05)
    assert result.t_pq == pytest.approx(2.0181, abs=5e-5) and result.t_p == pytest.approx(2.0796, abs=5e-5)
    # with the table's rounded SEs (0.566, 0.336) and its rounded t values the figure is 21.00 %
    a, b = Group(4.227, 0.566 * math.sqrt(22), 22), Group(4.999, 0.336 * math.sqrt(22), 22)
    rounded = tryon_with(a, b, pairs=10, alpha=0.05, t_pq=2.0181, t_p=2.0796, t_q=2.0796)
    assert rounded.rg_percent == pytest.approx(21.0035, abs=1e-3)


def test_e_ici_and_rg_against_hand_computation():
    a, b = Group(3.0, 2.0, 16), Group(5.0, 1.0, 16)  # SE 0.5 and 0.25
    result = tryon_with(a, b, pairs=8, alpha=0.05, t_pq=2.0, t_p=2.5, t_q=2.5)
    e = math.sqrt(0.5**2 + 0.25**2) / 0.75 * 2.0 / 2.5  # 0.59628...
    assert result.e == pytest.approx(e, rel=1e-15)
    assert result.ici_a == pytest.approx((3.0 - 2.5 * e * 0.5, 3.0 + 2.5 * e * 0.5), rel=1e-15)
    assert result.ici_b == pytest.approx((5.0 - 2.5 * e * 0.25, 5.0 + 2.5 * e * 0.25), rel=1e-15)
    assert result.rg == pytest.approx(2.0 + 2.5 * e * 0.75, rel=1e-15)
    assert result.rg_percent == pytest.approx(100 * result.rg / 8, rel=1e-15)
    # t_p·E·(S_p + S_q) is the half-width of the difference's interval, t_pq·√(S_p² + S_q²)
    assert result.rg - 2.0 == pytest.approx(2.0 * math.sqrt(0.5**2 + 0.25**2), rel=1e-14)


def test_the_ici_test_decides_exactly_as_rg_below_delta_on_random_data(rng):
    decisions = []
    for _ in range(2000):
        n = int(rng.integers(5, 40))
        a = Group(float(rng.uniform(0, 10)), float(rng.uniform(0.2, 4)), n)
        b = Group(float(rng.uniform(0, 10)), float(rng.uniform(0.2, 4)), int(rng.integers(5, 40)))
        result = tryon(a, b, pairs=10)
        delta = float(rng.uniform(0.1, 8))
        ici = result.ici_test(delta)
        assert ici.equivalent == result.equivalent(delta) and ici.side_alpha == 0.025
        assert ici.interval[1] == pytest.approx(result.b.mean - result.a.mean + (result.rg - abs(ici.difference)))
        decisions.append(ici.equivalent)
    assert 0.1 < np.mean(decisions) < 0.9  # both decisions occur


def exact_sample(rng, mean, sd, n):
    """n numbers whose mean and SD (ddof 1) are exactly ``mean`` and ``sd``."""
    z = rng.normal(size=n)
    return mean + sd * (z - z.mean()) / z.std(ddof=1)


def test_both_tests_against_statsmodels_and_pingouin_on_raw_data(rng):
    from pingouin import tost as pingouin_tost
    from statsmodels.stats.weightstats import ttost_ind

    for _ in range(60):
        n_a, n_b = int(rng.integers(4, 40)), int(rng.integers(4, 40))
        x = rng.normal(rng.uniform(2, 8), rng.uniform(0.5, 3), n_a)  # Group A's incorrect answers
        y = rng.normal(rng.uniform(2, 8), rng.uniform(0.5, 3), n_b)  # Group B's
        result = tryon(Group(x.mean(), x.std(ddof=1), n_a), Group(y.mean(), y.std(ddof=1), n_b), pairs=10)
        delta = float(rng.uniform(0.2, 4))
        p, lower, upper = ttost_ind(y, x, -delta, delta, usevar="pooled")  # low < m_B - m_A < upp
        tost = result.tost(delta)
        assert tost.p == pytest.approx(p, rel=1e-9, abs=1e-15)
        assert (tost.p_lower, tost.p_upper) == pytest.approx((lower[1], upper[1]), rel=1e-9, abs=1e-15)
        assert tost.equivalent == (p < 0.05) and tost.test == "Schuirmann's TOST"
        assert tost.p == pytest.approx(float(pingouin_tost(y, x, bound=delta, correction=False)["pval"].iloc[0]),
                                       rel=1e-9, abs=1e-15)
        if n_a == n_b:  # then Tryon's standard error is the pooled one: the same p, judged at alpha/2
            assert result.ici_test(delta).p == pytest.approx(p, rel=1e-9, abs=1e-15)
            assert result.ici_test(delta).equivalent == (p < 0.025)


def test_table_2_at_delta_2_the_two_tests_disagree_as_statsmodels_says(rng):
    """Rg = 2.097 answers > 2, so Tryon's test (the paper's) says no; the standard TOST says yes."""
    from statsmodels.stats.weightstats import ttost_ind

    result = from_summary(4.227, 2.654, 4.999, 1.564, 22, pairs=10)
    ici, tost = result.ici_test(2.0), result.tost(2.0)
    assert not ici.equivalent and tost.equivalent
    x, y = exact_sample(rng, 4.227, 2.654, 22), exact_sample(rng, 4.999, 1.564, 22)
    p, _, _ = ttost_ind(y, x, -2.0, 2.0)
    assert tost.p == pytest.approx(p, rel=1e-9) and ici.p == pytest.approx(p, rel=1e-9)
    assert 0.025 < p < 0.05
    assert ici.interval[1] == pytest.approx(result.rg, rel=1e-12)  # the 95 % interval ends at Rg
    assert tost.interval[1] == pytest.approx(0.772 + scipy_stats.t.ppf(0.95, 42) * math.hypot(result.a.se,
                                                                                             result.b.se))


def test_group_b_converges_to_5_and_root_2_5_for_10_pairs():
    group = simulate_guessing(22, 10, runs=40_000, seed=1)
    assert group.mean == pytest.approx(5.0, abs=0.01) and group.sd == pytest.approx(math.sqrt(2.5), abs=0.01)
    assert simulate_guessing(22, 10, seed=3) == simulate_guessing(22, 10, seed=3)  # seeded
    assert simulate_guessing(22, 10, seed=3) != simulate_guessing(22, 10, seed=4)


def write_responses(path, rng, subjects=12, pairs=10):
    rows, wrong = [], {}
    for s in range(subjects):
        for p in range(pairs):
            robot = "AB"[int(rng.integers(2))]
            answer = "AB"[int(rng.integers(2))]
            rows.append(f"s{s},p{p},{robot},{answer},{int(rng.integers(1, 6))},{int(rng.integers(1, 6))}")
            wrong[f"s{s}"] = wrong.get(f"s{s}", 0) + (answer != robot)
    path.write_text(HEADER + "\n".join(rows) + "\n")
    return rows, wrong


def test_analysis_of_raw_responses_against_independent_counts(tmp_path, rng):
    rows, wrong = write_responses(tmp_path / "r.csv", rng)
    analysis = analyze(read_responses(tmp_path / "r.csv"), runs=500, seed=2)
    assert analysis.incorrect.tolist() == [wrong[f"s{s}"] for s in range(12)]
    counts = np.array([wrong[f"s{s}"] for s in range(12)], float)
    assert analysis.tryon.a.mean == pytest.approx(counts.mean()) and analysis.tryon.a.sd == pytest.approx(
        counts.std(ddof=1))
    confidence = np.array([np.mean([int(r.split(",")[4]) for r in rows if r.startswith(f"s{s},")])
                           for s in range(12)])
    similarity = np.array([np.mean([int(r.split(",")[5]) for r in rows if r.startswith(f"s{s},")])
                           for s in range(12)])
    r, p = scipy_stats.pearsonr(counts, confidence)
    assert analysis.correlations["confidence_pearson"] == pytest.approx({"r": r, "p": p})
    rho, p = scipy_stats.spearmanr(counts, similarity)
    assert analysis.correlations["similarity_spearman"] == pytest.approx({"r": rho, "p": p})
    assert analysis.tryon.pairs == 10 and analysis.tryon.b.n == 12


@pytest.mark.parametrize("line, needle", [
    ("s1,p1,C,A,3,3", "robot must be A or B"),
    ("s1,p1,A,a,3,3", "answer must be A or B"),
    ("s1,p1,A,B,6,3", "confidence must be an integer in [1, 5]"),
    ("s1,p1,A,B,3,0", "similarity must be an integer in [1, 5]"),
    ("s1,p1,A,B,3", "expected 6 fields"),
    (",p1,A,B,3,3", "must not be empty"),
])
def test_bad_response_lines_are_named(line, needle):
    with pytest.raises(ParameterError, match="line 3") as error:
        parse_responses([["s0", "p1", "A", "B", "3", "3"], line.split(",")])
    assert needle in str(error.value)


def test_inconsistent_responses_are_refused(tmp_path):
    with pytest.raises(ParameterError, match="twice"):
        parse_responses([["s0", "p1", "A", "B", "3", "3"], ["s0", "p1", "A", "A", "3", "3"]])
    with pytest.raises(ParameterError, match="not the same"):
        parse_responses([["s0", "p1", "A", "B", "3", "3"], ["s1", "p2", "A", "A", "3", "3"]])
    (tmp_path / "bad.csv").write_text("who,what\n")
    with pytest.raises(ParameterError, match="header"):
        read_responses(tmp_path / "bad.csv")
    with pytest.raises(ParameterError, match="cannot be read"):
        read_responses(tmp_path / "missing.csv")
    with pytest.raises(ParameterError, match="delta"):
        from_summary(4, 2, 5, 1.5, 22).equivalent(-1)


def test_the_stats_command(tmp_path, rng):
    write_responses(tmp_path / "r.csv", rng)
    result = run("stats", tmp_path / "r.csv", "--delta", "2", "--json", tmp_path / "s.json")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "s.json").read_text())
    assert len(data["incorrect"]) == 12 and data["delta"]["equivalent"] == data["delta"]["tost_equivalent"]
    assert data["delta"]["ici_test"]["equivalent"] == data["delta"]["equivalent"]
    assert data["delta"]["schuirmann_tost"]["side_alpha"] == 0.05 and data["delta"]["ici_test"]["side_alpha"] == 0.025
    assert "Rg" in result.stdout and "spearman" in result.stdout
    result = run("stats", "--summary", "4.227,2.654,4.999,1.564,22", "--delta", "2")
    lines = [line for line in result.stdout.splitlines() if "p = 0.0342" in line]
    assert [line.split("(")[0].strip() for line in lines] == ["Tryon's ICI test", "Schuirmann's TOST"]
    assert "not shown equivalent" in lines[0] and ": equivalent" in lines[1]
    result = run("stats", "--summary", "4.227,2.654,4.999,1.564,22")
    assert result.returncode == 0 and "20.97 %" in result.stdout
    assert_one_line_error(run("stats"), "RESPONSES", "--summary")
    assert_one_line_error(run("stats", "--summary", "4,2,5"), "--summary")
    assert_one_line_error(run("stats", "--summary", "4,2,5,1,nan"), "N")
