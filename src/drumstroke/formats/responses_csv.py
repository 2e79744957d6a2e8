"""A listening test's responses as CSV, both ways: one row per subject and pair.

The header is ``subject,pair,robot,answer,confidence,similarity``: who answered, which pair,
which stimulus was the robot (A or B), the answer to "which is the robot?" (A or B), how
sure (1–5) and how similar (1–5). The values' checks are :func:`drumstroke.evaluation.stats.parse_responses`'s.

Examples
--------
>>> import pathlib, tempfile
>>> path = pathlib.Path(tempfile.mkdtemp()) / "responses.csv"
>>> write_responses_csv(path, [("s1", "p1", "A", "B", 3, 4)])
>>> read_responses_csv(path)
[['s1', 'p1', 'A', 'B', '3', '4']]
"""

import csv
import io

from .._atomic import write_atomic
from ..errors import ParameterError
from .reading import MIB, read_csv_rows

COLUMNS = ("subject", "pair", "robot", "answer", "confidence", "similarity")

MAX_BYTES = 16 * MIB
"""The largest responses file read (bytes): some 400,000 answers."""


def read_responses_csv(path, columns=COLUMNS):
    """The rows (lists of text) under the header ``columns`` of the CSV at ``path``; errors name the file."""
    rows = read_csv_rows(path, "responses", limit=MAX_BYTES)
    if not rows or tuple(c.strip() for c in rows[0]) != tuple(columns):
        raise ParameterError(f"responses {str(path)!r} must start with the header {','.join(columns)}")
    return rows[1:]


def responses_text(rows):
    """CSV text of response rows under the header (as an export sends it)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(COLUMNS)
    writer.writerows(rows)
    return buffer.getvalue()


def write_responses_csv(path, rows):
    """Write response rows as CSV under the header, atomically."""
    write_atomic(path, responses_text(rows))
