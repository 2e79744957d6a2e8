"""The ``drumstroke`` command: a thin layer over the API, and the only place that prints.

One module per command group registers its sub-commands and runs them: :mod:`.simulate`
(``simulate``, ``presets``, ``figures``, ``sweep``), :mod:`.library`, :mod:`.compose`, :mod:`.stats`,
:mod:`.listen`, :mod:`.robot` and :mod:`.demo`. Bad input ends with exit status 2 and one line
naming the parameter, the value and the allowed range.
"""

import os
import sys

from .. import __version__
from ..errors import DrumstrokeError
from . import compose, demo, library, listen, robot, simulate, stats
from ._common import Parser

_COMMANDS = (simulate.add_simulate, library.add_library, compose.add_compose, simulate.add_presets,
             simulate.add_figures, simulate.add_sweep, stats.add_stats, listen.add_listen, robot.add_robot,
             demo.add_demo)
"""Each command's registration, in the order ``drumstroke --help`` lists them."""


def main(argv=None):
    """Run the command line with ``argv`` (default: ``sys.argv[1:]``); return the exit status."""
    parser = build_parser()
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


def build_parser():
    """The ``drumstroke`` argument parser with every command (the CLI reference is generated from it)."""
    parser = Parser(prog="drumstroke", description="Drum strokes from a physical model of a bouncing stick.")
    parser.add_argument("--version", action="version", version=f"drumstroke {__version__}")
    commands = parser.add_subparsers(dest="command", parser_class=Parser, metavar="COMMAND")
    for add in _COMMANDS:
        add(commands)
    return parser
