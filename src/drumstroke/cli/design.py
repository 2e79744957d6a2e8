"""``drumstroke design`` and ``rudiment``: the thumb force that plays given notes, and the 40 PAS rudiments played."""

import argparse
import math
import sys

from .._atomic import Bundle
from ..errors import ParameterError
from ..formats import json, toml, trajectory_csv
from ..render import plot
from ._common import add_cor, add_model, add_sound_options, print_written, robot_config, thumb_range
from ._options import Output, add_mkdir, existing_file, number, whole


def add_design(des):
    """Give ``design``'s parser ``des`` its description and options."""
    des.description = ("Design, through the exact model, the force profile whose stroke plays the notes given (times "
                       "and levels) on one stick as consecutive bounces, or a buzz; simulate it and check it; write its "
                       "recipe and what it plays.")
    notes = des.add_argument_group("the notes (give times with velocities or levels, or a buzz)")
    notes.add_argument("--times", type=_numbers, metavar="T1,T2,...", help="the notes' times, s, increasing")
    notes.add_argument("--velocities", type=_numbers, metavar="V1,V2,...", help="their MIDI velocities, 1-127")
    notes.add_argument("--levels", type=_numbers, metavar="L1,L2,...", help="or their levels, dB re 1 m/s tip speed")
    notes.add_argument("--buzz", type=_span, metavar="T0:T1", help="a buzz from T0 to T1 s (with --velocity)")
    notes.add_argument("--velocity", type=number(low=1.0, high=127.0), default=90.0,
                       help="the buzz's first velocity, 1-127 (default 90)")
    notes.add_argument("--density", type=number(low=1.0, high=200.0, unit="bounces/s"), default=30.0,
                       help="the buzz's bounces a second, in [1, 200] (default 30; drummers play 15-40)")
    notes.add_argument("--decay", type=number(low=0.0, high=200.0, unit="dB/s"), default=0.0,
                       help="how much softer the buzz gets, dB a second (default 0)")
    des.add_argument("--end", choices=("catch", "press", "bounce"), default=None,
                     help="after the last note: caught at the rebound's apex (default; a buzz: press), pressed to "
                          "rest, or let bounce")
    add_model(des)
    add_cor(des)
    des.add_argument("--force-max", type=number(low=0.0, high=1e6, low_open=True, unit="m/s^2"), default=3000.0,
                     metavar="A", help="the strongest thumb acceleration allowed, m/s^2 (default 3000)")
    des.add_argument("--out", action=Output, suffixes=toml.SUFFIXES, metavar="RECIPE",
                     help="write the designed recipe as .toml (its t = 0 is the release: see --json)")
    des.add_argument("--json", action=Output, suffixes=json.SUFFIXES, metavar="PATH",
                     help="write the stroke (recipe, impacts, rests) and its design (notes, release, forces, errors)")
    des.add_argument("--csv", action=Output, suffixes=trajectory_csv.SUFFIXES, metavar="PATH",
                     help="write t (s, the recipe's clock), theta (rad), omega (rad/s) at 1 kHz")
    des.add_argument("--plot", action=Output, suffixes=plot.SUFFIXES, metavar="PATH",
                     help=f"draw theta(t) with the impacts over a(t): {', '.join(plot.SUFFIXES)}")
    add_sound_options(des)
    add_mkdir(des)
    des.set_defaults(run=_design)


def add_rudiment(rud):
    """Give ``rudiment``'s parser ``rud`` its description and options."""
    rud.description = ("Play a PAS International Drum Rudiment at a tempo on two sticks: every note designed by the "
                       "planner; write what it plays. --list lists the 40 with their tempo ranges.")
    rud.add_argument("name", nargs="?", metavar="NAME", help="a rudiment's name, title or number (1-40)")
    rud.add_argument("--list", action="store_true", help="list the 40 rudiments and their tempo ranges")
    rud.add_argument("--tempo", type=number(low=1.0, high=400.0, unit="bpm"), metavar="BPM",
                     help="quarter notes a minute, in [1, 400] (default: the middle of the rudiment's range)")
    rud.add_argument("--bars", type=whole(low=1, high=64), default=2, help="bars of 4/4 to play, 1-64 (default 2)")
    rud.add_argument("--config", type=existing_file, metavar="TOML",
                     help="robot config: the joint's [limits] (its range, speed, acceleration) every planned motion keeps")
    add_model(rud)
    rud.add_argument("--csv", action=Output, suffixes=trajectory_csv.SUFFIXES, metavar="PATH",
                     help="write t (s) and theta (rad), omega (rad/s) per stick as .csv")
    rud.add_argument("--json", action=Output, suffixes=json.SUFFIXES, metavar="PATH",
                     help="write the notes, the designed strokes and the impacts as .json")
    rud.add_argument("--plot", action=Output, suffixes=plot.SUFFIXES, metavar="PATH",
                     help=f"draw theta(t) per stick with the notes: {', '.join(plot.SUFFIXES)}")
    add_sound_options(rud)
    add_mkdir(rud)
    rud.add_argument("--strict", action="store_true", help="exit with status 3 if a note was left out")
    rud.set_defaults(run=_rudiment)


