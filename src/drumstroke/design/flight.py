"""One flight of the stick, designed in closed form (SPEC §1, §8).

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
from dataclasses import dataclass

from scipy.optimize import brentq

from ..solver.elliptic import parameter, time_from_apex

_XTOL = 1e-15
"""Absolute tolerance of the apex (in sin θ); flight times come out to ~1e-13 s."""


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


def flight_time(apex, *, u, v, s0, sh):
    """Duration (s) of a flight that rises from ``s0`` at ``u`` (rad/s) to ``apex`` and falls to ``sh`` at ``v``."""
    rise = height_time(apex, s0) / u if u > 0.0 else 0.0
    return rise + height_time(apex, sh) / v


def solve_apex(duration, *, u, v, s0, sh, top):
    """The apex (sin θ) of the flight of ``duration`` s from ``s0`` rising at ``u`` to ``sh`` arriving at ``v``.

    Returns None when no apex in (max(s0, sh), top) gives that duration: the flight is
    too short (shorter than falling from rest at s0) or too long (the apex would pass ``top``).
    """
    low = max(s0, sh)
    if not flight_time(low, u=u, v=v, s0=s0, sh=sh) < duration < flight_time(top, u=u, v=v, s0=s0, sh=sh):
        return None
    return brentq(lambda a: flight_time(a, u=u, v=v, s0=s0, sh=sh) - duration, low, top, xtol=_XTOL,
                  rtol=1e-15, maxiter=200)


def apex_for_fall(duration, *, v, sh, top):
    """The rest height (sin θ) from which a fall under a constant force reaches ``sh`` at ``v`` after ``duration`` s.

    None if even a fall from ``top`` is quicker.
    """
    return solve_apex(duration, u=0.0, v=v, s0=sh, sh=sh, top=top)


def force_to_reach(speed, rise):
    """The torque rate C (s⁻²) that turns ``speed`` (rad/s) into a change of ``rise`` in sin θ: speed²/(2·rise)."""
    return speed * speed / (2.0 * rise)



def orbit_time(s, w, c):
    """Time (s) between the state (sin θ = ``s``, |ω| = ``w``) and the apex of its orbit under ``c`` (a libration)."""
    return time_from_apex(s, abs(w), c, parameter(s, w, c))


@dataclass(frozen=True)
class Flight:
    """A flight from the head to the head with its forces (torque rates, s⁻²) and switch times (s from its start).

    ``rise`` acts from ``t_rise`` (0, or the end of a short first part under ``first``) to the apex at
    ``t_apex``; ``fall`` from the apex to ``t_last`` (the flight's end, or the start of a short last part
    under ``last``).
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
    s0, w0, t0 = sh, u, 0.0
    if first is not None:
        rate, s0 = first
        w0 = math.sqrt(max(u * u - 2.0 * rate * (s0 - sh), 0.0))
        if w0 == 0.0:
            return None
        t0 = orbit_time(sh, u, rate) - orbit_time(s0, w0, rate)
    s1, w1, t1 = sh, v, 0.0
    if last is not None:
        rate, s1 = last
        w1 = math.sqrt(max(v * v - 2.0 * rate * (s1 - sh), 0.0))
        if w1 == 0.0:
            return None
        t1 = orbit_time(sh, v, rate) - orbit_time(s1, w1, rate)
    span = duration - t0 - t1
    low = max(s0, s1)
    if span <= 0.0 or not flight_time(low, u=w0, v=w1, s0=s0, sh=s1) < span < flight_time(top, u=w0, v=w1, s0=s0,
                                                                                             sh=s1):
        return None
    apex = brentq(lambda a: flight_time(a, u=w0, v=w1, s0=s0, sh=s1) - span, low, top, xtol=_XTOL, rtol=1e-15,
                  maxiter=200)
    t_apex = t0 + height_time(apex, s0) / w0
    return Flight(apex, force_to_reach(w0, apex - s0), force_to_reach(w1, apex - s1), t0, t_apex, duration - t1,
                  duration, None if first is None else first[0], None if last is None else last[0])
