"""Export a validated trajectory in forms a robot stack takes: CSV at the control rate, ROS 2.

Every writer runs :func:`~drumstroke.robot.validate.validate` first and writes
nothing when it fails; every writer writes atomically, so a failed write leaves an
old file whole.

The acceleration written beside θ and ω is the forward difference
α[k] = (ω[k+1] − ω[k])·rate, the constant acceleration that carries ω from
sample k to sample k + 1, and 0 at the last sample, after which the trajectory
asks for nothing.

The ROS exports are exactly a ROS 2 ``trajectory_msgs/msg/JointTrajectory``, one joint
per stick: as JSON (:func:`export_ros_json`, with drumstroke's metadata in the sidecar
``X.meta.json``) and as a rosbag2 (:func:`export_rosbag`, MCAP or SQLite 3, the metadata in
its ``custom_data``); see :mod:`drumstroke.formats.ros_json` and :mod:`drumstroke.formats.rosbag`.

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

from pathlib import Path

import numpy as np

from .._atomic import Bundle, write_atomic
from .._version import __version__
from ..errors import ParameterError, TrajectoryError
from ..formats.ros_json import MESSAGE_TYPE, read_ros_json, seconds_to_duration, write_joint_trajectory
from ..formats.sidecar import sidecar_for, write_sidecar
from ..formats.trajectory_csv import columns_text as csv_text
from ..formats.trajectory_csv import metadata as csv_metadata
from ..trajectory import DEFAULT_STICK, Trajectory
from .validate import validate

__all__ = ["export_csv", "export_ros_json", "export_rosbag", "read_ros_json", "seconds_to_duration"]


def export_csv(path, trajectory, theta=None, omega=None, *, rate=None, model=None, name=None, head=None, limits=None,
               start=None, stick=None):
    """Validate a trajectory and write it as CSV ``t,theta,omega,alpha`` (s, rad, rad/s, rad/s²).

    The header comes first; the drumstroke version, the model, the name, the rate and the
    units are in the JSON beside it (``X.json`` for ``X.csv``, see :mod:`drumstroke.formats.sidecar`).
    :func:`~drumstroke.robot.validate.validate_file` and
    :meth:`drumstroke.trajectory.Trajectory.read_csv` read it back.

    Parameters
    ----------
    path : str or Path
    trajectory : Trajectory or ndarray
        A :class:`~drumstroke.trajectory.Trajectory` (one stick, or name its ``stick``), or the
        times t (s) [shape=(n,)] of samples given as arrays with ``theta`` (rad) and ``omega`` (rad/s).
    rate : float or None
        The control rate (Hz); default the trajectory's (arrays: 1000).
    model, name : str or None
        What made the trajectory and what it is called (one line each, no ';'); default the
        trajectory's (arrays must give them).
    head, limits, start, stick
        As for :func:`~drumstroke.robot.validate.validate`.

    Returns
    -------
    Checked
        What was validated and written.
    """
    model, name = _labels(trajectory, model, name, stick)
    checked = validate(trajectory, theta, omega, rate=rate, head=head, limits=limits, start=start, stick=stick)
    side = sidecar_for(path, name="path")
    names = ("t", "theta", "omega", "alpha")
    block = csv_metadata(path, names, model=model, name=name, rate=checked.rate, sticks=(stick or "stick",),
                         extra={"note": "alpha is the forward difference (omega[k+1] - omega[k])*rate, "
                                        "0 at the last sample"})
    with Bundle() as bundle:  # the CSV with the JSON beside it
        write_atomic(path, csv_text(names, (checked.t, checked.theta, checked.omega, np.append(checked.alpha, 0.0))),
                     bundle=bundle)
        write_sidecar(side, block, bundle=bundle)
    return checked


def export_ros_json(path, trajectory, theta=None, omega=None, *, rate=None, model=None, name=None, joint_names=None,
                    head=None, limits=None, start=None, metadata=True):
    """Validate a trajectory of one or several joints and write it as a ROS ``JointTrajectory`` in JSON.

    The file is exactly the message; drumstroke's metadata (:func:`ros_metadata`) goes to
    its sidecar, ``X.meta.json`` for ``X.json``.

    Parameters
    ----------
    path : str or Path
    trajectory : Trajectory or ndarray
        A :class:`~drumstroke.trajectory.Trajectory`, one joint per stick; or the times (s) from the
        header stamp [shape=(n,)] of samples given as arrays, t[0] ≥ 0, written exactly split as
        ``time_from_start`` {sec, nanosec}, nanosec in [0, 1e9), rounded to the nearest nanosecond.
    theta, omega : ndarray [shape=(n,) or (n, joints)] or None
        With times: rad, rad/s; one column per joint.
    rate : float or None
        The control rate (Hz); default the trajectory's (arrays: 1000).
    model, name : str or None
        One line each, no ';'; default the trajectory's (arrays must give them).
    joint_names : sequence of str or None
        One distinct name per joint, in the order of the trajectory's sticks; default
        ``<stick>_joint`` for each stick ("stick_joint" for one).
    head, limits
        As for :func:`~drumstroke.robot.validate.validate`, the same for every joint.
    start : (float, float), sequence of them, or None
        The joints' angle (rad) and speed (rad/s) now: one pair for one joint
        given as 1-D arrays, else one pair per joint.
    metadata : bool
        Write the sidecar.

    Returns
    -------
    tuple of Checked
        One per joint.
    """
    checked, names, sticks, model, name = _joints(trajectory, theta, omega, rate, model, name, joint_names, head,
                                                 limits, start)
    data = ros_metadata(checked, names, sticks, model, name, message=Path(path).name) if metadata else None
    write_joint_trajectory(path, *_columns(checked), names, metadata=data)
    return checked


def export_rosbag(path, trajectory, theta=None, omega=None, *, rate=None, model=None, name=None, joint_names=None,
                  head=None, limits=None, start=None, topic=None, storage="mcap", overwrite=False):
    """Validate a trajectory of one or several joints and write it as a rosbag2 of one ``JointTrajectory``.

    The bag is a folder written whole or not at all (:mod:`drumstroke.formats.rosbag`): one
    message on ``topic``, drumstroke's metadata (:func:`ros_metadata`) in its ``custom_data``.
    Needs the ``ros`` extra (rosbags).

    Parameters
    ----------
    path : str or Path
        The bag's folder, which must not exist unless ``overwrite``; its parent must exist.
    trajectory, theta, omega, rate, model, name, joint_names, head, limits, start
        As for :func:`export_ros_json`.
    topic : str or None
        A fully qualified ROS 2 topic name; default :data:`drumstroke.formats.rosbag.DEFAULT_TOPIC`.
    storage : {"mcap", "sqlite3"}
    overwrite : bool
        Replace an existing bag at ``path``.

    Returns
    -------
    tuple of Checked
        One per joint.
    """
    from ..formats.ros_json import joint_trajectory
    from ..formats.rosbag import DEFAULT_TOPIC, check_topic, write_rosbag

    topic = check_topic(DEFAULT_TOPIC if topic is None else topic)
    checked, names, sticks, model, name = _joints(trajectory, theta, omega, rate, model, name, joint_names, head,
                                                 limits, start)
    write_rosbag(path, joint_trajectory(*_columns(checked), names), topic=topic, storage=storage,
                 metadata=ros_metadata(checked, names, sticks, model, name, topic=topic), overwrite=overwrite)
    return checked


def ros_metadata(checked, joint_names, sticks, model, name, **where):
    """drumstroke's own data about a ROS message: what made it and what it was validated against.

    The keys of the old in-file ``drumstroke`` key (version, model, name, rate), then the message
    type, ``where`` (the message's file or topic), each joint's stick, the head angle (rad), the
    limits validated against, the units and how the accelerations were made.
    """
    first = checked[0]
    return {"version": __version__, "model": model, "name": name, "rate": first.rate, "type": MESSAGE_TYPE,
            **where, "joints": [{"name": j, "stick": s} for j, s in zip(joint_names, sticks)],
            "head": first.head, "limits": first.limits.to_dict(),
            "units": {"positions": "rad", "velocities": "rad/s", "accelerations": "rad/s^2", "time_from_start": "s"},
            "accelerations": "forward difference (omega[k+1] - omega[k])*rate, 0 at the last sample"}


def _joints(trajectory, theta, omega, rate, model, name, joint_names, head, limits, start):
    """Each joint validated: (Checked per joint, joint names, stick names or None each, model, name)."""
    model, name = _labels(trajectory, model, name, None)
    if isinstance(trajectory, Trajectory):
        sticks = trajectory.sticks
        names = check_joint_names(joint_names, sticks=sticks)
        t, thetas, omegas = trajectory.t, [], []
        for stick in sticks:
            part = trajectory.stick(stick)
            thetas.append(part.theta)
            omegas.append(part.omega)
        starts = [start] if len(sticks) == 1 else (list(start) if start is not None else [None] * len(sticks))
        rate = trajectory.rate if rate is None else rate
    else:
        t = trajectory
        names = check_joint_names(joint_names)
        sticks = (None,) * len(names)
        thetas, omegas, starts = _joint_columns(theta, omega, start, len(names))
    checked = []
    for joint, theta_j, omega_j, start_j in zip(names, thetas, omegas, starts):
        try:
            checked.append(validate(t, theta_j, omega_j, rate=rate, head=head, limits=limits, start=start_j))
        except TrajectoryError as error:
            raise TrajectoryError(f"joint {joint!r}: {error}") from None
    return tuple(checked), names, sticks, model, name


def _columns(checked):
    """Times, then positions, velocities and accelerations [shape=(n, joints)] of validated joints."""
    return (checked[0].t, np.column_stack([c.theta for c in checked]), np.column_stack([c.omega for c in checked]),
            np.column_stack([np.append(c.alpha, 0.0) for c in checked]))


def _labels(trajectory, model, name, stick):
    """The model and name written: given, else (for a Trajectory) its own; arrays must name them."""
    if isinstance(trajectory, Trajectory):
        model = trajectory.model if model is None else model
        name = (trajectory.name or "trajectory") + (f"-{stick}" if stick else "") if name is None else name
    return _check_text("model", model), _check_text("name", name)


def _check_text(name, value):
    if not isinstance(value, str) or "\n" in value or "\r" in value or ";" in value:
        raise ParameterError(f"{name} must be one line of text without ';', got {value!r}")
    return value


def check_joint_names(joint_names, *, sticks=None, name="joint_names"):
    """The ROS joint names: ``joint_names`` as distinct non-empty names, one per stick of ``sticks`` when given.

    Default ``<stick>_joint`` for each of ``sticks`` ("stick_joint" without them). ``name`` is
    the parameter named in the error.
    """
    if joint_names is None:
        return tuple(f"{s}_joint" for s in (sticks or (DEFAULT_STICK,)))
    if isinstance(joint_names, str):
        raise ParameterError(f"{name} must be a sequence of names, got the string {joint_names!r}")
    try:
        names = tuple(joint_names)
    except TypeError:
        raise ParameterError(f"{name} must be a sequence of names, got {joint_names!r}") from None
    if not names or not all(isinstance(n, str) and n.strip() for n in names) or len(set(names)) != len(names):
        raise ParameterError(f"{name} must be distinct non-empty names, at least one, got {joint_names!r}")
    if sticks is not None and len(names) != len(sticks):
        raise ParameterError(f"{name} must be one name per stick ({', '.join(sticks)}), got {len(names)}: "
                             f"{joint_names!r}")
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
