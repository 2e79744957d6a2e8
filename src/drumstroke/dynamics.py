"""Dynamic level ↔ MIDI velocity: one documented, monotonic map used both ways.

An impact's level is ``20·log10(tip speed / 1 m/s)`` dB (see
:attr:`drumstroke.Impacts.level_db`). MIDI velocity 1–127 is linear in that
level between :data:`FLOOR_DB` (velocity 1) and :data:`CEILING_DB` (velocity
127), about 0.38 dB a step: velocity 127 is a 4 m/s tip speed, 100 is 1.2 m/s,
64 is 0.26 m/s, 1 is 1.6 cm/s. Levels outside are clipped to 1 or 127.
Composition reads a note's velocity with :func:`velocity_to_level`; MIDI
rendering writes an impact's velocity with :func:`level_to_velocity`, so a
note composed at velocity v is written back as v.

Examples
--------
>>> level_to_velocity(velocity_to_level(100))
100
>>> round(velocity_to_level(127), 3), round(velocity_to_level(1), 3)
(12.041, -35.959)
"""

import math

import numpy as np

from ._checks import check_real
from .errors import ParameterError

CEILING_DB = 20.0 * math.log10(4.0)
"""Level (dB re 1 m/s tip speed) of MIDI velocity 127: a 4 m/s tip speed."""

FLOOR_DB = CEILING_DB - 48.0
"""Level (dB) of MIDI velocity 1, 48 dB below velocity 127."""


def velocity_to_level(velocity):
    """The level (dB re 1 m/s tip speed) a MIDI velocity stands for.

    Parameters
    ----------
    velocity : float in [1, 127]

    Returns
    -------
    float
        dB, from :data:`FLOOR_DB` to :data:`CEILING_DB`.
    """
    velocity = check_real("velocity", velocity, low=1.0, high=127.0)
    return FLOOR_DB + (velocity - 1.0) * (CEILING_DB - FLOOR_DB) / 126.0


FOOT_CEILING_DB = 17.0
"""Level (dB re 1 m/s beater head speed) of MIDI velocity 127 on a pedal: a hard kick.

Slow-motion video of a chain pedal measured 35-40 rad/s for a hard kick, 6.7-7.6 m/s at the 0.19 m
beater head: about 17 dB, 5 dB above a stick's velocity 127."""

FOOT_RANGE_DB = 24.0
"""dB from a pedal's velocity 127 down to its velocity 1 (half a stick's 48 dB)."""


def velocity_to_foot_level(velocity):
    """The level (dB re 1 m/s beater head speed) a MIDI velocity stands for on a pedal (the kick, the hi-hat's foot).

    Linear in the velocity, as :func:`velocity_to_level`, from :data:`FOOT_CEILING_DB` - :data:`FOOT_RANGE_DB`
    (velocity 1, -7 dB) to :data:`FOOT_CEILING_DB` (velocity 127, 17 dB), about 0.19 dB a step. Why its own
    map: a pedal's hard kick (17 dB) is above a stick's ceiling (12 dB), so the stick's map would leave the
    loudest kicks out; and the pedal's model keeps its timing within a few milliseconds of the exact gravity
    only down to about 0 dB, while under -10 dB the beater no longer reaches the head at all, so the range is
    halved to keep velocity 1 above that.

    Parameters
    ----------
    velocity : float in [1, 127]

    Returns
    -------
    float
        dB, from -7 to 17.

    Examples
    --------
    >>> velocity_to_foot_level(127), velocity_to_foot_level(1)
    (17.0, -7.0)
    """
    velocity = check_real("velocity", velocity, low=1.0, high=127.0)
    return FOOT_CEILING_DB - FOOT_RANGE_DB + (velocity - 1.0) * FOOT_RANGE_DB / 126.0


def level_to_velocity(level_db):
    """The MIDI velocity (int, 1–127) of an impact at ``level_db`` (dB re 1 m/s), or an array of them.

    Monotonic (non-decreasing) in the level; levels beyond the floor and the
    ceiling are clipped; −inf (a zero-speed impact) gives 1.
    """
    level = np.asarray(level_db, dtype=float)
    bad = np.isnan(level) | (level == np.inf)
    if np.any(bad):
        raise ParameterError(f"level_db must be a number in [-inf, inf) dB, got {float(level[bad].flat[0])!r}")
    with np.errstate(invalid="ignore"):
        steps = 1.0 + (level - FLOOR_DB) * 126.0 / (CEILING_DB - FLOOR_DB)
    velocity = np.clip(np.floor(steps + 0.5 + 1e-9), 1, 127).astype(int)
    return int(velocity) if velocity.ndim == 0 else velocity
