"""The ``drumstroke`` command: a thin layer over the API, and the only place that prints.

One module per command group gives its commands their options and runs them: :mod:`.simulate`
(``simulate``, ``presets``, ``figures``, ``sweep``), :mod:`.library`, :mod:`.compose`, :mod:`.design` (``design``, ``rudiment``), :mod:`.stats`,
:mod:`.listen`, :mod:`.live`, :mod:`.robot`, :mod:`.analysis` (``onsets``, ``measure-cor``), :mod:`.fit`,
:mod:`.compare`, :mod:`.demo` and :mod:`.studio`. A command's module is imported only when it runs (or its help is
asked for): ``drumstroke --version`` and ``--help`` import none, and each module imports what its
commands compute with only inside them. Every option is checked before any work
(:mod:`._options`): bad input ends with exit status 2 and one line naming the option, the value
and what is allowed, and nothing written.

:func:`main` is the one error path: whatever a command meets from a user's input (a
ParameterError, an OSError naming the user's path, text that is not UTF-8, a number, a nesting
or a file too large, a file that is not a database) ends in one line on stderr and exit status
2, a value in it longer than 80 characters cut and its length said (:func:`._parser.shortened`);
anything else is a bug, reported in one line that says where to report it and names the log
file holding its traceback, with exit status 1. ``drumstroke --debug COMMAND ...`` prints the
traceback of any error as well. A command runs with its inputs guarded: no output is written
over a file it read (:func:`drumstroke._atomic.guarding_inputs`).
"""

import gc
import os
import re
import sqlite3
import sys
import tempfile
import traceback
import warnings
from importlib import import_module

from .. import __version__
from ..errors import DrumstrokeError, ParameterError, SampledImpactsWarning
from ._parser import Parser, named_option, shortened

COMMANDS = {
    "simulate": ("simulate", "simulate one stroke: a preset, a palette stroke or a recipe file"),
    "library": ("library", "build, list or check a stroke library (text files a robot host loads)"),
    "compose": ("compose", "turn a score (MIDI file or text pattern) into one trajectory per stick"),
    "design": ("design", "design the thumb force that plays given notes on one stick"),
    "rudiment": ("design", "play one of the 40 PAS rudiments at a tempo, designed by the planner"),
    "presets": ("simulate", "list the named recipes and the strokes of the shipped palette"),
    "figures": ("simulate", "draw the paper's Figs. 4-7 as PNG files"),
    "sweep": ("simulate", "simulate a grid or random sample of recipes; one row of features each"),
    "stats": ("stats", "listening-test statistics: Tryon's ICIs, Rg, equivalence tests, correlations"),
    "listen": ("listen", "the listening-test web app: serve it, analyse it, make its stimuli"),
    "live": ("live", "play notes as they arrive: OSC, MIDI or a score in, setpoints at the control rate out"),
    "robot": ("robot", "play strokes on a simulated robot joint; validate and export trajectories"),
    "onsets": ("analysis", "find the stick's impacts in a recording: times (sub-ms) and relative levels"),
    "measure-cor": ("analysis", "measure the coefficient of restitution c from a recording of a dropped stick"),
    "fit": ("fit", "fit a recipe to a recorded stroke: start, c and force profile whose impacts match it"),
    "compare": ("compare", "compare two strokes: bounces, intervals, how the volume fades, bounce rate"),
    "demo": ("demo", "build the library, render every stroke, compose a groove, write index.html"),
    "studio": ("studio", "design, hear and see strokes and parts in the browser (a local web app)"),
}
"""Each command, in the order ``drumstroke --help`` lists them: the module whose ``add_NAME(parser)`` gives it its
options (NAME with ``_`` for ``-``), and its line in that list."""

REPORT = "the drumstroke project's issue tracker"
"""Where a bug is to be reported, as the message of an unexpected error says."""


