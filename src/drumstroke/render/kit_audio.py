"""The whole kit's impacts as audio: each piece rings as its kind of instrument (writing needs the ``audio`` extra).

A hit is a time (s), the piece struck (by its name in the kit), the General MIDI key played (which says
the hi-hat's state) and the striking speed v (m/s: the stick's tip, the kick's beater, the hi-hat's top
cymbal closing on the pedal). Each piece sounds as one of two physical models, chosen by its kind and
its first key (:func:`kit_voice`); the mix is limited to :data:`~.audio.PEAK` once, as the snare alone is.

Drums: a circular membrane (:class:`~.audio.Drum`, :mod:`.audio`'s model)
    Modes f_1 · j_mn / j_01, each weighted by its shape at the strike radius and by the spectrum of a
    half-sine contact force lasting τ = τ_1 · v^(-1/5) (Hertz), decaying in T_1 · f_1 / f_k.

    - **The snare** (a membrane whose first key is 37, 38 or 40) is :class:`~.audio.Drum`'s default,
      unchanged: the kit renders it sample for sample as :func:`~.audio.synthesize` does.
    - **A tom** (a membrane whose first key is a General MIDI tom's) has the nominal diameter d of
      :data:`TOM_DIAMETERS` (10" high tom to 18" low floor tom) and sounds at the ideal membrane's
      f_1 = j_01 · c / (π d), with c = :data:`HEAD_WAVE_SPEED` = 56 m/s, the transverse wave speed
      √(T/σ) of a head tuned so that a 12" tom sounds at 140 Hz (a 10" at 168 Hz, a 16" floor tom at
      105 Hz: the usual tuning ranges); no snares; it rings for T_1 = 0.4 s · d / 12", a larger head
      longer. A membrane with another first key is a 12" tom.
    - **The kick** is a 22" bass drum tuned low (:data:`KICK`: f_1 = 50 Hz), struck near the centre
      (r = 0.1, mostly the m = 0 modes), damped (T_1 = 0.3 s), by a felt beater whose contact lasts
      6 ms at 1 m/s instead of the stick's 1 ms: its spectrum's first zero, 1.5 / τ, falls at 250 Hz,
      so the kick's sound is the low modes: a thump, not a crack.

Cymbals and the hi-hat: a thin plate (:class:`Plate`)
    A thin plate's modes are dense and inharmonic: their number below f grows as √3 · A · f / (c_L h)
    (A the area, h the thickness, c_L = √(E / (ρ (1 - ν²))) ≈ 3800 m/s in cymbal bronze), a modal
    density independent of frequency, about 60 modes per kHz for a 16" cymbal 1 mm thick. The model
    draws ``modes`` frequencies uniformly (seeded) over [``low``, ``high``]: constant density, no
    harmonic series. Each mode k rings as a drum's does::

        x_k(t) = G · v · a_k · H(f_k, τ) · exp(-(t - t_i) / T_k) · sin(2π f_k (t - t_i))

    with a_k = |z_k| · (f_k / 1 kHz)^tilt (z_k a seeded normal deviate standing for the mode's shape at
    the strike point, the tilt for the radiation and the plate's profile), scaled so that the modes'
    RMS just after an impact is ``level`` · G · v before the contact's spectrum; H the half-sine
    spectrum of a contact lasting τ = ``contact_time`` · v^(-1/5); and T_k = ``decay`` ·
    (1 kHz / f_k)^``decay_slope``, the higher modes dying faster, as measured cymbal decays do. What
    the model leaves out: the plate's nonlinearity (energy flowing from low modes to high ones over the
    first tenths of a second, the "bloom" of a crash) and the cymbal's swing.

    - **The crash** (:data:`CRASH`, a thin 16" plate struck on its edge by the stick's shoulder): 240
      modes over 300 Hz–12 kHz, a bright tilt (+0.3), a 0.25 ms contact: a wash that rings for
      seconds (T = 0.8 s at 1 kHz).
    - **The ride** (:data:`RIDE`, a heavy 20" plate struck on its bow by the tip): 200 modes over
      250 Hz–10 kHz, darker (tilt −0.3), the tip's short 0.12 ms contact giving the ping, a longer
      ring (T = 1.5 s at 1 kHz) under it.
    - **The ride's bell** (:data:`BELL`, the thick cup by the mount): 14 modes over 600 Hz–5 kHz, so
      few that each is heard: a bell's tone, long (T = 2 s at 1 kHz, decay slope 0.3).
    - **The hi-hat**'s two 14" plates (:data:`HIHAT`), one set of modes (350 Hz–15 kHz) in four
      states: **closed**, the plates clamped together by the pedal, a short tick (T = 0.04 s at 1 kHz);
      **half** open, the plates brushing, a sizzle (T = 0.15 s, near the geometric mean of the two
      ends: a decay time's ratio, not its difference, is what the ear hears); **open**, the plates
      free but touching now and then, a wash (T = 0.5 s); **pedal**, the top plate clapped onto the
      bottom one by the foot, the "chick": a long contact of the two plates' whole rims (1 ms: the
      high modes barely start) dying at once (T = 0.03 s).

      The hi-hat is one instrument whose state follows the part: from each of its hits on (a stick's
      or the foot's), its modes decay at that hit's state's rate, those still ringing from earlier
      hits too. An open hi-hat's wash is cut by the next closed note or by the foot closing it
      (choked), as a drummer's foot cuts it; opened again, what still rings rings on.

Other cymbal keys (crash 2, china, splash) are crashes; the numbers are estimates, chosen to sound
like their instruments, to be replaced by measured ones.

>>> import numpy as np
>>> hits = KitHits.from_rows([(0.0, "kick", 36, 2.0), (0.0, "hihat", 42, 1.0), (0.25, "snare", 38, 1.5)])
>>> signal = synthesize_kit(hits, duration=0.5)
>>> signal.shape, bool(np.abs(signal).max() <= 0.99)
((24000,), True)
"""