def _design(args):
    from ..design import ForceRange, Setup, buzz, design
    from ..render.data import design_to_dict
    from ..render.outputs import write_stroke_outputs

    setup = Setup(model=args.model, cor=args.cor, forces=ForceRange(high=args.force_max))
    if args.buzz is not None:
        if args.times is not None or args.velocities is not None or args.levels is not None:
            raise ParameterError("give --buzz or --times, not both")
        made = buzz(*args.buzz, velocity=args.velocity, density=args.density, decay=args.decay,
                    finish=args.end or "press", setup=setup)
    else:
        if args.times is None or (args.velocities is None) == (args.levels is None):
            raise ParameterError("give --times with --velocities or --levels (or --buzz T0:T1)")
        made = design(args.times, args.levels, velocities=args.velocities, end=args.end or "catch", setup=setup)
    human = thumb_range(made.min_force, made.max_force)
    print(f"designed {len(made.times)} notes on the {made.model} model: released at {made.release:.6f} s, forces "
          f"{made.min_force:.4g} to {made.max_force:.4g} m/s^2, {human}; ends {made.end} at {made.t_end:.6f} s")
    print(f"{'#':>4} {'note (s)':>11} {'impact (s)':>11} {'note (dB)':>10} {'impact (dB)':>11}")
    for i, (t, level) in enumerate(zip(made.times, made.levels)):
        print(f"{i:>4} {t:>11.6f} {made.impacts.t[i]:>11.6f} {level:>10.3f} {made.impacts.level_db[i]:>11.3f}")
    print(f"largest errors by the solver: {made.time_error:.2e} s, {made.level_error:.2e} dB")
    written = []
    with Bundle() as bundle:  # the recipe with the other files
        if args.out:
            made.recipe.to_toml(args.out, bundle=bundle)
            written.append(args.out)
        written += write_stroke_outputs(made.stroke, json=args.json, csv=args.csv, plot=args.plot, audio=args.audio,
                                        midi=args.midi, snares=not args.no_snares,
                                        extra={"design": design_to_dict(made)}, bundle=bundle)
    print_written(written)


def _rudiment(args):
    from ..compose import compose, rudiment_score
    from ..design import Setup
    from ..palette.rudiments import rudiments
    from ..render.outputs import write_composition_outputs

    if args.list or args.name is None:
        if not args.list:
            raise ParameterError("give a rudiment's NAME, or --list")
        for r in rudiments():
            print(f"{r.number:>2}  {r.name:<30} {r.family:<7} {r.tempo[0]:g}-{r.tempo[1]:g} bpm  {r.sticking}")
        return 0
    from ..palette.rudiments import rudiment

    chosen = rudiment(args.name)
    tempo = args.tempo if args.tempo is not None else sum(chosen.tempo) / 2
    score, played = rudiment_score(chosen.name, tempo, bars=args.bars)
    if played.warning:
        print(f"warning: {played.warning}", file=sys.stderr)
    piece = compose(score, setup=Setup(model=args.model, limits=robot_config(args.config).limits))
    played_notes = sum(p.played for p in piece.placements)
    print(f"{chosen.number} {chosen.title} at {tempo:g} bpm, {args.bars} bar{'s' * (args.bars != 1)} (model "
          f"{piece.model}): {played_notes} of {len(score.notes)} notes played, {len(piece.designs)} designed strokes; "
          + ", ".join(f"{name} {len(s.impacts)} impacts" for name, s in piece.sticks.items()))
    for problem in piece.problems:
        print(f"warning: {problem}", file=sys.stderr)
    print_written(write_composition_outputs(piece, title=chosen.name, csv=args.csv, json=args.json, plot=args.plot,
                                            audio=args.audio, midi=args.midi, snares=not args.no_snares))
    return 3 if args.strict and piece.problems else 0


def _numbers(text):
    try:
        return [float(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be numbers separated by commas, got {text!r}") from None


def _span(text):
    """An argparse type: ``T0:T1`` in seconds, finite, with 0 <= T0 < T1."""
    start, _, end = text.partition(":")
    try:
        t0, t1 = float(start), float(end)
    except ValueError:
        t0 = t1 = math.nan
    if not (0.0 <= t0 < t1 < math.inf):  # NaN fails the comparisons too
        raise argparse.ArgumentTypeError(f"must be T0:T1 in seconds with 0 <= T0 < T1, finite, got {text!r}")
    return t0, t1

