"""A recording's onsets as CSV, both ways: ``t,level_db`` rows, or ``t,level_db,peak_db`` (the impacts found in a recording).

A file starts with its header ``t,level_db`` (onsets given as times and levels) or
``t,level_db,peak_db`` (onsets found in a recording), then one row per onset at full precision
(never ``-0``), so any CSV reader reads it as it is::

    t,level_db,peak_db
    0.10003125,0.0,0.0
    0.3125,-3.010299956639812,-2.5

``t`` is in s from the recording's start; ``level_db`` in dB re the loudest onset (≤ 0; the
loudest is 0): the drum's lowest modes' amplitude, in proportion to the stick's tip speed;
``peak_db`` in dB re the loudest onset's peak (≤ 0): each onset's broadband peak, the earlier
notes' sound taken off (:attr:`drumstroke.analysis.Onsets.peak_db`). What the header cannot say —
the drumstroke version, the source, the detection threshold (dB re the loudest; ``null`` when
the onsets were given, not detected), the units and what each column is — is in the JSON beside
the file (:mod:`.sidecar`).

Reading allows a byte-order mark (spreadsheets write one) and refuses, naming the file and the
line, anything but one of the two headers and rows of as many finite numbers; a file larger than
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
>>> t, level_db, peak_db, meta = read_onsets_csv(path)
>>> t.tolist(), level_db.tolist(), peak_db, meta["source"], meta["threshold_db"]
([0.1, 0.3125], [0.0, -3.0], None, 'drop.wav', -40.0)
>>> json.loads(path.with_suffix(".json").read_text())["csv"]["units"]
{'t': 's', 'level_db': 'dB re the loudest onset'}
>>> write_onsets_csv(path, [0.1, 0.3125], [0.0, -3.0], peak_db=[0.0, -2.5])
>>> print(path.read_text(), end="")
t,level_db,peak_db
0.1,0.0,0.0
0.3125,-3.0,-2.5
>>> read_onsets_csv(path)[2].tolist()
[0.0, -2.5]
"""

import io
import math
from pathlib import Path

import numpy as np

from .._atomic import bundled, write_atomic
from ..errors import ParameterError
from .reading import csv_rows, read_text
from .sidecar import describe, read_sidecar, sidecar_for, write_sidecar

SUFFIXES = (".csv",)
"""The extension of the onset files written."""

COLUMNS = ("t", "level_db")
"""The header of an onsets CSV without peaks (onsets given as times and levels)."""

PEAK_COLUMNS = (*COLUMNS, "peak_db")
"""The header of an onsets CSV with each onset's broadband peak (onsets found in a recording)."""

UNITS = {"t": "s", "level_db": "dB re the loudest onset", "peak_db": "dB re the loudest onset's peak"}
"""The unit of each column."""

MEANINGS = {"t": "the onset's time from the recording's start",
            "level_db": "the amplitude of the drum's lowest modes (in proportion to the stick's tip speed)",
            "peak_db": "the onset's broadband peak on the unfiltered signal, the earlier notes' sound taken off"}
"""What each column is (written in the JSON beside the file)."""

MAX_BYTES = 64 * 1024 * 1024
"""The largest onsets CSV read (bytes): ~2 million onsets, far more than any recording has."""


def check_onsets_path(path, *, name="out"):
    """``path`` as a Path if it names an onsets CSV (``.csv``); ``name`` is its parameter, for messages."""
    path = Path(path)
    if path.suffix.lower() not in SUFFIXES:
        raise ParameterError(f"{name} must end in .csv (an onsets CSV), got {str(path)!r}")
    return path


def onsets_text(t, level_db, peak_db=None):
    """CSV text: the header ``t,level_db`` (``t,level_db,peak_db`` with peaks), then one row per onset at full
    precision (no ``-0``)."""
    columns = (t, level_db) if peak_db is None else (t, level_db, peak_db)
    buffer = io.StringIO()
    buffer.write(",".join(COLUMNS if peak_db is None else PEAK_COLUMNS) + "\n")
    for row in zip(*columns):
        buffer.write(",".join(_number(value) for value in row) + "\n")
    return buffer.getvalue()


