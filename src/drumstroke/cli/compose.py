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
from .kit import add_kit_options, compose_kit

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
                      help=f"draw theta(t) per stick with the notes (with --kit: a lane per piece, every hit, over the "
                           f"joints' angles): {', '.join(plot.SUFFIXES)}")
    add_sound_options(comp)
    add_mkdir(comp)
    add_kit_options(comp)
    comp.add_argument("--strict", action="store_true",
                      help="exit with status 3 if a note of the channels and tracks played was left out or cut short")
    talk = comp.add_mutually_exclusive_group()
    talk.add_argument("--quiet", "-q", action="store_true", help="print nothing but errors")
    talk.add_argument("--verbose", "-v", action="store_true",
                      help="also list every note skipped or left out, one a line")
    comp.set_defaults(run=_compose)


def _compose(args):
    if args.kit is not None:
        return compose_kit(args)
    if args.plot_window is not None:
        raise ParameterError("--plot-window draws a stretch of the kit's picture: give --kit too")
    from ..compose import compose
    from ..design import Setup
    from ..palette.library import load_library, palette_library
    from ..render.outputs import write_composition_outputs
    from ..score import read_score
    from ..trajectory import check_sampling

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
    if args.csv and args.rate:  # the last note's time at least: a rate the CSV cannot hold is refused before composing
        check_sampling(max(note.time for note in score.notes), args.rate, 3, name="--rate")
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
    if args.csv and args.rate:
        check_sampling(piece.t_end, piece.rate, 1 + 2 * len(piece.sticks), name="--rate")
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
