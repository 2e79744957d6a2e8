"""The ``drumstroke`` command, run as a user runs it: a real process, real files."""

import csv
import json
import math

import matplotlib.image
import numpy as np
import pytest

import drumstroke
from _cli import EXE, assert_one_line_error, run
from drumstroke.cli import main


def test_console_script_is_installed():
    assert EXE is not None, "pip install should put 'drumstroke' on PATH"


def test_simulate_writes_json_csv_and_plot(tmp_path):
    result = run("simulate", "free-bounce", "--json", tmp_path / "s.json", "--csv", tmp_path / "s.csv",
                 "--plot", tmp_path / "s.png", "--rate", 500)
    assert result.returncode == 0, result.stderr
    assert "model paper" in result.stdout

    data = json.loads((tmp_path / "s.json").read_text())
    stroke = drumstroke.simulate("free-bounce")
    assert data["model"] == "paper" and data["t_end"] == 5.0
    assert data["recipe"] == drumstroke.preset("free-bounce").to_dict()
    assert data["rest_time"] == stroke.rest_time
    assert [i["t"] for i in data["impacts"]] == stroke.impacts.t.tolist()
    first = data["impacts"][0]
    assert first["tip_speed"] == pytest.approx(abs(first["omega"]) * 0.27, rel=1e-15)
    assert first["level_db"] == pytest.approx(20 * math.log10(first["tip_speed"]), rel=1e-12)

    with open(tmp_path / "s.csv", newline="") as handle:
        comment = handle.readline()
        rows = list(csv.reader(handle))
    assert comment.startswith("#") and "model=paper" in comment and "rate=500 Hz" in comment
    assert rows[0] == ["t", "theta", "omega"]
    table = np.array(rows[1:], dtype=float)
    assert len(table) == 5 * 500 + 1
    assert np.allclose(np.diff(table[:, 0]), 1 / 500, atol=1e-12, rtol=0)
    _, theta, omega = stroke.sample(500)
    assert np.array_equal(table[:, 1], theta) and np.array_equal(table[:, 2], omega)

    image = matplotlib.image.imread(tmp_path / "s.png")
    assert image.ndim == 3 and image.shape[0] > 300 and image.shape[1] > 500


def test_simulate_a_recipe_file_with_the_geometry_model(tmp_path):
    recipe = tmp_path / "press.toml"
    recipe.write_text('model = "geometry"\nt_end = 2.0\n[force]\nkind = "constant"\nvalue = 30.0\n')
    result = run("simulate", recipe, "--json", tmp_path / "p.json")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "p.json").read_text())
    assert data["model"] == "geometry" and data["recipe_name"] == "press" and data["t_end"] == 2.0
    # --model overrides the file
    result = run("simulate", recipe, "--model", "paper", "--json", tmp_path / "q.json")
    assert json.loads((tmp_path / "q.json").read_text())["model"] == "paper"


def test_presets_lists_every_preset():
    result = run("presets")
    assert result.returncode == 0
    for name in drumstroke.PRESETS:
        assert name in result.stdout


def test_figures_draws_figs_4_to_7(tmp_path):
    result = run("figures", tmp_path / "figs")
    assert result.returncode == 0, result.stderr
    names = sorted(p.name for p in (tmp_path / "figs").iterdir())
    assert names == ["fig4-free-bounce.png", "fig5-low-high.png", "fig6-high-low.png", "fig7-finger-pulses.png"]
    for path in (tmp_path / "figs").iterdir():
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_demo_writes_plots_and_json_for_the_four_figures(tmp_path):
    result = run("demo", tmp_path / "out")
    assert result.returncode == 0, result.stderr
    for stem in ("fig4-free-bounce", "fig5-low-high", "fig6-high-low", "fig7-finger-pulses"):
        data = json.loads((tmp_path / "out" / f"{stem}.json").read_text())
        assert data["model"] == "paper" and len(data["impacts"]) > 5
        assert (tmp_path / "out" / f"{stem}.png").stat().st_size > 10_000
        assert (tmp_path / "out" / f"{stem}.csv").read_text().splitlines()[1] == "t,theta,omega"


@pytest.mark.parametrize(
    "args, needles",
    [
        (["simulate", "no-such-preset"], ["recipe", "'no-such-preset'", "free-bounce"]),
        (["simulate", "free-bounce", "--rate", "0"], ["--rate", "0.0", "(0, 1e+06]"]),
        (["simulate", "free-bounce", "--rate", "nan"], ["--rate", "nan"]),
        (["simulate", "free-bounce", "--rate=-inf"], ["--rate", "-inf"]),
        (["simulate", "free-bounce", "--rate", "fast"], ["--rate", "'fast'"]),
        (["simulate", "free-bounce", "--model", "newton"], ["--model", "'newton'", "paper"]),
        (["simulate", "missing.toml"], ["missing.toml", "cannot be read"]),
        (["simulate"], ["STROKE"]),
        (["figures"], ["OUTDIR"]),
        (["transmogrify"], ["transmogrify"]),
    ],
)
def test_bad_arguments_give_one_line_and_status_2(args, needles):
    assert_one_line_error(run(*args), *needles)


@pytest.mark.parametrize(
    "text, needles",
    [
        ("cor = 1.5\n[force]\nkind='constant'\nvalue=0.0\n", ["cor", "1.5", "[0, 1]"]),
        ("cor = nan\n[force]\nkind='constant'\nvalue=0.0\n", ["cor", "nan"]),
        ("t_end = -1.0\n[force]\nkind='constant'\nvalue=0.0\n", ["t_end", "-1.0", "[1e-06, 3600]"]),
        ("theta0 = -0.5\n[force]\nkind='constant'\nvalue=0.0\n", ["theta0", "-0.5", "theta_max"]),
        ("[force]\nkind='piecewise-linear'\npoints=[[0.0, 1.0], [0.0, 2.0]]\n", ["force.points", "strictly increasing"]),
        ("[force]\nkind='pulses'\namplitude=1.0\nperiod=0.4\nduty=1.0\n", ["force.duty", "1.0", "(0, 1)"]),
        ("[force]\nkind='constant'\nvalue=inf\n", ["force.value", "inf"]),
        ("[force\nkind='constant'\n", ["not valid TOML"]),
        ("t_end = 5.0\n", ["[force]"]),
        ("[force]\nkind='samples'\nfile='nowhere.csv'\n", ["force.file", "nowhere.csv"]),
        ("[force]\nkind='constant'\nvalue=0.0\n[gravity]\nkind='constant'\nvalue=-60.0\n", ["vertical"]),
    ],
)
def test_bad_recipes_give_one_line_and_status_2(tmp_path, text, needles):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    assert_one_line_error(run("simulate", path), *needles)


def test_corrupt_samples_file_is_named(tmp_path):
    (tmp_path / "thumb.csv").write_text("t,value\n0.0,1.0\n0.1,oops\n")
    (tmp_path / "r.toml").write_text("[force]\nkind='samples'\nfile='thumb.csv'\n")
    assert_one_line_error(run("simulate", tmp_path / "r.toml"), "force.file", "thumb.csv", "line 3", "oops")


def test_unwritable_output_is_an_error_not_a_traceback(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert_one_line_error(run("simulate", "free-bounce", "--json", blocker / "x.json"))


def test_main_returns_the_status_without_exiting(tmp_path, capsys):
    assert main(["simulate", "constant", "--json", str(tmp_path / "c.json")]) == 0
    assert main(["simulate", "constant", "--rate", "-5"]) == 2
    assert "--rate" in capsys.readouterr().err
