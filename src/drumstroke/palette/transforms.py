"""Post-processing of strokes (paper §3.5): stretch, compress, reverse, trim, concat.

Each transform takes a :class:`~drumstroke.palette.Trajectory` (or a
:class:`~drumstroke.Stroke`, taken exactly) and returns a new one whose impacts
agree with its curve: θ = θ_max at every impact time.

- ``stretch(s, f)``: θ'(t) = θ(t/f). Impact times ×f, speeds ÷f.
- ``compress(s, f)``: θ' = θ_max + f·(θ − θ_max), the excursion above the head
  scaled; speeds ×f, times unchanged. The dynamic level moves by 20·log10 f dB.
- ``reverse(s)``: θ'(t) = θ(T − t). Times mirrored; each impact's speeds before
  and after swap, so a reversed bounce gains energy (1/c) — an un-natural stroke.
- ``trim(s, t0, t1)``: the part in [t0, t1], starting at 0.
- ``concat(strokes, gaps)``: one after another; in each gap the stick returns
  smoothly (:func:`plan_return`) from where one stroke ends to where the next
  begins, within speed and acceleration limits, never below the head.

None of them lets the stick below the head or past upright (θ ≤ π/2).

Examples
--------
>>> import drumstroke
>>> bounce = Trajectory.from_stroke(drumstroke.simulate("free-bounce"))
>>> slow = stretch(bounce, 2.0)
>>> float(slow.impacts.t[0] / bounce.impacts.t[0]), float(slow.impacts.omega[0] / bounce.impacts.omega[0])
(2.0, 0.5)
>>> [len(s.impacts) for s in (trim(bounce, 0.0, bounce.apex_after(3)), reverse(bounce))]
[3, 98]
"""

import math
from dataclasses import dataclass, replace

import numpy as np

from .._checks import check_real
from ..errors import ParameterError
from ..stroke import Stroke, as_trajectory
from ..trajectory import THETA_TOP, Impacts, Trajectory

STRETCH_LIMIT = 100.0
"""Largest stretch factor (and 1/smallest)."""


@dataclass(frozen=True)
class Limits:
    """Bounds on the stick's motion while it returns between strokes.

    Parameters
    ----------
    max_speed : float in (0, 1000]
        rad/s.
    max_acceleration : float in (0, 1e6]
        rad/s².
    """

    max_speed: float = 20.0
    max_acceleration: float = 1000.0

    def __post_init__(self):
        check_real("max_speed", self.max_speed, low=0.0, high=1000.0, low_open=True, unit="rad/s")
        check_real("max_acceleration", self.max_acceleration, low=0.0, high=1e6, low_open=True, unit="rad/s^2")


def stretch(stroke, factor):
    """Play ``stroke`` ``factor`` times slower (factor > 1) or faster (< 1).

    Parameters
    ----------
    stroke : Trajectory or Stroke
    factor : float in [0.01, 100]
    """
    s = as_trajectory(stroke)
    f = check_real("factor", factor, low=1.0 / STRETCH_LIMIT, high=STRETCH_LIMIT)
    path = s.path

    def stretched(t):
        theta, omega = path(np.asarray(t, dtype=float) / f)
        return theta, omega / f

    return _derived(s, f"stretch {f:g}", path=stretched, t_end=s.t_end * f,
                    impacts=_impacts(s, s.impacts.t * f, s.impacts.omega / f), omega_after=s.omega_after / f,
                    recipe_time=_then(lambda t: np.asarray(t) / f, s.recipe_time))


