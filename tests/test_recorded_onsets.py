"""Onsets on recorded drums: General MIDI SoundFonts' snares through FluidSynth, against each note's own start.

The corpus is tests/_recorded_drums.py's (seeded); the figures asserted are those reached (docs/analysis.md
has the whole corpus's table, benchmarks/recorded_onsets.py makes it).
"""


import numpy as np
import pytest

from _recorded_drums import LOUD_DB, RATE, first_above, match, note_block, recordings, render_alone, score
from _recordings import sample_player
from drumstroke.analysis import OnsetConfig, find_onsets

# the template search's own-burst, earlier-start, fitted-attack and bounce rules off (found_burst_db, earlier_reach,
# found_decay_db, bounce_likeness, bounce_ratio_low, found_echo_rise_db, and the quiet layer's own bounce search,
# layer_bounce_likeness): a control that measures a stage before them (those rules do part of its work since)
_BEFORE_FOUND = {"found_burst_db": -120.0, "earlier_reach": 0.0, "found_decay_db": -32.0, "bounce_likeness": 0.8,
                 "bounce_ratio_low": 0.35, "found_echo_rise_db": -3.5, "layer_bounce_likeness": 1.0,
                 # the ghost notes' rules under white noise (tests/test_recorded_noise_ghosts.py), after these
                 "ghost_rise_gap": 0.0, "ghost_noise_start": 0.0,
                 # and the ghost searches' span and rise over white noise (tests/test_recorded_ghost_span.py,
                 # tests/test_recorded_white_rise.py), after these too
                 "ghost_span": 0.13, "ghost_white_rise_db": 120.0}

# a room's echoes not refused (room_decay_db): a control that measures a rule before it in a recording step 4 finds
# reverberant (that rule does part of its work since)
_WITH_ECHOES = {"room_decay_db": -120.0}

# the earlier notes' own sound not refused (layer_echo_db): a control that measures a rule before it (that rule does
# part of its work since: the swells and returns it refuses are those the rules before it were measured on)
_WITH_OWN_SOUND = {"layer_echo_db": -120.0}

# FluidSynth and both SoundFonts are needed (scripts/install-system-packages.sh installs them): without them
# these tests fail with render_soundfont's error, they never skip


@pytest.fixture(scope="module")
def detected():
    """Key 38 of both SoundFonts, three sets, dry and with -60 dBFS noise: (recording, onsets)."""
    return [(r, find_onsets(r.signal, RATE)) for r in recordings(keys=(38,), sets=("singles", "roll", "flams"),
                                                                   conditions=("dry", "noise60"))]


def test_the_truth_is_each_note_rendered_alone():
    """The block FluidSynth starts a note at and the cached lead-in give its first sample above -40 dB alone."""
    from _recorded_drums import Leads

    leads = Leads()
    rng = np.random.default_rng(5)
    for font, key, velocity, t in [("TimGM6mb", 38, 100, 0.25), ("TimGM6mb", 40, 41, 1.3),
                                   ("FluidR3", 38, int(rng.integers(30, 128)), float(rng.uniform(0.05, 3.0))),
                                   ("FluidR3", 40, 127, float(rng.uniform(0.05, 3.0)))]:
        lead, peak = leads(font, key, velocity)
        alone = render_alone(font, key, velocity, t)
        assert first_above(alone) == note_block(t) + lead
        assert np.abs(alone).max() == pytest.approx(peak, rel=1e-6)
    # the start depends on the time, not only on it modulo a block or a millisecond
    assert note_block(0.1) - round(0.1 * RATE) != note_block(0.1003) - round(0.1003 * RATE)


def _pooled(detected, set_name, condition):
    total = {"loud": 0, "within_1ms": 0, "within_5ms": 0, "found": 0, "correct_5ms": 0}
    for recording, onsets in detected:
        if (recording.set, recording.condition) == (set_name, condition):
            for name, value in score(recording, onsets.t).items():
                total[name] += value
    return total["within_1ms"] / total["loud"], total["within_5ms"] / total["loud"], total["correct_5ms"] / total["found"]


@pytest.mark.parametrize("set_name, condition, least", [
    ("singles", "dry", (1.0, 1.0, 1.0)), ("singles", "noise60", (1.0, 1.0, 0.9)),
    ("flams", "dry", (1.0, 1.0, 0.85)), ("flams", "noise60", (0.95, 1.0, 0.85)),
    ("roll", "dry", (0.55, 0.75, 0.95)), ("roll", "noise60", (0.55, 0.7, 0.95)),
])
def test_loud_notes_are_found_at_their_first_transient(detected, set_name, condition, least):
    """Notes within 30 dB of the loudest: found within 1 ms, within 5 ms, and the detections' precision (5 ms).

    The figures reached (both SoundFonts' snare 38 pooled), a little under: the issue's targets (0.95, 0.99, 0.95)
    are not all reached yet (docs/analysis.md says where).
    """
    within_1ms, within_5ms, precision = _pooled(detected, set_name, condition)
    assert within_1ms >= least[0] and within_5ms >= least[1] and precision >= least[2]


def test_a_note_out_of_digital_silence_starts_at_its_first_transient_not_its_lead_in():
    """FluidR3's snare after digital silence: within 0.1 ms of its truth, where its faint lead-in is 2 ms earlier."""
    recording = next(recordings(fonts=("FluidR3",), keys=(38,), sets=("singles",), conditions=("dry",)))
    onsets = find_onsets(recording.signal, RATE)
    assert len(onsets) == len(recording.t)
    assert np.abs(onsets.t - recording.t).max() < 0.1e-3
    assert onsets.info["floor_db"] is None  # no "-1878 dB" floor from the filters' decay over digital silence
    late = find_onsets(recording.signal, RATE, config=OnsetConfig(start_reach=0.0))  # without the first transients
    assert np.abs(late.t[0] - recording.t[0]) > 1e-3


def _corpus_recording(name, condition):
    """The benchmark's recording ``name`` (font key set) in ``condition``, with the corpus's seeds."""
    return next(r for r in recordings(sets=("singles", "drop", "roll"), conditions=(condition,))
                if f"{r.font} {r.key} {r.set}" == name)


def test_swells_in_a_reverberant_tail_are_not_attacks():
    """FluidR3's snare with FluidSynth's reverb: the quiet swells of its tail that do not rise out of it are refused."""
    recording = _corpus_recording("FluidR3 38 singles", "reverb")
    kept = score(recording, find_onsets(recording.signal, RATE).t)
    every = score(recording, find_onsets(recording.signal, RATE, config=OnsetConfig(decay_db=-120.0)).t)
    assert kept["within_1ms"] == kept["loud"] == every["within_1ms"]
    assert kept["found"] - kept["correct_5ms"] < every["found"] - every["correct_5ms"]
    assert kept["correct_5ms"] / kept["found"] >= 0.75


