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

A kit's trajectory — a :class:`~drumstroke.compose.KitComposition` or the
:class:`~drumstroke.formats.trajectory_csv.KitSamples` of a kit CSV — exports every joint of every
limb, validated by :func:`~drumstroke.robot.validate.validate_kit`: as a kit CSV with each joint's
acceleration, or as one ``JointTrajectory`` of one joint per column (:func:`ros_joint_name`).

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

import re
from pathlib import Path

import numpy as np

from .._atomic import Bundle, write_atomic
from .._version import __version__
from ..errors import ParameterError, TrajectoryError
from ..formats.ros_json import MESSAGE_TYPE, read_ros_json, seconds_to_duration, write_joint_trajectory
from ..formats.sidecar import sidecar_for, write_sidecar
from ..formats.trajectory_csv import KitSamples, range_only, write_kit
from ..formats.trajectory_csv import columns_text as csv_text
from ..formats.trajectory_csv import metadata as csv_metadata
from ..trajectory import DEFAULT_STICK, Trajectory
from .validate import kit_samples, validate, validate_kit

__all__ = ["export_csv", "export_ros_json", "export_rosbag", "read_ros_json", "ros_joint_name", "seconds_to_duration"]

ACCELERATIONS = "forward difference (omega[k+1] - omega[k])*rate, 0 at the last sample"
"""How every export's accelerations are made."""

_ROS_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


def export_csv(path, trajectory, theta=None, omega=None, *, rate=None, model=None, name=None, head=None, limits=None,
               start=None, stick=None):
    """Validate a trajectory and write it as CSV ``t,theta,omega,alpha`` (s, rad, rad/s, rad/s²).

    The header comes first; the drumstroke version, the model, the name, the rate and the
    units are in the JSON beside it (``X.json`` for ``X.csv``, see :mod:`drumstroke.formats.sidecar`).
    :func:`~drumstroke.robot.validate.validate_file` and
    :meth:`drumstroke.trajectory.Trajectory.read_csv` read it back.

    A kit's trajectory is written as a kit CSV (:func:`~drumstroke.formats.trajectory_csv.write_kit`):
    ``t``, every joint's angle, speed and acceleration ``LIMB.JOINT.acceleration`` (the same forward
    difference), its metadata in the JSON beside it.

    Parameters
    ----------
    path : str or Path
    trajectory : Trajectory, ndarray, KitComposition or KitSamples
        A :class:`~drumstroke.trajectory.Trajectory` (one stick, or name its ``stick``), or the
        times t (s) [shape=(n,)] of samples given as arrays with ``theta`` (rad) and ``omega`` (rad/s);
        or a kit's trajectory (see :func:`export_ros_json`).
    rate : float or None
        The control rate (Hz); default the trajectory's (arrays: 1000).
    model, name : str or None
        What made the trajectory and what it is called (one line each, no ';'); default the
        trajectory's (arrays must give them).
    head, limits, start, stick
        As for :func:`~drumstroke.robot.validate.validate` (a kit: ``limits`` only, as for
        :func:`~drumstroke.robot.validate.validate_kit`).

    Returns
    -------
    Checked, or tuple of Checked
        What was validated and written (a kit: one per joint).
    """
    if _is_kit(trajectory):
        _refuse_for_kit(theta=theta, omega=omega, head=head, start=start, stick=stick)
        samples, checked, _ = _kit_joints(trajectory, rate, model, name, None, limits)
        write_kit(path, samples, accelerations={c: np.append(k.alpha, 0.0) for c, k in zip(samples.positions, checked)},
                  extra={"note": f"acceleration is the {ACCELERATIONS}"})
        return checked
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
    trajectory : Trajectory, ndarray, KitComposition or KitSamples
        A :class:`~drumstroke.trajectory.Trajectory`, one joint per stick; or the times (s) from the
        header stamp [shape=(n,)] of samples given as arrays, t[0] ≥ 0, written exactly split as
        ``time_from_start`` {sec, nanosec}, nanosec in [0, 1e9), rounded to the nearest nanosecond;
        or a kit's trajectory, one joint per column (a :class:`~drumstroke.compose.KitComposition`,
        sampled at ``rate``, default its own; or the :class:`~drumstroke.formats.trajectory_csv.KitSamples`
        of a kit CSV), validated by :func:`~drumstroke.robot.validate.validate_kit`.
    theta, omega : ndarray [shape=(n,) or (n, joints)] or None
        With times: rad, rad/s; one column per joint.
    rate : float or None
        The control rate (Hz); default the trajectory's (arrays: 1000).
    model, name : str or None
        One line each, no ';'; default the trajectory's (arrays must give them).
    joint_names : sequence of str or None
        One distinct ROS name (a letter, then letters, digits and "_") per joint, in the order of the trajectory's
        sticks (a kit's: its columns); default ``<stick>_joint`` for each stick ("stick_joint" for
        one), a kit's :func:`ros_joint_name` of each column.
    head, limits
        As for :func:`~drumstroke.robot.validate.validate`, the same for every joint (a kit: ``limits``
        only, the sticks' θ limits as for :func:`~drumstroke.robot.validate.validate_kit`).
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
    checked, names, describe = _ros_joints(trajectory, theta, omega, rate, model, name, joint_names, head, limits,
                                           start)
    write_joint_trajectory(path, *_columns(checked), names,
                           metadata=describe(message=Path(path).name) if metadata else None)
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
    checked, names, describe = _ros_joints(trajectory, theta, omega, rate, model, name, joint_names, head, limits,
                                           start)
    write_rosbag(path, joint_trajectory(*_columns(checked), names), topic=topic, storage=storage,
                 metadata=describe(topic=topic), overwrite=overwrite)
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
            "accelerations": ACCELERATIONS}


