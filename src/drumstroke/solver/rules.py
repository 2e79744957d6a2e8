"""The solver's thresholds, in one place for the Python solver and the compiled kernels."""

import math

ZENO_SPEED = 1e-6
"""Launch speed (rad/s) below which the rest of a bounce sequence is summed, not simulated..."""

ZENO_HEIGHT = 1e-12
"""...provided the bounce also rises less than this (rad) above the head (it does unless C is tiny)."""

NEARLY_VERTICAL = 1e-9
"""Orbits with elliptic parameter m ≥ 1 − this come near the vertical: left to the Taylor path."""


def zeno_floor(a):
    """Launch speed (rad/s) below which a bounce is part of the Zeno tail, where A = C·cos θ_max = ``a`` (s⁻²)."""
    return min(ZENO_SPEED, math.sqrt(2.0 * ZENO_HEIGHT * a))
