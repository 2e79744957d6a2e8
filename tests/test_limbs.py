"""The limb assignment: grooves, fills and cymbal patterns get the sticking a drummer writes for them;
on random parts no limb is in two places at once, every move fits the joints' limits, given limbs stay."""

import itertools
import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from drumstroke.errors import ParameterError
from drumstroke.kit.limbs import Costs, KitNote, assign_limbs, kit_notes, move_time, rest_to_rest_time
from drumstroke.kit.pieces import HANDS, Kit, default_kit
from drumstroke.palette.motion import Limits

KIT = default_kit()
R, L, RF, LF = "right", "left", "right-foot", "left-foot"


def part(rows, bpm=100.0, *, beats=True):
    """Notes from (beat, piece) or (beat, piece, state) rows at ``bpm``, with their beats (or without)."""
    notes = []
    for row in rows:
        beat, piece, state = (*row, None)[:3]
        notes.append(KitNote(beat * 60.0 / bpm, piece, state, beat if beats else None))
    return notes


def groove(bars=2):
    """8th-note hi-hat, kick on 1 and 3, snare on 2 and 4."""
    rows = []
    for bar in range(bars):
        for eighth in range(8):
            beat = 4 * bar + eighth / 2
            rows.append((beat, "hihat", "closed"))
            if eighth in (0, 4):
                rows.append((beat, "kick"))
            if eighth in (2, 6):
                rows.append((beat, "snare"))
    return rows


def limbs_of(notes, **options):
    result = assign_limbs(notes, KIT, **options)
    assert result.problems == ()
    return [(row.piece, limb) for row, limb in zip(notes, result.limbs)]


@pytest.mark.parametrize("beats", [True, False])
def test_a_groove_is_hi_hat_right_snare_left_kick_right_foot(beats):
    assigned = limbs_of(part(groove(), beats=beats))
    assert {limb for piece, limb in assigned if piece == "hihat"} == {R}
    assert {limb for piece, limb in assigned if piece == "snare"} == {L}
    assert {limb for piece, limb in assigned if piece == "kick"} == {RF}


@pytest.mark.parametrize("bpm", [90.0, 100.0, 120.0])
def test_a_16th_note_fill_around_the_toms_alternates_starting_right(bpm):
    pieces = ["snare"] * 4 + ["tom1"] * 4 + ["tom2"] * 4 + ["floor-tom"] * 4
    assigned = limbs_of(part([(k / 4, piece) for k, piece in enumerate(pieces)], bpm))
    assert [limb for _, limb in assigned] == [R, L] * 8


def test_a_ride_pattern_is_the_right_hand_with_the_hi_hat_pedal_on_2_and_4_on_the_left_foot():
    rows = []
    for bar in range(2):  # the jazz ride: 1, 2, 2-and (swung), 3, 4, 4-and; the hi-hat's foot on 2 and 4
        for beat in (0, 1, 1 + 2 / 3, 2, 3, 3 + 2 / 3):
            rows.append((4 * bar + beat, "ride"))
        for beat in (1, 3):
            rows.append((4 * bar + beat, "hihat", "pedal"))
        rows.append((4 * bar, "kick"))
    assigned = limbs_of(part(rows, 160.0))
    assert {limb for piece, limb in assigned if piece == "ride"} == {R}
    assert {limb for piece, limb in assigned if piece == "hihat"} == {LF}
    assert {limb for piece, limb in assigned if piece == "kick"} == {RF}


def test_a_crash_with_the_hi_hat_going_on_is_the_free_left_hand():
    rows = groove(1) + [(4.0, "crash"), (4.0, "kick"), (4.0, "hihat", "closed"), (4.5, "hihat", "closed")]
    assigned = limbs_of(part(rows))
    assert assigned[-4:] == [("crash", L), ("kick", RF), ("hihat", R), ("hihat", R)]


