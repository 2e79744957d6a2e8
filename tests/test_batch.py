"""simulate_many equals simulate, stroke by stroke."""

import numpy as np
import pytest

import drumstroke
from drumstroke import Recipe, Stick


def _random_constant_recipes(rng, n):
    theta_max = Stick().theta_max
    recipes = []
    for _ in range(n):
        recipes.append(Recipe(
            force=drumstroke.Constant(float(rng.choice([0.0, rng.uniform(0, 250), rng.uniform(250, 3000)]))),
            model=str(rng.choice(["paper", "geometry"])),
            theta0=float(rng.choice([theta_max, rng.uniform(theta_max, 0.6)])),
            omega0=float(rng.choice([0.0, rng.uniform(-5, 5)])),
            cor=float(rng.choice([0.0, 1.0, rng.uniform(0, 1), rng.uniform(0.9, 0.999)])),
            t_end=float(rng.uniform(0.5, 10.0)),
        ))
    return recipes


def _simulates(recipe):
    try:
        drumstroke.simulate(recipe)
    except drumstroke.SimulationError:
        with pytest.raises(drumstroke.SimulationError, match="vertical"):
            drumstroke.simulate_many([recipe])  # the batch refuses it too
        return False
    return True


def test_batch_equals_one_at_a_time_on_random_constant_forcing(rng):
    recipes = [r for r in _random_constant_recipes(rng, 300) if _simulates(r)]
    assert len(recipes) > 250
    batch = drumstroke.simulate_many(recipes)
    assert len(batch) == len(recipes)
    for recipe, impacts, rest in zip(recipes, batch.impacts, batch.rest_time):
        single = drumstroke.simulate(recipe)
        assert len(impacts) == len(single.impacts), recipe
        np.testing.assert_allclose(impacts.t, single.impacts.t, rtol=0, atol=1e-12)
        np.testing.assert_allclose(impacts.omega, single.impacts.omega, rtol=1e-12, atol=1e-15)
        if single.rest_time is None:
            assert np.isnan(rest)
        else:
            assert rest == pytest.approx(single.rest_time, abs=1e-12)


def test_batch_mixes_kernel_and_general_strokes():
    names = ["free-bounce", "low-high", "constant", "finger-pulses", "reversed-gravity"]
    batch = drumstroke.simulate_many(names)
    for name, impacts in zip(names, batch.impacts):
        np.testing.assert_allclose(impacts.t, drumstroke.simulate(name).impacts.t, rtol=0, atol=1e-12)


def test_trajectories_on_request():
    batch = drumstroke.simulate_many(["free-bounce", "constant"], rate=100.0)
    t, theta, omega = batch.trajectories[1]
    assert len(t) == 501 and np.array_equal(theta, drumstroke.simulate("constant").sample(100.0)[1])
