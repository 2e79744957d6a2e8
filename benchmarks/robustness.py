"""The fuzz and fault campaign, at scale: ``python benchmarks/robustness.py [--recipes N]``.

Two parts, defined here once and run by ``tests/test_robustness.py`` at the suite's scale:

- **Random valid recipes** (hypothesis, derandomized): both models; every profile kind for a(t)
  and g(t) — constant, piecewise-linear, pulses, samples (a CSV file written for the recipe and
  read through the recipe's reader) and sums of them, nested; values up to 10⁶ m/s² of either
  sign; breakpoints and samples 1 ns apart; c from 0 to 1 (both ends); θ₀ on the head, at 0 or up
  to 1.5 rad; ω₀ up to ±1000 rad/s; t_end from 1 µs to 2 s. Each recipe is simulated and sampled
  at 1 kHz: it must give finite impacts in time order, finite samples, none below the head or past
  the vertical, or be refused by the model with a SimulationError saying why (the stick driven
  past the vertical, or more impacts than the solver's limit). Anything else is a crash.
- **Hostile inputs** (:data:`HOSTILE`): every command and file reader given what a hostile user
  would give it — integers of 400 and 5,000 digits, deep nesting, ``/dev/zero``, a FIFO, a
  directory, a socket, a non-UTF-8 file, an empty file, a file over its size limit, a truncated
  MIDI file, a MIDI tempo of 0, NaN and infinities in every numeric option, negative durations, c
  outside [0, 1], non-increasing breakpoints, corrupt CSVs and more. Each must end in one line on
  stderr naming the parameter or the path, exit status 2, no traceback, within 10 s.

This script runs :data:`RECIPES` recipes and every hostile input through the installed
``drumstroke`` command in a subprocess, prints the counts and the worst times, and writes them to
``benchmarks/robustness_results.json``.
"""

import argparse
import contextlib
import datetime
import io
import json
import math
import os
import platform
import re
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from dataclasses import dataclass
from datetime import timedelta
from pathlib import Path

import numpy as np
from _timing import median_time
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

import drumstroke
from drumstroke.formats.library import MANIFEST
from drumstroke.profiles import ACCELERATION_LIMIT, MIN_SPACING

HERE = Path(__file__).resolve().parent

RECIPES = 100_000
"""Random recipes the script draws from the seeded generator (the suite runs 10,000)."""

HYPOTHESIS = 10_000
"""Random recipes the script draws with hypothesis (its edge values and shrinking; some 10 ms each)."""

BELOW = "a sample below the head or past the vertical"
"""The broken invariant counted as samples below the head."""

RATE = 1000.0
"""Hz: every stroke is sampled at the robot's control rate."""

DEADLINE = 5.0
"""s: the longest a recipe may take, simulated and sampled, before it counts as a hang."""

TIMEOUT = 10.0
"""s: the longest a hostile input may take to be refused."""

LOSSLESS = 0.999
"""Random recipes with c above this have constant forcing. A nearly lossless stick that forcing varying in time
sets micro-bouncing (µrad/s under 10³ m/s² and more) bounces at up to 10¹¹ Hz, and the solver steps through
millions of bounces (some 20 s) before its impact limit refuses the recipe; under constant forcing it takes
closed-form flights, some 100 ns each."""

THETA_MAX = drumstroke.Stick().theta_max

FUZZ = settings(
    max_examples=10_000,
    deadline=timedelta(seconds=DEADLINE),
    derandomize=True,
    database=None,
    phases=(Phase.explicit, Phase.generate, Phase.shrink),
    report_multiple_bugs=False,
    suppress_health_check=list(HealthCheck),
)
"""The campaign's hypothesis settings: 10,000 recipes, the same every run, a deadline per recipe."""


# -- random valid recipes -----------------------------------------------------------------------------------------


def reals(low, high):
    return st.floats(low, high, allow_nan=False, allow_infinity=False, allow_subnormal=False)


def levels(high=ACCELERATION_LIMIT):
    """m/s² of either sign up to ``high``: 0, any value, or a magnitude spread over nine decades."""
    spread = st.builds(lambda sign, exponent: sign * 10.0**exponent, st.sampled_from((1.0, -1.0)),
                       reals(-3.0, math.log10(high)))
    return st.one_of(st.just(0.0), reals(-high, high), spread)


def _after(t):
    """The first float at least 1 ns after ``t``: two breakpoints as close as a profile allows."""
    later = t + MIN_SPACING
    while later - t < MIN_SPACING:
        later = math.nextafter(later, math.inf)
    return later


@st.composite
def points(draw, values, t_end):
    """[t, value] pairs: times in [0, 1.2 t_end], increasing, at least 1 ns apart, some exactly 1 ns apart."""
    times = sorted(draw(st.lists(reals(0.0, 1.2 * t_end), min_size=1, max_size=6)))
    if draw(st.booleans()):  # a step 1 ns wide
        i = draw(st.integers(0, len(times) - 1))
        times.insert(i + 1, _after(times[i]))
    spaced = times[:1]
    for t in times[1:]:
        if t - spaced[-1] >= MIN_SPACING:
            spaced.append(t)
    return [[t, draw(values)] for t in spaced]


@dataclass(frozen=True)
class Rows:
    """A samples profile's rows, written to a CSV file when the recipe is run (:func:`materialize`)."""

    points: list


def profiles(values, t_end):
    """Profile tables of every kind (sums nested), as a recipe file holds them."""
    constant = st.builds(lambda v: {"kind": "constant", "value": v}, values)
    linear = st.builds(lambda p: {"kind": "piecewise-linear", "points": p}, points(values, t_end))
    samples = st.builds(lambda p: {"kind": "samples", "file": Rows(p)}, points(values, t_end))
    pulses = st.builds(_pulses, values, reals(1e-3, 1.0), reals(0.0, 1.0).filter(lambda d: 0.0 < d < 1.0),
                       st.one_of(st.just(0.0), reals(0.0, 1.0)), values)
    return st.recursive(st.one_of(constant, linear, pulses, samples),
                        lambda parts: st.lists(parts, min_size=1, max_size=3).map(
                            lambda p: {"kind": "sum", "parts": p}), max_leaves=5)


def _pulses(amplitude, period, duty, phase, base):
    if abs(amplitude + base) > ACCELERATION_LIMIT:
        base = 0.0
    return {"kind": "pulses", "amplitude": amplitude, "period": period, "duty": duty, "phase": phase, "base": base}


