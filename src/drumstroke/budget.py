"""Resource budgets: what an input asks for, estimated before the work, and refused beyond a stated budget.

A small file can ask for a lot: a WAV header can claim gigabytes of samples, four lines of recipe
an hour at a megahertz, an 81-byte sweep file ten million strokes. Every place where an input
sets how much is allocated or computed estimates it first, from the input alone, and calls
:func:`check_memory` or :func:`check_time`; beyond the budget the input is refused at once with
one line naming it, the estimate and the budget, and saying what raises the budget.

The budget in force is :func:`current`: :data:`DEFAULT_MEMORY_GB` of arrays and
:data:`DEFAULT_MINUTES` of work unless raised for a block of code by :func:`allowing` (the
command line's ``--budget-gb`` and ``--budget-minutes``, on every command). The estimates are
deliberately simple, counts times a size or a cost: memory as the values held times 8 bytes,
time as the items worked on times a cost measured on one core of a 2020s laptop; a budget is a
guard against an input asking for far more than it looks, not a precise forecast.

Examples
--------
>>> check_memory("rate", 8e9, "1e9 samples")
Traceback (most recent call last):
...
drumstroke.errors.ParameterError: rate asks for about 8 GB of memory (1e9 samples), over the budget of 1 GB (raise it with memory_gb)
>>> with allowing(Budget(memory_gb=16.0)):
...     check_memory("rate", 8e9, "1e9 samples")
>>> current().memory_gb
1.0
"""

import contextlib
import math
from contextvars import ContextVar
from dataclasses import dataclass

from ._checks import check_real
from .errors import ParameterError

DEFAULT_MEMORY_GB = 1.0
"""The memory an input may ask for by default (GB, 10⁹ bytes, of arrays)."""

DEFAULT_MINUTES = 10.0
"""The work an input may ask for by default (minutes, as estimated)."""

VALUE_BYTES = 8
"""Bytes of one number held (a float64)."""


@dataclass(frozen=True)
class Budget:
    """How much memory and time an input may ask for, and what raises each (for the messages).

    Attributes
    ----------
    memory_gb : float > 0
        GB (10⁹ bytes) of arrays.
    minutes : float > 0
        Minutes of work, as estimated.
    memory_option, minutes_option : str
        What raises each, as the refusals say it: the command line's option, or the field's name.
    """

    memory_gb: float = DEFAULT_MEMORY_GB
    minutes: float = DEFAULT_MINUTES
    memory_option: str = "memory_gb"
    minutes_option: str = "minutes"

    def __post_init__(self):
        object.__setattr__(self, "memory_gb", check_real(self.memory_option, self.memory_gb, low=0.0, low_open=True,
                                                         unit="GB"))
        object.__setattr__(self, "minutes", check_real(self.minutes_option, self.minutes, low=0.0, low_open=True,
                                                       unit="min"))


_DEFAULT = Budget()
_CURRENT = ContextVar("drumstroke_budget", default=None)  # None: the default budget


def current():
    """The budget in force (:class:`Budget`): the default, or the one :func:`allowing` set for this block."""
    return _CURRENT.get() or _DEFAULT


@contextlib.contextmanager
def allowing(budget):
    """``with allowing(Budget(memory_gb=4)):``: ``budget`` is in force inside the block (this thread, this task)."""
    if not isinstance(budget, Budget):
        raise ParameterError(f"budget must be a Budget, got {type(budget).__name__}")
    token = _CURRENT.set(budget)
    try:
        yield budget
    finally:
        _CURRENT.reset(token)


def check_memory(what, estimate, detail):
    """Refuse ``what`` (an input: a file, an option) when it asks for more than the budget's memory.

    Parameters
    ----------
    what : str or callable
        The input, as the message begins: ``"audio file 'a.wav'"``, ``"--rate"``.
    estimate : float
        Bytes it asks for.
    detail : str or callable
        What the estimate counts, for the message (``"225000000 frames of 8 channels"``).
        A callable (no arguments) gives the text, made only for the message: a check on every
        call of a hot path then costs no formatting.
    """
    budget = current()
    if estimate > budget.memory_gb * 1e9:
        what, detail = (what() if callable(what) else what), (detail() if callable(detail) else detail)
        raise ParameterError(f"{what} asks for about {_gb(estimate)} of memory ({detail}), over the budget of "
                             f"{_gb(budget.memory_gb * 1e9)} (raise it with {budget.memory_option})")


