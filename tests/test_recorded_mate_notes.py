"""Ghost notes past every layer-mate's own ghost note, where a sample player replays one sample at every velocity
(onsets' ``ghost_mate_notes``: ``_ghost_notes`` and ``_room_ghost_notes``, analysis/_ghosts.py's ``mates_notes``).

TimGM6mb's snare 38 is one waveform at every velocity (two notes rendered alone correlate 1.000 over 0-200 ms), so a
layer-mate's next note is the accent's own waveform too: taken off the mate's remainder with the accent's own sound
placed there, that remainder reaches on to the mate's note after it.
"""

import numpy as np

from _recorded_drums import RATE, score
from drumstroke.analysis import OnsetConfig, find_onsets
from drumstroke.analysis._ghosts import ghost_onsets
from test_recorded_ghosts import _roll, _Truth

_NOTE = 0.9739  # s: TimGM6mb's snare 38 roll's ghost note (seed 0, -24.5 dB), 120 ms after its accent (0.8539 s)


def test_a_ghost_note_past_every_mates_own_ghost_note_is_found():
    """TimGM6mb's snare 38 roll, dry and with FluidSynth's reverb (seed 0): the ghost note of 0.9739 s lies 120 ms after
    its accent, whose layer-mates are all cut by their own ghost notes 57-115 ms in, and the accent's own sound there
    is as loud as it. With each mate's ghost note taken off (``ghost_mate_notes``, the default 0.99) what is left
    before it is -150 dB dry and -40 to -53 dB with reverb, -31 dB on it: found within 1 ms, no false detection
    more. With ``ghost_mate_notes=1`` (as before) it is missed (none within 5 ms)."""
    for condition in ("dry", "reverb"):
        signal, t, level_db = _roll("TimGM6mb", 38, condition)
        truth = _Truth(t, level_db)
        note = t[np.argmin(np.abs(t - _NOTE))]
        found = find_onsets(signal, RATE).t
        before = find_onsets(signal, RATE, config=OnsetConfig(ghost_mate_notes=1.0)).t
        assert np.min(np.abs(found - note)) <= 1e-3 and np.min(np.abs(before - note)) > 5e-3, condition
        now, then = score(truth, found), score(truth, before)
        assert now["within_1ms"] == then["within_1ms"] + 1 == now["loud"], condition
        assert now["found"] - now["correct_5ms"] <= then["found"] - then["correct_5ms"], condition


def _one_sample_roll(late=0.12, seed=3):
    """A sample player's roll made here: one waveform (noise ringing down, 30 ms time constant) at four accents 0.45
    s apart, scaled 1 - 0.05 k, and at a ghost note 20 dB under each: accent 0's ``late`` s after it, the
    others' 57-95 ms after theirs (each mate cut before ``late``). Returns the signal, the accents' and the ghosts'
    samples."""
    rng = np.random.default_rng(seed)
    n = np.arange(round(0.3 * RATE))
    wave = rng.standard_normal(len(n)) * np.exp(-n / (0.03 * RATE))
    wave[:48] *= np.linspace(0.0, 1.0, 48)
    band = np.zeros(round(2.4 * RATE))
    accents = [round((0.1 + 0.45 * k) * RATE) for k in range(4)]
    ghosts = [accents[0] + round(late * RATE)] + [a + round(d * RATE) for a, d in zip(accents[1:], (0.057, 0.08, 0.095))]
    for k, at in enumerate(accents):
        band[at:at + len(n)] += wave * (1.0 - 0.05 * k)
    for g in ghosts:
        band[g:g + len(n)] += wave * 0.1
    return band / np.abs(band).max(), accents, ghosts


def test_a_mates_next_note_of_the_accents_waveform_is_taken_off():
    """On a sample player made here (one waveform at every velocity), the ghost note 120 ms after its accent, past
    every mate's own ghost note (57-95 ms), is found within a sample with ``mate_notes`` (0.99) and not without (1:
    the mates' remainders end at their ghost notes), and so is every other ghost note (the one 95 ms in also past
    two mates' ghost notes: without, it is missed too); nothing else is found."""
    band, accents, ghosts = _one_sample_roll()
    times = np.array(sorted(accents + ghosts), dtype=float)
    clear = np.isin(times, accents)
    kw = {"likeness": 0.999, "rise_db": 15.0, "least": 1e-2}
    found = ghost_onsets(band, times, clear, RATE, mate_notes=0.99, **kw)
    before = ghost_onsets(band, times, clear, RATE, **kw)
    assert len(found) == len(ghosts) and np.all(np.abs(found - np.sort(ghosts)) <= 1)
    assert np.min(np.abs(before - ghosts[0])) > 0.005 * RATE
