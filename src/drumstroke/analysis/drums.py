"""One drum of a kit: the onsets of a groove whose attack is the snare's, the kick's or the hi-hat's.

:func:`find_onsets` finds every impact in a recording; in a groove every drum is one. :func:`keep_drum`
keeps those whose attack is the chosen drum's, from two features of the signal around each onset:

- *Which band's attack is loudest.* Each drum of :data:`DRUM_BANDS` has a band where its attack's energy,
  over the first ``window`` s (30 ms), outweighs the other drums': the kick's fundamental below 100 Hz
  (a bass drum's head rings at 50–100 Hz), the snare's shell and batter-head body at 150–250 Hz (its
  lowest modes; the wires add noise at 2–8 kHz, which the hi-hat shares), the hi-hat's bright
  noise above 6 kHz (closed, it dies within tens of ms). These are the usual mixing engineers' bands
  (e.g. Owsinski, *The Mixing Engineer's Handbook*, the drums' frequency ranges) and hold on both
  General MIDI SoundFonts of the tests (FluidR3_GM, TimGM6mb). An onset where two drums meet (the snare
  and the hi-hat on a backbeat) counts as the one whose band is loudest: the snare on a backbeat, the
  kick on a downbeat, which is what a drummer would name.
- *Whether it is an attack at all.* The energy above 2 kHz (the stick's click, the wires, the cymbal)
  over the ``rise_window`` after the onset must exceed that over the ``rise_window`` before it by
  ``min_rise_db``: a new stroke's attack always does (a ghost note's too, by 5 dB or more), while
  onsets reported in a louder note's ringing or a sample's own re-trigger 100–140 ms later do not
  (their high band falls). Those are most of the snare-like onsets that are not notes.

Why a fixed profile and not clusters learned from the recording (k-means or a Gaussian mixture over the
onsets' features): a few bars hold a handful of onsets of a drum (a fill, a groove with a backbeat only),
too few for a stable cluster, and the mixtures (snare with hi-hat, kick with hi-hat) form clusters of
their own that a profile would still have to name. The band comparison is per onset, deterministic and
needs no count of drums. The decay time and the spectral centroid were not used: in a groove the next
hit (a sixteenth note is 115–170 ms at 90–130 bpm) cuts the snare's 100–200 ms decay before it can be
measured, and the centroid of a snare-with-hi-hat onset sits between the two drums'.

Examples
--------
>>> import numpy as np
>>> from drumstroke.analysis import Onsets
>>> rate = 48000
>>> t = np.arange(int(0.6 * rate)) / rate
>>> rng = np.random.default_rng(0)
>>> low = np.sin(2 * np.pi * 60 * t) * np.exp(-t / 0.1) * (t >= 0.1)   # a kick-like thump at 0.1 s
>>> hiss = rng.normal(size=t.size) * np.exp(-(t - 0.4) / 0.02) * (t >= 0.4)  # a hat-like burst at 0.4 s
>>> onsets = Onsets([0.1, 0.4], [0.0, -3.0])
>>> drum_of_onsets(low + 0.3 * hiss + 0.01 * (t >= 0.1) * rng.normal(size=t.size), rate, onsets).tolist()
['kick', 'hihat']
"""

from dataclasses import replace

import numpy as np

from .._checks import check_real, shown
from ..errors import ParameterError
from .onsets import Onsets

DRUM_BANDS = {"kick": (30.0, 100.0), "snare": (150.0, 250.0), "hihat": (6000.0, 16000.0)}
"""Each drum's band (Hz): where its attack's energy is the loudest of the three drums'."""

DRUMS = tuple(DRUM_BANDS)
"""The drums :func:`keep_drum` can keep."""

ATTACK_BAND = 2000.0
"""Hz: the attack's rise is measured above this (the click, the wires, the cymbal; not the ringing modes)."""


