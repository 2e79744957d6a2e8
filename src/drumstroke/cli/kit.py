"""``drumstroke compose --kit``: a song on the whole kit, its hands and feet, and what it writes."""

import argparse
import sys

from ..errors import ParameterError
from ..render.page import plural
from ._common import OPTIONS, print_written
from ._options import existing_file


def add_kit_options(comp):
    """Give ``compose``'s parser ``comp`` the kit's options."""
    kit = comp.add_argument_group("the kit (--kit)")
    kit.add_argument("--kit", nargs="?", const="", type=str, metavar="FILE",
                     help="play every channel-10 key the kit answers on its pieces, hands and feet (alone: the shipped "
                          "kit; FILE: a kit .toml); without it, the snare only")
    kit.add_argument("--pieces", metavar="LIST", help="with --kit: play only these pieces, comma-separated (default every piece)")
    kit.add_argument("--lead", choices=("right", "left"), default="right", help="with --kit: the lead hand, which keeps time on the hi-hat or ride (default right)")
    kit.add_argument("--open-handed", action="store_true", help="with --kit: the hand on a hi-hat's side keeps time")
    kit.add_argument("--soundfont", type=existing_file, metavar="SF2",
                     help="with --kit: render --audio through FluidSynth with this General MIDI SoundFont")
    kit.add_argument("--plot-window", type=_window, metavar="START,END",
                     help="with --kit and --plot: draw only from START to END, s of the score's time (default the "
                          "whole part)")


def _window(text):
    """An argparse type: ``START,END`` as two finite numbers of seconds, END after START."""
    from ..render.kit_plot import check_window

    try:
        start, end = (float(number) for number in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be START,END, two numbers of seconds, got {text!r}") from None
    try:
        return check_window((start, end))
    except ParameterError as error:
        raise argparse.ArgumentTypeError(str(_named(error))) from None


def _named(error, option=""):
    """A window's error about START or END as the command line names them: ``--plot-window END must be ...``."""
    return error.renamed(f"{option}{error.parameter.split()[-1].upper()}")


def compose_kit(args):
    """``compose --kit``: the score on the kit's pieces, every limb's joints, the notes' outcomes, the hits."""
    from ..compose import compose_kit as play
    from ..design import Setup
    from ..kit.pieces import default_kit, read_kit
    from ..render.kit_plot import check_window, part_span
    from ..render.outputs import write_kit_outputs
    from ..score import read_score

    say = (lambda *a, **k: None) if args.quiet else print
    if args.plot_window is not None and not args.plot:
        raise ParameterError("--plot-window draws a stretch of --plot's picture: give --plot too")
    kit = read_kit(args.kit) if args.kit else default_kit()
    midi_score = args.score.suffix.lower() in (".mid", ".midi")
    score = read_score(args.score, kit=kit if midi_score else None, channels=args.channel, tracks=args.track)
    say(score.report.summary(OPTIONS))
    if not score.notes:
        raise ParameterError(f"{args.score} has no notes the kit answers on the channels and tracks chosen")
    pieces = None if args.pieces is None else [p.strip() for p in args.pieces.split(",") if p.strip()]
    piece = play(score, kit, setup=Setup(model=args.model), rate=args.rate, pieces=pieces, lead=args.lead,
                 open_handed=args.open_handed)
    say(piece.summary())
    problems = piece.performance.problems
    if args.verbose:
        for problem in problems:
            print(f"warning: {problem}", file=sys.stderr)
    elif problems and not args.quiet:
        print(f"warning: {plural(len(problems), 'note')} left out; the first: {problems[0]}; --verbose lists them all",
              file=sys.stderr)
    if args.plot_window is not None:  # before anything is written: the window must be a stretch of this part
        try:
            check_window(args.plot_window, span=part_span(piece))
        except ParameterError as error:
            raise _named(error, "--plot-window ") from None
    written = write_kit_outputs(piece, title=args.score.stem, csv=args.csv, json=args.json, plot=args.plot,
                                window=args.plot_window, midi=args.midi, audio=args.audio, soundfont=args.soundfont)
    if not args.quiet:
        print_written(written)
    if args.strict and (score.report.count("unmapped") or problems):
        print("drumstroke compose: error: notes were left out (--strict)", file=sys.stderr)
        return 3
    return 0
