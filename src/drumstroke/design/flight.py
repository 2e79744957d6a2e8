"""One flight of the stick, designed in closed form.

Under a constant torque rate C (s⁻², :meth:`~drumstroke.model.Coefficients.torque_rate`) a
flight is an exact elliptic arc, and its shape does not depend on C: only its speed does.
Falling from rest at the apex ``sin θ = a`` to ``sin θ = s`` under C = 1 takes
Ψ(a, s) seconds and arrives at w = √(2(a − s)) rad/s; under C it takes Ψ/√C and arrives
at w·√C. So a fall that must arrive at speed v from the apex a takes

    H(a, s) / v,      H(a, s) = Ψ(a, s)·√(2(a − s))   (s · rad/s),

and the force that does it is C = v²/(2(a − s)). The same holds backwards for a rise
from s at speed u to the apex a (a flight is time-reversible). A flight with one level
on the way up (C_up) and one on the way down (C_down), switched at the apex, from
``sin θ = s0`` rising at u to the head ``sin θ = sh`` arriving at v, therefore lasts

    T(a) = H(a, s0)/u + H(a, sh)/v,

which grows strictly with the apex height a. Given T, u and v, one root of T(a) gives
the apex, and with it both forces exactly: C_up = u²/(2(a − s0)), C_down = v²/(2(a − sh)).
Energy is added on the way down whenever C_down > C_up, so a bounce can come back as
loud as it left, or louder.

Examples
--------
>>> import math
>>> sh = math.sin(-0.2623)
>>> apex = solve_apex(0.1, u=3.8, v=4.4, s0=sh, sh=sh, top=1.0)
>>> t = height_time(apex, sh) / 3.8 + height_time(apex, sh) / 4.4
>>> round(t, 12)
0.1
"""

import math
from typing import NamedTuple

import numpy as np

from .._jit import jit
from ..solver.elliptic import parameter, time_from_apex

_XTOL = 1e-15
"""Absolute tolerance of the apex (in sin θ); flight times come out to ~1e-13 s."""

_EPS = 2.220446049250313e-16


@jit
def height_time(apex, s):
    """H(a, s): the time (s) to fall from rest at ``sin θ = apex`` to ``sin θ = s`` times the speed there, at C = 1.

    A fall under C that arrives at speed v takes H/v; a rise from s at speed u to the apex takes H/u.

    Parameters
    ----------
    apex : float in (-1, 1)
        sin θ at the apex.
    s : float ≤ apex
        sin θ where the fall ends (or the rise starts).

    Returns
    -------
    float
        s · rad/s; 0 when ``s ≥ apex``.
    """
    if s >= apex:
        return 0.0
    w = math.sqrt(2.0 * (apex - s))
    return time_from_apex(s, w, 1.0, 0.5 * (1.0 + apex)) * w


@jit
def _flight_time(apex, u, v, s0, sh):
    rise = height_time(apex, s0) / u if u > 0.0 else 0.0
    return rise + height_time(apex, sh) / v


def flight_time(apex, *, u, v, s0, sh):
    """Duration (s) of a flight that rises from ``s0`` at ``u`` (rad/s) to ``apex`` and falls to ``sh`` at ``v``."""
    return _flight_time(apex, u, v, s0, sh)


def solve_apex(duration, *, u, v, s0, sh, top):
    """The apex (sin θ) of the flight of ``duration`` s from ``s0`` rising at ``u`` to ``sh`` arriving at ``v``.

    Returns None when no apex in (max(s0, sh), top) gives that duration: the flight is
    too short (shorter than falling from rest at s0) or too long (the apex would pass ``top``).
    """
    apex = _solve_apex(duration, u, v, s0, sh, top)
    return None if math.isnan(apex) else apex