from dataclasses import dataclass, field, replace

import numpy as np
from numba import njit
from scipy.special import jn_zeros

from .._checks import check_int, check_real, check_vector, shown
from ..errors import ParameterError, located
from ..formats.wav import audio_format, write_wav
from ..kit.pieces import Kit, default_kit
from .audio import (
    GAIN,
    SAMPLE_RATE,
    SNARE_BAND,
    TAIL_DECAYS,
    Drum,
    check_synthesis,
    contact_time,
    half_sine_spectrum,
    limit_peak,
    ring,
)

INCH = 0.0254
"""One inch (m): drums and cymbals are sold by their diameter in inches."""

SNARE_KEYS = (37, 38, 40)
"""General MIDI's side stick, acoustic snare and electric snare: a membrane whose first key is one is the snare."""

HEAD_WAVE_SPEED = 56.0
"""c = √(T/σ) (m/s) of a tom's head: a 12" tom at f_1 = j_01 · c / (π d) = 140 Hz."""

TOM_DIAMETERS = {41: 18.0, 43: 16.0, 45: 14.0, 47: 13.0, 48: 12.0, 50: 10.0}
"""A tom's nominal diameter (inches) by its first key: General MIDI's low floor tom (41) to high tom (50)."""

TOM_DECAY = 0.4
"""T_1 (s) of a 12" tom; a tom of diameter d rings for TOM_DECAY · d / 12"."""

KICK = Drum(fundamental=50.0, position=0.1, decay=0.3, contact_time=6e-3, snares=False)
"""The kick: a 22" bass drum tuned low, struck near its centre by a felt beater, damped."""

RIDE_KEYS = (51, 59)
"""General MIDI's ride cymbals 1 and 2: a cymbal whose first key is one is a ride."""

BELL_KEYS = (53,)
"""General MIDI's ride bell: a cymbal whose first key is it is a ride's bell."""


