"""Time drumstroke against an independent scipy reference, in one process: ``python benchmarks/run.py``.

For each case: the median time of several repeats (a warm-up run excluded; fast cases
loop until a repeat lasts at least MIN_REPEAT_TIME, as timeit does), ours and the
reference's (DOP853 with events and an impact/restart loop, benchmarks/reference.py),
timed alternately, the median of their paired ratios, and the largest impact-time error — ours against the exact elliptic oracle
where one exists (constant forcing), else against the reference; and the reference's
own error against the oracle. Prints a table and writes it with the machine and date to
benchmarks/results.json. Progress goes to stderr. Takes well under a minute.
"""

import argparse
import datetime
import gc
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy

import drumstroke
from drumstroke import Constant, Recipe, simulate
from drumstroke.model import coefficients

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from reference import ATOL, RTOL, oracle_for, reference_simulate

RATE = 1000.0  # Hz, the robot's control rate
MIN_REPEAT_TIME = 0.05  # s: a repeat of a fast case loops at least this long
REPEATS = 7
BATCH_SIZE = 20_000
BATCH_CHECKED = 200  # strokes checked against the oracle
HEADS_SIZE = 2_000  # strokes, each with a head of its own, in the before/after of the table over heads
BATCH_REFERENCE_SIZE = 10
BATCH_SEED = 20260101

TARGETS = {  # issue 30's
    "fig4 free-bounce (5 s, 1 kHz)": ("ratio", ">=", 1000.0, "x faster than the reference"),
    "fig7 finger-pulses (5 s, 1 kHz)": ("ratio", ">=", 400.0, "x faster than the reference"),
    "free-bounce impacts only": ("ours", "<=", 5e-6, "s per stroke"),
    "batch constant-force strokes/s": ("ours", ">=", 1_000_000.0, "strokes/s"),
    "`drumstroke simulate free-bounce` (process)": ("ours", "<=", 1.5, "s, warm cache"),
}
PROCESS_REPEATS = 5


def progress(message):
    print(message, file=sys.stderr, flush=True)


def _loops(fn):
    """How many calls of ``fn`` make one repeat last MIN_REPEAT_TIME (from one probe call)."""
    start = time.perf_counter()
    fn()
    return max(1, math.ceil(MIN_REPEAT_TIME / max(time.perf_counter() - start, 1e-9)))


def _once(fn, number):
    start = time.perf_counter()
    for _ in range(number):
        fn()
    return (time.perf_counter() - start) / number


def timed_pair(ours_fn, ref_fn, *, repeats=REPEATS, per_call=1, ref_per_call=1):
    """Median seconds per item of ours and of the reference, and the median of their paired ratios.

    One warm-up call of each is excluded. The repeats alternate, ours then the reference,
    so both see the same machine state: the host this was written on changes speed by up
    to 2x over seconds, which would otherwise bias the ratio. A repeat of ours loops until
    it lasts MIN_REPEAT_TIME (timeit-style), the reference (≥ 40 ms a call) runs once. The
    garbage collector is off while timing, as in timeit. ``per_call`` and ``ref_per_call``
    are the items (strokes) one call handles.
    """
    ours_fn()  # warm-up: numba's cache load, scipy's imports, first-touch allocations
    ref_fn()
    number = _loops(ours_fn)
    ours, ref = [], []
    enabled = gc.isenabled()
    gc.disable()
    try:
        for _ in range(repeats):
            ours.append(_once(ours_fn, number) / per_call)
            ref.append(_once(ref_fn, 1) / ref_per_call)
    finally:
        if enabled:
            gc.enable()
    ratio = statistics.median(r / o for r, o in zip(ref, ours))
    detail = {"repeats": repeats, "loops_ours": number, "ours_all": ours, "reference_all": ref,
              "ratio_of_medians": statistics.median(ref) / statistics.median(ours)}
    return statistics.median(ours), statistics.median(ref), ratio, detail


def max_error(ours, other):
    """Largest |difference| over the impacts both list (s), and whether the counts agree."""
    n = min(len(ours), len(other))
    error = float(np.max(np.abs(np.asarray(ours[:n]) - np.asarray(other[:n])))) if n else math.nan
    return error, len(ours) == len(other)


