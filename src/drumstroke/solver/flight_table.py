"""Flight times from the head by a table: piecewise Chebyshev series of one function, compiled.

A flight launched upward from the head θ_max at speed w under constant C lasts
T = 2·F(χ|m)/√C (:func:`.elliptic.flight_time`). Its time scaled by √C depends
on the launch only through the dimensionless energy e = w²/(2C), and for a
given head only through u = √(e/L) in [0, 1), where L = 1 − sin θ_max is the
energy that reaches the vertical (u = 1, m = 1). Written out,

    √C·T = u·g(u),   g(u) = 2/√m · R_F(q, q + (1 − m)·u²/m, 1),
    1 − m = L·d(2 − d)/2,   q = d(2 − d)(1 + sin θ_max)/(2m),   d = 1 − u,

and g is analytic on [0, 1) with a logarithmic singularity at u = 1 (the
orbit that stops at the vertical). The table holds g as a Chebyshev series on
pieces graded toward that singularity: piece k covers d⁸ in [2^−(k+1), 2^−k]
(piece 0 all d⁸ ≥ 1/2), so each piece lies as far from the singularity, in
its own half-widths, as every other, and one degree serves all of them.
A piece is found from the exponent of d⁸ (``frexp``) and evaluated by Horner's
rule: ten multiply-adds, no square root beyond √C, no loop of unknown length.

The table's values come from R_F at its nodes with d computed exactly, so it is
exact to the series' truncation and R_F's round-off; tests/test_flight_table.py
holds it to R_F and to mpmath (60 digits) over dense grids, both ends included.
It covers orbits up to m = 1 − :data:`.constants.NEARLY_VERTICAL`. Past its last
piece, and on a head whose table fails the check made when it is built (heads
steeper than about −0.95 rad), :func:`flight_time` is :func:`.elliptic.flight_time`.
"""

import math

import numpy as np

from .._jit import jit
from .carlson import rf
from .elliptic import flight_time as exact_flight_time

DEGREE = 10
"""Degree of each piece's polynomial (its Chebyshev series' next term is below 1e-17 relative)."""

GRADING = 8
"""Pieces per halving of d: piece k covers d⁸ in [2^−(k+1), 2^−k]."""

PIECES = 32 * GRADING
"""Pieces down to d = 2^−32 (1 − m ≈ 2.3e-10·L), past the solver's 1 − m = 1e-9 for any head."""

# a row of the table: d at the piece's centre, 1/half-width, then the DEGREE + 1 coefficients
_CENTRE, _SCALE, _FIRST = 0, 1, 2
_COLUMNS = DEGREE + 3
# row PIECES holds the head's constants: sin θ_max, 1/√(2L), 1/L, and 1 if the table passed its check
_HEAD = PIECES

CHECK_RTOL = 1e-14
"""The table is used only if it is within this of R_F (relative) at every piece's ends and midpoint."""


@jit
def scaled_flight(d, sin_head):
    """g(u) = √C·T/u at d = 1 − u, from R_F (the table's reference); d in (0, 1]."""
    big = 1.0 - sin_head
    gap = 0.5 * big * d * (2.0 - d)  # 1 − m
    m = 1.0 - gap
    u = 1.0 - d
    q = d * (2.0 - d) * (1.0 + sin_head) / (2.0 * m)
    return 2.0 / math.sqrt(m) * rf(q, q + gap * u * u / m, 1.0)


@jit
def _piece_bounds(k):
    """d at the ends of piece k."""
    high = 1.0 if k == 0 else 2.0 ** (-k / GRADING)
    return 2.0 ** (-(k + 1) / GRADING), high


@jit
def _chebyshev_powers(n):
    """Row j: the coefficients of T_j in powers of t, for j < n (T_{j+1} = 2t·T_j − T_{j−1})."""
    powers = np.zeros((n, n))
    powers[0, 0] = 1.0
    if n > 1:
        powers[1, 1] = 1.0
    for j in range(1, n - 1):
        powers[j + 1, 0] = -powers[j - 1, 0]
        for p in range(1, n):
            powers[j + 1, p] = 2.0 * powers[j, p - 1] - powers[j - 1, p]
    return powers


