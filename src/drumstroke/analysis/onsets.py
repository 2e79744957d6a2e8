"""A recording's impacts: when the stick struck the head and how loud, relative to the loudest.

Audio tells levels only up to one gain (the microphone's distance, the preamp): levels here are in
dB re the loudest onset (0 dB is the loudest, the others below). The model's levels are absolute (dB re
1 m/s tip speed, :mod:`drumstroke.dynamics`); a fit finds the offset (:mod:`.fit`).

Onsets go to and come from an onsets CSV (:mod:`drumstroke.formats.onsets_csv`: ``t,level_db``
rows, the source and threshold in the JSON beside it): :func:`write_onsets`, :func:`read_onsets`.

Examples
--------
>>> import pathlib, tempfile
>>> path = pathlib.Path(tempfile.mkdtemp()) / "onsets.csv"
>>> write_onsets(path, Onsets([0.1, 0.35], [0.0, -4.5], threshold_db=-40.0, source="drop.wav"))
>>> read_onsets(path)
Onsets(2 over [0.1, 0.35] s, levels -4.5 to 0 dB; drop.wav)
>>> read_onsets(path).threshold_db
-40.0
"""

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .._checks import check_int, check_real, check_vector
from ..errors import ParameterError
from ..formats.onsets_csv import read_onsets_csv, write_onsets_csv


@dataclass(frozen=True, repr=False)
class Onsets:
    """The impacts found in one recording (or given as times and levels).

    Attributes
    ----------
    t : ndarray [shape=(n,)]
        Onset times (s from the recording's start), finite, ≥ 0, strictly increasing.
    level_db : ndarray [shape=(n,)]
        Each onset's level (dB re the loudest onset: ≤ 0, finite; the loudest is 0).
    threshold_db : float
        The detection threshold used (dB re the loudest onset; onsets below it are not reported), or
        -inf when the onsets were given rather than detected.
    source : str
        What they came from (a file's name, or a description).
    """

    t: np.ndarray
    level_db: np.ndarray
    threshold_db: float = -np.inf
    source: str = ""
    info: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        t = check_vector("onset times t", self.t, low=0.0, unit="s")
        level = check_vector("onset levels level_db", self.level_db, high=0.0, unit="dB")
        if len(t) != len(level):
            raise ParameterError(f"onset times and levels must be as many, got {len(t)} times and {len(level)} levels")
        if len(t) > 1 and not np.all(np.diff(t) > 0.0):
            i = int(np.flatnonzero(np.diff(t) <= 0.0)[0]) + 1
            raise ParameterError(f"onset times t must be strictly increasing, got t[{i}] = {t[i]!r} after {t[i - 1]!r} s")
        if len(level) and level.max() != 0.0:
            raise ParameterError(f"onset levels level_db must be re the loudest (its level 0 dB), got a largest of "
                                 f"{level.max()!r} dB")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "level_db", level)

    def __len__(self):
        return len(self.t)

    def __repr__(self):
        if not len(self):
            return f"Onsets(none{'; ' + self.source if self.source else ''})"
        return (f"Onsets({len(self)} over [{self.t[0]:.6g}, {self.t[-1]:.6g}] s, levels {self.level_db.min():.3g} to "
                f"0 dB{'; ' + self.source if self.source else ''})")

    @classmethod
    def from_impacts(cls, impacts, *, source=""):
        """The onsets of a simulated stroke: its impacts' times and levels re the loudest (exact, no threshold).

        Parameters
        ----------
        impacts : drumstroke.trajectory.Impacts
            E.g. ``stroke.impacts`` of a :class:`drumstroke.Stroke`; impacts at zero speed are left out.
        source : str
            What they came from (a recipe's name).
        """
        level = impacts.level_db
        audible = np.isfinite(level)
        level = level[audible]
        return cls(impacts.t[audible], level - level.max() if len(level) else level, source=source)

    @property
    def intervals(self):
        """Times between successive onsets (s) [shape=(n - 1,)]."""
        return np.diff(self.t)

    def bounce_rate(self):
        """The bounce rate: 1 / each interval (Hz), at the interval's midpoint (s) [each shape=(n - 1,)].

        Returns
        -------
        midpoints, rate : ndarray
        """
        intervals = self.intervals
        return self.t[:-1] + intervals / 2.0, 1.0 / intervals


def write_onsets(path, onsets):
    """Write ``onsets`` to the onsets CSV at ``path`` (``t,level_db``) and the JSON beside it, atomically.

    The JSON holds the source, the detection threshold (dB re the loudest; null when the onsets
    were given) and ``info`` (how they were found).

    Parameters
    ----------
    path : str or os.PathLike
        Ending in ``.csv``, in an existing folder.
    onsets : Onsets
    """
    if not isinstance(onsets, Onsets):
        raise ParameterError(f"onsets must be an Onsets, got {type(onsets).__name__}")
    write_onsets_csv(path, onsets.t, onsets.level_db,
                     fields={"source": onsets.source, "threshold_db": onsets.threshold_db, "info": onsets.info})


def read_onsets(path, *, threshold_db=None, min_interval=None):
    """The onsets of the file at ``path``: an onsets CSV as written, or found in a recording.

    Parameters
    ----------
    path : str or os.PathLike
        An onsets CSV (``.csv``: ``t,level_db``, :func:`write_onsets`; its source and threshold
        from the JSON beside it when there is one, else the file's name and -inf), or an audio
        file soundfile reads (WAV, FLAC, OGG, …), whose impacts are found by :func:`find_onsets`
        (several channels are mixed down; ``info`` says so, and how many samples are clipped).
    threshold_db : float in [-120, 0] or None
        dB re the loudest onset, for a recording (default :data:`DEFAULT_THRESHOLD_DB`).
    min_interval : float in [0.5e-3, 1] or None
        s, for a recording (default :data:`MIN_INTERVAL`).

    Returns
    -------
    Onsets

    Raises
    ------
    ParameterError
        Naming the file (and the line) of what it refuses.
    """
    path = Path(path)
    if path.suffix.lower() != ".csv":
        signal, rate, notes = read_recording(path)
        return find_onsets(signal, rate, source=path.name, notes=notes,
                           threshold_db=DEFAULT_THRESHOLD_DB if threshold_db is None else threshold_db,
                           min_interval=MIN_INTERVAL if min_interval is None else min_interval)
    t, level_db, meta = read_onsets_csv(path)
    info = meta.get("info")
    try:
        return Onsets(t, level_db, threshold_db=meta.get("threshold_db", -np.inf),
                      source=str(meta.get("source") or path.name), info=info if isinstance(info, dict) else {})
    except ParameterError as error:
        raise ParameterError(f"onsets file {str(path)!r}: {error}") from None

# ------------------------------------------------------------------------------------------ onsets from audio

MIN_RATE = 8000
"""The lowest sample rate analysed (Hz)."""

MAX_SECONDS = 600.0
"""The longest recording analysed (s); a longer file is refused before it is read."""

DEFAULT_THRESHOLD_DB = -40.0
"""The default detection threshold (dB re the loudest onset)."""

FLOOR_MARGIN_DB = 10.0
"""How far above the noise floor an onset's level must be (dB): the threshold used is at least floor + this."""

