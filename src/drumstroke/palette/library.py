"""Palettes and the stroke library: what to simulate, and the strokes a robot host loads at run time.

A palette file names strokes — a recipe each (a preset, a recipe file or an inline table) and
the transforms to apply. :func:`build_library` simulates a palette and writes it as a library
folder, :func:`load_library` reads one back as trajectories; the folder's format (manifest,
per-stroke TOML/CSV/JSON files, sizes and checksums, the atomic switch, the checks on loading)
is :mod:`drumstroke.formats.library`'s; :func:`check_library` reports a damaged library file by file.

Examples
--------
>>> import tempfile
>>> folder = tempfile.mkdtemp()
>>> entries = [e for e in read_palette() if e.name in ("single", "double")]
>>> library = build_library(folder, palette=entries)
>>> loaded = load_library(folder)
>>> sorted(loaded), len(loaded["double"].trajectory.impacts)
(['double', 'single'], 2)
>>> check_library(folder).problems
()
"""

import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path

from .._checks import check_keys, check_real, did_you_mean
from ..errors import ParameterError
from ..formats import trajectory_csv
from ..formats.json import json_text
from ..formats.library import MANIFEST, Staging, diagnose
from ..formats.sidecar import KEY
from ..formats.toml import reading_toml, toml_text
from ..presets import PRESETS
from ..recipe import Recipe
from ..stroke import as_trajectory, resolve, simulate
from ..trajectory import DEFAULT_RATE, Impacts, Trajectory
from .transforms import apply_steps, trim

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

    def make(self, *, model=None, progress=None):
        """Simulate the recipe (with ``model`` instead of its own, if given) and apply the transforms.

        Returns the stroke's :class:`Trajectory`; ``progress`` is :func:`~drumstroke.simulate`'s.
        """
        stroke = simulate(self.recipe, model=model, progress=progress)
        return replace(apply_steps(stroke, list(self.transforms), where=f"{self.name}.transforms"), name=self.name)


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
    with reading_toml(path, "palette") as data:
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
        The library folder, or the palette file its strokes are simulated from (:func:`palette_library`).
    rate : float
        Samples per second of every trajectory (Hz).
    """

    def __init__(self, path, rate, strokes):
        self.path = Path(path)
        self.rate = rate
        self._strokes = {s.name: s for s in strokes}

    def __getitem__(self, name):
        try:
            stroke = self._strokes[name]
        except KeyError:
            raise ParameterError(f"stroke {name!r} is not in the library {str(self.path)!r}{did_you_mean(name, self)}; "
                                 f"it has {', '.join(self._strokes)}") from None
        if isinstance(stroke, Entry):  # a palette's stroke (palette_library): simulated once, when first asked for
            stroke = self._strokes[name] = _library_stroke(stroke, self.rate)
        return stroke

    def __contains__(self, name):
        return name in self._strokes

    def get(self, name, default=None):
        return self[name] if name in self._strokes else default

    def __iter__(self):
        return iter(self._strokes)

    def __len__(self):
        return len(self._strokes)

    def __repr__(self):
        return f"Library({str(self.path)!r}, rate={self.rate:g}, {len(self)} strokes)"


def make_stroke(source, *, library=None, model=None, progress=None):
    """The stroke ``source`` names: a recipe simulated, or a palette's or a library's stroke.

    What ``drumstroke simulate SOURCE`` and ``drumstroke robot track SOURCE`` play.

    Parameters
    ----------
    source : Recipe, str or Path
        A recipe, a preset name (:data:`drumstroke.PRESETS`), a recipe ``.toml`` file, or the name
        of a stroke of the shipped palette (``"double"``: its recipe simulated, then its
        transforms applied); with ``library``, the name of one of that library's strokes.
    library : str, Path, Library or None
        A library folder (``build_library``) or a loaded :class:`Library`.
    model : {"paper", "geometry"} or None
        Simulate with this model instead of the recipe's; not for a library's stroke (stored).
    progress : callable or None
        Called now and then with the fraction of the simulation done, in [0, 1].

    Returns
    -------
    Stroke or Trajectory
        A :class:`~drumstroke.Stroke` for a recipe; the :class:`Trajectory` of a palette's or a
        library's stroke (post-processed as the palette says).

    Examples
    --------
    >>> stroke = make_stroke("double")
    >>> stroke.history[1:], len(stroke.impacts)
    (('catch 2',), 2)
    """
    if library is not None:
        if model is not None:
            raise ParameterError(f"model cannot be changed for a library's stroke (stored as built), got {model!r}")
        strokes = library if isinstance(library, Library) else load_library(library)
        return strokes[str(source)].trajectory
    if isinstance(source, str) and source not in PRESETS and not source.endswith(".toml") and not Path(source).exists():
        entries = {entry.name: entry for entry in read_palette()}
        if source not in entries:
            raise ParameterError(f"stroke must be a preset, a stroke of the shipped palette or a recipe .toml file, "
                                 f"got {source!r}{did_you_mean(source, [*PRESETS, *entries])}; presets: "
                                 f"{', '.join(PRESETS)}; palette strokes: {', '.join(n for n in entries if n not in PRESETS)}")
        return entries[source].make(model=model, progress=progress)
    return simulate(source, model=model, progress=progress)


def planned_duration(source, steps=()):
    """The duration (s) of :func:`make_stroke`'s stroke after ``steps``, known before anything is simulated.

    A recipe's (a :class:`Recipe`, a preset, a recipe file) ``t_end`` times its stretches: what a
    sampling rate asks for is refused before the simulation (:func:`drumstroke.trajectory.check_sampling`).

    Parameters
    ----------
    source : Recipe, str or Path
        As :func:`make_stroke` takes it, without a library.
    steps : sequence of (str, value)
        The transforms to apply after, in order (``("stretch", 2.0)``).

    Returns
    -------
    float or None
        None for a stroke of the shipped palette, or when a step (trim, catch) ends it where its motion says.

    >>> planned_duration("low-high", [("stretch", 2.0), ("reverse", True)]) == 2 * PRESETS["low-high"].recipe.t_end
    True
    """
    if isinstance(source, str) and source not in PRESETS and not source.endswith(".toml") and not Path(source).exists():
        return None
    duration = resolve(source).t_end
    for op, value in steps:
        if op == "stretch":
            duration *= value
        elif op not in ("compress", "reverse"):
            return None
    return duration


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
    staging = Staging(directory)
    try:
        strokes = []
        for i, entry in enumerate(entries):
            stroke = _library_stroke(entry, rate)
            _write_stroke(staging, entry, stroke.trajectory, rate)
            strokes.append(stroke)
            if progress:
                progress((i + 1) / len(entries))
        staging.commit(rate)
    except BaseException:
        staging.discard()
        raise
    return Library(staging.directory, rate, strokes)


def save_stroke(directory, name, trajectory, *, category="", description="", replace_stroke=False):
    """Add one stroke to a library folder, written as :func:`build_library` writes its strokes; return the
    :class:`Library`.

    The library's other strokes are written again as they are (at its rate) and the library is switched to
    the new set atomically; a folder that holds no library yet becomes one at :data:`DEFAULT_RATE`.

    Parameters
    ----------
    directory : str or Path
        A library folder (``build_library``'s) or a folder that holds none yet.
    name : str
        1-64 of a-z, 0-9, '.', '_', '-', starting with a letter or digit (it names files).
    trajectory : Trajectory or Stroke
        One stick's stroke with the recipe it was simulated from (its transforms in its history).
    category, description : str
        One line each.
    replace_stroke : bool
        Whether a stroke of that name already there is replaced (else refused).

    Examples
    --------
    >>> import tempfile
    >>> from drumstroke.palette import stretch
    >>> folder = tempfile.mkdtemp()
    >>> library = save_stroke(folder, "soft-double", stretch(make_stroke("double"), 1.5))
    >>> list(load_library(folder)), load_library(folder)["soft-double"].trajectory.history[-1]
    (['soft-double'], 'stretch 1.5')
    """
    directory = Path(directory)
    if not isinstance(name, str) or not _NAME.match(name):
        raise ParameterError(f"name must be 1-64 of a-z, 0-9, '.', '_', '-' (starting with a letter or digit), "
                             f"got {name!r}")
    for key, text in (("category", category), ("description", description)):
        if not isinstance(text, str) or "\n" in text:
            raise ParameterError(f"{key} must be one line of text, got {text!r}")
    trajectory = as_trajectory(trajectory)
    if trajectory.recipe is None:
        raise ParameterError(f"stroke {name!r} has no recipe (a joined or recorded motion): a library keeps each "
                             "stroke's recipe; save the strokes it joins instead")
    library = load_library(directory) if (directory / MANIFEST).exists() else Library(directory, DEFAULT_RATE, [])
    if name in library and not replace_stroke:
        raise ParameterError(f"name {name!r} is a stroke of the library {str(directory)!r} already: choose "
                             "another name or ask to replace it")
    rate = library.rate
    stroke = LibraryStroke(name, category, description, _on_grid(replace(trajectory, name=name).sample(rate), rate))
    strokes = [stroke if old.name == name else old for old in library.values()]
    if name not in library:
        strokes.append(stroke)
    staging = Staging(directory)
    try:
        for kept in strokes:
            entry = Entry(kept.name, kept.category, kept.description, kept.trajectory.recipe)
            _write_stroke(staging, entry, kept.trajectory, rate)
        staging.commit(rate)
    except BaseException:
        staging.discard()
        raise
    return Library(directory, rate, strokes)


def palette_library(palette=None, *, rate=DEFAULT_RATE):
    """A palette's strokes as a :class:`Library`, each simulated when first asked for, nothing written.

    What ``drumstroke compose`` plays without ``--library``: the shipped palette's strokes by name,
    made as ``drumstroke simulate NAME`` makes them (:func:`make_stroke`: the recipe simulated, then
    its transforms), cut to end on a sample time as :func:`build_library` cuts them.

    Parameters
    ----------
    palette : str, Path or None
        A palette file, or None for the shipped palette (:data:`DEFAULT_PALETTE`).
    rate : float in [1, 100000]
        The library's rate (Hz): the default control rate of what is composed from it.

    Examples
    --------
    >>> library = palette_library()
    >>> len(library), library.path.name, len(library["double"].trajectory.impacts)
    (20, 'default.toml', 2)
    """
    rate = check_real("rate", rate, low=1.0, high=1e5, unit="Hz")
    return Library(DEFAULT_PALETTE if palette is None else palette, rate, read_palette(palette))


def _library_stroke(entry, rate):
    """A palette's entry made into a library's stroke at ``rate``: simulated, post-processed, ending on a sample."""
    return LibraryStroke(entry.name, entry.category, entry.description, _on_grid(entry.make(), rate))


def _on_grid(trajectory, rate):
    """The trajectory cut to end on its last sample time, so the CSV covers all of it."""
    end = math.floor(trajectory.t_end * rate * (1.0 + 1e-12)) / rate
    if trajectory.t_end - end > 1e-9:
        trimmed = trim(trajectory, 0.0, end)
        return replace(trimmed, history=trajectory.history)
    return trajectory


def _write_stroke(staging, entry, trajectory, rate):
    """Stage one stroke's files (recipe TOML, trajectory CSV at ``rate``, impacts JSON) and its manifest record."""
    trajectory = trajectory.sample(rate)
    impacts = trajectory.impacts
    csv = staging.folder / f"{entry.name}.csv"  # its metadata goes in NAME.json, the impacts file beside it
    texts = {"recipe": toml_text(entry.recipe.toml_data(staging.folder)),
             "trajectory": trajectory_csv.columns_text(("t", "theta", "omega"), trajectory.columns()),
             "impacts": json_text(trajectory.to_dict() | {"rate": rate, KEY: trajectory.csv_metadata(csv)})}
    record = {
        "name": entry.name,
        "category": entry.category,
        "description": entry.description,
        "model": trajectory.model,
        "theta_max": trajectory.theta_max,
        "t_end": trajectory.t_end,
        "samples": len(trajectory),
        "impacts": len(impacts),
        "first_impact": float(impacts.t[0]) if len(impacts) else None,
        "first_level_db": float(impacts.level_db[0]) if len(impacts) else None,
        "history": list(trajectory.history),
    }
    return staging.add(record, texts)


def load_library(directory):
    """Read and check a library folder (:func:`check_library`); return the :class:`Library`.

    Raises ParameterError naming every file at fault, as :func:`check_library` finds them: the
    manifest or a stroke file missing, unreadable, altered (its size or SHA-256 differs from
    the manifest's), holding values that are not finite, off the library's rate, below the head
    or inconsistent with the manifest, or a file the manifest does not list.
    """
    diagnosis, strokes = _diagnose(directory)
    if diagnosis.problems:
        raise ParameterError(diagnosis.error())
    return Library(directory, diagnosis.rate, strokes)


def check_library(directory):
    """Check a library folder file by file, as :func:`load_library` reads it, without stopping at the first problem.

    Returns
    -------
    drumstroke.formats.library.Diagnosis
        Its ``problems`` (one line per file at fault; none when the library is whole), its
        ``leftovers`` (old stroke folders, temporaries of killed builds: not problems; the next
        build removes them), its rate and the strokes read.
    """
    return _diagnose(directory)[0]


def _diagnose(directory):
    diagnosis = diagnose(directory)
    strokes, read, problems = [], [], list(diagnosis.problems)
    for stored in diagnosis.strokes:
        try:
            strokes.append(_stroke(stored, diagnosis.rate))
            read.append(stored)
        except ParameterError as error:
            problems.append(str(error))
    return replace(diagnosis, strokes=tuple(read), problems=tuple(problems)), strokes


def _stroke(stored, rate):
    record = stored.record
    try:
        recipe = Recipe.from_dict(stored.recipe_data, name=stored.recipe.stem, base_dir=stored.recipe.parent)
    except ParameterError as error:
        raise ParameterError(f"library file {str(stored.recipe)!r}: {error}") from None
    impacts = Impacts(stored.impact_t, stored.impact_omega, stored.tip_distance)
    trajectory = Trajectory.from_samples(stored.t, stored.theta, stored.omega, impacts, stored.omega_after,
                                         theta_max=record["theta_max"], rate=rate, name=record["name"],
                                         model=record["model"], recipe=recipe, history=tuple(record["history"]))
    return LibraryStroke(record["name"], record["category"], record["description"], trajectory)