@dataclass(frozen=True)
class Plate:
    """A cymbal, or a state of the hi-hat: a thin plate's dense, inharmonic modes (see the module's docstring).

    Attributes
    ----------
    low, high : float in [20, 24000], low < high
        The band the modes are drawn in (Hz); modes at or above half the sample rate are left out.
    modes : int in [1, 2000]
        How many modes.
    decay : float in (0, 20]
        Time for a mode at 1 kHz to fall by 1/e (s).
    decay_slope : float in [0, 2]
        α: a mode at f decays in ``decay`` · (1 kHz / f)^α.
    tilt : float in [-2, 2]
        β: the modes' amplitudes go as (f / 1 kHz)^β.
    contact_time : float in (0, 0.01]
        Duration of the contact at a striking speed of 1 m/s (s); it scales as v^(-1/5).
    level : float in (0, 10]
        RMS of the modes just after an impact, in units of G · v, before the contact's spectrum.
    seed : int ≥ 0
        Seed of the modes' frequencies and amplitudes: one seed, one plate.
    """

    low: float = 300.0
    high: float = 12000.0
    modes: int = 240
    decay: float = 0.8
    decay_slope: float = 0.5
    tilt: float = 0.5
    contact_time: float = 1.5e-4
    level: float = 0.7
    seed: int = 1

    def __post_init__(self):
        check_real("low", self.low, low=20.0, high=24000.0, unit="Hz")
        check_real("high", self.high, low=self.low, high=24000.0, low_open=True, unit="Hz")
        check_int("modes", self.modes, low=1, high=2000)
        check_real("decay", self.decay, low=0.0, high=20.0, low_open=True, unit="s")
        check_real("decay_slope", self.decay_slope, low=0.0, high=2.0)
        check_real("tilt", self.tilt, low=-2.0, high=2.0)
        check_real("contact_time", self.contact_time, low=0.0, high=0.01, low_open=True, unit="s")
        check_real("level", self.level, low=0.0, high=10.0, low_open=True)
        check_int("seed", self.seed, low=0)

    @property
    def ring_time(self):
        """The longest mode's decay time (s): the lowest mode's, ``decay`` · (1 kHz / ``low``)^α."""
        return self.decay * (1000.0 / self.low) ** self.decay_slope

    def frequencies_and_amplitudes(self):
        """The modes' frequencies f_k (Hz, increasing) and amplitudes a_k, each [shape=(modes,)].

        >>> f, a = Plate(modes=500).frequencies_and_amplitudes()
        >>> bool(300 <= f[0] and f[-1] <= 12000), round(float(np.sqrt(np.sum(a**2) / 2)), 6)
        (True, 0.7)
        """
        rng = np.random.default_rng(self.seed)
        frequencies = np.sort(rng.uniform(self.low, self.high, self.modes))
        amplitudes = rng.standard_normal(self.modes) * (frequencies / 1000.0) ** self.tilt
        return frequencies, amplitudes * self.level / np.sqrt(np.sum(amplitudes**2) / 2.0)


CRASH = Plate()
"""A 16" crash: a thin plate struck on its edge, a bright wash."""

RIDE = Plate(low=250.0, high=10000.0, modes=200, decay=1.5, tilt=-0.3, contact_time=1.2e-4, level=0.2, seed=2)
"""A 20" ride struck on its bow: the tip's ping and a long, darker ring."""

BELL = Plate(low=600.0, high=5000.0, modes=14, decay=1.2, decay_slope=0.3, tilt=0.0, contact_time=1e-4,
             level=0.2, seed=3)
"""The ride's bell: few, strong modes, a bell's tone."""

_HIHAT_PLATES = Plate(low=350.0, high=15000.0, modes=200, tilt=0.6, contact_time=1e-4, level=0.6, seed=4)
HIHAT = {
    "closed": replace(_HIHAT_PLATES, decay=0.04, decay_slope=0.3),
    "half": replace(_HIHAT_PLATES, decay=0.15, decay_slope=0.4),
    "open": replace(_HIHAT_PLATES, decay=0.5, decay_slope=0.5),
    "pedal": replace(_HIHAT_PLATES, decay=0.03, decay_slope=0.3, contact_time=4e-4, level=2.0),
}
"""The hi-hat's two 14" plates (one set of modes) by state: clamped (a tick), brushing (a sizzle), free (a wash),
clapped (the chick)."""


def tom(diameter):
    """The :class:`~.audio.Drum` of a tom of nominal ``diameter`` (inches, in [6, 24]) (see the module's docstring).

    >>> drum = tom(12.0)
    >>> round(drum.fundamental, 1), round(drum.decay, 3), drum.snares
    (140.6, 0.4, False)
    """
    diameter = check_real("diameter", diameter, low=6.0, high=24.0, unit="inches")
    fundamental = jn_zeros(0, 1)[0] * HEAD_WAVE_SPEED / (np.pi * diameter * INCH)
    return Drum(fundamental=float(fundamental), decay=TOM_DECAY * diameter / 12.0, snares=False)


