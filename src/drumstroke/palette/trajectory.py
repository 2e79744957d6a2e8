"""Trajectory CSV files (moving to :mod:`drumstroke.formats`)."""

import io
from pathlib import Path

import numpy as np

from .._version import __version__
from ..errors import ParameterError
from ..trajectory import THETA_TOP, Trajectory

__all__ = ["THETA_TOP", "Trajectory", "csv_header", "csv_text", "read_csv", "read_trajectory_csv"]

def csv_header(model, name, rate):
    """The comment line of a trajectory CSV: the version, the model, the stroke and the rate."""
    return f"drumstroke {__version__}; model={model}; stroke={name or 'custom'}; rate={rate:g} Hz; units s, rad, rad/s"


def csv_text(comment, names, columns):
    """CSV text: one ``#`` comment line, a header of ``names``, then the columns at full precision."""
    buffer = io.StringIO()
    buffer.write(f"# {comment}\n")
    np.savetxt(buffer, np.column_stack(columns), delimiter=",", header=",".join(names), comments="", fmt="%.17g")
    return buffer.getvalue()


def read_csv(path, *, what="trajectory file"):
    """Read a CSV as drumstroke writes them: its ``#`` comment, column names and columns (all finite numbers).

    Returns
    -------
    comment : str
    columns : dict of str to ndarray [shape=(n,)]
        In file order; n ≥ 2.
    """
    where = f"{what} {str(path)!r}"
    try:
        text = Path(path).read_text()
    except (OSError, UnicodeDecodeError) as error:
        reason = error.strerror if isinstance(error, OSError) else "not a UTF-8 text file"
        raise ParameterError(f"{where} cannot be read: {reason}") from None
    lines = text.split("\n", 2)
    if len(lines) < 3 or not lines[0].startswith("#") or not lines[1].startswith("t,"):
        raise ParameterError(f"{where} is corrupt: it must start with a # line and a header such as t,theta,omega")
    names = lines[1].strip().split(",")
    try:
        data = np.loadtxt(io.StringIO(lines[2]), delimiter=",", ndmin=2)
    except ValueError as error:
        raise ParameterError(f"{where} is corrupt: {error}") from None
    if data.shape[1] != len(names) or len(data) < 2:
        raise ParameterError(f"{where} is corrupt: {len(data)} rows of {data.shape[1]} columns under the header "
                             f"{','.join(names)} (at least 2 rows needed)")
    finite = np.isfinite(data).all(axis=1)
    if not finite.all():
        raise ParameterError(f"{where} is corrupt: row {int(np.flatnonzero(~finite)[0])} is not finite")
    return lines[0][1:].strip(), dict(zip(names, data.T))


def read_trajectory_csv(path, *, stick=None):
    """t (s), θ (rad), ω (rad/s) and the model from a stroke, library or composition CSV.

    A composition with several sticks has ``theta_<stick>`` columns: name the
    ``stick`` to read.
    """
    comment, columns = read_csv(path)
    sticks = [name[len("theta_"):] for name in columns if name.startswith("theta_")]
    if stick is None and not sticks:
        keys = ("theta", "omega")
    elif stick is None:
        raise ParameterError(f"trajectory file {str(path)!r} has the sticks {', '.join(sticks)}; name one (stick)")
    elif stick in sticks:
        keys = (f"theta_{stick}", f"omega_{stick}")
    else:
        raise ParameterError(f"stick must be one of {', '.join(sticks) or '(none: one stick)'}, got {stick!r}")
    if not all(key in columns for key in keys):
        raise ParameterError(f"trajectory file {str(path)!r} needs the columns t,{','.join(keys)}")
    model = next((part.split("=", 1)[1] for part in comment.split("; ") if part.startswith("model=")), "unknown")
    return columns["t"], columns[keys[0]], columns[keys[1]], model
