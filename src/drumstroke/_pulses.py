"""A pulse train's pieces, compiled (numba, cached on disk): :class:`drumstroke.profiles.Pulses` cut at its edges.

The same operations in the same order as the profile's numpy code (its breaks, their merging by
:func:`drumstroke.profiles.merge_edges`, its value just after each edge), so the same edges and values to the bit,
in one call instead of some forty numpy calls of a microsecond each on a few dozen numbers: every simulation of a
pulsed stroke cuts its forcing into pieces.
"""

import numpy as np

from ._jit import jit


@jit
def values(t, amplitude, period, phase, duty, base):
    """The pulse train at times ``t`` (s) [shape=(n,)]: ``Pulses.__call__``'s arithmetic, a time at a time."""
    out = np.empty(len(t))
    for i in range(len(t)):
        out[i] = _value(t[i], amplitude, period, phase, duty, base)
    return out


@jit(inline="always")
def _value(t, amplitude, period, phase, duty, base):
    k = np.floor((t - phase) / period)
    if t < phase + k * period:
        k -= 1.0
    if t >= phase + (k + 1.0) * period:
        k += 1.0
    start = phase + k * period
    return base + amplitude if t >= phase and t < start + duty * period else base


@jit
def pieces(amplitude, period, phase, duty, base, t_end, count, tol):
    """Edges (s) [shape=(n + 1,)] and the value after each left edge [shape=(n,)] of the train on [0, t_end].

    ``count`` pulses start before t_end (``Pulses._breaks``'s k = 0 … count − 1); edges closer than ``tol`` (s)
    are merged into the first, as :func:`drumstroke.profiles.merge_edges` merges them.
    """
    times = np.empty(2 * count + 2)
    times[0], times[1] = 0.0, t_end
    on = duty * period
    for k in range(count):
        rise = phase + float(k) * period
        times[2 + k], times[2 + count + k] = rise, rise + on
    times.sort()
    edges = np.empty(len(times))
    n = 0
    for edge in times:
        if 0.0 <= edge <= t_end and (n == 0 or edge != edges[n - 1]):
            if n > 0 and edge - edges[n - 1] <= tol:
                continue  # (kept edges are distinct, so a cluster is measured from its first edge, as there)
            edges[n] = edge
            n += 1
    edges = edges[:n].copy()
    edges[n - 1] = t_end
    left = edges[:n - 1]
    return edges, values(left + tol, amplitude, period, phase, duty, base)
