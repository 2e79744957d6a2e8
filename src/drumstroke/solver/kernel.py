"""The hybrid solver's loop and the trajectory's evaluation, compiled (numba, cached on disk).

:func:`run` walks the pieces of forcing with the rules of :mod:`.hybrid`:
closed-form flights one after another where the forcing is constant and
presses down, :func:`.taylor.run_piece` elsewhere, the Zeno tail, rest and
lift-off. Nothing returns to Python between flights or pieces.

:func:`evaluate` reads the arcs at many times. Samples at a fixed spacing in
one elliptic flight are carried from one to the next by the addition theorem
of sn, cn, dn (a few multiplications), and computed afresh every
:data:`REANCHOR` samples, or sooner on fast orbits (:data:`REACH`), so that
round-off cannot accumulate.
"""

import math

import numpy as np

from .. import _pulses
from .._jit import jit
from . import elliptic, flight_table
from .constants import ARC_COLUMNS, ELLIPTIC, NEARLY_VERTICAL, REST, TAYLOR, TAYLOR_ORDER
from .taylor import DONE as _TAYLOR_DONE
from .taylor import SETTLE as _TAYLOR_SETTLE
from .taylor import TOO_MANY as _TAYLOR_TOO_MANY
from .taylor import VERTICAL as _TAYLOR_VERTICAL
from .taylor import evaluate as polynomial
from .taylor import grow, holds, run_piece, zeno_floor

# run's outcomes
DONE, VERTICAL, TOO_MANY = 0, 1, 2

# slots of the state vector carried from one call of run to the next
T, THETA, OMEGA, RESTING, LIFTING, TAIL_C, REST_START, IMPACTS, STEPS = range(9)
STATE_SIZE = 9

REANCHOR = 128
"""Most samples carried by the addition theorem before one is computed afresh..."""

REACH = 1.0
"""...the farthest (in v = √C·τ) they are carried: near the vertical (m → 1) the
carried round-off grows like e^(2v), so the reach, not the count, bounds it (by e²)..."""

STEADY = 1000.0
"""...and at most STEADY·√(1 − m) of them: each carried step adds about ε/√(1 − m) to θ
near the vertical, where dn falls to √(1 − m); orbits that close are computed afresh."""

RUNS = 4
"""Runs of samples :func:`evaluate` carries side by side (fewer where the flights are too few to split):
a carried sample waits some 40 cycles for the one before it, and the other runs' samples fill the wait."""


@jit
def initial_state(theta0, omega0):
    """The state vector at t = 0: in flight at (θ₀, ω₀)."""
    state = np.zeros(STATE_SIZE)
    state[THETA], state[OMEGA] = theta0, omega0
    state[TAIL_C] = state[REST_START] = math.nan
    return state


@jit
def run_constant(c, t_end, theta0, omega0, theta_max, table, cor, closed_forms, max_step, max_impacts):
    """:func:`run` from (θ₀, ω₀) at t = 0 to ``t_end`` (s) under the constant C = ``c`` (s⁻²), the whole stroke.

    The commonest stroke, with nothing to build in Python first and one array handed back (making
    the forcing's arrays in Python, and handing back four, cost more than its bounces).

    Returns
    -------
    outcome : int
    extra : float
        As :func:`run`'s.
    rows : ndarray [shape=(n, ARC_COLUMNS)]
        :func:`run`'s arcs, then its impacts up to ``t_end`` and its rests in the first two columns, then
        its Taylor steps' numbers one after another (each step's TAYLOR_ORDER + 2 of them, row after row).
    n_arcs, n_through_impacts, n_through_rests : int
        Where the impacts', the rests' and the steps' rows start.
    n_steps : int
        How many Taylor steps :func:`run` took.
    """
    edges, c0, c1 = np.empty(2), np.empty(1), np.zeros(1)
    edges[0], edges[1], c0[0] = 0.0, t_end, c
    outcome, extra, arcs, steps, impacts, rests = run(edges, c0, c1, theta_max, table, cor, closed_forms, max_step,
                                                      max_impacts, True, initial_state(theta0, omega0))
    return _packed(outcome, extra, arcs, steps, impacts, rests, t_end)


@jit
def run_linear(points, values, tol, rates, t_end, theta0, omega0, theta_max, table, cor, closed_forms, max_step,
               max_impacts):
    """:func:`run` from (θ₀, ω₀) at t = 0 to ``t_end`` (s) under a piecewise-linear a(t) through a few points, the
    whole stroke (a designed stroke's forcing).

    The profile's pieces as :class:`drumstroke.profiles.PiecewiseLinear` cuts them in Python (its few points'
    edges merged within ``tol`` s, :func:`drumstroke.profiles.merge_edges`; its value and slope after each), and
    C = (k·g + k′·a)/D of them with ``rates`` = (k, k′, D, g): the same operations in the same order, so the same
    forcing to the bit. Returns as :func:`run_constant`.
    """
    edges, c0, c1 = _linear_forcing(points, values, tol, rates, t_end)
    outcome, extra, arcs, steps, impacts, rests = run(edges, c0, c1, theta_max, table, cor, closed_forms, max_step,
                                                      max_impacts, True, initial_state(theta0, omega0))
    return _packed(outcome, extra, arcs, steps, impacts, rests, t_end)


