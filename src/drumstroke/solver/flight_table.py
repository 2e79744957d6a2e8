"""Flight times from the head by one table for every head: piecewise polynomials in two variables, compiled.

A flight launched upward from the head θ_max at speed w under constant C lasts
T = 2·F(χ|m)/√C (:func:`.elliptic.flight_time`). Its time scaled by √C depends
on the launch only through the dimensionless energy e = w²/(2C), and for a
given head only through u = √(e/L) in [0, 1), where L = 1 − sin θ_max is the
energy that reaches the vertical (u = 1, m = 1). Written out,

    √C·T = u·g(u, v),   g = 2/√m · R_F(q, q + (1 − m)·u²/m, 1),
    1 − m = L·d(2 − d)/2,   q = d(2 − d)·v/(2m),   d = 1 − u,   v = 1 + sin θ_max = 2 − L,

and g is analytic in both variables except at u = 1 (the orbit that stops at
the vertical: a logarithmic singularity) and at v ≤ 0 (heads straight below
the pivot). The table holds g as a polynomial on each cell of a grid graded
toward both: in d, piece k covers d⁸ in [2^−(k+1), 2^−k] (piece 0 all
d⁸ ≥ 1/2); in v, piece j covers v in [V_LOW·r^j, V_LOW·r^(j+1)] with
r = (1/V_LOW)^(1/HEAD_PIECES). Each cell lies as far from the singularities,
in its own half-widths, as every other, so one pair of degrees serves them all.

A flight's cell is found from the exponent of d⁸ (its bits) and the head's
piece (once per head). The polynomial in v is summed once for the head and the
cell (a chain of bounces from one head stays in a few cells, and :func:`head`
keeps the last; :func:`head_cells` sums them all for a head many strokes share,
to the same numbers), then Horner's rule in d: ten multiply-adds per flight.

The table's values come from R_F at its nodes; tests/test_flight_table.py holds
it to R_F and to mpmath (60 digits) over dense grids, every cell and both ends
included. It covers heads with v ≥ V_LOW (θ_max ≥ −asin(1 − V_LOW), about
−0.93 rad: the stick's pivot at up to 0.8 of its tip's reach above the head)
and orbits up to 1 − m = L·2^−32 (past the solver's 1 − m = 1e-9). Beyond it,
and in a cell that fails the check made when the table is built, a flight is
:func:`.elliptic.flight_time`. Which applies depends on the flight alone, and
the table is the same in every process: a flight's time never depends on what a
process ran before (a sweep split over workers equals the one run locally, bit for bit).
"""

import functools
import math

import llvmlite.ir
import numpy as np
from numba import prange, types
from numba.extending import intrinsic

from .._jit import jit
from .carlson import rf
from .elliptic import flight_time as exact_flight_time

DEGREE = 10
"""Degree in d of each cell's polynomial (its Chebyshev series' next term is below 1e-17 relative)."""

GRADING = 8
"""Pieces per halving of d: piece k covers d⁸ in [2^−(k+1), 2^−k]."""

PIECES = 32 * GRADING
"""Pieces in d down to d = 2^−32 (1 − m ≈ 2.3e-10·L), past the solver's 1 − m = 1e-9 for any head."""

HEAD_DEGREE = 10
"""Degree in v = 1 + sin θ_max of each cell's polynomial."""

V_LOW = 0.2
"""The smallest v = 1 + sin θ_max covered (θ_max ≈ −0.927 rad); steeper heads keep R_F."""

HEAD_PIECES = 12
"""Pieces in v, graded geometrically from V_LOW to 1."""

CHECK_RTOL = 1e-14
"""A cell is used only if it is within this of R_F (relative) at its corners, edges' midpoints and centre."""

# a row of the table, one per cell (row j·PIECES + k: a head piece's cells one after another, as a chain
# reads them): d at the piece's centre, 1/half-width, then the coefficients of t_d^p·t_v^q at
# _FIRST + p·(HEAD_DEGREE + 1) + q
_CENTRE, _SCALE, _FIRST = 0, 1, 2
_COLUMNS = _FIRST + (DEGREE + 1) * (HEAD_DEGREE + 1)

