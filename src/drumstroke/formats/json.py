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
import os

import numpy as np

from .._atomic import write_atomic
from ..errors import ParameterError
from .reading import MAX_DEPTH, MIB, check_document, parse_int, read_text

SUFFIXES = (".json",)
"""The extension of the JSON files written."""

MAX_BYTES = 64 * MIB
"""The largest JSON file read (bytes): a stroke's, a composition's or a library manifest is far smaller."""


def write_json(path, data, *, indent=1, bundle=None):
    """Write ``data`` as JSON to ``path`` atomically; numpy arrays and numbers become lists and numbers.

    ``bundle``: a :class:`drumstroke._atomic.Bundle` the file is put in place with (default: at once)."""
    write_atomic(path, json_text(data, indent=indent), bundle=bundle)


def json_text(data, *, indent=1):
    """``data`` as JSON text (a final newline); numpy arrays and numbers become lists and numbers."""
    return json.dumps(data, indent=indent, default=_plain) + "\n"


def read_json(path, what, *, limit=MAX_BYTES):
    """The JSON document at ``path``, read within bounds (:mod:`.reading`).

    A missing, unreadable or invalid file, one that nests deeper than
    :data:`~drumstroke.formats.reading.MAX_DEPTH` or holds an integer beyond a float, is a
    ParameterError naming the ``what`` and the path. ``limit`` is the most bytes it may hold.
    """
    where = f"{what} {str(path)!r}"
    try:
        text = read_text(path, what, limit=limit)
    except ParameterError:
        if not _exists(path):
            raise ParameterError(f"{where} is missing") from None
        raise
    data = loads(text, where)
    check_document(data, where)
    return data


def loads(text, where):
    """The JSON document in ``text`` (from ``where``, named in errors), its integers bounded (:mod:`.reading`).

    Too deep a nesting, which would exhaust the stack, and invalid JSON are ParameterErrors.
    """
    try:
        return json.loads(text, parse_int=parse_int)
    except json.JSONDecodeError as error:
        raise ParameterError(f"{where} is not readable JSON: {error}") from None
    except RecursionError:
        raise ParameterError(f"{where} is not readable JSON: its objects or arrays nest more than {MAX_DEPTH} levels "
                             "deep, the most a file may") from None


def impact_columns(rows, where, *, start, end):
    """The impacts of a stroke's, a composition's or a library's JSON (``"impacts"``, one row each), as arrays.

    Parameters
    ----------
    rows : list of dict
        Each with ``t`` (s) and ``omega`` (rad/s), and ``omega_after`` (rad/s) in all or none, as
        :meth:`drumstroke.Trajectory.to_dict` (all) and :meth:`drumstroke.Stroke.to_dict` (none) write them.
    where : str
        The file, as errors name it.
    start, end : float
        The span (s) the impacts must lie in: the samples' first and last times.

    Returns
    -------
    t, omega : ndarray [shape=(m,)]
    omega_after : ndarray [shape=(m,)] or None
        None when the rows do not record it.

    Raises
    ------
    ParameterError
        Rows without those numbers, numbers not finite, impacts out of time order or outside
        [start, end], moving up before (ω > 0) or down after.
    """
    try:
        keys = ("t", "omega", "omega_after") if rows and all("omega_after" in row for row in rows) else ("t", "omega")
        table = np.array([[row[key] for key in keys] for row in rows], dtype=float).reshape(-1, len(keys))
    except (KeyError, TypeError, ValueError):
        raise ParameterError(f"{where}: it needs impacts with t, omega (and omega_after)") from None
    t, omega, after = (*table.T, None)[:3]
    if not np.all(np.isfinite(table)):
        raise ParameterError(f"{where}: {len(t)} impacts, not all finite")
    if (np.any(np.diff(t) < 0) or (len(t) and (t[0] < start or t[-1] > end)) or np.any(omega > 0)
            or (after is not None and np.any(after < 0))):
        raise ParameterError(f"{where}: impacts must be in time order within [{start:g}, {end:g}] s, moving "
                             "down before (omega <= 0) and up after (omega_after >= 0)")
    return t, omega, after


def _exists(path):
    try:
        return os.path.lexists(path)
    except ValueError:  # a NUL in the name
        return False


def _plain(value):
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return value.tolist()
    raise TypeError(f"cannot write {type(value).__name__} as JSON")
