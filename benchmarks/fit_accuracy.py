"""How well ``fit_stroke`` fits simulated strokes back: ``python benchmarks/fit_accuracy.py``.

The generator of tests/test_analysis_fit.py, larger: 80 random strokes (20 of each kind of force:
constant, low→high, high→low and pulsed, up to 250 m/s²; half on each model; c from 0.6 to 0.92; from
rest at 0.1–0.9 rad), their impacts above −30 dB re the loudest as onsets, every other stroke's
jittered by up to ±0.2 ms and ±0.3 dB (seeded). Each is fitted with its true c; the fitted recipe,
written to TOML, read back and simulated, must play every onset within 2 ms and 1 dB and make no other
impact at or above the threshold. Prints, per kind, the strokes (onsets), the fits that play every
onset so, the offset's error (the fitted offset less the stroke's loudest impact level: median and
largest, exact and jittered onsets apart), the largest residuals, and the designs beyond the human
thumb (a pull below 0 or a press over 250 m/s²); writes it with the machine and date to
benchmarks/fit_accuracy_results.json.
"""

import json
import sys
import tempfile
from pathlib import Path

import numpy as np
from _timing import machine, progress

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
import drumstroke
from drumstroke.analysis import fit_stroke
from drumstroke.design import HUMAN_FORCE
from test_analysis_fit import KINDS, onsets_of, replayed, stroke_of

STROKES = 20
SEED = 20261127


def plays(times, levels, onsets):
    """The largest |time| and |level| residuals of the onsets' nearest impacts, and the other impacts heard."""
    nearest = np.abs(times[None, :] - onsets.t[:, None]).argmin(axis=1)
    heard = np.ones(len(times), bool)
    heard[nearest] = False
    heard &= levels >= onsets.threshold_db
    return (float(np.max(np.abs(times[nearest] - onsets.t))), float(np.max(np.abs(levels[nearest] - onsets.level_db))),
            int(heard.sum()))


def run(kind, index, folder):
    rng = np.random.default_rng([SEED, KINDS.index(kind)])
    rows = []
    for case in range(STROKES):
        model = drumstroke.MODELS[case % 2]
        recipe, stroke = stroke_of(rng, kind, model)
        jittered = case % 4 >= 2
        onsets = onsets_of(stroke, rng if jittered else None)
        fit = fit_stroke(onsets, model=model, cor=recipe.cor)
        dt, dlevel, heard = plays(*replayed(fit, folder), onsets)
        rows.append({"kind": kind, "model": model, "jittered": jittered, "onsets": len(onsets),
                     "within": bool(dt <= 2e-3 and dlevel <= 1.0 and heard == 0 and not fit.unmatched),
                     "time_residual_s": dt, "level_residual_db": dlevel, "other_impacts_heard": heard,
                     "left_out": len(fit.unmatched), "offset_error_db": float(fit.offset - stroke.impacts.level_db.max()),
                     "min_force": fit.design.min_force, "max_force": fit.design.max_force})
        progress(f"  [{index}] {kind} {case + 1}/{STROKES}")
    return rows


def summary(rows):
    table = []
    for kind in KINDS:
        mine = [row for row in rows if row["kind"] == kind]
        errors = {jittered: np.abs([row["offset_error_db"] for row in mine if row["jittered"] == jittered])
                  for jittered in (False, True)}
        table.append({
            "kind": kind, "strokes": len(mine), "onsets": sum(row["onsets"] for row in mine),
            "within": sum(row["within"] for row in mine),
            "offset_exact_db": (float(np.median(errors[False])), float(errors[False].max())),
            "offset_jittered_db": (float(np.median(errors[True])), float(errors[True].max())),
            "largest_time_residual_s": max(row["time_residual_s"] for row in mine),
            "largest_level_residual_db": max(row["level_residual_db"] for row in mine),
            "pulls": sum(row["min_force"] < 0.0 for row in mine),
            "presses": sum(row["max_force"] > HUMAN_FORCE for row in mine)})
    return table


def main():
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for index, kind in enumerate(KINDS, start=1):
            rows += run(kind, index, Path(folder))
    table = summary(rows)
    print("| forces | strokes (onsets) | every onset within 2 ms and 1 dB | offset error from exact onsets: median "
          "(largest) | from jittered onsets | largest residuals | pull below 0 / press over 250 m/s^2 |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for row in table:
        print(f"| {row['kind']} | {row['strokes']} ({row['onsets']}) | {row['within']} | "
              f"{row['offset_exact_db'][0]:.2f} dB ({row['offset_exact_db'][1]:.2f}) | "
              f"{row['offset_jittered_db'][0]:.1f} dB ({row['offset_jittered_db'][1]:.1f}) | "
              f"{row['largest_time_residual_s']:.2g} s, {row['largest_level_residual_db']:.2g} dB | "
              f"{row['pulls']} / {row['presses']} |")
    out = HERE / "fit_accuracy_results.json"
    tmp = out.with_suffix(".json.tmp")
    tmp.write_text(json.dumps({"machine": machine(), "seed": SEED, "table": table, "strokes": rows}, indent=2) + "\n")
    tmp.replace(out)
    print(f"written: {out}")


if __name__ == "__main__":
    main()
