"""The solved trajectory as a chain of arcs, each exact on its time span.

An arc starts at ``start[i]`` and holds until the next one starts. Kinds:

REST      the stick lies on the head: θ = θ_max, ω = 0.
ELLIPTIC  a flight under constant forcing, in closed form (apex time, C, m).
TAYLOR    a step of the Taylor integrator: its start time and polynomial.

Evaluating an arc at any time is exact to round-off, so a trajectory sampled at
any rate is exact at its sample times, never interpolated between solver steps.
At its start time an arc gives the state it was started from, exactly: the
recipe's θ₀ and ω₀ at t = 0, θ_max and the launch speed after an impact.
"""

import functools
from dataclasses import dataclass

import numpy as np

from .constants import ARC_COLUMNS, ELLIPTIC, REST, TAYLOR, TAYLOR_ORDER

__all__ = ["ARC_COLUMNS", "ELLIPTIC", "REST", "TAYLOR", "TAYLOR_ORDER", "Arcs"]


@dataclass(frozen=True)
class Arcs:
    """A trajectory θ(t), ω(t) as a chain of exact arcs.

    Attributes
    ----------
    table : ndarray [shape=(n, ARC_COLUMNS)]
        One row per arc: its start time (s), non-decreasing from 0; its kind;
        then for ELLIPTIC the apex time (s), C (s⁻²) and m; for TAYLOR the row
        of its polynomial in ``taylor``; last the state it starts from, θ (rad)
        and ω (rad/s).
    taylor : ndarray [shape=(n_taylor, TAYLOR_ORDER + 2)]
        Step start time (s), then the coefficients of θ.
    theta_max : float
        The head (rad).
    """

    table: np.ndarray
    taylor: np.ndarray
    theta_max: float

    @classmethod
    def _of(cls, table, taylor, theta_max):
        """The Arcs of these fields, made without the frozen dataclass's ``__init__`` (which sets each field by
        ``object.__setattr__``); the same object."""
        arcs = object.__new__(cls)
        fields = arcs.__dict__
        fields["table"], fields["taylor"], fields["theta_max"] = table, taylor, theta_max
        return arcs

    @property
    def start(self):
        """Start time of each arc (s) [shape=(n,)]."""
        return self.table[:, 0]

    @property
    def kind(self):
        """REST, ELLIPTIC or TAYLOR for each arc [shape=(n,)]."""
        return self.table[:, 1].astype(np.int8)

    def evaluate(self, t, *, spacing=0.0):
        """θ (rad) and ω (rad/s) at times ``t`` (s), each of t's shape.

        At an impact time the state just after the impact is returned.
        θ is never below the head. ``spacing`` > 0 (s) promises increasing
        times that far apart (but perhaps the last), which is faster.
        """
        kernel = _kernel()
        t = np.asarray(t, dtype=float)
        value, omega, theta = kernel.evaluate(self.table, self.taylor, self.theta_max, t.ravel(), float(spacing))
        # In flight the kernel leaves θ's last step, θ = 2·asin(value) − π/2, to numpy's vectorised asin
        # (value is NaN elsewhere, whose asin is NaN without a warning).
        kernel.finish(theta, np.arcsin(value, out=value), self.theta_max)
        if t.ndim == 1:  # already of t's shape
            return theta, omega
        return theta.reshape(t.shape), omega.reshape(t.shape)


@functools.cache  # (an import statement costs some 0.5 µs a call, a cached call a tenth of it)
def _kernel():
    """The compiled evaluation (:mod:`.kernel`), imported on first use: ``import drumstroke`` stays light."""
    from . import kernel

    return kernel
