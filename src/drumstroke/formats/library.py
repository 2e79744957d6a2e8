"""The stroke library on disk, both ways: a folder of plain text files a robot host loads at run time.

A library folder holds ``manifest.json`` and one folder of stroke files. Per stroke there are
three files:

- ``NAME.toml``: the recipe it was simulated from (a recipe file);
- ``NAME.csv``: the trajectory ``t,theta,omega`` (s, rad, rad/s) at the library's rate, header
  first (:mod:`.trajectory_csv`);
- ``NAME.json``: its impacts (time s, ω before and after rad/s, tip speed m/s, level dB), how
  it was made (the transforms, in order) and, as the JSON beside ``NAME.csv``, that CSV's
  metadata under ``"csv"`` (:mod:`.sidecar`).

Libraries of format version 1 (older drumstroke) are read too: their ``NAME.csv`` has a ``#``
comment line before the header and their ``NAME.json`` no ``"csv"`` block.

The manifest lists the strokes with their category, description, sizes and each file's
SHA-256. Writing stages a new stroke folder beside the old one (:class:`Staging`), then
replaces the manifest in one atomic rename, then removes the old folder: a build interrupted
at any point leaves the previous library whole and loadable. Reading (:func:`read_library`)
checks everything — manifest and files agree, values finite, times on the library's rate, the
stick never below the head — and names the file at fault. Both directions deal in plain data
(texts, dicts, arrays); :mod:`drumstroke.palette.library` maps it to strokes.
"""

import hashlib
import math
import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._atomic import write_atomic
from .._checks import check_int, check_real
from .._version import __version__
from ..errors import ParameterError
from .json import json_text, read_json
from .trajectory_csv import read_columns

FORMAT = "drumstroke-library"
FORMAT_VERSION = 2
"""The version written: 2 since the CSV files start with their header (1 had a ``#`` comment line first)."""
READ_VERSIONS = (1, 2)
"""The versions read."""
MANIFEST = "manifest.json"
KINDS = ("recipe", "trajectory", "impacts")
"""The files of a stroke, by kind: NAME.toml, NAME.csv, NAME.json."""
_SUFFIX = {"recipe": ".toml", "trajectory": ".csv", "impacts": ".json"}


class Staging:
    """A library being written: stroke files go into a hidden folder until :meth:`commit` swaps it in.

    Parameters
    ----------
    directory : str or Path
        The library folder; created if missing.
    """

    def __init__(self, directory):
        directory = Path(directory)
        if directory.exists() and not directory.is_dir():
            raise ParameterError(f"directory {str(directory)!r} exists and is not a folder")
        directory.mkdir(parents=True, exist_ok=True)
        self.directory = directory
        self.folder = Path(tempfile.mkdtemp(dir=directory, prefix=".strokes-"))
        self.records = []

    def add(self, record, texts):
        """Write one stroke's files from ``texts`` ({kind: text}) and keep its manifest ``record`` (a dict)."""
        name = record["name"]
        files = {kind: f"{name}{_SUFFIX[kind]}" for kind in KINDS}
        for kind, file in files.items():
            (self.folder / file).write_text(texts[kind])
        self.records.append(record | {"files": files,
                                      "sha256": {kind: _sha256(self.folder / f) for kind, f in files.items()}})
        return self.records[-1]

    def commit(self, rate):
        """Swap the staged strokes in: their folder named by its contents, the manifest replaced atomically."""
        digest = hashlib.sha256("".join(f for r in self.records for f in r["sha256"].values()).encode()).hexdigest()
        folder = f"strokes-{digest[:16]}"
        if (self.directory / folder).exists():
            shutil.rmtree(self.folder)
        else:
            os.replace(self.folder, self.directory / folder)
        manifest = {"format": FORMAT, "version": FORMAT_VERSION, "drumstroke": __version__, "rate": rate,
                    "folder": folder, "strokes": self.records}
        write_atomic(self.directory / MANIFEST, json_text(manifest))
        for old in self.directory.glob("strokes-*"):
            if old.name != folder and old.is_dir():
                shutil.rmtree(old, ignore_errors=True)
        return folder

    def discard(self):
        """Remove the staged files; the library as it was stays."""
        shutil.rmtree(self.folder, ignore_errors=True)


