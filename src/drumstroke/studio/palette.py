"""The studio's palette operations: the library's strokes as cards, their post-processing heard before it is
saved, and a stroke saved into the library folder (the files ``drumstroke library build`` writes).

A stroke is named in a request by where it comes from: ``{"shipped": NAME}`` (a stroke of the shipped palette),
``{"library": NAME}`` (one of the ``--library`` folder's) or ``{"recipe": RECIPE}`` (a recipe simulated, as the
designer sends it). Each operation is a function ``(studio, request) -> dict``; a refused input is a
:class:`~drumstroke.errors.ParameterError` naming the field.
"""

import functools
import re

import numpy as np

from .._checks import shown
from ..errors import ParameterError
from ..formats.library import MANIFEST
from ..palette.library import load_library, palette_library, save_stroke
from ..palette.motion import concat
from ..palette.transforms import STEPS, apply_step
from ..stroke import as_trajectory
from ..stroke import simulate as simulate_recipe
from .session import fields, number, text
from .strokes import MAX_DURATION, MAX_SAMPLES, studio_recipe

CARD_SAMPLES = 400
"""The most samples of a card's small θ(t) plot."""

MAX_PARTS = 16
"""The most strokes a request joins."""

MAX_STEPS = 20
"""The most post-processing steps of one stroke."""

NAME = re.compile(r"[a-z0-9]+(-[a-z0-9]+)*")
"""A saved stroke's name: kebab-case (lower-case letters and digits, words joined by single hyphens)."""


@functools.cache
def _shipped():
    return palette_library()


def palette(studio, request):
    """``{}`` -> ``{"library": folder or None, "saving": bool, "problem": text or None, "strokes": [card, ...]}``.

    The shipped palette's strokes, then the library folder's (none while it holds no library; a damaged one's
    reason in ``problem``). A card: ``name``, ``source`` (shipped or library), ``category``, ``description``,
    ``recipe`` (its TOML data), ``history`` (how it was made), ``t_end``, ``theta_max``, θ(t) sampled (``t``,
    ``theta``, at most :data:`CARD_SAMPLES`) and its ``impacts`` (time s, tip speed m/s, level dB).
    """
    fields(request)
    cards = [_card(stroke, "shipped") for stroke in _shipped().values()]
    problem = None
    if studio.library is not None and (studio.library / MANIFEST).exists():
        try:
            cards += [_card(stroke, "library") for stroke in load_library(studio.library).values()]
        except ParameterError as error:
            problem = str(error)
    return {"library": None if studio.library is None else str(studio.library), "saving": studio.library is not None,
            "problem": problem, "strokes": cards}


def _card(stroke, source):
    trajectory = stroke.trajectory
    t, theta, _ = trajectory.sample(min(trajectory.rate, (CARD_SAMPLES - 1) / trajectory.t_end))
    return {"name": stroke.name, "source": source, "category": stroke.category, "description": stroke.description,
            "recipe": None if trajectory.recipe is None else trajectory.recipe.to_dict(),
            "history": list(trajectory.history), "t_end": trajectory.t_end, "theta_max": trajectory.theta_max,
            "t": t, "theta": theta, "impacts": _impacts(trajectory)}


def _impacts(trajectory):
    impacts = trajectory.impacts
    return {"t": impacts.t, "tip_speed": impacts.tip_speed, "level_db": impacts.level_db}


def transform(studio, request):
    """``{"parts": [{"stroke": SOURCE, "steps": [...]}, ...], "gap": s}`` -> the post-processed stroke drawn.

    Each part is a stroke (see the module) with its steps applied in order (``{"stretch": F}``,
    ``{"compress": F}``, ``{"reverse": true}``, ``{"trim": [t0, t1]}``, ``{"catch": N}``, at most
    :data:`MAX_STEPS`); several parts (at most :data:`MAX_PARTS`) are joined one after another ``gap`` s apart
    (default 0.2, in [0, 10]), the stick returning smoothly between them. Answers the stroke's ``t``, ``theta``
    and ``force`` (a(t) where a recipe's force plays, else None) sampled, its ``impacts``, ``t_end``,
    ``theta_max``, ``history`` and ``recipe`` (None for joined strokes).
    """
    fields(request, ("parts",), ("gap",))
    trajectory = _made(studio, request)
    rate = min(trajectory.rate, (MAX_SAMPLES - 1) / trajectory.t_end)
    sampled = trajectory.sample(rate)
    t, theta, _ = sampled
    force = [None] * len(t)
    if len(request["parts"]) == 1 and trajectory.recipe is not None and trajectory.recipe_time is not None:
        played = np.asarray(trajectory.recipe_time(t), dtype=float)  # NaN where no recipe time plays
        inside = np.isfinite(played)
        values = np.asarray(trajectory.recipe.force(np.where(inside, played, 0.0)), dtype=float)
        force = [float(v) if ok else None for v, ok in zip(values, inside)]
    joined = len(request["parts"]) > 1  # its recipe is its first part's only
    return {"t": t, "theta": theta, "force": force, "impacts": _impacts(trajectory), "t_end": trajectory.t_end,
            "theta_max": trajectory.theta_max, "history": list(trajectory.history),
            "recipe": None if joined or trajectory.recipe is None else trajectory.recipe.to_dict()}


