"""Tables of results, both ways where it makes sense: a sweep's columns as CSV (a header line, then rows) or parquet.

CSV cells are numbers at full precision (``repr``, never ``-0.0``), text as is, and NaN as an
empty cell; the JSON beside a CSV (:mod:`.sidecar`) holds the drumstroke version, the columns'
units and what else the writer says of the table. Parquet keeps the columns' types (needs
pyarrow, the ``sweep`` extra) and records the drumstroke version in its metadata. Writes are
atomic.

Examples
--------
>>> import json, pathlib, tempfile
>>> import numpy as np
>>> path = pathlib.Path(tempfile.mkdtemp()) / "sweep.csv"
>>> write_table({"point": np.arange(2), "rate_hz": np.array([1.5, np.nan])}, path, units={"rate_hz": "Hz"})
>>> read_table(path)
{'point': ['0', '1'], 'rate_hz': ['1.5', '']}
>>> json.loads(path.with_suffix(".json").read_text())["csv"]["units"]
{'point': '', 'rate_hz': 'Hz'}
"""

import csv
import io
import math
from pathlib import Path

import numpy as np

from .._atomic import bundled, write_atomic
from .._version import __version__
from ..errors import ParameterError
from .reading import MIB, read_csv_rows
from .sidecar import describe, sidecar_for, write_sidecar

SUFFIXES = (".csv", ".parquet")
"""The extensions of the tables written."""

MAX_BYTES = 256 * MIB
"""The largest CSV table read (bytes)."""


def check_table_path(path, *, name="out"):
    """``path`` as a Path if it names a table this module writes (.csv or .parquet); ``name`` is its parameter."""
    path = Path(path)
    if path.suffix not in SUFFIXES:
        raise ParameterError(f"{name} must end in .csv or .parquet, got {str(path)!r}")
    return path


def write_table(table, path, *, units=None, fields=None, bundle=None):
    """Write a sweep's columns to ``path``: ``.csv`` or ``.parquet`` (needs pyarrow), atomically.

    A CSV and the JSON beside it are put in place together.

    Parameters
    ----------
    table : dict of str to ndarray
        The columns by name, in order, of one length.
    path : str or Path
    units : dict of str to str, or None
        A CSV's columns' units, for the JSON beside it ("" for those not named).
    fields : dict or None
        What else that JSON says of the table.
    bundle : Bundle or None
        A :class:`drumstroke._atomic.Bundle` to put the files in place with (default: a bundle of their own).

    Raises
    ------
    ParameterError
        Before writing anything, when the JSON beside a CSV is a file already there that is not
        its metadata (:func:`.sidecar.sidecar_for`).
    """
    path = check_table_path(path)
    if path.suffix == ".csv":
        side = sidecar_for(path, name="path")
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(table)
        for row in zip(*table.values()):
            writer.writerow(_cell(value) for value in row)
        with bundled(bundle) as files:
            write_atomic(path, buffer.getvalue(), bundle=files)
            write_sidecar(side, describe(path, list(table), units or {}, fields or {}), bundle=files)
    else:
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError:
            raise ImportError("writing parquet needs pyarrow: pip install 'drumstroke[sweep]'") from None
        arrow = pa.table({name: list(values) if values.dtype == object else values for name, values in table.items()})
        arrow = arrow.replace_schema_metadata({"drumstroke": __version__})
        buffer = io.BytesIO()
        pq.write_table(arrow, buffer)
        write_atomic(path, buffer.getvalue(), bundle=bundle)


def read_table(path):
    """A CSV table's columns as text, by header name (``{name: [cell, ...]}``)."""
    rows = read_csv_rows(path, "table", limit=MAX_BYTES)
    if not rows:
        raise ParameterError(f"table {str(path)!r} is empty: it needs a header line")
    return {name: [row[i] for row in rows[1:]] for i, name in enumerate(rows[0])}


def _cell(value):
    if isinstance(value, (float, np.floating)):
        return "" if math.isnan(value) else repr(float(value) + 0.0)  # + 0.0: never "-0.0"
    return value
