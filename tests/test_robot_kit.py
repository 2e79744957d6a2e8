"""The kit robot: its MuJoCo scene, its contacts, the songs it plays and how they are scored per piece."""

import dataclasses
import math
from pathlib import Path

import mir_eval
import mujoco
import numpy as np
import pytest

from _cli import run
from drumstroke.compose import compose_kit
from drumstroke.errors import ParameterError
from drumstroke.kit.pieces import default_kit
from drumstroke.robot.kit import (
    ArmPlant,
    KitOnset,
    arm_inertia,
    first_seconds,
    kit_drop_test,
    kit_model,
    kit_robot,
    kit_scores,
    score_onsets,
    track_kit,
)
from drumstroke.robot.plant import Plant, SimpleJoint, contact_gains
from drumstroke.score import parse_pattern, read_score

MIDI = Path(__file__).parent / "data" / "midi"
SONGS = ["In Too Deep.mid", "Les Yeux Revolvers.mid", "d6caebd1964d9e4a3c5ea59525230e2a.mid",
         "d8faddb8596fff7abb24d78666f73e4e.mid"]  # the real songs with drums
KIT = default_kit()
ROBOT = kit_robot(KIT)


@pytest.fixture(scope="module")
def model():
    return kit_model(ROBOT)


def posed(model, joints):
    """A fresh MjData with the joints ``{name: qpos}`` set, the others clear of every pad (the sticks up, the beaters
    at rest), its derived quantities computed."""
    data = mujoco.MjData(model)
    clear = {"right.theta": 0.8, "left.theta": 0.8, "right-foot.theta": 1.0, "left-foot.theta": 1.0}
    for name, value in (clear | joints).items():
        data.qpos[model.joint(name).qposadr[0]] = value
    mujoco.mj_forward(model, data)
    return data


def at_place(hand, piece, theta):
    """A hand's joints at ``piece``'s place with its stick at ``theta`` to the horizontal (the motor's angle is
    theta less the lift)."""
    place = KIT.piece(piece).place
    return {f"{hand}.yaw": place["yaw"], f"{hand}.lift": place["lift"], f"{hand}.theta": theta - place["lift"]}


# --- the scene ------------------------------------------------------------------------------------------------------


def test_the_scene_has_two_arms_of_three_hinges_and_two_beaters(model):
    assert ROBOT.joints == ("right.yaw", "right.lift", "right.theta", "left.yaw", "left.lift", "left.theta",
                            "right-foot.theta", "left-foot.theta")
    assert [model.joint(j).name for j in range(model.njnt)] == list(ROBOT.joints)
    assert (model.nq, model.nv, model.nu) == (8, 8, 8)
    assert all(model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE for j in range(model.njnt))
    for hand in ("right", "left"):  # ranges from the kit's limits
        for joint, limits in KIT.limbs[hand].items():
            assert tuple(model.joint(f"{hand}.{joint}").range) == (limits.theta_low, limits.theta_high)
    assert sorted(model.geom(g).name for g in range(model.ngeom) if model.geom(g).name.startswith("pad:")) == sorted(
        f"pad:{name}" for name in ("snare", "hihat", "tom1", "tom2", "floor-tom", "ride", "ride-bell", "crash",
                                   "right-foot", "left-foot"))


def test_the_positioning_joints_inertia_is_mujocos_mass_matrix_at_level(model):
    """arm_inertia (the laws' feedforward and gain scaling, the simple engine) against MuJoCo's own mass matrix."""
    data = posed(model, {"right.theta": 0.0})
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, full)
    for joint in ("yaw", "lift"):
        inertia, _ = arm_inertia(ROBOT.arm, KIT.stick, joint)
        dof = model.joint(f"right.{joint}").dofadr[0]
        assert full[dof, dof] == pytest.approx(inertia, rel=1e-9)
    theta = model.joint("right.theta").dofadr[0]
    assert full[theta, theta] == pytest.approx(ROBOT.plant.inertia, rel=1e-9)  # the single joint's


