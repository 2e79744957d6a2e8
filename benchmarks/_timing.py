"""What the benchmark scripts share: a median of repeated runs and a progress line on stderr."""

import statistics
import sys
import time


def median_time(fn, repeats=7):
    """The median wall time (s) of ``repeats`` calls of ``fn``, after one warm-up call (numba's cache, imports)."""
    fn()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def progress(message):
    """Say what the script is doing, on stderr (the figures go to stdout)."""
    print(message, file=sys.stderr, flush=True)
