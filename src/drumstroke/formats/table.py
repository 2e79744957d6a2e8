"""Tables of results, both ways where it makes sense: a sweep's columns as CSV (a header line, then rows) or parquet.

CSV cells are numbers at full precision (``repr``), text as is, and NaN as an empty cell;
parquet keeps the columns' types (needs pyarrow, the ``sweep`` extra) and records the
drumstroke version in its metadata. Writes are atomic.

Examples
--------
>>> import pathlib, tempfile
>>> import numpy as np
>>> path = pathlib.Path(tempfile.mkdtemp()) / "sweep.csv"
>>> write_table({"point": np.arange(2), "rate_hz": np.array([1.5, np.nan])}, path)
>>> read_table(path)
{'point': ['0', '1'], 'rate_hz': ['1.5', '']}
"""

import csv
import io
import math
from pathlib import Path

import numpy as np

from .._atomic import write_atomic
from .._version import __version__
from ..errors import ParameterError

SUFFIXES = (".csv", ".parquet")
"""The extensions of the tables written."""


def check_table_path(path, *, name="out"):
    """``path`` as a Path if it names a table this module writes (.csv or .parquet); ``name`` is its parameter."""
    path = Path(path)
    if path.suffix not in SUFFIXES:
        raise ParameterError(f"{name} must end in .csv or .parquet, got {str(path)!r}")
    return path


def write_table(table, path):
    """Write a sweep's columns to ``path``: ``.csv`` or ``.parquet`` (needs pyarrow), atomically."""
    path = check_table_path(path)
    if path.suffix == ".csv":
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(table)
        for row in zip(*table.values()):
            writer.writerow(_cell(value) for value in row)
        write_atomic(path, buffer.getvalue())
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
        write_atomic(path, buffer.getvalue())


def read_table(path):
    """A CSV table's columns as text, by header name (``{name: [cell, ...]}``)."""
    try:
        with open(path, newline="") as handle:
            rows = list(csv.reader(handle))
    except (OSError, UnicodeDecodeError) as error:
        reason = error.strerror if isinstance(error, OSError) else "not a UTF-8 text file"
        raise ParameterError(f"table {str(path)!r} cannot be read: {reason}") from None
    if not rows:
        raise ParameterError(f"table {str(path)!r} is empty: it needs a header line")
    return {name: [row[i] for row in rows[1:]] for i, name in enumerate(rows[0])}


def _cell(value):
    if isinstance(value, (float, np.floating)):
        return "" if math.isnan(value) else repr(float(value))
    return value