def compress(stroke, factor):
    """Scale the stroke's excursion above the head by ``factor``: a louder (> 1) or softer (< 1) stroke.

    Parameters
    ----------
    stroke : Trajectory or Stroke
    factor : float in (0, f_max]
        f_max keeps the stick below upright: (π/2 − θ_max) / (peak − θ_max).
    """
    s = as_trajectory(stroke)
    f = check_real("factor", factor, low=0.0, low_open=True)
    top = compress_limit(s)
    if f > top:
        raise ParameterError(f"factor must be in (0, {top:.6g}] for {s.name!r} (its peak {s.peak:.4f} rad would "
                             f"pass upright, pi/2), got {f!r}")
    path, head = s.path, s.theta_max

    def compressed(t):
        theta, omega = path(t)
        return np.minimum(head + f * (theta - head), THETA_TOP), f * omega

    result = _derived(s, f"compress {f:g}", path=compressed, t_end=s.t_end,
                      impacts=_impacts(s, s.impacts.t, s.impacts.omega * f), omega_after=s.omega_after * f,
                      recipe_time=s.recipe_time)
    # Scaling the height keeps every time where the stick turns or lands: no need to search again.
    result.__dict__.update(apexes=s.apexes, rest_time=s.rest_time, peak=min(head + f * (s.peak - head), THETA_TOP))
    return result


def compress_limit(stroke):
    """The largest compress factor that keeps ``stroke`` below upright (π/2)."""
    s = as_trajectory(stroke)
    excursion = s.peak - s.theta_max
    return math.inf if excursion <= 0.0 else (THETA_TOP - s.theta_max) / excursion


def reverse(stroke):
    """Play ``stroke`` backwards in time."""
    s = as_trajectory(stroke)
    path, end = s.path, s.t_end

    def reversed_(t):
        theta, omega = path(end - np.asarray(t, dtype=float))
        return theta, -omega

    return _derived(s, "reverse", path=reversed_, t_end=end,
                    impacts=_impacts(s, end - s.impacts.t[::-1], -s.omega_after[::-1]),
                    omega_after=-s.impacts.omega[::-1].copy(),
                    recipe_time=_then(lambda t: end - np.asarray(t), s.recipe_time))


