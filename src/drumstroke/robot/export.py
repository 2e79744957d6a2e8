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

import numpy as np

from .._atomic import write_atomic
from .._version import __version__
from ..errors import ParameterError, TrajectoryError
from ..formats.ros_json import read_ros_json, seconds_to_duration, write_joint_trajectory
from ..formats.sidecar import sidecar_for, write_sidecar
from ..formats.trajectory_csv import columns_text as csv_text
from ..formats.trajectory_csv import metadata as csv_metadata
from ..trajectory import Trajectory
from .validate import validate

__all__ = ["export_csv", "export_ros_json", "read_ros_json", "seconds_to_duration"]


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
    write_atomic(path, csv_text(names, (checked.t, checked.theta, checked.omega, np.append(checked.alpha, 0.0))))
    write_sidecar(side, csv_metadata(path, names, model=model, name=name, rate=checked.rate, sticks=(stick or "stick",),
                                     extra={"note": "alpha is the forward difference (omega[k+1] - omega[k])*rate, "
                                                    "0 at the last sample"}))
    return checked


def export_ros_json(path, trajectory, theta=None, omega=None, *, rate=None, model=None, name=None, joint_names=None,
                    head=None, limits=None, start=None, metadata=True):
    """Validate a trajectory of one or several joints and write it as ROS ``JointTrajectory``-shaped JSON.

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
        One distinct name per joint; default ``<stick>_joint`` for each stick ("stick_joint" for one).
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
    model, name = _labels(trajectory, model, name, None)
    if isinstance(trajectory, Trajectory):
        sticks = trajectory.sticks
        names = _check_joint_names(joint_names if joint_names is not None else [f"{s}_joint" for s in sticks])
        if len(names) != len(sticks):
            raise ParameterError(f"joint_names must name each of the {len(sticks)} sticks, got {joint_names!r}")
        t, thetas, omegas = trajectory.t, [], []
        for stick in sticks:
            part = trajectory.stick(stick)
            thetas.append(part.theta)
            omegas.append(part.omega)
        starts = [start] if len(sticks) == 1 else (list(start) if start is not None else [None] * len(sticks))
        rate = trajectory.rate if rate is None else rate
    else:
        t = trajectory
        names = _check_joint_names(joint_names if joint_names is not None else ("stick_joint",))
        thetas, omegas, starts = _joint_columns(theta, omega, start, len(names))
    checked = []
    for joint, theta_j, omega_j, start_j in zip(names, thetas, omegas, starts):
        try:
            checked.append(validate(t, theta_j, omega_j, rate=rate, head=head, limits=limits, start=start_j))
        except TrajectoryError as error:
            raise TrajectoryError(f"joint {joint!r}: {error}") from None
    times = checked[0].t
    metadata = {"version": __version__, "model": model, "name": name, "rate": checked[0].rate} if metadata else None
    write_joint_trajectory(path, times, np.column_stack([c.theta for c in checked]),
                           np.column_stack([c.omega for c in checked]),
                           np.column_stack([np.append(c.alpha, 0.0) for c in checked]), names, metadata=metadata)
    return tuple(checked)


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