def batch_recipes():
    """BATCH_SIZE random 5 s constant-force strokes (seeded), none reaching the vertical."""
    rng = np.random.default_rng(BATCH_SEED)
    coef = coefficients("paper", drumstroke.Stick())
    recipes, redrawn = [], 0
    while len(recipes) < BATCH_SIZE:
        theta0 = rng.uniform(coef.theta_max, 0.5)
        omega0 = rng.uniform(-5.0, 5.0)
        cor = rng.uniform(0.5, 0.95)
        force = rng.uniform(0.0, 250.0)
        c = float(coef.torque_rate(9.8, force))
        if math.sin(theta0) + omega0 * omega0 / (2.0 * c) >= 0.999:  # would swing (nearly) to the vertical
            redrawn += 1
            continue
        recipes.append(Recipe(force=Constant(force), theta0=theta0, omega0=omega0, cor=cor, t_end=5.0))
    return recipes, redrawn


def run_stroke_case(name, recipe, *, rate, oracle):
    """One stroke, ours vs the reference; with ``rate``, sampled too."""
    def ours_fn():
        stroke = simulate(recipe)
        if rate is not None:
            t, theta, omega = stroke.sample(rate)  # read the samples: a Trajectory computes them when read

    def ref_fn():
        reference_simulate(recipe, rate=rate)

    progress("  timing ours and the reference, alternately ...")
    ours_time, ref_time, ratio, detail = timed_pair(ours_fn, ref_fn)
    progress(f"  ours {ours_time * 1e3:.4g} ms, reference {ref_time * 1e3:.4g} ms")

    stroke = simulate(recipe)
    ref_t, _, ref_rest, ref_samples = reference_simulate(recipe, rate=rate)
    row = {
        "case": name,
        "unit": "s",
        "ours": ours_time,
        "reference": ref_time,
        "ratio": ratio,
        "impacts_ours": len(stroke.impacts),
        "impacts_reference": len(ref_t),
        "rest_time_ours": stroke.rest_time,
        "rest_time_reference": ref_rest,
        "timing": detail,
    }
    if oracle:
        exact_t, _, exact_rest = oracle_for(recipe)
        row["impacts_oracle"] = len(exact_t)
        row["error_ours"], same = max_error(stroke.impacts.t, exact_t)
        row["error_ours_vs"] = "oracle"
        row["error_reference"], same_ref = max_error(ref_t, exact_t)
        row["counts_agree"] = same and same_ref
        row["rest_time_oracle"] = exact_rest
    else:
        row["error_ours"], row["counts_agree"] = max_error(stroke.impacts.t, ref_t)
        row["error_ours_vs"] = "reference"
        row["error_reference"] = None
    if rate is not None:
        _, theta, _ = stroke.sample(rate)
        row["theta_error_vs_reference"] = float(np.max(np.abs(theta - ref_samples[1])))
    return row


