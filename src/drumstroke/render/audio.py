"""Snare-drum audio from impacts: 48 kHz mono WAV (writing needs the ``audio`` extra: soundfile).

A drumstick striking an ideal circular membrane, plus snare wires. Every impact
i at time t_i (s) with tip speed v_i (m/s) sets each membrane mode k ringing::

    x_k(t) = G · v_i · W_k · H(f_k, τ_i) · exp(-(t - t_i) / T_k) · sin(2π f_k (t - t_i)),   t ≥ t_i

and the signal is the sum over impacts and modes, plus the snare noise below.

Modes
    The K = :data:`N_MODES` lowest modes (m, n) of an ideal circular membrane
    fixed at its rim, f_k = f_1 · j_mn / j_01, with j_mn the n-th zero of the
    Bessel function J_m (``scipy.special.jn_zeros``): ratios 1, 1.593, 2.136,
    2.295, 2.653, 2.917, … Each mode starts from rest (sin phase), so an impact
    adds no click.
Strike position
    W_k = |J_m(j_mn · r)| / Σ_k' |J_m'(j_m'n' · r)| at the strike radius r
    (fraction of the radius): the mode shape's amplitude where the stick lands,
    normalised so that moving the stick changes the timbre, not the level. A
    centre hit (r = 0) excites only the m = 0 modes.
Speed: louder and brighter
    The amplitude grows in proportion to v (fixed gain G = :data:`GAIN` per
    m/s). The contact lasts τ = τ_1 · (v / 1 m/s)^(-1/5) (Hertz's law of
    impact; τ_1 = ``Drum.contact_time``, 1 ms by default), and a half-sine
    force pulse of that duration weights mode k by its normalised magnitude
    spectrum H(f, τ) = |cos(π f τ) / (1 - (2 f τ)²)| (H(0) = 1, H = π/4 at
    f τ = 1/2, first zero at f τ = 3/2). Faster impacts are shorter, so high
    modes get more.
Decay
    T_k = T_1 · f_1 / f_k with T_1 = ``Drum.decay``: a constant quality factor
    Q = π f_1 T_1, so higher modes die faster.
Snare wires
    Band-limited noise: seeded white noise through a 4th-order Butterworth
    band-pass over :data:`SNARE_BAND` (2–9 kHz), scaled to unit RMS (divided by
    √(2 (f_hi - f_lo) / rate), the RMS of ideally band-passed unit white
    noise), times an envelope Σ_i G · s · v_i · exp(-(t - t_i) / T_s) with
    s = ``Drum.snare_level`` and T_s = ``Drum.snare_decay``. ``snares=False``
    adds exactly nothing.
Level
    The gain is fixed, so louder strokes make louder files. If the peak would
    exceed :data:`PEAK` (0.99 full scale), the whole signal is scaled down so
    that its peak is exactly :data:`PEAK`; a peak equal to :data:`PEAK` tells
    that this happened.
Timing
    Each mode and the snare envelope are one-pole recursions
    (``scipy.signal.lfilter``) driven by one weight per impact at the first
    sample at or after t_i; the weight carries the fraction of a sample, so the
    rendered decays start exactly at t_i.

>>> import numpy as np
>>> from drumstroke.render.audio import Drum, synthesize
>>> signal = synthesize([0.0, 0.25], [1.0, 0.5], duration=0.5, drum=Drum(position=0.2))
>>> signal.shape, signal.dtype
((24000,), dtype('float64'))
>>> bool(np.abs(signal).max() <= 0.99)
True
"""

from dataclasses import dataclass

import numpy as np
from scipy.signal import butter, lfilter, sosfilt
from scipy.special import jn_zeros, jv

from .._checks import check_int, check_real, check_vector
from ..budget import check_memory, synthesis_bytes
from ..errors import ParameterError, located
from ..formats.wav import audio_format, write_wav
from ..trajectory import LEVEL_REFERENCE

SAMPLE_RATE = 48000
"""Samples per second of the rendered audio (Hz)."""

N_MODES = 16
"""How many membrane modes sound."""

