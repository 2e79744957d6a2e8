"""The stroke palette: trajectories, their post-processing, and the library on disk."""

from ..stroke import as_trajectory
from .motion import RETURN_LIMITS, Limits, concat
from .transforms import apply_steps, catch, compress, reverse, stretch, trim

__all__ = [
    "RETURN_LIMITS",
    "Limits",
    "apply_steps",
    "as_trajectory",
    "catch",
    "compress",
    "concat",
    "reverse",
    "stretch",
    "trim",
]
