"""The compiled solver's whole-stroke calls and its sampler, held to independent paths bit for bit.

A whole stroke (constant, piecewise-linear or pulsed forcing) is one compiled call that hands its arcs,
impacts, rests and Taylor steps back packed in one array; the same stroke reported with progress goes
piece by piece through :func:`drumstroke.solver.kernel.run`, its arrays returned apart and joined in
Python. The sampler carries its samples in runs side by side, split where arcs start; evaluated in parts
split at arc starts, every sample must be the same.
"""

import itertools

import numpy as np
import pytest

from drumstroke import Constant, PiecewiseLinear, Pulses, Recipe, preset, simulate
from drumstroke.errors import SimulationError
from drumstroke.presets import PRESETS
from drumstroke.solver import solve
from drumstroke.solver.constants import ELLIPTIC
from drumstroke.solver.kernel import evaluate

DURATIONS = (0.3, 1.0, 5.0, 12.0)


def _same(a, b):
    """Equal to the bit: shape, and every float's bits (NaN included)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def _random_recipes(rng, model, n):
    recipes = []
    for i in range(n):
        if i % 3 == 0:
            force = Constant(float(rng.uniform(-5.0, 250.0)))
        elif i % 3 == 1:
            force = Pulses(amplitude=float(rng.uniform(50.0, 300.0)), period=float(rng.uniform(0.1, 0.6)),
                           duty=float(rng.uniform(0.02, 0.5)), phase=float(rng.uniform(0.0, 0.3)))
        else:
            points = zip(np.sort(rng.uniform(0.0, 2.0, 4)).tolist(), rng.uniform(0.0, 200.0, 4).tolist())
            force = PiecewiseLinear(tuple(points))
        recipes.append(Recipe(force=force, theta0=float(rng.uniform(-0.26, 0.8)), omega0=float(rng.uniform(-8, 8)),
                              cor=float(rng.uniform(0.3, 0.97)), t_end=float(rng.choice([0.5, 2.0, 5.0])),
                              model=model))
    return recipes


def _cases(rng):
    for model in ("paper", "geometry"):
        for name in PRESETS:
            for t_end in DURATIONS:
                yield preset(name).replace(t_end=t_end, model=model)
        yield from _random_recipes(rng, model, 40)


def _solved(recipe, progress):
    try:
        return solve(recipe.coefficients, recipe.force, recipe.gravity, theta0=recipe.theta0, omega0=recipe.omega0,
                     cor=recipe.cor, t_end=recipe.t_end, progress=progress)
    except SimulationError as error:
        return str(error)


def test_a_whole_stroke_equals_its_pieces_bit_for_bit(rng):
    reported = []
    whole_calls = pieces = 0
    for recipe in _cases(rng):
        whole, apart = _solved(recipe, None), _solved(recipe, reported.append)
        if isinstance(whole, str):
            assert whole == apart
            continue
        whole_calls += 1
        pieces += len(apart.arcs.taylor) > 0
        for field in ("impact_t", "impact_omega", "rests"):
            assert _same(getattr(whole, field), getattr(apart, field)), (recipe, field)
        assert _same(whole.arcs.table, apart.arcs.table), recipe
        assert _same(whole.arcs.taylor, apart.arcs.taylor), recipe
        assert whole.arcs.taylor.shape[1:] == apart.arcs.taylor.shape[1:]
        stroke = simulate(recipe)  # what simulate hands out: the same arrays
        assert _same(stroke.impacts.t, whole.impact_t) and _same(stroke.impacts.omega, whole.impact_omega)
        assert _same(stroke.rests, whole.rests) and _same(stroke.arcs.table, whole.arcs.table)
    assert whole_calls > 100 and pieces > 5  # (strokes with Taylor steps among them)


@pytest.mark.parametrize("name", ["free-bounce", "finger-pulses", "low-high", "high-low"])
@pytest.mark.parametrize("rate", [1000.0, 977.0, 44100.0])
def test_samples_do_not_depend_on_where_the_runs_split(name, rate, rng):
    """Evaluated in parts cut where arcs start, every sample is the whole grid's but each part's last, which a
    part computes afresh (its spacing to the next is unknown to it) where the whole grid carries it."""
    arcs = simulate(name, t_end=2.0).arcs
    t = np.arange(int(2.0 * rate) + 1) / rate
    whole = evaluate(arcs.table, arcs.taylor, arcs.theta_max, t, 1.0 / rate)
    starts = np.searchsorted(t, arcs.table[arcs.table[:, 1] == ELLIPTIC, 0])
    starts = np.unique(starts[(starts > 1) & (starts < len(t))])
    for _ in range(5):
        cuts = np.concatenate(([0], np.sort(rng.choice(starts, size=min(6, len(starts)), replace=False)), [len(t)]))
        kept = np.ones(len(t), dtype=bool)
        kept[cuts[1:-1] - 1] = False
        parts = [evaluate(arcs.table, arcs.taylor, arcs.theta_max, t[a:b], 1.0 / rate)
                 for a, b in itertools.pairwise(cuts)]
        assert _same(whole[:, kept], np.concatenate(parts, axis=1)[:, kept])
