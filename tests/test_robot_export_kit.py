"""A kit's trajectory, every joint of every limb: read back, validated and exported (CSV, ROS 2 JSON, rosbag2)."""

import json
import re
from fractions import Fraction
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

from _cli import assert_one_line_error, run
from drumstroke.compose import compose_kit
from drumstroke.errors import ParameterError, TrajectoryError
from drumstroke.formats.trajectory_csv import KitSamples, read_kit
from drumstroke.kit.pieces import default_kit
from drumstroke.palette.motion import Limits
from drumstroke.robot.export import export_csv, export_ros_json, export_rosbag
from drumstroke.robot.validate import validate_kit
from drumstroke.score import parse_pattern, read_score

MESSAGE = "trajectory_msgs/msg/JointTrajectory"
POINT = "trajectory_msgs/msg/JointTrajectoryPoint"
ROS_NAME = re.compile(r"[a-zA-Z][a-zA-Z0-9_]*")
SONG = Path(__file__).parent / "data" / "midi" / "Les Yeux Revolvers.mid"
PATTERN = """tempo 120
0 auto 100 auto kick
0 auto 90 auto hihat
0.5 auto 90 auto hihat
1 auto 110 auto
1 auto 70 left-foot hihat
1.5 auto 100 auto tom1
2 auto 120 auto crash
2 auto 127 auto kick
"""
JOINTS = ["right.yaw", "right.lift", "right.theta", "left.yaw", "left.lift", "left.theta", "right-foot.theta",
          "left-foot.theta"]


@pytest.fixture(scope="module")
def piece():
    """Both hands (yaw, lift, θ) and both feet (the kick, the hi-hat's pedal) on the shipped kit, 2 s."""
    return compose_kit(parse_pattern(PATTERN))


@pytest.fixture(scope="module")
def kit_csv(piece, tmp_path_factory):
    path = tmp_path_factory.mktemp("kit") / "piece.csv"
    piece.write_csv(path)
    return path


@pytest.fixture(scope="module")
def store():
    return get_typestore(Stores.ROS2_JAZZY)


def fields(store, msgtype):
    return [name for name, _ in store.fielddefs[msgtype][1]]


def nanoseconds(k, rate):
    """The exact time of sample k at ``rate`` Hz, in nanoseconds, rounded to the nearest."""
    return round(Fraction(k) / Fraction(rate) * 10**9)


def copy_kit(source, folder, name="copy", edit=None):
    """The kit CSV ``source`` and its JSON copied to ``folder/name``, the CSV's table edited by ``edit``."""
    table = pd.read_csv(source)
    if edit is not None:
        edit(table)
    path = folder / f"{name}.csv"
    table.to_csv(path, index=False, float_format="%.17g", na_rep="nan")
    block = json.loads(source.with_suffix(".json").read_text())
    block["csv"]["file"] = path.name
    path.with_suffix(".json").write_text(json.dumps(block))
    return path


# --- the CSV read back ---------------------------------------------------------------------------------------------

def test_the_kit_csv_reads_back_with_pandas_header_first(piece, kit_csv):
    table = pd.read_csv(kit_csv)
    t, columns = piece.sample()
    assert list(table.columns) == ["t", *JOINTS, *(f"{j}.velocity" for j in JOINTS)] == ["t", *columns]
    assert np.allclose(table["t"], t, rtol=0, atol=1e-12)
    for name, values in columns.items():
        assert np.allclose(table[name], values, rtol=0, atol=1e-12), name


def test_read_kit_gives_back_every_joint_and_the_json(piece, kit_csv):
    back = read_kit(kit_csv)
    t, columns = piece.sample()
    assert isinstance(back, KitSamples) and np.array_equal(back.t, t)
    assert list(back.positions) == JOINTS and list(back.velocities) == JOINTS
    for joint in JOINTS:
        assert np.array_equal(back.positions[joint], columns[joint])
        assert np.array_equal(back.velocities[joint], columns[f"{joint}.velocity"])
    assert back.limbs == {"right": ("yaw", "lift", "theta"), "left": ("yaw", "lift", "theta"),
                          "right-foot": ("theta",), "left-foot": ("theta",)}
    assert (back.rate, back.model, back.offset) == (1000.0, "paper", piece.offset)
    for limb in back.limbs:  # every impact of the limb, on the CSV's timeline
        assert back.hits[limb].tolist() == [h.t for h in piece.performance.hits if h.limb == limb]
    kit = default_kit()
    assert back.limits["right.yaw"] == kit.limbs["right"]["yaw"].to_dict()
    assert back.limits["left.lift"] == kit.limbs["left"]["lift"].to_dict()
    lowest = min(p.setup(piece.setup).head for p in kit.pieces if "right" in p.hands)  # the floor tom's
    assert back.limits["right.theta"] == {**Limits().to_dict(), "theta_low": lowest}
    assert back.limits["right-foot.theta"] == {"theta_low": 0.0, "theta_high": 1.0}  # the pedal's head to rest


