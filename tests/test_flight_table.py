"""The flight-time table against Carlson's R_F and against an mpmath oracle (60 digits).

* g(u, v) = √C·T/u from the table against :func:`scaled_flight` (R_F) at 20 points of every piece
  in d, both ends included, for heads at every head piece's ends and middle and at random;
* the same against docs/model.md's closed form 2[K(m) − F(ψ|m)] in mpmath at 60 digits
  (40 kept after the cancellation at small launches), on every piece and at the table's ends;
* flight_time from the table against :func:`.elliptic.flight_time` for launches from 1e-8 rad/s to
  near the vertical under C of both models; a head the table does not cover keeps R_F, bit for bit;
* a flight's time does not depend on what ran before: the same in a fresh chain as after any other
  flights, a batch the same stroke by stroke whatever its order or split, the table the same rebuilt;
* the batch and the solver with the table against themselves with R_F at every flight, impacts and
  rests within 1e-12 s.
"""

import math

import mpmath as mp
import numpy as np
import pytest

import drumstroke
from drumstroke.model import coefficients
from drumstroke.solver import elliptic
from drumstroke.solver import flight_table as ft
from drumstroke.solver.batch import OK, SHARED, constant_batch

TABLE_RTOL = 1e-14  # relative, g from the table against R_F and against mpmath [8.1e-15 against R_F]
HEADS = [-0.001, -0.1, -math.asin(0.07 / 0.27), -0.5, -0.8, -0.9]  # rad; Table 1's stick is −0.2623
IMPACT_TOL = 1e-12  # s, the batch with the table against the batch with R_F


def _mp_scaled_flight(d, sin_head):
    """g = 2[K(m) − F(ψ|m)]/u (docs/model.md) with u = 1 − d, e = u²·L, sin θ_a = sin θ_max + e, exact inputs."""
    with mp.workdps(60):
        s, u = mp.mpf(sin_head), 1 - mp.mpf(d)
        sin_apex = s + u * u * (1 - s)
        m = (1 + sin_apex) / 2
        psi = mp.asin(mp.sqrt((1 + s) / (1 + sin_apex)))
        return 2 * (mp.ellipk(m) - mp.ellipf(psi, m)) / u


def _sin_head(v):
    """sin θ_max with 1 + sin θ_max = v, rounded up to the table's range at its low end."""
    sin_head = v - 1.0
    return sin_head if 1.0 + sin_head >= ft.V_LOW else float(np.nextafter(sin_head, 0.0))


def _worse(worst, error):
    """The larger, NaN if either is (max() would drop a NaN error)."""
    return error if not error <= worst else worst


def _sin_heads(rng):
    """sin θ_max at every head piece's ends and middle, at the covered range's ends, and at random (with HEADS)."""
    sins = [math.sin(h) for h in HEADS] + [_sin_head(ft.V_LOW), -1e-15] + list(rng.uniform(ft.V_LOW, 1.0, 12) - 1.0)
    for j in range(ft.HEAD_PIECES):
        low, high = ft._head_bounds(j)
        sins += [_sin_head(low), _sin_head(0.5 * (low + high))]
    return sins


def test_table_matches_rf_on_every_cell(rng):
    table, worst = ft.table(), 0.0
    for sin_head in _sin_heads(rng):
        chain = ft.head(table, sin_head)
        for k in range(ft.PIECES):
            low, high = ft._piece_bounds(k)
            for d in np.linspace(low, high, 20):
                exact = ft.scaled_flight(d, sin_head)
                worst = _worse(worst, abs(ft.evaluate(table, chain, d) - exact) / exact)
    print(f"table vs R_F worst relative {worst:.3g}")
    assert worst <= TABLE_RTOL


@pytest.mark.parametrize("sin_head", [math.sin(HEADS[0]), math.sin(HEADS[2]), math.sin(HEADS[-1]), _sin_head(ft.V_LOW)])
def test_table_matches_mpmath(sin_head, rng):
    table = ft.table()
    chain = ft.head(table, sin_head)
    points = [1.0 - 1e-12, 1.0 - 1e-6, 2.0**-32 * 1.0000001]  # the smallest launches and the table's last piece
    for k in range(ft.PIECES):
        low, high = ft._piece_bounds(k)
        points += [low, float(rng.uniform(low, high))]
    worst = 0.0
    for d in points:
        exact = _mp_scaled_flight(d, sin_head)
        worst = _worse(worst, abs(float((ft.evaluate(table, chain, d) - exact) / exact)))
    print(f"sin θ_max {sin_head:.4f}: table vs mpmath worst relative {worst:.3g} on {len(points)} points")
    assert worst <= TABLE_RTOL


def _flight(table, chain, launch, c, cells=None):
    """A flight as the solver's chains take it: from the head's last cell, else its cell put there first."""
    duration, m = ft.flight_time(launch, c, chain)
    if math.isnan(duration):
        ft.fill(table, chain, launch, c, np.empty((0, ft.CELL_SIZE)) if cells is None else cells)
        duration, m = ft.flight_time(launch, c, chain)
    return duration, m


