"""Many strokes under constant forcing at once, in compiled code on every core.

The same rules as :mod:`.hybrid` (closed-form flights, c·w launches, the Zeno
floor on speed and height, rest), one stroke per parallel iteration and no
Python between steps. Strokes this kernel does not cover (forcing that lifts,
C ≤ 0, or a flight toward the vertical) are flagged for the general solver.

Two passes: the first bounds each stroke's impact count (one closed-form
flight per stroke), the second fills one flat array at those offsets.

Each flight from the head is read from the flight-time table (:mod:`.flight_table`,
one for every head, built once per process) unless ``exact`` asks for Carlson's
R_F at every impact, the table's reference.

tests/test_batch.py holds it equal to :mod:`.kernel`, stroke by stroke.
"""

import math

import numpy as np
from numba import prange

from .._jit import jit
from . import flight_table
from .constants import NEARLY_VERTICAL
from .elliptic import flight_time, parameter, to_head
from .taylor import zeno_floor

OK, UNSUPPORTED, TOO_MANY = 0, 1, 2


@jit
def _first_impact(theta, omega, c, theta_max):
    """(kind, time, speed) of the first event: 0 impact at ``time``, 1 at rest now, 2 settle, 3 unsupported."""
    sin_head = math.sin(theta_max)
    if theta == theta_max:
        if omega == 0.0:
            return 1, 0.0, 0.0
        if omega < 0.0:
            return 0, 0.0, -omega
        if omega < zeno_floor(c * math.cos(theta_max)):
            return 2, 0.0, omega
    sin_theta = math.sin(theta)
    m = parameter(sin_theta, omega, c)
    if m >= 1.0 - NEARLY_VERTICAL:
        return 3, 0.0, 0.0
    to_apex, apex_to_head, speed = to_head(sin_theta, omega, c, m, sin_head)
    return 0, to_apex + apex_to_head, speed


@jit
def _run(theta0, omega0, cor, c, theta_max, t_end, out_t, out_w, start, capacity, table, head, cells):
    """One stroke: fills out_t/out_w from ``start``; returns (status, count, rest time or NaN).

    ``head`` is room for :func:`.flight_table.set_head` (the stroke's own: strokes run in parallel);
    ``cells`` the head's :func:`.flight_table.head_cells` or empty.
    """
    if not c > 0.0:
        return UNSUPPORTED, 0, math.nan
    a = c * math.cos(theta_max)
    floor = zeno_floor(a)
    sin_head = math.sin(theta_max)
    kind, t, speed = _first_impact(theta0, omega0, c, theta_max)
    if kind == 3:
        return UNSUPPORTED, 0, math.nan
    if kind == 1:
        return OK, 0, 0.0
    n = 0
    if kind == 2:
        launch = speed
    else:
        if t > t_end:
            return OK, 0, math.nan
        if capacity < 1:
            return TOO_MANY, 0, math.nan
        out_t[start] = t
        out_w[start] = -speed
        n = 1
        launch = cor * speed
    flight_table.set_head(head, table, sin_head)
    while True:
        if launch == 0.0:
            return OK, n, t
        if launch < floor:
            rest = t + 2.0 * launch / (a * (1.0 - cor)) if cor < 1.0 else t
            return OK, n, rest if rest <= t_end else math.nan
        flight, m = flight_table.flight_time(launch, c, head)
        if math.isnan(flight):  # the first flight in a cell of the table: its polynomial for the head
            flight_table.fill(table, head, launch, c, cells)
            flight, m = flight_table.flight_time(launch, c, head)
        if m >= 1.0 - NEARLY_VERTICAL:
            return UNSUPPORTED, 0, math.nan
        end = t + flight
        if end > t_end:
            return OK, n, math.nan
        if n >= capacity:
            return TOO_MANY, n, math.nan
        out_t[start + n] = end
        out_w[start + n] = -launch
        n += 1
        t = end
        launch *= cor


