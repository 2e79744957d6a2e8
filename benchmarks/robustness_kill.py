"""SIGKILL at random points of ``library build``, ``compose`` and ``simulate``: what a kill leaves behind.

    python benchmarks/robustness_kill.py [--kills 120] [--seed 16] [--workers 2]

Each command writes into a folder that holds a whole result of an earlier run, from one of two
inputs, A or B; the run killed has the other input, so the previous result and the new one
differ:

- ``library build LIB``: the shipped palette (20 strokes) or examples/palettes/small.toml (4);
- ``compose SCORE --library LIB``: examples/backbeat.pattern or the same at another tempo, to a
  CSV, its JSON, WAV, MIDI and PNG;
- ``simulate double`` or ``simulate triple``, to the same five files.

A run is killed with SIGKILL at a random point, drawn with a seeded generator: half after a
delay uniform over a whole run's time (most of it is spent importing and computing), half just
before its k-th file-system call (os.open, fsync, mkdir, rename, replace, unlink, rmdir), k
uniform over a whole run's calls: the process sends the SIGKILL to itself from a hook this
script installs (:data:`HOOK`); drumstroke has no hook of its own. Then:

- the folder must hold the previous result or the new one, whole: the library loads and
  ``check_library`` finds no problem; the outputs are byte for byte all A's or all B's. Or the
  new run had committed its bundle and was killed while renaming its files into place: then the
  bundle's record is there (a mix that can be told), and the next run completes it — checked by
  doing what the next run does first (``remove_stale``) and finding all of the new result;
- the leftovers (temporaries of the killed run) are counted, files and bytes;
- the same command is run again to the end: its result must be whole and the folder must hold
  nothing else (no debris).

Two trials run at a time, each in its own folders. Prints a table and writes the figures to
benchmarks/robustness_kill_results.json. ``tests/test_crash.py`` runs a short campaign.
"""

import argparse
import concurrent.futures
import datetime
import hashlib
import json
import os
import platform
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import drumstroke
from drumstroke._atomic import describe_temporary, remove_stale
from drumstroke.palette.library import check_library, load_library

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "robustness_kill_results.json"
COMMANDS = ("library build", "compose", "simulate")
OUTPUTS = ("out.csv", "out.json", "out.wav", "out.mid", "out.png")
HOOK = """
import os, signal, sys
name, part, at, count_file, arguments = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4], sys.argv[5:]
calls = 0
def hooked(called, real):
    def call(*args, **kwargs):
        global calls
        if name in ("any", called) and part in str(args[0] if args else ""):
            calls += 1
            if calls == at:
                os.kill(os.getpid(), signal.SIGKILL)
        return real(*args, **kwargs)
    return call
for called in ("open", "fsync", "mkdir", "rename", "replace", "unlink", "rmdir"):
    setattr(os, called, hooked(called, getattr(os, called)))
"""
"""The start of a program run as ``python -c PROGRAM NAME PART K COUNT_FILE ARGS...``: it sends itself SIGKILL
just before the K-th call of os.NAME ("any": of every one of those hooked) whose first argument contains PART
(K = 0: never); the program has ``arguments`` (ARGS), ``calls`` and ``count_file``."""
CLI = HOOK + """
from drumstroke.cli import main
status = main(arguments)
if count_file:
    with open(count_file, "w") as handle:
        handle.write(str(calls))
sys.exit(status)
"""
"""drumstroke's command line with ARGS, under the hook; COUNT_FILE (if not "") receives the number of calls."""


