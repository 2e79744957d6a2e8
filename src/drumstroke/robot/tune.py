"""Formal tuning: gains that keep the most reference onsets, found by an optimiser over a set of strokes.

The objective, to minimise over the strokes together (one gain set) or one
stroke at a time (gain scheduling: one set per stroke)::

    missed onsets / reference onsets  +  0.1 · mean |timing error| / window  +  0.01 · RMS error / 1 rad

— the count of onsets kept decides, the timing and the tracking error break ties
and give the search a slope. scipy's Nelder–Mead searches each gain on the scale its
controller declares (:class:`drumstroke.robot.controllers.Gain`: the logarithm of a
positive gain, the logit of a fraction, a time in ms), from the controller's current gains.
"""

from dataclasses import dataclass, replace

import numpy as np

from .._checks import check_int
from ..errors import ParameterError
from .controllers import declared_gains
from .metrics import WINDOW, metrics
from .track import track


@dataclass(frozen=True)
class Tuned:
    """The result of :func:`tune`.

    Attributes
    ----------
    controllers : tuple
        The tuned controller for each stroke (all the same unless per stroke).
    before, after : tuple of Metrics
        Each stroke's metrics with the starting and the tuned gains.
    evaluations : int
        How many times the strokes were played.
    """

    controllers: tuple
    before: tuple
    after: tuple
    evaluations: int


def score(references, controller, plant=None):
    """The objective (see the module docstring) and the metrics of each stroke (Trajectories at the control rate)."""
    results = [metrics(track(ref, controller, plant)) for ref in references]
    total = sum(m.reference_onsets for m in results)
    kept = sum(m.kept for m in results)
    timing = [m.timing_mean for m in results if m.kept]
    value = (1.0 - kept / total if total else 0.0) + 0.1 * (float(np.mean(timing)) / WINDOW if timing else 1.0)
    value += 0.01 * float(np.mean([m.rms_error for m in results]))
    return value, results


def tune(references, controller, *, plant=None, per_stroke=False, evaluations=150, progress=None):
    """Tune ``controller``'s declared gains on ``references`` (Trajectories at the control rate, :func:`reference`).

    Parameters
    ----------
    references : sequence of Trajectory
    controller : Controller
        Where the search starts; every gain it declares is searched.
    plant : Plant, optional
    per_stroke : bool
        One gain set per stroke (scheduling) instead of one for all.
    evaluations : int in [1, 10000]
        Objective evaluations per optimisation.
    progress : callable or None
        Called with the fraction done.
    """
    from scipy.optimize import minimize

    references = list(references)
    if not references:
        raise ParameterError("references must hold at least one stroke")
    check_int("evaluations", evaluations, low=1, high=10000)
    groups = [[r] for r in references] if per_stroke else [references]
    declared = declared_gains(controller)
    tuned, count = [], 0
    for g, group in enumerate(groups):
        def objective(x, group=group):
            nonlocal count
            count += 1
            try:
                candidate = _from_vector(controller, declared, x)
            except ParameterError:
                return 10.0
            return score(group, candidate, plant)[0]

        start = _to_vector(controller, declared)
        simplex = np.vstack([start, start + 0.5 * np.eye(len(start))])  # steps of ×1.65 (0.5 ms for lead)
        best = minimize(objective, start, method="Nelder-Mead",
                        options={"maxfev": evaluations, "xatol": 1e-3, "fatol": 1e-6, "initial_simplex": simplex})
        found = _from_vector(controller, declared, best.x)
        if score(group, found, plant)[0] > score(group, controller, plant)[0]:
            found = controller  # never worse than where it started
        tuned.extend([found] * len(group))
        if progress:
            progress((g + 1) / len(groups))
    before = tuple(metrics(track(r, controller, plant)) for r in references)
    after = tuple(metrics(track(r, c, plant)) for r, c in zip(references, tuned))
    return Tuned(tuple(tuned), before, after, count)


def _to_vector(controller, declared):
    return np.array([gain.to_search(getattr(controller, name)) for name, gain in declared.items()])


def _from_vector(controller, declared, x):
    return replace(controller, **{name: gain.from_search(v) for (name, gain), v in zip(declared.items(), x)})
