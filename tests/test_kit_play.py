"""The hands' performance of a kit part, checked on the exact motion itself: every played note's impact at
its time and level, on its piece (the hand at the piece's place, the stick on its surface), no jump, every
joint within its limits, the stick clear of the surfaces it passes over, the rest reported with numbers."""

import itertools
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from drumstroke.design import Setup
from drumstroke.design.planner import LEADS
from drumstroke.errors import ParameterError
from drumstroke.kit.limbs import KitNote, assign_limbs, move_time, rest_to_rest_time
from drumstroke.kit.pieces import default_kit
from drumstroke.kit.play import CLEARANCE, FOOTPRINT, THETA, play_hands
from drumstroke.palette.motion import Limits, synchronised_move

KIT = default_kit()
SETUP = Setup()
HEADS = {p.name: p.setup(SETUP).head for p in KIT.pieces if p.hands}
X = SETUP.stick.pivot_to_tip


def groove(bpm=100.0):
    """Two bars: hi-hat 8ths (velocity 80), kick on 1 and 3, snare on 2 and 4 (110); the second bar's beats
    3 and 4 a 16th-note fill (100) snare, snare, tom1, tom1, tom2, tom2, floor tom, floor tom; then the
    floor tom and the kick on the next downbeat. Returns the notes and their velocities."""
    rows = []
    for bar in range(2):
        for eighth in range(8 if bar == 0 else 4):
            beat = 4 * bar + eighth / 2
            rows.append((beat, "hihat", "closed", 80))
            if eighth in (0, 4):
                rows.append((beat, "kick", None, 100))
            if eighth in (2, 6):
                rows.append((beat, "snare", None, 110))
    fill = ["snare", "snare", "tom1", "tom1", "tom2", "tom2", "floor-tom", "floor-tom"]
    rows += [(6 + k / 4, piece, None, 100) for k, piece in enumerate(fill)]
    rows += [(8, "floor-tom", None, 110), (8, "kick", None, 110)]
    beat = 60.0 / bpm
    notes = [KitNote(0.2 + b * beat, piece, state, b) for b, piece, state, _ in rows]
    return notes, [v for *_, v in rows]


def check_motion(motion, *, clearance=CLEARANCE, footprint=FOOTPRINT, rate=1000.0):
    """The hand's motion sampled: no jump, every joint within its limits, the stick clear of every surface."""
    if motion.curve is None:
        return
    assert motion.joints == (*KIT.limbs[motion.hand], THETA)
    t, q, v = motion.sample(rate, motion.t_end + 0.2)
    dt = 1.0 / rate
    joints = [KIT.limbs[motion.hand][j] for j in motion.joints[:-1]]
    for k, limits in enumerate(joints):  # the kit's joints: range, speed, acceleration, and no jump
        assert np.all(q[:, k] >= limits.theta_low - 1e-12) and np.all(q[:, k] <= limits.theta_high + 1e-12)
        assert np.max(np.abs(v[:, k])) <= limits.max_speed * (1 + 1e-9)
        assert np.max(np.abs(np.diff(q[:, k]))) <= limits.max_speed * dt * (1 + 1e-9)
        assert np.max(np.abs(np.diff(v[:, k]))) <= limits.max_acceleration * dt * (1 + 1e-9)
    lowest = min(HEADS[p.name] for p in KIT.pieces if motion.hand in p.hands)
    assert np.all(q[:, -1] >= lowest - 1e-9) and np.all(q[:, -1] <= SETUP.limits.theta_high)
    assert np.max(np.abs(v[:, -1])) <= SETUP.limits.max_speed
    assert np.max(np.abs(np.diff(q[:, -1]))) <= SETUP.limits.max_speed * dt
    fine = np.arange(t[0], t[-1], 1e-4)  # clearance on a finer grid than the control rate's
    check_clear(motion.curve(fine)[0], clearance, footprint)


