"""Every CSV drumstroke writes, read by the tools people read CSV with, at their default arguments.

Each file is made once, through the API and through the command line (``drumstroke.cli.main``), and
read with ``pandas.read_csv(path)``, ``csv.DictReader(open(path))`` and ``numpy.genfromtxt(path,
delimiter=",", names=True)``: the header must be the first line (no comment before it), the columns
named as documented, and every value equal to drumstroke's own array for it, exactly (floats are
written with 17 significant digits, or as ``repr``, so they read back bit for bit), with no ``-0``.
The JSON beside a CSV must parse with ``json.load`` and name the model. The oracles are the arrays
drumstroke computed (simulated, built, composed, swept) before anything was written, never its reading
of the files. Then: drumstroke's own readers read the new files and old files (a ``#`` comment line
first) alike; the first sample of a stroke is its recipe's start, exactly; and the JSON beside a CSV
never overwrites a file that is not that CSV's metadata.
"""

import contextlib
import csv
import io
import json
import math
import re
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import drumstroke
from drumstroke.cli import main
from drumstroke.compose import compose
from drumstroke.errors import ParameterError, SampledImpactsWarning
from drumstroke.formats.responses_csv import COLUMNS, write_responses_csv
from drumstroke.formats.signal_csv import write_signal
from drumstroke.palette.library import build_library, load_library, read_palette
from drumstroke.robot.validate import validate_file
from drumstroke.score import read_score
from drumstroke.sweep import Grid, run_sweep
from drumstroke.trajectory import Trajectory

RATE = 1000.0

PALETTE = """\
[[stroke]]
name = "single"
category = "single stroke"
description = "One full stroke, caught at the top of its rebound."
recipe = { theta0 = 0.1, omega0 = -2.0, t_end = 1.0, force = { kind = "constant", value = 200.0 } }
transforms = [{ catch = 1 }]

[[stroke]]
name = "backwards"
category = "un-natural"
description = "Four seconds of the free bounce played backwards: it starts at rest, where omega is -0 reversed."
recipe = "free-bounce"
transforms = [{ trim = [0.0, 4.0] }, { reverse = true }]
"""

PATTERN = "tempo 120\n0 single 100\n0.5 single 60 left\n1 single 127\n"

GRID = """\
base = "free-bounce"
[parameters]
cor = [0.5, 0.86]
"force.value" = [0.0, 50.0]
theta0 = [0.0, 0.2]
"""