@jit
def build(sin_head):
    """The table for the head sin θ_max = ``sin_head`` [shape=(PIECES + 1, DEGREE + 3)].

    Each piece is interpolated at the DEGREE + 1 Chebyshev nodes, then written in powers of
    its local t in [−1, 1] for Horner's rule: the series converges so fast on these pieces
    (each coefficient some 50 times below the last) that the powers' coefficients fall as fast
    and the sum is as stable as Clenshaw's.
    """
    n = DEGREE + 1
    table = np.zeros((PIECES + 1, _COLUMNS))
    values = np.empty(n)
    series = np.empty(n)
    cosines = np.empty((n, n))  # cos(jπ(i + ½)/n): row 1 the nodes, all rows the transform
    powers = _chebyshev_powers(n)
    for j in range(n):
        for i in range(n):
            cosines[j, i] = math.cos(math.pi * j * (i + 0.5) / n)
    for k in range(PIECES):
        low, high = _piece_bounds(k)
        centre, half = 0.5 * (low + high), 0.5 * (high - low)
        for i in range(n):
            values[i] = scaled_flight(centre + half * cosines[1, i], sin_head)
        for j in range(n):
            total = 0.0
            for i in range(n):
                total += values[i] * cosines[j, i]
            series[j] = (1.0 if j else 0.5) * 2.0 / n * total
        table[k, _CENTRE], table[k, _SCALE] = centre, 1.0 / half
        for p in range(n):
            total = 0.0
            for j in range(p, n):
                total += series[j] * powers[j, p]
            table[k, _FIRST + p] = total
    big = 1.0 - sin_head
    table[_HEAD, 0], table[_HEAD, 1], table[_HEAD, 2] = sin_head, 1.0 / math.sqrt(2.0 * big), 1.0 / big
    table[_HEAD, 3] = 1.0 if _checked(table, sin_head) else 0.0
    return table


@jit
def _checked(table, sin_head):
    """Whether every piece is within CHECK_RTOL of R_F at its ends and midpoint.

    On a head close to straight below the pivot (θ_max → −π/2) the orbit m = 0 comes near
    the smallest launches and the first pieces would need a higher degree: such a table fails
    this check and its head keeps R_F.
    """
    for k in range(PIECES):
        low, high = _piece_bounds(k)
        for d in (low, 0.5 * (low + high), high):
            exact = scaled_flight(d, sin_head)
            if not abs(_horner(table, k, d) - exact) <= CHECK_RTOL * exact:
                return False
    return True


@jit
def evaluate(table, d):
    """g at d = 1 − u from the table; NaN beyond its pieces (d ≤ 0 or d < 2^−32) or if it failed its check."""
    if not d > 0.0:
        return math.nan
    d2 = d * d
    d4 = d2 * d2
    k = max(-math.frexp(d4 * d4)[1], 0)
    if k >= PIECES or table[_HEAD, 3] == 0.0:
        return math.nan
    return _horner(table, k, d)


@jit(inline="always")
def _horner(table, k, d):
    t = (d - table[k, _CENTRE]) * table[k, _SCALE]
    total = table[k, _FIRST + DEGREE]
    for j in range(_FIRST + DEGREE - 1, _FIRST - 1, -1):
        total = total * t + table[k, j]
    return total


@jit(inline="always")
def flight_time(launch_speed, c, table):
    """:func:`.elliptic.flight_time` from the table of the head: (duration (s), m).

    Compiled into its callers, so that in a chain of bounces under one C the square root and
    reciprocal of C are computed once.

    Parameters
    ----------
    launch_speed : float ≥ 0
        ω just after the impact (rad/s).
    c : float > 0
        C (s⁻²).
    table : ndarray
        From :func:`build` for the head.
    """
    sin_head = table[_HEAD, 0]
    energy = launch_speed * launch_speed / (2.0 * c)
    m = 0.5 * (1.0 + sin_head + energy)  # (as parameter computes it)
    per_root_c = 1.0 / math.sqrt(c)
    u = launch_speed * table[_HEAD, 1] * per_root_c
    # Near the vertical d = 1 − u would lose the relative accuracy of 1 − m that the closed form
    # keeps: there d = (1 − u²)/(1 + u) with 1 − u² = (L − e)/L.
    d = 1.0 - u if u < 0.5 else ((1.0 - sin_head) - energy) * table[_HEAD, 2] / (1.0 + u)
    g = evaluate(table, d)
    if math.isnan(g):
        return exact_flight_time(launch_speed, c, sin_head)
    return u * g * per_root_c, m


KEPT = 256
"""Tables kept, the most recently built (some 27 kB each)."""

_TABLES = {}


def table_for(theta_max):
    """The table of the head θ_max (rad): built on first use (about 0.3 ms), then kept (the last KEPT).

    Every flight from a head is read from its table, whatever ran before: a result never depends on
    which heads a process has seen.
    """
    sin_head = math.sin(theta_max)
    table = _TABLES.get(sin_head)
    if table is None:
        if len(_TABLES) >= KEPT:
            del _TABLES[next(iter(_TABLES))]
        table = _TABLES[sin_head] = build(sin_head)
    return table