@pytest.mark.parametrize("condition, least_precision, found_1ms, found_5ms", [
    ("dry", 0.95, 18, 25), ("reverb", 0.88, 16, 25),
])
def test_a_samples_second_burst_is_not_a_note(condition, least_precision, found_1ms, found_5ms):
    """FluidR3's electric snare (key 40) bursts again 4-6 ms into its sample, in its lowest modes as loud as its
    note: in a roll (dry, and with FluidSynth's reverb) those bursts after the ghost notes are refused, as
    attacks that do not rise out of the note just before them; no loud note found is lost.

    Precision within 5 ms: 0.781 dry, 0.758 with reverb before (6 and 5 such bursts taken for notes), 0.962 and
    0.893 now; the loud notes found within 1 and 5 ms (18 and 25 dry, 16 and 25 with reverb of 29) as before. The
    control (``echo_reach=0``) has ``_BEFORE_FOUND``'s rules off too: the template search's own-burst rule drops
    most of those bursts since; and the earlier notes' own sound kept (``_WITH_OWN_SOUND``), which drops some.
    """
    recording = _corpus_recording("FluidR3 40 roll", condition)
    kept = score(recording, find_onsets(recording.signal, RATE).t)
    control = OnsetConfig(echo_reach=0.0, **_BEFORE_FOUND, **_WITH_OWN_SOUND)
    every = score(recording, find_onsets(recording.signal, RATE, config=control).t)
    assert kept["correct_5ms"] / kept["found"] >= least_precision
    assert kept["within_1ms"] >= found_1ms and kept["within_5ms"] >= found_5ms
    assert every["found"] - every["correct_5ms"] >= kept["found"] - kept["correct_5ms"] + 4


def test_a_roll_over_its_own_ringing_is_timed_by_the_learned_lead_in():
    """TimGM6mb's snare 40 in a roll: notes over the ringing (their click hidden, ~1.3 ms before the main rise) within 1 ms."""
    recording = _corpus_recording("TimGM6mb 40 roll", "dry")
    figures = score(recording, find_onsets(recording.signal, RATE).t)
    assert figures["within_1ms"] / figures["loud"] >= 0.85  # 0.50 (14 of 28) before: placed on the main rise


@pytest.mark.parametrize("set_name, condition, most_95, most_median", [
    ("singles", "dry", 4.5, 0.5), ("singles", "noise60", 2.5, 0.5), ("roll", "dry", 4.5, 1.0),
    ("roll", "noise60", 3.5, 1.0), ("flams", "dry", 25.0, 1.0), ("flams", "noise60", 25.0, 1.5),
])
def test_levels_of_loud_notes_found(detected, set_name, condition, most_95, most_median):
    """The level error (dB re the loudest onset, less the truth: each note's own peak alone re the loudest's) of the
    loud notes found within 5 ms: its 95th percentile and median (absolute), the figures reached a little over.

    Measured (both SoundFonts' snare 38 pooled): 95th percentile 3.9, 1.9, 3.4, 2.9, 22.5, 22.9 dB; median
    0.11-0.98 dB. The rolls dry 4.2 dB since the ghost notes under an accent are sought in what is left once the
    accent's layer-mate is taken off (``ghost_rise_db``): a ghost note more (TimGM6mb, 1.0113 s, -23 dB) whose lowest
    modes read 4.5 dB off under the accent's tail (3.6 dB without it). The issue's 1 dB is not reached: the levels are the lowest modes' amplitude (in proportion to the
    tip speed on drumstroke's drums), not the broadband peak (docs/analysis.md says how far apart the two are).
    """
    errors = [onsets.level_db[j] - recording.level_db[i] for recording, onsets in detected
              if (recording.set, recording.condition) == (set_name, condition)
              for i, j in match(recording.t, onsets.t, 5e-3) if recording.level_db[i] >= -LOUD_DB]
    errors = np.abs(errors)
    assert np.quantile(errors, 0.95) <= most_95 and np.median(errors) <= most_median
@pytest.mark.parametrize("name, condition, least_1ms, least_precision, off_1ms", [
    ("TimGM6mb 38 drop", "dry", 0.93, 0.92, 41),  # 52 of 55 loud notes within 1 ms, precision 0.93 (41 and 0.91 without)
    # without the stage, 30 and 14 before the quiet attacks just before a louder one and those without a sound of
    # their own were refused (_one_attack_each, _new_sound): those took the notes' matches from the right times
    ("FluidR3 38 drop", "dry", 0.65, 0.85, 38),  # 40 of 56, 0.96 (38 without)
    ("FluidR3 38 roll", "noise60", 0.8, 0.95, 19),  # 24 of 29, 0.96 (19 without)
])
def test_attacks_over_ringing_are_timed_and_found_by_the_recordings_own_attack(name, condition, least_1ms,
                                                                               least_precision, off_1ms):
    """A drop's fast bounces and a roll's ghost notes over the ringing: within 1 ms by fitting the clearest attack.

    Without the stage (``template_likeness=1``: no fit passes; and ``_BEFORE_FOUND``'s rules) the notes within 1 ms are as few as measured before
    it (the stage's gain is asserted, not only a floor).
    """
    recording = _corpus_recording(name, condition)
    figures = score(recording, find_onsets(recording.signal, RATE).t)
    assert figures["within_1ms"] / figures["loud"] >= least_1ms
    assert figures["correct_5ms"] / figures["found"] >= least_precision
    off = score(recording, find_onsets(recording.signal, RATE,
                                       config=OnsetConfig(template_likeness=1.0, **_BEFORE_FOUND)).t)
    assert off["within_1ms"] <= off_1ms < figures["within_1ms"]


@pytest.mark.parametrize("set_name, condition, most_95, most_median", [
    ("singles", "dry", 0.1, 0.05), ("singles", "noise60", 0.5, 0.1), ("roll", "dry", 0.8, 0.1),
    ("roll", "noise60", 1.7, 0.2), ("flams", "dry", 0.6, 0.6), ("flams", "noise60", 1.0, 0.3),
])
def test_peaks_of_loud_notes_found(detected, set_name, condition, most_95, most_median):
    """peak_db (each onset's broadband peak, the earlier notes' sound taken off, dB re the loudest onset's) less the
    truth (each note's own peak alone, dB re the loudest's), on the loud notes found within 5 ms: its 95th
    percentile and median (absolute), the figures reached a little over.

    Measured (both SoundFonts' snare 38 pooled): 95th percentile 0.01, 0.21, 4.85, 2.63, 1.28, 0.83 dB (rolls at
    -60 dBFS: 2.18 over 49 notes before the softer strokes' attacks were found, 2.63 over 54 after: the 5 ghost notes
    gained read 2.0-2.9 dB high, the accent's sound not all taken off them; 2.81 over 56 once the template's second
    opinion on refused onsets found two more ghost notes, one of FluidR3's reading 6.0 dB high); median
    0.00-0.48 dB (level_db, the lowest modes' amplitude: 1.9-22.9 dB at the 95th percentile). The issue's 1 dB is
    reached on singles and flams with noise; in rolls a ghost note 100 ms after an accent is 2-26 dB off where a
    template holds a ghost note the detector missed (taken off the later ghost at the same distance), and
    flams' main notes 1-1.6 dB where the grace note is of another velocity layer than the templates
    (docs/analysis.md). Since each velocity layer's template is the median of its clear notes' waveforms, followed
    past the quieter onsets (a ghost note in one of them outvoted), and the quieter layer's second opinion finds more
    ghost notes (``layer_likeness=0.8``): 0.01, 0.21, 0.60, 1.49, 0.49, 0.83 dB; median 0.00-0.29 dB (with the
    templates cut at the next onset, that pass's one ghost note more in the rolls at -60 dBFS cut the one long
    template and read the others' up to 4 dB off: 4.84 dB).
    """
    errors = [onsets.peak_db[j] - recording.level_db[i] for recording, onsets in detected
              if (recording.set, recording.condition) == (set_name, condition)
              for i, j in match(recording.t, onsets.t, 5e-3) if recording.level_db[i] >= -LOUD_DB]
    errors = np.abs(errors)
    assert np.quantile(errors, 0.95) <= most_95 and np.median(errors) <= most_median