class Campaign:
    """The folders, inputs and reference results of a campaign; :meth:`run` runs it.

    Parameters
    ----------
    folder : Path
        An empty folder to work in.
    outputs : tuple of str
        The files compose and simulate write (their suffixes choose the options).
    workers : int
        Trials run at a time.
    """

    def __init__(self, folder, *, outputs=OUTPUTS, workers=2):
        self.folder, self.outputs, self.workers = Path(folder), tuple(outputs), workers
        self.references, self.spaces = {}, {}

    def command_line(self, command, workspace, variant):
        """The drumstroke arguments of ``command`` with input ``variant`` ("A" or "B"), writing into ``workspace``."""
        if command == "library build":
            palette = [] if variant == "A" else ["--palette", str(ROOT / "examples" / "palettes" / "small.toml")]
            return ["library", "build", str(workspace / "lib"), *palette]
        options = {".csv": "--csv", ".json": "--json", ".wav": "--audio", ".mid": "--midi", ".png": "--plot"}
        outputs = [part for name in self.outputs for part in (options[Path(name).suffix], str(workspace / "out" / name))]
        if command == "compose":
            return ["compose", str(self.folder / f"score-{variant}.pattern"), "--library", str(self.folder / "library"),
                    "-q", *outputs]
        return ["simulate", "double" if variant == "A" else "triple", *outputs]

    def result_of(self, command, workspace):
        """What a folder holds: a library's stroke folder name (None if it does not check whole); the outputs'
        SHA-256 (None for a missing one)."""
        if command == "library build":
            diagnosis = check_library(workspace / "lib")
            if diagnosis.problems:
                return None
            return json.loads((workspace / "lib" / "manifest.json").read_text())["folder"]
        return tuple(digest(workspace / "out" / name) if (workspace / "out" / name).exists() else None
                     for name in self.outputs)

    def leftovers(self, command, workspace):
        """The entries of the command's folder that are not its result: (count, bytes)."""
        folder = _folder(command, workspace)
        if command == "library build":
            keep = {"manifest.json", json.loads((folder / "manifest.json").read_text())["folder"]}
        else:
            keep = set(self.outputs)
        extra = [folder / name for name in os.listdir(folder) if name not in keep]
        return len(extra), sum(_size(path) for path in extra)

    def prepare(self):
        """The library compose reads, the two scores; a reference run of every command and input (time,
        file-system calls, result); a copy of input A's folders per worker."""
        run(["library", "build", str(self.folder / "library")])
        text = (ROOT / "examples" / "backbeat.pattern").read_text()
        (self.folder / "score-A.pattern").write_text(text)
        (self.folder / "score-B.pattern").write_text(text.replace("tempo 100", "tempo 132"))
        cases = [(command, variant) for command in COMMANDS for variant in ("A", "B")]
        with concurrent.futures.ThreadPoolExecutor(self.workers) as pool:
            done = dict(zip(cases, pool.map(lambda case: self._reference(*case), cases)))
        self.references = {command: {v: done[command, v] for v in ("A", "B")} for command in COMMANDS}
        for worker in range(self.workers):
            for command in COMMANDS:
                workspace = self.folder / f"worker{worker}" / command.replace(" ", "-")
                shutil.copytree(self.folder / "reference-A" / command.replace(" ", "-"), workspace,
                                ignore=shutil.ignore_patterns("calls.txt"))
                self.spaces[worker, command] = workspace

    def _reference(self, command, variant):
        workspace = self.folder / f"reference-{variant}" / command.replace(" ", "-")
        (workspace / "out").mkdir(parents=True)
        count = workspace / "calls.txt"
        _, seconds = run(self.command_line(command, workspace, variant), count_file=str(count))
        return {"seconds": seconds, "calls": int(count.read_text()), "result": self.result_of(command, workspace)}

    def trial(self, command, workspace, rng):
        """Kill one run at a random point, check what it left, run again to the end; return the figures."""
        references = self.references[command]
        before = self.result_of(command, workspace)
        previous = next(v for v, ref in references.items() if ref["result"] == before)
        variant = "B" if previous == "A" else "A"
        new = references[variant]
        arguments = self.command_line(command, workspace, variant)
        if rng.random() < 0.5:
            mode, at = "time", float(rng.uniform(0.0, new["seconds"]))
            status, seconds = run(arguments, delay=at)
        else:
            mode, at = "call", int(rng.integers(1, new["calls"] + 1))
            status, seconds = run(arguments, kill=("any", "", at))
        figures = {"command": command, "mode": mode, "at": at, "killed": status == -signal.SIGKILL,
                   "seconds": seconds, "from": previous, "to": variant}
        after = self.result_of(command, workspace)
        figures["leftover_files"], figures["leftover_bytes"] = self.leftovers(command, workspace)
        if after == before:
            figures["outcome"] = "previous"
        elif after == new["result"]:
            figures["outcome"] = "new"
        elif _bundle_records(_folder(command, workspace)):
            remove_stale(_folder(command, workspace))  # what the next run writing there does first
            completed = self.result_of(command, workspace) == new["result"]
            figures["outcome"] = "completed by the next run" if completed else "mix"
        else:
            figures["outcome"] = "mix" if after is not None else "damaged"
        if command == "library build" and after is not None:
            load_library(workspace / "lib")  # loads whole, or raises
        run(arguments)
        figures["whole_after_next_run"] = self.result_of(command, workspace) == new["result"]
        figures["debris_after_next_run"] = self.leftovers(command, workspace)
        return figures

    def run(self, *, kills, seed):
        """Run trials until ``kills`` runs were killed (a third per command, in a shuffled order); the figures."""
        started = time.monotonic()
        self.prepare()
        order = [command for command in COMMANDS for _ in range(-(-kills // len(COMMANDS)))]
        np.random.default_rng(seed).shuffle(order)
        trials = []

        def worker(number, queue):
            rng = np.random.default_rng([seed, number])
            for command in queue:
                killed = False
                while not killed:  # a run that ended before its kill is recorded, and another drawn
                    figures = self.trial(command, self.spaces[number, command], rng)
                    trials.append(figures | {"worker": number})
                    killed = figures["killed"]
                    progress(f"{sum(t['killed'] for t in trials)} of {len(order)} kills: {command} "
                             f"{figures['outcome']}, {figures['leftover_files']} leftovers")

        with concurrent.futures.ThreadPoolExecutor(self.workers) as pool:
            for future in [pool.submit(worker, w, order[w::self.workers]) for w in range(self.workers)]:
                future.result()
        return self.summarize(trials, seed, time.monotonic() - started)

    def summarize(self, trials, seed, seconds):
        commands = {}
        for command in COMMANDS:
            runs = [t for t in trials if t["command"] == command]
            killed = [t for t in runs if t["killed"]]
            outcomes = {}
            for t in killed:
                outcomes[t["outcome"]] = outcomes.get(t["outcome"], 0) + 1
            references = self.references[command]
            commands[command] = {
                "kills": len(killed),
                "kills_by_time": sum(t["mode"] == "time" for t in killed),
                "kills_by_call": sum(t["mode"] == "call" for t in killed),
                "finished_before_the_kill": len(runs) - len(killed),
                "outcomes": outcomes,
                "failures": [t for t in runs if t["outcome"] not in WHOLE or not t["whole_after_next_run"]
                             or tuple(t["debris_after_next_run"]) != (0, 0)],
                "kills_leaving_leftovers": sum(t["leftover_files"] > 0 for t in killed),
                "leftover_files": sum(t["leftover_files"] for t in killed),
                "leftover_bytes": sum(t["leftover_bytes"] for t in killed),
                "debris_after_next_run": [sum(t["debris_after_next_run"][i] for t in runs) for i in (0, 1)],
                "whole_run_s": {v: round(ref["seconds"], 3) for v, ref in references.items()},
                "whole_run_calls": {v: ref["calls"] for v, ref in references.items()},
                "killed_at_s_median": round(statistics.median(t["at"] for t in killed if t["mode"] == "time"), 3)
                if any(t["mode"] == "time" for t in killed) else None,
            }
        return {"seed": seed, "workers": self.workers, "outputs": list(self.outputs),
                "kills": sum(c["kills"] for c in commands.values()),
                "failures": sum(len(c["failures"]) for c in commands.values()), "seconds": round(seconds, 1),
                "commands": commands, "trials": trials}


WHOLE = ("previous", "new", "completed by the next run")
"""The outcomes of a kill that leave a whole result (the last: a run committed and interrupted while its
files were renamed, completed by the next run writing there, as its record says)."""


def run(arguments, *, kill=("any", "", 0), delay=None, count_file="", program=CLI):
    """Run ``program`` (default: drumstroke's command line) with ``arguments`` in a subprocess; return (exit status,
    seconds).

    ``kill``: (name, part, k) for the :data:`HOOK`; ``delay``: SIGKILL from here after that many seconds.
    """
    environment = {**os.environ, "PYTHONPATH": str(Path(drumstroke.__file__).resolve().parents[1]),
                   "MPLBACKEND": "Agg"}
    started = time.monotonic()
    process = subprocess.Popen([sys.executable, "-c", program, kill[0], kill[1], str(kill[2]), count_file, *arguments],
                               env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    if delay is not None:
        try:
            process.wait(timeout=delay)
        except subprocess.TimeoutExpired:
            process.send_signal(signal.SIGKILL)
    _, errors = process.communicate(timeout=300)
    if process.returncode not in (0, -signal.SIGKILL):
        raise RuntimeError(f"{' '.join(arguments)} failed ({process.returncode}): {errors.decode()}")
    return process.returncode, time.monotonic() - started


def progress(message):
    print(message, file=sys.stderr, flush=True)


def digest(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _folder(command, workspace):
    return workspace / ("lib" if command == "library build" else "out")


def _bundle_records(folder):
    """The records of bundles in ``folder`` (drumstroke's temporaries ``….bundle``)."""
    return [name for name in os.listdir(folder) if name.endswith(".bundle") and describe_temporary(folder / name)]


def _size(path):
    if path.is_dir() and not path.is_symlink():
        return sum(p.stat().st_size for p in path.rglob("*") if p.is_file() and not p.is_symlink())
    return path.lstat().st_size


def table(result):
    lines = [(f"{'command':<14} {'kills':>5} {'time/call':>9} {'previous':>8} {'new':>5} {'completed':>9} "
              f"{'mix':>4} {'leftovers after kill':>22} {'debris after next run':>21}"),
             "-" * 104]
    for command, c in result["commands"].items():
        o = c["outcomes"]
        mix = sum(n for k, n in o.items() if k not in ("previous", "new", "completed by the next run"))
        leftovers = f"{c['kills_leaving_leftovers']} kills, {c['leftover_bytes'] / 1e6:.1f} MB"
        debris = f"{c['debris_after_next_run'][0]} files, {c['debris_after_next_run'][1]} B"
        lines.append(f"{command:<14} {c['kills']:>5} {c['kills_by_time']:>4}/{c['kills_by_call']:<4} "
                     f"{o.get('previous', 0):>8} {o.get('new', 0):>5} {o.get('completed by the next run', 0):>9} "
                     f"{mix:>4} {leftovers:>22} {debris:>21}")
    lines.append(f"{result['kills']} kills, {result['failures']} failures, {result['seconds']} s on "
                 f"{result['workers']} workers (seed {result['seed']})")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--kills", type=int, default=120)
    parser.add_argument("--seed", type=int, default=16)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        result = Campaign(folder, workers=args.workers).run(kills=args.kills, seed=args.seed)
    result["machine"] = f"{platform.platform()}, {os.cpu_count()} CPUs; python {platform.python_version()}"
    result["drumstroke"] = drumstroke.__version__
    result["date"] = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
    print(table(result))
    RESULTS.write_text(json.dumps(result, indent=1) + "\n")
    progress(f"wrote {RESULTS.relative_to(ROOT)}")
    return 1 if result["failures"] else 0


if __name__ == "__main__":
    sys.exit(main())
