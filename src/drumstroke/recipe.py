"""Recipes: everything that defines one stroke, as a TOML file a person writes.

A recipe names the model, the stick, the coefficient of restitution, the start
state, the duration, and the two profiles a(t) and g(t). Only ``[force]`` is
required in a file::

    model = "paper"        # or "geometry"
    t_end = 5.0            # s
    theta0 = 0.0           # rad, in [theta_max, pi/2)
    omega0 = 0.0           # rad/s
    cor = 0.86             # in [0, 1]
    [stick]                # Table 1
    length = 0.39          # L, m
    pivot_to_tip = 0.27    # x, m
    pivot_to_com = 0.075   # k, m
    pivot_to_thumb = 0.01  # k', m
    pivot_height = 0.07    # h, m
    mass = 0.0373          # kg
    [force]                # a(t), m/s^2
    kind = "piecewise-linear"
    points = [[0.0, 10.0], [1.0, 10.0], [1.05, 220.0], [2.0, 220.0], [2.05, 10.0]]
    [gravity]              # g(t), m/s^2
    kind = "constant"
    value = 9.8
"""

import math
import os
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path

from ._checks import check_choice, check_keys, check_real
from .errors import ParameterError
from .formats.toml import reading_toml, write_toml
from .model import MODELS, Stick, coefficients
from .profiles import Constant, Profile, Samples, profile_from_dict

T_END_LIMIT = 3600.0
"""Longest stroke (s)."""

OMEGA_LIMIT = 1000.0
"""Largest |ω₀| (rad/s)."""

STANDARD_GRAVITY = 9.8
"""g of the paper's runs (m/s²), the default gravity."""

DEFAULT_COR = 0.86
"""The paper's coefficient of restitution between stick and head."""

COR_RANGE = (0.3, 0.99)
"""The coefficients of restitution a fit searches (``fit_stroke(fit_cor=True)``; drumheads and sticks measure 0.5–0.9)."""

_TOP_KEYS = ("model", "t_end", "theta0", "omega0", "cor", "stick", "force", "gravity")


