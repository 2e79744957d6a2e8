"""Export a validated trajectory in forms a robot stack takes (SPEC §5): CSV at the control rate, ROS JSON.

Both writers run :func:`~drumstroke.robot.validate.validate` first and write
nothing when it fails; both write atomically, so a failed write leaves an old
file whole.

The acceleration written beside θ and ω is the forward difference
α[k] = (ω[k+1] − ω[k])·rate, the constant acceleration that carries ω from
sample k to sample k + 1, and 0 at the last sample, after which the trajectory
asks for nothing.

The JSON has the shape of ROS 2 ``trajectory_msgs/msg/JointTrajectory``
(``header``, ``joint_names``, ``points`` with ``positions``, ``velocities``,
``accelerations``, ``effort`` and ``time_from_start`` {sec, nanosec}), plus a
top-level ``drumstroke`` key with the version, model, name and rate. ROS's own
``rosidl_runtime_py.set_message_fields`` refuses keys the message does not
have, so drop that key before filling a message with it, or export with
``metadata=False`` for a file that is exactly the message.

Examples
--------
>>> import tempfile, pathlib
>>> import numpy as np
>>> t = np.arange(201) / 1000.0
>>> theta = 0.1 * np.cos(np.pi * t / 0.2)
>>> omega = -0.1 * np.pi / 0.2 * np.sin(np.pi * t / 0.2)
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> _ = export_ros_json(folder / "move.json", t, theta, omega, rate=1000.0, model="paper", name="move")
>>> back = read_ros_json(folder / "move.json")
>>> back.joint_names, back.positions.shape, bool(np.array_equal(back.positions[:, 0], theta))
(('stick_joint',), (201, 1), True)
"""

import json
from fractions import Fraction
from pathlib import Path
from typing import NamedTuple

import numpy as np

from .._atomic import write_atomic
from .._checks import check_real
from .._version import __version__
from ..errors import ParameterError, TrajectoryError
from ..formats.trajectory_csv import columns_text as csv_text
from ..formats.trajectory_csv import comment_line as csv_header
from .validate import validate

NANOSECONDS = 1_000_000_000
_MAX_SECONDS = 2**31 - 1
"""builtin_interfaces/Duration.sec is an int32."""


def export_csv(path, t, theta, omega, *, rate, model, name, head=None, limits=None, start=None):
    """Validate a trajectory and write it as CSV ``t,theta,omega,alpha`` (s, rad, rad/s, rad/s²).

    One ``#`` comment line comes first: the drumstroke version, the model, the
    name, the rate and the units. :func:`~drumstroke.robot.validate.validate_file`
    and :func:`~drumstroke.palette.trajectory.read_trajectory_csv` read it back.

    Parameters
    ----------
    path : str or Path
    t, theta, omega : ndarray [shape=(n,)]
        s, rad, rad/s at the control rate.
    rate : float
        The control rate (Hz).
    model, name : str
        What made the trajectory and what it is called (one line each, no ';').
    head, limits, start
        As for :func:`~drumstroke.robot.validate.validate`.

    Returns
    -------
    Checked
        What was validated and written.
    """
    model, name = _check_text("model", model), _check_text("name", name)
    checked = validate(t, theta, omega, rate=rate, head=head, limits=limits, start=start)
    alpha = np.append(checked.alpha, 0.0)
    comment = (f"{csv_header(model, name, checked.rate)}, rad/s^2; alpha is the forward difference "
               "(omega[k+1] - omega[k])*rate, 0 at the last sample")
    write_atomic(path, csv_text(comment, ("t", "theta", "omega", "alpha"),
                                (checked.t, checked.theta, checked.omega, alpha)))
    return checked


