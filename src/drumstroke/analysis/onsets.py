"""A recording's impacts: when the stick struck the head and how loud, relative to the loudest.

Audio tells levels only up to one gain (the microphone's distance, the preamp): levels here are in
dB re the loudest onset (0 dB is the loudest, the others below). The model's levels are absolute (dB re
1 m/s tip speed, :mod:`drumstroke.dynamics`); a fit finds the offset (:mod:`.fit`).

A recording's onsets are found by :func:`find_onsets` (samples) or :func:`find_recording_onsets` (a
file), a pipeline of stages whose every threshold is a field of :class:`OnsetConfig`. Onsets go to and
come from an onsets CSV (:mod:`drumstroke.formats.onsets_csv`: ``t,level_db`` rows, the source and
threshold in the JSON beside it): :func:`write_onsets`, :func:`read_onsets` (which reads CSVs only).

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

import math
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from functools import cache
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
        Each onset's level (dB re the loudest onset: ≤ 0, finite; the loudest is 0): the amplitude of
        the drum's lowest modes, in proportion to the stick's tip speed on drumstroke's drums (what
        :mod:`.drop` compares with the model; :mod:`.fit` plays it or ``peak_db``, whichever changes
        more smoothly from bounce to bounce, unless told).
    threshold_db : float
        The detection threshold used (dB re the loudest onset; onsets below it are not reported), or
        -inf when the onsets were given rather than detected.
    source : str
        What they came from (a file's name, or a description).
    peak_db : ndarray [shape=(n,)] or None
        Each onset's broadband peak (dB re the loudest onset's peak: ≤ 0, finite; the largest is 0): the
        loudest sample of its own sound on the unfiltered signal, the earlier notes' continuation taken
        off (:func:`find_onsets`); what a recording's loudness of each note is. None when the onsets
        were given as times and levels.
    """

    t: np.ndarray
    level_db: np.ndarray
    threshold_db: float = -np.inf
    source: str = ""
    peak_db: np.ndarray | None = None
    info: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        t = check_vector("onset times t", self.t, low=0.0, unit="s")
        level = check_vector("onset levels level_db", self.level_db, high=0.0, unit="dB")
        if len(t) != len(level):
            raise ParameterError(f"onset times and levels must be as many, got {len(t)} times and {len(level)} levels")
        if len(t) > 1 and not np.all(np.diff(t) > 0.0):
            i = int(np.flatnonzero(np.diff(t) <= 0.0)[0]) + 1
            raise ParameterError(f"onset times t must be strictly increasing, got t[{i}] = {float(t[i])!r} after "
                                 f"{float(t[i - 1])!r} s")
        if len(level) and level.max() != 0.0:
            raise ParameterError(f"onset levels level_db must be re the loudest (its level 0 dB), got a largest of "
                                 f"{level.max()!r} dB")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "level_db", level)
        if self.peak_db is not None:
            peak = check_vector("onset peaks peak_db", self.peak_db, high=0.0, unit="dB")
            if len(peak) != len(t):
                raise ParameterError(f"onset peaks peak_db must be as many as the times, got {len(peak)} peaks and "
                                     f"{len(t)} times")
            if len(peak) and peak.max() != 0.0:
                raise ParameterError(f"onset peaks peak_db must be re the loudest peak (its peak 0 dB), got a largest "
                                     f"of {peak.max()!r} dB")
            object.__setattr__(self, "peak_db", peak)

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


def write_onsets(path, onsets, *, bundle=None):
    """Write ``onsets`` to the onsets CSV at ``path`` (``t,level_db``, and ``peak_db`` when they have it) and the JSON
    beside it, atomically, together.

    The JSON holds the source, the detection threshold (dB re the loudest; null when the onsets
    were given) and ``info`` (how they were found).

    Parameters
    ----------
    path : str or os.PathLike
        Ending in ``.csv``, in an existing folder.
    onsets : Onsets
    bundle : Bundle or None
        A :class:`drumstroke._atomic.Bundle` to put the files in place with (default: a bundle of their own).
    """
    if not isinstance(onsets, Onsets):
        raise ParameterError(f"onsets must be an Onsets, got {type(onsets).__name__}")
    write_onsets_csv(path, onsets.t, onsets.level_db, peak_db=onsets.peak_db,
                     fields={"source": onsets.source, "threshold_db": onsets.threshold_db, "info": onsets.info},
                     bundle=bundle)


def read_onsets(path):
    """The onsets in the onsets CSV at ``path``, as :func:`write_onsets` wrote them.

    A recording is not read here: :func:`find_recording_onsets` finds its onsets (detection).

    Parameters
    ----------
    path : str or os.PathLike
        An onsets CSV (``.csv``: ``t,level_db`` or ``t,level_db,peak_db``); its source and threshold from the JSON beside it
        when there is one, else the file's name and -inf.

    Returns
    -------
    Onsets

    Raises
    ------
    ParameterError
        Naming the file (and the line) of what it refuses; naming :func:`find_recording_onsets`
        for a file that is not a CSV (a recording).
    """
    path = Path(path)
    if path.suffix.lower() != ".csv":
        raise ParameterError(f"read_onsets reads onsets CSVs (.csv) only, got {str(path)!r}: find a recording's "
                             "onsets with find_recording_onsets(path) (or find_onsets(signal, rate))")
    t, level_db, peak_db, meta = read_onsets_csv(path)
    info = meta.get("info")
    try:
        return Onsets(t, level_db, threshold_db=meta.get("threshold_db", -np.inf),
                      source=str(meta.get("source") or path.name), peak_db=peak_db,
                      info=info if isinstance(info, dict) else {})
    except ParameterError as error:
        raise ParameterError(f"onsets file {str(path)!r}: {error}") from None

# ------------------------------------------------------------------------------------------ onsets from audio

MIN_RATE = 8000
"""The lowest sample rate analysed (Hz)."""

MAX_SECONDS = 600.0
"""The longest recording analysed (s); a longer file is refused before it is read."""

WORKING_COPIES = 3
"""Signals as long as the recording that reading and the detector hold besides the file's samples (measured on a
mono file: some 33 bytes a sample in all), for the memory a recording is estimated to ask for
(:mod:`drumstroke.budget`)."""

CLIP_LEVEL = 0.999
"""Samples at or above this magnitude (full scale) count as clipped."""

_BLOCK = 1 << 20  # samples a block when looking for jumps: bounds the memory, not a tuning
_LAG_ROWS = 256  # rows of the lagged data a block of the normal equations: 84 kB at order 40, not a tuning
_SPECTRA = 4096  # the most frames whose spectra choose the decimation: bounds the time on a long file


@dataclass(frozen=True)
class OnsetConfig:
    """Every threshold, length and count of the onset detector (:func:`find_onsets`), each with its unit.

    The defaults are the values the accuracy in docs/analysis.md was measured with; a variant is
    ``dataclasses.replace(OnsetConfig(), threshold_db=-30.0)``. The steps named are those of
    :func:`find_onsets`. A jump is the RMS over the next window over that over the 4 windows before.

    Parameters
    ----------
    threshold_db : float in [-120, 0]
        dB re the loudest onset: quieter onsets are not reported (step 6).
    min_interval : float in [0.0005, 1]
        s: the shortest time between two onsets; closer attacks are one (steps 2-4).
    floor_margin_db : float in [0, 60]
        dB: how far over the noise floor an onset must be; the threshold used is at least the floor
        plus this (step 6).
    floor_quantile : float in [0, 1]
        Ratio: the quantile of the lowest band's 5-ms peaks that is the noise floor (step 6).
    high_pass : float in [1, 1000]
        Hz: the corner of the high-pass that takes off rumble and DC first; also the lowest
        frequency a strong mode of the level band may have (steps 1, 5).
    analysis_rate : int in [2000, 768000]
        Hz: the rate step 2 decimates to at most (less where the signal's band ends lower).
    order : int in [1, 400]
        The order of step 2's linear predictor (Burg's method): up to 20 ringing modes and the
        anti-alias filter's 8 poles.
    min_jump : float in [1, 100]
        RMS ratio: the least jump of step 2's innovation (over 1 ms) at a candidate, and of the
        modes' band's remainder at an attack (step 4).
    broadband_jump : float in [1, 100]
        RMS ratio: the least jump of the first difference (over 1 ms) at a broadband attack (step 3).
    tonal_support : float in [1, 100]
        RMS ratio: the least jump of step 2's innovation at a broadband attack too (beating modes
        make broadband jumps alone; step 3).
    strong_rise : float in [1, 1000]
        RMS ratio: the jump of step 2's innovation at which its time is trusted over a broadband time
        of the same onset more than ``disagreement`` away (step 3).
    disagreement : float in [0, 0.01]
        s: how far apart an onset's broadband and tonal times may be and still be one attack's (step 3).
    modes_rate : int in [500, 8000]
        Hz: the rate the modes' band is decimated to (its anti-alias corner at 0.4 of it: below the
        snare wires; step 4).
    modes_width : int in [1, 64]
        Samples of the modes' band: the shortest window of its jumps (2 ms at 2 kHz; step 4).
    modes_order : int in [1, 400]
        The order of the modes' band's predictor (least squares, reweighted; step 4).
    signature : float in [0.001, 0.5]
        s: how long an attack's signature in the modes' band's innovation lasts past its spike: the
        spike, the modes' beating, the room's first reflections (step 4).
    head : int in [1, 100]
        Samples of the modes' band: the start of the signature after its spike whose correlation
        with an onset's start is its likeness (step 4).
    tail : float in [0.001, 2]
        s: how long the attacks' common response (the room's tail, least squares over all the
        onsets) lasts from the signature's start (steps 4, 5).
    room : float in [0, 100]
        Energy ratio: the least energy of the room's tail past the signature, over the signature's
        part, that makes a recording reverberant (measured 0.11-0.14 in the tests' room, under 0.01
        without it; steps 4, 5).
    tail_ridge : float in [1e-06, 1]
        Ratio: the ridge on the tail's least-squares fit, a fraction of its normal equations' diagonal.
    second_gap : float in [0, 100]
        Multiples of ``min_interval``: how far a later round's onset in the modes' band must be from
        the onsets known before it (step 4).
    likeness : float in [0, 1]
        Correlation: the least likeness of an onset's start to the signature for an attack found in
        the modes' band alone (step 4).
    weak_likeness : float in [0, 1]
        Correlation: a likeness that makes an onset an attack when step 2's innovation jumps
        ``weak_rise`` times at it (a quiet one in a room's tail; step 4), and lets the search after
        louder attacks accept ``after_weak_f``.
    weak_rise : float in [1, 100]
        RMS ratio: that jump of step 2's innovation (step 4).
    sure_likeness : float in [0, 1]
        Correlation: a likeness that makes an onset an attack with a jump of ``sure_jump`` only (step 4).
    sure_jump : float in [1, 100]
        RMS ratio: that least jump of the remainder (step 4).
    precise_likeness : float in [0, 1]
        Correlation: the least likeness of the broadband and tonal onsets whose times set the offset
        of the times fitted in the modes' band (step 4).
    moved_jump : float in [1, 100]
        RMS ratio: the least jump of the remainder where an onset in a room's tail that does not look
        like the signature is tried again, a little later (step 4, reverberant recordings).
    move_reach : float in [0, 100]
        Multiples of ``min_interval``: how far after it such an onset is tried again (step 4).
    after_reach : float in [0, 0.5]
        s: how far after an attack a quiet one is sought by fitting its whole signature (step 4).
    after_f : float ≥ 0
        The least F statistic (two parameters, over the louder attack's signature) of such a quiet
        attack's fit (step 4).
    after_weak_f : float ≥ 0
        The F statistic enough for a quiet attack whose start looks like the signature by
        ``weak_likeness`` (step 4).
    after_ratio_low : float in [0, 100], ≤ ``after_ratio_high``
        Amplitude ratio: the least scale of such a quiet attack over the louder one's (a bouncing
        stick's next impact: a few dB quieter, not what is left of the louder one's signature; step 4).
    after_ratio_high : float in [0, 100]
        Amplitude ratio: the largest such scale (step 4).
    after_rounds : int in [0, 100]
        How many times at most that search runs (each with the attacks it found taken off too), while
        it finds more (step 4).
    spike_db : float in [-60, 60]
        dB: how far the modes' band's innovation must spike at an attack found there alone, over its
        RMS over the 10 ms before the spike (step 4).
    spike_clear : float in [0, 1]
        s: that spike is asked of such an attack this long or more after the attack before it (step 4).
    level_order : int in [1, 400]
        The order of the predictor of the band levels are measured in (step 5).
    level_ratio : float in [1, 10]
        Frequency ratio: the top of the level band over its lowest strong mode (step 5).
    level_band : float in [50, 4000]
        Hz: the lowest top of the level band (step 5).
    start_db : float in [-120, 0]
        dB re an attack's peak: where its first transient starts (step 5).
    start_over : float in [1, 100]
        Peak ratio: how far its first transient stands over the sound before it (step 5).
    start_reach : float in [0, 0.02]
        s: how far from where it was found an attack's first transient is sought (step 5).
    start_clear_db : float in [-120, 0]
        dB re an attack's peak: the loudest the sound before it may be for its first transient to
        be sought (step 5).
    decay_db : float in [-120, 0]
        dB re the loudest attack: a quieter one must rise out of the sound before it (step 5).
    decay_rise_db : float in [-60, 60]
        dB: how far such a quiet attack's first difference must rise over the 2 ms after it above
        its peak over the 5 ms before (step 5).
    echo_reach : float in [0, 0.05]
        s: an attack this close after the one before it must rise out of that one's sound too (a
        recorded sample's second burst; step 5); a detection no template fits, this close before a
        bounce the search finds past it, is that bounce placed early (step 5).
    echo_rise_db : float in [-60, 60]
        dB: how far such a close attack's first difference must rise over the 2 ms after it above
        its peak over the 5 ms before (step 5).
    lead_rise : float in [0.01, 1]
        Ratio to an attack's peak first difference: where its main rise is (step 5).
    lead_clear_db : float in [-120, 0]
        dB re an attack's peak: the loudest the sound before it may be for it to be clear, its
        lead-in to its main rise measured (step 5).
    lead_db : float in [0, 120]
        dB: how much louder than an attack one within ``start_reach`` after it must be for the
        earlier to be taken for its first transient, the two one attack (step 5).
    template_likeness : float in [0, 1]
        Correlation: the least correlation of an attack's sound with the recording's own attack
        (its template) for it to be timed or found by fitting that template (step 5).
    template_reach : float in [0, 0.01]
        s: how far from where it was found an attack over earlier sound is timed by the template (step 5).
    template_fit : float in [0.0005, 0.1]
        s: how much of the template (or up to the next attack) an attack's fit covers (step 5).
    template_head : float in [0.0005, 0.05]
        s: how much of the template a new attack's start is matched with (step 5).
    peak_window : float in [0.001, 0.1]
        s: how long after an onset (or up to the next) its broadband peak is sought (step 6).
    peak_reach : float in [0.01, 2]
        s: the longest an earlier note's sound is followed and taken off under the later ones (step 6).
    peak_templates : int in [0, 100]
        How many of the recording's clear notes (the loudest) make the templates of a note's sound, one a
        velocity layer (step 6; 0: none taken off).
    peak_clear_db : float in [-120, 0]
        dB re a note's peak: the loudest the 10 ms before it may be for it to make a template (step 6).
    peak_layer_likeness : float in [0, 1]
        Correlation over ``peak_window`` s: the least for a clear note to share a layer's template (step 6).
    peak_apart_db : float in [-120, 0]
        dB re a note's peak: the least rise of a later onset's peak (over the 10 ms before it) that ends the
        note's waveform in its layer's template; quieter ones are outvoted there (step 6).
    peak_realign : float in [0, 0.005]
        s: how far either way of an onset its template's fit is sought again where the fit within 60 µs leaves
        more than 30 % of the note unexplained (step 6; 0: never, as before issue 28's levels round).
    peak_learn : float in [0, 1]
        The fraction of a note's first ``peak_window`` s its best template leaves unexplained over which the
        layers no clear note makes a template of are learned from the quietest notes with 40 ms or more of room,
        and a note closer than ``peak_window`` s to the next has its peak read from its fitted template where that
        explains 70 % or more of its window (step 6;
        0: never, every peak its window's largest sample, as before issue 28's peak-levels round).
    sound_templates : int in [0, 100]
        How many of the recording's clear notes (the loudest), each up to the next onset, are templates of the
        earlier notes' sound where an attack's own sound is weighed (step 5, ``new_sound_db``).
    soft_jump : float in [1, 100]
        RMS ratio: the least jump of the remainder at a refused onset that starts like a softer stroke's
        signature (step 4).
    soft_contact : float in [0, 0.02]
        s: the longest contact (a half sine) the signature is smoothed by to look like a softer stroke's
        (step 4; 0: only the signature itself).
    bounce_reach : float in [0, 0.5]
        s: how far after an attack a quieter one is sought where the template's start fits what is
        left, whatever it rises, past a detection no template fits (step 5; 0: not at all).
    refused_likeness : float in [0, 1]
        Correlation: the least of the template's fit (its first ``template_fit`` s and its start) at an
        onset refused in step 4, ``signature`` s or more after the attack before it, for it to be an
        attack after all (step 5; 1: none is).
    new_sound_db : float in [-120, 0]
        dB re the sound at an attack: the least its own sound (the earlier attacks' taken off as in
        step 6, over ``peak_window`` s) may be for it to be an attack (step 5; -120: every one is).
    burst_db : float in [-120, 0]
        dB re what was there: the most that taking off the template's fit of an attack it timed may leave over the
        1 ms after a detection within ``echo_reach`` s after it for that detection to be the attack's own sound
        (step 5; -120: none is).
    layer_likeness : float in [0, 1]
        Correlation: the least of the quietest clear attack's fit (its first ``template_fit`` s and its start) at an
        onset step 4 refused, as for ``refused_likeness``, for it to be an attack after all (step 5; 1: none is,
        the pass not run; 0.8 finds 7 more of the corpus's loud notes within 1 ms, in rolls' ghost notes).
    reflection_pairs : int in [0, 100]
        How many pairs of successive onsets, each later one ``reflection_db`` or more under the one before it,
        at one delay (within ``reflection_spread`` s) make every such later one a room's reflection, no onset
        (step 6; 0: none is).
    reflection_db : float in [0, 120]
        dB: how much quieter than the onset before it a reflection is at least (step 6).
    reflection_spread : float in [0, 0.005]
        s: how far apart the delays of one reflection's pairs may be (step 6).
    room_decay_db : float in [-120, 0]
        dB re the loudest: in a reverberant recording, an attack found in the modes' band alone (kind 2, no
        template fitted it), ``spike_clear`` s or more after the attack before it and quieter than this, that does
        not rise ``room_rise_db`` out of the sound before it and brings nothing new over the sound the recording
        has at the same delay after another note (``room_echo_db``) is a room's echo, no attack (step 5,
        :func:`_room_echoes`; -120: none is, as before this field).
    room_rise_db : float in [-60, 60]
        dB: how far the first difference over the 2 ms after such an attack must pass its peak over the 5 ms before
        for it to be an attack whatever it repeats (step 5, :func:`_room_echoes`).
    room_echo_db : float in [-60, 60]
        dB: the most that the power left over the 5 ms after such an attack may pass that left over the 5 ms before
        it, once the band over those 10 ms is fitted (by least squares, within 0.5 ms) by the band at the same
        delay after another note as loud as one ``reflection_db`` or more louder than it 35 ms to 0.3 s before it
        (nothing found between), for it to be that note's echo (step 5, :func:`_room_echoes`).
    room_fit_db : float in [-60, 0]
        dB re its energy: the most that fit may leave of the band over those 10 ms for the other note's sound to
        explain it at all (step 5, :func:`_room_echoes`).
    room_found_fit_db : float in [-120, 0]
        dB re its energy: the same for an attack the template timed (kind 3), tried after the reflections are taken
        off (step 6, :func:`_room_returns`): such an attack is a room's return only where that sound explains
        nearly all of it; the attacks of the modes' band alone are tried again there (-120: neither, as before
        this field).
    found_burst_db : float in [-120, 0]
        dB re what was there: the most that taking off an attack's fit in the template search may leave over the
        1 ms after the next detection, within ``bounce_reach`` s after it, for that detection to be the attack's own
        sound, dropped (step 5, :func:`_template_search`; -120: none is, as before this field).
    found_decay_db : float in [-120, 0]
        dB re the loudest: as ``decay_db``, for an attack the template timed or found (step 5, :func:`_out_of_decay`;
        its fit over what is left of the earlier sound is its test; -32, ``decay_db``'s: as before this field).
    earlier_reach : float in [0, 0.02]
        s: how far before a detection over earlier sound (not clear by ``lead_clear_db``) the template search seeks
        where it starts: where the template fits better than at the detection, its start correlating by
        ``weak_likeness`` and the whole template by ``template_likeness`` (a sample's second burst detected and its
        first not: FluidR3's electric snare, 3.4 ms into a note; step 5, :func:`_template_search`; 0: not at all, as
        before this field).
    bounce_likeness : float in [0, 1]
        Correlation: the least of the template's start (``template_head`` s) with what is left at a close bounce the
        template search finds; the template's first ``template_fit`` s must
        still correlate by ``template_likeness`` (a quiet velocity layer's start is unlike the loud template's; step 5;
        0.8, ``template_likeness``'s: as before this field).
    bounce_ratio_low : float in [0, 100]
        Amplitude ratio: the least scale of a close bounce the template search finds re the template's fit of the
        attack before it, as ``after_ratio_low`` for step 4's search (step 5; 0.35, ``after_ratio_low``'s: as before
        this field).
    found_echo_rise_db : float in [-60, 60]
        dB: as ``echo_rise_db``, for an attack the template timed or found (step 5, :func:`_out_of_decay`; its fit is
        its test; -3.5, ``echo_rise_db``'s: as before this field).
    layer_bounce_likeness : float in [0, 1]
        Correlation: where the template search's loud template finds no close bounce after an attack the quietest
        clear attack's sound (the second template) took off, the least correlation of that sound's first
        ``template_fit`` s with what is left at a bounce it finds, its start by ``weak_likeness`` (a drop's quiet
        bounces are that layer's; step 5; only where the recording replays a sample, by ``replay_likeness``; 1: none
        is sought, as before this field).
    replay_likeness : float in [0, 1]
        Correlation: a recording replays a sample (a sample player's velocity layers, ``layer_bounce_likeness``) where
        two clear attacks' first ``template_fit`` s correlate so (step 5; 0: every recording with two clear attacks
        does).
    ghost_rise_db : float in [0, 120]
        dB: a ghost note under an accent's sound, where the recording replays a sample, rises so much over the
        10 ms before in what is left once the accent's own sound (another note of its layer) is taken off (step 5,
        :func:`_ghost_notes`; 120: none sought, as before this field).
    layer_echo_db : float in [-120, 60]
        dB: the most that the power left over the 5 ms after a quiet attack of the modes' band alone may pass that
        left over the 5 ms before it, once the band over those 10 ms is fitted (by least squares, together) by the
        band at the same delays after other notes, one window for each note before it, for it to be the earlier
        notes' own sound going on, where the recording replays a sample (``replay_likeness``; step 5,
        :func:`_layer_echoes`; -120: none is, as before this field).
    layer_decay_db : float in [-120, 0]
        dB re the loudest: the attacks so tried are quieter than this (step 5, :func:`_layer_echoes`).
    ghost_own_db : float in [-60, 120]
        dB: where one layer-mate alone reaches a ghost note (the others' own next notes came first), a rise in what
        is left once it is taken off counts when the note's sound over the 11 ms from it is so much louder in the
        accent than in that mate (scaled), the accent's own note, not the mate's left negated (step 5,
        :func:`_ghost_notes`; 120: two mates needed, as before this field).
    ghost_room_own_db : float in [-60, 120]
        dB: in a recording step 4 finds reverberant, a ghost note's rise in what is left once a layer-mate is taken
        off counts when the note's sound over the 11 ms from it is so much louder in the accent than in that mate:
        what is left of the room's returns of earlier notes is alike in both (step 5, :func:`_ghost_notes`; 120: none
        sought in a reverberant recording, as before this field).
    ghost_room_fit : float in [0, 1]
        Correlation: in a recording step 4 finds reverberant, a ghost note's rise of 4 dB or more in what is left
        once a layer-mate is taken off counts where the quietest clear attack's first 5 ms fit that remainder so:
        the earlier notes' returns are a smoothed sound, a ghost note its layer's waveform (step 5,
        :func:`_room_ghost_notes`; 1: none sought, as before this field).
    found_bursts : int in [1, 10]
        How many detections in a row after an attack the template search may drop as that attack's own sound by
        ``found_burst_db``, the first within ``bounce_reach`` s after it, the others within ``earlier_reach`` s
        (FluidR3's electric snare: a detection on a bounce's main rise 1 ms late, then its second burst 3.4 ms in;
        step 5, :func:`_template_search`; 1: the first only, as before this field).
    burst_unfitted_likeness : float in [0, 1]
        Correlation: once a detection is dropped as an attack's own sound (``found_burst_db``), the next one within
        ``bounce_reach`` s, over earlier sound and not timed by the template, where the attack's fitted sound
        correlates under this is no end to that attack's fit: fitted past it, the search for a close bounce looks
        past it (FluidR3's snare 40 with reverb: a bounce detected in the modes' band 1.3 ms late; step 5,
        :func:`_template_search`; 0: none is, as before this field).
    fitted_lead_db : float in [0, 120]
        dB: ``lead_db`` for two attacks both timed or found by the template (step 5, :func:`_one_attack_each`): a
        dropped stick's close bounces, each fitted apart, whose quiet velocity layer reads louder than the bounce
        before (120: never one attack; 6, ``lead_db``'s, as before this field).
    layer_whole_likeness : float in [0, 1]
        Correlation: where neither template's search with its start finds a close bounce after an attack the
        quietest clear attack's sound took off (``layer_bounce_likeness``), the least correlation of that sound's
        first ``template_fit`` s alone with what is left at a bounce (its scale ``bounce_ratio_low`` to
        ``after_ratio_high`` times that attack's; no start asked: the quiet layer peaks 9.4 ms in and its first
        3 ms lie under the room's sound or the bounce before's; step 5; 1: not sought, as before this field).
    layer_echo_partners : int in [0, 1]
        1: a note whose sound at a delay explains a quiet attack (:func:`_layer_echoes`) may have its own return at
        that delay (within 1.5 ms), an attack tried so too, in the window it needs clear (two returns of the room
        67 ms after a drop's two trains' last bounces each lie in the other's partner's window; 0: no attack may, as
        before this field).
    layer_start_reach : float in [0, 0.005]
        s: a detection over earlier sound, not timed by the template, within ``bounce_reach`` s after an attack
        (a train's bounce), is put where the quietest clear attack's sound (its first ``template_fit`` s) correlates
        best within this before it, by ``template_likeness`` and more than two samples before it, and a detection
        within this after a bounce the search found is that bounce (FluidR3's snare 40: bounces detected on their
        main rise 0.94 ms late, their sound taken off there hid the next; step 5; 0: not sought, as before this
        field).
    layer_joint_likeness : float in [0, 1]
        Correlation: where ``layer_whole_likeness`` finds no close bounce after a flight of 9 ms or less, the
        bounce before fitted again together with the quietest clear attack's sound at each sample (two scales,
        least squares), from 3.5 ms on: the least correlation of that sound's first ``template_fit`` s with what
        the bounce before so fitted leaves (its fit alone took in some of the next bounce's sound: FluidR3's snare
        38 with reverb, 0.70 alone, 0.73 so); not after a bounce so found (step 5; 1: not sought, as before this
        field).
    layer_train_found : int in [0, 1]
        1: a bounce the quiet layer's searches found (``layer_bounce_likeness``, ``layer_whole_likeness``,
        ``layer_joint_likeness``) is taken off by the layer where the loud template fitted it better (the layer's
        train goes on: FluidR3's snare 38, seed 1, 4.0554 s), and the next bounce is sought up to one and a half
        times the longer of the flight before and the mean of the two flights before (FluidSynth's 1.3-ms blocks
        jitter each onset: a flight of 4.0 ms then one of 6.7; step 5; 0: neither, as before this field).
    layer_found_bursts : int in [0, 1]
        1: a detection over earlier sound, not timed by the template, within ``earlier_reach`` s after a bounce the
        search found after one the quiet layer took off, where the bounce's fit cut there correlates under
        ``template_likeness``, is that bounce's own rise (dropped, the bounce fitted past it) where the layer fitted
        past it correlates by ``template_likeness`` and the layer fitted at the detection does not (FluidR3's snare
        40 dry, seed 2: 4.0404 s detected again 1.6 ms in, 0.42 cut there, 0.93 past it, -0.4 at it; step 5; 0: not
        sought, as before this field).
    layer_train_refit : int in [0, 4]
        How many of a train's bounces the quiet layer took off (each within 10 ms after the one before) are
        fitted again together with the next bounce once the search finds it: their scales by least squares with
        the layer's at the new one, from the first one's window to the end of the new one's first
        ``template_fit`` s or one flight after it (where the bounce after it may sound), each taken off again so (kept as they were where a scale so fitted is not positive).
        Each bounce's own fit takes in the next one's start, and what it leaves adds up along the train (FluidR3's
        drops' last bounces are another velocity layer than the template's, 0.96 alike: at the snare 40 dry drop's
        last bounce, seed 2, what the earlier ones leave is -2.4 dB re the bounce, even so; step 5; 0: none, as
        before this field, its default: with 2, FluidR3's snare 38 drop with reverb of tests/test_onsets_fast_path.py
        lost a bounce at 4.0554 s, -25.9 dB, that ``layer_joint_likeness`` found: the bounce before's own fit, over a
        remainder the refit changed, took in more of it, 0.711 there, 0.649 so; on seeds 1-2 of the corpus it found
        3 loud notes more, FluidR3's snare 38 drop with reverb, seed 1, and snare 40 drop at -60 dBFS, seed 2).
    layer_skipped_search : int in [0, 1]
        1: where the template's search after a bounce the quiet layer took off finds the next past a detection that
        bounce's fit skipped (which is then dropped as that bounce placed early, up to ``echo_reach`` s before it),
        the layer's search (``layer_bounce_likeness``) is made first up to the detection: a quiet bounce detected on
        its later burst alone, whose start the loud template does not fit (FluidR3's snare 40 drop with reverb, seed
        2: 4.0217 s, detected 3.8 ms in, the template's bounce 9.3 ms on; step 5; 0: not, as before this field).
    ghost_noise_start : float in [0, 0.005]
        s: where what is left before a ghost note is white noise (its correlation one sample on within 0.6 of 0),
        the note's onset, read as its first sample four times that noise's RMS (late by a slow lead-in under it), is
        moved to where the power changes (the split into two white noises of the most likelihood) up to so long
        before its rise, where it is a new note (step 5, :func:`_ghost_notes`; 0: not moved, as before this field).
    ghost_rise_gap : float in [0, 0.005]
        s: where what is left before a ghost note is white noise, its rise by ``ghost_rise_db`` is read also against
        the 10 ms before a gap so long, and its onset sought from the gap's start: a quiet note's lead-in under the
        noise is in the 10 ms before its main rise (step 5, :func:`_ghost_notes`; 0: not, as before this field).
    ghost_mate_notes : float in [0, 1]
        Correlation: where a layer-mate's next note is the accent's own waveform by this much (over its first 10.5 ms,
        the mate taken off; a sample player that replays one sample at every velocity: TimGM6mb's snare 38, 1.000 dry,
        0.996-0.998 with reverb), it is taken off the mate's remainder with the accent's own sound placed there and
        scaled by least squares, and that remainder reaches on to the mate's note after it: a ghost note late after
        its accent, past every mate's own ghost note (steps 5, :func:`_ghost_notes` and :func:`_room_ghost_notes`;
        1: none taken off, each mate's remainder up to its next attack, as before this field).
    ghost_matched_fit : float in [0, 1]
        Correlation: where the recording replays a sample, a ghost note is also sought by a matched filter of its
        layer's own first 5.5 ms, learned from the ghost notes found (their remainders once the accents' mates are
        taken off, aligned and averaged, kept where they correlate so): where the mean of what the mates leave (a
        mate whose own next attack is such a note taken off less it) rises 6 dB over 1 ms and fits that head by this
        or more, a note (step 5, :func:`_matched_ghost_notes`; 1: none sought, as before this field).
    template_start_db : float in [-120, 0]
        dB re the template's attack's peak (its band's largest magnitude over the 5 ms after it): the template's
        start (:func:`_attack_sound`) is moved back to the first sample up to 2 ms before
        where it was detected whose magnitude is over this and 1.5 times the largest over the 5 ms before (noise): the
        attacks it times inherit its time (TimGM6mb's snare 40 rises to 2-4 % of its peak a millisecond before its main
        rise, which at -60 dBFS noise is what is detected: every template-timed bounce was 0.5-1.2 ms late); 0: the
        start stays where it was detected, as before this field.
    template_start_past_db : float in [0, 120]
        dB: a detection less than 7 ms before the template's attack stops its start being sought (the 5 ms of noise
        it is read against must come after that detection) only when its own peak (the band's largest magnitude over
        the 0.5 ms after it) is less than this under the attack's (over 5 ms): a detection in the noise before a clear attack is not an
        attack, and the noise's level the start is asked to pass covers its sound (TimGM6mb's snare 40 at -72 dBFS:
        a detection 1.4 ms before the note, and every template-timed bounce was 1.13 ms late; a detection 0.5 ms
        before the main rise, on the note's own lead-in); 0: only one as loud as the attack, which a clear attack
        never has before it; 120: every detection stops it, as before this field.
    train_reach : float in [0, 0.1]
        s: step 5's search for a close bounce reaches past ``bounce_reach`` (:func:`_template_search`): up to
        ``echo_reach`` after a detection the attack's fit looked past or dropped as its own sound (the next bounce,
        placed early by the modes' band); and where none is found, after a bounce of a train whose flight before is
        this or less (no longer than the flight before it, nor shorter than two thirds of it, the bounce no more than
        1 dB louder by its fit than the one before: a drop's flights shrink, its bounces fade), from 0.7 times that
        flight on to 1.5 ms past it. Where step 4 finds none of a drop's bounces 26-30 ms apart (FluidR3's snare 38
        with reverb), the search, 25 ms long, ended the train there, its last 12 bounces lost; 0 (or
        ``bounce_reach`` 0, no close bounce sought): neither, as before this field.
    ghost_room_reach : float in [0, 0.005]
        s: in a recording step 4 finds reverberant, the quiet attack is fitted to what the layer-mates leave from so
        long before the rise's block (to 5 ms after it; :func:`_room_ghost_notes`): a swell of what they leave before
        a ghost note lifts the level its rise is read against, and the rise comes up to 1.7 ms after the attack's
        window's start (FluidR3's snare 38 roll with reverb, seed 0: 1.7621 s); 1e-3: as before this field.
    room_partner_under_db : float in [0, 120]
        dB: in step 5's test of a room's echo (:func:`_room_echoes`), an attack kept there is tried again with each
        partner's sound clear up to its next attack less than so much under it (a ghost note found after an accent
        ends no partner's window for a return of another accent 149 ms on: FluidR3's snare 38 roll with reverb,
        seed 0, 4.3427 s; that pass only refuses: :func:`_layer_echoes` sees the attacks the first one left);
        120: the next attack ends it, as before this field.
    ghost_room_spare_likeness : float in [0, 1]
        Correlation: in :func:`_room_ghost_notes`, a roll's accent (within 10 dB of the loudest clear attack, none
        as loud for 0.2 s after it) with fewer than two layer-mates (by ``replay_likeness``) takes as its mates the
        clear attacks whose first 10 ms correlate with it so (FluidR3's snare 40, velocity 95 among accents of
        97-120: 0.993 with one of 97); 1: none, as before this field.
    ghost_matched_back : float in [0, 0.005]
        s: :func:`_matched_ghost_notes` aligns the ghost notes it learns the layer's head from up to so long earlier
        (0.25 ms later) where ±0.25 ms reached both ways; one so moved more than 0.5 ms (a note found late on its
        sample's own +1 ms step: FluidR3's snare 40 roll, dry, seed 2, 3.5350 s at +1.19 ms, whose alignment ±0.25
        ms fitted the head 0.41 and taught none) is a note at the head's onset there; 0.25e-3 or less: as before this
        field.
    ghost_step_reach : float in [0, 0.005]
        s: an attack more than 2 ms and up to so long after a ghost note the room search (:func:`_room_ghost_notes`)
        or the matched search (:func:`_matched_ghost_notes`) finds, within 5 ms (so no new note), is moved onto that
        note's onset once every stage is done (:func:`_on_first_steps`): FluidR3's ghost layer rises in steps, and
        under an accent's ringing the first difference finds such a note on a later step, 2.1-4.6 ms late, where those
        searches, fitting the note's waveform, find it within 0.5 ms (seeds 0-9: 14 notes more within 1 ms, none lost,
        no false detection more). Not the ghost search's rises (:func:`_ghost_notes`: the first sample over 1 % of a
        rise's peak): on TimGM6mb's snare 40 roll with reverb (seeds 1 and 9) it finds rises 3.1-4.6 ms before notes
        found within 0.1 ms. 0: none moved, as before this field.
    reflection_drop_spread : float in [0, 120]
        dB: where step 4 finds no room, the pairs of one reflection (:func:`_without_reflections`) must also lie as
        much under their notes within so much (a room returns each note with one gain; a roll's ghost notes on the
        sound card's blocks share a delay after their accents by chance: TimGM6mb's snare 38 roll, dry, seed 4,
        three at 104.00 ms, 13.3-20.1 dB under); 120: the delay alone, as before this field.
    reflection_excess : float in [0, 1]
        Correlation: a delay step 6 would take for a room's (:func:`_without_reflections`) is a roll's ghost notes
        at it by chance (kept) where the least likeness of its pairs' later onsets to their notes exceeds the median
        likeness D later after the other loud notes by more than so much (:func:`_chance_delays`: a room returns
        every note at its one delay, chance ghost notes follow only a few accents). Over the corpus's seeds 0-9 the
        seven rooms' delays (FluidR3's snare 38 drop with reverb, 83.4-83.5 ms; TimGM6mb's snare 40 roll with reverb,
        seed 3, 55.6 ms) lie -0.12 to -0.01 over, the eight chance ones (TimGM6mb's 38 roll, seed 8, 64.00 ms, each
        condition; FluidR3's 40 roll, seeds 8 and 4, 90.67 and 97.35 ms) +0.27 to +0.61: 0.15 keeps their 22 notes,
        no recording of the 640 losing one; 1: the delay alone, as before this field.
    ghost_span : float in [0.03, 0.5]
        s: how long after an accent its ghost notes are sought and learned from (step 5, :func:`_ghost_notes`,
        :func:`_room_ghost_notes`, :func:`_matched_ghost_notes`; each accent's window ends at its next attack within
        10 dB sooner): the corpus's rolls put ghost notes up to 0.17 s after their accents (held-out seeds 1-4: 8
        missed more than 0.13 s after; 0.3 loses a note found within 1 ms at 0.18); 0.13: as before this field.
    ghost_white_rise_db : float in [0, 120]
        dB: where what is left before a ghost note is white noise (:func:`_ghost_notes`, ``ghost_rise_gap``'s test),
        a rise so much over the 10 ms before ``ghost_rise_gap`` is a note too, where the note is the accent's own
        (``ghost_own_db``: a mate's missed note, left negated in its remainder, rises so): that noise's energy over
        1 ms spreads +-20 %, and ``ghost_rise_db`` was set for what the mates leave of the accent's own sound (its
        low modes). FluidR3's ghost notes at -60 dBFS rise 9-12 dB over it (held-out seeds 1-4: 14 missed);
        ``ghost_rise_db`` or more: none, as before this field.
    ghost_spare_mates : int in [0, 20]
        :func:`_matched_ghost_notes` reads an accent's window with up to so many more layer-mates than its first
        three (the most alike), each counting only from where fewer than two of the first reach (to its own next
        attack): in a roll every accent has ghost notes of its own 55-130 ms after it, so a ghost note later after
        its accent (its second or third, 95-172 ms after it) lay past every first mate's reach (FluidR3's rolls,
        held-out seeds 1-9: 27 of 85 missed; seeds 0-9: 3 more found within 1 ms, one false detection fewer, none
        lost). 0: the first three alone, as before this field.

    Examples
    --------
    >>> OnsetConfig(threshold_db=-30.0).threshold_db
    -30.0
    >>> OnsetConfig(min_jump=0.5)
    Traceback (most recent call last):
    ...
    drumstroke.errors.ParameterError: min_jump must be in [1, 100] (RMS ratio), got 0.5
    """

    threshold_db: float = -40.0
    min_interval: float = 2e-3
    floor_margin_db: float = 10.0
    floor_quantile: float = 0.05
    high_pass: float = 60.0
    analysis_rate: int = 6000
    order: int = 48
    min_jump: float = 2.0
    broadband_jump: float = 3.0
    tonal_support: float = 1.6
    strong_rise: float = 10.0
    disagreement: float = 0.5e-3
    modes_rate: int = 2000
    modes_width: int = 4
    modes_order: int = 40
    signature: float = 50e-3
    head: int = 6
    tail: float = 0.15
    room: float = 0.03
    tail_ridge: float = 0.01
    second_gap: float = 2.0
    likeness: float = 0.7
    weak_likeness: float = 0.5
    weak_rise: float = 1.6
    sure_likeness: float = 0.9
    sure_jump: float = 1.5
    precise_likeness: float = 0.9
    moved_jump: float = 3.0
    move_reach: float = 3.0
    after_reach: float = 40e-3
    after_f: float = 8.0
    after_weak_f: float = 6.0
    after_ratio_low: float = 0.35
    after_ratio_high: float = 1.5
    after_rounds: int = 3
    spike_db: float = 6.0
    spike_clear: float = 35e-3
    level_order: int = 24
    level_ratio: float = 2.1
    level_band: float = 400.0
    start_db: float = -40.0
    start_over: float = 2.0
    start_reach: float = 5e-3
    start_clear_db: float = -30.0
    decay_db: float = -32.0
    decay_rise_db: float = 6.0
    echo_reach: float = 8e-3
    echo_rise_db: float = -3.5
    lead_rise: float = 0.7
    lead_clear_db: float = -20.0
    lead_db: float = 6.0
    template_likeness: float = 0.8
    template_reach: float = 3e-3
    template_fit: float = 10e-3
    template_head: float = 3e-3
    peak_window: float = 10e-3
    peak_reach: float = 0.3
    peak_templates: int = 12
    peak_clear_db: float = -30.0
    peak_layer_likeness: float = 0.98
    peak_apart_db: float = -20.0
    peak_realign: float = 1e-3
    peak_learn: float = 0.035
    sound_templates: int = 6
    new_sound_db: float = -20.0
    soft_jump: float = 3.0
    soft_contact: float = 3e-3
    bounce_reach: float = 25e-3
    refused_likeness: float = 0.8
    burst_db: float = -6.0
    layer_likeness: float = 0.8
    reflection_pairs: int = 3
    reflection_db: float = 12.0
    reflection_spread: float = 0.2e-3
    room_decay_db: float = -20.0
    room_rise_db: float = 3.0
    room_echo_db: float = 2.0
    room_fit_db: float = -6.0
    room_found_fit_db: float = -15.0
    found_burst_db: float = -6.0
    found_decay_db: float = -120.0
    earlier_reach: float = 5e-3
    bounce_likeness: float = 0.7
    bounce_ratio_low: float = 0.3
    found_echo_rise_db: float = -60.0
    layer_bounce_likeness: float = 0.75
    replay_likeness: float = 0.999
    ghost_rise_db: float = 15.0
    layer_echo_db: float = 0.0
    layer_decay_db: float = -12.0
    ghost_own_db: float = 1.0
    ghost_room_own_db: float = 2.0
    found_bursts: int = 2
    burst_unfitted_likeness: float = 0.8
    fitted_lead_db: float = 120.0
    ghost_room_fit: float = 0.8
    layer_whole_likeness: float = 0.8
    layer_echo_partners: int = 1
    layer_start_reach: float = 1.5e-3
    layer_joint_likeness: float = 0.7
    layer_train_found: int = 1
    layer_found_bursts: int = 1
    layer_train_refit: int = 0
    layer_skipped_search: int = 1
    ghost_noise_start: float = 1e-3
    ghost_rise_gap: float = 1e-3
    ghost_mate_notes: float = 0.99
    ghost_matched_fit: float = 0.9
    template_start_db: float = -40.0
    template_start_past_db: float = 0.0
    train_reach: float = 35e-3
    ghost_room_reach: float = 2e-3
    room_partner_under_db: float = 15.0
    ghost_room_spare_likeness: float = 0.99
    ghost_matched_back: float = 4.5e-3
    ghost_step_reach: float = 4.6e-3
    reflection_drop_spread: float = 6.0
    reflection_excess: float = 0.15
    ghost_span: float = 0.18
    ghost_white_rise_db: float = 6.0
    ghost_spare_mates: int = 5

    def __post_init__(self):
        for name, (low, high, unit) in _RANGES.items():
            value = getattr(self, name)
            if isinstance(low, int):
                value = check_int(name, value, low=low, high=high, unit=unit)
            else:
                value = check_real(name, value, low=low, high=high, unit=unit)
            object.__setattr__(self, name, value)
        if self.after_ratio_low > self.after_ratio_high:
            raise ParameterError(f"after_ratio_low must be at most after_ratio_high ({self.after_ratio_high!r}), "
                                 f"got {self.after_ratio_low!r}")


