"""Ghost notes of FluidR3's rolls with FluidSynth's reverb (onsets' ``_room_ghost_notes``, analysis/_ghosts.py's
``room_ghost_onsets``, and ``_room_echoes``' partners).

In a reverberant recording that replays a sample a ghost note is sought where what is left once a layer-mate takes
the accent's own sound off rises over 5 ms and the quiet layer's attack fits it. These tests are the rules added to
that search on the recorded corpus (tests/_recorded_drums.py, seed 0): where the fit is read from
(``ghost_room_reach``), which attacks an accent with no layer-mate takes as its mates (``ghost_room_spare_likeness``)
and which later attacks end a partner's clear sound in the test of a room's echo (``room_partner_under_db``).
"""

import numpy as np

from _recorded_drums import FONTS, KEYS, RATE, SETS, Leads, match, note_block, notes, score, speed_of
from drumstroke.analysis import OnsetConfig, find_onsets


def _roll(key, seed=0):
    """FluidR3's roll of snare ``key`` with reverb (as tests/_recorded_drums.py's ``recordings`` makes it): (signal,
    true times s, levels dB re the loudest)."""
    from drumstroke.render.soundfont import render_soundfont

    base = seed * 1000 + 100 * list(FONTS).index("FluidR3") + 10 * KEYS.index(key) + SETS.index("roll")
    played = notes("roll", base)
    leads = Leads()
    measured = [leads("FluidR3", key, v) for _, v in played]
    t = np.array([note_block(t) + lead for (t, _), (lead, _) in zip(played, measured)]) / RATE
    peak = np.array([p for _, p in measured])
    hits = [(t, "snare", key, speed_of(v)) for t, v in played]
    signal = render_soundfont(hits, FONTS["FluidR3"], duration=5.0, rate=RATE, reverb=True)
    return signal, t, 20.0 * np.log10(peak / peak.max())


class _Truth:
    def __init__(self, t, level_db):
        self.t, self.level_db = t, level_db


def _gains(key, note, now, then):
    """Asserts that ``note`` (s) is found within 1 ms with the config ``now`` and not within 5 ms with ``then``, one
    note more within 1 ms and 5 ms, no false detection more, and every note found before as close now."""
    signal, t, level = _roll(key)
    truth = _Truth(t, level)
    found = find_onsets(signal, RATE, config=now).t
    before = find_onsets(signal, RATE, config=then).t
    assert np.min(np.abs(found - note)) < 1e-3 and np.min(np.abs(before - note)) > 5e-3
    got, had = score(truth, found), score(truth, before)
    assert got["within_1ms"] == had["within_1ms"] + 1 and got["within_5ms"] == had["within_5ms"] + 1
    assert got["found"] - got["correct_5ms"] <= had["found"] - had["correct_5ms"]
    for i, j in match(t, before, 1e-3):
        assert np.min(np.abs(found - t[i])) <= abs(before[j] - t[i])
    return found, before


def test_a_ghost_notes_attack_fitted_from_2_ms_before_the_rise_is_found():
    """FluidR3's snare 38 roll with reverb (seed 0): the ghost note of 1.7621 s (-20.3 dB, 62.8 ms after its accent).
    A swell of what the mates leave 10 ms before it lifts the level its rise is read against, so the 5-ms energy
    first rises 4 dB at 1.7633 s, 1.2 ms after the note's start and 1.7 ms after the quiet attack's window's (from
    0.5 ms before it), where the fit read from 1 ms before the rise does not reach: there it fits 0.56, from 1.7616 s
    0.91-0.96 (each of the accent's mates). Read from 2 ms before (``ghost_room_reach``) it is found within 1 ms;
    from 1 ms (as before) not within 5 ms."""
    _gains(38, 1.7621, OnsetConfig(), OnsetConfig(ghost_room_reach=1e-3))


def test_a_partner_clear_of_louder_attacks_tells_a_rooms_echo_once_its_ghost_note_is_found():
    """The same roll: the room's return of 4.3427 s (148.7 ms after the accent of 4.1940 s, -31.9 dB) is refused as
    an echo (``_room_echoes``) by the sound at the same delay after the accent of 1.6993 s, the one accent of the
    roll whose next note was missed (1.7621 s, 62.8 ms after it, 20.3 dB under it); the others' ghost notes lie
    within that delay. With that note found, the partner's sound counts as clear up to its next attack less than
    ``room_partner_under_db`` (15 dB) under it: the return is refused again; with every attack ending it (120, as
    before) it is a false detection."""
    signal, t, level = _roll(38)
    truth = _Truth(t, level)
    found = find_onsets(signal, RATE).t
    before = find_onsets(signal, RATE, config=OnsetConfig(room_partner_under_db=120.0)).t
    assert np.min(np.abs(found - 4.3427)) > 5e-3 and np.min(np.abs(before - 4.3427)) < 0.5e-3
    got, had = score(truth, found), score(truth, before)
    assert got["found"] - got["correct_5ms"] == had["found"] - had["correct_5ms"] - 1
    assert got["within_1ms"] == had["within_1ms"]


def test_an_accent_with_no_layer_mate_takes_the_attacks_nearest_it_as_mates():
    """FluidR3's snare 40 roll with reverb (seed 0): the ghost note of 3.6004 s (-25.2 dB, 92.1 ms after its accent
    of 3.5083 s). That accent (velocity 95, its two layers' mix its own) correlates with no other attack by 0.999
    over its first 10 ms, so no mate takes its sound off; the accents of velocity 97-110 correlate with it 0.99
    (it is a roll's accent: within 10 dB of the loudest, none as loud for 0.2 s after it),
    and one of them scaled leaves -46 dB over the 5 ms before the note and -36 dB after, where the quiet attack fits
    0.965. With ``ghost_room_spare_likeness`` 0.99 it is found within 1 ms; with 1 (none, as before) not within
    5 ms."""
    _gains(40, 3.6004, OnsetConfig(), OnsetConfig(ghost_room_spare_likeness=1.0))
