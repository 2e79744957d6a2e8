"""A high-order Taylor-series integrator for θ̈ = −(C₀ + C₁·τ)·cos θ, compiled with numba.

Where the forcing is linear in time (every piece of every profile is), the
solution is analytic, and its Taylor coefficients follow from a recurrence
(automatic differentiation of sin and cos):

    n·sₙ = Σⱼ₌₁ⁿ j·xⱼ·cₙ₋ⱼ,    n·cₙ = −Σⱼ₌₁ⁿ j·xⱼ·sₙ₋ⱼ,
    (n + 1)(n + 2)·xₙ₊₂ = −(C₀·cₙ + C₁·cₙ₋₁),

with x the coefficients of θ and s, c those of sin θ and cos θ. A step of
order 24 with the step size chosen from the last coefficients (Jorba & Zou,
2005) has a truncation error near 1e-16, and its polynomial *is* the solution
on the step: evaluating it at a sample time is exact to round-off, not an
interpolation.

Events inside a step (the stick reaching the head, or the vertical) are found
on the polynomial: sign changes on a grid of the step, and local minima between
grid points, so a bounce shorter than a grid cell is not missed; then a
safeguarded Newton iteration to full precision.

:func:`run_piece` carries the stick through one piece of forcing, impacts
included, in compiled code; it returns to Python only for what needs a
decision there (rest, the Zeno tail, the vertical, the impact limit).
"""

import math

import numpy as np

from .._jit import jit
from . import constants
from .constants import TAYLOR_ORDER as ORDER

TOLERANCE = 1e-16
GRID = 32

zeno_floor = jit(constants.zeno_floor)

# run_piece's outcomes
DONE, REST, SETTLE, VERTICAL, TOO_MANY = 0, 1, 2, 3, 4


@jit
def coefficients(theta, omega, c0, c1):
    """Taylor coefficients x₀…x_ORDER of θ about a state (θ, ω) where C(τ) = c0 + c1·τ."""
    x = np.zeros(ORDER + 1)
    s = np.zeros(ORDER + 1)
    c = np.zeros(ORDER + 1)
    x[0], x[1] = theta, omega
    s[0], c[0] = math.sin(theta), math.cos(theta)
    x[2] = -c0 * c[0] / 2.0
    for n in range(1, ORDER - 1):
        sn = 0.0
        cn = 0.0
        for j in range(1, n + 1):
            jx = j * x[j]
            sn += jx * c[n - j]
            cn -= jx * s[n - j]
        s[n] = sn / n
        c[n] = cn / n
        x[n + 2] = -(c0 * c[n] + c1 * c[n - 1]) / ((n + 1) * (n + 2))
    return x


@jit
def step_size(x):
    """The largest step whose truncation error stays near TOLERANCE (s); inf for a polynomial.

    Uses the last four coefficients, since symmetric states (e.g. θ = 0, ω = 0)
    leave three of every four zero.
    """
    n = len(x) - 1
    h = math.inf
    for k in range(n - 3, n + 1):
        if x[k] != 0.0:
            h = min(h, (TOLERANCE / abs(x[k])) ** (1.0 / k))
    return h


@jit
def evaluate(x, tau):
    """The polynomial with coefficients ``x`` and its derivative at ``tau``."""
    p = x[len(x) - 1]
    d = 0.0
    for k in range(len(x) - 2, -1, -1):
        d = d * tau + p
        p = p * tau + x[k]
    return p, d


@jit
def first_crossing(x, level, h, downward):
    """The first τ in (0, h] where the polynomial crosses ``level``, or −1.

    ``downward=True`` looks for θ falling through ``level`` from above (the head),
    ``downward=False`` for θ rising through it (the vertical). A start exactly
    on the level, moving away from it, is not a crossing.
    """
    sign = 1.0 if downward else -1.0
    f = x * sign
    f[0] = sign * (x[0] - level)  # exact zero when the step starts on the level
    df = np.empty(len(f) - 1)
    for k in range(1, len(f)):
        df[k - 1] = k * f[k]
    a = 0.0
    fa, sa = evaluate(f, a)
    for j in range(1, GRID + 1):
        b = h * j / GRID
        fb, sb = evaluate(f, b)
        if fb < 0.0:
            if fa > 0.0:
                return _root(f, a, b)
            if fa < 0.0 or sa < 0.0:
                return a  # on (or past) the level and moving through it
            if sa == 0.0:
                # On the level at rest: leaving it if the polynomial rises first, so
                # find a point above it, halving toward the start.
                probe = b
                for _ in range(64):
                    probe *= 0.5
                    if evaluate(f, probe)[0] > 0.0:
                        return _root(f, probe, b)
                return a
            # On the level and leaving it: the return lies beyond the apex.
            apex = _root(df, a, b)
            if apex < 0.0:  # the slope's sign change was round-off
                return a
            if evaluate(f, apex)[0] > 0.0:
                return _root(f, apex, b)
            return min(2.0 * apex - a, b)  # a bounce smaller than round-off
        if fa > 0.0 and sa < 0.0 < sb:
            low = _root(df, a, b)
            if low >= 0.0 and evaluate(f, low)[0] < 0.0:
                return _root(f, a, low)
        a, fa, sa = b, fb, sb
    return -1.0


