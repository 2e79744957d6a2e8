"""The stroke library on disk: text files a robot host loads at run time (SPEC §4).

A library folder holds ``manifest.json`` and one folder of stroke files. Per
stroke there are three files:

- ``NAME.toml``: the recipe it was simulated from (a recipe file);
- ``NAME.csv``: the trajectory ``t,theta,omega`` (s, rad, rad/s) at the
  library's rate, after one ``#`` comment line naming the model;
- ``NAME.json``: its impacts (time s, ω before and after rad/s, tip speed m/s,
  level dB) and how it was made (the transforms, in order).

The manifest lists the strokes with their category, description, sizes and
each file's SHA-256. A build writes a new stroke folder beside the old one,
then replaces the manifest in one atomic rename, then removes the old folder:
a build interrupted at any point leaves the previous library whole and
loadable. :func:`load_library` checks everything — manifest and files agree,
values finite, times on the library's rate, the stick never below the head —
and names the file at fault.

Examples
--------
>>> import tempfile
>>> folder = tempfile.mkdtemp()
>>> entries = [e for e in read_palette() if e.name in ("single", "double")]
>>> library = build_library(folder, palette=entries)
>>> loaded = load_library(folder)
>>> sorted(loaded), len(loaded["double"].trajectory.impacts)
(['double', 'single'], 2)
"""

import hashlib
import json
import math
import os
import re
import shutil
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .._atomic import write_atomic
from .._checks import check_int, check_keys, check_real, read_toml
from .._version import __version__
from ..errors import ParameterError
from ..presets import PRESETS
from ..recipe import Recipe
from ..stroke import simulate
from ..trajectory import DEFAULT_RATE, Impacts, Trajectory
from .trajectory import csv_header, csv_text, read_csv
from .transforms import apply_steps, trim

FORMAT = "drumstroke-library"
FORMAT_VERSION = 1
MANIFEST = "manifest.json"
DEFAULT_PALETTE = Path(__file__).with_name("default.toml")
"""The shipped palette: 20 strokes covering every category of the paper."""
DEMO_PATTERN = Path(__file__).with_name("groove.pattern")
"""The shipped text pattern the demo composes: four bars at 96 bpm on two sticks."""

_NAME = re.compile(r"^[a-z0-9][a-z0-9._-]{0,63}$")
_ENTRY_KEYS = ("name", "category", "description", "recipe", "transforms")


@dataclass(frozen=True)
class Entry:
    """One stroke of a palette file: what to simulate and how to post-process it.

    Attributes
    ----------
    name : str
        Lower case letters, digits, ``.``, ``_``, ``-`` (it names files).
    category : str
    description : str
        One line, musical.
    recipe : Recipe
    transforms : tuple of dict
        Steps for :func:`~drumstroke.palette.transforms.apply_steps`.
    """

    name: str
    category: str
    description: str
    recipe: Recipe
    transforms: tuple = ()

    def make(self):
        """Simulate the recipe and apply the transforms: the stroke's :class:`Trajectory`."""
        stroke = apply_steps(simulate(self.recipe), list(self.transforms), where=f"{self.name}.transforms")
        return replace(stroke, name=self.name)


@dataclass(frozen=True)
class LibraryStroke:
    """A stroke of a library: its trajectory and what it is."""

    name: str
    category: str
    description: str
    trajectory: Trajectory


def read_palette(path=None):
    """The entries of a palette file (default: the shipped palette, :data:`DEFAULT_PALETTE`).

    A palette file is TOML with one ``[[stroke]]`` table per stroke; see the
    shipped file for the keys. Recipes may be preset names, recipe files
    (relative to the palette file) or inline tables.
    """
    path = Path(path) if path is not None else DEFAULT_PALETTE
    data = read_toml(path, "palette")
    check_keys("palette", data, ("stroke",))
    tables = data.get("stroke")
    if not isinstance(tables, list) or not tables:
        raise ParameterError(f"palette {str(path)!r} needs at least one [[stroke]] table")
    entries, seen = [], set()
    for i, table in enumerate(tables):
        where = f"stroke[{i}]"
        if not isinstance(table, dict):
            raise ParameterError(f"{where} must be a table, got {table!r}")
        check_keys(where, table, _ENTRY_KEYS)
        name = table.get("name")
        if not isinstance(name, str) or not _NAME.match(name):
            raise ParameterError(f"{where}.name must be 1-64 of a-z, 0-9, '.', '_', '-' (starting with a letter "
                                 f"or digit), got {name!r}")
        if name in seen:
            raise ParameterError(f"{where}.name {name!r} appears twice in the palette")
        seen.add(name)
        texts = {key: table.get(key, "") for key in ("category", "description")}
        for key, text in texts.items():
            if not isinstance(text, str) or "\n" in text:
                raise ParameterError(f"{where}.{key} must be one line of text, got {text!r}")
        transforms = table.get("transforms", [])
        if not isinstance(transforms, list):
            raise ParameterError(f"{where}.transforms must be a list of one-key tables, got {transforms!r}")
        recipe = _entry_recipe(table.get("recipe"), name, path.parent, where)
        entries.append(Entry(name, texts["category"], texts["description"], recipe, tuple(transforms)))
    return entries


