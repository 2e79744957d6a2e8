"""Trajectory CSV, both ways: the samples of one stick or several at a control rate.

A file is one ``#`` comment line (the drumstroke version, the model, the name, the rate and
the units), the header, then one row per sample at full precision (17 significant digits)::

    # drumstroke 0.1.0; model=paper; stroke=free-bounce; rate=1000 Hz; units s, rad, rad/s
    t,theta,omega
    0,2.2204460492503131e-16,0
    ...

One stick has the columns ``t,theta,omega`` (an export adds ``alpha``, rad/s²); several have
``t`` then ``theta_<stick>,omega_<stick>`` for each stick in turn. numpy's ``loadtxt`` and
``genfromtxt`` skip the comment line by default; pandas needs ``comment="#"``.

Examples
--------
>>> import pathlib, tempfile
>>> import numpy as np
>>> path = pathlib.Path(tempfile.mkdtemp()) / "move.csv"
>>> t = np.arange(3) / 1000.0
>>> write_columns(path, ("t", "theta", "omega"), (t, 0.1 * t, np.full(3, 0.1)),
...               comment=comment_line("paper", "move", 1000.0))
>>> comment, columns = read_columns(path)
>>> stated_rate(comment), list(columns), bool(np.array_equal(columns["t"], t))
(1000.0, ['t', 'theta', 'omega'], True)
"""

import io
import re
from pathlib import Path

import numpy as np

from .._atomic import write_atomic
from .._version import __version__
from ..errors import ParameterError

SUFFIXES = (".csv",)
"""The extension of the trajectory files written."""

UNITS = "units s, rad, rad/s"

_RATE = re.compile(r"(?:^|; )rate=([^ ;]+) Hz(?:;|$)")


def comment_line(model, name, rate):
    """The comment line of a trajectory CSV: the version, the model, the name and the rate (Hz)."""
    return f"drumstroke {__version__}; model={model}; stroke={name or 'custom'}; rate={rate:g} Hz; {UNITS}"


def columns_text(comment, names, columns):
    """CSV text: one ``#`` comment line, a header of ``names``, then the columns at full precision."""
    buffer = io.StringIO()
    buffer.write(f"# {comment}\n")
    np.savetxt(buffer, np.column_stack(columns), delimiter=",", header=",".join(names), comments="", fmt="%.17g")
    return buffer.getvalue()


def write_columns(path, names, columns, *, comment):
    """Write columns (1-D arrays of one length) under ``names`` with the ``comment`` line, atomically."""
    write_atomic(path, columns_text(comment, names, columns))


def stick_columns(sticks, theta, omega, alpha=None):
    """Column names and arrays for θ, ω (and α) of one stick (``theta``) or several (``theta_<stick>``).

    ``theta``, ``omega``, ``alpha`` are [shape=(n,)] for one stick, (n, sticks) for several.
    """
    if len(sticks) == 1:
        names, columns = ["theta", "omega"], [np.reshape(theta, -1), np.reshape(omega, -1)]
        if alpha is not None:
            names.append("alpha")
            columns.append(np.reshape(alpha, -1))
        return names, columns
    names, columns = [], []
    for j, stick in enumerate(sticks):
        names += [f"theta_{stick}", f"omega_{stick}"] + ([f"alpha_{stick}"] if alpha is not None else [])
        columns += [theta[:, j], omega[:, j]] + ([alpha[:, j]] if alpha is not None else [])
    return names, columns


def read_columns(path, *, what="trajectory file"):
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


def sticks_in(columns):
    """The stick names of a several-stick file's columns (``theta_<stick>``), or () for one stick."""
    return tuple(name[len("theta_"):] for name in columns if name.startswith("theta_"))


def read_stick(path, *, stick=None):
    """t (s), θ (rad), ω (rad/s), α (rad/s², or None) and the comment of one stick of a trajectory CSV.

    A file with several sticks has ``theta_<stick>`` columns: name the ``stick`` to read.
    """
    comment, columns = read_columns(path)
    return (*stick_of(columns, stick, path), comment)


def stick_of(columns, stick, path):
    """t, θ, ω and α (or None) of one stick from a file's ``columns`` (see :func:`read_stick`)."""
    sticks = sticks_in(columns)
    if stick is None and not sticks:
        keys = ("theta", "omega", "alpha")
    elif stick is None:
        raise ParameterError(f"trajectory file {str(path)!r} has the sticks {', '.join(sticks)}; name one (stick)")
    elif stick in sticks:
        keys = (f"theta_{stick}", f"omega_{stick}", f"alpha_{stick}")
    else:
        raise ParameterError(f"stick must be one of {', '.join(sticks) or '(none: one stick)'}, got {stick!r}")
    if not all(key in columns for key in keys[:2]):
        raise ParameterError(f"trajectory file {str(path)!r} needs the columns t,{','.join(keys[:2])}")
    return columns["t"], columns[keys[0]], columns[keys[1]], columns.get(keys[2])


def stated_model(comment):
    """The ``model=`` of a comment line, or "unknown"."""
    return next((part.split("=", 1)[1] for part in comment.split("; ") if part.startswith("model=")), "unknown")


def stated_rate(comment):
    """The ``rate=… Hz`` of a comment line (Hz), or None when it states none."""
    match = _RATE.search(comment.lstrip("#").strip())
    if match is None:
        return None
    try:
        return float(match.group(1))
    except ValueError:
        return None
