"""Time the fit of a 30-impact stroke against the design and the simulation of it: ``python benchmarks/fit.py``.

Cases, on both models: five strokes under one constant force (seeded: height, force, c from 0.88 to
0.92, so that 30 or more impacts lie within 30 dB of the loudest); their first 30 impacts are the
onsets (exact times, levels re the loudest, the detection threshold between the 30th and the 31st).

- ``fit_stroke`` with c given, and with ``fit_cor`` (c and the offset searched);
- references in the same process: one ``design`` of the same notes at the true levels (the inverse
  the fit calls many times, once checked by the solver) and the forward simulation of the stroke's
  own recipe (``drumstroke.simulate``). Ratios are fit / reference: how many designs or simulations
  a fit costs.

Each time is the median over the five strokes of the median of 3 runs (warm-up excluded). Prints a
table and writes it, with the accuracy of each fit (largest residuals, offset and c errors), the
machine and the date, to benchmarks/fit_results.json.
"""

import json
import statistics
from pathlib import Path

import numpy as np
from _timing import machine, median_time, progress

import drumstroke
from drumstroke.analysis import Onsets, fit_stroke
from drumstroke.design import Setup, design

HERE = Path(__file__).resolve().parent
IMPACTS = 30
STROKES = 5
REPEATS = 3


def strokes(model, seed=20261125):
    """Five constant-force strokes with at least 31 impacts within 30 dB of the loudest, and their 30 onsets."""
    rng = np.random.default_rng(seed)
    found = []
    while len(found) < STROKES:
        recipe = drumstroke.Recipe(force=drumstroke.Constant(rng.uniform(0.0, 200.0)), model=model,
                                   theta0=rng.uniform(0.1, 0.6), cor=rng.uniform(0.88, 0.92), t_end=8.0)
        stroke = drumstroke.simulate(recipe)
        level = stroke.impacts.level_db
        if len(level) <= IMPACTS or level.max() > drumstroke.dynamics.CEILING_DB or level[IMPACTS] < level.max() - 30:
            continue
        relative = level - level.max()
        onsets = Onsets(stroke.impacts.t[:IMPACTS], relative[:IMPACTS],
                        threshold_db=(relative[IMPACTS - 1] + relative[IMPACTS]) / 2, source=f"{model} stroke")
        found.append((recipe, stroke, onsets))
    return found


def case(model):
    rows = {"fit (c given)": [], "fit (fit_cor)": [], "design": [], "simulate": []}
    accuracy = []
    for k, (recipe, stroke, onsets) in enumerate(strokes(model)):
        progress(f"  {model} stroke {k + 1}/{STROKES} ...")
        levels = stroke.impacts.level_db[:IMPACTS]
        cor = recipe.cor
        rows["fit (c given)"].append(median_time(lambda o=onsets, c=cor: fit_stroke(o, model=model, cor=c), REPEATS))
        rows["fit (fit_cor)"].append(median_time(lambda o=onsets: fit_stroke(o, model=model, fit_cor=True), repeats=1))
        rows["design"].append(median_time(lambda o=onsets, lv=levels, c=cor: design(o.t, lv, setup=Setup(model=model, cor=c)), REPEATS))
        rows["simulate"].append(median_time(lambda r=recipe: drumstroke.simulate(r), REPEATS))
        given = fit_stroke(onsets, model=model, cor=recipe.cor)
        fitted = fit_stroke(onsets, model=model, fit_cor=True)
        accuracy.append({"force": recipe.force.value, "cor": recipe.cor, "within": given.within and fitted.within,
                         "time_error": max(given.time_error, fitted.time_error),
                         "level_error": max(given.level_error, fitted.level_error),
                         "offset_error": abs(given.offset - levels.max()),
                         "offset_error_fit_cor": abs(fitted.offset - levels.max()),
                         "cor_error": abs(fitted.cor - recipe.cor)})
    medians = {name: statistics.median(values) for name, values in rows.items()}
    return {"model": model, "impacts": IMPACTS, "strokes": STROKES, "medians": medians,
            "fit_over_design": medians["fit (c given)"] / medians["design"],
            "fit_cor_over_design": medians["fit (fit_cor)"] / medians["design"],
            "fit_over_simulate": medians["fit (c given)"] / medians["simulate"], "accuracy": accuracy}


def main():
    results = [case(model) for model in drumstroke.MODELS]
    header = (f"{'model':<9} {'fit, c given':>13} {'fit, fit_cor':>13} {'design':>9} {'simulate':>9} "
              f"{'fit/design':>11} {'fit_cor/design':>15} {'fit/simulate':>13}  accuracy")
    lines = [header, "-" * len(header)]
    for row in results:
        m, acc = row["medians"], row["accuracy"]
        lines.append(
            f"{row['model']:<9} {m['fit (c given)'] * 1e3:>10.4g} ms {m['fit (fit_cor)'] * 1e3:>10.4g} ms "
            f"{m['design'] * 1e3:>6.3g} ms {m['simulate'] * 1e3:>6.3g} ms {row['fit_over_design']:>10.0f}x "
            f"{row['fit_cor_over_design']:>14.0f}x {row['fit_over_simulate']:>12.0f}x  residuals <= {max(a['time_error'] for a in acc):.1e} s, "
            f"{max(a['level_error'] for a in acc):.1e} dB; offset error <= {max(a['offset_error'] for a in acc):.1e} "
            f"dB ({max(a['offset_error_fit_cor'] for a in acc):.1e} with fit_cor); c error <= "
            f"{max(a['cor_error'] for a in acc):.1e}")
    print("\n".join(lines))
    print(f"\n* {STROKES} constant-force strokes per model, their first {IMPACTS} impacts as onsets; medians over the "
          "strokes of the median of 3 runs (fit_cor: 1 run).")
    (HERE / "fit_results.json").write_text(json.dumps({"machine": machine(), "rows": results}, indent=2) + "\n")


if __name__ == "__main__":
    main()
