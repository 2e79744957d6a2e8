"""The ``drumstroke`` command: a thin layer over the API, and the only place that prints.

Sub-commands: ``simulate``, ``presets``, ``figures``, ``sweep``, ``demo``. Bad input ends
with exit status 2 and one line naming the parameter, the value and the
allowed range.
"""

import argparse
import dataclasses
import math
import os
import sys
import time
from pathlib import Path

from . import __version__
from ._checks import check_real
from .errors import DrumstrokeError
from .model import MODELS, inertia_ratio
from .presets import PRESETS
from .stroke import DEFAULT_RATE, simulate

FIGURES = {p.figure: name for name, p in PRESETS.items() if p.figure}
"""The paper's figures and the presets that reproduce them."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


def main(argv=None):
    """Run the command line with ``argv`` (default: ``sys.argv[1:]``); return the exit status."""
    parser = _build_parser()
    args = parser.parse_args(argv)
    if not hasattr(args, "run"):
        parser.print_help()
        return 2
    try:
        return args.run(args) or 0
    except DrumstrokeError as error:
        print(f"drumstroke {args.command}: error: {error}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. piped into head: stop quietly, as other tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as error:
        where = f" {error.filename!r}" if error.filename else ""
        print(f"drumstroke {args.command}: error:{where} {error.strerror or error}", file=sys.stderr)
        return 2
    except ImportError as error:
        print(f"drumstroke {args.command}: error: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"drumstroke {args.command}: interrupted", file=sys.stderr)
        return 130


def _build_parser():
    parser = _Parser(prog="drumstroke", description="Drum strokes from a physical model of a bouncing stick.")
    parser.add_argument("--version", action="version", version=f"drumstroke {__version__}")
    commands = parser.add_subparsers(dest="command", parser_class=_Parser, metavar="COMMAND")

    sim = commands.add_parser("simulate", help="simulate one stroke from a recipe file or a preset")
    sim.add_argument("recipe", metavar="RECIPE", help="a recipe .toml file or a preset name (see 'drumstroke presets')")
    sim.add_argument("--rate", type=float, default=DEFAULT_RATE, metavar="HZ",
                     help=f"sampling rate of --csv in Hz (default {DEFAULT_RATE:g})")
    sim.add_argument("--model", choices=MODELS, help="override the recipe's model")
    sim.add_argument("--json", type=Path, metavar="PATH", help="write recipe, impacts and rests as JSON")
    sim.add_argument("--csv", type=Path, metavar="PATH", help="write t,theta,omega at --rate as CSV")
    sim.add_argument("--plot", type=Path, metavar="PATH", help="write a PNG of theta(t), impacts and a(t)")
    sim.set_defaults(run=_simulate)

    pre = commands.add_parser("presets", help="list the named recipes")
    pre.set_defaults(run=_presets)

    fig = commands.add_parser("figures", help="draw the paper's Figs. 4-7 as PNG files")
    fig.add_argument("outdir", type=Path, metavar="OUTDIR")
    fig.add_argument("--model", choices=MODELS, default="paper", help="model to draw them with (default paper)")
    fig.set_defaults(run=_figures)

    swp = commands.add_parser("sweep", help="simulate a grid or random sample of recipes; one row of features each")
    swp.add_argument("grid", type=Path, metavar="GRID", help="a sweep .toml file (see the README)")
    swp.add_argument("--out", type=Path, required=True, metavar="TABLE", help="the table to write: .csv or .parquet")
    swp.add_argument("--scheduler", metavar="ADDRESS", help="a Dask scheduler (tcp://host:8786) to run on")
    swp.add_argument("--audible-db", type=float, metavar="DB",
                     help="override the file's audibility threshold (dB below the loudest impact)")
    swp.set_defaults(run=_sweep)

    demo = commands.add_parser("demo", help="simulate the paper's four figure cases: plots, JSON and CSV")
    demo.add_argument("outdir", type=Path, metavar="OUTDIR")
    demo.set_defaults(run=_demo)
    return parser


def _simulate(args):
    rate = check_real("--rate", args.rate, low=0.0, high=1e6, low_open=True, unit="Hz")
    bar = _Bar("simulating", delay=1.0)
    stroke = simulate(args.recipe, model=args.model, progress=bar.update)
    bar.close()
    _print_summary(stroke)
    _write_outputs(stroke, json_path=args.json, csv_path=args.csv, plot_path=args.plot, rate=rate)


def _write_outputs(stroke, *, json_path=None, csv_path=None, plot_path=None, rate=DEFAULT_RATE, title=None):
    from .render.data import write_csv, write_json

    if json_path:
        write_json(stroke, json_path)
        print(f"wrote {json_path}")
    if csv_path:
        write_csv(stroke, csv_path, rate=rate)
        print(f"wrote {csv_path} ({rate:g} Hz)")
    if plot_path:
        from .render.plot import save_stroke_plot

        save_stroke_plot(stroke, plot_path, title=title)
        print(f"wrote {plot_path}")


def _print_summary(stroke, *, rows=10):
    recipe = stroke.recipe
    d = inertia_ratio(recipe.model, recipe.stick)
    print(
        f"stroke {recipe.name or 'custom'}: model {recipe.model} (D = {d:.4f} m^2), "
        f"theta_max = {recipe.theta_max:.4f} rad, c = {recipe.cor:g}, {recipe.t_end:g} s"
    )
    impacts = stroke.impacts
    rest = f"at rest from {stroke.rest_time:.6f} s" if stroke.rest_time is not None else "still moving at the end"
    print(f"{len(impacts)} impacts; {rest}")
    if len(impacts):
        print(f"{'#':>5} {'t (s)':>11} {'omega (rad/s)':>14} {'tip (m/s)':>10} {'level (dB)':>10}")
        for i in range(min(rows, len(impacts))):
            print(
                f"{i + 1:>5} {impacts.t[i]:>11.6f} {impacts.omega[i]:>14.6f} "
                f"{impacts.tip_speed[i]:>10.6f} {impacts.level_db[i]:>10.2f}"
            )
        if len(impacts) > rows:
            print(f"{'...':>5} ({len(impacts) - rows} more; level re 1 m/s tip speed)")


def _sweep(args):
    from .sweep import Grid, check_table_path, run_sweep, write_table

    grid = Grid.from_toml(args.grid)
    if args.audible_db is not None:
        grid = dataclasses.replace(grid, audible_db=args.audible_db)
    check_table_path(args.out, name="--out")  # before the work, not after it
    where = f"on {args.scheduler}" if args.scheduler else "here"
    print(f"sweep {args.grid}: {len(grid)} points ({grid.mode}), {where}")
    started = time.monotonic()
    bar = _Bar("sweeping")
    table = run_sweep(grid, scheduler=args.scheduler, progress=bar.update)
    bar.close()
    write_table(table, args.out)
    failed = int(sum(1 for error in table["error"] if error))
    note = f"; {failed} could not be simulated (see the error column)" if failed else ""
    print(f"wrote {args.out}: {len(table['point'])} rows in {time.monotonic() - started:.1f} s{note}")


def _presets(args):
    width = max(len(name) for name in PRESETS)
    for name, p in PRESETS.items():
        figure = f" [{p.figure}]" if p.figure else ""
        print(f"{name:<{width}}  {p.category}{figure}: {p.description}")


def _figures(args):
    bar = _Bar("drawing figures")
    for i, (figure, name) in enumerate(FIGURES.items()):
        stroke = simulate(name, model=args.model)
        path = args.outdir / f"{_slug(figure)}-{name}.png"
        _write_outputs(stroke, plot_path=path, title=f"{figure} {name}")
        bar.update((i + 1) / len(FIGURES))
    bar.close()


def _demo(args):
    bar = _Bar("demo")
    for i, (figure, name) in enumerate(FIGURES.items()):
        stroke = simulate(name)
        stem = args.outdir / f"{_slug(figure)}-{name}"
        print()
        _print_summary(stroke, rows=3)
        _write_outputs(
            stroke,
            json_path=stem.with_suffix(".json"),
            csv_path=stem.with_suffix(".csv"),
            plot_path=stem.with_suffix(".png"),
            title=f"{figure} {name}",
        )
        bar.update((i + 1) / len(FIGURES))
    bar.close()
    print(f"\ndemo written to {args.outdir}/")


def _slug(figure):
    return figure.lower().replace(". ", "").replace(" ", "")


class _Bar:
    """A progress bar on stderr, drawn only on a terminal and only after ``delay`` seconds."""

    def __init__(self, label, *, delay=0.0):
        self.label = label
        self.start = time.monotonic()
        self.delay = delay
        self.drawn = False
        self.enabled = sys.stderr.isatty()

    def update(self, fraction):
        if not self.enabled or time.monotonic() - self.start < self.delay:
            return
        filled = math.floor(30 * min(max(fraction, 0.0), 1.0))
        sys.stderr.write(f"\r{self.label} [{'#' * filled}{'.' * (30 - filled)}] {100 * fraction:5.1f}%")
        sys.stderr.flush()
        self.drawn = True

    def close(self):
        if self.drawn:
            sys.stderr.write("\n")
            sys.stderr.flush()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