def test_the_lifts_gravity_torque_is_mujocos_at_level(model):
    data = posed(model, {"right.theta": 0.0})
    _, gravity = arm_inertia(ROBOT.arm, KIT.stick, "lift")
    assert data.qfrc_bias[model.joint("right.lift").dofadr[0]] == pytest.approx(gravity, rel=1e-9)
    assert data.qfrc_bias[model.joint("right.yaw").dofadr[0]] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("piece", ["snare", "hihat", "tom1", "tom2", "floor-tom", "ride", "ride-bell", "crash"])
@pytest.mark.parametrize("hand", ["right", "left"])
def test_a_stick_lowered_onto_a_piece_at_its_place_touches_it_at_theta_max(model, hand, piece):
    """Within 1e-7 rad (0.03 µm at the tip): above it no contact, below it that piece's pad alone, MuJoCo's
    distance the tip's depth."""
    head = ROBOT.sticks[hand][piece].head
    assert head == pytest.approx(-math.asin(KIT.piece(piece).height / KIT.stick.pivot_to_tip), abs=1e-15)
    assert posed(model, at_place(hand, piece, head + 1e-7)).ncon == 0
    data = posed(model, at_place(hand, piece, head - 1e-7))
    assert data.ncon == 1
    contact = data.contact[0]
    assert {model.geom(contact.geom1).name, model.geom(contact.geom2).name} == {f"pad:{piece}", f"tip:{hand}"}
    depth = KIT.stick.pivot_to_tip * (math.sin(head) - math.sin(head - 1e-7))
    assert contact.dist == pytest.approx(-depth, rel=1e-3)


@pytest.mark.parametrize("foot", ["right-foot", "left-foot"])
def test_a_beater_meets_its_pedals_head_at_phi_head(model, foot):
    head = -ROBOT.pedal_of(foot).phi_head
    assert posed(model, {f"{foot}.theta": head + 1e-7}).ncon == 0
    data = posed(model, {f"{foot}.theta": head - 1e-7})
    assert data.ncon == 1
    assert {model.geom(data.contact[0].geom1).name, model.geom(data.contact[0].geom2).name} == {
        f"pad:{foot}", f"tip:{foot}"}


@pytest.mark.parametrize("surface", list(ROBOT.surfaces))
def test_a_drop_on_each_piece_rebounds_with_its_restitution(surface):
    """Within 2 %: the arm gives a little under the strike (the sticks rebound 0.7-1.1 % low) and the meeting falls
    within a 100 µs step; the contact lasts the plant's contact time to two steps."""
    drop = kit_drop_test(ROBOT, surface)
    assert drop.restitution == pytest.approx(ROBOT.surfaces[surface].cor, rel=0.02)
    assert drop.contact_time == pytest.approx(ROBOT.plant.contact_time, abs=2e-4)


def test_the_drop_test_names_a_surface_it_does_not_know():
    with pytest.raises(ParameterError, match="surface must be one of snare, .* got 'cowbell'"):
        kit_drop_test(ROBOT, "cowbell")


# --- the songs ------------------------------------------------------------------------------------------------------


def song(name, seconds=30.0):
    """The first ``seconds`` of a song's drum part on the shipped kit."""
    return compose_kit(first_seconds(read_score(MIDI / name, kit=KIT), seconds), KIT)


@pytest.mark.parametrize("name", SONGS + ["All The Small Things.mid", "Funkytown.mid", "Mr. Blue Sky.mid"])
def test_the_mujoco_kit_keeps_95_percent_of_a_songs_notes_on_their_piece_within_2_ms(name):
    played = track_kit(song(name), "impedance", "mujoco")
    scores = kit_scores(played)
    assert len(played.notes) > 40
    assert scores.fraction >= 0.95, [(s.piece, s.matched, s.notes) for s in scores.pieces]
    assert scores.total.extra <= 0.05 * len(played.notes)


