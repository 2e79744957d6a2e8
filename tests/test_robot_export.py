"""Export: validated first, written atomically, and read back exactly (CSV and ROS JointTrajectory JSON)."""

import dataclasses
import json
import os
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
import yaml
from rosbags.interfaces import Nodetype
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

import drumstroke
from drumstroke._version import __version__
from drumstroke.errors import ParameterError, SampledImpactsWarning, TrajectoryError
from drumstroke.model import Stick
from drumstroke.palette.library import read_palette
from drumstroke.palette.motion import Limits
from drumstroke.robot.export import export_csv, export_ros_json, export_rosbag, read_ros_json, seconds_to_duration
from drumstroke.robot.validate import validate_file
from drumstroke.trajectory import Trajectory

RATE = 1000.0
HEAD = Stick().theta_max
MESSAGE = "trajectory_msgs/msg/JointTrajectory"
INTEGERS = {"int32": (-(2**31), 2**31), "uint32": (0, 2**32)}


@pytest.fixture(scope="module")
def stroke():
    """The shipped palette's double stroke at 1 kHz: two impacts and their rebounds, 549 samples."""
    entry = next(e for e in read_palette() if e.name == "double")
    return tuple(entry.make().sample(RATE))  # t, theta, omega


def bad_copy(stroke, index=123):
    t, theta, omega = (a.copy() for a in stroke)
    theta[index] = HEAD - 0.05
    return t, theta, omega


def exact_seconds(duration):
    return duration["sec"] + Fraction(duration["nanosec"], 10**9)


def build(store, msgtype, data):
    """The typestore's ``msgtype`` object from plain data: every field of the type, no other, of its kind."""
    fields = store.fielddefs[msgtype][1]
    names = [name for name, _ in fields]
    assert isinstance(data, dict) and set(data) == set(names), (msgtype, sorted(set(data) ^ set(names)))
    return store.types[msgtype](**{name: value(store, kind, data[name]) for name, kind in fields})


def value(store, kind, data):
    """A field's value from plain data, checked against its kind: a base type, a message, or a sequence of either."""
    node, spec = kind
    if node == Nodetype.NAME:
        return build(store, spec, data)
    if node == Nodetype.SEQUENCE:
        (item_node, item_spec), _ = spec
        assert isinstance(data, list), (spec, data)
        items = [value(store, (item_node, item_spec), item) for item in data]
        numeric = item_node == Nodetype.BASE and item_spec[0] != "string"
        return np.array(items, dtype=item_spec[0]) if numeric else items
    base = spec[0]
    assert node == Nodetype.BASE and base in ("string", "float64", *INTEGERS), kind
    if base == "string":
        assert isinstance(data, str), data
    elif base == "float64":
        assert type(data) is float, data
    else:
        low, high = INTEGERS[base]
        assert type(data) is int and low <= data < high, (base, data)
    return data


def build_document(message):
    """A typestore message as plain data (the inverse of build, for messages read from a bag)."""
    if isinstance(message, np.ndarray):
        return message.tolist()
    if isinstance(message, list):
        return [build_document(m) for m in message]
    if hasattr(message, "__msgtype__"):
        return {f.name: build_document(getattr(message, f.name)) for f in dataclasses.fields(message)
                if f.name != "__msgtype__"}
    return message


# --- CSV -----------------------------------------------------------------------------------------------------------

def test_csv_round_trips_to_17_digits(stroke, tmp_path):
    t, theta, omega = stroke
    path = tmp_path / "double.csv"
    checked = export_csv(path, t, theta, omega, rate=RATE, model="paper", name="double")
    lines = path.read_text().splitlines()
    assert lines[0] == "t,theta,omega,alpha"  # the header first; what it is, in the JSON beside it
    meta = json.loads((tmp_path / "double.json").read_text())["csv"]
    assert meta == {"file": "double.csv", "drumstroke": __version__, "model": "paper", "name": "double",
                    "rate": 1000.0, "sticks": ["stick"], "note": meta["note"], "columns": ["t", "theta", "omega", "alpha"],
                    "units": {"t": "s", "theta": "rad", "omega": "rad/s", "alpha": "rad/s^2"}}
    assert meta["note"].startswith("alpha is the forward difference")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    assert data.shape == (len(t), 4)
    assert np.array_equal(data[:, 0], t) and np.array_equal(data[:, 1], theta) and np.array_equal(data[:, 2], omega)
    assert np.array_equal(data[:, 3], np.append(np.diff(omega) * RATE, 0.0))
    assert checked.peak_speed == np.abs(omega).max()