def _entry_recipe(spec, name, folder, where):
    if isinstance(spec, dict):
        return Recipe.from_dict(spec, name=name, base_dir=folder)
    if isinstance(spec, str) and spec in PRESETS:
        return PRESETS[spec].recipe
    if isinstance(spec, str) and spec.endswith(".toml"):
        return Recipe.from_toml(folder / spec)
    raise ParameterError(f"{where}.recipe must be a preset name ({', '.join(PRESETS)}), a .toml file or an "
                         f"inline table, got {spec!r}")


class Library(Mapping):
    """Strokes by name, in the library's order; each a :class:`LibraryStroke`.

    Attributes
    ----------
    path : Path
        The library folder.
    rate : float
        Samples per second of every trajectory (Hz).
    """

    def __init__(self, path, rate, strokes):
        self.path = Path(path)
        self.rate = rate
        self._strokes = {s.name: s for s in strokes}

    def __getitem__(self, name):
        try:
            return self._strokes[name]
        except KeyError:
            raise ParameterError(f"stroke {name!r} is not in the library {str(self.path)!r}; it has "
                                 f"{', '.join(self._strokes)}") from None

    def __contains__(self, name):
        return name in self._strokes

    def get(self, name, default=None):
        return self._strokes.get(name, default)

    def __iter__(self):
        return iter(self._strokes)

    def __len__(self):
        return len(self._strokes)

    def __repr__(self):
        return f"Library({str(self.path)!r}, rate={self.rate:g}, {len(self)} strokes)"


def build_library(directory, *, rate=DEFAULT_RATE, palette=None, progress=None):
    """Simulate a palette and write it as a library folder; return the :class:`Library`.

    Parameters
    ----------
    directory : str or Path
        Created if missing. An existing library there is replaced atomically.
    rate : float in [1, 100000]
        Samples per second of the trajectories (Hz).
    palette : path, sequence of Entry or None
        A palette file, entries, or None for the shipped palette.
    progress : callable or None
        Called with the fraction done, in [0, 1].
    """
    rate = check_real("rate", rate, low=1.0, high=1e5, unit="Hz")
    entries = read_palette(palette) if palette is None or isinstance(palette, (str, os.PathLike)) else list(palette)
    directory = Path(directory)
    if directory.exists() and not directory.is_dir():
        raise ParameterError(f"directory {str(directory)!r} exists and is not a folder")
    directory.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(dir=directory, prefix=".strokes-"))
    try:
        records, strokes = [], []
        for i, entry in enumerate(entries):
            trajectory = _on_grid(entry.make(), rate)
            records.append(_write_stroke(staging, entry, trajectory, rate))
            strokes.append(LibraryStroke(entry.name, entry.category, entry.description, trajectory))
            if progress:
                progress((i + 1) / len(entries))
        digest = hashlib.sha256("".join(f for r in records for f in r["sha256"].values()).encode()).hexdigest()
        folder = f"strokes-{digest[:16]}"
        if (directory / folder).exists():
            shutil.rmtree(staging)
        else:
            os.replace(staging, directory / folder)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    manifest = {"format": FORMAT, "version": FORMAT_VERSION, "drumstroke": __version__, "rate": rate,
                "folder": folder, "strokes": records}
    write_atomic(directory / MANIFEST, json.dumps(manifest, indent=1) + "\n")
    for old in directory.glob("strokes-*"):
        if old.name != folder and old.is_dir():
            shutil.rmtree(old, ignore_errors=True)
    return Library(directory, rate, strokes)


def _on_grid(trajectory, rate):
    """The trajectory cut to end on its last sample time, so the CSV covers all of it."""
    end = math.floor(trajectory.t_end * rate * (1.0 + 1e-12)) / rate
    if trajectory.t_end - end > 1e-9:
        trimmed = trim(trajectory, 0.0, end)
        return replace(trimmed, history=trajectory.history)
    return trajectory