def drum_of_onsets(signal, rate, onsets, *, window=0.03, rise_window=0.01, min_rise_db=3.0):
    """Each onset's drum: the one of :data:`DRUMS` whose band's attack is loudest, or '' where no attack rises.

    Parameters
    ----------
    signal : ndarray [shape=(samples,)]
        The recording (mono, finite).
    rate : int in [8000, 384000]
        Samples per second (Hz); the hi-hat's band is cut at the Nyquist frequency.
    onsets : Onsets
        The onsets found in it (e.g. by :func:`drumstroke.analysis.find_onsets`), times within it.
    window : float in [0.005, 0.2]
        How long after each onset its band energies are summed (s).
    rise_window : float in [0.002, 0.05]
        The windows before and after an onset whose energies above :data:`ATTACK_BAND` are compared (s).
    min_rise_db : float in [-60, 60]
        How far the energy after an onset must rise over that before it for the onset to be an attack (dB).

    Returns
    -------
    drums : ndarray of str [shape=(n,)]
        'kick', 'snare', 'hihat', or '' (not an attack).
    """
    signal, rate, onsets = _checked(signal, rate, onsets)
    window = check_real("window", window, low=0.005, high=0.2, unit="s")
    rise_window = check_real("rise_window", rise_window, low=0.002, high=0.05, unit="s")
    min_rise_db = check_real("min_rise_db", min_rise_db, low=-60.0, high=60.0, unit="dB")
    starts = np.round(onsets.t * rate).astype(int)
    energies = np.array([_sums(_band_power(signal, rate, band), starts, round(window * rate))
                         for band in DRUM_BANDS.values()])
    attack = _band_power(signal, rate, (ATTACK_BAND, None))
    n = max(1, round(rise_window * rate))
    tiny = np.finfo(float).tiny
    rise = 10.0 * np.log10((_sums(attack, starts, n) + tiny) / (_sums(attack, starts - n, n) + tiny))
    drums = np.array(DRUMS)[np.argmax(energies, axis=0)] if len(onsets) else np.array([], dtype=str)
    return np.where(rise >= min_rise_db, drums, "")


def keep_drum(signal, rate, onsets, drum, **options):
    """The onsets whose attack is ``drum``'s (see the module's description); levels re the loudest kept.

    Parameters
    ----------
    signal, rate, onsets
        As :func:`drum_of_onsets`'s.
    drum : {'snare', 'kick', 'hihat'}
        The drum to keep.
    **options
        ``window``, ``rise_window``, ``min_rise_db``: as :func:`drum_of_onsets`'s.

    Returns
    -------
    Onsets
        The kept onsets, their levels shifted so the loudest kept is 0 dB (the threshold and the noise floor
        with them; their peaks, when they have them, so the loudest kept peak is 0 dB);
        ``info`` says which drum was kept, the shift (dB) and how many onsets there were.
    """
    if not isinstance(drum, str) or drum not in DRUM_BANDS:
        raise ParameterError(f"drum must be one of {', '.join(DRUMS)}, got {shown(drum)}", parameter="drum", value=drum)
    kept = drum_of_onsets(signal, rate, onsets, **options) == drum
    level = onsets.level_db[kept]
    shift = float(-level.max()) if len(level) else 0.0
    info = {**onsets.info, "drum": drum, "drum_level_shift_db": shift, "onsets_of_all_drums": len(onsets)}
    if info.get("floor_db") is not None:  # re the loudest onset, as the levels
        info["floor_db"] += shift
    peak = None if onsets.peak_db is None else onsets.peak_db[kept]
    if peak is not None and len(peak):
        peak = peak - peak.max()  # re the loudest kept, as the levels
    return replace(onsets, t=onsets.t[kept], level_db=level + shift, threshold_db=onsets.threshold_db + shift,
                   peak_db=peak, info=info)


def _checked(signal, rate, onsets):
    signal = np.asarray(signal, dtype=float)
    if signal.ndim != 1 or not signal.size or not np.all(np.isfinite(signal)):
        raise ParameterError(f"signal must be a non-empty 1-D array of finite samples, got shape {signal.shape}",
                             parameter="signal")
    rate = round(check_real("rate", rate, low=8000.0, high=384000.0, unit="Hz"))
    if not isinstance(onsets, Onsets):
        raise ParameterError(f"onsets must be an Onsets, got {type(onsets).__name__}", parameter="onsets")
    if len(onsets) and onsets.t[-1] * rate >= signal.size:
        raise ParameterError(f"onsets must lie within the signal's {signal.size / rate:.6g} s, got one at "
                             f"{float(onsets.t[-1])!r} s", parameter="onsets")
    return signal, rate, onsets


def _band_power(signal, rate, band):
    """The signal's power in ``band`` (low, high Hz; high None or past Nyquist: a high-pass)."""
    from scipy.signal import butter, sosfilt  # not needed to read or write onsets, nor by the command line's parser

    low, high = band
    if high is None or high >= 0.45 * rate:
        sos = butter(4, low, "highpass", fs=rate, output="sos")
    else:
        sos = butter(4, (low, high), "bandpass", fs=rate, output="sos")
    return sosfilt(sos, signal) ** 2


def _sums(power, starts, length):
    """``power`` summed over ``length`` samples from each of ``starts`` (clipped to the signal)."""
    total = np.concatenate([[0.0], np.cumsum(power)])
    return total[np.clip(starts + length, 0, power.size)] - total[np.clip(starts, 0, power.size)]
