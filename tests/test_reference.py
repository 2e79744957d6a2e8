"""The benchmark's reference (benchmarks/reference.py) against the exact oracle, and drumstroke against it.

The reference is scipy's DOP853 with events and an impact/restart loop; the oracle is the
closed form of docs/model.md for constant forcing. If the reference agrees with the oracle, it
can stand in for it where there is none (time-varying forcing: the paper's Figs. 5–7).
"""

import functools
import sys
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest

import drumstroke
from drumstroke import simulate

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from reference import oracle_for, oracle_impacts, reference_simulate

IMPACT_TIME_TOL = 1e-9  # s, as the docs require (docs/model.md)
THETA_TOL = 1e-8  # rad
AUDIBLE = 1e-3  # rad/s: impacts slower than this are part of the inaudible buzz before rest
RATE = 1000.0  # Hz
FIGURES = ("free-bounce", "low-high", "high-low", "finger-pulses")


@functools.cache
def reference(name):
    return reference_simulate(drumstroke.preset(name), rate=RATE)


def test_oracle_matches_spec_formula_in_mpmath():
    """The scipy oracle (ψ through atan2, for accuracy) equals docs/model.md's asin form at 30 digits."""
    recipe = drumstroke.preset("free-bounce")
    coef = drumstroke.model.coefficients(recipe.model, recipe.stick)
    c = float(coef.torque_rate(9.8, 0.0))
    times, speeds, _ = oracle_impacts(0.0, 0.0, 0.86, c, coef.theta_max, 6)
    with mp.workdps(30):
        big_c, head, cor = mp.mpf(c), mp.mpf(coef.theta_max), mp.mpf("0.86")

        def to_apex(sin_theta, sin_apex):
            m = (1 + sin_apex) / 2
            psi = mp.asin(mp.sqrt((1 + sin_theta) / (1 + sin_apex)))
            return (mp.ellipk(m) - mp.ellipf(psi, m)) / mp.sqrt(big_c)

        t = to_apex(mp.sin(head), mp.mpf(0))  # dropped from θ = 0: the apex is the start
        speed = mp.sqrt(2 * big_c * (0 - mp.sin(head)))
        expected = []
        for _ in range(6):
            expected.append((t, speed))
            speed *= cor
            sin_apex = mp.sin(head) + speed**2 / (2 * big_c)
            t += 2 * to_apex(mp.sin(head), sin_apex)
    assert len(times) == 6
    np.testing.assert_allclose(times, [float(e[0]) for e in expected], rtol=0, atol=1e-13)
    np.testing.assert_allclose(speeds, [float(e[1]) for e in expected], rtol=1e-12, atol=0)


def test_reference_matches_oracle_free_bounce():
    recipe = drumstroke.preset("free-bounce")
    t, omega, rest, _ = reference("free-bounce")
    exact_t, exact_speed, exact_rest = oracle_for(recipe)
    assert len(t) == len(exact_t) >= 20
    error = np.abs(t[:20] - exact_t[:20])
    worst = int(np.argmax(error))
    assert error.max() <= IMPACT_TIME_TOL, f"impact {worst}: {t[worst]!r} vs oracle {exact_t[worst]!r}"
    np.testing.assert_allclose(-omega[:20], exact_speed[:20], rtol=1e-9, atol=0)
    assert rest is not None and abs(rest - exact_rest) <= IMPACT_TIME_TOL


def test_reference_matches_oracle_thrown_up_under_thumb_force():
    """Constant forcing from a raised start thrown upward, with a thumb press and another c."""
    recipe = drumstroke.Recipe(force=drumstroke.Constant(120.0), theta0=0.3, omega0=2.5, cor=0.7)
    t, omega, rest, _ = reference_simulate(recipe)
    exact_t, exact_speed, exact_rest = oracle_for(recipe)
    assert len(t) == len(exact_t) >= 20
    assert np.max(np.abs(t - exact_t)) <= IMPACT_TIME_TOL
    np.testing.assert_allclose(-omega[:20], exact_speed[:20], rtol=1e-9, atol=0)
    assert rest is not None and abs(rest - exact_rest) <= IMPACT_TIME_TOL


@pytest.mark.parametrize("name", FIGURES)
def test_drumstroke_matches_reference_on_paper_figures(name):
    ref_t, ref_omega, ref_rest, (ref_ts, ref_theta, _) = reference(name)
    stroke = simulate(name)
    audible = np.abs(ref_omega) > AUDIBLE
    n = int(audible.sum())
    assert n >= 10 and audible[:n].all()  # the audible ones come first: speeds fall off before rest
    ours_audible = np.abs(stroke.impacts.omega) > AUDIBLE
    assert int(ours_audible.sum()) == n, f"{int(ours_audible.sum())} audible impacts, reference {n}"
    error = np.abs(stroke.impacts.t[:n] - ref_t[:n])
    worst = int(np.argmax(error))
    assert error.max() <= IMPACT_TIME_TOL, (
        f"impact {worst}: {stroke.impacts.t[worst]!r} vs reference {ref_t[worst]!r}"
    )
    if ref_rest is None:
        assert stroke.rest_time is None
    else:
        assert stroke.rest_time is not None and abs(stroke.rest_time - ref_rest) <= IMPACT_TIME_TOL

    ts, theta, _ = stroke.sample(RATE)
    assert len(ts) == len(ref_ts) == 5001
    np.testing.assert_array_equal(ts, ref_ts)
    error = np.abs(theta - ref_theta)
    worst = int(np.argmax(error))
    assert error.max() <= THETA_TOL, f"theta at t = {ts[worst]!r}: {theta[worst]!r} vs {ref_theta[worst]!r}"
    assert ref_theta.max() - ref_theta.min() > 0.2  # a real trajectory, not a resting stick
    assert theta.min() >= stroke.recipe.theta_max  # never below the head
