"""A robot config: the plant, every controller's gains and the joint's limits, read once from one TOML file.

A config file has up to three tables, each optional (missing values take the defaults)::

    [plant]                  # drumstroke.robot.plant.Plant's fields; [plant.stick] a Stick's
    gear_ratio = 20.0

    [controller.impedance]   # one table per controller (pi, pid-ff, impedance) of its gains
    kp = 40.0

    [limits]                 # drumstroke.palette.motion.Limits' fields
    max_speed = 30.0

:func:`load_source` turns what a user names (a preset, a recipe file, a library stroke or a
trajectory CSV) into the :class:`~drumstroke.trajectory.Trajectory` the robot is asked to play.

Examples
--------
>>> config = RobotConfig.from_dict({"plant": {"gear_ratio": 10.0}, "controller": {"pi": {"kp": 5.0}}})
>>> config.plant.gear_ratio, config.controllers["pi"].kp, list(config.controllers)
(10.0, 5.0, ['pi', 'pid-ff', 'impedance'])
>>> RobotConfig().limits.max_speed
30.0
"""

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from .._checks import check_keys
from ..errors import ParameterError
from ..formats.toml import reading_toml
from ..palette.motion import Limits
from .controllers import CONTROLLERS, controller_from_dict, to_dict
from .plant import Plant

TABLES = ("plant", "controller", "limits")
"""The top-level tables a robot config file may have."""


def _default_controllers():
    return {name: controller_from_dict(name, {}) for name in CONTROLLERS}


@dataclass(frozen=True)
class RobotConfig:
    """The simulated joint, the controllers' gains and the joint's limits.

    Parameters
    ----------
    plant : Plant
        The joint (motor, gearbox, stick, drumhead). Default: ``Plant()``.
    controllers : mapping of str to controller
        Each controller by name (keys of :data:`~drumstroke.robot.controllers.CONTROLLERS`), with its
        gains; stored read-only. Default: every controller with its default gains.
    limits : Limits
        What the joint may do (rad, rad/s, rad/s², rad/s³), for validation and export.
        Default: ``Limits()``.
    """

    plant: Plant = field(default_factory=Plant)
    controllers: Mapping = field(default_factory=_default_controllers)
    limits: Limits = field(default_factory=Limits)

    def __post_init__(self):
        if not isinstance(self.plant, Plant):
            raise ParameterError(f"plant must be a drumstroke.robot.plant.Plant, got {self.plant!r}")
        if not isinstance(self.limits, Limits):
            raise ParameterError(f"limits must be a drumstroke.palette.motion.Limits, got {self.limits!r}")
        try:
            controllers = dict(self.controllers)
        except (TypeError, ValueError):
            raise ParameterError(f"controllers must be a mapping of name to controller, got "
                                 f"{self.controllers!r}") from None
        for name, law in controllers.items():
            if name not in CONTROLLERS or not isinstance(law, CONTROLLERS[name]):
                raise ParameterError(f"controllers[{name!r}] must be a {', '.join(CONTROLLERS)} controller under "
                                     f"its own name, got {law!r}")
        object.__setattr__(self, "controllers", MappingProxyType(controllers))

    @classmethod
    def from_dict(cls, data):
        """A config from a TOML document as a dict: ``[plant]``, ``[controller.NAME]`` and ``[limits]`` tables.

        Missing tables and values take the defaults; an unknown table or key is a ParameterError that names it.
        """
        if not isinstance(data, dict):
            raise ParameterError(f"robot config must be a table, got {data!r}")
        check_keys("robot config", data, TABLES)
        plant = Plant.from_dict(data.get("plant", {}))
        tables = data.get("controller", {})
        if not isinstance(tables, dict):
            raise ParameterError(f"controller must be a table of [controller.NAME] tables, got {tables!r}")
        check_keys("controller", tables, list(CONTROLLERS))
        controllers = {name: controller_from_dict(name, tables.get(name, {})) for name in CONTROLLERS}
        return cls(plant, controllers, Limits.from_dict(data.get("limits", {})))

    @classmethod
    def from_toml(cls, path):
        """A config from the TOML file at ``path`` (see :meth:`from_dict`)."""
        with reading_toml(path, "robot config") as data:
            return cls.from_dict(data)

    def to_dict(self):
        """The config as plain data, tables as in a config file (:meth:`from_dict` reads it back)."""
        return {"plant": self.plant.to_dict(),
                "controller": {name: to_dict(law) for name, law in self.controllers.items()},
                "limits": self.limits.to_dict()}


def load_source(source, *, library=None, stick=None, plant=None):
    """The trajectory a robot is asked to play, from what a user names.

    Parameters
    ----------
    source : str or Path
        With ``library``, the name of one of its strokes; otherwise a trajectory ``.csv`` file (one
        stick's t (s), θ (rad), ω (rad/s); its impacts are found in the samples), or what
        :func:`~drumstroke.palette.library.make_stroke` takes: a recipe ``.toml`` file, a preset
        name or the name of a stroke of the shipped palette.
    library : str, Path, Library or None
        A stroke library (a folder written by ``build_library`` or a loaded
        :class:`~drumstroke.palette.library.Library`).
    stick : str or None
        The stick to read from a composition CSV (which has several); ignored for other sources.
    plant : Plant or None
        The joint whose head angle θ_max (rad) and stick length (m) a CSV's impacts are found with.
        Default: ``Plant()``.

    Returns
    -------
    Trajectory
    """
    from ..palette.library import make_stroke
    from ..stroke import as_trajectory

    if library is None and str(source).lower().endswith(".csv"):
        from ..trajectory import Trajectory

        plant = Plant() if plant is None else plant
        return Trajectory.read_csv(source, stick=stick, theta_max=plant.head, tip_distance=plant.stick.pivot_to_tip)
    return as_trajectory(make_stroke(source, library=library))