def run_batch_case(name):
    recipes, redrawn = batch_recipes()
    subset = recipes[:BATCH_REFERENCE_SIZE]
    arrays = {key: np.array([getattr(r, key) for r in recipes]) for key in ("theta0", "omega0", "cor")}
    arrays["force"] = np.array([r.force.value for r in recipes])

    def ours_fn():
        drumstroke.simulate_many(**arrays)

    def ref_fn():
        for recipe in subset:
            reference_simulate(recipe)

    progress(f"  timing ours ({len(recipes)} strokes) and the reference ({len(subset)}), alternately ...")
    ours_time, ref_time, ratio, detail = timed_pair(
        ours_fn, ref_fn, per_call=len(recipes), ref_per_call=len(subset)
    )
    progress(f"  ours {1 / ours_time:.4g} strokes/s, reference {1 / ref_time:.4g} strokes/s")

    error_ours, error_ref, agree, impacts = 0.0, 0.0, True, 0
    batch = drumstroke.simulate_many(**arrays)
    assert batch.recipes[:BATCH_CHECKED] == tuple(recipes[:BATCH_CHECKED])
    for i, recipe in enumerate(recipes[:BATCH_CHECKED]):
        exact_t, _, _ = oracle_for(recipe)
        error, same = max_error(batch.impacts[i].t, exact_t)
        error_ours, agree, impacts = max(error_ours, error), agree and same, impacts + len(exact_t)
        if i < len(subset):
            error, same = max_error(reference_simulate(recipe)[0], exact_t)
            error_ref, agree = max(error_ref, error), agree and same
    return {
        "case": name,
        "unit": "strokes/s",
        "ours": 1.0 / ours_time,
        "reference": 1.0 / ref_time,
        "ratio": ratio,
        "error_ours": error_ours,
        "error_ours_vs": "oracle",
        "error_reference": error_ref,
        "counts_agree": agree,
        "strokes_ours": len(recipes),
        "strokes_reference": len(subset),
        "impacts_oracle": impacts,
        "redrawn": redrawn,
        "timing": detail,
        "note": (
            f"{len(recipes)} random 5 s constant-force strokes (seed {BATCH_SEED}: theta0 in [theta_max, 0.5] rad, "
            f"omega0 in [-5, 5] rad/s, cor in [0.5, 0.95], force in [0, 250] m/s^2; {redrawn} draws that would swing "
            f"(nearly) to the vertical redrawn), in one call of drumstroke.simulate_many with parameter arrays "
            f"(compiled, both cores); the first {BATCH_CHECKED} checked against the oracle. The reference runs the first {len(subset)} one at a "
            f"time, scaled to strokes/s. Impacts only, no sampling."
        ),
    }


def _kernel_columns(recipes):
    """The batch kernel's input arrays for constant-force recipes (what simulate_many passes it)."""
    coef = coefficients("paper", drumstroke.Stick())
    c = np.array([float(coef.torque_rate(9.8, r.force.value)) for r in recipes])
    return ([np.array([getattr(r, key) for r in recipes]) for key in ("theta0", "omega0", "cor")]
            + [c, np.full(len(c), coef.theta_max), np.array([r.t_end for r in recipes])])


def _paired_row(name, unit, after_fn, before_fn, *, per_call, after_t, before_t, recipes):
    """A before/after row: the new path as "ours", the old (R_F at every flight) as "reference", timed alternately."""
    progress("  timing after and before, alternately ...")
    after, before, ratio, detail = timed_pair(after_fn, before_fn, per_call=per_call, ref_per_call=per_call)
    progress(f"  after {after:.4g}, before {before:.4g} s per item")
    errors = [0.0, 0.0]
    agree = True
    for i, recipe in enumerate(recipes):
        exact_t, _, _ = oracle_for(recipe)
        for k, times in enumerate((after_t(i), before_t(i))):
            e, same = max_error(times, exact_t)
            errors[k], agree = max(errors[k], e), agree and same
    per_second = unit == "strokes/s"
    return {"case": name, "unit": unit, "ours": 1.0 / after if per_second else after,
            "reference": 1.0 / before if per_second else before, "ratio": ratio, "error_ours": errors[0],
            "error_ours_vs": "oracle", "error_reference": errors[1], "counts_agree": agree, "timing": detail,
            "before_after": True}


def run_solver_pair(name):
    """free-bounce's impacts by the solver alone (no Stroke built): flights by the table, then by R_F."""
    from drumstroke.solver import solve

    recipe = drumstroke.preset("free-bounce")
    kwargs = dict(theta0=recipe.theta0, omega0=recipe.omega0, cor=recipe.cor, t_end=recipe.t_end)

    def run(tabled):
        return solve(recipe.coefficients, recipe.force, recipe.gravity, **kwargs, tabled=tabled)

    return _paired_row(name, "s", lambda: run(True), lambda: run(False), per_call=1,
                       after_t=lambda i: run(True).impact_t, before_t=lambda i: run(False).impact_t,
                       recipes=[recipe])