GAIN = 0.5
"""Amplitude per unit tip speed (full scale per m/s) of the modes and the snare envelope."""

PEAK = 0.99
"""Largest absolute sample value (full scale); louder signals are scaled down to it."""

SNARE_BAND = (2000.0, 9000.0)
"""Band of the snare-wire noise (Hz)."""

TAIL_DECAYS = 7.0
"""Default ring-out after the last impact, in fundamental decay times (7 T_1: −61 dB)."""



@dataclass(frozen=True)
class Drum:
    """A snare drum: membrane, strike position and snare wires.

    Attributes
    ----------
    fundamental : float in [20, 1000]
        Frequency of the (0, 1) mode (Hz).
    position : float in [0, 1)
        Strike radius as a fraction of the drum's radius (0 = centre).
    decay : float in (0, 10]
        Time for the fundamental to fall by 1/e (s); mode k takes decay · f_1 / f_k.
    contact_time : float in (0, 0.01]
        Duration of the stick's contact at a tip speed of 1 m/s (s); it scales as v^(-1/5).
    snares : bool
        Whether the snare wires sound.
    snare_level : float in [0, 10]
        RMS of the snare noise just after an impact, in units of G · v (dimensionless).
    snare_decay : float in (0, 1]
        Time for the snare noise to fall by 1/e after an impact (s).
    seed : int ≥ 0
        Seed of the snare noise, so renders are deterministic.
    """

    fundamental: float = 190.0
    position: float = 0.3
    decay: float = 0.25
    contact_time: float = 1e-3
    snares: bool = True
    snare_level: float = 0.3
    snare_decay: float = 0.06
    seed: int = 0

    def __post_init__(self):
        check_real("fundamental", self.fundamental, low=20.0, high=1000.0, unit="Hz")
        check_real("position", self.position, low=0.0, high=1.0, high_open=True)
        check_real("decay", self.decay, low=0.0, high=10.0, low_open=True, unit="s")
        check_real("contact_time", self.contact_time, low=0.0, high=0.01, low_open=True, unit="s")
        if not isinstance(self.snares, bool):
            raise ParameterError(f"snares must be True or False, got {self.snares!r}")
        check_real("snare_level", self.snare_level, low=0.0, high=10.0)
        check_real("snare_decay", self.snare_decay, low=0.0, high=1.0, low_open=True, unit="s")
        check_int("seed", self.seed, low=0)


def membrane_modes(count=N_MODES):
    """The ``count`` lowest modes of an ideal circular membrane, by frequency.

    Parameters
    ----------
    count : int ≥ 1
        How many modes.

    Returns
    -------
    ratios : ndarray [shape=(count,)]
        f_mn / f_01 = j_mn / j_01, increasing (dimensionless).
    orders : ndarray [shape=(count, 2)]
        (m, n) of each mode: m nodal diameters, n nodal circles counting the rim.

    >>> ratios, orders = membrane_modes(6)
    >>> [round(float(r), 3) for r in ratios]
    [1.0, 1.593, 2.136, 2.295, 2.653, 2.917]
    >>> orders.tolist()
    [[0, 1], [1, 1], [2, 1], [0, 2], [3, 1], [1, 2]]
    """
    check_int("count", count, low=1)
    # The count lowest zeros overall have m < count and n ≤ count.
    zeros = np.array([jn_zeros(m, count) for m in range(count)])
    m, n = np.unravel_index(np.argsort(zeros, axis=None, kind="stable")[:count], zeros.shape)
    return zeros[m, n] / zeros[0, 0], np.column_stack((m, n + 1))


def contact_time(tip_speed, *, reference=1e-3):
    """Duration of a Hertzian contact, τ = reference · (v / 1 m/s)^(-1/5) (s).

    Parameters
    ----------
    tip_speed : float or ndarray > 0
        Impact speed (m/s).
    reference : float > 0
        Contact duration at 1 m/s (s).

    >>> round(float(contact_time(32.0)), 6)
    0.0005
    """
    return reference * (np.asarray(tip_speed, dtype=float) / LEVEL_REFERENCE) ** -0.2


