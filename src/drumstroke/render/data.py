"""Strokes, trajectories and compositions as data files: JSON and CSV.

Every file records the model that made it; every file is written atomically. A CSV starts
with its header; its metadata (version, model, name, rate, units, sticks) is in the JSON
beside it (:mod:`drumstroke.formats.sidecar`), or in the run's own JSON when that is the
file beside it: the ``csv`` argument of :func:`write_json` and :func:`write_composition_json`.
"""

from ..formats.json import write_json as write_json_data
from ..formats.sidecar import KEY
from ..stroke import as_trajectory
from ..trajectory import DEFAULT_RATE


def write_json(stroke, path, *, csv=None):
    """Write a Stroke's or a Trajectory's ``to_dict()`` as JSON to ``path``, with a CSV's metadata ``csv`` if given."""
    write_json_data(path, _with_csv(stroke.to_dict(), csv))


def write_composition_json(composition, path, *, csv=None):
    """Write a composition's notes, placements, impacts and problems (:func:`composition_to_dict`) as JSON.

    ``csv``: the metadata of the composition's CSV, when this JSON is the one beside it.
    """
    write_json_data(path, _with_csv(composition_to_dict(composition), csv))


def write_csv(stroke, path, *, rate=DEFAULT_RATE, sidecar=True):
    """Write a Stroke's or a Trajectory's θ(t) sampled at ``rate`` (Hz) as CSV with the header ``t,theta,omega``.

    Units: s, rad, rad/s. The metadata goes in the JSON beside it (``sidecar``, see
    :meth:`~drumstroke.trajectory.Trajectory.write_csv`) and is returned.
    """
    return as_trajectory(stroke, rate=rate).write_csv(path, sidecar=sidecar)


def write_composition_csv(composition, path, *, rate=None, sidecar=True):
    """Write a :class:`~drumstroke.compose.Composition` at ``rate`` (Hz; default its own) as CSV.

    One stick: the header ``t,theta,omega``, like a stroke. Several: ``t`` then
    ``theta_<stick>,omega_<stick>`` for each stick in turn. The metadata (with ``offset``, the
    time of the score's time 0, s) goes in the JSON beside it (``sidecar``) and is returned.
    """
    return composition.trajectory.sample(rate).write_csv(path, metadata={"offset": composition.offset},
                                                          sidecar=sidecar)


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
        "designs": [
            {"stick": stick, "model": d.model, "notes": d.times.tolist(), "levels_db": d.levels.tolist(),
             "release": d.release, "t_end": d.t_end, "end": d.end, "force_min": d.min_force,
             "force_max": d.max_force, "beyond_human": d.beyond_human, "time_error": d.time_error,
             "level_error": d.level_error, "recipe": d.recipe.to_dict()}
            for stick, d in composition.designs
        ],
    }


def _with_csv(data, csv):
    return data if csv is None else data | {KEY: csv}
