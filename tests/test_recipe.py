"""Recipe files: the issue's example, round trips, relative sample files, atomic writes."""

import os
import textwrap
import tomllib

import pytest

import drumstroke
import drumstroke.recipe
from drumstroke import Constant, PiecewiseLinear, Recipe, Samples, Stick

# The example the recipe module documents (the issue's own), read from its docstring so the
# test checks the documentation itself.
EXAMPLE = textwrap.dedent(drumstroke.recipe.__doc__.split("::\n", 1)[1])


def test_the_documented_example_reads_as_the_low_high_preset(tmp_path):
    path = tmp_path / "example.toml"
    path.write_text(EXAMPLE)
    recipe = Recipe.from_toml(path)
    assert recipe.replace(name="low-high") == drumstroke.preset("low-high")
    assert recipe.name == "example"


def test_only_force_is_required_and_defaults_are_the_papers(tmp_path):
    path = tmp_path / "minimal.toml"
    path.write_text('[force]\nkind = "constant"\nvalue = 0.0\n')
    recipe = Recipe.from_toml(path)
    assert (recipe.model, recipe.t_end, recipe.theta0, recipe.omega0, recipe.cor) == ("paper", 5.0, 0.0, 0.0, 0.86)
    assert recipe.stick == Stick() and recipe.gravity == Constant(9.8)


def test_to_toml_is_valid_toml_that_reads_back_equal(tmp_path):
    recipe = drumstroke.preset("finger-pulses").replace(model="geometry", cor=0.5, stick=Stick(mass=0.05))
    recipe.to_toml(tmp_path / "r.toml")
    assert tomllib.loads((tmp_path / "r.toml").read_text()) == recipe.to_dict()
    assert Recipe.from_toml(tmp_path / "r.toml").replace(name="finger-pulses") == recipe


def test_samples_file_is_found_relative_to_the_recipe_and_rewritten_relative(tmp_path):
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "thumb.csv").write_text("0.0,0.0\n0.2,150.0\n0.4,0.0\n")
    (tmp_path / "data" / "r.toml").write_text('[force]\nkind = "samples"\nfile = "thumb.csv"\n')
    recipe = Recipe.from_toml(tmp_path / "data" / "r.toml")
    assert isinstance(recipe.force, Samples) and recipe.force(0.1) == 75.0
    (tmp_path / "elsewhere").mkdir()  # writers create no folder
    recipe.to_toml(tmp_path / "elsewhere" / "copy.toml")
    text = (tmp_path / "elsewhere" / "copy.toml").read_text()
    assert f'file = "{os.path.join("..", "data", "thumb.csv")}"' in text
    assert Recipe.from_toml(tmp_path / "elsewhere" / "copy.toml").force == recipe.force.__class__(
        tmp_path / "elsewhere" / ".." / "data" / "thumb.csv")


def test_a_crash_mid_write_leaves_the_old_file_whole(tmp_path, monkeypatch):
    path = tmp_path / "r.toml"
    drumstroke.preset("free-bounce").to_toml(path)
    before = path.read_text()

    def crash(*args):
        raise OSError("disk pulled out")

    monkeypatch.setattr(os, "replace", crash)
    with pytest.raises(OSError, match="disk pulled out"):
        drumstroke.preset("low-high").to_toml(path)
    assert path.read_text() == before
    assert [p.name for p in tmp_path.iterdir()] == ["r.toml"]  # no temporary left behind


def test_simulate_accepts_a_recipe_a_preset_name_or_a_path(tmp_path):
    path = tmp_path / "free.toml"
    drumstroke.preset("free-bounce").to_toml(path)
    by_name = drumstroke.simulate("free-bounce")
    by_path = drumstroke.simulate(path)
    by_recipe = drumstroke.simulate(drumstroke.preset("free-bounce"))
    by_keywords = drumstroke.simulate(force=0.0)
    for stroke in (by_path, by_recipe, by_keywords):
        assert stroke.impacts.t.tolist() == by_name.impacts.t.tolist()


def test_keyword_overrides_replace_recipe_fields():
    stroke = drumstroke.simulate("free-bounce", cor=0.5, model="geometry", force=PiecewiseLinear([(0, 5.0)]))
    assert stroke.recipe.cor == 0.5 and stroke.model == "geometry" and stroke.recipe.force(3.0) == 5.0
