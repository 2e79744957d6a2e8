"""The hybrid solver: flights, impacts, the Zeno tail, rest and lift-off.

The time line is cut at every edge of a(t) and g(t), so on each piece the
forcing C(t) = (k·g + k′·a)/D is linear, C₀ + C₁·(t − t₀); no step ever
crosses an edge. On a piece:

* **Constant forcing pressing down** (C₁ = 0, C₀ > 0) with the stick below the
  vertical: every flight is an elliptic arc in closed form (:mod:`.elliptic`).
  After an impact at speed w the launch speeds are c·w, c²·w, …: one
  closed-form flight after another, each costing one R_F.
* **Anything else** (a ramp, forcing that lifts, a flight near the vertical):
  Taylor steps of order 24 (:mod:`.taylor`), with the head crossing located on
  each step's polynomial to full precision.

**Impacts** reverse and scale the speed, ω⁺ = −c·ω⁻ (paper Eq. 6).

**Zeno.** With c < 1 and the forcing pressing down, the bounces accumulate:
infinitely many impacts before a finite time. Once a launch speed L is below
:data:`.constants.ZENO_SPEED` and the bounce rises less than :data:`.constants.ZENO_HEIGHT`
(L²/(2A) with A = C·cos θ_max), flights are so short that the forcing is
constant over the rest of them and each lasts 2L/A (the error of that
parabola is O(L²) relative, below 1e-12). The tail of the geometric series
then sums to 2L/(A·(1 − c)): the stick comes to rest at that accumulation
time. Impacts in that tail (tip speeds under a micrometre per second) are
never listed, wherever t_end falls. A tail that runs into the next piece has its remaining time rescaled by the new
forcing (it lasts microseconds), or ends at once if the stick lifts off. With
c = 1 such a micro-bounce never accumulates, but never rises above
``ZENO_HEIGHT`` either: the stick counts as resting from that launch.

**Rest.** The stick stays on the head while C ≥ 0 and lifts off the moment C
turns negative, which only un-natural profiles do (a < 0 or g < 0).

**Compiled.** The loop over pieces and flights runs in :mod:`.kernel` (numba,
cached on disk); this module cuts the forcing into pieces and reads the result.

**Limits.** The model covers θ in [θ_max, π/2): a stick driven past the
vertical raises :class:`~drumstroke.errors.SimulationError`, and so does a
stroke with more than :data:`MAX_IMPACTS` impacts.
"""

import functools
import time
from dataclasses import dataclass

import numpy as np

from ..errors import SimulationError
from ..profiles import MAX_PIECES, Constant, PiecewiseLinear, Pulses, merge_edges, merge_tolerance
from .arcs import Arcs
from .constants import TAYLOR_ORDER

MAX_IMPACTS = 5_000_000
"""Most impacts one stroke may have."""

_MAX_STEP = 1.0
_PROGRESS_CHUNKS = 100  # calls of the kernel when progress is reported


@dataclass(frozen=True)
class Solution:
    """What the solver found.

    Attributes
    ----------
    arcs : Arcs
        The trajectory.
    impact_t : ndarray [shape=(n,)]
        Impact times (s), strictly increasing.
    impact_omega : ndarray [shape=(n,)]
        ω just before each impact (rad/s, ≤ 0).
    rests : ndarray [shape=(r, 2)]
        Start and end (s) of each time the stick lies on the head.
    """

    arcs: Arcs
    impact_t: np.ndarray
    impact_omega: np.ndarray
    rests: np.ndarray


def solve(coefficients, force, gravity, *, theta0, omega0, cor, t_end, method="auto", progress=None, tabled=True):
    """Simulate the stick from (θ₀, ω₀) at t = 0 to ``t_end``.

    Parameters
    ----------
    coefficients : drumstroke.model.Coefficients
    force, gravity : drumstroke.profiles.Profile
        a(t) and g(t) (m/s²).
    theta0 : float in [θ_max, π/2)
        rad.
    omega0 : float
        rad/s.
    cor : float in [0, 1]
        Coefficient of restitution.
    t_end : float > 0
        s.
    method : {"auto", "taylor"}
        "taylor" integrates every flight numerically (a cross-check of the
        closed forms); "auto" uses the closed forms wherever they apply.
    progress : callable or None
        Called now and then with the fraction of ``t_end`` done.
    tabled : bool
        Flights from the head by the flight-time table (:mod:`.flight_table`); False evaluates
        R_F at every flight (the table's reference, for checks and benchmarks).

    Returns
    -------
    Solution
    """
    return Solution(*solved(coefficients, force, gravity, theta0=theta0, omega0=omega0, cor=cor, t_end=t_end,
                            method=method, progress=progress, tabled=tabled))


def solved(coefficients, force, gravity, theta0, omega0, cor, t_end, method="auto", progress=None, tabled=True):
    """:func:`solve`'s :class:`Solution` as the tuple of its fields (what :func:`drumstroke.simulate` reads; its
    arguments by position, some 0.1 µs quicker than by name)."""
    kernel, table = _compiled()
    theta_max = coefficients.theta_max
    closed_forms = method == "auto"
    if not (closed_forms and tabled):
        table = _NO_TABLE
    result = None if progress is not None or type(gravity) is not Constant else _whole(
        kernel, coefficients, theta_max, force, gravity.value, theta0, omega0, cor, t_end, closed_forms, table)
    if result is not None:
        outcome, _, rows, n_arcs, n_through_impacts, n_through_rests, n_steps = result
        if outcome != kernel.DONE:
            _checked(result, cor, kernel)
        steps = _NO_STEPS if n_steps == 0 else rows[n_through_rests:].reshape(-1)[:n_steps * _STEP].reshape(
            n_steps, _STEP)
        return (Arcs._of(rows[:n_arcs], steps, theta_max), rows[n_arcs:n_through_impacts, 0],
                rows[n_arcs:n_through_impacts, 1], rows[n_through_impacts:n_through_rests, :2])
    arcs, steps, impacts, rests = _pieces(kernel, coefficients, force, gravity, theta0, omega0, cor, t_end,
                                          closed_forms, table, progress)
    if len(impacts) and impacts[-1, 0] > t_end:
        impacts = impacts[impacts[:, 0] <= t_end]
    return Arcs(arcs, steps, theta_max), impacts[:, 0], impacts[:, 1], rests


