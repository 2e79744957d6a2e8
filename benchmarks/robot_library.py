"""The robot's figures over the whole shipped library, as reported in the README.

Plays every library stroke on the simple plant with every controller the package offers, at its
default gains — the paper's PI first — and with PI tuned formally (one gain set for all; then one per
stroke). Scores the onsets as onset detection is scored (drumstroke.robot.metrics: a maximum
one-to-one matching, mir_eval's) within ±2 ms and ±10 ms, pooled over the library, and the tracking.
Prints two Markdown tables (onsets; tracking) and writes benchmarks/robot_results.json.

    python benchmarks/robot_library.py [--evaluations N]
"""

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

from drumstroke.palette.library import build_library
from drumstroke.robot.controllers import CONTROLLERS, controller
from drumstroke.robot.metrics import WINDOWS, metrics, pool
from drumstroke.robot.track import reference, track
from drumstroke.robot.tune import tune


def summary(key, name, scores):
    """One row: the old fields (±2 ms, as before) and each window's scores pooled over the library."""
    total = sum(m.reference_onsets for m in scores)
    kept = sum(m.kept for m in scores)
    tail_total = sum(m.reference_onsets - m.reference_onsets // 2 for m in scores)
    tail_kept = sum(round(m.tail_kept_fraction * (m.reference_onsets - m.reference_onsets // 2)) for m in scores)
    timing = np.concatenate([[m.timing_mean] for m in scores if m.kept])
    return {
        "id": key,
        "controller": name,
        "kept": kept, "onsets": total, "kept_fraction": kept / total,
        "tail_kept_fraction": tail_kept / tail_total,
        "timing_mean_ms": 1e3 * float(np.mean(timing)),
        "timing_p95_ms": 1e3 * float(np.max([m.timing_p95 for m in scores if m.kept])),
        "shortfall_s": float(np.sum([m.tail_shortfall for m in scores])),
        "rms_rad": float(np.mean([m.rms_error for m in scores])),
        "peak_torque": float(max(m.peak_torque for m in scores)),
        "torque_limit": scores[0].torque_limit,
        "played": sum(m.played_onsets for m in scores),
        "windows": [pool(m.windows[w] for m in scores).to_dict() for w in range(len(WINDOWS))],
    }


def onset_table(rows):
    header = ("| controller | window | matched (recall) | extra | precision | F | timing \\|error\\| median / p95 (ms) "
              "| timing mean, played − reference (ms) | level \\|error\\| median / p95 (dB) |")
    lines = [header, "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        for k, w in enumerate(r["windows"]):
            lines.append(
                f"| {r['controller'] if not k else ''} | ±{1e3 * w['window']:g} ms | {w['matched']}/{r['onsets']} "
                f"({100 * w['recall']:.1f} %) | {w['extra']} | {100 * w['precision']:.1f} % | {w['f_measure']:.3f} | "
                f"{1e3 * w['timing_median']:.2f} / {1e3 * w['timing_p95']:.2f} | {1e3 * w['timing_mean_signed']:+.2f} | "
                f"{w['level_median']:.2f} / {w['level_p95']:.2f} |")
    return "\n".join(lines)


def tracking_table(rows):
    header = ("| controller | onsets played | tail kept (±2 ms) | tail shortfall, sum (s) | RMS error (rad) "
              "| peak torque (N·m) |")
    lines = [header, "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['controller']} | {r['played']} | {100 * r['tail_kept_fraction']:.1f} % | "
                     f"{r['shortfall_s']:.2f} | {r['rms_rad']:.4f} | {r['peak_torque']:.2f} / {r['torque_limit']:g} |")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--evaluations", type=int, default=120)
    args = parser.parse_args()
    started = time.monotonic()
    library = build_library(tempfile.mkdtemp())
    refs = [reference(s.trajectory) for s in library.values()]
    played = {name: [metrics(track(r, controller(name))) for r in refs] for name in CONTROLLERS}
    shared = tune(refs, controller("pi"), evaluations=args.evaluations)
    scheduled = tune(refs, shared.controllers[0], per_stroke=True, evaluations=args.evaluations // 2)
    gains = shared.controllers[0]
    rows = [summary("pi-fixed", "PI, fixed gains (the paper's)", played["pi"]),
            summary("pi-tuned", f"PI tuned, one set ({gains.kp:.3g}, {gains.ki:.3g})", shared.after),
            summary("pi-per-stroke", "PI tuned per stroke", scheduled.after)]
    rows += [summary(name, f"{name}, default gains", played[name]) for name in CONTROLLERS if name != "pi"]
    print(f"{len(refs)} strokes, {rows[0]['onsets']} reference onsets; {time.monotonic() - started:.0f} s\n")
    print(onset_table(rows) + "\n\n" + tracking_table(rows))
    strokes = {r.name: {"pi": a.to_dict(), "impedance": played["impedance"][k].to_dict(),
                        "pi-fixed": played["pi"][k].to_dict(), "pi-tuned": shared.after[k].to_dict(),
                        **{name: played[name][k].to_dict() for name in CONTROLLERS if name not in ("pi", "impedance")}}
               for k, (r, a) in enumerate(zip(refs, scheduled.after))}
    out = Path(__file__).with_name("robot_results.json")
    legend = {"pi": "PI tuned per stroke (the key's meaning before the others were added)", "pi-fixed": rows[0]["controller"],
              "pi-tuned": rows[1]["controller"], **{r["id"]: r["controller"] for r in rows[3:]}}
    out.write_text(json.dumps({"rows": rows, "strokes": strokes, "stroke_keys": legend}, indent=1) + "\n")
    print(f"\nwrote {out}")


if __name__ == "__main__":
    main()