def check_clear(q, clearance, footprint):
    """At a piece's place the stick is on or above its surface; elsewhere above every surface under its yaw."""
    places = {p.name: np.array([p.place[j] for j in KIT.limbs["right"]]) for p in KIT.pieces if p.hands}
    yaw = q[:, list(KIT.limbs["right"]).index("yaw")]
    theta = q[:, -1]
    at = np.zeros(len(q), bool)
    for name, place in places.items():
        here = np.all(np.abs(q[:, :-1] - place) <= 1e-9, axis=1)
        assert np.all(theta[here] >= HEADS[name] - 1e-9), name
        at |= here
    for name, place in places.items():
        over = (np.abs(yaw - KIT.piece(name).place["yaw"]) <= footprint) & ~at
        assert np.all(theta[over] >= HEADS[name] + clearance - 1e-9), (name, np.min(theta[over] - HEADS[name]))


def check_played(performance, notes, levels):
    """Every played note's impact on the hand's curve: at its time, its level, over its piece, on its surface."""
    for hand, motion in performance.hands.items():
        played = [o for o in performance.outcomes if o.limb == hand and o.played]
        impacts = motion.curve.impacts if motion.curve is not None else np.empty(0)
        assert len(impacts) == len(played)  # every impact of the stick is a note of its hand
        for outcome in played:
            note = notes[outcome.index]
            k = int(np.argmin(np.abs(impacts - note.time)))
            t = float(impacts[k])
            assert abs(t - note.time) <= 1e-6
            assert abs(outcome.impact - note.time) <= 1e-6 and abs(outcome.impact_level - levels[outcome.index]) <= 0.01
            q, v = motion.curve(np.array([t - 1e-9, t]))
            level = 20 * math.log10(abs(v[0, -1]) * X)  # the tip's speed just before the impact, from the curve
            assert abs(level - levels[outcome.index]) <= 0.01
            assert abs(q[1, -1] - HEADS[note.piece]) <= 1e-6  # the stick on the piece's surface
            place = [KIT.piece(note.piece).place[j] for j in motion.joints[:-1]]
            # held still over it while it strikes: through the shortest throw onto it and just after
            window, _ = motion.curve(np.linspace(t - LEADS[-1], t + 0.005, 41))
            assert np.all(window[:, :-1] == place)


def test_a_groove_with_a_tom_fill_is_played_note_for_note():
    notes, velocities = groove()
    performance = play_hands(notes, KIT, velocities=velocities)
    levels = [o.level for o in performance.outcomes]
    assert performance.problems == ()
    assert [f.note.piece for f in performance.feet] == ["kick"] * 4
    by_note = {o.index: o for o in performance.outcomes}
    assert {by_note[i].limb for i, n in enumerate(notes) if n.piece == "hihat"} == {"right"}
    assert {by_note[i].limb for i, n in enumerate(notes) if n.piece == "snare" and n.beat < 6} == {"left"}
    assert {by_note[i].limb for i, n in enumerate(notes) if n.beat >= 6 and n.piece != "kick"} == {"right", "left"}
    levels = {o.index: o.level for o in performance.outcomes}
    check_played(performance, notes, levels)
    for motion in performance.hands.values():
        check_motion(motion)
    assert len(performance.hands["right"].hits) + len(performance.hands["left"].hits) == len(performance.outcomes)


def test_quiet_notes_from_piece_to_piece_lift_the_stick_over_the_surfaces_between():
    """A ghost note's stick is caught a few millimetres above the head: to move it has to lift first."""
    notes = [KitNote(0.3, "snare"), KitNote(1.0, "hihat"), KitNote(1.6, "tom2"), KitNote(2.4, "ride")]
    performance = play_hands(notes, KIT, velocities=[20] * 4, limbs=["right"] * 4)
    assert performance.problems == ()
    motion = performance.hands["right"]
    check_played(performance, notes, {o.index: o.level for o in performance.outcomes})
    check_motion(motion)
    for a, b in itertools.pairwise(notes):  # between two notes the stick rises above the surfaces' clearance
        t = np.linspace(a.time + 0.01, b.time - 0.01, 500)
        q, _ = motion.curve(t)
        moving = np.any(np.abs(np.diff(q[:, 0])) > 0)
        assert moving
        assert q[:, -1].max() >= max(HEADS[a.piece], HEADS[b.piece]) + CLEARANCE - 1e-9