@st.composite
def recipe_tables(draw):
    """A valid recipe as the table of a recipe file (its samples as :class:`Rows`).

    Nearly lossless strokes (c > :data:`LOSSLESS`) are drawn under constant forcing only (see there).
    """
    t_end = draw(st.one_of(reals(1e-6, 1e-3), reals(1e-3, 0.5), reals(0.5, 2.0)))
    cor = draw(st.one_of(st.just(0.0), st.just(1.0), reals(0.0, 1.0)))
    kinds = st.builds(lambda v: {"kind": "constant", "value": v}, levels()) if cor > LOSSLESS else profiles(
        levels(), t_end)
    gravity = draw(st.one_of(st.just({"kind": "constant", "value": 9.8}), kinds))
    return {
        "model": draw(st.sampled_from(drumstroke.MODELS)),
        "t_end": t_end,
        "theta0": draw(st.one_of(st.just(THETA_MAX), st.just(0.0), reals(THETA_MAX, 1.5))),
        "omega0": draw(st.one_of(st.just(0.0), reals(-30.0, 30.0), reals(-1000.0, 1000.0))),
        "cor": cor,
        "force": draw(kinds),
        "gravity": gravity,
    }


class Seeded:
    """Random valid recipe tables from a seeded generator, drawn as :func:`recipe_tables` draws them.

    The same kinds, ranges and edges (0, ±10⁶ m/s², c = 0 and 1, θ₀ on the head, steps 1 ns wide),
    some 100 times faster to draw than hypothesis's: the suite runs its 10,000 recipes this way.
    """

    def __init__(self, seed):
        self.rng = np.random.default_rng(seed)

    def pick(self, *choices):
        return choices[self.rng.integers(len(choices))]

    def uniform(self, low, high):
        return float(self.rng.uniform(low, high))

    def level(self, high=ACCELERATION_LIMIT):
        kind = self.rng.integers(5)
        if kind == 0:
            return 0.0
        if kind == 1:
            return self.pick(high, -high)
        if kind == 2:
            return self.uniform(-high, high)
        return self.pick(1.0, -1.0) * 10.0 ** self.uniform(-3.0, math.log10(high))

    def points(self, t_end):
        times = sorted(self.uniform(0.0, 1.2 * t_end) for _ in range(self.rng.integers(1, 7)))
        if self.rng.random() < 0.5:
            i = int(self.rng.integers(len(times)))
            times.insert(i + 1, _after(times[i]))
        spaced = times[:1]
        for t in times[1:]:
            if t - spaced[-1] >= MIN_SPACING:
                spaced.append(t)
        return [[t, self.level()] for t in spaced]

    def profile(self, t_end, leaves=5):
        """A profile table of any kind; a sum's parts share at most ``leaves`` leaves, as hypothesis's do."""
        kind = self.rng.integers(5) if leaves > 1 else self.rng.integers(4)
        if kind == 0:
            return {"kind": "constant", "value": self.level()}
        if kind == 1:
            return {"kind": "piecewise-linear", "points": self.points(t_end)}
        if kind == 2:
            return {"kind": "samples", "file": Rows(self.points(t_end))}
        if kind == 3:
            duty = self.uniform(1e-3, 1.0 - 1e-3)
            return _pulses(self.level(), self.uniform(1e-3, 1.0), duty, self.pick(0.0, self.uniform(0.0, 1.0)),
                           self.level())
        parts = []
        for _ in range(self.rng.integers(1, 4)):
            if leaves <= len(parts):
                break
            parts.append(self.profile(t_end, leaves=max(1, (leaves - len(parts)) // 2)))
        return {"kind": "sum", "parts": parts}

    def table(self):
        t_end = self.pick(self.uniform(1e-6, 1e-3), self.uniform(1e-3, 0.5), self.uniform(0.5, 2.0))
        cor = self.pick(0.0, 1.0, self.uniform(0.0, 1.0), self.uniform(0.0, 1.0))
        def kinds():
            return {"kind": "constant", "value": self.level()} if cor > LOSSLESS else self.profile(t_end)
        return {
            "model": self.pick(*drumstroke.MODELS),
            "t_end": t_end,
            "theta0": self.pick(THETA_MAX, 0.0, self.uniform(THETA_MAX, 1.5)),
            "omega0": self.pick(0.0, self.uniform(-30.0, 30.0), self.uniform(-1000.0, 1000.0)),
            "cor": cor,
            "force": kinds(),
            "gravity": self.pick({"kind": "constant", "value": 9.8}, kinds()),
        }


def materialize(table, folder):
    """The table with each samples profile's rows written to a CSV file in ``folder`` (named by its place)."""
    def place(value, name):
        if isinstance(value, Rows):
            path = folder / f"{name}.csv"
            path.write_text("t,value\n" + "".join(f"{t!r},{v!r}\n" for t, v in value.points))
            return path.name
        if isinstance(value, dict):
            return {key: place(item, f"{name}.{key}") for key, item in value.items()}
        if isinstance(value, list):
            return [place(item, f"{name}{i}") for i, item in enumerate(value)]
        return value

    return place(table, "samples")


def run_recipe(table, folder):
    """Simulate a recipe table and sample it at 1 kHz: ``("simulated" or "refused", broken invariants)``.

    A SimulationError saying the stick passed the vertical or the impact limit is a refusal;
    any other exception propagates (a crash).
    """
    recipe = drumstroke.Recipe.from_dict(materialize(table, folder), base_dir=folder)
    try:
        stroke = drumstroke.simulate(recipe)
    except drumstroke.SimulationError as error:
        if "vertical" in str(error) or "impacts" in str(error):
            return "refused", []
        raise
    t, theta, omega = stroke.sample(RATE)
    impacts, broken = stroke.impacts, []
    if not (np.isfinite(theta).all() and np.isfinite(omega).all() and np.isfinite(impacts.t).all()
            and np.isfinite(impacts.omega).all() and np.isfinite(stroke.rests).all()):
        broken.append("NaN")
    if np.any(theta < recipe.theta_max) or np.any(theta >= math.pi / 2):
        broken.append(BELOW)
    if np.any(np.diff(impacts.t) < 0) or np.any(impacts.t < 0) or np.any(impacts.t > recipe.t_end):
        broken.append("impacts out of time order")
    if len(t) != math.floor(recipe.t_end * RATE + 1e-9) + 1:
        broken.append("samples off the control rate")
    return "simulated", broken


# -- hostile inputs -----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Hostile:
    """One hostile input: what it attacks, and how to make it in a folder.

    ``make(folder)`` writes its files there and returns the command's arguments and the texts the
    one-line error must contain (the parameter or the path).
    """

    id: str
    make: object
    blocking: bool = False  # a FIFO or a device: could hang a reader that opened it
    limits: tuple = ()  # (resource, value) pairs the command runs under: a file size limit ("File too large")

    @property
    def own_process(self):
        """Whether it must run in a process of its own (it could block its reader, or needs resource limits)."""
        return self.blocking or bool(self.limits)


RECIPE = '[force]\nkind = "constant"\nvalue = 100.0\n'
PATTERN = "tempo 120\n0 auto 100\n"
DIGITS_400, DIGITS_5000 = "9" * 400, "9" * 5000


def _write(path, content):
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    return path


def _sparse(path, size):
    """A file of ``size`` bytes that takes no room on disk (zeros)."""
    with open(path, "wb") as handle:
        handle.truncate(size)
    return path


def _midi(path, *, tempo=500_000, notes=((0, 38, 100),), resolution=480, cut=None):
    """A type-1 MIDI file: a tempo, then notes (tick, key, velocity) on channel 10, each 10 ticks long."""
    import mido

    file = mido.MidiFile(type=1, ticks_per_beat=resolution)
    track = mido.MidiTrack([mido.MetaMessage("set_tempo", tempo=tempo)])
    now = 0
    for tick, key, velocity in notes:
        track.append(mido.Message("note_on", channel=9, note=key, velocity=velocity, time=tick - now))
        track.append(mido.Message("note_off", channel=9, note=key, velocity=0, time=10))
        now = tick + 10
    file.tracks.append(track)
    buffer = io.BytesIO()
    file.save(file=buffer)
    return _write(path, buffer.getvalue()[:cut])


def _nested_sum(depth):
    table = '{kind = "constant", value = 1.0}'
    for _ in range(depth):
        table = '{kind = "sum", parts = [' + table + "]}"
    return f"force = {table}\n"


def _kinds(reader, name, argv, *, limit, text=True, empty=("{path}",)):
    """The same reader given a FIFO, /dev/zero, a directory, a socket, a file over its size limit, an empty file (its
    error names ``empty``; None: an empty file is valid) and non-UTF-8 bytes (``text``): ``argv(path, folder)`` runs
    the reader on ``path`` (a file named ``name``)."""
    def case(kind, make, blocking=False, needles=("{path}",)):
        def made(folder):
            path = make(folder / name)
            return argv(path, folder), [n.format(path=path) for n in needles]
        return Hostile(f"{reader}/{kind}", made, blocking)

    cases = [
        case("fifo", lambda p: (os.mkfifo(p), p)[1], True),
        case("dev-zero", lambda p: (os.symlink("/dev/zero", p), p)[1], True),
        case("directory", lambda p: (p.mkdir(), p)[1]),
        case("socket", _socket, True),
        case("over-size-limit", lambda p: _sparse(p, limit + 1)),
    ]
    if empty:
        cases.append(case("empty", lambda p: _write(p, b""), needles=empty))
    if text:
        cases.append(case("not-utf8", lambda p: _write(p, b"# caf\xe9 \xff\xfe\n" + bytes(range(256)))))
    return cases


def _socket(path):
    """A Unix socket's file at ``path`` (it stays when the socket is closed)."""
    with socket.socket(socket.AF_UNIX) as server:
        server.bind(str(path))
    return path


def _recipe(text, *needles, name="r.toml", extra=()):
    def made(folder):
        path = _write(folder / name, text)
        return ["simulate", str(path), *extra], [n.format(path=path, folder=folder) for n in needles]
    return made


def _option(*argv_and_needles):
    """A command line (``{folder}`` filled in) whose error must name the last items (after '|')."""
    split = argv_and_needles.index("|")

    def made(folder):
        argv = [a.format(folder=folder) for a in argv_and_needles[:split]]
        return argv, [n.format(folder=folder) for n in argv_and_needles[split + 1:]]
    return made


def _with_files(files, argv, *needles):
    """Write ``files`` ({name: content or a callable(path)}) in the folder, then run ``argv`` ({folder} filled)."""
    def made(folder):
        for name, content in files.items():
            content(folder / name) if callable(content) else _write(folder / name, content)
        return [a.format(folder=folder) for a in argv], [n.format(folder=folder) for n in needles]
    return made


def _samples_recipe(path, folder):
    recipe = _write(folder / "with-samples.toml", f'[force]\nkind = "samples"\nfile = "{path.name}"\n')
    return ["simulate", str(recipe)]


def _library_list(path, folder):
    return ["library", "list", str(folder)]


def _hostile():
    from drumstroke.formats import json as json_format
    from drumstroke.formats import midi, pattern, responses_csv, signal_csv, toml, trajectory_csv

    cases = []
    # every file reader given what is not a file of its kind
    cases += _kinds("recipe", "r.toml", lambda p, f: ["simulate", str(p)], limit=toml.MAX_BYTES, empty=("[force]",))
    cases += _kinds("samples", "thumb.csv", _samples_recipe, limit=signal_csv.MAX_BYTES)
    cases += _kinds("pattern", "p.pattern", lambda p, f: ["compose", str(p)], limit=pattern.MAX_BYTES)
    cases += _kinds("midi", "s.mid", lambda p, f: ["compose", str(p)], limit=midi.MAX_BYTES, text=False)
    cases += _kinds("mapping", "m.toml",
                    lambda p, f: ["compose", str(_midi(f / "s.mid")), "--mapping", str(p)], limit=toml.MAX_BYTES)
    cases += _kinds("robot-config", "robot.toml", lambda p, f: ["robot", "track", "single", "--config", str(p)],
                    limit=toml.MAX_BYTES, empty=None)  # an empty config is every default
    cases += _kinds("trajectory", "t.csv", lambda p, f: ["robot", "validate", str(p)],
                    limit=trajectory_csv.MAX_BYTES)
    cases += _kinds("responses", "answers.csv", lambda p, f: ["stats", str(p)], limit=responses_csv.MAX_BYTES)
    cases += _kinds("palette", "palette.toml", lambda p, f: ["library", "build", str(f / "lib"), "--palette", str(p)],
                    limit=toml.MAX_BYTES)
    cases += _kinds("sweep-grid", "grid.toml", lambda p, f: ["sweep", str(p), "--out", str(f / "out.csv")],
                    limit=toml.MAX_BYTES, empty=("[parameters]",))
    cases += _kinds("library-manifest", MANIFEST, _library_list, limit=json_format.MAX_BYTES)
    cases += _kinds("listening-config", "test.toml",
                    lambda p, f: ["listen", "serve", str(p), "--db", str(f / "answers.db"), "--port", "8999"],
                    limit=toml.MAX_BYTES, empty=("config",))

    # numbers: too many digits, NaN, infinities, out of range, in files
    cases += [
        Hostile("recipe/t_end-400-digits", _recipe(f"t_end = {DIGITS_400}\n{RECIPE}", "t_end", "{path}")),
        Hostile("recipe/t_end-5000-digits", _recipe(f"t_end = {DIGITS_5000}\n{RECIPE}", "t_end", "{path}")),
        Hostile("recipe/force-400-digits",
                _recipe(f'[force]\nkind = "constant"\nvalue = {DIGITS_400}\n', "force.value", "{path}")),
        Hostile("recipe/force-5000-digits",
                _recipe(f'[force]\nkind = "constant"\nvalue = -{DIGITS_5000}\n', "value", "{path}")),
        Hostile("recipe/breakpoint-400-digits",
                _recipe(f'[force]\nkind = "piecewise-linear"\npoints = [[0, 1], [{DIGITS_400}, 2]]\n', "force.points")),
        Hostile("recipe/t_end-nan", _recipe(f"t_end = nan\n{RECIPE}", "t_end", "nan")),
        Hostile("recipe/t_end-inf", _recipe(f"t_end = inf\n{RECIPE}", "t_end", "inf")),
        Hostile("recipe/t_end-negative", _recipe(f"t_end = -1.0\n{RECIPE}", "t_end", "-1.0")),
        Hostile("recipe/t_end-zero", _recipe(f"t_end = 0\n{RECIPE}", "t_end")),
        Hostile("recipe/t_end-text", _recipe(f't_end = "5 s"\n{RECIPE}', "t_end", "'5 s'")),
        Hostile("recipe/cor-above-1", _recipe(f"cor = 1.5\n{RECIPE}", "cor", "1.5", "[0, 1]")),
        Hostile("recipe/cor-negative", _recipe(f"cor = -0.1\n{RECIPE}", "cor", "-0.1", "[0, 1]")),
        Hostile("recipe/theta0-inf", _recipe(f"theta0 = -inf\n{RECIPE}", "theta0", "-inf")),
        Hostile("recipe/omega0-huge", _recipe(f"omega0 = 1e300\n{RECIPE}", "omega0", "1e+300")),
        Hostile("recipe/force-beyond-1e6", _recipe('[force]\nkind = "constant"\nvalue = 2e6\n', "force.value")),
        Hostile("recipe/pulses-period-0",
                _recipe('[force]\nkind = "pulses"\namplitude = 100.0\nperiod = 0.0\nduty = 0.5\n', "force.period")),
        Hostile("recipe/pulses-duty-1",
                _recipe('[force]\nkind = "pulses"\namplitude = 100.0\nperiod = 0.1\nduty = 1.0\n', "force.duty")),
        Hostile("recipe/breakpoints-decreasing",
                _recipe('[force]\nkind = "piecewise-linear"\npoints = [[0.0, 1.0], [1.0, 2.0], [0.5, 3.0]]\n',
                        "force.points", "strictly increasing")),
        Hostile("recipe/breakpoints-repeated",
                _recipe('[force]\nkind = "piecewise-linear"\npoints = [[0.5, 1.0], [0.5, 2.0]]\n', "force.points")),
        Hostile("recipe/breakpoints-closer-than-1ns",
                _recipe('[force]\nkind = "piecewise-linear"\npoints = [[0.5, 1.0], [0.5000000000001, 2.0]]\n',
                        "force.points", "1e-09")),
        Hostile("recipe/unknown-kind", _recipe('[force]\nkind = "ramp"\nvalue = 1.0\n', "force.kind", "'ramp'")),
        Hostile("recipe/unknown-key", _recipe(f"speed = 3\n{RECIPE}", "recipe", "'speed'")),
        Hostile("recipe/no-force", _recipe("t_end = 1.0\n", "[force]")),
        Hostile("recipe/not-toml", _recipe("t_end = = 1\n", "{path}", "not valid TOML")),
        Hostile("recipe/sum-nested-250", _recipe(_nested_sum(250), "{path}", "nest")),
        Hostile("recipe/sum-nested-20", _recipe(_nested_sum(20), "force", "16")),
        Hostile("recipe/array-nested-100000", _recipe("a = " + "[" * 100_000 + "]" * 100_000 + "\n", "{path}", "nest")),
        Hostile("recipe/table-nested-100", _recipe("".join(f"[{'.'.join(['t'] * k)}]\n" for k in range(1, 101)),
                                                   "{path}", "nest")),
        Hostile("recipe/samples-missing",
                _recipe('[force]\nkind = "samples"\nfile = "none.csv"\n', "{folder}/none.csv", "No such file")),
        Hostile("recipe/samples-absolute-dev-zero",
                _recipe('[force]\nkind = "samples"\nfile = "/dev/zero"\n', "/dev/zero", "character device")),
        Hostile("recipe/model-unknown", _recipe(f'model = "newton"\n{RECIPE}', "model", "'newton'")),
        Hostile("recipe/stick-negative-length",
                _recipe(f"{RECIPE}[stick]\nlength = -0.39\n", "length", "-0.39")),
    ]

    def samples(text, *needles):
        def made(folder):
            _write(folder / "thumb.csv", text)
            return _samples_recipe(folder / "thumb.csv", folder), [n.format(folder=folder) for n in needles]
        return made

    cases += [
        Hostile("samples/text-in-numbers", samples("t,value\n0,1\n0.1,lots\n", "{folder}/thumb.csv", "line 3")),
        Hostile("samples/times-decreasing", samples("0,1\n0.2,2\n0.1,3\n", "{folder}/thumb.csv", "increasing")),
        Hostile("samples/nan", samples("0,1\n0.1,nan\n", "{folder}/thumb.csv", "nan")),
        Hostile("samples/value-1e400", samples("0,1\n0.1,1e400\n", "{folder}/thumb.csv", "inf")),
        Hostile("samples/value-400-digits", samples(f"0,1\n0.1,{DIGITS_400}\n", "{folder}/thumb.csv")),
        Hostile("samples/three-columns", samples("0,1,2\n", "{folder}/thumb.csv", "line 1")),
        Hostile("samples/header-only", samples("t,value\n", "{folder}/thumb.csv", "no 't,value' rows")),
        Hostile("samples/unclosed-quote", samples('0,"1\n0.1,2\n', "{folder}/thumb.csv")),
    ]

    def score(text, *needles, name="p.pattern"):
        def made(folder):
            path = _write(folder / name, text)
            return ["compose", str(path)], [n.format(path=path) for n in needles]
        return made

    cases += [
        Hostile("pattern/tempo-0", score("tempo 0\n0 auto 100\n", "{path}", "tempo")),
        Hostile("pattern/tempo-nan", score("tempo nan\n0 auto 100\n", "{path}", "tempo")),
        Hostile("pattern/tempo-5000-digits", score(f"tempo {DIGITS_5000}\n0 auto 100\n", "{path}", "tempo")),
        Hostile("pattern/velocity-5000-digits", score(f"tempo 120\n0 auto {DIGITS_5000}\n", "{path}", "velocity")),
        Hostile("pattern/beat-negative", score("tempo 120\n-1 auto 100\n", "{path}", "beat")),
        Hostile("pattern/beat-inf", score("tempo 120\ninf auto 100\n", "{path}", "beat")),
        Hostile("pattern/buzz-length-negative", score("tempo 120\n0 buzz 100 right -1\n", "{path}", "buzz length")),
        Hostile("pattern/no-tempo", score("0 auto 100\n", "{path}", "tempo")),
        Hostile("midi/tempo-0", lambda f: (["compose", str(_midi(f / "s.mid", tempo=0))], [str(f / "s.mid"), "tempo"])),
        Hostile("midi/tempo-1us", lambda f: (["compose", str(_midi(f / "s.mid", tempo=1))], [str(f / "s.mid"), "tempo"])),
        Hostile("midi/truncated",
                lambda f: (["compose", str(_midi(f / "s.mid", notes=[(i * 120, 38, 90) for i in range(50)], cut=200))],
                           [str(f / "s.mid"), "truncated"])),
        Hostile("midi/not-midi", score("tempo 120\n0 auto 100\n", "{path}", name="s.mid")),
        Hostile("midi/random-bytes", lambda f: (["compose", str(_write(f / "s.mid", bytes(range(256)) * 8))],
                                                [str(f / "s.mid")])),
        Hostile("mapping/key-400-digits", _with_files(
            {"s.mid": _midi, "m.toml": f'[notes]\n{DIGITS_400} = "single"\n'},
            ["compose", "{folder}/s.mid", "--mapping", "{folder}/m.toml"], "mapping notes", "400 characters")),
        Hostile("mapping/value-400-digits", _with_files(
            {"s.mid": _midi, "m.toml": f"[notes]\n38 = {DIGITS_400}\n"},
            ["compose", "{folder}/s.mid", "--mapping", "{folder}/m.toml"], "{folder}/m.toml", "notes.38")),
        Hostile("robot-config/gain-5000-digits", _with_files(
            {"robot.toml": f"[controller.pi]\nkp = {DIGITS_5000}\n"},
            ["robot", "track", "single", "--config", "{folder}/robot.toml"], "{folder}/robot.toml", "kp")),
        Hostile("robot-config/gain-400-digits", _with_files(
            {"robot.toml": f"[controller.pi]\nkp = {DIGITS_400}\n"},
            ["robot", "track", "single", "--config", "{folder}/robot.toml"], "controller.pi.kp")),
        Hostile("robot-config/limit-nan", _with_files(
            {"robot.toml": "[limits]\nmax_speed = nan\n"},
            ["robot", "track", "single", "--config", "{folder}/robot.toml"], "max_speed", "nan")),
        Hostile("trajectory/nan-row", _with_files(
            {"t.csv": "t,theta,omega\n0,0,0\n0.001,nan,0\n"}, ["robot", "validate", "{folder}/t.csv"],
            "{folder}/t.csv", "not finite")),
        Hostile("trajectory/header-only", _with_files(
            {"t.csv": "t,theta,omega\n"}, ["robot", "validate", "{folder}/t.csv"], "{folder}/t.csv")),
        Hostile("trajectory/text-row", _with_files(
            {"t.csv": "t,theta,omega\n0,0,0\n0.001,x,0\n"}, ["robot", "export", "{folder}/t.csv", "--format", "csv",
                                                            "--out", "{folder}/o.csv"], "{folder}/t.csv")),
        Hostile("trajectory/ragged", _with_files(
            {"t.csv": "t,theta,omega\n0,0,0\n0.001,0\n"}, ["robot", "validate", "{folder}/t.csv"], "{folder}/t.csv")),
        Hostile("responses/wrong-header", _with_files(
            {"answers.csv": "who,what\ns1,p1\n"}, ["stats", "{folder}/answers.csv"], "{folder}/answers.csv", "header")),
        Hostile("responses/confidence-5000-digits", _with_files(
            {"answers.csv": f"subject,pair,robot,answer,confidence,similarity\ns1,p1,A,B,{DIGITS_5000},3\n"},
            ["stats", "{folder}/answers.csv"], "{folder}/answers.csv")),
        Hostile("palette/t_end-5000-digits", _with_files(
            {"palette.toml": f'[[stroke]]\nname = "x"\nt_end = {DIGITS_5000}\n'},
            ["library", "build", "{folder}/lib", "--palette", "{folder}/palette.toml"], "{folder}/palette.toml")),
        Hostile("sweep-grid/num-400-digits", _with_files(
            {"grid.toml": f'base = "constant"\n[parameters]\ncor = {{ start = 0.5, stop = 0.9, num = {DIGITS_400} }}\n'},
            ["sweep", "{folder}/grid.toml", "--out", "{folder}/o.csv"], "{folder}/grid.toml")),
        Hostile("library-manifest/rate-400-digits", _with_files(
            {MANIFEST: f'{{"rate": {DIGITS_400}}}'}, ["library", "list", "{folder}"], f"{{folder}}/{MANIFEST}", "rate")),
        Hostile("library-manifest/rate-5000-digits", _with_files(
            {MANIFEST: f'{{"rate": {DIGITS_5000}}}'}, ["library", "list", "{folder}"], f"{{folder}}/{MANIFEST}",
            "rate")),
        Hostile("library-manifest/array-nested-100000", _with_files(
            {MANIFEST: "[" * 100_000 + "]" * 100_000}, ["library", "list", "{folder}"], f"{{folder}}/{MANIFEST}",
            "nest")),
        Hostile("library-manifest/not-json", _with_files(
            {MANIFEST: "{rate: 1000"}, ["library", "list", "{folder}"], f"{{folder}}/{MANIFEST}")),
        Hostile("listening-config/seed-400-digits", _with_files(
            {"test.toml": f'admin_token = "a-long-enough-token"\nseed = {DIGITS_400}\n'},
            ["listen", "serve", "{folder}/test.toml", "--db", "{folder}/a.db", "--port", "8999"], "{folder}/test.toml")),
        Hostile("listen-analyze/not-a-database", _with_files(
            {"answers.db": "this is not a database\n" * 100}, ["listen", "analyze", "--db", "{folder}/answers.db"],
            "{folder}/answers.db")),
        Hostile("listen-analyze/fifo", _with_files(
            {"answers.db": os.mkfifo}, ["listen", "analyze", "--db", "{folder}/answers.db"], "{folder}/answers.db"),
            blocking=True),
        Hostile("listen-serve/port-99999", _with_files(
            {"test.toml": ""}, ["listen", "serve", "{folder}/test.toml", "--db", "{folder}/a.db", "--port", "99999"],
            "--port", "99999")),
    ]

    # every numeric option: NaN, infinities, too many digits, out of range, negative durations
    simulate = ["simulate", "free-bounce"]
    cases += [Hostile(f"simulate/{option}-{value}", _option(*simulate, option, value, "|", option))
              for option in ("--rate", "--stretch", "--compress") for value in ("nan", "inf", "-inf")]
    cases += [
        Hostile("simulate/--rate-5000-digits", _option(*simulate, "--rate", DIGITS_5000, "|", "--rate")),
        Hostile("simulate/--catch-5000-digits", _option(*simulate, "--catch", DIGITS_5000, "|", "--catch")),
        Hostile("simulate/--catch-0", _option(*simulate, "--catch", "0", "|", "--catch")),
        Hostile("simulate/--trim-nan", _option(*simulate, "--trim", "nan:1", "|", "--trim", "nan:1")),
        Hostile("simulate/--trim-negative-duration", _option(*simulate, "--trim", "2:1", "|", "--trim", "2:1")),
        Hostile("simulate/--trim-inf", _option(*simulate, "--trim", "0:inf", "|", "--trim")),
        Hostile("simulate/--library-fifo", _with_files({"lib": os.mkfifo}, [*simulate, "--library", "{folder}/lib"],
                                                       "--library", "{folder}/lib"), blocking=True),
        Hostile("compose/--rate-nan", _with_files({"p.pattern": PATTERN}, ["compose", "{folder}/p.pattern", "--rate",
                                                                          "nan"], "--rate")),
        Hostile("compose/--channel-5000-digits", _with_files(
            {"s.mid": _midi}, ["compose", "{folder}/s.mid", "--channel", DIGITS_5000], "--channel")),
        Hostile("library-build/--rate-inf", _option("library", "build", "{folder}/lib", "--rate", "inf", "|",
                                                    "--rate")),
        Hostile("design/--times-nan", _option("design", "--times", "nan,0.1", "--velocities", "90,90", "|", "times")),
        Hostile("design/--times-decreasing",
                _option("design", "--times", "0.2,0.1", "--velocities", "90,90", "|", "times")),
        Hostile("design/--velocities-inf",
                _option("design", "--times", "0.1,0.2", "--velocities", "inf,90", "|", "velocit")),
        Hostile("design/--levels-nan", _option("design", "--times", "0.1,0.2", "--levels", "nan,-6", "|", "level")),
        Hostile("design/--buzz-negative-duration", _option("design", "--buzz", "1:0", "|", "buzz")),
        Hostile("design/--buzz-nan", _option("design", "--buzz", "0:nan", "|", "buzz")),
        Hostile("design/--cor-1", _option("design", "--buzz", "0:0.5", "--cor", "1", "|", "--cor")),
        Hostile("design/--force-max-inf", _option("design", "--buzz", "0:0.5", "--force-max", "inf", "|",
                                                  "--force-max")),
        Hostile("design/--density-nan", _option("design", "--buzz", "0:0.5", "--density", "nan", "|", "--density")),
        Hostile("rudiment/--tempo-nan", _option("rudiment", "single-stroke-roll", "--tempo", "nan", "|", "--tempo")),
        Hostile("rudiment/--bars-5000-digits", _option("rudiment", "single-stroke-roll", "--bars", DIGITS_5000, "|",
                                                       "--bars")),
        Hostile("sweep/--audible-db-nan", _with_files({"grid.toml": 'base = "constant"\n'}, [
            "sweep", "{folder}/grid.toml", "--out", "{folder}/o.csv", "--audible-db", "nan"], "--audible-db")),
        Hostile("stats/--delta-nan", _option("stats", "--summary", "4.227,2.654,4.999,1.564,22", "--delta", "nan", "|",
                                             "--delta")),
        Hostile("stats/--alpha-inf", _option("stats", "--summary", "4.227,2.654,4.999,1.564,22", "--alpha", "inf",
                                             "|", "--alpha")),
        Hostile("stats/--summary-nan", _option("stats", "--summary", "nan,2.654,4.999,1.564,22", "|", "--summary",
                                               "mean_a")),
        Hostile("stats/--summary-5000-digits", _option("stats", "--summary", f"4,2,4,1,{DIGITS_5000}", "|",
                                                       "summary")),
        Hostile("robot-track/--rate-nan", _option("robot", "track", "single", "--rate", "nan", "|", "--rate")),
        Hostile("robot-tune/--evaluations-5000-digits", _with_files({"lib": os.mkdir}, [
            "robot", "tune", "--library", "{folder}/lib", "--evaluations", DIGITS_5000], "--evaluations")),
        Hostile("listen-analyze/--delta-inf", _with_files({"answers.db": b""}, [
            "listen", "analyze", "--db", "{folder}/answers.db", "--delta", "inf"], "--delta")),
        Hostile("simulate/stroke-name-too-long", _option("simulate", "x" * 5000 + ".toml", "|", "xxxx")),
        Hostile("simulate/--library-name-too-long", _option(*simulate, "--library", "l" * 5000, "|", "--library")),
    ]

    # writing: onto a directory, into a missing folder, past the file size limit (as a full disk would)
    csv_out = [*simulate, "--csv", "{folder}/out.csv"]
    cases += [
        Hostile("write/--csv-onto-directory", _with_files({"out.csv": os.mkdir}, csv_out, "--csv",
                                                          "{folder}/out.csv", "directory")),
        Hostile("write/--json-onto-directory", _with_files({"out.json": os.mkdir}, [
            *simulate, "--json", "{folder}/out.json"], "--json", "{folder}/out.json")),
        Hostile("write/--csv-missing-folder", _option(*simulate, "--csv", "{folder}/none/out.csv", "|", "--csv",
                                                      "{folder}/none")),
        Hostile("write/--csv-file-too-large", _option(*csv_out, "|", "--csv", "{folder}/out.csv", "File too large"),
                limits=(("RLIMIT_FSIZE", 4096),)),
        Hostile("write/compose-file-too-large", _with_files({"p.pattern": PATTERN}, [
            "compose", "{folder}/p.pattern", "--csv", "{folder}/out.csv"], "--csv", "{folder}/out.csv",
            "File too large"), limits=(("RLIMIT_FSIZE", 4096),)),
        Hostile("write/library-onto-file", _with_files({"lib": "a file\n"}, ["library", "build", "{folder}/lib"],
                                                       "{folder}/lib")),
        Hostile("library-check/not-a-folder", _with_files({"lib": "a file\n"}, ["library", "check", "{folder}/lib"],
                                                          "{folder}/lib")),
        Hostile("simulate/--library-manifest-rate-400-digits", _with_files(
            {"lib": os.mkdir, f"lib/{MANIFEST}": f'{{"rate": {DIGITS_400}}}'}, [*simulate, "--library", "{folder}/lib"],
            f"{{folder}}/lib/{MANIFEST}", "rate")),
        Hostile("compose/song-over-an-hour", lambda f: (
            ["compose", str(_midi(f / "s.mid", notes=[(i * 4800, 38, 90) for i in range(800)], tempo=5_000_000))],
            [str(f / "s.mid"), "3600 s"])),
    ]

    # the listening test's database: not a database, a directory, in a missing folder, under a file; ports
    serve = ["listen", "serve", "{folder}/test.toml", "--port", "8999", "--db"]
    cases += [
        Hostile("listen-serve/db-not-a-database", _with_files(
            {"test.toml": _listening_test, "answers.db": "this is not a database\n" * 100},
            [*serve, "{folder}/answers.db"], "{folder}/answers.db")),
        Hostile("listen-serve/db-is-a-directory", _with_files(
            {"test.toml": _listening_test, "answers.db": os.mkdir}, [*serve, "{folder}/answers.db"],
            "{folder}/answers.db")),
        Hostile("listen-serve/db-in-missing-folder", _with_files(
            {"test.toml": _listening_test}, [*serve, "{folder}/none/answers.db"], "--db", "{folder}/none")),
        Hostile("listen-serve/db-under-a-file", _with_files(
            {"test.toml": _listening_test, "file": "x\n"}, [*serve, "{folder}/file/answers.db"], "--db",
            "{folder}/file")),
        Hostile("listen-serve/db-fifo", _with_files(
            {"test.toml": _listening_test, "answers.db": os.mkfifo}, [*serve, "{folder}/answers.db"],
            "{folder}/answers.db"), blocking=True),
        Hostile("listen-serve/port-negative", _with_files(
            {"test.toml": _listening_test}, ["listen", "serve", "{folder}/test.toml", "--db", "{folder}/a.db",
                                             "--port", "-1"], "--port", "-1")),
        Hostile("listen-serve/port-5000-digits", _with_files(
            {"test.toml": _listening_test}, ["listen", "serve", "{folder}/test.toml", "--db", "{folder}/a.db",
                                             "--port", DIGITS_5000], "--port")),
        Hostile("listen-analyze/db-is-a-directory", _with_files(
            {"answers.db": os.mkdir}, ["listen", "analyze", "--db", "{folder}/answers.db"], "{folder}/answers.db")),
        Hostile("listen-analyze/db-missing", _option("listen", "analyze", "--db", "{folder}/none.db", "|",
                                                     "{folder}/none.db")),
        Hostile("listen-analyze/db-under-a-file", _with_files(
            {"file": "x\n"}, ["listen", "analyze", "--db", "{folder}/file/answers.db"], "{folder}/file/answers.db")),
        Hostile("listen-analyze/db-random-bytes", _with_files(
            {"answers.db": bytes(range(256)) * 64}, ["listen", "analyze", "--db", "{folder}/answers.db"],
            "{folder}/answers.db")),
        Hostile("listening-config/seed-5000-digits", _with_files(
            {"test.toml": f'admin_token = "a-long-enough-token"\nseed = {DIGITS_5000}\n'},
            [*serve[:-1], "--db", "{folder}/a.db"], "{folder}/test.toml", "seed")),
    ]

    def stimulus(make, named="{folder}/robot.wav"):
        def made(folder):
            _listening_test(folder / "test.toml")
            (folder / "robot.wav").unlink()
            make(folder / "robot.wav")
            return [a.format(folder=folder) for a in [*serve, "{folder}/a.db"]], ["pair[0].robot", named.format(folder=folder)]
        return made

    cases += [
        Hostile("listening-config/stimulus-fifo", stimulus(os.mkfifo), blocking=True),
        Hostile("listening-config/stimulus-dev-zero", stimulus(lambda p: os.symlink("/dev/zero", p),
                                                                          named="/dev/zero"), blocking=True),
        Hostile("listening-config/stimulus-directory", stimulus(os.mkdir)),
        Hostile("listening-config/stimulus-missing", stimulus(lambda p: None)),
    ]

    # playing live: its score and robot config are read before anything starts
    cases += [
        Hostile("live/--score-midi-tempo-0", lambda f: (["live", "--score", str(_midi(f / "s.mid", tempo=0)), "--csv"],
                                                        [str(f / "s.mid"), "tempo"])),
        Hostile("live/--score-dev-zero", _option("live", "--score", "/dev/zero", "--csv", "|", "--score",
                                                 "/dev/zero")),
        Hostile("live/--score-fifo", _with_files({"p.pattern": os.mkfifo}, [
            "live", "--score", "{folder}/p.pattern", "--csv"], "--score", "{folder}/p.pattern"), blocking=True),
        Hostile("live/--score-not-a-pattern", _with_files({"p.pattern": "tempo fast\n"}, [
            "live", "--score", "{folder}/p.pattern", "--csv"], "{folder}/p.pattern")),
        Hostile("live/--config-5000-digits", _with_files({"p.pattern": PATTERN, "robot.toml": f"[limits]\nmax_speed = "
                                                          f"{DIGITS_5000}\n"}, [
            "live", "--score", "{folder}/p.pattern", "--csv", "--config", "{folder}/robot.toml"],
            "{folder}/robot.toml")),
        Hostile("live/--latency-nan", _with_files({"p.pattern": PATTERN}, [
            "live", "--score", "{folder}/p.pattern", "--csv", "--latency", "nan"], "--latency")),
    ]
    return cases


def _listening_test(path):
    """A valid listening test's config and its stimuli at ``path`` (needs the ``audio`` extra)."""
    from drumstroke.render.audio import render_wav

    for side, speed in (("human", 1.0), ("robot", 0.7)):
        render_wav(path.parent / f"{side}.wav", [0.01, 0.12], [speed, 0.5 * speed], duration=0.3)
    _write(path, 'title = "Robot or human?"\nadmin_token = "a-token-made-for-this-test-17"\nseed = 3\n'
                 '[[pair]]\nid = "p0"\nhuman = "human.wav"\nrobot = "robot.wav"\n')


HOSTILE = _hostile()
"""Every hostile input of the campaign."""


def run_in_process(argv, *, timeout=TIMEOUT):
    """``drumstroke.cli.main(argv)`` in a thread: (exit status or None if it hung, stderr, seconds)."""
    from drumstroke.cli import main

    result, err = {}, io.StringIO()

    def call():
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            result["status"] = main(argv)

    start = time.perf_counter()
    worker = threading.Thread(target=call, daemon=True)  # a blocked reader must not keep the process alive
    worker.start()
    worker.join(timeout)
    return result.get("status"), err.getvalue(), time.perf_counter() - start


def console_script():
    """The command that runs the ``drumstroke`` console script (``python -m drumstroke`` if it is not installed)."""
    executable = shutil.which("drumstroke")
    return [executable] if executable else [sys.executable, "-m", "drumstroke"]


def run_command(argv, *, timeout=TIMEOUT, limits=()):
    """The ``drumstroke`` console script (this drumstroke's) running ARGV in a subprocess under ``limits``.

    Returns (exit status or None if it hung, stderr, seconds).
    """
    import resource

    source = str(Path(drumstroke.__file__).resolve().parent.parent)  # the code under test, not another install
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, (source, os.environ.get("PYTHONPATH"))))}

    def limited():
        for name, value in limits:
            resource.setrlimit(getattr(resource, name), (value, value))

    start = time.perf_counter()
    try:
        done = subprocess.run([*console_script(), *argv], capture_output=True, text=True, timeout=timeout, check=False,
                              stdin=subprocess.DEVNULL, env=env, preexec_fn=limited if limits else None)
    except subprocess.TimeoutExpired as expired:
        stderr = expired.stderr or b""
        return None, stderr.decode(errors="replace") if isinstance(stderr, bytes) else stderr, \
            time.perf_counter() - start
    return done.returncode, done.stderr, time.perf_counter() - start