def row_edit(row, column, value):
    def edit(table):
        table.loc[row, column] = value
    return edit


@pytest.mark.parametrize("edit, message", [
    (row_edit(5, "left.lift", np.nan), r"row 5 is not finite \(line 7, column 6 'left.lift': nan\)"),
    (row_edit(9, "right-foot.theta.velocity", np.inf),
     r"row 9 is not finite \(line 11, column 16 'right-foot.theta.velocity': inf\)"),
    (row_edit(3, "t", 0.001), r"line 5: t = 0.001 s does not come after 0.002 s \(line 4\); times must increase"),
    (lambda table: table.pop("left.theta.velocity"),
     r"has no column 'left.theta.velocity'"),
    (lambda table: table.insert(2, "right.lift.velocity", table.pop("right.lift.velocity")),
     r"has 'right.lift.velocity' as column 3, where 'right.lift' belongs"),
])
def test_a_defect_in_a_kit_csv_names_the_file_and_where(kit_csv, tmp_path, edit, message):
    path = copy_kit(kit_csv, tmp_path, edit=edit)
    if "no column" in message or "as column" in message:  # the JSON describes the CSV as it now is
        block = json.loads(path.with_suffix(".json").read_text())
        block["csv"]["columns"] = list(pd.read_csv(path, nrows=1).columns)
        path.with_suffix(".json").write_text(json.dumps(block))
    with pytest.raises(ParameterError, match=re.escape(repr(str(path))) + ".*" + message):
        read_kit(path)


def test_a_kit_csv_needs_the_json_beside_it(kit_csv, tmp_path):
    path = tmp_path / "alone.csv"
    path.write_bytes(kit_csv.read_bytes())
    with pytest.raises(ParameterError, match=r"'.*alone.csv' has no metadata beside it: '.*alone.json'"):
        read_kit(path)
    path.with_suffix(".json").write_text(json.dumps({"csv": {"file": "alone.csv", "columns": ["t", "x"]}}))
    with pytest.raises(ParameterError, match=r"describes the columns \['t', 'x'\], but the CSV beside it has"):
        read_kit(path)


# --- validation ----------------------------------------------------------------------------------------------------

def test_a_composed_song_passes_every_joint():
    kit = default_kit()
    song = compose_kit(read_score(SONG, kit=kit), kit)
    samples = song.samples()
    checked = validate_kit(samples)
    assert list(checked) == JOINTS
    for column, c in checked.items():
        assert np.array_equal(c.theta, samples.positions[column]) and len(c.t) == len(samples.t) > 200_000
        limits = c.limits
        assert limits.theta_low - 1e-9 <= c.lowest_angle <= c.highest_angle <= limits.theta_high + 1e-9, column
        if column != "right-foot.theta" and column != "left-foot.theta":
            assert c.peak_speed <= limits.max_speed and c.peak_acceleration <= limits.max_acceleration
            assert c.peak_jerk <= limits.max_jerk


def test_a_joint_tampered_beyond_its_limit_is_named(kit_csv, tmp_path):
    path = copy_kit(kit_csv, tmp_path, "yaw", row_edit(700, "right.yaw", 1.05))  # theta_high 1
    with pytest.raises(TrajectoryError, match=r"^joint 'right.yaw': sample 700: theta 1.05 rad exceeds theta_high "
                                              r"1 rad$"):
        validate_kit(read_kit(path))
    result = run("robot", "validate", path)
    assert_one_line_error(result, f"kit trajectory file {str(path)!r}: joint 'right.yaw': sample 700: theta 1.05 rad")
    path = copy_kit(kit_csv, tmp_path, "two", lambda table: (row_edit(40, "left.theta.velocity", -31.5)(table),
                                                             row_edit(900, "right.lift", -0.4)(table)))
    with pytest.raises(TrajectoryError, match=r"^2 of 8 joints fail: joint 'right.lift': sample 900: theta -0.4 rad "
                                              r"is below theta_low -0.3 rad; joint 'left.theta': sample 40: speed "
                                              r"31.5 rad/s exceeds max_speed 30 rad/s$"):
        validate_kit(read_kit(path))


def test_a_beater_is_checked_for_its_range_only(kit_csv, tmp_path):
    fast = copy_kit(kit_csv, tmp_path, "fast", row_edit(300, "right-foot.theta.velocity", 500.0))
    assert validate_kit(fast)["right-foot.theta"].peak_speed == 500.0
    behind = copy_kit(kit_csv, tmp_path, "behind", row_edit(300, "right-foot.theta", 1.01))
    with pytest.raises(TrajectoryError, match=r"joint 'right-foot.theta': sample 300: theta 1.01 rad exceeds "
                                              r"theta_high 1 rad"):
        validate_kit(behind)