def _kernel_row(name, recipes, columns):
    """The batch kernel on ``columns`` (``recipes``' parameters): flights by the table, then by R_F, paired."""
    from drumstroke.solver.batch import constant_batch

    after = constant_batch(*columns, max_impacts=100_000)
    before = constant_batch(*columns, max_impacts=100_000, exact=True)

    def impacts(result, i):
        offsets, count, t = result[1], result[2], result[3]
        return t[offsets[i]:offsets[i] + count[i]]

    return _paired_row(name, "strokes/s", lambda: constant_batch(*columns, max_impacts=100_000),
                       lambda: constant_batch(*columns, max_impacts=100_000, exact=True), per_call=len(recipes),
                       after_t=lambda i: impacts(after, i), before_t=lambda i: impacts(before, i),
                       recipes=recipes[:BATCH_CHECKED])


def run_kernel_pair(name):
    """The batch kernel alone (constant_batch) on the batch's strokes: flights by the table, then by R_F."""
    recipes, _ = batch_recipes()
    columns = _kernel_columns(recipes)
    return _kernel_row(name, recipes, columns)


def run_heads_pair(name):
    """The batch kernel on HEADS_SIZE strokes each with a head of its own: flights by the table, then by R_F.

    The sweep a planner or a palette search makes when it varies the stick: the table holds every head,
    so no stroke pays for a head new to the process.
    """
    rng = np.random.default_rng(BATCH_SEED)
    recipes = []
    for recipe in batch_recipes()[0][:HEADS_SIZE]:
        stick = drumstroke.Stick(pivot_height=float(rng.uniform(0.01, 0.2)))  # a head from −0.04 to −0.83 rad
        recipes.append(recipe.replace(stick=stick, theta0=max(recipe.theta0, stick.theta_max)))
    coefs = [coefficients("paper", r.stick) for r in recipes]
    columns = ([np.array([getattr(r, key) for r in recipes]) for key in ("theta0", "omega0", "cor")]
               + [np.array([float(k.torque_rate(9.8, r.force.value)) for k, r in zip(coefs, recipes)]),
                  np.array([k.theta_max for k in coefs]), np.array([r.t_end for r in recipes])])
    return _kernel_row(name, recipes, columns)


def run_batch_pair(name):
    """simulate_many on the batch's strokes, against what it did before: R_F at every flight, every Impacts built."""
    from drumstroke.solver.batch import constant_batch
    from drumstroke.trajectory import Impacts

    recipes, _ = batch_recipes()
    arrays = {key: np.array([getattr(r, key) for r in recipes]) for key in ("theta0", "omega0", "cor")}
    arrays["force"] = np.array([r.force.value for r in recipes])
    columns = _kernel_columns(recipes)
    tip = drumstroke.Stick().pivot_to_tip

    def before_fn():
        _, offsets, count, t, omega, _ = constant_batch(*columns, max_impacts=100_000, exact=True)
        starts, ends = offsets[:-1].tolist(), (offsets[:-1] + count).tolist()
        return [Impacts(t[a:b], omega[a:b], tip) for a, b in zip(starts, ends)]

    after, before = drumstroke.simulate_many(**arrays), before_fn()
    return _paired_row(name, "strokes/s", lambda: drumstroke.simulate_many(**arrays), before_fn,
                       per_call=len(recipes), after_t=lambda i: after.impacts[i].t, before_t=lambda i: before[i].t,
                       recipes=recipes[:BATCH_CHECKED])


def run_process_case(name):
    """The whole command as a user runs it: interpreter start, imports, the cached kernel, the summary."""
    command = [shutil.which("drumstroke") or sys.executable, "simulate", "free-bounce"]
    if command[0] == sys.executable:
        command[1:1] = ["-m", "drumstroke.cli"]
    times = []
    for _ in range(PROCESS_REPEATS + 1):  # the first run warms the disk cache; not counted
        start = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True, timeout=120)
        times.append(time.perf_counter() - start)
    return {
        "case": name,
        "unit": "s",
        "ours": statistics.median(times[1:]),
        "reference": None,
        "ratio": None,
        "error_ours": None,
        "error_ours_vs": None,
        "error_reference": None,
        "counts_agree": True,
        "timing": {"repeats": PROCESS_REPEATS, "ours_all": times[1:],
                   "command": " ".join([Path(command[0]).name, *command[1:]])},  # as typed: no path of this host
    }


