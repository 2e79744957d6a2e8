"""The stroke library on disk: palettes, build, write→read round trips, corruption, atomic rebuilds.

The files are read back here independently of the loader (numpy.loadtxt, json, hashlib) and compared
bit for bit with what the build returned. Every corruption the loader must catch is made on a copy
of a small library built once per module; each must raise ParameterError naming the file at fault.
A damaged library is named file by file by check_library and load_library alike, and the next build
repairs it, trusting no folder it reuses; leftovers of killed builds (real processes) are noted, not
problems, and swept by the next build — never those of a build still running.
"""

import errno
import hashlib
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import drumstroke
from drumstroke import ParameterError
from drumstroke._atomic import locked
from drumstroke.formats import library as library_format
from drumstroke.palette import library as library_module
from drumstroke.palette.library import Entry, build_library, check_library, load_library, read_palette

SMALL = ("single", "double", "triple", "free-bounce", "backwards-bounce", "whisper-roll")  # palette order
SOURCE = str(Path(drumstroke.__file__).resolve().parents[1])
CATEGORIES = ("gravity only", "constant torque", "low to high", "high to low", "sustained finger pulses",
              "un-natural", "single stroke", "double stroke", "triple stroke")


@pytest.fixture(scope="module")
def palette():
    return {entry.name: entry for entry in read_palette()}


@pytest.fixture(scope="module")
def small(palette, tmp_path_factory):
    """The built library (as build_library returned it), its folder and entries."""
    folder = tmp_path_factory.mktemp("library") / "small"
    entries = [palette[name] for name in SMALL]
    return build_library(folder, palette=entries), folder, entries


def manifest_of(folder):
    return json.loads((Path(folder) / "manifest.json").read_text())


def stroke_files(folder, name):
    """The (recipe, trajectory, impacts) paths of stroke ``name``, from the manifest."""
    manifest = manifest_of(folder)
    record = next(r for r in manifest["strokes"] if r["name"] == name)
    base = Path(folder) / manifest["folder"]
    return tuple(base / record["files"][key] for key in ("recipe", "trajectory", "impacts"))


def read_csv(path):
    return np.loadtxt(path, skiprows=1, delimiter=",").T  # the header, then the rows


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


# --- the shipped palette -------------------------------------------------------------------------------------------


def test_the_shipped_palette_builds_into_a_library_that_meets_the_requirements(tmp_path):
    built = build_library(tmp_path / "full")
    loaded = load_library(tmp_path / "full")
    assert len(loaded) >= 17 and list(loaded) == list(built)
    strokes = list(loaded.values())
    categories = [s.category for s in strokes]
    for category in CATEGORIES:
        assert category in categories, category
    assert categories.count("un-natural") >= 2
    impacts = {s.name: len(s.trajectory.impacts) for s in strokes}
    assert (impacts["single"], impacts["double"], impacts["triple"]) == (1, 2, 3)
    for s in strokes:
        assert s.description.strip() and "\n" not in s.description
        _, theta, omega = read_csv(stroke_files(tmp_path / "full", s.name)[1])
        assert theta.min() >= s.trajectory.theta_max, s.name
        assert np.all(np.isfinite(omega)), s.name
        assert len(s.trajectory.impacts) >= 1, s.name


# --- write -> read -------------------------------------------------------------------------------------------------


def test_the_files_hold_the_built_trajectories_bit_for_bit(small):
    built, folder, entries = small
    for entry in entries:
        trajectory = built[entry.name].trajectory
        _, csv_path, json_path = stroke_files(folder, entry.name)
        written = read_csv(csv_path)
        for column, sampled in zip(written, trajectory.sample(1000.0)):
            assert np.array_equal(column, sampled)
        data = json.loads(json_path.read_text())
        impacts = data["impacts"]
        assert np.array_equal([i["t"] for i in impacts], trajectory.impacts.t)
        # NAME.json is the JSON beside NAME.csv: it holds the CSV's metadata too
        assert csv_path.read_text().split("\n", 1)[0] == "t,theta,omega"
        assert data["csv"] == {"file": f"{entry.name}.csv", "drumstroke": drumstroke.__version__,
                               "model": trajectory.model, "name": entry.name, "rate": 1000.0, "sticks": ["stick"],
                               "columns": ["t", "theta", "omega"],
                               "units": {"t": "s", "theta": "rad", "omega": "rad/s"}}
        assert np.array_equal([i["omega"] for i in impacts], trajectory.impacts.omega)
        assert np.array_equal([i["omega_after"] for i in impacts], trajectory.omega_after)


