"""Time the live runtime, in one process: ``python benchmarks/live.py [--seconds 60]``.

Cases:

- **planning**: a note in to its stroke planned into the running motion (``Performer.note``'s compute
  time, median and p99; and the thread's CPU time of the whole call, its log row included, steadier
  on a shared host) over 3,000 notes of a random two-stick groove (gaps 60-250 ms, velocities
  20-127), on a manual clock with the setpoints taken as it goes, after ``warm_up`` (as a host's
  ``Runtime`` does). Reference: the offline planner (``plan_stick``) given the whole groove at once,
  per note. Target: p99 ≤ 0.2 ms (issue 30).
- **jitter**: ``Runtime`` on the system clock at 1 kHz for ``--seconds`` s (default 60) with a note
  every 125 ms (a score), setpoints to an OSC socket on loopback: how late each setpoint is sent
  against its time (median, p99, largest) and the CPU it takes (process time / wall time).
  Reference: the loop a host would write without drumstroke, ``time.sleep`` of the period, one
  setpoint a period. Target: p99 ≤ 0.2 ms on an idle host.

Prints a table and writes it with the machine and date to benchmarks/live_results.json.
"""

import argparse
import datetime
import json
import os
import platform
import socket
import sys
import time
from pathlib import Path

import numpy as np

import drumstroke
from drumstroke.design import Target, plan_stick
from drumstroke.dynamics import velocity_to_level
from drumstroke.live import ManualClock, Performer, Runtime
from drumstroke.live.inputs import Request
from drumstroke.live.outputs import OscOutput

HERE = Path(__file__).resolve().parent


def progress(message):
    print(message, file=sys.stderr, flush=True)


def groove(n, seed=1):
    rng = np.random.default_rng(seed)
    arrivals = np.cumsum(rng.uniform(0.06, 0.25, n))
    sticks = rng.choice(["right", "left"], n)
    velocities = rng.integers(20, 128, n)
    return arrivals, sticks, velocities


def planning_case(n=3000):
    arrivals, sticks, velocities = groove(n)
    clock = ManualClock()
    performer = Performer(clock=clock)
    performer.warm_up()
    compute, cpu = [], []
    for t, stick, velocity in zip(arrivals, sticks, velocities):
        clock.set(t)
        performer.setpoints(t)
        start = time.thread_time()
        compute.append(performer.note(str(stick), int(velocity)).compute)
        cpu.append(time.thread_time() - start)
    compute, cpu = np.array(compute) * 1e3, np.array(cpu) * 1e3
    planned = sum(o.planned for o in performer.log)
    # the reference: the offline planner, the whole groove known in advance
    start = time.perf_counter()
    for name in ("right", "left"):
        mine = sticks == name
        targets = [Target(float(t + 0.05), velocity_to_level(float(v))) for t, v in
                   zip(arrivals[mine], velocities[mine])]
        plan_stick(targets)
    offline = (time.perf_counter() - start) / n * 1e3
    return {"notes": n, "planned": int(planned), "median_ms": float(np.median(compute)),
            "p99_ms": float(np.percentile(compute, 99)), "max_ms": float(compute.max()),
            "cpu_median_ms": float(np.median(cpu)), "cpu_p99_ms": float(np.percentile(cpu, 99)),
            "cpu_max_ms": float(cpu.max()),
            "offline_planner_ms_per_note": offline}


def jitter_case(seconds):
    sink = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sink.bind(("127.0.0.1", 0))
    sink.setblocking(False)
    performer = Performer()
    runtime = Runtime(performer)
    output = OscOutput("127.0.0.1", sink.getsockname()[1])

    def drain(chunk):
        output(chunk)
        try:
            while True:
                sink.recv(65535)
        except BlockingIOError:
            pass

    runtime.outputs.append(drain)
    n = int((seconds - 1.0) / 0.125)
    rng = np.random.default_rng(2)
    runtime.schedule([Request(0.5 + 0.125 * i, "auto", int(v), source="bench") for i, v in
                      enumerate(rng.integers(30, 128, n))])
    cpu, wall = time.process_time(), time.perf_counter()
    runtime.run(duration=seconds)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    timing = runtime.timing()
    planned = sum(o.planned for o in performer.log)
    return {"seconds": seconds, "setpoints": timing["setpoints"], "notes": n, "planned": int(planned),
            "late_median_ms": timing["lateness_ms"]["median"], "late_p99_ms": timing["lateness_ms"]["p99"],
            "late_max_ms": timing["lateness_ms"]["max"], "late_over_1ms": timing["late_over_1ms"],
            "planning_p99_ms": timing["planning_ms"]["p99"] if timing["planning_ms"] else None,
            "cpu_percent": 100.0 * cpu / wall}


def naive_case(seconds):
    """time.sleep of one period, a setpoint a period: how late each is against its time."""
    period = 1e-3
    late = []
    zero = time.monotonic()
    k = 0
    while k * period < seconds:
        time.sleep(period)
        k += 1
        late.append(time.monotonic() - zero - k * period)
    late = np.array(late) * 1e3
    return {"late_median_ms": float(np.median(late)), "late_p99_ms": float(np.percentile(late, 99)),
            "late_max_ms": float(late.max())}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=60.0, help="length of the jitter run, s (default 60)")
    args = parser.parse_args()
    progress("planning 3,000 notes ...")
    planning = planning_case()
    progress(f"jitter over {args.seconds:g} s at 1 kHz ...")
    jitter = jitter_case(args.seconds)
    progress(f"reference: time.sleep of the period over {min(args.seconds, 10.0):g} s ...")
    naive = naive_case(min(args.seconds, 10.0))
    print(f"planning a live note ({planning['notes']} notes, {planning['planned']} planned): median "
          f"{planning['median_ms']:.3f} ms, p99 {planning['p99_ms']:.3f} ms, max "
          f"{planning['max_ms']:.2f} ms; the offline planner {planning['offline_planner_ms_per_note']:.3f} ms a note "
          f"({planning['median_ms'] / planning['offline_planner_ms_per_note']:.2f}x); in thread CPU time, the whole "
          f"note() with its log row: median {planning['cpu_median_ms']:.3f} ms, p99 {planning['cpu_p99_ms']:.3f} ms "
          f"(target <= 0.2 ms), max {planning['cpu_max_ms']:.2f} ms")
    print(f"setpoints sent late at 1 kHz over {jitter['seconds']:g} s ({jitter['setpoints']} setpoints, "
          f"{jitter['planned']}/{jitter['notes']} notes): median {jitter['late_median_ms']:.3f} ms, p99 "
          f"{jitter['late_p99_ms']:.3f} ms (target <= 0.2 ms), max {jitter['late_max_ms']:.2f} ms; CPU "
          f"{jitter['cpu_percent']:.0f}% of a core")
    print(f"reference, time.sleep of the period: median {naive['late_median_ms']:.3f} ms, p99 "
          f"{naive['late_p99_ms']:.3f} ms (drift grows: {naive['late_max_ms']:.1f} ms at the end)")
    results = {"machine": {"python": platform.python_version(), "cpus": os.cpu_count(),
                           "platform": platform.platform(), "drumstroke": drumstroke.__version__},
               "date": datetime.date.today().isoformat(), "planning": planning, "jitter": jitter,
               "reference_sleep": naive}
    (HERE / "live_results.json").write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
