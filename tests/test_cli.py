"""The ``drumstroke`` command, run as a user runs it, on real files: in-process through ``main`` (tests/_cli.py),
and as the console script in a process of its own where the process is what is tested."""

import argparse
import csv
import errno
import io
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest
import soundfile

import drumstroke
import drumstroke.compose
import drumstroke.demo
import drumstroke.evaluation.stimuli
import drumstroke.palette.library
import drumstroke.robot.track
import drumstroke.stroke
import drumstroke.sweep
from _cli import EXE, assert_one_line_error, run, run_process
from drumstroke.cli import COMMANDS, build_parser, main
from drumstroke.cli._common import Bar
from drumstroke.cli._options import Output


def test_console_script_is_installed():
    assert EXE is not None, "pip install should put 'drumstroke' on PATH"


@pytest.mark.parametrize("args", [("presets",), ("simulate", "free-bounce", "--rate", "-5"), ("--version",),
                                  ("compose", "--help")])
def test_the_console_script_prints_and_exits_as_the_in_process_run_of_the_tests(args):
    """What tests/_cli.py's run() returns is what the console script in its own process gives."""
    process, in_process = run_process(*args), run(*args)
    assert (process.returncode, process.stdout, process.stderr) == (
        in_process.returncode, in_process.stdout, in_process.stderr)


def test_the_console_script_writes_what_the_in_process_run_writes(tmp_path):
    """The console script leaves its objects to the exit (cli.console): every file it wrote is there, whole."""
    for where, runner in (("process", run_process), ("in-process", run)):
        (tmp_path / where).mkdir()
        done = runner("simulate", "double", "--json", "s.json", "--csv", "s.csv", "--midi", "s.mid", cwd=tmp_path / where)
        assert done.returncode == 0, done.stderr
    for name in ("s.json", "s.csv", "s.mid"):
        assert (tmp_path / "process" / name).read_bytes() == (tmp_path / "in-process" / name).read_bytes(), name


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
        rows = list(csv.reader(handle))
    assert rows[0] == ["t", "theta", "omega"]  # the header first
    # s.json is the JSON beside s.csv: the CSV's metadata is added to it, its own fields kept
    assert data["csv"] == {"file": "s.csv", "drumstroke": drumstroke.__version__, "model": "paper",
                           "name": "free-bounce", "rate": 500.0, "sticks": ["stick"],
                           "columns": ["t", "theta", "omega"], "units": {"t": "s", "theta": "rad", "omega": "rad/s"}}
    assert "wrote " + str(tmp_path / "s.json") + " (with the metadata of s.csv)" in result.stdout
    assert not (tmp_path / "s.csv.json").exists() and len(list(tmp_path.iterdir())) == 3
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


def test_demo_writes_plots_and_json_for_the_four_figures(demo):
    result, out = demo
    assert result.returncode == 0, result.stderr
    for stem in ("fig4-free-bounce", "fig5-low-high", "fig6-high-low", "fig7-finger-pulses"):
        data = json.loads((out / f"{stem}.json").read_text())
        assert data["model"] == "paper" and len(data["impacts"]) > 5
        assert (out / f"{stem}.png").stat().st_size > 10_000
        assert (out / f"{stem}.csv").read_text().splitlines()[0] == "t,theta,omega"
        assert data["csv"]["file"] == f"{stem}.csv" and data["csv"]["model"] == "paper"


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


# --- the command line a user expects -------------------------------------------------------------------------------

def _parsers(parser=None, words=("drumstroke",)):
    """Every parser of the command line, with its words: the top one, each command's, each action's."""
    parser = parser or build_parser()
    yield " ".join(words), parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _parsers(sub, (*words, name))


def test_python_dash_m_drumstroke_is_the_command():
    for module in ("drumstroke", "drumstroke.cli"):
        result = subprocess.run([sys.executable, "-m", module, "--version"], capture_output=True, text=True,
                                timeout=60, check=False)
        assert result.returncode == 0 and result.stdout == f"drumstroke {drumstroke.__version__}\n", result


def test_abbreviated_options_are_refused_by_every_parser(capsys):
    assert all(parser.allow_abbrev is False for _, parser in _parsers())
    assert main(["simulate", "free-bounce", "--rat", "100"]) == 2
    assert "unrecognized arguments: --rat 100" in capsys.readouterr().err
    assert main(["library", "build", "lib", "--pal", "x.toml"]) == 2
    assert "unrecognized arguments: --pal" in capsys.readouterr().err


