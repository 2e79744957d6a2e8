"""drumstroke: a human-like stroke palette for robotic drummers.

A physical model of a drumstick bouncing on a drumhead, driven by the force of
the thumb, makes single, double, triple and buzz strokes.

>>> import drumstroke
>>> stroke = drumstroke.simulate("low-high")
>>> stroke.model, len(stroke.impacts) > 10
('paper', True)
"""

from ._version import __version__
from .errors import DrumstrokeError, ParameterError, SimulationError
from .model import MODELS, Stick
from .palette.library import make_stroke
from .presets import PRESETS, preset
from .profiles import Constant, PiecewiseLinear, Profile, Pulses, Samples, Sum
from .recipe import Recipe
from .stroke import Batch, Stroke, simulate, simulate_many
from .trajectory import Impacts, Trajectory

__all__ = [
    "MODELS",
    "PRESETS",
    "Batch",
    "Constant",
    "DrumstrokeError",
    "Impacts",
    "ParameterError",
    "PiecewiseLinear",
    "Profile",
    "Pulses",
    "Recipe",
    "Samples",
    "SimulationError",
    "Stick",
    "Stroke",
    "Sum",
    "Trajectory",
    "__version__",
    "make_stroke",
    "preset",
    "simulate",
    "simulate_many",
]
