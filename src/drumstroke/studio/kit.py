"""The part editor's kit mode: a part played on the whole kit, as the page draws it, and the files it takes away.

A kit part is composed as ``drumstroke compose --kit`` composes it (the shipped kit,
:func:`~drumstroke.compose.compose_kit`); :mod:`drumstroke.studio.parts` reads the request and composes it, this
module turns the :class:`~drumstroke.compose.KitComposition` into the page's lanes (:func:`kit_answer`), the grid's
rows (:func:`kit_rows`) and the files the command writes (:func:`kit_file`).

A note's mark is written as a drummer writes a limb: ``R`` and ``L`` the hands, ``RF`` and ``LF`` the feet, with
the sticking's accents and ghost notes (:func:`~drumstroke.render.sticking.mark`: ``R>``, ``(L)``) and the hi-hat's
state as drum notation marks it: ``o`` open, ``½`` half open (closed unmarked; the pedal is the left foot's).

Examples
--------
>>> from drumstroke.kit.pieces import default_kit
>>> [row["name"] for row in kit_rows(default_kit())]  # doctest: +NORMALIZE_WHITESPACE
['crash', 'ride-bell', 'ride', 'hihat:open', 'hihat:half', 'hihat', 'tom1', 'tom2', 'snare', 'floor-tom', 'kick',
 'hihat:pedal']
>>> kit_mark("right-foot", 116), kit_mark("left", 40), kit_mark("right", 100, "open"), kit_mark(None, 100)
('RF>', '(L)', 'R o', '?')
"""

import tempfile
from pathlib import Path

import numpy as np

from ..kit.pieces import HIHAT_STATES, PEDAL_STATE
from ..render.sticking import bar_times, mark

STAFF = ("crash", "ride-bell", "ride", "hihat", "tom1", "tom2", "snare", "floor-tom", "kick")
"""The shipped kit's pieces in the order drum notation writes them, from the top of the staff down (a piece another
kit adds comes after them, in that kit's order); the hi-hat's pedal is written below the staff, last."""

LIMB_LETTERS = {"right": "R", "left": "L", "right-foot": "RF", "left-foot": "LF"}
"""How a drummer writes each limb of a note."""

STATE_MARKS = {"open": "o", "half": "½"}
"""The hi-hat's states written beside a hand's note (drum notation's circle over an open hi-hat); closed unmarked."""

DEFAULT_STATE = "closed"
"""The hi-hat's state of a hand's note that names none (``compose --kit``'s): its row is the piece's name alone."""

KIT_DOWNLOADS = {
    "csv": ("text/csv", "csv", "csv"),
    "json": ("application/json", "json", "json"),
    "midi": ("audio/midi", "mid", "midi"),
    "wav": ("audio/wav", "wav", "audio"),
    "plot": ("image/png", "png", "plot"),
}
"""What a kit part's download writes: kind -> (media type, file name ending, ``compose --kit``'s option)."""


def kit_rows(kit):
    """The grid's rows of ``kit``: a piece a row (the hi-hat's a row for each state a hand plays, and its pedal's),
    in the staff's order (:data:`STAFF`), the pedal's last; each ``{"name", "piece", "state", "limbs", "also"}``:
    ``name`` what the pattern's piece column writes, ``also`` the other spellings that read as the same row."""
    rows, pedals = [], []
    for piece in _staff_order(kit.pieces):
        states = list(dict.fromkeys(piece.states.values()))
        if not states:
            rows.append({"name": piece.name, "piece": piece.name, "state": None, "limbs": list(piece.limbs_for()),
                         "also": []})
            continue
        hand_states = sorted((s for s in states if s != PEDAL_STATE), key=lambda s: -HIHAT_STATES.index(s))
        for state in hand_states:  # the most open on top: closed, the default, last, next to the drums
            closed = state == DEFAULT_STATE
            rows.append({"name": piece.name if closed else f"{piece.name}:{state}", "piece": piece.name,
                         "state": state, "limbs": list(piece.limbs_for(state)),
                         "also": [f"{piece.name}:{state}"] if closed else []})
        if PEDAL_STATE in states:
            pedals.append({"name": f"{piece.name}:{PEDAL_STATE}", "piece": piece.name, "state": PEDAL_STATE,
                           "limbs": list(piece.limbs_for(PEDAL_STATE)), "also": []})
    return rows + pedals