@pytest.mark.parametrize("rate", [1000.0, 10_000.0, 100_000.0])
def test_an_impact_does_not_fail_at_any_rate(piece, rate):
    samples = piece.samples(rate)
    checked = validate_kit(samples)
    assert checked["right.theta"].peak_acceleration < 2000.0  # between impacts: the same at every rate
    if rate > 1000.0:  # the impacts' own finite differences grow with the rate, beyond the limits
        with pytest.raises(TrajectoryError, match=r"joint 'right.theta': sample \d+: (acceleration|jerk) "):
            validate_kit(samples._replace(hits={}))


def test_a_step_between_impacts_still_fails_at_a_high_rate(piece):
    samples = piece.samples(10_000.0)
    omega = samples.velocities["left.theta"].copy()
    omega[5000:] += 10.0  # 1e5 rad/s² at 0.5 s, no impact near
    velocities = {**samples.velocities, "left.theta": omega}
    with pytest.raises(TrajectoryError, match=r"joint 'left.theta': sample 4999: acceleration 100000 rad/s²"):
        validate_kit(samples._replace(velocities=velocities))


def test_the_sticks_limits_may_be_given(piece):
    with pytest.raises(TrajectoryError, match=r"joint 'right.theta': sample \d+: speed [\d.]+ rad/s exceeds max_speed "
                                              r"1 rad/s"):
        validate_kit(piece, limits=Limits(max_speed=1.0))


# --- ROS 2 ---------------------------------------------------------------------------------------------------------

def check_message(document, samples, store):
    """``document`` is exactly a JointTrajectory of every joint of ``samples``, every value as sampled."""
    assert list(document) == fields(store, MESSAGE)
    assert document["header"] == {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}
    names = document["joint_names"]
    assert len(names) == len(samples.positions) and len(set(names)) == len(names)
    assert all(ROS_NAME.fullmatch(name) for name in names)
    assert len(document["points"]) == len(samples.t)
    positions = np.column_stack(list(samples.positions.values()))
    velocities = np.column_stack(list(samples.velocities.values()))
    accelerations = np.vstack([np.diff(velocities, axis=0) * samples.rate, np.zeros(len(names))])
    for k, point in enumerate(document["points"]):
        assert list(point) == fields(store, POINT)
        assert point["positions"] == positions[k].tolist() and point["velocities"] == velocities[k].tolist()
        assert point["accelerations"] == accelerations[k].tolist() and point["effort"] == []
        duration = point["time_from_start"]
        assert duration["sec"] * 10**9 + duration["nanosec"] == nanoseconds(k, samples.rate)
        assert 0 <= duration["nanosec"] < 10**9


def test_the_ros_json_is_a_joint_trajectory_of_every_joint(piece, tmp_path, store):
    checked = export_ros_json(tmp_path / "piece.json", piece)
    document = json.loads((tmp_path / "piece.json").read_text())
    check_message(document, piece.samples(), store)
    assert document["joint_names"] == ["right_yaw", "right_lift", "right_theta", "left_yaw", "left_lift", "left_theta",
                                       "right_foot_theta", "left_foot_theta"]
    assert len(checked) == 8
    meta = json.loads((tmp_path / "piece.meta.json").read_text())
    assert [j["column"] for j in meta["joints"]] == JOINTS and meta["type"] == MESSAGE
    assert meta["joints"][6]["limits"] == {"theta_low": 0.0, "theta_high": 1.0}


def test_a_composition_and_its_csv_export_the_same_message(piece, kit_csv, tmp_path):
    export_ros_json(tmp_path / "a.json", piece, joint_names=[f"j{i}" for i in range(8)])
    export_ros_json(tmp_path / "b.json", read_kit(kit_csv), joint_names=[f"j{i}" for i in range(8)])
    assert (tmp_path / "a.json").read_text() == (tmp_path / "b.json").read_text()


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_the_rosbag_holds_one_joint_trajectory_of_every_joint(piece, tmp_path, store, storage):
    bag = tmp_path / "bag"
    export_rosbag(bag, piece, storage=storage)
    with Reader(bag) as reader:
        assert [c.msgtype for c in reader.connections] == [MESSAGE]
        messages = [(c.msgtype, store.deserialize_cdr(data, c.msgtype)) for c, _, data in reader.messages()]
    assert len(messages) == 1
    msgtype, message = messages[0]
    assert msgtype == MESSAGE and message.__msgtype__ == MESSAGE
    samples = piece.samples()
    assert message.joint_names == ["right_yaw", "right_lift", "right_theta", "left_yaw", "left_lift", "left_theta",
                                   "right_foot_theta", "left_foot_theta"]
    positions = np.column_stack(list(samples.positions.values()))
    velocities = np.column_stack(list(samples.velocities.values()))
    assert len(message.points) == len(samples.t)
    for k, point in enumerate(message.points):
        assert np.array_equal(point.positions, positions[k]) and np.array_equal(point.velocities, velocities[k])
        duration = point.time_from_start
        assert duration.sec * 10**9 + duration.nanosec == nanoseconds(k, samples.rate)


