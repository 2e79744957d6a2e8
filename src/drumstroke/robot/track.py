"""Playing a reference on a simulated joint: the reference at the control rate, the run, what was played.

The reference is a one-stick :class:`~drumstroke.trajectory.Trajectory` at the control rate
(:func:`reference`); :func:`track` steps the one control loop
(:class:`~drumstroke.robot.loop.ControlLoop`) through it on the simple joint or on MuJoCo's.

Examples
--------
>>> import drumstroke
>>> from drumstroke.robot.controllers import controller
>>> ref = reference(drumstroke.simulate("finger-pulses"))
>>> played = track(ref, controller("impedance"))
>>> played.controller, len(played.reference.t), len(played.trajectory.impacts) == len(played.onsets)
('impedance', 5001, True)
"""

import math
from dataclasses import dataclass, replace

import numpy as np

from .._checks import check_real
from ..budget import check_memory, check_time, track_cost
from ..errors import ParameterError
from ..recipe import DEFAULT_COR
from ..stroke import as_trajectory
from ..trajectory import DEFAULT_RATE, Impacts, Trajectory
from . import ENGINES
from .controllers import Controller
from .loop import ControlLoop
from .plant import Plant, SimpleJoint


def reference(source, rate=DEFAULT_RATE):
    """What the robot is asked to play: ``source`` (a Stroke or a one-stick Trajectory) at ``rate`` (Hz).

    Parameters
    ----------
    source : Stroke or Trajectory
    rate : float in [10, 1e5]
        The control rate (Hz).

    Returns
    -------
    Trajectory
        One stick, sampled at ``rate`` (each sample evaluated afresh): θ, ω, the flight acceleration α, the impacts.
    """
    rate = check_real("rate", rate, low=10.0, high=1e5, unit="Hz")
    trajectory = as_trajectory(source, rate=rate)
    return trajectory if not trajectory.carry else replace(trajectory, carry=False)  # each sample afresh


def check_tracking(duration, rate, *, joints=1, controllers=1, name="rate"):
    """Refuse playing ``duration`` s at ``rate`` Hz (``joints`` joints, ``controllers`` runs) beyond the budget.

    The memory of the reference's samples and of each run's angles, speeds and torques, and the time
    of its control periods (:func:`drumstroke.budget.track_cost`); ``name`` is the input as the
    message names it (``"--rate"`` on the command line).

    >>> check_tracking(3600.0, 1e5, name="--rate")
    Traceback (most recent call last):
    ...
    drumstroke.errors.ParameterError: --rate asks for about 31.7 GB of memory (360000001 control periods of 1 joint, 1 run: 3600 s at 100000 Hz), over the budget of 1 GB (raise it with memory_gb)
    """
    periods = math.floor(duration * rate * (1.0 + 1e-12)) + 1
    memory, seconds = track_cost(periods, joints=joints, controllers=controllers)
    detail = (f"{periods} control periods of {joints} joint{'s' * (joints > 1)}, {controllers} "
              f"run{'s' * (controllers > 1)}: {duration:g} s at {rate:g} Hz")
    check_memory(name, memory, detail)
    check_time(name, seconds, detail)


@dataclass(frozen=True, repr=False)
class Played:
    """A reference played by a controller on a plant.

    Attributes
    ----------
    reference : Trajectory
    controller : str
    theta, omega, torque : ndarray [shape=(n,)]
        The joint at each control period: rad, rad/s, N·m.
    onsets, onset_speed : ndarray [shape=(m,)]
        When the stick touched the head (s) and its tip speed then (m/s).
    max_torque : float
        The plant's torque limit (N·m).
    plant : str
        "simple" or "mujoco".
    contacts : Contacts or None
        The joint's contacts as it logged them (ω in rad/s, releases).
    """

    reference: Trajectory
    controller: str
    theta: np.ndarray
    omega: np.ndarray
    torque: np.ndarray
    onsets: np.ndarray
    onset_speed: np.ndarray
    max_torque: float
    plant: str = "simple"
    contacts: object = None

    def __repr__(self):
        ref = self.reference
        return (f"Played({ref.name!r} by {self.controller!r} on the {self.plant} plant, model={ref.model!r}: "
                f"{len(self.theta)} periods at {ref.rate:g} Hz, {len(self.onsets)} onsets for "
                f"{len(ref.impacts)} reference impacts)")

    @property
    def trajectory(self):
        """What the joint played, as a Trajectory at the control rate with its contacts as the impacts.

        Each impact leaves with the speed the head let the stick go with (0 if it was still
        on the head at the end). Without ``contacts`` the impacts are found in the samples.
        """
        ref = self.reference
        info = {"theta_max": ref.theta_max, "rate": ref.rate, "name": f"{ref.name} played by {self.controller}",
                "model": ref.model}
        if self.contacts is None:
            return Trajectory.from_samples(ref.t, self.theta, self.omega, tip_distance=ref.impacts.tip_distance,
                                           **info)
        c = self.contacts
        return Trajectory.from_samples(ref.t, self.theta, self.omega, Impacts(c.t, c.omega, c.tip_distance),
                                       np.nan_to_num(c.omega_after, nan=0.0), **info)


