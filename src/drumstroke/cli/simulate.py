"""``drumstroke simulate``, ``presets``, ``figures`` and ``sweep``: strokes from recipes."""

import argparse
import dataclasses
import time

from ..errors import DrumstrokeError, ParameterError
from ..formats import json, table, trajectory_csv
from ..model import MODELS
from ..palette.transforms import STRETCH_LIMIT
from ..presets import PRESETS
from ..render import plot
from ..trajectory import DEFAULT_RATE
from ._common import Bar, add_model, add_sound_options, print_summary, print_written
from ._options import Output, add_mkdir, existing_file, existing_folder, number, whole


def add_simulate(sim):
    """Give ``simulate``'s parser ``sim`` its description and options."""
    sim.description = ("Simulate one stroke and print its impacts; write its data, picture and sound if asked. The "
                       "post-processing options apply in the order given, and what is printed and written is the "
                       "stroke after them.")
    sim.add_argument("stroke", metavar="STROKE",
                     help="a preset ('drumstroke presets'), a stroke of the shipped palette (e.g. double: its recipe "
                          "simulated, then its transforms), or a recipe .toml file; with --library, one of its strokes")
    sim.add_argument("--library", type=existing_folder, metavar="DIR",
                     help="take STROKE from this library folder ('library build'), as stored: no simulation")
    sim.add_argument("--rate", type=number(low=0.0, high=1e6, low_open=True, unit="Hz"), metavar="HZ",
                     help=f"samples per second of --csv, in (0, 1e6] Hz (default {DEFAULT_RATE:g}; with --library, "
                          "the library's)")
    sim.add_argument("--model", choices=MODELS, help="simulate with this model instead of the recipe's "
                                                     "(default: the recipe's, paper unless it says geometry)")
    sim.add_argument("--json", action=Output, suffixes=json.SUFFIXES, metavar="PATH",
                     help="write the recipe, impacts and rests as .json")
    sim.add_argument("--csv", action=Output, suffixes=trajectory_csv.SUFFIXES, metavar="PATH",
                     help="write t (s), theta (rad), omega (rad/s) at --rate as .csv; its model, rate and units go "
                          "in the JSON beside it")
    sim.add_argument("--plot", action=Output, suffixes=plot.SUFFIXES, metavar="PATH",
                     help=f"draw theta(t) with the impacts over a(t): {', '.join(plot.SUFFIXES)}")
    add_sound_options(sim)
    add_mkdir(sim)
    steps = sim.add_argument_group("post-processing, applied in the order given")
    steps.add_argument("--stretch", action=_Step, type=number(low=1 / STRETCH_LIMIT, high=STRETCH_LIMIT), metavar="F",
                       help=f"play F times slower (F < 1: faster), F in [{1 / STRETCH_LIMIT:g}, {STRETCH_LIMIT:g}]")
    steps.add_argument("--compress", action=_Step, type=number(low=0.0, low_open=True), metavar="F",
                       help="scale the height above the head by F > 0 (louder or softer), up to the stick upright")
    steps.add_argument("--reverse", action=_Step, nargs=0, help="play backwards")
    steps.add_argument("--trim", action=_Step, type=_trim, metavar="T0:T1",
                       help="keep the part from T0 to T1 (s; either may be empty: the start, the end)")
    steps.add_argument("--catch", action=_Step, type=whole(low=1), metavar="N",
                       help="end at the top of the rebound after impact N (1, 2, ...)")
    sim.set_defaults(run=_simulate, steps=[])


def add_presets(pre):
    """Give ``presets``'s parser ``pre`` its description and options."""
    pre.description = ("List the presets (the paper's stroke categories) and the strokes of the shipped "
                       "palette: the names 'drumstroke simulate' takes. Writes nothing.")
    pre.set_defaults(run=_presets)


def add_figures(fig):
    """Give ``figures``'s parser ``fig`` its description and options."""
    fig.description = ("Simulate the presets of the paper's Figs. 4-7 and draw each as "
                       "OUTDIR/figN-PRESET.png.")
    fig.add_argument("outdir", action=Output, folder=True, metavar="OUTDIR",
                     help="the folder to write the four PNG files to (created if missing)")
    add_model(fig, what="the model to draw them with")
    add_mkdir(fig)
    fig.set_defaults(run=_figures)


def add_sweep(swp):
    """Give ``sweep``'s parser ``swp`` its description and options."""
    swp.description = ("Simulate every point of a sweep file (a grid or a random sample of "
                       "recipe parameters) and write one row of stroke features per point.")
    swp.add_argument("grid", type=existing_file, metavar="GRID",
                     help="a sweep .toml file (docs/profiles.md: sweeps; examples/sweeps/)")
    swp.add_argument("--out", action=Output, suffixes=table.SUFFIXES, required=True, metavar="TABLE",
                     help="the table to write: .csv or .parquet (parquet needs pyarrow)")
    swp.add_argument("--scheduler", metavar="ADDRESS",
                     help="a Dask scheduler (tcp://host:8786) to run on (default: here, on every core)")
    swp.add_argument("--audible-db", type=number(low=0.0, high=200.0, low_open=True, unit="dB"), metavar="DB",
                     help="impacts within DB of the loudest count as audible, in (0, 200] (default: the file's, or 40)")
    add_mkdir(swp)
    swp.set_defaults(run=_sweep)