def test_loading_gives_back_what_was_written(small):
    built, folder, entries = small
    loaded = load_library(folder)
    assert loaded.rate == 1000.0
    assert list(loaded) == [e.name for e in entries]
    for entry in entries:
        got, want = loaded[entry.name], built[entry.name]
        assert (got.name, got.category, got.description) == (entry.name, entry.category, entry.description)
        recipe_path, csv_path, _ = stroke_files(folder, entry.name)
        assert got.trajectory.recipe.to_dict() == entry.recipe.to_dict()
        assert drumstroke.Recipe.from_toml(recipe_path).to_dict() == entry.recipe.to_dict()
        assert np.array_equal(got.trajectory.impacts.t, want.trajectory.impacts.t)
        assert np.array_equal(got.trajectory.impacts.omega, want.trajectory.impacts.omega)
        assert np.array_equal(got.trajectory.omega_after, want.trajectory.omega_after)
        assert got.trajectory.impacts.tip_distance == want.trajectory.impacts.tip_distance
        assert got.trajectory.theta_max == want.trajectory.theta_max
        # The loaded curve passes through the written samples exactly.
        written = read_csv(csv_path)
        for column, sampled in zip(written, got.trajectory.sample(loaded.rate)):
            assert np.array_equal(column, sampled)


def test_the_loaded_curve_follows_the_built_one_between_samples(small, rng):
    built, folder, _ = small
    loaded = load_library(folder)
    for name in ("free-bounce", "double"):
        got, want = loaded[name].trajectory, built[name].trajectory
        t = rng.uniform(0.0, got.t_end, 20_000)
        assert np.abs(got.state(t)[0] - want.state(t)[0]).max() < 1e-10


def test_the_manifest_describes_the_files(small):
    built, folder, entries = small
    manifest = manifest_of(folder)
    assert manifest["format"] == "drumstroke-library" and manifest["rate"] == 1000.0 and manifest["version"] == 3
    assert [r["name"] for r in manifest["strokes"]] == [e.name for e in entries]
    for record, entry in zip(manifest["strokes"], entries):
        paths = stroke_files(folder, entry.name)
        t, _, _ = read_csv(paths[1])
        impacts = json.loads(paths[2].read_text())["impacts"]
        assert record["samples"] == len(t)
        assert record["impacts"] == len(impacts) == len(built[entry.name].trajectory.impacts)
        assert record["t_end"] == t[-1] == built[entry.name].trajectory.t_end
        assert (record["category"], record["description"]) == (entry.category, entry.description)
        assert record["sha256"] == {key: sha256(p) for key, p in zip(("recipe", "trajectory", "impacts"), paths)}
        assert record["bytes"] == {key: p.stat().st_size for key, p in zip(("recipe", "trajectory", "impacts"), paths)}
        if impacts:
            assert record["first_impact"] == impacts[0]["t"]


def test_another_rate_puts_samples_on_its_grid(palette, tmp_path):
    build_library(tmp_path, rate=500.0, palette=[palette["double"], palette["free-bounce"]])
    loaded = load_library(tmp_path)
    assert loaded.rate == 500.0
    for name in ("double", "free-bounce"):
        path = stroke_files(tmp_path, name)[1]
        t, _, _ = read_csv(path)
        assert np.array_equal(t, np.arange(len(t)) / 500.0)
        assert json.loads(stroke_files(tmp_path, name)[2].read_text())["csv"]["rate"] == 500.0
        assert np.array_equal(loaded[name].trajectory.sample(500.0).t, t)
    assert len(read_csv(stroke_files(tmp_path, "free-bounce")[1])[0]) == 2501


