"""The studio's stroke operations: what the stroke designer asks for.

Simulate a recipe, design the recipe that plays given notes, list the recipes to start from, hear a stroke and
download it as the command line writes it. Each operation is a function ``(studio, request) -> dict or File``
(:mod:`drumstroke.studio.session`); a refused input is a :class:`~drumstroke.errors.ParameterError` naming the
field. Recipes come as their TOML files hold them (``Recipe.to_dict``), bounded here so that no request computes
for long: :func:`studio_recipe`.
"""

import math
import tempfile
from pathlib import Path

import numpy as np

from ..design import ENDS, ForceRange, Setup, Unreachable
from ..design import design as design_notes
from ..design.chain import DRIFT
from ..dynamics import CEILING_DB, FLOOR_DB
from ..errors import ParameterError
from ..formats.toml import toml_text
from ..model import MODELS, Stick
from ..palette.library import read_palette
from ..presets import PRESETS
from ..recipe import Recipe
from ..render.data import design_to_dict
from ..stroke import simulate as simulate_recipe
from .session import File, choice, fields, number, numbers

MAX_SAMPLES = 20000
"""The most samples of θ(t) an answer draws (the rate is lowered to keep within them)."""

MAX_DURATION = 60.0
"""The longest stroke the studio simulates or plays (s)."""

MAX_POINTS = 2000
"""The most breakpoints and profile tables a recipe's force and gravity hold together."""

MAX_PULSES = 10000
"""The most pulses of a ``pulses`` profile before the stroke's end."""

MAX_NOTES = 200
"""The most notes a design asks for."""

MAX_IMPACTS = 5000
"""The most impacts a sound is rendered of."""


def studio_recipe(data, key="recipe"):
    """The recipe ``data`` (a recipe's TOML data) checked and built, within the studio's bounds.

    Beyond :meth:`Recipe.from_dict`'s checks: ``t_end`` at most :data:`MAX_DURATION` s, at most
    :data:`MAX_POINTS` breakpoints and tables, :data:`MAX_PULSES` pulses, and no ``samples`` profile (it names
    a file on the server's disk).
    """
    if not isinstance(data, dict):
        raise ParameterError(f"{key} must be a recipe's table (a JSON object), got {type(data).__name__}")
    t_end = number({f"{key}.t_end": data.get("t_end", 5.0)}, f"{key}.t_end", low=1e-6, high=MAX_DURATION, unit="s")
    size = 0
    for name in ("force", "gravity"):
        size += _profile_size(data.get(name), f"{key}.{name}", t_end)
    if size > MAX_POINTS:
        raise ParameterError(f"{key} must hold at most {MAX_POINTS} breakpoints and profile tables in force and "
                             f"gravity together, got {size}")
    try:
        return Recipe.from_dict(data, name="studio")
    except ParameterError as error:
        raise ParameterError(f"{key}: {error}") from None


def _profile_size(spec, where, t_end):
    """The breakpoints and tables of a profile table, counted (sums walked without recursion); a ``samples`` table
    or too many pulses refused."""
    size, tables = 0, [(spec, where)]
    while tables:
        table, place = tables.pop()
        size += 1
        if size > MAX_POINTS:
            break
        if not isinstance(table, dict):
            continue  # Recipe.from_dict names it
        kind = table.get("kind")
        if kind == "samples":
            raise ParameterError(f"{place}.kind must not be 'samples' in the studio (it reads a file on the "
                                 "server): give the points as a piecewise-linear profile")
        if kind == "piecewise-linear" and isinstance(table.get("points"), list):
            size += len(table["points"])
        if kind == "sum" and isinstance(table.get("parts"), list):
            tables.extend((part, f"{place}.parts[{i}]") for i, part in enumerate(table["parts"]))
        period = table.get("period")
        if (kind == "pulses" and isinstance(period, (int, float)) and not isinstance(period, bool) and period > 0
                and t_end / period > MAX_PULSES):
            raise ParameterError(f"{place}.period must give at most {MAX_PULSES} pulses before t_end = "
                                     f"{t_end:g} s, got {period!r} s")
    return size


def simulate(studio, request):
    """``{"recipe": RECIPE, "rate": HZ}`` -> the stroke: θ(t) and a(t) sampled, its impacts and rests.

    ``RECIPE`` is a recipe as its TOML file holds it (``Recipe.to_dict``; :func:`studio_recipe`'s bounds);
    ``rate`` (default 1000 Hz, in [1, 100000]) is lowered so that at most :data:`MAX_SAMPLES` samples are drawn.
    """
    fields(request, ("recipe",), ("rate",))
    recipe = studio_recipe(request["recipe"])
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


def presets(studio, request):
    """``{}`` -> the recipes to start from: ``{"presets": [...], "palette": [...], "models", "stick", "ends",
    "levels": [low, high] dB, "tolerance": {"time" s, "level" dB}}``.

    Each preset and each stroke of the shipped palette as ``{"name", "category", "description", "recipe"}`` (a
    palette stroke also with its ``transforms``, which the designer does not apply).
    """
    fields(request)
    shipped = [{"name": e.name, "category": e.category, "description": e.description, "recipe": e.recipe.to_dict(),
                "transforms": list(e.transforms)} for e in read_palette()]
    return {
        "presets": [{"name": p.name, "category": p.category, "description": p.description,
                     "recipe": p.recipe.to_dict()} for p in PRESETS.values()],
        "palette": shipped,
        "models": list(MODELS),
        "stick": Stick().to_dict(),
        "ends": list(ENDS),
        "levels": [FLOOR_DB, CEILING_DB],
        "tolerance": {"time": DRIFT[0], "level": DRIFT[1]},
    }