def kit_voice(piece, key):
    """What ``piece`` sounds as when ``key`` is played on it: a :class:`~.audio.Drum` or a :class:`Plate`.

    By its kind and its first key (the module's docstring says how): the snare, a tom of the key's size,
    the kick, a crash, ride or bell, the hi-hat in the key's state.

    Parameters
    ----------
    piece : drumstroke.kit.pieces.Piece
    key : int
        One of the piece's keys (for the hi-hat, the one that says its state).

    >>> kit = default_kit()
    >>> kit_voice(kit.piece("snare"), 38) == Drum(), kit_voice(kit.piece("hihat"), 46) == HIHAT["open"]
    (True, True)
    >>> round(kit_voice(kit.piece("floor-tom"), 41).fundamental, 1)
    105.5
    """
    if key not in piece.keys:
        raise ParameterError(f"key must be one of pieces.{piece.name}'s keys ({', '.join(map(str, piece.keys))}), "
                             f"got {shown(key)}")
    first = piece.keys[0]
    if piece.kind == "hihat":
        return HIHAT[piece.state(key)]
    if piece.kind == "kick":
        return KICK
    if piece.kind == "cymbal":
        return RIDE if first in RIDE_KEYS else BELL if first in BELL_KEYS else CRASH
    return Drum() if first in SNARE_KEYS else tom(TOM_DIAMETERS.get(first, 12.0))


@dataclass(frozen=True, eq=False)
class KitHits:
    """Impacts on a kit: what :func:`synthesize_kit` renders.

    Attributes
    ----------
    t : ndarray [shape=(n,)]
        Times (s), finite and ≥ 0, in any order.
    piece : tuple of str [length n]
        The piece each struck, by its name in the kit.
    key : ndarray of int in [0, 127] [shape=(n,)]
        The General MIDI key each played (one of its piece's: for the hi-hat, its state).
    speed : ndarray [shape=(n,)]
        The striking speed of each (m/s), finite and ≥ 0: its level is 20 log10(v / 1 m/s) dB
        (:mod:`drumstroke.dynamics` maps it to a MIDI velocity).

    >>> hits = KitHits([0.5, 0.0], ["snare", "kick"], [38, 36], [1.0, 2.0])
    >>> len(hits), hits.piece, hits.key.tolist()
    (2, ('snare', 'kick'), [38, 36])
    """

    t: np.ndarray
    piece: tuple
    key: np.ndarray
    speed: np.ndarray = field(repr=False)

    def __post_init__(self):
        t = check_vector("t", self.t, low=0.0, unit="s")
        speed = check_vector("speed", self.speed, low=0.0, unit="m/s")
        if isinstance(self.piece, (str, bytes)) or not isinstance(self.piece, (list, tuple, np.ndarray)):
            raise ParameterError(f"piece must be a sequence of piece names, got {shown(self.piece)}")
        piece = tuple(self.piece)
        for i, name in enumerate(piece):
            if not isinstance(name, str):
                raise ParameterError(f"piece[{i}] must be a piece's name (str), got {shown(name)}")
        key = check_vector("key", self.key, low=0, high=127)
        bad = np.flatnonzero(key != np.round(key))
        if len(bad):
            raise ParameterError(f"key[{bad[0]}] must be a MIDI key, an integer in [0, 127], got {key[bad[0]]!r}")
        if not len(t) == len(piece) == len(key) == len(speed):
            raise ParameterError(f"t, piece, key and speed must have the same length, got {len(t)}, {len(piece)}, "
                                 f"{len(key)} and {len(speed)}")
        key = key.astype(np.int64)
        for name, value in (("t", t), ("piece", piece), ("key", key), ("speed", speed)):
            if isinstance(value, np.ndarray):
                value.setflags(write=False)
            object.__setattr__(self, name, value)

    @classmethod
    def from_rows(cls, rows):
        """Hits from rows (time s, piece name, key, speed m/s), e.g. a list of tuples."""
        try:
            columns = [list(column) for column in zip(*rows, strict=True)] if len(rows) else [[], [], [], []]
        except (TypeError, ValueError):
            raise ParameterError(f"rows must be a sequence of (time s, piece, key, speed m/s), got {shown(rows)}") \
                from None
        if len(columns) != 4:
            raise ParameterError(f"rows must be (time s, piece, key, speed m/s): 4 values each, got {len(columns)}")
        return cls(*columns)

    def __len__(self):
        return len(self.t)