def test_a_library_of_the_old_formats_still_loads(small, tmp_path):
    """Version 2: no file sizes in the manifest. Version 1, as drumstroke 0.1.0 wrote it: also a # comment line
    first in each CSV, no "csv" block in NAME.json."""
    built, _, entries = small
    for version in (2, 1):
        folder = tmp_path / f"v{version}"
        shutil.copytree(small[1], folder)
        manifest = manifest_of(folder)
        for record in manifest["strokes"]:
            del record["bytes"]
            if version == 2:
                continue
            _, csv_path, json_path = (folder / manifest["folder"] / record["files"][key]
                                      for key in ("recipe", "trajectory", "impacts"))
            comment = (f"# drumstroke 0.1.0; model={record['model']}; stroke={record['name']}; rate=1000 Hz; "
                       "units s, rad, rad/s\n")
            csv_path.write_text(comment + csv_path.read_text())
            data = json.loads(json_path.read_text())
            del data["csv"]
            json_path.write_text(json.dumps(data, indent=1) + "\n")
            record["sha256"].update(trajectory=sha256(csv_path), impacts=sha256(json_path))
        manifest["version"] = version
        (folder / "manifest.json").write_text(json.dumps(manifest))
        loaded = load_library(folder)
        assert loaded.rate == 1000.0 and list(loaded) == [e.name for e in entries]
        for entry in entries:
            got, want = loaded[entry.name].trajectory, built[entry.name].trajectory.sample(1000.0)
            assert np.array_equal(got.t, want.t) and np.array_equal(got.theta, want.theta)
            assert np.array_equal(got.omega, want.omega) and got.model == want.model
            assert np.array_equal(got.impacts.t, want.impacts.t)
        # Without sizes, damage is still found by the checksums.
        path = stroke_files(folder, "double")[1]
        path.write_bytes(path.read_bytes()[:-7])
        with pytest.raises(ParameterError, match=r"double\.csv' is corrupt: its SHA-256 differs"):
            load_library(folder)
    manifest["version"] = 4
    (folder / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ParameterError, match=r"manifest\.json' has version 4; this drumstroke reads the versions 1, 2, 3"):
        load_library(folder)


# --- corruption is named -------------------------------------------------------------------------------------------


def edit_row(path, row, column, value):
    """Set one CSV value (row of data, column 0..2) as text."""
    lines = path.read_text().split("\n")
    fields = lines[1 + row].split(",")
    fields[column] = value
    lines[1 + row] = ",".join(fields)
    path.write_text("\n".join(lines))


def reseal(folder, name, key, path):
    """Update the manifest's checksum of one file: a library consistent with itself but bad."""
    manifest = manifest_of(folder)
    record = next(r for r in manifest["strokes"] if r["name"] == name)
    record["sha256"][key] = sha256(path)
    record["bytes"][key] = path.stat().st_size
    (Path(folder) / "manifest.json").write_text(json.dumps(manifest))


def set_manifest(folder, change):
    manifest = manifest_of(folder)
    change(manifest)
    (Path(folder) / "manifest.json").write_text(json.dumps(manifest))


def change_value(folder):
    path = stroke_files(folder, "double")[1]
    edit_row(path, 10, 1, "0.125")
    return path, "is corrupt: .*truncated or altered"


def truncate_csv(folder):
    path = stroke_files(folder, "double")[1]
    path.write_text("".join(path.read_text().splitlines(keepends=True)[:40]))
    return path, r"is corrupt: \d+ bytes, the manifest says \d+ \(truncated or altered\)"


def delete_json(folder):
    path = stroke_files(folder, "triple")[2]
    path.unlink()
    return path, "missing"


def invalid_manifest(folder):
    path = Path(folder) / "manifest.json"
    path.write_text(path.read_text()[:200])
    return path, "corrupt"


def record_missing_key(folder):
    set_manifest(folder, lambda m: m["strokes"][2].pop("samples"))
    return Path(folder) / "manifest.json", r"strokes\[2\]"


def missing_folder(folder):
    set_manifest(folder, lambda m: m.update(folder="strokes-0123456789abcdef"))
    return Path(folder) / "strokes-0123456789abcdef", "missing"


def garbage_recipe(folder):
    path = stroke_files(folder, "single")[0]
    path.write_text("this is not = [a recipe\n")
    return path, "is corrupt"


def garbage_recipe_resealed(folder):
    path = stroke_files(folder, "single")[0]
    path.write_text("this is not = [a recipe\n")
    reseal(folder, "single", "recipe", path)
    return path, "TOML"


def not_a_recipe_resealed(folder):
    path = stroke_files(folder, "single")[0]
    path.write_text('model = "paper"\nt_end = -1.0\n')  # valid TOML, not a recipe
    reseal(folder, "single", "recipe", path)
    return path, ""


