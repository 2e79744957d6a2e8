"""The solver's shared constants, in one place for the Python solver and the compiled kernels.

The arc kinds and the Taylor order are read by the kernels that write arcs and by
:mod:`.arcs`, which reads them; the thresholds by every kernel. Keeping them here,
below all of those modules, keeps the solver's imports one-way.
"""

import math

REST, ELLIPTIC, TAYLOR = 0, 1, 2
"""Kinds of arc: the stick at rest on the head; a closed-form flight; a Taylor step (see :mod:`.arcs`)."""

ARC_COLUMNS = 7
"""Columns of an arc's row: start, kind, three of the kind's numbers, and the state it starts from (see :mod:`.arcs`)."""

TAYLOR_ORDER = 24
"""Degree of the Taylor arcs' polynomials (the integrator's order)."""

ZENO_SPEED = 1e-6
"""Launch speed (rad/s) below which the rest of a bounce sequence is summed, not simulated..."""

ZENO_HEIGHT = 1e-12
"""...provided the bounce also rises less than this (rad) above the head (it does unless C is tiny)."""

NEARLY_VERTICAL = 1e-9
"""Orbits with elliptic parameter m ≥ 1 − this come near the vertical: left to the Taylor path."""


def zeno_floor(a):
    """Launch speed (rad/s) below which a bounce is part of the Zeno tail, where A = C·cos θ_max = ``a`` (s⁻²)."""
    return min(ZENO_SPEED, math.sqrt(2.0 * ZENO_HEIGHT * a))