def _made(studio, request):
    """The stroke a request's ``parts`` and ``gap`` make."""
    parts = request["parts"]
    if not isinstance(parts, list) or not 1 <= len(parts) <= MAX_PARTS:
        raise ParameterError(f"parts must be a list of 1 to {MAX_PARTS} strokes, got {type(parts).__name__}"
                             f"{f' of {len(parts)}' if isinstance(parts, list) else ''}")
    gap = number(request, "gap", low=0.0, high=10.0, unit="s", default=0.2)
    made = [_part(part, f"parts[{i}]", studio.library) for i, part in enumerate(parts)]
    trajectory = made[0] if len(made) == 1 else concat(made, gap, name="joined")
    if trajectory.t_end > 2 * MAX_DURATION:
        raise ParameterError(f"the stroke must last at most {2 * MAX_DURATION:g} s, got {trajectory.t_end:.6g} s "
                             "(a smaller stretch, fewer parts)")
    return trajectory


def _part(part, where, library):
    if not isinstance(part, dict):
        raise ParameterError(f"{where} must be a JSON object with 'stroke' and 'steps', got {type(part).__name__}")
    fields(part, ("stroke",), ("steps",), what=where)
    steps = part.get("steps", [])
    if not isinstance(steps, list) or len(steps) > MAX_STEPS:
        raise ParameterError(f"{where}.steps must be a list of at most {MAX_STEPS} one-key objects such as "
                             f"{{\"stretch\": 2}}, got {type(steps).__name__}")
    stroke = _source(part["stroke"], f"{where}.stroke", library)
    for i, step in enumerate(steps):
        if not isinstance(step, dict) or len(step) != 1 or next(iter(step)) not in STEPS:
            raise ParameterError(f"{where}.steps[{i}] must be a one-key object with a key among {', '.join(STEPS)}, "
                                 f"got {shown(step)}")
        (op, value), = step.items()
        try:
            if op == "stretch" and isinstance(value, (int, float)) and stroke.t_end * value > 2 * MAX_DURATION:
                raise ParameterError(f"the stroke must stay at most {2 * MAX_DURATION:g} s long, got a stretch of "
                                     f"{value!r} of {stroke.t_end:.6g} s")
            stroke = apply_step(stroke, op, value)
        except ParameterError as error:
            raise ParameterError(f"{where}.steps[{i}] ({op}): {error}") from None
    return stroke


def _source(source, where, library):
    if not isinstance(source, dict) or len(source) != 1:
        raise ParameterError(f"{where} must be one of {{\"shipped\": NAME}}, {{\"library\": NAME}}, "
                             f"{{\"recipe\": RECIPE}}, got {type(source).__name__}")
    (kind, value), = source.items()
    if kind == "recipe":
        return as_trajectory(simulate_recipe(studio_recipe(value, f"{where}.recipe")))
    if kind not in ("shipped", "library"):
        raise ParameterError(f"{where} must be one of {{\"shipped\": NAME}}, {{\"library\": NAME}}, "
                             f"{{\"recipe\": RECIPE}}, got the key {kind[:40]!r}")
    name = text(source, kind, most=64)
    if kind == "shipped":
        return _shipped()[name].trajectory
    if library is None:
        raise ParameterError(f"{where}.library names a library stroke, but the studio has no library (start it "
                             "with --library DIR)")
    return load_library(library)[name].trajectory


def save(studio, request):
    """``{"name", "category", "description", "replace", "parts", "gap"}`` -> ``{"saved", "library", "strokes"}``.

    The stroke :func:`transform` makes of ``parts`` and ``gap``, saved into the studio's library folder under
    ``name`` (kebab-case, at most 64 characters), with the files ``drumstroke library build`` writes; the folder
    written atomically, one save at a time. A name already there is refused unless ``replace`` is true. Without
    ``--library`` nothing can be saved.
    """
    if studio.library is None:
        raise ParameterError("saving needs a library folder: start the studio with 'drumstroke studio --library "
                             "DIR' (a library built by 'drumstroke library build', or a new empty folder)")
    fields(request, ("name", "parts"), ("gap", "category", "description", "replace"))
    name = text(request, "name", most=64)
    if not NAME.fullmatch(name):
        raise ParameterError(f"name must be kebab-case: lower-case letters and digits in words joined by single "
                             f"hyphens, 1-64 characters, no '/' (e.g. 'soft-double'), got {name!r}")
    category = text(request, "category", most=200, default="")
    description = text(request, "description", most=500, default="")
    replacing = request.get("replace", False)
    if not isinstance(replacing, bool):
        raise ParameterError(f"replace must be true or false, got {replacing!r}")
    if isinstance(request["parts"], list) and len(request["parts"]) > 1:
        raise ParameterError(f"parts must be one stroke to save, got {len(request['parts'])} joined: a library keeps "
                             "each stroke's recipe, and a joined stroke has several; save each part")
    trajectory = _made(studio, request)
    with studio.lock:
        library = save_stroke(studio.library, name, trajectory, category=category, description=description,
                              replace_stroke=replacing)
    return {"saved": name, "library": str(studio.library), "strokes": list(library)}


OPERATIONS = {"palette": palette, "transform": transform, "save": save}
"""This module's operations by name."""
