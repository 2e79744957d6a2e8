"""Sweeps: one row of stroke features per point of a grid or a random sample of recipe parameters.

A sweep file (TOML) names a base recipe and the parameters to vary::

    base = "free-bounce"      # a preset, or a recipe file (relative to this file)
    mode = "grid"             # every combination; or "random": `samples` points
    audible_db = 40.0         # impacts within this many dB of the loudest are audible
    [parameters]
    cor = [0.6, 0.75, 0.86]                         # these values
    theta0 = { start = 0.0, stop = 0.5, num = 3 }   # evenly spaced, both ends included
    "force.value" = [0.0, 100.0]                    # a field of the base's force table
    model = ["paper", "geometry"]

For ``mode = "random"`` also give ``samples`` (points) and ``seed``; a parameter
is then a list (drawn uniformly from it) or ``{ low = …, high = … }`` (uniform
in [low, high), or log-uniform with ``log = true``).

Parameters are a recipe's keys (``model``, ``t_end``, ``theta0``, ``omega0``,
``cor``), whole profiles (``force``, ``gravity``: a list of tables such as
``{ kind = "pulses", amplitude = 189.0, period = 0.4, duty = 0.05 }``), or one
field of the base's tables (``force.value``, ``force.amplitude``,
``gravity.value``, ``stick.pivot_to_tip``, …). Whole profiles are set before
their fields.

Examples
--------
>>> grid = Grid.from_dict({"base": "free-bounce", "parameters": {"cor": [0.5, 0.86]}})
>>> table = run_sweep(grid)
>>> [round(float(d), 4) for d in table["decay_db_per_bounce"]]  # −20·log10(c)
[6.0206, 1.31]
"""

import itertools
import json
import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ._checks import check_choice, check_keys, check_real
from .budget import check_memory, check_time, sweep_cost
from .errors import ParameterError, SimulationError
from .formats.toml import reading_toml
from .recipe import Recipe
from .stroke import resolve, simulate, simulate_many

MODES = ("grid", "random")
MAX_POINTS = 10_000_000
"""Most points one sweep may have."""

FEATURES = (
    "impacts",
    "audible_impacts",
    "first_impact_time_s",
    "first_impact_speed_m_s",
    "duration_s",
    "mean_bounce_rate_hz",
    "final_bounce_rate_hz",
    "decay_db_per_bounce",
    "rest_time_s",
)
"""The features of each stroke, in the table's order (see :func:`stroke_features`)."""

UNITS = {"first_impact_time_s": "s", "first_impact_speed_m_s": "m/s", "duration_s": "s", "mean_bounce_rate_hz": "Hz",
         "final_bounce_rate_hz": "Hz", "decay_db_per_bounce": "dB", "rest_time_s": "s"}
"""The units of the features that have one (counts, the model and the error have none)."""
_RECIPE_UNITS = {"t_end": "s", "theta0": "rad", "omega0": "rad/s"}

_RECIPE_KEYS = ("model", "t_end", "theta0", "omega0", "cor")
_TABLES = ("force", "gravity", "stick")
_TOP_KEYS = ("base", "mode", "samples", "seed", "audible_db", "parameters")
_CHUNK = 1000  # most points per chunk


