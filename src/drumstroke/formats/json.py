"""JSON files, both ways: strokes, compositions, reports, a library's manifest and impacts.

Numpy arrays and numbers are written as lists and numbers; NaN and infinities are refused
(they are not JSON). Writes are atomic.

Examples
--------
>>> import pathlib, tempfile
>>> import numpy as np
>>> path = pathlib.Path(tempfile.mkdtemp()) / "s.json"
>>> write_json(path, {"t": np.array([0.5, 1.0]), "model": "paper"})
>>> read_json(path, "stroke file")
{'t': [0.5, 1.0], 'model': 'paper'}
"""

import json
from pathlib import Path

from .._atomic import write_atomic
from ..errors import ParameterError

SUFFIXES = (".json",)
"""The extension of the JSON files written."""


def write_json(path, data, *, indent=1):
    """Write ``data`` as JSON to ``path`` atomically; numpy arrays and numbers become lists and numbers."""
    write_atomic(path, json_text(data, indent=indent))


def json_text(data, *, indent=1):
    """``data`` as JSON text (a final newline); numpy arrays and numbers become lists and numbers."""
    return json.dumps(data, indent=indent, default=_plain) + "\n"


def read_json(path, what):
    """The JSON document at ``path``; a missing, unreadable or invalid file is a ParameterError naming the ``what``."""
    try:
        return json.loads(Path(path).read_text())
    except FileNotFoundError:
        raise ParameterError(f"{what} {str(path)!r} is missing") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ParameterError(f"{what} {str(path)!r} is corrupt: {error}") from None


def _plain(value):
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return value.tolist()
    raise TypeError(f"cannot write {type(value).__name__} as JSON")