def check_time(what, seconds, detail):
    """Refuse ``what`` when the work it asks for is estimated at more than the budget's minutes (``seconds``: s)."""
    budget = current()
    if seconds > budget.minutes * 60.0:
        raise ParameterError(f"{what} asks for about {_minutes(seconds)} of work ({detail}), over the budget of "
                             f"{budget.minutes:g} min (raise it with {budget.minutes_option})")


def values_bytes(count):
    """Bytes of ``count`` numbers held (float64)."""
    return float(count) * VALUE_BYTES


# --- what each kind of input asks for ------------------------------------------------------------------------------

BREAK_VALUES = 3
"""Numbers held a breakpoint of a profile while its pieces are made: the parts', their concatenation, the sorted."""

SAMPLE_VALUES = 4
"""Numbers held a stick a sample of a trajectory (θ and ω, and the copies that put the sticks side by side)."""

CSV_SECONDS_PER_VALUE = 1.5e-6
"""Time to sample and write one number of a trajectory CSV (s; measured: some 1 µs to format, 0.5 to sample)."""

SWEEP_BYTES_PER_POINT = 8000
"""Memory one point of a sweep holds until its table is written (bytes; measured some 7 kB: its values, recipe, row)."""

SWEEP_SECONDS_PER_POINT = 2e-4
"""Time to simulate one point of a sweep (s; its strokes vary, some 0.2 ms on one core)."""

DROP_SECONDS_PER_TRIPLE = 2e-4
"""Time measure-cor spends on one candidate triple of onsets (s; matched to every onset of its sequence)."""


AUDIO_VALUES = 6
"""Numbers held a sample of audio while it is synthesized (a drive and its ring, complex, and the mix; measured some
40 bytes a sample at 48 kHz, a drum's or a kit's)."""

TRACK_VALUES = 6
"""Numbers a controller's run holds a control period of each joint: the angle, the speed, the torque and the loop's
working copies (measured: 60 s at 100 kHz with three controllers peaked at 1.13 GB, some 190 bytes a period)."""

TRACK_SECONDS_PER_STEP = 1e-5
"""Time to simulate one control period of one joint on the simple plant (s; measured 8 to 14 µs)."""


PLOT_BYTES_PER_POINT = 100
"""Memory a point of a curve drawn holds until the picture is written (bytes; its samples and the plotting library's
copies: measured 30 to 100)."""


def synthesis_bytes(samples):
    """Memory (bytes) of synthesizing ``samples`` samples of audio."""
    return values_bytes(samples * AUDIO_VALUES)


def track_cost(periods, *, joints=1, controllers=1):
    """Memory (bytes) and time (s) of playing ``periods`` control periods of ``joints`` joints with each of
    ``controllers`` controllers: the reference's samples, and each run's angles, speeds, torques and steps."""
    memory = samples_bytes(periods, joints) + values_bytes(periods * joints * controllers * TRACK_VALUES)
    return memory, periods * joints * controllers * TRACK_SECONDS_PER_STEP


def audio_bytes(frames, channels, working):
    """Memory (bytes) of an audio file's ``frames`` × ``channels`` samples as float64, and ``working`` copies of one channel."""
    return values_bytes(frames * (channels + working))


def samples_bytes(rows, sticks):
    """Memory (bytes) of ``rows`` samples of a trajectory of ``sticks`` sticks: the times, and each stick's."""
    return values_bytes(rows * (1 + SAMPLE_VALUES * sticks))


def csv_seconds(rows, columns):
    """Time (s) to sample and write a trajectory CSV of ``rows`` rows of ``columns`` numbers."""
    return rows * columns * CSV_SECONDS_PER_VALUE


def drop_seconds(triples):
    """Time (s) measure-cor takes over ``triples`` candidate triples of onsets."""
    return triples * DROP_SECONDS_PER_TRIPLE


def sweep_cost(points):
    """Memory (bytes) and time (s) of a sweep of ``points`` points."""
    return points * SWEEP_BYTES_PER_POINT, points * SWEEP_SECONDS_PER_POINT


def _gb(size):
    return f"{size / 1e9:.2g} GB" if size < 1e10 else f"{size / 1e9:.3g} GB"


def _minutes(seconds):
    minutes = seconds / 60.0
    return f"{minutes:.2g} min" if minutes < 100 else f"{math.floor(minutes):,} min"
