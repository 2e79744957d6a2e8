"""Every example recipe in examples/ reads and simulates."""

from pathlib import Path

import numpy as np
import pytest

import drumstroke

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.toml"))


def test_there_are_examples():
    assert len(EXAMPLES) >= 3


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_simulates(path):
    recipe = drumstroke.Recipe.from_toml(path)
    stroke = drumstroke.simulate(recipe)
    t, theta, omega = stroke.sample(1000.0)
    assert len(stroke.impacts) >= 3
    assert np.all(np.isfinite(theta)) and np.all(theta >= recipe.theta_max)
    assert stroke.to_dict()["model"] == recipe.model and stroke.to_dict()["recipe_name"] == path.stem


def test_the_recorded_thumb_is_read_from_its_file():
    recipe = drumstroke.Recipe.from_toml(EXAMPLES[0].parent / "recorded-thumb.toml")
    assert isinstance(recipe.force, drumstroke.Samples)
    assert recipe.force(1.1) == pytest.approx(140.0, abs=13.0)  # the press's peak, plus tremor
    assert len(recipe.force.points) == 1501
