"""A song's whole drum part on the kit, timed stage by stage: ``python benchmarks/kit.py [--rounds N] [--profile]``.

For two real General MIDI songs of tests/data/midi ("In Too Deep", 3.5 minutes of drums, 1,460 notes the
shipped kit answers; and the type-0 song d6caebd1…, 3.7 minutes, 590), in one process, each round:

- read: ``read_score(path, kit=kit)``, the drum part's notes on the kit's pieces;
- compose: ``compose_kit(score, kit)``, every limb assigned, every hand's runs planned on their pieces, the
  feet's presses designed;
- sample: ``KitComposition.sample()`` at 1 kHz, every joint of every limb;

and, alternating with them, a reference run: the scipy ``solve_ivp`` free bounce of ``benchmarks/reference.py``
(5 s at 1 kHz), the yardstick ``run.py`` measures the solver against. Each stage's figure is the median of the
rounds (the first, cold round excluded); its ratio is the median of the rounds' paired stage / reference times:
how many reference runs the stage costs, which stays put while this shared host's speed drifts. The target is
read + compose + sample ≤ 3 s per song on 2 cores.

``--profile`` adds cProfile's top costs of one round per song (by own time and by cumulative time) on stderr.
Prints a table and writes it with the machine and date to benchmarks/kit_results.json.
"""

import argparse
import cProfile
import io
import json
import pstats
import statistics
import sys
import time
from pathlib import Path

from _timing import machine, progress

import drumstroke
from drumstroke.compose import compose_kit
from drumstroke.kit.pieces import default_kit
from drumstroke.score import read_score

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from reference import reference_simulate

SONGS = [HERE.parent / "tests" / "data" / "midi" / name
         for name in ("In Too Deep.mid", "d6caebd1964d9e4a3c5ea59525230e2a.mid")]
TARGET = 3.0
"""s: read + compose + sample of a song's whole kit part, on 2 cores."""
STAGES = ("read", "compose", "sample")


def one_round(path, kit):
    """Each stage's wall time (s), and the composition."""
    times = {}
    start = time.perf_counter()
    score = read_score(path, kit=kit)
    times["read"] = time.perf_counter() - start
    start = time.perf_counter()
    piece = compose_kit(score, kit)
    times["compose"] = time.perf_counter() - start
    start = time.perf_counter()
    t, columns = piece.sample()
    times["sample"] = time.perf_counter() - start
    times["total"] = sum(times.values())
    return times, piece, len(t) * len(columns)


def reference_time(recipe):
    start = time.perf_counter()
    reference_simulate(recipe, rate=1000.0)
    return time.perf_counter() - start


def measure(path, kit, rounds, recipe):
    progress(f"{path.name}: a cold round, then {rounds} rounds, each with a reference run")
    one_round(path, kit)
    ours, references = [], []
    for _ in range(rounds):
        references.append(reference_time(recipe))
        times, piece, values = one_round(path, kit)
        ours.append(times)
    outcomes = piece.performance.outcomes
    row = {"song": path.name, "notes": len(outcomes), "played": sum(o.played for o in outcomes),
           "seconds": piece.t_end, "samples": values, "reference": statistics.median(references)}
    for stage in (*STAGES, "total"):
        row[stage] = statistics.median(t[stage] for t in ours)
        row[f"{stage}_ratio"] = statistics.median(t[stage] / r for t, r in zip(ours, references))
    row["target_met"] = row["total"] <= TARGET
    return row


def profile(path, kit, top=15):
    """cProfile's top ``top`` functions of one round, by own time and by cumulative time, as text."""
    profiler = cProfile.Profile()
    profiler.enable()
    one_round(path, kit)
    profiler.disable()
    text = io.StringIO()
    stats = pstats.Stats(profiler, stream=text).strip_dirs()
    stats.sort_stats("tottime").print_stats(top)
    stats.sort_stats("cumulative").print_stats(top)
    return text.getvalue()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rounds", type=int, default=5, help="timed rounds per song, after a cold one (default 5)")
    parser.add_argument("--profile", action="store_true", help="print cProfile's top costs of one round per song")
    args = parser.parse_args(argv)
    kit, recipe = default_kit(), drumstroke.preset("free-bounce")
    rows = [measure(path, kit, args.rounds, recipe) for path in SONGS]
    header = (f"{'song':<40} {'notes':>11} {'read':>8} {'compose':>8} {'sample':>8} {'total':>8} {'reference':>9}  "
              "total in reference runs")
    lines = [header, "-" * len(header)]
    for row in rows:
        lines.append(f"{row['song'][:40]:<40} {row['played']:>5}/{row['notes']:<5} "
                     + " ".join(f"{row[stage]:>7.3f}s" for stage in (*STAGES, "total"))
                     + f" {row['reference'] * 1e3:>6.1f} ms  {row['total_ratio']:.1f}"
                     + " (" + ", ".join(f"{s} {row[s + '_ratio']:.1f}" for s in STAGES) + ")")
    lines.append(f"target: read + compose + sample <= {TARGET:g} s per song: "
                 + ", ".join(f"{row['total']:.2f} s {'met' if row['target_met'] else 'MISSED'}" for row in rows))
    print("\n".join(lines))
    (HERE / "kit_results.json").write_text(json.dumps({"machine": machine(), "rounds": args.rounds,
                                                       "target_s": TARGET, "rows": rows}, indent=2) + "\n")
    if args.profile:
        for path in SONGS:
            print(f"\n=== cProfile, one round of {path.name} ===\n{profile(path, kit)}", file=sys.stderr)


if __name__ == "__main__":
    main()