@pytest.mark.parametrize("condition", ["dry", "noise60"])
def test_swells_of_a_samples_decay_without_a_spike_are_not_attacks(condition):
    """FluidR3's snare in a drop: the swells of a sample's decay, 30 ms or more after the detection before them and
    no note, are refused where the modes' band's innovation does not spike (a stick's impact is a burst there).

    Before (``spike_db=-60``: every attack spikes enough), 5 such false detections in each recording; now at most
    1, and the loud notes found within 1 and 5 ms (40 and 42 of 56) are as before. The control has a room's echoes
    kept too (``_WITH_ECHOES``: step 4 finds these recordings reverberant, and that rule refuses most such swells),
    and the earlier notes' own sound (``_WITH_OWN_SOUND``, which refuses some).
    """
    recording = _corpus_recording("FluidR3 38 drop", condition)
    for config, most in ((OnsetConfig(), 1), (OnsetConfig(spike_db=-60.0, **_WITH_ECHOES, **_WITH_OWN_SOUND), None)):
        onsets = find_onsets(recording.signal, RATE, config=config)
        figures = score(recording, onsets.t)
        correct = np.zeros(len(onsets), dtype=bool)
        correct[[j for _, j in match(recording.t, onsets.t, 5e-3)]] = True
        swells = np.count_nonzero(~correct & (np.diff(onsets.t, prepend=-1.0) >= 0.03))
        assert figures["within_1ms"] >= 40 and figures["within_5ms"] >= 42
        if most is None:
            assert swells >= 4  # the swells are there without the spike asked
        else:
            assert swells <= most


@pytest.mark.parametrize("name, condition, extras", [
    ("TimGM6mb 38 drop", "dry", 2), ("TimGM6mb 38 drop", "noise60", 3), ("TimGM6mb 40 drop", "dry", 2),
])
def test_an_attack_without_a_sound_of_its_own_is_none(name, condition, extras):
    """TimGM6mb's snare in a drop: the swells of a sample's decay 10-80 ms after a bounce, whose own sound (the earlier
    notes' fitted by the recording's clear notes and taken off) stands 20 dB or more under the sound there, are
    refused; every detection left is a note within 5 ms, and the loud notes found within 1 and 5 ms are as before.

    Without the rule (``new_sound_db=-120``; and ``_BEFORE_FOUND``'s rules, which drop one of them) those ``extras``
    false detections stay (measured: 2, 3 and 2), and the loud notes found are those found with the rule (both with
    ``_BEFORE_FOUND``'s rules off); those rules lose none either. The control keeps a room's echoes too
    (``_WITH_ECHOES``: step 4 finds TimGM6mb's snare 40 drop reverberant, and that rule refuses one of them), and the
    earlier notes' own sound (``_WITH_OWN_SOUND``, which refuses some).
    """
    recording = _corpus_recording(name, condition)
    kept = score(recording, find_onsets(recording.signal, RATE).t)
    before = score(recording, find_onsets(recording.signal, RATE, config=OnsetConfig(**_BEFORE_FOUND)).t)
    every = score(recording, find_onsets(recording.signal, RATE,
                                         config=OnsetConfig(new_sound_db=-120.0, **_BEFORE_FOUND, **_WITH_ECHOES,
                                                                            **_WITH_OWN_SOUND)).t)
    assert kept["correct_5ms"] == kept["found"]
    assert every["found"] - every["correct_5ms"] >= extras
    assert (before["within_1ms"], before["within_5ms"]) == (every["within_1ms"], every["within_5ms"])
    assert kept["within_1ms"] >= before["within_1ms"] and kept["within_5ms"] >= before["within_5ms"]


def test_a_quiet_attack_just_before_a_much_louder_one_is_none():
    """TimGM6mb's snare 38 in a roll with -72 dBFS noise: a point of the earlier sound 2 ms before an accent, 30 dB
    under it in the lowest modes and in its first difference, is no stroke of its own; the accent stays at its time.

    With ``lead_db=120`` (no attack is taken for a louder one's first transient or refused before it), 3 such false
    detections; none now, and the loud notes found within 1 and 5 ms are as many.
    """
    recording = _corpus_recording("TimGM6mb 38 roll", "noise72")
    kept = score(recording, find_onsets(recording.signal, RATE).t)
    every = score(recording, find_onsets(recording.signal, RATE, config=OnsetConfig(lead_db=120.0)).t)
    assert kept["correct_5ms"] == kept["found"] and every["found"] - every["correct_5ms"] >= 3
    assert (kept["within_1ms"], kept["within_5ms"]) == (every["within_1ms"], every["within_5ms"])


def test_a_first_click_out_of_silence_is_the_note_even_where_its_sound_dips_after_it():
    """TimGM6mb's singles (snares 38 and 40, dry): every note within 1 ms of its truth, at its first click.

    Its electric snare (key 40) clicks out of digital silence, dips 20 dB, and rises 1.1 ms later: the click was
    refused as no attack of its own before (a swell before a louder one), the note put on the main rise (8 of the
    12 notes within 1 ms, all 12 within 5 ms); nothing sounds before the click, so it is the note's first transient.
    """
    for key in (38, 40):
        recording = _corpus_recording(f"TimGM6mb {key} singles", "dry")
        onsets = find_onsets(recording.signal, RATE)
        assert len(onsets) == len(recording.t)
        assert np.abs(onsets.t - recording.t).max() < 1e-3


def test_a_softer_strokes_attack_is_its_signature_smoothed_by_a_longer_contact():
    """The signature smoothed by a half-sine contact, placed in silence, is found alike (correlation 1) by the soft
    likeness at each contact up to ``soft_contact``, while the signature alone (``soft_contact=0``) likens it less."""
    from drumstroke.analysis.onsets import _soft_heads, _soft_likeness

    rng = np.random.default_rng(3)
    rate = 2000.0
    template = rng.standard_normal(100) * np.exp(-np.arange(100) / 10.0)
    template[2] = 6.0  # the spike, two samples in (as the modes' band's signature is cut)
    for width in (2, 4, 6):
        pulse = np.sin(np.pi * (np.arange(width) + 0.5) / width)
        e = np.zeros(400)
        e[148:148 + 100 + width - 1] = np.convolve(template, pulse / pulse.sum())  # its onset at sample 150
        assert _soft_likeness(e, _soft_heads(template, rate, OnsetConfig()), 150) == pytest.approx(1.0, abs=1e-9)
        assert _soft_likeness(e, _soft_heads(template, rate, OnsetConfig(soft_contact=0.0)), 150) < 0.95