@dataclass(frozen=True)
class Grid:
    """What a sweep explores.

    Attributes
    ----------
    base : Recipe
        The recipe every point starts from.
    parameters : dict
        Parameter name → the values to take (grid) or a ``{low, high, log}``
        range or list of values to draw from (random).
    mode : {"grid", "random"}
    samples : int
        Points drawn in random mode.
    seed : int
        The random generator's seed (random mode).
    audible_db : float in (0, 200]
        dB below a stroke's loudest impact that still count as audible.
    source : str
        The file the sweep was read from, for messages ("" when made otherwise).
    """

    base: Recipe
    parameters: dict
    mode: str = "grid"
    samples: int = 0
    seed: int = 0
    audible_db: float = 40.0
    source: str = ""

    def __post_init__(self):
        check_choice("mode", self.mode, MODES)
        object.__setattr__(self, "audible_db", check_real("audible_db", self.audible_db, low=0.0, high=200.0,
                                                          low_open=True, unit="dB"))
        if not isinstance(self.parameters, dict) or not self.parameters:
            raise ParameterError(f"parameters must be a table naming at least one parameter, got {self.parameters!r}")
        for name, spec in self.parameters.items():
            _check_name(name)
            _values(name, spec, self.mode, count=True)  # validates the spec
        if self.mode == "random":
            for key, value, low in (("samples", self.samples, 1), ("seed", self.seed, 0)):
                if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= 2**63 - 1:
                    raise ParameterError(f"{key} must be an integer in [{low}, 2**63 - 1], got {value!r}")
        if len(self) > MAX_POINTS:
            raise ParameterError(f"the sweep has {len(self)} points; at most {MAX_POINTS} are allowed")

    def __len__(self):
        if self.mode == "random":
            return self.samples
        return math.prod(_values(name, spec, "grid", count=True) for name, spec in self.parameters.items())

    @classmethod
    def from_dict(cls, data, *, base_dir=None):
        """A grid from plain data (as read from TOML); ``base_dir`` anchors a ``base`` recipe file."""
        if not isinstance(data, dict):
            raise ParameterError(f"a sweep must be a table, got {data!r}")
        check_keys("sweep", data, _TOP_KEYS)
        if "parameters" not in data:
            raise ParameterError("sweep needs a [parameters] table naming what to vary")
        base = data.get("base")
        if isinstance(base, str) and base_dir is not None and base.endswith(".toml"):
            base = Path(base_dir) / base
        options = {key: data[key] for key in ("mode", "samples", "seed", "audible_db") if key in data}
        return cls(base=resolve(base), parameters=data["parameters"], **options)

    @classmethod
    def from_toml(cls, path):
        """Read a sweep file."""
        path = Path(path)
        with reading_toml(path, "sweep") as data:
            return replace(cls.from_dict(data, base_dir=path.parent), source=str(path))

    def points(self):
        """Each point as a dict of parameter name → value, in the table's order."""
        names = list(self.parameters)
        if self.mode == "grid":
            lists = [_values(name, self.parameters[name], "grid") for name in names]
            return [dict(zip(names, combination)) for combination in itertools.product(*lists)]
        rng = np.random.default_rng(self.seed)
        drawn = {name: _draw(self.parameters[name], rng, self.samples) for name in names}
        return [{name: drawn[name][i] for name in names} for i in range(self.samples)]

    def recipes(self, points=None):
        """The recipe of each point (validated; an error names the point and its values)."""
        base = self.base.to_dict()
        recipes = []
        for i, point in enumerate(self.points() if points is None else points):
            data = json.loads(json.dumps(base))  # a deep copy of plain data
            for name in sorted(point, key=lambda key: key.count(".")):  # whole tables before their fields
                table, _, field = name.partition(".")
                if field:
                    data[table][field] = point[name]
                else:
                    data[name] = point[name]
            try:
                recipes.append(Recipe.from_dict(data, name=f"{self.base.name or 'sweep'}-{i}"))
            except ParameterError as error:
                raise ParameterError(f"sweep point {i} ({_describe(point)}): {error}") from None
        return recipes


def stroke_features(impacts, rest_time, *, audible_db=40.0):
    """The features of one stroke, as a dict in the order of :data:`FEATURES`.

    Parameters
    ----------
    impacts : drumstroke.Impacts
    rest_time : float or None
        When the stick comes to rest for good (s).
    audible_db : float > 0
        Impacts whose level is within this many dB of the stroke's loudest are audible.

    Returns
    -------
    dict
        ``impacts``, ``audible_impacts``; the first impact's time (s) and tip speed
        (m/s); over the audible impacts: ``duration_s`` (first to last, s), the mean
        bounce rate ((n − 1)/duration, Hz), the final one (1/last interval, Hz), the
        decay per bounce (least-squares slope of the level against the impact's
        number, negated, dB); the rest time (s). NaN where a stroke has too few impacts.
    """
    features = dict.fromkeys(FEATURES, math.nan)
    features["impacts"] = len(impacts)
    features["audible_impacts"] = 0
    features["rest_time_s"] = math.nan if rest_time is None else float(rest_time)
    if not len(impacts):
        return features
    level = impacts.level_db
    audible = level >= np.max(level) - audible_db
    t, level = impacts.t[audible], level[audible]
    features.update(
        audible_impacts=int(np.count_nonzero(audible)),
        first_impact_time_s=float(impacts.t[0]),
        first_impact_speed_m_s=float(impacts.tip_speed[0]),
    )
    if len(t) >= 2:
        duration = float(t[-1] - t[0])
        features.update(
            duration_s=duration,
            mean_bounce_rate_hz=(len(t) - 1) / duration,
            final_bounce_rate_hz=1.0 / float(t[-1] - t[-2]),
            decay_db_per_bounce=-float(np.polyfit(np.arange(len(level)), level, 1)[0]),
        )
    else:
        features["duration_s"] = 0.0
    return features