def cli(*args):
    """Run the command line in this process; its printed lines."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        status = main([str(a) for a in args])
    assert status == 0, out.getvalue()
    return out.getvalue()


def columns_of(trajectory, alpha=False):
    """A trajectory's samples by CSV column name: t, then θ, ω (and α) per stick."""
    t, theta, omega, acceleration = trajectory.samples()
    arrays = [a.reshape(len(t), -1) for a in (theta, omega) + ((acceleration,) if alpha else ())]
    names = drumstroke.formats.trajectory_csv.column_names(trajectory.sticks, alpha=alpha)
    per_stick = [a[:, j] for j in range(len(trajectory.sticks)) for a in arrays]
    return dict(zip(names, [t, *per_stick]))


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """Every CSV drumstroke writes, made once: {case: (path, {column: expected values}, model or None)}.

    ``model`` is what the JSON beside the file must name; None for the two input formats (a recorded
    signal, listening-test responses), whose columns and units are fixed and which have no JSON beside.
    """
    folder = tmp_path_factory.mktemp("csv")
    (folder / "palette.toml").write_text(PALETTE)
    (folder / "groove.pattern").write_text(PATTERN)
    (folder / "grid.toml").write_text(GRID)
    cases = {}

    # the command line
    cli("simulate", "free-bounce", "--csv", folder / "simulate.csv")
    stroke = drumstroke.simulate("free-bounce").sample(RATE)
    cases["simulate --csv"] = (folder / "simulate.csv", columns_of(stroke), "paper")

    cli("library", "build", folder / "lib", "--palette", folder / "palette.toml")
    built = build_library(folder / "api-lib", palette=folder / "palette.toml")  # the same strokes, through the API
    manifest = json.loads((folder / "lib" / "manifest.json").read_text())
    for name in ("single", "backwards"):
        path = folder / "lib" / manifest["folder"] / f"{name}.csv"
        cases[f"library build: {name}"] = (path, columns_of(built[name].trajectory.sample(RATE)), "paper")
        api = next((folder / "api-lib").glob(f"strokes-*/{name}.csv"))
        assert api.read_bytes() == path.read_bytes()  # the command and the API write the same file

    cli("compose", folder / "groove.pattern", "--library", folder / "lib", "--csv", folder / "groove.csv")
    loaded = load_library(folder / "lib")  # what the command composes from: the library as a robot host loads it
    notes = read_score(folder / "groove.pattern", stroke_names=list(loaded))
    piece = compose(notes, loaded)
    cases["compose --csv"] = (folder / "groove.csv", columns_of(piece.trajectory.sample(None)), "paper")

    cli("robot", "export", folder / "simulate.csv", "--format", "csv", "--out", folder / "export.csv")
    alpha = np.append(np.diff(stroke.omega) * RATE, 0.0)  # the forward difference, 0 at the end
    cases["robot export --format csv"] = (folder / "export.csv", {**columns_of(stroke), "alpha": alpha}, "paper")

    cli("sweep", folder / "grid.toml", "--out", folder / "sweep.csv")
    table = run_sweep(Grid.from_toml(folder / "grid.toml"))
    cases["sweep --out"] = (folder / "sweep.csv", table, "paper")

    # the API
    pair = Trajectory.from_sticks({"right": drumstroke.simulate("finger-pulses").sample(RATE), "left": stroke},
                                  name="pair")
    pair.write_csv(folder / "pair.csv")
    cases["Trajectory.write_csv, two sticks"] = (folder / "pair.csv", columns_of(pair), "paper")
    reversed_stroke = built["backwards"].trajectory
    reversed_stroke.write_csv(folder / "alpha.csv", alpha=True)
    cases["Trajectory.write_csv, alpha"] = (folder / "alpha.csv", columns_of(reversed_stroke, alpha=True), "paper")

    rows = [("s01", "pair01", "A", "B", 3, 4), ("s01", "pair02", "B", "B", 5, 1), ("s02", "pair01", "B", "A", 1, 2)]
    write_responses_csv(folder / "responses.csv", rows)
    cases["listening responses"] = (folder / "responses.csv", dict(zip(COLUMNS, map(np.array, zip(*rows)))), None)

    t = np.arange(6) / 500.0
    values = np.array([0.0, -0.0, 1 / 3, -2e-300, 189.0, math.pi])
    write_signal(folder / "signal.csv", t, values)
    cases["recorded signal"] = (folder / "signal.csv", {"t": t, "value": values}, None)
    return cases


CASES = ["simulate --csv", "library build: single", "library build: backwards", "compose --csv",
         "robot export --format csv", "sweep --out", "Trajectory.write_csv, two sticks", "Trajectory.write_csv, alpha",
         "listening responses", "recorded signal"]


def is_text(values):
    return np.asarray(values).dtype.kind in "OUS"


def assert_same(read, expected, what):
    """Numbers read equal the expected exactly (NaN where an empty cell stands for it)."""
    expected = np.asarray(expected, dtype=float)
    read = np.asarray(read, dtype=float)
    assert read.shape == expected.shape, what
    assert np.array_equal(read, expected, equal_nan=True), (what, read[read != expected][:3])


def test_every_case_is_made(written):
    assert sorted(written) == sorted(CASES)