def test_ghost_notes_of_a_softer_sample_are_found():
    """TimGM6mb's snare 38 in a roll at -72 dBFS noise: its ghost notes (low-passed by the SoundFont's velocity filter)
    start unlike the accent's signature; 25 of the 30 loud notes within 1 ms, all the detections right, where
    without the softer strokes' likeness (``soft_jump=100``) 23 (and without the template's second opinion on the
    onsets refused, ``refused_likeness=1``, nor its second pass with the quietest clear attack, ``layer_likeness=1``,
    which find them too; nor the ghost searches' later span and rise over white noise, ``ghost_span=0.13``,
    ``ghost_white_rise_db=120``)."""
    recording = _corpus_recording("TimGM6mb 38 roll", "noise72")
    figures = score(recording, find_onsets(recording.signal, RATE).t)
    off = score(recording, find_onsets(recording.signal, RATE,
                                       config=OnsetConfig(soft_jump=100.0, refused_likeness=1.0,
                                                          layer_likeness=1.0, ghost_rise_db=120.0, ghost_span=0.13,
                                                          ghost_white_rise_db=120.0)).t)
    assert figures["within_1ms"] >= 25 and figures["correct_5ms"] == figures["found"]
    assert off["within_1ms"] <= 23


def test_a_detection_just_after_an_attack_only_the_template_found_is_that_attack():
    """TimGM6mb's snare 38 in a roll with FluidSynth's reverb: the template finds the note at 1.317 s over the
    ringing, and the detection 2.8 ms after it is the same attack's late time (not a second attack that would
    take the note's place): the note is found within 1 ms."""
    recording = _corpus_recording("TimGM6mb 38 roll", "reverb")
    onsets = find_onsets(recording.signal, RATE)
    note = recording.t[np.argmin(np.abs(recording.t - 1.3166))]
    assert np.min(np.abs(onsets.t - note)) <= 1e-3


def test_a_flams_grace_note_is_measured_at_its_fit_not_at_an_earlier_detection():
    """FluidR3's snare 38 in flams at -72 dBFS noise: the grace note at 1.550 s (-25.6 dB re the loudest note) was
    detected 2.1 ms early, on the noise, and the template put it at its start. Measured at that early detection its
    lowest modes, not yet rising, read -41 dB, under the threshold; measured at the fit it is found within 1 ms, its
    level within 5 dB of its own peak (level_db's 95th-percentile error on flams is 5-7 dB)."""
    recording = next(r for r in recordings(fonts=("FluidR3",), keys=(38,), conditions=("noise72",))
                     if r.set == "flams")
    onsets = find_onsets(recording.signal, RATE)
    note = np.argmin(np.abs(recording.t - 1.5501))
    found = np.argmin(np.abs(onsets.t - recording.t[note]))
    assert abs(onsets.t[found] - recording.t[note]) <= 1e-3
    assert abs(onsets.level_db[found] - recording.level_db[note]) <= 5.0


@pytest.mark.parametrize("condition", ["dry", "noise72"])
def test_a_level_is_measured_again_where_its_window_was_cut_at_a_refused_detection(condition):
    """TimGM6mb's singles (both snares): a detection `_out_of_decay` refuses just after a note had cut that note's
    level window (snare 40 dry: -1.96 dB off, the others re it -1.09; snare 38 at -72 dBFS: 1.68); measured again
    without it, every loud note's ``level_db`` is within 1 dB of its own peak re the loudest (0.84 at most)."""
    for recording in recordings(fonts=("FluidR3", "TimGM6mb"), sets=("singles",), conditions=(condition,)):
        if recording.font != "TimGM6mb":
            continue
        onsets = find_onsets(recording.signal, RATE)
        loud = recording.level_db >= -LOUD_DB
        errors = [onsets.level_db[j] - recording.level_db[i] for i, j in match(recording.t, onsets.t, 1e-3) if loud[i]]
        assert len(errors) == loud.sum()
        assert np.max(np.abs(errors)) <= 1.0


@pytest.mark.parametrize("name, condition, least_1ms, off_1ms, reach", [
    ("FluidR3 38 drop", "noise72", 46, 40, 3e-3),  # each drop's bounces 12-17 ms apart, -16 to -20 dB
    ("TimGM6mb 38 drop", "noise72", 55, 49, 2.5e-3),  # every loud note (the last bounces 5-10 ms apart)
])
def test_a_drops_close_bounces_are_found_by_the_templates_whole_fit(name, condition, least_1ms, off_1ms, reach):
    """A dropped stick's last bounces start under the one before still at its loudest: what is left of it does not
    rise, but the recording's own attack fits there (its start and its first 10 ms), with no false detection more;
    without the search (``bounce_reach=0``) as few notes within 1 ms as measured before it. (TimGM6mb's are found by
    the template's fit alone once it reaches 3 ms, ``template_reach``'s default: its search is shown at 2.5 ms.)"""
    recording = _corpus_recording(name, condition)
    figures = score(recording, find_onsets(recording.signal, RATE, config=OnsetConfig(template_reach=reach)).t)
    off = score(recording, find_onsets(recording.signal, RATE,
                                       config=OnsetConfig(bounce_reach=0.0, template_reach=reach)).t)
    assert figures["within_1ms"] >= least_1ms and off["within_1ms"] <= off_1ms
    assert figures["found"] - figures["correct_5ms"] <= off["found"] - off["correct_5ms"]


@pytest.mark.parametrize("condition, least_1ms, off_1ms", [("dry", 27, 25), ("noise72", 28, 25)])
def test_ghost_notes_step_4_refused_are_attacks_where_the_template_fits(condition, least_1ms, off_1ms):
    """TimGM6mb's snare 38 in a roll: ghost notes 56-120 ms after an accent that step 4 refused (their signature in
    the modes' band unlike the accent's) are found where the recording's own attack fits them at full rate, with no
    false detection more; without that second opinion (``refused_likeness=1``, and its second pass with the quietest
    clear attack, ``layer_likeness=1``, which finds some of them too; and ``_BEFORE_FOUND``'s rules) as few as
    measured before it."""
    recording = _corpus_recording("TimGM6mb 38 roll", condition)
    figures = score(recording, find_onsets(recording.signal, RATE).t)
    off = score(recording, find_onsets(recording.signal, RATE,
                                       config=OnsetConfig(refused_likeness=1.0, layer_likeness=1.0,
                                                          ghost_rise_db=120.0, **_BEFORE_FOUND)).t)
    assert figures["within_1ms"] >= least_1ms and off["within_1ms"] <= off_1ms
    assert figures["found"] - figures["correct_5ms"] <= off["found"] - off["correct_5ms"]


def test_a_rooms_reflection_planted_after_every_note_is_no_onset():
    """FluidR3's snare 38 in singles (dry) with a reflection planted: the recording again 150 ms later, 24 dB quieter.
    Without the test of repeated delays (``reflection_pairs=0``) three or more reflections are onsets, at their
    place (within 0.5 ms of a note's truth plus 150 ms); with it none is, and every loud note found within 1 ms
    without the test is still so found."""
    recording = _corpus_recording("FluidR3 38 singles", "dry")
    delay = round(0.15 * RATE)
    signal = recording.signal.copy()
    signal[delay:] += 10.0 ** (-24.0 / 20.0) * recording.signal[:-delay]
    reflections = recording.t + delay / RATE
    kept = find_onsets(signal, RATE)
    every = find_onsets(signal, RATE, config=OnsetConfig(reflection_pairs=0))
    assert len(match(reflections, every.t, 0.5e-3)) >= 3
    assert not match(reflections, kept.t, 5e-3)
    assert score(recording, kept.t)["within_1ms"] == score(recording, every.t)["within_1ms"] >= 5


