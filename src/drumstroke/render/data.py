"""A stroke as data files: JSON (recipe, impacts, rests) and CSV (t, θ, ω at a rate).

Both record which model made the stroke; both are written atomically.
"""

import io
import json

import numpy as np

from .._atomic import write_atomic
from .._version import __version__
from ..stroke import DEFAULT_RATE


def write_json(stroke, path):
    """Write ``stroke.to_dict()`` as JSON to ``path``."""
    write_atomic(path, json.dumps(stroke.to_dict(), indent=1) + "\n")


def write_csv(stroke, path, *, rate=DEFAULT_RATE):
    """Write the trajectory sampled at ``rate`` (Hz) as CSV with the header ``t,theta,omega``.

    One comment line (``#``) comes first: the drumstroke version, the model, the
    recipe's name and the rate. Units: s, rad, rad/s.
    """
    t, theta, omega = stroke.sample(rate)
    buffer = io.StringIO()
    buffer.write(
        f"# drumstroke {__version__}; model={stroke.model}; recipe={stroke.recipe.name or 'custom'}; "
        f"rate={rate:g} Hz; units s, rad, rad/s\n"
    )
    np.savetxt(buffer, np.column_stack((t, theta, omega)), delimiter=",", header="t,theta,omega",
               comments="", fmt="%.17g")
    write_atomic(path, buffer.getvalue())