def synthesize_kit(hits, *, kit=None, duration=None, rate=SAMPLE_RATE):
    """Render impacts on the pieces of ``kit`` as mono audio (see the module's docstring for the models).

    Parameters
    ----------
    hits : KitHits or sequence of (time s, piece, key, speed m/s)
        The impacts; may be empty.
    kit : Kit or None
        The kit whose pieces are named (default: :func:`~drumstroke.kit.pieces.default_kit`).
    duration : float ≥ max(hits.t) or None
        Length of the signal (s). Defaults to the last hit (0 if none) plus :data:`~.audio.TAIL_DECAYS`
        times the longest decay time of the instruments played.
    rate : float > 18000
        Samples per second (Hz).

    Returns
    -------
    signal : ndarray [shape=(round(duration · rate),), dtype=float64]
        Samples in [-0.99, 0.99] (full scale); the mix is scaled down as a whole if its peak is higher.

    >>> snare = synthesize_kit([(0.0, "snare", 38, 1.0)], duration=0.1)
    >>> from drumstroke.render.audio import synthesize
    >>> bool(np.array_equal(snare, synthesize([0.0], [1.0], duration=0.1)))
    True
    """
    hits = hits if isinstance(hits, KitHits) else KitHits.from_rows(hits)
    kit = default_kit() if kit is None else kit
    if not isinstance(kit, Kit):
        raise ParameterError(f"kit must be a drumstroke.kit.pieces.Kit, got {shown(kit)}")
    rate = check_real("rate", rate, low=2.0 * SNARE_BAND[1], low_open=True, unit="Hz")
    voices, hihats = _voices(hits, kit), _hihats(hits, kit)
    last = float(hits.t.max()) if len(hits) else 0.0
    if duration is None:
        rings = [_ring_time(voice) for voice in voices] + [p.ring_time for _, plates in hihats.values() for p in plates]
        duration = last + TAIL_DECAYS * max(rings, default=0.0)
    duration = check_real("duration", duration, low=last, unit="s")
    check_synthesis(duration, rate)
    size = round(duration * rate)
    signal = np.zeros(size)
    for voice, chosen in voices.items():
        if isinstance(voice, Drum):
            signal += ring(hits.t[chosen], hits.speed[chosen], voice, rate=rate, size=size)
        else:
            signal += _plate(hits.t[chosen], hits.speed[chosen], voice, rate, size)
    for chosen, plates in hihats.values():
        signal += _plates(hits.t[chosen], hits.speed[chosen], plates, rate, size)
    return limit_peak(signal)


def render_kit_wav(path, hits, *, kit=None, duration=None, rate=SAMPLE_RATE, bundle=None):
    """Synthesize impacts on a kit (see :func:`synthesize_kit`) and write them as an audio file, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Where to write: ``.wav``, ``.flac`` or ``.ogg`` (the format follows the extension).
    hits : KitHits or sequence of (time s, piece, key, speed m/s)
    kit : Kit or None
        The kit (default: the shipped one).
    duration : float or None
        Length (s); defaults to the last hit plus a ring-out.
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
    ...     signal = render_kit_wav(pathlib.Path(folder) / "kit.wav", [(0.0, "crash", 49, 1.0)], duration=0.5)
    ...     len(signal)
    24000
    """
    audio_format(path)  # before the work, not after it
    with located(f"audio file {str(path)!r}"):
        signal = synthesize_kit(hits, kit=kit, duration=duration, rate=rate)
    write_wav(path, signal, rate=rate, bundle=bundle)
    return signal


