"""Buzz strokes: a multiple-bounce stroke of a given density and level envelope over a span.

A buzz (a press or closed roll's stroke) is many quick bounces of one stick. Here it is
designed like any other notes (:func:`~drumstroke.design.chain.design`): bounces at a
steady ``density`` (bounces per second; drummers play 15–40) from the span's start, the
first at ``level`` dB and each later one ``decay`` dB per second softer, and after the
last one the stick is pressed to rest (or caught) by the span's end.

Examples
--------
>>> roll = buzz(0.0, 0.5, velocity=90, density=30.0)
>>> len(roll.times), bool(roll.t_end <= 0.5), roll.end
(13, True, 'press')
"""

import numpy as np

from .._checks import check_real
from ..dynamics import velocity_to_level
from ..errors import ParameterError
from .chain import LEAD, design

DENSITY = 30.0
"""Default bounces per second of a buzz (human buzzes: 15–40)."""

DENSITY_RANGE = (1.0, 200.0)
"""Bounces per second a buzz may ask for."""


def buzz_times(start, end, density):
    """The bounce times (s) of a buzz from ``start`` to ``end`` at ``density`` per second: start + k/density < end."""
    return start + np.arange(int(np.ceil((end - start) * density - 1e-9))) / density


def buzz(start, end, *, level=None, velocity=None, density=DENSITY, decay=0.0, finish="press", start_state=None,
         setup=None, lead=LEAD):
    """Design a buzz from ``start`` to ``end`` (s): bounces at ``density`` per second, at rest (or caught) by ``end``.

    Parameters
    ----------
    start, end : float
        s; the span, ``end − start`` ≥ 2/density.
    level : float, optional
        dB re 1 m/s of the first bounce; or give ``velocity`` (MIDI 1–127).
    density : float in [1, 200]
        Bounces per second.
    decay : float in [0, 200]
        dB per second each bounce is softer than the first (0: even).
    finish : {"press", "catch"}
        Pressed to rest on the head, or caught at the last rebound's apex, by ``end``.
    start_state : Start, optional
        The stick's state before the first bounce (:func:`~drumstroke.design.chain.design`'s ``start``).
    setup : Setup, optional
        The model, c, the stick, the forces and the joint's limits (default ``Setup()``).
    lead : float in (0, 10]
        s, the throw's duration without a ``start_state``.

    Returns
    -------
    Design
        Its notes are the bounces; the last ones of the span are dropped until the finish fits.
    """
    start = check_real("start", start, low=-1e6, high=1e6, unit="s")
    end = check_real("end", end, low=start, high=start + 3600.0, low_open=True, unit="s")
    density = check_real("density", density, low=DENSITY_RANGE[0], high=DENSITY_RANGE[1], unit="bounces/s")
    decay = check_real("decay", decay, low=0.0, high=200.0, unit="dB/s")
    if finish not in ("press", "catch"):
        raise ParameterError(f"finish must be 'press' or 'catch', got {finish!r}")
    if (level is None) == (velocity is None):
        raise ParameterError("give the buzz's first level (dB) or its velocity (1-127), not both or neither")
    first = velocity_to_level(velocity) if velocity is not None else check_real("level", level, unit="dB")
    times = buzz_times(start, end, density)
    if len(times) < 2:
        raise ParameterError(f"a buzz of {density:g} bounces/s needs at least {2 / density:.4g} s, got "
                             f"{end - start:.4g} s from {start:g} to {end:g}")
    for count in range(len(times), 0, -1):
        designed = design(times[:count], first - decay * (times[:count] - start), start=start_state, end=finish,
                          setup=setup, lead=lead)
        if designed.t_end <= end:
            return designed
    raise ParameterError(f"the buzz cannot {finish} by {end:g} s")  # pragma: no cover - one bounce always fits
