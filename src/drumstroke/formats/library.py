"""The stroke library on disk, both ways: a folder of plain text files a robot host loads at run time.

A library folder holds ``manifest.json`` and one folder of stroke files, ``strokes-HASH``. Per
stroke there are three files:

- ``NAME.toml``: the recipe it was simulated from (a recipe file);
- ``NAME.csv``: the trajectory ``t,theta,omega`` (s, rad, rad/s) at the library's rate, header
  first (:mod:`.trajectory_csv`);
- ``NAME.json``: its impacts (time s, ω before and after rad/s, tip speed m/s, level dB), how
  it was made (the transforms, in order) and, as the JSON beside ``NAME.csv``, that CSV's
  metadata under ``"csv"`` (:mod:`.sidecar`).

The manifest lists the strokes with their category, description, counts and each file's
size and SHA-256. Libraries of format versions 1 and 2 (older drumstroke) are read too: 1's
``NAME.csv`` has a ``#`` comment line before the header and its ``NAME.json`` no ``"csv"``
block; neither records the files' sizes.

Writing (:class:`Staging`) stages the stroke files in a temporary folder beside the library's,
synced, and names it by its contents (``strokes-HASH``): a folder of that name already there is
reused only if every file matches the manifest to be written, else it is moved aside. Then
the manifest is replaced in one atomic rename — the switch — and the old stroke folders are
renamed to temporary names and removed. A build killed at any point leaves the previous library
or the new one, whole; its leftovers (temporary names naming their writer, see
:mod:`drumstroke._atomic`) are removed by the next build. Reading (:func:`diagnose`,
:func:`read_library`) checks everything — each file there, a regular file, readable, of the
manifest's size and SHA-256, no file the manifest does not list, values finite, times on the
library's rate, the stick never below the head — and names every file at fault. A build's
switch and a reading hold a lock on the folder (``flock``, exclusive and shared), so a reader
never sees a folder disappear under it. Both directions deal in plain data (texts, dicts,
arrays); :mod:`drumstroke.palette.library` maps it to strokes.
"""

import hashlib
import math
import os
import re
import stat
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._atomic import (
    describe_temporary,
    locked,
    move_aside,
    naming,
    remove,
    remove_stale,
    sync_folder,
    temporary_folder,
    write_atomic,
    write_new,
)
from .._checks import check_int, check_real
from .._version import __version__
from ..errors import ParameterError
from .json import impact_columns, json_text, read_json
from .toml import read_toml
from .trajectory_csv import read_columns

FORMAT = "drumstroke-library"
FORMAT_VERSION = 3
"""The version written: 3 since the manifest records each file's size (2: the CSV files start with their
header; 1 had a ``#`` comment line first)."""
READ_VERSIONS = (1, 2, 3)
"""The versions read."""
MANIFEST = "manifest.json"
KINDS = ("recipe", "trajectory", "impacts")
"""The files of a stroke, by kind: NAME.toml, NAME.csv, NAME.json."""
_SUFFIX = {"recipe": ".toml", "trajectory": ".csv", "impacts": ".json"}
_FOLDER = re.compile(r"strokes-[0-9a-f]{16}")


