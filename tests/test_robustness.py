"""The fuzz and fault campaign of benchmarks/robustness.py, at the suite's scale.

* 10,000 random valid recipes (its seeded generator: both models, every profile kind, sums nested,
  forces up to 10⁶ m/s², breakpoints 1 ns apart) and a few hundred drawn by hypothesis: none
  crashes, hangs or gives NaN, no sample lies below the head, impacts come in time order.
* Every hostile input of the campaign (:data:`robustness.HOSTILE`, over 200 across every command
  and file reader) through ``drumstroke.cli.main`` in-process, and a representative subset, with
  those that need a process of their own (a file size limit), through the console script in a
  subprocess: one line on stderr naming the parameter or the path, exit status 2, no traceback,
  none over 10 s.
* The CLI's one error path: each exception type a command can meet from a user's input ends in
  one line and exit 2; any other is a bug, reported in one line that says where to report it,
  with its traceback in a log file, and exit 1 — in-process and in a real subprocess.
"""

import errno
import math
import os
import sqlite3
import subprocess
import sys
import textwrap
from collections import Counter
from pathlib import Path

import pytest
from hypothesis import given, settings

import drumstroke
from drumstroke import cli
from drumstroke.errors import ParameterError
from drumstroke.solver import taylor

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import robustness  # the campaign, shared with the benchmark

RECIPES = 10_000
"""Random valid recipes from the seeded generator."""


def _kinds(table):
    """Every profile kind in a recipe table, sums' parts included."""
    found = Counter()

    def walk(profile):
        found[profile["kind"]] += 1
        for part in profile.get("parts", ()):
            walk(part)

    walk(table["force"])
    walk(table["gravity"])
    return found


def test_ten_thousand_random_valid_recipes(tmp_path):
    draw, tally, kinds, models = robustness.Seeded(16), robustness.Tally(), Counter(), Counter()
    for _ in range(RECIPES):
        table = draw.table()
        kinds.update(_kinds(table))
        models[table["model"]] += 1
        tally.run(table, tmp_path)
    print(f"{tally.runs} recipes: {dict(tally.outcomes)}; slowest {tally.slowest:.3f} s")
    assert tally.runs == RECIPES
    assert tally.failures == []
    for broken in ("crash", "hang", "NaN", robustness.BELOW, "impacts out of time order",
                   "samples off the control rate"):
        assert tally.count(broken) == 0, broken
    # the campaign is not empty: both models, every kind, sums, most strokes simulated to their end
    assert set(models) == set(drumstroke.MODELS) and min(models.values()) > RECIPES // 3
    assert set(kinds) == {"constant", "piecewise-linear", "samples", "pulses", "sum"}
    assert min(kinds.values()) > RECIPES // 10
    assert tally.count("simulated") > RECIPES // 2


@settings(robustness.FUZZ, max_examples=300, deadline=None)
@given(robustness.recipe_tables())
def test_random_valid_recipes_drawn_by_hypothesis(tmp_path_factory, table):
    tally = robustness.Tally()
    tally.run(table, tmp_path_factory.mktemp("recipe"))
    assert tally.failures == []


def test_a_stick_on_the_head_stays_under_a_pull_too_brief_to_lift_it():
    """C = -1e-96 s⁻² rising at 1e3 s⁻³ turns to pressing after 1e-99 s, when the stick could have gained at most
    1e-195 rad/s: it stays on the head. (It used to be lifted and land again at the same instant for ever.)"""
    theta_max = drumstroke.Stick().theta_max
    outcome, t, theta, omega, *_ = taylor.run_piece(0.0, theta_max, 0.0, False, 0.0, 1e-3, -1e-96, 1e3, theta_max,
                                                    0.5, 1e-3, 10**6)
    assert (outcome, t, theta, omega) == (taylor.REST, 0.0, theta_max, 0.0)
    # a real pull still lifts it: C = -1 s⁻² easing to 0 over 1 ms gives ω = cos θ_max · 0.5e-3 rad/s (4.8e-4),
    # beyond the Zeno floor (θ moves by under 2e-7 rad meanwhile)
    outcome, t, theta, omega, *_ = taylor.run_piece(0.0, theta_max, 0.0, False, 0.0, 1e-3, -1.0, 1e3, theta_max,
                                                    0.5, 1e-3, 10**6)
    assert outcome == taylor.DONE and theta > theta_max
    assert omega == pytest.approx(0.5e-3 * math.cos(theta_max), rel=1e-3)


# -- hostile inputs -------------------------------------------------------------------------------------------------

IN_PROCESS = [case for case in robustness.HOSTILE if not case.own_process]
OWN_PROCESS = [case for case in robustness.HOSTILE if case.own_process]


