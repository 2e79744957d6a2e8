"""The stick and the two named models of its dynamics (the paper's Section 3.3).

The stick is a uniform rigid rod turning about a fixed fulcrum. With θ its
angle (rad, 0 parallel to the head, downward negative) the equation of motion
is

    dω/dt = −cos θ · (k·g(t) + k′·a(t)) / D

where D = I/m (m²). The two models differ only in D:

``paper``
    D = 0.0714 m², as printed in the paper's Eq. 7 (the paper's simulations and
    figures use it). The default.
``geometry``
    D = (3x² − 3xL + L²)/3 from the stick's length L and fulcrum-to-tip distance
    x (paper Eq. 1). For Table 1 this is 0.0183 m², so the dynamics run about
    3.9 times faster than in the ``paper`` model.

Examples
--------
>>> stick = Stick()
>>> round(stick.theta_max, 4)
-0.2623
>>> round(inertia_ratio("geometry", stick), 4)
0.0183
>>> coefficients("paper", stick).torque_rate(9.8, 0.0) == 0.735 / 0.0714
True
"""

import math
from dataclasses import dataclass

from ._checks import check_choice, check_real
from .errors import ParameterError

MODELS = ("paper", "geometry")
"""The names of the models, the default first."""

PAPER_INERTIA_RATIO = 0.0714
"""D of the paper's Eq. 7 (m²)."""


@dataclass(frozen=True)
class Stick:
    """A drumstick and where it is held (defaults: Table 1, Zildjian Maple Mini-ball).

    Parameters
    ----------
    length : float > 0
        L, the stick's length (m).
    pivot_to_tip : float in (pivot_height, length]
        x, fulcrum to tip (m).
    pivot_to_com : float in [0, length)
        k, fulcrum to the centre of mass (m).
    pivot_to_thumb : float in [0, length)
        k′, fulcrum to the thumb's contact (m).
    pivot_height : float in (0, pivot_to_tip)
        h, height of the fulcrum above the drumhead (m).
    mass : float > 0
        m (kg); converts the thumb's acceleration to a force.
    """

    length: float = 0.39
    pivot_to_tip: float = 0.27
    pivot_to_com: float = 0.075
    pivot_to_thumb: float = 0.01
    pivot_height: float = 0.07
    mass: float = 0.0373

    def __post_init__(self):
        length = check_real("stick.length", self.length, low=0.0, high=10.0, low_open=True, unit="m")
        tip = check_real("stick.pivot_to_tip", self.pivot_to_tip, low=0.0, high=length, low_open=True, unit="m")
        com = check_real("stick.pivot_to_com", self.pivot_to_com, low=0.0, high=length, high_open=True, unit="m")
        thumb = check_real("stick.pivot_to_thumb", self.pivot_to_thumb, low=0.0, high=length, high_open=True, unit="m")
        height = check_real("stick.pivot_height", self.pivot_height, low=0.0, high=10.0, low_open=True, unit="m")
        if height >= tip:
            raise ParameterError(
                f"stick.pivot_height must be in (0, pivot_to_tip = {tip:g}) m so the tip reaches the head, got {height!r}"
            )
        mass = check_real("stick.mass", self.mass, low=0.0, high=100.0, low_open=True, unit="kg")
        for name, value in zip(
            ("length", "pivot_to_tip", "pivot_to_com", "pivot_to_thumb", "pivot_height", "mass"),
            (length, tip, com, thumb, height, mass),
        ):
            object.__setattr__(self, name, value)

    @property
    def theta_max(self):
        """The angle at which the tip touches the head, −asin(h/x) (rad, paper Eq. 5)."""
        return -math.asin(self.pivot_height / self.pivot_to_tip)

    def to_dict(self):
        """The stick as a plain dict, keys as in a recipe's ``[stick]`` table."""
        return {
            "length": self.length,
            "pivot_to_tip": self.pivot_to_tip,
            "pivot_to_com": self.pivot_to_com,
            "pivot_to_thumb": self.pivot_to_thumb,
            "pivot_height": self.pivot_height,
            "mass": self.mass,
        }


def inertia_ratio(model, stick):
    """D = I/m of ``model`` for ``stick`` (m²).

    Parameters
    ----------
    model : {"paper", "geometry"}
    stick : Stick
    """
    check_choice("model", model, MODELS)
    if model == "paper":
        return PAPER_INERTIA_RATIO
    length, tip = stick.length, stick.pivot_to_tip
    return (3 * tip**2 - 3 * tip * length + length**2) / 3


@dataclass(frozen=True)
class Coefficients:
    """The numbers the solver needs from a model and a stick.

    Attributes
    ----------
    k, k_thumb : float
        Lever arms of gravity and of the thumb (m).
    inertia_ratio : float
        D (m²).
    theta_max : float
        The drumhead angle (rad).
    tip_distance : float
        x, converts angular speed to tip speed (m).
    """

    k: float
    k_thumb: float
    inertia_ratio: float
    theta_max: float
    tip_distance: float

    def torque_rate(self, gravity, force):
        """C = (k·g + k′·a)/D (s⁻²) for gravity g and thumb acceleration a (m/s²).

        Works element-wise on arrays. C > 0 presses the stick toward the head.
        """
        return (self.k * gravity + self.k_thumb * force) / self.inertia_ratio


def coefficients(model, stick):
    """The :class:`Coefficients` of ``model`` for ``stick``."""
    return Coefficients(
        k=stick.pivot_to_com,
        k_thumb=stick.pivot_to_thumb,
        inertia_ratio=inertia_ratio(model, stick),
        theta_max=stick.theta_max,
        tip_distance=stick.pivot_to_tip,
    )
