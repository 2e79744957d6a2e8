"""The studio's part operations: what the part editor, its audio and downloads, and the robot view ask for.

Each operation is a function ``(studio, request) -> dict or File`` (:mod:`drumstroke.studio.session`); a
refused input is a :class:`~drumstroke.errors.ParameterError` naming the field.

A part is given in one of three ways, the fields of :data:`PART_FIELDS`:

- ``pattern``: the text pattern (:data:`drumstroke.formats.pattern.FORMAT`), what the grid writes;
- ``midi``: a MIDI file's bytes as base64 (``name`` its file name, for messages), read as ``drumstroke compose``
  reads one (channel 10 through the drum map);
- ``rudiment`` (a PAS rudiment's name or number), ``tempo`` (bpm) and ``bars``.

It is composed as ``drumstroke compose`` composes it (:func:`composed`): the shipped palette, the joint's default
limits, ``model`` (paper or geometry), both sticks; a pattern's CSV is the command's to the bit.

With ``"kit": true`` it is played on the whole kit as ``drumstroke compose --kit`` plays it (:func:`composed_kit`:
the shipped kit, each note on the piece its pattern line names, a MIDI file's every key the kit answers; ``lead``
and ``open_handed`` as the command's ``--lead`` and ``--open-handed``), and answered a lane per piece
(:mod:`drumstroke.studio.kit`).
"""

import base64
import binascii
import functools
import re
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

from .._checks import shown
from ..compose import compose, compose_kit, rudiment_score
from ..design import Setup, Target, plan_stick
from ..dynamics import velocity_to_level
from ..errors import ParameterError
from ..formats.midi import TempoMap
from ..formats.pattern import parse_pattern as pattern_rows
from ..formats.pattern import pattern_text
from ..kit.pieces import default_kit
from ..model import MODELS
from ..palette.library import palette_library
from ..palette.rudiments import rudiments as all_rudiments
from ..render.sticking import bar_times, mark, sticking
from ..robot.config import RobotConfig
from ..score import PLANNED, Score, ScoreReport, read_score
from ..score import parse_pattern as pattern_notes
from .kit import KIT_DOWNLOADS, kit_answer, kit_file, kit_rows
from .session import File, choice, fields, number, text

PART_FIELDS = ("pattern", "midi", "name", "rudiment", "tempo", "bars", "model", "kit", "lead", "open_handed")
"""The fields that give a part (one of pattern, midi, rudiment), the model it is planned with, and whether it is
played on the kit (``kit``, and with it ``lead`` and ``open_handed``)."""

KIT_FIELDS = ("lead", "open_handed")
"""The fields that go with ``"kit": true``: the hands' options of ``compose --kit``."""

MAX_NOTES = 2000
"""The most notes a part may have."""

MAX_SECONDS = 60.0
"""The longest part (s, its last note's time), so that no request plans, sounds or writes for long."""

MAX_ROBOT_SECONDS = 20.0
"""The longest part the robot plays (s, the composition's length): each stick is stepped period by period."""

MAX_MIDI_BYTES = 512 * 1024
"""The largest MIDI file (bytes; its base64 is a third longer, within the studio's 1 MiB request)."""

LEVEL_TOLERANCE = 1e-3
"""dB: a note played further than this from its velocity's level was played at another (the loudest it could)."""

SAMPLES = 1500
"""θ(t) samples sent per stick by default (the impacts are added to them, so each touch of the head shows)."""

DOWNLOADS = {
    "csv": ("text/csv", "csv"),
    "json": ("application/json", "json"),
    "midi": ("audio/midi", "mid"),
    "wav": ("audio/wav", "wav"),
    "ros": ("application/json", "ros.json"),
    "pattern": ("text/plain; charset=utf-8", "pattern"),
}
"""What ``download`` writes: kind -> (media type, file name ending)."""


def rudiments(studio, request):
    """``{}`` -> ``{"rudiments": [{"number", "name", "title", "tempo": [low, high]}, ...]}``: the 40 PAS rudiments."""
    fields(request)
    return {"rudiments": [{"number": r.number, "name": r.name, "title": r.title, "tempo": list(r.tempo)}
                          for r in all_rudiments()]}


def part_options(studio, request):
    """``{}`` -> ``{"strokes", "models", "controllers", "downloads", "kit_rows", "kit_downloads"}``: the palette's
    stroke names a note may name, the models a part is planned with, the robot's controllers, the kinds of file
    ``download`` writes, and on the kit: the grid's rows (:func:`~drumstroke.studio.kit.kit_rows` of the shipped
    kit) and the kinds of file ``download`` writes of a kit part."""
    fields(request)
    return {"strokes": list(palette_library()), "models": list(MODELS),
            "controllers": list(RobotConfig().controllers), "downloads": list(DOWNLOADS),
            "kit_rows": kit_rows(default_kit()), "kit_downloads": [*KIT_DOWNLOADS, "pattern"]}


