"""The hybrid solver: flights, impacts, the Zeno tail, rest and lift-off.

The time line is cut at every edge of a(t) and g(t), so on each piece the
forcing C(t) = (k·g + k′·a)/D is linear, C₀ + C₁·(t − t₀); no step ever
crosses an edge. On a piece:

* **Constant forcing pressing down** (C₁ = 0, C₀ > 0) with the stick below the
  vertical: every flight is an elliptic arc in closed form (:mod:`.elliptic`).
  After an impact at speed w the launch speeds are c·w, c²·w, …, so a whole
  run of bounces is computed at once: their flight times, their impact times
  (a cumulative sum), their speeds.
* **Anything else** (a ramp, forcing that lifts, a flight near the vertical):
  Taylor steps of order 24 (:mod:`.taylor`), with the head crossing located on
  each step's polynomial to full precision.

**Impacts** reverse and scale the speed, ω⁺ = −c·ω⁻ (paper Eq. 6).

**Zeno.** With c < 1 and the forcing pressing down, the bounces accumulate:
infinitely many impacts before a finite time. Once a launch speed L is below
:data:`.rules.ZENO_SPEED` and the bounce rises less than :data:`.rules.ZENO_HEIGHT`
(L²/(2A) with A = C·cos θ_max), flights are so short that the forcing is
constant over the rest of them and each lasts 2L/A (the error of that
parabola is O(L²) relative, below 1e-12). The tail of the geometric series
then sums to 2L/(A·(1 − c)): the stick comes to rest at that accumulation
time. Impacts in that tail (tip speeds under a micrometre per second) are
never listed, wherever t_end falls. A
tail that runs into the next piece has its remaining time rescaled by the new
forcing (it lasts microseconds), or ends at once if the stick lifts off. With
c = 1 such a micro-bounce never accumulates, but never rises above
``ZENO_HEIGHT`` either: the stick counts as resting from that launch.

**Rest.** The stick stays on the head while C ≥ 0 and lifts off the moment C
turns negative, which only un-natural profiles do (a < 0 or g < 0).

**Limits.** The model covers θ in [θ_max, π/2): a stick driven past the
vertical raises :class:`~drumstroke.errors.SimulationError`, and so does a
stroke with more than :data:`MAX_IMPACTS` impacts.
"""

import math
import time
from dataclasses import dataclass

import numpy as np

from ..errors import SimulationError
from ..profiles import merge_edges
from . import elliptic
from .arcs import ArcBuilder, Arcs
from .rules import NEARLY_VERTICAL, zeno_floor

MAX_IMPACTS = 5_000_000
"""Most impacts one stroke may have."""

_CHUNK = 4096
_MAX_STEP = 1.0


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


