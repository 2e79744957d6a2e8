"""Real songs' whole drum parts on the shipped kit: every note played on time, at its level, on its piece, or
reported with a reason; and nearly all the notes two hands and two feet can play are played.

Every General MIDI file in ``tests/data/midi`` with notes on channel 10 is composed once, with default options.
The checks are against the file (read with mido here, not by drumstroke) and against the limbs' exact motions
themselves, not only the performance's own account of each note: a hand's curve must put the stick's
positioning joints at the piece's place and θ on its surface at the impact, coming down onto it; a foot's
beater must reach its pedal's head.
"""

from collections import Counter, namedtuple
from pathlib import Path

import numpy as np
import pytest

from _midi import read_with_mido
from drumstroke.compose import compose_kit
from drumstroke.design.setup import Setup
from drumstroke.dynamics import velocity_to_foot_level, velocity_to_level
from drumstroke.kit.pieces import FEET, HANDS, default_kit
from drumstroke.kit.play import kit_pedals
from drumstroke.score import read_score

DATA = Path(__file__).resolve().parent / "data" / "midi"
DRUMS = 9  # General MIDI's channel 10, counted from 0 as mido counts
SIMULTANEOUS = 1e-3  # s: notes this close are played at one time (the limb assignment's default)
BEFORE = 1e-6  # s before an impact, where the stick (or the beater) is still coming down
THIRD_HAND = "a third hand note at one time"
NO_FOOT = "no foot is free"
PLAYED_OF_PLAYABLE = 0.95


def drum_notes(path):
    """The file's channel-10 notes, as mido reads them: dicts with time (s), note (key) and velocity."""
    return [note for note in read_with_mido(path)[4] if note["channel"] == DRUMS]


SONGS = sorted(path.name for path in DATA.glob("*.mid") if drum_notes(path))

Song = namedtuple("Song", "name kit score piece drums")


@pytest.fixture(scope="module", params=SONGS)
def song(request):
    """One song composed on the shipped kit with default options, and its drum notes as mido reads them."""
    path = DATA / request.param
    kit = default_kit()
    score = read_score(path, kit=kit)
    return Song(request.param, kit, score, compose_kit(score), drum_notes(path))


def outcomes_with_notes(song):
    """Each note's outcome with its score note (the composition keeps the score's order when it plays every piece)."""
    outcomes = song.piece.performance.outcomes
    assert len(outcomes) == len(song.score.notes), song.name
    return list(zip(outcomes, song.score.notes, strict=True))


def where(song, outcome, note):
    return f"{song.name}: note {outcome.index} ({note.source}, {outcome.piece}, limb {outcome.limb})"


def by_key_and_velocity(notes):
    """{(key, velocity): sorted times (s)} of ``(time, key, velocity)`` triples."""
    grouped = {}
    for time, key, velocity in notes:
        grouped.setdefault((key, velocity), []).append(time)
    return {k: np.sort(times) for k, times in grouped.items()}


def test_the_score_holds_every_note_the_kit_answers(song):
    answered = by_key_and_velocity((n["time"], n["note"], n["velocity"]) for n in song.drums
                                   if song.kit.piece_for_key(n["note"]) is not None)
    read = by_key_and_velocity((n.time, n.key, n.velocity) for n in song.score.notes)
    assert read.keys() == answered.keys(), f"{song.name}: (key, velocity) pairs {sorted(read ^ answered.keys())}"
    for pair, times in answered.items():
        assert len(read[pair]) == len(times), f"{song.name}: key {pair[0]} at velocity {pair[1]}"
        assert np.allclose(read[pair], times, rtol=0.0, atol=1e-9), f"{song.name}: key {pair[0]} at velocity {pair[1]}"
    keys = song.piece.performance.keys
    for outcome, note in outcomes_with_notes(song):
        assert outcome.piece == song.kit.piece_for_key(note.key)[0].name == note.piece, where(song, outcome, note)
        assert keys[outcome.index] == note.key, where(song, outcome, note)
        assert outcome.note.time == pytest.approx(note.time + song.piece.offset, abs=1e-9), where(song, outcome, note)


def test_every_note_is_played_or_reported_with_a_reason(song):
    for outcome, note in outcomes_with_notes(song):
        if outcome.played:
            assert outcome.impact is not None and outcome.limb is not None, where(song, outcome, note)
        else:
            reason = outcome.problem.reason
            assert isinstance(reason, str) and reason.strip(), where(song, outcome, note)