@pytest.mark.parametrize("case", CASES)
def test_the_header_is_the_first_line_and_there_is_no_minus_zero(written, case):
    path, expected, _ = written[case]
    text = path.read_text()
    assert text.split("\n", 1)[0] == ",".join(expected)
    assert not re.search(r"(^|,)-0(\.0*)?(,|$)", text, flags=re.MULTILINE)


@pytest.mark.parametrize("case", CASES)
def test_pandas_reads_it_with_no_arguments(written, case):
    path, expected, _ = written[case]
    frame = pd.read_csv(path)
    assert list(frame.columns) == list(expected)
    for name, values in expected.items():
        if is_text(values):  # pandas reads an empty cell as NaN
            assert ["" if pd.isna(v) else str(v) for v in frame[name]] == [str(v) for v in values], name
        else:
            assert_same(frame[name].to_numpy(), values, name)


@pytest.mark.parametrize("case", CASES)
def test_the_csv_module_reads_it_with_no_arguments(written, case):
    path, expected, _ = written[case]
    with open(path) as handle:
        reader = csv.DictReader(handle)
        rows = list(reader)
    assert reader.fieldnames == list(expected)
    for name, values in expected.items():
        cells = [row[name] for row in rows]
        if is_text(values):
            assert cells == [str(v) for v in values], name
        else:
            assert_same([float(c) if c else math.nan for c in cells], values, name)


@pytest.mark.parametrize("case", CASES)
def test_numpy_reads_it_by_name(written, case):
    path, expected, _ = written[case]
    table = np.genfromtxt(path, delimiter=",", names=True)
    # genfromtxt leaves characters such as '.' out of the names it makes ("force.value" -> "forcevalue")
    assert table.dtype.names == tuple(name.replace(".", "") for name in expected)
    for name, values in expected.items():
        if not is_text(values):  # genfromtxt reads numbers (text as NaN, unasked)
            assert_same(table[name.replace(".", "")], values, name)


@pytest.mark.parametrize("case", CASES)
def test_the_json_beside_it_names_the_model(written, case):
    path, expected, model = written[case]
    side = path.with_suffix(".json")
    if model is None:
        assert not side.exists()  # an input format: fixed columns and units, nothing to say beside it
        return
    with open(side) as handle:
        meta = json.load(handle)["csv"]
    assert meta["model"] == model and meta["file"] == path.name and meta["drumstroke"] == drumstroke.__version__
    assert meta["columns"] == list(expected) and list(meta["units"]) == list(expected)
    if case != "sweep --out":
        assert meta["rate"] == RATE
        assert meta["units"]["t"] == "s" and all(meta["units"][n] == "rad" for n in expected if n.startswith("theta"))


def test_the_sweep_table_says_its_units_and_grid(written):
    path, _, _ = written["sweep --out"]
    meta = json.loads(path.with_suffix(".json").read_text())["csv"]
    assert meta["units"]["theta0"] == "rad" and meta["units"]["force.value"] == "m/s^2" and meta["units"]["cor"] == ""
    assert meta["units"]["first_impact_time_s"] == "s" and meta["units"]["mean_bounce_rate_hz"] == "Hz"
    assert meta["rows"] == 8 and meta["sweep"]["base"] == "free-bounce"
    assert meta["sweep"]["parameters"] == {"cor": [0.5, 0.86], "force.value": [0.0, 50.0], "theta0": [0.0, 0.2]}


# --- drumstroke reads them back ------------------------------------------------------------------------------------

@pytest.mark.parametrize("case", ["simulate --csv", "compose --csv", "robot export --format csv",
                                  "Trajectory.write_csv, two sticks", "Trajectory.write_csv, alpha"])
def test_read_csv_round_trips_the_new_files(written, case):
    path, expected, model = written[case]
    back = _read_sampled(path)
    assert (back.model, back.rate) == (model, RATE)
    columns = back.columns() if back.sticks != ("stick",) else (back.t, back.theta, back.omega)
    for name, values in zip(expected, columns):
        assert np.array_equal(values, expected[name]), name


