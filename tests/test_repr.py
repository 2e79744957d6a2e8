"""Every result object that holds arrays prints as one short line: its name, model, counts and span."""

from pathlib import Path

import numpy as np
import pytest

import drumstroke
from drumstroke.compose import compose
from drumstroke.palette.library import build_library, read_palette
from drumstroke.robot.controllers import controller
from drumstroke.robot.track import reference, track
from drumstroke.robot.validate import validate
from drumstroke.score import parse_pattern


def one_short_line(obj):
    text = repr(obj)
    assert "\n" not in text and len(text) <= 200, text
    return text


def test_a_stroke_and_its_impacts():
    stroke = drumstroke.simulate("free-bounce")
    assert one_short_line(stroke) == ("Stroke('free-bounce', model='paper', 98 impacts over [0, 5] s, at rest from "
                                      f"{stroke.rest_time:.6g} s)")
    assert one_short_line(stroke.impacts).startswith(f"Impacts(98 over [{stroke.impacts.t[0]:.6g}, ")
    assert one_short_line(drumstroke.simulate("free-bounce", t_end=0.1).impacts) == "Impacts(none; tip distance 0.27 m)"
    assert "still moving at t_end" in one_short_line(drumstroke.simulate("finger-pulses"))


def test_a_trajectory_a_batch_and_a_recorded_profile():
    assert one_short_line(drumstroke.make_stroke("double")).startswith("Trajectory('double', model='paper', 549 samples")
    batch = drumstroke.simulate_many(theta0=np.linspace(0.0, 0.5, 1000), force=100.0)
    assert one_short_line(batch) == (f"Batch(1000 strokes, {sum(len(i) for i in batch.impacts)} impacts, 1000 at rest "
                                     "by t_end; not sampled)")
    recipe = drumstroke.Recipe.from_toml(Path(__file__).resolve().parents[1] / "examples" / "recorded-thumb.toml")
    assert one_short_line(recipe.force) == f"Samples(file={str(recipe.force.file)!r})"  # not its 1,500 points


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    return build_library(tmp_path_factory.mktemp("lib"), palette=[e for e in read_palette() if e.name in ("single",
                                                                                                          "double")])


def test_a_composition_and_what_the_robot_played(library):
    piece = compose(parse_pattern("tempo 120\n0 single 100\n1 double 80 left\n"), library)
    assert one_short_line(piece).startswith("Composition(model='paper', 2 of 2 notes played, ")
    assert one_short_line(piece).endswith("impacts: right 1, left 2)")
    played = track(reference(library["double"].trajectory, 1000.0), controller("pi"))
    assert one_short_line(played).startswith("Played('double' by 'pi' on the simple plant, model='paper': ")
    assert one_short_line(played.contacts).startswith(f"Contacts({len(played.onsets)} over [")
    assert one_short_line(validate(played.reference)).startswith("Checked(")