# a head (from :func:`head`): its constants, then the last cell's polynomial in d summed for it (k in _CACHED)
_SIN, _PER_ROOT_2L, _PER_L, _ROW, _T_V, _CACHED, _CACHED_CENTRE, _CACHED_SCALE, _CACHED_FIRST = range(9)
HEAD_SIZE = _CACHED_FIRST + DEGREE + 1
CELL_SIZE = HEAD_SIZE - _CACHED_CENTRE


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


_HEAD_EDGES = tuple(V_LOW ** (1.0 - j / HEAD_PIECES) for j in range(HEAD_PIECES)) + (1.0,)
"""v at the head pieces' ends (computed once, so a head's piece costs a few comparisons)."""


@jit(inline="always")
def _head_bounds(j):
    """v at the ends of head piece j."""
    return _HEAD_EDGES[j], _HEAD_EDGES[j + 1]


@jit(inline="always")
def _head_piece(v):
    """The head piece holding v, −1 below V_LOW."""
    if not v >= V_LOW:
        return -1
    j = HEAD_PIECES - 1
    while v < _HEAD_EDGES[j]:
        j -= 1
    return j


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
def _cosines(n):
    """cos(jπ(i + ½)/n): row 1 the Chebyshev nodes, all rows the transform."""
    cosines = np.empty((n, n))
    for j in range(n):
        for i in range(n):
            cosines[j, i] = math.cos(math.pi * j * (i + 0.5) / n)
    return cosines


@jit(parallel=True)
def build():
    """The table for every head [shape=(PIECES·HEAD_PIECES, _COLUMNS)].

    Each cell is interpolated at the tensor product of DEGREE + 1 and HEAD_DEGREE + 1
    Chebyshev nodes, then written in powers of its local (t_d, t_v) in [−1, 1]²: the series
    converges so fast on these cells (each coefficient some 50 times below the last, in
    either variable) that the powers' coefficients fall as fast and the sums are as stable
    as Clenshaw's. Each cell depends only on its indices, so the table is the same whatever
    the order the cells are built in.
    """
    n, nv = DEGREE + 1, HEAD_DEGREE + 1
    table = np.empty((PIECES * HEAD_PIECES, _COLUMNS))
    cos_d, cos_v = _cosines(n), _cosines(nv)
    powers_d, powers_v = _chebyshev_powers(n), _chebyshev_powers(nv)
    for cell in prange(PIECES * HEAD_PIECES):
        _build_cell(table, cell, cos_d, cos_v, powers_d, powers_v)
    return table


@jit
def _build_cell(table, cell, cos_d, cos_v, powers_d, powers_v):
    n, nv = DEGREE + 1, HEAD_DEGREE + 1
    j, k = cell // PIECES, cell % PIECES
    low, high = _piece_bounds(k)
    centre, half = 0.5 * (low + high), 0.5 * (high - low)
    v_low, v_high = _head_bounds(j)
    v_centre, v_half = 0.5 * (v_low + v_high), 0.5 * (v_high - v_low)
    values = np.empty((n, nv))
    for i in range(n):
        for l in range(nv):
            values[i, l] = scaled_flight(centre + half * cos_d[1, i], v_centre + v_half * cos_v[1, l] - 1.0)
    # the Chebyshev series, one variable at a time
    along_d = np.empty((n, nv))
    for a in range(n):
        for l in range(nv):
            total = 0.0
            for i in range(n):
                total += values[i, l] * cos_d[a, i]
            along_d[a, l] = (1.0 if a else 0.5) * 2.0 / n * total
    series = np.empty((n, nv))
    for a in range(n):
        for b in range(nv):
            total = 0.0
            for l in range(nv):
                total += along_d[a, l] * cos_v[b, l]
            series[a, b] = (1.0 if b else 0.5) * 2.0 / nv * total
    # then in powers, one variable at a time
    in_d = np.zeros((n, nv))
    for p in range(n):
        for b in range(nv):
            total = 0.0
            for a in range(p, n):
                total += series[a, b] * powers_d[a, p]
            in_d[p, b] = total
    table[cell, _CENTRE], table[cell, _SCALE] = centre, 1.0 / half
    for p in range(n):
        for q in range(nv):
            total = 0.0
            for b in range(q, nv):
                total += in_d[p, b] * powers_v[b, q]
            table[cell, _FIRST + p * nv + q] = total
    if not _cell_checked(table, cell, low, high, v_low, v_high):
        table[cell, _FIRST:] = math.nan  # (a flight in it then keeps R_F)