def test_the_library_loads_its_new_files(written, tmp_path):
    path, expected, _ = written["library build: backwards"]
    library = load_library(path.parent.parent)
    trajectory = library["backwards"].trajectory
    assert library.rate == RATE and trajectory.model == "paper"
    assert np.array_equal(trajectory.omega, expected["omega"]) and np.array_equal(trajectory.theta, expected["theta"])


OLD_COMMENT = "# drumstroke 0.1.0; model=paper; stroke=free-bounce; rate=1000 Hz; units s, rad, rad/s"


def test_an_old_file_with_a_comment_line_first_is_read(written, tmp_path):
    """As drumstroke 0.1.0 wrote it: a # comment line, the header, the rows (here with its -0)."""
    _, expected, _ = written["simulate --csv"]
    t, theta, omega = (expected[n] for n in ("t", "theta", "omega"))
    rows = "".join(f"{a:.17g},{b:.17g},{c:.17g}\n" for a, b, c in zip(t, theta, omega))
    old = tmp_path / "old.csv"
    old.write_text(f"{OLD_COMMENT}\nt,theta,omega\n0,2.2204460492503131e-16,-0\n" + rows.split("\n", 1)[1])
    back = _read_sampled(old)
    assert (back.model, back.rate, back.name) == ("paper", RATE, "old")
    assert np.array_equal(back.theta[1:], theta[1:]) and back.theta[0] == 2.2204460492503131e-16
    assert validate_file(old).rate == RATE
    # the comment's rate is the file's: a time step that disagrees is refused
    (tmp_path / "fast.csv").write_text(OLD_COMMENT.replace("1000 Hz", "2000 Hz") + "\nt,theta,omega\n" + rows)
    with pytest.raises(drumstroke.errors.TrajectoryError, match="disagrees with the rate 2000 Hz of its comment line"):
        validate_file(tmp_path / "fast.csv")


def test_a_file_with_neither_metadata_nor_comment_takes_its_rate_from_t(written, tmp_path):
    """Another program's file (here pandas', without the JSON): the rate from the t column, the model unknown."""
    _, expected, _ = written["simulate --csv"]
    path = tmp_path / "theirs.csv"
    pd.DataFrame({name: expected[name][:2001] / (2.0 if name == "t" else 1.0) for name in expected}).to_csv(
        path, index=False)
    back = _read_sampled(path)
    assert (back.model, back.rate) == ("unknown", 2 * RATE)
    assert np.array_equal(back.theta, expected["theta"][:2001])


def test_metadata_that_does_not_describe_the_file_is_refused(written, tmp_path):
    path, _, _ = written["simulate --csv"]
    copy = tmp_path / "copy.csv"
    copy.write_text(path.read_text().replace("t,theta,omega", "t,x,y", 1))
    copy.with_suffix(".json").write_text(path.with_suffix(".json").read_text())
    with pytest.raises(ParameterError, match=r"metadata '.*copy\.json' describes the columns \['t', 'theta', 'omega'\]"
                                             r", but the CSV beside it has \['t', 'x', 'y'\]"):
        Trajectory.read_csv(copy)


# --- starting values exactly as given ------------------------------------------------------------------------------

@pytest.mark.parametrize("preset", [name for name, p in drumstroke.PRESETS.items()
                                    if (p.recipe.theta0, p.recipe.omega0) == (0.0, 0.0)])
def test_simulate_csv_starts_at_rest_exactly(preset, tmp_path):
    cli("simulate", preset, "--csv", tmp_path / "s.csv")
    assert (tmp_path / "s.csv").read_text().split("\n")[1] == "0,0,0"


# --- the JSON beside a CSV -----------------------------------------------------------------------------------------

