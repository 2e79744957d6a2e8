"""Strokes, trajectories and compositions as data files: JSON and CSV.

Every file records the model that made it; every file is written atomically.
"""

from ..formats.json import write_json as write_json_data
from ..stroke import as_trajectory
from ..trajectory import DEFAULT_RATE


def write_json(stroke, path):
    """Write a Stroke's or a Trajectory's ``to_dict()`` as JSON to ``path``."""
    write_json_data(path, stroke.to_dict())


def write_composition_json(composition, path):
    """Write a composition's notes, placements, impacts and problems (:func:`composition_to_dict`) as JSON."""
    write_json_data(path, composition_to_dict(composition))


def write_csv(stroke, path, *, rate=DEFAULT_RATE):
    """Write a Stroke's or a Trajectory's θ(t) sampled at ``rate`` (Hz) as CSV with the header ``t,theta,omega``.

    One comment line (``#``) comes first: the drumstroke version, the model, the
    stroke's name and the rate. Units: s, rad, rad/s.
    """
    as_trajectory(stroke, rate=rate).write_csv(path)


def write_composition_csv(composition, path, *, rate=None):
    """Write a :class:`~drumstroke.compose.Composition` at ``rate`` (Hz; default its own) as CSV.

    One stick: the header ``t,theta,omega``, like a stroke. Several: ``t`` then
    ``theta_<stick>,omega_<stick>`` for each stick in turn.
    """
    composition.trajectory.sample(rate).write_csv(path, note=f"score time 0 at t = {composition.offset:g} s")


def composition_to_dict(composition):
    """A composition's notes and impacts as plain data for JSON."""
    return {
        "model": composition.model,
        "rate": composition.rate,
        "offset": composition.offset,
        "t_end": composition.t_end,
        "notes": [
            {"time": p.note.time, "stroke": p.note.stroke, "velocity": p.note.velocity, "stick": p.note.stick,
             "source": p.note.source, "played": p.played, "impact": p.impact if p.played else None,
             "start": p.start if p.played else None, "factor": p.factor, "cut": p.cut}
            for p in composition.placements
        ],
        "impacts": {stick: s.to_dict()["impacts"] for stick, s in composition.sticks.items()},
        "problems": list(composition.problems),
    }