@jit(parallel=True)
def _capacities(theta0, omega0, cor, c, theta_max, t_end, max_impacts):
    """An upper bound on each stroke's impact count (one flight each; exact counts come in the fill)."""
    out = np.zeros(len(theta0), dtype=np.int64)
    for i in prange(len(theta0)):
        if not c[i] > 0.0:
            continue
        kind, t, speed = _first_impact(theta0[i], omega0[i], c[i], theta_max[i])
        if kind != 0:
            continue
        a = c[i] * math.cos(theta_max[i])
        floor = zeno_floor(a)
        launch = cor[i] * speed
        if launch < floor:
            out[i] = 1
        elif cor[i] < 1.0:
            out[i] = min(max_impacts, int(math.log(floor / launch) / math.log(cor[i])) + 3)
        else:
            flight, m = flight_time(launch, c[i], math.sin(theta_max[i]))
            if m >= 1.0 - NEARLY_VERTICAL:
                continue
            out[i] = min(max_impacts, int((t_end[i] - t) / flight) + 3)
    return out


@jit(parallel=True)
def _fill(theta0, omega0, cor, c, theta_max, t_end, offsets, out_t, out_w, status, count, rest, table, heads, cells,
          shared):
    no_cells = np.empty((0, cells.shape[2]))
    for i in prange(len(theta0)):
        capacity = offsets[i + 1] - offsets[i]
        status[i], count[i], rest[i] = _run(
            theta0[i], omega0[i], cor[i], c[i], theta_max[i], t_end[i], out_t, out_w, offsets[i], capacity, table,
            heads[i], cells[shared[i]] if shared[i] >= 0 else no_cells
        )


SHARED = 64
"""Strokes sharing a head from which the batch sums all its cells at once (some 12 µs) for them to read."""


def _shared_cells(theta_max, table):
    """The cells of each head at least SHARED strokes share, and each stroke's row in them (−1: none).

    Only a matter of speed: a stroke's flights are the same whether its chain reads these or sums its cells.
    """
    heads, inverse, counts = np.unique(theta_max, return_inverse=True, return_counts=True)
    row = np.full(len(heads), -1, dtype=np.int64)
    cells = []
    for j in np.flatnonzero(counts >= SHARED) if len(table) else ():
        head_cells = _head_cells(table, heads[j])
        if len(head_cells):  # (a head the table covers)
            row[j] = len(cells)
            cells.append(head_cells)
    if not cells:
        return np.empty((1, 0, flight_table.CELL_SIZE)), row[inverse.ravel()]
    return np.stack(cells), row[inverse.ravel()]


@jit
def _head_cells(table, theta_max):
    """:func:`.flight_table.head_cells` of the head θ_max, with its sine as :func:`_run` takes it."""
    return flight_table.head_cells(table, math.sin(theta_max))


def constant_batch(theta0, omega0, cor, c, theta_max, t_end, *, max_impacts, exact=False):
    """Impacts of many strokes under constant forcing C (s⁻²), all arrays of one length.

    ``exact`` evaluates each flight by R_F instead of the flight-time table (the reference).

    Returns
    -------
    status : ndarray of int
        OK, UNSUPPORTED (use the general solver) or TOO_MANY (over ``max_impacts``).
    offsets : ndarray [shape=(n + 1,)]
        Stroke i's impacts are ``t[offsets[i]:offsets[i] + count[i]]``.
    count : ndarray of int
    t, omega : ndarray
        Impact times (s) and ω just before them (rad/s), stroke after stroke.
    rest : ndarray
        When each stroke comes to rest for good (s), NaN if it does not by t_end.
    """
    arrays = [np.ascontiguousarray(x, dtype=float) for x in (theta0, omega0, cor, c, theta_max, t_end)]
    capacity = _capacities(*arrays, max_impacts)
    offsets = np.concatenate(([0], np.cumsum(capacity)))
    out_t = np.empty(offsets[-1])
    out_w = np.empty(offsets[-1])
    n = len(arrays[0])
    status = np.zeros(n, dtype=np.int64)
    count = np.zeros(n, dtype=np.int64)
    rest = np.full(n, np.nan)
    table = np.empty((0, 0)) if exact else flight_table.table()
    heads = np.empty((n, flight_table.HEAD_SIZE))  # (one allocation, not one a stroke)
    _fill(*arrays, offsets, out_t, out_w, status, count, rest, table, heads, *_shared_cells(arrays[4], table))
    return status, offsets, count, out_t, out_w, rest