def verdict(status, stderr, seconds, needles):
    """What is wrong with a hostile input's outcome ("" when it is one line, exit 2, naming ``needles``, in time)."""
    lines = stderr.strip().splitlines()
    if status is None:
        return f"no answer within {TIMEOUT:g} s (a hang)"
    if status != 2:
        return f"exit status {status}, not 2"
    if "Traceback" in stderr or len(lines) != 1:
        return f"{len(lines)} lines on stderr, not one: {stderr[-500:]!r}"
    if re.search(r"\.tmp\b", lines[0]):
        return f"the error names a temporary file: {lines[0][:300]!r}"
    missing = [n for n in needles if n not in lines[0]]
    if missing:
        return f"the error does not name {missing[0][:80]!r}: {lines[0][:300]!r}"
    if seconds > TIMEOUT:
        return f"took {seconds:.1f} s"
    return ""


# -- the script -----------------------------------------------------------------------------------------------------


class Tally:
    """The outcomes of random recipes: counts by outcome and broken invariant, the slowest, and each failure."""

    def __init__(self):
        self.outcomes, self.slowest, self.failures = Counter(), 0.0, []

    def run(self, table, folder):
        """Run one recipe table (see :func:`run_recipe`) and count what it gave; a crash is caught and counted."""
        start = time.perf_counter()
        try:
            outcome, broken = run_recipe(table, folder)
        except Exception as error:  # noqa: BLE001 - a crash, counted
            outcome, broken = "crash", [f"{type(error).__name__}: {error}"]
        seconds = time.perf_counter() - start
        self.slowest = max(self.slowest, seconds)
        self.outcomes[outcome] += 1
        if seconds > DEADLINE:
            self.outcomes["hang"] += 1
            broken = [*broken, f"took {seconds:.1f} s"]
        self.outcomes.update(b for b in broken if outcome != "crash")
        if outcome == "crash" or broken:
            self.failures.append((outcome, broken, table))

    def count(self, key):
        return self.outcomes[key]

    @property
    def runs(self):
        return self.outcomes["simulated"] + self.outcomes["refused"] + self.outcomes["crash"]