def plan(studio, request):
    """A part -> what the planner made of it, for the lanes.

    ``{part fields, "samples"?}`` -> ``{"title", "pattern", "tempo", "meter", "offset", "t_end", "head", "bars",
    "sticks": {name: {"t", "theta", "impacts": {"t", "level_db"}}}, "notes": [...], "problems": [...],
    "sticking"}``: times on the score's time (s from its time 0; the composition's is ``t + offset``); each note
    with its stick, its mark as a drummer writes it (``R``, ``L>``, ``(L)``), its impact (time, level dB) or
    None; each problem with the index of its note, its reason, and the nearest time (s) and level (dB) the
    planner found playable (None when it names none).

    On the kit: ``{"title", "pattern", "tempo", "meter", "model"}`` and
    :func:`~drumstroke.studio.kit.kit_answer`'s lane per piece, notes, problems and limbs.
    """
    fields(request, optional=(*PART_FIELDS, "samples"))
    samples = int(number(request, "samples", low=100, high=5000, default=SAMPLES))
    piece, score, title, model = _part(request)
    if _on_kit(request):
        return {"title": title, "pattern": _text(score, piece.kit), "tempo": 60e6 / score.tempo_map.tempi[0][1],
                "meter": list(score.tempo_map.meters[0][1:]), "model": model,
                **kit_answer(piece, score, samples=samples)}
    head = float(next(iter(piece.sticks.values())).theta_max)
    notes = [p.note for p in piece.placements]
    firsts = {name: (t[first], level[first]) for name, (t, level, first) in piece.stick_impacts().items()}
    answer_notes = []
    for p in piece.placements:
        note, impact = p.note, None
        if p.played:
            t, level = firsts[note.stick]
            if t.size:
                k = int(np.argmin(np.abs(t - (p.impact - piece.offset))))
                impact = {"t": float(t[k]), "level_db": float(level[k])}
        answer_notes.append({"time": note.time, "beat": note.beat, "stick": note.stick, "velocity": note.velocity,
                             "stroke": note.stroke, "source": note.source, "played": p.played, "impact": impact,
                             "mark": mark(note.stick, note.velocity, buzz=note.stroke == "buzz")})
    return {
        "title": title, "pattern": _text(score), "tempo": 60e6 / score.tempo_map.tempi[0][1],
        "meter": list(score.tempo_map.meters[0][1:]), "model": model, "offset": piece.offset,
        "t_end": piece.t_end - piece.offset, "head": head,
        "bars": bar_times(notes, score.tempo_map).tolist(),
        "sticks": {name: _lane(stick, piece.offset, samples) for name, stick in piece.sticks.items()},
        "notes": answer_notes, "problems": _problems(piece, model, answer_notes),
        "sticking": sticking(notes, score.tempo_map),
    }


def audio(studio, request):
    """A part -> its sound as a WAV file (48 kHz), on the composition's time (the score's time 0 at ``offset``); on
    the kit, the kit's sound as ``compose --kit --audio`` renders it."""
    fields(request, optional=PART_FIELDS)
    if _on_kit(request):
        return File(*kit_file(_part(request)[0], "wav", "part"))
    return _written(_part(request)[0], "wav")


def download(studio, request):
    """A part and ``kind`` (one of :data:`DOWNLOADS`) -> the file ``drumstroke compose`` writes of it.

    csv, json, midi and wav are :func:`~drumstroke.render.outputs.write_composition_outputs`' (the CSV without
    the JSON of its metadata beside it), ros the ROS 2 ``JointTrajectory`` of both sticks
    (:func:`~drumstroke.robot.export.export_ros_json`, validated against the joint's limits), pattern the part's
    text pattern (a pattern as it was given).

    On the kit, ``kind`` one of :data:`~drumstroke.studio.kit.KIT_DOWNLOADS` or pattern: what ``compose --kit``
    writes with ``--csv``, ``--json``, ``--midi``, ``--audio`` and ``--plot`` (PNG).
    """
    fields(request, required=("kind",), optional=PART_FIELDS)
    on_kit = _on_kit(request)
    kind = choice(request, "kind", (*KIT_DOWNLOADS, "pattern") if on_kit else tuple(DOWNLOADS))
    piece, score, title, _ = _part(request)
    if kind == "pattern":  # a pattern as it was written (its comments too); a rudiment or a MIDI file as text
        written = request["pattern"] if "pattern" in request else _text(score, piece.kit if on_kit else None)
        return File(written.encode("utf-8"), DOWNLOADS[kind][0], f"{title}.pattern")
    if on_kit:
        return File(*kit_file(piece, kind, title))
    return _written(piece, kind, title)


