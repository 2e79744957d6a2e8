"""The hybrid integrator: exact flights, located impacts, the Zeno tail, rest and lift-off."""

from .arcs import Arcs
from .hybrid import MAX_IMPACTS, Solution, solve
from .constants import ZENO_HEIGHT, ZENO_SPEED

__all__ = ["Arcs", "MAX_IMPACTS", "ZENO_HEIGHT", "ZENO_SPEED", "Solution", "solve"]