@jit
def run_pulses(train, count, tol, rates, t_end, theta0, omega0, theta_max, table, cor, closed_forms, max_step,
               max_impacts):
    """:func:`run` from (θ₀, ω₀) at t = 0 to ``t_end`` (s) under a pulse train a(t), the whole stroke.

    ``train`` = (amplitude, period, phase, duty, base) of :class:`drumstroke.profiles.Pulses`, cut as it cuts
    itself (:func:`drumstroke._pulses.pieces`, ``count`` pulses, edges merged within ``tol`` s); C = (k·g + k′·a)/D
    on each piece and its slope 0 with ``rates`` = (k, k′, D, g), as the solver's Python makes them. Returns as
    :func:`run_constant`.
    """
    edges, values = _pulses.pieces(train[0], train[1], train[2], train[3], train[4], t_end, count, tol)
    k, k_thumb, inertia_ratio, gravity = rates[0], rates[1], rates[2], rates[3]
    c0, c1 = np.empty(len(values)), np.empty(len(values))
    for i in range(len(values)):
        c0[i] = (k * gravity + k_thumb * values[i]) / inertia_ratio
        c1[i] = (k * 0.0 + k_thumb * 0.0) / inertia_ratio
    outcome, extra, arcs, steps, impacts, rests = run(edges, c0, c1, theta_max, table, cor, closed_forms, max_step,
                                                      max_impacts, True, initial_state(theta0, omega0))
    return _packed(outcome, extra, arcs, steps, impacts, rests, t_end)


@jit
def _linear_forcing(points, values, tol, rates, t_end):
    """Edges (s) [shape=(n + 1,)], C at the start of each piece (s⁻²) and its slope (s⁻³) of a piecewise-linear a(t)
    through ``points`` (s) and ``values`` (m/s²), under constant gravity (see :func:`run_linear`)."""
    ordered = np.sort(np.concatenate((np.array([0.0, t_end]), points)))
    kept = np.empty(len(ordered))
    n = 0
    for edge in ordered:  # in [0, t_end], each once, and a cluster within tol merged into its first edge
        if 0.0 <= edge <= t_end and (n == 0 or (edge != kept[n - 1] and edge - kept[n - 1] > tol)):
            kept[n] = edge
            n += 1
    kept[n - 1] = t_end
    k, k_thumb, inertia_ratio, gravity = rates[0], rates[1], rates[2], rates[3]
    c0, c1 = np.empty(n - 1), np.empty(n - 1)
    last = len(points) - 1
    for i in range(n - 1):
        x = kept[i]
        j = np.searchsorted(points, x + tol, side="right") - 1  # the segment the piece lies on
        if 0 <= j < last:
            slope = (values[j + 1] - values[j]) / (points[j + 1] - points[j])
            value = values[j] + slope * (x - points[j])
        else:
            slope, value = 0.0, values[0] if x < points[0] else values[last]
        c0[i] = (k * gravity + k_thumb * value) / inertia_ratio
        c1[i] = (k * 0.0 + k_thumb * slope) / inertia_ratio
    return kept[:n], c0, c1