def seeded(count, folder, *, seed=16, tally=None):
    """Run ``count`` recipes from :class:`Seeded` (``seed``); the :class:`Tally`."""
    tally, draw = tally or Tally(), Seeded(seed)
    for _ in range(count):
        tally.run(draw.table(), folder)
    return tally


def fuzz(count, folder, *, tally=None):
    """Run ``count`` recipes drawn by hypothesis (:func:`recipe_tables`, derandomized); the :class:`Tally`."""
    tally = tally or Tally()

    @settings(FUZZ, max_examples=count, deadline=None)
    @given(recipe_tables())
    def one(table):
        tally.run(table, folder)

    one()
    return tally


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--recipes", type=int, default=RECIPES,
                        help=f"random recipes from the seeded generator (default {RECIPES:,})")
    parser.add_argument("--hypothesis", type=int, default=HYPOTHESIS,
                        help=f"random recipes drawn by hypothesis (default {HYPOTHESIS:,})")
    options = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        drumstroke.simulate("free-bounce")  # compile (or load) the solver before anything is timed
        reference = median_time(lambda: drumstroke.simulate("free-bounce").sample(1000.0))
        startup = statistics.median(run_command(["--version"])[2] for _ in range(5))
        print(f"{options.recipes:,} seeded and {options.hypothesis:,} hypothesis recipes ...", file=sys.stderr)
        start = time.perf_counter()
        tally = seeded(options.recipes, scratch)
        fuzz(options.hypothesis, scratch, tally=tally)
        fuzz_seconds = time.perf_counter() - start
        print(f"{len(HOSTILE)} hostile inputs, each in a subprocess ...", file=sys.stderr)
        results = []
        for i, case in enumerate(HOSTILE):
            folder = scratch / f"hostile-{i}"
            folder.mkdir()
            argv, needles = case.make(folder)
            status, stderr, seconds = run_command(argv, limits=case.limits)
            results.append({"id": case.id, "status": status, "seconds": round(seconds, 3),
                            "problem": verdict(status, stderr, seconds, needles),
                            "error": stderr.strip()[:300]})
    failed = [r for r in results if r["problem"]]
    slowest_hostile = max(results, key=lambda r: r["seconds"])
    report = {
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "machine": f"{platform.platform()}, {os.cpu_count()} CPUs; python {platform.python_version()}",
        "drumstroke": drumstroke.__version__,
        "recipes": {"run": tally.runs, "seeded": options.recipes, "hypothesis": options.hypothesis,
                    "simulated": tally.count("simulated"), "refused_by_the_model": tally.count("refused"),
                    "crashes": tally.count("crash"), "hangs": tally.count("hang"), "NaN": tally.count("NaN"),
                    "below_the_head": tally.count(BELOW),
                    "impacts_out_of_order": tally.count("impacts out of time order"),
                    "off_the_control_rate": tally.count("samples off the control rate"),
                    "slowest_s": round(tally.slowest, 4), "seconds": round(fuzz_seconds, 1),
                    "reference_s": reference, "slowest_over_reference": tally.slowest / reference,
                    "failures": [repr(f)[:500] for f in tally.failures[:20]]},
        "hostile": {"inputs": len(results), "one_line_exit_2_named": len(results) - len(failed),
                    "failed": failed, "slowest_s": slowest_hostile["seconds"], "slowest": slowest_hostile["id"],
                    "median_s": round(float(np.median([r["seconds"] for r in results])), 3),
                    "startup_s": round(startup, 3), "slowest_over_startup": slowest_hostile["seconds"] / startup,
                    "median_over_startup": float(np.median([r["seconds"] for r in results])) / startup,
                    "cases": results},
    }
    (HERE / "robustness_results.json").write_text(json.dumps(report, indent=1) + "\n")
    r, h = report["recipes"], report["hostile"]
    print(f"random valid recipes: {r['run']:,} run in {r['seconds']} s ({r['simulated']:,} simulated, "
          f"{r['refused_by_the_model']:,} refused by the model): {r['crashes']} crashes, {r['hangs']} hangs, "
          f"{r['NaN']} NaN, {r['below_the_head']} samples below the head, {r['impacts_out_of_order']} impacts out "
          f"of order; slowest {r['slowest_s'] * 1000:.1f} ms, {r['slowest_over_reference']:.1f}x the free-bounce "
          f"preset simulated and sampled at 1 kHz ({r['reference_s'] * 1000:.2f} ms; a hang: over {DEADLINE:g} s)")
    print(f"hostile inputs: {h['one_line_exit_2_named']} of {h['inputs']} a one-line error, exit 2, naming the "
          f"parameter or path; slowest {h['slowest_s']:.2f} s ({h['slowest']}), median {h['median_s']:.2f} s, "
          f"{h['slowest_over_startup']:.1f}x and {h['median_over_startup']:.1f}x the command's bare start-up "
          f"(`drumstroke --version`, {h['startup_s']:.2f} s; a process each)")
    for failure in failed:
        print(f"  FAILED {failure['id']}: {failure['problem']}")
    print(f"wrote {HERE / 'robustness_results.json'}")
    return 1 if failed or r["crashes"] or tally.failures else 0


if __name__ == "__main__":
    sys.exit(main())