def test_only_successive_onsets_at_one_delay_make_reflections():
    """The reflection rule on given onsets: three successive pairs 83.5 ms apart (within 0.2 ms), each later 12 dB or
    more quieter, lose their later ones, exactly; two such pairs, or pairs with an onset between (a drop's sums of
    intervals), or a later one only 11 dB quieter, keep every onset."""
    from drumstroke.analysis.onsets import Onsets, _without_reflections

    config = OnsetConfig()
    t = np.array([0.1, 0.1835, 0.5, 0.58355, 1.0, 1.08345, 1.5])
    level = np.array([0.0, -15.0, -3.0, -20.0, -6.0, -18.0, -1.0])
    left = _without_reflections(Onsets(t, level), config)
    np.testing.assert_array_equal(left.t, t[[0, 2, 4, 6]])
    np.testing.assert_array_equal(left.level_db, level[[0, 2, 4, 6]])
    for t_, level_ in ((t[:4], level[:4]), (t, np.where(np.arange(7) == 5, -6.0 - 11.0, level)),
                       (np.array([0.1, 0.15, 0.1835, 0.5, 0.55, 0.5835, 1.0, 1.05, 1.0835]),
                        np.array([0.0, -9.0, -15.0, -1.0, -9.0, -15.0, -2.0, -9.0, -15.0]))):
        onsets = Onsets(t_, level_)
        assert len(_without_reflections(onsets, config)) == len(onsets)


def test_an_electric_snares_second_burst_is_the_attack_the_template_timed():
    """FluidR3's snare 40 in a drop (dry): its sample bursts again 3.4 ms in. At the bounces of 1.8764 and 1.8924 s the
    template times the attack at its start, and a detection on the second burst that the template's fit takes off
    is that attack again: each bounce within 1 ms of its truth, and no onset 2.5-4.5 ms after the first (after the
    second, one at 1.8958 s stays). Without that
    (``burst_db=-120``, and ``_BEFORE_FOUND``'s rules, which find the start too) the second burst cut each attack's level window, the attack was refused and the burst kept
    (each onset 3.4 ms late)."""
    recording = _corpus_recording("FluidR3 40 drop", "dry")
    notes = recording.t[[np.argmin(np.abs(recording.t - t)) for t in (1.8764, 1.8924)]]
    kept = find_onsets(recording.signal, RATE).t
    late = find_onsets(recording.signal, RATE, config=OnsetConfig(burst_db=-120.0, **_BEFORE_FOUND)).t
    for t in notes:
        assert np.min(np.abs(kept - t)) <= 1e-3
        assert np.min(np.abs(late - t)) > 1e-3 and np.any((late > t + 3e-3) & (late < t + 4e-3))
    assert not np.any((kept > notes[0] + 2.5e-3) & (kept < notes[0] + 4.5e-3))


def test_a_ghost_note_of_another_velocity_layer_is_found_by_the_quietest_clear_attack():
    """TimGM6mb's snare 38 in a roll (at -72 dBFS noise): the ghost note at 3.1713 s (56 ms after an accent, -20 dB)
    that step 4 refused and the loudest clear attack does not fit is found where the quietest clear attack fits it
    (``layer_likeness=0.8``, the default), within 1 ms of its truth, with no false detection more; without that pass
    (``layer_likeness=1``) there is no onset within 5 ms of it. (The dry roll's ghost note at 2.5019 s, this test's
    note before, is found without it too, since the search takes each attack off by its own layer's template.)"""
    recording = _corpus_recording("TimGM6mb 38 roll", "noise72")
    note = recording.t[np.argmin(np.abs(recording.t - 3.1713))]
    found = find_onsets(recording.signal, RATE).t
    without = find_onsets(recording.signal, RATE, config=OnsetConfig(layer_likeness=1.0, ghost_rise_db=120.0)).t
    assert np.min(np.abs(found - note)) <= 1e-3
    assert np.min(np.abs(without - note)) > 5e-3
    figures, before = score(recording, found), score(recording, without)
    assert figures["found"] - figures["correct_5ms"] <= before["found"] - before["correct_5ms"]


def test_an_attack_placed_early_in_the_modes_band_is_the_one_the_template_timed():
    """FluidR3's snare 38 in a drop (dry): at the bounces of 1.8140 and 3.9060 s the modes' band alone had put an
    attack 3.7 ms early, unfitted by the template, and the broadband detection of the same bounce, which the template
    times, followed it: one onset each now, within 1 ms, none 2-8 ms before it."""
    recording = _corpus_recording("FluidR3 38 drop", "dry")
    found = find_onsets(recording.signal, RATE).t
    for t in recording.t[[np.argmin(np.abs(recording.t - t)) for t in (1.8140, 3.9060)]]:
        assert np.min(np.abs(found - t)) <= 1e-3
        assert not np.any((found > t - 8e-3) & (found < t - 2e-3))


def test_one_more_true_onset_moves_no_other_notes_peak_db():
    """TimGM6mb's snare 38 in a roll at -72 dBFS noise: the quieter layer's second opinion finds one more ghost note
    (within 1 ms of its truth). Every other onset's ``peak_db`` is the same within 0.05 dB with it and without it,
    but the note right after it, whose earlier sound now includes the ghost's own (taken off): it reads nearer its
    truth. (With the templates cut at the next onset, such a ghost note cut the one long template and moved the
    other notes' by up to 4 dB.)"""
    recording = _corpus_recording("TimGM6mb 38 roll", "noise72")
    found = find_onsets(recording.signal, RATE, config=OnsetConfig(ghost_rise_db=120.0))
    without = find_onsets(recording.signal, RATE, config=OnsetConfig(layer_likeness=1.0, ghost_rise_db=120.0))
    new = np.flatnonzero(~np.isin(found.t, without.t))
    assert len(new) == 1 and np.all(np.isin(without.t, found.t))
    assert np.min(np.abs(recording.t - found.t[new[0]])) <= 1e-3
    kept = np.isin(found.t, without.t)
    moved = found.peak_db[kept] - without.peak_db
    after = np.flatnonzero(found.t[kept] > found.t[new[0]])[0]
    assert np.abs(np.delete(moved, after)).max() <= 0.05
    truth = recording.level_db[np.argmin(np.abs(recording.t - without.t[after]))]
    assert abs(found.peak_db[kept][after] - truth) < abs(without.peak_db[after] - truth)


def test_a_layers_template_outvotes_a_note_inside_one_of_its_waveforms():
    """Four notes of one waveform (scaled), a quieter other sound 60 ms into one of them (a ghost note, onset or not):
    the layer's template is the waveform itself, to rounding, over its whole 0.3 s (the median of four, three alike);
    with the ghost an onset, each waveform still follows past it (-20 dB re the note: ``peak_apart_db``)."""
    from drumstroke.analysis.onsets import _peak_templates

    rate, reach = 48000, 14400
    rng = np.random.default_rng(3)
    t = np.arange(reach) / rate
    wave = np.sin(2 * np.pi * 190 * t) * np.exp(-t / 0.05) + 0.3 * rng.standard_normal(reach) * np.exp(-t / 0.01)
    ghost = 0.08 * np.sin(2 * np.pi * 330 * t[:4800]) * np.exp(-t[:4800] / 0.02)
    x = np.zeros(4 * rate)
    starts = np.array([4800, 52800, 100800, 148800])
    for start, scale in zip(starts, (1.0, 0.8, 0.9, 0.7)):
        x[start:start + reach] += scale * wave
    x[starts[2] + 2880:starts[2] + 2880 + 4800] += ghost
    for onsets in (starts, np.sort(np.append(starts, starts[2] + 2880))):
        following = np.append(onsets[1:], len(x))
        ends = np.minimum(onsets + 480, following)
        templates = _peak_templates(x, onsets, following, ends, rate, OnsetConfig())
        assert len(templates) == 1 and len(templates[0]) == reach
        np.testing.assert_allclose(templates[0], wave, rtol=0.0, atol=1e-12)