def machine():
    cpu = platform.processor() or ""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        import numba

        numba_version = numba.__version__
    except ImportError:
        numba_version = None
    try:
        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], check=False, cwd=HERE, capture_output=True, text=True, timeout=5
        ).stdout.strip() or None
    except (OSError, subprocess.SubprocessError):
        commit = None
    return {
        "platform": platform.platform(),
        "cpu": cpu,
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "numba": numba_version,
        "drumstroke": drumstroke.__version__,
        "git_commit": commit,
    }


def format_value(value, unit):
    if unit == "strokes/s":
        return f"{value:,.0f}/s"
    if value >= 1.0:
        return f"{value:.3g} s"
    if value >= 1e-3:
        return f"{value * 1e3:.3g} ms"
    return f"{value * 1e6:.3g} µs"


def format_error(value, vs=None):
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    text = f"{value:.1e} s"
    return f"{text} ({vs})" if vs else text


def table(rows):
    header = ("case", "ours", "reference", "ratio", "ours err (vs)", "ref err vs oracle")
    lines = [
        (
            row["case"],
            format_value(row["ours"], row["unit"]),
            "—" if row["reference"] is None else format_value(row["reference"], row["unit"]),
            "—" if row["ratio"] is None else f"{row['ratio']:.3g}x",
            format_error(row["error_ours"], "oracle" if row["error_ours_vs"] == "oracle" else "ref")
            + ("" if row["counts_agree"] else " [counts differ]"),
            format_error(row["error_reference"]),
        )
        for row in rows
    ]
    widths = [max(len(header[i]), *(len(line[i]) for line in lines)) for i in range(len(header))]
    out = ["  ".join(h.ljust(w) for h, w in zip(header, widths)), "  ".join("-" * w for w in widths)]
    out += ["  ".join(cell.ljust(w) if i == 0 else cell.rjust(w) for i, (cell, w) in enumerate(zip(line, widths)))
            for line in lines]
    return "\n".join(out)


def targets(rows):
    by_case = {row["case"]: row for row in rows}
    result = []
    for case, (field, op, value, unit) in TARGETS.items():
        if case not in by_case:  # (a run of some of the cases)
            continue
        measured = by_case[case][field]
        met = measured >= value if op == ">=" else measured <= value
        result.append({"case": case, "quantity": field, "target": f"{op} {value:g} {unit}", "measured": measured,
                       "met": met})
    return result