MIN_INTERVAL = 2e-3
"""The default shortest time between two onsets (s): closer attacks are one."""

MIN_JUMP = 2.0
"""How much an attack's sound must rise over what the sound before it predicts (RMS ratio, 6 dB)."""

BROADBAND_JUMP = 3.0
"""How much the first difference's RMS must rise at a broadband attack (over 1 ms, against the 4 ms before)."""

TONAL_SUPPORT = 1.6
"""How much the innovation must rise too at a broadband attack (beating modes make broadband jumps alone)."""

STRONG_RISE = 10.0
"""How many times step 2's innovation rises at a tonal onset whose change point is trusted over a broadband
onset of the same group more than :data:`DISAGREE` away (the modes' beating makes broadband jumps too)."""

DISAGREE = 0.5e-3
"""s: how far apart a group's broadband and tonal times may be and still be one attack's."""

MODES_RATE = 2000
"""The rate (Hz) to which the modes' band is decimated (its anti-alias corner at 0.4 of it: below the snare wires)."""

MODES_WIDTH = 4
"""The shortest window (samples) of the modes' band's jumps (2 ms at 2 kHz)."""

MODES_ORDER = 40
"""The modes' band predictor's order."""

LEVEL_ORDER = 24
"""The order of the predictor in the band levels are measured in (the lowest modes: up to 2.1 times the lowest strong one)."""

SIGNATURE = 50e-3
"""How long an attack's signature in the modes' band's innovation lasts (s): the spike, the beating, first reflections."""

HEAD = 6
"""The samples after the spike that tell whether an onset's start looks like the signature."""

TAIL = 0.15
"""How long the attacks' common response taken off past the signature lasts (s): the room's tail, fitted by least
squares over all the first onsets (each scaled by its signature's fit), so overlapping neighbours average out."""

ROOM = 0.03
"""The least energy of the room's tail past the signature (a fraction of the signature's part) that makes a recording
reverberant: its levels are then measured with the earlier onsets' tails taken off (step 5). Measured: 0.11-0.14 in the
tests' room, under 0.01 without it."""

TAIL_RIDGE = 0.01
"""The ridge on that least-squares fit (a fraction of its normal equations' diagonal)."""

SECOND_GAP = 2.0
"""How far (in multiples of ``min_interval``) a second round's onset in the modes' band must be from the onsets
known before it."""

LIKENESS = 0.7
"""The least correlation of an onset's start with the signature's for an onset found in the modes' band alone."""

WEAK_LIKENESS = 0.5
"""A likeness to the signature that makes an onset an attack when step 2's innovation rises :data:`WEAK_RISE` times
at it."""

WEAK_RISE = 1.6
"""The rise of step 2's innovation that, with :data:`WEAK_LIKENESS`, makes an onset an attack (a quiet one in a
room's tail)."""

SURE_LIKENESS = 0.9
"""A likeness to the signature that makes an onset an attack with a jump of only :data:`SURE_JUMP`."""

SURE_JUMP = 1.5
"""The least jump of the remainder at an onset whose start is almost the signature (:data:`SURE_LIKENESS`)."""

MOVED_JUMP = 3.0
"""The least jump of the remainder where an onset in a room's tail that does not look like the signature is tried
again (a little later: step 4)."""

MOVE_REACH = 3.0
"""How far after it (in multiples of ``min_interval``) such an onset is tried again."""

AFTER_REACH = 40e-3
"""How far after an attack (s) a quiet one is sought by fitting its whole signature (the end of step 4)."""

AFTER_F = 8.0
"""The least F statistic (two parameters, over the louder attack's signature) of such a quiet attack's fit."""

AFTER_WEAK_F = 6.0
"""The lower F statistic enough for a quiet attack whose start looks half like the signature (:data:`WEAK_LIKENESS`)."""

AFTER_RATIO = (0.35, 1.5)
"""The range of such a quiet attack's scale over the louder one's (a bouncing stick's next impact: a few dB quieter)."""

AFTER_ROUNDS = 3
"""The most times that search runs (each with the attacks it found taken off too), while it finds more."""

ORDER = 48
"""The linear predictor's order: up to 20 ringing modes and the anti-alias filter's 8 poles."""

CLIP_LEVEL = 0.999
"""Samples at or above this magnitude (full scale) count as clipped."""

HIGH_PASS = 60.0
"""Corner of the high-pass (Hz) that removes rumble and DC before anything else."""

_FLOOR_QUANTILE = 0.05
_BLOCK = 1 << 20  # samples a block when looking for jumps
_SPECTRA = 4096  # the most frames whose spectra choose the decimation


def read_recording(path, *, max_seconds=MAX_SECONDS):
    """A recording's mono samples (full scale, float64), rate (Hz) and what was done to read it.

    Parameters
    ----------
    path : str or os.PathLike
        An audio file soundfile reads (WAV, FLAC, OGG, AIFF, …), any channel count.
    max_seconds : float
        The longest file read (s); checked from the file's header before reading.

    Returns
    -------
    signal : ndarray [shape=(n,)]
        The channels' mean when there are several ("mixed down").
    rate : int
        Hz.
    notes : dict
        ``channels`` (int), ``mixed_down`` (bool), ``clipped`` (how many samples of the file
        are at or above :data:`CLIP_LEVEL` full scale).
    """
    from ..formats.wav import read_audio

    samples, rate = read_audio(path, max_seconds=max_seconds)
    channels = samples.shape[1]
    clipped = int(np.count_nonzero(np.abs(samples) >= CLIP_LEVEL))
    signal = samples[:, 0] if channels == 1 else samples.mean(axis=1)
    return signal, rate, {"channels": channels, "mixed_down": channels > 1, "clipped": clipped}