def test_an_exported_csv_reads_and_validates_again(stroke, tmp_path):
    path = tmp_path / "double.csv"
    export_csv(path, *stroke, rate=RATE, model="paper", name="double")
    back = _read_sampled(path)
    t, theta, omega, model = back.t, back.theta, back.omega, back.model
    assert model == "paper" and all(np.array_equal(a, b) for a, b in zip((t, theta, omega), stroke))
    again = validate_file(path)
    impacts = next(e for e in read_palette() if e.name == "double").make().impacts.t
    struck = ((t[:-1, None] <= impacts) & (impacts <= t[1:, None])).any(axis=1)  # the steps an impact falls in
    assert 2 <= struck.sum() <= len(impacts)
    steps = np.abs(np.diff(omega)) * RATE
    assert again.rate == RATE and np.array_equal(again.alpha, np.diff(omega) * RATE)
    assert again.peak_acceleration == pytest.approx(steps[~struck].max())
    assert steps.max() > 100 * again.peak_acceleration  # the strikes', unbounded


def test_csv_at_another_rate_carries_its_rate(tmp_path):
    t, theta, omega = Trajectory.from_stroke(drumstroke.simulate("free-bounce")).sample(500.0)
    path = tmp_path / "bounce.csv"
    export_csv(path, t, theta, omega, rate=500.0, model="paper", name="free-bounce")
    assert json.loads((tmp_path / "bounce.json").read_text())["csv"]["rate"] == 500.0
    assert np.array_equal(np.loadtxt(path, delimiter=",", skiprows=1)[:, 3], np.append(np.diff(omega) * 500.0, 0.0))
    assert validate_file(path).rate == 500.0


# --- ROS JSON ------------------------------------------------------------------------------------------------------

def test_ros_json_is_a_joint_trajectory_read_independently(stroke, tmp_path):
    t, theta, omega = stroke
    path = tmp_path / "double.json"
    export_ros_json(path, t, theta, omega, rate=RATE, model="paper", name="double")
    document = json.loads(path.read_text())
    assert set(document) == {"header", "joint_names", "points"}  # exactly the message
    assert document["header"] == {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}
    assert document["joint_names"] == ["stick_joint"]
    points = document["points"]
    assert len(points) == len(t)
    alpha = np.append(np.diff(omega) * RATE, 0.0)
    for k, point in enumerate(points):
        assert set(point) == {"positions", "velocities", "accelerations", "effort", "time_from_start"}
        assert point["positions"] == [theta[k]] and point["velocities"] == [omega[k]]
        assert point["accelerations"] == [alpha[k]] and point["effort"] == []
        duration = point["time_from_start"]
        assert type(duration["sec"]) is int and type(duration["nanosec"]) is int
        assert 0 <= duration["nanosec"] < 10**9
        assert abs(exact_seconds(duration) - Fraction(float(t[k]))) <= Fraction(1, 2 * 10**9)
    sidecar = json.loads((tmp_path / "double.meta.json").read_text())
    assert sidecar == {
        "version": __version__, "model": "paper", "name": "double", "rate": RATE,
        "type": "trajectory_msgs/msg/JointTrajectory", "message": "double.json",
        "joints": [{"name": "stick_joint", "stick": None}], "head": HEAD, "limits": Limits().to_dict(),
        "units": {"positions": "rad", "velocities": "rad/s", "accelerations": "rad/s^2", "time_from_start": "s"},
        "accelerations": "forward difference (omega[k+1] - omega[k])*rate, 0 at the last sample"}


