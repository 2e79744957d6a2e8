"""What the benchmark scripts share: a median of repeated runs, a progress line on stderr, the machine's description."""

import datetime
import platform
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


def machine():
    """The machine and versions a results file was measured with."""
    import numpy as np
    import scipy

    import drumstroke

    return {"date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
            "platform": platform.platform(), "processor": platform.processor(), "python": platform.python_version(),
            "numpy": np.__version__, "scipy": scipy.__version__, "drumstroke": drumstroke.__version__}


def progress(message):
    """Say what the script is doing, on stderr (the figures go to stdout)."""
    print(message, file=sys.stderr, flush=True)