def write_json_atomic(path, data):
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w") as file:
            json.dump(data, file, indent=2)
            file.write("\n")
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", default=str(HERE / "results.json"), help="JSON file (default: %(default)s)")
    parser.add_argument("--only", action="append", metavar="TEXT",
                        help="run only the cases whose name contains TEXT (repeatable), e.g. --only fig7 "
                             "--only 'impacts only'; the JSON then holds those rows")
    args = parser.parse_args(argv)
    wanted = (lambda name: any(text in name for text in args.only)) if args.only else (lambda name: True)

    started = time.perf_counter()
    date = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
    figure_cases = [
        ("fig4 free-bounce (5 s, 1 kHz)", "free-bounce", True),
        ("fig5 low-high (5 s, 1 kHz)", "low-high", False),
        ("fig6 high-low (5 s, 1 kHz)", "high-low", False),
        ("fig7 finger-pulses (5 s, 1 kHz)", "finger-pulses", False),
    ]
    cases = [(name, drumstroke.preset(p), RATE, oracle) for name, p, oracle in figure_cases]
    cases.append(("free-bounce impacts only", drumstroke.preset("free-bounce"), None, True))
    cases.append(("finger-pulses 60 s", drumstroke.preset("finger-pulses").replace(t_end=60.0), None, False))
    # before/after of the flight-time table, in this one process: the new path and R_F at every flight, alternately
    pairs = [("free-bounce impacts, solver only: after vs before", run_solver_pair),
             ("batch kernel strokes/s: after vs before", run_kernel_pair),
             (f"batch kernel, {HEADS_SIZE:,} heads, strokes/s: after vs before", run_heads_pair),
             ("simulate_many strokes/s: after vs before", run_batch_pair),
             ("batch constant-force strokes/s", run_batch_case),
             ("`drumstroke simulate free-bounce` (process)", run_process_case)]
    runs = [(name, lambda name=name, recipe=recipe, rate=rate, oracle=oracle: run_stroke_case(
        name, recipe, rate=rate, oracle=oracle)) for name, recipe, rate, oracle in cases]
    runs = [(name, run) for name, run in runs + [(name, lambda name=name, case=case: case(name)) for name, case in pairs]
            if wanted(name)]
    rows = []
    for i, (name, run) in enumerate(runs, start=1):
        progress(f"[{i}/{len(runs)}] {name}")
        rows.append(run())

    info = machine()
    notes = [
        "Model: paper (D = 0.0714 m^2, Eq. 7), Table 1 stick, for every case.",
        (
            f"Times are the median of {REPEATS} repeats in this one process, warm-up excluded, ours and the "
            "reference alternating; ratio = the median of the paired reference/ours time ratios (for the batch, "
            "per stroke): above 1 means drumstroke is faster."
        ),
        (
            "'ours err': largest |impact-time difference| over every listed impact, against the exact elliptic "
            "oracle (constant forcing) or else the reference; 'ref err': the reference against the oracle."
        ),
        (
            f"Reference: scipy.integrate.solve_ivp DOP853, rtol={RTOL:g}, atol={ATOL:g}, events and a restart at "
            "each impact, integrated piece by piece (benchmarks/reference.py)."
        ),
        *(row["note"] for row in rows if row["case"] == "batch constant-force strokes/s"),
        (
            "Rows 'after vs before': 'ours' is the new path, 'reference' the old one, timed alternately in this run, "
            "ratio = before/after; 'ref err' is the old path's error against the oracle. After: flights from the "
            "head by the table of every head (drumstroke.solver.flight_table); before: Carlson's R_F at every flight. "
            "The solver alone (solve, no Stroke built) on free-bounce; the batch kernel alone (constant_batch) on the "
            f"batch's strokes, and on {HEADS_SIZE:,} of them each given a stick of its own (its own head angle); "
            "simulate_many on the batch's strokes, before also building every stroke's Impacts up front as it did."
        ),
        *(f"The process case runs `{row['timing']['command']}` {PROCESS_REPEATS} times after one warm-up run "
          "(the numba cache on disk, as after a first use); the median wall time." for row in rows
          if row["case"].endswith("(process)")),
    ]
    text = table(rows)
    print(f"drumstroke {info['drumstroke']} benchmark, {date}")
    print(f"machine: {info['platform']}, {info['cpu']}, {info['cpu_count']} CPUs; python {info['python']}, "
          f"numpy {info['numpy']}, scipy {info['scipy']}, numba {info['numba']}; commit {info['git_commit']}")
    print()
    print(text)
    print()
    for note in notes:
        print(f"* {note}")
    goal = targets(rows)
    print()
    print("targets:")
    for item in goal:
        measured = format_value(item["measured"], "strokes/s" if "strokes" in item["target"] else "s") \
            if item["quantity"] == "ours" else f"{item['measured']:.3g}x"
        print(f"  {item['case']}: {item['quantity']} {item['target']}: measured {measured} — "
              f"{'met' if item['met'] else 'NOT met'}")
    elapsed = time.perf_counter() - started
    write_json_atomic(args.output, {
        "date": date,
        "machine": info,
        "model": "paper",
        "reference": {"method": "DOP853", "rtol": RTOL, "atol": ATOL, "file": "benchmarks/reference.py"},
        "rate_hz": RATE,
        "cases": rows,
        "targets": goal,
        "notes": notes,
        "table": text,
        "elapsed_s": elapsed,
    })
    progress(f"wrote {args.output} ({elapsed:.0f} s)")


if __name__ == "__main__":
    main()