def kit_mark(limb, velocity, state=None):
    """A kit note as a drummer writes it: its limb's letters (:data:`LIMB_LETTERS`; ``?`` when no limb plays it)
    with the accent or ghost its MIDI ``velocity`` makes, and the hi-hat's ``state`` (:data:`STATE_MARKS`)."""
    if limb is None:
        return "?"
    written = mark(LIMB_LETTERS.get(limb, limb), velocity)
    return f"{written} {STATE_MARKS[state]}" if state in STATE_MARKS else written


def kit_answer(piece, score, *, samples):
    """A kit composition as the page draws it, on the score's time (s from its time 0; the composition's is
    ``t + offset``).

    Parameters
    ----------
    piece : KitComposition
    score : Score
        The notes it played, in the composition's order (their beats make the bars).
    samples : int
        Samples of each limb's joints, evenly spaced (its hits' times added).

    Returns
    -------
    dict
        ``{"kit": True, "offset", "t_end", "bars", "pieces", "lanes", "notes", "problems", "limbs"}``: ``pieces``
        the pieces with notes in the staff's order, a lane each; ``lanes[piece]`` its hits ``{"t", "level_db",
        "limb", "state", "note"}`` (``note`` −1 for a stick's bounce); every note with its piece, state, limb,
        mark and impact (time, level dB) or None; each note not played a problem ``{"note", "reason",
        "message", "nearest_time", "nearest_level"}`` (``message`` what ``compose --kit --verbose`` warns);
        ``limbs[limb]`` its joints' angles ``{"t", "joints": {joint: θ}}`` (rad).
    """
    performance, offset, kit = piece.performance, piece.offset, piece.kit
    notes, problems = [], []
    for outcome, note in zip(performance.outcomes, score.notes, strict=True):
        state = outcome.note.state
        impact = ({"t": outcome.impact - offset, "level_db": outcome.impact_level} if outcome.played else None)
        notes.append({"time": note.time, "beat": note.beat, "piece": outcome.piece, "state": state,
                      "limb": outcome.limb, "velocity": note.velocity, "source": note.source,
                      "played": outcome.played, "impact": impact, "mark": kit_mark(outcome.limb, note.velocity, state)})
        if not outcome.played:
            problem = outcome.problem
            problems.append({"note": outcome.index, "reason": problem.reason, "message": str(problem),
                             "nearest_time": None if problem.nearest_time is None else problem.nearest_time - offset,
                             "nearest_level": problem.nearest_level})
    drawn = [p for p in _staff_order(kit.pieces) if any(o.piece == p.name for o in performance.outcomes)]
    lanes = {}
    for name in (p.name for p in drawn):
        hits = [h for h in performance.hits if h.piece == name]
        lanes[name] = {"t": [h.t - offset for h in hits], "level_db": [20.0 * np.log10(h.speed) for h in hits],
                       "limb": [h.limb for h in hits], "state": [kit.piece(name).state(h.key) for h in hits],
                       "note": [h.note for h in hits]}
    return {"kit": True, "offset": offset, "t_end": piece.t_end - offset,
            "bars": bar_times(list(score.notes), score.tempo_map).tolist(), "pieces": [p.name for p in drawn],
            "lanes": lanes, "notes": notes, "problems": problems, "limbs": _limbs(piece, samples)}


def kit_file(piece, kind, title):
    """The file ``drumstroke compose --kit`` writes of ``piece`` as ``kind`` (one of :data:`KIT_DOWNLOADS`), written
    by :func:`~drumstroke.render.outputs.write_kit_outputs` in a folder of its own: (bytes, media type, file name)."""
    from ..render.outputs import write_kit_outputs

    media_type, ending, option = KIT_DOWNLOADS[kind]
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"{title}.{ending}"
        write_kit_outputs(piece, title=title, **{option: path})
        return path.read_bytes(), media_type, path.name


def _staff_order(pieces):
    """``pieces`` in the staff's order (:data:`STAFF`), any other after them in the order given."""
    rank = {name: k for k, name in enumerate(STAFF)}
    return sorted(pieces, key=lambda p: rank.get(p.name, len(STAFF)))


def _limbs(piece, samples):
    """Each limb's joints at ``samples`` even times from 0 to the composition's end and at each of its hits."""
    answer = {}
    for limb, (joints, curve) in piece.performance.motions.items():
        hits = [h.t for h in piece.performance.hits if h.limb == limb]
        t = np.union1d(np.linspace(0.0, piece.t_end, samples), hits)
        positions, _ = curve(t)
        columns = positions.reshape(len(t), -1)
        answer[limb] = {"t": t - piece.offset, "joints": {j: columns[:, k] for k, j in enumerate(joints)}}
    return answer