class Staging:
    """A library being written: stroke files go into a temporary folder until :meth:`commit` switches to it.

    Parameters
    ----------
    directory : str or Path
        The library folder; created if missing. The leftovers of killed builds in it are removed
        (never those of a build still running).
    """

    def __init__(self, directory):
        directory = Path(directory)
        if directory.exists() and not directory.is_dir():
            raise ParameterError(f"directory {str(directory)!r} exists and is not a folder")
        directory.mkdir(parents=True, exist_ok=True)
        self.directory = directory
        remove_stale(directory)
        with naming(directory):
            self.folder = temporary_folder(directory / "strokes")
        self.records = []

    def add(self, record, texts):
        """Write one stroke's files from ``texts`` ({kind: text}) and keep its manifest ``record`` (a dict)."""
        name = record["name"]
        files = {kind: f"{name}{_SUFFIX[kind]}" for kind in KINDS}
        data = {kind: texts[kind].encode() for kind in KINDS}
        with naming(self.directory):
            for kind, file in files.items():
                write_new(self.folder / file, data[kind])
        self.records.append(record | {"files": files, "bytes": {kind: len(data[kind]) for kind in KINDS},
                                      "sha256": {kind: hashlib.sha256(data[kind]).hexdigest() for kind in KINDS}})
        return self.records[-1]

    def commit(self, rate):
        """Switch the library to the staged strokes; return the stroke folder's name.

        The staged folder is named by its contents; one of that name already there is reused
        only if it holds exactly the staged files. The manifest is replaced atomically, then
        the other stroke folders are removed. An ``OSError`` names the library's folder.
        """
        listing = "".join(f"{r['files'][k]} {r['bytes'][k]} {r['sha256'][k]}\n" for r in self.records for k in KINDS)
        folder = f"strokes-{hashlib.sha256(listing.encode()).hexdigest()[:16]}"
        target = self.directory / folder
        manifest = {"format": FORMAT, "version": FORMAT_VERSION, "drumstroke": __version__, "rate": rate,
                    "folder": folder, "strokes": self.records}
        sync_folder(self.folder)
        asides = []
        with locked(self.directory), naming(self.directory):
            if os.path.lexists(target) and _folder_problems(target, self.records, FORMAT_VERSION):
                asides.append(move_aside(target))  # a damaged folder of that name is never reused
            placed = not os.path.lexists(target)
            if placed:
                os.replace(self.folder, target)
                sync_folder(self.directory)
            try:
                write_atomic(self.directory / MANIFEST, json_text(manifest))  # the switch
            except BaseException:
                if placed:
                    asides.append(move_aside(target))
                raise
            finally:
                for aside in asides:
                    remove(aside)
            asides = [move_aside(old) for old in _stroke_folders(self.directory) if old.name != folder]
            sync_folder(self.directory)
        for aside in asides:
            remove(aside)
        self.discard()
        return folder

    def discard(self):
        """Remove the staged files; the library as it was stays."""
        remove(self.folder)


def _stroke_folders(directory):
    try:
        entries = list(os.scandir(directory))
    except OSError:
        return []
    return [Path(e.path) for e in entries if _FOLDER.fullmatch(e.name) and e.is_dir(follow_symlinks=False)]


@dataclass(frozen=True)
class StoredStroke:
    """One stroke as read from a library: its manifest record, its recipe and its checked arrays.

    Attributes
    ----------
    record : dict
        The manifest's entry (name, category, description, model, theta_max, t_end, history, …).
    recipe : Path
        Its recipe file.
    recipe_data : dict
        That file's TOML, as read.
    t, theta, omega : ndarray [shape=(n,)]
        s, rad, rad/s at the library's rate.
    impact_t, impact_omega, omega_after : ndarray [shape=(m,)]
        s; rad/s before (≤ 0) and after (≥ 0) each impact.
    tip_distance : float
        m.
    """

    record: dict
    recipe: Path
    recipe_data: dict
    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    impact_t: np.ndarray
    impact_omega: np.ndarray
    omega_after: np.ndarray
    tip_distance: float


@dataclass(frozen=True)
class Diagnosis:
    """What :func:`diagnose` found in a library folder.

    Attributes
    ----------
    directory : Path
    rate : float or None
        Samples per second (Hz); None when the manifest cannot be read.
    strokes : tuple of StoredStroke
        The strokes whose files are whole and hold what the manifest says.
    problems : tuple of str
        One line per damaged file (or the manifest, or the stroke folder), naming it: missing,
        not a regular file, unreadable, its size or SHA-256 not the manifest's, its values wrong,
        or a file the manifest does not list; none for a whole library.
    leftovers : tuple of str
        One line per leftover beside the library, naming it: an old stroke folder, a temporary
        of a killed build (the next build removes them), a build's still running. They do not
        make the library damaged: it is read through the manifest only.
    """

    directory: Path
    rate: float | None
    strokes: tuple
    problems: tuple
    leftovers: tuple

    def error(self):
        """The problems as one line, for an error: the only one, or their count and each in turn."""
        if len(self.problems) == 1:
            return self.problems[0]
        return f"library {str(self.directory)!r} has {len(self.problems)} problems: " + "; ".join(self.problems)


