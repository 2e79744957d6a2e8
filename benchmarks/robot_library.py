"""The robot's figures over the whole shipped library (SPEC §5), as reported in the README.

Plays every library stroke on the simple plant with each controller: the paper's PI with
fixed gains, then PI tuned formally (one gain set for all; then one per stroke), PID with
feedforward, and the impedance controller. Prints a Markdown table and writes
benchmarks/robot_results.json.

    python benchmarks/robot_library.py [--evaluations N]
"""

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

from drumstroke.palette.library import build_library
from drumstroke.robot.controllers import controller
from drumstroke.robot.metrics import metrics
from drumstroke.robot.track import reference, track
from drumstroke.robot.tune import tune


def summary(name, scores):
    total = sum(m.reference_onsets for m in scores)
    kept = sum(m.kept for m in scores)
    tail_total = sum(m.reference_onsets - m.reference_onsets // 2 for m in scores)
    tail_kept = sum(round(m.tail_kept_fraction * (m.reference_onsets - m.reference_onsets // 2)) for m in scores)
    timing = np.concatenate([[m.timing_mean] for m in scores if m.kept])
    return {
        "controller": name,
        "kept": kept, "onsets": total, "kept_fraction": kept / total,
        "tail_kept_fraction": tail_kept / tail_total,
        "timing_mean_ms": 1e3 * float(np.mean(timing)),
        "timing_p95_ms": 1e3 * float(np.max([m.timing_p95 for m in scores if m.kept])),
        "shortfall_s": float(np.sum([m.tail_shortfall for m in scores])),
        "rms_rad": float(np.mean([m.rms_error for m in scores])),
        "peak_torque": float(max(m.peak_torque for m in scores)),
        "torque_limit": scores[0].torque_limit,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--evaluations", type=int, default=120)
    args = parser.parse_args()
    started = time.monotonic()
    library = build_library(tempfile.mkdtemp())
    refs = [reference(s.trajectory) for s in library.values()]
    rows = []
    pi = controller("pi")
    rows.append(summary("PI, fixed gains (the paper's)", [metrics(track(r, pi)) for r in refs]))
    shared = tune(refs, pi, evaluations=args.evaluations)
    rows.append(summary(f"PI tuned, one set ({shared.controllers[0].kp:.3g}, {shared.controllers[0].ki:.3g})",
                        shared.after))
    scheduled = tune(refs, shared.controllers[0], per_stroke=True, evaluations=args.evaluations // 2)
    rows.append(summary("PI tuned per stroke", scheduled.after))
    for name in ("pid-ff", "impedance"):
        c = controller(name)
        rows.append(summary(f"{name}, default gains", [metrics(track(r, c)) for r in refs]))
    print(f"{len(refs)} strokes, {rows[0]['onsets']} reference onsets; {time.monotonic() - started:.0f} s\n")
    print("| controller | onsets kept within ±2 ms | tail kept | timing mean / p95 (ms) | tail shortfall, sum (s) "
          "| RMS error (rad) | peak torque (N·m) |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['controller']} | {r['kept']}/{r['onsets']} ({100 * r['kept_fraction']:.1f} %) | "
              f"{100 * r['tail_kept_fraction']:.1f} % | {r['timing_mean_ms']:.2f} / {r['timing_p95_ms']:.2f} | "
              f"{r['shortfall_s']:.2f} | {r['rms_rad']:.4f} | {r['peak_torque']:.2f} / {r['torque_limit']:g} |")
    per_stroke = {r.name: {"pi": a.to_dict(), "impedance": metrics(track(r, controller("impedance"))).to_dict()}
                  for r, a in zip(refs, scheduled.after)}
    out = Path(__file__).with_name("robot_results.json")
    out.write_text(json.dumps({"rows": rows, "strokes": per_stroke}, indent=1) + "\n")
    print(f"\nwrote {out}")


if __name__ == "__main__":
    main()