def ros_joint_name(column):
    """The ROS joint name of a kit's column: '.' and '-' become '_'.

    Examples
    --------
    >>> ros_joint_name("right.yaw"), ros_joint_name("right-foot.theta")
    ('right_yaw', 'right_foot_theta')
    """
    return column.replace(".", "_").replace("-", "_")


def _ros_joints(trajectory, theta, omega, rate, model, name, joint_names, head, limits, start):
    """Each joint validated, the joint names, and the function that makes the message's metadata (where it goes)."""
    if _is_kit(trajectory):
        _refuse_for_kit(theta=theta, omega=omega, head=head, start=start)
        samples, checked, names = _kit_joints(trajectory, rate, model, name, joint_names, limits)
        return checked, names, lambda **where: _kit_ros_metadata(samples, checked, names, **where)
    checked, names, sticks, model, name = _joints(trajectory, theta, omega, rate, model, name, joint_names, head,
                                                 limits, start)
    return checked, names, lambda **where: ros_metadata(checked, names, sticks, model, name, **where)


def _is_kit(trajectory):
    from ..compose import KitComposition

    return isinstance(trajectory, (KitComposition, KitSamples))


def _refuse_for_kit(**given):
    for option, value in given.items():
        if value is not None:
            raise ParameterError(f"{option} is not for a kit's trajectory: its joints' heads, ranges and samples are "
                                 f"its own; got {option}={value!r}")


def _kit_joints(trajectory, rate, model, name, joint_names, limits):
    """A kit's samples (at ``rate``, labelled), each joint validated (a tuple, in column order), the ROS names."""
    if rate is not None and isinstance(trajectory, KitSamples):
        if rate != trajectory.rate:
            raise ParameterError(f"rate must be the kit trajectory's own, {trajectory.rate:g} Hz, or None, "
                                 f"got {rate!r}")
    else:
        trajectory = trajectory.samples(rate) if rate is not None else trajectory
    samples, _ = kit_samples(trajectory)
    samples = samples._replace(model=_check_text("model", samples.model if model is None else model),
                               name=_check_text("name", samples.name if name is None else name))
    columns = tuple(samples.positions)
    names = check_joint_names([ros_joint_name(c) for c in columns] if joint_names is None else joint_names,
                              sticks=columns, what="joint")
    return samples, tuple(validate_kit(samples, limits=limits).values()), names


def _kit_ros_metadata(samples, checked, joint_names, **where):
    """drumstroke's own data about a kit's ROS message: as :func:`ros_metadata`, each joint with its column and
    the limits it was validated against (a beater's range alone), and the offset of the score's time 0."""
    joints = [{"name": joint, "column": column,
               "limits": table if range_only(table) else c.limits.to_dict()}
              for joint, column, c, table in zip(joint_names, samples.positions, checked, samples.limits.values())]
    return {"version": __version__, "model": samples.model, "name": samples.name, "rate": samples.rate,
            "type": MESSAGE_TYPE, **where, "joints": joints, "offset": samples.offset,
            "units": {"positions": "rad", "velocities": "rad/s", "accelerations": "rad/s^2", "time_from_start": "s"},
            "accelerations": ACCELERATIONS}


def _joints(trajectory, theta, omega, rate, model, name, joint_names, head, limits, start):
    """Each joint validated: (Checked per joint, joint names, stick names or None each, model, name)."""
    model, name = _labels(trajectory, model, name, None)
    if isinstance(trajectory, Trajectory):
        sticks = trajectory.sticks
        names = check_joint_names(joint_names, sticks=sticks)
        t, thetas, omegas, impacts = trajectory.t, [], [], []
        for stick in sticks:
            part = trajectory.stick(stick)
            thetas.append(part.theta)
            omegas.append(part.omega)
            impacts.append(part.impacts.t)
        starts = [start] if len(sticks) == 1 else (list(start) if start is not None else [None] * len(sticks))
        rate = trajectory.rate if rate is None else rate
    else:
        t = trajectory
        names = check_joint_names(joint_names)
        sticks = (None,) * len(names)
        thetas, omegas, starts = _joint_columns(theta, omega, start, len(names))
        impacts = [None] * len(names)
    checked = []
    for joint, theta_j, omega_j, start_j, impacts_j in zip(names, thetas, omegas, starts, impacts):
        try:
            checked.append(validate(t, theta_j, omega_j, rate=rate, head=head, limits=limits, start=start_j,
                                    impacts=impacts_j))
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


def check_joint_names(joint_names, *, sticks=None, name="joint_names", what="stick"):
    """The ROS joint names: ``joint_names`` as distinct ROS names, one per stick of ``sticks`` when given.

    A ROS name is a letter, then letters, digits and '_'. Default ``<stick>_joint`` for each of
    ``sticks`` ("stick_joint" without them). ``name`` is the parameter named in the error, ``what``
    what ``sticks`` are ("stick", "joint").
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
        raise ParameterError(f"{name} must be one name per {what} ({', '.join(sticks)}), got {len(names)}: "
                             f"{joint_names!r}")
    bad = next((n for n in names if not _ROS_NAME.fullmatch(n)), None)
    if bad is not None:
        raise ParameterError(f"{name} must be ROS names, a letter then letters, digits and '_' "
                             f"([A-Za-z][A-Za-z0-9_]*), got {bad!r}")
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