def test_a_move_too_fast_for_the_joints_is_a_problem_with_the_numbers():
    notes = [KitNote(1.0, "hihat", "closed"), KitNote(1.02, "floor-tom")]
    performance = play_hands(notes, KIT, velocities=[90, 90], limbs=["right", "right"])
    first, second = performance.outcomes
    assert first.played and abs(first.impact - 1.0) <= 1e-6
    assert not second.played
    match = re.fullmatch(r"the right hand's move from 'hihat' to 'floor-tom' needs ([\d.]+) s, (-?[\d.]+) s available "
                         r"\(leaving at ([\d.]+) s, its stick's last impact at ([\d.]+) s, the throw onto the note "
                         r"released at ([\d.]+) s\)", second.problem.reason)
    assert match, second.problem.reason
    need, available, leave, impact, release = map(float, match.groups())
    assert need >= move_time(KIT, "right", "hihat", "floor-tom") - 1e-3  # at least the arm's own move
    assert impact == pytest.approx(first.impact, abs=1e-5)  # it tried leaving on the rise after the impact
    assert impact < leave < first.impact + 0.1 and release < 1.02 and available < need
    assert available == pytest.approx(release - leave, abs=1e-3)
    assert second.problem.nearest_time == pytest.approx(1.02 + need - available, rel=1e-3)
    check_motion(performance.hands["right"])
    assert len(performance.hands["right"].curve.impacts) == 1


def test_a_hand_short_of_time_leaves_on_the_rebound_not_at_the_catch():
    """The hi-hat's rebound is caught 0.157 s after its impact, too late to reach the snare 0.2 s after it: the
    move takes the stick over on its rise, at the flight's angle and speed, and both notes are played."""
    notes = [KitNote(1.0, "hihat", "closed"), KitNote(1.2, "snare")]
    performance = play_hands(notes, KIT, velocities=[90, 90], limbs=["right", "right"])
    assert [o.played for o in performance.outcomes] == [True, True]
    check_played(performance, notes, [velocity_to_level(90)] * 2)
    motion = performance.hands["right"]
    (_, hihat), _ = motion.designs
    leave = next(s.end for s in motion.curve.segments if s.source is hihat)
    assert hihat.impacts.t[-1] < leave < hihat.t_end - 0.05  # on the rise, well before the catch
    flight = hihat.state(np.array([leave - 1e-7, leave]))
    q, v = motion.curve(np.array([leave - 1e-7, leave + 1e-7]))
    assert q[:, -1] == pytest.approx(flight[0], abs=1e-5) and v[0, -1] == pytest.approx(flight[1][0], rel=1e-6)
    assert v[1, -1] == pytest.approx(flight[1][1], rel=1e-3)  # the move starts at the flight's speed: no jump
    check_motion(motion)


def test_the_synchronised_move_takes_the_slowest_joints_time_optimal_move():
    """All joints arrive together, in the closed-form time of the slowest (within the moves' 2 % margin)."""
    limits = [KIT.limbs["right"]["yaw"], KIT.limbs["right"]["lift"], Limits(theta_low=-0.5)]
    start, target = np.array([0.7, 0.25, 0.1]), np.array([-0.8, 0.0, 0.05])
    move = synchronised_move(start, target, limits)
    inside = [Limits(theta_low=-1.0, max_speed=0.98 * j.max_speed, max_acceleration=0.98 * j.max_acceleration,
                     max_jerk=0.98 * j.max_jerk) for j in limits]
    expected = max(rest_to_rest_time(b - a, j) for a, b, j in zip(start, target, inside))
    assert move.duration == pytest.approx(expected, rel=1e-9)
    t = np.linspace(0.0, move.duration, 2001)
    q, v = move.path(t)
    np.testing.assert_allclose(q[0], start, atol=1e-12)
    np.testing.assert_allclose(q[-1], target, atol=1e-9)
    np.testing.assert_allclose(v[[0, -1]], 0.0, atol=1e-9)
    for k, joint in enumerate(limits):
        assert np.max(np.abs(v[:, k])) <= joint.max_speed
        assert np.all(np.diff(q[:, k]) * np.sign(target[k] - start[k]) >= -1e-12)  # rest to rest: monotone
    assert synchronised_move([0.0], [2.0], [Limits(theta_low=-1.0, theta_high=1.0)]) is None  # out of range