def nan_sample(folder):
    path = stroke_files(folder, "double")[1]
    edit_row(path, 7, 1, "nan")
    reseal(folder, "double", "trajectory", path)
    return path, "row 7 is not finite"


def sample_below_head(folder):
    path = stroke_files(folder, "double")[1]
    edit_row(path, 12, 1, "-0.3")
    reseal(folder, "double", "trajectory", path)
    return path, r"theta\[12\] = (np\.float64\()?-0\.3\)? rad is below the head"


def wrong_time_step(folder):
    path = stroke_files(folder, "double")[1]
    edit_row(path, 9, 0, "0.0095")
    reseal(folder, "double", "trajectory", path)
    return path, r"t\[9\] = (np\.float64\()?0\.0095\)? s is not 9/1000 Hz"


def truncated_resealed(folder):
    path = stroke_files(folder, "double")[1]
    path.write_text("".join(path.read_text().splitlines(keepends=True)[:40]))
    reseal(folder, "double", "trajectory", path)
    return path, "39 rows"


def impacts_out_of_order(folder):
    path = stroke_files(folder, "triple")[2]
    data = json.loads(path.read_text())
    data["impacts"][0]["t"], data["impacts"][1]["t"] = data["impacts"][1]["t"], data["impacts"][0]["t"]
    path.write_text(json.dumps(data))
    reseal(folder, "triple", "impacts", path)
    return path, "time order"


CORRUPTIONS = [change_value, truncate_csv, delete_json, invalid_manifest, record_missing_key, missing_folder,
               garbage_recipe, garbage_recipe_resealed, not_a_recipe_resealed, nan_sample, sample_below_head,
               wrong_time_step, truncated_resealed, impacts_out_of_order]


@pytest.mark.parametrize("corrupt", CORRUPTIONS, ids=[c.__name__ for c in CORRUPTIONS])
def test_a_corrupt_library_is_refused_naming_the_file(small, tmp_path, corrupt):
    folder = tmp_path / "copy"
    shutil.copytree(small[1], folder)
    load_library(folder)  # the copy is whole before the damage
    path, problem = corrupt(folder)
    with pytest.raises(ParameterError) as error:
        load_library(folder)
    message = str(error.value)
    assert str(path) in message
    assert re.search(problem, message), message


@pytest.mark.parametrize("key, value", [("theta_max", "x"), ("theta_max", math.nan), ("t_end", "0.548"),
                                        ("history", 5)])
def test_a_manifest_with_a_bad_value_is_refused_naming_the_manifest(small, tmp_path, key, value):
    # The manifest has no checksum of its own: its values are all the loader has to check it by.
    folder = tmp_path / "copy"
    shutil.copytree(small[1], folder)
    set_manifest(folder, lambda m: m["strokes"][1].update({key: value}))
    with pytest.raises(ParameterError) as error:
        load_library(folder)
    assert str(folder / "manifest.json") in str(error.value)


# --- builds are atomic ---------------------------------------------------------------------------------------------


def snapshot(folder):
    """Names and the samples of every stroke of the library at ``folder``, as loaded."""
    loaded = load_library(folder)
    return {name: [a.copy() for a in s.trajectory.sample(loaded.rate)] for name, s in loaded.items()}


def assert_same_snapshot(a, b):
    assert list(a) == list(b)
    for name in a:
        for x, y in zip(a[name], b[name]):
            assert np.array_equal(x, y)


def stroke_folders(folder):
    return sorted(p.name for p in Path(folder).iterdir() if p.is_dir())


@pytest.fixture
def library_a(palette, tmp_path):
    folder = tmp_path / "lib"
    build_library(folder, palette=[palette["single"], palette["double"], palette["triple"]])
    return folder, snapshot(folder)


def other_entries(palette):
    return [palette[name] for name in ("tap", "free-bounce", "whisper-roll", "moon-bounce")]