_RANGES = {  # each OnsetConfig field: its least and largest value (ints for a count) and its unit
    "threshold_db": (-120.0, 0.0, "dB"), "min_interval": (0.5e-3, 1.0, "s"),
    "floor_margin_db": (0.0, 60.0, "dB"), "floor_quantile": (0.0, 1.0, "(ratio)"),
    "high_pass": (1.0, 1000.0, "Hz"), "analysis_rate": (2000, 768000, "Hz"), "order": (1, 400, ""),
    "min_jump": (1.0, 100.0, "(RMS ratio)"), "broadband_jump": (1.0, 100.0, "(RMS ratio)"),
    "tonal_support": (1.0, 100.0, "(RMS ratio)"), "strong_rise": (1.0, 1000.0, "(RMS ratio)"),
    "disagreement": (0.0, 0.01, "s"), "modes_rate": (500, 8000, "Hz"), "modes_width": (1, 64, "samples"),
    "modes_order": (1, 400, ""), "signature": (1e-3, 0.5, "s"), "head": (1, 100, "samples"),
    "tail": (1e-3, 2.0, "s"), "room": (0.0, 100.0, "(energy ratio)"), "tail_ridge": (1e-6, 1.0, "(ratio)"),
    "second_gap": (0.0, 100.0, "(min_interval)"), "likeness": (0.0, 1.0, "(correlation)"),
    "weak_likeness": (0.0, 1.0, "(correlation)"), "weak_rise": (1.0, 100.0, "(RMS ratio)"),
    "sure_likeness": (0.0, 1.0, "(correlation)"), "sure_jump": (1.0, 100.0, "(RMS ratio)"),
    "precise_likeness": (0.0, 1.0, "(correlation)"), "moved_jump": (1.0, 100.0, "(RMS ratio)"),
    "move_reach": (0.0, 100.0, "(min_interval)"), "after_reach": (0.0, 0.5, "s"),
    "after_f": (0.0, math.inf, ""), "after_weak_f": (0.0, math.inf, ""),
    "after_ratio_low": (0.0, 100.0, "(amplitude ratio)"), "after_ratio_high": (0.0, 100.0, "(amplitude ratio)"),
    "after_rounds": (0, 100, ""), "spike_db": (-60.0, 60.0, "dB"), "spike_clear": (0.0, 1.0, "s"),
    "level_order": (1, 400, ""), "level_ratio": (1.0, 10.0, "(frequency ratio)"),
    "level_band": (50.0, 4000.0, "Hz"), "start_db": (-120.0, 0.0, "dB"), "start_over": (1.0, 100.0, "(ratio)"),
    "start_reach": (0.0, 0.02, "s"), "start_clear_db": (-120.0, 0.0, "dB"),
    "decay_db": (-120.0, 0.0, "dB"), "decay_rise_db": (-60.0, 60.0, "dB"),
    "echo_reach": (0.0, 0.05, "s"), "echo_rise_db": (-60.0, 60.0, "dB"),
    "lead_rise": (0.01, 1.0, "(ratio)"), "lead_clear_db": (-120.0, 0.0, "dB"),
    "lead_db": (0.0, 120.0, "dB"),
    "template_likeness": (0.0, 1.0, "(correlation)"), "template_reach": (0.0, 0.01, "s"),
    "template_fit": (0.5e-3, 0.1, "s"), "template_head": (0.5e-3, 0.05, "s"),
    "peak_window": (1e-3, 0.1, "s"), "peak_reach": (0.01, 2.0, "s"), "peak_templates": (0, 100, ""),
    "peak_clear_db": (-120.0, 0.0, "dB"), "peak_layer_likeness": (0.0, 1.0, "(correlation)"),
    "peak_apart_db": (-120.0, 0.0, "dB"), "peak_realign": (0.0, 5e-3, "s"), "peak_learn": (0.0, 1.0, "(fraction)"),
    "sound_templates": (0, 100, ""), "new_sound_db": (-120.0, 0.0, "dB"),
    "soft_jump": (1.0, 100.0, "(RMS ratio)"), "soft_contact": (0.0, 0.02, "s"),
    "bounce_reach": (0.0, 0.5, "s"), "refused_likeness": (0.0, 1.0, "(correlation)"),
    "burst_db": (-120.0, 0.0, "dB"), "layer_likeness": (0.0, 1.0, "(correlation)"), "reflection_pairs": (0, 100, ""), "reflection_db": (0.0, 120.0, "dB"),
    "reflection_spread": (0.0, 5e-3, "s"), "room_decay_db": (-120.0, 0.0, "dB"), "room_rise_db": (-60.0, 60.0, "dB"),
    "room_echo_db": (-60.0, 60.0, "dB"), "room_fit_db": (-60.0, 0.0, "dB"),
    "room_found_fit_db": (-120.0, 0.0, "dB"),
    "found_burst_db": (-120.0, 0.0, "dB"), "found_decay_db": (-120.0, 0.0, "dB"),
    "earlier_reach": (0.0, 0.02, "s"), "bounce_likeness": (0.0, 1.0, "(correlation)"),
    "bounce_ratio_low": (0.0, 100.0, "(amplitude ratio)"), "found_echo_rise_db": (-60.0, 60.0, "dB"),
    "layer_bounce_likeness": (0.0, 1.0, "(correlation)"),
    "replay_likeness": (0.0, 1.0, "(correlation)"),
    "ghost_rise_db": (0.0, 120.0, "dB"),
    "layer_echo_db": (-120.0, 60.0, "dB"), "layer_decay_db": (-120.0, 0.0, "dB"),
    "ghost_own_db": (-60.0, 120.0, "dB"),
    "ghost_room_own_db": (-60.0, 120.0, "dB"),
    "found_bursts": (1, 10, ""), "burst_unfitted_likeness": (0.0, 1.0, "(correlation)"),
    "fitted_lead_db": (0.0, 120.0, "dB"),
    "ghost_room_fit": (0.0, 1.0, "(correlation)"),
    "layer_whole_likeness": (0.0, 1.0, "(correlation)"),
    "layer_echo_partners": (0, 1, ""),
    "layer_start_reach": (0.0, 5e-3, "s"),
    "layer_joint_likeness": (0.0, 1.0, "(correlation)"),
    "layer_train_found": (0, 1, ""), "layer_found_bursts": (0, 1, ""), "layer_train_refit": (0, 4, ""),
    "layer_skipped_search": (0, 1, ""),
    "ghost_noise_start": (0.0, 5e-3, "s"),
    "ghost_rise_gap": (0.0, 5e-3, "s"),
    "ghost_mate_notes": (0.0, 1.0, "(correlation)"),
    "ghost_matched_fit": (0.0, 1.0, "(correlation)"),
    "template_start_db": (-120.0, 0.0, "dB"),
    "template_start_past_db": (0.0, 120.0, "dB"),
    "train_reach": (0.0, 0.1, "s"),
    "ghost_room_reach": (0.0, 5e-3, "s"),
    "room_partner_under_db": (0.0, 120.0, "dB"),
    "ghost_room_spare_likeness": (0.0, 1.0, "(correlation)"),
    "ghost_matched_back": (0.0, 5e-3, "s"),
    "ghost_step_reach": (0.0, 5e-3, "s"),
    "reflection_drop_spread": (0.0, 120.0, "dB"), "reflection_excess": (0.0, 1.0, "(correlation)"),
    "ghost_span": (0.03, 0.5, "s"),
    "ghost_white_rise_db": (0.0, 120.0, "dB"),
    "ghost_spare_mates": (0, 20, ""),
}