@pytest.mark.parametrize("model", ["paper", "geometry"])
def test_flight_time_matches_the_closed_form(model, rng):
    """Under C of the model from no force to 3000 m/s²: the same m, the time to the closed form's conditioning.

    Near the vertical both round 1 − m from the launch (differently); the time's relative sensitivity to
    that is ~ε/(2(1 − m)·K), so the bound grows as 1 − m shrinks: 1e-13 plus 4ε/(1 − m).
    """
    stick = drumstroke.Stick()
    sin_head = math.sin(stick.theta_max)
    table = ft.table()
    chain = ft.head(table, sin_head)
    worst = 0.0
    for force in (0.0, 30.0, 250.0, 3000.0):
        c = float(coefficients(model, stick).torque_rate(9.8, force))
        top = math.sqrt(2.0 * c * (1.0 - sin_head))  # reaches the vertical
        launches = np.concatenate([10.0 ** rng.uniform(-8.0, math.log10(top), 300),
                                   top * (1.0 - 10.0 ** rng.uniform(-10.0, -1.0, 100)), [1e-6, 1e-8]])
        for launch in launches:
            reference, m = elliptic.flight_time(launch, c, sin_head)
            duration, m_table = _flight(table, chain, launch, c)
            assert m_table == m
            if m >= 1.0 - 1e-9:
                continue
            error = abs(duration - reference) / reference
            assert error <= 1e-13 + 4 * 2.0**-52 / (1.0 - m), (launch, c, m, duration, reference)
            if 1.0 - m > 1e-4:
                worst = max(worst, error)
    print(f"{model}: flight_time table vs R_F worst relative {worst:.3g} (1 − m > 1e-4)")
    assert worst <= 1e-14


@pytest.mark.parametrize("sin_head", [math.sin(-1.2), ft.V_LOW - 1.0 - 1e-12])  # (below the table's range)
def test_a_head_the_table_does_not_cover_keeps_rf(sin_head):
    table = ft.table()
    for chain in (ft.head(table, sin_head), ft.head(np.empty((0, 0)), math.sin(-0.2))):
        assert math.isnan(ft.evaluate(table, chain, 0.9))
    for launch in (1e-6, 0.1, 3.0):
        assert ft.flight_time(launch, 40.0, ft.head(table, sin_head)) == elliptic.flight_time(launch, 40.0, sin_head)
        empty = ft.head(np.empty((0, 0)), math.sin(-0.2))  # (the reference: R_F at every flight)
        assert ft.flight_time(launch, 40.0, empty) == elliptic.flight_time(launch, 40.0, math.sin(-0.2))


def test_beyond_the_last_piece_is_rf():
    sin_head = math.sin(HEADS[2])
    c = 40.0
    launch = math.sqrt(2.0 * c * (1.0 - sin_head)) * (1.0 - 1e-11)  # 1 − m below the last piece's
    assert ft.flight_time(launch, c, ft.head(ft.table(), sin_head)) == elliptic.flight_time(launch, c, sin_head)


def test_a_flight_does_not_depend_on_the_flights_before(rng):
    """The same launch from a fresh head, from one that has served other cells, and from the head's cells summed
    at once: the same time, bit for bit."""
    table = ft.table()
    for sin_head in rng.uniform(ft.V_LOW, 1.0, 20) - 1.0:
        c = float(rng.uniform(20.0, 500.0))
        top = math.sqrt(2.0 * c * (1.0 - sin_head))
        launches = top * np.concatenate([rng.uniform(0.0, 1.0, 30), 1.0 - 10.0 ** rng.uniform(-9.0, -1.0, 10)])
        chain, cells = ft.head(table, sin_head), ft.head_cells(table, sin_head)
        for launch in rng.permutation(np.repeat(launches, 2)):
            fresh = _flight(table, ft.head(table, sin_head), launch, c)
            assert _flight(table, chain, launch, c) == fresh
            assert _flight(table, ft.head(table, sin_head), launch, c, cells) == fresh


def test_the_table_is_the_same_rebuilt():
    """Built in parallel, cell by cell: the same bits whatever the order the cells were built in."""
    np.testing.assert_array_equal(ft.build(), ft.table())


def _batch_columns(rng, n):
    stick = drumstroke.Stick()
    theta_max = np.where(rng.uniform(size=n) < 0.8, stick.theta_max, rng.uniform(-1.3, -0.01, n))
    model = rng.choice(["paper", "geometry"], n)
    force = rng.choice([0.0, 100.0, 2000.0], n) * rng.uniform(size=n)
    c = np.array([float(coefficients(m, stick).torque_rate(9.8, f)) for m, f in zip(model, force)])
    theta0 = theta_max + rng.uniform(0.0, 0.6, n)
    omega0 = rng.uniform(-5.0, 5.0, n)
    cor = np.where(rng.uniform(size=n) < 0.5, rng.uniform(0.0, 1.0, n), rng.uniform(0.9, 0.99, n))
    t_end = rng.uniform(0.5, 10.0, n)
    return theta0, omega0, cor, c, theta_max, t_end