def run_sweep(grid, *, scheduler=None, progress=None):
    """Simulate every point of ``grid``; one row of features per point.

    Parameters
    ----------
    grid : Grid
    scheduler : str or None
        The address of a Dask scheduler (``tcp://host:8786``) to spread the
        points over its workers; None runs here, on every core.
    progress : callable or None
        Called with the fraction of points done.

    Returns
    -------
    dict of str → ndarray
        Columns: ``point``, each parameter, ``model``, the :data:`FEATURES`, and
        ``error`` (empty, or why that point could not be simulated).
    """
    what = f"sweep {grid.source!r}" if grid.source else "the sweep"
    memory, seconds = sweep_cost(len(grid))
    check_memory(what, memory, f"{len(grid)} points")
    check_time(what, seconds, f"{len(grid)} points")
    points = grid.points()
    recipes = grid.recipes(points)
    # Here, chunks small enough for a smooth progress bar (a hundred steps); on Dask, big enough
    # to pay for a task's overhead.
    size = min(_CHUNK, max(1, math.ceil(len(recipes) / 100))) if scheduler is None else _CHUNK
    chunks = [recipes[i:i + size] for i in range(0, len(recipes), size)]
    if scheduler is None:
        rows = []
        for chunk in chunks:
            rows.extend(_rows(chunk, grid.audible_db))
            if progress is not None:
                progress(len(rows) / len(recipes))
    else:
        rows = _on_dask(scheduler, chunks, grid.audible_db, progress)
    return _columns(grid, points, recipes, rows)


def table_metadata(grid, table):
    """What the JSON beside a sweep's CSV table says of it: its columns' units, and its models and grid.

    Returns
    -------
    units : dict of str to str
        Each column's unit ("" for none: counts, text, a whole profile's table).
    fields : dict
        ``model`` ("paper", "geometry", or "mixed" when the rows have both), ``rows``, and
        ``sweep``: the base recipe's name, the mode, samples, seed, audible_db and parameters.
    """
    units = {name: _unit(name, grid.base) for name in grid.parameters} | UNITS
    models = sorted(set(table["model"]))
    sweep = {"base": grid.base.name, "mode": grid.mode, "samples": grid.samples, "seed": grid.seed,
             "audible_db": grid.audible_db, "parameters": grid.parameters}
    return units, {"model": models[0] if len(models) == 1 else "mixed", "rows": len(table["point"]), "sweep": sweep}


def _unit(name, base):
    """The unit of a parameter's values: a recipe key's, a stick's field's, or the base profile's field's."""
    table, _, field = name.partition(".")
    if not field:
        return _RECIPE_UNITS.get(name, "")
    if table == "stick":
        return "kg" if field == "mass" else "m"
    return next((p.unit for p in type(getattr(base, table)).parameters if p.name == field), "")


def _rows(recipes, audible_db):
    """Features (and an error message) of each recipe; strokes the solver refuses get NaN and the reason."""
    try:
        batch = simulate_many(recipes)
        results = [(impacts, None if math.isnan(rest) else rest, "") for impacts, rest in
                   zip(batch.impacts, batch.rest_time)]
    except SimulationError:  # find which: one at a time
        results = []
        for recipe in recipes:
            try:
                stroke = simulate(recipe)
                results.append((stroke.impacts, stroke.rest_time, ""))
            except SimulationError as error:
                results.append((None, None, str(error)))
    rows = []
    for impacts, rest, error in results:
        if impacts is None:
            features = dict.fromkeys(FEATURES, math.nan)
        else:
            features = stroke_features(impacts, rest, audible_db=audible_db)
        rows.append((features, error))
    return rows


