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
    assert len(t) == 501 and np.array_equal(theta, drumstroke.simulate("constant").sample(100.0).theta)


def test_parameter_arrays_equal_the_recipes_they_describe(rng):
    n = 400
    theta_max = Stick().theta_max
    theta0 = rng.uniform(theta_max, 0.5, n)
    omega0 = rng.uniform(-4.0, 4.0, n)
    cor = rng.uniform(0.0, 1.0, n)
    force = rng.uniform(0.0, 300.0, n)
    batch = drumstroke.simulate_many(theta0=theta0, omega0=omega0, cor=cor, force=force, t_end=3.0, model="geometry")
    assert len(batch) == n
    for i in rng.choice(n, 60, replace=False):
        recipe = batch.recipes[i]
        assert (recipe.theta0, recipe.omega0, recipe.cor, recipe.force.value, recipe.t_end, recipe.model) == (
            theta0[i], omega0[i], cor[i], force[i], 3.0, "geometry")
        single = drumstroke.simulate(recipe)
        np.testing.assert_allclose(batch.impacts[i].t, single.impacts.t, rtol=0, atol=1e-12)
        np.testing.assert_allclose(batch.impacts[i].omega, single.impacts.omega, rtol=1e-12, atol=1e-15)
        assert np.isnan(batch.rest_time[i]) == (single.rest_time is None)


def test_parameter_arrays_broadcast_and_default():
    batch = drumstroke.simulate_many(cor=np.array([[0.5], [0.9]]), force=[0.0, 100.0, 200.0])
    assert len(batch) == 6
    expected = drumstroke.simulate(force=200.0, cor=0.9)  # row-major: the last pair
    np.testing.assert_allclose(batch.impacts[5].t, expected.impacts.t, rtol=0, atol=1e-12)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"theta0": [0.0, 2.0]}, r"theta0\[1\] must be in \[-0.262255, 1.5708\) rad"),
        ({"cor": [0.5, np.nan]}, r"cor\[1\] must be a finite number in \[0, 1\]"),
        ({"t_end": -1.0}, r"t_end\[0\] must be in \[1e-06, 3600\] s"),
        ({"force": [1e7]}, r"force\[0\] must be in \[-1e\+06, 1e\+06\] m/s\^2"),
        ({"cor": [0.5, 0.6], "force": [1, 2, 3]}, r"must broadcast together"),
        ({"force": "hard"}, r"force must be a number or an array of numbers"),
        ({"force": 1.0, "model": "toy"}, r"model must be one of"),
        ({"force": 1.0, "stick": 3}, r"stick must be a Stick"),
        ({}, r"needs recipes or at least one parameter array"),
    ],
)
def test_bad_parameter_arrays_are_named(kwargs, message):
    with pytest.raises(drumstroke.ParameterError, match=message):
        drumstroke.simulate_many(**kwargs)


def test_recipes_and_arrays_together_are_refused():
    with pytest.raises(drumstroke.ParameterError, match="not both"):
        drumstroke.simulate_many(["free-bounce"], cor=0.5)