def test_every_played_note_lands_on_time_at_its_velocitys_level(song):
    for outcome, note in outcomes_with_notes(song):
        if not outcome.played:
            continue
        time = note.time + song.piece.offset
        assert abs(outcome.impact - time) <= 1e-3, f"{where(song, outcome, note)}: impact {outcome.impact} s"
        level = (velocity_to_foot_level if outcome.limb in FEET else velocity_to_level)(note.velocity)
        assert abs(outcome.impact_level - level) <= 1.5, \
            f"{where(song, outcome, note)}: {outcome.impact_level:.3f} dB for velocity {note.velocity} ({level:.3f} dB)"


def test_every_hand_note_is_struck_on_its_piece_by_the_hands_curve(song):
    performance = song.piece.performance
    pairs = [(o, n) for o, n in outcomes_with_notes(song) if o.played and o.limb in HANDS]
    for hand in HANDS:
        mine = [(o, n) for o, n in pairs if o.limb == hand]
        if not mine:
            continue
        motion = performance.hands[hand]
        assert motion.joints[-1] == "theta", song.name
        impacts = np.array([o.impact for o, _ in mine])
        at, _ = motion.curve(impacts)
        before, _ = motion.curve(impacts - BEFORE)
        for k, (outcome, note) in enumerate(mine):
            piece = song.kit.piece(outcome.piece)
            place = [piece.place[joint] for joint in motion.joints[:-1]]
            head = piece.setup(Setup()).head
            assert np.allclose(at[k, :-1], place, rtol=0.0, atol=1e-9), \
                f"{where(song, outcome, note)}: joints {at[k, :-1]} at the impact, the piece's place {place}"
            assert abs(at[k, -1] - head) <= 1e-9, \
                f"{where(song, outcome, note)}: θ {at[k, -1]!r} at the impact, the surface at {head!r} rad"
            assert before[k, -1] > head, \
                f"{where(song, outcome, note)}: θ {before[k, -1]!r} {BEFORE:g} s before the impact, surface {head!r}"


def test_every_foot_note_brings_the_beater_onto_its_pedals_head(song):
    performance = song.piece.performance
    pedals = kit_pedals(None, song.kit)
    pairs = [(o, n) for o, n in outcomes_with_notes(song) if o.played and o.limb in FEET]
    for foot in FEET:
        mine = [(o, n) for o, n in pairs if o.limb == foot]
        if not mine:
            continue
        motion = performance.feet[foot]
        head = -pedals[motion.pedal].phi_head  # θ = −φ: the head bounds θ from below
        for outcome, note in mine:
            assert song.kit.piece(outcome.piece).pedal == motion.pedal, where(song, outcome, note)
        impacts = np.array([o.impact for o, _ in mine])
        at = np.reshape(motion.curve(impacts)[0], len(mine))
        before = np.reshape(motion.curve(impacts - BEFORE)[0], len(mine))
        for k, (outcome, note) in enumerate(mine):
            assert abs(at[k] - head) <= 1e-9, f"{where(song, outcome, note)}: beater at {at[k]!r} rad, head {head!r}"
            assert before[k] > head, f"{where(song, outcome, note)}: beater at {before[k]!r} rad just before"


def limbs_of(outcome, kit):
    """The limbs that may play a note's piece in its state."""
    return kit.piece(outcome.piece).limbs_for(outcome.note.state)


def test_the_notes_left_for_want_of_a_limb_have_no_limb_free(song):
    outcomes = song.piece.performance.outcomes
    times = np.array([o.note.time for o in outcomes])
    for outcome, note in outcomes_with_notes(song):
        if outcome.played:
            continue
        at_once = [outcomes[i] for i in np.flatnonzero(np.abs(times - outcome.note.time) <= SIMULTANEOUS + 1e-9)]
        if outcome.problem.reason.startswith(THIRD_HAND):
            hands_only = [o for o in at_once if not set(limbs_of(o, song.kit)) - set(HANDS)]
            assert len(hands_only) >= 3, f"{where(song, outcome, note)}: {len(hands_only)} hand notes at its time"
        elif outcome.problem.reason.startswith(NO_FOOT):
            busy = {o.limb for o in at_once if o.played and o.limb in FEET}
            assert set(limbs_of(outcome, song.kit)) <= busy, \
                f"{where(song, outcome, note)}: feet playing at its time {sorted(busy)}"


def test_nearly_every_note_two_hands_and_two_feet_can_play_is_played(song):
    playable = [o for o in song.piece.performance.outcomes
                if o.played or not o.problem.reason.startswith((THIRD_HAND, NO_FOOT))]
    played = sum(o.played for o in playable)
    reasons = Counter(o.problem.reason.split(" needs ")[0] for o in playable if not o.played)
    assert played >= PLAYED_OF_PLAYABLE * len(playable), \
        f"{song.name}: {played} of {len(playable)} playable notes played ({played / len(playable):.1%}); " \
        f"the others: {reasons.most_common(3)}"