@jit
def _packed(outcome, extra, arcs, steps, impacts, rests, t_end):
    """:func:`run`'s results as :func:`run_constant` returns them: one array of rows, and where its parts start.

    One array, not several: handing an array back to Python costs some 0.3 µs, a tenth of a free bounce.
    """
    n_arcs, n_impacts = len(arcs), len(impacts)
    while n_impacts and impacts[n_impacts - 1, 0] > t_end:  # (found by a Taylor step that ends past t_end)
        n_impacts -= 1
    n_rests_end = n_arcs + n_impacts + len(rests)
    width = TAYLOR_ORDER + 2
    flat = np.empty((n_rests_end + -(-len(steps) * width // ARC_COLUMNS)) * ARC_COLUMNS)
    rows = flat.reshape((-1, ARC_COLUMNS))
    for i in range(n_arcs):  # (loops, not slices: numba copies slices of these views element by element, slower)
        for j in range(ARC_COLUMNS):
            rows[i, j] = arcs[i, j]
    for i in range(n_impacts):
        rows[n_arcs + i, 0], rows[n_arcs + i, 1] = impacts[i, 0], impacts[i, 1]
    for i in range(len(rests)):
        rows[n_arcs + n_impacts + i, 0], rows[n_arcs + n_impacts + i, 1] = rests[i, 0], rests[i, 1]
    first = n_rests_end * ARC_COLUMNS
    for k in range(len(steps)):
        for j in range(width):
            flat[first + k * width + j] = steps[k, j]
    return outcome, extra, rows, n_arcs, n_arcs + n_impacts, n_rests_end, len(steps)


@jit
def _lift_off(ts, te, c0, c1, t):
    """When, in [t, te), a resting stick lifts off under C = c0 + c1·(t − ts); NaN if it stays."""
    if not holds(c0 + c1 * (t - ts), c1, te - t):
        return t
    if c1 < 0.0:
        zero = ts - c0 / c1
        if zero < te:
            return max(zero, t)
    return math.nan


# how a chain of bounces ends (_bounces)
_FLOOR, _STEEP, _PAST, _LIMIT, _ROOM, _NONE = range(6)  # (_NONE: no chain)
_MIN_ROOM = 64


@jit(inline="always")
def _fit(array, rows):
    """``array``, or a copy of it doubled as often as it takes to hold ``rows`` rows."""
    while len(array) < rows:
        array = grow(array, len(array))
    return array


@jit(inline="always")  # (a call that passes the buffers on counted references to five arrays, atomically)
def _bounces(arcs, n_arcs, impacts, n_impacts, room, impacts_left, t, te, launch, c, cor, floor, theta_max, table,
             head, no_cells):
    """Flights from the head at ``t`` (s), launched at ``launch``, c·launch, … (rad/s) under C = ``c`` until ``te``.

    Writes their arcs and impacts from rows ``n_arcs`` and ``n_impacts`` on, at most ``room`` of each
    (the buffers never change here: a kernel that may swap a buffer counts references to it at every
    write, which cost twice a flight).

    Returns
    -------
    end : int
        _FLOOR (the launch is below ``floor``), _STEEP (the flight nears the vertical; not written),
        _PAST (the flight written ends after ``te``), _LIMIT (more than ``impacts_left`` impacts)
        or _ROOM (``room`` flights written).
    n_arcs, n_impacts : int
    t : float
        The last flight's start (_PAST) or the last impact (s).
    launch : float
        The next launch (rad/s).
    flight, m : float
        The last flight's duration (s) and parameter.
    """
    flight = m = math.nan
    stop = n_arcs + room
    while n_impacts <= impacts_left:
        if launch < floor:  # (launch = 0 included)
            return _FLOOR, n_arcs, n_impacts, t, launch, flight, m
        if n_arcs == stop:
            return _ROOM, n_arcs, n_impacts, t, launch, flight, m
        flight, m = flight_table.flight_time(launch, c, head)
        if math.isnan(flight):  # the first flight in a cell of the table: its polynomial for the head
            flight_table.fill(table, head, launch, c, no_cells)
            flight, m = flight_table.flight_time(launch, c, head)
        if m >= 1.0 - NEARLY_VERTICAL:
            return _STEEP, n_arcs, n_impacts, t, launch, flight, m
        _put_arc(arcs, n_arcs, t, ELLIPTIC, t + 0.5 * flight, c, m, theta_max, launch)
        n_arcs += 1
        if t + flight > te:
            return _PAST, n_arcs, n_impacts, t, launch, flight, m
        t += flight
        impacts[n_impacts, 0], impacts[n_impacts, 1] = t, -launch
        n_impacts += 1
        launch *= cor
    return _LIMIT, n_arcs, n_impacts, t, launch, flight, m


@jit(inline="always")
def _put_arc(arcs, n, start, kind, apex, c, m, theta, omega):
    arcs[n, 0], arcs[n, 1], arcs[n, 2], arcs[n, 3], arcs[n, 4] = start, kind, apex, c, m
    arcs[n, 5], arcs[n, 6] = theta, omega


@jit
def run(edges, c0, c1, theta_max, table, cor, closed_forms, max_step, max_impacts, finish, state):
    """Carry the stick through the pieces [edges[i], edges[i+1]) where C = c0[i] + c1[i]·(t − edges[i]).

    Parameters
    ----------
    edges : ndarray [shape=(n + 1,)]
        s, strictly increasing.
    c0, c1 : ndarray [shape=(n,)]
        C at the start of each piece (s⁻²) and its slope (s⁻³).
    theta_max : float
        The head (rad).
    table : ndarray
        The flight-time table (:func:`.flight_table.table`) for the flights from the head;
        empty, R_F at every flight (the table's reference).
    cor : float in [0, 1]
    closed_forms : bool
        False integrates every flight with Taylor steps (a cross-check).
    max_step : float
        Longest Taylor step (s).
    max_impacts : int
        Impacts allowed in all, counting those of earlier calls.
    finish : bool
        These are the last pieces: a rest still going ends at ``edges[-1]`` (t_end).
    state : ndarray [shape=(STATE_SIZE,)]
        Where the stick is; updated in place.

    Returns
    -------
    outcome : int
        DONE, VERTICAL or TOO_MANY (``extra`` is then the time it happened).
    extra : float
    arcs : ndarray [shape=(n_arcs, ARC_COLUMNS)]
        Rows of :attr:`.arcs.Arcs.table`.
    steps : ndarray [shape=(n_steps, TAYLOR_ORDER + 2)]
        The Taylor arcs' start times and polynomials, in order.
    impacts : ndarray [shape=(n_impacts, 2)]
        Time (s) and ω just before (rad/s).
    rests : ndarray [shape=(n_rests, 2)]
        Start and end (s) of the rests that ended in these pieces (by lift-off, or at
        t_end if ``finish``); one still going is in ``state``.
    """
    sin_head, cos_head = math.sin(theta_max), math.cos(theta_max)
    head = flight_table.head(table, sin_head)
    no_cells = np.empty((0, flight_table.CELL_SIZE))  # (a chain sums the cells it meets)
    agm = elliptic.agm_scratch()  # (for the states at the pieces' ends)
    t, theta, omega = state[T], state[THETA], state[OMEGA]
    resting, lifting = state[RESTING] != 0.0, state[LIFTING] != 0.0
    tail_c, rest_start = state[TAIL_C], state[REST_START]
    n_before, steps_before = int(state[IMPACTS]), int(state[STEPS])
    arcs, n_arcs = np.empty((256, ARC_COLUMNS)), 0
    steps, n_steps = np.empty((4, TAYLOR_ORDER + 2)), 0
    impacts, n_impacts = np.empty((256, 2)), 0
    rests, n_rests = np.empty((4, 2)), 0
    outcome, extra = DONE, math.nan

    # The buffers are grown (reassigned) only in the outer loop, which goes round again only when they are full:
    # numba counts the references to an array reassigned within a loop at every pass of it, atomically, which cost
    # a third of a pulsed stroke's solving. A pass that finds too little room stops before it changes anything, or
    # with a chain of bounces to ``resume`` from its last impact, and the piece goes on once the buffers have grown.
    i, begun, full, resume = 0, False, False, -1.0
    taylor_rows, taylor_impacts = 0, 0  # what a Taylor piece found no room for
    while True:  # (again only after the buffers grew)
        if full:
            arcs = _fit(arcs, n_arcs + max(taylor_rows + 1, _MIN_ROOM + 1))
            impacts = _fit(impacts, n_impacts + max(taylor_impacts, _MIN_ROOM))
            steps = _fit(steps, n_steps + taylor_rows)
            rests = _fit(rests, n_rests + 1)
            full, taylor_rows, taylor_impacts = False, 0, 0
        while i < len(c0):
            ts, te, a, b = edges[i], edges[i + 1], c0[i], c1[i]
            if not begun:
                begun = True
                t = ts
                if resting and rest_start > ts and a > 0.0:
                    # A Zeno tail summed under the last piece's forcing runs on into this one:
                    # its remaining time scales as 1/C.
                    rest_start = ts + (rest_start - ts) * tail_c / a
                    tail_c = a
            while t < te and outcome == DONE:
                if len(arcs) - n_arcs < 2 or len(impacts) - n_impacts < 1 or len(rests) - n_rests < 1:
                    full = True  # (a pass writes at most two arcs, an impact and a rest, but for its chain and steps)
                    break
                if resting:
                    lift = _lift_off(ts, te, a, b, t)
                    if math.isnan(lift):
                        break
                    if rest_start < lift:  # (lifting during the Zeno tail: that rest never began)
                        rests[n_rests, 0], rests[n_rests, 1] = rest_start, lift
                        n_rests += 1
                    t, theta, omega = lift, theta_max, 0.0
                    resting, lifting = False, True
                    continue

                settle, settle_c = -1.0, a  # settle ≥ 0: the stick rests after a launch this slow at t
                taylor = True
                if closed_forms and b == 0.0 and a > 0.0:
                    floor = zeno_floor(a * cos_head)
                    launch = -1.0  # ≥ 0: a run of bounces starts from the head at t
                    if resume >= 0.0:  # the chain the buffers' room cut, on from its last impact at t
                        taylor, lifting, launch, resume = False, False, resume, -1.0
                    elif theta == theta_max and omega <= 0.0:
                        taylor, lifting = False, False
                        if omega == 0.0:
                            launch = 0.0
                        else:
                            impacts[n_impacts, 0], impacts[n_impacts, 1] = t, omega
                            n_impacts += 1
                            launch = -cor * omega
                    elif theta == theta_max and omega < floor:
                        taylor, lifting = False, False
                        settle = omega  # a launch too small to see: the Zeno tail from the start
                    else:
                        sin_theta = math.sin(theta)
                        m = elliptic.parameter(sin_theta, omega, a)
                        if m < 1.0 - NEARLY_VERTICAL:
                            taylor, lifting = False, False
                            to_apex, apex_to_head, speed = elliptic.to_head(sin_theta, omega, a, m, sin_head)
                            apex = t + to_apex
                            hit = apex + apex_to_head
                            _put_arc(arcs, n_arcs, t, ELLIPTIC, apex, a, m, theta, omega)
                            n_arcs += 1
                            if hit > te:
                                theta, omega = elliptic.state_with(te - apex, a, m, agm)
                                t, theta = te, max(theta, theta_max)
                                continue
                            t = hit
                            impacts[n_impacts, 0], impacts[n_impacts, 1] = t, -speed
                            n_impacts += 1
                            launch = cor * speed
                    # After an impact at speed w the launches are c·w, c²·w, …: one closed-form flight each.
                    chain = _ROOM if launch >= 0.0 else _NONE
                    while chain == _ROOM:
                        room = min(len(arcs) - n_arcs - 1, len(impacts) - n_impacts)  # (a row kept for a rest's arc)
                        if room < _MIN_ROOM:
                            full, resume = True, launch
                            break
                        chain, n_arcs, n_impacts, t, launch, flight, m = _bounces(
                            arcs, n_arcs, impacts, n_impacts, room, max_impacts - n_before, t, te, launch, a, cor,
                            floor, theta_max, table, head, no_cells)
                    if full:
                        break
                    if chain == _FLOOR:
                        settle = launch
                    elif chain == _STEEP:  # toward the vertical: the Taylor steps take it
                        theta, omega = theta_max, launch
                    elif chain == _PAST:
                        if t == te:
                            theta, omega = theta_max, launch
                        else:
                            theta, omega = elliptic.state_with(te - (t + 0.5 * flight), a, m, agm)
                            t, theta = te, max(theta, theta_max)
                    if n_before + n_impacts > max_impacts:
                        outcome, extra = TOO_MANY, t
                        break
                    if settle < 0.0 and launch >= 0.0:
                        continue  # the bounces reached te, or left the rest of the piece to the Taylor steps
                if taylor and settle < 0.0:
                    (piece_outcome, piece_t_end, piece_theta, piece_omega_end, piece_lifting, piece_extra, piece_steps,
                     piece_t, piece_omega) = run_piece(t, theta, omega, lifting, ts, te, a, b, theta_max, cor, max_step,
                                                       max_impacts - n_before - n_impacts)
                    if (len(arcs) - n_arcs < len(piece_steps) + 1 or len(steps) - n_steps < len(piece_steps)
                            or len(impacts) - n_impacts < len(piece_t)):
                        full, taylor_rows, taylor_impacts = True, len(piece_steps), len(piece_t)
                        break  # (taken again once there is room: nothing changed yet)
                    t, theta, omega, lifting = piece_t_end, piece_theta, piece_omega_end, piece_lifting
                    for k in range(len(piece_steps)):
                        _put_arc(arcs, n_arcs, piece_steps[k, 0], TAYLOR, steps_before + n_steps, 0.0, 0.0,
                                 piece_steps[k, 1], piece_steps[k, 2])
                        n_arcs += 1
                        steps[n_steps] = piece_steps[k]
                        n_steps += 1
                    for k in range(len(piece_t)):
                        impacts[n_impacts, 0], impacts[n_impacts, 1] = piece_t[k], piece_omega[k]
                        n_impacts += 1
                    if piece_outcome == _TAYLOR_VERTICAL:
                        outcome, extra = VERTICAL, piece_extra
                        break
                    if piece_outcome == _TAYLOR_TOO_MANY:
                        outcome, extra = TOO_MANY, t
                        break
                    if piece_outcome == _TAYLOR_DONE:
                        continue
                    if piece_outcome == _TAYLOR_SETTLE:
                        settle, settle_c = omega, piece_extra
                    else:
                        settle = 0.0
                # Rest: at once after a zero-speed launch, or at the accumulation time of the
                # Zeno tail, 2L/(A·(1 − c)) after a launch L, with A = C·cos θ_max. With c = 1
                # such a micro-bounce never ends but never rises above ZENO_HEIGHT: rest from now.
                tail = 2.0 * settle / (settle_c * cos_head * (1.0 - cor)) if settle > 0.0 and cor < 1.0 else 0.0
                _put_arc(arcs, n_arcs, t, REST, 0.0, 0.0, 0.0, theta_max, 0.0)
                n_arcs += 1
                tail_c, rest_start = settle_c, t + tail
                theta, omega, resting = theta_max, 0.0, True
            if full or outcome != DONE:
                break
            i += 1
            begun = False
        if not full:
            break

    if finish and resting and rest_start <= edges[-1]:
        # (a rest starting beyond t_end means t_end falls inside the Zeno tail: not at rest yet)
        rests = grow(rests, n_rests)
        rests[n_rests, 0], rests[n_rests, 1] = rest_start, edges[-1]
        n_rests += 1
    state[T], state[THETA], state[OMEGA] = t, theta, omega
    state[RESTING], state[LIFTING] = 1.0 if resting else 0.0, 1.0 if lifting else 0.0
    state[TAIL_C], state[REST_START] = tail_c, rest_start
    state[IMPACTS], state[STEPS] = n_before + n_impacts, steps_before + n_steps
    return outcome, extra, arcs[:n_arcs], steps[:n_steps], impacts[:n_impacts], rests[:n_rests]


@jit(error_model="numpy")  # (no divisor here is zero: dn ≥ √(1 − m) > 0, spacing > 0 where divided by)
def evaluate(table, steps, theta_max, t, spacing):
    """The arcs (see :class:`.arcs.Arcs`) at the times ``t`` (s): all but the last step of θ, and ω.

    With ``spacing`` > 0 the times are increasing and ``t[k + 1] − t[k] = spacing``
    (s) up to round-off, except perhaps for the last; with 0 they may be anything.
    At an arc's start time the new arc holds, and its stored start state is returned exactly
    (the recipe's θ₀, ω₀ at t = 0; the state just after an impact).

    Returns
    -------
    samples : ndarray [shape=(3, n)]
        Rows value, ω and θ, one array (handing an array back to Python costs some 0.3 µs). value:
        in flight sin((θ + π/2)/2) = √m·cd(v | m), elsewhere NaN: :meth:`.arcs.Arcs.evaluate`
        takes its asin with numpy, whose vectorised asin is some ten times quicker than one
        call at a time here, and :func:`finish` makes θ of it. ω (rad/s). θ (rad), but NaN in flight.
    """
    n = len(t)
    samples = np.empty((3, n))
    value, omega, theta = samples[0], samples[1], samples[2]
    # RUNS runs of samples side by side, split where arcs start (a sample computed afresh either way, so
    # each sample is computed as in one run, to the bit).
    first = _split(table, t) if spacing > 0.0 else np.array([0, n])
    runs = len(first) - 1
    # each run's arc, the flight it carries (or −1), the samples it may still carry, the most it may carry
    # from one computed afresh; then the carried sn, cn, dn, those of the spacing, √m, 2√(m(1 − m)C), m,
    # and when the next arc starts (s)
    ints = np.zeros((runs, 4), dtype=np.int64)
    ints[:, 1] = -1
    floats = np.zeros((runs, 10))
    # each run's AGM of its last flight's m, kept for the samples it computes afresh in that flight
    agms = np.empty((runs, elliptic.AGM_SIZE))
    agms[:, 0] = math.nan
    longest = 0
    for r in range(runs):
        longest = max(longest, first[r + 1] - first[r])
    for i in range(longest):
        for r in range(runs):
            k = first[r] + i
            if k >= first[r + 1]:
                continue
            if ints[r, 2] > 0:  # carried in the flight it carries (the commonest sample: no arc looked up)
                ints[r, 2] -= 1
                sn, cn, dn = elliptic.shift(floats[r, 0], floats[r, 1], floats[r, 2], floats[r, 3], floats[r, 4],
                                            floats[r, 5], floats[r, 8])
                floats[r, 0], floats[r, 1], floats[r, 2] = sn, cn, dn
                inverse = 1.0 / dn
                value[k], omega[k], theta[k] = floats[r, 6] * cn * inverse, -floats[r, 7] * sn * inverse, math.nan
                continue
            j, current = ints[r, 0], ints[r, 1]
            if spacing > 0.0:
                while j + 1 < len(table) and table[j + 1, 0] <= t[k]:
                    j += 1
            else:
                j = max(np.searchsorted(table[:, 0], t[k], side="right") - 1, 0)
            ints[r, 0] = j
            kind = table[j, 1]
            if t[k] == table[j, 0]:
                # The state the arc starts from, as given (the recipe's θ₀, ω₀) or as the solver made it (the
                # launch after an impact): a flight's closed form would return it to round-off only.
                value[k], omega[k], theta[k] = math.nan, table[j, 6], table[j, 5]
            elif kind == ELLIPTIC:
                apex, c, m = table[j, 2], table[j, 3], table[j, 4]
                if j != current and spacing > 0.0:  # a flight's first sample, and the spacing's sn, cn, dn
                    step = math.sqrt(c) * spacing
                    sn, cn, dn, floats[r, 3], floats[r, 4], floats[r, 5] = elliptic.jacobi_pair(
                        math.sqrt(c) * (t[k] - apex), step, m, agms[r])
                    floats[r, 6], floats[r, 7] = math.sqrt(m), 2.0 * math.sqrt(m * (1.0 - m) * c)
                    ints[r, 3] = int(min(REANCHOR, REACH / step, STEADY * math.sqrt(1.0 - m)))
                    ints[r, 1] = j
                    floats[r, 8] = m
                    floats[r, 9] = table[j + 1, 0] if j + 1 < len(table) else math.inf
                else:  # a sample computed afresh in the flight it carries, or any sample without a spacing
                    sn, cn, dn = elliptic.jacobi_with(math.sqrt(c) * (t[k] - apex), m, agms[r])
                    if j != current:
                        floats[r, 6], floats[r, 7] = math.sqrt(m), 2.0 * math.sqrt(m * (1.0 - m) * c)
                if spacing > 0.0:
                    ints[r, 2] = _carried(t, k, floats[r, 9], spacing, ints[r, 3])
                floats[r, 0], floats[r, 1], floats[r, 2] = sn, cn, dn
                inverse = 1.0 / dn
                value[k], omega[k], theta[k] = floats[r, 6] * cn * inverse, -floats[r, 7] * sn * inverse, math.nan
            elif kind == TAYLOR:
                ints[r, 1] = -1
                row = int(table[j, 2])
                theta[k], omega[k] = polynomial(steps[row, 1:], t[k] - steps[row, 0])
                value[k] = math.nan
            else:
                ints[r, 1] = -1
                value[k], omega[k], theta[k] = math.nan, 0.0, theta_max
    return samples


@jit(inline="always")
def _carried(t, k, end, spacing, most):
    """How many samples after ``t[k]`` (one computed afresh) :func:`evaluate` carries from it: those before ``end``
    (s, where the next arc starts), at most ``most`` of them, and never the last of ``t`` (its spacing may differ)."""
    limit = min(k + 1 + most, len(t) - 1)
    q = min(k + 1 + int(min((end - t[k]) / spacing, float(most))), limit)  # (then exact: the times' round-off)
    while q > k + 1 and t[q - 1] >= end:
        q -= 1
    while q < limit and t[q] < end:
        q += 1
    return max(q - (k + 1), 0)


# the kinds of segment :func:`evaluate_runs` evaluates (a curve's other segments: in Python, by their paths)
PATH, ARCS, HOLD, CUBIC = range(4)


@jit
def evaluate_runs(t, first, segment, kinds, rows, places, tables, steps, phases, spacing):
    """A curve's segments at the increasing times ``t`` (s), run by run, in one call.

    Run r is ``t[first[r]:first[r + 1]]``, held by segment ``segment[r]``. Segment s is of kind ``kinds[s]``:
    ARCS, a stroke's arcs (rows ``rows[s, 0]:rows[s, 1]`` of ``tables``, its Taylor steps ``rows[s, 2]:rows[s, 3]``
    of ``steps``), evaluated as :func:`evaluate` evaluates them, with ``spacing`` when the run lies within the
    segment's span; HOLD, still at θ = ``places[s, 3]``; CUBIC, a jerk-limited move (its phases, rows
    ``rows[s, 0]:rows[s, 1]`` of ``phases``: start, jerk, acceleration, speed, position); PATH, left as it is
    (the caller evaluates it). ``places[s, :3]`` are the segment's start, end and offset (s): each run's local
    times are t − offset, clamped to the span first when the run is not within it, as a curve clamps them.
    Each run is computed by the same operations as its path alone, so the same values to the bit.

    Returns
    -------
    value, omega, theta : ndarray [shape=(n,)]
        As :func:`evaluate`'s on the arcs' runs (:func:`finish_runs` makes θ there); elsewhere θ and ω, and
        value NaN.
    """
    n = len(t)
    value, omega, theta = np.full(n, math.nan), np.empty(n), np.empty(n)
    for r in range(len(first) - 1):
        a, b, s = first[r], first[r + 1], segment[r]
        kind = kinds[s]
        if kind == PATH:
            continue
        start, end, offset = places[s, 0], places[s, 1], places[s, 2]
        within = start <= t[a] and t[b - 1] <= end
        local = np.empty(b - a)
        for k in range(b - a):
            local[k] = t[a + k] - offset if within else min(max(t[a + k], start), end) - offset
        if kind == ARCS:
            samples = evaluate(tables[rows[s, 0]:rows[s, 1]], steps[rows[s, 2]:rows[s, 3]], places[s, 3], local,
                               spacing if within else 0.0)
            value[a:b], omega[a:b], theta[a:b] = samples[0], samples[1], samples[2]
        elif kind == HOLD:
            omega[a:b], theta[a:b] = 0.0, places[s, 3]
        else:
            _cubic(phases[rows[s, 0]:rows[s, 1]], local, omega[a:b], theta[a:b])
    return value, omega, theta


@jit
def runs_of(starts, t):
    """The runs of the increasing times ``t`` (s) that one segment holds, a segment starting at each of ``starts`` (s,
    increasing): the first time of each run and its end [shape=(r + 1,)], and each run's segment [shape=(r,)], the
    last that starts at or before its times (the first for times before it), as a curve finds it."""
    first, segment = np.empty(len(t) + 1, dtype=np.int64), np.empty(len(t), dtype=np.int64)
    runs, j = 0, 0
    for k in range(len(t)):
        while j + 1 < len(starts) and starts[j + 1] <= t[k]:
            j += 1
        if k == 0 or j != segment[runs - 1]:
            first[runs], segment[runs] = k, j
            runs += 1
    first[runs] = len(t)
    return first[:runs + 1], segment[:runs]


@jit(inline="always")
def _cubic(phases, local, omega, theta):
    """θ and ω of a jerk-limited move at ``local`` times: :class:`drumstroke.curve.Cubic`'s arithmetic."""
    last = len(phases) - 1
    for k in range(len(local)):
        x = local[k]
        j = 0
        while j < last and phases[j + 1, 0] <= x:
            j += 1
        dt = max(x - phases[j, 0], 0.0)
        jerk, acceleration, speed, position = phases[j, 1], phases[j, 2], phases[j, 3], phases[j, 4]
        theta[k] = position + dt * (speed + dt * (acceleration / 2.0 + dt * jerk / 6.0))
        omega[k] = speed + dt * (acceleration + dt * jerk / 2.0)


@jit
def finish_runs(theta, arcsin, first, segment, kinds, places):
    """:func:`finish` on the runs of :func:`evaluate_runs` that arcs hold (the head at ``places[s, 3]``)."""
    for r in range(len(first) - 1):
        s = segment[r]
        if kinds[s] == ARCS:
            finish(theta[first[r]:first[r + 1]], arcsin[first[r]:first[r + 1]], places[s, 3])


@jit
def sample_times(first, stop, rate, start, t_end):
    """The sample times ``start`` + k/``rate`` (s) for k = ``first``, …, ``stop`` − 1, none past ``t_end``.

    numpy's ``np.arange(first, stop, dtype=float) / rate (+ start)``, clipped to t_end, in one pass: the same
    operations in the same order, so the same times to the bit.
    """
    t = np.empty(stop - first)
    for k in range(stop - first):
        value = float(first + k) / rate
        if start != 0.0:
            value += start
        t[k] = min(value, t_end)
    return t


@jit
def _split(table, t):
    """Where :func:`evaluate`'s runs start in ``t`` (increasing), and its end [shape=(runs + 1,)].

    Each run but the first starts at the first sample of the arc that holds a RUNS-th of the flights'
    time within ``t`` (samples in flight are the costly ones): a sample never carried from the one before it.
    """
    n = len(t)
    first = np.empty(RUNS + 1, dtype=np.int64)
    first[0], runs = 0, 1
    if n >= 2:
        flying = np.zeros(len(table) + 1)  # flight time (s) within [t[0], t[-1]] before each arc
        for j in range(len(table)):
            low = max(table[j, 0], t[0])
            high = t[n - 1] if j + 1 == len(table) else min(table[j + 1, 0], t[n - 1])
            flying[j + 1] = flying[j] + (max(high - low, 0.0) if table[j, 1] == ELLIPTIC else 0.0)
        for q in range(1, RUNS):
            j = np.searchsorted(flying, q / RUNS * flying[-1]) - 1
            if j >= 1:
                k = np.searchsorted(t, table[j, 0])
                if first[runs - 1] < k < n:
                    first[runs] = k
                    runs += 1
    first[runs] = n
    return first[:runs + 1]


@jit
def finish(theta, arcsin, theta_max):
    """θ (rad) into ``theta`` where it is NaN (in flight), from the asin of :func:`evaluate`'s value there.

    θ = 2·asin(value) − π/2 in flight; then θ never below the head, where round-off can put a
    flight a few ulps under it.
    """
    for k in range(len(theta)):
        value = theta[k]
        if math.isnan(value):
            value = 2.0 * arcsin[k] - 0.5 * math.pi
        theta[k] = max(value, theta_max)