def test_ros_json_is_a_message_of_rosbags_typestore(stroke, tmp_path):
    """Built field by field with the ROS 2 types themselves: a field the message lacks, or lacks a field, fails."""
    path = tmp_path / "double.json"
    export_ros_json(path, *stroke, rate=RATE, model="paper", name="double", joint_names=["right_wrist"])
    document = json.loads(path.read_text())
    store = get_typestore(Stores.ROS2_JAZZY)
    message = build(store, MESSAGE, document)
    assert message.joint_names == ["right_wrist"] and len(message.points) == len(stroke[0])
    assert np.array_equal([p.positions[0] for p in message.points], stroke[1])
    back = store.deserialize_cdr(store.serialize_cdr(message, MESSAGE), MESSAGE)
    assert back.points[100].time_from_start.nanosec == 100_000_000
    document["points"][3]["extra"] = 1.0
    with pytest.raises(AssertionError, match=r"JointTrajectoryPoint.*\['extra'\]"):
        build(store, MESSAGE, document)
    document["points"][3].pop("extra")
    document["points"][4].pop("effort")
    with pytest.raises(AssertionError, match=r"JointTrajectoryPoint.*\['effort'\]"):
        build(store, MESSAGE, document)
    old = {**json.loads(path.read_text()), "drumstroke": {"version": __version__}}  # the old in-file metadata
    with pytest.raises(AssertionError, match=r"JointTrajectory.*\['drumstroke'\]"):
        build(store, MESSAGE, old)


def test_the_joint_trajectory_is_the_same_type_from_humble_to_jazzy():
    """The bag is written with Jazzy's types; Humble's definition and hash are the same."""
    humble, jazzy = get_typestore(Stores.ROS2_HUMBLE), get_typestore(Stores.ROS2_JAZZY)
    for name in (MESSAGE, "trajectory_msgs/msg/JointTrajectoryPoint", "std_msgs/msg/Header",
                 "builtin_interfaces/msg/Time", "builtin_interfaces/msg/Duration"):
        assert humble.fielddefs[name] == jazzy.fielddefs[name]
        assert humble.hash_rihs01(name) == jazzy.hash_rihs01(name)


def test_read_ros_json_gives_the_same_arrays(stroke, tmp_path):
    t, theta, omega = stroke
    path = tmp_path / "double.json"
    export_ros_json(path, t, theta, omega, rate=RATE, model="paper", name="double", joint_names=["right_wrist"])
    back = read_ros_json(path)
    assert back.joint_names == ("right_wrist",)
    assert back.positions.shape == back.velocities.shape == back.accelerations.shape == (len(t), 1)
    assert np.array_equal(back.positions[:, 0], theta) and np.array_equal(back.velocities[:, 0], omega)
    assert np.array_equal(back.accelerations[:, 0], np.append(np.diff(omega) * RATE, 0.0))
    assert np.max(np.abs(back.t - t)) <= 0.5e-9
    unpacked = tuple(back)  # the documented tuple
    assert len(unpacked) == 5 and unpacked[1] is back.positions and unpacked[4] == ("right_wrist",)


def test_time_from_start_is_split_exactly_with_a_carry(tmp_path):
    assert seconds_to_duration(0.0) == (0, 0)
    assert seconds_to_duration(1.5) == (1, 500_000_000)
    assert seconds_to_duration(2.9999999996) == (3, 0)
    assert seconds_to_duration(2.9999999994) == (2, 999_999_999)
    assert seconds_to_duration(1e-10) == (0, 0)
    t = 0.9999999996 + np.arange(3001) / RATE  # sample 0 rounds up to 1 s; later ones straddle whole seconds
    theta = np.full(len(t), 0.1)
    omega = np.zeros(len(t))
    path = tmp_path / "hold.json"
    export_ros_json(path, t, theta, omega, rate=RATE, model="paper", name="hold")
    points = json.loads(path.read_text())["points"]
    assert points[0]["time_from_start"] == {"sec": 1, "nanosec": 0}
    assert points[1000]["time_from_start"] == {"sec": 2, "nanosec": 0}
    for k, point in enumerate(points):
        duration = point["time_from_start"]
        assert 0 <= duration["nanosec"] < 10**9
        assert abs(exact_seconds(duration) - Fraction(float(t[k]))) <= Fraction(1, 2 * 10**9)


def test_several_joints_at_once(stroke, tmp_path):
    t, theta, omega = stroke
    lifted = np.maximum(HEAD, theta[::-1])  # any second valid joint: the stroke reversed in time
    thetas = np.column_stack((theta, lifted))
    omegas = np.column_stack((omega, -omega[::-1]))
    path = tmp_path / "two.json"
    checked = export_ros_json(path, t, thetas, omegas, rate=RATE, model="paper", name="two",
                              joint_names=("left", "right"), start=[(theta[0], omega[0]), (lifted[0], -omega[-1])])
    assert len(checked) == 2 and checked[1].peak_speed == np.abs(omega).max()
    document = json.loads(path.read_text())
    assert document["joint_names"] == ["left", "right"]
    assert document["points"][7]["positions"] == [theta[7], lifted[7]]
    back = read_ros_json(path)
    assert np.array_equal(back.positions, thetas) and np.array_equal(back.velocities, omegas)