@jit
def _cell_checked(table, cell, low, high, v_low, v_high):
    """Whether the cell is within CHECK_RTOL of R_F at its corners, edges' midpoints and centre."""
    probe = np.empty(HEAD_SIZE)
    for v in (v_low, 0.5 * (v_low + v_high), v_high):
        _set_head(probe, v - 1.0, cell // PIECES)
        _sum_cell(table, probe, cell % PIECES)  # (the ends belong to the neighbours' pieces too)
        for d in (low, 0.5 * (low + high), high):
            exact = scaled_flight(d, v - 1.0)
            if not abs(_horner(probe, d) - exact) <= CHECK_RTOL * exact:
                return False
    return True


@jit
def head(table, sin_head):
    """What a chain of flights from the head sin θ_max needs of ``table`` [shape=(HEAD_SIZE,)].

    With an empty ``table``, or a head it does not cover, every flight is R_F's.
    """
    out = np.empty(HEAD_SIZE)
    set_head(out, table, sin_head)
    return out


@jit
def set_head(out, table, sin_head):
    """:func:`head` into ``out`` [shape=(HEAD_SIZE,)]."""
    _set_head(out, sin_head, _head_piece(1.0 + sin_head) if len(table) else -1)


@jit(inline="always")
def _set_head(out, sin_head, j):
    big = 1.0 - sin_head
    out[_SIN], out[_PER_ROOT_2L], out[_PER_L] = sin_head, 1.0 / math.sqrt(2.0 * big), 1.0 / big
    out[_ROW], out[_CACHED], out[_T_V] = j, -1.0, 0.0
    if j >= 0:
        v_low, v_high = _head_bounds(j)
        out[_T_V] = ((1.0 + sin_head) - 0.5 * (v_low + v_high)) / (0.5 * (v_high - v_low))


@jit(inline="always")
def _horner(head, d):
    """The head's last cell's polynomial in d, at d."""
    t = (d - head[_CACHED_CENTRE]) * head[_CACHED_SCALE]
    total = head[_CACHED_FIRST + DEGREE]
    for p in range(DEGREE - 1, -1, -1):
        total = total * t + head[_CACHED_FIRST + p]
    return total


@jit(inline="always")
def _sum_cell(table, head, k):
    """The polynomial in d of the cell (k, the head's piece) at the head's v, into ``head``."""
    row = int(head[_ROW]) * PIECES + k
    t_v = head[_T_V]
    for p in range(DEGREE + 1):
        first = _FIRST + p * (HEAD_DEGREE + 1)
        total = table[row, first + HEAD_DEGREE]
        for q in range(HEAD_DEGREE - 1, -1, -1):
            total = total * t_v + table[row, first + q]
        head[_CACHED_FIRST + p] = total
    head[_CACHED_CENTRE], head[_CACHED_SCALE], head[_CACHED] = table[row, _CENTRE], table[row, _SCALE], k


@intrinsic
def _bits(typingctx, x):
    """The bits of the float64 ``x`` as an int64 (compiled to no instruction)."""

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], llvmlite.ir.IntType(64))

    return types.int64(types.float64), codegen


