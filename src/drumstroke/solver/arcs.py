"""The solved trajectory as a chain of arcs, each exact on its time span.

An arc starts at ``start[i]`` and holds until the next one starts. Kinds:

REST      the stick lies on the head: θ = θ_max, ω = 0.
ELLIPTIC  a flight under constant forcing, in closed form (apex time, C, m).
TAYLOR    a step of the Taylor integrator: its start time and polynomial.

Evaluating an arc at any time is exact to round-off, so a trajectory sampled at
any rate is exact at its sample times, never interpolated between solver steps.
"""

from dataclasses import dataclass

import numpy as np

from . import elliptic

REST, ELLIPTIC, TAYLOR = 0, 1, 2

TAYLOR_ORDER = 24
"""Degree of the Taylor arcs' polynomials (the integrator's order)."""


@dataclass(frozen=True)
class Arcs:
    """A trajectory θ(t), ω(t) as a chain of exact arcs.

    Attributes
    ----------
    start : ndarray [shape=(n,)]
        Start time of each arc (s), non-decreasing; ``start[0] = 0``.
    kind : ndarray [shape=(n,)]
        REST, ELLIPTIC or TAYLOR.
    row : ndarray [shape=(n,)]
        Each arc's row in its kind's table.
    elliptic : ndarray [shape=(n_elliptic, 3)]
        Apex time (s), C (s⁻²), m.
    taylor : ndarray [shape=(n_taylor, TAYLOR_ORDER + 2)]
        Step start time (s), then the coefficients of θ.
    theta_max : float
        The head (rad).
    """

    start: np.ndarray
    kind: np.ndarray
    row: np.ndarray
    elliptic: np.ndarray
    taylor: np.ndarray
    theta_max: float

    def evaluate(self, t):
        """θ (rad) and ω (rad/s) at times ``t`` (s) [shape=(n,)].

        At an impact time the state just after the impact is returned.
        θ is never below the head.
        """
        t = np.asarray(t, dtype=float)
        index = np.searchsorted(self.start, t, side="right") - 1
        index = np.clip(index, 0, len(self.start) - 1)
        kind = self.kind[index]
        row = self.row[index]
        theta = np.full(t.shape, self.theta_max)
        omega = np.zeros(t.shape)

        flying = kind == ELLIPTIC
        if np.any(flying):
            apex, c, m = self.elliptic[row[flying]].T
            theta[flying], omega[flying] = elliptic.state(t[flying] - apex, c, m)

        stepping = kind == TAYLOR
        if np.any(stepping):
            table = self.taylor[row[stepping]]
            theta[stepping], omega[stepping] = _polynomials(table[:, 1:].T, t[stepping] - table[:, 0])

        # Round-off can put a flight a few ulps under the head; the stick is never there.
        np.maximum(theta, self.theta_max, out=theta)
        return theta, omega


class ArcBuilder:
    """Collects arcs in time order while the solver runs."""

    def __init__(self, theta_max):
        self.theta_max = theta_max
        self._start, self._kind, self._row = [], [], []
        self._elliptic, self._taylor = [], []
        self._n_elliptic = 0
        self._n_taylor = 0

    def rest(self, t):
        self._start.append(np.atleast_1d(float(t)))
        self._kind.append(np.array([REST], dtype=np.int8))
        self._row.append(np.zeros(1, dtype=np.int64))

    def elliptic(self, start, apex, c, m):
        """Flights starting at ``start`` (s) [shape=(n,)] with their apex times, C and m."""
        start = np.atleast_1d(np.asarray(start, dtype=float))
        n = len(start)
        table = np.empty((n, 3))
        table[:, 0], table[:, 1], table[:, 2] = apex, c, m
        self._start.append(start)
        self._kind.append(np.full(n, ELLIPTIC, dtype=np.int8))
        self._row.append(np.arange(self._n_elliptic, self._n_elliptic + n))
        self._elliptic.append(table)
        self._n_elliptic += n

    def taylor(self, steps):
        """Taylor steps [shape=(n, TAYLOR_ORDER + 2)]: each row a start time (s) and the coefficients of θ."""
        n = len(steps)
        if n == 0:
            return
        self._start.append(steps[:, 0].copy())
        self._kind.append(np.full(n, TAYLOR, dtype=np.int8))
        self._row.append(np.arange(self._n_taylor, self._n_taylor + n))
        self._taylor.append(steps)
        self._n_taylor += n

    def build(self):
        empty_taylor = np.empty((0, TAYLOR_ORDER + 2))
        return Arcs(
            start=np.concatenate(self._start),
            kind=np.concatenate(self._kind),
            row=np.concatenate(self._row),
            elliptic=np.concatenate(self._elliptic) if self._elliptic else np.empty((0, 3)),
            taylor=np.concatenate(self._taylor) if self._taylor else empty_taylor,
            theta_max=self.theta_max,
        )


def _polynomials(table, tau):
    """Many polynomials at once: ``table`` [shape=(TAYLOR_ORDER + 1, n)], ``tau`` [shape=(n,)] → values, slopes."""
    p = np.zeros_like(tau) + table[-1]
    d = np.zeros_like(p)
    for k in range(len(table) - 2, -1, -1):
        d = d * tau + p
        p = p * tau + table[k]
    return p, d