def test_every_command_and_option_says_what_it_does_and_its_default():
    for words, parser in _parsers():
        assert parser.description, f"{words} --help has no description"
        for action in parser._actions:
            if isinstance(action, (argparse._HelpAction, argparse._VersionAction, argparse._SubParsersAction)):
                continue
            name = f"{words} {'/'.join(action.option_strings) or action.dest}"
            assert action.help, f"{name} has no help"
            if action.default not in (None, False, [], argparse.SUPPRESS):
                assert "default" in action.help, f"{name}: the help does not give the default {action.default!r}"
            if action.metavar == "HZ":
                assert "Hz" in action.help, f"{name}: the help does not give the unit"
        if any(isinstance(action, Output) for action in parser._actions):
            assert "--mkdir" in parser._option_string_actions, f"{words} writes files but has no --mkdir"


@pytest.fixture
def work(monkeypatch):
    """The calls that do a command's work, recorded (and refused): a test asserts that none was made."""
    calls = []

    def refuse(name):
        def call(*args, **kwargs):
            calls.append(name)
            raise AssertionError(f"{name} was called")
        return call

    for module, name in [(drumstroke.stroke, "solved"), (drumstroke.palette.library, "build_library"),
                         (drumstroke.sweep, "run_sweep"), (drumstroke.compose, "compose"),
                         (drumstroke.robot.track, "track"), (drumstroke.evaluation.stimuli, "make_stimuli"),
                         (drumstroke.evaluation.stimuli, "fit_stimuli"),
                         (drumstroke.demo, "run_demo"), (drumstroke.demo, "write_figures")]:
        monkeypatch.setattr(module, name, refuse(name))
    return calls


EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("args, needles", [
    (["simulate", "free-bounce", "--stretch", "-1"], ["argument --stretch:", "-1.0", "[0.01, 100]"]),
    (["simulate", "free-bounce", "--compress", "0"], ["argument --compress:", "0.0", "(0, inf)"]),
    (["simulate", "free-bounce", "--catch", "1.5"], ["argument --catch:", "integer", "'1.5'"]),
    (["simulate", "free-bounce", "--trim", "1:1"], ["argument --trim:", "'1:1'", "0 <= T0 < T1"]),
    (["simulate", "free-bounce", "--rate", "-5"], ["argument --rate:", "-5.0", "(0, 1e+06] Hz"]),
    (["simulate", "free-bounce", "--csv", "{tmp}/no/such/x.csv"],
     ["--csv: directory '{tmp}/no/such' does not exist (use --mkdir to create it)"]),
    (["simulate", "free-bounce", "--wav", "{tmp}/out.mp3"], ["argument --audio/--wav:", "out.mp3", ".wav, .flac, .ogg"]),
    (["simulate", "free-bounce", "--plot", "{tmp}/s.jpg"], ["argument --plot:", "s.jpg", ".png, .pdf, .svg"]),
    (["simulate", "free-bounce", "--json", "{tmp}/s.csv"], ["argument --json:", "s.csv", ".json"]),
    (["simulate", "free-bounce", "--midi", "{tmp}/s.wav"], ["argument --midi:", "s.wav", ".mid, .midi"]),
    (["simulate", "dubble"], ["'dubble'", "did you mean 'double'?", "palette strokes: single"]),
    (["simulate", "single", "--library", "{tmp}", "--model", "geometry"], ["--model cannot be used with --library"]),
    (["simulate", "single", "--library", "{tmp}/no-lib"], ["argument --library:", "'{tmp}/no-lib' does not exist"]),
    (["library", "build", "{tmp}/no/lib"], ["DIR: directory '{tmp}/no' does not exist (use --mkdir"]),
    (["library", "build", "{tmp}/lib", "--rate", "0.5"], ["argument --rate:", "0.5", "[1, 100000] Hz"]),
    (["library", "build", "{tmp}/lib", "--palette", "{tmp}/p.toml"], ["argument --palette:", "does not exist"]),
    (["figures", "{tmp}/no/figs"], ["OUTDIR: directory '{tmp}/no' does not exist"]),
    (["demo", "{tmp}/no/out"], ["OUTDIR: directory '{tmp}/no' does not exist"]),
    (["sweep", "{examples}/sweeps/press-and-bounce.toml", "--out", "{tmp}/t.txt"], ["argument --out:", ".csv, .parquet"]),
    (["sweep", "{examples}/sweeps/press-and-bounce.toml", "--out", "{tmp}/t.csv", "--audible-db", "0"],
     ["argument --audible-db:", "(0, 200] dB"]),
    (["compose", "{examples}/backbeat.pattern", "--library", "{tmp}", "--rate", "0"], ["argument --rate:", "[1, 100000]"]),
    (["compose", "{examples}/backbeat.pattern", "--library", "{tmp}", "--wav", "{tmp}/p.aiff"], ["--wav", ".ogg"]),
    (["robot", "track", "free-bounce", "--rate", "5"], ["argument --rate:", "5.0", "[10, 100000] Hz"]),
    (["robot", "track", "free-bounce", "--report", "{tmp}/r.txt"], ["argument --report:", ".json"]),
    (["listen", "make-stimuli", "--library", "{tmp}", "--out", "{tmp}/no/stimuli"], ["--out: directory"]),
    (["listen", "make-stimuli", "--recordings", "{tmp}/none.wav", "--out", "{tmp}/s"], ["'{tmp}/none.wav' does not"]),
    (["listen", "make-stimuli", "--recordings", "{examples}/backbeat.pattern", "--out", "{tmp}/s", "--strokes", "a"],
     ["--strokes picks library strokes"]),
    (["listen", "serve", "{examples}/listening-responses.csv", "--db", "{tmp}/a.db", "--port", "70000"],
     ["argument --port:", "70000", "[1, 65535]"]),
    (["stats", "--summary", "4.227,2.654,4.999,1.564,22", "--alpha", "0.7"], ["argument --alpha:", "(0, 0.5)"]),
])
def test_every_option_is_checked_before_any_work(tmp_path, capsys, work, args, needles):
    fill = {"tmp": str(tmp_path), "examples": str(EXAMPLES)}
    assert main([arg.format(**fill) for arg in args]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle.format(**fill) in err, (needle, err)
    assert work == [] and list(tmp_path.iterdir()) == []  # no work started, nothing written, no folder made


def test_an_output_that_is_a_directory_is_refused_before_any_work(tmp_path, capsys, work):
    (tmp_path / "s.json").mkdir()
    assert main(["simulate", "free-bounce", "--json", str(tmp_path / "s.json")]) == 2
    assert capsys.readouterr().err == f"drumstroke simulate: error: --json: '{tmp_path / 's.json'}' is a directory, not a file\n"
    assert work == [] and list(tmp_path.iterdir()) == [tmp_path / "s.json"]


def test_mkdir_creates_the_missing_folders_and_nothing_else(tmp_path, capsys):
    (tmp_path / "d.csv").mkdir()
    assert main(["simulate", "constant", "--json", str(tmp_path / "a" / "s.json"), "--csv", str(tmp_path / "d.csv"),
                 "--mkdir"]) == 2
    assert "--csv:" in capsys.readouterr().err and not (tmp_path / "a").exists()  # every check before any folder
    (tmp_path / "d.csv").rmdir()
    out = tmp_path / "a" / "b" / "s.json"
    assert main(["simulate", "constant", "--json", str(out), "--mkdir"]) == 0
    assert json.loads(out.read_text())["recipe_name"] == "constant"
    assert capsys.readouterr().out.endswith(f"wrote {out}\n")
    assert main(["figures", str(tmp_path / "c" / "figs"), "--mkdir"]) == 0
    assert len(list((tmp_path / "c" / "figs").glob("*.png"))) == 4
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a", "c"]


def test_a_write_error_names_the_option_the_path_and_the_reason(tmp_path, capsys, monkeypatch):
    def full_disk(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", full_disk)
    path = tmp_path / "s.json"
    assert main(["simulate", "constant", "--json", str(path)]) == 2
    assert capsys.readouterr().err == (f"drumstroke simulate: error: --json: cannot write '{path}': "
                                       f"{os.strerror(errno.ENOSPC)}\n")
    assert list(tmp_path.iterdir()) == []  # not the file, not its temporary


@pytest.mark.parametrize("name, file_format, subtype", [("s.wav", "WAV", "PCM_24"), ("s.flac", "FLAC", "PCM_24"),
                                                        ("s.OGG", "OGG", "VORBIS")])
def test_the_audio_format_follows_the_extension(tmp_path, name, file_format, subtype):
    assert main(["simulate", "double", "--audio", str(tmp_path / name)]) == 0
    info = soundfile.info(tmp_path / name)
    assert (info.format, info.subtype, info.samplerate, info.channels) == (file_format, subtype, 48000, 1)
    signal, _ = soundfile.read(tmp_path / name)
    assert np.abs(signal).max() > 0.1  # the two impacts sound


def test_the_picture_format_follows_the_extension(tmp_path):
    assert main(["simulate", "double", "--plot", str(tmp_path / "d.pdf"), "--wav", str(tmp_path / "d.wav")]) == 0
    assert (tmp_path / "d.pdf").read_bytes().startswith(b"%PDF")
    assert soundfile.info(tmp_path / "d.wav").format == "WAV"  # --wav is --audio
    assert main(["simulate", "double", "--plot", str(tmp_path / "d.svg")]) == 0
    assert "<svg" in (tmp_path / "d.svg").read_text()


def test_a_palette_stroke_is_simulated_then_post_processed_as_the_palette_says(tmp_path, capsys):
    assert main(["simulate", "double", "--json", str(tmp_path / "d.json")]) == 0
    out = capsys.readouterr().out
    double = drumstroke.make_stroke("double")
    assert out.startswith("stroke double: model paper") and "; after catch 2\n2 impacts;" in out
    data = json.loads((tmp_path / "d.json").read_text())
    assert [i["t"] for i in data["impacts"]] == double.impacts.t.tolist()
    assert data["history"] == list(double.history) and data["t_end"] == double.t_end
    assert main(["simulate", "double", "--model", "geometry", "--json", str(tmp_path / "g.json")]) == 0
    assert json.loads((tmp_path / "g.json").read_text())["model"] == "geometry"


def test_a_library_stroke_is_played_as_stored(tmp_path, capsys):
    from drumstroke.palette.library import build_library, load_library, read_palette

    build_library(tmp_path / "lib", palette=[e for e in read_palette() if e.name == "single"], rate=500.0)
    assert main(["simulate", "single", "--library", str(tmp_path / "lib"), "--csv", str(tmp_path / "s.csv")]) == 0
    assert "stroke single: model paper" in capsys.readouterr().out
    stored = load_library(tmp_path / "lib")["single"].trajectory
    rows = np.loadtxt(tmp_path / "s.csv", delimiter=",", skiprows=1)  # the header first
    assert np.array_equal(rows[:, 0], stored.t) and np.array_equal(rows[:, 1], stored.theta)  # at its own rate
    assert main(["simulate", "singel", "--library", str(tmp_path / "lib")]) == 2
    assert "did you mean 'single'?" in capsys.readouterr().err


def test_presets_lists_the_palette_strokes_too(capsys):
    assert main(["presets"]) == 0
    out = capsys.readouterr().out
    for name in ("double", "triple", "moon-bounce", "whisper-roll"):
        assert f"\n  {name} " in out


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def _screen(text):
    """The lines a terminal shows for ``text``: a carriage return starts the line over, overwriting it."""
    lines = []
    for line in text.split("\n"):
        shown = ""
        for part in line.split("\r"):
            shown = part + shown[len(part):]
        lines.append(shown.rstrip())
    return lines


def test_the_progress_bar_draws_on_a_terminal_only_and_is_cleared(monkeypatch):
    terminal = _Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    bar = Bar("building")
    bar.update(0.5)
    bar.close()
    assert "building:   0%|" in terminal.getvalue() and _screen(terminal.getvalue()) == [""]
    piped = io.StringIO()
    monkeypatch.setattr(sys, "stderr", piped)
    with Bar("building") as bar:
        bar.update(1.0)
    assert piped.getvalue() == ""


def test_a_progress_bar_and_the_output_do_not_collide_on_a_terminal(tmp_path, monkeypatch):
    terminal = _Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    monkeypatch.setattr(sys, "stdout", terminal)
    assert main(["figures", str(tmp_path / "figs"), "--mkdir"]) == 0
    # the bar was drawn (its 0 % at once; which later states tqdm draws depends on the time between updates, its
    # 0.1-s least interval, so none of them is asserted)
    assert "drawing figures:   0%|" in terminal.getvalue()
    screen = [line for line in _screen(terminal.getvalue()) if line]
    assert screen == [f"wrote {p}" for p in sorted((tmp_path / "figs").iterdir())]


@pytest.mark.parametrize("argv", [["--version"], ["--help"], ["simulate", "--help"]])
def test_the_front_door_imports_no_command_work(argv):
    """--version and --help (and a command's help) import none of what the commands compute with (not timed)."""
    heavy = ("scipy.optimize", "numba", "librosa", "matplotlib", "drumstroke.design", "drumstroke.analysis")
    code = ("import contextlib, io, sys\nfrom drumstroke.cli import main\n"
            f"with contextlib.redirect_stdout(io.StringIO()):\n    status = main({argv!r})\n"
            f"print(status, [m for m in {heavy!r} if m in sys.modules])")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["0", "[]"]


def test_every_command_listed_is_built_by_its_module():
    """Each command --help lists (without importing its module) gets its description and options from the module."""
    commands = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    assert list(commands.choices) == list(COMMANDS)
    for name, parser in commands.choices.items():
        assert parser.description, name
        assert parser.get_default("run") or any(isinstance(a, argparse._SubParsersAction) for a in parser._actions)
