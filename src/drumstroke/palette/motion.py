"""Moving the stick between strokes: returns, holds and joins, within one joint-limits type.

:class:`Limits` is what a joint may do — its range, speed, acceleration and jerk — and how near
its state a trajectory must start; the robot (:mod:`drumstroke.robot`) validates trajectories
against it, and the moves here are planned within it. ``Limits()`` is a strong drumming joint
that plays the shipped palette at 1 kHz; :data:`RETURN_LIMITS` is the gentler default budget of
the moves between strokes.

- :func:`plan_return`: from where one stroke ends to where the next begins in a given time —
  a quintic move to the target angle at rest, a hold, a quintic wind-up into the target speed —
  every move with zero acceleration at its ends, within the limits, never below the head.
- :func:`assemble`: trajectories placed on one timeline with the returns between them;
  :func:`concat`: one after another with given gaps.

Examples
--------
>>> import drumstroke
>>> single = drumstroke.simulate("free-bounce", t_end=0.5).sample(1000.0)
>>> twice = concat([single, single], 0.4)
>>> round(twice.t_end, 6), len(twice.impacts) == 2 * len(single.impacts)
(1.4, True)
>>> Limits().max_speed, RETURN_LIMITS.max_speed
(30.0, 20.0)
"""

import functools
import math
from dataclasses import dataclass, fields

import numpy as np

from .._checks import check_keys, check_real
from ..errors import ParameterError
from ..model import Stick
from ..stroke import Stroke, as_trajectory
from ..trajectory import THETA_TOP, Impacts, Trajectory