def test_a_defect_in_one_joint_names_the_joint(stroke, tmp_path):
    t, theta, omega = stroke
    bad_theta = bad_copy(stroke, index=200)[1]
    path = tmp_path / "two.json"
    with pytest.raises(TrajectoryError, match=r"^joint 'right': sample 200: theta .* is below the head"):
        export_ros_json(path, t, np.column_stack((theta, bad_theta)), np.column_stack((omega, omega)), rate=RATE,
                        model="paper", name="two", joint_names=("left", "right"))
    assert not path.exists()


def test_the_sidecar_can_be_left_out_and_old_files_still_read(stroke, tmp_path):
    path = tmp_path / "plain.json"
    export_ros_json(path, *stroke, rate=RATE, model="paper", name="double", metadata=False)
    assert [p.name for p in tmp_path.iterdir()] == ["plain.json"]
    document = json.loads(path.read_text())
    document["drumstroke"] = {"version": "0.1.0", "model": "paper", "name": "double", "rate": RATE}  # as 0.1.0 wrote
    path.write_text(json.dumps(document))
    assert np.array_equal(read_ros_json(path).positions[:, 0], stroke[1])


def two_sticks(stroke):
    """A Trajectory of two sticks, right then left: the stroke, and the stroke reversed in time."""
    t, theta, omega = stroke
    thetas = np.column_stack((theta, np.maximum(HEAD, theta[::-1])))
    omegas = np.column_stack((omega, -omega[::-1]))
    return Trajectory.from_samples(t, thetas, omegas, rate=RATE, sticks=("right", "left"), name="piece",
                                   model="paper")


def test_both_sticks_of_a_trajectory_in_one_message(stroke, tmp_path):
    piece = two_sticks(stroke)
    path = tmp_path / "piece.json"
    checked = export_ros_json(path, piece, joint_names=("r_wrist", "l_wrist"))
    document = json.loads(path.read_text())
    assert document["joint_names"] == ["r_wrist", "l_wrist"] and len(checked) == 2
    for j, stick in enumerate(piece.sticks):
        part = piece.stick(stick)
        assert np.array_equal([p["positions"][j] for p in document["points"]], part.theta)
        assert np.array_equal([p["velocities"][j] for p in document["points"]], part.omega)
    sidecar = json.loads((tmp_path / "piece.meta.json").read_text())
    assert sidecar["joints"] == [{"name": "r_wrist", "stick": "right"}, {"name": "l_wrist", "stick": "left"}]
    assert sidecar["model"] == "paper" and sidecar["rate"] == piece.rate
    export_ros_json(tmp_path / "default.json", piece)
    assert json.loads((tmp_path / "default.json").read_text())["joint_names"] == ["right_joint", "left_joint"]
    for names, message in [(("a",), r"joint_names must be one name per stick \(right, left\), got 1: \('a',\)"),
                           (("a", "a"), r"joint_names must be distinct non-empty names"),
                           (("a", " "), r"joint_names must be distinct non-empty names")]:
        with pytest.raises(ParameterError, match=message):
            export_ros_json(tmp_path / "bad.json", piece, joint_names=names)
    assert not (tmp_path / "bad.json").exists()


# --- rosbag2 -------------------------------------------------------------------------------------------------------

def read_bag(path):
    """Every message of the bag, deserialized with the typestore, with its topic, type and time; and custom_data."""
    store = get_typestore(Stores.ROS2_JAZZY)
    with Reader(path) as reader:
        messages = [(c.topic, c.msgtype, stamp, store.deserialize_cdr(data, c.msgtype))
                    for c, stamp, data in reader.messages()]
    custom = yaml.safe_load((path / "metadata.yaml").read_text())["rosbag2_bagfile_information"]["custom_data"]
    return messages, custom