def robot(studio, request):
    """A part and ``controller`` -> each stick played on the simulated joint (as ``drumstroke robot track`` plays).

    ``{part fields, "controller", "samples"?}`` -> ``{"controller", "offset", "bars", "sticks": {name: {"t",
    "reference", "played", "onsets": {"t", "kept"}, "extra", "kept", "total", "rms", "peak_torque",
    "torque_limit"}}}``: times on the score's time; the reference's audible onsets, each kept (a played onset
    within ±2 ms) or missed; ``extra`` the played onsets matched to none.
    """
    from ..robot.metrics import AUDIBLE_SPEED, WINDOW, match_onsets, metrics
    from ..robot.track import reference, track

    fields(request, required=("controller",), optional=(*PART_FIELDS, "samples"))
    if _on_kit(request):
        raise ParameterError("kit: the robot tracks a part's two sticks on the snare, not the kit; switch the part "
                             "editor's Kit off")
    config = RobotConfig()
    name = choice(request, "controller", tuple(config.controllers))
    samples = int(number(request, "samples", low=100, high=5000, default=SAMPLES))
    piece, score, _, _ = _part(request)
    if piece.t_end > MAX_ROBOT_SECONDS:
        given = next(key for key in ("pattern", "midi", "rudiment") if key in request)
        raise ParameterError(f"{given}: the part lasts {piece.t_end:.3g} s; the robot plays at most "
                             f"{MAX_ROBOT_SECONDS:g} s (give fewer bars)")
    sticks = {}
    for stick, trajectory in piece.sticks.items():
        played = track(reference(trajectory, piece.rate), config.controllers[name], config.plant)
        ref, scores = played.reference, metrics(played)
        audible = ref.impacts.tip_speed >= AUDIBLE_SPEED
        got = played.onsets[played.onset_speed >= AUDIBLE_SPEED]
        match = match_onsets(ref.impacts.t[audible], got, window=WINDOW)
        every = np.unique(np.linspace(0, len(ref.t) - 1, samples).astype(int))
        sticks[stick] = {
            "t": ref.t[every] - piece.offset, "reference": ref.theta[every], "played": played.theta[every],
            "onsets": {"t": ref.impacts.t[audible] - piece.offset, "kept": match >= 0},
            "extra": np.delete(got, match[match >= 0]) - piece.offset,
            "kept": scores.kept, "total": scores.reference_onsets, "rms": scores.rms_error,
            "peak_torque": scores.peak_torque, "torque_limit": scores.torque_limit,
        }
    return {"controller": name, "offset": piece.offset, "head": float(config.plant.head),
            "bars": bar_times([p.note for p in piece.placements], score.tempo_map).tolist(), "sticks": sticks}


def _on_kit(request):
    """Whether the request's part is played on the kit (``kit``: true or false, default false); ``lead`` and
    ``open_handed`` are refused without it."""
    on_kit = request.get("kit", False)
    if not isinstance(on_kit, bool):
        raise ParameterError(f"kit must be true or false, got {shown(on_kit)}")
    for key in KIT_FIELDS:
        if key in request and not on_kit:
            raise ParameterError(f"{key} goes with kit: true (the hands on the kit)")
    return on_kit