def solve(coefficients, force, gravity, *, theta0, omega0, cor, t_end, method="auto", progress=None):
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

    Returns
    -------
    Solution
    """
    edges, c0, c1 = _forcing(coefficients, force, gravity, t_end)
    run = _Run(coefficients.theta_max, theta0, omega0, cor, closed_forms=(method == "auto"))
    last_report = time.monotonic()
    for i in range(len(c0)):
        run.advance(float(edges[i]), float(edges[i + 1]), float(c0[i]), float(c1[i]))
        if progress is not None and time.monotonic() - last_report > 0.1:
            progress(edges[i + 1] / t_end)
            last_report = time.monotonic()
    return run.solution(t_end)


def _forcing(coefficients, force, gravity, t_end):
    """Edges of the pieces of C(t), with C and its slope at the start of each."""
    a, g = force.pieces(t_end), gravity.pieces(t_end)
    edges = merge_edges(np.concatenate((a.edges, g.edges)), t_end)
    (a0, a1), (g0, g1) = a.at(edges[:-1], t_end), g.at(edges[:-1], t_end)
    return edges, coefficients.torque_rate(g0, a0), coefficients.torque_rate(g1, a1)


class _Run:
    """The solver's state as it walks through the pieces."""

    def __init__(self, theta_max, theta0, omega0, cor, *, closed_forms):
        self.theta_max = theta_max
        self.sin_head = math.sin(theta_max)
        self.cos_head = math.cos(theta_max)
        self.cor = cor
        self.closed_forms = closed_forms
        self.t, self.theta, self.omega = 0.0, theta0, omega0
        self.resting = False
        self.lifting = False
        self.tail_c = math.nan
        self.arcs = ArcBuilder(theta_max)
        self.impact_t, self.impact_omega = [], []
        self.n_impacts = 0
        self.rests = []

    def advance(self, ts, te, c0, c1):
        """Carry the stick from ``ts`` to ``te`` where C(t) = c0 + c1·(t − ts)."""
        self.t = ts
        if self.resting and self.rests[-1][0] > ts:
            self._retime_tail(c0)
        while self.t < te:
            if self.resting:
                lift = _lift_off(ts, te, c0, c1, self.t)
                if lift is None:
                    return
                self._lift(lift)
            elif not (self.closed_forms and c1 == 0.0 and c0 > 0.0 and self._closed_form(te, c0)):
                self._taylor_piece(ts, te, c0, c1)

    # -- closed forms ------------------------------------------------------

    def _closed_form(self, te, c):
        """Fly under constant C > 0 until the head, then bounce on until ``te`` or rest.

        Returns False, having done nothing, if the flight would come near the vertical.
        """
        t, theta, omega = self.t, self.theta, self.omega
        self.lifting = False
        if theta == self.theta_max and omega <= 0.0:
            if omega == 0.0:
                self._rest(t, t)
            else:
                self._record(t, omega)
                self._bounces(t, -omega, c, te)
            return True
        if theta == self.theta_max and omega < zeno_floor(c * self.cos_head):
            self._settle(t, omega, c)  # a launch too small to see: the Zeno tail from the start
            return True
        sin_theta = math.sin(theta)
        m = elliptic.parameter(sin_theta, omega, c)
        if m >= 1.0 - NEARLY_VERTICAL:
            return False
        since_apex = float(elliptic.time_from_apex(sin_theta, omega, c, m))
        apex = t + since_apex if omega > 0.0 else t - since_apex
        speed = math.sqrt(omega * omega + 2.0 * c * max(sin_theta - self.sin_head, 0.0))
        hit = apex + float(elliptic.time_from_apex(self.sin_head, speed, c, m))
        self.arcs.elliptic(t, apex, c, m)
        if hit > te:
            self._fly_to(te, apex, c, m)
        else:
            self._record(hit, -speed)
            self._bounces(hit, speed, c, te)
        return True

    def _bounces(self, t, speed, c, te):
        """The run of bounces after an impact at ``t`` with speed ``speed`` under constant C."""
        cor = self.cor
        launch = cor * speed
        floor = zeno_floor(c * self.cos_head)
        n = 16  # flights per batch, doubling: short pieces hold few, long ones many
        while True:
            if launch == 0.0:
                self._rest(t, t)
                return
            if launch < floor:
                self._settle(t, launch, c)
                return
            if elliptic.parameter(self.sin_head, launch, c) >= 1.0 - NEARLY_VERTICAL:
                # Launched toward the vertical: the Taylor path takes it (and reports it).
                self.t, self.theta, self.omega = t, self.theta_max, launch
                return
            if cor < 1.0:  # no more than it takes to fall below the floor
                n = min(n, max(1, math.ceil(math.log(floor / launch) / math.log(cor)) + 1))
            # (floor > 0 here: launch < floor would have settled otherwise)
            launches = launch * cor ** np.arange(n)
            flights = elliptic.flight_time(launches, c, self.sin_head)
            ends = t + np.cumsum(flights)
            starts = np.concatenate(([t], ends[:-1]))
            done = int(np.searchsorted(ends, te, side="right"))
            below = np.flatnonzero(launches < floor)
            settles = len(below) > 0 and below[0] <= done
            if settles:
                done = below[0]
            m = elliptic.parameter(self.sin_head, launches, c)
            self.arcs.elliptic(starts[:done], starts[:done] + flights[:done] / 2, c, m[:done])
            self._record(ends[:done], -launches[:done])
            if settles:
                self._settle(starts[done], launches[done], c)
                return
            if done < n:
                start, apex = starts[done], starts[done] + flights[done] / 2
                self.arcs.elliptic(start, apex, c, m[done])
                if start == te:
                    self.t, self.theta, self.omega = te, self.theta_max, launches[done]
                else:
                    self._fly_to(te, apex, c, m[done])
                return
            t, launch = ends[-1], launches[-1] * cor
            n = min(2 * n, _CHUNK)

    def _fly_to(self, te, apex, c, m):
        theta, omega = elliptic.state(te - apex, c, m)
        self.t, self.theta, self.omega = te, max(float(theta), self.theta_max), float(omega)

    # -- Taylor steps ------------------------------------------------------

    def _taylor_piece(self, ts, te, c0, c1):
        from . import taylor  # compiled on first use: strokes in closed form never load numba

        outcome, t, theta, omega, lifting, extra, steps, impact_t, impact_omega = taylor.run_piece(
            self.t, self.theta, self.omega, self.lifting, ts, te, c0, c1, self.theta_max, self.cor,
            _MAX_STEP, MAX_IMPACTS - self.n_impacts,
        )
        self.arcs.taylor(steps)
        self._record(impact_t, impact_omega)
        self.t, self.theta, self.omega, self.lifting = t, theta, omega, lifting
        if outcome == taylor.VERTICAL:
            raise SimulationError(
                f"the stick reaches the vertical (theta = pi/2 rad) at t = {extra:.6g} s; the model covers "
                f"theta in [theta_max, pi/2): lower omega0 or the upward forcing (negative force or gravity)"
            )
        if outcome == taylor.REST:
            self._rest(t, t)
        elif outcome == taylor.SETTLE:
            self._settle(t, omega, extra)

    # -- impacts, rest, lift-off ------------------------------------------

    def _record(self, t, omega):
        t, omega = np.atleast_1d(t), np.atleast_1d(omega)
        if len(t) == 0:
            return
        self.impact_t.append(t)
        self.impact_omega.append(omega)
        self.n_impacts += len(t)
        if self.n_impacts > MAX_IMPACTS:
            raise SimulationError(
                f"the stroke has more than {MAX_IMPACTS} impacts by t = {float(t[-1]):.6g} s; "
                f"shorten t_end or lower cor (now {self.cor:g})"
            )

    def _settle(self, t, launch, c):
        """Sum the Zeno tail of a bounce launched at ``t`` with speed ``launch`` < ZENO_SPEED under C = ``c``.

        The rest starts at the accumulation time, which may lie beyond the
        current piece: :meth:`_retime_tail` then carries it into the next one.
        """
        self.tail_c = c
        # With c = 1 the micro-bounce never ends but never rises above ZENO_HEIGHT: rest from now.
        tail = 2.0 * launch / (c * self.cos_head * (1.0 - self.cor)) if self.cor < 1.0 else 0.0
        self._rest(t, t + tail)

    def _retime_tail(self, c):
        """A pending Zeno tail enters a piece whose forcing starts at ``c``: its remaining time scales as 1/C."""
        if c > 0.0:
            start = self.rests[-1][0]
            self.rests[-1][0] = self.t + (start - self.t) * self.tail_c / c
            self.tail_c = c

    def _rest(self, arc_start, rest_start):
        """The stick rests on the head from ``rest_start``; its trajectory reads θ_max from ``arc_start``.

        Between the two lies a summed Zeno tail, whose bounces are below 1e-12 rad.
        """
        self.arcs.rest(arc_start)
        self.rests.append([rest_start, math.nan])
        self.t, self.theta, self.omega = arc_start, self.theta_max, 0.0
        self.resting = True

    def _lift(self, t):
        if self.rests[-1][0] >= t:
            self.rests.pop()  # lifted during the Zeno tail: that rest never began
        else:
            self.rests[-1][1] = t
        self.t, self.theta, self.omega = t, self.theta_max, 0.0
        self.resting = False
        self.lifting = True

    def solution(self, t_end):
        if self.resting and self.rests[-1][0] > t_end:
            self.rests.pop()  # t_end falls inside the Zeno tail: not at rest yet
        elif self.resting:
            self.rests[-1][1] = t_end
        impact_t = np.concatenate(self.impact_t) if self.impact_t else np.empty(0)
        impact_omega = np.concatenate(self.impact_omega) if self.impact_omega else np.empty(0)
        keep = impact_t <= t_end
        return Solution(
            arcs=self.arcs.build(),
            impact_t=impact_t[keep],
            impact_omega=impact_omega[keep],
            rests=np.array(self.rests, dtype=float).reshape(-1, 2),
        )


def _lift_off(ts, te, c0, c1, t):
    """When, in [t, te), a resting stick lifts off under C = c0 + c1·(t − ts); None if it stays."""
    c_now = c0 + c1 * (t - ts)
    if c_now < 0.0 or (c_now == 0.0 and c1 < 0.0):
        return t
    if c1 < 0.0:
        zero = ts - c0 / c1
        if zero < te:
            return max(zero, t)
    return None