_NO_TABLE = np.empty((0, 0))
_STEP = TAYLOR_ORDER + 2  # a Taylor step's numbers: its start time and polynomial
_NO_STEPS = np.empty((0, _STEP))  # (empty: shared by the strokes that take no Taylor step)


def _whole(kernel, coefficients, theta_max, force, gravity, theta0, omega0, cor, t_end, closed_forms, table):
    """The kernel's result for the commonest strokes in one call, their forcing's pieces made in compiled code (the
    same operations as the profiles' own), or None for another kind of a(t).

    A constant a(t); a piecewise-linear one (every designed stroke's) of fewer points than MAX_PIECES, and a pulse
    train of fewer pulses than half of it, so that their count of pieces is never refused (``Profile.pieces``).
    """
    kind = type(force)
    if kind is Constant:
        return kernel.run_constant(coefficients.torque_rate(gravity, force.value), t_end, theta0, omega0, theta_max,
                                   table, cor, closed_forms, _MAX_STEP, MAX_IMPACTS)
    if kind is not PiecewiseLinear and kind is not Pulses:
        return None
    count = len(force.points) if kind is PiecewiseLinear else force._break_count(t_end) // 2  # (pulses)
    if (count if kind is PiecewiseLinear else 2 * count + 1) >= MAX_PIECES:  # (pieces: at most points + 1)
        return None
    force.check_budget(t_end)
    # (tuples: handed to compiled code for a third of what making an array costs)
    rates = (coefficients.k, coefficients.k_thumb, coefficients.inertia_ratio, gravity)
    if kind is PiecewiseLinear:
        return kernel.run_linear(force._t, force._v, merge_tolerance(t_end), rates, t_end, theta0, omega0, theta_max,
                                 table, cor, closed_forms, _MAX_STEP, MAX_IMPACTS)
    train = (force.amplitude, force.period, force.phase, force.duty, force.base)
    return kernel.run_pulses(train, count, merge_tolerance(t_end), rates, t_end, theta0, omega0, theta_max, table,
                             cor, closed_forms, _MAX_STEP, MAX_IMPACTS)


def _pieces(kernel, coefficients, force, gravity, theta0, omega0, cor, t_end, closed_forms, table, progress):
    """The kernel's arrays over the forcing's pieces, in chunks when ``progress`` is reported."""
    edges, c0, c1 = _forcing(coefficients, force, gravity, t_end)
    state = kernel.initial_state(theta0, omega0)
    chunk = len(c0) if progress is None else max(1, -(-len(c0) // _PROGRESS_CHUNKS))
    parts = []
    last_report = time.monotonic() if progress is not None else 0.0
    for first in range(0, len(c0), chunk):
        last = min(first + chunk, len(c0))
        pieces = (edges, c0, c1) if chunk == len(c0) else (edges[first:last + 1], c0[first:last], c1[first:last])
        parts.append(_checked(kernel.run(
            *pieces, coefficients.theta_max, table, cor, closed_forms, _MAX_STEP, MAX_IMPACTS, last == len(c0), state,
        ), cor, kernel))
        if progress is not None and time.monotonic() - last_report > 0.1:
            progress(edges[last] / t_end)
            last_report = time.monotonic()
    return parts[0] if len(parts) == 1 else (np.concatenate(c) for c in zip(*parts))


@functools.cache
def _compiled():
    """The compiled solver and the flight-time table, made on first use (`import drumstroke` stays light)."""
    from . import flight_table, kernel

    return kernel, flight_table.table()


def _checked(result, cor, kernel):
    """The kernel's arrays (and counts), or the error it ran into."""
    outcome, extra = result[0], result[1]
    if outcome == kernel.DONE:
        return result[2:]
    if outcome == kernel.VERTICAL:
        raise SimulationError(
            f"the stick reaches the vertical (theta = pi/2 rad) at t = {extra:.6g} s; the model covers "
            f"theta in [theta_max, pi/2): lower omega0 or the upward forcing (negative force or gravity)"
        )
    if outcome == kernel.TOO_MANY:
        raise SimulationError(
            f"the stroke has more than {MAX_IMPACTS} impacts by t = {extra:.6g} s; shorten t_end or lower cor "
            f"(now {cor:g})"
        )
    return result[2:]


def _forcing(coefficients, force, gravity, t_end):
    """Edges of the pieces of C(t), with C and its slope at the start of each."""
    rate = coefficients.torque_rate
    if isinstance(gravity, Constant):  # the commonest strokes, made quick
        if isinstance(force, Constant):
            return np.array([0.0, t_end]), np.array([rate(gravity.value, force.value)]), np.zeros(1)
        a = force.pieces(t_end)
        return a.edges, rate(gravity.value, a.values), rate(0.0, a.slopes)
    a, g = force.pieces(t_end), gravity.pieces(t_end)
    edges = merge_edges(np.concatenate((a.edges[1:-1], g.edges[1:-1])), t_end)
    (a0, a1), (g0, g1) = a.at(edges[:-1], t_end), g.at(edges[:-1], t_end)
    return edges, rate(g0, a0), rate(g1, a1)