@jit
def _root(f, a, b):
    """The root of the polynomial f in [a, b] where f changes sign (safeguarded Newton), or −1."""
    fa = evaluate(f, a)[0]
    fb = evaluate(f, b)[0]
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if (fa > 0.0) == (fb > 0.0):
        return -1.0
    if fa > 0.0:
        a, b = b, a  # keep f(a) < 0 < f(b)
    t = 0.5 * (a + b)
    for _ in range(200):
        p, d = evaluate(f, t)
        if p == 0.0:
            return t
        if p < 0.0:
            a = t
        else:
            b = t
        lo, hi = min(a, b), max(a, b)
        guess = t - p / d if d != 0.0 else math.inf
        t_new = guess if lo < guess < hi else 0.5 * (a + b)
        if t_new == t or hi - lo <= 4.0 * 2.220446049250313e-16 * max(abs(a), abs(b)):
            return t_new
        t = t_new
    return t


@jit
def _presses(c_now, slope):
    return c_now > 0.0 or (c_now == 0.0 and slope >= 0.0)


@jit
def holds(c_now, slope, left):
    """Whether the head holds a stick lying on it at zero speed under C = ``c_now`` rising by ``slope`` (s⁻³).

    It does while C presses the stick down, and also while C pulls it up so briefly, before
    pressing again or before the ``left`` seconds of the piece are over, that the stick could
    not reach ZENO_SPEED: such a stick (C = −1e-96 s⁻² for 1e-99 s, say) would otherwise be
    lifted and land again at the same instant for ever.
    """
    if _presses(c_now, slope):
        return True
    return slope > 0.0 and -c_now * min(-c_now / slope, left) < constants.ZENO_SPEED


@jit(inline="always")
def grow(array, n):
    """``array``, or a copy twice as long, so that row ``n`` exists (a growable buffer)."""
    if n < len(array):
        return array
    bigger = np.empty((2 * len(array),) + array.shape[1:])
    bigger[: len(array)] = array
    return bigger


@jit
def run_piece(t, theta, omega, lifting, ts, te, c0, c1, theta_max, cor, max_step, impacts_left):
    """Carry the stick from ``t`` to ``te`` where C(t) = c0 + c1·(t − ts), with Taylor steps.

    Returns
    -------
    outcome : int
        DONE (reached ``te`` in flight), REST (lies on the head from ``t``),
        SETTLE (a launch below the Zeno floor of :mod:`.constants` under
        forcing C = ``extra``: sum the tail),
        VERTICAL (reaches π/2 at time ``extra``), TOO_MANY (impact limit).
    t, theta, omega : float
        The state where it stopped (after the impact, for SETTLE and REST).
    lifting : bool
        The stick left the head at zero speed and must not be pressed back by round-off.
    extra : float
        See ``outcome``.
    steps : ndarray [shape=(n_steps, ORDER + 2)]
        Each step's start time and coefficients.
    impact_t, impact_omega : ndarray
        Impacts found (s, rad/s before impact).
    """
    steps = np.empty((16, ORDER + 2))
    impact_t = np.empty(16)
    impact_omega = np.empty(16)
    n_steps = 0
    n_impacts = 0
    outcome = DONE
    extra = 0.0
    while t < te:
        c_now = c0 + c1 * (t - ts)
        if theta == theta_max and not lifting:
            if omega < 0.0:
                hit, w = 0.0, omega
            elif omega == 0.0 and holds(c_now, c1, te - t):
                outcome = REST
                break
            elif c_now > 0.0 and omega < zeno_floor(c_now * math.cos(theta_max)):
                outcome, extra = SETTLE, c_now  # a launch too small to see
                break
            else:
                hit, w = -1.0, 0.0
        else:
            hit, w = -1.0, 0.0
        if hit < 0.0:
            if lifting:
                c_now = min(c_now, 0.0)  # round-off must not press a lifting stick back down
                lifting = False
            x = coefficients(theta, omega, c_now, c1)
            h = min(step_size(x), te - t, max_step)
            hit = first_crossing(x, theta_max, h, True)
            top = first_crossing(x, 0.5 * math.pi, hit if hit >= 0.0 else h, False)
            if top >= 0.0:
                outcome, extra = VERTICAL, t + top
                break
            steps = grow(steps, n_steps)
            steps[n_steps, 0] = t
            steps[n_steps, 1:] = x
            n_steps += 1
            if hit < 0.0:
                theta, omega = evaluate(x, h)
                t = te if h == te - t else t + h
                theta = max(theta, theta_max)
                continue
            if t + hit == t and holds(c0 + c1 * (t - ts), c1, te - t):
                # bouncing back sooner than the clock at t can tell: no time would pass between impacts
                # (a launch of 1e-35 rad/s as C rises from 0), so the stick lies on the head from now
                theta, omega = theta_max, 0.0
                outcome = REST
                break
            w = min(evaluate(x, hit)[1], 0.0)
        t = t + hit
        if w == 0.0:  # touching down at zero speed is no impact
            theta, omega = theta_max, 0.0
            if holds(c0 + c1 * (t - ts), c1, te - t):
                outcome = REST
                break
            lifting = True
            continue
        # an impact at t with speed w
        impact_t = grow(impact_t, n_impacts)
        impact_omega = grow(impact_omega, n_impacts)
        impact_t[n_impacts] = t
        impact_omega[n_impacts] = w
        n_impacts += 1
        if n_impacts > impacts_left:
            outcome = TOO_MANY
            break
        launch = -cor * w
        theta, omega = theta_max, launch
        c_hit = c0 + c1 * (t - ts)
        if launch == 0.0 and holds(c_hit, c1, te - t):
            outcome = REST
            break
        if not _presses(c_hit, c1):
            lifting = launch == 0.0
        elif c_hit > 0.0 and launch < zeno_floor(c_hit * math.cos(theta_max)):
            outcome, extra = SETTLE, c_hit
            break
    steps, impact_t, impact_omega = steps[:n_steps], impact_t[:n_impacts], impact_omega[:n_impacts]
    return outcome, t, theta, omega, lifting, extra, steps, impact_t, impact_omega