@dataclass(frozen=True)
class Limits:
    """What a robot joint may do: its speed, acceleration and jerk limits, its range, and how near it a start must be.

    The defaults are those of a strong joint that can play the shipped palette
    at 1 kHz, composed at any velocity. Impacts are velocity reversals within
    one control period, so the finite-difference acceleration and jerk at an
    impact are about (1 + c)·|ω|·rate and that times the rate; the defaults are
    set at least twice the largest values measured at 1 kHz: the shipped
    library reaches 12.12 rad/s, 22 544 rad/s² and 2.283e7 rad/s³
    (``superhuman-press``), compositions at velocity 127 (a 4 m/s tip speed)
    14.81 rad/s, 27 458 rad/s² and 2.756e7 rad/s³. At another rate r the
    impacts' acceleration scales with r/1000 and their jerk with (r/1000)².
    Moves between strokes are planned within their speed and acceleration
    (:data:`RETURN_LIMITS` by default).

    Parameters
    ----------
    theta_low : float in [-π/2, π/2)
        The lowest angle the joint may reach (rad). Default: the paper stick's
        head, ``Stick().theta_max`` ≈ −0.2623 rad.
    theta_high : float in (theta_low, π/2]
        The highest angle (rad). Default π/2, the stick upright.
    max_speed : float > 0
        |ω| limit (rad/s). Default 30.
    max_acceleration : float > 0
        |α| limit (rad/s²). Default 60 000.
    max_jerk : float > 0
        |j| limit (rad/s³). Default 6e7.
    start_angle_tolerance : float ≥ 0
        How far the first sample's θ may be from the joint's angle (rad). Default 0.01.
    start_speed_tolerance : float ≥ 0
        How far the first sample's ω may be from the joint's speed (rad/s). Default 0.5.

    Examples
    --------
    >>> Limits().max_speed
    30.0
    >>> Limits(max_speed=-1)
    Traceback (most recent call last):
    ...
    drumstroke.errors.ParameterError: limits.max_speed must be in (0, inf) rad/s, got -1.0
    """

    theta_low: float = Stick().theta_max
    theta_high: float = THETA_TOP
    max_speed: float = 30.0
    max_acceleration: float = 6.0e4
    max_jerk: float = 6.0e7
    start_angle_tolerance: float = 0.01
    start_speed_tolerance: float = 0.5

    def __post_init__(self):
        low = check_real("limits.theta_low", self.theta_low, low=-THETA_TOP, high=THETA_TOP, high_open=True,
                         unit="rad")
        values = {
            "theta_low": low,
            "theta_high": check_real("limits.theta_high", self.theta_high, low=low, high=THETA_TOP, low_open=True,
                                     unit="rad"),
            "max_speed": check_real("limits.max_speed", self.max_speed, low=0.0, low_open=True, unit="rad/s"),
            "max_acceleration": check_real("limits.max_acceleration", self.max_acceleration, low=0.0,
                                           low_open=True, unit="rad/s^2"),
            "max_jerk": check_real("limits.max_jerk", self.max_jerk, low=0.0, low_open=True, unit="rad/s^3"),
            "start_angle_tolerance": check_real("limits.start_angle_tolerance", self.start_angle_tolerance,
                                                low=0.0, unit="rad"),
            "start_speed_tolerance": check_real("limits.start_speed_tolerance", self.start_speed_tolerance,
                                                low=0.0, unit="rad/s"),
        }
        for name, value in values.items():
            object.__setattr__(self, name, value)

    @classmethod
    def from_dict(cls, table):
        """Limits from a TOML ``[limits]`` table (a dict); keys as the parameters, missing ones default."""
        if not isinstance(table, dict):
            raise ParameterError(f"limits must be a table, got {table!r}")
        check_keys("limits", table, [f.name for f in fields(cls)])
        return cls(**table)

    def to_dict(self):
        """The limits as a plain dict, keys as in a ``[limits]`` table."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


RETURN_LIMITS = Limits(max_speed=20.0, max_acceleration=1000.0)
"""The default budget of the moves between strokes: 20 rad/s, 1000 rad/s² (gentler than the joint can)."""


def concat(strokes, gaps=0.0, *, limits=None, name="concat"):
    """The strokes one after another, the stick returning smoothly in each gap.

    Parameters
    ----------
    strokes : sequence of Trajectory or Stroke
        At least one, all for the same stick (the same head angle).
    gaps : float or sequence of float ≥ 0
        Time (s) between the end of each stroke and the start of the next
        [one, or shape=(len(strokes) - 1,)]. A gap of 0 needs the next stroke
        to start where the previous one ends.
    limits : Limits or None
        Speed and acceleration bounds on the returns (default :data:`RETURN_LIMITS`).
    name : str
    """
    pieces = [as_trajectory(s) for s in strokes] if not isinstance(strokes, (Stroke, Trajectory)) else None
    if not pieces:
        raise ParameterError(f"strokes must be a non-empty sequence of strokes, got {strokes!r}")
    gaps = np.broadcast_to(np.asarray(gaps, dtype=float), (len(pieces) - 1,)) if len(pieces) > 1 else np.empty(0)
    for i, gap in enumerate(gaps):
        check_real(f"gaps[{i}]", float(gap), low=0.0, high=3600.0, unit="s")
    starts = np.concatenate(([0.0], np.cumsum([p.t_end for p in pieces[:-1]] + gaps)))
    return assemble(pieces, starts, limits=limits or RETURN_LIMITS, name=name)


def assemble(pieces, starts, *, limits, name, end=None):
    """Place trajectories at ``starts`` (s) on one timeline, with smooth returns between them.

    Before the first piece the stick holds its start angle (and winds up into
    its start speed); after the last, if ``end`` (s) is given, it returns to the
    last piece's start angle and holds there until ``end``. Raises
    ParameterError naming ``gaps[i]`` when a return
    does not fit.
    """
    head = pieces[0].theta_max
    for i, p in enumerate(pieces):
        if abs(p.theta_max - head) > 1e-12 or p.impacts.tip_distance != pieces[0].impacts.tip_distance:
            raise ParameterError(f"strokes[{i}] is for a different stick (theta_max {p.theta_max:.6g} rad, "
                                 f"strokes[0] has {head:.6g} rad); concatenate strokes of one stick")
    segments = []  # (start, duration, path)
    first = _start_state(pieces[0])
    if starts[0] > 0.0:
        plan = plan_return((first[0], 0.0), first, starts[0], head, limits)
        if plan is None:
            raise ParameterError(f"the first stroke needs a lead-in before it starts at {starts[0]:g} s")
        segments += _placed(plan, 0.0)
    for i, piece in enumerate(pieces):
        segments.append((starts[i], piece.t_end, piece.path))
        after = starts[i] + piece.t_end
        if i + 1 < len(pieces):
            window = starts[i + 1] - after
            plan = plan_return(_end_state(piece), _start_state(pieces[i + 1]), window, head, limits)
            if plan is None:
                label = f"gaps[{i}]"
                need = return_time(_end_state(piece), _start_state(pieces[i + 1]), head, limits)
                needed = f"at least {need:.4g} s" if math.isfinite(need) else "a different end or start state"
                raise ParameterError(
                    f"{label} = {window:.6g} s is too short for the stick to return from {piece.name!r} to "
                    f"{pieces[i + 1].name!r} within {limits.max_speed:g} rad/s and {limits.max_acceleration:g} "
                    f"rad/s^2 above the head; it needs {needed}")
            segments += _placed(plan, after)
    t_end = starts[-1] + pieces[-1].t_end
    if end is not None and end > t_end:
        last = pieces[-1]
        home = (_start_state(last)[0], 0.0)
        plan = plan_return(_end_state(last), home, end - t_end, head, limits)
        if plan is None:
            raise ParameterError(f"the last stroke {last.name!r} cannot return home by {end:g} s")
        segments += _placed(plan, t_end)
        t_end = end
    impacts_t = np.concatenate([p.impacts.t + s for p, s in zip(pieces, starts)])
    omega = np.concatenate([p.impacts.omega for p in pieces])
    after = np.concatenate([p.omega_after for p in pieces])
    models = sorted({p.model for p in pieces})
    recipes = {id(p.recipe) for p in pieces}
    return Trajectory.single(
        _sequence(segments), Impacts(impacts_t, omega, pieces[0].impacts.tip_distance), after, theta_max=head,
        t_end=float(t_end), rate=pieces[0].rate, name=name, model=models[0] if len(models) == 1 else "mixed",
        recipe=pieces[0].recipe if len(recipes) == 1 else None,
        history=(f"{name} of " + ", ".join(p.name for p in pieces),))


_COMFORT = 1.5  # returns take this many times their shortest duration within the limits, when there is room


def plan_return(start, target, window, theta_max, limits):
    """How the stick gets from ``start`` to ``target`` (θ rad, ω rad/s) in ``window`` seconds, or None.

    A quintic move to the target angle at rest, a hold, then (if the target
    moves) a quintic wind-up from rest into the target speed — each with zero
    acceleration at its ends, velocity continuous throughout — or, when that
    does not fit, one quintic over the whole window. Every move stays within
    ``limits`` and on or above the head.

    Returns
    -------
    list of (duration s, path) or None
    """
    if window < -1e-12:
        return None
    window = max(window, 0.0)
    rest = (target[0], 0.0)
    move = _shortest(start, rest, theta_max, limits, window)
    wind = _shortest(rest, target, theta_max, limits, window)
    for scale in (_COMFORT, 1.0):
        a, b = move * scale, wind * scale
        if a + b <= window + 1e-12 and _fits(start, rest, a, theta_max, limits) and _fits(rest, target, b, theta_max,
                                                                                          limits):
            return [p for p in (_quintic(start, rest, a), _hold(target[0], window - a - b), _quintic(rest, target, b))
                    if p[0] > 0.0]
    if _fits(start, target, window, theta_max, limits):
        return [_quintic(start, target, window)] if window > 0.0 else []
    return None


def return_time(start, target, theta_max, limits):
    """The shortest window (s) :func:`plan_return` can use, or inf."""
    rest = (target[0], 0.0)
    total = _shortest(start, rest, theta_max, limits, math.inf) + _shortest(rest, target, theta_max, limits, math.inf)
    direct = _shortest(start, target, theta_max, limits, math.inf)
    return min(total, direct)


_COARSE = 1e-4 * 1.25 ** np.arange(64)  # 0.1 ms to ~130 s
_S = np.linspace(0.0, 1.0, 129)


def _shortest(start, target, theta_max, limits, longest):
    """The shortest duration (s) of a quintic move within the limits (to 1 %), 0 for none needed, or inf.

    Found on the coarse grid up to ``longest`` (s), then refined below the first coarse duration that fits.
    """
    coarse, refined = _shortest_on_grid(tuple(start), tuple(target), theta_max, limits)
    return refined if coarse <= longest * 1.0000001 else math.inf


@functools.lru_cache(maxsize=4096)
def _shortest_on_grid(start, target, theta_max, limits):
    """The first coarse duration (s) that fits, and the shortest refined one; (inf, inf) if none fits.

    Cached: a composition asks for the same moves between the same stroke ends and starts again and again."""
    if abs(start[0] - target[0]) < 1e-15 and abs(start[1]) < 1e-15 and abs(target[1]) < 1e-15:
        return 0.0, 0.0
    ok = _fits_many(start, target, _COARSE, theta_max, limits)
    if not ok.any():
        return math.inf, math.inf
    k = int(np.argmax(ok))
    if k == 0:
        return float(_COARSE[0]), float(_COARSE[0])
    fine = _COARSE[k - 1] * 1.01 ** np.arange(1, 24)  # 1.01**23 > 1.25
    fine = fine[fine < _COARSE[k]]
    ok_fine = _fits_many(start, target, fine, theta_max, limits)
    return float(_COARSE[k]), float(fine[np.argmax(ok_fine)]) if ok_fine.any() else float(_COARSE[k])


def _fits(start, target, duration, theta_max, limits):
    if duration <= 0.0:
        return abs(start[0] - target[0]) < 1e-12 and abs(start[1] - target[1]) < 1e-9
    return _fits_once(tuple(start), tuple(target), duration, theta_max, limits)


@functools.lru_cache(maxsize=4096)
def _fits_once(start, target, duration, theta_max, limits):
    return bool(_fits_many(start, target, np.array([duration]), theta_max, limits)[0])


def _fits_many(start, target, durations, theta_max, limits):
    d = durations[:, None]
    c3, c4, c5 = _coefficients(start, target, d)
    s = _S[None, :]
    theta = start[0] + start[1] * d * s + c3 * s**3 + c4 * s**4 + c5 * s**5
    omega = (start[1] * d + 3 * c3 * s**2 + 4 * c4 * s**3 + 5 * c5 * s**4) / d
    alpha = (6 * c3 * s + 12 * c4 * s**2 + 20 * c5 * s**3) / d**2
    margin = 0.98  # the peaks may fall between the checked points
    return ((np.abs(omega).max(axis=1) <= margin * limits.max_speed)
            & (np.abs(alpha).max(axis=1) <= margin * limits.max_acceleration)
            & (theta.min(axis=1) >= theta_max - 1e-12) & (theta.max(axis=1) <= THETA_TOP))


def _coefficients(start, target, d):
    h, v0, v1 = target[0] - start[0], start[1] * d, target[1] * d
    return 10 * h - 6 * v0 - 4 * v1, -15 * h + 8 * v0 + 7 * v1, 6 * h - 3 * v0 - 3 * v1


def _quintic(start, target, duration):
    c3, c4, c5 = _coefficients(start, target, duration)
    theta0, v0 = start[0], start[1] * duration

    def move(t):
        s = np.asarray(t, dtype=float) / duration
        theta = theta0 + v0 * s + c3 * s**3 + c4 * s**4 + c5 * s**5
        return theta, (v0 + 3 * c3 * s**2 + 4 * c4 * s**3 + 5 * c5 * s**4) / duration

    return duration, move


def _hold(theta, duration):
    def hold(t):
        t = np.asarray(t, dtype=float)
        return np.full(t.shape, theta), np.zeros(t.shape)

    return duration, hold


def _placed(plan, start):
    out = []
    for duration, path in plan:
        out.append((start, duration, path))
        start += duration
    return out


def _sequence(segments):
    """One path from segments (start s, duration s, path) that tile the timeline."""
    starts = np.array([s for s, _, _ in segments])
    paths = [p for _, _, p in segments]

    def path(t):
        t = np.asarray(t, dtype=float)
        flat = t.ravel()
        theta, omega = np.empty(flat.shape), np.empty(flat.shape)
        which = np.clip(np.searchsorted(starts, flat, side="right") - 1, 0, len(paths) - 1)
        for k in np.unique(which):
            mask = which == k
            local = np.clip(flat[mask] - starts[k], 0.0, segments[k][1])
            theta[mask], omega[mask] = paths[k](local)
        return theta.reshape(t.shape), omega.reshape(t.shape)

    return path


def _start_state(s):
    theta, omega = s.path(np.array([0.0]))
    return float(theta[0]), float(omega[0])


def _end_state(s):
    theta, omega = s.path(np.array([s.t_end]))
    return float(theta[0]), float(omega[0])