def _voices(hits, kit):
    """{voice: indices of the hits it plays}, each hit's piece and key checked against the kit (a hi-hat's hits,
    of every state, are one instrument: :func:`_hihats`)."""
    chosen = {}
    for i, (name, key) in enumerate(zip(hits.piece, hits.key.tolist())):
        try:
            voice = kit_voice(kit.piece(name), key)
        except ParameterError as error:
            raise ParameterError(f"hit {i} (t = {hits.t[i]:g} s): {error}") from None
        if kit.piece(name).kind != "hihat":
            chosen.setdefault(voice, []).append(i)
    return {voice: np.array(indices) for voice, indices in chosen.items()}


def _hihats(hits, kit):
    """{hi-hat's name: (indices of its hits, each hit's Plate: its state's)}: each hi-hat one instrument, whatever
    the state of each hit (the hits checked by :func:`_voices`)."""
    chosen = {}
    for i, (name, key) in enumerate(zip(hits.piece, hits.key.tolist())):
        piece = kit.piece(name)
        if piece.kind == "hihat":
            indices, plates = chosen.setdefault(name, ([], []))
            indices.append(i)
            plates.append(kit_voice(piece, key))
    return {name: (np.array(indices), plates) for name, (indices, plates) in chosen.items()}


def _ring_time(voice):
    return voice.decay if isinstance(voice, Drum) else voice.ring_time


def _plate(times, speeds, plate, rate, size):
    """The plate's modes ringing after impacts at ``times`` with ``speeds`` (as :func:`~.audio.ring` for a drum)."""
    return _plates(times, speeds, [plate] * len(times), rate, size)


def _plates(times, speeds, plates, rate, size):
    """One set of modes struck at ``times`` with ``speeds``, each hit as its :class:`Plate` of ``plates`` (one per
    hit, all with the same modes: a hi-hat's states): its amplitudes and contact, and from it on every mode's decay."""
    kinds = list(dict.fromkeys(plates))
    which = np.array([kinds.index(plate) for plate in plates], dtype=np.int64)
    frequencies, _ = kinds[0].frequencies_and_amplitudes()
    amplitudes = np.array([kind.frequencies_and_amplitudes()[1] for kind in kinds])
    below = frequencies < rate / 2.0
    frequencies, amplitudes = frequencies[below], amplitudes[:, below]
    start = np.ceil(times * rate).astype(np.int64)
    order = np.argsort(start, kind="stable")
    order = order[start[order] < size]
    start, offset, speeds, which = start[order], start[order] - times[order] * rate, speeds[order], which[order]
    if not len(start) or not len(frequencies):
        return np.zeros(size)
    # A resting stick (v = 0) is silent anyway; the floor only keeps its contact time finite.
    reference = np.array([kind.contact_time for kind in kinds])[which]
    durations = contact_time(np.maximum(speeds, 1e-12), reference=reference)
    weights = GAIN * speeds[:, None] * amplitudes[which] * half_sine_spectrum(frequencies, durations[:, None])
    decays = np.array([kind.decay * (1000.0 / frequencies) ** kind.decay_slope for kind in kinds])
    poles = (-1.0 / decays + 2j * np.pi * frequencies) / rate
    # the fraction of a sample between t_i and its first sample: the decay starts exactly at t_i
    return _ring_modes(start, weights * np.exp(poles[which] * offset[:, None]), np.exp(poles), which, size)


@njit(cache=True)
def _ring_modes(start, weights, poles, which, size):
    """Σ_k Im y_k[n], y_k[n] = x_k[n] + pole_k · y_k[n-1], x_k the weights[:, k] at the (sorted) samples ``start``.

    The poles are those of the last hit so far: ``poles[which[hit]]`` (one row per kind of hit), so a hi-hat's
    modes ring at the rate of its latest state. One pass over the samples for all the modes: a plate has
    hundreds, and one filter each would cost ten times as much.
    """
    out = np.zeros(size)
    state = np.zeros(poles.shape[1], np.complex128)
    now = poles[which[0]]
    hit = 0
    for n in range(size):
        while hit < start.shape[0] and start[hit] == n:
            state += weights[hit]
            now = poles[which[hit]]
            hit += 1
        total = 0.0
        for k in range(poles.shape[1]):
            total += state[k].imag
            state[k] *= now[k]
        out[n] = total
    return out