def _first_of_each(prefixes):
    """The first hostile case of each reader or command named in ``prefixes`` (a subset for subprocesses)."""
    chosen = {}
    for case in robustness.HOSTILE:
        for prefix in prefixes:
            if case.id.startswith(prefix) and prefix not in chosen:
                chosen[prefix] = case
    assert len(chosen) == len(prefixes), set(prefixes) - set(chosen)
    return list(chosen.values())


SUBPROCESS = OWN_PROCESS + [case for case in _first_of_each((
    "recipe/fifo", "samples/dev-zero", "recipe/t_end-5000-digits", "recipe/force-400-digits",
    "recipe/sum-nested-250", "recipe/array-nested-100000", "recipe/samples-absolute-dev-zero", "midi/tempo-0",
    "library-manifest/rate-400-digits", "listen-serve/port-99999", "listen-serve/db-not-a-database",
    "listen-analyze/not-a-database", "listen-analyze/fifo", "write/--csv-onto-directory",
    "listening-config/seed-5000-digits", "live/--score-midi-tempo-0")) if not case.own_process]


def test_the_campaign_covers_every_reader_and_command():
    assert len(robustness.HOSTILE) >= 100
    groups = {case.id.split("/")[0] for case in robustness.HOSTILE}
    assert {"recipe", "samples", "pattern", "midi", "mapping", "robot-config", "trajectory", "responses", "palette",
            "sweep-grid", "library-manifest", "listening-config", "listen-serve", "listen-analyze", "write", "live",
            "simulate", "compose", "design", "rudiment", "stats", "library-build", "robot-track"} <= groups
    assert len({case.id for case in robustness.HOSTILE}) == len(robustness.HOSTILE)


@pytest.mark.parametrize("case", IN_PROCESS, ids=lambda case: case.id)
def test_hostile_input_in_process(case, tmp_path):
    argv, needles = case.make(tmp_path)
    status, stderr, seconds = robustness.run_in_process(argv)
    assert robustness.verdict(status, stderr, seconds, needles) == "", stderr


@pytest.mark.parametrize("case", SUBPROCESS, ids=lambda case: case.id)
def test_hostile_input_through_the_console_script(case, tmp_path):
    argv, needles = case.make(tmp_path)
    status, stderr, seconds = robustness.run_command(argv, limits=case.limits)
    assert robustness.verdict(status, stderr, seconds, needles) == "", stderr
    assert not [p.name for p in tmp_path.rglob("*.tmp")]  # a refused write leaves no temporary file


def test_writing_past_the_file_size_limit_leaves_nothing(tmp_path):
    """'File too large' (a full disk alike) names the user's path, and leaves neither the file nor a temporary."""
    status, stderr, _ = robustness.run_command(["simulate", "free-bounce", "--csv", str(tmp_path / "out.csv")],
                                               limits=(("RLIMIT_FSIZE", 4096),))
    assert status == 2 and stderr.strip() == (f"drumstroke simulate: error: --csv: cannot write "
                                              f"{str(tmp_path / 'out.csv')!r}: File too large")
    assert list(tmp_path.iterdir()) == []


def test_wav_reader_refuses_what_is_not_audio(tmp_path):
    from drumstroke.formats.wav import read_wav

    (tmp_path / "folder.wav").mkdir()
    (tmp_path / "noise.wav").write_bytes(b"RIFF" + bytes(range(256)) * 4)
    (tmp_path / "empty.wav").write_bytes(b"")
    os.mkfifo(tmp_path / "fifo.wav")
    os.symlink("/dev/zero", tmp_path / "zero.wav")
    for name, reason in (("folder.wav", "directory"), ("noise.wav", ""), ("empty.wav", ""), ("fifo.wav", "FIFO"),
                         ("zero.wav", "character device"), ("missing.wav", "No such file")):
        with pytest.raises(ParameterError) as caught:
            read_wav(tmp_path / name)
        message = str(caught.value)
        assert str(tmp_path / name) in message and reason in message and "\n" not in message, message


# -- the one error path ----------------------------------------------------------------------------------------------

INPUT_ERRORS = [
    ParameterError("t_end must be in [1e-06, 3600] s, got 5000"),
    FileNotFoundError(errno.ENOENT, "No such file or directory", "/nowhere/r.toml"),
    PermissionError(errno.EACCES, "Permission denied", "/root/r.toml"),
    IsADirectoryError(errno.EISDIR, "Is a directory", "/tmp"),
    OSError(errno.EFBIG, "File too large", "/tmp/out.csv"),
    OSError(errno.ENOSPC, "No space left on device", "/tmp/out.csv"),
    UnicodeDecodeError("utf-8", b"\xff", 0, 1, "invalid start byte"),
    sqlite3.DatabaseError("file is not a database"),
    sqlite3.OperationalError("unable to open database file"),
    RecursionError("maximum recursion depth exceeded"),
    MemoryError(),
    ValueError("Exceeds the limit (4300 digits) for integer string conversion"),
    OverflowError("int too large to convert to float"),
]