def main(argv=None):
    """Run the command line with ``argv`` (default: ``sys.argv[1:]``); return the exit status.

    0 when the command succeeded; 2 for bad input (one line on stderr); 1 for a missing
    optional dependency or a bug (one line; a bug's traceback in a log file it names); 130
    when interrupted; 141 when the output pipe closed.
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    name, args = "drumstroke", None
    try:
        parser = _parser([word for word in argv if not word.startswith("-")][:1])  # the command: no option takes a value
        args = parser.parse_args(argv)
        if getattr(args, "command", None):  # named as argparse names it: with the action of a command group
            action = getattr(args, f"{args.command}_command", None)
            name = " ".join(filter(None, ("drumstroke", args.command, action)))
        if not hasattr(args, "run"):
            parser.print_help()
            return 2
        from .._atomic import guarding_inputs
        from ..budget import allowing
        from ._options import budget_of, check_outputs

        with guarding_inputs(), warnings.catch_warnings(), allowing(budget_of(args)):  # no output over an input
            check_outputs(args)
            warnings.simplefilter("ignore", SampledImpactsWarning)  # the commands read a CSV for its samples
            return args.run(args) or 0
    except SystemExit as stop:  # --help, --version, or a bad option: argparse has said so
        return stop.code
    except BaseException as error:  # noqa: BLE001 - the one place every error ends
        if args is not None and args.debug or args is None and "--debug" in argv:
            traceback.print_exc(file=sys.stderr)
        return _failed(error, name, args)


def console():
    """The ``drumstroke`` command in a process of its own (the console script, ``python -m drumstroke``).

    :func:`main`, then what the process no longer needs is left to the exit: the interpreter's
    shutdown runs garbage collections over every object still alive, numba's tens of thousands
    among them (some 0.1 s of a warm ``drumstroke simulate``). The command's own garbage is
    collected first (its finalizers run, as at any exit); what is left, the modules' objects the
    process is about to drop, is frozen out of those collections. A program that calls
    :func:`main` itself keeps its collector as it was.
    """
    status = main()
    gc.collect()
    gc.freeze()
    return status


def _failed(error, name, args):
    """Say what went wrong in one line on stderr; return the exit status."""
    if isinstance(error, KeyboardInterrupt):
        print(f"{name}: interrupted", file=sys.stderr)
        return 130
    if isinstance(error, BrokenPipeError):  # e.g. piped into head: stop quietly, as other tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    if isinstance(error, ImportError):  # an optional dependency missing: the message names its extra
        print(f"{name}: error: {error}", file=sys.stderr)
        return 1
    reason = _input_error(error, args)
    if reason is None:
        print(f"{name}: internal error: {type(error).__name__}: {shortened(_one_line(error))}; this is a bug in "
              f"drumstroke: please report it to {REPORT}, {_logged(error, name)}", file=sys.stderr)
        return 1
    print(f"{name}: error: {shortened(reason)}", file=sys.stderr)
    return 2


def _input_error(error, args):
    """The one line to say for an error a user's input can cause, or None for a bug."""
    if isinstance(error, ParameterError):
        return _one_line(named_option(error))
    if isinstance(error, DrumstrokeError):
        return _one_line(error)
    if isinstance(error, OSError):
        from ._options import output_option

        option = output_option(args, error.filename) if error.filename and args is not None else None
        where = f"{option}: cannot write {error.filename!r}: " if option else (
            f"{error.filename!r}: " if error.filename else "")
        return f"{where}{error.strerror or _one_line(error)}"
    if isinstance(error, UnicodeError):
        return f"the input is not UTF-8 text ({_one_line(error)})"
    if isinstance(error, sqlite3.Error):
        database = getattr(args, "db", None)
        return f"database {str(database)!r}: {_one_line(error)}" if database else f"database: {_one_line(error)}"
    if isinstance(error, RecursionError):
        return "the input nests too deeply to read"
    if isinstance(error, MemoryError):
        return "out of memory: the input is too large for this machine"
    if isinstance(error, ValueError | OverflowError):
        return f"{type(error).__name__}: {_one_line(error)}"
    return None


def _logged(error, name):
    """Where the traceback of ``error`` was written (a new log file), or why it could not be."""
    try:
        descriptor, path = tempfile.mkstemp(prefix="drumstroke-", suffix=".log")
        with os.fdopen(descriptor, "w") as log:
            log.write(f"{name} (drumstroke {__version__}, Python {sys.version.split()[0]}): {sys.argv!r}\n")
            traceback.print_exception(error, file=log)
    except OSError as failure:
        return f"with the traceback `drumstroke --debug ...` prints (no log file: {failure.strerror or failure})"
    return f"with the traceback in {path}"


def _one_line(error):
    """The message of ``error`` on one line."""
    return re.sub(r"\s*\n\s*", " ", str(error).strip()) or type(error).__name__


def build_parser():
    """The ``drumstroke`` argument parser with every command (the CLI reference is generated from it)."""
    return _parser(COMMANDS)


def _parser(built):
    """The argument parser listing every command, with the options of the commands named in ``built``.

    The others are listed by name and line only, their modules not imported: a command runs
    with the same parser either way.
    """
    parser = Parser(prog="drumstroke", description="Drum strokes from a physical model of a bouncing stick.")
    parser.add_argument("--version", action="version", version=f"drumstroke {__version__}")
    parser.add_argument("--debug", action="store_true", help="print the traceback of an error too")
    commands = parser.add_subparsers(dest="command", parser_class=Parser, metavar="COMMAND")
    for name, (module, line) in COMMANDS.items():
        command = commands.add_parser(name, help=line)
        if name in built:
            from ._options import add_budget

            add = getattr(import_module(f".{module}", __name__), f"add_{name.replace('-', '_')}")
            add(command)
            add_budget(command)
    return parser