@jit
def _solve_apex(duration, u, v, s0, sh, top):
    """:func:`solve_apex` compiled, NaN for none: Brent's method on the strictly increasing flight time."""
    a = max(s0, sh)
    b = top
    fa = _flight_time(a, u, v, s0, sh) - duration
    fb = _flight_time(b, u, v, s0, sh) - duration
    if not (fa < 0.0 < fb):
        return math.nan
    c, fc = a, fa
    d = e = b - a
    for _ in range(200):
        if (fb > 0.0) == (fc > 0.0):
            c, fc = a, fa
            d = e = b - a
        if abs(fc) < abs(fb):
            a, b, c = b, c, b
            fa, fb, fc = fb, fc, fb
        tol = 2.0 * _EPS * abs(b) + 0.5 * _XTOL
        m = 0.5 * (c - b)
        if abs(m) <= tol or fb == 0.0:
            return b
        if abs(e) >= tol and abs(fa) > abs(fb):
            s = fb / fa
            if a == c:
                p = 2.0 * m * s
                q = 1.0 - s
            else:
                q, r = fa / fc, fb / fc
                p = s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0))
                q = (q - 1.0) * (r - 1.0) * (s - 1.0)
            if p > 0.0:
                q = -q
            else:
                p = -p
            if 2.0 * p < min(3.0 * m * q - abs(tol * q), abs(e * q)):
                e, d = d, p / q
            else:
                d = e = m
        else:
            d = e = m
        a, fa = b, fb
        b += d if abs(d) > tol else (tol if m > 0.0 else -tol)
        fb = _flight_time(b, u, v, s0, sh) - duration
    return b


def apex_for_fall(duration, *, v, sh, top):
    """The rest height (sin θ) from which a fall under a constant force reaches ``sh`` at ``v`` after ``duration`` s.

    None if even a fall from ``top`` is quicker.
    """
    return solve_apex(duration, u=0.0, v=v, s0=sh, sh=sh, top=top)


def force_to_reach(speed, rise):
    """The torque rate C (s⁻²) that turns ``speed`` (rad/s) into a change of ``rise`` in sin θ: speed²/(2·rise)."""
    return speed * speed / (2.0 * rise)



@jit
def orbit_time(s, w, c):
    """Time (s) between the state (sin θ = ``s``, |ω| = ``w``) and the apex of its orbit under ``c`` (a libration)."""
    return time_from_apex(s, abs(w), c, parameter(s, w, c))


class Flight(NamedTuple):
    """A flight from the head to the head with its forces (torque rates, s⁻²) and switch times (s from its start).

    ``rise`` acts from ``t_rise`` (0, or the end of a short first part under ``first``) to the apex at
    ``t_apex``; ``fall`` from the apex to ``t_last`` (the flight's end, or the start of a short last part
    under ``last``). A named tuple: a design solves dozens (each flight again until its neighbours' forces
    settle), and a frozen dataclass costs more to make than the flight to solve.
    """

    apex: float
    rise: float
    fall: float
    t_rise: float
    t_apex: float
    t_last: float
    duration: float
    first: float | None = None
    last: float | None = None


def solve_flight(duration, *, u, v, sh, top, first=None, last=None):
    """The flight of ``duration`` s leaving the head at ``u`` and arriving at ``v`` (rad/s), or None.

    One force (``rise``) on the way up, switched at the apex to another (``fall``) on the way down.
    Optionally the flight starts under the force ``first = (rate, height)`` until it has risen to
    sin θ = height, and ends under ``last = (rate, height)`` from sin θ = height on the way down: the
    neighbouring flights' forces, so that no force changes at an impact (see :mod:`drumstroke.design.chain`).
    None when no apex below ``top`` gives the duration, or a part is impossible.
    """
    s0, w0, t0 = _near_head(first, u, sh)
    s1, w1, t1 = _near_head(last, v, sh)
    apex, rise, fall, t_apex = _flight(duration, s0, w0, t0, s1, w1, t1, top)
    if math.isnan(apex):
        return None
    return Flight(apex, rise, fall, t0, t_apex, duration - t1, duration, None if first is None else first[0],
                  None if last is None else last[0])