BUGS = [KeyError("rate"), TypeError("unsupported operand"), AttributeError("'NoneType' has no attribute 'x'"),
        ZeroDivisionError("float division by zero"), AssertionError("unreachable"), IndexError("list index"),
        RuntimeError("dictionary changed size"), NotImplementedError("later"), Exception("odd")]


def _failing(monkeypatch, error):
    """``drumstroke simulate`` made to raise ``error`` when it runs (the command is a thin wrapper: any
    exception its library calls raise reaches main the same way)."""
    from drumstroke.cli import simulate

    def run(args):
        raise error

    monkeypatch.setattr(simulate, "_simulate", run)
    return ["simulate", "free-bounce"]


def test_simulate_runs_through_the_patched_function(monkeypatch, capsys):
    # the hook the tests below use is the command's real one
    argv = _failing(monkeypatch, ParameterError("hooked"))
    assert cli.main(argv) == 2
    assert capsys.readouterr().err == "drumstroke simulate: error: hooked\n"


@pytest.mark.parametrize("error", INPUT_ERRORS, ids=lambda e: type(e).__name__ + str(getattr(e, "errno", "") or ""))
def test_an_input_error_is_one_line_and_exit_2(error, monkeypatch, capsys, tmp_path):
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    assert cli.main(_failing(monkeypatch, error)) == 2
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("drumstroke simulate: error: "), captured.err
    assert "Traceback" not in captured.err and "internal error" not in captured.err
    if getattr(error, "filename", None):
        assert repr(error.filename) in lines[0] and error.strerror in lines[0]
    assert list(tmp_path.iterdir()) == []  # no log: it is not a bug


@pytest.mark.parametrize("error", BUGS, ids=lambda e: type(e).__name__)
def test_an_unexpected_error_says_where_to_report_it_and_exits_1(error, monkeypatch, capsys, tmp_path):
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    assert cli.main(_failing(monkeypatch, error)) == 1
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1 and "Traceback" not in captured.err, captured.err
    assert lines[0].startswith(f"drumstroke simulate: internal error: {type(error).__name__}")
    assert "this is a bug in drumstroke" in lines[0] and cli.REPORT in lines[0]
    (log,) = tmp_path.glob("drumstroke-*.log")
    assert str(log) in lines[0]
    text = log.read_text()
    assert "Traceback (most recent call last)" in text and f"{type(error).__name__}" in text and "in run" in text


def test_debug_prints_the_traceback_too(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    assert cli.main(["--debug", *_failing(monkeypatch, ParameterError("t_end must be positive"))]) == 2
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err and err.endswith("drumstroke simulate: error: t_end must be "
                                                                       "positive\n")


def test_an_interrupt_is_one_line_and_exit_130(monkeypatch, capsys):
    assert cli.main(_failing(monkeypatch, KeyboardInterrupt())) == 130
    assert capsys.readouterr().err == "drumstroke simulate: interrupted\n"


def test_a_bug_in_a_real_process_of_the_console_script(tmp_path):
    """The console script in a subprocess, a fault injected into its command by a sitecustomize module."""
    (tmp_path / "inject").mkdir()
    (tmp_path / "inject" / "sitecustomize.py").write_text(textwrap.dedent("""
        import drumstroke.cli.simulate as simulate
        def run(args):
            return {}["missing"]
        simulate._simulate = run
    """))
    source = str(Path(drumstroke.__file__).resolve().parent.parent)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join((str(tmp_path / "inject"), source)), "TMPDIR": str(tmp_path)}
    done = subprocess.run([*robustness.console_script(), "simulate", "free-bounce"], capture_output=True, text=True,
                          timeout=60, env=env, check=False)
    assert done.returncode == 1 and len(done.stderr.splitlines()) == 1, done.stderr
    assert "internal error: KeyError" in done.stderr and cli.REPORT in done.stderr
    assert "Traceback" not in done.stderr
    (log,) = tmp_path.glob("drumstroke-*.log")
    assert str(log) in done.stderr and "KeyError: 'missing'" in log.read_text()


def test_a_real_input_error_in_a_real_process_is_one_line(tmp_path):
    recipe = tmp_path / "r.toml"
    recipe.write_text(f"t_end = {'9' * 400}\n[force]\nkind = \"constant\"\nvalue = 1.0\n")
    status, stderr, _ = robustness.run_command(["simulate", str(recipe)])
    assert status == 2 and stderr.count("\n") == 1 and str(recipe) in stderr and "t_end" in stderr, stderr
    assert "Traceback" not in stderr and "OverflowError" not in stderr
