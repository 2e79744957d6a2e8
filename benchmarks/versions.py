"""Time the same workloads on two versions of drumstroke, in one run: ``python benchmarks/versions.py OLD [NEW]``.

OLD and NEW are git revisions of this repository (NEW defaults to the working tree). Each is
checked out into a temporary worktree (the working tree is used as it is), and every workload
runs in a fresh interpreter with that version's ``src`` first on ``sys.path``: the versions
alternate, OLD then NEW, round after round, so both see the same machine state, and each
round's figure is the median of several timed calls after a warm-up call (numba's cache,
imports). The table gives each version's median over the rounds and the median of the paired
ratios NEW/OLD: below 1 means NEW is faster. The workloads use the public API that both
versions have: a stroke simulated and sampled, a part planned and composed, design.py's 1,000-note
piece planned and sampled, live notes planned into the running motion and their setpoints, onsets
found in a recording, the library written, and the command's start-up.

Writes the table with the machine and the two revisions to benchmarks/versions_results.json.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from _timing import machine, progress

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

_TIMER = """
import statistics, sys, time
{setup}
def work():
{body}
work()
times = []
for _ in range({repeats}):
    start = time.perf_counter()
    work()
    times.append(time.perf_counter() - start)
print(statistics.median(times))
"""

WORKLOADS = {
    "free-bounce simulated and sampled at 1 kHz": (
        "import drumstroke",
        "    drumstroke.simulate('free-bounce').sample(1000.0).theta", 20),
    "finger-pulses simulated, alpha at 1 kHz": (
        "import drumstroke",
        "    drumstroke.simulate('finger-pulses').sample(1000.0).alpha", 10),
    "backbeat.pattern composed (library strokes)": (
        "import drumstroke, tempfile\n"
        "from drumstroke.compose import compose\n"
        "from drumstroke.palette.library import build_library, load_library\n"
        "from drumstroke.score import read_score\n"
        f"folder = tempfile.mkdtemp(); build_library(folder + '/lib'); library = load_library(folder + '/lib')\n"
        f"score = read_score({str(ROOT / 'examples' / 'backbeat.pattern')!r})",
        "    compose(score, library=library).trajectory.theta", 5),
    "single-paradiddle at 120 bpm, 8 bars, planned and composed": (
        "from drumstroke.compose import compose, rudiment_score\n"
        "score, _ = rudiment_score('single-paradiddle', 120.0, bars=8)",
        "    compose(score).trajectory.theta", 5),
    "the 1,000-note two-stick piece of design.py planned and sampled at 1 kHz": (
        "import sys\n"
        "sys.path.insert(0, 'benchmarks')\n"
        "import numpy as np\n"
        "from design import piece\n"
        "from drumstroke.design import Setup, Target, assign_sticks, plan_stick\n"
        "notes = piece(); onsets = np.array([n[0] for n in notes]); beats = np.array([n[1] for n in notes])",
        "    sticks = assign_sticks(onsets, beats=beats)\n"
        "    for hand in ('right', 'left'):\n"
        "        chosen = [Target.from_velocity(t, v, kind=kind, duration=0.0625 if kind == 'buzz' else None, key=k)\n"
        "                  for k, ((t, _, v, kind), s) in enumerate(zip(notes, sticks)) if s == hand]\n"
        "        plan_stick(chosen, setup=Setup()).trajectory(t_end=onsets[-1] + 1.0).theta", 5),
    "live: 200 notes planned, 10 s of setpoints at 1 kHz": (
        "import numpy as np\n"
        "from drumstroke.live import ManualClock, Performer",
        "    clock = ManualClock(); performer = Performer(clock=clock)\n"
        "    rng = np.random.default_rng(1)\n"
        "    for k in range(200):\n"
        "        clock.set(k * 0.05); performer.setpoints(clock.now())\n"
        "        performer.note(('right', 'left')[k % 2], int(rng.integers(30, 127)))\n"
        "    performer.close(); performer.setpoints(performer.done)", 3),
    "library of 20 strokes built (files written)": (
        "import tempfile, shutil\n"
        "from drumstroke.palette.library import build_library",
        "    folder = tempfile.mkdtemp(); build_library(folder + '/lib'); shutil.rmtree(folder)", 3),
    "onsets of a 5-s recording": (
        "import numpy as np, drumstroke\n"
        "from drumstroke.analysis import onsets as _onsets\n"
        "from drumstroke.render.audio import SAMPLE_RATE, synthesize\n"
        "stroke = drumstroke.simulate('finger-pulses')\n"
        "signal, rate = synthesize(stroke.impacts.t, stroke.impacts.tip_speed, duration=5.0), SAMPLE_RATE\n"
        "detect = getattr(_onsets, 'detect_onsets', None) or _onsets.find_onsets",
        "    detect(signal, rate)", 5),
    "`drumstroke --version` (process)": (
        "import subprocess, sys",
        "    subprocess.run([sys.executable, '-m', 'drumstroke', '--version'], check=True, capture_output=True)", 5),
    "`drumstroke simulate free-bounce` (process)": (
        "import subprocess, sys",
        "    subprocess.run([sys.executable, '-m', 'drumstroke', 'simulate', 'free-bounce'], check=True, "
        "capture_output=True)", 5),
}


def checkout(revision, into):
    """A worktree of ``revision`` in ``into``; None for the working tree."""
    if revision is None:
        return ROOT
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "--quiet", str(into), revision], check=True)
    return Path(into)


def run_once(tree, workload):
    setup, body, repeats = WORKLOADS[workload]
    env = dict(os.environ, PYTHONPATH=str(tree / "src"))
    done = subprocess.run([sys.executable, "-c", _TIMER.format(setup=setup, body=body, repeats=repeats)], env=env,
                          cwd=str(tree), capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{workload} failed on {tree}:\n{done.stderr[-2000:]}")
    return float(done.stdout.strip().splitlines()[-1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old", help="the git revision to compare against")
    parser.add_argument("new", nargs="?", help="the git revision to time (default: the working tree)")
    parser.add_argument("--rounds", type=int, default=5, help="rounds of OLD then NEW (default 5)")
    parser.add_argument("--only", help="run the workloads whose name contains this text")
    args = parser.parse_args(argv)
    names = [name for name in WORKLOADS if args.only is None or args.only in name]
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        trees = {"old": checkout(args.old, Path(scratch) / "old"), "new": checkout(args.new, Path(scratch) / "new")}
        try:
            for name in names:
                progress(f"{name}: {args.rounds} rounds")
                times = {"old": [], "new": []}
                for _ in range(args.rounds):
                    for side in ("old", "new"):
                        times[side].append(run_once(trees[side], name))
                ratios = [n / o for o, n in zip(times["old"], times["new"])]
                rows.append({"workload": name, "old": statistics.median(times["old"]),
                             "new": statistics.median(times["new"]), "ratio": statistics.median(ratios)})
        finally:
            for side, tree in trees.items():
                if tree != ROOT:
                    subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], check=False)
    print(f"{'workload':62}  {'old':>10}  {'new':>10}  {'new/old':>8}")
    for row in rows:
        print(f"{row['workload']:62}  {row['old'] * 1e3:8.2f}ms  {row['new'] * 1e3:8.2f}ms  {row['ratio']:8.3f}")
    results = {"machine": machine(), "old": args.old, "new": args.new or "working tree", "rounds": args.rounds,
               "rows": rows}
    (HERE / "versions_results.json").write_text(json.dumps(results, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