def test_the_simple_engine_plays_a_song_too():
    scores = kit_scores(track_kit(song(SONGS[2]), "impedance", "simple"))
    assert scores.fraction >= 0.95 and scores.total.extra <= 2


def test_first_seconds_starts_the_drum_part_at_zero():
    score = read_score(MIDI / SONGS[1], kit=KIT)  # its drums come in at 78 s
    excerpt = first_seconds(score, 30.0)
    first = min(n.time for n in score.notes)
    assert first == pytest.approx(78.0)
    assert [n.time for n in excerpt.notes] == [n.time - first for n in score.notes if n.time < first + 30.0]
    assert min(n.time for n in excerpt.notes) == 0.0


# --- what was played, scored per piece -------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def short():
    piece = compose_kit(parse_pattern("tempo 120\n0 auto 100 auto kick\n0.5 auto 90 auto hihat\n"
                                      "1 auto 90 auto snare\n2 auto 100 auto floor-tom\n3 auto 100 auto crash\n"))
    return track_kit(piece, "impedance", "simple")


def test_every_note_of_a_short_part_is_struck_on_its_piece(short):
    scores = kit_scores(short)
    assert [(s.piece, s.matched, s.notes, s.scores.extra) for s in scores.pieces] == [
        ("snare", 1, 1, 0), ("kick", 1, 1, 0), ("hihat", 1, 1, 0), ("floor-tom", 1, 1, 0), ("crash", 1, 1, 0)]
    assert scores.fraction == 1.0
    for joint, angles in short.angles.items():  # every joint followed its reference
        assert np.max(np.abs(angles - short.reference[joint])) < 0.02, joint


def test_an_onset_on_the_wrong_piece_is_counted_wrong(short):
    onsets = list(short.onsets)
    k = next(i for i, o in enumerate(onsets) if o.piece == "snare")
    onsets[k] = onsets[k]._replace(piece="tom1")  # the same stroke, at the same time, on the tom next to the snare
    scores = kit_scores(dataclasses.replace(short, onsets=tuple(onsets)))
    assert scores.piece("snare").matched == 0 and scores.piece("snare").scores.missed == 1
    assert scores.piece("tom1").scores.extra == 1 and scores.piece("tom1").notes == 0
    assert scores.fraction == pytest.approx(4 / 5)
    assert scores.total.extra == 1


def test_a_note_struck_outside_the_window_is_missed():
    notes = [(1.0, "snare", 0.0)]
    assert score_onsets(notes, [KitOnset(1.0019, "snare", "left", 1.0)]).fraction == 1.0
    assert score_onsets(notes, [KitOnset(1.0021, "snare", "left", 1.0)]).fraction == 0.0
    assert score_onsets(notes, [KitOnset(1.0, "tom1", "left", 1.0)]).fraction == 0.0


def test_each_pieces_f_measure_is_mir_evals(rng):
    notes, onsets = [], []
    for piece in ("snare", "kick", "hihat"):
        times = np.sort(rng.uniform(0.0, 10.0, 40))
        notes += [(t, piece, 0.0) for t in times]
        kept = times[rng.random(40) < 0.8]
        struck = np.sort(np.concatenate((kept + rng.normal(0.0, 0.0015, len(kept)), rng.uniform(0.0, 10.0, 5))))
        onsets += [KitOnset(t, piece, "right", 1.0) for t in struck]
    scores = score_onsets(notes, onsets, window=0.002)
    for s in scores.pieces:
        ref = np.array([n[0] for n in notes if n[1] == s.piece])
        est = np.array([o.t for o in onsets if o.piece == s.piece])
        f, p, r = mir_eval.onset.f_measure(ref, est, window=0.002)
        assert (s.scores.f_measure, s.scores.precision, s.scores.recall) == pytest.approx((f, p, r), abs=1e-12)


# --- the simple joint's head, moved --------------------------------------------------------------------------------


