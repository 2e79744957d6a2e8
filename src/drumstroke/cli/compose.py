"""``drumstroke compose``: a score (MIDI file or text pattern) into one trajectory per stick."""

import argparse
import sys
from pathlib import Path

from ..errors import ParameterError
from ..formats import json, trajectory_csv
from ..formats.midi import PERCUSSION_CHANNEL
from ..formats.pattern import FORMAT
from ..render import plot
from ..render.page import plural
from ..score import BOUNCE_NOTE, DRUM_MAP, FIRST_IMPACT_NOTE, FIRST_LIBRARY_NOTE, PLANNED
from ._common import OPTIONS, Bar, add_model, add_sound_options, print_written, robot_config
from ._options import Output, add_mkdir, existing_file, existing_folder, number

_WRITTEN = {"first": "; written for each stroke's first impact", "bounce": "; written for bounces", None: ""}
_DRUM_MAP = "\n".join(f"  {key}  {row.name:<15} read as {row.stroke!r}{_WRITTEN[row.written]}"
                      for key, row in DRUM_MAP.items())

EPILOG = f"""\
SCORE as a MIDI file (.mid, .midi; type 0 or 1, every tempo change honoured):
only the notes on the channels chosen (--channel, default {PERCUSSION_CHANNEL}: General MIDI
percussion) and in the tracks chosen (--track, default all) are read, and of
those only the keys the mapping names are played. Without --mapping, channel
{PERCUSSION_CHANNEL} is read through the drum map:

{_DRUM_MAP}

('auto': a note the planner designs, on a stick it chooses; no library needed),
and any other channel also plays key {FIRST_LIBRARY_NOTE} + i (C4 and up) as the library's
i-th stroke, in the order of 'drumstroke library list' (without --library, of the
shipped palette, 'drumstroke presets'). Every note not played
is counted in one summary line, the keys no mapping plays named with their
counts (on channel {PERCUSSION_CHANNEL} with their General MIDI names: 42 Closed Hi-Hat ×12);
--verbose lists each note, --quiet nothing.

The planner (auto and buzz notes) designs, per stick, the thumb force that plays
the notes as bounces of the model (--model), chooses the sticks of notes that
name none (--sticks: the lead hand on the beat, the hands alternating), and
joins its strokes with jerk-limited moves; a note it cannot play is left out
and reported with the nearest time and level it could play.

--midi writes the impacts on the score's time, tempo map and time signature:
one track per stick, channel {PERCUSSION_CHANNEL}, velocity from each impact's level, each
stroke's first impact on key {FIRST_IMPACT_NOTE} and its bounces on key {BOUNCE_NOTE}.

SCORE as a text pattern (any other file name):

{FORMAT}"""


