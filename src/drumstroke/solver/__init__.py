"""The hybrid integrator: exact flights, located impacts, the Zeno tail, rest and lift-off."""

from .arcs import Arcs
from .hybrid import MAX_IMPACTS, ZENO_SPEED, Solution, solve

__all__ = ["Arcs", "MAX_IMPACTS", "ZENO_SPEED", "Solution", "solve"]