PROGRESS_PERIODS = 1000
"""Control periods between two calls of :func:`track`'s ``progress``."""


def track(reference, controller, plant=None, *, engine="simple", cor=None, progress=None):
    """Play ``reference`` with ``controller`` on ``plant``: many steps of the one control loop.

    The controller steers by the reference (:meth:`~drumstroke.robot.controllers.Controller.steer`);
    the joint starts at the reference's θ[0], ω[0] and its clock at the reference's start.

    Parameters
    ----------
    reference : Trajectory
        One stick at the control rate in [10, 1e5] Hz (:func:`reference`).
    controller : Controller
    plant : Plant, optional
        Default :class:`~drumstroke.robot.plant.Plant`; its head must be the reference's.
    engine : {"simple", "mujoco"}
        The simple joint (:class:`~drumstroke.robot.plant.SimpleJoint`) or MuJoCo's
        (:class:`~drumstroke.robot.mujoco_plant.MujocoJoint`, needs the ``robot`` extra).
    cor : float in [0, 1] or None
        The head's coefficient of restitution; default the reference's recipe's, else
        :data:`drumstroke.recipe.DEFAULT_COR`.
    progress : callable or None
        Called with the fraction of the reference played, every :data:`PROGRESS_PERIODS` periods and at the end.

    Returns
    -------
    Played
    """
    plant = Plant() if plant is None else plant
    if not isinstance(reference, Trajectory) or len(reference.sticks) != 1:
        raise ParameterError("reference must be a one-stick drumstroke Trajectory (see drumstroke.robot.track."
                             f"reference), got {reference!r}")
    if not isinstance(controller, Controller):
        raise ParameterError(f"controller must be a drumstroke.robot.controllers.Controller, got {controller!r}")
    if not isinstance(plant, Plant):
        raise ParameterError(f"plant must be a drumstroke.robot.plant.Plant, got {plant!r}")
    if engine not in ENGINES:
        raise ParameterError(f"engine must be one of {', '.join(ENGINES)}, got {engine!r}")
    rate = check_real("reference.rate", reference.rate, low=10.0, high=1e5, unit="Hz")
    check_tracking(reference.t_end - reference.start, rate, name="reference.rate")
    if abs(plant.head - reference.theta_max) > 1e-9:
        raise ParameterError(f"the reference's head ({reference.theta_max:.6g} rad) is not the plant's "
                             f"({plant.head:.6g} rad); give the plant the stick the reference was made with")
    if cor is None:
        cor = reference.recipe.cor if reference.recipe is not None else DEFAULT_COR
    cor = check_real("cor", cor, low=0.0, high=1.0)
    start = {"theta0": float(reference.theta[0]), "omega0": float(reference.omega[0]), "start": float(reference.t[0])}
    if engine == "mujoco":
        from .mujoco_plant import MujocoJoint

        joint = MujocoJoint(plant, cor, rate=rate, **start)
    else:
        joint = SimpleJoint(plant, cor, **start)
    loop = ControlLoop(joint, controller, rate)
    steered = controller.steer(reference)
    n = len(steered[0])
    for first in range(0, n, PROGRESS_PERIODS):
        loop.run(*(a[first:first + PROGRESS_PERIODS] for a in steered))
        if progress:
            progress(min(first + PROGRESS_PERIODS, n) / n)
    log = loop.log()
    return Played(reference, controller.name, log.theta, log.omega, log.torque, log.onsets,
                  log.contacts.tip_speed, plant.max_torque, engine, log.contacts)