def add_compose(comp):
    """Give ``compose``'s parser ``comp`` its description and options."""
    comp.description = ("Turn a score into one motor-angle trajectory per stick, its\n"
                        "strokes designed by the planner or taken from a library, and\n"
                        "write it.")
    comp.epilog = EPILOG
    comp.formatter_class = argparse.RawDescriptionHelpFormatter
    comp.add_argument("score", type=Path, metavar="SCORE", help="a .mid/.midi file or a text pattern (formats below)")
    comp.add_argument("--library", type=existing_folder, metavar="DIR",
                      help="a library folder ('library build') whose strokes the score names (default: the shipped "
                           "palette's, simulated as 'drumstroke simulate NAME' makes them)")
    comp.add_argument("--rate", type=number(low=1.0, high=1e5, unit="Hz"), metavar="HZ",
                      help="control rate of the result, in [1, 1e5] Hz (default: the library's, else 1000)")
    add_model(comp, what="the model the planner designs auto and buzz notes with")
    comp.add_argument("--config", type=existing_file, metavar="TOML",
                      help="robot config: the joint's [limits] (its range, speed, acceleration) every planned motion "
                           "keeps")
    comp.add_argument("--sticks", type=int, choices=(1, 2), default=2,
                      help="sticks the planner may give notes that name none (default 2)")
    midi = comp.add_argument_group("MIDI scores")
    midi.add_argument("--channel", type=int, action="append", metavar="N",
                      help=f"play MIDI channel N, 1-16 as musicians count (repeat for more; default "
                           f"{PERCUSSION_CHANNEL}, General MIDI percussion)")
    midi.add_argument("--track", action="append", metavar="TRACK",
                      help="play only this track, by number (from 0, in the file's order) or name (repeat for more; "
                           "default every track)")
    midi.add_argument("--mapping", type=existing_file, metavar="FILE",
                      help="MIDI key -> stroke mapping .toml for every channel played (default: the drum map below)")
    comp.add_argument("--csv", action=Output, suffixes=trajectory_csv.SUFFIXES, metavar="PATH",
                      help="write t (s) and theta (rad), omega (rad/s) per stick as .csv; its metadata goes in the "
                           "JSON beside it")
    comp.add_argument("--json", action=Output, suffixes=json.SUFFIXES, metavar="PATH",
                      help="write the notes, placements and impacts as .json")
    comp.add_argument("--plot", action=Output, suffixes=plot.SUFFIXES, metavar="PATH",
                      help=f"draw theta(t) per stick with the notes: {', '.join(plot.SUFFIXES)}")
    add_sound_options(comp)
    add_mkdir(comp)
    kit = comp.add_argument_group("the kit (--kit)")
    kit.add_argument("--kit", nargs="?", const="", type=str, metavar="FILE",
                     help="play every channel-10 key the kit answers on its pieces, hands and feet (alone: the shipped "
                          "kit; FILE: a kit .toml); without it, the snare only")
    kit.add_argument("--pieces", metavar="LIST", help="with --kit: play only these pieces, comma-separated")
    kit.add_argument("--lead", choices=("right", "left"), default="right", help="with --kit: the lead hand")
    kit.add_argument("--open-handed", action="store_true", help="with --kit: the hand on a hi-hat's side keeps time")
    kit.add_argument("--soundfont", type=existing_file, metavar="SF2",
                     help="with --kit: render --audio through FluidSynth with this General MIDI SoundFont")
    comp.add_argument("--strict", action="store_true",
                      help="exit with status 3 if a note of the channels and tracks played was left out or cut short")
    talk = comp.add_mutually_exclusive_group()
    talk.add_argument("--quiet", "-q", action="store_true", help="print nothing but errors")
    talk.add_argument("--verbose", "-v", action="store_true",
                      help="also list every note skipped or left out, one a line")
    comp.set_defaults(run=_compose)


def _compose(args):
    if args.kit is not None:
        return _compose_kit(args)
    from ..compose import compose
    from ..design import Setup
    from ..palette.library import load_library, palette_library
    from ..render.outputs import write_composition_outputs
    from ..score import read_score

    say = (lambda *a, **k: None) if args.quiet else print
    rate = args.rate
    library = load_library(args.library) if args.library else palette_library()
    score = read_score(args.score, mapping=args.mapping, stroke_names=list(library), channels=args.channel,
                       tracks=args.track)
    report = score.report
    say(report.summary(OPTIONS))
    if args.verbose:
        for line in report.details(OPTIONS):
            print(line)
    if not score.notes:
        raise ParameterError(f"{args.score} has no notes to play on the channels and tracks chosen; choose others "
                             "with --channel, --track or --mapping (--verbose lists every note skipped)")
    bar = None if args.quiet else Bar("composing", delay=1.0)
    setup = Setup(model=args.model, limits=robot_config(args.config).limits)
    piece = compose(score, library, rate=rate, progress=bar.update if bar else None, setup=setup, sticks=args.sticks)
    if bar:
        bar.close()
    played = sum(p.played for p in piece.placements)
    sticks = ", ".join(f"{name} ({plural(len(s.impacts), 'impact')})" for name, s in piece.sticks.items())
    say(f"composed {played} of {len(score.notes)} notes from {args.score} (model {piece.model}"
        f"{_strokes_from(score, args)}): {piece.t_end:.3f} s at {piece.rate:g} Hz, score time 0 at {piece.offset:g} s; "
        f"sticks: {sticks}")
    _warn(piece, played, args, say)
    written = write_composition_outputs(piece, title=args.score.stem, csv=args.csv, json=args.json, plot=args.plot,
                                        audio=args.audio, midi=args.midi, snares=not args.no_snares)
    if not args.quiet:
        print_written(written)
    if args.strict and (report.count("unmapped") or piece.problems):
        print("drumstroke compose: error: notes were left out (--strict)", file=sys.stderr)
        return 3
    return 0


def _strokes_from(score, args):
    """Where the score's library strokes came from, when it names any: the summary says which library played."""
    if all(note.stroke in PLANNED for note in score.notes):
        return ""
    return f"; strokes from library {args.library}" if args.library else "; strokes from the shipped palette: no --library"