def test_a_hand_without_notes_has_no_motion_and_feet_pass_through():
    notes = [KitNote(0.5, "snare"), KitNote(0.5, "kick"), KitNote(1.0, "hihat", "pedal")]
    performance = play_hands(notes, KIT, levels=[0.0, -3.0, -6.0])
    assert performance.hands["left"].curve is None and performance.hands["left"].hits == ()
    assert [(f.index, f.limb, f.level) for f in performance.feet] == [(1, "right-foot", -3.0), (2, "left-foot", -6.0)]
    assert [o.index for o in performance.outcomes] == [0]
    with pytest.raises(ParameterError, match="the left hand plays no note"):
        performance.hands["left"].sample()


def test_notes_no_limb_can_play_are_reported_with_the_assignments_reason():
    notes = [KitNote(1.0, "snare"), KitNote(1.0, "tom1"), KitNote(1.0, "tom2")]
    performance = play_hands(notes, KIT, velocities=[100] * 3)
    left_out = [o for o in performance.outcomes if not o.played]
    assert len(left_out) == 1 and left_out[0].limb is None
    assert "a third hand note at one time" in left_out[0].problem.reason


@pytest.mark.parametrize("options, match", [
    ({}, "give the notes' levels"),
    ({"levels": [0.0], "velocities": [100]}, "give the notes' levels"),
    ({"velocities": [100, 100]}, r"levels \(or velocities\) must hold one per note \(1\), got 2"),
    ({"velocities": [200]}, "velocities"),
    ({"levels": [30.0]}, "levels"),
    ({"velocities": [100], "clearance": 1.0}, r"clearance must be in \[0, 0.5\] rad, got 1.0"),
    ({"velocities": [100], "footprint": -0.1}, "footprint must be in"),
    ({"velocities": [100], "footprint": {"kick": 0.1}}, "footprint names 'kick', not a piece a hand plays"),
    ({"velocities": [100], "setup": "fast"}, "setup must be a drumstroke.design.Setup"),
    ({"velocities": [100], "limbs": ["right-foot"]}, r"given\[0\] must be a limb that plays 'snare'"),
])
def test_bad_input_is_refused_naming_the_parameter(options, match):
    with pytest.raises(ParameterError, match=match):
        play_hands([KitNote(0.5, "snare")], KIT, **options)
    with pytest.raises(ParameterError, match="kit must be a drumstroke.kit.pieces.Kit"):
        play_hands([KitNote(0.5, "snare")], "kit", velocities=[100])


def test_an_assignment_given_is_checked_against_the_notes():
    notes = [KitNote(0.5, "snare"), KitNote(1.0, "kick")]
    assignment = assign_limbs(notes, KIT)
    played = play_hands(notes, KIT, velocities=[100, 100], limbs=assignment)
    assert [o.limb for o in played.outcomes] == ["right"] and played.feet[0].limb == "right-foot"
    with pytest.raises(ParameterError, match=r"limbs must hold a limb for each of the 1 notes, got 2"):
        play_hands(notes[:1], KIT, velocities=[100], limbs=assignment)
    with pytest.raises(ParameterError, match=r"limbs\[0\] must be a limb that plays 'kick' \(right-foot\), got 'right'"):
        play_hands(notes[::-1], KIT, velocities=[100, 100], limbs=assignment)
    with pytest.raises(ParameterError, match="piece must be one of the kit's pieces"):
        play_hands([KitNote(0.5, "gong"), notes[1]], KIT, velocities=[100, 100], limbs=assignment)


def test_no_notes_are_no_motion():
    performance = play_hands([], KIT, velocities=[])
    assert performance.outcomes == () and performance.feet == ()
    assert all(motion.curve is None for motion in performance.hands.values())


HAND_PIECES = [p.name for p in KIT.pieces if p.hands]


