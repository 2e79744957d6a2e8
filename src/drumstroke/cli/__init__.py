"""The ``drumstroke`` command: a thin layer over the API, and the only place that prints.

One module per command group registers its sub-commands and runs them: :mod:`.simulate`
(``simulate``, ``presets``, ``figures``, ``sweep``), :mod:`.library`, :mod:`.compose`, :mod:`.design` (``design``, ``rudiment``), :mod:`.stats`,
:mod:`.listen`, :mod:`.live`, :mod:`.robot`, :mod:`.analysis` (``onsets``, ``measure-cor``), :mod:`.fit`,
:mod:`.compare` and :mod:`.demo`. Every option is checked before any work
(:mod:`._options`): bad input ends with exit status 2 and one line naming the option, the value
and what is allowed, and nothing written.
"""

import os
import sys

from .. import __version__
from ..errors import DrumstrokeError
from . import analysis, compare, compose, demo, design, fit, library, listen, live, robot, simulate, stats
from ._common import Parser
from ._options import check_outputs, output_option

_COMMANDS = (simulate.add_simulate, library.add_library, compose.add_compose, design.add_design,
             design.add_rudiment, simulate.add_presets, simulate.add_figures, simulate.add_sweep, stats.add_stats,
             listen.add_listen, live.add_live, robot.add_robot, analysis.add_onsets, analysis.add_measure_cor,
             fit.add_fit, compare.add_compare, demo.add_demo)
"""Each command's registration, in the order ``drumstroke --help`` lists them."""


def main(argv=None):
    """Run the command line with ``argv`` (default: ``sys.argv[1:]``); return the exit status."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as stop:  # --help, --version, or a bad option: argparse has said so
        return stop.code
    if not hasattr(args, "run"):
        parser.print_help()
        return 2
    try:
        check_outputs(args)
        return args.run(args) or 0
    except DrumstrokeError as error:
        print(f"drumstroke {args.command}: error: {error}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. piped into head: stop quietly, as other tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as error:
        option = output_option(args, error.filename) if error.filename else None
        where = f" {option}: cannot write {error.filename!r}:" if option else (
            f" {error.filename!r}:" if error.filename else "")
        print(f"drumstroke {args.command}: error:{where} {error.strerror or error}", file=sys.stderr)
        return 2
    except ImportError as error:
        print(f"drumstroke {args.command}: error: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"drumstroke {args.command}: interrupted", file=sys.stderr)
        return 130


def build_parser():
    """The ``drumstroke`` argument parser with every command (the CLI reference is generated from it)."""
    parser = Parser(prog="drumstroke", description="Drum strokes from a physical model of a bouncing stick.")
    parser.add_argument("--version", action="version", version=f"drumstroke {__version__}")
    commands = parser.add_subparsers(dest="command", parser_class=Parser, metavar="COMMAND")
    for add in _COMMANDS:
        add(commands)
    return parser
