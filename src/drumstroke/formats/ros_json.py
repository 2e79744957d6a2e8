"""ROS 2 ``trajectory_msgs/msg/JointTrajectory`` as JSON, both ways, and its metadata sidecar.

The document is exactly the message — ``header`` {stamp {sec, nanosec}, frame_id},
``joint_names``, ``points`` with ``positions``, ``velocities``, ``accelerations``, ``effort`` and
``time_from_start`` {sec, nanosec} — and nothing else, so ROS's own
``rosidl_runtime_py.set_message_fields`` fills a message from it. drumstroke's own metadata
goes beside it, into ``X.meta.json`` for ``X.json`` (:func:`metadata_path`). Files written before
the sidecar, with the metadata under a top-level ``drumstroke`` key, still read.

Examples
--------
>>> import json, pathlib, tempfile
>>> import numpy as np
>>> path = pathlib.Path(tempfile.mkdtemp()) / "move.json"
>>> t = np.arange(3) / 1000.0
>>> write_joint_trajectory(path, t, 0.1 * t[:, None], np.full((3, 1), 0.1), np.zeros((3, 1)), ("stick_joint",),
...                        metadata={"rate": 1000.0})
>>> back = read_ros_json(path)
>>> back.joint_names, back.positions.shape, back.t.tolist()
(('stick_joint',), (3, 1), [0.0, 0.001, 0.002])
>>> sorted(json.loads(path.read_text())), metadata_path(path).name
(['header', 'joint_names', 'points'], 'move.meta.json')
"""

import json
from fractions import Fraction
from pathlib import Path
from typing import NamedTuple

import numpy as np

from .._atomic import bundled, write_atomic
from .._checks import check_real
from ..errors import ParameterError
from .json import read_json, write_json
from .reading import MIB

MAX_BYTES = 1024 * MIB
"""The largest ROS trajectory file read (bytes): an hour of four joints at 1 kHz is some 900 MB."""

NANOSECONDS = 1_000_000_000
_MAX_SECONDS = 2**31 - 1
"""builtin_interfaces/Duration.sec is an int32."""


MESSAGE_TYPE = "trajectory_msgs/msg/JointTrajectory"
"""The ROS 2 message type the document is."""


def joint_trajectory(t, positions, velocities, accelerations, joint_names):
    """A ``JointTrajectory`` message as plain data (dicts, lists, ints and floats), header stamp 0.

    Parameters
    ----------
    t : ndarray [shape=(n,)]
        Times from the header stamp (s), in [0, 2**31 − 1): split exactly as
        ``time_from_start`` {sec, nanosec}, rounded to the nearest nanosecond.
    positions, velocities, accelerations : ndarray [shape=(n, joints)]
        rad, rad/s, rad/s².
    joint_names : sequence of str
    """
    t = np.asarray(t, dtype=float)
    if t[0] < 0.0 or t[-1] >= _MAX_SECONDS:
        raise ParameterError(f"t must be in [0, {_MAX_SECONDS}) s for time_from_start, got {float(t[0])!r} "
                             f"to {float(t[-1])!r} s")
    points = [
        {"positions": p, "velocities": v, "accelerations": a, "effort": [],
         "time_from_start": {"sec": sec, "nanosec": nanosec}}
        for p, v, a, (sec, nanosec) in zip(np.asarray(positions, float).tolist(), np.asarray(velocities, float).tolist(),
                                           np.asarray(accelerations, float).tolist(), map(seconds_to_duration, t))
    ]
    return {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}, "joint_names": list(joint_names),
            "points": points}


def write_joint_trajectory(path, t, positions, velocities, accelerations, joint_names, *, metadata=None,
                           bundle=None):
    """Write a JointTrajectory document to ``path``, and its metadata to :func:`metadata_path`, atomically, together.

    Parameters
    ----------
    path : str or Path
    t, positions, velocities, accelerations, joint_names
        As for :func:`joint_trajectory`.
    metadata : dict or None
        drumstroke's own data about the message (plain data), written to the sidecar; None writes none.
    bundle : Bundle or None
        A :class:`drumstroke._atomic.Bundle` to put the files in place with (default: a bundle of their own).
    """
    message = joint_trajectory(t, positions, velocities, accelerations, joint_names)
    with bundled(bundle) as files:
        write_atomic(path, json.dumps(message, allow_nan=False) + "\n", bundle=files)
        if metadata is not None:
            write_json(metadata_path(path), metadata, bundle=files)


def metadata_path(path):
    """Where the metadata of the message at ``path`` goes: ``X.meta.json`` for ``X.json`` (any other suffix too).

    Examples
    --------
    >>> metadata_path("out/single.json").as_posix(), metadata_path("piece").as_posix()
    ('out/single.meta.json', 'piece.meta.json')
    """
    return Path(path).with_suffix(".meta.json")


