"""drumstroke: a human-like stroke palette for robotic drummers.

A physical model of a drumstick bouncing on a drumhead, driven by the force of
the thumb, makes single, double, triple and buzz strokes.

>>> import drumstroke
>>> stroke = drumstroke.simulate("low-high")
>>> stroke.model, len(stroke.impacts) > 10
('paper', True)
"""

from importlib import import_module

from ._version import __version__

_WHERE = {
    "DrumstrokeError": "errors", "ParameterError": "errors", "SimulationError": "errors",
    "MODELS": "model", "Stick": "model",
    "make_stroke": "palette.library",
    "PRESETS": "presets", "preset": "presets",
    "Constant": "profiles", "PiecewiseLinear": "profiles", "Profile": "profiles", "Pulses": "profiles",
    "Samples": "profiles", "Sum": "profiles",
    "Recipe": "recipe",
    "Batch": "stroke", "Stroke": "stroke", "simulate": "stroke", "simulate_many": "stroke",
    "Impacts": "trajectory", "Trajectory": "trajectory",
}
"""Where each name of the package's namespace lives: imported on first use, so ``import drumstroke`` (and with it
the command's ``--version`` and ``--help``) costs next to nothing."""


def __getattr__(name):
    if name not in _WHERE:
        raise AttributeError(f"module 'drumstroke' has no attribute {name!r}")
    value = getattr(import_module(f".{_WHERE[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_WHERE))


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