def test_the_runs_own_json_beside_the_csv_takes_the_metadata(tmp_path):
    printed = cli("simulate", "free-bounce", "--json", tmp_path / "s.json", "--csv", tmp_path / "s.csv")
    data = json.loads((tmp_path / "s.json").read_text())
    assert data["recipe_name"] == "free-bounce" and len(data["impacts"]) == 98  # its own fields, as before
    assert data["csv"]["file"] == "s.csv" and data["csv"]["model"] == "paper"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.csv", "s.json"]
    assert f"wrote {tmp_path / 's.json'} (with the metadata of s.csv)" in printed


def test_another_json_leaves_the_metadata_to_a_sidecar_and_says_so(tmp_path):
    printed = cli("simulate", "free-bounce", "--csv", tmp_path / "s.csv", "--json", tmp_path / "other.json")
    assert "csv" not in json.loads((tmp_path / "other.json").read_text())
    assert json.loads((tmp_path / "s.json").read_text()) == {"csv": json.loads((tmp_path / "s.json").read_text())["csv"]}
    assert printed.splitlines()[-3:] == [f"wrote {tmp_path / 'other.json'}", f"wrote {tmp_path / 's.csv'}",
                                         f"wrote {tmp_path / 's.json'} (with the metadata of s.csv)"]
    cli("simulate", "constant", "--csv", tmp_path / "s.csv")  # the CSV's own metadata is rewritten with it
    assert json.loads((tmp_path / "s.json").read_text())["csv"]["name"] == "constant"


@pytest.mark.parametrize("setup, args, needles", [
    (lambda d: (d / "s.json").write_text('{"mine": 1}\n'), ["--csv", "s.csv"],
     ["s.json', a file that is already there and is not drumstroke's metadata of 's.csv'"]),
    (lambda d: None, ["--csv", "s.csv", "--plot", "s.json"], ["--plot", "must end in one of .png"]),
    (lambda d: None, ["--csv", "s.json"], ["--csv", "must end in one of .csv"]),
], ids=["a file of yours", "another output", "the CSV itself"])
def test_the_sidecar_never_overwrites_another_file(tmp_path, capsys, setup, args, needles):
    setup(tmp_path)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    status = main(["simulate", "free-bounce", *(str(tmp_path / a) if "." in a else a for a in args)])
    assert status == 2
    error = capsys.readouterr().err
    assert all(needle in error for needle in needles), error
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before  # nothing written


def test_the_api_refuses_too(tmp_path):
    trajectory = drumstroke.simulate("free-bounce").sample(RATE)
    (tmp_path / "s.json").write_text("[1, 2, 3]\n")
    with pytest.raises(ParameterError, match=r"^csv '.*s\.csv' keeps its metadata in '.*s\.json', a file that is"):
        trajectory.write_csv(tmp_path / "s.csv")
    assert not (tmp_path / "s.csv").exists() and (tmp_path / "s.json").read_text() == "[1, 2, 3]\n"
    meta = trajectory.write_csv(tmp_path / "s.csv", sidecar=False)  # the caller keeps the metadata
    assert meta["columns"] == ["t", "theta", "omega"] and (tmp_path / "s.json").read_text() == "[1, 2, 3]\n"


# --- the impacts read back -----------------------------------------------------------------------------------------

PRESS = "examples/pulses-over-a-press.toml"  # 73 impacts, 41 of them closer than two periods at 1 kHz


def test_the_impacts_of_a_runs_own_json_are_read_exactly(tmp_path):
    """The simulated stroke's impacts, exactly, where the JSON beside the CSV records them; no warning."""
    root = Path(__file__).resolve().parents[1]
    stroke = drumstroke.simulate(root / PRESS)
    assert len(stroke.impacts) == 73
    cli("simulate", root / PRESS, "--json", tmp_path / "s.json", "--csv", tmp_path / "s.csv", "--rate", RATE)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = Trajectory.read_csv(tmp_path / "s.csv")
    assert np.array_equal(back.impacts.t, stroke.impacts.t) and np.array_equal(back.impacts.omega, stroke.impacts.omega)
    assert back.impacts.tip_distance == pytest.approx(stroke.impacts.tip_distance, rel=1e-15)
    assert np.array_equal(back.theta, stroke.sample(RATE).theta)  # the samples as before