def test_a_detection_the_search_takes_off_with_the_attack_before_is_that_attacks_own_sound():
    """TimGM6mb's snare 40, singles at -60 dBFS: a detection 14 ms into a note (2.3250 s), that taking off the note's
    fit (the template search's, up to the detection or past it) leaves under ``found_burst_db`` (-6 dB) of the energy
    over the 1 ms after it, is the note's own sound: dropped. Every detection is then a note within 5 ms, every loud
    note found within 1 ms; without the rule (``found_burst_db=-120``) that false detection stays."""
    recording = _corpus_recording("TimGM6mb 40 singles", "noise60")
    kept = score(recording, find_onsets(recording.signal, RATE).t)
    every = score(recording, find_onsets(recording.signal, RATE, config=OnsetConfig(found_burst_db=-120.0)).t)
    assert kept["correct_5ms"] == kept["found"] and kept["within_1ms"] == kept["loud"]
    assert every["found"] - every["correct_5ms"] == 1 and every["within_1ms"] == kept["within_1ms"]


def test_a_ghost_note_the_template_found_over_an_accents_ringing_is_kept():
    """FluidR3's snare 38 in a roll (dry): the ghost note of 4.2514 s (-23 dB, 57 ms after an accent) is found by the
    template search at its start (its fit over what is left of the accent), and kept: its first difference does not
    rise 6 dB over the accent's ringing (``decay_rise_db``, asked of quiet attacks), nor need it, the template's fit
    being its test (``found_decay_db``). With ``found_decay_db=-32`` (``decay_db``'s, as before) it is refused."""
    recording = _corpus_recording("FluidR3 38 roll", "dry")
    note = recording.t[np.argmin(np.abs(recording.t - 4.2514))]
    kept = find_onsets(recording.signal, RATE).t
    refused = find_onsets(recording.signal, RATE, config=OnsetConfig(found_decay_db=-32.0)).t
    assert np.min(np.abs(kept - note)) <= 0.1e-3
    assert np.min(np.abs(refused - note)) > 5e-3
    figures, before = score(recording, kept), score(recording, refused)
    assert figures["within_1ms"] == before["within_1ms"] + 1 and figures["correct_5ms"] / figures["found"] >= 0.95


def test_an_attack_detected_on_its_samples_second_burst_is_moved_to_its_start():
    """FluidR3's snare 40 in a drop at -60 dBFS: its sample bursts again 3.4 ms in, and over the earlier bounce's sound
    only that burst was detected at 1.9190 and 4.0204 s (3.4-3.5 ms late). The template search seeks the start up to
    ``earlier_reach`` (5 ms) before such a detection (not clear of the earlier sound): where its start correlates by
    ``weak_likeness`` and the whole template by ``template_likeness``, better than at the detection. Both within
    0.25 ms of their truth now (0.14 ms at most), and the loud notes found within 1 ms 50 of 51 (45 with
    ``earlier_reach=0``, the search as before; the quiet layer's own bounce search, which finds them too, off, and the
    template's start where it was detected, ``template_start_db=0``)."""
    recording = _corpus_recording("FluidR3 40 drop", "noise60")
    notes = recording.t[[np.argmin(np.abs(recording.t - t)) for t in (1.9190, 4.0204)]]
    moved = find_onsets(recording.signal, RATE).t
    late = find_onsets(recording.signal, RATE, config=OnsetConfig(earlier_reach=0.0, bounce_likeness=0.8,
                                                                 layer_bounce_likeness=1.0, template_start_db=0.0)).t
    for t in notes:
        assert np.min(np.abs(moved - t)) <= 0.25e-3
        assert np.min(np.abs(late - t)) > 1e-3 and np.any((late > t + 3e-3) & (late < t + 4e-3))
    figures, before = score(recording, moved), score(recording, late)
    assert figures["within_1ms"] / figures["loud"] >= 0.96 and before["within_1ms"] / before["loud"] <= 0.9
    assert figures["correct_5ms"] / figures["found"] >= 0.95


def test_a_drops_quiet_bounce_is_found_by_the_whole_template_where_its_start_is_another_layers():
    """FluidR3's snare 38 in a drop (dry): its bounce of 1.9634 s (-27.2 dB, 4 ms after the one before) is another
    velocity layer's sample than the loud template, whose start (3.5 ms) correlates with it under 0.8; the template
    search takes a close bounce where its start correlates by ``bounce_likeness`` (0.7) and its first 10 ms by
    ``template_likeness`` (0.8). Found within 0.25 ms, every detection a note within 5 ms; with
    ``bounce_likeness=0.8`` (``template_likeness``'s, as before; the quiet layer's own bounce search, which finds it
    too, off) it is missed; that rule alone (the quiet layer's search off in both, and two bounces the template fitted
    made one attack as before ``fitted_lead_db``) finds that one note more within 1 ms."""
    recording = _corpus_recording("FluidR3 38 drop", "dry")
    note = recording.t[np.argmin(np.abs(recording.t - 1.9634))]
    found = find_onsets(recording.signal, RATE, config=OnsetConfig(layer_bounce_likeness=1.0, fitted_lead_db=6.0)).t
    before = find_onsets(recording.signal, RATE, config=OnsetConfig(bounce_likeness=0.8, layer_bounce_likeness=1.0,
                                                                   fitted_lead_db=6.0)).t
    assert np.min(np.abs(found - note)) <= 0.25e-3 and np.min(np.abs(before - note)) > 5e-3
    figures, earlier = score(recording, found), score(recording, before)
    assert figures["correct_5ms"] == figures["found"] and figures["within_1ms"] == earlier["within_1ms"] + 1
    assert np.min(np.abs(find_onsets(recording.signal, RATE).t - note)) <= 0.25e-3


def test_a_bounce_over_a_rooms_sound_is_found_at_a_lower_scale():
    """FluidR3's snare 38 drop with FluidSynth's reverb: the fit of its bounce of 1.9114 s over the room's sound reads
    it louder than it is, and the next (1.9234 s, 1.5 dB quieter) scales 0.34 of it, under ``after_ratio_low`` (0.35).
    The template search asks ``bounce_ratio_low`` (0.3): that bounce and the next three (to 1.9514 s, -23 dB) are
    found, each within 0.25 ms; with ``bounce_ratio_low=0.35`` (as before; the quiet layer's own bounce search, which
    finds them too, off) none of them is within 5 ms."""
    recording = _corpus_recording("FluidR3 38 drop", "reverb")
    notes = recording.t[[np.argmin(np.abs(recording.t - t)) for t in (1.9234, 1.9354, 1.9434, 1.9514)]]
    found = find_onsets(recording.signal, RATE).t
    before = find_onsets(recording.signal, RATE, config=OnsetConfig(bounce_ratio_low=0.35, layer_bounce_likeness=1.0)).t
    for t in notes:
        assert np.min(np.abs(found - t)) <= 0.25e-3 and np.min(np.abs(before - t)) > 5e-3