def read_library(directory):
    """Read and check a library folder: its rate (Hz) and a :class:`StoredStroke` per stroke, in order.

    Raises ParameterError naming each file at fault (:func:`diagnose`): the manifest or a stroke
    file missing, unreadable, altered (its size or SHA-256 differs from the manifest's), holding
    values that are not finite, off the library's rate, below the head or inconsistent with the
    manifest, or a file in the stroke folder the manifest does not list.
    """
    diagnosis = diagnose(directory)
    if diagnosis.problems:
        raise ParameterError(diagnosis.error())
    return diagnosis.rate, list(diagnosis.strokes)


def diagnose(directory):
    """Check a library folder file by file, not stopping at the first problem: a :class:`Diagnosis`."""
    directory = Path(directory)
    with locked(directory, shared=True):
        try:
            rate, folder, records, version = _read_manifest(directory)
        except ParameterError as error:
            return Diagnosis(directory, None, (), (str(error),), _leftovers(directory, None))
        leftovers = _leftovers(directory, folder.name)
        if not folder.is_dir():
            problem = f"stroke folder {str(folder)!r} is {'not a folder' if folder.exists() else 'missing'}"
            return Diagnosis(directory, rate, (), (problem,), leftovers)
        strokes, problems = [], []
        for record in records:
            damaged = _folder_problems(folder, [record], version, extra=False)
            try:
                if not damaged:
                    strokes.append(_read_stroke(folder, record, rate))
            except ParameterError as error:
                damaged = [str(error)]
            problems += damaged
        problems += _extra_files(folder, records)
    return Diagnosis(directory, rate, tuple(strokes), tuple(problems), leftovers)


def _read_manifest(directory):
    manifest_path = directory / MANIFEST
    manifest = read_json(manifest_path, "library manifest")
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        raise ParameterError(f"library manifest {str(manifest_path)!r} is not a drumstroke library manifest")
    version = manifest.get("version")
    if version not in READ_VERSIONS or isinstance(version, bool):
        raise ParameterError(f"library manifest {str(manifest_path)!r} has version {version!r}; "
                             f"this drumstroke reads the versions {', '.join(map(str, READ_VERSIONS))}")
    keys = STROKE_KEYS if version >= 3 else tuple(k for k in STROKE_KEYS if k != "bytes")
    try:
        rate = check_real("rate", manifest.get("rate"), low=1.0, high=1e5, unit="Hz")
        folder = directory / _safe_name(manifest.get("folder"), "folder")
        records = manifest.get("strokes")
        if not isinstance(records, list) or not records:
            raise ParameterError("strokes must be a non-empty list")
        for i, record in enumerate(records):
            if not isinstance(record, dict) or set(record) != set(keys):
                raise ParameterError(f"strokes[{i}] must have the keys {', '.join(keys)}")
            _check_record(record, f"strokes[{i}]")
            for key in KINDS:
                _safe_name(record["files"].get(key), f"strokes[{i}].files.{key}")
    except ParameterError as error:
        raise ParameterError(f"library manifest {str(manifest_path)!r} is corrupt: {error}") from None
    return rate, folder, records, version


def _read_stroke(folder, record, rate):
    """The stroke of ``record`` from its files (whole: sizes and SHA-256 checked), its values checked."""
    paths = {key: folder / record["files"][key] for key in KINDS}
    recipe = read_toml(paths["recipe"], "library file")
    t, theta, omega = _read_trajectory(paths["trajectory"], record, rate)
    data = read_json(paths["impacts"], "library file")
    impact_t, impact_omega, after, tip = _read_impacts(paths["impacts"], data, record, t[-1])
    return StoredStroke(record, paths["recipe"], recipe, t, theta, omega, impact_t, impact_omega, after, tip)