def trim(stroke, t0=0.0, t1=None):
    """The part of ``stroke`` from ``t0`` to ``t1`` (s), moved to start at 0.

    Parameters
    ----------
    stroke : Trajectory or Stroke
    t0 : float in [0, t_end)
        s.
    t1 : float in (t0, t_end] or None
        s; None is the end.
    """
    s = as_trajectory(stroke)
    t0 = check_real("t0", t0, low=0.0, high=s.t_end, high_open=True, unit="s")
    t1 = s.t_end if t1 is None else check_real("t1", t1, low=t0, high=s.t_end, low_open=True, unit="s")
    keep = (s.impacts.t >= t0) & (s.impacts.t <= t1)
    path = s.path

    def trimmed(t):
        return path(np.asarray(t, dtype=float) + t0)

    return _derived(s, f"trim {t0:.6g}..{t1:.6g}", path=trimmed, t_end=t1 - t0,
                    impacts=_impacts(s, s.impacts.t[keep] - t0, s.impacts.omega[keep]),
                    omega_after=s.omega_after[keep],
                    recipe_time=_then(lambda t: np.asarray(t) + t0, s.recipe_time))


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
        Speed and acceleration bounds on the returns (default :class:`Limits`).
    name : str
    """
    pieces = [as_trajectory(s) for s in strokes] if not isinstance(strokes, (Stroke, Trajectory)) else None
    if not pieces:
        raise ParameterError(f"strokes must be a non-empty sequence of strokes, got {strokes!r}")
    gaps = np.broadcast_to(np.asarray(gaps, dtype=float), (len(pieces) - 1,)) if len(pieces) > 1 else np.empty(0)
    for i, gap in enumerate(gaps):
        check_real(f"gaps[{i}]", float(gap), low=0.0, high=3600.0, unit="s")
    starts = np.concatenate(([0.0], np.cumsum([p.t_end for p in pieces[:-1]] + gaps)))
    return assemble(pieces, starts, limits=limits or Limits(), name=name)


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


# --- returns between strokes: quintic moves with zero end accelerations --------------------------------------------

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
    """The shortest duration (s) of a quintic move within the limits (to 1 %), 0 for none needed, or inf."""
    if abs(start[0] - target[0]) < 1e-15 and abs(start[1]) < 1e-15 and abs(target[1]) < 1e-15:
        return 0.0
    coarse = _COARSE[_COARSE <= longest * 1.0000001] if math.isfinite(longest) else _COARSE
    ok = _fits_many(start, target, coarse, theta_max, limits) if len(coarse) else np.zeros(0, bool)
    if not ok.any():
        return math.inf
    k = int(np.argmax(ok))
    if k == 0:
        return float(coarse[0])
    fine = coarse[k - 1] * 1.01 ** np.arange(1, 24)  # 1.01**23 > 1.25
    fine = fine[fine < coarse[k]]
    ok_fine = _fits_many(start, target, fine, theta_max, limits)
    return float(fine[np.argmax(ok_fine)]) if ok_fine.any() else float(coarse[k])


def _fits(start, target, duration, theta_max, limits):
    if duration <= 0.0:
        return abs(start[0] - target[0]) < 1e-12 and abs(start[1] - target[1]) < 1e-9
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


def _impacts(s, t, omega):
    return Impacts(np.asarray(t, dtype=float), np.asarray(omega, dtype=float), s.impacts.tip_distance)


def _then(outer, inner):
    """``inner ∘ outer`` for recipe-time maps (None stays None)."""
    if inner is None:
        return None
    return lambda t: inner(outer(t))


def _derived(s, step, *, path, t_end, impacts, omega_after, recipe_time):
    return Trajectory.single(path, impacts, omega_after, theta_max=s.theta_max, t_end=t_end, rate=s.rate,
                             stick=s.sticks[0], name=s.name, model=s.model, recipe=s.recipe,
                             history=(*s.history, step), recipe_time=recipe_time)


STEPS = ("stretch", "compress", "reverse", "trim", "catch")
"""The transforms a recipe file, a palette file or the command line can name, as ``{name = value}`` steps."""


def catch(stroke, n):
    """Trim ``stroke`` at the apex after its ``n``-th impact: the hand catches the stick at the top of a rebound."""
    s = as_trajectory(stroke)
    caught = trim(s, 0.0, s.apex_after(n))
    return replace(caught, history=(*s.history, f"catch {n}"))


def apply_steps(stroke, steps, *, where="transforms"):
    """Apply transform steps in order: ``[{"catch": 2}, {"stretch": 1.5}, {"reverse": True}, {"trim": [0, 1]}]``.

    Parameters
    ----------
    stroke : Trajectory or Stroke
    steps : sequence of dict
        Each a one-key table: ``stretch`` (factor), ``compress`` (factor),
        ``reverse`` (true), ``trim`` ([start s, end s]), ``catch`` (impact number).
    where : str
        What ``steps`` is called in error messages.
    """
    s = as_trajectory(stroke)
    if not isinstance(steps, (list, tuple)):
        raise ParameterError(f"{where} must be a list of one-key tables such as {{stretch = 2.0}}, got {steps!r}")
    for i, step in enumerate(steps):
        if not isinstance(step, dict) or len(step) != 1 or next(iter(step)) not in STEPS:
            raise ParameterError(f"{where}[{i}] must be a one-key table with a key among {', '.join(STEPS)}, "
                                 f"got {step!r}")
        (op, value), = step.items()
        try:
            s = apply_step(s, op, value)
        except ParameterError as error:
            raise ParameterError(f"{where}[{i}] ({op}): {error}") from None
    return s


def apply_step(s, op, value):
    """Apply one transform named in :data:`STEPS` with its value (see :func:`apply_steps`)."""
    s = as_trajectory(s)
    if op == "stretch":
        return stretch(s, value)
    if op == "compress":
        return compress(s, value)
    if op == "reverse":
        if value is not True:
            raise ParameterError(f"reverse must be true, got {value!r}")
        return reverse(s)
    if op == "catch":
        return catch(s, value)
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise ParameterError(f"trim must be [start, end] in s, got {value!r}")
    return trim(s, value[0], value[1])