@pytest.mark.parametrize("storage, suffix", [("mcap", ".mcap"), ("sqlite3", ".db3")])
def test_a_rosbag_holds_the_same_points(stroke, tmp_path, storage, suffix):
    t, theta, omega = stroke
    bag = tmp_path / "double"
    export_rosbag(bag, t, theta, omega, rate=RATE, model="paper", name="double", storage=storage)
    assert sorted(p.suffix for p in bag.iterdir()) == sorted([suffix, ".yaml"])
    assert [p.name for p in tmp_path.iterdir()] == ["double"]  # no temporary left
    (topic, msgtype, stamp, message), = read_bag(bag)[0]
    assert (topic, msgtype, stamp) == ("/drumstroke/joint_trajectory", MESSAGE, 0)
    document = json.loads(json.dumps(build_document(message)))
    export_ros_json(tmp_path / "double.json", t, theta, omega, rate=RATE, model="paper", name="double")
    assert document == json.loads((tmp_path / "double.json").read_text())  # the JSON message, point for point
    alpha = np.append(np.diff(omega) * RATE, 0.0)
    assert np.array_equal(np.concatenate([p.positions for p in message.points]), theta)
    assert np.array_equal(np.concatenate([p.velocities for p in message.points]), omega)
    assert np.array_equal(np.concatenate([p.accelerations for p in message.points]), alpha)
    assert [(p.time_from_start.sec, p.time_from_start.nanosec) for p in message.points] == [
        seconds_to_duration(x) for x in t]
    custom = json.loads(read_bag(bag)[1]["drumstroke"])
    assert custom["topic"] == "/drumstroke/joint_trajectory" and custom["name"] == "double" and custom["rate"] == RATE


def test_a_rosbag_of_two_joints_on_another_topic(stroke, tmp_path):
    piece = two_sticks(stroke)
    bag = tmp_path / "piece"
    export_rosbag(bag, piece, joint_names=("r", "l"), topic="/robot/arm_controller/joint_trajectory",
                  storage="sqlite3")
    (topic, _, _, message), = read_bag(bag)[0]
    assert topic == "/robot/arm_controller/joint_trajectory" and message.joint_names == ["r", "l"]
    assert np.array_equal([p.positions[1] for p in message.points], piece.stick("left").theta)


def test_an_existing_bag_is_kept_unless_overwritten(stroke, tmp_path):
    bag = tmp_path / "bag"
    export_rosbag(bag, *stroke, rate=RATE, model="paper", name="first")
    with pytest.raises(ParameterError, match=r"^rosbag '.*bag' exists; choose a new path, or overwrite it"):
        export_rosbag(bag, *stroke, rate=RATE, model="paper", name="second")
    assert json.loads(read_bag(bag)[1]["drumstroke"])["name"] == "first"
    export_rosbag(bag, *stroke, rate=RATE, model="paper", name="second", storage="sqlite3", overwrite=True)
    assert json.loads(read_bag(bag)[1]["drumstroke"])["name"] == "second"
    assert sorted(p.name for p in bag.iterdir()) == ["bag.db3", "metadata.yaml"]
    assert [p.name for p in tmp_path.iterdir()] == ["bag"]