def test_the_kit_csv_export_adds_accelerations_and_reads_back(piece, tmp_path):
    export_csv(tmp_path / "out.csv", piece)
    table = pd.read_csv(tmp_path / "out.csv")
    assert list(table.columns)[-8:] == [f"{j}.acceleration" for j in JOINTS]
    back = read_kit(tmp_path / "out.csv")
    samples = piece.samples()
    for joint in JOINTS:
        assert np.array_equal(back.positions[joint], samples.positions[joint])
        omega = samples.velocities[joint]
        assert np.array_equal(table[f"{joint}.acceleration"], np.append(np.diff(omega) * 1000.0, 0.0))
    validate_kit(back)


def test_joint_names_are_one_ros_name_per_joint(piece, tmp_path):
    for names, message in [(["a", "b"], r"joint_names must be one name per joint \(right.yaw, .*\), got 2"),
                           ([f"j.{i}" for i in range(8)], r"joint_names must be ROS names.*got 'j.0'"),
                           ([f"{i}j" for i in range(8)], r"got '0j'")]:
        with pytest.raises(ParameterError, match=message):
            export_ros_json(tmp_path / "bad.json", piece, joint_names=names)
    with pytest.raises(ParameterError, match=r"head is not for a kit's trajectory"):
        export_rosbag(tmp_path / "bag", piece, head=-0.2)
    assert not list(tmp_path.iterdir())


# --- the command line ----------------------------------------------------------------------------------------------

def test_robot_export_writes_every_joint(kit_csv, tmp_path, store):
    result = run("robot", "export", kit_csv, "--format", "ros-json", "--out", tmp_path / "k.json", "--rosbag",
                 tmp_path / "bag", "--joint-names", ",".join(f"q{i}" for i in range(8)))
    assert result.returncode == 0, result.stderr
    document = json.loads((tmp_path / "k.json").read_text())
    check_message(document, read_kit(kit_csv), store)
    assert document["joint_names"] == [f"q{i}" for i in range(8)]
    with Reader(tmp_path / "bag") as reader:
        (connection, _, data), = list(reader.messages())
        assert store.deserialize_cdr(data, connection.msgtype).joint_names == document["joint_names"]
    for joint in JOINTS:
        assert f"  {joint} (ROS q{JOINTS.index(joint)}):" in result.stdout
    result = run("robot", "validate", kit_csv)
    assert result.returncode == 0 and result.stdout.count("\n") == 9 and "8 joints" in result.stdout


@pytest.mark.parametrize("options, needle", [
    (["--format", "ros-json", "--out", "x.json", "--joint-names", "a,b,c"],
     "--joint-names must be one name per joint (right.yaw, right.lift"),
    (["--rosbag", "bag", "--stick", "right"], "--stick names a stick of a composition CSV"),
])
def test_a_bad_export_writes_nothing(kit_csv, tmp_path, options, needle):
    result = run("robot", "export", kit_csv, *options, cwd=tmp_path)
    assert_one_line_error(result, needle)
    assert not list(tmp_path.iterdir())


def test_a_kit_csv_without_its_json_is_refused(kit_csv, tmp_path):
    path = tmp_path / "alone.csv"
    path.write_bytes(kit_csv.read_bytes())
    result = run("robot", "export", path, "--format", "csv", "--out", tmp_path / "out.csv")
    assert_one_line_error(result, "has no metadata beside it")
    assert [p.name for p in tmp_path.iterdir()] == ["alone.csv"]
    tampered = copy_kit(kit_csv, tmp_path, "tampered", row_edit(3, "left.yaw", 2.0))
    result = run("robot", "export", tampered, "--rosbag", tmp_path / "bag")
    assert_one_line_error(result, "joint 'left.yaw': sample 3: theta 2 rad exceeds theta_high 1.3 rad")
    assert not (tmp_path / "bag").exists()


def test_a_composition_exports_at_another_rate(piece, tmp_path, store):
    checked = export_ros_json(tmp_path / "fast.json", piece, rate=4000.0)
    document = json.loads((tmp_path / "fast.json").read_text())
    check_message(document, piece.samples(4000.0), store)
    assert all(c.rate == 4000.0 for c in checked)
    assert len(document["points"]) == int(piece.t_end * 4000.0 + 1e-9) + 1
    with pytest.raises(ParameterError, match=r"rate must be the kit trajectory's own, 1000 Hz, or None, got 4000"):
        export_ros_json(tmp_path / "no.json", piece.samples(), rate=4000.0)
