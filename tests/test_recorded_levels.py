"""Onsets' broadband peaks on recorded drums (issue 28: "levels right within 1 dB relative to the loudest"):
``peak_db`` against the truth of tests/_recorded_drums.py's corpus (seed 0; each note's own peak rendered alone, dB
re the loudest's), on the loud notes found within 5 ms, as benchmarks/recorded_onsets.py scores it.

The detector places some onsets a little late (TimGM6mb's snare 40: 0.47 ms in its drop at -60 dBFS, 0.9 ms on its
flams' main notes): a note's template fitted within 60 µs of it then leaves most of the note unexplained and its
sound under the next notes' peaks, and a clear note's waveform ends after the next note's attack has begun.
``peak_realign`` (1 ms) seeks a poor fit again that far either way and ends a template's waveform where the next
note's attack already rises; 0 gives the outputs before it. The onsets and ``level_db`` are the same either way.
"""

import numpy as np
import pytest

from _recorded_drums import LOUD_DB, RATE, match, recordings
from drumstroke.analysis import OnsetConfig, find_onsets

# the outputs before the rule: without the later peak_learn too (which also reads the drop at -60 dBFS placed late
# within 4.2 dB without this rule: tests/test_recorded_peak_levels.py)
_BEFORE = OnsetConfig(peak_realign=0.0, peak_learn=0.0)
# onsets placed late as before the template's own start (``template_start_db=0``), with and without the rule: the
# rule's cases, which the template's start since puts on time in the drop and the flams
_LATE = OnsetConfig(template_start_db=0.0)
_LATE_BEFORE = OnsetConfig(template_start_db=0.0, peak_realign=0.0, peak_learn=0.0)

# FluidSynth and both SoundFonts are needed (scripts/install-system-packages.sh installs them): without them these
# tests fail with render_soundfont's error, they never skip


@pytest.fixture(scope="module")
def timgm40():
    """TimGM6mb's snare 40 drop, roll and flams, dry and in noise, with the corpus's seeds (every font, key and set
    passed: a recording's seed is its index among them)."""
    wanted = {}
    for r in recordings(conditions=("dry", "noise72", "noise60")):
        if (r.font, r.key) == ("TimGM6mb", 40) and r.set != "singles":
            wanted[r.set, r.condition] = r
        if r.font == "TimGM6mb" and r.key == 40 and r.set == "flams" and r.condition == "noise60":
            break
    return wanted


@pytest.fixture(scope="module")
def timgm38_flams():
    return next(r for r in recordings(conditions=("dry",)) if (r.font, r.key, r.set) == ("TimGM6mb", 38, "flams"))


def _errors(recording, onsets):
    """``peak_db`` less the truth (dB) on the loud notes found within 5 ms, and their truth times (s)."""
    loud = recording.level_db >= -LOUD_DB
    pairs = [(i, j) for i, j in match(recording.t, onsets.t, 5e-3) if loud[i]]
    return (np.array([onsets.peak_db[j] - recording.level_db[i] for i, j in pairs]),
            np.array([recording.t[i] for i, _ in pairs]))


def _q95(recording, config=None):
    """The 95th percentile of ``_errors``' magnitudes (dB) with ``config`` (the default's for None)."""
    config = OnsetConfig() if config is None else config
    return float(np.quantile(np.abs(_errors(recording, find_onsets(recording.signal, RATE, config=config))[0]), 0.95))


def test_a_ghost_note_after_an_accent_placed_late_reads_its_own_peak(timgm40):
    """At -72 dBFS the roll's accent of 0.4642 s is placed 5 samples (0.1 ms) late: fitted within 3 samples its
    template left 70 % of it unexplained, and the ghost note 85 ms after it (0.5496 s, -23.4 dB) read 9.3 dB high.
    Sought again within 1 ms the fit leaves next to nothing: the ghost is within 1 dB, every loud note within 1 dB."""
    recording = timgm40["roll", "noise72"]
    now, t = _errors(recording, find_onsets(recording.signal, RATE))
    before, t_before = _errors(recording, find_onsets(recording.signal, RATE, config=_BEFORE))
    ghost = np.argmin(np.abs(t - 0.5496))
    assert abs(t[ghost] - 0.5496) < 1e-3 and abs(now[ghost]) <= 1.0
    assert before[np.argmin(np.abs(t_before - 0.5496))] > 5.0
    assert np.abs(now).max() <= 1.0 < np.abs(before).max()


def test_a_drop_in_noise_placed_late_has_its_bounces_taken_off(timgm40):
    """At -60 dBFS the drop's onsets are placed 0.47 ms late but for one: every fit within 60 µs left 70 % or more
    unexplained, no bounce's sound was taken off, and the quiet last bounces read up to 12 dB high (95th percentile
    8.7 dB). Sought again: 95th percentile within 2 dB (what is left: the noise over the quietest bounces' peaks).
    Both on the onsets as placed before ``template_start_db``; with it (the default) within 2 dB too."""
    recording = timgm40["drop", "noise60"]
    assert _q95(recording, _LATE) <= 2.0 and _q95(recording, _LATE_BEFORE) > 5.0 and _q95(recording) <= 2.0


@pytest.mark.parametrize("condition", ["dry", "noise72"])
def test_flams_main_notes_placed_late_leave_no_attack_in_the_graces_template(timgm40, condition):
    """The flams' main notes are placed 0.9 ms late: the grace notes' waveforms (the template, the main notes never
    clear) ran into their main notes' attacks, and taking a grace note off took part of an attack off the next main
    note near its peak: the loudest read 1.3 dB high, all the others low (95th percentile 1.07-1.22 dB). Ended where
    the next attack rises: within 0.5 dB. Both on the onsets as placed before ``template_start_db``; with it (the
    default) within 0.5 dB too."""
    recording = timgm40["flams", condition]
    assert _q95(recording, _LATE) <= 0.5 and _q95(recording, _LATE_BEFORE) > 1.0 and _q95(recording) <= 0.5


def test_a_template_keeps_its_tail_where_the_next_onset_is_on_time(timgm38_flams):
    """On the snare 38's flams the main notes are placed on time (within 0.01 ms): the graces' waveforms keep their
    tails up to the main notes (ended 1 ms before every next onset instead, the grace notes' template lost its last
    voices and the main note of 1.3939 s read 1.1 dB high: 95th percentile 1.08 dB); 0.20 dB as before."""
    assert _q95(timgm38_flams) <= 0.3


@pytest.mark.parametrize("key", [("drop", "noise60"), ("flams", "dry")])
def test_peak_realign_changes_peak_db_only(timgm40, key):
    """The switch changes ``peak_db`` alone: the times and ``level_db`` are the same to the bit (on the onsets as
    placed before ``template_start_db``, where it changes them)."""
    recording = timgm40[key]
    now, before = (find_onsets(recording.signal, RATE, config=c) for c in (_LATE, _LATE_BEFORE))
    assert np.array_equal(now.t, before.t) and np.array_equal(now.level_db, before.level_db)
    assert not np.array_equal(now.peak_db, before.peak_db)
