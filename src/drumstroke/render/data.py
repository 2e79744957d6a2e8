"""Strokes, trajectories and compositions as data files: JSON and CSV.

Every file records the model that made it; every file is written atomically, and each writer
puts its files in place with those of a ``bundle`` (a :class:`drumstroke._atomic.Bundle`) when
given one. A CSV starts
with its header; its metadata (version, model, name, rate, units, sticks) is in the JSON
beside it (:mod:`drumstroke.formats.sidecar`), or in the run's own JSON when that is the
file beside it: the ``csv`` argument of :func:`write_json` and :func:`write_composition_json`.
"""

from ..formats.json import write_json as write_json_data
from ..formats.sidecar import KEY
from ..stroke import as_trajectory
from ..trajectory import DEFAULT_RATE


def write_json(stroke, path, *, csv=None, extra=None, bundle=None):
    """Write a Stroke's or a Trajectory's ``to_dict()`` as JSON to ``path``, with a CSV's metadata ``csv`` if given
    and the fields of ``extra`` (a dict) beside its own."""
    write_json_data(path, _with_csv(stroke.to_dict() | (extra or {}), csv), bundle=bundle)


def write_composition_json(composition, path, *, csv=None, bundle=None):
    """Write a composition's notes, placements, impacts and problems (:func:`composition_to_dict`) as JSON.

    ``csv``: the metadata of the composition's CSV, when this JSON is the one beside it.
    """
    write_json_data(path, _with_csv(composition_to_dict(composition), csv), bundle=bundle)


def write_csv(stroke, path, *, rate=DEFAULT_RATE, sidecar=True, bundle=None):
    """Write a Stroke's or a Trajectory's θ(t) sampled at ``rate`` (Hz) as CSV with the header ``t,theta,omega``.

    Units: s, rad, rad/s. The metadata goes in the JSON beside it (``sidecar``, see
    :meth:`~drumstroke.trajectory.Trajectory.write_csv`) and is returned.
    """
    return as_trajectory(stroke, rate=rate).write_csv(path, sidecar=sidecar, bundle=bundle)


def write_composition_csv(composition, path, *, rate=None, sidecar=True, bundle=None):
    """Write a :class:`~drumstroke.compose.Composition` at ``rate`` (Hz; default its own) as CSV.

    One stick: the header ``t,theta,omega``, like a stroke. Several: ``t`` then
    ``theta_<stick>,omega_<stick>`` for each stick in turn. The metadata (with ``offset``, the
    time of the score's time 0, s) goes in the JSON beside it (``sidecar``) and is returned.
    """
    return composition.trajectory.sample(rate).write_csv(path, metadata={"offset": composition.offset},
                                                          sidecar=sidecar, bundle=bundle)


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
        "designs": [{"stick": stick} | design_to_dict(d) for stick, d in composition.designs],
    }


def design_to_dict(design):
    """A designed stroke as plain data: its notes, when it starts and ends, its forces and its check by the solver.

    ``release`` is when the recipe's t = 0 falls on the notes' timeline (s); forces are the thumb's
    acceleration a(t) (m/s²); ``beyond_human`` says whether they leave the human range, 0–250 m/s².
    """
    return {"model": design.model, "notes": design.times.tolist(), "levels_db": design.levels.tolist(),
            "release": design.release, "t_end": design.t_end, "end": design.end, "force_min": design.min_force,
            "force_max": design.max_force, "beyond_human": design.beyond_human, "time_error": design.time_error,
            "level_error": design.level_error, "recipe": design.recipe.to_dict()}


def _with_csv(data, csv):
    return data if csv is None else data | {KEY: csv}


def write_kit_json(piece, path, *, csv=None, bundle=None):
    """Write a kit composition (:func:`kit_to_dict`) as JSON; ``csv``: its CSV's metadata, when this is the JSON
    beside it."""
    write_json_data(path, _with_csv(kit_to_dict(piece), csv), bundle=bundle)


def kit_to_dict(piece):
    """A kit composition (:func:`drumstroke.compose.compose_kit`) as plain data: the kit, every note's outcome (its
    key, piece, limb, whether played: its impact's time and level, or the reason), every hit, the units."""
    performance = piece.performance
    notes = []
    for outcome, key in zip(performance.outcomes, performance.keys):
        note = {"index": outcome.index, "time": outcome.note.time - piece.offset, "key": key, "piece": outcome.piece,
                "state": outcome.note.state, "limb": outcome.limb, "played": outcome.played,
                "level": outcome.level}
        if outcome.played:
            note |= {"impact": outcome.impact - piece.offset, "impact_level": outcome.impact_level}
        else:
            note["reason"] = outcome.problem.reason
        notes.append(note)
    hits = [{"t": h.t - piece.offset, "piece": h.piece, "key": h.key, "limb": h.limb, "speed": h.speed,
             "note": h.note} for h in performance.hits]
    return {"model": piece.model, "kit": {p.name: p.to_dict() for p in piece.kit.pieces}, "offset": piece.offset,
            "rate": piece.rate,
            "t_end": piece.t_end, "notes": notes, "hits": hits, "left_out": piece.left_out,
            "units": {"time": "s from the score's time 0", "level": "dB re 1 m/s", "speed": "m/s"}}

