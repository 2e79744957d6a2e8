"""A one-note stroke's forces in one compiled call (drumstroke.design.throw): the Python path's pieces, to the bit."""

import math
import re

import numpy as np
import pytest

import drumstroke
from drumstroke.design import Setup, Start, Unreachable, design
from drumstroke.design.chain import LEAD, _Plan
from drumstroke.dynamics import CEILING_DB, FLOOR_DB
from drumstroke.palette.motion import Limits


def bits(pieces):
    """The pieces' numbers as bytes (equal floats, to the bit) and their names."""
    return np.array([piece[:3] for piece in pieces], dtype=float).tobytes(), [piece[3:] for piece in pieces]


def plans(rng, count):
    """Random one-note plans: both models, a range of c and force limits, standard throws of every lead, starts held at
    heights from the head to the top (many refused), catches by grip or at a height (some refused)."""
    setups = [Setup(model=model, cor=cor, moves=Limits()) for model in drumstroke.MODELS for cor in (0.86, 0.5, 0.95)]
    setups.append(Setup(forces=drumstroke.design.ForceRange(low=20.0, high=120.0)))
    for _ in range(count):
        setup = setups[rng.integers(len(setups))]
        t = float(rng.uniform(-5.0, 50.0))
        level = float(rng.uniform(FLOOR_DB, CEILING_DB))
        start = None
        if rng.random() < 0.6:
            start = Start(t - float(rng.uniform(0.001, 0.4)), float(rng.uniform(setup.head - 0.05, 1.2)))
        catch_at = float(rng.uniform(setup.head + 1e-4, 1.0)) if rng.random() < 0.3 else None
        lead = float(rng.choice([LEAD, LEAD / 2, LEAD / 4, LEAD / 8, rng.uniform(0.005, 0.5)]))
        try:
            yield _Plan.of([t], [level], None, start=start, end="catch", setup=setup, lead=lead, tail=None,
                           catch_at=catch_at)
        except (Unreachable, drumstroke.ParameterError):  # refused before any force is worked out
            continue


def test_one_notes_compiled_pieces_are_the_python_paths_to_the_bit(rng):
    """Over thousands of random one-note plans the compiled call gives the same pieces, release, hold and start angle
    as the step-by-step path, to the bit, and refuses exactly those the step-by-step path refuses."""
    compiled = refused = 0
    for plan in plans(rng, 4000):
        thrown = plan.one_note()
        try:
            expected = plan.pieces_in_python()
        except Unreachable:
            assert thrown is None
            refused += 1
            continue
        assert thrown is not None
        pieces, release, hold, theta0 = thrown
        assert bits(pieces) == bits(expected[0])
        assert np.array([release, hold, theta0]).tobytes() == np.array(expected[1:]).tobytes()
        assert all(type(x) is float for piece in pieces for x in piece[:3])
        compiled += 1
    assert compiled > 1000 and refused > 300


def test_a_one_note_design_is_made_and_checked_from_the_compiled_pieces():
    """design() takes the compiled path for one note (standard throw and held start) and its stroke plays the note."""
    setup = Setup()
    for start in (None, Start(0.2, 0.3)):
        made = design([1.0], [0.0], start=start, setup=setup)
        plan = _Plan.of([1.0], [0.0], None, start=start, end="catch", setup=setup, lead=LEAD, tail=None)
        assert bits(made.pieces) == bits(plan.pieces_in_python()[0])
        assert made.time_error < 1e-8 and made.level_error < 1e-6
        assert math.isclose(made.heard[0][0], 1.0, abs_tol=1e-8)


@pytest.mark.parametrize("notes, start, end", [
    ([1.0], Start(0.9, 0.2, -3.0), "catch"),  # falling start
    ([1.0], Start(0.8, 0.1, 3.0), "catch"),  # rising start
    ([1.0, 1.1], None, "catch"),  # a chain
    ([1.0], None, "press"),
    ([1.0], None, "bounce"),
])
def test_other_strokes_take_the_step_by_step_path(notes, start, end):
    plan = _Plan.of(notes, [0.0] * len(notes), None, start=start, end=end, setup=Setup(), lead=LEAD, tail=None)
    try:
        expected = plan.pieces_in_python()
    except Unreachable as error:
        with pytest.raises(Unreachable, match=re.escape(str(error))):
            plan.pieces()
        return
    pieces, *rest = plan.pieces()
    assert bits(pieces) == bits(expected[0]) and rest == list(expected[1:])
