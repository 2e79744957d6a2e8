"""The stroke palette (SPEC §4): trajectories, their post-processing, and the library on disk."""

from .trajectory import Trajectory
from .transforms import Limits, apply_steps, as_trajectory, catch, compress, concat, reverse, stretch, trim

__all__ = [
    "Limits", "Trajectory", "apply_steps", "as_trajectory", "catch", "compress", "concat", "reverse", "stretch", "trim",
]