def test_a_bounce_the_template_found_close_after_another_is_not_asked_to_rise_over_it():
    """FluidR3's snare 38 drop at -60 dBFS: the template search finds its bounce of 1.9514 s (-23 dB) 8.0 ms after the
    one before, within ``echo_reach`` of it, and its first difference rises -3.7 dB over that one's sound, under
    ``echo_rise_db`` (-3.5). For an attack the template found its fit is its test (``found_echo_rise_db``, -60): it is
    kept, within 0.25 ms, every detection a note within 5 ms; with ``found_echo_rise_db=-3.5`` (as before) it is
    refused."""
    recording = _corpus_recording("FluidR3 38 drop", "noise60")
    note = recording.t[np.argmin(np.abs(recording.t - 1.9514))]
    kept = find_onsets(recording.signal, RATE).t
    refused = find_onsets(recording.signal, RATE, config=OnsetConfig(found_echo_rise_db=-3.5)).t
    assert np.min(np.abs(kept - note)) <= 0.25e-3 and np.min(np.abs(refused - note)) > 5e-3
    figures = score(recording, kept)
    assert figures["correct_5ms"] == figures["found"]


@pytest.mark.parametrize("name, most_false, least_false_off", [("FluidR3 38 drop", 4, 8), ("TimGM6mb 38 drop", 0, 4)])
def test_a_rooms_echoes_that_another_note_repeats_are_no_attacks(name, most_false, least_false_off):
    """FluidSynth's reverb returns each note 54-175 ms later, smoothed, 20 dB and more under it; over a drop's tail the
    modes' band alone takes some returns for quiet attacks (8 and 4 false detections in these recordings, 67-160 ms
    after a note) that do not rise out of the tail. The same delay after another note as loud, the room has the same
    sound: fitted by it, such a return leaves no more after its time than before it (``_room_echoes``). With it 4 and 0
    false detections are left; every loud note found within 1 and 5 ms without it (``room_decay_db=-120``, the
    detector before, with the earlier notes' own sound kept too: ``_WITH_OWN_SOUND`` refuses some such returns) is
    found so with it."""
    recording = _corpus_recording(name, "reverb")
    kept = score(recording, find_onsets(recording.signal, RATE).t)
    every = score(recording, find_onsets(recording.signal, RATE,
                                         config=OnsetConfig(room_decay_db=-120.0, **_WITH_OWN_SOUND)).t)
    assert (kept["within_1ms"], kept["within_5ms"], kept["correct_5ms"]) == (
        every["within_1ms"], every["within_5ms"], every["correct_5ms"])
    assert kept["found"] - kept["correct_5ms"] <= most_false
    assert every["found"] - every["correct_5ms"] >= least_false_off


def test_a_ghost_note_under_an_accents_tail_is_not_taken_for_its_echo():
    """FluidR3's electric snare (40) roll with reverb, seed 2: a ghost note (2.5777 s, -30 dB) 50.7 ms after an accent
    is found in the modes' band alone and does not rise out of the accent's tail, as the room's returns do, and the
    accent's sound at that delay after other accents fits its 10 ms to -16 dB. What the fit leaves after its start is
    14 dB over what it leaves before (a new sound; the room's returns: -3.6 to 5.9 dB over the corpus and four more
    seeds): kept, within 0.1 ms, while two false detections of the recording go. Asked nothing of what the fit leaves
    (``room_echo_db=60``) it would be refused. (The control keeps the earlier notes' own sound too,
    ``_WITH_OWN_SOUND``: that rule refuses those false detections as well.)"""
    recording = next(r for r in recordings(seed=2, conditions=("reverb",)) if r.name == "FluidR3 40 roll reverb")
    note = recording.t[np.argmin(np.abs(recording.t - 2.5777))]
    kept = find_onsets(recording.signal, RATE).t
    careless = find_onsets(recording.signal, RATE, config=OnsetConfig(room_echo_db=60.0)).t
    every = find_onsets(recording.signal, RATE, config=OnsetConfig(room_decay_db=-120.0, **_WITH_OWN_SOUND)).t
    assert np.min(np.abs(kept - note)) < 0.1e-3 and np.min(np.abs(careless - note)) > 5e-3
    figures, before = score(recording, kept), score(recording, every)
    assert figures["correct_5ms"] == before["correct_5ms"] and figures["found"] <= before["found"] - 2


def test_an_echos_novelty_is_what_its_fit_by_another_notes_sound_leaves_after_it_over_before_it():
    """``echo_novelty`` on a made sound: a note (decaying noise, low-passed as a drum's band is) at two times, the second half as loud, each followed
    90 ms later by the same return, in white noise 40 dB under the returns. At the first return, fitted by the second
    note's return, what is left is the noise alike before and after (within 1.5 dB of 0 dB; the fit's lag found within
    the reach); with a new burst starting at the return it is over 10 dB; fitted by a window of noise alone, the fit
    leaves more than ``most_left`` of it: no answer (inf)."""
    from drumstroke.analysis._rooms import echo_novelty

    rng = np.random.default_rng(11)
    note = np.convolve(rng.standard_normal(4000), np.hanning(24), mode="same") * np.exp(-np.arange(4000) / 800.0)
    x = np.zeros(40000)
    for start, scale in ((2000, 1.0), (20000, 0.5)):
        x[start:start + 4000] += scale * note
        x[start + 4320:start + 8320] += 0.1 * scale * note
    x += 1e-3 * rng.standard_normal(len(x))
    at, partner = 2000 + 4320 + 1200, [20000 + 4320 + 1200 + 7]  # the partner window 7 samples off
    novelty = echo_novelty(x, at, np.array(partner), 240, 240, 24, 3, 0.25)
    assert abs(10 * np.log10(novelty)) < 1.5
    burst = x.copy()
    burst[at:at + 240] += 0.02 * rng.standard_normal(240)
    assert 10 * np.log10(echo_novelty(burst, at, np.array(partner), 240, 240, 24, 3, 0.25)) > 10.0
    assert echo_novelty(x, at, np.array([36000]), 240, 240, 24, 3, 0.25) == np.inf