def find_onsets(signal, rate, *, threshold_db=DEFAULT_THRESHOLD_DB, min_interval=MIN_INTERVAL, source="",
                notes=None):
    """The impacts in a recording: their times to a fraction of a millisecond and their relative levels.

    How (docs/analysis.md tells more):

    1. The signal is high-passed (:data:`HIGH_PASS`) and decimated (causal 8th-order Butterworth)
       to ~6 kHz, or further where its band 20 dB over the noise floor (the quietest tenth of its
       21-ms frames) ends lower (≥ 2.5 times that band's top, ≥ 2 kHz).
    2. *Ringing is predicted away.* A linear predictor (Burg's method, order :data:`ORDER`) fitted
       to the whole decimated signal — the drum's modes, the room — leaves the innovation: what
       the past does not predict, which is where a stick strikes. Candidates are where its RMS
       over the next 1 ms rises :data:`MIN_JUMP` times over the 4 ms before (peaks picked by
       ``librosa.util.peak_pick``); Akaike's information criterion (AIC) places each on the
       change point; the anti-alias filter's delay is taken off.
    3. *Broadband attacks* (snare wires, a stick's click) are found the same way at full rate on
       the first difference (a jump of :data:`BROADBAND_JUMP`, with the innovation rising
       :data:`TONAL_SUPPORT` times too: beating modes alone make broadband jumps). Their
       full-rate time replaces a decimated one within ``min_interval`` (closer onsets are one),
       unless the decimated one is more than :data:`DISAGREE` away and step 2's innovation rises
       :data:`STRONG_RISE` times there: a sharp attack's change point, beside its modes' beating.
    4. *Quiet attacks in louder ones' ringing and rattle* are found in the drum's modes' band
       (decimated to ~:data:`MODES_RATE` Hz: below the snare wires), whose innovation (a
       predictor of order :data:`MODES_ORDER` fitted by least squares reweighted by the
       inverse local power of a first fit's innovation: the ringing between attacks, not the
       attacks, sets it) holds each attack's *signature*: a spike and :data:`SIGNATURE` s of what
       the predictor cannot follow (beating modes, the room's first reflections). Matching
       pursuit: the loudest attack's signature, fitted by least squares (with its derivative:
       a fraction of a sample) at each onset found, is taken off in time order; jumps of the
       remainder (windows of :data:`MODES_WIDTH` samples) are more onsets, timed by where their
       signature fits (offset by the other onsets' precise times). Past the signature, the
       attacks' common response over :data:`TAIL` s (the room's tail: least squares over all the
       onsets found, each scaled by its signature's fit) is taken off too; a second round takes off
       the quiet onsets found as well and adds the remainder's new jumps (farther than
       :data:`SECOND_GAP` times ``min_interval`` from the onsets known). An onset is an attack when
       the remainder jumps :data:`MIN_JUMP` times at it and either its start looks like the
       signature (correlation ≥ :data:`LIKENESS`) or step 2 or 3 found it rising (or it looks
       half like it, :data:`WEAK_LIKENESS`, and step 2's innovation rises :data:`WEAK_RISE` times);
       a start almost the signature (:data:`SURE_LIKENESS`) needs a jump of :data:`SURE_JUMP` only.
       In a reverberant recording (below), a decimated onset whose start does not look like the
       signature is tried again where the remainder jumps most up to :data:`MOVE_REACH` times
       ``min_interval`` later (its change point is often placed early on the earlier tails), kept
       there when the remainder jumps :data:`MOVED_JUMP` times and it looks like the signature; and
       a last round takes off only the attacks found, at their final times, and fits them again
       with the remainder's new jumps: the new and the refused ones that look like the signature
       (and jump :data:`MIN_JUMP` times) are attacks. Then, in every recording, a quiet attack up
       to :data:`AFTER_REACH` s after each attack, where the remainder does not jump, is sought by
       fitting its whole signature there: the best fit over the louder one's signature is an attack
       when an F-test passes (:data:`AFTER_F`, or :data:`AFTER_WEAK_F` with a start half like the
       signature) and its scale is :data:`AFTER_RATIO` of the louder one's (a bouncing stick's next
       impact); again while it finds more.
    5. An onset's amplitude is the peak of its own sound in the drum's lowest modes (the band up
       to 2.1 times its lowest strong mode, ≥ 400 Hz, decimated to 2.5 times that: a stick's
       speed sets their amplitude in proportion, while the higher modes grow faster with it,
       Hertz's contact being shorter): the band over the next 5 ms (or up to the next onset)
       less the earlier sound extrapolated by a predictor (order :data:`LEVEL_ORDER`, fitted as
       in step 4), its peak between samples (4 times upsampled). In a reverberant recording (the
       room's tail past the signature carries ≥ :data:`ROOM` of its energy), an onset whose start
       looks like the signature has the earlier such onsets' tails (the band's innovation's common
       response, as in step 4, past 5 ms) taken off its innovation first. Its level is in dB re the
       loudest onset. The noise floor (the 5th percentile of that band's peaks over 5-ms frames)
       plus :data:`FLOOR_MARGIN_DB`, or ``threshold_db`` if higher, is the threshold used.

    Parameters
    ----------
    signal : array_like [shape=(n,)]
        Mono samples (full scale), finite.
    rate : int in [8000, 768000]
        Samples per second (Hz).
    threshold_db : float in [-120, 0]
        Onsets quieter than this (dB re the loudest onset) are not reported. The threshold used is
        the higher of this and the noise floor plus :data:`FLOOR_MARGIN_DB` (in :attr:`Onsets.threshold_db`).
    min_interval : float in [0.5e-3, 1]
        The shortest time between two onsets (s).
    source : str
        What the signal is (a file's name), kept in the result.
    notes : dict or None
        What was done to read it (:func:`read_recording`), kept in the result's ``info``.

    Returns
    -------
    Onsets
        Its ``info`` says the rate, the analysis rate, the noise floor (dB re the loudest onset),
        the threshold asked for, and ``"no impacts found: …"`` when none was.

    Examples
    --------
    >>> import numpy as np
    >>> rate = 48000
    >>> t = np.arange(rate) / rate
    >>> hit = lambda t0, a: a * np.where(t >= t0, np.exp(-(t - t0) / 0.03) * np.sin(2 * np.pi * 400 * (t - t0)), 0.0)
    >>> onsets = find_onsets(hit(0.2, 0.8) + hit(0.55, 0.4), rate)
    >>> np.round(onsets.t, 4).tolist(), np.round(onsets.level_db, 1).tolist()
    ([0.2, 0.55], [0.0, -6.2])
    """
    signal = check_vector("signal", signal, unit="full scale")
    rate = check_int("rate", rate, low=MIN_RATE, high=768000, unit="Hz")
    threshold_db = check_real("threshold_db", threshold_db, low=-120.0, high=0.0, unit="dB")
    min_interval = check_real("min_interval", min_interval, low=0.5e-3, high=1.0, unit="s")
    if len(signal) > MAX_SECONDS * rate:
        raise ParameterError(f"signal lasts {len(signal) / rate:.6g} s; at most {MAX_SECONDS:g} s are analysed: cut "
                             "it into parts")
    info = {**(notes or {}), "rate": rate, "seconds": len(signal) / rate, "requested_threshold_db": threshold_db,
            "method": "jumps of the linear-prediction innovation (decimated) and of the first difference; AIC change points; "
                      "matching pursuit of attack signatures in the modes' band"}

    def none(reason):
        return Onsets(np.empty(0), np.empty(0), threshold_db=threshold_db, source=source,
                      info={**info, "found": f"no impacts found: {reason}", "floor_db": None})

    if len(signal) < round(0.05 * rate):
        return none("the signal is shorter than 50 ms")
    band = _high_pass(signal, rate)
    peak = float(np.abs(band).max())
    if not peak > 1e-9:  # −180 dB full scale: digital silence
        return none("the signal is silent")
    band = band / peak
    q = max(_decimation(band, rate), rate // 6000)
    low, low_rate, delay = _decimate(band, rate, q)
    _, innovation = _innovation(low)
    tonal = [k * q - delay for k in _jumps(innovation, low_rate, min_interval, MIN_JUMP)]
    broadband = list(_broadband_onsets(band, rate, min_interval))

    def strong(tonal_at, broadband_at):  # a sharp attack's change point, and a broadband jump of its beating apart
        return abs(tonal_at - broadband_at) > DISAGREE * rate and _jump_at(
            innovation, [(tonal_at + delay) / q], low_rate)[0] >= STRONG_RISE

    first, _ = _merge(tonal, broadband, min_interval * rate, strong=strong)
    q2 = max(q, rate // MODES_RATE)
    modes_band, modes_rate, modes_delay = _decimate(band, rate, q2)
    modes = _Modes(_robust_innovation(modes_band), q2, modes_delay, modes_rate)
    residual, _, _, _, at, amp, template = _pursue(modes.e, modes.at(first), modes.rate, spikes=True)
    tail = _room_tail(modes.e, at, amp, round(TAIL * modes.rate))
    if tail is not None:
        modes = replace(modes, tail=tail)
        residual = modes.pursue(first)[0]
    size = len(template)
    reverberant = (tail is not None and len(tail) > size
                   and tail[size:] @ tail[size:] >= ROOM * (tail[:size] @ tail[:size]))  # step 5 takes tails off
    deep = modes.jumps(residual, min_interval)
    more, _ = _merge(first, deep, min_interval * rate)  # a second round: the quiet ones found taken off too
    residual = modes.pursue(more)[0]
    # a new one only away from the known ones (not a spike's leftover before one)
    deep += _away(modes.jumps(residual, min_interval), np.sort(np.concatenate((more, deep))),
                  SECOND_GAP * min_interval * rate)
    times, kinds = _merge(tonal, broadband, min_interval * rate, deep, strong=strong)
    _, modes_jump, likeness, where = modes.pursue(times)
    times, offset = _retime(times, kinds, modes.samples(where), likeness)
    tonal_jump = _jump_at(innovation, (times + delay) / q, low_rate)
    broadband_jump = _jump_at(np.diff(band, prepend=band[0]), times + 0.5, rate)
    rises = (tonal_jump >= MIN_JUMP) | ((broadband_jump >= BROADBAND_JUMP) & (tonal_jump >= TONAL_SUPPORT))
    weak = (likeness >= WEAK_LIKENESS) & (tonal_jump >= WEAK_RISE)  # half like it, rising a little
    attack = (modes_jump >= MIN_JUMP) & ((likeness >= LIKENESS) | rises | weak)
    attack |= (modes_jump >= SURE_JUMP) & (likeness >= SURE_LIKENESS)
    if reverberant:
        times, attack, likeness = _try_later(modes, times, kinds, attack, likeness, residual, min_interval, rate,
                                             offset)
        times, kinds, attack, likeness = _last_round(modes, times, kinds, attack, likeness, min_interval, rate, offset)
    for _ in range(AFTER_ROUNDS):  # again with the ones found taken off, while it finds more
        count = np.count_nonzero(attack)
        times, kinds, attack, likeness = _after_louder(modes, times, kinds, attack, likeness, min_interval, rate,
                                                       offset)
        if np.count_nonzero(attack) == count:
            break
    q3 = max(q, int(rate // (2.5 * _level_corner(band, rate, first))))
    lowest, lowest_rate, lowest_delay = _decimate(band, rate, q3)
    _, level_coefficients = _robust_innovation(lowest, LEVEL_ORDER, coefficients=True)
    amplitude = _attack_amplitudes(lowest, level_coefficients, (times + lowest_delay) / q3, lowest_rate,
                                   tail=round(TAIL * lowest_rate) if reverberant else 0, sure=likeness >= LIKENESS)
    floor = _noise_floor(lowest, lowest_rate)
    info = {**info, "analysis_rate": low_rate}
    found = (amplitude > floor * 10.0 ** (FLOOR_MARGIN_DB / 20.0)) & attack
    if not np.any(found):
        return none("no attack rises above the noise floor")
    times, amplitude = times[found], amplitude[found]
    level = 20.0 * np.log10(amplitude / amplitude.max())
    floor_db = float(20.0 * np.log10(floor / amplitude.max())) if floor > 0.0 else -np.inf
    used = max(threshold_db, floor_db + FLOOR_MARGIN_DB)
    keep = level >= used
    info["floor_db"] = floor_db if np.isfinite(floor_db) else None
    return Onsets(np.maximum(times[keep] / rate, 0.0), level[keep], threshold_db=float(used), source=source,
                  info=info)


def _high_pass(signal, rate):
    from scipy.signal import butter, sosfilt

    return sosfilt(butter(2, HIGH_PASS, btype="highpass", fs=rate, output="sos"), signal)


def _decimation(band, rate):
    """How far to decimate: to ≥ 2.5 times the top of the band 20 dB over the noise floor, ≥ 2 kHz."""
    size = 1 << int(np.ceil(np.log2(rate * 0.02)))
    if len(band) < 4 * size:
        return 1
    starts = np.unique(np.linspace(0, len(band) - size, min(_SPECTRA, (len(band) - size) // (size // 2) + 1))
                       .astype(np.int64))  # half-overlapping frames, or as many spread over a long file
    frames = band[starts[:, None] + np.arange(size)] * np.hanning(size)
    power = np.abs(np.fft.rfft(frames, axis=1).T) ** 2
    frequencies = np.fft.rfftfreq(size, 1.0 / rate)
    energy = power.sum(axis=0)
    noise = power[:, energy <= np.quantile(energy, 0.1)].mean(axis=1)
    loud = power[:, energy >= np.quantile(energy, 0.9)].mean(axis=1)
    good = np.flatnonzero(loud > 100.0 * noise)
    top = frequencies[good[-1]] if len(good) else frequencies[-1]
    return int(max(1, min(rate // (2.5 * max(top, 1.0)), rate // 2000)))


def _decimate(band, rate, q, corner=None):
    """``band`` low-passed (causal Butterworth, 8th order, at ``corner`` Hz: by default 0.8 of the new Nyquist) and decimated by ``q``.

    Returns the samples, their rate (Hz) and the filter's delay at low frequencies (full-rate samples).
    """
    if q == 1 and corner is None:
        return band, rate, 0.0
    from scipy.signal import butter, sosfilt, sosfreqz

    corner = 0.8 * rate / q / 2.0 if corner is None else min(corner, 0.8 * rate / q / 2.0)
    sos = butter(8, corner, fs=rate, output="sos")
    step = corner / 800.0  # the group delay at corner / 8, from the phase's slope (the sections: well conditioned)
    _, response = sosfreqz(sos, worN=[corner / 8.0 - step, corner / 8.0 + step], fs=rate)
    delay = -np.diff(np.unwrap(np.angle(response)))[0] / (2.0 * np.pi * 2.0 * step) * rate
    return sosfilt(sos, band)[::q].copy(), rate / q, float(delay)


def _innovation(x, order=ORDER):
    """A linear predictor of ``x`` (Burg's method; its error filter's coefficients) and what it does not predict."""
    import librosa
    from scipy.signal import lfilter

    order = min(order, max(1, len(x) // 8))
    a = librosa.lpc(x, order=order)
    if not np.all(np.isfinite(a)):
        a = np.array([1.0, -1.0])
    return a, lfilter(a, [1.0], x)


def _robust_innovation(x, order=MODES_ORDER, *, coefficients=False):
    """The innovation of ``x`` by a linear predictor fitted by least squares reweighted by the inverse local power of a first fit's innovation.

    With ``coefficients``, also the predictor's error filter (first the innovation, then the filter).
    """
    from numpy.lib.stride_tricks import sliding_window_view
    from scipy.ndimage import uniform_filter1d
    from scipy.signal import lfilter

    order = min(order, max(1, len(x) // 8))
    burg, first = _innovation(x, order)
    power = np.maximum(uniform_filter1d(first * first, 9), 0.0)
    weight = 1.0 / np.sqrt(power + 1e-12 * power.mean() + 1e-300)
    gram = np.zeros((order + 1, order + 1))
    for start in range(order, len(x), _BLOCK // 8):  # the normal equations block by block: memory stays bounded
        stop = min(len(x), start + _BLOCK // 8)
        rows = sliding_window_view(x[start - order:stop], order + 1)[:, ::-1] * weight[start:stop, None]
        gram += rows.T @ rows
    try:
        c, *_ = np.linalg.lstsq(gram[1:, 1:], -gram[1:, 0], rcond=None)
        a = np.concatenate(([1.0], c))
    except np.linalg.LinAlgError:
        a = burg
    if not np.all(np.isfinite(a)):
        a = burg
    e = lfilter(a, [1.0], x)
    return (e, a) if coefficients else e


def _pursue(e, positions, rate, span=SIGNATURE, tail=None, spikes=False):
    """``e`` less each onset's signature, the onsets taken in time order; how each onset rises over what went before.

    The signature is the innovation of the loudest attack (its largest spike and the ``span`` s
    after it); each onset's is fitted by least squares (the signature and its derivative: a
    fraction of a sample's shift) at the best of five alignments and taken off before the next.
    With ``tail`` (a longer response, from the signature's start: :func:`_room_tail`), its part
    past the signature is taken off too, scaled by the signature's fit.

    Returns
    -------
    residual : ndarray
        ``e`` less every onset's fitted signature.
    jumps : ndarray
        Each onset's jump (:func:`_jump_at`, windows of ≥ :data:`MODES_WIDTH` samples) in ``e``
        less the earlier onsets' signatures.
    likeness : ndarray
        The largest correlation coefficient (magnitude) of the signature's start (its spike and
        :data:`HEAD` samples) with what is there, over the five alignments.
    where : ndarray
        Where each onset's signature fits best (samples of ``e``, to a fraction: the derivative's
        weight over the signature's).
    at, amplitude, template : ndarray
        With ``spikes`` only: where each fitted signature starts (samples), its scale, and the signature.
    """
    from numpy.lib.stride_tricks import sliding_window_view

    length = max(4, round(span * rate))
    peak = int(np.argmax(np.abs(e)))
    lead = min(2, peak)
    template = e[peak - lead:peak + length].copy()
    size = len(template)
    basis = np.column_stack([template, np.gradient(template)]) if size > 1 else template[:, None]
    gram = basis.T @ basis
    positions = np.asarray(positions, dtype=float)
    if not np.all(np.isfinite(gram)) or np.linalg.cond(gram) > 1e12:  # no signature to fit: nothing taken off
        found = e.copy(), _jump_at(e, positions, rate, MODES_WIDTH), np.ones(len(positions)), positions.copy()
        if spikes:
            return *found, np.round(positions).astype(np.int64), np.zeros(len(positions)), template
        return found
    solve = np.linalg.solve(gram, basis.T)
    head = template[:lead + HEAD]
    head_norm = float(np.sqrt(head @ head))
    width = max(MODES_WIDTH, round(1e-3 * rate))
    half = max(1, width // 2)
    r = e.copy()
    jumps = np.zeros(len(positions))
    likeness = np.zeros(len(positions))
    where = positions.copy()
    at, amp = np.zeros(len(positions), dtype=np.int64), np.zeros(len(positions))
    for i, c in enumerate(np.round(positions).astype(np.int64)):
        # the jump: the next window's power over the 4 windows before, the largest within half a window
        low, high = max(0, c - half - 4 * width), min(len(r), c + half + width + 1)
        jumps[i] = _jump_at(r[low:high], [c - low], rate, MODES_WIDTH)[0] if high - low > width else 0.0
        starts = c - lead + np.arange(-2, 3)
        starts = starts[(starts >= 0) & (starts + size <= len(r))]
        if not len(starts):
            continue
        block = sliding_window_view(r[starts[0]:starts[-1] + size], size)
        heads = block[:, :len(head)]
        likeness[i] = float(np.max(np.abs(heads @ head) / (np.sqrt(np.einsum("ij,ij->i", heads, heads)) * head_norm + 1e-300)))
        weights = block @ solve.T
        cost = np.einsum("ij,ij->i", block, block) - np.einsum("ij,ij->i", weights, weights @ gram)
        k = int(np.argmin(cost))
        r[starts[k]:starts[k] + size] -= basis @ weights[k]
        if tail is not None and len(tail) > size:
            stop = min(len(r), starts[k] + len(tail))
            r[starts[k] + size:stop] -= weights[k][0] * tail[size:stop - starts[k]]
        at[i], amp[i] = starts[k], weights[k][0]
        shift = -weights[k][1] / weights[k][0] if len(weights[k]) > 1 and weights[k][0] != 0.0 else 0.0
        where[i] = starts[k] + lead + float(np.clip(shift, -1.0, 1.0))
    if spikes:
        return r, jumps, likeness, where, at, amp, template
    return r, jumps, likeness, where


def _room_tail(e, at, amp, length):
    """The attacks' common response (``length`` samples from each start), by least squares over all of them."""
    from scipy.linalg import solve_toeplitz

    keep = amp != 0.0
    at, amp = at[keep], amp[keep]
    if len(at) == 0:
        return None
    s = np.zeros(len(e))
    np.add.at(s, at, amp)
    size = 1 << int(np.ceil(np.log2(len(e) + length)))
    S = np.fft.rfft(s, size)
    r_ss = np.fft.irfft(S * np.conj(S), size)[:length]
    r_se = np.fft.irfft(np.conj(S) * np.fft.rfft(e, size), size)[:length]
    r_ss[0] *= 1.0 + TAIL_RIDGE
    h = solve_toeplitz(r_ss, r_se)
    return h if np.all(np.isfinite(h)) else None


@dataclass(frozen=True)
class _Modes:
    """The drum's modes' band of step 4: its innovation ``e``, decimated ``q`` times with ``delay``
    samples of filter delay (full rate), at ``rate`` Hz, and the room's ``tail`` once fitted."""

    e: np.ndarray
    q: int
    delay: float
    rate: float
    tail: np.ndarray | None = None

    def at(self, samples):
        """Full-rate ``samples`` as (fractional) samples of the band."""
        return (samples + self.delay) / self.q

    def samples(self, at):
        """Samples of the band ``at`` as full-rate samples."""
        return at * self.q - self.delay

    def pursue(self, samples, spikes=False):
        """:func:`_pursue` of the onsets at full-rate ``samples``, the room's tail taken off with each."""
        return _pursue(self.e, self.at(samples), self.rate, tail=self.tail, spikes=spikes)

    def jumps(self, residual, min_interval):
        """Where ``residual`` (in the band) jumps :data:`MIN_JUMP` times, as a list of full-rate samples."""
        return [self.samples(k) for k in _jumps(residual, self.rate, min_interval, MIN_JUMP, MODES_WIDTH)]


def _away(candidates, known, gap):
    """The ``candidates`` farther than ``gap`` from their nearest neighbours in ``known`` (sorted), in order."""
    kept = []
    for s in candidates:
        near = np.searchsorted(known, s)
        if all(abs(known[j] - s) > gap for j in (near - 1, near) if 0 <= j < len(known)):
            kept.append(s)
    return kept


def _try_later(modes, times, kinds, attack, likeness, residual, min_interval, rate, offset):
    """Decimated onsets whose start does not look like the signature, tried again where the remainder jumps most just after.

    In a room's tail the change point of an onset found in the decimated innovation or in the modes' band
    is often placed 1-6 ms early (on what is left of the earlier onsets' tails), where its start does not
    look like the signature: refused, or accepted at the wrong time. It is moved to where ``residual``
    (the modes' band's remainder) jumps most before :data:`MOVE_REACH` times ``min_interval`` (s) later,
    and taken there when the remainder jumps :data:`MOVED_JUMP` times and its start looks like the
    signature (:data:`LIKENESS`), timed by its signature's fit plus ``offset`` (full-rate samples, as
    :func:`_retime`); else it stays as it was. Times are full-rate samples, ``residual`` in ``modes``' band.
    """
    after, before, _ = _windows(residual, modes.rate, MODES_WIDTH)
    profile = np.sqrt(after / np.maximum(before, 1e-300 + after * 1e-12))
    moved = times.copy()
    for i in np.flatnonzero((likeness < LIKENESS) & (kinds >= 1)):
        end = min(times[i] + MOVE_REACH * min_interval * rate,
                  times[i + 1] - min_interval * rate if i + 1 < len(times) else np.inf)
        low, high = int(np.ceil(modes.at(times[i]))) + 1, min(int(modes.at(end)), len(profile))
        if high > low:
            k = low + int(np.argmax(profile[low:high]))
            if profile[k] >= MIN_JUMP:
                moved[i] = modes.samples(k)
    tried = moved != times
    if not np.any(tried):
        return times, attack, likeness
    _, jump, like, where = modes.pursue(moved)
    take = tried & (jump >= MOVED_JUMP) & (like >= LIKENESS)
    times, attack, likeness = times.copy(), attack.copy(), likeness.copy()
    times[take] = modes.samples(where[take]) + offset
    attack[take], likeness[take] = True, like[take]
    return times, attack, likeness


def _last_round(modes, times, kinds, attack, likeness, min_interval, rate, offset):
    """New onsets where the remainder jumps once only the attacks found are taken off; the refused ones tried again.

    The rounds before take off their candidates, the refused ones too and some 1-6 ms early
    (:func:`_try_later`); with the attacks alone, at their final times, a quiet attack in a room's tail
    may jump out. The remainder's jumps farther than :data:`SECOND_GAP` times ``min_interval`` (s) from
    every onset join the onsets (found in the modes' band alone); all are fitted again in time order at
    their final times, and the new and the refused ones are attacks when the remainder jumps
    :data:`MIN_JUMP` times at them and their start looks like the signature (:data:`LIKENESS`), the new
    ones timed by their signature's fit plus ``offset``. Times are full-rate samples.
    """
    residual = modes.pursue(times[attack])[0]
    new = _away(modes.jumps(residual, min_interval), times, SECOND_GAP * min_interval * rate)
    every, kinds, attack, likeness, fresh = _insert(times, kinds, attack, likeness, new, taken=False,
                                                    like=np.zeros(len(new)))
    _, jump, like, where = modes.pursue(every)
    take = ~attack & (jump >= MIN_JUMP) & (like >= LIKENESS)
    every[take & fresh] = modes.samples(where[take & fresh]) + offset
    likeness = np.where(take, like, likeness)
    attack |= take
    keep = ~fresh | take
    every, kinds, attack, likeness = every[keep], kinds[keep], attack[keep], likeness[keep]
    order = np.argsort(every, kind="stable")  # a fitted time stays between its neighbours' (2 min_interval away)
    return every[order], kinds[order], attack[order], likeness[order]


def _after_louder(modes, times, kinds, attack, likeness, min_interval, rate, offset):
    """A quiet attack in each attack's signature, found by fitting its whole signature where the remainder jumps too little.

    A bouncing stick's impact 13-40 ms after one a few dB louder may not make the remainder jump over
    its 2-ms windows: what is left of the louder one's signature (and of the snare wires' rattle, the
    room's tails) is as loud there. Its whole signature (the spike and the 50 ms after it) stands out more. Over each
    attack's signature in the remainder (the attacks taken off, at their final times), the signature and
    its derivative are fitted by least squares at every trial time from ``min_interval`` (s) after the
    attack to :data:`AFTER_REACH` s after it (or ``min_interval`` before the next attack), truncated to
    that window. The fit that takes off the most with a positive scale is an attack when it takes off
    enough of the window's remainder (an F-test of its two parameters: :data:`AFTER_F`, or
    :data:`AFTER_WEAK_F` when its start looks half like the signature, :data:`WEAK_LIKENESS`) and its
    scale is :data:`AFTER_RATIO` of the louder one's (a bouncing stick's next impact, not what is left
    of the louder one's signature). It is timed by its signature's fit plus ``offset`` (full-rate
    samples, as :func:`_retime`) and replaces a refused onset within ``min_interval``. Times are full-rate
    samples. (Fitting the louder attack again jointly with each trial changes the fit's gain by 0.1-4 %
    at the impacts missed, more at false trials: it is not done.)
    """
    sure = np.flatnonzero(attack)
    if not len(sure):
        return times, kinds, attack, likeness
    residual, _, _, _, at, amp, template = modes.pursue(times[sure], spikes=True)
    size = len(template)
    basis = np.column_stack([template, np.gradient(template)])
    grams = np.cumsum(basis[:, :, None] * basis[:, None, :], axis=0)  # the truncated signatures' normal equations
    gap = max(1, round(min_interval * modes.rate))
    reach = round(AFTER_REACH * modes.rate)
    spike = int(np.argmax(np.abs(template)))
    head = template[:spike + HEAD]
    head_norm = float(np.sqrt(head @ head))
    positions = np.round(modes.at(times[sure])).astype(np.int64)
    new, likes = [], []
    for i, (s, alpha) in enumerate(zip(at, amp)):
        if alpha <= 0.0 or s + size > len(residual):
            continue
        stop = positions[i] + reach if i + 1 == len(sure) else min(positions[i] + reach, positions[i + 1] - gap)
        lags = np.arange(positions[i] + gap, stop + 1) - spike - s  # where each trial signature starts in the window
        lags = lags[(lags > 0) & (lags < size - 2 * MODES_WIDTH)]  # two jump windows of it in the window at least
        if not len(lags):
            continue
        k, weights, f = _best_trial(residual[s:s + size], basis, grams, lags)
        if k is None:
            continue
        ratio = weights[0] / alpha
        start = residual[s + lags[k]:s + lags[k] + len(head)]
        like = abs(start @ head) / (np.sqrt(start @ start) * head_norm + 1e-300)
        passes = f >= AFTER_F or (f >= AFTER_WEAK_F and like >= WEAK_LIKENESS)
        if passes and AFTER_RATIO[0] <= ratio <= AFTER_RATIO[1]:
            shift = float(np.clip(-weights[1] / weights[0], -1.0, 1.0))
            new.append(modes.samples(s + lags[k] + spike + shift) + offset)
            likes.append(like)
    if not new:
        return times, kinds, attack, likeness
    new = np.array(new)
    near = np.abs(times[:, None] - new[None, :]).min(axis=1) < min_interval * rate
    refused = ~attack & near  # a refused onset where one is found now: the new one replaces it
    times, kinds, attack, likeness = times[~refused], kinds[~refused], attack[~refused], likeness[~refused]
    return _insert(times, kinds, attack, likeness, new, taken=True, like=likes)[:4]


def _insert(times, kinds, attack, likeness, new, *, taken, like):
    """The onsets with ``new`` ones among them (full-rate samples, found in the modes' band alone), in time order.

    ``taken`` says whether the new ones are attacks, ``like`` their likeness. Returns the times, kinds,
    attack and likeness arrays, and which onsets are the new ones.
    """
    order = np.argsort(np.concatenate((times, new)), kind="stable")
    fresh = np.concatenate((np.zeros(len(times), dtype=bool), np.ones(len(new), dtype=bool)))[order]
    return (np.concatenate((times, new))[order], np.concatenate((kinds, np.full(len(new), 2)))[order],
            np.concatenate((attack, np.full(len(new), taken)))[order], np.concatenate((likeness, like))[order], fresh)


def _best_trial(y, basis, grams, lags):
    """The trial signature that takes off the most of ``y`` (a window of the remainder) with a positive scale.

    Each trial is ``basis`` (the signature and its derivative, as columns) starting ``lags`` samples
    into the window, truncated to it (``grams``: the normal equations of its first rows, cumulated).
    Returns the trial's index in ``lags``, its least-squares weights and the F statistic of its two
    parameters against what is left of ``y`` (``len(y) - 4`` degrees of freedom: the window's own
    attack's two parameters too), or ``(None, None, None)`` when no trial has a positive scale.
    """
    from numpy.lib.stride_tricks import sliding_window_view

    size = len(y)
    total = float(y @ y)
    windows = sliding_window_view(np.concatenate((y, np.zeros(size))), size)[lags]  # from each trial on; zeros past
    rhs = np.stack([windows @ basis[:, 0], windows @ basis[:, 1]], axis=1)
    gram = grams[size - lags - 1]
    try:
        weights = np.linalg.solve(gram + 1e-12 * np.trace(gram[0]) * np.eye(2), rhs[:, :, None])[:, :, 0]
    except np.linalg.LinAlgError:
        return None, None, None
    drop = np.einsum("ij,ij->i", weights, rhs)  # what each trial's fit takes off the window
    drop[weights[:, 0] <= 0.0] = -np.inf
    k = int(np.argmax(drop))
    if not np.isfinite(drop[k]):
        return None, None, None
    return k, weights[k], (drop[k] / 2.0) / max(total - drop[k], 1e-300) * (size - 4)


def _retime(times, kinds, fitted, likeness):
    """Onsets found only in the modes' band timed by their signature's fit, against the others' times.

    ``fitted`` (full-rate samples) is where each signature fits; its offset from the precise
    times (broadband or tonal onsets whose start looks like the signature, likeness ≥ 0.9) is
    their median difference, added to the fitted time of each onset found only in the modes' band. Returns
    the times and that offset (0 when there is no precise onset or none to retime).
    """
    sure = (kinds < 2) & (likeness >= 0.9)
    if not np.any(sure) or not np.any(kinds == 2):
        return times, 0.0
    offset = float(np.median(times[sure] - fitted[sure]))
    out = times.copy()
    out[kinds == 2] = fitted[kinds == 2] + offset
    order = np.argsort(out, kind="stable")
    return (out[order] if np.all(np.diff(out[order]) > 0) else times), offset


def _level_corner(band, rate, onsets):
    """The top (Hz) of the band levels are measured in: 2.1 times its lowest strong mode, ≥ 400 Hz.

    The lowest strong mode is the lowest frequency within 20 dB of the strongest in the 50 ms
    after the loudest of ``onsets`` (full-rate samples; the signal's largest sample if none).
    """
    if len(onsets):
        starts = np.clip(np.round(onsets).astype(np.int64), 0, len(band) - 1)
        peaks = [np.abs(band[k:k + max(1, round(5e-3 * rate))]).max() for k in starts]
        start = int(starts[int(np.argmax(peaks))])
    else:
        start = int(np.argmax(np.abs(band)))
    size = 1 << int(np.ceil(np.log2(rate * 0.05)))
    segment = band[start:start + size]
    if len(segment) < size // 4:
        return 400.0
    power = np.abs(np.fft.rfft(segment * np.hanning(len(segment)), size)) ** 2
    frequencies = np.fft.rfftfreq(size, 1.0 / rate)
    strong = np.flatnonzero((power >= 0.01 * power.max()) & (frequencies >= HIGH_PASS))
    lowest = frequencies[strong[0]] if len(strong) else 190.0
    return float(max(400.0, 2.1 * lowest))


def _windows(x, rate, least=12):
    """The mean square of ``x`` over the 1 ms (≥ ``least`` samples) from each sample, and over the 4 times that before it."""
    width = max(least, round(1e-3 * rate))
    power = np.concatenate(([0.0], np.cumsum(x * x)))
    n = np.arange(len(x))
    after = (power[np.minimum(n + width, len(x))] - power[n]) / width
    before = (power[n] - power[np.maximum(n - 4 * width, 0)]) / (4 * width)
    return after, before, width


def _jumps(x, rate, min_interval, least, samples=12):
    """Samples of ``x`` where its RMS over the next 1 ms rises ``least`` times over the 4 ms before: the AIC's change points.

    A long signal is taken in blocks of :data:`_BLOCK` samples (overlapping by more than the windows
    and ``min_interval``), so memory does not grow with its length.
    """
    import librosa

    width = max(samples, round(1e-3 * rate))
    gap = max(1, round(min_interval * rate))
    margin = 6 * width + 2 * gap
    peaks = []
    for start in range(0, len(x), _BLOCK):
        low, high = max(0, start - margin), min(len(x), start + _BLOCK + margin)
        after, before, _ = _windows(x[low:high], rate, samples)
        jump = np.sqrt(after / np.maximum(before, 1e-300 + after * 1e-12))
        jump[: 4 * width] = 0.0
        found = librosa.util.peak_pick(jump, pre_max=gap, post_max=gap, pre_avg=1, post_avg=1, delta=0.0, wait=gap)
        found = found[(jump[found] >= least) & (low + found >= start) & (low + found < start + _BLOCK)]
        peaks += list(low + found)
    return [max(0, p - 4 * width) + _aic(x[max(0, p - 4 * width):p + 2 * width]) for p in peaks]


def _broadband_onsets(band, rate, min_interval):
    """Full-rate samples of broadband attacks: where the first difference's RMS jumps, placed by the AIC."""
    d = np.diff(band, prepend=band[0])
    return [k - 0.5 for k in _jumps(d, rate, min_interval, BROADBAND_JUMP)]  # the difference is centred ½ sample early


def _merge(tonal, broadband, gap, deep=(), strong=None):
    """The onsets (samples), sorted, and how each was found (0 broadband, 1 tonal, 2 deep only).

    Onsets closer than ``gap`` are one (as are two groups' choices closer than a quarter of it), at the broadband
    time if any, else the tonal one. With ``strong`` (``(tonal, broadband)`` samples → whether the tonal
    time is trusted over the broadband one), a group's tonal time nearest its broadband time replaces it
    when ``strong`` says so.
    """
    marked = sorted([(s, 1) for s in tonal] + [(s, 0) for s in broadband] + [(s, 2) for s in deep])
    groups = []
    for s, kind in marked:
        if groups and s - groups[-1][0][0] < gap:
            groups[-1].append((s, kind))
        else:
            groups.append([(s, kind)])
    chosen = []
    for group in groups:  # a group's choice may fall on the next group's (its broadband time on that one's tonal)
        s, kind = min(group, key=lambda item: item[1])
        near = min((t for t, k in group if k == 1), key=lambda t: abs(t - s), default=None)
        if kind == 0 and near is not None and strong is not None and strong(near, s):
            s, kind = near, 1
        if chosen and s - chosen[-1][0] < gap / 4:
            if kind < chosen[-1][1]:
                chosen[-1] = (s, kind)
        else:
            chosen.append((s, kind))
    return np.array([s for s, _ in chosen], dtype=float), np.array([k for _, k in chosen], dtype=np.int64)


def _attack_amplitudes(low, coefficients, positions, rate, *, tail=0, sure=None):
    """Each attack's own peak (full scale): the signal less the earlier sound predicted on past the onset.

    The earlier sound (the drum's and the room's ringing) is extrapolated past the onset from the
    samples before it by the linear predictor; what remains is the new attack's sound, whose
    peak over the next 5 ms (or up to the next onset), between samples, is its amplitude. With
    ``tail`` (samples), the earlier onsets' room tails are taken off too: the innovation's common
    response to the onsets over ``tail`` samples (:func:`_room_tail`, each onset scaled by its first
    amplitude) is what the predictor cannot foresee of the earlier sound; an onset's own sound is
    then the predictor's response to its innovation less the tails (past the 5 ms) of the earlier
    onsets. ``sure`` (booleans, one per onset): the onsets so measured and whose tails are taken off.
    """
    from scipy.signal import firwin, lfilter, upfirdn

    horizon = max(2, round(5e-3 * rate))
    interpolator = 4.0 * firwin(81, 0.25, window=("kaiser", 5.0))  # as scipy's resample_poly(x, 4, 1)
    starts = np.clip(np.round(positions).astype(np.int64), 0, len(low))
    stops = [min(len(low), k + horizon, starts[i + 1] if i + 1 < len(starts) else len(low))
             for i, k in enumerate(starts)]
    amplitude = np.array([_residual_peak(low, coefficients, k, stop, interpolator) for k, stop in zip(starts, stops)])
    inside = starts < len(low)
    if tail <= 0 or not np.any(inside):
        return amplitude
    e = lfilter(coefficients, [1.0], low)
    h = _room_tail(e, starts[inside], amplitude[inside], tail)
    if h is None:
        return amplitude
    sure = np.ones(len(starts), dtype=bool) if sure is None else np.asarray(sure, dtype=bool)
    out = amplitude.copy()
    for i, (k, stop) in enumerate(zip(starts, stops)):
        if k < len(coefficients) - 1 or stop <= k or not sure[i]:
            continue
        own = e[k:stop].copy()
        for j in np.flatnonzero(sure[:i]):  # the earlier onsets' tails over this onset's window
            lag = k - starts[j]
            if horizon <= lag < len(h):
                part = h[lag:lag + stop - k]
                own[:len(part)] -= amplitude[j] * part
        own = lfilter([1.0], coefficients, own)  # the predictor's response: the sound less its extrapolation
        out[i] = float(np.abs(upfirdn(interpolator, np.concatenate((np.zeros(4), own, np.zeros(4))), 4)).max())
    return out


def _jump_at(x, positions, rate, samples=12):
    """The largest RMS jump of ``x`` (the next 1 ms over the 4 ms before) within half a window of each position."""
    width = max(samples, round(1e-3 * rate))
    half = max(1, width // 2)
    out = np.zeros(len(positions))
    for n, i in enumerate(np.round(np.asarray(positions, dtype=float)).astype(np.int64)):
        low, high = max(0, i - half - 4 * width), min(len(x), i + half + width + 1)
        after, before, _ = _windows(x[low:high], rate, samples)
        k = np.arange(max(i - half, low), min(i + half + 1, high)) - low
        valid = k >= min(4 * width, i)  # a full window before, or the signal's start
        jump = np.sqrt(after[k] / np.maximum(before[k], 1e-300 + after[k] * 1e-12))
        out[n] = jump[valid].max(initial=0.0)
    return out


def _residual_peak(x, coefficients, start, stop, interpolator=None):
    """The peak of ``x[start:stop]`` less its linear prediction from the samples before ``start``.

    With ``interpolator`` (a 4-times upsampling low-pass FIR), the peak between samples.
    """
    order = len(coefficients) - 1
    if stop <= start:
        return 0.0
    actual = x[start:stop]
    if start >= order:
        past = np.concatenate((x[start - order:start], np.zeros(stop - start)))
        taps = -coefficients[:0:-1]  # oldest first
        for j in range(stop - start):
            past[order + j] = taps @ past[j:order + j]
        actual = actual - past[order:]
    if interpolator is None or len(actual) < 2:
        return float(np.abs(actual).max())
    from scipy.signal import upfirdn

    padded = np.concatenate((np.zeros(4), actual, np.zeros(4)))  # the new sound starts from nothing
    return float(np.abs(upfirdn(interpolator, padded, 4)).max())


def _aic(x):
    """Akaike's change point of ``x``: the first sample of its second, louder-or-quieter segment."""
    n = len(x)
    power = np.cumsum(x * x)
    total = power[-1]
    k = np.arange(1, n)
    before = power[:-1] / k
    after = (total - power[:-1]) / (n - k)
    tiny = total / n * 1e-12 + 1e-300
    aic = k * np.log(before + tiny) + (n - k - 1) * np.log(after + tiny)
    edge = max(2, n // 50)
    aic[:edge] = np.inf
    aic[-edge:] = np.inf
    return int(np.argmin(aic)) + 1


def _noise_floor(x, rate):
    """The 5th percentile of the peaks of ``x`` over 5-ms frames (full scale)."""
    frame = max(1, round(5e-3 * rate))
    count = len(x) // frame
    if count < 1:
        return 0.0
    peaks = np.abs(x[:count * frame]).reshape(count, frame).max(axis=1)
    return float(np.quantile(peaks, _FLOOR_QUANTILE))
