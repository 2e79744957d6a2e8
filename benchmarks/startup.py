"""How long the ``drumstroke`` command takes to start, against the interpreter alone: ``python benchmarks/startup.py``.

    python benchmarks/startup.py [--repeats 15]

Each case is a whole process, as a user runs it: ``python -c pass`` (the reference: the interpreter
starting and stopping), ``drumstroke --version``, ``drumstroke --help`` and ``drumstroke simulate
free-bounce`` (a stroke simulated and its impacts printed, numba's kernels loaded from its on-disk
cache). Every case runs once first (the warm-up: the disk cache, numba's cache, the .pyc files, written
even where PYTHONDONTWRITEBYTECODE is set, as an installed package has them), then the cases run in turn
``--repeats`` times, so a drift of the host's speed touches them alike. Prints
the median wall time of each and its ratio to the reference's, and writes them with the machine and
date to benchmarks/startup_results.json.
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

from _timing import machine, progress

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "startup_results.json"
ENVIRONMENT = {name: value for name, value in os.environ.items() if name != "PYTHONDONTWRITEBYTECODE"}
"""The cases' environment: this one, with the .pyc files written (a warm start reads them)."""
TARGETS = {"drumstroke --version": 0.25, "drumstroke --help": 0.25, "drumstroke simulate free-bounce": 0.5}
"""The most each command may take (s, median, warm), as the project's issue asks."""


def commands():
    """{case: argv}: the reference first, then the command lines timed (the installed script, else ``-m``)."""
    script = shutil.which("drumstroke")
    drumstroke = [script] if script else [sys.executable, "-m", "drumstroke.cli"]
    cases = {"python -c pass": [sys.executable, "-c", "pass"]}
    for arguments in (["--version"], ["--help"], ["simulate", "free-bounce"]):
        cases[" ".join(["drumstroke", *arguments])] = [*drumstroke, *arguments]
    return cases


def wall_time(argv):
    """The wall time (s) of one run of ``argv``, which must succeed."""
    start = time.perf_counter()
    subprocess.run(argv, check=True, capture_output=True, timeout=120, env=ENVIRONMENT)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15, help="runs of each case after the warm-up (default 15)")
    repeats = parser.parse_args().repeats
    cases = commands()
    progress("warming up: each case once")
    for argv in cases.values():
        wall_time(argv)
    times = {case: [] for case in cases}
    for i in range(repeats):
        progress(f"[{i + 1}/{repeats}] each case once, in turn")
        for case, argv in cases.items():
            times[case].append(wall_time(argv))
    medians = {case: statistics.median(t) for case, t in times.items()}
    reference = medians["python -c pass"]
    info = machine()
    print(f"drumstroke {info['drumstroke']} start-up, {info['date']}; {info['platform']}, {info['processor']}; "
          f"python {info['python']}; the median of {repeats} runs of each case, after a warm-up run")
    print(f"    {'case':<34} {'time':>9} {'ratio':>7}  target")
    rows = []
    for case, median in medians.items():
        target = TARGETS.get(case)
        verdict = f"<= {target:g} s: {'met' if median <= target else 'NOT met'}" if target else "(the reference)"
        print(f"    {case:<34} {median * 1e3:>6.0f} ms {median / reference:>6.1f}x  {verdict}")
        typed = [Path(cases[case][0]).name, *cases[case][1:]]  # as typed: no path of this host
        rows.append({"case": case, "command": " ".join(typed), "median_s": median, "ratio": median / reference,
                     "target_s": target, "all_s": times[case]})
    print("    ratio: the case's median over that of `python -c pass` (the interpreter alone) in the same run")
    RESULTS.write_text(json.dumps({"machine": info, "repeats": repeats, "cases": rows}, indent=2) + "\n")
    progress(f"wrote {RESULTS}")


if __name__ == "__main__":
    main()
