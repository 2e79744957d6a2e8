"""The 40 PAS rudiments, designed by the planner, played by the robot: the onsets it keeps.

Each rudiment at the bottom, the middle and the top of its tempo range, two bars on two sticks, is
composed by the planner (``paper`` model) and each stick's trajectory tracked by the impedance
controller (default gains) on the simple plant at 1 kHz. The onsets are scored as onset detection
is scored (drumstroke.robot.metrics: a maximum one-to-one matching within ±2 ms, the reference's
audible impacts against the played ones). Prints the worst rudiments and a Markdown table per family
and tempo (the README's), and writes benchmarks/rudiments_robot.json.

    python benchmarks/rudiments_robot.py [--controller impedance]
"""

import argparse
import json
import sys
import time
from pathlib import Path

from drumstroke.compose import compose, rudiment_score
from drumstroke.palette.rudiments import FAMILIES, rudiments
from drumstroke.robot.controllers import controller
from drumstroke.robot.metrics import metrics, pool
from drumstroke.robot.track import reference, track

HERE = Path(__file__).resolve().parent
TEMPI = ("bottom", "middle", "top")


def play(rudiment, where, law):
    """The ±2 ms scores of every stick of ``rudiment`` at its ``where`` tempo, and the tempo."""
    low, high = rudiment.tempo
    tempo = {"bottom": low, "middle": (low + high) / 2, "top": high}[where]
    score, _ = rudiment_score(rudiment.name, tempo, bars=2)
    piece = compose(score)
    scores = [metrics(track(reference(piece.sticks[stick]), law)).windows[0] for stick in piece.sticks]
    return tempo, scores, len(piece.problems)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--controller", default="impedance")
    args = parser.parse_args()
    law = controller(args.controller)
    started = time.monotonic()
    rows = []
    for rudiment in rudiments():
        for where in TEMPI:
            tempo, scores, problems = play(rudiment, where, law)
            pooled = pool(scores)
            rows.append({"number": rudiment.number, "name": rudiment.name, "family": rudiment.family, "where": where,
                         "tempo": tempo, "problems": problems, **pooled.to_dict()})
            print(f"{rudiment.number:>2} {rudiment.name:<28} {where:<6} {tempo:>5.0f} bpm: {pooled.matched:>3}/"
                  f"{pooled.matched + pooled.missed:<3} onsets within ±2 ms ({100 * pooled.recall:.1f} %), "
                  f"{pooled.extra} extra", file=sys.stderr, flush=True)
    lines = ["| family | tempo | rudiments | onsets | kept within ±2 ms | extra | timing \\|error\\| median / p95 (ms) "
             "| worst rudiment |", "|---|---|---|---|---|---|---|---|"]
    for family in FAMILIES:
        for where in TEMPI:
            chosen = [r for r in rows if r["family"] == family and r["where"] == where]
            onsets = sum(r["matched"] + r["missed"] for r in chosen)
            matched = sum(r["matched"] for r in chosen)
            worst = min(chosen, key=lambda r: r["recall"])
            median = max(r["timing_median"] for r in chosen)
            p95 = max(r["timing_p95"] for r in chosen)
            lines.append(f"| {family} | {where} | {len(chosen)} | {onsets} | {matched} ({100 * matched / onsets:.1f} %) "
                         f"| {sum(r['extra'] for r in chosen)} | ≤ {1e3 * median:.2f} / ≤ {1e3 * p95:.2f} | "
                         f"{worst['name']} at {worst['tempo']:g} bpm, {100 * worst['recall']:.1f} % |")
    onsets = sum(r["matched"] + r["missed"] for r in rows)
    matched = sum(r["matched"] for r in rows)
    lines.append(f"| all | all | {len(rows)} | {onsets} | {matched} ({100 * matched / onsets:.1f} %) | "
                 f"{sum(r['extra'] for r in rows)} | | |")
    print("\n".join(lines))
    print(f"\n{len(rows)} rudiment tempi in {time.monotonic() - started:.0f} s; every rudiment at least "
          f"{100 * min(r['recall'] for r in rows):.1f} %", file=sys.stderr)
    (HERE / "rudiments_robot.json").write_text(json.dumps({"controller": args.controller, "rows": rows}, indent=1)
                                               + "\n")


if __name__ == "__main__":
    main()
