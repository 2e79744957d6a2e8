"""``drumstroke compose``: a score (MIDI file or text pattern) into one trajectory per stick."""

import sys
from pathlib import Path

from ..formats import json, trajectory_csv
from ..render import plot
from ._common import add_sound_options, print_written
from ._options import Output, add_mkdir, existing_folder, number


def add_compose(commands):
    """Register ``compose``."""
    comp = commands.add_parser("compose", help="turn a score (MIDI file or text pattern) into one trajectory per stick",
                               description="Compose a score from a library's strokes into one continuous trajectory "
                                           "per stick; write it as data, a picture, audio and MIDI if asked.")
    comp.add_argument("score", type=Path, metavar="SCORE", help="a .mid/.midi file or a text pattern (see the README)")
    comp.add_argument("--library", type=existing_folder, required=True, metavar="DIR",
                      help="a library folder ('library build')")
    comp.add_argument("--rate", type=number(low=1.0, high=1e5, unit="Hz"), metavar="HZ",
                      help="control rate of the result, in [1, 1e5] Hz (default: the library's)")
    comp.add_argument("--mapping", type=Path, metavar="FILE", help="MIDI note -> stroke mapping .toml (default: see README)")
    comp.add_argument("--csv", action=Output, suffixes=trajectory_csv.SUFFIXES, metavar="PATH",
                      help="write t (s) and theta (rad), omega (rad/s) per stick as .csv; its metadata goes in the "
                           "JSON beside it")
    comp.add_argument("--json", action=Output, suffixes=json.SUFFIXES, metavar="PATH",
                      help="write the notes, placements and impacts as .json")
    comp.add_argument("--plot", action=Output, suffixes=plot.SUFFIXES, metavar="PATH",
                      help=f"draw theta(t) per stick with the notes: {', '.join(plot.SUFFIXES)}")
    add_sound_options(comp)
    add_mkdir(comp)
    comp.add_argument("--strict", action="store_true", help="exit with status 3 if any note was left out")
    comp.set_defaults(run=_compose)


def _compose(args):
    from ..compose import compose
    from ..palette.library import load_library
    from ..render.outputs import write_composition_outputs
    from ..score import read_score

    library = load_library(args.library)
    notes, unmapped = read_score(args.score, mapping=args.mapping, stroke_names=list(library), mapping_name="--mapping")
    piece = compose(notes, library, rate=args.rate)
    played = sum(p.played for p in piece.placements)
    sticks = ", ".join(f"{name} ({len(s.impacts)} impacts)" for name, s in piece.sticks.items())
    print(f"composed {played} of {len(notes)} notes from {args.score} (model {piece.model}): {piece.t_end:.3f} s at "
          f"{piece.rate:g} Hz, score time 0 at {piece.offset:g} s; sticks: {sticks}")
    for note, count in sorted(unmapped.items()):
        print(f"warning: {count} MIDI notes with number {note} have no mapping; left out", file=sys.stderr)
    for problem in piece.problems:
        print(f"warning: {problem}", file=sys.stderr)
    print_written(write_composition_outputs(piece, title=args.score.stem, csv=args.csv, json=args.json,
                                            plot=args.plot, audio=args.audio, midi=args.midi,
                                            snares=not args.no_snares))
    if args.strict and (unmapped or played < len(notes)):
        print("drumstroke compose: error: notes were left out (--strict)", file=sys.stderr)
        return 3
    return 0