@jit
def _flight(duration, s0, w0, t0, s1, w1, t1, top):
    """:func:`solve_flight`'s apex (sin θ), its two torque rates (s⁻²) and the apex time (s), NaN for none."""
    if w0 == 0.0 or w1 == 0.0:
        return math.nan, math.nan, math.nan, math.nan
    span = duration - t0 - t1
    if span <= 0.0:
        return math.nan, math.nan, math.nan, math.nan
    apex = _solve_apex(span, w0, w1, s0, s1, top)
    if math.isnan(apex):
        return math.nan, math.nan, math.nan, math.nan
    t_apex = t0 + height_time(apex, s0) / w0
    return apex, w0 * w0 / (2.0 * (apex - s0)), w1 * w1 / (2.0 * (apex - s1)), t_apex


def _near_head(part, speed, sh):
    """Where a short part of a flight next to the head ends: (sin θ, |ω| rad/s, its duration s).

    ``part`` is (rate, height) or None (no part: the head itself, at ``speed``); the stick crosses the part
    at ``speed`` on the head, rising or falling alike (a flight is time-reversible). |ω| is 0 when the
    part would not reach its height.
    """
    if part is None:
        return sh, speed, 0.0
    rate, height = part
    w, duration = _part(sh, speed, height, rate)
    if math.isnan(duration):  # a rotation orbit: by quadrature
        duration = part_time(sh, speed, height, w, rate)
    return height, w, duration


@jit
def _part(sh, speed, height, rate):
    """|ω| (rad/s) where a part under ``rate`` from the head at ``speed`` reaches ``height``, and its duration (s) on a
    libration orbit (:func:`part_time`'s first case; 0 if it does not get there; NaN on a rotation orbit)."""
    w = math.sqrt(max(speed * speed - 2.0 * rate * (height - sh), 0.0))
    if w <= 0.0:
        return w, 0.0
    if parameter(sh, speed, rate) < 1.0:
        return w, orbit_time(sh, speed, rate) - orbit_time(height, w, rate)
    return w, math.nan


def settled_flights(times, speeds, *, cor, sh, top, rates, theta_max, max_acceleration, switch, rounds):
    """The flights of a chain of notes, each with its neighbours' forces next to the head, settled; or None.

    :meth:`drumstroke.design.chain._Plan.flights`'s rounds, compiled: the flights solved as if the force
    changed at the impacts, then again with the short parts (at ``switch`` of each flight's height) until
    the forces settle. None when a flight of any round fails a check of the plan's (no apex, a force
    outside ``rates`` ± 1e-9 relative, an acceleration over ``max_acceleration``) or needs a part on a
    rotation orbit: the plan then solves them one by one, and says which note fails and why.

    Returns
    -------
    list of Flight or None
    """
    table = _settle(np.asarray(times, dtype=float), np.asarray(speeds, dtype=float), cor, sh, top, rates[0],
                    rates[1], math.cos(theta_max), max_acceleration, switch, rounds)
    if table is None:
        return None
    return [Flight(*row[:7].tolist(), None if math.isnan(row[7]) else float(row[7]),
                   None if math.isnan(row[8]) else float(row[8])) for row in table]


def possible_flights(times, speeds, *, cor, sh, top, rates, theta_max, max_acceleration):
    """For each pair of consecutive notes, whether the flight between them (its force changed at the impacts)
    passes the plan's checks (:func:`settled_flights`'): list of bool [len(times) − 1]."""
    return _possible(np.asarray(times, dtype=float), np.asarray(speeds, dtype=float), cor, sh, top, rates[0], rates[1],
                     math.cos(theta_max), max_acceleration).tolist()


@jit
def _possible(times, speeds, cor, sh, top, low, high, head_cos, max_acceleration):
    n = len(times) - 1
    row = np.empty((n, 9))
    within = np.empty(n, dtype=np.bool_)
    for i in range(n):
        within[i] = _bounce(row, i, times, speeds, cor, sh, top, low, high, head_cos, max_acceleration, False, 0.0,
                            False, 0.0, 0.0)
    return within