def _folder_problems(folder, records, version, *, extra=True):
    """What is wrong with the files of ``records`` in ``folder`` (and, if ``extra``, files it has beyond them)."""
    problems = []
    for record in records:
        for key in KINDS:
            size = record["bytes"][key] if version >= 3 else None
            problem = _file_problem(folder / record["files"][key], size, record["sha256"].get(key), record["name"])
            if problem:
                problems.append(problem)
    return problems + (_extra_files(folder, records) if extra else [])


def _file_problem(path, size, digest, name):
    """What is wrong with one stroke file — missing, not a regular file, unreadable, size, SHA-256 — or None."""
    where = f"library file {str(path)!r}"
    try:
        info = os.stat(path)
        if not stat.S_ISREG(info.st_mode):
            return f"{where} is not a regular file (stroke {name!r})"
        if size is not None and info.st_size != size:
            return f"{where} is corrupt: {info.st_size} bytes, the manifest says {size} (truncated or altered)"
        with open(path, "rb") as handle:
            data = handle.read()
    except FileNotFoundError:
        return f"{where} is missing (stroke {name!r})"
    except OSError as error:
        return f"{where} cannot be read: {error.strerror or error}"
    if hashlib.sha256(data).hexdigest() != digest:
        return f"{where} is corrupt: its SHA-256 differs from the manifest's"
    return None


def _extra_files(folder, records):
    listed = {record["files"][key] for record in records for key in KINDS}
    try:
        names = sorted(os.listdir(folder))
    except OSError:
        return []
    return [f"library file {str(folder / name)!r} is not in the manifest (an extra file in the stroke folder)"
            for name in names if name not in listed]


def _leftovers(directory, current):
    """The leftovers beside the library: old stroke folders, temporaries of builds killed or running."""
    try:
        names = sorted(os.listdir(directory))
    except OSError:
        return ()
    found = []
    for name in names:
        path = directory / name
        temporary = describe_temporary(path)
        if temporary:
            found.append(f"{str(path)!r}: {temporary}")
        elif _FOLDER.fullmatch(name) and name != current and path.is_dir():
            found.append(f"{str(path)!r}: an old stroke folder, not the manifest's; the next build removes it")
    return tuple(found)


STROKE_KEYS = ("name", "category", "description", "model", "theta_max", "t_end", "samples", "impacts",
               "first_impact", "first_level_db", "history", "files", "bytes", "sha256")
"""The keys of each stroke's entry in the manifest (version 3; versions 1 and 2 have no ``bytes``)."""


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
    if "bytes" in record:
        sizes = record["bytes"]
        if not isinstance(sizes, dict) or set(sizes) != set(KINDS):
            raise ParameterError(f"{where}.bytes must be a table of {', '.join(KINDS)}, got {sizes!r}")
        for key in KINDS:
            check_int(f"{where}.bytes.{key}", sizes[key], low=0, unit="bytes")


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
    where = f"library file {str(path)!r} is corrupt"
    try:
        tip = float(data["tip_distance"])
    except (KeyError, TypeError, ValueError):
        raise ParameterError(f"{where}: it needs tip_distance and impacts") from None
    t, omega, after = impact_columns(data.get("impacts"), where, start=0.0, end=t_end)
    if after is None and len(t):
        raise ParameterError(f"{where}: its impacts need omega_after")
    if len(t) != record["impacts"] or not math.isfinite(tip):
        raise ParameterError(f"{where}: {len(t)} impacts, tip_distance {tip!r}; the manifest says {record['impacts']} "
                             "impacts")
    return t, omega, after, tip


def _safe_name(name, key):
    """A file or folder name from the manifest: plain, no separators, no '..'."""
    if not isinstance(name, str) or not name or "/" in name or "\\" in name or name in (".", ".."):
        raise ParameterError(f"{key} must be a plain file name, got {name!r}")
    return name
