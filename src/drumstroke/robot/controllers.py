"""Controllers at the control rate, behind one interface: each names its law and its gains.

- :class:`PI`, the paper's: position error in, torque out, gains fixed for every stroke (the
  defaults were picked by hand, as the paper's were, for a small tracking error on Figs. 4–7).
- :class:`PIDFeedforward`: PID plus the model's feedforward, J·α_ref + m·g·k·cos θ_ref, the torque
  the reference itself needs.
- :class:`Impedance`: the same feedforward with a PD spring whose stiffness fades near the head,
  so the drumhead bounces the stick as a drummer's loose grip lets it, and the arm only steers the
  flights between contacts.

The laws run compiled in :mod:`drumstroke.robot.kernel`.

Examples
--------
>>> controller("pi").gains()
array([3., 2., 0., 0.])
>>> controller("impedance", kp=40.0).kp
40.0
"""

from dataclasses import asdict, dataclass, fields

import numpy as np

from .._checks import check_keys, check_real
from ..errors import ParameterError
from . import kernel


class _Controller:
    """What every controller shares: its gains checked on creation, and packed for the kernel in ``slots`` order."""

    slots = ()

    def __post_init__(self):
        for f in fields(self):
            low, high, unit = _RANGES[f.name]
            object.__setattr__(self, f.name, check_real(f"{self.name}.{f.name}", getattr(self, f.name),
                                                        low=low, high=high, unit=unit))

    def gains(self):
        """The gains as the kernel takes them [shape=(4,)]."""
        return np.array([getattr(self, slot) if slot else 0.0 for slot in self.slots])


@dataclass(frozen=True)
class PI(_Controller):
    """τ = Kp·e + Ki·∫e (the paper's controller).

    Parameters
    ----------
    kp : float in [0, 1e4]
        N·m/rad.
    ki : float in [0, 1e6]
        N·m/(rad·s).
    """

    kp: float = 3.0
    ki: float = 2.0
    name = "pi"
    law = kernel.PI
    slots = ("kp", "ki", "", "")


@dataclass(frozen=True)
class PIDFeedforward(_Controller):
    """τ = J·α_ref + m·g·k·cos θ_ref + Kp·e + Ki·∫e + Kd·ė.

    Parameters
    ----------
    kp : float in [0, 1e4]
        N·m/rad.
    ki : float in [0, 1e6]
        N·m/(rad·s).
    kd : float in [0, 1e3]
        N·m·s/rad.
    """

    kp: float = 30.0
    ki: float = 100.0
    kd: float = 0.3
    name = "pid-ff"
    law = kernel.PID_FF
    slots = ("kp", "ki", "kd", "")


@dataclass(frozen=True)
class Impedance(_Controller):
    """τ = J·α_ref + m·g·k·cos θ_ref + s(θ_ref)·(Kp·e + Kd·ė), s fading to ``floor`` at the head.

    Parameters
    ----------
    kp : float in [0, 1e4]
        N·m/rad, in the air.
    kd : float in [0, 1e3]
        N·m·s/rad, in the air.
    band : float in (0, 1]
        Height above the head (rad) below which the spring softens.
    floor : float in [0, 1]
        What is left of it on the head.
    lead : float in [0, 0.02]
        How long the head holds the stick at each impact (s): each flight is
        steered to leave that much later and land on time
        (:func:`drumstroke.robot.track.lead_in_contact`); 0 follows the reference as it is.
    """

    kp: float = 100.0
    kd: float = 2.0
    band: float = 0.05
    floor: float = 0.5
    lead: float = 0.002
    name = "impedance"
    law = kernel.IMPEDANCE
    slots = ("kp", "kd", "band", "floor")



CONTROLLERS = {c.name: c for c in (PI, PIDFeedforward, Impedance)}
"""Every controller by name."""

_RANGES = {"kp": (0.0, 1e4, "N m/rad"), "ki": (0.0, 1e6, "N m/(rad s)"), "kd": (0.0, 1e3, "N m s/rad"),
           "band": (1e-4, 1.0, "rad"), "floor": (0.0, 1.0, ""), "lead": (0.0, 0.02, "s")}


def controller(name, **gains):
    """The controller ``name`` (see :data:`CONTROLLERS`) with some gains changed."""
    if name not in CONTROLLERS:
        raise ParameterError(f"controller must be one of {', '.join(CONTROLLERS)}, got {name!r}")
    cls = CONTROLLERS[name]
    check_keys(f"controller {name}", gains, [f.name for f in fields(cls)])
    return cls(**gains)


def controller_from_dict(name, table):
    """A controller from a TOML ``[controller.NAME]`` table of gains."""
    if not isinstance(table, dict):
        raise ParameterError(f"controller.{name} must be a table of gains, got {table!r}")
    return controller(name, **table)


def to_dict(controller):
    """The controller's gains as a table."""
    return asdict(controller)