def half_sine_spectrum(frequency, duration):
    """|F(f)| / F(0) of a half-sine force pulse lasting ``duration``: |cos(π f τ) / (1 - (2 f τ)²)|.

    Parameters
    ----------
    frequency : float or ndarray ≥ 0
        Frequency (Hz).
    duration : float or ndarray > 0
        Length of the pulse (s); broadcasts against ``frequency``.

    >>> float(half_sine_spectrum(0.0, 1e-3)), round(float(half_sine_spectrum(500.0, 1e-3)), 6)
    (1.0, 0.785398)
    """
    ft = np.asarray(frequency, dtype=float) * np.asarray(duration, dtype=float)
    denominator = 1.0 - 4.0 * ft**2
    near_pole = np.abs(denominator) < 1e-9
    # At f τ = 1/2 numerator and denominator both vanish; the limit is π/4.
    return np.where(near_pole, np.pi / 4.0, np.abs(np.cos(np.pi * ft) / np.where(near_pole, 1.0, denominator)))


def synthesize(times, tip_speeds, *, duration=None, drum=Drum(), rate=SAMPLE_RATE):
    """Render impacts on ``drum`` as mono audio (see the module's docstring for the model).

    Parameters
    ----------
    times : array_like [shape=(n,)]
        Impact times (s), finite and ≥ 0, in any order; may be empty.
    tip_speeds : array_like [shape=(n,)]
        Tip speed of each impact (m/s), finite and ≥ 0.
    duration : float ≥ max(times) or None
        Length of the signal (s). Defaults to the last impact (0 if none) plus a
        ring-out of :data:`TAIL_DECAYS` · ``drum.decay``.
    drum : Drum
        The instrument.
    rate : float > 18000
        Samples per second (Hz); above twice the top of :data:`SNARE_BAND`.

    Returns
    -------
    signal : ndarray [shape=(round(duration · rate),), dtype=float64]
        Samples in [-0.99, 0.99] (full scale).

    >>> import numpy as np
    >>> signal = synthesize([0.0], [0.5], duration=0.1, drum=Drum(snares=False))
    >>> len(signal), round(float(np.abs(signal).max()), 3)
    (4800, 0.127)
    """
    times = check_vector("times", times, low=0.0, unit="s")
    tip_speeds = check_vector("tip_speeds", tip_speeds, low=0.0, unit="m/s")
    if len(times) != len(tip_speeds):
        raise ParameterError(f"times and tip_speeds must have the same length, got {len(times)} and {len(tip_speeds)}")
    if not isinstance(drum, Drum):
        raise ParameterError(f"drum must be a Drum, got {drum!r}")
    rate = check_real("rate", rate, low=2.0 * SNARE_BAND[1], low_open=True, unit="Hz")
    last = float(times.max()) if len(times) else 0.0
    if duration is None:
        duration = last + TAIL_DECAYS * drum.decay
    duration = check_real("duration", duration, low=last, unit="s")
    check_synthesis(duration, rate)
    return limit_peak(ring(times, tip_speeds, drum, rate=rate, size=round(duration * rate)))


def check_synthesis(duration, rate):
    """Refuse ``duration`` s of audio at ``rate`` Hz when synthesizing it asks for more memory than the budget's."""
    size = round(duration * rate)
    check_memory(f"synthesizing {duration:g} s of audio", synthesis_bytes(size), f"{size} samples at {rate:g} Hz")


def ring(times, tip_speeds, drum, *, rate, size):
    """The drum's ringing after impacts, before :func:`limit_peak`: :func:`synthesize` without its checks.

    For a caller that mixes several instruments and limits the mix's peak once
    (:mod:`drumstroke.render.kit_audio`). Arguments as :func:`synthesize`'s, already checked; ``size``
    is the number of samples (impacts at or after it are left out).
    """
    start = np.ceil(times * rate).astype(np.int64)
    inside = start < size
    start, offset = start[inside], start[inside] - times[inside] * rate
    amplitude = GAIN * tip_speeds[inside]
    if not len(start):
        return np.zeros(size)

    signal = _membrane(start, offset, amplitude, tip_speeds[inside], drum, rate, size)
    if drum.snares and drum.snare_level > 0.0:
        signal += _snare(start, offset, drum.snare_level * amplitude, drum, rate, size)
    return signal


