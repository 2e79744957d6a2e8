"""The JSON beside a CSV: what a CSV file is, kept out of the CSV so any CSV reader reads it as it is.

Every CSV drumstroke writes starts with its header line. What the header cannot say — the
drumstroke version, the model, the name, the rate, each column's unit, the sticks — goes
in the JSON file beside it, ``X.json`` for ``X.csv``, under the key ``"csv"``::

    {"csv": {"file": "X.csv", "drumstroke": "0.1.0", "model": "paper", "name": "free-bounce",
             "rate": 1000.0, "sticks": ["stick"], "columns": ["t", "theta", "omega"],
             "units": {"t": "s", "theta": "rad", "omega": "rad/s"}}}

When the same run writes a JSON of its own at exactly that path (``simulate --json s.json
--csv s.csv``, a library stroke's ``NAME.json``), the ``"csv"`` block is added to that JSON
beside its other fields; otherwise a JSON holding only the block is written. The JSON beside
a CSV belongs to it: writing the CSV again rewrites it. A file already there that is not this
CSV's metadata (another program's, or another output of the same run) is never overwritten:
the write is refused before anything is written (:func:`sidecar_for`).

Examples
--------
>>> import json, pathlib, tempfile
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> block = describe(folder / "move.csv", ["t", "x"], {"t": "s", "x": "m"}, {"model": "paper"})
>>> write_sidecar(sidecar_for(folder / "move.csv"), block)
>>> json.loads((folder / "move.json").read_text())["csv"]["units"]
{'t': 's', 'x': 'm'}
>>> read_sidecar(folder / "move.csv")["model"]
'paper'
"""

import os
from pathlib import Path

from .._atomic import not_an_input, remove_stale
from .._version import __version__
from ..errors import ParameterError
from .json import read_json, write_json

KEY = "csv"
"""The key of a CSV's metadata in the JSON beside it."""


def sidecar_path(csv):
    """The JSON beside the CSV at ``csv``: the same name with the suffix ``.json``."""
    return Path(csv).with_suffix(".json")


def describe(csv, columns, units, fields):
    """The metadata block of the CSV at ``csv``: its file name, the drumstroke version, ``fields``, the columns.

    Parameters
    ----------
    csv : str or Path
    columns : sequence of str
        The header's names, in order.
    units : dict of str to str
        The unit of each column ("" for a number without one or text); a column not named has "".
    fields : dict
        What else the CSV is (model, name, rate, sticks, …), in the order to write.
    """
    return {"file": Path(csv).name, "drumstroke": __version__, **fields, "columns": list(columns),
            "units": {column: units.get(column, "") for column in columns}}


def sidecar_for(csv, *, json=None, others=None, name="csv"):
    """Where the metadata of the CSV at ``csv`` goes: the JSON to write beside it, or None for the run's ``json``.

    Parameters
    ----------
    csv : str or Path
    json : str, Path or None
        The JSON the same run writes of its own. If it is the JSON beside the CSV, the metadata
        goes into it (None is returned).
    others : dict of str to path, or None
        The run's other outputs by option name (``{"plot": ..., "wav": ...}``, None for those not asked for).
    name : str
        The CSV's option or parameter name, for messages.

    Returns
    -------
    Path or None

    Raises
    ------
    ParameterError
        When the JSON beside the CSV would be the CSV itself or one of ``others``, or is a file
        already there that is not this CSV's metadata: nothing must be overwritten unasked.
    """
    csv, side = Path(csv), sidecar_path(csv)
    if json is not None and _same(side, json):
        return None
    if _same(side, csv):
        raise ParameterError(f"{name} {str(csv)!r} must not end in .json: its metadata goes in the JSON beside it, "
                             f"{str(side)!r}")
    for option, path in (others or {}).items():
        if path is not None and _same(side, path):
            raise ParameterError(f"{name} {str(csv)!r} keeps its metadata in {str(side)!r}, which is also the "
                                 f"{option} file; name one of them differently")
    if side.exists() and not _describes(side, csv):
        raise ParameterError(f"{name} {str(csv)!r} keeps its metadata in {str(side)!r}, a file that is already there "
                             f"and is not drumstroke's metadata of {csv.name!r}; move that file away or name the CSV "
                             "differently")
    return side


def write_sidecar(path, block, *, bundle=None):
    """Write a JSON holding only a CSV's metadata ``block`` to ``path``, atomically (in ``bundle``, if given)."""
    write_json(path, {KEY: block}, bundle=bundle)


def read_sidecar(csv):
    """The metadata block of the CSV at ``csv`` from the JSON beside it, or None when there is none.

    A missing JSON, one that cannot be read (:func:`.json.read_json`), and one without a
    ``"csv"`` table (an older drumstroke's, another program's) all give None: the CSV is then
    read on its own.
    """
    return _block(sidecar_path(csv))


def read_sidecar_document(csv):
    """The whole JSON beside the CSV at ``csv``, read as :func:`read_sidecar` reads it (errors raised here)."""
    return _document(sidecar_path(csv))


def _document(side):
    """The JSON at ``side``: it describes its CSV, which is the input, and a command may write over it (``robot
    export p.csv --out p.json``), so it is not noted as an input of the run (:func:`drumstroke._atomic.note_input`)."""
    with not_an_input():
        return read_json(side, "metadata")


def _describes(side, csv):
    """Whether the JSON ``side`` holds the metadata of the CSV ``csv`` (so writing that CSV may rewrite it).

    A killed writer's bundle that lists it is finished first, as the write would.
    """
    remove_stale(side.parent, side.name)
    block = _block(side)
    return block is not None and block.get("file") == csv.name


def _block(side):
    """The ``"csv"`` table of the JSON at ``side``, or None (no such file, not readable JSON, no such table)."""
    try:
        data = _document(side)
    except ParameterError:
        return None
    block = data.get(KEY) if isinstance(data, dict) else None
    return block if isinstance(block, dict) else None


def _same(a, b):
    return os.path.realpath(a) == os.path.realpath(b)  # not resolve(): it raises on a link loop
