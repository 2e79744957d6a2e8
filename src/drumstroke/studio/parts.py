"""The studio's part operations: what the part editor, its audio and downloads, and the robot view ask for.

Each operation is a function ``(studio, request) -> dict or File`` (:mod:`drumstroke.studio.session`); a
refused input is a :class:`~drumstroke.errors.ParameterError` naming the field.
"""

from ..palette.rudiments import rudiments as all_rudiments
from .session import fields


def rudiments(studio, request):
    """``{}`` -> ``{"rudiments": [{"number", "name", "title", "tempo": [low, high]}, ...]}``: the 40 PAS rudiments."""
    fields(request)
    return {"rudiments": [{"number": r.number, "name": r.name, "title": r.title, "tempo": list(r.tempo)}
                          for r in all_rudiments()]}


OPERATIONS = {"rudiments": rudiments}
"""This module's operations by name."""