def limit_peak(signal):
    """``signal`` scaled down in place so that its largest absolute sample is :data:`PEAK`, if it is above; returned."""
    peak = np.abs(signal).max(initial=0.0)
    if peak > PEAK:
        signal *= PEAK / peak
    return signal


def render_wav(path, times, tip_speeds, *, duration=None, drum=Drum(), rate=SAMPLE_RATE, bundle=None):
    """Synthesize impacts (see :func:`synthesize`) and write them as an audio file (see :func:`write_wav`).

    Parameters
    ----------
    path : str or os.PathLike
        Where to write: ``.wav``, ``.flac`` or ``.ogg`` (the format follows the extension).
    times : array_like [shape=(n,)]
        Impact times (s).
    tip_speeds : array_like [shape=(n,)]
        Tip speed of each impact (m/s).
    duration : float or None
        Length of the signal (s); defaults to the last impact plus a ring-out.
    drum : Drum
        The instrument.
    rate : int > 18000
        Samples per second (Hz).
    bundle : Bundle or None
        Put the file in place with this :class:`drumstroke._atomic.Bundle`'s others (default: at once).

    Returns
    -------
    signal : ndarray [shape=(round(duration · rate),)]
        The samples written, before 24-bit quantisation.

    >>> import pathlib, tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = pathlib.Path(folder) / "two.wav"
    ...     signal = render_wav(path, [0.0, 0.1], [1.0, 0.3], duration=0.2)
    ...     len(signal), path.stat().st_size  # a 44-byte header, then 3 bytes a sample
    (9600, 28844)
    """
    audio_format(path)  # before the work, not after it
    with located(f"audio file {str(path)!r}"):
        signal = synthesize(times, tip_speeds, duration=duration, drum=drum, rate=rate)
    write_wav(path, signal, rate=rate, bundle=bundle)
    return signal


def _membrane(start, offset, amplitude, tip_speeds, drum, rate, size):
    """Sum of the ringing modes: each a complex one-pole resonator fed one weight per impact."""
    ratios, orders = membrane_modes()
    frequencies = drum.fundamental * ratios
    shape = np.abs(jv(orders[:, 0], ratios * jn_zeros(0, 1)[0] * drum.position))
    shape /= shape.sum()
    # A resting stick (v = 0) is silent anyway; the floor only keeps its contact time finite.
    durations = contact_time(np.maximum(tip_speeds, 1e-12), reference=drum.contact_time)
    weights = amplitude[:, None] * shape * half_sine_spectrum(frequencies, durations[:, None])

    signal = np.zeros(size)
    for frequency, ratio, weight in zip(frequencies, ratios, weights.T):
        pole = (-ratio / drum.decay + 2j * np.pi * frequency) / rate
        signal += _ring(start, weight * np.exp(pole * offset), np.exp(pole), size).imag
    return signal


def _snare(start, offset, amplitude, drum, rate, size):
    """Band-passed, unit-RMS noise under an envelope that jumps at each impact and decays."""
    pole = -1.0 / (drum.snare_decay * rate)
    envelope = _ring(start, amplitude * np.exp(pole * offset), np.exp(pole), size)
    low, high = SNARE_BAND
    noise = np.random.default_rng(drum.seed).standard_normal(size)
    noise = sosfilt(butter(4, (low, high), btype="bandpass", fs=rate, output="sos"), noise)
    return envelope * noise / np.sqrt(2.0 * (high - low) / rate)


def _ring(start, weight, pole, size):
    """y[n] = x[n] + pole · y[n-1], with x the weights placed at samples ``start`` (summed where they share one)."""
    drive = np.zeros(size, dtype=np.result_type(weight, pole))
    np.add.at(drive, start, weight)
    return lfilter([1.0], [1.0, -pole], drive)