def design(studio, request):
    """``{"times": [s], "levels": [dB], "end", "model", "cor", "stick", "force_max"}`` -> the designed stroke.

    ``times`` strictly increasing in [0, 60] s (at most :data:`MAX_NOTES`), ``levels`` as many, in dB re 1 m/s
    within the MIDI map; ``end`` one of catch (default), press, bounce; ``model`` (default paper), ``cor`` in
    [0, 0.99] (default 0.86), ``stick`` a recipe's ``[stick]`` table, ``force_max`` in [1, 1e6] m/s² (default
    3000). Answers ``{"design": {...}, "stroke": {...}}`` (the design's notes, ``release`` — when its recipe's
    t = 0 falls on the notes' timeline, s — its errors and recipe; the stroke as :func:`simulate` answers it), or
    ``{"unreachable": {"reason", "note", "nearest_time", "nearest_level"}}`` when a note cannot be played.
    """
    fields(request, ("times", "levels"), ("end", "model", "cor", "stick", "force_max"))
    times = numbers(request, "times", low=0.0, high=MAX_DURATION, unit="s", most=MAX_NOTES, increasing=True)
    levels = numbers(request, "levels", low=FLOOR_DB, high=CEILING_DB, unit="dB", most=MAX_NOTES)
    if not times or len(levels) != len(times):
        raise ParameterError(f"levels must give one level for each of the {len(times)} times, got {len(levels)}"
                             if times else "times must hold at least one note, got []")
    end = choice(request, "end", ENDS, default="catch")
    model = choice(request, "model", MODELS, default="paper")
    cor = number(request, "cor", low=0.0, high=0.99, default=0.86)
    force_max = number(request, "force_max", low=1.0, high=1e6, unit="m/s^2", default=3000.0)
    setup = Setup(model=model, cor=cor, stick=_stick(request.get("stick", {})), forces=ForceRange(high=force_max))
    try:
        made = design_notes(times, levels, end=end, setup=setup)
    except Unreachable as error:
        return {"unreachable": {"reason": str(error), "note": error.note, "drift": error.drift,
                                "nearest_time": _finite(error.nearest_time),
                                "nearest_level": _finite(error.nearest_level)}}
    return {"design": design_to_dict(made), "stroke": stroke_answer(made.stroke),
            "tolerance": {"time": DRIFT[0], "level": DRIFT[1]}}


def _stick(table):
    if not isinstance(table, dict):
        raise ParameterError(f"stick must be a recipe's [stick] table (a JSON object), got {type(table).__name__}")
    known = list(Stick().to_dict())
    fields(table, (), known, what="stick")
    return Stick(**{key: number({f"stick.{key}": value}, f"stick.{key}", low=-1e3, high=1e3)
                    for key, value in table.items()})


def _finite(value):
    return float(value) if value is not None and math.isfinite(value) else None


def stroke_audio(studio, request):
    """``{"times": [s], "tip_speeds": [m/s], "duration": s}`` -> the impacts heard on the synthesized snare drum, a
    48 kHz WAV (``audio/wav``).

    ``times`` in [0, 120] s (a palette's stroke may be stretched or joined past :data:`MAX_DURATION`) and
    ``tip_speeds`` in [0, 50] m/s, as many (at most :data:`MAX_IMPACTS`); ``duration`` (default: the last impact
    and the drum's ring) in [the last time, 125] s.
    """
    fields(request, ("times", "tip_speeds"), ("duration",))
    times = numbers(request, "times", low=0.0, high=2 * MAX_DURATION, unit="s", most=MAX_IMPACTS)
    speeds = numbers(request, "tip_speeds", low=0.0, high=50.0, unit="m/s", most=MAX_IMPACTS)
    if len(speeds) != len(times):
        raise ParameterError(f"tip_speeds must give one speed for each of the {len(times)} times, got {len(speeds)}")
    duration = None
    if "duration" in request:
        duration = number(request, "duration", low=max(times, default=0.0), high=2 * MAX_DURATION + 5.0, unit="s")
    from ..render.audio import render_wav

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "stroke.wav"
        render_wav(path, times, speeds, duration=duration)
        return File(path.read_bytes(), "audio/wav", "stroke.wav")


FILES = {"toml": "application/toml", "json": "application/json", "csv": "text/csv"}
"""What :func:`stroke_file` writes, by the file's suffix, and the media types."""


def stroke_file(studio, request):
    """``{"recipe": RECIPE, "format": "toml" | "json" | "csv"}`` -> the file the command line writes of it.

    ``toml``: the recipe (``drumstroke design --out``'s); ``json`` and ``csv``: ``drumstroke simulate RECIPE
    --json`` / ``--csv`` (the impacts and rests; t, θ, ω at 1 kHz).
    """
    fields(request, ("recipe", "format"))
    recipe = studio_recipe(request["recipe"])
    suffix = choice(request, "format", tuple(FILES))
    if suffix == "toml":
        return File(toml_text(recipe.to_dict()).encode(), FILES[suffix], "stroke.toml")
    from ..render.outputs import write_stroke_outputs

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"stroke.{suffix}"
        write_stroke_outputs(simulate_recipe(recipe), **{suffix: path})
        return File(path.read_bytes(), FILES[suffix], path.name)


OPERATIONS = {"simulate": simulate, "presets": presets, "design": design, "stroke_audio": stroke_audio,
              "stroke_file": stroke_file}
"""This module's operations by name."""
