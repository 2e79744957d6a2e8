"""A ghost note's rise over white noise (onsets' ``ghost_white_rise_db``: ``_ghost_notes``, analysis/_ghosts.py's
``ghost_onsets``).

What is left once an accent's layer-mates are taken off is, before a ghost note in a recording with noise, the noise
of both recordings: white (its correlation one sample on near 0). Its energy over 1 ms (48 samples at 48 kHz) spreads
+-20 % (sqrt(2/48)), its most over 10 ms some 1.5 times its mean, so a rise of 6 dB over that most is a chance under
1e-15 of the noise alone, where ``ghost_rise_db`` (15) was set for what the mates leave of the accent's own sound in a
dry recording, its low modes. FluidR3's ghost notes at -60 dBFS (held-out seeds 1-4) rise 9-12 dB over the noise
and were missed. A rise by ``ghost_white_rise_db`` over the 10 ms before the 1-ms gap of ``ghost_rise_gap``, where
what is left over the 5 ms before is white, is a note where it is the accent's own (louder in its sound than in the
mate's, ``ghost_own_db``): a mate's own ghost note missed, left negated in its remainder, rises so too.
"""

import numpy as np

from _recorded_drums import RATE, match, score
from drumstroke.analysis import OnsetConfig, find_onsets
from test_recorded_ghosts import _roll, _Truth


def test_ghost_notes_rising_under_15_db_over_white_noise_are_found():
    """FluidR3's snare 40 roll at -60 dBFS (seed 2): the ghost notes of 0.2590, 1.4337 and 2.5777 s (-26.4, -28.1,
    -27.0 dB) rise under 15 dB over what the mates leave before them, white noise: with ``ghost_white_rise_db`` 6 (the
    default) all three are found within 1 ms (1.4337 s 1.17 ms late with ``ghost_matched_back=0``, its head moved
    back to 0.44 ms), with no false detection more and every note found before as close; with 120 (as before) none is
    found within 5 ms. Both with ``ghost_step_reach=0``: its move of the note of 3.5350 s (the matched search's
    onset, 3.7 ms before its attack; tests/test_recorded_ghost_steps.py) counts a fourth note here."""
    signal, t, level = _roll("FluidR3", 40, "noise60", seed=2)
    truth = _Truth(t, level)
    found = find_onsets(signal, RATE, config=OnsetConfig(ghost_step_reach=0.0)).t
    before = find_onsets(signal, RATE, config=OnsetConfig(ghost_white_rise_db=120.0, ghost_step_reach=0.0)).t
    for note, within in ((0.2590, 1e-3), (1.4337, 1e-3), (2.5777, 1e-3)):
        note = t[np.argmin(np.abs(t - note))]
        assert np.min(np.abs(found - note)) <= within and np.min(np.abs(before - note)) > 5e-3
    now, then = score(truth, found), score(truth, before)
    assert now["correct_5ms"] == then["correct_5ms"] + 3
    assert now["within_1ms"] == then["within_1ms"] + 3
    assert now["found"] - now["correct_5ms"] <= then["found"] - then["correct_5ms"]
    for i, j in match(t, before, 1e-3):
        assert np.min(np.abs(found - t[i])) <= abs(before[j] - t[i]) + 1e-9


def test_a_mates_missed_ghost_note_left_negated_is_not_a_note():
    """FluidR3's snare 40 roll at -60 dBFS (seed 4): the accent of 4.059 s has as mates the accents of 2.339 and
    2.631 s, whose own ghost notes 60 and 80 ms after them were missed before this search: left negated in their
    remainders, the one of 2.631 s rises 9 dB over what is left before it (white) at 4.1398 s, 17 ms before the
    ghost note of 4.1564 s. It is louder in the mate's sound than in the accent's: not found (no false detection
    there), while both mates' ghost notes (2.3990 and 2.7110 s) are found within 5 ms."""
    signal, t, level = _roll("FluidR3", 40, "noise60", seed=4)
    truth = _Truth(t, level)
    found = find_onsets(signal, RATE).t
    before = find_onsets(signal, RATE, config=OnsetConfig(ghost_white_rise_db=120.0)).t
    assert np.min(np.abs(found - 4.1398)) > 5e-3
    for note in (2.3990, 2.7110):
        note = t[np.argmin(np.abs(t - note))]
        assert np.min(np.abs(found - note)) <= 5e-3 and np.min(np.abs(before - note)) > 5e-3
    now, then = score(truth, found), score(truth, before)
    assert now["found"] - now["correct_5ms"] <= then["found"] - then["correct_5ms"]
