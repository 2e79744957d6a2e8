"""Named recipes, one or more for every stroke category of the paper (its Section 3.2).

All start as the paper's runs do (t ∈ [0, 5] s, θ₀ = 0, ω₀ = 0, g = 9.8 m/s²,
c = 0.86, the ``paper`` model) unless their description says otherwise.

Examples
--------
>>> sorted(PRESETS)[:3]
['constant', 'finger-pulses', 'free-bounce']
>>> preset("finger-pulses").force.period
0.4
"""

from dataclasses import dataclass

from .errors import ParameterError
from .profiles import Constant, PiecewiseLinear, Pulses
from .recipe import Recipe


@dataclass(frozen=True)
class Preset:
    """A named recipe and what it shows.

    Attributes
    ----------
    name : str
    category : str
        The paper's stroke category.
    description : str
        What the stroke shows, in a sentence.
    figure : str
        The paper's figure it reproduces, or "".
    recipe : Recipe
    """

    name: str
    category: str
    description: str
    figure: str
    recipe: Recipe


def _preset(name, category, description, figure="", **recipe):
    return Preset(name, category, description, figure, Recipe(name=name, **recipe))


_ALL = [
    _preset(
        "free-bounce",
        "gravity only",
        "No thumb: the stick drops from horizontal and bounces like a ball, intervals shrinking "
        "geometrically until it rests on the head (rubato buzz).",
        "Fig. 4",
        force=Constant(0.0),
    ),
    _preset(
        "constant",
        "constant torque",
        "A steady thumb press of 100 m/s^2 (3.7 N): a free bounce as if under 3.9 times stronger "
        "gravity, faster and shorter.",
        force=Constant(100.0),
    ),
    _preset(
        "low-high",
        "low to high",
        "A light grip (10 m/s^2) that jumps to 220 m/s^2 between 1 and 2 s: wide bounces, then a "
        "sudden dense burst that presses the stick to rest; later changes do nothing.",
        "Fig. 5",
        force=PiecewiseLinear([(0.0, 10.0), (1.0, 10.0), (1.05, 220.0), (2.0, 220.0), (2.05, 10.0)]),
    ),
    _preset(
        "high-low",
        "high to low",
        "A hard grip (250 m/s^2, the top of the human range) released at 0.57 s, just before an "
        "impact: quick close bounces, then wide ones over twice as long once only gravity acts.",
        "Fig. 6",
        force=PiecewiseLinear([(0.0, 250.0), (0.57, 250.0), (0.59, 0.0)]),
    ),
    _preset(
        "finger-pulses",
        "sustained finger pulses",
        "Square-wave finger pulses (189 m/s^2, period 0.4 s, duty 5 %) feed energy in each cycle: "
        "the bounce never dies and settles at the pulse period.",
        "Fig. 7",
        force=Pulses(amplitude=189.0, period=0.4, duty=0.05, phase=0.08),
    ),
    _preset(
        "reversed-gravity",
        "un-natural",
        "A free bounce, then gravity flips to -9.8 m/s^2 from 3.2 to 3.45 s: the resting stick lifts "
        "off the head, floats up and falls back into a second bounce sequence (7 s).",
        t_end=7.0,
        force=Constant(0.0),
        gravity=PiecewiseLinear([(0.0, 9.8), (3.2, 9.8), (3.2001, -9.8), (3.45, -9.8), (3.4501, 9.8)]),
    ),
    _preset(
        "rising-gravity",
        "un-natural",
        "Gravity grows from 2 to 60 m/s^2 over the stroke: slow floating bounces that speed up as "
        "if the drum were falling into a heavier world.",
        force=Constant(0.0),
        gravity=PiecewiseLinear([(0.0, 2.0), (5.0, 60.0)]),
    ),
    _preset(
        "superhuman-press",
        "un-natural",
        "A thumb press of 2000 m/s^2 (75 N, eight times the human range): a machine-gun buzz over "
        "in a fraction of a second.",
        force=Constant(2000.0),
    ),
]

PRESETS = {p.name: p for p in _ALL}
"""Every preset by name."""


def preset(name):
    """The :class:`~drumstroke.recipe.Recipe` of the preset ``name``."""
    if name not in PRESETS:
        raise ParameterError(f"preset must be one of {', '.join(PRESETS)}, got {name!r}")
    return PRESETS[name].recipe