@jit
def _settle(times, speeds, cor, sh, top, low, high, head_cos, max_acceleration, switch, rounds):
    """:func:`settled_flights`'s rounds: a row per flight (its Flight's fields, NaN for no part), or None."""
    n = len(times) - 1
    plain = np.empty((n, 9))
    for i in range(n):
        if not _bounce(plain, i, times, speeds, cor, sh, top, low, high, head_cos, max_acceleration, False, 0.0,
                       False, 0.0, 0.0):
            return None
    heights = np.empty(n)
    for i in range(n):
        heights[i] = sh + switch * (plain[i, 0] - sh)
    before = np.zeros(n, dtype=np.bool_)
    for i in range(1, n):
        before[i] = plain[i, 1] < plain[i - 1, 2]
    flights = plain
    for _ in range(rounds):
        settled = np.empty((n, 9))
        for i in range(n):
            has_first = i > 0 and not before[i]
            has_last = i + 1 < n and before[i + 1]
            if not _bounce(settled, i, times, speeds, cor, sh, top, low, high, head_cos, max_acceleration, has_first,
                           flights[i - 1, 2] if has_first else 0.0, has_last, flights[i + 1, 1] if has_last else 0.0,
                           heights[i]):
                return None
        change = -math.inf
        largest = -math.inf
        for i in range(n):
            change = max(change, abs(settled[i, 2] - flights[i, 2]) + abs(settled[i, 1] - flights[i, 1]))
            largest = max(largest, settled[i, 2])
        flights = settled
        if change <= 1e-13 * largest:
            break
    return flights


@jit
def _bounce(out, i, times, speeds, cor, sh, top, low, high, head_cos, max_acceleration, has_first, first, has_last,
            last, height):
    """Row i of ``out``: the flight from note i to note i + 1 (:func:`solve_flight`); False if it fails a check."""
    u, v = cor * speeds[i], speeds[i + 1]
    duration = times[i + 1] - times[i]
    s0, w0, t0 = sh, u, 0.0
    if has_first:
        w0, t0 = _part(sh, u, height, first)
        s0 = height
    s1, w1, t1 = sh, v, 0.0
    if has_last:
        w1, t1 = _part(sh, v, height, last)
        s1 = height
    if math.isnan(t0) or math.isnan(t1):  # a rotation orbit: its part by quadrature, in Python
        return False
    apex, rise, fall, t_apex = _flight(duration, s0, w0, t0, s1, w1, t1, top)
    if math.isnan(apex):
        return False
    slack = 1e-9 * max(abs(low), abs(high))
    for rate in (rise, fall):
        if not (low - slack <= rate <= high + slack):
            return False
    lowest_cos = max(head_cos, math.sqrt(max(0.0, 1.0 - apex * apex)))
    if max(rise, fall) * (1.0 if apex >= 0.0 else lowest_cos) > max_acceleration:
        return False
    out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4] = apex, rise, fall, t0, t_apex
    out[i, 5], out[i, 6] = duration - t1, duration
    out[i, 7] = first if has_first else math.nan
    out[i, 8] = last if has_last else math.nan
    return True


_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(24)


def part_time(s0, w0, s1, w1, c):
    """Time (s) for the stick to rise from sin θ = ``s0`` at ``w0`` to ``s1`` at ``w1`` (rad/s, > 0) under ``c`` (s⁻²).

    On a libration orbit (one that turns back below the vertical) the difference of the two times to its
    apex, exactly; on a rotation orbit (its energy would carry the stick over the vertical: a fast stick
    under a light force, near the head) ω stays at least ``w1`` > 0 over the part and the time is
    ∫ dθ/ω, to round-off by 24-point Gauss–Legendre quadrature of the smooth integrand.
    """
    if parameter(s0, w0, c) < 1.0:
        return orbit_time(s0, w0, c) - orbit_time(s1, w1, c)
    theta0, theta1 = math.asin(s0), math.asin(s1)
    half = 0.5 * (theta1 - theta0)
    theta = theta0 + half * (_NODES + 1.0)
    omega = np.sqrt(np.maximum(w0 * w0 - 2.0 * c * (np.sin(theta) - s0), w1 * w1))
    return float(half * np.sum(_WEIGHTS / omega))
