"""A one-note stroke's forces in one compiled call: the throw onto the note and the catch after it.

Most strokes a planner makes play one note (every live note but a buzz, a caught single offline): a
throw from rest (a standard throw of ``lead`` s, or from where the stick is held) under one force, the
impact, and the rebound caught at its apex under another. :func:`one_note` works out both forces, the
release and the catch in compiled code, by the operations :meth:`~drumstroke.design.chain._Plan.pieces`
makes in Python (the same doubles in the same order, so the same pieces to the bit): called from
Python, the closed forms' own compiled functions cost more to reach than to run.

What it refuses (a force out of range, a throw that does not fit) it leaves to the Python path, which
says why.
"""

import math

from .._jit import jit
from .flight import _solve_apex, height_time


@jit
def one_note(v, t1, held, s0, start_t, catch, lead, cor, head, top, low, high, k, gravity, k_thumb, ratio):
    """The pieces of a one-note stroke caught after its note, or NaNs where the Python path must say why not.

    Parameters
    ----------
    v : float
        rad/s, the note's speed at the head; ``t1`` (s) its time.
    held : bool
        Thrown from rest at ``s0`` (sin θ), held from ``start_t`` (s); else a standard throw of ``lead`` s.
    catch : float
        sin θ to catch the rebound at, NaN for the grip of the throw.
    cor, head, top, low, high
        The coefficient of restitution, sin θ at the head and at the highest, the force range's torque
        rates (s⁻²).
    k, gravity, k_thumb, ratio : float
        The model's coefficients and g (m/s²): a torque rate C = (k·g + k′·a)/ratio.

    Returns
    -------
    (float, float, float, float, float, float, float)
        The throw's duration (s) and force (m/s²), the release (s, the notes' timeline), the rest height
        (sin θ) of a standard throw, the catch's start and end (s, from the release) and force (m/s²).
    """
    nan = math.nan
    refused = (nan, nan, nan, nan, nan, nan, nan)
    kg = k * gravity
    slack = 1e-9 * max(abs(low), abs(high))
    if held:  # _Plan.held_throw
        if s0 <= head:
            return refused
        rate = v * v / (2.0 * (s0 - head))
        if not (low - slack <= rate <= high + slack):
            return refused
        duration = height_time(s0, head) / v
        release = t1 - duration
        if release < start_t - 1e-9:
            return refused
        height = s0
    else:  # _Plan.throw
        height = _solve_apex(lead, 0.0, v, head, head, top)
        rate = v * v / (2.0 * ((top if math.isnan(height) else height) - head))
        if rate > high:
            rate = high
        elif rate < low:
            rate = low
        if rate <= 0.0 or head + v * v / (2.0 * rate) > top + 1e-12:
            return refused
        height = head + v * v / (2.0 * rate)
        duration = height_time(height, head) / v
        release = t1 - duration
    force = (rate * ratio - kg) / k_thumb
    # _Plan.ending: caught at ``catch``, or with the grip of the throw (its force's torque rate)
    u = cor * v
    t_last = t1 - release
    if math.isnan(catch):
        grip = (kg + k_thumb * force) / ratio
        caught = max(grip, u * u / (2.0 * (top - head)), 1e-12)
        apex = head + u * u / (2.0 * caught)
    else:
        apex = catch
        caught = u * u / (2.0 * (apex - head)) if apex > head else math.inf
        if not (low - slack <= caught <= high + slack):
            return refused
    end = t_last + height_time(apex, head) / u
    return duration, force, release, height, t_last, end, (caught * ratio - kg) / k_thumb
