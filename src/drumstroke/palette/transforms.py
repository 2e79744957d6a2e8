"""Post-processing of strokes (paper §3.5): stretch, compress, reverse, trim, catch.

Each transform takes a :class:`~drumstroke.trajectory.Trajectory` (or a
:class:`~drumstroke.Stroke`, taken exactly) and returns a new one whose impacts
agree with its curve: θ = θ_max at every impact time.

- ``stretch(s, f)``: θ'(t) = θ(t/f). Impact times ×f, speeds ÷f.
- ``compress(s, f)``: θ' = θ_max + f·(θ − θ_max), the excursion above the head
  scaled; speeds ×f, times unchanged. The dynamic level moves by 20·log10 f dB.
- ``reverse(s)``: θ'(t) = θ(T − t). Times mirrored; each impact's speeds before
  and after swap, so a reversed bounce gains energy (1/c) — an un-natural stroke.
- ``trim(s, t0, t1)``: the part in [t0, t1], starting at 0.
- ``catch(s, n)``: end at the apex after impact n (the hand catches the stick).

Joining strokes (``concat``) and the moves between them are :mod:`.motion`'s.

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
from dataclasses import replace

import numpy as np

from .._checks import check_real
from ..errors import ParameterError
from ..stroke import as_trajectory
from ..trajectory import THETA_TOP, Impacts, Trajectory

STRETCH_LIMIT = 100.0
"""Largest stretch factor (and 1/smallest)."""


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


def compress_limit(stroke, top=THETA_TOP):
    """The largest compress factor that keeps ``stroke`` at or below ``top`` (rad; default upright, π/2)."""
    s = as_trajectory(stroke)
    top = check_real("top", top, low=s.theta_max, high=THETA_TOP, low_open=True, unit="rad")
    excursion = s.peak - s.theta_max
    return math.inf if excursion <= 0.0 else (top - s.theta_max) / excursion


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
