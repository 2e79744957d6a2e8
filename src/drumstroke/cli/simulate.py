"""``drumstroke simulate``, ``presets``, ``figures`` and ``sweep``: strokes from recipes."""

import argparse
import dataclasses
import time
from pathlib import Path

from .._checks import check_real
from ..errors import DrumstrokeError
from ..model import MODELS
from ..presets import PRESETS
from ..trajectory import DEFAULT_RATE
from ._common import Bar, add_sound_options, print_summary, print_written


def add_simulate(commands):
    """Register ``simulate``."""
    sim = commands.add_parser("simulate", help="simulate one stroke from a recipe file or a preset")
    sim.add_argument("recipe", metavar="RECIPE", help="a recipe .toml file or a preset name (see 'drumstroke presets')")
    sim.add_argument("--rate", type=float, default=DEFAULT_RATE, metavar="HZ",
                     help=f"sampling rate of --csv in Hz (default {DEFAULT_RATE:g})")
    sim.add_argument("--model", choices=MODELS, help="override the recipe's model")
    sim.add_argument("--json", type=Path, metavar="PATH", help="write recipe, impacts and rests as JSON")
    sim.add_argument("--csv", type=Path, metavar="PATH", help="write t,theta,omega at --rate as CSV; its model, rate and units go in the JSON beside it")
    sim.add_argument("--plot", type=Path, metavar="PATH", help="write a PNG of theta(t), impacts and a(t)")
    add_sound_options(sim)
    steps = sim.add_argument_group("post-processing, applied in the order given")
    steps.add_argument("--stretch", action=_Step, type=float, metavar="F", help="play F times slower (F < 1: faster)")
    steps.add_argument("--compress", action=_Step, type=float, metavar="F",
                       help="scale the height above the head by F (louder or softer)")
    steps.add_argument("--reverse", action=_Step, nargs=0, help="play backwards")
    steps.add_argument("--trim", action=_Step, metavar="T0:T1", help="keep the part from T0 to T1 s (either may be empty)")
    steps.add_argument("--catch", action=_Step, type=int, metavar="N", help="end at the top of the rebound after impact N")
    sim.set_defaults(run=_simulate, steps=[])


def add_presets(commands):
    """Register ``presets``."""
    commands.add_parser("presets", help="list the named recipes").set_defaults(run=_presets)


def add_figures(commands):
    """Register ``figures``."""
    fig = commands.add_parser("figures", help="draw the paper's Figs. 4-7 as PNG files")
    fig.add_argument("outdir", type=Path, metavar="OUTDIR")
    fig.add_argument("--model", choices=MODELS, default="paper", help="model to draw them with (default paper)")
    fig.set_defaults(run=_figures)


def add_sweep(commands):
    """Register ``sweep``."""
    swp = commands.add_parser("sweep", help="simulate a grid or random sample of recipes; one row of features each")
    swp.add_argument("grid", type=Path, metavar="GRID", help="a sweep .toml file (see the README)")
    swp.add_argument("--out", type=Path, required=True, metavar="TABLE", help="the table to write: .csv or .parquet")
    swp.add_argument("--scheduler", metavar="ADDRESS", help="a Dask scheduler (tcp://host:8786) to run on")
    swp.add_argument("--audible-db", type=float, metavar="DB",
                     help="override the file's audibility threshold (dB below the loudest impact)")
    swp.set_defaults(run=_sweep)


def _simulate(args):
    from ..render.outputs import write_stroke_outputs
    from ..stroke import simulate

    rate = check_real("--rate", args.rate, low=0.0, high=1e6, low_open=True, unit="Hz")
    bar = Bar("simulating", delay=1.0)
    stroke = simulate(args.recipe, model=args.model, progress=bar.update)
    bar.close()
    print_summary(stroke)
    if args.steps:
        from ..palette.transforms import apply_step

        for op, value in args.steps:
            try:
                stroke = apply_step(stroke, op, value)
            except DrumstrokeError as error:
                raise type(error)(f"--{op}: {error}") from None
        print(f"after {', '.join(stroke.history[1:])}: {len(stroke.impacts)} impacts over {stroke.t_end:.6g} s")
    print_written(write_stroke_outputs(stroke, json=args.json, csv=args.csv, plot=args.plot, wav=args.wav,
                                       midi=args.midi, rate=rate, snares=not args.no_snares))


def _presets(args):
    width = max(len(name) for name in PRESETS)
    for name, p in PRESETS.items():
        figure = f" [{p.figure}]" if p.figure else ""
        print(f"{name:<{width}}  {p.category}{figure}: {p.description}")


def _figures(args):
    from ..demo import write_figures

    bar = Bar("drawing figures")
    figures = write_figures(args.outdir, model=args.model, progress=bar.update)
    bar.close()
    for figure in figures:
        print_written(figure.paths)


def _sweep(args):
    from ..formats.sidecar import sidecar_for
    from ..formats.table import check_table_path, write_table
    from ..sweep import Grid, run_sweep, table_metadata

    grid = Grid.from_toml(args.grid)
    if args.audible_db is not None:
        grid = dataclasses.replace(grid, audible_db=args.audible_db)
    check_table_path(args.out, name="--out")  # before the work, not after it
    side = sidecar_for(args.out, name="--out") if args.out.suffix == ".csv" else None
    where = f"on {args.scheduler}" if args.scheduler else "here"
    print(f"sweep {args.grid}: {len(grid)} points ({grid.mode}), {where}")
    started = time.monotonic()
    bar = Bar("sweeping")
    table = run_sweep(grid, scheduler=args.scheduler, progress=bar.update)
    bar.close()
    units, fields = table_metadata(grid, table)
    write_table(table, args.out, units=units, fields=fields)
    failed = int(sum(1 for error in table["error"] if error))
    note = f"; {failed} could not be simulated (see the error column)" if failed else ""
    print(f"wrote {args.out}: {len(table['point'])} rows in {time.monotonic() - started:.1f} s{note}")
    if side:
        print(f"wrote {side} (with the metadata of {args.out.name})")


class _Step(argparse.Action):
    """Record a post-processing option and its value in ``steps``, in command-line order."""

    def __call__(self, parser, namespace, values, option_string=None):
        if self.dest == "reverse":
            values = True
        elif self.dest == "trim":
            values = _trim_value(parser, values)
        namespace.steps = [*namespace.steps, (self.dest, values)]


def _trim_value(parser, text):
    start, sep, end = text.partition(":")
    try:
        if sep:
            return [float(start) if start else 0.0, float(end) if end else None]
    except ValueError:
        pass
    parser.error(f"argument --trim: must be START:END in seconds (either may be empty), got {text!r}")