@dataclass(frozen=True)
class StoredStroke:
    """One stroke as read from a library: its manifest record, its recipe file and its checked arrays.

    Attributes
    ----------
    record : dict
        The manifest's entry (name, category, description, model, theta_max, t_end, history, …).
    recipe : Path
        Its recipe file.
    t, theta, omega : ndarray [shape=(n,)]
        s, rad, rad/s at the library's rate.
    impact_t, impact_omega, omega_after : ndarray [shape=(m,)]
        s; rad/s before (≤ 0) and after (≥ 0) each impact.
    tip_distance : float
        m.
    """

    record: dict
    recipe: Path
    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    impact_t: np.ndarray
    impact_omega: np.ndarray
    omega_after: np.ndarray
    tip_distance: float


def _sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def read_library(directory):
    """Read and check a library folder: its rate (Hz) and a :class:`StoredStroke` per stroke, in order.

    Raises ParameterError naming the file when the manifest or a stroke file
    is missing, unreadable, altered (its SHA-256 differs from the manifest's),
    or holds values that are not finite, off the library's rate, below the head
    or inconsistent with the manifest.
    """
    directory = Path(directory)
    manifest_path = directory / MANIFEST
    manifest = read_json(manifest_path, "library manifest")
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        raise ParameterError(f"library manifest {str(manifest_path)!r} is not a drumstroke library manifest")
    if manifest.get("version") not in READ_VERSIONS or isinstance(manifest.get("version"), bool):
        raise ParameterError(f"library manifest {str(manifest_path)!r} has version {manifest.get('version')!r}; "
                             f"this drumstroke reads the versions {', '.join(map(str, READ_VERSIONS))}")
    try:
        rate = check_real("rate", manifest.get("rate"), low=1.0, high=1e5, unit="Hz")
        folder = directory / _safe_name(manifest.get("folder"), "folder")
        records = manifest.get("strokes")
        if not isinstance(records, list) or not records:
            raise ParameterError("strokes must be a non-empty list")
        for i, record in enumerate(records):
            if not isinstance(record, dict) or set(record) != set(STROKE_KEYS):
                raise ParameterError(f"strokes[{i}] must have the keys {', '.join(STROKE_KEYS)}")
            _check_record(record, f"strokes[{i}]")
    except ParameterError as error:
        raise ParameterError(f"library manifest {str(manifest_path)!r} is corrupt: {error}") from None
    return rate, [_read_stroke(folder, record, rate) for record in records]


def _read_stroke(folder, record, rate):
    name = _safe_name(record["name"], "name")
    paths = {key: folder / _safe_name(record["files"].get(key), key) for key in KINDS}
    for key, path in paths.items():
        if not path.is_file():
            raise ParameterError(f"library file {str(path)!r} is missing (stroke {name!r})")
        if _sha256(path) != record["sha256"].get(key):
            raise ParameterError(f"library file {str(path)!r} is corrupt: its SHA-256 differs from the manifest's")
    t, theta, omega = _read_trajectory(paths["trajectory"], record, rate)
    data = read_json(paths["impacts"], "library file")
    impact_t, impact_omega, after, tip = _read_impacts(paths["impacts"], data, record, t[-1])
    return StoredStroke(record, paths["recipe"], t, theta, omega, impact_t, impact_omega, after, tip)


STROKE_KEYS = ("name", "category", "description", "model", "theta_max", "t_end", "samples", "impacts",
               "first_impact", "first_level_db", "history", "files", "sha256")
