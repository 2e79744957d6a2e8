"""Pictures of strokes like the paper's Figs. 4–7 (needs the ``plot`` extra: matplotlib).

θ(t) on top with the drumhead and the impacts marked (marker size grows with
the impact's level), the thumb's acceleration a(t) underneath, and g(t) beside
it when it varies. The title names the stroke and the model that made it.
"""

import io

import numpy as np

from .._atomic import write_atomic
from ..model import inertia_ratio

try:
    from matplotlib.figure import Figure
except ImportError as error:  # pragma: no cover - exercised only without the extra
    raise ImportError("drumstroke plots need matplotlib: pip install 'drumstroke[plot]'") from error


def stroke_figure(stroke, *, title=None, rate=2000.0):
    """A matplotlib Figure of ``stroke``: θ(t) with impacts over a(t) (and g(t)).

    Parameters
    ----------
    stroke : drumstroke.Stroke
    title : str or None
        Defaults to the recipe's name.
    rate : float > 0
        Samples per second drawn (Hz).
    """
    recipe = stroke.recipe
    t, theta, _ = stroke.sample(rate)
    figure = Figure(figsize=(9.0, 5.6), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True, height_ratios=(2.2, 1.0))

    top.axhline(recipe.theta_max, color="0.55", lw=1.0, ls="--", label=f"drumhead θ_max = {recipe.theta_max:.4f} rad")
    top.plot(t, theta, color="C0", lw=1.1, label="θ(t)")
    impacts = stroke.impacts
    if len(impacts):
        level = impacts.level_db
        size = np.clip(4.0 + (level - level.max() + 40.0), 1.0, 44.0)
        top.scatter(impacts.t, np.full(len(impacts), recipe.theta_max), s=size, color="C3", zorder=3,
                    label=f"{len(impacts)} impacts")
    for start, end in stroke.rests:
        top.axvspan(start, end, color="C2", alpha=0.12, lw=0)
    if stroke.rest_time is not None:
        top.axvline(stroke.rest_time, color="C2", lw=1.0, label=f"at rest from {stroke.rest_time:.4f} s")
    top.set_ylabel("θ (rad)")
    top.legend(loc="upper right", fontsize=8)
    top.grid(alpha=0.25)

    bottom.plot(t, recipe.force(t), color="C1", lw=1.2, label="a(t), thumb")
    bottom.set_ylabel("a (m/s²)")
    bottom.set_xlabel("t (s)")
    bottom.grid(alpha=0.25)
    gravity = recipe.gravity(t)
    if np.ptp(gravity) > 0:
        twin = bottom.twinx()
        twin.plot(t, gravity, color="C4", lw=1.0, ls="-.", label="g(t)")
        twin.set_ylabel("g (m/s²)")
        twin.legend(loc="lower right", fontsize=8)
    bottom.legend(loc="upper right", fontsize=8)
    bottom.set_xlim(0.0, recipe.t_end)

    d = inertia_ratio(recipe.model, recipe.stick)
    name = title or recipe.name or "stroke"
    figure.suptitle(f"{name} — model: {recipe.model} (D = {d:.4f} m², c = {recipe.cor:g})", fontsize=11)
    return figure


def save_stroke_plot(stroke, path, *, title=None):
    """Draw ``stroke`` (see :func:`stroke_figure`) to a PNG file, written atomically."""
    buffer = io.BytesIO()
    stroke_figure(stroke, title=title).savefig(buffer, format="png", dpi=110)
    write_atomic(path, buffer.getvalue())
