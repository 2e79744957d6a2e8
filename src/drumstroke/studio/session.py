"""What every operation of the studio shares: the :class:`Studio` it runs in, the :class:`File` it may answer with,
and the checks of a request's JSON fields (each error names the field, the value and what is allowed)."""

import math
import threading
from dataclasses import dataclass, field
from itertools import pairwise
from pathlib import Path

from .._checks import shown
from ..errors import ParameterError


@dataclass
class Studio:
    """The studio's state across requests.

    Attributes
    ----------
    library : Path or None
        The library folder strokes are saved into and listed from (``drumstroke library build``'s files); None:
        the shipped palette only, and saving is refused.
    lock : threading.Lock
        Held while the library folder is written.
    """

    library: Path | None = None
    lock: threading.Lock = field(default_factory=threading.Lock, repr=False)


@dataclass(frozen=True)
class File:
    """An operation's answer that is a file: its bytes, media type and the name a download gives it."""

    data: bytes
    media_type: str
    filename: str


def fields(data, required=(), optional=(), *, what="the request"):
    """``data`` (a JSON object) checked to hold every ``required`` key and no key outside ``required`` and
    ``optional``; returns it."""
    if not isinstance(data, dict):
        raise ParameterError(f"{what} must be a JSON object, got {type(data).__name__}")
    known = (*required, *optional)
    for key in data:
        if key not in known:
            raise ParameterError(f"{what} has an unknown field {shown(key)}; its fields: {', '.join(known)}")
    for key in required:
        if key not in data:
            raise ParameterError(f"{what} needs the field {key!r}")
    return data


def number(data, key, *, low, high, unit="", default=None):
    """The finite number ``data[key]`` (or ``default`` when absent), in [low, high]."""
    value = data.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or not (
            low <= value <= high):
        unit = f" {unit}" if unit else ""
        raise ParameterError(f"{key} must be a number in [{low:g}, {high:g}]{unit}, got {shown(value)}")
    return float(value)


def numbers(data, key, *, low, high, unit="", most=10000, increasing=False):
    """The list of finite numbers ``data[key]`` in [low, high] (at most ``most``; strictly increasing if asked)."""
    values = data.get(key)
    if not isinstance(values, list) or len(values) > most:
        raise ParameterError(f"{key} must be a list of at most {most} numbers, got {shown(values)}")
    checked = [number({key: v}, key, low=low, high=high, unit=unit) for v in values]
    if increasing and any(b <= a for a, b in pairwise(checked)):
        raise ParameterError(f"{key} must be strictly increasing, got {shown(values)}")
    return checked


def choice(data, key, choices, *, default=None):
    """``data[key]`` (or ``default``), one of ``choices``."""
    value = data.get(key, default)
    if value not in choices:
        raise ParameterError(f"{key} must be one of {', '.join(map(str, choices))}, got {shown(value)}")
    return value


def text(data, key, *, most=100000, default=None):
    """The string ``data[key]`` (or ``default``), at most ``most`` characters."""
    value = data.get(key, default)
    if not isinstance(value, str) or len(value) > most:
        raise ParameterError(f"{key} must be text of at most {most} characters, got {shown(value)}")
    return value