"""The keys of each stroke's entry in the manifest."""


def _check_record(record, where):
    for key in ("name", "category", "description", "model"):
        if not isinstance(record[key], str):
            raise ParameterError(f"{where}.{key} must be text, got {record[key]!r}")
    check_real(f"{where}.theta_max", record["theta_max"], low=-math.pi / 2, high=0.0, unit="rad")
    check_real(f"{where}.t_end", record["t_end"], low=0.0, low_open=True, unit="s")
    check_int(f"{where}.samples", record["samples"], low=2)
    check_int(f"{where}.impacts", record["impacts"], low=0)
    for key in ("first_impact", "first_level_db"):
        if record[key] is not None:
            check_real(f"{where}.{key}", record[key])
    if not isinstance(record["history"], list) or not all(isinstance(h, str) for h in record["history"]):
        raise ParameterError(f"{where}.history must be a list of text, got {record['history']!r}")
    for key in ("files", "sha256"):
        if not isinstance(record[key], dict) or not all(isinstance(v, str) for v in record[key].values()):
            raise ParameterError(f"{where}.{key} must be a table of text, got {record[key]!r}")


def _read_trajectory(path, record, rate):
    where = f"library file {str(path)!r}"
    _, columns = read_columns(path, what="library file")
    if list(columns) != ["t", "theta", "omega"] or len(columns["t"]) != record["samples"]:
        raise ParameterError(f"{where} is corrupt: {len(columns['t'])} rows of {','.join(columns)}; the manifest "
                             f"says {record['samples']} rows of t,theta,omega")
    t, theta, omega = columns.values()
    off = np.abs(t - np.arange(len(t)) / rate) > 1e-9 * max(1.0, t[-1])
    if np.any(off):
        i = int(np.flatnonzero(off)[0])
        raise ParameterError(f"{where} is corrupt: t[{i}] = {float(t[i])!r} s is not {i}/{rate:g} Hz")
    if abs(t[-1] - record["t_end"]) > 1e-9:
        raise ParameterError(f"{where} ends at {float(t[-1])!r} s; the manifest says t_end = {record['t_end']!r} s")
    below = theta < record["theta_max"] - 1e-12
    if np.any(below):
        i = int(np.flatnonzero(below)[0])
        raise ParameterError(f"{where} is corrupt: theta[{i}] = {float(theta[i])!r} rad is below the head "
                             f"({record['theta_max']!r} rad)")
    return t, theta, omega


def _read_impacts(path, data, record, t_end):
    where = f"library file {str(path)!r}"
    try:
        rows = data["impacts"]
        table = np.array([[row["t"], row["omega"], row["omega_after"]] for row in rows], dtype=float).reshape(-1, 3)
        tip = float(data["tip_distance"])
    except (KeyError, TypeError, ValueError):
        raise ParameterError(f"{where} is corrupt: it needs tip_distance and impacts with t, omega, omega_after") \
            from None
    t, omega, after = table.T
    if len(t) != record["impacts"] or not np.all(np.isfinite(table)) or not math.isfinite(tip):
        raise ParameterError(f"{where} is corrupt: {len(t)} impacts (finite: {bool(np.isfinite(table).all())}); "
                             f"the manifest says {record['impacts']}")
    if np.any(np.diff(t) < 0) or (len(t) and (t[0] < 0 or t[-1] > t_end)) or np.any(omega > 0) or np.any(after < 0):
        raise ParameterError(f"{where} is corrupt: impacts must be in time order within [0, {t_end:g}] s, moving "
                             "down before (omega <= 0) and up after (omega_after >= 0)")
    return t, omega, after, tip


def _safe_name(name, key):
    """A file or folder name from the manifest: plain, no separators, no '..'."""
    if not isinstance(name, str) or not name or "/" in name or "\\" in name or name in (".", ".."):
        raise ParameterError(f"{key} must be a plain file name, got {name!r}")
    return name