def test_the_impacts_of_a_composition_and_a_library_stroke_are_read_exactly(tmp_path):
    root = Path(__file__).resolve().parents[1]
    cli("compose", root / "examples" / "backbeat.pattern", "--json", tmp_path / "c.json", "--csv", tmp_path / "c.csv")
    recorded = json.loads((tmp_path / "c.json").read_text())["impacts"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        both, left = Trajectory.read_csv(tmp_path / "c.csv"), Trajectory.read_csv(tmp_path / "c.csv", stick="left")
    assert both.sticks == ("right", "left") and left.sticks == ("left",)
    for stick in ("right", "left"):
        assert np.array_equal(both.stick(stick).impacts.t, [row["t"] for row in recorded[stick]])
        assert np.array_equal(both.stick(stick).motions[0].omega_after, [row["omega_after"] for row in recorded[stick]])
    assert np.array_equal(left.impacts.t, both.stick("left").impacts.t) and len(left.impacts) == 108
    built = build_library(tmp_path / "lib", palette=[e for e in read_palette() if e.name == "double"])
    csv = next((tmp_path / "lib").glob("strokes-*/double.csv"))
    assert np.array_equal(Trajectory.read_csv(csv).impacts.t, built["double"].trajectory.impacts.t)


def test_without_recorded_impacts_they_are_found_in_the_samples_with_a_warning(tmp_path):
    """What the docstring says is missed: bounces closer than two sample periods; each found one is a real one."""
    root = Path(__file__).resolve().parents[1]
    stroke = drumstroke.simulate(root / PRESS)
    stroke.sample(RATE).write_csv(tmp_path / "w.csv")  # the metadata alone beside it
    with pytest.warns(drumstroke.errors.SampledImpactsWarning, match=r"w\.csv'.* found again in its samples"):
        back = Trajectory.read_csv(tmp_path / "w.csv")
    true = stroke.impacts.t
    assert len(back.impacts) == 32 < len(true)
    nearest = np.abs(back.impacts.t[:, None] - true[None, :]).min(axis=1)
    assert nearest.max() < 1.0 / RATE
    gaps = np.diff(true)
    assert len(true) - len(back.impacts) <= np.count_nonzero(gaps < 2.0 / RATE)  # only close ones are missed
    with warnings.catch_warnings(record=True) as caught:  # the command line reads the CSV for its samples: no warning
        warnings.simplefilter("always")
        cli("robot", "export", tmp_path / "w.csv", "--format", "csv", "--out", tmp_path / "e.csv")
        Trajectory.read_csv(tmp_path / "w.csv")
    assert [type(w.message) for w in caught] == [drumstroke.errors.SampledImpactsWarning]  # the API's only


def test_recorded_impacts_outside_the_samples_are_refused_naming_the_json(tmp_path):
    cli("simulate", "free-bounce", "--json", tmp_path / "s.json", "--csv", tmp_path / "s.csv")
    data = json.loads((tmp_path / "s.json").read_text())
    data["impacts"][-1]["t"] = 99.0
    (tmp_path / "s.json").write_text(json.dumps(data))
    with pytest.raises(ParameterError, match=r"metadata '.*s\.json': impacts must be in time order within \[0, 5\] s"):
        Trajectory.read_csv(tmp_path / "s.csv")


def _read_sampled(path, **options):
    """Trajectory.read_csv of a CSV with no JSON recording its impacts: they are found again in the samples, and
    it says so."""
    with pytest.warns(SampledImpactsWarning, match="found again in its samples"):
        return Trajectory.read_csv(path, **options)