def test_a_simple_joint_meets_a_head_only_where_it_is_put():
    plant = Plant()
    joint = SimpleJoint(plant, stiffness=0.0, damping=0.0, theta0=0.0)
    joint.set_head(None, 0.0, 0.0)
    for _ in range(400):
        joint.advance(0.0, 1e-3)
    assert len(joint.contacts()) == 0 and joint.theta < plant.head  # fell through where there is none
    joint.set_head(plant.head, *contact_gains(plant, 0.86))  # the head put back: as if it had always been there
    fresh = SimpleJoint(plant, 0.86, theta0=0.0)
    joint = SimpleJoint(plant, stiffness=0.0, damping=0.0, theta0=0.0)
    joint.set_head(plant.head, *contact_gains(plant, 0.86))
    for _ in range(400):
        joint.advance(0.0, 1e-3)
        fresh.advance(0.0, 1e-3)
    assert len(joint.contacts()) > 1
    np.testing.assert_array_equal(joint.contacts().t, fresh.contacts().t)
    with pytest.raises(ParameterError, match="head must be in"):
        joint.set_head(2.0, 0.0, 0.0)


# --- bad input ------------------------------------------------------------------------------------------------------


def test_bad_input_is_refused_by_name(short):
    piece = short.composition
    with pytest.raises(ParameterError, match="composition must be a drumstroke.compose.KitComposition"):
        track_kit("song.mid")
    with pytest.raises(ParameterError, match="engine must be one of simple, mujoco, got 'bullet'"):
        track_kit(piece, engine="bullet")
    with pytest.raises(ParameterError, match="controller must be one of pi, pid-ff, impedance or a Controller"):
        track_kit(piece, "pd")
    with pytest.raises(ParameterError, match=r"seconds must be in \(0, \d\.\d+\] s, got 0"):
        track_kit(piece, engine="simple", seconds=0.0)
    with pytest.raises(ParameterError, match=r"arm.reach must be in \(0, 2\] m, got -1"):
        ArmPlant(reach=-1.0)
    with pytest.raises(ParameterError, match="window must be in"):
        kit_scores(short, window=0.0)
    with pytest.raises(ParameterError, match="played must be a drumstroke.robot.kit.KitPlayed"):
        kit_scores(piece)
    with pytest.raises(ParameterError, match=r"seconds must be in \(0, inf\) s, got -1"):
        first_seconds(read_score(MIDI / SONGS[1], kit=KIT), -1.0)


def test_the_command_prints_each_pieces_figures(tmp_path):
    report = tmp_path / "kit.json"
    done = run("robot", "track", MIDI / SONGS[3], "--kit", "--seconds", "5", "--engine", "simple", "--controller",
               "impedance", "--report", report)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert "the first 5 s of its drum part on the shipped kit" in lines[0]
    assert lines[1].startswith("impedance on the simple engine at 1000 Hz: ")
    assert [line.split()[:3] for line in lines[3:6]] == [["ride", "2", "2"], ["crash", "9", "9"], ["all", "11", "11"]]
    assert lines[6] == f"wrote {report}"
    assert report.exists()


@pytest.mark.parametrize(("args", "message"), [
    (["--kit", "--seconds", "0"], "argument --seconds: must be in (0, inf) s, got 0.0"),
    (["--kit", "--engine", "bullet"], "argument --plant/--engine: invalid choice: 'bullet'"),
    (["--kit", "--controller", "pd"], "--controller must be one of pi, pid-ff, impedance or all, got 'pd'"),
    (["--seconds", "5"], "--seconds is for a song played on the kit (--kit), got --seconds 5 without --kit"),
    (["--kit", "--stick", "left"], "--stick is for one stroke, not a song on the kit (--kit), got --stick left"),
])
def test_the_command_refuses_bad_options_and_writes_nothing(tmp_path, args, message):
    report = tmp_path / "kit.json"
    done = run("robot", "track", MIDI / SONGS[3], *args, "--report", report)
    assert done.returncode == 2
    assert message in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert not report.exists()