def _on_dask(address, chunks, audible_db, progress):
    try:
        from dask.distributed import Client, as_completed
    except ImportError:
        raise ImportError("--scheduler needs Dask: pip install 'drumstroke[sweep]'") from None
    with Client(address) as client:
        futures = client.map(_rows, chunks, audible_db=audible_db, pure=False)
        for done, _ in enumerate(as_completed(futures), start=1):
            if progress is not None:
                progress(done / len(futures))
        return [row for chunk in client.gather(futures) for row in chunk]


def _columns(grid, points, recipes, rows):
    n = len(points)
    columns = {"point": np.arange(n)}
    for name in grid.parameters:
        values = [point[name] for point in points]
        if isinstance(values[0], dict):
            values = [json.dumps(value, sort_keys=True) for value in values]
        columns[name] = np.array(values, dtype=object if isinstance(values[0], str) else float)
    columns["model"] = np.array([recipe.model for recipe in recipes], dtype=object)
    for feature in FEATURES:
        dtype = np.int64 if feature in ("impacts", "audible_impacts") else float
        values = [features[feature] for features, _ in rows]
        if dtype is np.int64 and any(isinstance(v, float) for v in values):
            dtype = float  # a failed point has NaN counts
        columns[feature] = np.array(values, dtype=dtype)
    columns["error"] = np.array([error for _, error in rows], dtype=object)
    return columns


def _check_name(name):
    table, _, field = name.partition(".")
    valid = (table in _TABLES and "." not in field) if field else name in (*_RECIPE_KEYS, "force", "gravity")
    if not valid:
        raise ParameterError(
            f"parameter {name!r} is not one a sweep can vary: use a recipe key ({', '.join(_RECIPE_KEYS)}), "
            f"a whole profile (force, gravity) or a field of a table (force.value, stick.pivot_to_tip, ...)"
        )


def _values(name, spec, mode, *, count=False):
    """The list of values of a grid parameter (with ``count``, how many: none made), or (random mode) the spec checked."""
    where = f"parameters.{name}"
    if isinstance(spec, list):
        if not spec:
            raise ParameterError(f"{where} must list at least one value, got []")
        return len(spec) if count and mode == "grid" else spec
    if not isinstance(spec, dict):
        raise ParameterError(f"{where} must be a list of values or a table, got {spec!r}")
    if mode == "grid":
        if set(spec) != {"start", "stop", "num"}:
            raise ParameterError(f"{where} in a grid must be a list or {{start, stop, num}}, got {spec!r}")
        start, stop = check_real(f"{where}.start", spec["start"]), check_real(f"{where}.stop", spec["stop"])
        num = spec["num"]
        if isinstance(num, bool) or not isinstance(num, int) or not 1 <= num <= MAX_POINTS:
            raise ParameterError(f"{where}.num must be an integer in [1, {MAX_POINTS}], got {num!r}")
        return num if count else [float(v) for v in np.linspace(start, stop, num)]
    if not {"low", "high"} <= set(spec) <= {"low", "high", "log"}:
        raise ParameterError(f"{where} in a random sweep must be a list or {{low, high[, log]}}, got {spec!r}")
    low, high = check_real(f"{where}.low", spec["low"]), check_real(f"{where}.high", spec["high"])
    if not low < high:
        raise ParameterError(f"{where}.high must be above low = {low:g}, got {high!r}")
    if spec.get("log", False) is not False:
        if spec["log"] is not True:
            raise ParameterError(f"{where}.log must be true or false, got {spec['log']!r}")
        if not low > 0.0:
            raise ParameterError(f"{where}.low must be above 0 with log = true, got {low!r}")
    return spec


def _draw(spec, rng, n):
    if isinstance(spec, list):
        return [spec[i] for i in rng.integers(0, len(spec), n)]
    low, high = float(spec["low"]), float(spec["high"])
    if spec.get("log", False):
        return [float(v) for v in np.exp(rng.uniform(math.log(low), math.log(high), n))]
    return [float(v) for v in rng.uniform(low, high, n)]


def _describe(point):
    return ", ".join(f"{name} = {value!r}" for name, value in point.items())