@st.composite
def random_parts(draw):
    """Up to 8 notes on the kit's pieces (the kick too), one or two at a time, 1/8 to 1/2 s apart."""
    notes, t = [], 0.3
    for _ in range(draw(st.integers(1, 8))):
        t += draw(st.sampled_from([0.125, 0.25, 0.375, 0.5]))
        for piece in draw(st.lists(st.sampled_from(HAND_PIECES + ["kick"]), min_size=1, max_size=2, unique=True)):
            notes.append(KitNote(t, piece, "closed" if piece == "hihat" else None))
    velocities = draw(st.lists(st.integers(20, 127), min_size=len(notes), max_size=len(notes)))
    return notes, velocities


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_parts())
def test_random_parts_play_every_note_or_report_it_and_the_motion_is_sound(drawn):
    notes, velocities = drawn
    assignment = assign_limbs(notes, KIT)
    performance = play_hands(notes, KIT, velocities=velocities, limbs=assignment)
    indices = sorted([o.index for o in performance.outcomes] + [f.index for f in performance.feet])
    assert indices == list(range(len(notes)))  # every note once: a hand's outcome or a foot's note
    for outcome in performance.outcomes:
        assert outcome.limb == assignment.limbs[outcome.index]
        if not outcome.played:
            assert outcome.problem.key == outcome.index and outcome.problem.reason
    check_played(performance, notes, {o.index: o.level for o in performance.outcomes})
    for motion in performance.hands.values():
        check_motion(motion)


# --- the whole kit: the feet on their pedals -----------------------------------------------------------------------

from drumstroke.dynamics import velocity_to_foot_level, velocity_to_level  # noqa: E402
from drumstroke.kit.pedal import Pedal  # noqa: E402
from drumstroke.kit.play import play_kit  # noqa: E402


def first_arrival(curve, before, after, step=1e-6):
    """The first time in [before, after] (s) the beater leaves the head (ω turns > 0: its arrival's rebound), to
    ``step``: a grid, then bisection. Before it the press drives the beater on (ω ≤ 0)."""
    t = np.arange(before, after, step * 100)
    _, omega = curve(t)
    k = int(np.flatnonzero(omega > 1e-3)[0])  # (at rest ω is 0 to round-off)
    low, high = t[k - 1], t[k]
    while high - low > step / 10:
        mid = (low + high) / 2
        if curve(np.array([mid]))[1][0] > 1e-3:
            high = mid
        else:
            low = mid
    return high


def test_feet_notes_land_on_the_feet_curves_at_their_times_and_levels():
    """Kicks and the hi-hat's pedal, each note found on the foot's own curve: the beater reaches the head at the
    note's time (within 1e-6 s) and at its level from the speed just before (within 0.01 dB)."""
    notes = [KitNote(0.4 + 0.6 * k, "kick") for k in range(4)] + [KitNote(0.7 + 0.6 * k, "hihat", "pedal")
                                                                    for k in range(4)]
    velocities = [127, 100, 64, 20] * 2
    part = play_kit(notes, KIT, velocities=velocities)
    assert not part.problems
    pedal = Pedal()
    for outcome, velocity in zip(part.outcomes, velocities):
        motion = part.feet[outcome.limb]
        assert outcome.limb == ("right-foot" if outcome.piece == "kick" else "left-foot")
        t = first_arrival(motion.curve, outcome.note.time - 0.25, outcome.note.time + 0.01)
        assert motion.curve(np.array([t]))[0][0] == pytest.approx(-pedal.phi_head, abs=1e-5)  # at the head
        assert abs(t - outcome.note.time) <= 1e-6
        _, omega = motion.curve(np.array([outcome.note.time - 1e-9]))
        level = 20 * math.log10(abs(omega[0]) * pedal.length)
        assert level == pytest.approx(velocity_to_foot_level(velocity), abs=0.01)
        assert outcome.impact == pytest.approx(outcome.note.time, abs=1e-9)
    for motion in part.feet.values():  # within its travel, at rest before and after
        theta, _ = motion.curve(np.arange(0.0, motion.t_end + 0.5, 1e-3))
        assert np.all(theta >= -pedal.phi_head - 1e-12) and np.all(theta <= -pedal.phi_rest + 1e-12)
        assert theta[0] == -pedal.phi_rest and theta[-1] == pytest.approx(-pedal.phi_rest, abs=1e-12)


def test_a_double_kick_is_two_notes_from_the_rebound():
    notes = [KitNote(0.5, "kick"), KitNote(0.6, "kick")]
    part = play_kit(notes, KIT, velocities=[100, 100])
    assert [o.played for o in part.outcomes] == [True, True]
    design = part.feet["right-foot"].design
    assert [p.phase for p in design.pieces] == ["wait", "press", "rise", "press", "return", "wait"]
    assert [h.t for h in part.hits] == pytest.approx([0.5, 0.6], abs=1e-9)
    level = velocity_to_foot_level(100)
    assert [20 * math.log10(h.speed) for h in part.hits] == pytest.approx([level, level], abs=1e-6)