def test_a_build_failing_midway_leaves_the_previous_library(palette, library_a, monkeypatch):
    folder, before = library_a
    write = library_module._write_stroke
    calls = []

    def failing(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise OSError("disk full")
        return write(*args, **kwargs)

    monkeypatch.setattr(library_module, "_write_stroke", failing)
    with pytest.raises(OSError, match="disk full"):
        build_library(folder, palette=other_entries(palette))
    assert len(calls) == 3
    assert_same_snapshot(snapshot(folder), before)
    assert len(stroke_folders(folder)) == 1 and stroke_folders(folder)[0].startswith("strokes-")


def test_a_stroke_failing_to_simulate_leaves_the_previous_library(palette, library_a, monkeypatch):
    folder, before = library_a
    make = Entry.make

    def failing(entry):
        if entry.name == "whisper-roll":
            raise KeyboardInterrupt
        return make(entry)

    monkeypatch.setattr(Entry, "make", failing)
    with pytest.raises(KeyboardInterrupt):
        build_library(folder, palette=other_entries(palette))
    assert_same_snapshot(snapshot(folder), before)
    assert not [p for p in Path(folder).iterdir() if p.name.startswith(".strokes-")]
    assert len(stroke_folders(folder)) == 1


def test_a_failed_manifest_write_leaves_the_previous_library(palette, library_a, monkeypatch):
    folder, before = library_a

    def failing(path, data, **options):
        raise OSError("killed while writing the manifest")

    with monkeypatch.context() as patch:
        patch.setattr(library_format, "write_atomic", failing)
        with pytest.raises(OSError, match="killed"):
            build_library(folder, palette=other_entries(palette))
    assert_same_snapshot(snapshot(folder), before)
    assert not [p for p in Path(folder).iterdir() if p.name.startswith(".")]
    # The next build that succeeds leaves only its own stroke folder.
    build_library(folder, palette=other_entries(palette))
    assert stroke_folders(folder) == [manifest_of(folder)["folder"]]
    assert list(load_library(folder)) == [e.name for e in other_entries(palette)]


def test_a_full_disk_during_a_build_names_the_library_and_leaves_the_previous_one(palette, library_a, monkeypatch):
    folder, before = library_a

    def full(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    with monkeypatch.context() as patch:
        patch.setattr(os, "fsync", full)
        with pytest.raises(OSError, match="No space left on device") as caught:
            build_library(folder, palette=other_entries(palette))
    assert caught.value.filename == str(folder) and caught.value.errno == errno.ENOSPC  # not the staging folder
    assert_same_snapshot(snapshot(folder), before)
    assert not [p for p in Path(folder).iterdir() if p.name.startswith(".")]


def test_a_rebuild_replaces_the_old_library(palette, library_a):
    folder, _ = library_a
    old = manifest_of(folder)["folder"]
    built = build_library(folder, palette=other_entries(palette))
    new = manifest_of(folder)["folder"]
    assert new != old and stroke_folders(folder) == [new]
    assert sorted(p.name for p in Path(folder).iterdir()) == ["manifest.json", new]
    loaded = load_library(folder)
    assert list(loaded) == [e.name for e in other_entries(palette)]
    for name in loaded:
        assert np.array_equal(loaded[name].trajectory.sample(1000.0).theta, built[name].trajectory.sample(1000.0).theta)


# --- palette files -------------------------------------------------------------------------------------------------


def write_palette(path, text):
    path.write_text(text)
    return path


GOOD = '[[stroke]]\nname = "a"\nrecipe = "free-bounce"\n'


@pytest.mark.parametrize("text, message", [
    (GOOD + GOOD, r"^palette '[^']*palette.toml': stroke\[1\]\.name 'a' appears twice"),
    ('[[stroke]]\nname = "Big A"\nrecipe = "free-bounce"\n', r"^palette '[^']*palette.toml': stroke\[0\]\.name must be 1-64 of"),
    (GOOD + '[[stroke]]\nname = "b/c"\nrecipe = "free-bounce"\n', r"^palette '[^']*palette.toml': stroke\[1\]\.name must be"),
    (GOOD + '[[stroke]]\nname = "b"\nrecipe = "free-bounce"\ncolour = "red"\n',
     r"^palette '[^']*palette.toml': stroke\[1\] has unknown key 'colour'"),
    ('[[stroke]]\nname = "a"\nrecipe = 42\n', r"^palette '[^']*palette.toml': stroke\[0\]\.recipe must be a preset name"),
    ('[[stroke]]\nname = "a"\nrecipe = "no-such-preset"\n', r"^palette '[^']*palette.toml': stroke\[0\]\.recipe must be a preset name"),
    ('[[stroke]]\nname = "a"\nrecipe = "free-bounce"\ndescription = "two\\nlines"\n',
     r"^palette '[^']*palette.toml': stroke\[0\]\.description must be one line"),
    ('[[stroke]]\nname = "a"\nrecipe = "free-bounce"\ntransforms = { reverse = true }\n',
     r"^palette '[^']*palette.toml': stroke\[0\]\.transforms must be a list"),
])
def test_a_bad_palette_is_refused_naming_the_stroke_and_key(tmp_path, text, message):
    with pytest.raises(ParameterError, match=message):
        read_palette(write_palette(tmp_path / "palette.toml", text))


def test_a_user_palette_finds_its_recipe_files_beside_it(tmp_path, monkeypatch):
    (tmp_path / "recipes").mkdir()
    recipe_text = 't_end = 1.2\ntheta0 = 0.2\nomega0 = -1.0\n[force]\nkind = "constant"\nvalue = 150.0\n'
    (tmp_path / "recipes" / "firm.toml").write_text(recipe_text)
    palette = write_palette(tmp_path / "mine.toml", (
        '[[stroke]]\nname = "firm"\ncategory = "single stroke"\ndescription = "A firm single."\n'
        'recipe = "recipes/firm.toml"\ntransforms = [{ catch = 1 }]\n'
        '[[stroke]]\nname = "inline"\nrecipe = { t_end = 0.5, force = { kind = "constant", value = 50.0 } }\n'))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # relative to the palette file, not to the working folder
    firm, inline = read_palette(Path("..") / "mine.toml")
    assert (firm.name, firm.category, firm.description) == ("firm", "single stroke", "A firm single.")
    assert firm.transforms == ({"catch": 1},)
    want = drumstroke.Recipe(force=drumstroke.Constant(150.0), t_end=1.2, theta0=0.2, omega0=-1.0)
    assert firm.recipe.to_dict() == want.to_dict()
    assert inline.recipe.to_dict() == drumstroke.Recipe(force=drumstroke.Constant(50.0), t_end=0.5).to_dict()
    library = build_library(tmp_path / "lib", palette=palette)
    assert list(load_library(tmp_path / "lib")) == ["firm", "inline"]
    assert len(library["firm"].trajectory.impacts) == 1


# --- the Library mapping -------------------------------------------------------------------------------------------


def test_a_missing_stroke_is_refused_listing_the_names(small):
    built, folder, _ = small
    for library in (built, load_library(folder)):
        with pytest.raises(ParameterError, match=r"^stroke 'nope' is not in the library") as error:
            library["nope"]
        assert str(error.value).endswith("it has " + ", ".join(SMALL))


def test_a_library_iterates_in_palette_order(small):
    built, folder, _ = small
    assert list(SMALL) != sorted(SMALL)
    assert list(built) == list(load_library(folder)) == list(SMALL)
    assert len(built) == len(SMALL)
    assert [s.name for s in load_library(folder).values()] == list(SMALL)


# --- a damaged library is named file by file, and a build repairs it -----------------------------------------------


def missing_stroke_file(folder):
    path = stroke_files(folder, "double")[2]
    path.unlink()
    return [(path, r"is missing \(stroke 'double'\)")]


def truncated_stroke_file(folder):
    path = stroke_files(folder, "double")[1]
    path.write_bytes(path.read_bytes()[:1000])
    return [(path, r"is corrupt: 1000 bytes, the manifest says \d+ \(truncated or altered\)")]


def flipped_byte(folder):
    path = stroke_files(folder, "triple")[1]
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0x01
    path.write_bytes(bytes(data))
    return [(path, r"is corrupt: its SHA-256 differs from the manifest's")]


def a_folder_for_a_file(folder):
    path = stroke_files(folder, "single")[0]
    path.unlink()
    path.mkdir()
    return [(path, r"is not a regular file \(stroke 'single'\)")]


def extra_file(folder):
    path = stroke_files(folder, "single")[0].parent / "cymbal.csv"
    path.write_text("t,theta,omega\n")
    return [(path, r"is not in the manifest")]


def half_deleted(folder):
    """What a build killed while removing the folder left, and a build that reused it kept (issue 16)."""
    paths = [stroke_files(folder, "double")[1], stroke_files(folder, "triple")[0], stroke_files(folder, "triple")[2]]
    for path in paths:
        path.unlink()
    return [(path, "is missing") for path in paths]


def missing_stroke_folder(folder):
    path = stroke_files(folder, "single")[0].parent
    shutil.rmtree(path)
    return [(path, r"^stroke folder '.*' is missing$")]


DAMAGES = [missing_stroke_file, truncated_stroke_file, flipped_byte, a_folder_for_a_file, extra_file, half_deleted,
           missing_stroke_folder]


@pytest.mark.parametrize("damage", DAMAGES, ids=[d.__name__ for d in DAMAGES])
def test_a_damaged_library_is_named_by_check_and_load_and_repaired_by_a_build(palette, library_a, damage):
    folder, before = library_a
    entries = [palette["single"], palette["double"], palette["triple"]]
    problems = damage(folder)
    diagnosis = check_library(folder)
    assert len(diagnosis.problems) == len(problems) and diagnosis.leftovers == ()
    for (path, pattern), line in zip(problems, diagnosis.problems):
        assert str(path) in line and re.search(pattern, line), line
    with pytest.raises(ParameterError) as error:
        load_library(folder)
    assert str(error.value) == diagnosis.error()
    for path, _ in problems:
        assert str(path) in str(error.value)
    build_library(folder, palette=entries)  # the same strokes: the folder of that name is checked, not trusted
    assert check_library(folder).problems == ()
    assert_same_snapshot(snapshot(folder), before)
    assert sorted(p.name for p in folder.iterdir()) == ["manifest.json", manifest_of(folder)["folder"]]


def test_a_whole_stroke_folder_of_the_same_strokes_is_reused(palette, library_a):
    folder, before = library_a
    stroke_folder = folder / manifest_of(folder)["folder"]
    identity = stroke_folder.stat().st_ino
    build_library(folder, palette=[palette["single"], palette["double"], palette["triple"]])
    assert (folder / manifest_of(folder)["folder"]).stat().st_ino == identity
    assert_same_snapshot(snapshot(folder), before)


def test_a_stale_half_deleted_stroke_folder_is_never_reused(palette, library_a, tmp_path):
    """Issue 16: a build killed while removing an old folder left it half there; a later build of the same strokes
    kept it, and the library did not load. Now it is a leftover, not the library, and it is not trusted."""
    folder, before = library_a
    others = other_entries(palette)
    elsewhere = tmp_path / "elsewhere"
    build_library(elsewhere, palette=others)
    stale = folder / manifest_of(elsewhere)["folder"]
    shutil.copytree(elsewhere / stale.name, stale)
    for path in sorted(stale.iterdir())[::2]:
        path.unlink()
    diagnosis = check_library(folder)
    assert diagnosis.problems == ()
    note = f"{str(stale)!r}: an old stroke folder, not the manifest's; the next build removes it"
    assert diagnosis.leftovers == (note,)
    assert_same_snapshot(snapshot(folder), before)  # it is not the library: the library loads
    build_library(folder, palette=others)
    assert manifest_of(folder)["folder"] == stale.name and check_library(folder).problems == ()
    assert_same_snapshot(snapshot(folder), snapshot(elsewhere))
    assert sorted(p.name for p in folder.iterdir()) == ["manifest.json", stale.name]


STAGE = """
import sys
from pathlib import Path
from drumstroke._atomic import temporary_folder, temporary_path, write_new
library = Path(sys.argv[1])
staged = temporary_folder(library / "strokes")
write_new(staged / "single.csv", b"t,theta,omega\\n" * 1000)
write_new(temporary_path(library / "manifest.json"), b"{")
print(staged.name, flush=True)
if sys.argv[2] == "wait":
    sys.stdin.read()
"""


def stage_in(folder, mode):
    """A real process leaves a staging folder and a manifest's temporary in the library, and exits or waits."""
    process = subprocess.Popen([sys.executable, "-c", STAGE, str(folder), mode], stdin=subprocess.PIPE,
                               stdout=subprocess.PIPE, text=True, env={**os.environ, "PYTHONPATH": SOURCE})
    name = process.stdout.readline().strip()
    if mode == "exit":
        process.wait()
    return process, name


def test_leftovers_of_killed_builds_are_noted_and_swept_and_a_running_builds_are_kept(palette, library_a):
    folder, before = library_a
    entries = [palette["single"], palette["double"], palette["triple"]]
    stage_in(folder, "exit")
    live, live_name = stage_in(folder, "wait")
    try:
        diagnosis = check_library(folder)
        assert diagnosis.problems == () and len(diagnosis.leftovers) == 4
        notes = "\n".join(diagnosis.leftovers)
        assert notes.count("which was stopped before it finished; the next run writing here removes it") == 2
        assert notes.count(f"drumstroke process {live.pid}, running") == 2
        assert f"{str(folder / live_name)!r}: a temporary folder of drumstroke process {live.pid}" in notes
        assert_same_snapshot(snapshot(folder), before)
        build_library(folder, palette=entries)
        left = sorted(p.name for p in folder.iterdir() if p.name.startswith("."))
        assert len(left) == 2 and live_name in left  # the running build's, and only they
    finally:
        live.communicate("")
    build_library(folder, palette=entries)
    assert sorted(p.name for p in folder.iterdir()) == ["manifest.json", manifest_of(folder)["folder"]]
    assert check_library(folder).leftovers == ()


BUILD = """
import sys
from drumstroke.palette.library import build_library, read_palette
names = sys.argv[2].split(",")
build_library(sys.argv[1], palette=[e for e in read_palette() if e.name in names])
"""


def test_a_build_switches_the_library_only_when_no_reader_holds_it(palette, library_a):
    folder, before = library_a
    with locked(folder, shared=True):  # what load_library holds while it reads
        build = subprocess.Popen([sys.executable, "-c", BUILD, str(folder), "tap,free-bounce"],
                                 env={**os.environ, "PYTHONPATH": SOURCE})
        deadline = time.monotonic() + 60
        while not [p for p in folder.glob(".strokes.drumstroke-*") if len(list(p.iterdir())) == 6]:
            assert time.monotonic() < deadline and build.poll() is None
            time.sleep(0.05)
        time.sleep(1.0)
        assert build.poll() is None  # staged, waiting to switch
        assert_same_snapshot(snapshot(folder), before)
    assert build.wait(timeout=60) == 0
    assert list(load_library(folder)) == ["tap", "free-bounce"]
    assert sorted(p.name for p in folder.iterdir()) == ["manifest.json", manifest_of(folder)["folder"]]


# --- one stroke saved into a library -----------------------------------------------------------------------------


def test_a_saved_stroke_joins_the_library_and_leaves_the_others_bit_for_bit(small, tmp_path):
    _, folder, entries = small
    copy = tmp_path / "copy"
    shutil.copytree(folder, copy)
    before = {name: [Path(p).read_bytes() for p in stroke_files(copy, name)] for name in SMALL}
    stretched = drumstroke.palette.stretch(entries[1].make(), 1.5)
    library = library_module.save_stroke(copy, "slow-double", stretched, category="double stroke",
                                         description="slower")
    assert list(library) == [*SMALL, "slow-double"]
    assert check_library(copy).problems == ()
    assert {name: [Path(p).read_bytes() for p in stroke_files(copy, name)] for name in SMALL} == before
    loaded = load_library(copy)["slow-double"]
    assert (loaded.category, loaded.description) == ("double stroke", "slower")
    assert loaded.trajectory.history[-1] == "stretch 1.5"
    np.testing.assert_allclose(loaded.trajectory.impacts.t, stretched.impacts.t, rtol=0, atol=1e-12)


def test_a_saved_stroke_makes_an_empty_folder_a_library_and_is_refused_twice_unless_replacing(palette, tmp_path):
    single = palette["single"].make()
    library_module.save_stroke(tmp_path, "one", single)
    assert list(load_library(tmp_path)) == ["one"] and load_library(tmp_path).rate == 1000.0
    with pytest.raises(ParameterError, match="'one' is a stroke of the library"):
        library_module.save_stroke(tmp_path, "one", single)
    library_module.save_stroke(tmp_path, "one", drumstroke.palette.reverse(single), replace_stroke=True)
    assert load_library(tmp_path)["one"].trajectory.history[-1] == "reverse"
    for name in ("../up", "a/b", "Upper", ""):
        with pytest.raises(ParameterError, match="name must be"):
            library_module.save_stroke(tmp_path, name, single)
    with pytest.raises(ParameterError, match="description must be one line"):
        library_module.save_stroke(tmp_path, "two", single, description="a\nb")
    assert list(load_library(tmp_path)) == ["one"]