def _write_stroke(folder, entry, trajectory, rate):
    files = {"recipe": f"{entry.name}.toml", "trajectory": f"{entry.name}.csv", "impacts": f"{entry.name}.json"}
    entry.recipe.to_toml(folder / files["recipe"])
    t, theta, omega = trajectory.sample(rate)
    (folder / files["trajectory"]).write_text(
        csv_text(csv_header(trajectory.model, entry.name, rate), ("t", "theta", "omega"), (t, theta, omega)))
    impacts = trajectory.to_dict() | {"rate": rate}
    (folder / files["impacts"]).write_text(json.dumps(impacts, indent=1) + "\n")
    impacts_list = trajectory.impacts
    return {
        "name": entry.name,
        "category": entry.category,
        "description": entry.description,
        "model": trajectory.model,
        "theta_max": trajectory.theta_max,
        "t_end": trajectory.t_end,
        "samples": len(t),
        "impacts": len(impacts_list),
        "first_impact": float(impacts_list.t[0]) if len(impacts_list) else None,
        "first_level_db": float(impacts_list.level_db[0]) if len(impacts_list) else None,
        "history": list(trajectory.history),
        "files": files,
        "sha256": {key: _sha256(folder / name) for key, name in files.items()},
    }


def _sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


# --- loading -------------------------------------------------------------------------------------------------------

_STROKE_KEYS = ("name", "category", "description", "model", "theta_max", "t_end", "samples", "impacts",
                "first_impact", "first_level_db", "history", "files", "sha256")


def load_library(directory):
    """Read and check a library folder; return the :class:`Library`.

    Raises ParameterError naming the file when the manifest or a stroke file
    is missing, unreadable, altered (its SHA-256 differs from the manifest's),
    or holds values that are not finite, off the library's rate, below the head
    or inconsistent with the manifest.
    """
    directory = Path(directory)
    manifest_path = directory / MANIFEST
    manifest = _read_json(manifest_path, "library manifest")
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        raise ParameterError(f"library manifest {str(manifest_path)!r} is not a drumstroke library manifest")
    if manifest.get("version") != FORMAT_VERSION:
        raise ParameterError(f"library manifest {str(manifest_path)!r} has version {manifest.get('version')!r}; "
                             f"this drumstroke reads version {FORMAT_VERSION}")
    try:
        rate = check_real("rate", manifest.get("rate"), low=1.0, high=1e5, unit="Hz")
        folder = directory / _safe_name(manifest.get("folder"), "folder")
        records = manifest.get("strokes")
        if not isinstance(records, list) or not records:
            raise ParameterError("strokes must be a non-empty list")
        for i, record in enumerate(records):
            if not isinstance(record, dict) or set(record) != set(_STROKE_KEYS):
                raise ParameterError(f"strokes[{i}] must have the keys {', '.join(_STROKE_KEYS)}")
            _check_record(record, f"strokes[{i}]")
    except ParameterError as error:
        raise ParameterError(f"library manifest {str(manifest_path)!r} is corrupt: {error}") from None
    strokes = [_load_stroke(folder, record, rate) for record in records]
    return Library(directory, rate, strokes)


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


def _load_stroke(folder, record, rate):
    name = _safe_name(record["name"], "name")
    paths = {key: folder / _safe_name(record["files"].get(key), key) for key in ("recipe", "trajectory", "impacts")}
    for key, path in paths.items():
        if not path.is_file():
            raise ParameterError(f"library file {str(path)!r} is missing (stroke {name!r})")
        if _sha256(path) != record["sha256"].get(key):
            raise ParameterError(f"library file {str(path)!r} is corrupt: its SHA-256 differs from the manifest's")
    try:
        recipe = Recipe.from_toml(paths["recipe"])
    except ParameterError as error:
        text = str(error)
        raise ParameterError(text if str(paths["recipe"]) in text else f"library file {str(paths['recipe'])!r}: "
                             f"{text}") from None
    impacts_data = _read_json(paths["impacts"], "library file")
    t, theta, omega = _read_trajectory(paths["trajectory"], record, rate)
    impacts, omega_after = _read_impacts(paths["impacts"], impacts_data, record, t[-1])
    trajectory = Trajectory.from_samples(t, theta, omega, impacts, omega_after, theta_max=record["theta_max"],
                                         name=name, model=record["model"], recipe=recipe,
                                         history=tuple(record["history"]))
    return LibraryStroke(name, record["category"], record["description"], trajectory)


def _read_trajectory(path, record, rate):
    where = f"library file {str(path)!r}"
    _, columns = read_csv(path, what="library file")
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
    return Impacts(t, omega, tip), after


def _read_json(path, what):
    try:
        return json.loads(Path(path).read_text())
    except FileNotFoundError:
        raise ParameterError(f"{what} {str(path)!r} is missing") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ParameterError(f"{what} {str(path)!r} is corrupt: {error}") from None


def _safe_name(name, key):
    """A file or folder name from the manifest: plain, no separators, no '..'."""
    if not isinstance(name, str) or not name or "/" in name or "\\" in name or name in (".", ".."):
        raise ParameterError(f"{key} must be a plain file name, got {name!r}")
    return name
