"""The inverse of the model: from the notes a stick must play to the force that plays them.

- :mod:`.setup`: :class:`Setup`, what every design and plan of one stick is made with (the model, c,
  the stick, the force range, the joint's limits, the moves' budget).
- :mod:`.flight`: one flight in closed form — the apex and the two forces of a flight of given
  duration, launch and arrival speeds.
- :mod:`.chain`: :func:`design`, the stroke that plays one stick's notes as consecutive bounces,
  checked by simulating it.
- :mod:`.buzz`: :func:`buzz`, a multiple-bounce stroke of a given density and level envelope.
- :mod:`.planner`: :func:`next_stroke`, the one decision of what takes a stick from where it is to
  its next notes (the offline planner's and the live performer's); :func:`plan_stick`, one stick's
  notes as chains of designed strokes joined by moves, the unplayable reported; :func:`assign_sticks`, sticking for parts that name no stick.
"""

from .buzz import DENSITY, buzz
from .chain import ENDS, FORCE_LIMIT, HUMAN_FORCE, Design, ForceRange, Piece, Start, Unreachable, design, design_pieces
from .planner import Problem, StickPlan, Target, assign_sticks, next_stroke, plan_stick
from .setup import Setup

__all__ = ["DENSITY", "ENDS", "FORCE_LIMIT", "HUMAN_FORCE", "Design", "ForceRange", "Piece", "Problem", "Setup", "Start", "StickPlan", "Target", "Unreachable", "assign_sticks", "buzz", "design", "design_pieces", "next_stroke", "plan_stick"]
