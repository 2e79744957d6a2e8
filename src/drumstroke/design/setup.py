"""What every stroke of one stick is designed and planned with: a :class:`Setup`, made once.

The designer, the planner, composition and the live performer each take one frozen setup (the
model, c, the stick, the thumb's force range, the joint's limits and the moves' budget) instead
of the same keyword arguments passed down through every call.

Examples
--------
>>> setup = Setup(model="geometry", cor=0.8)
>>> setup.forces, setup.head == setup.stick.theta_max
(ForceRange(low=0.0, high=3000.0), True)
>>> Setup(limits=Limits(theta_high=0.5)).moves.theta_high      # the moves keep the joint's range
0.5
>>> Setup(cor=1.0)
Traceback (most recent call last):
...
drumstroke.errors.ParameterError: cor must be in [0, 1), got 1.0
"""

import functools
from dataclasses import dataclass, field, replace

from .._checks import check_choice, check_real
from ..errors import ParameterError
from ..model import MODELS, Stick
from ..palette.motion import RETURN_LIMITS, Limits
from ..profiles import ACCELERATION_LIMIT
from ..recipe import DEFAULT_COR

FORCE_LIMIT = 3000.0
"""The default strongest a(t) a design may ask for (m/s²): 12 times the human thumb."""


@dataclass(frozen=True)
class ForceRange:
    """The thumb accelerations a design may use (m/s²).

    Parameters
    ----------
    low : float in [-1e6, high)
        m/s²; default 0, the thumb only presses (negative values pull the stick up: un-natural).
    high : float in (low, 1e6]
        m/s²; default :data:`FORCE_LIMIT`.
    """

    low: float = 0.0
    high: float = FORCE_LIMIT

    def __post_init__(self):
        low = check_real("forces.low", self.low, low=-ACCELERATION_LIMIT, high=ACCELERATION_LIMIT, unit="m/s^2")
        high = check_real("forces.high", self.high, low=low, high=ACCELERATION_LIMIT, low_open=True, unit="m/s^2")
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)


@dataclass(frozen=True)
class Setup:
    """The context of every design and plan of one stick.

    Parameters
    ----------
    model : {"paper", "geometry"}
        The model the strokes are designed with.
    cor : float in [0, 1)
        The coefficient of restitution c of the head.
    stick : Stick
        The stick (its head angle θ_max, rad, and its geometry); default the paper's (Table 1).
    forces : ForceRange
        The thumb accelerations a design may use (m/s²); default 0 to :data:`FORCE_LIMIT`.
    limits : Limits
        The joint's range (rad), speed (rad/s) and acceleration (rad/s²) every stroke keeps;
        default ``Limits()``.
    moves : Limits, optional
        The budget of the jerk-limited moves between strokes; default
        :data:`~drumstroke.palette.motion.RETURN_LIMITS` (gentler than the joint can) narrowed to
        ``limits`` (:meth:`~drumstroke.palette.motion.Limits.within`): no move leaves the joint's range.
    """

    model: str = "paper"
    cor: float = DEFAULT_COR
    stick: Stick = field(default_factory=Stick)
    forces: ForceRange = field(default_factory=ForceRange)
    limits: Limits = field(default_factory=Limits)
    moves: Limits | None = None

    def __post_init__(self):
        check_choice("model", self.model, MODELS)
        object.__setattr__(self, "cor", check_real("cor", self.cor, low=0.0, high=1.0, high_open=True))
        for name, kind, where in (("stick", Stick, "drumstroke.Stick"),
                                  ("forces", ForceRange, "drumstroke.design.ForceRange"),
                                  ("limits", Limits, "drumstroke.palette.motion.Limits"),
                                  ("moves", Limits, "drumstroke.palette.motion.Limits")):
            if not isinstance(getattr(self, name), kind) and not (name == "moves" and self.moves is None):
                raise ParameterError(f"{name} must be a {where}, got {getattr(self, name)!r}")
        if self.moves is None:
            object.__setattr__(self, "moves", _default_moves(self.limits))
        # asked for at every design and looked up in the planner's caches: worked out once
        object.__setattr__(self, "_head", self.stick.theta_max)
        # of numbers only (the model by its index): the same in every process, so a pickled setup keeps it right
        object.__setattr__(self, "_hash", hash((MODELS.index(self.model), self.cor, self.stick, self.forces,
                                                self.limits, self.moves)))

    def __hash__(self):
        return self._hash

    @property
    def head(self):
        """θ_max (rad): where the stick meets the head."""
        return self._head

    def replace(self, **changes):
        """The same setup with ``changes`` (validated again); new ``limits`` narrow the default moves anew."""
        if "limits" in changes and "moves" not in changes and self.moves == _default_moves(self.limits):
            changes["moves"] = None
        return replace(self, **changes)


@functools.lru_cache(maxsize=64)
def _default_moves(limits):
    """The default moves' budget within the joint's ``limits``: worked out once for each (every design makes a setup)."""
    return RETURN_LIMITS.within(limits)
