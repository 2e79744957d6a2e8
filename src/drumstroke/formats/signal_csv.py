"""A recorded signal as CSV, both ways: ``t,value`` rows (a thumb-force recording, a ``samples`` profile).

Reading allows a byte-order mark (spreadsheets write one), ``#`` comment lines and one header
row before the numbers; every other line must hold two numbers. The values' checks (times
increasing, ranges) are the profile's.

Examples
--------
>>> import pathlib, tempfile
>>> path = pathlib.Path(tempfile.mkdtemp()) / "thumb.csv"
>>> write_signal(path, [0.0, 0.1], [0.0, 140.0])
>>> read_signal(path, "samples.file")
[(0.0, 0.0), (0.1, 140.0)]
"""

import io

from .._atomic import write_atomic
from ..errors import ParameterError
from .reading import MIB, read_csv_rows

MAX_BYTES = 64 * MIB
"""The largest signal file read (bytes): about a million samples."""


def read_signal(path, what):
    """The ``(t, value)`` rows of the CSV at ``path``, as floats; errors name ``what``, the file and the line."""
    where = f"{what} {str(path)!r}"
    lines = read_csv_rows(path, what, limit=MAX_BYTES, rows_of=" of 't,value' rows")
    rows = []
    for number, row in enumerate(lines, start=1):
        if not row or row[0].lstrip().startswith("#"):
            continue
        try:
            if len(row) != 2:
                raise ValueError
            rows.append((float(row[0]), float(row[1])))
        except ValueError:
            is_header = not rows and not any(_is_number(cell) for cell in row)
            if not is_header:
                raise ParameterError(f"{where} line {number} must be 't,value' with two numbers, got "
                                     f"{','.join(row)!r}", parameter=what, value=str(path)) from None
    if not rows:
        raise ParameterError(f"{where} has no 't,value' rows", parameter=what, value=str(path))
    return rows


def write_signal(path, t, values, *, header="t,value"):
    """Write a signal as CSV: the ``header`` line, then one ``t,value`` row per sample, at full precision (no -0.0)."""
    buffer = io.StringIO()
    buffer.write(header + "\n")
    for ti, vi in zip(t, values):
        buffer.write(f"{float(ti) + 0.0!r},{float(vi) + 0.0!r}\n")
    write_atomic(path, buffer.getvalue())


def _is_number(text):
    try:
        float(text)
    except ValueError:
        return False
    return True