def test_a_failed_bag_leaves_nothing_or_the_old_bag(stroke, tmp_path, monkeypatch):
    bag = tmp_path / "bag"
    with pytest.raises(TrajectoryError, match="sample 123"):
        export_rosbag(bag, *bad_copy(stroke), rate=RATE, model="paper", name="bad")
    assert list(tmp_path.iterdir()) == []
    export_rosbag(bag, *stroke, rate=RATE, model="paper", name="old")

    def fail(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr("rosbags.rosbag2.Writer.write", fail)
    with pytest.raises(OSError, match="disk full"):
        export_rosbag(bag, *stroke, rate=RATE, model="paper", name="new", overwrite=True)
    assert [p.name for p in tmp_path.iterdir()] == ["bag"]
    assert json.loads(read_bag(bag)[1]["drumstroke"])["name"] == "old"


def test_a_bag_that_cannot_be_renamed_into_place_leaves_the_old_one(stroke, tmp_path, monkeypatch):
    bag = tmp_path / "bag"
    export_rosbag(bag, *stroke, rate=RATE, model="paper", name="old")
    replace = os.replace

    def fail_the_new_one(source, target):
        if Path(source).name == "bag":  # the new bag, from its temporary folder; the old one moves as bag.old
            raise OSError("rename failed")
        replace(source, target)

    monkeypatch.setattr("drumstroke._atomic.os.replace", fail_the_new_one)
    with pytest.raises(OSError, match="rename failed"):
        export_rosbag(bag, *stroke, rate=RATE, model="paper", name="new", overwrite=True)
    assert [p.name for p in tmp_path.iterdir()] == ["bag"]
    assert json.loads(read_bag(bag)[1]["drumstroke"])["name"] == "old"


@pytest.mark.parametrize("options, message", [
    ({"topic": "joint_trajectory"}, r"^topic must be a ROS 2 topic name: '/' then names"),
    ({"topic": "/drum//stroke"}, r"^topic must be a ROS 2 topic name"),
    ({"topic": "/1st"}, r"^topic must be a ROS 2 topic name"),
    ({"storage": "bag"}, r"^storage must be one of 'mcap', 'sqlite3', got 'bag'"),
])
def test_bad_bag_options_are_refused(stroke, tmp_path, options, message):
    with pytest.raises(ParameterError, match=message):
        export_rosbag(tmp_path / "bag", *stroke, rate=RATE, model="paper", name="x", **options)
    with pytest.raises(ParameterError, match=r"^rosbag '.*bag': the folder '.*nowhere' does not exist"):
        export_rosbag(tmp_path / "nowhere" / "bag", *stroke, rate=RATE, model="paper", name="x")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("edit, message", [
    (lambda d: d.pop("points"), r"key 'points' is missing"),
    (lambda d: d.pop("joint_names"), r"key 'joint_names' is missing"),
    (lambda d: d.update(extra=1), r"key 'extra' is not a JointTrajectory field"),
    (lambda d: d.update(joint_names=[]), r"joint_names must be a non-empty list of names"),
    (lambda d: d["points"][3].pop("positions"), r"key points\[3\]\.positions is missing"),
    (lambda d: d["points"][4].update(velocities=[1.0, 2.0]), r"points\[4\]\.velocities must be a list of 1 numbers"),
    (lambda d: d["points"][5].update(positions=["x"]), r"points\[5\]\.positions\[0\] must be a number"),
    (lambda d: d["points"][6].pop("time_from_start"), r"key points\[6\]\.time_from_start is missing"),
    (lambda d: d["points"][7]["time_from_start"].update(nanosec=10**9),
     r"points\[7\]\.time_from_start\.nanosec must be an integer in \[0, 999999999\], got 1000000000"),
    (lambda d: d["points"][8]["time_from_start"].update(sec=1.5), r"points\[8\]\.time_from_start\.sec must be an int32"),
    (lambda d: d["points"][9].update(accelerations=[]), r"points\[9\]\.accelerations must have 1 values like"),
    (lambda d: d.update(points=d["points"][:1]), r"points must be a list of at least 2 points"),
])
def test_read_ros_json_names_the_path_and_the_key(stroke, tmp_path, edit, message):
    path = tmp_path / "double.json"
    export_ros_json(path, *stroke, rate=RATE, model="paper", name="double")
    document = json.loads(path.read_text())
    edit(document)
    path.write_text(json.dumps(document))
    with pytest.raises(ParameterError, match=rf"^ROS trajectory file '.*double\.json': {message}"):
        read_ros_json(path)


def test_read_ros_json_refuses_non_finite_values_and_non_json(stroke, tmp_path):
    path = tmp_path / "nan.json"
    export_ros_json(path, *stroke, rate=RATE, model="paper", name="double")
    document = json.loads(path.read_text())
    document["points"][0]["positions"] = [float("nan")]
    path.write_text(json.dumps(document))  # Python's json writes and reads the non-standard NaN
    assert "[NaN]" in path.read_text()
    with pytest.raises(ParameterError, match=r"points\[0\]\.positions\[0\] must be a finite number in \(-inf, inf\), got nan"):
        read_ros_json(path)
    path.write_text("{not json")
    with pytest.raises(ParameterError, match=r"^ROS trajectory file '.*nan\.json' is not readable JSON"):
        read_ros_json(path)
    with pytest.raises(ParameterError, match=r"^ROS trajectory file '.*none\.json' is missing"):
        read_ros_json(tmp_path / "none.json")


def test_empty_accelerations_everywhere_read_as_none(stroke, tmp_path):
    path = tmp_path / "double.json"
    export_ros_json(path, *stroke, rate=RATE, model="paper", name="double")
    document = json.loads(path.read_text())
    for point in document["points"]:
        point["accelerations"] = []
    path.write_text(json.dumps(document))
    assert read_ros_json(path).accelerations is None


# --- refusals: nothing written, old files kept ---------------------------------------------------------------------

@pytest.mark.parametrize("export", [export_csv, export_ros_json])
def test_an_invalid_trajectory_is_not_exported(stroke, tmp_path, export):
    path = tmp_path / "new.out"
    with pytest.raises(TrajectoryError, match="sample 123: theta .* below the head"):
        export(path, *bad_copy(stroke), rate=RATE, model="paper", name="bad")
    assert not path.exists() and list(tmp_path.iterdir()) == []
    old = tmp_path / "old.out"
    old.write_text("the old trajectory\n")
    with pytest.raises(TrajectoryError, match="sample 123"):
        export(old, *bad_copy(stroke), rate=RATE, model="paper", name="bad")
    assert old.read_text() == "the old trajectory\n"


@pytest.mark.parametrize("export", [export_csv, export_ros_json])
def test_limits_and_start_reach_the_validator(stroke, tmp_path, export):
    path = tmp_path / "out"
    with pytest.raises(TrajectoryError, match=r"exceeds max_speed 3 rad/s"):
        export(path, *stroke, rate=RATE, model="paper", name="x", limits=Limits(max_speed=3.0))
    with pytest.raises(TrajectoryError, match=r"sample 0: theta .* beyond start_angle_tolerance"):
        export(path, *stroke, rate=RATE, model="paper", name="x", start=(stroke[1][0] + 0.1, stroke[2][0]))
    with pytest.raises(TrajectoryError, match=r"sample 1: .*not the control period 0\.0005 s"):
        export(path, *stroke, rate=2000.0, model="paper", name="x")
    assert not path.exists()


@pytest.mark.parametrize("export", [export_csv, export_ros_json])
def test_a_failed_write_leaves_the_old_file_whole(stroke, tmp_path, monkeypatch, export):
    path = tmp_path / "double.out"
    export(path, *stroke, rate=RATE, model="paper", name="double")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}  # the metadata beside it too

    def fail(*args):
        raise OSError("disk full")

    monkeypatch.setattr("drumstroke._atomic.os.replace", fail)
    t, theta, omega = stroke
    with pytest.raises(OSError, match="disk full"):
        export(path, t, theta * 0.5 + 0.5 * HEAD, omega * 0.5, rate=RATE, model="paper", name="softer")
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    assert sorted(before) == (["double.json", "double.out"] if export is export_csv else
                              ["double.meta.json", "double.out"])