def _warn(piece, played, args, say):
    """Compose's problems: each with --verbose, else one line with the first and the count."""
    problems = piece.problems
    if args.verbose:
        for problem in problems:
            print(f"warning: {problem}", file=sys.stderr)
    elif problems:
        left_out = len(piece.placements) - played
        others = len(problems) - left_out
        other = "other problem" if left_out else "problem"  # "other" only after the notes left out
        kinds = [f"{plural(left_out, 'note')} left out" if left_out else "",
                 f"{plural(others, other)} (velocities out of reach, strokes cut short)" if others > 0 else ""]
        more = f"; the first: {problems[0]}; --verbose lists them all" if len(problems) > 1 else f": {problems[0]}"
        say(f"warning: {', '.join(kind for kind in kinds if kind)}{more}", file=sys.stderr)


def _compose_kit(args):
    """``compose --kit``: the score on the kit's pieces, every limb's joints, the notes' outcomes, the hits."""
    import time
    from collections import Counter

    from ..compose import compose_kit
    from ..design import Setup
    from ..kit.pieces import default_kit, read_kit
    from ..score import read_score

    say = (lambda *a, **k: None) if args.quiet else print
    kit = read_kit(args.kit) if args.kit else default_kit()
    midi_score = args.score.suffix.lower() in (".mid", ".midi")
    score = read_score(args.score, kit=kit if midi_score else None, channels=args.channel, tracks=args.track)
    say(score.report.summary(OPTIONS))
    if not score.notes:
        raise ParameterError(f"{args.score} has no notes the kit answers on the channels and tracks chosen")
    pieces = None if args.pieces is None else [p.strip() for p in args.pieces.split(",") if p.strip()]
    start = time.perf_counter()
    piece = compose_kit(score, kit, setup=Setup(model=args.model), rate=args.rate, pieces=pieces, lead=args.lead,
                        open_handed=args.open_handed)
    took = time.perf_counter() - start
    outcomes = piece.performance.outcomes
    played = Counter(o.piece for o in outcomes if o.played)
    counts = ", ".join(f"{name} {played[name]}/{n}" for name, n in Counter(o.piece for o in outcomes).most_common())
    left = "".join(f"; not chosen (--pieces): {', '.join(f'{k} ×{n}' for k, n in piece.left_out.items())}"
                   if piece.left_out else "")
    say(f"played {sum(played.values())} of {len(outcomes)} notes on the kit ({counts}){left}; "
        f"{piece.t_end:.3f} s at {piece.rate:g} Hz, score time 0 at {piece.offset:g} s; composed in {took:.2f} s")
    problems = piece.performance.problems
    if args.verbose:
        for problem in problems:
            print(f"warning: {problem}", file=sys.stderr)
    elif problems:
        say(f"warning: {plural(len(problems), 'note')} left out; the first: {problems[0]}; --verbose lists them all",
            file=sys.stderr)
    written = _write_kit_outputs(piece, args)
    if not args.quiet:
        print_written(written)
    if args.strict and (score.report.count("unmapped") or problems):
        print("drumstroke compose: error: notes were left out (--strict)", file=sys.stderr)
        return 3
    return 0


def _write_kit_outputs(piece, args):
    """--csv, --json, --midi, --audio of a kit composition; the paths written."""
    written = []
    if args.csv:
        piece.write_csv(args.csv)
        written += [args.csv, args.csv.with_suffix(".json")]
    if args.json:
        json.write_json(args.json, _kit_document(piece))
        written.append(args.json)
    hits = piece.performance.hits
    if args.midi or args.audio:
        from ..render.kit_audio import KitHits, render_kit_wav
        from ..render.soundfont import render_soundfont_wav, write_kit_midi

        rows = KitHits.from_rows([(h.t, h.piece, h.key, h.speed) for h in hits])
        if args.midi:
            write_kit_midi(args.midi, rows)
            written.append(args.midi)
        if args.audio and args.soundfont:
            render_soundfont_wav(args.audio, rows, args.soundfont)
            written.append(args.audio)
        elif args.audio:
            render_kit_wav(args.audio, rows, kit=piece.kit)
            written.append(args.audio)
    return written


def _kit_document(piece):
    """The JSON of a kit composition: the kit, every note's outcome, every hit."""
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
    return {"kit": {p.name: p.to_dict() for p in piece.kit.pieces}, "offset": piece.offset, "rate": piece.rate,
            "t_end": piece.t_end, "notes": notes, "hits": hits, "left_out": piece.left_out,
            "units": {"time": "s from the score's time 0", "level": "dB re 1 m/s", "speed": "m/s"}}