@pytest.mark.parametrize(("name", "condition", "times"), [
    ("FluidR3 38 drop", "dry", (1.9687, 4.0501, 4.0554, 4.0607)),
    ("FluidR3 38 drop", "noise60", (1.9687, 4.0501, 4.0554, 4.0607)),
    ("FluidR3 40 drop", "noise72", (1.9190, 1.9297, 1.9390, 1.9470)),
])
def test_a_drops_last_bounces_are_found_by_the_quiet_layers_own_template(name, condition, times):
    """A drop's last bounces are the quiet velocity layer's sample, whose start the loud template's does not fit.
    FluidR3's snare 38 (1.9687 s; 4.0501, 4.0554 and 4.0607 s: -24 to -29 dB, 5.3-6.7 ms apart; 0.62 at 4.0501 s):
    where the loud template finds no close bounce after an attack the quiet layer's template took off, the search
    looks with that layer's (its first 10 ms by ``layer_bounce_likeness``, its start by ``weak_likeness``). FluidR3's
    snare 40 at -72 dBFS: its quietest clear attack comes in the second drop, so the first drop's last bounces
    (1.9190-1.9470 s, -22 to -28 dB, 8-12 ms apart) come before the loop has that layer's template (what is left there
    once the attacks before it are taken off); before it, the layer's template is its sound as recorded. Each is found
    within 0.1 ms, no false detection more (every row of the corpus the same); with ``layer_bounce_likeness=1`` (no
    quiet layer's search, as before) none of them is within 5 ms."""
    recording = _corpus_recording(name, condition)
    notes = recording.t[[np.argmin(np.abs(recording.t - t)) for t in times]]
    found = find_onsets(recording.signal, RATE).t
    before = find_onsets(recording.signal, RATE, config=OnsetConfig(layer_bounce_likeness=1.0)).t
    for t in notes:
        assert np.min(np.abs(found - t)) <= 0.1e-3 and np.min(np.abs(before - t)) > 5e-3
    figures, earlier = score(recording, found), score(recording, before)
    assert figures["found"] - figures["correct_5ms"] <= earlier["found"] - earlier["correct_5ms"]


def test_a_recording_replays_a_sample_where_two_clear_attacks_are_one_waveform():
    """The quiet layer's bounce search runs where the recording replays a sample (``replay_likeness``): two clear notes
    of one velocity layer are one waveform scaled (FluidSynth: correlation 1 to rounding), while each of our synthetic
    drum's strokes is a new waveform (the speed changes its spectrum; 180 strokes measured: 0.998 at most)."""
    from _recordings import RATE as SYNTHETIC_RATE, random_strokes, render
    from drumstroke.analysis.onsets import _clear, _high_pass, _replays

    config = OnsetConfig()

    def replays(signal, rate, times):
        band = _high_pass(signal, rate, config.high_pass)[0]
        samples = np.asarray(times) * rate
        _, (clear,) = _clear(np.abs(np.diff(band, prepend=0.0)), samples, rate, [config.lead_clear_db])
        return _replays(band, samples, clear, rate, config)

    recording = next(recordings(fonts=("FluidR3",), keys=(38,), sets=("singles",), conditions=("dry",)))
    assert replays(recording.signal, RATE, recording.t)
    times, speeds = random_strokes(1, seed=28)[0]
    signal, truth = render(times, speeds, seed=0, snares=False)
    assert not replays(signal, SYNTHETIC_RATE, truth)


def test_a_rooms_return_the_template_timed_is_no_onset():
    """FluidR3's snare 38 singles with FluidSynth's reverb: the room's return 83.5 ms after its loudest note (3.0935 s,
    -21 dB) is clear enough for the template to time it (kind 3), which ``_room_echoes`` does not try. The same delay
    after the other loud note (4 dB quieter), the room's sound leaves -18 dB of its 10 ms, and no more after its time
    than before it: with ``_room_returns`` it is no onset (one false detection fewer), and every loud note is found
    within 1 and 5 ms as without it (``room_found_fit_db=-120``, the detector before)."""
    recording = _corpus_recording("FluidR3 38 singles", "reverb")
    kept = find_onsets(recording.signal, RATE).t
    every = find_onsets(recording.signal, RATE, config=OnsetConfig(room_found_fit_db=-120.0)).t
    assert np.min(np.abs(every - 3.0935)) < 0.5e-3 and np.min(np.abs(kept - 3.0935)) > 5e-3
    figures, before = score(recording, kept), score(recording, every)
    assert (figures["within_1ms"], figures["within_5ms"], figures["correct_5ms"]) == (
        before["within_1ms"], before["within_5ms"], before["correct_5ms"]) == (figures["loud"],) * 3
    assert figures["found"] == before["found"] - 1


def test_a_rooms_return_is_tried_again_once_the_onsets_around_are_known():
    """FluidR3's snare 38 drop with FluidSynth's reverb: a return of the modes' band alone 159.6 ms after the drop's
    first note (0.3736 s, -27 dB) that step 5 kept, no other note then clear of the next attack for as long as that
    delay. Tried again on the reported onsets (``_room_returns``: the attacks left out since leave more notes clear),
    it is no onset; every loud note is found within 1 and 5 ms as without it (``room_found_fit_db=-120``)."""
    recording = _corpus_recording("FluidR3 38 drop", "reverb")
    kept = find_onsets(recording.signal, RATE).t
    # room_partner_under_db (a later rule) refuses it already in step 5: off here
    every = find_onsets(recording.signal, RATE, config=OnsetConfig(room_found_fit_db=-120.0,
                                                                   room_partner_under_db=120.0)).t
    assert np.min(np.abs(every - 0.3736)) < 0.5e-3 and np.min(np.abs(kept - 0.3736)) > 5e-3
    figures, before = score(recording, kept), score(recording, every)
    assert (figures["within_1ms"], figures["within_5ms"], figures["correct_5ms"]) == (
        before["within_1ms"], before["within_5ms"], before["correct_5ms"])
    assert figures["found"] == before["found"] - 1


@pytest.mark.parametrize("name, condition, least_1ms, off_1ms", [
    ("TimGM6mb 38 roll", "noise60", 30, 27), ("FluidR3 38 roll", "dry", 28, 27), ("FluidR3 38 roll", "noise72", 27, 26),
])
def test_ghost_notes_under_an_accent_are_found_once_its_layer_mate_is_taken_off(name, condition, least_1ms, off_1ms):
    """Rolls of the corpus: ghost notes 50-120 ms after an accent, under its ringing (unseen, or found on their main
    rise 1.1 ms late), are found in what is left once another note of the accent's layer, replayed sample for sample,
    is taken off, with no false detection more; without that search (``ghost_rise_db=120``) as few as before it.
    Both with ``ghost_matched_fit=1``: the ghost layer's head, learned from the ghost notes the earlier stages found,
    finds some of them too."""
    recording = _corpus_recording(name, condition)
    figures = score(recording, find_onsets(recording.signal, RATE, config=OnsetConfig(ghost_matched_fit=1.0)).t)
    off = score(recording, find_onsets(recording.signal, RATE, config=OnsetConfig(ghost_rise_db=120.0,
                                                                                  ghost_matched_fit=1.0)).t)
    assert figures["within_1ms"] >= least_1ms and off["within_1ms"] <= off_1ms
    assert figures["found"] - figures["correct_5ms"] <= off["found"] - off["correct_5ms"]


def test_a_replayed_samples_later_notes_are_its_remainder_less_a_layer_mate():
    """The ghost search on a sample player's recording made here: one accent waveform (the same samples, scaled)
    at six times, a ghost waveform 26 dB under it after four of them at known samples, each accent's mates the
    others. Every ghost note is found at its first sample (1 % of its peak passed there at once), none elsewhere."""
    from drumstroke.analysis._ghosts import ghost_onsets

    rate = 48000
    band, accents, ghosts = sample_player({0: 3100, 2: 4500, 3: 2700, 5: 5200}, accents=6, ringing=0.08, rate=rate)
    found = ghost_onsets(band, np.array(accents, dtype=float), np.ones(6, dtype=bool), rate, likeness=0.999,
                         rise_db=15.0, least=0.0)
    np.testing.assert_array_equal(found, ghosts)
