"""Spare layer-mates where an accent's first ones stop reaching (onsets' ``ghost_spare_mates``:
``_matched_ghost_notes``, analysis/_ghosts.py's ``matched_search``).

What an accent's layer-mates leave counts, in the ghost layer's matched search, only up to each mate's own next
attack, and the accent's window ends where fewer than two of its first three mates (the most alike) reach. In a roll
every accent has ghost notes of its own 55-130 ms after it, so a ghost note later than that after its accent (its
second or third note, 95-172 ms after it) lies past every first mate's reach (FluidR3's rolls, seeds 1-9: 27 of the
85 notes missed). An accent of a roll has more mates than three (up to eight, the same sample within 0.999): the
mates past the first three count from where fewer than two of the first reach, each up to its own next attack.
"""

from _recorded_drums import RATE
from drumstroke.analysis import OnsetConfig, find_onsets
from test_recorded_ghosts import _roll, _Truth
from test_recorded_noise_ghosts import _gains


def test_a_ghost_note_past_the_first_mates_reach_is_found_by_spare_mates():
    """FluidR3's snare 38 roll, dry (seed 5): the ghost note of 3.8701 s (-18.1 dB, 103 ms after its accent of
    3.7674 s, the next attack of its first three mates 105-122 ms after them, less the head) is found within 1 ms by
    the ghost layer's head with spare mates (``ghost_spare_mates`` 5, the default), with no false detection more and
    every note found before as close; with ``ghost_spare_mates=0`` (as before) not within 5 ms."""
    signal, t, level = _roll("FluidR3", 38, "dry", seed=5)
    truth = _Truth(t, level)
    found = find_onsets(signal, RATE).t
    before = find_onsets(signal, RATE, config=OnsetConfig(ghost_spare_mates=0)).t
    _gains(truth, found, before, (3.8701,))
