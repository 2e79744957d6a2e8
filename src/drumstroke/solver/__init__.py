"""The hybrid integrator: exact flights, located impacts, the Zeno tail, rest and lift-off."""

from .arcs import Arcs
from .constants import ZENO_HEIGHT, ZENO_SPEED
from .hybrid import MAX_IMPACTS, Solution, solve

__all__ = ["MAX_IMPACTS", "ZENO_HEIGHT", "ZENO_SPEED", "Arcs", "Solution", "solve"]
