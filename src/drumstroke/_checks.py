"""Input checks shared by every public entry point.

Each check raises :class:`~drumstroke.errors.ParameterError` with a message that
names the parameter, the value and the allowed range (and carries them as its
``parameter``, ``value`` and ``allowed``), and returns the value as a float so
callers can write ``x = check_real("x", x)``. A value too long to show
(an integer of 400 digits, a long text) is shown by its length:

>>> check_real("t_end", 10**400, low=1e-6, high=3600.0, unit="s")
Traceback (most recent call last):
...
drumstroke.errors.ParameterError: t_end must be in [1e-06, 3600] s, got an integer of 401 digits
"""

import difflib
import math
import sys
from numbers import Integral, Real

import numpy as np

from .errors import ParameterError

_FLOATS = (float, np.float64)


def check_real(name, value, *, low=-math.inf, high=math.inf, low_open=False, high_open=False, unit=""):
    """Return ``value`` as a finite float within [low, high] (ends open on request)."""
    # a float within range (the call on every hot path) passes without the slower checks of numbers.Real
    if (type(value) in _FLOATS and -math.inf < value < math.inf and (low < value if low_open else low <= value)
            and (value < high if high_open else value <= high)):
        return float(value)
    limits = (low, high, low_open, high_open, unit)
    if isinstance(value, bool) or not isinstance(value, Real):
        raise _refused(name, value, "must be a number in", shown(value), limits)
    try:
        number = float(value)
    except OverflowError:  # an integer beyond any float: out of every range
        raise _refused(name, value, "must be in", shown(value), limits) from None
    if not math.isfinite(number):
        raise _refused(name, value, "must be a finite number in", repr(number), limits)
    too_low = number <= low if low_open else number < low
    too_high = number >= high if high_open else number > high
    if too_low or too_high:
        raise _refused(name, value, "must be in", shown(value) if _is_long(value) else repr(number), limits)
    return number


def _refused(name, value, must, got, limits):
    """The error of a value out of its range, the range worded only now: a check that passes is on every hot path."""
    allowed = _range_text(*limits)
    return ParameterError(f"{name} {must} {allowed}, got {got}", parameter=name, value=value, allowed=allowed)


def check_vector(name, values, *, low=-math.inf, high=math.inf, unit=""):
    """Return ``values`` as a 1-D float array of finite numbers in [low, high]; a bad entry is named by index."""
    vector = as_vector(name, values)
    if len(vector):  # the usual case in two reductions: the least and the largest finite and in range (NaN is neither)
        least, largest = float(vector.min()), float(vector.max())
        if math.isfinite(least) and math.isfinite(largest) and low <= least and largest <= high:
            return vector
    bad = ~(np.isfinite(vector) & (vector >= low) & (vector <= high))
    if bad.any():
        i = int(np.argmax(bad))
        allowed = _range_text(low, high, False, False, unit)
        raise ParameterError(f"{name}[{i}] must be a finite number in {allowed}, got {float(vector[i])!r}",
                             parameter=name, value=values, allowed=allowed)
    return vector


def as_vector(name, values):
    """Return ``values`` as a 1-D float array (any values), or raise naming ``name``."""
    about = {"parameter": name, "value": values, "allowed": "a 1-D array of numbers"}
    try:
        vector = np.asarray(values, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"{name} must be a 1-D array of numbers, got {shown(values)}", **about) from None
    if vector.ndim != 1:
        raise ParameterError(f"{name} must be a 1-D array of numbers, got shape {vector.shape}", **about)
    return vector


def check_int(name, value, *, low, high=None, unit=""):
    """Return ``value`` as an int if it is an integer (not a bool) in [low, high] ([low, inf) without high)."""
    allowed = f"[{low}, {high}]" if high is not None else f"[{low}, inf)"
    allowed = f"{allowed} {unit}" if unit else allowed
    if isinstance(value, bool) or not isinstance(value, Integral) or value < low or (high is not None and value > high):
        raise ParameterError(f"{name} must be an integer in {allowed}, got {shown(value)}", parameter=name, value=value,
                             allowed=allowed)
    return int(value)


def check_choice(name, value, choices):
    """Return ``value`` if it is one of ``choices``."""
    if value not in choices:
        allowed = "one of " + ", ".join(repr(c) for c in choices)
        raise ParameterError(f"{name} must be {allowed}, got {shown(value)}", parameter=name, value=value,
                             allowed=allowed)
    return value


def check_keys(name, table, allowed):
    """Raise unless every key of the dict ``table`` (called ``name`` in the message) is in ``allowed``."""
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        keys = ", ".join(allowed)
        raise ParameterError(f"{name} has unknown key {unknown[0]!r}; allowed keys: {keys}", parameter=name,
                             value=unknown[0], allowed=f"the keys {keys}")


def closest(name, names, *, most=3):
    """The names in ``names`` most like ``name``, the likeliest first: a suggestion for a name not found.

    The names that contain ``name`` (three characters or more, case aside) come first, in their given
    order (a list shipped in order puts the plain ones first: ``paradiddle`` suggests
    ``single-paradiddle`` before ``flam-paradiddle``), at most ``most`` of them; when none does, the one
    most like it (a misspelling): the highest :class:`difflib.SequenceMatcher` ratio, at least 0.6 (as
    :func:`difflib.get_close_matches`), the first of equals.

    >>> closest("paradiddle", ["flam-tap", "single-paradiddle", "double-paradiddle", "flam-paradiddle"])
    ['single-paradiddle', 'double-paradiddle', 'flam-paradiddle']
    >>> closest("dubble", ["single", "double", "triple"]), closest("xyz", ["single"])
    (['double'], [])
    """
    names = [str(n) for n in names]
    key = str(name).lower()
    within = [n for n in names if len(key) >= 3 and key in n.lower()]
    if within:
        return within[:most]
    ratios = [difflib.SequenceMatcher(None, key, n.lower()).ratio() for n in names]
    best = max(range(len(names)), key=ratios.__getitem__, default=None)  # max keeps the first of equals
    return [names[best]] if best is not None and ratios[best] >= 0.6 else []


def did_you_mean(name, names):
    """`` (did you mean 'a', 'b' or 'c'?)`` with :func:`closest`'s names for ``name``, or an empty string."""
    close = [repr(n) for n in closest(name, names)]
    if not close:
        return ""
    return f" (did you mean {' or '.join([', '.join(close[:-1]), close[-1]] if len(close) > 1 else close)}?)"


def shown(value, *, most=80):
    """``repr(value)`` for a message, or its length when that is long: an integer's digits, a text's characters."""
    if _is_long(value):
        return f"an integer of {digits(int(value))} digits"
    if isinstance(value, str) and len(value) > most:
        return f"{value[:most // 2]!r}... ({len(value)} characters)"
    try:
        text = repr(value)
    except ValueError:  # it holds an integer too long to convert to text
        return f"a {type(value).__name__} holding an integer of over {sys.get_int_max_str_digits()} digits"
    return text if len(text) <= most else f"{text[:most]}... ({len(text)} characters)"


def digits(integer):
    """How many decimal digits ``integer`` has (exact up to 4000 digits, which Python converts to text; then estimated)."""
    if integer.bit_length() <= 13_000:
        return len(str(abs(integer)))
    return int(integer.bit_length() * math.log10(2)) + 1


def _is_long(value):
    """Whether ``value`` is an integer of more than 20 digits (shown by its length)."""
    return isinstance(value, Integral) and not isinstance(value, bool) and abs(int(value)) >= 10**20


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
