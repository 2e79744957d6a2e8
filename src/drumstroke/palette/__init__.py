"""The stroke palette (SPEC §4): trajectories, their post-processing, and the library on disk."""

from ..stroke import as_trajectory
from .transforms import Limits, apply_steps, catch, compress, concat, reverse, stretch, trim

__all__ = [
    "Limits", "apply_steps", "as_trajectory", "catch", "compress", "concat", "reverse", "stretch", "trim",
]
