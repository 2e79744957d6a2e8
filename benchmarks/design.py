"""Time the inverse design against a scipy shooting reference, in one process: ``python benchmarks/design.py``.

Cases:

- a diddle (two notes 100 ms apart at velocity 100), both models: ``drumstroke.design.design``
  against the reference a user would write without drumstroke: the flight's two forces (one up to
  the apex, one down) found by ``scipy.optimize.fsolve`` on a ``solve_ivp`` (DOP853) simulation with
  an apex event and a head event. Both are checked by simulating their forces with drumstroke.
- a one-second buzz at 30 bounces/s: ``drumstroke.design.buzz`` against the same reference run
  flight by flight.
- planning a 1,000-note two-stick piece (sixteenths at 120 bpm with accents, taps, diddles, flams
  and buzzes; sticks assigned by the planner): ``assign_sticks`` and ``plan_stick`` for each stick,
  and the trajectories sampled at 1 kHz. No reference: the targets are a diddle in 0.1 ms and the
  piece in 0.1 s on 2 cores.

Each case's wall time is the median of repeated runs; its CPU time (``cpu``) the least process time of
repeated runs (of 100 designs for a diddle), steadier than the wall time on a shared host. Prints a table
and writes it with the machine and date to benchmarks/design_results.json.
"""

import json
import sys
import time
from pathlib import Path

import numpy as np
from _timing import machine, median_time, progress

import drumstroke
from drumstroke.design import Setup, Target, assign_sticks, buzz, design, plan_stick
from drumstroke.dynamics import velocity_to_level

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from reference import reference_flight

STICK = drumstroke.Stick()


def cpu_time(fn, repeats=7, calls=1):
    """The least process time (s) of ``repeats`` runs of ``calls`` calls of ``fn``, per call, after one warm-up call."""
    fn()
    best = float("inf")
    for _ in range(repeats):
        start = time.process_time()
        for _ in range(calls):
            fn()
        best = min(best, (time.process_time() - start) / calls)
    return best


def diddle_case(model):
    times, velocities = [0.2, 0.3], [100, 100]
    levels = [velocity_to_level(v) for v in velocities]
    v = 10 ** (levels[1] / 20) / STICK.pivot_to_tip
    u = 0.86 * 10 ** (levels[0] / 20) / STICK.pivot_to_tip
    ours = median_time(lambda: design(times, levels, setup=Setup(model=model)))
    cpu = cpu_time(lambda: design(times, levels, setup=Setup(model=model)), calls=100)
    reference = median_time(lambda: reference_flight(0.1, u, v, model), repeats=3)
    made = design(times, levels, setup=Setup(model=model))
    up, down = reference_flight(0.1, u, v, model)
    rise, fall = [p.force for p in made.pieces if p.phase in ("rise", "fall")][:2]
    return {"case": f"diddle, 100 ms at velocity 100 ({model})", "ours": ours, "cpu": cpu, "reference": reference,
            "ratio": reference / ours, "time_error": made.time_error, "level_error": made.level_error,
            "force_difference": max(abs(up - rise), abs(down - fall))}


def buzz_case(model):
    ours = median_time(lambda: buzz(0.0, 1.0, velocity=90, density=30.0, setup=Setup(model=model)))
    made = buzz(0.0, 1.0, velocity=90, density=30.0, setup=Setup(model=model))
    level = velocity_to_level(90)
    v = 10 ** (level / 20) / STICK.pivot_to_tip

    def reference():
        for _ in range(len(made.times) - 1):
            reference_flight(1.0 / 30.0, 0.86 * v, v, model)

    reference_time = median_time(reference, repeats=1)
    return {"case": f"buzz, 1 s at 30/s ({model})", "ours": ours, "reference": reference_time,
            "ratio": reference_time / ours, "time_error": made.time_error, "level_error": made.level_error,
            "bounces": len(made.times)}


def piece(notes=1000, seed=20261124):
    """A two-stick part: sixteenths at 120 bpm, accents on beats, taps, diddles, flams, buzzes (seeded)."""
    rng = np.random.default_rng(seed)
    out, beat = [], 0.0
    while len(out) < notes:
        figure = rng.choice(["sixteenths", "accents", "diddles", "flam", "buzz", "rest"], p=[.3, .2, .2, .1, .1, .1])
        t = 0.5 + beat * 0.5
        if figure == "sixteenths":
            out += [(t + k * 0.125, beat + k / 4, 90, "auto") for k in range(4)]
        elif figure == "accents":
            out += [(t + k * 0.125, beat + k / 4, 120 if k == 0 else 50, "auto") for k in range(4)]
        elif figure == "diddles":
            out += [(t + k * 0.0625, beat + k / 8, 96, "auto") for k in range(8)]
        elif figure == "flam":
            out += [(t - 0.03, beat - 0.06, 50, "auto"), (t, beat, 115, "auto")]
        elif figure == "buzz":
            out += [(t + k * 0.125, beat + k / 4, 90, "buzz") for k in range(4)]
        beat += 1.0
    return out[:notes]


def plan_case(model):
    notes = piece()
    times = np.array([n[0] for n in notes])
    beats = np.array([n[1] for n in notes])

    def plan():
        sticks = assign_sticks(times, beats=beats)
        plans = {}
        for hand in ("right", "left"):
            chosen = [Target.from_velocity(t, v, kind=kind, duration=0.0625 if kind == "buzz" else None, key=k)
                      for k, ((t, _, v, kind), s) in enumerate(zip(notes, sticks)) if s == hand]
            plans[hand] = plan_stick(chosen, setup=Setup(model=model))
        end = times[-1] + 1.0
        return {hand: p.trajectory(t_end=end).theta for hand, p in plans.items()}, plans

    progress(f"  planning {len(notes)} notes ({model}) ...")
    start = time.perf_counter()
    plan()
    first = time.perf_counter() - start
    ours = median_time(lambda: plan(), repeats=3)
    cpu = cpu_time(lambda: plan(), repeats=5)
    _, plans = plan()
    problems = sum(len(p.problems) for p in plans.values())
    played = sum(sum(map(len, p.keys)) for p in plans.values())
    return {"case": f"plan a {len(notes)}-note two-stick piece ({model})", "ours": ours, "cpu": cpu, "reference": None,
            "ratio": None, "first_run": first, "played": played, "problems": problems}


def main():
    rows = []
    for model in drumstroke.MODELS:
        progress(f"diddle ({model})")
        rows.append(diddle_case(model))
        progress(f"buzz ({model})")
        rows.append(buzz_case(model))
        rows.append(plan_case(model))
    header = f"{'case':<48} {'ours':>10} {'CPU':>10} {'reference':>10} {'ratio':>8}  notes"
    lines = [header, "-" * len(header)]
    for row in rows:
        ref = "—" if row["reference"] is None else f"{row['reference'] * 1e3:.4g} ms"
        ratio = "—" if row["ratio"] is None else f"{row['ratio']:.0f}x"
        extra = (f"played {row['played']}, problems {row['problems']}" if "played" in row
                 else f"time error {row['time_error']:.1e} s, level error {row['level_error']:.1e} dB")
        cpu = f"{row['cpu'] * 1e3:.4g} ms" if "cpu" in row else "—"
        lines.append(f"{row['case']:<48} {row['ours'] * 1e3:>7.4g} ms {cpu:>10} {ref:>10} {ratio:>8}  {extra}")
    print("\n".join(lines))
    (HERE / "design_results.json").write_text(json.dumps({"machine": machine(), "rows": rows}, indent=2) + "\n")


if __name__ == "__main__":
    main()