def write_onsets_csv(path, t, level_db, *, peak_db=None, fields=None, bundle=None):
    """Write onsets to the CSV at ``path`` and their metadata to the JSON beside it, atomically, together.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV, ending in ``.csv``, in an existing folder.
    t : array_like [shape=(n,)]
        Onset times (s from the recording's start).
    level_db : array_like [shape=(n,)]
        Onset levels (dB re the loudest onset).
    peak_db : array_like [shape=(n,)] or None
        Onset peaks (dB re the loudest onset's peak), written as a third column; None: no such column.
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
    columns = COLUMNS if peak_db is None else PEAK_COLUMNS
    fields = {**{key: _plain(value) for key, value in (fields or {}).items()},
              "meanings": {column: MEANINGS[column] for column in columns}}
    with bundled(bundle) as files:
        write_atomic(path, onsets_text(t, level_db, peak_db), bundle=files)
        write_sidecar(side, describe(path, columns, UNITS, fields), bundle=files)


def read_onsets_csv(path):
    """The onset times (s), levels (dB re the loudest), peaks (dB re the loudest peak) and metadata of the onsets CSV at ``path``.

    Returns
    -------
    t : ndarray [shape=(n,)]
    level_db : ndarray [shape=(n,)]
    peak_db : ndarray [shape=(n,)] or None
        None for a file without the column (``t,level_db``).
    metadata : dict
        The ``"csv"`` block of the JSON beside it (:mod:`.sidecar`), ``{}`` when there is none;
        its ``threshold_db`` is a float (``-inf`` for null).

    Raises
    ------
    ParameterError
        Naming the file (and the line): missing, not a regular file, larger than
        :data:`MAX_BYTES`, not UTF-8 text, no ``t,level_db`` or ``t,level_db,peak_db`` header first, a
        row that is not as many finite numbers or whose time does not follow the row before's; or
        metadata beside it that describes other columns.
    """
    where = f"onsets file {str(path)!r}"
    path = Path(path)
    text = read_text(path, "onsets file", limit=MAX_BYTES)
    plain = _plain_rows(text)
    if plain is not None:
        header, data = plain
        return data[:, 0], data[:, 1], data[:, 2] if len(header) == 3 else None, _metadata(path, header)
    lines = csv_rows(text, path, "onsets file", rows_of=" of 't,level_db' rows")
    header = tuple(cell.strip() for cell in lines[0]) if lines else ()
    if header not in (COLUMNS, PEAK_COLUMNS):
        first = ",".join(lines[0]) if lines else "(an empty file)"
        raise ParameterError(f"{where} line 1 must be the header {','.join(COLUMNS)} (or {','.join(PEAK_COLUMNS)}), "
                             f"got {first[:80]!r}")
    rows = []
    for number, row in enumerate(lines[1:], start=2):
        if not row:
            continue
        try:
            if len(row) != len(header):
                raise ValueError
            values = tuple(float(cell) for cell in row)
            if not all(math.isfinite(v) for v in values):
                raise ValueError
        except ValueError:
            raise ParameterError(f"{where} line {number} must be '{','.join(header)}' with "
                                 f"{'two' if len(header) == 2 else 'three'} finite numbers, got {','.join(row)[:80]!r}") from None
        if rows and values[0] <= rows[-1][0]:
            raise ParameterError(f"{where} line {number}: t = {values[0]!r} s comes after {rows[-1][0]!r} s on the "
                                 "line before; times must be strictly increasing")
        rows.append(values)
    data = np.array(rows, dtype=float).reshape(-1, len(header))
    return data[:, 0], data[:, 1], data[:, 2] if len(header) == 3 else None, _metadata(path, header)


def _plain_rows(text):
    """The header and the rows (an array) of an onsets CSV that holds nothing but finite numbers, increasing in time,
    one row a line ending in a newline alone; None for any other text, read row by row to name the line at fault.

    Reads a million rows in a fraction of the time the row-by-row reading takes: the numbers are
    converted all at once, as ``float`` converts each.
    """
    if '"' in text or "\r" in text or "\0" in text:  # quoted cells and other line ends: the csv module reads them
        return None
    lines = text.split("\n")
    header = tuple(cell.strip() for cell in lines[0].split(","))
    body = [line for line in lines[1:] if line]
    commas = len(header) - 1
    if header not in (COLUMNS, PEAK_COLUMNS) or not body or any(line.count(",") != commas for line in body):
        return None
    try:
        data = np.array(",".join(body).split(","), dtype=float).reshape(-1, len(header))
    except ValueError:
        return None
    if not np.isfinite(data).all() or (np.diff(data[:, 0]) <= 0.0).any():
        return None
    return header, data


def _metadata(path, columns):
    block = read_sidecar(path)
    if block is None or block.get("file") != path.name:
        return {}
    if block.get("columns") != list(columns):
        raise ParameterError(f"metadata {str(path.with_suffix('.json'))!r} describes the columns "
                             f"{block.get('columns')!r}, but the CSV beside it has {list(columns)!r}; remove or "
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
