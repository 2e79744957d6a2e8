"""The studio's stroke operations: simulate a recipe, and what the stroke designer and the palette ask for.

Each operation is a function ``(studio, request) -> dict or File`` (:mod:`drumstroke.studio.session`); a
refused input is a :class:`~drumstroke.errors.ParameterError` naming the field.
"""

import numpy as np

from ..recipe import Recipe
from ..stroke import simulate as simulate_recipe
from .session import fields, number

MAX_SAMPLES = 20000
"""The most samples of θ(t) an answer draws (the rate is lowered to keep within them)."""


def simulate(studio, request):
    """``{"recipe": RECIPE, "rate": HZ}`` -> the stroke: θ(t) and a(t) sampled, its impacts and rests.

    ``RECIPE`` is a recipe as its TOML file holds it (``Recipe.to_dict``); ``rate`` (default 1000 Hz, in
    [1, 100000]) is lowered so that at most :data:`MAX_SAMPLES` samples are drawn.
    """
    fields(request, ("recipe",), ("rate",))
    recipe = Recipe.from_dict(request["recipe"], name="studio")
    rate = number(request, "rate", low=1.0, high=1e5, unit="Hz", default=1000.0)
    return stroke_answer(simulate_recipe(recipe), rate=rate)


def stroke_answer(stroke, *, rate=1000.0):
    """A stroke as the page draws and plays it: its model and recipe, θ, ω and the force a(t) sampled at ``rate``
    (Hz, lowered to keep within :data:`MAX_SAMPLES`), its impacts (time s, tip speed m/s, level dB) and rests (s)."""
    rate = min(rate, (MAX_SAMPLES - 1) / stroke.t_end)
    t, theta, omega = stroke.sample(rate)
    impacts = stroke.impacts
    return {
        "model": stroke.model,
        "recipe": stroke.recipe.to_dict(),
        "t_end": stroke.t_end,
        "theta_max": stroke.recipe.theta_max,
        "t": t, "theta": theta, "omega": omega,
        "force": np.asarray(stroke.recipe.force(t), dtype=float),
        "impacts": {"t": impacts.t, "tip_speed": impacts.tip_speed, "level_db": impacts.level_db},
        "rests": stroke.rests,
        "rest_time": stroke.rest_time,
    }


OPERATIONS = {"simulate": simulate}
"""This module's operations by name."""