def export_ros_json(path, t, theta, omega, *, rate, model, name, joint_names=("stick_joint",), head=None,
                    limits=None, start=None, metadata=True):
    """Validate a trajectory of one or several joints and write it as ROS ``JointTrajectory``-shaped JSON.

    Parameters
    ----------
    path : str or Path
    t : ndarray [shape=(n,)]
        Times (s) from the header stamp, t[0] ≥ 0; written exactly split as
        ``time_from_start`` {sec, nanosec}, nanosec in [0, 1e9), rounded to the
        nearest nanosecond.
    theta, omega : ndarray [shape=(n,) or (n, joints)]
        rad, rad/s; one column per joint.
    rate : float
        The control rate (Hz).
    model, name : str
        One line each, no ';'.
    joint_names : sequence of str
        One distinct name per joint.
    head, limits
        As for :func:`~drumstroke.robot.validate.validate`, the same for every joint.
    start : (float, float), sequence of them, or None
        The joints' angle (rad) and speed (rad/s) now: one pair for one joint
        given as 1-D arrays, else one pair per joint.
    metadata : bool
        Add the top-level ``drumstroke`` key (version, model, name, rate).

    Returns
    -------
    tuple of Checked
        One per joint.
    """
    model, name = _check_text("model", model), _check_text("name", name)
    names = _check_joint_names(joint_names)
    thetas, omegas, starts = _joint_columns(theta, omega, start, len(names))
    checked = []
    for joint, theta_j, omega_j, start_j in zip(names, thetas, omegas, starts):
        try:
            checked.append(validate(t, theta_j, omega_j, rate=rate, head=head, limits=limits, start=start_j))
        except TrajectoryError as error:
            raise TrajectoryError(f"joint {joint!r}: {error}") from None
    times = checked[0].t
    if times[0] < 0.0 or times[-1] >= _MAX_SECONDS:
        raise ParameterError(f"t must be in [0, {_MAX_SECONDS}) s for time_from_start, got {float(times[0])!r} "
                             f"to {float(times[-1])!r} s")
    positions = np.column_stack([c.theta for c in checked]).tolist()
    velocities = np.column_stack([c.omega for c in checked]).tolist()
    accelerations = np.column_stack([np.append(c.alpha, 0.0) for c in checked]).tolist()
    points = [
        {"positions": p, "velocities": v, "accelerations": a, "effort": [],
         "time_from_start": {"sec": sec, "nanosec": nanosec}}
        for p, v, a, (sec, nanosec) in zip(positions, velocities, accelerations, map(seconds_to_duration, times))
    ]
    document = {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}, "joint_names": list(names),
                "points": points}
    if metadata:
        document["drumstroke"] = {"version": __version__, "model": model, "name": name, "rate": checked[0].rate}
    write_atomic(path, json.dumps(document, allow_nan=False) + "\n")
    return tuple(checked)


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
    """Read and check ROS ``JointTrajectory``-shaped JSON as :func:`export_ros_json` writes it.

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
    try:
        document = json.loads(Path(path).read_text())
    except FileNotFoundError:
        raise ParameterError(f"{where} is missing") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ParameterError(f"{where} is not readable JSON: {error}") from None
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
    unknown = sorted(set(document) - {"header", "joint_names", "points", "drumstroke"})
    if unknown:
        raise ParameterError(f"key {unknown[0]!r} is not a JointTrajectory field (nor 'drumstroke')")
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


def _check_text(name, value):
    if not isinstance(value, str) or "\n" in value or "\r" in value or ";" in value:
        raise ParameterError(f"{name} must be one line of text without ';', got {value!r}")
    return value


def _check_joint_names(joint_names):
    if isinstance(joint_names, str):
        raise ParameterError(f"joint_names must be a sequence of names, got the string {joint_names!r}")
    try:
        names = tuple(joint_names)
    except TypeError:
        raise ParameterError(f"joint_names must be a sequence of names, got {joint_names!r}") from None
    if not names or not all(isinstance(n, str) and n for n in names) or len(set(names)) != len(names):
        raise ParameterError(f"joint_names must be distinct non-empty names, at least one, got {joint_names!r}")
    return names


def _joint_columns(theta, omega, start, joints):
    """θ and ω as one 1-D array per joint, and the start state of each."""
    arrays = []
    for label, values in (("theta", theta), ("omega", omega)):
        try:
            array = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(f"{label} must be an array of numbers, got {values!r}") from None
        if array.ndim == 1 and joints == 1:
            array = array[:, None]
        if array.ndim != 2 or array.shape[1] != joints:
            raise ParameterError(f"{label} must have shape (n, {joints}) for {joints} joint name(s)"
                                 f"{' or shape (n,)' if joints == 1 else ''}, got shape {array.shape}")
        arrays.append(array.T)
    one_pair = np.ndim(theta) == 1
    if start is None:
        starts = [None] * joints
    elif one_pair:
        starts = [start]
    else:
        try:
            starts = list(start)
        except TypeError:
            raise ParameterError(f"start must be one (angle, speed) pair per joint, got {start!r}") from None
        if len(starts) != joints:
            raise ParameterError(f"start must be one (angle, speed) pair per joint ({joints}), got {start!r}")
    return arrays[0], arrays[1], starts