@jit(inline="always")
def _piece(d):
    """The piece in d holding d, PIECES past the last (or for d ≤ 0)."""
    if not d > 0.0:
        return PIECES
    d2 = d * d
    d4 = d2 * d2
    d8 = d4 * d4
    # −frexp(d⁸)'s exponent, read from the bits (frexp is a call, a fifth of a flight's time)
    biased = (_bits(d8) >> 52) & 0x7FF
    if biased == 0:  # zero (frexp's exponent 0) or subnormal (frexp's −1022 or below)
        return 0 if d8 == 0.0 else PIECES
    return min(max(1022 - biased, 0), PIECES)


@jit
def evaluate(table, head, d):
    """g at d = 1 − u for the head from the table; NaN where the table does not serve."""
    k = _piece(d)
    if k >= PIECES or head[_ROW] < 0.0:
        return math.nan
    if head[_CACHED] != k:
        _sum_cell(table, head, k)
    return _horner(head, d)


@jit(inline="always")
def flight_time(launch_speed, c, head):
    """:func:`.elliptic.flight_time` from the table: (duration (s), m), or (NaN, m) for a cell new to the head.

    On NaN, call :func:`fill` and this again. The two steps are the caller's, in its own code: numba
    counts references to the arrays at every call of a function compiled into a kernel that passes
    them on to another call, and that made a flight four times slower. Where the table does not
    serve (a head below V_LOW, or past the last piece, or in a cell that failed its check), R_F.

    Parameters
    ----------
    launch_speed : float ≥ 0
        ω just after the impact (rad/s).
    c : float > 0
        C (s⁻²).
    head : ndarray
        From :func:`head` for the table and the head; holds the last cell's polynomial in d.
    """
    m, u, d, per_root_c = _launch(launch_speed, c, head)
    k = _piece(d)
    if k >= PIECES or head[_ROW] < 0.0:
        return exact_flight_time(launch_speed, c, head[_SIN])
    if k != head[_CACHED]:
        return math.nan, m
    g = _horner(head, d)
    if math.isnan(g):  # (a cell that failed its check)
        return exact_flight_time(launch_speed, c, head[_SIN])
    return u * g * per_root_c, m


@jit(inline="always")
def _launch(launch_speed, c, head):
    """m, u, d = 1 − u and 1/√C of a flight launched from the head."""
    sin_head = head[_SIN]
    energy = launch_speed * launch_speed / (2.0 * c)
    m = 0.5 * (1.0 + sin_head + energy)  # (as parameter computes it)
    per_root_c = 1.0 / math.sqrt(c)
    u = launch_speed * head[_PER_ROOT_2L] * per_root_c
    # Near the vertical d = 1 − u would lose the relative accuracy of 1 − m that the closed form
    # keeps: there d = (1 − u²)/(1 + u) with 1 − u² = (L − e)/L.
    d = 1.0 - u if u < 0.5 else ((1.0 - sin_head) - energy) * head[_PER_L] / (1.0 + u)
    return m, u, d, per_root_c


@jit
def fill(table, head, launch_speed, c, cells):
    """Put into ``head`` the polynomial in d of the cell of a flight launched at ``launch_speed`` under ``c``.

    ``cells`` is the head's :func:`head_cells`, or empty: then the cell's polynomial is summed now.
    Both give the same numbers, so a flight's time does not depend on which a caller had.
    """
    k = _piece(_launch(launch_speed, c, head)[2])
    if k < len(cells):
        head[_CACHED_CENTRE:] = cells[k]
        head[_CACHED] = k
    else:
        _sum_cell(table, head, k)


@jit
def head_cells(table, sin_head):
    """Every cell's polynomial in d summed for the head [shape=(PIECES, CELL_SIZE)], for :func:`fill`.

    Some 12 µs: worth it for a head many strokes share (a chain sums only the cells it meets).
    """
    head = np.empty(HEAD_SIZE)
    set_head(head, table, sin_head)
    if head[_ROW] < 0.0:
        return np.empty((0, CELL_SIZE))
    cells = np.empty((PIECES, CELL_SIZE))
    for k in range(PIECES):
        _sum_cell(table, head, k)
        cells[k] = head[_CACHED_CENTRE:]
    return cells


@functools.cache
def table():
    """The table, built on first use in a process (the same in every process)."""
    return build()