@pytest.mark.parametrize("options, message", [
    ({"model": "paper; rate=1 Hz"}, r"model must be one line of text without ';'"),
    ({"name": "two\nlines"}, r"name must be one line of text without ';'"),
    ({"model": None}, r"model must be one line of text"),
])
@pytest.mark.parametrize("export", [export_csv, export_ros_json])
def test_bad_text_is_refused(stroke, tmp_path, export, options, message):
    with pytest.raises(ParameterError, match=message):
        export(tmp_path / "out", *stroke, rate=RATE, **({"model": "paper", "name": "x"} | options))
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("options, message", [
    ({"joint_names": "stick"}, r"joint_names must be a sequence of names, got the string 'stick'"),
    ({"joint_names": ("a", "a")}, r"joint_names must be distinct non-empty names"),
    ({"joint_names": ()}, r"joint_names must be distinct non-empty names, at least one"),
    ({"joint_names": ("a", "b")}, r"theta must have shape \(n, 2\) for 2 joint name\(s\), got shape \(549,\)"),
])
def test_bad_joints_are_refused(stroke, tmp_path, options, message):
    with pytest.raises(ParameterError, match=message):
        export_ros_json(tmp_path / "out.json", *stroke, rate=RATE, model="paper", name="x", **options)


def test_ros_time_must_start_at_or_after_the_stamp(stroke, tmp_path):
    t, theta, omega = stroke
    with pytest.raises(ParameterError, match=r"t must be in \[0, 2147483647\) s for time_from_start, got -1\.0"):
        export_ros_json(tmp_path / "out.json", t - 1.0, theta, omega, rate=RATE, model="paper", name="x")
    assert not (tmp_path / "out.json").exists()


def _read_sampled(path, **options):
    """Trajectory.read_csv of a CSV with no JSON recording its impacts: they are found again in the samples, and
    it says so."""
    with pytest.warns(SampledImpactsWarning, match="found again in its samples"):
        return Trajectory.read_csv(path, **options)
