"""A simulated stroke and the function that makes one.

Examples
--------
>>> stroke = simulate("free-bounce")
>>> stroke.model
'paper'
>>> round(float(stroke.impacts.t[0]), 6)
0.225986
>>> t, theta, omega = stroke.sample(1000.0)
>>> len(t), bool(theta.min() >= stroke.recipe.theta_max)
(5001, True)
"""

import math
from collections.abc import Sequence
from dataclasses import dataclass
from numbers import Real
from pathlib import Path

import numpy as np

from ._checks import check_choice, check_real, did_you_mean
from ._version import __version__
from .errors import ParameterError, SimulationError
from .model import MODELS, Stick, coefficients
from .presets import PRESETS, preset
from .profiles import ACCELERATION_LIMIT, Constant, Profile, named
from .recipe import DEFAULT_COR, OMEGA_LIMIT, STANDARD_GRAVITY, T_END_LIMIT, Recipe
from .solver import MAX_IMPACTS, Arcs
from .solver.hybrid import solved
from .trajectory import DEFAULT_RATE, LEVEL_REFERENCE, Impacts, Trajectory


@dataclass(frozen=True, repr=False)
class Stroke:
    """The result of one simulation.

    Attributes
    ----------
    recipe : Recipe
        What made it.
    impacts : Impacts
    rests : ndarray [shape=(r, 2)]
        Start and end (s) of each time the stick lies on the head.
    arcs : Arcs
        The exact trajectory; use :meth:`sample` or :meth:`state` to read it.
    """

    recipe: Recipe
    impacts: Impacts
    rests: np.ndarray
    arcs: Arcs

    @classmethod
    def _of(cls, recipe, impacts, rests, arcs):
        """The Stroke of these fields, made without the frozen dataclass's ``__init__`` (which sets each field by
        ``object.__setattr__``: 0.2 µs of a 5-µs stroke); the same object."""
        stroke = object.__new__(cls)
        fields = stroke.__dict__
        fields["recipe"], fields["impacts"], fields["rests"], fields["arcs"] = recipe, impacts, rests, arcs
        return stroke

    @property
    def model(self):
        """The model that made the stroke, ``"paper"`` or ``"geometry"``."""
        return self.recipe.model

    @property
    def name(self):
        """The recipe's name, or ``"custom"``."""
        return self.recipe.name or "custom"

    @property
    def t_end(self):
        """Duration (s)."""
        return self.recipe.t_end

    @property
    def rest_time(self):
        """When the stick comes to rest for good (s), or None if it still moves at ``t_end``.

        For constant forcing with c < 1 this is the accumulation time of the
        bounces. A stick that rests and lifts off again (un-natural profiles) has
        the start of its last rest here, if that rest lasts to ``t_end``; all
        rests are in :attr:`rests`.
        """
        if len(self.rests) and self.rests[-1, 1] >= self.t_end:
            return float(self.rests[-1, 0])
        return None

    def __repr__(self):
        rest = "still moving at t_end" if self.rest_time is None else f"at rest from {self.rest_time:.6g} s"
        return (f"Stroke({self.name!r}, model={self.model!r}, {len(self.impacts)} impacts over [0, {self.t_end:g}] s, "
                f"{rest})")

    def state(self, t):
        """θ (rad) and ω (rad/s) at times ``t`` (s) in [0, t_end], exact.

        At an impact time, the state just after the impact.
        """
        try:
            t = np.asarray(t, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(f"t must be times in [0, {self.t_end:g}] s, got {t!r}") from None
        within = (t >= 0.0) & (t <= self.t_end)  # False for NaN and ±inf too, as t_end is finite
        if not within.all():  # one method: numpy's functions cost more than the check on a planner's single times
            bad = t[~within].flat[0]
            raise ParameterError(f"t must be in [0, {self.t_end:g}] s, got {float(bad)!r}")
        return self.arcs.evaluate(t)

    def sample(self, rate=DEFAULT_RATE):
        """The stroke as a :class:`~drumstroke.trajectory.Trajectory` at ``rate`` samples per second.

        Exact at each sample time (it reads the solver's arcs). It unpacks as its columns,
        ``t, theta, omega = stroke.sample(rate)``: t = k/rate for k = 0, 1, … up to
        ``t_end`` (s), θ (rad, never below the head), ω (rad/s).

        Parameters
        ----------
        rate : float in (0, 1e6]
            Hz.

        Returns
        -------
        Trajectory
        """
        trajectory = Trajectory.from_stroke(self, rate=rate)
        len(trajectory)  # refuses too many samples now, not when they are read
        return trajectory

    def to_dict(self):
        """The stroke as plain data for JSON: model, recipe, impacts, rests."""
        impacts = self.impacts
        return {
            "drumstroke": __version__,
            "model": self.model,
            "recipe_name": self.recipe.name,
            "recipe": self.recipe.to_dict(),
            "t_end": self.t_end,
            "theta_max": self.recipe.theta_max,
            "level_reference": {"quantity": "tip speed", "value": LEVEL_REFERENCE, "unit": "m/s"},
            "impacts": [
                {"t": float(t), "omega": float(w), "tip_speed": float(v), "level_db": float(db)}
                for t, w, v, db in zip(impacts.t, impacts.omega, impacts.tip_speed, impacts.level_db)
            ],
            "rest_time": self.rest_time,
            "rests": self.rests.tolist(),
        }


def simulate(
    recipe=None,
    *,
    force=None,
    gravity=None,
    model=None,
    t_end=None,
    theta0=None,
    omega0=None,
    cor=None,
    stick=None,
    method="auto",
    progress=None,
):
    """Simulate one stroke.

    Parameters
    ----------
    recipe : Recipe, str, Path or None
        A recipe, a preset name (see :func:`drumstroke.presets`) or a path to
        a TOML recipe. None starts from the defaults with no thumb force.
    force, gravity : Profile or float, optional
        Replace a(t) or g(t) (m/s²); a number means a constant.
    model : {"paper", "geometry"}, optional
    t_end : float in [1e-6, 3600], optional
        s.
    theta0 : float in [theta_max, pi/2), optional
        rad.
    omega0 : float in [-1000, 1000], optional
        rad/s.
    cor : float in [0, 1], optional
    stick : Stick, optional
    method : {"auto", "taylor"}
        "taylor" integrates every flight numerically instead of using the
        closed forms (a cross-check; slower).
    progress : callable or None
        Called now and then with the fraction done, in [0, 1].

    Returns
    -------
    Stroke
    """
    check_choice("method", method, ("auto", "taylor"))
    base = resolve(recipe)
    recipe = base
    if not (force is None and gravity is None and model is None and t_end is None and theta0 is None
            and omega0 is None and cor is None and stick is None):  # (a generator over them cost 0.4 µs a stroke)
        changes = {
            "force": _as_profile("force", force),
            "gravity": _as_profile("gravity", gravity),
            "model": model,
            "t_end": t_end,
            "theta0": theta0,
            "omega0": omega0,
            "cor": cor,
            "stick": stick,
        }
        recipe = base.replace(**{key: value for key, value in changes.items() if value is not None})
    arcs, impact_t, impact_omega, rests = solved(recipe.coefficients, recipe.force, recipe.gravity, recipe.theta0,
                                                 recipe.omega0, recipe.cor, recipe.t_end, method, progress)
    return Stroke._of(recipe, Impacts._of(impact_t, impact_omega, recipe.stick.pivot_to_tip), rests, arcs)


def as_trajectory(source, *, rate=None):
    """A one-stick :class:`~drumstroke.trajectory.Trajectory` from a Trajectory or a Stroke (exact).

    Parameters
    ----------
    source : Trajectory or Stroke
    rate : float in (0, 1e6] or None
        Hz; default a Trajectory's own, a Stroke's :data:`~drumstroke.trajectory.DEFAULT_RATE`.
    """
    if isinstance(source, Stroke):
        return source.sample(DEFAULT_RATE if rate is None else rate)
    if isinstance(source, Trajectory):
        if len(source.sticks) != 1:
            raise ParameterError(f"stroke must be a one-stick trajectory; this one has the sticks "
                                 f"{', '.join(source.sticks)}: pick one with trajectory.stick(name)")
        return source.sample(rate)
    raise ParameterError(f"stroke must be a drumstroke Stroke or Trajectory, got {source!r}")


def resolve(recipe):
    """A :class:`Recipe` from a recipe, a preset name, a TOML path, or None (no thumb force)."""
    if recipe is None:
        return Recipe(force=Constant(0.0))
    if isinstance(recipe, Recipe):
        return recipe
    if isinstance(recipe, str) and recipe in PRESETS:
        return preset(recipe)
    if isinstance(recipe, (str, Path)):
        path = Path(recipe)
        if path.suffix == ".toml" or path.exists():
            return Recipe.from_toml(path)
        raise ParameterError(
            f"recipe must be a preset name ({', '.join(PRESETS)}) or a .toml file, got {str(recipe)!r}"
            + did_you_mean(recipe, PRESETS)
            + "; a stroke of the shipped palette (e.g. 'double') is made by drumstroke.make_stroke"
        )
    raise ParameterError(f"recipe must be a Recipe, a preset name or a path, got {recipe!r}")


def _as_profile(name, value):
    if value is None or isinstance(value, Profile):
        return value
    if isinstance(value, Real) and not isinstance(value, bool):
        with named(name, Constant.kind):
            return Constant(value)
    raise ParameterError(f"{name} must be a profile or a number (m/s^2), got {value!r}")


@dataclass(frozen=True, repr=False)
class Batch:
    """The results of :func:`simulate_many`, stroke by stroke.

    Attributes
    ----------
    recipes : sequence of Recipe
        What made each stroke. From parameter arrays each is built when read.
    impacts : sequence of Impacts
        Each stroke's, built when read (views into the batch's arrays).
    rest_time : ndarray [shape=(n,)]
        When each stroke comes to rest for good (s); NaN where it is still moving at t_end.
    trajectories : tuple of (t, theta, omega) or None
        Sampled at the requested rate, if one was.
    """

    recipes: Sequence
    impacts: Sequence
    rest_time: np.ndarray
    trajectories: tuple | None

    def __len__(self):
        return len(self.impacts)

    def __repr__(self):
        sampled = f"sampled at {self.trajectories[0].rate:g} Hz" if self.trajectories else "not sampled"
        return (f"Batch({len(self)} strokes, {sum(len(i) for i in self.impacts)} impacts, "
                f"{int(np.sum(~np.isnan(self.rest_time)))} at rest by t_end; {sampled})")


class _BatchImpacts(Sequence):
    """Each stroke's Impacts, built when read: views into the compiled batch's flat arrays.

    Stroke i's are ``t[start[i]:end[i]]`` and ``omega[start[i]:end[i]]``, or ``others[i]`` for
    a stroke simulated on its own.
    """

    def __init__(self, t, omega, start, end, tips, others):
        self._t, self._omega, self._start, self._end, self._tips, self._others = t, omega, start, end, tips, others

    def __len__(self):
        return len(self._start)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return tuple(self[j] for j in range(*i.indices(len(self))))
        i = range(len(self))[i]  # (negative indices; IndexError past the end)
        if i in self._others:
            return self._others[i]
        start, end = self._start[i], self._end[i]
        return Impacts(self._t[start:end], self._omega[start:end], self._tips[i])


class _Recipes(Sequence):
    """Recipes of strokes simulated from parameter arrays, each built when read."""

    def __init__(self, parameters, model, stick):
        self._parameters, self._model, self._stick = parameters, model, stick

    def __len__(self):
        return len(self._parameters["theta0"])

    def __getitem__(self, i):
        if isinstance(i, slice):
            return tuple(self[j] for j in range(*i.indices(len(self))))
        p = {key: float(values[i]) for key, values in self._parameters.items()}
        return Recipe(force=Constant(p.pop("force")), gravity=Constant(p.pop("gravity")), model=self._model,
                      stick=self._stick, **p)


_ARRAY_DEFAULTS = {"force": 0.0, "gravity": STANDARD_GRAVITY, "theta0": 0.0, "omega0": 0.0, "cor": DEFAULT_COR,
                   "t_end": 5.0}


def simulate_many(recipes=None, *, rate=None, force=None, gravity=None, theta0=None, omega0=None, cor=None,
                  t_end=None, model="paper", stick=None):
    """Simulate many strokes; those with constant forcing in one compiled pass on every core.

    Give either ``recipes`` or parameter arrays of strokes under constant forcing
    (numbers or arrays, broadcast together; unnamed ones take a recipe's defaults).

    Parameters
    ----------
    recipes : sequence of Recipe, preset names or paths, optional
    rate : float in (0, 1e6] or None
        Hz. If given, each stroke's trajectory is sampled too (stroke by stroke).
    force, gravity : float or ndarray, optional
        Constant a and g (m/s², |value| ≤ 1e6); defaults 0 and 9.8.
    theta0 : float or ndarray in [theta_max, pi/2), optional
        rad; default 0.
    omega0 : float or ndarray in [-1000, 1000], optional
        rad/s; default 0.
    cor : float or ndarray in [0, 1], optional
        Default 0.86.
    t_end : float or ndarray in [1e-6, 3600], optional
        s; default 5.
    model : {"paper", "geometry"}
        For parameter arrays.
    stick : Stick, optional
        For parameter arrays; default Table 1's.

    Returns
    -------
    Batch
        Impacts and rest times equal to :func:`simulate`'s, stroke by stroke.

    Examples
    --------
    >>> batch = simulate_many(cor=[0.5, 0.86, 0.95], force=100.0)
    >>> [len(impacts) for impacts in batch.impacts]
    [22, 101, 38]
    >>> batch.recipes[1].model
    'paper'
    """
    arrays = {"force": force, "gravity": gravity, "theta0": theta0, "omega0": omega0, "cor": cor, "t_end": t_end}
    named = [key for key, value in arrays.items() if value is not None]
    if recipes is not None and named:
        raise ParameterError(f"give recipes or parameter arrays, not both (got recipes and {named[0]})")
    if recipes is None:
        if not named:
            raise ParameterError("simulate_many needs recipes or at least one parameter array (e.g. force=...)")
        check_choice("model", model, MODELS)
        stick = Stick() if stick is None else stick
        if not isinstance(stick, Stick):
            raise ParameterError(f"stick must be a Stick, got {stick!r}")
        parameters = _parameter_arrays(arrays, stick.theta_max)
        recipes = _Recipes(parameters, model, stick)
        constant = np.ones(len(recipes), dtype=bool)
        c = coefficients(model, stick).torque_rate(parameters["gravity"], parameters["force"])
        columns = [parameters[key] for key in ("theta0", "omega0", "cor")] + [c, np.full(len(c), stick.theta_max),
                                                                             parameters["t_end"]]
        tips = [stick.pivot_to_tip] * len(c)
    else:
        recipes = tuple(resolve(r) for r in recipes)
        constant = np.array([isinstance(r.force, Constant) and isinstance(r.gravity, Constant) for r in recipes],
                            dtype=bool)
        chosen = [r for r, flag in zip(recipes, constant) if flag]
        columns = [[r.theta0 for r in chosen], [r.omega0 for r in chosen], [r.cor for r in chosen],
                   [r.coefficients.torque_rate(r.gravity.value, r.force.value) for r in chosen],
                   [r.theta_max for r in chosen], [r.t_end for r in chosen]]
        tips = [r.stick.pivot_to_tip for r in chosen]
    if rate is not None:
        strokes = [simulate(r) for r in recipes]
        return Batch(recipes, tuple(s.impacts for s in strokes), np.array([_rest_or_nan(s) for s in strokes]),
                     tuple(s.sample(rate) for s in strokes))
    return _constant_batch(recipes, constant, columns, tips)


def _parameter_arrays(arrays, theta_max):
    """The parameter arrays broadcast together and checked; an error names the parameter, index and value."""
    limits = {
        "force": (-ACCELERATION_LIMIT, ACCELERATION_LIMIT, "m/s^2"),
        "gravity": (-ACCELERATION_LIMIT, ACCELERATION_LIMIT, "m/s^2"),
        "theta0": (theta_max, math.pi / 2, "rad (theta_max to pi/2)"),
        "omega0": (-OMEGA_LIMIT, OMEGA_LIMIT, "rad/s"),
        "cor": (0.0, 1.0, ""),
        "t_end": (1e-6, T_END_LIMIT, "s"),
    }
    values = {}
    for key, value in arrays.items():
        value = _ARRAY_DEFAULTS[key] if value is None else value
        try:
            values[key] = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(f"{key} must be a number or an array of numbers, got {value!r}") from None
    try:
        shape = np.broadcast_shapes(*(v.shape for v in values.values()))
    except ValueError:
        shapes = ", ".join(f"{k} {v.shape}" for k, v in values.items())
        raise ParameterError(f"the parameter arrays must broadcast together, got {shapes}") from None
    out = {}
    for key, value in values.items():
        low, high, unit = limits[key]
        flat = np.broadcast_to(value, shape).ravel()
        bad = ~np.isfinite(flat) | (flat < low) | (flat > high) | ((flat >= high) if key == "theta0" else False)
        if np.any(bad):
            i = int(np.flatnonzero(bad)[0])
            check_real(f"{key}[{i}]", float(flat[i]), low=low, high=high, high_open=key == "theta0", unit=unit)
        out[key] = np.ascontiguousarray(flat)
    return out


def _constant_batch(recipes, constant, columns, tips):
    """Strokes with constant forcing through the compiled batch kernel, the rest (and its refusals) one by one.

    ``columns`` are the kernel's inputs and ``tips`` the tip distances (m) of the strokes flagged ``constant``.
    """
    from .solver.batch import OK, TOO_MANY, constant_batch

    index = np.flatnonzero(constant)
    rest = np.full(len(recipes), np.nan)
    start, end = np.zeros(len(recipes), dtype=np.int64), np.zeros(len(recipes), dtype=np.int64)
    tip = np.zeros(len(recipes))
    t = omega = np.empty(0)
    done = np.zeros(len(recipes), dtype=bool)
    if len(index):
        status, offsets, count, t, omega, rests = constant_batch(*columns, max_impacts=MAX_IMPACTS)
        if np.any(status == TOO_MANY):
            i = int(index[np.flatnonzero(status == TOO_MANY)[0]])
            raise SimulationError(
                f"stroke {i} has more than {MAX_IMPACTS} impacts; shorten t_end or lower cor (now {recipes[i].cor:g})"
            )
        ok = status == OK
        done[index[ok]] = True
        rest[index[ok]] = rests[ok]
        start[index], end[index], tip[index] = offsets[:-1], offsets[:-1] + count, tips
    others = {}
    for i in np.flatnonzero(~done).tolist():  # not constant forcing, or outside the kernel's reach
        try:
            stroke = simulate(recipes[i])
        except SimulationError as error:
            raise SimulationError(f"stroke {i}: {error}") from None
        others[i], rest[i] = stroke.impacts, _rest_or_nan(stroke)
    return Batch(recipes, _BatchImpacts(t, omega, start.tolist(), end.tolist(), tip.tolist(), others), rest, None)


def _rest_or_nan(stroke):
    return np.nan if stroke.rest_time is None else stroke.rest_time
