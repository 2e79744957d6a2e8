"""A high-order Taylor-series integrator for θ̈ = −(C₀ + C₁·τ)·cos θ.

Where the forcing is linear in time (every piece of every profile is), the
solution is analytic, and its Taylor coefficients follow from a recurrence
(automatic differentiation of sin and cos):

    n·sₙ = Σⱼ₌₁ⁿ j·xⱼ·cₙ₋ⱼ,    n·cₙ = −Σⱼ₌₁ⁿ j·xⱼ·sₙ₋ⱼ,
    (n + 1)(n + 2)·xₙ₊₂ = −(C₀·cₙ + C₁·cₙ₋₁),

with x the coefficients of θ and s, c those of sin θ and cos θ. A step of
order 24 with the step size chosen from the last two coefficients
(Jorba & Zou, 2005) has a truncation error near 1e-16, and its polynomial *is*
the solution on the step: evaluating it at a sample time is exact to round-off,
not an interpolation.

Events inside a step (the stick reaching the head, or the vertical) are found
on the polynomial: sign changes on a grid of the step, and local minima between
grid points, so a bounce shorter than a grid cell is not missed; then a
safeguarded Newton iteration to full precision.
"""

import math

import numpy as np

ORDER = 24
TOLERANCE = 1e-16
GRID = 32


def coefficients(theta, omega, c0, c1, order=ORDER):
    """Taylor coefficients x₀…x_order of θ about a state (θ, ω) where C(τ) = c0 + c1·τ."""
    x = [0.0] * (order + 1)
    s = [0.0] * (order + 1)
    c = [0.0] * (order + 1)
    x[0], x[1] = theta, omega
    s[0], c[0] = math.sin(theta), math.cos(theta)
    x[2] = -c0 * c[0] / 2.0
    for n in range(1, order - 1):
        sn = 0.0
        cn = 0.0
        for j in range(1, n + 1):
            jx = j * x[j]
            sn += jx * c[n - j]
            cn -= jx * s[n - j]
        s[n] = sn / n
        c[n] = cn / n
        x[n + 2] = -(c0 * c[n] + c1 * c[n - 1]) / ((n + 1) * (n + 2))
    return np.array(x)


def step_size(x, tolerance=TOLERANCE):
    """The largest step whose truncation error stays near ``tolerance`` (s); inf for a polynomial.

    Uses the last four coefficients, since symmetric states (e.g. θ = 0, ω = 0)
    leave three of every four zero.
    """
    n = len(x) - 1
    h = math.inf
    for k in range(n - 3, n + 1):
        if x[k] != 0.0:
            h = min(h, (tolerance / abs(x[k])) ** (1.0 / k))
    return h


def evaluate(x, tau):
    """The polynomial and its derivative at ``tau`` (float or array, time since the step start)."""
    p = np.zeros_like(np.asarray(tau, dtype=float)) + x[-1]
    d = np.zeros_like(p)
    for k in range(len(x) - 2, -1, -1):
        d = d * tau + p
        p = p * tau + x[k]
    return p, d


def first_crossing(x, level, h, *, downward):
    """The first τ in (0, h] where the polynomial crosses ``level``, or None.

    ``downward=True`` looks for θ falling through ``level`` from above (the head),
    ``downward=False`` for θ rising through it (the vertical). A start exactly
    on the level, moving away from it, is not a crossing.
    """
    sign = 1.0 if downward else -1.0
    f = np.array(x, dtype=float) * sign
    f[0] = sign * (x[0] - level)  # exact zero when the step starts on the level
    df = f[1:] * np.arange(1, len(f))
    grid = np.linspace(0.0, h, GRID + 1)
    values, slopes = evaluate(f, grid)
    for j in range(1, GRID + 1):
        a, b = grid[j - 1], grid[j]
        fa, fb = values[j - 1], values[j]
        if fb < 0.0:
            if fa > 0.0:
                return _root(f, a, b)
            if fa < 0.0 or slopes[j - 1] <= 0.0:
                return a  # on (or past) the level and moving through it
            # On the level and leaving it: the return lies beyond the apex.
            apex = _root(df, a, b)
            if apex is None:  # the slope's sign change was round-off
                return a
            if _value(f, apex) > 0.0:
                return _root(f, apex, b)
            return min(2.0 * apex - a, b)  # a bounce smaller than round-off
        if fa > 0.0 and slopes[j - 1] < 0.0 < slopes[j]:
            low = _root(df, a, b)
            if low is not None and _value(f, low) < 0.0:
                return _root(f, a, low)
    return None


def _value(f, tau):
    return evaluate(f, tau)[0]


def _root(f, a, b):
    """The root of the polynomial f in [a, b] where f changes sign, by safeguarded Newton."""
    fa = _value(f, a)
    fb = _value(f, b)
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if (fa > 0.0) == (fb > 0.0):
        return None
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
        step = p / d if d != 0.0 else math.inf
        guess = t - step
        lo, hi = min(a, b), max(a, b)
        t_new = guess if lo < guess < hi else 0.5 * (a + b)
        if t_new == t or abs(b - a) <= 4.0 * np.finfo(float).eps * max(abs(a), abs(b), 1e-300):
            return t_new
        t = t_new
    return t
