"""Input checks shared by every public entry point.

Each check raises :class:`~drumstroke.errors.ParameterError` with a message that
names the parameter, the value and the allowed range, and returns the value as
a float so callers can write ``x = check_real("x", x)``.
"""

import math
from numbers import Integral, Real

import numpy as np

from .errors import ParameterError


def check_real(name, value, *, low=-math.inf, high=math.inf, low_open=False, high_open=False, unit=""):
    """Return ``value`` as a finite float within [low, high] (ends open on request)."""
    if isinstance(value, bool) or not isinstance(value, Real):
        allowed = _range_text(low, high, low_open, high_open, unit)
        raise ParameterError(f"{name} must be a number in {allowed}, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        allowed = _range_text(low, high, low_open, high_open, unit)
        raise ParameterError(f"{name} must be a finite number in {allowed}, got {value!r}")
    too_low = value <= low if low_open else value < low
    too_high = value >= high if high_open else value > high
    if too_low or too_high:
        allowed = _range_text(low, high, low_open, high_open, unit)
        raise ParameterError(f"{name} must be in {allowed}, got {value!r}")
    return value


def check_vector(name, values, *, low=-math.inf, high=math.inf, unit=""):
    """Return ``values`` as a 1-D float array of finite numbers in [low, high]; a bad entry is named by index."""
    vector = as_vector(name, values)
    bad = np.flatnonzero(~(np.isfinite(vector) & (vector >= low) & (vector <= high)))
    if len(bad):
        i = int(bad[0])
        allowed = _range_text(low, high, False, False, unit)
        raise ParameterError(f"{name}[{i}] must be a finite number in {allowed}, got {float(vector[i])!r}")
    return vector


def as_vector(name, values):
    """Return ``values`` as a 1-D float array (any values), or raise naming ``name``."""
    try:
        vector = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a 1-D array of numbers, got {values!r}") from None
    if vector.ndim != 1:
        raise ParameterError(f"{name} must be a 1-D array of numbers, got shape {vector.shape}")
    return vector


def check_int(name, value, *, low, high=None, unit=""):
    """Return ``value`` as an int if it is an integer (not a bool) in [low, high] ([low, inf) without high)."""
    allowed = f"[{low}, {high}]" if high is not None else f"[{low}, inf)"
    allowed = f"{allowed} {unit}" if unit else allowed
    if isinstance(value, bool) or not isinstance(value, Integral) or value < low or (high is not None and value > high):
        raise ParameterError(f"{name} must be an integer in {allowed}, got {value!r}")
    return int(value)


def check_choice(name, value, choices):
    """Return ``value`` if it is one of ``choices``."""
    if value not in choices:
        listed = ", ".join(repr(c) for c in choices)
        raise ParameterError(f"{name} must be one of {listed}, got {value!r}")
    return value


def check_keys(name, table, allowed):
    """Raise unless every key of the dict ``table`` (called ``name`` in the message) is in ``allowed``."""
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise ParameterError(f"{name} has unknown key {unknown[0]!r}; allowed keys: {', '.join(allowed)}")


def _range_text(low, high, low_open, high_open, unit):
    left = "(" if low_open or low == -math.inf else "["
    right = ")" if high_open or high == math.inf else "]"
    text = f"{left}{_fmt(low)}, {_fmt(high)}{right}"
    return f"{text} {unit}" if unit else text


def _fmt(x):
    if x == math.inf:
        return "inf"
    if x == -math.inf:
        return "-inf"
    return f"{x:g}"