def read_recording(path, *, max_seconds=MAX_SECONDS):
    """A recording's mono samples (full scale, float64), rate (Hz) and what was done to read it.

    Parameters
    ----------
    path : str or os.PathLike
        An audio file soundfile reads (WAV, FLAC, OGG, AIFF, …), any channel count.
    max_seconds : float
        The longest file read (s); checked from the file's header before reading, as is the memory
        its samples and the detector's :data:`WORKING_COPIES` of them ask for (:mod:`drumstroke.budget`).

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

    samples, rate = read_audio(path, max_seconds=max_seconds, working=WORKING_COPIES)
    channels = samples.shape[1]
    clipped = int(np.count_nonzero(samples >= CLIP_LEVEL) + np.count_nonzero(samples <= -CLIP_LEVEL))  # no copy
    signal = samples[:, 0] if channels == 1 else samples.mean(axis=1)
    return signal, rate, {"channels": channels, "mixed_down": channels > 1, "clipped": clipped}


def find_recording_onsets(path, *, config=OnsetConfig()):
    """The impacts in the recording at ``path``: :func:`read_recording`, then :func:`find_onsets`.

    Parameters
    ----------
    path : str or os.PathLike
        An audio file soundfile reads (WAV, FLAC, OGG, …); several channels are mixed down.
    config : OnsetConfig
        The detector's thresholds.

    Returns
    -------
    Onsets
        Its source is the file's name; its ``info`` says how the file was read (channels, mixed
        down, clipped samples) besides how the onsets were found.

    Raises
    ------
    ParameterError
        Naming the file, when it cannot be read as audio or lasts more than :data:`MAX_SECONDS`.
    """
    path = Path(path)
    signal, rate, notes = read_recording(path)
    return find_onsets(signal, rate, config=config, source=path.name, notes=notes)


def find_onsets(signal, rate, *, config=OnsetConfig(), source="", notes=None):
    """The impacts in a recording: their times to a fraction of a millisecond and their relative levels.

    The detector is a pipeline of stages, each a function of the recording and ``config``
    (:class:`OnsetConfig`, whose fields are named below; docs/analysis.md tells more):

    1. :func:`_tonal_innovation`. The signal is high-passed (``high_pass``) and decimated (causal
       8th-order Butterworth) to ``analysis_rate``, or further where its band 20 dB over the noise
       floor (the quietest tenth of its 21-ms frames) ends lower (≥ 2.5 times that band's top,
       ≥ 2 kHz). *Ringing is predicted away:* a linear predictor (Burg's method, order ``order``)
       fitted to the whole decimated signal — the drum's modes, the room — leaves the innovation:
       what the past does not predict, which is where a stick strikes.
    2. :func:`_heard_jumps`. Candidates are where the innovation's RMS over the next 1 ms rises
       ``min_jump`` times over the 4 ms before (peaks picked as ``librosa.util.peak_pick`` picks them);
       Akaike's information criterion (AIC) places each on the change point; the anti-alias
       filter's delay is taken off.
    3. The same stage finds *broadband attacks* (snare wires, a stick's click) the same way at full
       rate on the first difference (a jump of ``broadband_jump``, with the innovation rising
       ``tonal_support`` times too: beating modes alone make broadband jumps). Their full-rate
       time replaces a decimated one within ``min_interval`` (closer onsets are one), unless the
       decimated one is more than ``disagreement`` away and step 2's innovation rises
       ``strong_rise`` times there: a sharp attack's change point, beside its modes' beating.
    4. *Quiet attacks in louder ones' ringing and rattle* are found in the drum's modes' band
       (:func:`_modes_band`: decimated to ~``modes_rate`` Hz, below the snare wires), whose
       innovation (a predictor of order ``modes_order`` fitted by least squares reweighted by the
       inverse local power of a first fit's innovation: the ringing between attacks, not the
       attacks) leaves each attack a *signature* (its spike and ``signature`` s after it) that the
       predictor cannot follow (beating modes, the room's first reflections). Matching pursuit:
       the loudest attack's signature, fitted by least squares (with its derivative: a fraction of
       a sample) at each onset found, is taken off in time order; jumps of the remainder (windows
       of ``modes_width`` samples) are more onsets (:func:`_quiet_jumps`), timed by where their
       signature fits (offset by the precise times of the other onsets, those whose start looks like
       the signature by ``precise_likeness``). Past the signature, the attacks' common response
       over ``tail`` s (the room's tail: least squares over all the onsets found, each scaled by its
       signature's fit) is taken off too; a second round takes off the quiet onsets found as well
       and adds the remainder's new jumps (farther than ``second_gap`` times ``min_interval`` from
       the onsets known). :func:`_judged` makes an onset an attack when the remainder jumps
       ``min_jump`` times at it and either its start looks like the signature (correlation ≥
       ``likeness``) or step 2 or 3 found it rising (or it looks half like it, ``weak_likeness``,
       and step 2's innovation rises ``weak_rise`` times); a start almost the signature
       (``sure_likeness``) needs a jump of ``sure_jump`` only. In a reverberant recording (below),
       :func:`_try_later` tries a decimated onset whose start does not look like the signature
       again where the remainder jumps most up to ``move_reach`` times ``min_interval`` later (its
       change point is often placed early on the earlier tails), kept there when the remainder
       jumps ``moved_jump`` times and it looks like the signature; and :func:`_last_round` takes
       off only the attacks found, at their final times, and fits them again with the remainder's
       new jumps: the new and the refused ones that look like the signature (and jump ``min_jump``
       times) are attacks. Then, in every recording, :func:`_search_after_louder` seeks a quiet
       attack up to ``after_reach`` s after each attack, where the remainder does not jump, by
       fitting its whole signature there: the best fit over the louder one's signature is an attack
       when an F-test passes (``after_f``, or ``after_weak_f`` with a start half like the signature)
       and its scale is ``after_ratio_low`` to ``after_ratio_high`` of the louder one's (a bouncing
       stick's next impact); again while it finds more (``after_rounds`` times at most).
       :func:`_impulsive`: an attack found in the modes' band alone, ``spike_clear`` s or more after
       the attack before it, is none unless the innovation spikes there ``spike_db`` over its RMS
       before (a stick's impact is a burst; a decay's or a room's swell is not).
    5. :func:`_fit_template`. The recording's clearest loud attack is a template of its attacks: fitted
       to each in time order (``template_fit``, ``template_reach``) and taken off, it times those over
       earlier sound where it correlates by ``template_likeness``, and finds new ones where its start
       (``template_head``) correlates so with what is left and that rises ``min_jump`` times. A detection
       within ``echo_reach`` s after an attack the template timed, where taking its fit off leaves ``burst_db``
       or less, is that attack's own sound (a sample's second burst).
       :func:`_template_search`: up to ``bounce_reach`` s after each attack, a quieter one (a bouncing
       stick's next impact, ``bounce_ratio_low`` to ``after_ratio_high`` times it) where the template's
       start (by ``bounce_likeness``) and its first ``template_fit`` s correlate so with what is left, however
       little it rises; after an attack the quiet layer's template took off, in a train of close attacks, where the
       recording replays a sample (two clear attacks one waveform by ``replay_likeness``), that layer's template
       may find it too (its first ``template_fit`` s by ``layer_bounce_likeness``, its start by ``weak_likeness``; where
       that finds none after a flight of 10 ms or less, its first ``template_fit`` s alone by ``layer_whole_likeness``,
       and after one of 9 ms or less, fitted together with the bounce before, by ``layer_joint_likeness``; a detection
       of such a train over earlier sound is put where the layer fits best up to ``layer_start_reach`` s before it;
       a bounce the layer found is the layer's, ``layer_train_found``, and a detection on a found bounce's rise is dropped,
       ``layer_found_bursts``, and one past a detection its fit skipped sought first up to it by the layer,
       ``layer_skipped_search``);
       else an onset step 4 refused, ``signature`` s or more after it, where both correlate by
       ``refused_likeness``; then that second opinion again with the quietest clear attack as
       the template (another velocity layer of a sample), by ``layer_likeness``. A detection there that taking off
       the attack before it explains (``found_burst_db``) is that attack's own sound (a sample's second burst); one
       over earlier sound whose start the template fits better up to ``earlier_reach`` s before it is put there.
       :func:`_ghost_notes`: where the recording replays a sample, the notes after a clear
       attack (ghost notes under an accent) are sought in what is left once its layer-mates (other clear attacks
       one waveform with it by ``replay_likeness``) are taken off, where that rises ``ghost_rise_db`` (where one mate
       alone reaches, or the recording is reverberant, and the note is louder in the accent than in the mate by
       ``ghost_own_db``, ``ghost_room_own_db``); each is put at its first sample there (a new attack, or one found
       0.5-1.5 ms late moved). :func:`_matched_ghost_notes`: and where what the
       mates leave fits the ghost layer's own head, learned from the ghost notes found (aligned up to
       ``ghost_matched_back`` s earlier: a note so moved is one there), by ``ghost_matched_fit`` (a matched filter;
       past where its first mates reach, ``ghost_spare_mates`` more).
       :func:`_level_band`. An onset's amplitude is the peak of its own sound in the drum's lowest
       modes (the band up to ``level_ratio`` times its lowest strong mode, ≥ ``level_band`` Hz,
       decimated to 2.5 times that: a stick's speed sets their amplitude in proportion, while the
       higher modes grow faster with it, Hertz's contact being shorter): the band over the next
       5 ms (or up to the next onset) less the earlier sound extrapolated by a predictor (order
       ``level_order``, fitted as in step 4), its peak between samples (4 times upsampled). In a
       reverberant recording (the room's tail past the signature carries ≥ ``room`` of its
       energy), an onset whose start looks like the signature has the earlier such onsets' tails
       (the band's innovation's common response, as in step 4, past 5 ms) taken off its innovation
       first. :func:`_one_attack_each`: an attack followed within ``start_reach`` by one ``lead_db``
       louder, standing out and rising on into it, is that one's first transient (one attack).
       :func:`_out_of_decay`: an attack quieter than ``decay_db`` re the loudest is none when
       its first difference does not rise ``decay_rise_db`` over the sound before it (a sample's
       own decay, a room's tail), and so is one within ``echo_reach`` s after the attack before it
       that does not pass ``echo_rise_db`` (a sample's second burst); for an attack the template timed or found,
       ``found_decay_db`` and ``found_echo_rise_db`` instead (its fit is its test). :func:`_room_echoes`, in a
       reverberant recording: an attack of the modes' band alone, ``spike_clear`` s or more after the attack
       before it, quieter than ``room_decay_db`` and not rising ``room_rise_db``, is a room's echo where the band at
       the same delay after another note as loud as a much louder one before it (``reflection_db``) explains its
       10 ms (``room_fit_db``) alike before and after its time (``room_echo_db``). :func:`_learned_lead_ins`: an
       attack over loud earlier sound (over ``lead_clear_db`` re its peak) is placed its recording's
       lead-in before its main rise (its first difference's first sample over ``lead_rise`` of its
       peak), that lead-in being the median over the clear attacks (≥ 3) of their main rise less
       their onset.
    6. :func:`_reported`. Its level is in dB re the loudest onset. The noise floor (the
       ``floor_quantile`` quantile of the level band's peaks over 5-ms frames) plus
       ``floor_margin_db``, or ``threshold_db`` if higher, is the threshold used. Each reported
       onset's broadband peak (:attr:`Onsets.peak_db`, dB re the loudest onset's) is read on the
       signal itself by :func:`_peak_amplitudes`: the loudest sample over ``peak_window`` s after it (or
       up to the next onset), after the earlier notes' sound is taken off (each fitted by the
       recording's own templates, one a velocity layer, each the median of its clear notes' waveforms, of the
       ``peak_templates`` loudest, followed ``peak_reach`` s; with ``peak_learn``, the layers no clear note has
       learned on the way from their quietest notes with room, and a window the next onset cuts short read from
       its note's fit).
       :func:`_without_reflections`: where ``reflection_pairs`` pairs of successive onsets or more, the later
       ``reflection_db`` under the earlier, share one delay (within ``reflection_spread`` s; where step 4 finds no
       room, and their drop within ``reflection_drop_spread`` dB), each such later one is a room's reflection and is
       left out, unless the band D after the pairs' notes is more like them than D after the other loud notes by
       ``reflection_excess`` (:func:`_chance_delays`: a roll's ghost notes at one delay by chance; a room returns
       every note). :func:`_room_returns`, in a reverberant recording: an onset the
       template timed (kind 3) that :func:`_room_echoes`' test finds a room's echo, its fit leaving
       ``room_found_fit_db`` or less, is left out too.

    Parameters
    ----------
    signal : array_like [shape=(n,)]
        Mono samples (full scale), finite.
    rate : int in [8000, 768000]
        Samples per second (Hz).
    config : OnsetConfig
        The detector's thresholds (its ``threshold_db``: dB re the loudest onset; the threshold
        used is the higher of it and the noise floor plus ``floor_margin_db``, in
        :attr:`Onsets.threshold_db`).
    source : str
        What the signal is (a file's name), kept in the result.
    notes : dict or None
        What was done to read it (:func:`read_recording`), kept in the result's ``info``.

    Returns
    -------
    Onsets
        With :attr:`Onsets.peak_db`. Its ``info`` says the rate, the analysis rate, the noise floor
        (dB re the loudest onset), the threshold asked for, and ``"no impacts found: …"`` when none was.

    Examples
    --------
    >>> import numpy as np
    >>> rate = 48000
    >>> t = np.arange(rate) / rate
    >>> hit = lambda t0, a: a * np.where(t >= t0, np.exp(-(t - t0) / 0.03) * np.sin(2 * np.pi * 400 * (t - t0)), 0.0)
    >>> onsets = find_onsets(hit(0.2, 0.8) + hit(0.55, 0.4), rate)
    >>> np.round(onsets.t, 4).tolist(), np.round(onsets.level_db, 1).tolist(), np.round(onsets.peak_db, 1).tolist()
    ([0.2, 0.55], [0.0, -6.2], [0.0, -6.0])
    >>> len(find_onsets(hit(0.2, 0.8) + hit(0.55, 0.4), rate, config=OnsetConfig(threshold_db=-3.0)))
    1
    """
    signal = check_vector("signal", signal, unit="full scale")
    rate = check_int("rate", rate, low=MIN_RATE, high=768000, unit="Hz")
    if not isinstance(config, OnsetConfig):
        raise ParameterError(f"config must be an OnsetConfig, got {type(config).__name__}")
    if len(signal) > MAX_SECONDS * rate:
        raise ParameterError(f"signal lasts {len(signal) / rate:.6g} s; at most {MAX_SECONDS:g} s are analysed: cut "
                             "it into parts")
    info = {**(notes or {}), "rate": rate, "seconds": len(signal) / rate, "requested_threshold_db": config.threshold_db,
            "method": "jumps of the linear-prediction innovation (decimated) and of the first difference; AIC change points; "
                      "matching pursuit of attack signatures in the modes' band"}
    if len(signal) < round(0.05 * rate):
        return _no_onsets("the signal is shorter than 50 ms", info, source, config)
    with _one_blas_thread():
        return _detected(signal, rate, config, source, info)


def _detected(signal, rate, config, source, info):
    """:func:`find_onsets`' pipeline, on a checked ``signal`` of 50 ms or more."""
    from ._detect import normalised

    band, peak, loudest = _high_pass(signal, rate, config.high_pass)
    if not peak > 1e-9:  # −180 dB full scale: digital silence
        return _no_onsets("the signal is silent", info, source, config)
    # the band over its peak, its first difference (centred ½ sample early: several stages read it) and that
    # difference's magnitude (as many stages read it), in one pass
    band, rise, d = normalised(band, peak)
    q = max(_decimation(band, rate), rate // config.analysis_rate)
    q2 = max(q, rate // config.modes_rate)
    # the level band's decimation guessed from 5 ms before the loudest sample (step 5's from the loudest onset, whose
    # 5-ms window's peak it mostly is: the guess right on all 64 corpus recordings, 54 from the sample itself): its
    # filter runs beside the two others, and step 5 takes it where it guessed right
    guess = _level_decimation(band, rate, q, np.array([float(max(0, loudest - round(5e-3 * rate)))]), config)
    low, modes_low, lowest, rise_jumps = _decimate_three(band, rate, q, q2, guess, rise)
    tonal = _tonal_innovation(low, q, config)
    heard = _heard_jumps(rise, rate, tonal, config, rise_jumps)
    first, _ = heard.merge()
    modes, residual = _modes_band(modes_low, q2, first, config)
    deep, residual = _quiet_jumps(modes, first, residual, rate, config)
    candidates, modes = _judged(rise, rate, tonal, modes, heard.merge(deep), config)
    if modes.reverberant:
        candidates = _try_later(modes, candidates, residual, rate, config)
        candidates = _last_round(modes, candidates, rate, config)
    candidates = _search_after_louder(modes, candidates, rate, config)
    candidates = _impulsive(modes, candidates, rate, config)
    refused = candidates.times[~candidates.attack]
    candidates = _first_transients(d, rate, candidates.take(candidates.attack), config)
    found = candidates.times
    candidates = _fit_template(band, d, rate, candidates, config)
    replays = _replaying(band, d, candidates.times, rate, config)
    candidates = _template_search(band, d, rate, candidates, refused, config, replays)
    candidates = _template_search(band, d, rate, candidates, refused, config, replays, quietest=True)
    shared = {}  # what step 5's ghost search found (layer-mates, levels) that its room search asks again
    steps = [] if config.ghost_step_reach > 0.0 else None  # attacks found on a ghost note's later step
    candidates = _ghost_notes(band, d, rate, candidates, config, replays, modes.reverberant, shared)
    if modes.reverberant:
        candidates = _room_ghost_notes(band, d, rate, candidates, config, replays, shared, steps)
    candidates = _matched_ghost_notes(band, d, rate, candidates, config, replays, shared, steps)
    levels = _level_band(band, rate, q, first, config, lowest)
    amplitude = levels.amplitudes(_measured_at(candidates, found, rate, config), modes.reverberant, config)
    candidates, amplitude = _one_attack_each(d, rate, candidates, amplitude, config)
    decided = _out_of_decay(band, d, rate, candidates, amplitude, config, replays, modes.reverberant)
    # an attack measured on a window cut at the next detection, refused here, is measured again without it
    cut = np.flatnonzero(decided.attack[:-1] & candidates.attack[1:] & ~decided.attack[1:])
    if len(cut):
        kept = decided.take(decided.attack)
        again = levels.amplitudes(_measured_at(kept, found, rate, config), modes.reverberant, config)
        amplitude[cut] = again[np.searchsorted(kept.times, decided.times[cut])]
    candidates = _learned_lead_ins(d, rate, decided, config)
    onsets = _reported(candidates, amplitude, levels.floor, {**info, "analysis_rate": tonal.rate}, source, rate, config)
    onsets = _without_reflections(onsets, config, modes.reverberant, rise, rate)
    if modes.reverberant and len(onsets.t):
        onsets = _room_returns(band, d, rate, candidates, amplitude, onsets, config)
    if steps:
        onsets = _on_first_steps(onsets, steps, rate)
    return replace(onsets, peak_db=_peak_db(signal, onsets.t * rate, rate, config))


@contextmanager
def _one_blas_thread():
    """A context in which BLAS and LAPACK (numpy's and scipy's) run on one thread (set through threadpoolctl, undone on
    exit).

    The detector's products and solves are small (normal equations of 41 unknowns over some ten
    thousand rows): threads cost more to start and join than they save, and on a busy machine they
    made its time swing 20 times over. With one thread the onsets found do not depend on the machine's
    thread count either. A library on one thread already is left alone (setting it again costs some
    70 µs after BLAS has run). Without threadpoolctl (drumstroke's ``analysis`` extra), the libraries'
    own settings are left.
    """
    busy = [(library, library.num_threads) for library in _blas_threads() if library.num_threads != 1]
    for library, _ in busy:
        library.set_num_threads(1)
    try:
        yield
    finally:
        for library, threads in busy:
            library.set_num_threads(threads)


@cache
def _blas_threads():
    """threadpoolctl's controllers of the BLAS libraries loaded (numpy's and scipy's), found once; none without it."""
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:
        return ()
    import scipy.linalg  # noqa: F401  (scipy's own BLAS, loaded before the controller looks for the libraries)

    return tuple(ThreadpoolController().select(user_api="blas").lib_controllers)


def _no_onsets(reason, info, source, config):
    return Onsets(np.empty(0), np.empty(0), threshold_db=config.threshold_db, source=source,
                  info={**info, "found": f"no impacts found: {reason}", "floor_db": None})


# ------------------------------------------------------------------------------------------ the stages


@dataclass(frozen=True)
class _Innovation:
    """What a linear predictor of the band decimated ``q`` times does not predict: ``e``, at ``rate`` Hz,
    its filter's delay ``delay`` (full-rate samples)."""

    e: np.ndarray
    q: int
    delay: float
    rate: float

    def at(self, samples):
        """Full-rate ``samples`` as (fractional) samples of the band."""
        return (samples + self.delay) / self.q

    def samples(self, at):
        """Samples of the band ``at`` as full-rate samples."""
        return at * self.q - self.delay


@dataclass(frozen=True)
class _Modes(_Innovation):
    """The drum's modes' band of step 4: its innovation, the room's ``tail`` once fitted, whether the
    recording is ``reverberant``, the ``offset`` (full-rate samples) of the times fitted there from
    the precise times (:func:`_retime`), and the ``signature`` :func:`_pursue` fits (:func:`_signature`, once)."""

    tail: np.ndarray | None = None
    reverberant: bool = False
    offset: float = 0.0
    signature: "_Signature | None" = field(default=None, compare=False)

    def pursue(self, samples, config):
        """:func:`_pursue` of the onsets at full-rate ``samples``, the room's tail taken off with each."""
        return _pursue(self.e, self.at(samples), self.rate, config, tail=self.tail, signature=self.signature)

    def jumps(self, residual, config):
        """Where ``residual`` (in the band) jumps ``config.min_jump`` times, as a list of full-rate samples."""
        return self.samples(_jumps(residual, self.rate, config.min_interval, config.min_jump,
                                   config.modes_width)).tolist()

    def fitted(self, where):
        """Full-rate times of signatures fitted at ``where`` (samples of the band): offset to the precise times."""
        return self.samples(where) + self.offset


@dataclass(frozen=True)
class _Candidates:
    """The onsets under judgement, in time order (each an array [shape=(n,)]).

    Attributes
    ----------
    times : ndarray
        Full-rate samples (fractional).
    kinds : ndarray of int
        How each was found: 0 broadband (step 3), 1 tonal (step 2), 2 in the modes' band alone (step 4).
    attack : ndarray of bool
        Whether it is judged an attack (a stick's impact) so far.
    likeness : ndarray
        The correlation of its start with the signature's (step 4).
    """

    times: np.ndarray
    kinds: np.ndarray
    attack: np.ndarray
    likeness: np.ndarray

    def __len__(self):
        return len(self.times)

    def take(self, which):
        """The candidates ``which`` selects (booleans, or indices in the order wanted)."""
        return _Candidates(self.times[which], self.kinds[which], self.attack[which], self.likeness[which])

    def insert(self, new, *, attack, likeness):
        """These candidates and ``new`` ones (full-rate samples, found in the modes' band alone), in time order.

        ``attack`` (bool) says whether the new ones are attacks, ``likeness`` is theirs. Returns the
        candidates and which of them are the new ones.
        """
        order = np.argsort(np.concatenate((self.times, new)), kind="stable")
        fresh = np.concatenate((np.zeros(len(self.times), dtype=bool), np.ones(len(new), dtype=bool)))[order]
        merged = _Candidates(np.concatenate((self.times, new))[order],
                             np.concatenate((self.kinds, np.full(len(new), 2)))[order],
                             np.concatenate((self.attack, np.full(len(new), attack)))[order],
                             np.concatenate((self.likeness, likeness))[order])
        return merged, fresh


@dataclass(frozen=True)
class _Heard:
    """Steps 2 and 3's onsets (full-rate samples): ``tonal`` ones, ``broadband`` ones, and ``strong``, which
    says when a group's tonal time is trusted over its broadband one (:func:`_merge`'s); ``gap`` is ``min_interval``
    in samples."""

    tonal: list
    broadband: list
    strong: tuple
    gap: float

    def merge(self, deep=()):
        """:func:`_merge` of these onsets and the ``deep`` ones (found in the modes' band): times and kinds."""
        return _merge(self.tonal, self.broadband, self.gap, deep, strong=self.strong)


@dataclass(frozen=True)
class _Pursuit:
    """What :func:`_pursue` leaves and finds, each onset's values in an array [shape=(n,)].

    Attributes
    ----------
    residual : ndarray
        The innovation less every onset's fitted signature (and the room's tail with it).
    jumps : ndarray
        Each onset's jump (:func:`_jump_at`, windows of ≥ ``modes_width`` samples) in the innovation
        less the earlier onsets' signatures.
    likeness : ndarray
        The largest correlation coefficient (magnitude) of the signature's start (its spike and
        ``head`` samples) with what is there, over the five alignments.
    where : ndarray
        Where each onset's signature fits best (samples of the band, to a fraction: the derivative's
        weight over the signature's).
    at : ndarray of int
        Where each fitted signature starts (samples of the band).
    amplitude : ndarray
        Each fitted signature's scale (0 where none was fitted).
    template : ndarray
        The signature.
    """

    residual: np.ndarray
    jumps: np.ndarray
    likeness: np.ndarray
    where: np.ndarray
    at: np.ndarray
    amplitude: np.ndarray
    template: np.ndarray


def _tonal_innovation(low, q, config):
    """Step 1: the innovation (Burg's predictor, ``config.order``) of the band (high-passed, normalised) decimated ``q``
    times, ``low`` (:func:`_decimate`'s samples, their rate and the filter's delay)."""
    low, low_rate, delay = low
    _, innovation = _innovation(low, config.order)
    return _Innovation(innovation, q, delay, low_rate)


def _heard_jumps(rise, rate, tonal, config, rise_jumps=None):
    """Steps 2 and 3: the jumps of the decimated innovation (``tonal``) and of the first difference at full rate (``rise``;
    its jump profile ``rise_jumps`` when :func:`_decimate_three` found it)."""
    tonal_onsets = tonal.samples(_jumps(tonal.e, tonal.rate, config.min_interval, config.min_jump)).tolist()
    broadband = (_jumps(rise, rate, config.min_interval, config.broadband_jump,
                        profile=rise_jumps) - 0.5).tolist()  # the difference is centred ½ sample early

    # each tonal onset's rise, once (the merges ask for it again and again): a sharp attack's change point, and a
    # broadband jump of its beating apart
    rises = _jump_at(tonal.e, tonal.at(np.array(tonal_onsets, dtype=float)), tonal.rate)
    return _Heard(tonal_onsets, broadband, (rises, config.disagreement * rate, config.strong_rise),
                  config.min_interval * rate)


def _modes_band(modes_low, q2, first, config):
    """Step 4's band: its innovation, the room's tail fitted over the ``first`` onsets, whether it is reverberant.

    ``modes_low`` is the band decimated ``q2`` times (:func:`_decimate`'s samples, their rate and the filter's delay).
    Returns the :class:`_Modes` and the innovation less the first onsets' signatures (and tails).
    """
    modes_band, modes_rate, modes_delay = modes_low
    e = _robust_innovation(modes_band, config.modes_order)[1]
    modes = _Modes(e, q2, modes_delay, modes_rate, signature=_signature(e, modes_rate, config))  # fitted once
    pursuit = modes.pursue(first, config)
    tail = _room_tail(modes.e, pursuit.at, pursuit.amplitude, round(config.tail * modes.rate), config.tail_ridge)
    if tail is None:
        return modes, pursuit.residual
    size = len(pursuit.template)
    reverberant = bool(len(tail) > size and tail[size:] @ tail[size:] >= config.room * (tail[:size] @ tail[:size]))
    modes = replace(modes, tail=tail, reverberant=reverberant)
    return modes, modes.pursue(first, config).residual


def _quiet_jumps(modes, first, residual, rate, config):
    """Step 4's two rounds: the remainder's jumps after the ``first`` onsets, then after those found too.

    Returns the onsets found (full-rate samples) and the remainder of the second round.
    """
    deep = modes.jumps(residual, config)
    more, _ = _merge(first, deep, config.min_interval * rate)  # a second round: the quiet ones found taken off too
    residual = modes.pursue(more, config).residual
    # a new one only away from the known ones (not a spike's leftover before one)
    deep += _away(modes.jumps(residual, config), np.sort(np.concatenate((more, deep))),
                  config.second_gap * config.min_interval * rate)
    return deep, residual


def _judged(rise, rate, tonal, modes, merged, config):
    """Step 4's judgement of the ``merged`` onsets (times, kinds): their times, whether each is an attack (``rise``:
    the band's first difference).

    Returns the :class:`_Candidates` and ``modes`` with the offset of its fitted times (:func:`_retime`).
    """
    times, kinds = merged
    pursuit = modes.pursue(times, config)
    likeness = pursuit.likeness
    times, offset = _retime(times, kinds, modes.samples(pursuit.where), likeness, config.precise_likeness)
    tonal_jump = _jump_at(tonal.e, tonal.at(times), tonal.rate)
    broadband_jump = _jump_at(rise, times + 0.5, rate)
    rises = (tonal_jump >= config.min_jump) | ((broadband_jump >= config.broadband_jump)
                                              & (tonal_jump >= config.tonal_support))
    weak = (likeness >= config.weak_likeness) & (tonal_jump >= config.weak_rise)  # half like it, rising a little
    attack = (pursuit.jumps >= config.min_jump) & ((likeness >= config.likeness) | rises | weak)
    attack |= (pursuit.jumps >= config.sure_jump) & (likeness >= config.sure_likeness)
    attack = _softer_attacks(modes, times, attack, pursuit, rate, config)
    return _Candidates(times, kinds, attack, likeness), replace(modes, offset=offset)


def _softer_attacks(modes, times, attack, pursuit, rate, config):
    """Step 4: a refused onset that jumps ``soft_jump`` times and starts like a softer stroke's signature is an attack.

    A softer stroke stays longer on the head (Hertz's contact: the quieter, the longer), which
    low-passes its attack; a sample player does the same to a quiet note (a SoundFont's velocity
    lowers its filter's corner). Its innovation in the modes' band is then a slower burst than the
    loudest attack's spike, and its start does not look like the signature (TimGM6mb's ghost notes,
    16-27 dB under the accent: likeness 0.2-0.5). A refused onset ``signature`` s or more after the
    attack before it (whose signature is over: the innovation there is the onset's own) is an
    attack when the remainder jumps ``soft_jump`` times at it and its start looks like the
    signature smoothed by a contact (a half sine) of up to ``soft_contact`` s, by ``likeness``
    (:func:`_soft_likeness`). Returns the new ``attack`` (booleans).
    """
    clear = round(config.signature * rate)
    out = attack.copy()
    last, heads = -np.inf, None
    for i in range(len(times)):
        if out[i]:
            last = times[i]
        elif pursuit.jumps[i] >= config.soft_jump and times[i] - last >= clear:
            k = round(modes.at(times[i]))
            heads = heads or _soft_heads(pursuit.template, modes.rate, config)  # smoothed once, where one is tried
            out[i] = _soft_likeness(modes.e, heads, k) >= config.likeness
            if out[i]:
                last = times[i]
    return out


def _soft_heads(template, rate, config):
    """The signature's start (``template``: its spike and ``head`` samples) smoothed by each contact: half sines of 1 to
    ``soft_contact`` s (at ``rate`` Hz; 1 sample: no smoothing), each head with the contact's length more.

    Returns the spike's sample, each contact's length (samples), the smoothed heads one after the other, where each
    starts and its length in them, and each one's norm.
    """
    spike = int(np.argmax(np.abs(template)))
    widths, heads = np.arange(1, max(1, round(config.soft_contact * rate)) + 1), []
    for width in widths:
        pulse = np.sin(np.pi * (np.arange(width) + 0.5) / width)
        heads.append(np.convolve(template, pulse / pulse.sum())[:spike + config.head + width])
    lengths = np.array([len(head) for head in heads], dtype=np.int64)
    return (spike, widths, np.concatenate(heads), np.cumsum(lengths) - lengths, lengths,
            np.array([np.sqrt(head @ head) for head in heads]))


def _soft_likeness(e, heads, k):
    """The largest correlation (magnitude) of ``e`` at sample ``k`` with the signature's start smoothed by a contact.

    Each smoothed start (:func:`_soft_heads`) is tried from two samples before its alignment with ``k``
    to two and half the contact after (it peaks later).
    """
    from ._kernels import soft_likeness

    return soft_likeness(e, *heads, k)


def _try_later(modes, candidates, residual, rate, config):
    """Decimated onsets whose start does not look like the signature, tried again where the remainder jumps most just after.

    In a room's tail the change point of an onset found in the decimated innovation or in the modes' band
    is often placed 1-6 ms early (on what is left of the earlier onsets' tails), where its start does not
    look like the signature: refused, or accepted at the wrong time. It is moved to where ``residual``
    (the modes' band's remainder) jumps most before ``move_reach`` times ``min_interval`` later,
    and taken there when the remainder jumps ``moved_jump`` times and its start looks like the
    signature (``likeness``), timed by its signature's fit (:meth:`_Modes.fitted`); else it stays as it was.
    """
    from ._detect import later_peaks

    times, likeness = candidates.times, candidates.likeness
    # the remainder's jumps as _windows gives them (≥ modes_width samples), each onset's tried in a compiled loop
    moved = later_peaks(np.ascontiguousarray(residual, dtype=float), float(modes.delay), modes.q, times,
                        np.flatnonzero((likeness < config.likeness) & (candidates.kinds >= 1)),
                        config.move_reach * config.min_interval * rate, config.min_interval * rate,
                        max(config.modes_width, round(1e-3 * modes.rate)), config.min_jump)
    tried = moved != times
    if not np.any(tried):
        return candidates
    pursuit = modes.pursue(moved, config)
    take = tried & (pursuit.jumps >= config.moved_jump) & (pursuit.likeness >= config.likeness)
    times, attack, likeness = times.copy(), candidates.attack.copy(), likeness.copy()
    times[take] = modes.fitted(pursuit.where[take])
    attack[take], likeness[take] = True, pursuit.likeness[take]
    return _Candidates(times, candidates.kinds, attack, likeness)


def _last_round(modes, candidates, rate, config):
    """New onsets where the remainder jumps once only the attacks found are taken off; the refused ones tried again.

    The rounds before take off their candidates, the refused ones too and some 1-6 ms early
    (:func:`_try_later`); with the attacks alone, at their final times, a quiet attack in a room's tail
    may jump out. The remainder's jumps farther than ``second_gap`` times ``min_interval`` from
    every onset join the onsets (found in the modes' band alone); all are fitted again in time order at
    their final times, and the new and the refused ones are attacks when the remainder jumps
    ``min_jump`` times at them and their start looks like the signature (``likeness``), the new
    ones timed by their signature's fit (:meth:`_Modes.fitted`).
    """
    residual = modes.pursue(candidates.times[candidates.attack], config).residual
    new = _away(modes.jumps(residual, config), candidates.times, config.second_gap * config.min_interval * rate)
    every, fresh = candidates.insert(new, attack=False, likeness=np.zeros(len(new)))
    pursuit = modes.pursue(every.times, config)
    take = ~every.attack & (pursuit.jumps >= config.min_jump) & (pursuit.likeness >= config.likeness)
    times = every.times.copy()
    times[take & fresh] = modes.fitted(pursuit.where[take & fresh])
    every = _Candidates(times, every.kinds, every.attack | take, np.where(take, pursuit.likeness, every.likeness))
    every = every.take(~fresh | take)
    return every.take(np.argsort(every.times, kind="stable"))  # a fitted time stays between its neighbours'


def _search_after_louder(modes, candidates, rate, config):
    """:func:`_after_louder` again, the attacks it found taken off, while it finds more (``after_rounds`` at most)."""
    for _ in range(config.after_rounds):
        count = np.count_nonzero(candidates.attack)
        candidates = _after_louder(modes, candidates, rate, config)
        if np.count_nonzero(candidates.attack) == count:
            break
    return candidates


def _after_louder(modes, candidates, rate, config):
    """A quiet attack in each attack's signature, found by fitting its whole signature where the remainder jumps too little.

    A bouncing stick's impact 13-40 ms after one a few dB louder may not make the remainder jump over
    its 2-ms windows: what is left of the louder one's signature (and of the snare wires' rattle, the
    room's tails) is as loud there. Its whole signature (the spike and the 50 ms after it) stands out more. Over each
    attack's signature in the remainder (the attacks taken off, at their final times), the signature and
    its derivative are fitted by least squares at every trial time from ``min_interval`` after the
    attack to ``after_reach`` s after it (or ``min_interval`` before the next attack), truncated to
    that window. The fit that takes off the most with a positive scale is an attack when it takes off
    enough of the window's remainder (an F-test of its two parameters: ``after_f``, or
    ``after_weak_f`` when its start looks half like the signature, ``weak_likeness``) and its
    scale is ``after_ratio_low`` to ``after_ratio_high`` of the louder one's (a bouncing stick's next
    impact, not what is left of the louder one's signature). It is timed by its signature's fit
    (:meth:`_Modes.fitted`) and replaces a refused onset within ``min_interval``. (Fitting the louder
    attack again jointly with each trial changes the fit's gain by 0.1-4 % at the impacts missed,
    more at false trials: it is not done.)
    """
    from ._kernels import after_louder

    sure = np.flatnonzero(candidates.attack)
    if not len(sure):
        return candidates
    if modes.signature is None:
        modes = replace(modes, signature=_signature(modes.e, modes.rate, config))
    signature, times = modes.signature, candidates.times
    pursuit = modes.pursue(times[sure], config)
    gap = max(1, round(config.min_interval * modes.rate))
    reach = round(config.after_reach * modes.rate)
    positions = np.round(modes.at(times[sure])).astype(np.int64)
    # the signature's largest spike is its lead's sample (the innovation's first largest), its start its head
    found, likes = after_louder(pursuit.residual, signature.basis, signature.grams, pursuit.at, pursuit.amplitude,
                                positions, signature.head, signature.head_norm, gap, reach, signature.lead,
                                config.modes_width, config.after_f, config.after_weak_f, config.weak_likeness,
                                config.after_ratio_low, config.after_ratio_high)
    if not len(found):
        return candidates
    new = modes.fitted(found)
    near = np.abs(times[:, None] - new[None, :]).min(axis=1) < config.min_interval * rate
    refused = ~candidates.attack & near  # a refused onset where one is found now: the new one replaces it
    return candidates.take(~refused).insert(new, attack=True, likeness=likes)[0]


def _impulsive(modes, candidates, rate, config):
    """Step 4's last part: an attack found in the modes' band alone, clear of the attack before it, must spike there.

    A stick's impact excites the drum's modes at once, with a definite phase: what the predictor does
    not foresee is a burst, a spike in the innovation. A recorded sample's decay or a room's tail
    swells too, 30-300 ms after a note and 10-30 dB under it, as its beating modes come back into
    phase; the predictor follows such a slow change of modes already ringing, and the innovation
    grows no more than its own fluctuations (over the corpus of recorded drums, the swells' largest
    innovation sample stood under 7 dB over the RMS before it at 44 of 76 swells, 7 dB or more at the notes but
    one). At an attack
    found in the modes' band alone (kind 2), ``spike_clear`` s or more after the attack before it
    (closer, the earlier one's signature is in that RMS), the largest magnitude of the innovation from
    2.5 ms before it to 4.5 ms after must pass, at some sample, the RMS over the 10 ms before that
    sample (up to 1 ms before) by ``spike_db``: else it is no attack.
    """
    which = np.flatnonzero(candidates.attack)
    clear = np.diff(candidates.times[which], prepend=-np.inf) >= config.spike_clear * rate
    which = which[clear & (candidates.kinds[which] == 2)]
    if not len(which):
        return candidates
    from ._detect import spiking

    before, gap = max(1, round(10e-3 * modes.rate)), max(1, round(1e-3 * modes.rate))
    attack = spiking(np.ascontiguousarray(modes.e, dtype=float), float(modes.delay), modes.q, candidates.times, which,
                     candidates.attack, before, gap, round(2.5e-3 * modes.rate), round(4.5e-3 * modes.rate),
                     10.0 ** (config.spike_db / 20.0))
    return replace(candidates, attack=attack)


def _first_transients(d, rate, candidates, config):
    """Step 5's first part: each attack moved to its first transient, the first sample its sound stands out at.

    The stages before place an onset on its sound's main rise, which a recorded sample may reach
    1-2 ms after its first transient (a click), or on a faint lead-in milliseconds before it out of
    digital silence. Within ``start_reach`` s of it (and half way to its neighbours), the onset is the
    first sample where ``d`` (the magnitude of the band's first difference) passes ``start_db`` re its peak over the 5 ms
    after where it was found and ``start_over`` times its own peak over the ``start_reach`` s before
    (the earlier sound, the noise), that earlier peak being under ``start_clear_db`` re the peak (else
    the first transient is hidden under it). It stays where it was when no sample is such.
    """
    from ._kernels import first_transients

    reach = round(config.start_reach * rate)
    if reach < 1:
        return candidates
    times = first_transients(np.ascontiguousarray(d), np.ascontiguousarray(candidates.times, dtype=float), reach,
                             max(1, round(5e-3 * rate)), 10.0 ** (config.start_db / 20.0), config.start_over,
                             10.0 ** (config.start_clear_db / 20.0))
    if not np.all(np.diff(times) > 0):
        return candidates
    return replace(candidates, times=times)


def _fit_template(band, d, rate, candidates, config):
    """Step 5: attacks over earlier sound timed, and attacks hidden in it found, by fitting the recording's own attack.

    A drum struck again and again sounds each time much as before, only louder or quieter: its
    clearest loud attack (:func:`_template`) is a template of them all. In time order, each attack's
    sound is that template scaled, taken off the band once fitted, so that a later attack is seen
    over what is left (the earlier attacks' sounds mostly gone). An attack over earlier sound (not
    clear by ``lead_clear_db``, :func:`_clear`; or not by ``start_clear_db``, its first transient not sought,
    and fitted by ``precise_likeness``) is timed where the template's first ``template_fit`` s
    (up to the next attack) correlates best with the band within ``template_reach`` s of where it was
    found, when that correlation is ``template_likeness`` or more: thresholds on its rise put it on
    the earlier sound, or late on its main rise. Between an attack and the next (``min_interval``
    from each), a new attack is where the template's first ``template_head`` s first correlates by
    ``template_likeness`` with what is left (at the best correlation within ``template_reach`` s
    after), scaled ``threshold_db`` or more re the template: a bouncing stick's impacts milliseconds
    apart, a ghost note in an accent's ringing. A detection less than ``min_interval`` after an attack
    so timed (and ``template_reach`` s more after one so found) is that attack again, the later found
    where the sound rose on (as :func:`_one_attack_each` merges them), and one the modes' band alone found, unfitted,
    within ``echo_reach`` s before it (:func:`_placed_early`); so is a detection within ``echo_reach`` s after
    an attack so timed where taking that attack off leaves ``burst_db`` or less of the energy over the 1 ms after it
    (a recorded sample bursts again milliseconds into itself: FluidR3's electric snare 3.4 ms in, a detection there
    would cut the attack's level window and have it refused). The attacks so timed or found are of kind 3
    (:func:`_learned_lead_ins` leaves them); the candidates are all attacks. ``d`` is the magnitude of ``band``'s
    first difference.
    """
    from ._templates import fitted_attacks

    template, offset = _template(band, d, rate, candidates.times, config)
    if template is None:
        return candidates
    fitting = _Fitting.of(template, rate, config)
    pre, reach, gap = fitting.pre, fitting.reach, max(1, round(config.min_interval * rate))
    shortest, longest = pre + round(1e-3 * rate), pre + round(config.template_fit * rate)  # a fit's span
    _, clear = _clear(d, candidates.times, rate, [config.lead_clear_db, config.start_clear_db])
    # the attacks fitted in time order and taken off a copy of the band (compiled: _templates.fitted_attacks)
    times, kinds, likeness, fits = fitted_attacks(
        band.copy(), template, fitting.head, np.ascontiguousarray(candidates.times, dtype=float),
        np.ascontiguousarray(candidates.kinds, dtype=np.int64), np.ascontiguousarray(candidates.likeness, dtype=float),
        clear[0], clear[1], pre, reach, gap, shortest, longest, offset, fitting.likeness,
        config.precise_likeness, round(1e-3 * rate), config.echo_reach * rate, 10.0 ** (config.burst_db / 10.0),
        fitting.width, fitting.back, fitting.rise, fitting.least, fitting.head_energy)
    if not np.all(np.diff(times) > 0):
        return candidates
    keep = ~_placed_early(times, kinds, fits, rate, config)
    return _Candidates(times[keep], kinds[keep], np.ones(int(keep.sum()), dtype=bool), likeness[keep])


def _placed_early(times, kinds, fitted, rate, config):
    """Which of :func:`_fit_template`'s attacks (``times`` in full-rate samples, ``kinds``, whether the template
    ``fitted`` each) are the next one's attack placed early: found in the modes' band alone (kind 2), unfitted,
    within ``echo_reach`` s before an attack the template timed (kind 3). A signature fitted in the modes' band
    puts a recorded sample's attack some milliseconds early (FluidR3's snare 38 in a drop: 3.7-7.9 ms) and the
    broadband detection of the same attack, which the template times, follows it."""
    early = np.zeros(len(times), dtype=bool)
    early[:-1] = ((kinds[:-1] == 2) & ~fitted[:-1] & (kinds[1:] == 3)
                  & (np.diff(times) <= config.echo_reach * rate))
    return early


def _template_search(band, d, rate, candidates, refused, config, replays, quietest=False):
    """Step 5: attacks the stages before missed, found by fitting the template where they did not look or look enough.

    *A quieter attack close after an attack.* A dropped stick's last bounces come 4-17 ms apart, each
    a dB or two quieter than the one before, while a recorded snare's sound peaks 1-9 ms after its
    start: a bounce starts under the earlier one's sound still at its loudest, and what is left of
    that sound once the template is taken off (:func:`_fit_template`) is as loud over a millisecond
    as the new bounce's lead-in. The remainder does not rise there (:func:`._templates.next_attack` asks it to),
    but its shape is the template's start. In time order, each attack is fitted by the template (its
    scale by least squares over ``template_fit`` s or up to the next attack, at its time) and taken
    off; between it and ``bounce_reach`` s after it (``min_interval`` from it and from the next
    attack), the first sample where the template's start (``template_head`` s) correlates by
    ``bounce_likeness`` with what is left, scaled ``bounce_ratio_low`` to ``after_ratio_high`` times
    that attack (a bouncing stick's next impact, not what is left of the earlier one), and the
    template over ``template_fit`` s (or up to the next attack) correlates by ``template_likeness`` (a drum's
    beating modes left over often look like its start alone: our synthetic drum without snares), is an attack
    (moved to the best correlation of the start within ``template_reach`` s after). The start asks less than the
    whole: a drop's quiet bounces are another velocity layer's (FluidR3's snares), whose first 3.5 ms correlate
    0.5-0.8 with the loud template's (``bounce_likeness`` 0.7 instead of ``template_likeness``'s 0.8 finds 7 more of
    the corpus's loud notes within 5 ms, in drops, none falsely; 0.5-0.65 finds 14, but takes 3-4 false bounces in
    TimGM6mb's rolls on other seeds). The fit of a bounce over a reverberant room's sound reads it louder than it is
    (FluidR3's snare 38 drop with reverb: the next bounce, 1.5 dB quieter, at 0.34 of it), so the scale asked of the
    next is ``bounce_ratio_low`` (0.3) or more, not ``after_ratio_low`` (0.35).

    *An onset step 4 refused, a second opinion.* A ghost note 50-120 ms after an accent, on a quieter
    velocity layer of a sample (TimGM6mb's snare: its velocity filter), leaves the modes' band a
    signature unlike the accent's, and step 4 refuses it; at full rate, with the earlier attacks taken
    off, the recording's own attack still fits it (0.83-0.97 over ``template_fit`` s). Where no close
    bounce is found, the first ``refused`` onset (full-rate samples) ``signature`` s or more after the
    attack (``min_interval`` before the next) is an attack where the template's first ``template_fit``
    s, at their best lag within ``template_reach`` s, correlate by ``refused_likeness`` and scale
    ``threshold_db`` or more re the template, and its start there correlates so too (what is left of an
    earlier note, a room's echo, fits less: FluidSynth's reverb's echoes 84 ms after a note 0.77-0.79 over
    10 ms, 0.6 at the start); it is put at that lag.

    *Each attack taken off by its own layer.* A sample's notes are recorded at a few velocities (FluidR3's snare 38:
    one waveform up to velocity 80, another above), alike after their first 10 ms (the drum's modes) but not in
    them: the loud template taken off a quiet note leaves a fifth of it, which hides a bounce after. The template
    is continued past its next attack by the sound of the clear attack with the most room (up to ``tail`` s;
    :func:`._attacks.continued`), for a note's sound 100 ms on is still as loud as a drop's last bounces; and where
    the loop reaches the quietest clear attack, what is left there (up to its next attack, continued so too) is a
    second template, and each attack after is taken off by the one of the two that fits it better. A detection
    within ``bounce_reach`` s after an attack that neither fits (an attack the modes' band placed early, what is
    left of the earlier sound) ends neither that attack's fit nor the search: a bounce found up to ``echo_reach``
    s after it is that attack, and the detection is dropped.

    *A quiet layer's bounce by its own template.* A drop's last bounces (FluidR3's snare 38: -24 to -29 dB, 4-7 ms
    apart) are the quiet layer's sample, whose start the loud template's does not fit (0.62 at a bounce 6.7 ms after
    the one before, where the layer's own first 10 ms correlate 0.90). Where the loud template finds no close bounce
    after an attack the quiet layer's template took off, itself within ``bounce_reach`` s after the attack before it
    (a train of close bounces), the search is made again with that layer's template: its first ``template_fit`` s by
    ``layer_bounce_likeness``, its start by ``weak_likeness``, the scale re that attack's by the layer. Only where the
    recording replays a sample (:func:`_replays`, by ``replay_likeness``): a struck drum's strokes are each a new
    waveform, and on drumstroke's synthetic drums the quietest clear attack is no layer (there this search took the
    modes' beating 7-23 ms after an impact for bounces: 7 false onsets in the fast path's strokes). Before the loop
    reaches the quietest clear attack, the layer's template is that attack's sound as recorded (a drop's first train
    of close bounces may come before it). On the corpus 24 more loud notes within 1 ms and 22 within 5 ms (FluidR3's
    drops), 2 false detections fewer; 24 and 14 more within 1 ms on two other seeds, no false detection more.
    Under a reverberant room's sound a drop's last bounces (5-7 ms apart) keep the layer's first 10 ms (0.81-0.84) but
    not its start (0.2-0.3: the layer peaks 9.4 ms in, its first 3 ms carry a tenth of the energy): where neither
    template's search finds the next bounce (or finds one past its time), after a flight of 10 ms or less, the layer's
    first ``template_fit`` s alone by ``layer_whole_likeness`` (:func:`._attacks._whole_after`), scaled
    ``bounce_ratio_low`` to ``after_ratio_high`` times that attack, a half to one and a half times the flight before
    on (a drop's flights shrink; FluidSynth's blocks jitter them by 1.3 ms), find it. The bounce before's own fit
    over the layer's first 10 ms takes in some of the next bounce's sound: where that finds none either, after a
    flight of 9 ms or less, the bounce before is fitted again together with the layer at each sample from 3.5 ms on
    (two scales, least squares from the bounce before to the next one's 10 ms; :func:`._attacks._joint_after`), and
    the layer's first ``template_fit`` s correlating by ``layer_joint_likeness`` with what the bounce before so
    fitted leaves (scaled as above) is the next bounce (FluidR3's snare 38 with reverb: 0.70 alone, 0.73 so); not
    after a bounce so found (the train's end on: TimGM6mb's snare 38 drops, bounces at -32 and -35 dB whose own sound
    the fit took for a bounce 2.2-2.9 ms on, or after which step 5 kept a detection 15 ms on). And a detection of
    such a train over earlier sound, not timed by the template (FluidR3's snare 40: on its main rise, 0.94 ms late),
    is put where the layer's first ``template_fit`` s correlate best, by ``template_likeness``, up to
    ``layer_start_reach`` s before it, and a detection that close after a bounce found is that bounce: taken off
    there, the bounce's sound hid the next (0.65 there, 0.72 once put at its start). On the corpus, seed 0: 3 more
    loud notes within 1 and 5 ms (FluidR3's drops with reverb: snare 38's 1.9687 s, snare 40's 1.9537 s); seeds 1-4:
    8, 11, 10 and 3 more within 1 and 5 ms, 3 false detections fewer (seed 3); no recording of seeds 0-4 loses a
    note or gains a false detection.
    Along such a train each bounce's fit over the layer's first 10 ms takes in the next bounce's start, and what
    it leaves adds up (FluidR3's drops end in a lower velocity layer than the quietest clear attack's, 0.96 alike
    there: at the snare 40 dry drop's last bounce, seed 2, what the earlier ones leave is -2.4 dB re the bounce even
    with the rules below, which leave it missed).
    (``layer_train_refit``, off by default: once the search finds the next bounce, the last bounces the layer took
    off are fitted again together with the layer there, :func:`._attacks._refit`, up to one flight after it, where
    the bounce after it may sound; it found 3 loud notes more on seeds 1-2 but lost one the joint fit found on
    tests/test_onsets_fast_path.py's FluidR3 snare 38 drop with reverb: the newest bounce's own fit still takes in
    the next one's start.) A bounce the layer's searches found is taken off by the layer even where the loud
    template fits it better, so that
    the search after it is the layer's again, and the next bounce is sought up to one and a half times the longer
    of the flight before and the mean of the two before (``layer_train_found``: FluidSynth's blocks jitter each
    onset by 1.3 ms, a flight of 4.0 ms then one of 6.7). And a detection over earlier sound within
    ``earlier_reach`` s after a bounce the search found after one the layer took off, where the bounce's fit cut
    there correlates under ``template_likeness`` (the layer's first 1.6 ms carry little of it), is that bounce's
    own rise where the layer fitted past it correlates by ``template_likeness`` and the layer fitted at the
    detection does not: dropped, the bounce fitted past it (``layer_found_bursts``: FluidR3's snare 40 dry, seed 2,
    0.42 cut, 0.93 past, -0.4 at the detection). Where the template's search after a bounce the layer took off finds
    the next past a detection that bounce's fit skipped (the detection then dropped as the bounce placed early), the
    layer's search is made first up to the detection (``layer_skipped_search``: FluidR3's snare 40 with reverb, seed
    2, a bounce at 4.0217 s detected on its burst 3.8 ms in alone, the template's bounce 9.3 ms on). On the corpus,
    seed 0: no loud note moves (FluidR3's snare 40 drop at -72 dBFS: an onset a sample earlier); seeds 1-4: 2, 4, 0
    and 0 more loud notes within 1 and 5 ms (FluidR3's drops), no false detection more; no recording of seeds 0-4
    loses a note or gains a false detection.

    *A sample's second burst.* FluidR3's electric snare (40) bursts again 3.4 ms into a note. A detection within
    ``bounce_reach`` s after an attack, where taking that attack's fit off (up to the detection, or past it to the
    next) leaves under ``found_burst_db`` of the energy over the 1 ms after it, is the attack's own sound: dropped
    (as :func:`_fit_template`'s ``burst_db`` drops one after an attack it timed). Where the burst alone was detected,
    over an earlier bounce's sound (not clear by ``lead_clear_db``), its note's start is sought up to
    ``earlier_reach`` s before it: of the samples where the template's start correlates with what is left by
    ``weak_likeness`` or more (at peaks of that correlation; a quiet velocity layer's start fits the loud
    template's less: 0.67 at one such bounce, its whole first 10 ms 0.88), the one where the template's first ``template_fit`` s correlates best, by
    ``template_likeness`` and better than anywhere within ``template_reach`` s of the detection, is the attack (the
    detection dropped): on FluidR3's snare 40 drops and rolls the corpus's bounces detected 3.1-3.9 ms late were
    put within 0.14 ms of their start. A bounce may be detected twice after its start (FluidR3's snare 40: on its main
    rise 0.9 ms late, and on its second burst 3.5 ms in): once the first is dropped, the next detections within
    ``earlier_reach`` s after the attack are tested so too, each with the attack's fit past it taken off, up to
    ``found_bursts`` in a row; else the burst stayed an attack no template fits, and the search after it found
    nothing (the snare 40 dry drop's last three bounces, 6.7-10.7 ms apart, missed). Where the attack's fit cut at the
    first such detection correlates under ``template_likeness`` (a room's sound under it: 0.62 over its first 1.5 ms
    with FluidSynth's reverb, 0.96 over 10 ms), the template is fitted past the detections in the same way, by itself
    (the quiet layer's sound, cut at a detection the modes' band placed early, would fit a note of its layer there as
    well as 2 ms later: a FluidR3 flam's grace note). On the corpus 3 more loud notes within 1 and 5 ms, 2 false
    detections fewer (FluidR3's snare 40 drops dry and with reverb); no other recording changes, nor on seeds 1-4.
    And once a detection is dropped so, the next within ``bounce_reach`` s, over earlier sound and not timed by the
    template, where the attack's fitted sound correlates under ``burst_unfitted_likeness``, ends not its fit either
    (fitted past it, as for the first): the search for a close bounce looks past it (FluidR3's snare 40 drop with
    reverb: a bounce detected in the modes' band 1.3 ms late, 0.0 there, found at its start). On the corpus one more
    loud note within 1 ms; on seed 4 7 more within 1 ms, 4 within 5 ms, a false detection fewer (its snare 40 drop at
    -60 dBFS); seeds 1-3 unchanged. Asked of a detection the template timed, it took a real bounce no template fits
    for no end (TimGM6mb's snare 38 drop at -72 dBFS, seed 2: two bounces lost).

    *Another velocity layer.* A sample's notes are recorded at a few velocities: a ghost note may be another
    layer's than the loudest clear attack. With ``quietest``, the search runs again with the quietest clear attack
    (:func:`_template`) as the template, for the onsets step 4 refused only (the attacks found so far fitted and taken
    off in turn), where both fits correlate by ``layer_likeness``; not when that attack is the loudest's.

    Each attack found is of kind 3, fitted and sought after in turn (:func:`._attacks.template_search`,
    compiled). ``d`` is the magnitude of ``band``'s first difference; ``refused`` the onsets step 4
    refused (full-rate samples, in time order).
    """
    from ._attacks import continued, template_search

    if not len(candidates):
        return candidates
    if quietest and config.layer_likeness >= 1.0:
        return candidates
    loudest, quiet, longest = _template_attacks(d, rate, candidates.times, config)
    layer = quiet if quiet != loudest else None
    chosen = layer if quietest else loudest
    if chosen is None:
        return candidates
    template, offset = _attack_sound(band, candidates.times, chosen, rate, config, own=not quietest)
    fit = round(config.template_fit * rate)
    layer_size = 0
    # the quietest layer's search: no close bounces, the refused onsets by layer_likeness (two values, not a
    # replaced config: checking its fields again took 0.15 ms)
    bounce_reach, refused_likeness = config.bounce_reach, config.refused_likeness
    if quietest:
        bounce_reach, refused_likeness, layer = 0.0, config.layer_likeness, None
    else:
        template = continued(template, _attack_sound(band, candidates.times, longest, rate, config)[0], fit)
        layer_size = 0 if layer is None else len(_attack_sound(band, candidates.times, layer, rate, config)[0])
    pre = round(0.5e-3 * rate)
    head = pre + round(config.template_head * rate)
    _, (lead_clear,) = _clear(d, candidates.times, rate, [config.lead_clear_db])
    layer_bounce = config.layer_bounce_likeness
    if quietest or layer is None or layer_bounce >= 1.0 or not replays():
        layer_bounce = 1.0  # (none sought)
    found, likes, dropped = template_search(band.copy(), template, template[:head],
                                            np.ascontiguousarray(candidates.times, dtype=float),
                                            np.where(candidates.kinds == 3, offset, 0.0),  # timed at its sample
                                            np.ascontiguousarray(refused, dtype=float), offset,
                                            -1 if layer is None else layer, layer_size, pre,
                                            max(1, round(config.min_interval * rate)), round(1e-3 * rate), fit,
                                            round(bounce_reach * rate), round(config.echo_reach * rate),
                                            round(config.signature * rate), round(config.template_reach * rate),
                                            config.template_likeness, refused_likeness,
                                            config.bounce_ratio_low, config.after_ratio_high,
                                            10.0 ** (config.threshold_db / 20.0),
                                            10.0 ** (config.found_burst_db / 10.0) if config.found_burst_db > -120.0 else 0.0,
                                            0 if quietest else round(config.earlier_reach * rate), ~lead_clear & (candidates.kinds != 3),
                                            config.weak_likeness, config.bounce_likeness, layer_bounce,
                                            config.found_bursts, config.burst_unfitted_likeness,
                                            config.layer_whole_likeness if layer_bounce < 1.0 else 1.0,
                                            round(_TRAIN_FLIGHT * rate),
                                            round(config.layer_start_reach * rate) if layer_bounce < 1.0 else 0,
                                            config.layer_joint_likeness if layer_bounce < 1.0 else 1.0,
                                            round(_JOINT_FLIGHT * rate), round(_JOINT_TRAIN * rate),
                                            round(config.echo_reach * rate) if config.train_reach > 0.0 else 0,
                                            round(config.train_reach * rate), round(_TRAIN_JITTER * rate),
                                            config.layer_train_found if layer_bounce < 1.0 else 0,
                                            config.layer_found_bursts if layer_bounce < 1.0 else 0,
                                            config.layer_train_refit if layer_bounce < 1.0 else 0,
                                            config.layer_skipped_search if layer_bounce < 1.0 else 0)
    if not len(found) and not dropped.any():
        return candidates
    merged, fresh = candidates.take(~dropped).insert(found, attack=True, likeness=likes)
    return replace(merged, kinds=np.where(fresh, 3, merged.kinds))


_JOINT_FLIGHT = 3.5e-3  # s: the shortest flight ``layer_joint_likeness`` takes (the corpus's drops' last flights: 3.9 ms
# or more; what the joint fit finds 2.2-2.9 ms after a TimGM6mb snare 38 train's last bounce is that bounce's own sound)
_JOINT_TRAIN = 9e-3  # s: the longest flight before a bounce that ``layer_joint_likeness`` seeks after
_TRAIN_JITTER = 1.5e-3  # s: how much longer than the flight before a train's next flight may be (FluidSynth starts
# a note at a 64-sample block boundary: 1.3 ms at 48 kHz)
_TRAIN_FLIGHT = 10e-3  # s: the longest flight before a drop's last bounce that ``layer_whole_likeness`` seeks after
# (FluidR3's snares: 3.9-9.3 ms; a room's detections 18 ms apart took the room's sound for a train of bounces)


def _ghost_notes(band, d, rate, candidates, config, replays, reverberant=False, shared=None):
    """Step 5: ghost notes under an accent's sound, found where the recording replays a sample (:func:`_replays`).

    A sample player replays a velocity layer's waveform sample for sample (the corpus's SoundFonts: 0.9998 or more
    over the first 10 ms of two notes of a layer), so an accent's own sound is known from another clear attack of
    its layer: taken off (scaled by least squares over the first ``template_fit`` s), it leaves the notes after the
    accent alone (:func:`._ghosts.ghost_onsets`), where the first difference had the accent's ringing louder than
    a ghost note 50-120 ms after it (FluidR3's rolls: a ghost note's main rise found 1.1-1.3 ms late, or none).
    Each of up to three mates gives a remainder; over each millisecond the quietest counts (a mate's own later
    notes are left in its remainder only), and only up to each mate's next attack. Where one mate alone reaches (a
    ghost note late after its accent, the other mates' own next notes first: FluidR3's 0.3204 s, 117 ms after its
    accent), its remainder counts where the note is the accent's own: its sound over the 11 ms from the rise
    ``ghost_own_db`` louder in the accent than in the mate (scaled); a note the mate's (missed) is left there negated,
    louder in the mate (on the corpus's rolls the notes found so read -6.0 to +12.4 dB, the rises on no note of the
    accent's -4.3 to -0.0 dB; ``ghost_own_db`` 120: two mates needed, as before). A note is where that remainder's
    energy over 1 ms (read every 0.25 ms) rises ``ghost_rise_db`` over its most over the 10 ms before, 6 dB or more
    under the accent and within 30 dB of it; its onset is the remainder's first sample over 1 % of its peak (and
    four times its RMS before). In a recording step 4 finds reverberant every rise must be the accent's own so,
    by ``ghost_room_own_db``: FluidSynth's reverb is linear and time-invariant, so a mate's sound takes the accent's
    own returns off with it, but what is left of the returns of the notes before each swells like a note (the
    corpus's recordings step 4 finds reverberant, seeds 0-4: 55 such rises, most 54-85 ms after a note, the
    reverb's delays) and is alike in both sounds (-4.2 to +0.6 dB the accent's over the mate's but two, 1.6 and 3.6;
    the 144 rises on a note, dry rolls step 4 took for reverberant among them, median 2.9 dB): 2 dB asked (120:
    none sought there, as before). A new note (no attack within 5 ms) is an attack of kind 3; an attack 0.5-1.5 ms
    after it (on its main rise: a sample's lead-in late) is moved there; one later (on the sample's later steps) is
    left where it is. ``ghost_rise_db`` 120: none sought (as before this stage).

    *Under white noise.* Where what is left before a rise is white noise (its correlation one sample on within 0.6
    of 0: the noise of both recordings, with what the mates leave of the accent; the drum's or a room's sound left
    over, 0.84-0.98), a quiet note's lead-in rises slowly out of it and its first millisecond is in the 10 ms its rise
    is read against (FluidR3's snare 38 at -72 dBFS: 0.7874 s, 14.4 dB): with ``ghost_rise_gap`` the rise is read also
    against the 10 ms before a gap so long (19.4 dB), the onset sought from the gap's start. And the first sample four
    times the noise's RMS is late by the lead-in under it (FluidR3's snare 40 at -72 dBFS: 0.3204 s, its first 1.2 ms
    1.5-4 times that RMS, found 1.19 ms late): with ``ghost_noise_start`` the onset is where the power changes (the
    split of the 5 ms before and up to that sample into two white noises of the most likelihood), up to so long
    before the rise, where it is a new note (an attack found after it is moved to it as before: moved earlier so,
    TimGM6mb's snare 40 at -60 dBFS on seed 4 lost a note to the later stages). That noise's energy over 1 ms spreads
    +-20 % (48 samples), where ``ghost_rise_db`` was set for the accent's own sound left over: a rise of
    ``ghost_white_rise_db`` over the 10 ms before that gap is a note too, where it is the accent's own (as where one
    mate reaches: a mate's own ghost note missed, left negated in its remainder, rises so; FluidR3's snare 40 at -60
    dBFS, seed 4, 4.1398 s, 9 dB) and the 5 ms before are white (FluidR3's ghost notes at -60 dBFS, held-out seeds
    1-4: 14 missed rising 9-12 dB; 8 more found within 5 ms, no false detection more).

    *Past the mates' own ghost notes.* Where a sample player replays one sample at every velocity (TimGM6mb's snare
    38: every velocity the one waveform, correlation 1.000 over 0-200 ms), a mate's next note is the accent's own
    waveform too: with ``ghost_mate_notes`` it is taken off the mate's remainder (the accent's own sound placed at
    it, within 0.5 ms by its first 2 ms, scaled by least squares), which reaches on to the mate's note after it.
    TimGM6mb's snare 38 roll, seed 0: the ghost note 120 ms after its accent (0.9739 s), whose mates were all cut
    by their own ghost notes 57-115 ms in, leaves -150 dB (dry: found here) or -40 to -53 dB (with reverb: a rise of
    9-12 dB over 1 ms, found by :func:`_room_ghost_notes`' 5 ms) before it and -31 dB on it. A rise so read must still rise once the accent's own later notes of its waveform are taken off as well
    (a rise in such a note's own sound is none), and one past a note found in the accent's window, a mate's lag on,
    is not sought (that note, in the accent's sound added back, is left there).
    """
    from ._ghosts import ghost_onsets

    own_db = config.ghost_room_own_db if reverberant else config.ghost_own_db
    if config.ghost_rise_db >= 120.0 or len(candidates) < 3 or (reverberant and own_db >= 120.0):
        return candidates
    if not replays():
        return candidates
    lead_clear = _lead_clear(d, candidates.times, rate, config.lead_clear_db, shared)
    which = np.flatnonzero(candidates.attack)
    ghosts = ghost_onsets(band, candidates.times[which], lead_clear[which], rate, likeness=config.replay_likeness,
                          rise_db=config.ghost_rise_db, least=10.0 ** (config.threshold_db / 20.0),
                          own_db=own_db, own_everywhere=reverberant, noise_start=config.ghost_noise_start,
                          rise_gap=config.ghost_rise_gap, mate_notes=config.ghost_mate_notes,
                          span=config.ghost_span, white_rise_db=config.ghost_white_rise_db, shared=shared)
    ghosts, starts = ghosts if config.ghost_noise_start > 0.0 else (ghosts, ghosts)
    # an attack found late is one on the main rise after the note's lead-in; a new note under white noise starts
    # where its power changes (ghost_noise_start)
    return _placed_ghosts(candidates, ghosts, which, rate, starts, late=1.5e-3)


def _room_ghost_notes(band, d, rate, candidates, config, replays, shared=None, steps=None):
    """Step 5, in a recording step 4 finds reverberant and that replays a sample: the ghost notes under an accent's
    sound that rise too little for :func:`_ghost_notes`, found by their own attack's waveform.

    What is left once a layer-mate takes an accent's own sound off holds what is left of the room's returns of the
    earlier notes (each mate's and the accent's, unlike), 6-10 dB under a ghost note's first milliseconds: FluidR3's
    snare 38 roll with reverb, seed 0, leaves -41 to -39 dB (re the band's peak) over the 5 ms before its ghost notes
    of 1.1021, 1.7621 and 3.2034 s and -31 dB after, so their energy over 1 ms rises under 4 dB, and the test of
    whose the note is (``ghost_room_own_db``) reads -1.4 to +3.4 dB at them, the accent's ringing most of both. A
    ghost note is its layer's waveform, the returns a smoothed sound: where that remainder's energy over 5 ms rises
    4 dB over its most over the 10 ms before (a mate or more reaching; no test of whose), the quietest clear
    attack's first 5 ms (from 0.5 ms before it: :func:`_template`, ``quietest``) must correlate with the remainder
    by ``ghost_room_fit`` or more, placed within ``ghost_room_reach`` s before to 5 ms after the rise's block, one
    rise tried in 5 ms (:func:`._ghosts.room_ghost_onsets`). On the corpus's recordings step 4 finds reverberant (seeds 0-4, every set
    and condition) the rises on no note fit 0.77 at most, those on a note missed before 0.82-1.00. The quietest
    clear attack of a roll is an accent (FluidR3's: velocity 95-98, its two layers' mix), whose first 5 ms correlate
    0.86-0.98 with a ghost note's alone. A swell of what the mates leave 10 ms before a ghost note lifts the level
    its rise is read against: FluidR3's snare 38 note of 1.7621 s (seed 0) first rises at 1.7633 s, 1.7 ms after
    the attack's window's start, where it fits 0.91-0.96 (each mate) and from 1 ms before the rise 0.56: the fit is
    read from ``ghost_room_reach`` (2 ms) before. An accent whose velocity mixes its two layers its own way has no
    layer-mate (FluidR3's snare 40 accent of 3.5083 s, velocity 95, seed 0: none by 0.999, its ghost note of 3.6004
    s missed): a roll's accent so (none as loud for 0.2 s after it: not a drop's bounce) takes as its mates the
    attacks that correlate with it by ``ghost_room_spare_likeness`` (0.99; an accent of velocity 97 scaled leaves
    -46 dB over the 5 ms before that note, -36 dB after, where the attack fits 0.965). A new note (no attack within
    5 ms) is an attack of kind 3; an attack 0.5-2 ms after it is moved there (a ghost note found late on its main rise:
    FluidR3's rolls, 1.0-1.8 ms; moved 2.1 ms, FluidR3's snare 38 roll with reverb's note of 3.4234 s, seed 2, a
    return 24.6 ms after it, -32 dB, that :func:`_layer_echoes` refused by 0.5 dB, passes by 0.3).
    ``ghost_room_fit`` 1: none sought (as before this field). A mate's next note of the accent's waveform is taken
    off as :func:`_ghost_notes` does (``ghost_mate_notes``; TimGM6mb's snare 38 roll with reverb, seed 0: 0.9739 s).
    """
    from ._ghosts import room_ghost_onsets

    if config.ghost_room_fit >= 1.0 or len(candidates) < 3 or not replays():
        return candidates
    lead_clear = _lead_clear(d, candidates.times, rate, config.lead_clear_db, shared)
    template, _ = _template(band, d, rate, candidates.times, config, quietest=True)
    size = round(0.5e-3 * rate) + round(5e-3 * rate)
    if template is None or len(template) < size:
        return candidates
    which = np.flatnonzero(candidates.attack)
    ghosts = room_ghost_onsets(band, candidates.times[which], lead_clear[which], rate, template[:size],
                               likeness=config.replay_likeness, rise_db=4.0,
                               least=10.0 ** (config.threshold_db / 20.0), fit=config.ghost_room_fit,
                               reach=config.ghost_room_reach, spare_likeness=config.ghost_room_spare_likeness,
                               mate_notes=config.ghost_mate_notes, span=config.ghost_span, shared=shared)
    return _placed_ghosts(candidates, ghosts, which, rate, steps=steps, reach=config.ghost_step_reach)


def _matched_ghost_notes(band, d, rate, candidates, config, replays, shared=None, steps=None):
    """Step 5, where the recording replays a sample: the ghost notes under an accent's sound found by a matched
    filter of their layer's own attack, learned from the ghost notes already found.

    A ghost layer's notes are one waveform replayed, and what the accent's layer-mates leave of it after a ghost
    note found is that note alone with the noise of the recordings: those remainders' first 5.5 ms, aligned and
    averaged (three or more, two mates or more reaching each, correlating by ``ghost_matched_fit``), are the head;
    each note's projection on it its amplitude, and its remainders past the head so scaled and averaged the layer's
    longer sound, so a mate whose own next attack is such a note is taken off less it and reaches on past that note
    (:func:`._ghosts.matched_ghost_onsets`). Under white noise a quiet ghost note's first millisecond rises too
    little over the noise of the two recordings taken one from the other (FluidR3's snare 38 roll at -60 dBFS, seed
    0: 0.7874 s, 10.3 dB where ``ghost_rise_db`` asks 15), while the head's 5.5 ms gather its energy: the mean of
    the reaching mates' remainders fits it 0.98 there; that roll's notes of 2.8007 s (every mate's own next note
    first) and 3.9647 s (found 1.25 ms late) fit 0.97 and 0.99 once the mates' own ghost notes are taken off them.
    Where what the mates leave rises 6 dB over 1 ms (over its most over the 10 ms before) and the head fits by
    ``ghost_matched_fit`` or more (on the corpus's seed 0 the rises 5 ms or more from every note fit 0.61 at most),
    a new note (no attack within 5 ms) is an attack of kind 3 at the head's onset; an attack 0.5-2 ms after it is
    moved there. ``ghost_matched_fit`` 1: none sought (as before this field).

    *Notes found late.* FluidR3's ghost layer rises in steps (its first millisecond 14-22 dB under its peak, 11 dB
    under at +1.0 ms, 6 dB under at +1.75 ms, its peak at +4.0-4.5 ms), and the ghost search's first sample four
    times the RMS before may come on the +1 ms step (FluidR3's snare 40 roll, dry, seed 2: 3.5350 s, +1.19 ms; seed
    4: 2.7110 and 3.3284 s). Notes so found 1.2 ms apart align with the reference by 0.41 at most within ±0.25 ms,
    and no head is learned; with ``ghost_matched_back`` the alignment reaches so far earlier (0.25 ms later: the
    reference is the clearest note), they fit 0.995-1.000, and a note its lag moves more than 0.5 ms earlier than
    the median's is a note at the head's onset there (the attack 0.5-2 ms after it moved to it).

    *Past the first mates' reach.* A roll's accents have ghost notes of their own 55-130 ms after them, so the first
    three mates' remainders stop there and a ghost note later after its accent lay past the window (FluidR3's snare
    38 roll, dry, seed 5: 3.8701 s, 103 ms after its accent, its first mates' next attacks 105-122 ms after them):
    with ``ghost_spare_mates`` up to so many more mates (an accent of a roll has up to eight) count from where fewer
    than two of the first reach, each up to its own next attack (where two of the first reach, as before).
    """
    from ._ghosts import matched_ghost_onsets

    if config.ghost_matched_fit >= 1.0 or len(candidates) < 3 or not replays():
        return candidates
    lead_clear = _lead_clear(d, candidates.times, rate, config.lead_clear_db, shared)
    which = np.flatnonzero(candidates.attack)
    ghosts = matched_ghost_onsets(band, candidates.times[which], lead_clear[which], rate,
                                  likeness=config.replay_likeness, least=10.0 ** (config.threshold_db / 20.0),
                                  fit=config.ghost_matched_fit, back=config.ghost_matched_back,
                                  span=config.ghost_span, spare_mates=config.ghost_spare_mates, shared=shared)
    return _placed_ghosts(candidates, ghosts, which, rate, steps=steps, reach=config.ghost_step_reach)


def _placed_ghosts(candidates, ghosts, which, rate, starts=None, late=2e-3, steps=None, reach=0.0):
    """``candidates`` with each of ``ghosts`` (full-rate samples) an attack of kind 3: new where no attack of
    ``which`` lies within 5 ms (at its ``starts``, the same samples, or ``ghosts`` for None), else the attack 0.5 ms
    to ``late`` s after it moved there (found late). The times are kept where moving would unorder them. An attack
    more than ``late`` and up to ``reach`` s after a ghost (the nearest, as moved) is left where it is, its times and
    the ghosts' appended to ``steps`` as one array [shape=(2, n)] (full-rate samples: moved only once every stage is
    done, :func:`_on_first_steps`)."""
    if not len(ghosts):
        return candidates
    from ._ghosts import placed_ghosts

    starts = ghosts if starts is None else starts
    times, kinds = candidates.times.copy(), candidates.kinds.copy()
    fresh = placed_ghosts(times, kinds, which, np.asarray(ghosts, dtype=float), 5e-3 * rate, 0.5e-3 * rate, late * rate)
    if steps is not None and reach > late and len(which):
        at, g = times[which], np.asarray(ghosts, dtype=float)
        off = at[np.argmin(np.abs(at[None, :] - g[:, None]), axis=1)] - g
        later = (off > late * rate) & (off <= min(reach, 5e-3) * rate)
        steps.append(np.stack((g[later] + off[later], g[later])))
    new = [start for start, is_new in zip(starts, fresh.tolist()) if is_new]
    moved = replace(candidates, times=times, kinds=kinds)
    if not np.all(np.diff(times) > 0):
        moved = candidates
    if not new:
        return moved
    merged, fresh = moved.insert(np.array(new), attack=True, likeness=np.ones(len(new)))
    return replace(merged, kinds=np.where(fresh, 3, merged.kinds))


def _on_first_steps(onsets, steps, rate):
    """``onsets`` with each onset at an attack of ``steps`` (arrays [shape=(2, n)] of full-rate samples: the attacks'
    times when a ghost search found them, and those ghost notes' onsets, :func:`_placed_ghosts`) moved onto the ghost
    note's onset, where the onset before lies before it and the attack's time is unchanged (within 1 sample) by the
    later stages; none moved where that would unorder them.

    FluidR3's ghost layer rises in steps (its first millisecond 14-22 dB under its peak, 11 dB under at +1.0 ms, 6 dB
    under at +1.75 ms, its peak at +4.0-4.5 ms), and under an accent's ringing the first difference finds such a note
    on a later step, 2-4.6 ms late, where the ghost searches (each mate's remainder, the room's fit, the matched
    filter) find it within 0.5 ms of its onset (seeds 1-9: 24 notes). Moved in step 5 it
    moves what the later stages learn from it (the templates, the echoes' and lead-ins' tests) and on the held-out
    seeds it lost notes (up to 4.5 ms after the ghost search's onsets: 11 gained, but in four recordings of seeds 5-9
    a note lost or a false detection more); moved here, once every stage has judged the attack where it was found, nothing else moves
    (``ghost_step_reach``: the room's and the matched searches' notes alone)."""
    at, ghost = np.concatenate(steps, axis=1)
    if not len(at):
        return onsets
    t = onsets.t.copy()
    k = np.argmin(np.abs(t[None, :] * rate - at[:, None]), axis=1)
    ok = (np.abs(t[k] * rate - at) <= 1.0) & ((k == 0) | (t[np.maximum(k - 1, 0)] * rate < ghost))
    t[k[ok]] = np.maximum(ghost[ok] / rate, 0.0)
    if not np.all(np.diff(t) > 0):
        return onsets
    return replace(onsets, t=t)


def _replaying(band, d, times, rate, config):
    """Whether the recording replays a sample (:func:`_replays`), judged once, when first asked, on the attacks at
    ``times`` (full-rate samples: those the template fitted, step 5) clear by ``lead_clear_db``: a function of no
    argument. Three stages ask; a property of the recording, judged alike by each on its own attacks over the corpus
    (five seeds) and our synthetic drums."""
    @cache
    def replays():
        _, (lead_clear,) = _clear(d, times, rate, [config.lead_clear_db])
        return _replays(band, times, lead_clear, rate, config)

    return replays


def _replays(band, times, clear, rate, config):
    """Whether the recording replays a sample: two attacks clear by ``lead_clear_db`` (``clear``, each 20 ms or more
    before the next) whose first ``template_fit`` s correlate by ``replay_likeness`` (within 2 samples), as a sample
    player's notes of one velocity layer do (the corpus's SoundFonts: 0.9998 or more in every drop and roll), not a
    struck drum's (drumstroke's synthetic drums, 180 strokes: 0.998 at most)."""
    from ._ghosts import windows

    pre, lag = round(0.5e-3 * rate), 2
    size = pre + round(config.template_fit * rate)
    starts = np.rint(times).astype(np.int64) - pre
    which = np.flatnonzero(clear & (np.append(np.diff(times), np.inf) >= 20e-3 * rate))
    starts = starts[which[(starts[which] >= lag) & (starts[which] + size + lag <= len(band))]]
    if len(starts) < 2:
        return False
    views = windows(band, size)
    own = views[starts]
    own = own / np.maximum(np.linalg.norm(own, axis=1), 1e-300)[:, None]
    for shift in sorted(range(-lag, lag + 1), key=abs):  # the same lag first: where a sample is replayed, it is found
        shifted = views[starts + shift]
        likeness = shifted @ own.T / np.maximum(np.linalg.norm(shifted, axis=1), 1e-300)[:, None]
        np.fill_diagonal(likeness, -1.0)  # (an attack with itself)
        if likeness.max() >= config.replay_likeness:
            return True
    return False


def _measured_at(candidates, found, rate, config):
    """The candidates, each an attack the template retimed measured where it was found (levels, step 5).

    The lowest modes' amplitude is read over the 5 ms after an onset, where that band is still
    rising: a start moved by a fraction of a millisecond moves it by decibels. Retiming is for the
    time; the level stays that of the detection (within ``template_reach`` s after it), a new attack's at its fit.
    A detection before the attack's fit is not its measuring point: it was on earlier sound or noise,
    where the lowest modes, not yet rising, read decibels low (a FluidR3 flam's grace note 16 dB).
    A detection still a candidate of its own is not another's: the template found a new attack just
    before it (measured there, both would read one window, the earlier's empty: 0, refused as quiet).
    """
    from ._modes import measured_at

    if not len(found) or not len(candidates):
        return candidates
    return replace(candidates, times=measured_at(np.ascontiguousarray(candidates.times, dtype=float),
                                                 np.ascontiguousarray(found, dtype=float), config.template_reach * rate))


def _template(band, d, rate, times, config, quietest=False):
    """The recording's own attack: ``band`` from 0.5 ms before its loudest clear attack, and that attack's offset.

    The loudest attack (its first difference's peak over the 5 ms after it) that is clear by ``lead_clear_db``
    (:func:`_clear`) and 20 ms or more before the next, up to the next (less 0.5 ms) or
    ``tail`` s (``d``: the magnitude of ``band``'s first difference); with ``quietest``, the quietest such attack
    instead (``threshold_db`` or more re the loudest attack's peak), when it is not the loudest. Returns the samples and the attack's time less its whole sample, or
    ``(None, 0.0)`` when there is no such attack.
    """
    loudest, quiet, _ = _template_attacks(d, rate, times, config)
    chosen = (quiet if quiet != loudest else None) if quietest else loudest
    if chosen is None:
        return None, 0.0
    return _attack_sound(band, times, chosen, rate, config, own=not quietest)


def _template_attacks(d, rate, times, config):
    """:func:`_template`'s clear attacks: the loudest, the quietest and the one with the most room before the next
    (up to ``tail`` s; the loudest of those), as indices in ``times`` (None for none): compiled,
    :func:`._templates.template_attacks`."""
    from ._templates import template_attacks

    chosen = template_attacks(d, np.ascontiguousarray(times, dtype=float), round(5e-3 * rate), round(0.5e-3 * rate),
                              round(0.5e-3 * rate), 10.0 ** (config.lead_clear_db / 20.0),
                              10.0 ** (config.threshold_db / 20.0), 20e-3 * rate, config.tail * rate)
    return tuple(None if k < 0 else k for k in chosen)


def _attack_sound(band, times, k, rate, config, own=False):
    """``band`` from 0.5 ms before the attack ``times[k]`` up to the next (less 0.5 ms) or ``tail`` s after, and
    that attack's time less its whole sample. With ``own`` (the loudest clear attack's, which times the attacks over
    earlier sound) and ``template_start_db`` under 0, the attack's time (the offset returned, then negative: the same
    samples) is where it rises out of what comes before (:func:`_own_start`): a detection on its main rise, in noise,
    put every attack it timed as late."""
    pre = round(0.5e-3 * rate)
    t, end = times[k], (times[k + 1] if k + 1 < len(times) else len(band))
    c = round(t)
    if own and config.template_start_db < 0.0:
        # the same samples (the fits, their scales and remainders unchanged), the attack's time moved back to its start
        start = _own_start(band, c, _attack_before(band, times, k, rate, config.template_start_past_db), rate,
                           config.template_start_db)
        t = float(start) if start < c else t
    return band[c - pre:min(int(end) - pre, c + round(config.tail * rate))].copy(), float(t - c)


def _attack_before(band, times, k, rate, past_db):
    """The detection before ``times[k]`` (full-rate samples) as an attack its start is sought after: ``-inf`` (none)
    where it is first or where its own peak (``band``'s largest magnitude over the 0.5 ms after it, before the next
    note's sound) is ``past_db`` or more under the peak of ``times[k]`` (over the 5 ms after it): a detection in the
    noise or on the note's own lead-in, not an attack before it."""
    if not k:
        return -np.inf
    before, c = max(0, round(times[k - 1])), round(times[k])  # (a detection may be placed before the recording's start)
    own = np.max(np.abs(band[before:max(before + 1, min(c, before + round(0.5e-3 * rate)))]))
    if own < np.max(np.abs(band[c:c + round(5e-3 * rate)])) * 10.0 ** (-past_db / 20.0):
        return -np.inf
    return times[k - 1]


def _own_start(band, c, before, rate, db):
    """Where the attack detected at sample ``c`` rises out of what comes before: the first sample up to 2 ms before
    ``c`` whose magnitude is over ``db`` re the attack's peak (``band``'s largest magnitude over the 5 ms after ``c``)
    and 1.5 times the largest over the 5 ms before that window (which must come after the attack ``before``, full-rate
    samples); else ``c``."""
    back, span = round(2e-3 * rate), round(5e-3 * rate)
    low = c - back
    if low - span < 0 or low - span <= before or c + span > len(band):
        return c
    # over the note's own -db point, and 1.5 times the largest magnitude of what comes before (noise, a room's sound):
    # Gaussian noise's largest over 5 ms is some 3 sigma, 1.5 times that a 1-in-10^5 sample
    level = max(np.max(np.abs(band[c:c + span])) * 10.0 ** (db / 20.0), 1.5 * np.max(np.abs(band[low - span:low])))
    over = np.flatnonzero(np.abs(band[low:c + 1]) > level)
    return int(low + over[0]) if len(over) else c


def _clear(d, times, rate, dbs):
    """Whether each attack at ``times`` (full-rate samples, rounded) is clear by each of ``dbs``: ``d`` (the first
    difference's magnitude) over the 5 ms before (up to 0.5 ms before) under ``db`` re its peak over the 5 ms after.

    Returns those peaks [shape=(n,)] and, for each of ``dbs``, an array of booleans [shape=(n,)].
    """
    from ._kernels import peaks_around

    span, gap = round(5e-3 * rate), round(0.5e-3 * rate)
    peaks, priors = peaks_around(d, np.rint(times).astype(np.int64), span, span, gap)
    return peaks, [priors <= peaks * 10.0 ** (db / 20.0) for db in dbs]


def _lead_clear(d, times, rate, db, shared=None):
    """:func:`_clear`'s booleans by ``db``, kept in ``shared`` (a dict, or None) and given again for the same ``d`` (the
    same object), times and level (the ghost searches on the same attacks)."""
    key = (times.tobytes(), rate, db)
    if shared is not None and shared.get("clear_d") is d and shared.get("clear_key") == key:
        return shared["clear"]
    _, (clear,) = _clear(d, times, rate, [db])
    if shared is not None:
        shared.update(clear_d=d, clear_key=key, clear=clear)
    return clear


def _best_lag(x, template, start, reach):
    """Where ``template`` correlates best with ``x`` from ``start`` (samples) within ``reach`` samples each way.

    Returns the lag (samples), the template's least-squares scale there and the correlation (0 when
    no window fits in ``x``).
    """
    from ._kernels import best_lag

    low, high = max(0, start - reach), min(len(x), start + reach + len(template))
    if high - low < len(template):
        return 0, 0.0, 0.0
    template = np.ascontiguousarray(template, dtype=float)
    energy = template @ template
    k, dot, like = best_lag(x, template, low, high - low - len(template) + 1, energy)
    return low + k - start, float(dot / energy), float(like)


@dataclass(frozen=True)
class _Fitting:
    """:func:`_fit_template`'s template and what its fits and searches ask of it (in samples): each fit's best lag
    within ``reach`` each way, the ``head`` (its first ``template_head`` s from ``pre`` before its attack) sought after
    each attack where the remainder rises (over ``width`` samples, from ``back`` before, ``rise`` times in power) and
    the head correlates by ``likeness`` and scales ``least`` or more, and the head's energy (numpy's, once)."""

    template: np.ndarray
    head: np.ndarray
    pre: int
    reach: int
    width: int
    back: int
    rise: float
    likeness: float
    least: float
    head_energy: float

    @classmethod
    def of(cls, template, rate, config):
        """The fitting of ``template`` (``band`` from 0.5 ms before its attack: :func:`_template`) at ``rate`` Hz."""
        pre = round(0.5e-3 * rate)
        head = template[:pre + round(config.template_head * rate)]
        return cls(template, head, pre, round(config.template_reach * rate), max(12, round(1e-3 * rate)),
                   4 * round(1e-3 * rate), config.min_jump ** 2, config.template_likeness,
                   10.0 ** (config.threshold_db / 20.0), head @ head)


def _out_of_decay(band, d, rate, candidates, amplitude, config, replays, reverberant=False):
    """Step 5's last part: a quiet or a close attack that does not rise out of the sound before it is no attack.

    A recorded sample's own decay and a room's tail beat and flutter: the stages before take some
    of their swells, quiet and milliseconds to a quarter second after a note, for attacks. A
    stick's impact adds a click to whatever rings: the first difference of ``band`` over the 2 ms
    after an attack quieter than ``decay_db`` re the loudest must pass its peak over the 5 ms
    before (up to 0.5 ms before the attack) by ``decay_rise_db``. A sample may also burst again a
    few milliseconds into itself (FluidR3's electric snare, 4-6 ms in, as loud as its note in the
    drum's lowest modes): an attack within ``echo_reach`` s after the one before it must pass that
    earlier peak by ``echo_rise_db`` (its first difference falls there: the earlier note goes on).
    In a reverberant recording, a room's echo of an earlier note is none either (:func:`_room_echoes`); nor is a
    quiet attack that the earlier notes' sound at the same delays after other notes explains
    (:func:`_layer_echoes`, where the recording replays a sample). Last, an attack must bring a sound of its own (:func:`_new_sound`). An attack the
    template timed or found (kind 3) is quiet under ``found_decay_db`` instead of ``decay_db``, and must pass ``found_echo_rise_db`` instead of
    ``echo_rise_db`` within ``echo_reach`` s after the one before: the template's fit over what is left of the
    earlier sound is its test. A ghost note 57 ms after an accent found so does not rise 6 dB in its first difference
    over the accent's ringing, nor a drop's bounce 8 ms after the one before -3.5 dB over its sound. ``d`` is the
    magnitude of ``band``'s first difference; ``reverberant``: whether step 4 found the recording so.
    """
    from ._kernels import peaks_around

    attack = candidates.attack
    if not np.any(attack):
        return candidates
    which = np.flatnonzero(attack)
    loudest = amplitude[attack].max()
    # an attack the template timed or found (kind 3) was fitted over what is left of the earlier sound: its test
    fitted = candidates.kinds[which] == 3
    quiet = amplitude[which] < loudest * 10.0 ** (np.where(fitted, config.found_decay_db, config.decay_db) / 20.0)
    close = np.diff(candidates.times[which], prepend=-np.inf) <= config.echo_reach * rate
    echo = np.where(fitted, config.found_echo_rise_db, config.echo_rise_db)
    least = np.where(quiet, 10.0 ** (config.decay_rise_db / 20.0), 10.0 ** (echo / 20.0))
    tried = which[quiet | close]
    rise, prior = peaks_around(d, np.rint(candidates.times[tried]).astype(np.int64), round(2e-3 * rate),
                               round(5e-3 * rate), round(0.5e-3 * rate))
    keep = attack.copy()
    keep[tried] = rise > prior * least[quiet | close]
    again = keep
    if reverberant:
        keep, again = _room_echoes(band, d, rate, candidates, amplitude, keep, config,
                                   under_db=config.room_partner_under_db, passes=True)
    # the layer's test sees the attacks as the room's first pass left them: the second pass (``room_partner_under_db``)
    # only refuses, its returns taken off after (one it refused, 0.3736 s, was a partner window's note that explained
    # the return 4.1281 s after FluidR3's snare 38 drop with reverb, seed 0: -0.24 dB with it, +0.09 dB without)
    keep = _layer_echoes(band, d, rate, candidates, amplitude, keep, config, replays) & again
    return _new_sound(band, rate, replace(candidates, attack=keep), config)


def _room_echoes(band, d, rate, candidates, amplitude, attack, config, kind=2, fit_db=None, under_db=120.0,
                 passes=False):
    """Step 5, in a reverberant recording: ``attack`` less the attacks that are a room's echo of an earlier note.

    A room returns each note again and again, each return a smoothed copy of it (FluidSynth's reverb: from 54 ms
    after the note, 20 dB and more under it); where little else sounds, the stages before take some for attacks,
    found in the modes' band alone (kind 2: the recording's clear attack, the template, does not fit a smoothed
    copy), as quiet as a ghost note and rising no more than one out of the sound before it. What tells them apart
    is the room: it repeats each note's returns after every note alike, at the same delays, while a stick's ghost
    note is new there. An attack of kind 2, ``spike_clear`` s or more after the attack before it, quieter than
    ``room_decay_db`` re the loudest (``amplitude``), whose first difference (``d``, magnitudes) over the 2 ms
    after it does not pass its peak over the 5 ms before by ``room_rise_db``, is an echo when, for some attack
    ``reflection_db`` or more louder 35 ms to 0.3 s before it, the band at the same delay after another attack as
    loud (within 6 dB; no attack found from 1 ms after that one to the end of the window) explains the band over
    the 5 ms before and after it, and alike: its fit (least squares) leaves ``room_fit_db`` or less of that
    band's energy, and the power it leaves after it passes that before it by ``room_echo_db`` at most
    (:func:`._rooms.echo_novelty`; the partners and fits compiled: :func:`._rooms.room_echoes`). A ghost note under
    an accent's tail, as quiet and as flat, leaves 3.6-19 dB more after its start. In a roll every accent's ghost
    note lies within a return's delay, so no accent is a partner at it but one whose ghost note was missed: with
    ``under_db`` (step 5: ``room_partner_under_db``) an attack kept is tried again with each partner's sound clear
    up to its next attack less than so much under it (a second pass, so no echo refused before is kept: its best
    fit may be another partner's, which leaves more after). ``kind`` and ``fit_db``
    (``room_fit_db`` unless given): the attacks tried and the most their fit may leave (:func:`_room_returns` tries
    the template's, kind 3); ``under_db``: 120, no second pass. ``passes``: return the attacks the first pass
    keeps and those the second keeps, apart (the same without a second pass).
    """
    from ._kernels import peaks_around
    from ._rooms import room_echoes

    which = np.flatnonzero(attack)
    times, levels = candidates.times[which], 20.0 * np.log10(np.maximum(amplitude[which], 1e-300))
    apart = np.diff(times, prepend=-np.inf)
    fit_db = config.room_fit_db if fit_db is None else fit_db
    tried = np.flatnonzero((candidates.kinds[which] == kind) & (apart >= config.spike_clear * rate)
                           & (levels < levels.max() + config.room_decay_db))
    if not len(tried):
        return (attack, attack) if passes else attack
    rise, prior = peaks_around(d, np.rint(times[tried]).astype(np.int64), round(2e-3 * rate), round(5e-3 * rate),
                               round(0.5e-3 * rate))
    tried = tried[rise <= prior * 10.0 ** (config.room_rise_db / 20.0)]
    width, reach, novel = round(5e-3 * rate), round(0.5e-3 * rate), 10.0 ** (config.room_echo_db / 10.0)
    # how long the sound after each attack stays clear of the next one found (from 1 ms after it)
    after = np.searchsorted(times, times + 1e-3 * rate, side="right")
    clear = np.append(times, np.inf)[after] - times
    # each tried attack's partners and fits, in one compiled loop
    args = (tried, attack, which, 35e-3 * rate, 0.3 * rate, config.reflection_db, 6.0, width, width, reach,
            max(1, round(60e-6 * rate)), 10.0 ** (fit_db / 10.0), novel)
    kept = first = room_echoes(band, times, levels, clear, *args)
    if under_db < 120.0:  # and those kept, again with the partners clear of the next attack less than so much under
        louder = _clear_of_louder(times, levels, after, under_db)
        again = tried[kept[which[tried]]]
        if len(again) and np.any(louder > clear):
            kept = room_echoes(band, times, levels, louder, again, kept, *args[2:])
    return (first, kept) if passes else kept


def _clear_of_louder(times, levels, after, under_db):
    """How long the sound after each attack (``times``, samples; ``levels``, dB) stays clear of the next one from
    ``after`` on (indices: the first 1 ms or more after each) less than ``under_db`` dB under it."""
    index = np.arange(len(times))
    ends = (index[None, :] >= after[:, None]) & (levels[None, :] > levels[:, None] - under_db)
    return np.where(ends.any(axis=1), times[np.argmax(ends, axis=1)], np.inf) - times


def _layer_echoes(band, d, rate, candidates, amplitude, attack, config, replays):
    """Step 5: ``attack`` less the attacks that are the earlier notes' own sound going on.

    A sample player replays a velocity layer's waveform sample for sample, and a room returns it alike each time:
    whatever a note's sound does a given time after it (a swell of the sample's own decay: TimGM6mb's snare 40 has
    one 44-48 ms in, the same at every velocity; a return of FluidSynth's reverb, 57-175 ms in), it does as much the
    same time after the notes nearest it in level. The stages before take some such swells, quiet, for attacks of
    the modes' band alone (kind 2). Such an attack, quieter than ``layer_decay_db`` re the loudest (``amplitude``),
    is the earlier notes' sound when they explain the band over the 5 ms before and after it together: for each
    attack as loud or louder 2 ms to 0.3 s before it, of the band's windows at the same delay after the 4 other
    attacks nearest that one in level (no attack found from 1 ms after them to the end of the window), the one
    that fits it best alone (least squares, within 60 µs: the notes are placed so); all those windows, fitted
    together (least squares: where a note's sound meets the next's, each explains its own), leave ``room_fit_db`` or
    less of its energy, and the power they leave over the 5 ms after it passes that over the 5 ms before by
    ``layer_echo_db`` at most (compiled: :func:`._rooms.layer_echoes`). One window per earlier note: the return of
    FluidR3's singles with reverb 83.4 ms after a -3.8 dB note, which a partner as loud leaves 3.1-3.6 dB more after
    than before (:func:`_room_echoes`: the reverb's wet part after one note fits that after another to -13 dB
    only, its lag 6 samples off the dry part's), is explained to -17.9 dB, -0.4 dB after, by a quieter note's.

    A note adds a sound of its own that no other note's at the same delays holds, and a ghost note under an
    accent's sound, as quiet and as flat, is explained as well before its start (the accent's sound is most of
    its window) but not after. Over the corpus's seeds 0-4 (each attack so tried: 175 false, 115 notes) the
    windows explain 91 false ones so (-153 to -6.1 dB left, -28.5 to 0.0 dB more after than before); of the notes,
    those they explain to -6 dB or less (33) leave 0.5-19.3 dB more after, the ghost notes 50-120 ms after an
    accent 5.6 dB or more. Only where the recording replays a sample (:func:`_replays`; asked last, where an attack
    would be refused): drumstroke's synthetic drums, each stroke's sound its own but alike, would lose notes. The
    false detections reported over the five seeds fall from 113 to 67; no note is lost or moved.
    """
    from ._rooms import layer_echoes

    if config.layer_echo_db <= -120.0:
        return attack
    which = np.flatnonzero(attack)
    times, levels = candidates.times[which], 20.0 * np.log10(np.maximum(amplitude[which], 1e-300))
    tried = np.flatnonzero((candidates.kinds[which] == 2) & (levels < levels.max() + config.layer_decay_db))
    if not len(tried):
        return attack
    width, reach = round(5e-3 * rate), max(1, round(60e-6 * rate))
    # how long the sound after each attack stays clear of the next one found (from 1 ms after it), and of the one
    # after that where the next is tried here (``layer_echo_partners``: the partner's own return at the delay tried)
    after = np.searchsorted(times, times + 1e-3 * rate, side="right")
    clear = np.append(times, np.inf)[after] - times
    beyond, same = clear, -1.0
    if config.layer_echo_partners:
        echo = np.zeros(len(times) + 1, dtype=bool)
        echo[tried] = True
        beyond = np.where(echo[after], np.append(times, [np.inf, np.inf])[np.minimum(after + 1, len(times))] - times,
                          clear)
        same = _ECHO_SAME * rate
    kept = layer_echoes(band, times, levels, clear, tried, attack, which, 2e-3 * rate, 0.3 * rate, width, width, reach,
                        10.0 ** (config.room_fit_db / 10.0), 10.0 ** (config.layer_echo_db / 10.0), 4, beyond, same)
    if np.array_equal(kept, attack):
        return attack
    # only where the recording replays a sample (asked last: most recordings refuse nothing here)
    return kept if replays() else attack


_ECHO_SAME = 1.5e-3  # s: how near a partner's next attack must lie to the delay tried to be its own return there
# (``layer_echo_partners``; FluidSynth's blocks jitter a note by 1.33 ms)


def _room_returns(band, d, rate, candidates, amplitude, onsets, config):
    """Step 6's last part, in a reverberant recording: ``onsets`` less a room's return that the template timed.

    A room's return can be clear enough for the template to fit it (kind 3; FluidR3's snare, 83.5 ms after a
    note, -21 dB): :func:`_room_echoes`' test with ``room_found_fit_db``, asking that the other note's sound at the
    same delay explain nearly all of it (such a return: -18 dB left). Tried on what is reported, after
    :func:`_without_reflections`: an attack taken off before changes the windows and the pairs of the stages after
    it (a drop's returns, each repeated, are found reflections there). Then the returns of the modes' band alone
    (kind 2) are tried again as in step 5: the onsets left out since (refused, reflections, the returns above)
    leave more notes clear for as long as the delay, whose sound may explain them. ``candidates`` and
    ``amplitude`` are the stages' attacks the onsets were reported from; ``room_found_fit_db=-120``: nothing is
    tried.
    """
    if config.room_found_fit_db <= -120.0 or len(onsets.t) < 2:
        return onsets
    at = candidates.times / rate
    nearest = np.clip(np.searchsorted(onsets.t, at), 1, len(onsets.t) - 1)
    nearest -= at - onsets.t[nearest - 1] < onsets.t[nearest] - at
    reported = candidates.attack & (np.abs(onsets.t[nearest] - at) < 1e-6)
    kept = _room_echoes(band, d, rate, candidates, amplitude, reported, config, kind=3,
                        fit_db=config.room_found_fit_db)
    # what is left is clear of the onsets left out since step 5: other notes' sound at the same delay may now explain
    # a return of the modes' band alone that step 5 kept
    kept = _room_echoes(band, d, rate, candidates, amplitude, kept, config)
    keep = np.ones(len(onsets.t), bool)
    keep[nearest[reported & ~kept]] = False
    return replace(onsets, t=onsets.t[keep], level_db=onsets.level_db[keep])


def _new_sound(band, rate, candidates, config):
    """Step 5's very last part: an attack whose own sound is ``new_sound_db`` or more under the sound there is none.

    A stick's impact adds a sound of its own to whatever rings; a swell of a sample's decay, a
    room's echo or a sample's second burst is the earlier notes' sound going on. Where a recording
    repeats its notes' waveforms (a sample player; a drum struck alike), the earlier attacks' sound,
    fitted by the recording's ``sound_templates`` clear notes, each up to the next onset (:func:`_cut_templates`),
    and taken off as for :attr:`Onsets.peak_db` (:func:`_own_peaks`), leaves little of such a swell: over the corpus of recorded drums, its own
    peak over ``peak_window`` s stood 20-73 dB under the sound's peak there at 20 of the 103 false
    detections, at most 17.5 dB under it at the notes (a ghost note over an accent's ringing). Where
    the earlier sound is not so explained (each stroke's sound its own), little is taken off and
    nothing refused.
    """
    which = np.flatnonzero(candidates.attack)
    if len(which) < 2:
        return candidates
    own, heard = _own_peaks(band, candidates.times[which], rate, config, _cut_templates)[:2]
    attack = candidates.attack.copy()
    attack[which] = own >= heard * 10.0 ** (config.new_sound_db / 20.0)
    return replace(candidates, attack=attack)


def _one_attack_each(d, rate, candidates, amplitude, config):
    """Step 5: an attack followed within ``start_reach`` s by one ``lead_db`` louder is one attack with it.

    A recorded sample's first click can be found as an attack of its own, about 1-3 ms before its
    main rise (found too), and so can a point of the earlier sound's decay 2-4 ms before a note: a
    stick's impact is not a quiet one followed so closely by a much louder one. The earlier is the
    later's first transient, kept at its time with the later's amplitude, when the first
    difference's peak over its 0.25 ms passes ``start_over`` times that over the ``start_reach`` s
    before it and ``start_db`` re the later's (over ``start_reach`` s), and either the sound rises on
    from it (that peak over every 0.25 ms up to the later stays over half of it) or it rises out of
    silence (the peak over the ``start_reach`` s before it under ``start_clear_db`` re the later's:
    no earlier sound to swell there; TimGM6mb's electric snare clicks, dips 20 dB, then rises 1.1 ms
    later). Else, when the later is
    ``lead_db`` louder in its first difference too (its peak over ``start_reach`` s against the
    earlier's up to it), the earlier is no attack (a swell of the decay before a note, noise): the
    later stays alone. Else both stay (a quiet note and its sample's second burst, louder in the
    lowest modes only: :func:`_out_of_decay` tells them). Two attacks the template both timed or found
    (kind 3) are asked ``fitted_lead_db`` instead of ``lead_db``: a dropped stick's close bounces, each
    fitted apart by :func:`_template_search`, whose levels read here say little of which is louder
    (FluidR3's snare 38's quiet velocity layer peaks 9.4 ms into a note, 5 dB over its first 4 ms: of two
    bounces 4 ms apart, the earlier's level, read up to the later, reads low and the later's, over the
    earlier's rise, 8 dB too loud; the earlier, a bounce found within 0.05 ms, was taken for a swell before
    the later and the bounce lost). On the corpus 2 more loud notes within 1 and 5 ms (FluidR3's snare 38
    drop dry and at -72 dBFS), no false detection more; seeds 1-4 unchanged. First, an attack the template timed or found
    (kind 3, :func:`_fit_template`) followed within ``template_reach`` s by one it did not is that
    one's start: the template found the attack's start, the detection is its late time (up to the
    reach the template seeks an attack over); one attack, at the earlier time, with the later's
    level (:func:`_measured_at`). ``d`` is the magnitude of the band's first difference. Returns the candidates
    and their amplitudes.
    """
    from ._detect import one_attack_each

    which = np.flatnonzero(candidates.attack)
    if len(which) < 2:
        return candidates, amplitude
    # out of silence (the sound before it under start_clear_db re the later), nothing earlier can swell there
    keep, amplitude = one_attack_each(d, candidates.times, candidates.kinds, amplitude, which,
                                      max(1, round(0.25e-3 * rate)), round(config.start_reach * rate),
                                      config.template_reach * rate, 10.0 ** (config.lead_db / 20.0), config.start_over,
                                      10.0 ** (config.start_db / 20.0), 10.0 ** (config.start_clear_db / 20.0),
                                      10.0 ** (config.fitted_lead_db / 20.0))
    return candidates.take(keep), amplitude[keep]


def _learned_lead_ins(d, rate, candidates, config):
    """Step 5's last part: an attack whose first transient is hidden by earlier sound is put its lead-in before its main rise.

    A recorded sample restarted over its own ringing hides its first click; the stages before then
    place the onset on the main rise, a sample's fixed lead-in (about 1 ms) late. The lead-in is
    learned on the same recording: on its clear attacks (the sound over the 5 ms before, up to
    0.5 ms before, under ``lead_clear_db`` re the attack's peak first difference over the 5 ms
    after), the median time from the onset to the main rise, the first sample within 2 ms before
    to 3 ms after it whose first difference passes ``lead_rise`` of that peak. The others are put
    that long before their own main rise, when that earlier sound is quieter than they and the move
    is no more than the lead-in and 0.3 ms earlier (or 0.3 ms later) than where they were. Nothing
    moves with fewer than 3 clear attacks, a lead-in under 0.25 ms or spread over more than 0.2 ms
    (interquartile: not a sample's own), or when the attacks would not stay in time order. ``d`` is the magnitude
    of the band's first difference.
    """
    from ._kernels import first_at_least, peaks_around

    which = np.flatnonzero(candidates.attack)
    centres = np.rint(candidates.times[which]).astype(np.int64)
    peak, prior = peaks_around(d, centres, round(5e-3 * rate), round(5e-3 * rate), round(0.5e-3 * rate))
    clear, over = prior <= peak * 10.0 ** (config.lead_clear_db / 20.0), prior < peak
    low = np.maximum(0, centres - round(2e-3 * rate))
    above = first_at_least(d, low, centres + round(3e-3 * rate), config.lead_rise * peak)
    rise = np.where((above >= 0) & (peak > 0.0), low + above, candidates.times[which])
    if clear.sum() < 3:
        return candidates
    leads = rise[clear] - candidates.times[which[clear]]
    lead, spread = _median_and_spread(leads)
    if lead < 0.25e-3 * rate or spread > 0.2e-3 * rate:  # no lead-in to restore, or not a sample's fixed one
        return candidates
    times = candidates.times.copy()
    shift = rise - lead - times[which]
    # under louder earlier sound the main rise found is that sound's, not the attack's; farther than
    # its lead-in (and a little) before where the stages before put it, it is not this attack's either
    moved = ~clear & over & (shift >= -lead - 0.3e-3 * rate) & (shift <= 0.3e-3 * rate) & (candidates.kinds[which] != 3)
    times[which[moved]] += shift[moved]
    if not np.all(np.diff(times[which]) > 0):
        return candidates
    return replace(candidates, times=times)


def _median_and_spread(values):
    """``np.median(values)`` and ``np.subtract(*np.percentile(values, [75, 25]))`` (the interquartile range), the same
    to the bit, from one sort (numpy's two calls cost some 0.1 ms on a few values): the two middle values' mean, and
    numpy's linear interpolation between neighbours, from the nearer one where the weight is a half or more."""
    ordered = np.sort(values).tolist()
    count = len(ordered)
    middle = ordered[count // 2] if count % 2 else (ordered[count // 2 - 1] + ordered[count // 2]) / 2.0

    def quantile(q):
        at = (count - 1) * q
        below = math.floor(at)
        if at >= count - 1:
            return ordered[-1]
        weight, low, high = at - below, ordered[below], ordered[below + 1]
        step = high - low
        return high - step * (1 - weight) if weight >= 0.5 else low + step * weight

    return middle, quantile(0.75) - quantile(0.25)


@dataclass(frozen=True)
class _LevelBand:
    """Step 5's band of the drum's lowest modes: ``x`` decimated ``q`` times (at ``rate`` Hz, its filter's delay
    ``delay`` full-rate samples), its predictor's error filter ``coefficients``, what that does not predict ``e``, and
    its noise ``floor`` (full scale)."""

    x: np.ndarray
    q: int
    delay: float
    rate: float
    coefficients: np.ndarray
    e: np.ndarray
    floor: float

    def amplitudes(self, candidates, reverberant, config):
        """Each candidate's amplitude in the band (full scale): :func:`_attack_amplitudes`."""
        return _attack_amplitudes(self.x, self.coefficients, (candidates.times + self.delay) / self.q, self.rate,
                                  tail=round(config.tail * self.rate) if reverberant else 0,
                                  sure=candidates.likeness >= config.likeness, ridge=config.tail_ridge, e=self.e)


def _level_band(band, rate, q, first, config, guessed=None):
    """Step 5: the :class:`_LevelBand` of ``band``, its top from the ``first`` onsets (:func:`_level_corner`); ``q`` is
    step 1's decimation; ``guessed``, a :func:`_decimate` of ``band`` already made (or None), is taken where its
    decimation is this band's."""
    q3 = _level_decimation(band, rate, q, first, config)
    if guessed is not None and guessed[1] == rate / q3:
        lowest, lowest_rate, lowest_delay = guessed
    else:
        lowest, lowest_rate, lowest_delay = _decimate(band, rate, q3)
    coefficients, e = _robust_innovation(lowest, config.level_order)
    return _LevelBand(lowest, q3, lowest_delay, lowest_rate, coefficients, e,
                      _noise_floor(lowest, lowest_rate, config.floor_quantile))


def _level_decimation(band, rate, q, onsets, config):
    """The level band's decimation (≥ step 1's ``q``), its top from the loudest of ``onsets`` (:func:`_level_corner`)."""
    return max(q, int(rate // (2.5 * _level_corner(band, rate, onsets, config))))


def _reported(candidates, amplitude, floor, info, source, rate, config):
    """Step 6: the attacks above the noise floor and the threshold, in s and dB re the loudest."""
    found = (amplitude > floor * 10.0 ** (config.floor_margin_db / 20.0)) & candidates.attack
    if not np.any(found):
        return _no_onsets("no attack rises above the noise floor", info, source, config)
    times, amplitude = candidates.times[found], amplitude[found]
    level = 20.0 * np.log10(amplitude / amplitude.max())
    # digital silence between the attacks leaves only the filters' decay (-1000 dB and less): no floor at all
    floor_db = float(20.0 * np.log10(floor / amplitude.max())) if floor > 1e-9 * amplitude.max() else -np.inf
    used = max(config.threshold_db, floor_db + config.floor_margin_db)
    keep = level >= used
    info = {**info, "floor_db": floor_db if np.isfinite(floor_db) else None}
    return Onsets(np.maximum(times[keep] / rate, 0.0), level[keep], threshold_db=float(used), source=source,
                  info=info)


def _without_reflections(onsets, config, reverberant=True, rise=None, rate=None):
    """Step 6: the ``onsets`` less a room's discrete reflections of the louder ones.

    A room (FluidSynth's reverb) returns each note once more a fixed delay later, some 20 dB quieter:
    where nothing sounds between a note and the next, that return is heard as an attack. Successive
    onsets, the later ``reflection_db`` or more under the earlier, that ``reflection_pairs`` pairs or more
    share a delay (within ``reflection_spread`` s) are such: the later is left out. Only successive
    ones: a stick's bounces, whose sums of intervals do repeat (a drop's, notes starting on a
    sound card's blocks), have other onsets between. Where step 4 finds no room (``reverberant`` False), the pairs
    must also lie as much under their notes within ``reflection_drop_spread`` dB: a room returns each note with one
    gain, while a roll's ghost notes on the sound card's blocks share a delay after their accents by chance
    (TimGM6mb's snare 38 roll, dry, seed 4: three at 104.00 ms, 13.3, 13.8 and 20.1 dB under; the reflections of
    FluidR3's snare 38 drop with reverb, seed 2, four at 83.4-83.5 ms, lie 15.9-23.1 dB under: a room's tail adds
    to a return, and that recording step 4 finds reverberant). Given the band's first difference (``rise``, at
    ``rate``), a delay :func:`_chance_delays` finds a roll's ghost notes' by chance keeps its onsets.
    """
    if config.reflection_pairs == 0 or len(onsets) <= config.reflection_pairs:
        return onsets
    drops = onsets.level_db[:-1] - onsets.level_db[1:]
    pairs = np.flatnonzero(drops >= config.reflection_db)
    own = np.diff(onsets.t)[pairs]
    if config.reflection_drop_spread < 120.0 and not reverberant:  # as much under its note each time as well
        drop = drops[pairs]
        alike = np.sum((np.abs(own[:, None] - own[None, :]) <= config.reflection_spread)
                       & (np.abs(drop[:, None] - drop[None, :]) <= config.reflection_drop_spread), axis=1)
    else:
        delays = np.sort(own)
        alike = (np.searchsorted(delays, own + config.reflection_spread, side="right")
                 - np.searchsorted(delays, own - config.reflection_spread, side="left"))
    keep = np.ones(len(onsets), dtype=bool)
    marked = pairs[alike >= config.reflection_pairs]
    if config.reflection_excess < 1.0 and rise is not None and len(marked):
        marked = marked[~_chance_delays(onsets, marked, rise, rate, config)]
    keep[marked + 1] = False
    if keep.all():
        return onsets
    return replace(onsets, t=onsets.t[keep], level_db=onsets.level_db[keep])


def _chance_delays(onsets, marked, rise, rate, config):
    """Which of step 6's ``marked`` pairs (indices of their earlier onsets) share their delay by chance, no room's.

    A room returns every note at its one delay: D after any loud note whose next onset comes later, the band
    holds the same (a return, or the note's own ring) as D after the pair's earlier notes. A roll's ghost notes
    follow only a few accents at one delay by chance: D after those, a new attack like the accent's own, and
    after the others only the note's ring. The likeness: the largest |correlation| within ±0.25 ms of the band's
    first difference (``rise``) 3 ms from the onset with 3 ms from D later. Where the least pair's likeness
    exceeds the median of the other loud notes' (within 20 dB of the loudest, their next onset 3 ms or more
    past D; 3 at least) by ``reflection_excess``, the delay is chance.
    """
    t, level = onsets.t, onsets.level_db
    gap = np.append(np.diff(t), np.inf)
    width, reach = round(3e-3 * rate), round(0.25e-3 * rate)
    delays = gap[marked]
    order = np.argsort(delays)
    chance = np.zeros(len(marked), dtype=bool)

    def likeness(at, delay):  # at each onset of ``at``: nan where a window leaves the signal
        a, b = np.round(t[at] * rate).astype(int), np.round((t[at] + delay) * rate).astype(int)
        inside = (a >= 0) & (a + width <= len(rise)) & (b - reach >= 0) & (b + reach + width <= len(rise))
        out = np.full(len(at), np.nan)
        if inside.any():
            u = rise[a[inside, None] + np.arange(width)]
            v = rise[b[inside, None] + np.arange(-reach, reach + width)]
            shifted = np.lib.stride_tricks.sliding_window_view(v, width, axis=1)
            power = np.einsum("ij,ij->i", u, u)[:, None] * np.einsum("isj,isj->is", shifted, shifted)
            out[inside] = np.max(np.abs(np.einsum("ij,isj->is", u, shifted)) / np.sqrt(np.maximum(power, 1e-30)),
                                 axis=1)
        return out

    start = 0
    for k in range(1, len(order) + 1):  # groups of delays, each within reflection_spread of the one before
        if k < len(order) and delays[order[k]] - delays[order[k - 1]] <= config.reflection_spread:
            continue
        group = order[start:k]
        start = k
        delay = float(np.median(delays[group]))
        both = likeness(np.concatenate([marked[group], np.flatnonzero((gap > delay + 3e-3) & (level >= -20.0))]),
                        delay)
        own, theirs = both[:len(group)], both[len(group):]
        theirs = theirs[np.isfinite(theirs)]
        if len(theirs) >= 3 and np.all(np.isfinite(own)) and own.min() - np.median(theirs) > config.reflection_excess:
            chance[group] = True
    return chance


def _peak_db(signal, times, rate, config):
    """Step 6's :attr:`Onsets.peak_db` of the onsets reported at ``times`` (full-rate samples): dB re the loudest's."""
    if not len(times):
        return np.empty(0)
    peaks = np.maximum(_peak_amplitudes(signal, times, rate, config), np.finfo(float).tiny)  # never -inf dB
    return 20.0 * np.log10(peaks / peaks.max())


def _peak_amplitudes(signal, times, rate, config):
    """Each onset's broadband peak (full scale) on the signal itself, the earlier notes' sound taken off.

    ``times`` (full-rate samples, increasing) are the onsets reported (an attack refused there would have its
    window, and take a whole note off, in a reported one's). A recording's loudness of a note is its
    loudest sample, but over a later note the earlier ones still sound (a drop's last bounces 4-12 ms
    apart, a ghost note over an accent's ringing): read as it is, the peak is theirs together. So each
    note in time order has its peak read over ``peak_window`` s (or up to the next onset) of the
    remainder, then its own sound is fitted there by the recording's own templates, one a velocity layer
    (:func:`_peak_templates`: the one that fits best, scaled by least squares, a few samples either
    way, or within ``peak_realign`` s where that leaves over 30 % unexplained) and taken off for ``peak_reach`` s. A template is a whole waveform: where a recording repeats
    a sample (a drum machine, a SoundFont) it cancels the earlier note; where each stroke differs, the
    least-squares scale falls with the likeness, and less is taken off (never more than it explains).
    A decay extrapolated from before the note (its envelope, or a linear predictor's free response)
    cannot follow an earlier note still rising to its own peak (up to 9 ms after its start), and
    subtracting envelopes in power leaves the two waveforms' beating: both measured 2-10 dB worse on
    rolls and drops (docs/analysis.md). The signal is not high-passed (a 60 Hz high-pass moves a
    sample's peak by up to 1.8 dB), only its mean taken off.

    With ``peak_learn`` (over 0), the layers no clear note has a template of are learned from their quietest notes
    with room, the earlier notes' fits taken off (:func:`._templates.own_peaks`), and a note whose window the next
    onset cuts short of ``peak_window`` has its peak read from its fit where that explains 70 % or more of the window
    (the fitted template's scale times its peak over the window): a drop's close bounces (4-8 ms apart) on FluidR3's snare, whose quiet layer peaks 9.4 ms
    into the note, read 1-2.7 dB low over their windows cut short and (fitted by the loud layer's template) left
    their sound under the next bounces' peaks, up to 4.6 dB high.
    """
    peaks, _, fitted = _own_peaks(np.asarray(signal, dtype=float) - float(np.mean(signal)), times, rate, config,
                                  overwrite=True, realign=round(config.peak_realign * rate), learn=config.peak_learn)
    return np.where(np.isnan(fitted), peaks, fitted)


def _own_peaks(x, times, rate, config, templates=None, overwrite=False, realign=0, learn=0.0):
    """Each onset's own peak (:func:`_peak_amplitudes`: ``x`` less the earlier notes' sound) and the peak of ``x`` itself
    over the same window (full scale) [each shape=(n,)].

    ``templates`` makes the templates from ``(x, starts, following, ends, rate, config)``: :func:`_peak_templates`
    by default; :func:`_new_sound` uses :func:`_cut_templates` (its figures were measured with them). With
    ``overwrite`` (``x`` a float array of the caller's, not read after), the notes' sound is taken off ``x`` itself
    (no copy of the recording's length).

    In time order, each onset's peaks are read over its window, then the template that fits the remainder from it
    to the next onset best (placed within 60 µs either way; those that last to the end of the next onset's window
    preferred, else the longest) is taken off, scaled by least squares (compiled: :func:`._templates.own_peaks`).
    With ``realign`` (samples; ``peak_realign``'s, for :attr:`Onsets.peak_db` only), a fit that leaves more than
    :data:`_POOR_FIT` of its window unexplained is sought again that far either way (a template misplaced by an onset
    0.1-1 ms late leaves its note's sound under the next notes' peaks: up to 12 dB over a ghost note's). With
    ``learn`` (``peak_learn``'s, for :attr:`Onsets.peak_db` only), the layers the templates lack are learned on the
    way, and a third array [shape=(n,)] is each fit's peak where the next onset cuts a window short (NaN elsewhere;
    :func:`._templates.own_peaks`).
    """
    from ._templates import own_peaks

    starts = np.round(times).astype(np.int64).clip(0, len(x) - 1)
    following = np.append(starts[1:], len(x))
    ends = np.maximum(np.minimum(starts + round(config.peak_window * rate), following), starts + 1)
    window, reach = round(config.peak_window * rate), round(config.peak_reach * rate)
    shift = max(1, round(6e-5 * rate))  # the onsets are placed within a few samples
    templates = (templates or _peak_templates)(x, starts, following, ends, rate, config)
    lengths = np.array([len(t) for t in templates], dtype=np.int64)
    bank = np.concatenate(templates) if templates else np.empty(0)
    rest = x if overwrite else np.array(x, dtype=float)
    return own_peaks(rest, starts, following, ends, bank, np.cumsum(lengths) - lengths, lengths, window, reach, shift,
                     realign, _POOR_FIT, learn, round(_LEARN_ROOM * rate), 10.0 ** (_LEARN_CLEAR_DB / 20.0))


_LEARN_CLEAR_DB = -20.0  # (peak_learn) a note learned: what the earlier notes' fits leave over its window before, re its peak
_LEARN_ROOM = 40e-3  # s (peak_learn) a note learned: its room before the next onset, and how much of the template is its own
_POOR_FIT = 0.3  # the fraction of a note a fit leaves unexplained over which it is sought again (``peak_realign``)


def _peak_templates(x, starts, following, ends, rate, config):
    """The recording's own note waveforms, one a velocity layer: each the median of that layer's clear notes.

    A clear note: quiet before (its 10 ms before under ``peak_clear_db`` re its peak), ``peak_window`` s at
    least before the next onset; ``peak_templates`` of the loudest are sorted into layers by their first
    ``peak_window`` s (:func:`_layers`), and each layer's waveforms, each scaled to the layer's loudest,
    make its template (:func:`_layer_template`), ``peak_reach`` s at most. A note's waveform is followed past
    the quieter onsets after it, up to the first whose peak rises ``peak_apart_db`` or more re its own (a
    later note that loud is not outvoted): a template cut at the next onset, as it once was, lost its
    tail wherever one more (true) onset was found in it, and the notes after read up to 4 dB higher. With
    ``peak_realign``, a waveform ends where the next note's attack already rises before its onset
    (:func:`_before_rise`: an onset placed late left that attack in the template, taken off the next notes).
    """
    chosen, (peaks, priors) = _clear_notes(x, starts, following, ends, rate, config, config.peak_templates)
    rises, apart = peaks - priors, 10.0 ** (config.peak_apart_db / 20.0)
    free = {i: next((starts[j] for j in range(i + 1, len(starts)) if rises[j] >= apart * peaks[i]), len(x))
            for i in chosen}
    shift = max(1, round(6e-5 * rate))  # the onsets are placed within a few samples
    guard = round(config.peak_realign * rate)  # a next onset placed late: its attack not in the waveform
    if guard:
        following = following.copy()
        for i in chosen:
            following[i] = _before_rise(x, starts[i], following[i], guard)
        free = {i: _before_rise(x, starts[i], end, guard) for i, end in free.items()}
    return [_layer_template(x, starts, following, free, layer, round(config.peak_reach * rate))
            for layer in _layers(x, starts, chosen, round(config.peak_window * rate), shift, config.peak_layer_likeness)]


def _before_rise(x, start, end, guard):
    """``end`` (samples), or earlier where the next note's attack is already under way before it: the first of the
    ``guard`` samples before ``end`` where ``|x|`` passes twice its peak over the ``guard`` before them (an onset
    placed up to ``peak_realign`` late), no earlier than ``start + 1``."""
    low = max(end - guard, start + 1)
    if end - low < 1 or low - guard < start:
        return end
    rise = np.flatnonzero(np.abs(x[low:end]) > 2.0 * np.abs(x[low - guard:low]).max())
    return low + int(rise[0]) if len(rise) else end


def _cut_templates(x, starts, following, ends, rate, config):
    """:func:`_new_sound`'s templates: the ``sound_templates`` loudest clear notes' waveforms, each up to the next onset."""
    chosen, _ = _clear_notes(x, starts, following, ends, rate, config, config.sound_templates)
    return [x[starts[i]:min(following[i], starts[i] + round(config.peak_reach * rate))] for i in chosen]


def _clear_notes(x, starts, following, ends, rate, config, count):
    """The ``count`` loudest clear notes (indices of ``starts``, loudest first) and every onset's peak and the peak over
    its 10 ms before (full scale) [each shape=(n,)]: a clear note is quiet before (its 10 ms before under
    ``peak_clear_db`` re its peak over ``starts`` to ``ends``), ``peak_window`` s at least before the next onset."""
    from ._kernels import window_peaks

    window, before = round(config.peak_window * rate), round(10e-3 * rate)
    peaks = window_peaks(x, starts, ends)
    priors = window_peaks(x, np.maximum(starts - before, 0), starts)
    quiet = 10.0 ** (config.peak_clear_db / 20.0)
    clear = np.flatnonzero((following - starts >= window) & (priors <= quiet * peaks))
    return clear[np.argsort(-peaks[clear], kind="stable")][:count].tolist(), (peaks, priors)  # ties in time order


def _layers(x, starts, chosen, head, shift, likeness):
    """The notes ``chosen`` (indices of ``starts``, loudest first) in velocity layers: lists of (index, lag, scale).

    A note joins the first layer whose loudest note's first ``head`` samples correlate with its own by
    ``likeness`` or more (placed within ``shift`` samples either way; the lag in samples, and its scale re that
    note's by least squares), else starts a layer. A SoundFont's snare has one sample a velocity range (TimGM6mb's
    one for all, FluidR3's some four, correlating 0.96-0.99 with each other over 10 ms).
    """
    layers = []
    for i in chosen:
        for layer in layers:
            first = starts[layer[0][0]]
            lag, scale, like = _best_lag(x, x[first:first + head], starts[i], shift)
            if like >= likeness and scale > 0.0:
                layer.append((i, lag, scale))
                break
        else:
            layers.append([(i, 0, 1.0)])
    return layers


def _layer_template(x, starts, following, free, layer, reach):
    """A layer's template: at each sample the median of its notes' waveforms (each over its scale), up to ``reach``.

    Each note's waveform lasts to ``free[i]`` (the next onset loud enough to count); where three or more last,
    their median, in which another note in one of them (a ghost note, a missed one) is outvoted; elsewhere the
    median of the notes' waveforms up to their next onset (clean), as far as one lasts.
    """
    from ._templates import layer_median

    notes = np.array([i for i, _, _ in layer], dtype=np.int64)
    at = starts[notes] + np.array([lag for _, lag, _ in layer], dtype=np.int64)
    whole = np.maximum(0, np.minimum(np.minimum([free[i] for i in notes.tolist()] - starts[notes], reach),
                                     len(x) - at))
    clean = np.minimum(whole, following[notes] - starts[notes])
    return layer_median(x, at, np.array([scale for _, _, scale in layer]), whole, clean)


# ------------------------------------------------------------------------------------------ the stages' tools


def _high_pass(signal, rate, corner):
    """``signal`` less its rumble and DC (a 2nd-order Butterworth high-pass at ``corner`` Hz), its largest magnitude and
    where that first is."""
    from ._front import high_pass

    band, peak, loudest = high_pass(_high_pass_sections(corner, rate), np.ascontiguousarray(signal, dtype=float))
    return band, float(peak), int(loudest)


@cache
def _high_pass_sections(corner, rate):
    """:func:`_high_pass`'s filter (second-order sections), designed once a corner and rate."""
    from scipy.signal import butter

    return butter(2, corner, btype="highpass", fs=rate, output="sos")


def _decimation(band, rate):
    """How far to decimate: to ≥ 2.5 times the top of the band 20 dB over the noise floor, ≥ 2 kHz."""
    from ._front import frame_energies

    size = 1 << int(np.ceil(np.log2(rate * 0.02)))
    if len(band) < 4 * size:
        return 1
    starts = np.linspace(0, len(band) - size, min(_SPECTRA, (len(band) - size) // (size // 2) + 1)).astype(np.int64)
    starts = starts[np.concatenate(([True], starts[1:] != starts[:-1]))]  # half-overlapping frames, or as many spread
    # over a long file (each once: the starts are sorted, the repeated ones next to each other)
    window = _hann(size)
    # each frame's energy over its spectrum's bins (Parseval's): only the quietest and the loudest tenths are transformed
    energy = frame_energies(np.ascontiguousarray(band, dtype=float), starts, window)
    frequencies = np.fft.rfftfreq(size, 1.0 / rate)

    def mean_power(which):
        frames = _frames(band, 0, len(band) - size + 1, size)[starts[which]] * window
        return np.ascontiguousarray(np.abs(np.fft.rfft(frames, axis=1).T) ** 2).mean(axis=1)

    quiet, high = np.quantile(energy, [0.1, 0.9])
    noise = mean_power(energy <= quiet)
    loud = mean_power(energy >= high)
    good = np.flatnonzero(loud > 100.0 * noise)
    top = frequencies[good[-1]] if len(good) else frequencies[-1]
    return int(max(1, min(rate // (2.5 * max(top, 1.0)), rate // 2000)))


@cache
def _hann(size):
    """``np.hanning(size)``, computed once a size (read only)."""
    window = np.hanning(size)
    window.flags.writeable = False
    return window


def _decimate(band, rate, q, corner=None):
    """``band`` low-passed (causal Butterworth, 8th order, at ``corner`` Hz: by default 0.8 of the new Nyquist) and decimated by ``q``.

    Returns the samples, their rate (Hz) and the filter's delay at low frequencies (full-rate samples).
    """
    if q == 1 and corner is None:
        return band, rate, 0.0
    from ._kernels import low_pass_every

    corner = 0.8 * rate / q / 2.0 if corner is None else min(corner, 0.8 * rate / q / 2.0)
    sos, delay = _low_pass(corner, rate)
    return low_pass_every(sos, np.ascontiguousarray(band, dtype=float), q), rate / q, delay


def _decimate_three(band, rate, q, q2, q3, rise):
    """``(_decimate(band, rate, q), _decimate(band, rate, q2), _decimate(band, rate, q3))`` and :func:`_jumps`' jump
    profile of ``rise`` (as long as ``band``; None where :func:`_jumps` is left to find it: a signal of more than one
    block, or a filter not run). The third is None where ``q`` or ``q2`` is 1 (its filter not run).

    The filters run side by side in one pass (the first two's eight sections as one vector's lanes, the third's as
    another's), and the jumps with them: the filters wait on their recursions, the jumps on divisions.
    """
    from ._front import low_pass_three, low_pass_three_and_jumps

    if q == 1 or q2 == 1:
        return _decimate(band, rate, q), _decimate(band, rate, q2), None, None
    (sos, delay), (sos2, delay2) = _low_pass(0.8 * rate / q / 2.0, rate), _low_pass(0.8 * rate / q2 / 2.0, rate)
    sos3, delay3 = _low_pass(0.8 * rate / q3 / 2.0, rate)
    band = np.ascontiguousarray(band, dtype=float)
    if len(rise) > _BLOCK:  # the jumps found block by block
        low, low2, low3, jumps = *low_pass_three(sos, q, sos2, q2, sos3, q3, band), None
    else:
        low, low2, low3, jumps = low_pass_three_and_jumps(sos, q, sos2, q2, sos3, q3, band,
                                                          np.ascontiguousarray(rise, dtype=float), _jump_width(rate))
    return (low, rate / q, delay), (low2, rate / q2, delay2), (low3, rate / q3, delay3), jumps


@cache
def _low_pass(corner, rate):
    """:func:`_decimate`'s filter (second-order sections) and its delay at low frequencies (samples), designed once a corner and rate."""
    from scipy.signal import butter, sosfreqz

    sos = butter(8, corner, fs=rate, output="sos")
    step = corner / 800.0  # the group delay at corner / 8, from the phase's slope (the sections: well conditioned)
    _, response = sosfreqz(sos, worN=[corner / 8.0 - step, corner / 8.0 + step], fs=rate)
    delay = -np.diff(np.unwrap(np.angle(response)))[0] / (2.0 * np.pi * 2.0 * step) * rate
    return sos, float(delay)


def _innovation(x, order):
    """A linear predictor of ``x`` (Burg's method; its error filter's coefficients) and what it does not predict."""
    from ._front import burg, prediction_error

    x = np.ascontiguousarray(x, dtype=float)
    order = min(order, max(1, len(x) // 8))
    a = burg(x, order)  # librosa.lpc's operations (its sums in four lanes), in one pass an order
    if not np.all(np.isfinite(a)):
        a = np.array([1.0, -1.0])
    return a, prediction_error(a, x)


def _robust_innovation(x, order):
    """A linear predictor of ``x`` fitted by least squares reweighted by the inverse local power of a first fit's innovation.

    Returns its error filter's coefficients and what it does not predict (as :func:`_innovation`).
    """
    from ._kernels import prediction_error
    from ._modes import reweighting, weighted_gram

    x = np.ascontiguousarray(x, dtype=float)
    order = min(order, max(1, len(x) // 8))
    burg, first = _innovation(x, order)
    weight = reweighting(first, 9)  # the inverse RMS over 9 samples (scipy's uniform_filter1d's sums)
    # the normal equations added up over blocks of _LAG_ROWS rows, each block's product as BLAS's: all the lagged rows of
    # a 5-s recording at once were the detector's largest block (3.3 MB at order 40)
    gram = weighted_gram(x, weight, order, _LAG_ROWS)
    try:
        c, *_ = np.linalg.lstsq(gram[1:, 1:], -gram[1:, 0], rcond=None)
        a = np.concatenate(([1.0], c))
    except np.linalg.LinAlgError:
        a = burg
    if not np.all(np.isfinite(a)):
        a = burg
    return a, prediction_error(a, x)


def _jumps(x, rate, min_interval, least, samples=12, profile=None):
    """Samples of ``x`` where its RMS over the next 1 ms rises ``least`` times over the 4 ms before: the AIC's change points
    [int, shape=(n,)].

    A long signal is taken in blocks of :data:`_BLOCK` samples (overlapping by more than the windows
    and ``min_interval``), so memory does not grow with its length. ``profile`` is the jump profile of an ``x`` of one
    block (the RMS ratio at each sample, ``samples`` = 12), when found already.
    """
    from ._front import jump_profile, peak_pick_over
    from ._kernels import change_points

    width = _jump_width(rate, samples)
    gap = max(1, round(min_interval * rate))
    margin = 6 * width + 2 * gap
    peaks = []
    for start in range(0, len(x), _BLOCK):
        low, high = max(0, start - margin), min(len(x), start + _BLOCK + margin)
        jump = profile if profile is not None else \
            jump_profile(np.ascontiguousarray(x[low:high], dtype=float), width)  # 0 over the first 4 windows
        found = peak_pick_over(jump, gap, np.nextafter(least, -np.inf))  # _peak_pick's at least ``least``
        found = found[(jump[found] >= least) & (low + found >= start) & (low + found < start + _BLOCK)]
        peaks.append(low + found)
    x = np.ascontiguousarray(x, dtype=float)
    return change_points(x, np.concatenate(peaks).astype(np.int64) if peaks else np.empty(0, dtype=np.int64), width)


def _jump_width(rate, least=12):
    """The windows of the RMS jumps (:func:`_jumps`, :func:`_windows`, :func:`_jump_at`): 1 ms, ≥ ``least`` samples."""
    return max(least, round(1e-3 * rate))


def _peak_pick(x, gap):
    """``librosa.util.peak_pick(x, pre_max=gap, post_max=gap, pre_avg=1, post_avg=1, delta=0, wait=gap)``, its sliding maximum in linear time.

    A sample is a peak when it is the largest from ``gap`` samples before it to ``gap - 1`` after, at
    least its predecessor, and more than ``gap`` samples after the last peak (greedily, in order; the
    first sample is a peak when it is the largest of the first ``gap``).
    """
    from ._front import peak_pick_over

    return peak_pick_over(np.ascontiguousarray(x, dtype=float), gap, -np.inf)


def _frames(x, start, count, size):
    """``count`` windows of ``size`` samples of ``x`` (contiguous) from ``start``, a sample apart: a view.

    What ``sliding_window_view(x[start:start + count + size - 1], size)`` gives (the same strides: numpy
    multiplies it by the same loops), without its checks' time.
    """
    return np.ndarray((count, size), dtype=x.dtype, buffer=x, offset=start * x.itemsize,
                      strides=(x.itemsize, x.itemsize))


def _windows(x, rate, least=12):
    """The mean square of ``x`` over the 1 ms (≥ ``least`` samples) from each sample, and over the 4 times that before it."""
    width = _jump_width(rate, least)
    power = np.concatenate(([0.0], np.cumsum(x * x)))
    count = len(x)  # slices, not indices: power[min(n + width, count)] and power[max(n - 4 width, 0)] for each n
    ahead = np.concatenate((power[min(width, count):], np.full(max(min(width, count) - 1, 0), power[-1])))[:count]
    behind = np.concatenate((np.zeros(min(4 * width, count)), power[:max(count - 4 * width, 0)]))
    after = (ahead - power[:count]) / width
    before = (power[:count] - behind) / (4 * width)
    return after, before, width


def _jump_at(x, positions, rate, samples=12):
    """The largest RMS jump of ``x`` (the next 1 ms over the 4 ms before) within half a window of each position."""
    from ._kernels import jump_at

    # each position's windows over the slice of x around it: from half a window and 4 windows before it
    # (a full window before, or the signal's start) to half a window and a window after
    x = np.ascontiguousarray(x, dtype=float)
    return jump_at(x, np.round(np.asarray(positions, dtype=float)).astype(np.int64), _jump_width(rate, samples),
                   _rounding_floor(x))


def _rounding_floor(x):
    """A mean power 240 dB under ``x``'s largest sample's: what is left under it is rounding, not sound.

    Far under any recording's noise (24-bit audio: −144 dB) and far over a double's rounding of it
    (about −310 dB): a note fitted and taken off to its last bits leaves no jump.
    """
    from ._kernels import largest_magnitude

    return 1e-24 * largest_magnitude(np.ascontiguousarray(x, dtype=float)) ** 2


def _merge(tonal, broadband, gap, deep=(), strong=None):
    """The onsets (samples), sorted, and how each was found (0 broadband, 1 tonal, 2 deep only).

    Onsets closer than ``gap`` are one (as are two groups' choices closer than a quarter of it), at the broadband
    time if any, else the tonal one. With ``strong`` (each tonal onset's rise [shape=(len(tonal),)], a distance
    (samples) and a rise), a group's tonal time nearest its broadband time replaces it when it is farther than
    that distance from it and rises so much (a group's choice may so fall on the next group's: its broadband time
    on that one's tonal). Compiled: :func:`._detect.merge`.
    """
    from ._detect import merge

    parts = [np.asarray(samples, dtype=float).ravel() for samples in (broadband, tonal, deep)]
    values = np.concatenate(parts)
    kinds = np.repeat(np.arange(3, dtype=np.int64), [len(part) for part in parts])
    rises, apart, least = (np.zeros(len(parts[1])), 0.0, 0.0) if strong is None else strong
    rises = np.concatenate((np.zeros(len(parts[0])), np.asarray(rises, dtype=float), np.zeros(len(parts[2]))))
    order = np.lexsort((kinds, values))  # by time, then kind
    return merge(values[order], kinds[order], rises[order], float(gap), float(apart), float(least), strong is not None)


def _away(candidates, known, gap):
    """The ``candidates`` farther than ``gap`` from their nearest neighbours in ``known`` (sorted), in order."""
    known = np.asarray(known, dtype=float)
    if not len(known):
        return list(candidates)
    at = np.asarray(candidates, dtype=float)
    near = np.searchsorted(known, at)
    before = np.abs(known[np.maximum(near - 1, 0)] - at) > gap
    after = np.abs(known[np.minimum(near, len(known) - 1)] - at) > gap
    far = (before | (near == 0)) & (after | (near == len(known)))
    return [s for s, keep in zip(candidates, far.tolist()) if keep]


@dataclass(frozen=True)
class _Signature:
    """The signature :func:`_pursue` fits: the loudest attack's innovation from ``lead`` samples before its largest
    spike, its least-squares ``basis`` (the signature and its derivative, as columns), the normal equations of its
    first rows ``grams`` (cumulated: :func:`_after_louder`'s truncated signatures'), their whole ``gram`` and ``solve`` (the least-squares weights of a window are ``solve @ window``; None when the basis is too
    ill-conditioned to fit), its start ``head`` (the spike and ``config.head`` samples) and that start's norm
    ``head_norm``, and the innovation's rounding ``floor`` (:func:`_rounding_floor`): each pursuit reads them."""

    template: np.ndarray
    basis: np.ndarray
    grams: np.ndarray
    gram: np.ndarray
    solve: np.ndarray | None
    head: np.ndarray
    lead: int
    head_norm: float
    floor: float


def _signature(e, rate, config):
    """The :class:`_Signature` of the innovation ``e`` (at ``rate`` Hz)."""
    length = max(4, round(config.signature * rate))
    peak = int(np.argmax(np.abs(e)))
    lead = min(2, peak)
    template = e[peak - lead:peak + length].copy()
    basis = np.column_stack([template, np.gradient(template)]) if len(template) > 1 else template[:, None].copy()
    gram = basis.T @ basis
    solve = None
    if np.all(np.isfinite(gram)) and np.linalg.cond(gram) <= 1e12:
        solve = np.ascontiguousarray(np.linalg.solve(gram, basis.T))
    head = template[:lead + config.head]
    return _Signature(template, basis, np.cumsum(basis[:, :, None] * basis[:, None, :], axis=0), gram, solve, head,
                      lead, float(np.sqrt(head @ head)), _rounding_floor(e))


def _pursue(e, positions, rate, config, tail=None, signature=None):
    """``e`` less each onset's signature, the onsets taken in time order; how each onset rises over what went before.

    The signature is the innovation of the loudest attack (its largest spike and the
    ``config.signature`` s after it); each onset's is fitted by least squares (the signature and its derivative: a
    fraction of a sample's shift) at the best of five alignments and taken off before the next.
    With ``tail`` (a longer response, from the signature's start: :func:`_room_tail`), its part
    past the signature is taken off too, scaled by the signature's fit. ``positions`` and ``rate``
    are in samples of ``e`` and Hz; ``signature`` is :func:`_signature`'s of ``e`` when it is known.
    Returns a :class:`_Pursuit`.
    """
    from ._kernels import pursue

    signature = _signature(e, rate, config) if signature is None else signature
    positions = np.asarray(positions, dtype=float)
    if signature.solve is None:  # no signature to fit: nothing taken off
        return _Pursuit(e.copy(), _jump_at(e, positions, rate, config.modes_width), np.ones(len(positions)),
                        positions.copy(), np.round(positions).astype(np.int64), np.zeros(len(positions)),
                        signature.template)
    r = e.copy()
    jumps, likeness, where, at, amp = pursue(
        r, positions, np.round(positions).astype(np.int64), signature.basis, signature.gram, signature.solve,
        signature.head, signature.head_norm, signature.lead, max(config.modes_width, round(1e-3 * rate)),
        np.empty(0) if tail is None else np.ascontiguousarray(tail, dtype=float), signature.floor)
    return _Pursuit(r, jumps, likeness, where, at, amp, signature.template)


def _room_tail(e, at, amp, length, ridge):
    """The attacks' common response (``length`` samples from each start), by least squares over all of them.

    ``ridge`` is added to the normal equations' diagonal, as a fraction of it.
    """
    from scipy.linalg import solve_toeplitz

    from ._kernels import impulse_correlations
    from ._modes import levinson

    keep = amp != 0.0
    at, amp = at[keep], amp[keep]
    if len(at) == 0:
        return None
    # the attacks as impulses, correlated with themselves and with e over the tail's lags: sums over the few impulses
    # (tens, against FFTs of the whole band's length)
    r_ss, r_se = impulse_correlations(np.ascontiguousarray(e, dtype=float), np.ascontiguousarray(at, dtype=np.int64),
                                      np.ascontiguousarray(amp, dtype=float), length)
    r_ss[0] *= 1.0 + ridge
    h, solved = levinson(r_ss, r_se)  # scipy's solve_toeplitz without its checks' time
    if not solved or not (np.all(np.isfinite(r_ss)) and np.all(np.isfinite(r_se))):
        h = solve_toeplitz(r_ss, r_se)  # scipy's errors
    return h if np.all(np.isfinite(h)) else None


def _retime(times, kinds, fitted, likeness, precise):
    """Onsets found only in the modes' band timed by their signature's fit, against the others' times.

    ``fitted`` (full-rate samples) is where each signature fits; its offset from the precise
    times (broadband or tonal onsets whose start looks like the signature, likeness ≥ ``precise``) is
    their median difference, added to the fitted time of each onset found only in the modes' band. Returns
    the times and that offset (0 when there is no precise onset or none to retime).
    """
    sure = (kinds < 2) & (likeness >= precise)
    if not np.any(sure) or not np.any(kinds == 2):
        return times, 0.0
    offset = float(np.median(times[sure] - fitted[sure]))
    out = times.copy()
    out[kinds == 2] = fitted[kinds == 2] + offset
    order = np.argsort(out, kind="stable")
    return (out[order] if np.all(np.diff(out[order]) > 0) else times), offset


def _level_corner(band, rate, onsets, config):
    """The top (Hz) of the band levels are measured in: ``config.level_ratio`` times its lowest strong mode, ≥
    ``config.level_band`` Hz.

    The lowest strong mode is the lowest frequency within 20 dB of the strongest in the 50 ms
    after the loudest of ``onsets`` (full-rate samples; the signal's largest sample if none).
    """
    from ._kernels import window_peaks

    if len(onsets):
        starts = np.clip(np.round(onsets).astype(np.int64), 0, len(band) - 1)
        peaks = window_peaks(band, starts, starts + max(1, round(5e-3 * rate)))
        start = int(starts[int(np.argmax(peaks))])
    else:
        start = int(np.argmax(np.abs(band)))
    size = 1 << int(np.ceil(np.log2(rate * 0.05)))
    segment = band[start:start + size]
    if len(segment) < size // 4:
        return config.level_band
    power = np.abs(np.fft.rfft(segment * _hann(len(segment)), size)) ** 2
    frequencies = np.fft.rfftfreq(size, 1.0 / rate)
    strong = np.flatnonzero((power >= 0.01 * power.max()) & (frequencies >= config.high_pass))
    lowest = frequencies[strong[0]] if len(strong) else 190.0
    return float(max(config.level_band, config.level_ratio * lowest))


def _attack_amplitudes(low, coefficients, positions, rate, *, tail=0, sure=None, ridge=0.01, e=None):
    """Each attack's own peak (full scale): the signal less the earlier sound predicted on past the onset.

    The earlier sound (the drum's and the room's ringing) is extrapolated past the onset from the
    samples before it by the linear predictor; what remains is the new attack's sound, whose
    peak over the next 5 ms (or up to the next onset), between samples, is its amplitude. With
    ``tail`` (samples), the earlier onsets' room tails are taken off too: the innovation's common
    response to the onsets over ``tail`` samples (:func:`_room_tail`, each onset scaled by its first
    amplitude) is what the predictor cannot foresee of the earlier sound; an onset's own sound is
    then the predictor's response to its innovation less the tails (past the 5 ms) of the earlier
    onsets. ``sure`` (booleans, one per onset): the onsets so measured and whose tails are taken off;
    ``ridge``: the tail's fit's (:func:`_room_tail`); ``e``: ``low``'s prediction error by ``coefficients``, where known.
    """
    from ._kernels import prediction_error, residual_peaks, tail_free_peaks

    horizon = max(2, round(5e-3 * rate))
    interpolator = _interpolator()
    starts = np.clip(np.round(positions).astype(np.int64), 0, len(low))
    stops = np.minimum(np.minimum(starts + horizon, len(low)), np.append(starts[1:], len(low)))
    amplitude = residual_peaks(np.ascontiguousarray(low, dtype=float), np.ascontiguousarray(coefficients, dtype=float),
                               starts, stops, interpolator)
    inside = starts < len(low)
    if tail <= 0 or not np.any(inside):
        return amplitude
    if e is None:
        e = prediction_error(np.ascontiguousarray(coefficients, dtype=float), np.ascontiguousarray(low, dtype=float))
    h = _room_tail(e, starts[inside], amplitude[inside], tail, ridge)
    if h is None:
        return amplitude
    sure = np.ones(len(starts), dtype=bool) if sure is None else np.asarray(sure, dtype=bool)
    return tail_free_peaks(e, np.ascontiguousarray(coefficients, dtype=float), starts, stops, sure, amplitude,
                           np.ascontiguousarray(h, dtype=float), horizon, interpolator)


@cache
def _interpolator():
    """A 4-times upsampling low-pass FIR, as scipy's ``resample_poly(x, 4, 1)`` designs it."""
    from scipy.signal import firwin

    return 4.0 * firwin(81, 0.25, window=("kaiser", 5.0))


def _noise_floor(x, rate, quantile):
    """The ``quantile`` of the peaks of ``x`` over 5-ms frames (full scale)."""
    from ._kernels import frame_peaks

    frame = max(1, round(5e-3 * rate))
    count = len(x) // frame
    if count < 1:
        return 0.0
    return float(np.quantile(frame_peaks(np.ascontiguousarray(x, dtype=float), frame, count), quantile))
