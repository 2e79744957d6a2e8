"""The stroke palette (SPEC §4): trajectories, their post-processing, and the library on disk."""

from .transforms import Limits, as_trajectory, compress, concat, reverse, stretch, trim
from .trajectory import Trajectory

__all__ = ["Limits", "Trajectory", "as_trajectory", "compress", "concat", "reverse", "stretch", "trim"]