def _part(request):
    """The part a request gives, composed: (Composition or KitComposition, Score, title, model)."""
    model = choice(request, "model", MODELS, default="paper")
    given = [key for key in ("pattern", "midi", "rudiment") if key in request]
    if len(given) != 1:
        raise ParameterError(f"the request must give one part: pattern, midi or rudiment, got "
                             f"{', '.join(given) or 'none'}")
    for key in ("tempo", "bars"):
        if key in request and given != ["rudiment"]:
            raise ParameterError(f"{key} goes with a rudiment (a pattern and a MIDI file give their own)")
    if "name" in request and given != ["midi"]:
        raise ParameterError("name goes with a midi file")
    if given == ["pattern"]:
        source = ("pattern", text(request, "pattern", most=200_000))
    elif given == ["midi"]:
        name = text(request, "name", most=100, default="part.mid")
        source = ("midi", text(request, "midi", most=MAX_MIDI_BYTES * 4 // 3 + 4), re.sub(r"[^\w.-]", "_", name))
    else:
        source = ("rudiment", text(request, "rudiment", most=64),
                  number(request, "tempo", low=20.0, high=400.0, unit="bpm", default=100.0),
                  int(number(request, "bars", low=1, high=8, default=2)))
    if _on_kit(request):
        lead = choice(request, "lead", ("right", "left"), default="right")
        open_handed = request.get("open_handed", False)
        if not isinstance(open_handed, bool):
            raise ParameterError(f"open_handed must be true or false, got {shown(open_handed)}")
        piece, score, title = composed_kit(source, model, lead, open_handed)
    else:
        piece, score, title = composed(source, model)
    return piece, score, title, model


@functools.lru_cache(maxsize=8)  # a part is planned, heard, downloaded and played by the robot in turn
def composed(source, model):
    """A part composed as ``drumstroke compose`` composes it: (Composition, Score, title).

    Parameters
    ----------
    source : tuple
        ``("pattern", text)``, ``("midi", base64, file name)`` or ``("rudiment", name, tempo bpm, bars)``.
    model : {"paper", "geometry"}
    """
    score, title = _score(source)
    setup = Setup(model=model, limits=RobotConfig().limits)  # compose's: the default robot config's limits
    return compose(score, palette_library(), setup=setup), score, title


@functools.lru_cache(maxsize=8)
def composed_kit(source, model, lead="right", open_handed=False):
    """A part played on the shipped kit as ``drumstroke compose --kit`` plays it: (KitComposition, Score, title).

    Parameters
    ----------
    source : tuple
        As :func:`composed` takes it; a MIDI file's notes are every key the kit answers.
    model : {"paper", "geometry"}
    lead : {"right", "left"}
        The hand that keeps time (``--lead``).
    open_handed : bool
        Whether the hand on the hi-hat's side keeps time (``--open-handed``).
    """
    kit = default_kit()
    score, title = _score(source, kit)
    setup = Setup(model=model)  # compose --kit's: the hands' joints are the kit's, θ the setup's default limits
    try:
        return compose_kit(score, kit, setup=setup, lead=lead, open_handed=open_handed), score, title
    except ParameterError as error:  # a limb the note's piece is not played by: said at its line, not its index
        given = re.fullmatch(r"given\[(\d+)\] (.*)", str(error))
        if given is None:
            raise
        raise ParameterError(f"{score.notes[int(given[1])].source}: limb {given[2]}") from None


def _score(source, kit=None):
    """The score a part's source gives (a MIDI file read with ``kit``, when given), checked for size: (Score,
    title)."""
    kind = source[0]
    if kind == "pattern":
        score, title = _pattern_score(source[1]), "part"
    elif kind == "midi":
        score, title = _midi_score(*source[1:], kit=kit), Path(source[2]).stem or "part"
    else:
        score, title = rudiment_score(source[1], source[2], bars=source[3])[0], source[1]
    _check_size(score, kind)
    return score, title


def _pattern_score(pattern):
    lines = pattern.count("\n") + 1
    if lines > 4 * MAX_NOTES:  # refused before it is read
        raise ParameterError(f"pattern has {lines} lines; a part has at most {MAX_NOTES} notes")
    read = pattern_rows(pattern, name="pattern")
    if len(read.rows) > MAX_NOTES:
        raise ParameterError(f"pattern has {len(read.rows)} notes; a part has at most {MAX_NOTES}")
    notes = pattern_notes(pattern, name="pattern")
    return Score(tuple(notes), TempoMap.constant(read.tempo, meter=read.meter),
                 ScoreReport("pattern", {("played", None): len(notes)}))


def _midi_score(data, name, *, kit=None):
    try:
        raw = base64.b64decode(data, validate=True)
    except (binascii.Error, ValueError):
        raise ParameterError(f"midi must be a MIDI file as base64, got {len(data)} characters that are not "
                             "base64") from None
    if len(raw) > MAX_MIDI_BYTES:
        raise ParameterError(f"midi is {len(raw)} bytes; at most {MAX_MIDI_BYTES} bytes")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "part.mid"
        path.write_bytes(raw)
        try:
            score = (read_score(path, stroke_names=list(palette_library())) if kit is None
                     else read_score(path, kit=kit))
        except ParameterError as error:
            raise ParameterError(f"midi {name!r}: {str(error).replace(str(path), name)}") from None
    if not score.notes:
        played = "the kit answers" if kit else "the drum map plays (snares 37, 38, 40)"
        raise ParameterError(f"midi {name!r} has no notes on channel 10 {played}: {score.report.summary()}")
    notes = tuple(replace(n, source=n.source.replace(str(path), name)) for n in score.notes)
    return replace(score, notes=notes)


def _check_size(score, field):
    if len(score.notes) > MAX_NOTES:
        raise ParameterError(f"{field} has {len(score.notes)} notes; a part has at most {MAX_NOTES}")
    last = max(note.time for note in score.notes)
    if last > MAX_SECONDS:
        raise ParameterError(f"{field}'s last note is at {last:.6g} s; a part lasts at most {MAX_SECONDS:g} s")


def _text(score, kit=None):
    """The score as a text pattern: beats at its first tempo (exact for a pattern or a rudiment, one tempo); played
    on ``kit``, each note's piece and state (its key's) in the piece column."""
    tempo_map = score.tempo_map
    beats = tempo_map.beats(np.array([n.time for n in score.notes]))
    rows = [(round(float(beat), 9), n.stroke, n.velocity, n.stick or "auto", "", None if n.duration is None
             else round(n.duration * 60e6 / tempo_map.tempi[0][1] / 60.0, 9), *_piece_column(n, kit))
            for beat, n in zip(beats, score.notes)]
    return pattern_text(60e6 / tempo_map.tempi[0][1], rows, tempo_map.meters[0][1:])


def _piece_column(note, kit):
    """(piece, state) of ``note`` on ``kit`` for the pattern's piece column; () without a kit."""
    if kit is None or note.piece is None:
        return ()
    return note.piece, note.state or (None if note.key is None else kit.piece(note.piece).state(note.key))


def _lane(stick, offset, samples):
    """One stick's θ(t) for its lane: ``samples`` evenly spaced times and every impact, on the score's time."""
    t = np.union1d(np.linspace(stick.start, stick.t_end, samples), stick.impacts.t)
    theta, _ = stick.path(t)
    impacts = stick.impacts
    return {"t": t - offset, "theta": theta,
            "impacts": {"t": impacts.t - offset, "level_db": impacts.level_db}}


def _problems(piece, model, notes):
    """Each problem with its note's index and the nearest time and level it could be played at: the planner's for a
    note it left out (:class:`~drumstroke.design.planner.Problem`: the composition's problems keep only its
    reason), the level it was played at for a note played at another level than its velocity's (a velocity out of
    reach); None where there is none. ``notes``: the answer's notes, each with its impact."""
    nearest = _nearest(piece, model) if piece.problems else {}
    answer = []
    for problem in piece.problems:
        index = next((k for k, n in enumerate(notes) if problem.startswith(n["source"] + ":")), None)
        near_time, near_level = nearest.get(notes[index]["source"], (None, None)) if index is not None else (None, None)
        impact = notes[index]["impact"] if index is not None else None
        if impact and abs(impact["level_db"] - velocity_to_level(notes[index]["velocity"])) > LEVEL_TOLERANCE:
            near_level = impact["level_db"]
        answer.append({"note": index, "reason": problem, "nearest_time": near_time, "nearest_level": near_level})
    return answer


def _nearest(piece, model):
    """``{note source: (nearest time s, nearest level dB)}`` of the planned notes left out, planned again per stick
    exactly as :func:`~drumstroke.compose.compose` plans them (the planner's problems are where they are kept)."""
    setup = Setup(model=model, limits=RobotConfig().limits)
    found = {}
    for stick in {p.note.stick for p in piece.placements if not p.played}:
        wanted = [p.note for p in piece.placements if p.note.stick == stick and p.note.stroke in PLANNED]
        targets = [Target.from_velocity(n.time, n.velocity, kind=n.stroke, duration=n.duration, key=k)
                   for k, n in enumerate(wanted)]
        for problem in plan_stick(targets, setup=setup).problems if targets else ():
            found[wanted[problem.key].source] = (problem.nearest_time, problem.nearest_level)
    return found


def _written(piece, kind, title="part"):
    """The file ``drumstroke compose`` writes of ``piece`` as ``kind``, written in a folder of its own."""
    from ..render.outputs import write_composition_outputs
    from ..robot.export import export_ros_json

    media_type, ending = DOWNLOADS[kind]
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"{title}.{ending}"
        if kind == "ros":
            export_ros_json(path, piece.trajectory)
        else:
            write_composition_outputs(piece, title=title, **{"audio" if kind == "wav" else kind: path})
        return File(path.read_bytes(), media_type, path.name)


OPERATIONS = {"rudiments": rudiments, "part_options": part_options, "plan": plan, "audio": audio, "download": download,
              "robot": robot}
"""This module's operations by name."""