def _strokes(result):
    """Each stroke's (status, impact times, ω, rest) from constant_batch's arrays."""
    status, offsets, count, t, omega, rest = result
    return [(status[i], t[offsets[i]:offsets[i] + count[i]], omega[offsets[i]:offsets[i] + count[i]], rest[i])
            for i in range(len(status))]


def test_a_batch_does_not_depend_on_its_order_or_split(rng):
    """A sweep split over workers equals the one run at once, stroke by stroke, bit for bit."""
    columns = _batch_columns(rng, 600)
    whole = _strokes(constant_batch(*columns, max_impacts=100_000))
    order = rng.permutation(600)
    # (the whole batch reads its common head's cells summed at once; parts of 15 strokes sum them as they go)
    assert np.count_nonzero(columns[4] == columns[4][0]) > 3 * SHARED and 15 < SHARED
    parts = [_strokes(constant_batch(*(x[part] for x in columns), max_impacts=100_000))
             for part in np.array_split(order, 40)]
    for i, stroke in zip(order, [s for part in parts for s in part]):
        assert stroke[0] == whole[i][0] and np.array_equal(stroke[1], whole[i][1])
        assert np.array_equal(stroke[2], whole[i][2]) and np.array_equal(stroke[3], whole[i][3], equal_nan=True)


def test_batch_with_the_table_equals_the_batch_with_rf(rng):
    n = 3000
    columns = _batch_columns(rng, n)
    fast = constant_batch(*columns, max_impacts=100_000)
    exact = constant_batch(*columns, max_impacts=100_000, exact=True)
    status, offsets, count, t, _, rest = fast
    assert np.array_equal(status, exact[0]) and np.array_equal(count, exact[2])
    ok = status == OK
    assert np.count_nonzero(ok) > 0.9 * n and count.sum() > 50 * n
    worst = 0.0
    for i in np.flatnonzero(ok):
        ours, theirs = slice(offsets[i], offsets[i] + count[i]), slice(exact[1][i], exact[1][i] + count[i])
        if count[i]:
            worst = max(worst, float(np.max(np.abs(t[ours] - exact[3][theirs]))))
        assert np.isnan(rest[i]) == np.isnan(exact[5][i])
        if not np.isnan(rest[i]):
            assert abs(rest[i] - exact[5][i]) <= IMPACT_TOL
    print(f"batch: table vs R_F worst impact-time difference {worst:.3g} s over {count[ok].sum()} impacts")
    assert worst <= IMPACT_TOL


@pytest.mark.parametrize("model", ["paper", "geometry"])
def test_solver_with_the_table_equals_the_solver_with_rf(model, rng):
    """simulate's solver, flights by the table and by R_F: impacts and rests within 1e-12 s."""
    from drumstroke.solver import solve

    worst, impacts = 0.0, 0
    for preset in ("free-bounce", "low-high", "high-low", "finger-pulses"):
        for _ in range(10):
            recipe = drumstroke.preset(preset).replace(
                model=model, cor=float(rng.uniform(0.3, 0.98)), omega0=float(rng.uniform(-5.0, 5.0)))
            kwargs = {"theta0": recipe.theta0, "omega0": recipe.omega0, "cor": recipe.cor, "t_end": recipe.t_end}
            try:
                fast = solve(recipe.coefficients, recipe.force, recipe.gravity, **kwargs)
            except drumstroke.SimulationError:  # (to the vertical) then so with R_F
                with pytest.raises(drumstroke.SimulationError, match="vertical"):
                    solve(recipe.coefficients, recipe.force, recipe.gravity, **kwargs, tabled=False)
                continue
            exact = solve(recipe.coefficients, recipe.force, recipe.gravity, **kwargs, tabled=False)
            assert len(fast.impact_t) == len(exact.impact_t)
            if len(fast.impact_t):
                worst = max(worst, float(np.max(np.abs(fast.impact_t - exact.impact_t))))
            np.testing.assert_allclose(fast.rests, exact.rests, rtol=0.0, atol=IMPACT_TOL)
            impacts += len(fast.impact_t)
    print(f"{model}: solver table vs R_F worst impact-time difference {worst:.3g} s over {impacts} impacts")
    assert worst <= IMPACT_TOL


def test_the_piece_is_frexps(rng):
    """A flight's piece, read from the bits of d⁸, is the one math.frexp's exponent gives, at every edge."""
    from numba import njit

    piece = njit(ft._piece.py_func)
    edges = 2.0 ** (-np.arange(ft.PIECES + 2) / ft.GRADING)
    d = np.concatenate([edges, np.nextafter(edges, 0.0), np.nextafter(edges, 2.0), rng.uniform(0.0, 1.0, 10_000),
                        10.0 ** rng.uniform(-45.0, 0.0, 10_000), [1.0, 5e-324, 1e-200, 1e-40, 2e-39, 0.0, -1.0]])
    for x in d:
        d4 = (x * x) * (x * x)
        d8 = d4 * d4  # (as _piece rounds it)
        expected = ft.PIECES if not x > 0.0 else min(max(-math.frexp(d8)[1], 0), ft.PIECES)
        assert piece(x) == expected, x
