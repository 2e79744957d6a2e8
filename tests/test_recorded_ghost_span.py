"""How long after an accent its ghost notes are sought (onsets' ``ghost_span``: ``_ghost_notes``,
``_room_ghost_notes`` and ``_matched_ghost_notes``, analysis/_ghosts.py).

The searches read what is left once an accent's layer-mates are taken off, up to the next attack within 10 dB of the
accent and up to ``ghost_span`` s after it (0.13 s before this field). The corpus's rolls (tests/_recorded_drums.py)
put ghost notes up to 0.17 s after their accents: on the held-out seeds 1-4, 8 ghost notes missed lay more than
0.13 s after theirs.
"""

from _recorded_drums import RATE
from drumstroke.analysis import OnsetConfig, find_onsets
from test_recorded_ghosts import _roll, _Truth
from test_recorded_noise_ghosts import _gains


def test_ghost_notes_more_than_130_ms_after_their_accent_are_found():
    """FluidR3's snare 38 roll with FluidSynth's reverb (seed 3): the ghost notes of 3.4834 s (-24.1 dB, 169 ms after
    its accent of 3.3140 s) and 3.9047 s (-22.2 dB, 136 ms after 3.7687 s) lie past 0.13 s: with ``ghost_span`` 0.18
    (the default) both are found within 1 ms, with no false detection more and every note found before as close;
    with ``ghost_span=0.13`` (as before) neither is found within 5 ms."""
    signal, t, level = _roll("FluidR3", 38, "reverb", seed=3)
    truth = _Truth(t, level)
    found = find_onsets(signal, RATE).t
    before = find_onsets(signal, RATE, config=OnsetConfig(ghost_span=0.13)).t
    _gains(truth, found, before, (3.4834, 3.9047))


def test_the_ghost_layers_head_is_learned_from_the_later_notes_too():
    """FluidR3's snare 38 roll, dry (seed 1): the ghost note of 2.8727 s (-20.1 dB, 93 ms after its accent of
    2.7794 s) is found by the ghost layer's head (``ghost_matched_fit``), learned from the ghost notes found within
    ``ghost_span`` of their accents: with 0.18 (the default) within 1 ms, no false detection more; with 0.13 (as
    before) not within 5 ms."""
    signal, t, level = _roll("FluidR3", 38, "dry", seed=1)
    truth = _Truth(t, level)
    found = find_onsets(signal, RATE).t
    before = find_onsets(signal, RATE, config=OnsetConfig(ghost_span=0.13)).t
    _gains(truth, found, before, (2.8727,))
