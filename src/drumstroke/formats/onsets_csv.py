"""A recording's onsets as CSV, both ways: ``t,level_db`` rows (the impacts found in a recording).

A file starts with its header ``t,level_db``, then one row per onset at full precision (never
``-0``), so any CSV reader reads it as it is::

    t,level_db
    0.10003125,0.0
    0.3125,-3.010299956639812

``t`` is in s from the recording's start, ``level_db`` in dB re the loudest onset (≤ 0; the
loudest is 0). What the header cannot say — the drumstroke version, the source, the detection
threshold (dB re the loudest; ``null`` when the onsets were given, not detected), the units —
is in the JSON beside the file (:mod:`.sidecar`).

Reading allows a byte-order mark (spreadsheets write one) and refuses, naming the file and the
line, anything but the header and rows of two finite numbers; a file larger than
:data:`MAX_BYTES` is refused unread. The onsets' own checks (times increasing, levels ≤ 0) are
:class:`drumstroke.analysis.Onsets`'s.

Examples
--------
>>> import json, pathlib, tempfile
>>> path = pathlib.Path(tempfile.mkdtemp()) / "onsets.csv"
>>> write_onsets_csv(path, [0.1, 0.3125], [0.0, -3.0], fields={"source": "drop.wav", "threshold_db": -40.0})
>>> print(path.read_text(), end="")
t,level_db
0.1,0.0
0.3125,-3.0
>>> t, level_db, meta = read_onsets_csv(path)
>>> t.tolist(), level_db.tolist(), meta["source"], meta["threshold_db"]
([0.1, 0.3125], [0.0, -3.0], 'drop.wav', -40.0)
>>> json.loads(path.with_suffix(".json").read_text())["csv"]["units"]
{'t': 's', 'level_db': 'dB re the loudest onset'}
"""

import io
import math
from pathlib import Path

import numpy as np

from .._atomic import bundled, write_atomic
from ..errors import ParameterError
from .reading import read_csv_rows
from .sidecar import describe, read_sidecar, sidecar_for, write_sidecar

SUFFIXES = (".csv",)
"""The extension of the onset files written."""

COLUMNS = ("t", "level_db")
"""The header of an onsets CSV."""

UNITS = {"t": "s", "level_db": "dB re the loudest onset"}
"""The unit of each column."""

MAX_BYTES = 64 * 1024 * 1024
"""The largest onsets CSV read (bytes): ~2 million onsets, far more than any recording has."""


def check_onsets_path(path, *, name="out"):
    """``path`` as a Path if it names an onsets CSV (``.csv``); ``name`` is its parameter, for messages."""
    path = Path(path)
    if path.suffix.lower() not in SUFFIXES:
        raise ParameterError(f"{name} must end in .csv (an onsets CSV), got {str(path)!r}")
    return path


def onsets_text(t, level_db):
    """CSV text: the header ``t,level_db``, then one row per onset at full precision (no ``-0``)."""
    buffer = io.StringIO()
    buffer.write(",".join(COLUMNS) + "\n")
    for ti, li in zip(t, level_db):
        buffer.write(f"{_number(ti)},{_number(li)}\n")
    return buffer.getvalue()


def write_onsets_csv(path, t, level_db, *, fields=None, bundle=None):
    """Write onsets to the CSV at ``path`` and their metadata to the JSON beside it, atomically, together.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV, ending in ``.csv``, in an existing folder.
    t : array_like [shape=(n,)]
        Onset times (s from the recording's start).
    level_db : array_like [shape=(n,)]
        Onset levels (dB re the loudest onset).
    fields : dict or None
        What else the JSON beside it says, in order (``source``, ``threshold_db`` in dB re the
        loudest — a non-finite one is written as null —, how they were found).
    bundle : Bundle or None
        A :class:`drumstroke._atomic.Bundle` to put the files in place with (default: a bundle of their own).

    Raises
    ------
    ParameterError
        Before writing anything, for a path not ending in ``.csv`` or when the JSON beside it is a
        file already there that is not this CSV's metadata (:func:`.sidecar.sidecar_for`).
    """
    path = check_onsets_path(path, name="path")
    side = sidecar_for(path, name="path")
    fields = {key: _plain(value) for key, value in (fields or {}).items()}
    with bundled(bundle) as files:
        write_atomic(path, onsets_text(t, level_db), bundle=files)
        write_sidecar(side, describe(path, COLUMNS, UNITS, fields), bundle=files)


def read_onsets_csv(path):
    """The onset times (s), levels (dB re the loudest) and metadata of the onsets CSV at ``path``.

    Returns
    -------
    t : ndarray [shape=(n,)]
    level_db : ndarray [shape=(n,)]
    metadata : dict
        The ``"csv"`` block of the JSON beside it (:mod:`.sidecar`), ``{}`` when there is none;
        its ``threshold_db`` is a float (``-inf`` for null).

    Raises
    ------
    ParameterError
        Naming the file (and the line): missing, not a regular file, larger than
        :data:`MAX_BYTES`, not UTF-8 text, no ``t,level_db`` header first, a row that is not two
        finite numbers or whose time does not follow the row before's; or metadata beside it that
        describes other columns.
    """
    where = f"onsets file {str(path)!r}"
    path = Path(path)
    lines = read_csv_rows(path, "onsets file", limit=MAX_BYTES, rows_of=" of 't,level_db' rows")
    if not lines or tuple(cell.strip() for cell in lines[0]) != COLUMNS:
        first = ",".join(lines[0]) if lines else "(an empty file)"
        raise ParameterError(f"{where} line 1 must be the header {','.join(COLUMNS)}, got {first[:80]!r}")
    rows = []
    for number, row in enumerate(lines[1:], start=2):
        if not row:
            continue
        try:
            if len(row) != 2:
                raise ValueError
            values = (float(row[0]), float(row[1]))
            if not all(math.isfinite(v) for v in values):
                raise ValueError
        except ValueError:
            raise ParameterError(f"{where} line {number} must be 't,level_db' with two finite numbers, got "
                                 f"{','.join(row)[:80]!r}") from None
        if rows and values[0] <= rows[-1][0]:
            raise ParameterError(f"{where} line {number}: t = {values[0]!r} s comes after {rows[-1][0]!r} s on the "
                                 "line before; times must be strictly increasing")
        rows.append(values)
    data = np.array(rows, dtype=float).reshape(-1, 2)
    return data[:, 0], data[:, 1], _metadata(path)


def _metadata(path):
    block = read_sidecar(path)
    if block is None or block.get("file") != path.name:
        return {}
    if block.get("columns") != list(COLUMNS):
        raise ParameterError(f"metadata {str(path.with_suffix('.json'))!r} describes the columns "
                             f"{block.get('columns')!r}, but the CSV beside it has {list(COLUMNS)!r}; remove or "
                             "rewrite the JSON")
    block = dict(block)
    threshold = block.get("threshold_db")
    if threshold is None:
        block["threshold_db"] = -math.inf
    elif isinstance(threshold, bool) or not isinstance(threshold, (int, float)) or threshold > 0.0:
        raise ParameterError(f"metadata {str(path.with_suffix('.json'))!r}: csv.threshold_db must be a number ≤ 0 "
                             f"dB or null, got {threshold!r}")
    else:
        block["threshold_db"] = float(threshold)
    return block


def _number(value):
    return repr(float(value) + 0.0)  # + 0.0: never "-0.0"


def _plain(value):
    """A field for JSON: non-finite floats as None (JSON has no infinity)."""
    if isinstance(value, (float, np.floating)) and not math.isfinite(value):
        return None
    return value