def test_a_crash_after_a_fill_is_the_hand_that_can_get_there():
    # the fill ends R L on the floor tom: the left hand, 0.15 s before the crash, cannot reach it (0.15 s is
    # too short), the right hand (0.3 s) can
    pieces = ["snare"] * 4 + ["tom1"] * 4 + ["tom2"] * 4 + ["floor-tom"] * 4
    rows = [(k / 4, piece) for k, piece in enumerate(pieces)] + [(4.0, "crash"), (4.0, "kick")]
    assigned = limbs_of(part(rows))
    assert move_time(KIT, L, "floor-tom", "crash") > 0.15
    assert assigned[-2:] == [("crash", R), ("kick", RF)]
    assert [limb for _, limb in assigned[:16]] == [R, L] * 8


def mirrored(kit):
    """The kit for a left-handed drummer: every place mirrored (yaw negated), the hands' joints swapped,
    and each foot's pieces the other foot's."""
    swap = {R: L, L: R, RF: LF, LF: RF}

    def flip(limits):
        return replace(limits, theta_low=-limits.theta_high, theta_high=-limits.theta_low)

    limbs = {swap[limb]: {joint: flip(limits) if joint == "yaw" else limits for joint, limits in joints.items()}
             for limb, joints in kit.limbs.items()}
    pieces = tuple(replace(piece, limbs=tuple(swap[limb] for limb in piece.limbs),
                           place={**piece.place, "yaw": -piece.place["yaw"]} if piece.place else {})
                   for piece in kit.pieces)
    return Kit(pieces, limbs, stick=kit.stick)


def test_a_left_handed_drummer_on_a_mirrored_kit_plays_the_mirror_image():
    swap = {R: L, L: R, RF: LF, LF: RF}
    pieces = ["snare"] * 4 + ["tom1"] * 4 + ["tom2"] * 4 + ["floor-tom"] * 4
    rows = groove(1) + [(4 + k / 4, piece) for k, piece in enumerate(pieces)] + [(8.0, "crash"), (8.0, "kick")]
    notes = part(rows)
    right_handed = assign_limbs(notes, KIT)
    left_handed = assign_limbs(notes, mirrored(KIT), lead="left")
    assert right_handed.problems == left_handed.problems == ()
    assert left_handed.limbs == tuple(swap[limb] for limb in right_handed.limbs)
    assert math.isclose(left_handed.cost, right_handed.cost)


def test_a_left_lead_on_the_right_handed_kit_keeps_time_with_the_left_hand():
    assigned = limbs_of(part(groove()), lead="left")
    assert {limb for piece, limb in assigned if piece == "hihat"} == {L}
    assert {limb for piece, limb in assigned if piece == "snare"} == {R}


def test_open_handed_the_left_hand_plays_the_hi_hat_and_the_right_the_snare_only_when_asked():
    closed = limbs_of(part(groove()))
    opened = limbs_of(part(groove()), open_handed=True)
    assert {limb for piece, limb in closed if piece == "hihat"} == {R}
    assert {limb for piece, limb in opened if piece == "hihat"} == {L}
    assert {limb for piece, limb in opened if piece == "snare"} == {R}
    ride = part([(k / 2, "ride") for k in range(8)] + [(1.0, "snare"), (3.0, "snare")])
    assert {limb for piece, limb in limbs_of(ride, open_handed=True) if piece == "ride"} == {R}


def test_a_third_hand_note_at_one_time_is_a_problem_with_its_reason():
    notes = part([(0, "snare"), (0, "tom1"), (0, "crash"), (1, "snare")])
    result = assign_limbs(notes, KIT)
    assert sum(limb is None for limb in result.limbs) == 1
    (index, reason), = result.problems
    assert result.limbs[index] is None and "third hand note" in reason
    assert sorted(limb for limb in result.limbs[:3] if limb) == [L, R]


def test_a_move_faster_than_the_joints_allow_is_a_problem_with_its_reason():
    # hi-hat and snare with both hands, then 20 ms later the floor tom: no hand can play all three
    notes = part([(0, "hihat", "closed"), (0, "snare"), (0.02 / 0.6, "floor-tom")])
    result = assign_limbs(notes, KIT)
    (index, reason), = result.problems
    assert result.limbs[index] is None and sorted(filter(None, result.limbs)) == [L, R]
    assert "needs" in reason and "and has 0.02 s" in reason