def seconds_to_duration(seconds):
    """A time (s) as ROS ``builtin_interfaces/Duration`` (sec, nanosec): exact to the nearest nanosecond.

    nanosec is in [0, 1e9); a time that rounds up to a whole second carries.

    Examples
    --------
    >>> seconds_to_duration(1.5), seconds_to_duration(2.9999999999)
    ((1, 500000000), (3, 0))
    """
    return divmod(round(Fraction(float(seconds)) * NANOSECONDS), NANOSECONDS)


class RosTrajectory(NamedTuple):
    """A trajectory read from ROS ``JointTrajectory``-shaped JSON.

    Attributes
    ----------
    t : ndarray [shape=(n,)]
        sec + nanosec·1e-9 of each point (s).
    positions, velocities : ndarray [shape=(n, joints)]
        rad, rad/s.
    accelerations : ndarray [shape=(n, joints)] or None
        rad/s²; None when every point's list is empty (ROS allows it).
    joint_names : tuple of str
    """

    t: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray | None
    joint_names: tuple


def read_ros_json(path):
    """Read and check ROS ``JointTrajectory``-shaped JSON as :func:`write_joint_trajectory` writes it.

    Returns
    -------
    RosTrajectory
        (t, positions, velocities, accelerations, joint_names).

    Raises
    ------
    ParameterError
        Naming the path and the key when the file cannot be read, is not JSON,
        or a key is missing, of the wrong type or length, or not finite.
    """
    where = f"ROS trajectory file {str(path)!r}"
    document = read_json(path, "ROS trajectory file", limit=MAX_BYTES)
    try:
        return _parse_trajectory(document)
    except ParameterError as error:
        raise ParameterError(f"{where}: {error}") from None


def _parse_trajectory(document):
    if not isinstance(document, dict):
        raise ParameterError("the document must be a JointTrajectory object")
    for key in ("joint_names", "points"):
        if key not in document:
            raise ParameterError(f"key {key!r} is missing")
    unknown = sorted(set(document) - {"header", "joint_names", "points", "drumstroke"})  # 'drumstroke': older files
    if unknown:
        raise ParameterError(f"key {unknown[0]!r} is not a JointTrajectory field")
    names = document["joint_names"]
    if not isinstance(names, list) or not names or not all(isinstance(n, str) and n for n in names):
        raise ParameterError(f"joint_names must be a non-empty list of names, got {names!r}")
    points = document["points"]
    if not isinstance(points, list) or len(points) < 2:
        raise ParameterError("points must be a list of at least 2 points")
    joints = len(names)
    t, positions, velocities, accelerations = [], [], [], []
    for i, point in enumerate(points):
        key = f"points[{i}]"
        if not isinstance(point, dict):
            raise ParameterError(f"{key} must be a JointTrajectoryPoint object, got {point!r}")
        positions.append(_numbers(point, "positions", key, joints))
        velocities.append(_numbers(point, "velocities", key, joints))
        accelerations.append(_numbers(point, "accelerations", key, joints, empty_ok=True))
        t.append(_duration(point, key))
    empty = [len(a) == 0 for a in accelerations]
    if any(empty) and not all(empty):
        i = empty.index(not empty[0])
        raise ParameterError(f"points[{i}].accelerations must have {joints} values like points[0]'s, or every "
                             "point none")
    return RosTrajectory(t=np.array(t), positions=np.array(positions), velocities=np.array(velocities),
                         accelerations=None if all(empty) else np.array(accelerations), joint_names=tuple(names))


def _numbers(point, field, key, joints, empty_ok=False):
    values = point.get(field)
    if values is None:
        raise ParameterError(f"key {key}.{field} is missing")
    ok = isinstance(values, list) and (len(values) == joints or (empty_ok and not values))
    if not ok:
        raise ParameterError(f"{key}.{field} must be a list of {joints} numbers (one per joint), got {values!r}")
    for j, value in enumerate(values):
        check_real(f"{key}.{field}[{j}]", value)
    return [float(v) for v in values]


def _duration(point, key):
    duration = point.get("time_from_start")
    if duration is None:
        raise ParameterError(f"key {key}.time_from_start is missing")
    if not isinstance(duration, dict) or "sec" not in duration or "nanosec" not in duration:
        raise ParameterError(f"{key}.time_from_start must be {{'sec': int, 'nanosec': int}}, got {duration!r}")
    sec, nanosec = duration["sec"], duration["nanosec"]
    if not _is_int(sec) or not -(2**31) <= sec < 2**31:
        raise ParameterError(f"{key}.time_from_start.sec must be an int32, got {sec!r}")
    if not _is_int(nanosec) or not 0 <= nanosec < NANOSECONDS:
        raise ParameterError(f"{key}.time_from_start.nanosec must be an integer in [0, {NANOSECONDS - 1}], "
                             f"got {nanosec!r}")
    return (sec * NANOSECONDS + nanosec) / NANOSECONDS


def _is_int(value):
    return isinstance(value, int) and not isinstance(value, bool)