@dataclass(frozen=True)
class Recipe:
    """Everything that defines one stroke.

    Parameters
    ----------
    force : Profile
        a(t), the thumb's linear acceleration (m/s²); positive presses the tip
        toward the head.
    model : {"paper", "geometry"}
        Which D = I/m to use (see :mod:`drumstroke.model`).
    t_end : float in [1e-6, 3600]
        Duration (s).
    theta0 : float in [theta_max, pi/2)
        Start angle (rad).
    omega0 : float in [-1000, 1000]
        Start angular speed (rad/s).
    cor : float in [0, 1]
        Coefficient of restitution between stick and head.
    stick : Stick
        Geometry and mass.
    gravity : Profile
        g(t) (m/s²).
    name : str
        What the recipe is called (a preset name or a file name); not part of
        the physics.
    """

    force: Profile
    model: str = "paper"
    t_end: float = 5.0
    theta0: float = 0.0
    omega0: float = 0.0
    cor: float = DEFAULT_COR
    stick: Stick = field(default_factory=Stick)
    gravity: Profile = field(default_factory=lambda: Constant(STANDARD_GRAVITY))
    name: str = ""

    def __post_init__(self):
        check_choice("model", self.model, MODELS)
        for name in ("force", "gravity"):
            value = getattr(self, name)
            if not isinstance(value, Profile):
                raise ParameterError(f"{name} must be a profile (e.g. drumstroke.Constant(9.8)), got {value!r}")
        if not isinstance(self.stick, Stick):
            raise ParameterError(f"stick must be a drumstroke.Stick, got {self.stick!r}")
        theta_max = self.stick.theta_max
        checked = {
            "t_end": check_real("t_end", self.t_end, low=1e-6, high=T_END_LIMIT, unit="s"),
            "theta0": check_real(
                "theta0", self.theta0, low=theta_max, high=math.pi / 2, high_open=True, unit="rad (theta_max to pi/2)"
            ),
            "omega0": check_real("omega0", self.omega0, low=-OMEGA_LIMIT, high=OMEGA_LIMIT, unit="rad/s"),
            "cor": check_real("cor", self.cor, low=0.0, high=1.0),
        }
        for key, value in checked.items():
            object.__setattr__(self, key, value)

    def _varied(self, force, t_end, theta0, omega0, name):
        """This recipe with another a(t), duration, start and name, only those checked (a designer's recipe from its
        base, which holds the model, stick, c and g(t) checked: made at every design). Its coefficients are the
        base's (the same model and stick), not worked out again."""
        theta_max = self.stick.theta_max
        recipe = object.__new__(Recipe)
        if not isinstance(force, Profile):
            raise ParameterError(f"force must be a profile (e.g. drumstroke.Constant(9.8)), got {force!r}")
        recipe.__dict__.update(
            force=force, model=self.model,
            t_end=check_real("t_end", t_end, low=1e-6, high=T_END_LIMIT, unit="s"),
            theta0=check_real("theta0", theta0, low=theta_max, high=math.pi / 2, high_open=True,
                              unit="rad (theta_max to pi/2)"),
            omega0=check_real("omega0", omega0, low=-OMEGA_LIMIT, high=OMEGA_LIMIT, unit="rad/s"),
            cor=self.cor, stick=self.stick, gravity=self.gravity, name=name, coefficients=self.coefficients)
        return recipe

    @property
    def theta_max(self):
        """The drumhead angle of this recipe's stick (rad)."""
        return self.stick.theta_max

    @cached_property
    def coefficients(self):
        """The solver's :class:`~drumstroke.model.Coefficients` for this recipe's model and stick."""
        return coefficients(self.model, self.stick)

    def replace(self, **changes):
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)

    def to_dict(self):
        """The recipe as plain data: the same keys as the TOML file."""
        return {
            "model": self.model,
            "t_end": self.t_end,
            "theta0": self.theta0,
            "omega0": self.omega0,
            "cor": self.cor,
            "stick": self.stick.to_dict(),
            "force": self.force.to_dict(),
            "gravity": self.gravity.to_dict(),
        }

    @classmethod
    def from_dict(cls, data, *, name="", base_dir=None):
        """Build a recipe from plain data (as read from TOML); ``base_dir`` anchors ``samples`` files."""
        if not isinstance(data, dict):
            raise ParameterError(f"a recipe must be a table, got {data!r}")
        check_keys("recipe", data, _TOP_KEYS)
        if "force" not in data:
            raise ParameterError("recipe needs a [force] table (the thumb's acceleration a(t))")
        stick = data.get("stick", {})
        if not isinstance(stick, dict):
            raise ParameterError(f"stick must be a table, got {stick!r}")
        check_keys("stick", stick, list(Stick().to_dict()))
        options = {key: data[key] for key in ("model", "t_end", "theta0", "omega0", "cor") if key in data}
        gravity = data.get("gravity", {"kind": "constant", "value": STANDARD_GRAVITY})
        return cls(
            force=profile_from_dict(data["force"], name="force", base_dir=base_dir),
            gravity=profile_from_dict(gravity, name="gravity", base_dir=base_dir),
            stick=Stick(**stick),
            name=name,
            **options,
        )

    @classmethod
    def from_toml(cls, path):
        """Read a recipe file; ``samples`` files are found relative to it.

        A profile whose breakpoints are more than the memory budget's worth is refused naming the
        file (:meth:`drumstroke.profiles.Profile.check_budget`).
        """
        path = Path(path)
        with reading_toml(path, "recipe") as data:
            recipe = cls.from_dict(data, name=path.stem, base_dir=path.parent)
        for name in ("force", "gravity"):
            profile = getattr(recipe, name)
            profile.check_budget(recipe.t_end, what=f"recipe {str(path)!r}: {name} ({profile.kind})")
        return recipe

    def to_toml(self, path, *, bundle=None):
        """Write the recipe as TOML, atomically (a crash leaves any old file whole).

        A ``samples`` file is written relative to the new file's folder when it can be. ``bundle``:
        a :class:`drumstroke._atomic.Bundle` the file is put in place with (default: at once).
        """
        path = Path(path)
        write_toml(path, self.toml_data(path.parent), bundle=bundle)

    def toml_data(self, folder):
        """The recipe as TOML data for a file in ``folder``: ``samples`` files relative to it when they can be."""
        data = self.to_dict()
        _relocate_samples(data["force"], self.force, Path(folder))
        _relocate_samples(data["gravity"], self.gravity, Path(folder))
        return data


def _relocate_samples(data, profile, folder):
    if isinstance(profile, Samples):
        source = os.path.realpath(profile.file)
        try:
            data["file"] = os.path.relpath(source, os.path.realpath(folder))
        except ValueError:  # another drive
            data["file"] = str(source)
    elif data.get("kind") == "sum":
        for part_data, part in zip(data["parts"], profile.parts):
            _relocate_samples(part_data, part, folder)