def test_given_limbs_are_kept_even_against_the_drummers_way():
    notes = part(groove(1))
    given = [L if n.piece == "hihat" else None for n in notes]
    result = assign_limbs(notes, KIT, given=given)
    assert [limb for n, limb in zip(notes, result.limbs) if n.piece == "hihat"] == [L] * 8
    assert {limb for n, limb in zip(notes, result.limbs) if n.piece == "snare"} == {R}
    assert result.problems == ()


def test_a_given_move_that_is_too_fast_is_kept_and_reported():
    notes = part([(0, "hihat", "closed"), (0.02 / 0.6, "floor-tom")])
    result = assign_limbs(notes, KIT, given=[R, R])
    assert result.limbs == (R, R)
    assert result.reasons[0] is None and "given" in result.reasons[1]


def test_kit_notes_map_keys_and_report_the_unanswered():
    notes, unanswered = kit_notes([0.0, 0.0, 0.3, 0.6], [42, 36, 44, 81], KIT, beats=[0, 0, 0.5, 1])
    assert notes == [KitNote(0.0, "hihat", "closed", 0.0), KitNote(0.0, "kick", None, 0.0),
                     KitNote(0.3, "hihat", "pedal", 0.5)]
    assert unanswered == [3]
    assert assign_limbs(notes, KIT).limbs == (R, RF, LF)


def test_bad_input_is_refused_naming_the_parameter():
    with pytest.raises(ParameterError, match=r"notes\[0\]\.piece"):
        assign_limbs([KitNote(0.0, "cowbell")], KIT)
    with pytest.raises(ParameterError, match=r"given\[0\] must be a limb that plays 'kick'"):
        assign_limbs([KitNote(0.0, "kick")], KIT, given=[R])
    with pytest.raises(ParameterError, match=r"notes\[0\]\.state"):
        assign_limbs([KitNote(0.0, "snare", "open")], KIT)
    with pytest.raises(ParameterError, match="lead must be one of"):
        assign_limbs([], KIT, lead="both")
    with pytest.raises(ParameterError, match=r"costs\.comfort"):
        Costs(comfort=0.0)
    assert assign_limbs([], KIT).limbs == ()


@pytest.mark.parametrize("distance", [1e-4, 0.01, 0.1, 0.3, 0.6, 1.0, 1.6, 3.0])
@pytest.mark.parametrize("limits", [Limits(max_speed=12.0, max_acceleration=400.0, max_jerk=2e4),
                                    Limits(max_speed=8.0, max_acceleration=300.0, max_jerk=1.5e4),
                                    Limits(max_speed=1.0, max_acceleration=400.0, max_jerk=2e4),
                                    Limits(max_speed=30.0, max_acceleration=50.0, max_jerk=1e6)])
def test_the_rest_to_rest_time_is_ruckigs_time_optimal_move(distance, limits):
    ruckig = pytest.importorskip("ruckig")
    parameters = ruckig.InputParameter(1)
    parameters.current_position, parameters.current_velocity, parameters.current_acceleration = [0.0], [0.0], [0.0]
    parameters.target_position, parameters.target_velocity, parameters.target_acceleration = [distance], [0.0], [0.0]
    parameters.max_velocity = [limits.max_speed]
    parameters.max_acceleration = [limits.max_acceleration]
    parameters.max_jerk = [limits.max_jerk]
    trajectory = ruckig.Trajectory(1)
    ruckig.Ruckig(1).calculate(parameters, trajectory)
    assert rest_to_rest_time(distance, limits) == pytest.approx(trajectory.duration, rel=1e-9, abs=1e-12)
    assert rest_to_rest_time(-distance, limits) == rest_to_rest_time(distance, limits)


# --- properties on random parts of the default kit ---------------------------------------------------------

PIECES = [(piece.name, state) for piece in KIT.pieces for state in (dict.fromkeys(piece.states.values()) or [None])]