def _simulate(args):
    from ..palette.library import make_stroke, planned_duration
    from ..palette.transforms import apply_step
    from ..render.data import as_trajectory
    from ..render.outputs import write_stroke_outputs
    from ..trajectory import check_sampling

    if args.library and args.model:
        raise ParameterError("--model cannot be used with --library: a library's strokes are stored as built")
    duration = planned_duration(args.stroke, args.steps) if args.csv and not args.library else None
    if duration is not None:  # before the simulation: a rate the CSV cannot hold is refused at once
        check_sampling(duration, args.rate or DEFAULT_RATE, 3, name="--rate")
    with Bar("simulating", delay=1.0) as bar:
        stroke = make_stroke(args.stroke, library=args.library, model=args.model, progress=bar.update)
    for op, value in args.steps:
        try:
            stroke = apply_step(stroke, op, value)
        except DrumstrokeError as error:
            raise type(error)(f"--{op}: {error}") from None
    if args.csv:  # the stroke as the CSV samples it, after the steps
        sampled = as_trajectory(stroke)
        check_sampling(sampled.t_end - sampled.start, args.rate or sampled.rate, 3, name="--rate")
    print_summary(stroke)
    print_written(write_stroke_outputs(stroke, json=args.json, csv=args.csv, plot=args.plot, audio=args.audio,
                                       midi=args.midi, rate=args.rate, snares=not args.no_snares))


def _presets(args):
    from ..palette.library import read_palette

    width = max(len(name) for name in PRESETS)
    print("presets (recipes):")
    for name, p in PRESETS.items():
        figure = f" [{p.figure}]" if p.figure else ""
        print(f"  {name:<{width}}  {p.category}{figure}: {p.description}")
    entries = [entry for entry in read_palette() if entry.name not in PRESETS]
    print("strokes of the shipped palette (a recipe, then transforms):")
    width = max(len(entry.name) for entry in entries)
    for entry in entries:
        steps = ", ".join(f"{op} {value}" for step in entry.transforms for op, value in step.items())
        print(f"  {entry.name:<{width}}  {entry.category}: {entry.description}" + (f" [{steps}]" if steps else ""))


def _figures(args):
    from ..demo import write_figures

    with Bar("drawing figures") as bar:
        figures = write_figures(args.outdir, model=args.model, progress=bar.update)
    for figure in figures:
        print_written(figure.paths)


def _sweep(args):
    from ..errors import located
    from ..formats.sidecar import sidecar_for
    from ..formats.table import write_table
    from ..sweep import Grid, run_sweep, table_metadata

    grid = Grid.from_toml(args.grid)
    if args.audible_db is not None:
        grid = dataclasses.replace(grid, audible_db=args.audible_db)
    side = sidecar_for(args.out, name="--out") if args.out.suffix == ".csv" else None  # before the work
    where = f"on {args.scheduler}" if args.scheduler else "here"
    print(f"sweep {args.grid}: {len(grid)} points ({grid.mode}), {where}")
    started = time.monotonic()
    with Bar("sweeping") as bar, located(f"sweep {str(args.grid)!r}"):  # a point's recipe is checked as it is made
        rows = run_sweep(grid, scheduler=args.scheduler, progress=bar.update)
    units, fields = table_metadata(grid, rows)
    write_table(rows, args.out, units=units, fields=fields)  # the table with the JSON beside it, together
    failed = int(sum(1 for error in rows["error"] if error))
    note = f"; {failed} could not be simulated (see the error column)" if failed else ""
    print(f"wrote {args.out}: {len(rows['point'])} rows in {time.monotonic() - started:.1f} s{note}")
    if side:
        print(f"wrote {side} (with the metadata of {args.out.name})")


class _Step(argparse.Action):
    """Record a post-processing option and its value in ``steps``, in command-line order."""

    def __call__(self, parser, namespace, values, option_string=None):
        namespace.steps = [*namespace.steps, (self.dest, True if self.dest == "reverse" else values)]


def _trim(text):
    """An argparse type: ``T0:T1`` in seconds, T0 >= 0 (default 0), T1 > T0 (default the end, None)."""
    start, sep, end = text.partition(":")
    try:
        t0, t1 = float(start) if start else 0.0, float(end) if end else None
    except ValueError:
        sep = ""
    if not sep or not (0.0 <= t0 and (t1 is None or t1 > t0)):  # NaN fails the comparisons too
        raise argparse.ArgumentTypeError(f"must be T0:T1 in s with 0 <= T0 < T1 (either may be empty), got {text!r}")
    return [t0, t1]
