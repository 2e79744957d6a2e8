"""Ghost notes found by a matched filter of their layer's own attack (onsets' ``_matched_ghost_notes``,
analysis/_ghosts.py: ``matched_ghost_onsets``, ``ghost_matched_fit``).

A sample player replays a ghost layer's waveform sample for sample, and what an accent's layer-mates leave of it
after a ghost note already found is that note alone with the recording's noise: the ghost notes found teach the
layer's first 5.5 ms (and, scaled, its longer sound), and that head is sought in what the mates leave (a mate whose
own next attack is such a note taken off less it). Under white noise the head's 5.5 ms gather a quiet note's energy
where a 1-ms rise reads its first millisecond alone. These tests are that rule on the recorded corpus
(tests/_recorded_drums.py) and its search on a sample player made here.
"""

import numpy as np

from drumstroke.analysis._ghosts import matched_search
from test_recorded_noise_ghosts import _compare, _no_worse


def test_quiet_ghost_notes_under_white_noise_are_found_by_their_layers_head():
    """FluidR3's snare 38 roll at -60 dBFS (seed 0): the ghost note of 0.7874 s (-23 dB) rises 10.3 dB over 1 ms
    out of the noise of the two recordings taken one from the other (15 asked), and no layer-mate reaches the one of
    2.8007 s (each mate's own next note first), nor 3.9647 s's first 1.25 ms. The layer's head learned from the ghost
    notes found fits 0.97-0.99 at each, the two mates' own ghost notes taken off them for the later two: all three
    within 1 ms, no false detection more, every note found before within 1 ms found as close; with
    ``ghost_matched_fit=1`` (as before) the first two are missed and the third over 1 ms late. Both with
    ``ghost_white_rise_db=120``: a rise of 6 dB over the white noise finds 0.7874 s too."""
    truth, found, before = _compare("FluidR3", 38, "noise60", 0.7874, {"ghost_matched_fit": 1.0},
                                    {"ghost_white_rise_db": 120.0})
    for t in (0.7874, 2.8007, 3.9647):
        assert np.min(np.abs(found - t)) < 1e-3
    assert np.min(np.abs(before - 0.7874)) > 5e-3 and np.min(np.abs(before - 2.8007)) > 5e-3
    assert np.min(np.abs(before - 3.9647)) > 1e-3
    now, then = _no_worse(truth, found, before)
    assert now["within_1ms"] == then["within_1ms"] + 3


def _player(rate=48000):
    """A made sample player: an accent (a decaying 180-Hz tone with a click) and a ghost layer (a short burst of
    fixed noise), one waveform each replayed; three accents, the first with a ghost note 60 ms after it at -20 dB,
    and white noise at -60 dB under all. Returns the signal, the accents' onsets and the ghost's (samples)."""
    rng = np.random.default_rng(5)
    t = np.arange(round(0.2 * rate)) / rate
    accent = np.sin(2 * np.pi * 180 * t) * np.exp(-t / 0.08)
    accent[:48] += rng.standard_normal(48)
    ghost = rng.standard_normal(round(0.03 * rate)) * np.exp(-np.arange(round(0.03 * rate)) / (0.004 * rate)) * 0.1
    x = np.zeros(rate)
    onsets = [round(0.05 * rate), round(0.35 * rate), round(0.65 * rate)]
    for o in onsets:
        x[o:o + len(accent)] += accent
    g = onsets[0] + round(0.06 * rate)
    x[g:g + len(ghost)] += ghost
    return x + rng.standard_normal(len(x)) * 1e-3, onsets, g, ghost


def test_matched_search_finds_a_ghost_by_its_head_in_what_the_mates_leave():
    """In the made player, what the two later accents leave of the first is the ghost note and noise: the head
    (the ghost's first 5.5 ms, unit norm) fits it at its onset to the sample, within 0.9 or more; with the mates
    reaching no further than the ghost's onset (fewer than two past it) the window ends there and nothing is
    found."""
    x, onsets, g, ghost = _player()
    pre, n = 24, 264
    head = np.concatenate((np.zeros(pre), ghost[:n - pre]))
    head /= np.linalg.norm(head)
    args = (x, onsets[0], 0, round(0.13 * 48000), np.array(onsets[1:], dtype=np.int64), np.ones(2),
            np.array([10 ** 6, 10 ** 6], dtype=np.int64), np.zeros(2), np.zeros(2, dtype=np.int64), np.zeros(1), head,
            12, 48, 480, 10.0 ** 0.6, 24, pre, 2, 480)
    found, fits, _ = matched_search(*args)
    assert len(found) and onsets[0] + found[np.argmax(fits)] == g and fits.max() >= 0.9
    short = args[:6] + (np.array([g - onsets[0]] * 2, dtype=np.int64),) + args[7:]
    found, _, _ = matched_search(*short)
    assert not len(found)