def test_foot_notes_the_pedal_cannot_play_are_reported_with_the_reason():
    """A kick 10 ms in (its press from rest takes longer), a loud double 20 ms apart, two kicks at one time."""
    notes = [KitNote(0.01, "kick"), KitNote(0.5, "kick"), KitNote(0.52, "kick"), KitNote(1.0, "kick"),
             KitNote(1.0, "kick")]
    part = play_kit(notes, KIT, velocities=[100, 127, 127, 100, 100], limbs=["right-foot"] * 5)
    played = [o.played for o in part.outcomes]
    assert played == [False, True, False, True, False]
    first, double, twice = (o.problem for o in part.outcomes if not o.played)
    assert "at rest from t = 0" in first.reason and first.nearest_time > 0.01
    assert re.search(r"needs a press of [\d.]+ N .*max_force is 300 N", double.reason)
    assert "at least 0.001 s apart" in twice.reason
    assert [h.t for h in part.hits] == pytest.approx([0.5, 1.0], abs=1e-9)


def test_the_hi_hat_states_are_recorded_with_every_hit():
    """Closed, open, closed by the hand, the pedal by the foot: each hit sounds its note's key, a bounce too."""
    notes = [KitNote(0.3, "hihat", "closed"), KitNote(0.6, "hihat", "open"), KitNote(0.9, "hihat", "closed"),
             KitNote(1.2, "hihat", "pedal")]
    part = play_kit(notes, KIT, velocities=[90, 90, 30, 90], keys=[42, 46, 42, 44])
    assert all(o.played for o in part.outcomes)
    for hit in part.hits:
        previous = max((o for o in part.outcomes if o.impact <= hit.t + 1e-12), key=lambda o: o.impact)
        assert hit.key == {"closed": 42, "open": 46, "pedal": 44}[previous.note.state]
        assert hit.piece == "hihat"
    assert [h.limb for h in part.hits if h.note >= 0] == ["right", "right", "right", "left-foot"]
    with pytest.raises(ParameterError, match=r"keys\[1\] must be a key of 'hihat' when open \(46\), got 42"):
        play_kit(notes, KIT, velocities=[90] * 4, keys=[42, 42, 42, 44])


def test_play_kit_hands_are_play_hands():
    notes, velocities = groove()
    part = play_kit(notes, KIT, velocities=velocities)
    hands = play_hands(notes, KIT, levels=[velocity_to_level(v) for v in velocities])
    assert [o for o in part.outcomes if o.limb in ("right", "left")] == list(hands.outcomes)
    assert all(o.played for o in part.outcomes)


def test_each_hi_hat_state_is_played_with_its_own_c_and_rebounds_with_it():
    """Closed, open and half-open notes on one hand are three runs, each planned on its state's surface: the
    stroke's c is the state's, and the stick leaves the cymbals at c times its arrival speed (the exact solver's
    impact law, as the state's Setup has it)."""
    notes = [KitNote(1.0, "hihat", "closed"), KitNote(1.5, "hihat", "open"), KitNote(2.0, "hihat", "half")]
    performance = play_hands(notes, KIT, velocities=[90, 90, 90], limbs=["right"] * 3)
    assert all(o.played for o in performance.outcomes)
    motion = performance.hands["right"]
    hihat = KIT.piece("hihat")
    for (name, made), state in zip(motion.designs, ("closed", "open", "half"), strict=True):
        cor = hihat.surface(state).cor
        assert name == "hihat" and made.recipe.cor == cor
        t = made.impacts.t[0]
        _, before = motion.curve(np.array([t - 1e-7]))
        _, after = motion.curve(np.array([t]))
        assert after[0, -1] == pytest.approx(-cor * before[0, -1], rel=1e-4)
    assert [hihat.surface(s).cor for s in ("closed", "half", "open")] == sorted(
        (hihat.surface(s).cor for s in ("closed", "half", "open")), reverse=True)
    check_motion(motion)