@st.composite
def random_parts(draw):
    """Up to 60 notes on a grid of 1/48 s (some at one time), any piece, some with a given limb."""
    count = draw(st.integers(0, 60))
    ticks = sorted(draw(st.lists(st.integers(0, 400), min_size=count, max_size=count)))
    notes, given = [], []
    for tick in ticks:
        name, state = draw(st.sampled_from(PIECES))
        notes.append(KitNote(tick / 48.0, name, state, draw(st.none() | st.just(tick / 24.0))))
        limbs = KIT.piece(name).limbs_for(state)
        given.append(draw(st.none() | st.none() | st.none() | st.sampled_from(limbs)))
    return notes, given


def check_assignment(notes, given, result):
    assert len(result.limbs) == len(notes) == len(result.reasons)
    for i, note in enumerate(notes):
        # every note has a limb, or a reason it is not played; a given limb is never changed
        assert result.limbs[i] is not None or result.reasons[i]
        if given[i] is not None:
            assert result.limbs[i] == given[i]
        if result.limbs[i] is not None:
            assert result.limbs[i] in KIT.piece(note.piece).limbs_for(note.state)
    # the notes each limb plays: those without a reason, and those given a limb too fast (played all the same)
    played = sorted((note.time, i) for i, note in enumerate(notes) if result.limbs[i] is not None
                    and (result.reasons[i] is None or "needs" in result.reasons[i]))
    for limb in KIT.limbs:
        mine = [(t, i) for t, i in played if result.limbs[i] == limb]
        for (t0, i0), (t1, i1) in itertools.pairwise(mine):
            assert t1 - t0 > 0.001, (limb, notes[i0], notes[i1])  # no limb plays two notes at one time
            if limb in HANDS and notes[i0].piece != notes[i1].piece and result.reasons[i1] is None:
                # every hand move fits in the time between the hand's notes within its joints' limits
                assert move_time(KIT, limb, notes[i0].piece, notes[i1].piece) <= t1 - t0 + 1e-9


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_parts(), st.sampled_from(HANDS), st.booleans())
def test_random_parts_are_assigned_consistently(drawn, lead, open_handed):
    notes, given_limbs = drawn
    check_assignment(notes, [None] * len(notes), assign_limbs(notes, KIT, lead=lead, open_handed=open_handed))
    check_assignment(notes, given_limbs, assign_limbs(notes, KIT, lead=lead, open_handed=open_handed,
                                                      given=given_limbs))


@settings(max_examples=60, deadline=None)
@given(random_parts())
def test_giving_the_assigned_limbs_back_changes_nothing(drawn):
    notes, _ = drawn
    first = assign_limbs(notes, KIT)
    again = assign_limbs(notes, KIT, given=first.limbs)
    assert again.limbs == first.limbs and again.reasons == first.reasons
    assert again.cost == pytest.approx(first.cost)


def test_the_notes_order_does_not_matter(rng):
    notes = part(groove(2))
    order = rng.permutation(len(notes))
    shuffled = assign_limbs([notes[i] for i in order], KIT)
    assert [shuffled.limbs[list(order).index(i)] for i in range(len(notes))] == list(assign_limbs(notes, KIT).limbs)


def test_the_dynamic_programme_finds_the_cheapest_assignment_of_a_short_part(rng):
    """Against every assignment of the hands, tried one by one (a part of 9 notes: 2^9 tries)."""
    names = ["snare", "tom1", "tom2", "floor-tom", "hihat", "crash", "ride"]
    for _ in range(5):
        times = np.cumsum(rng.choice([0.1, 0.15, 0.2, 0.3], size=9))
        notes = [KitNote(float(t), str(rng.choice(names)), None) for t in times]
        notes = [n._replace(state="closed") if n.piece == "hihat" else n for n in notes]
        best = assign_limbs(notes, KIT)
        costs = []
        for hands in itertools.product(HANDS, repeat=len(notes)):
            tried = assign_limbs(notes, KIT, given=hands)
            if tried.problems == ():
                costs.append(tried.cost)
        assert best.problems == () and best.cost == pytest.approx(min(costs))
