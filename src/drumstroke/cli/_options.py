"""Options checked before any work: numbers in range, inputs that exist, outputs that can be written.

A number or an input is checked as it is parsed (an argparse ``type``), an output's extension too
(the :class:`Output` action); an output's folder is checked after parsing and before the command
runs (:func:`check_outputs`): it must exist unless ``--mkdir`` asks for it to be created. Errors
name the option, the value and what is allowed, on one line.
"""

import argparse
import math
import os
import stat
from pathlib import Path

from .._atomic import check_target, note_input
from .._checks import check_int, check_real
from ..errors import ParameterError
from ..formats.reading import check_regular


def number(*, low=-math.inf, high=math.inf, low_open=False, high_open=False, unit=""):
    """An argparse type: a finite number in [low, high] (ends open on request), as a float."""
    limits = {"low": low, "high": high, "low_open": low_open, "high_open": high_open, "unit": unit}
    return lambda text: _checked(check_real, _parsed(text, float), **limits)


def whole(*, low, high=None, unit=""):
    """An argparse type: an integer in [low, high] ([low, inf) without high)."""
    return lambda text: _checked(check_int, _parsed(text, int), low=low, high=high, unit=unit)


def existing_file(text):
    """An argparse type: the path of a regular file that exists (a directory, a FIFO or a device is refused by name)."""
    if not os.path.lexists(text):  # a link that leads nowhere, or in a loop, is said so below
        raise argparse.ArgumentTypeError(f"file {text!r} does not exist")
    try:
        check_regular(text, "file")
    except ParameterError as error:
        raise argparse.ArgumentTypeError(str(error)) from None
    return Path(text)


def existing_folder(text):
    """An argparse type: the path of a directory that exists."""
    try:
        mode = os.stat(text).st_mode
    except (OSError, ValueError) as error:  # ValueError: a NUL in the name
        missing = isinstance(error, FileNotFoundError | NotADirectoryError | ValueError)
        reason = "does not exist" if missing else f"cannot be opened: {error.strerror or error}"
        raise argparse.ArgumentTypeError(f"directory {text!r} {reason}") from None
    if not stat.S_ISDIR(mode):
        raise argparse.ArgumentTypeError(f"{text!r} is not a directory")
    return Path(text)


def _parsed(text, kind):
    try:
        return kind(text)
    except ValueError:
        return text  # the check names it as not a number


def _checked(check, value, **limits):
    try:
        return check("value", value, **limits)
    except ParameterError as error:
        raise argparse.ArgumentTypeError(error.reason) from None


class Output(argparse.Action):
    """An output path: a file whose extension is among ``suffixes`` (any if None), or a ``folder``.

    The extension is checked when the option is parsed; every output is recorded in the
    namespace's ``outputs`` ({dest: (option, path, folder)}) for :func:`check_outputs`.
    """

    def __init__(self, option_strings, dest, *, suffixes=None, folder=False, **kwargs):
        super().__init__(option_strings, dest, **kwargs)
        self.suffixes, self.folder = suffixes, folder

    def __call__(self, parser, namespace, value, option_string=None):
        path = Path(value)
        if self.suffixes is not None and path.suffix.lower() not in self.suffixes:
            raise argparse.ArgumentError(self, f"{value!r} must end in one of {', '.join(self.suffixes)}")
        setattr(namespace, self.dest, path)
        option = option_string or self.metavar
        namespace.outputs = {**getattr(namespace, "outputs", {}), self.dest: (option, path, self.folder)}


def add_mkdir(parser):
    """``--mkdir``, for a command that writes files: create their missing folders."""
    parser.add_argument("--mkdir", action="store_true",
                        help="create the missing folders of the output paths (default: a missing folder is an error)")


def add_budget(parser):
    """``--budget-gb`` and ``--budget-minutes`` on ``parser``, or on every command under it when it has sub-commands."""
    from ..budget import DEFAULT_MEMORY_GB, DEFAULT_MINUTES

    commands = [action for action in parser._actions if isinstance(action, argparse._SubParsersAction)]
    for sub in (commands[0].choices.values() if commands else ()):
        add_budget(sub)
    if commands:
        return
    group = parser.add_argument_group("resource budget (what an input may ask for, estimated before the work)")
    group.add_argument("--budget-gb", type=number(low=0.0, low_open=True, unit="GB"), default=DEFAULT_MEMORY_GB,
                       metavar="GB", help=f"memory an input may ask for, GB of arrays (default {DEFAULT_MEMORY_GB:g})")
    group.add_argument("--budget-minutes", type=number(low=0.0, low_open=True, unit="min"), default=DEFAULT_MINUTES,
                       metavar="MIN", help=f"work an input may ask for, minutes as estimated (default "
                                           f"{DEFAULT_MINUTES:g})")


def budget_of(args):
    """The :class:`~drumstroke.budget.Budget` the options of ``args`` give, its refusals naming the options."""
    from ..budget import DEFAULT_MEMORY_GB, DEFAULT_MINUTES, Budget

    return Budget(getattr(args, "budget_gb", DEFAULT_MEMORY_GB), getattr(args, "budget_minutes", DEFAULT_MINUTES),
                  memory_option="--budget-gb", minutes_option="--budget-minutes")


def check_outputs(args):
    """Check every output's folder before the work; then, if ``args.mkdir``, create the missing ones.

    A file's folder must exist (or is created with ``--mkdir``) and be writable, and the file must
    not be a directory, a FIFO or a device, nor one of the command's input files
    (:func:`drumstroke._atomic.check_target`: the inputs the command line names are noted first); a
    folder output must be a directory or not exist yet (the command creates it, in a folder that
    must exist or is created with ``--mkdir``).
    """
    outputs = getattr(args, "outputs", {})
    for dest, value in vars(args).items():
        for item in value if isinstance(value, list | tuple) else (value,):
            if isinstance(item, Path) and dest not in outputs:
                note_input(item)
    missing = []
    for option, path, is_folder in outputs.values():
        if is_folder and path.exists() and not path.is_dir():
            raise ParameterError(f"{option}: {str(path)!r} is a file, not a directory")
        if not is_folder and path.is_dir():
            raise ParameterError(f"{option}: {str(path)!r} is a directory, not a file")
        if not is_folder:
            check_target(path)
        folder = path if is_folder and path.is_dir() else path.parent
        if not folder.is_dir():
            if folder.exists():
                raise ParameterError(f"{option}: {str(folder)!r} is not a directory")
            if not getattr(args, "mkdir", False):
                raise ParameterError(f"{option}: directory {str(folder)!r} does not exist (use --mkdir to create it)")
            missing.append(folder)
        elif not os.access(folder, os.W_OK | os.X_OK):
            raise ParameterError(f"{option}: directory {str(folder)!r} is not writable")
    for folder in missing:
        folder.mkdir(parents=True, exist_ok=True)


def output_option(args, filename):
    """The option whose output ``filename`` (a file written, or one inside a folder output) is, or None."""
    written = Path(os.path.abspath(filename))  # a bundle names its files by their absolute paths
    for option, path, folder in getattr(args, "outputs", {}).values():
        path = Path(os.path.abspath(path))
        if written == path or (folder and path in written.parents):
            return option
    return None
