"""Running the ``drumstroke`` command in tests: in-process, or as a subprocess where the process is tested.

:func:`run` calls :func:`drumstroke.cli.main` in this process (no second or so of start-up per call), with
what a subprocess would have of its own: its stdout and stderr captured, warnings shown on its stderr
with Python's default filters, its own numpy error state, logging and ``sys.argv``, an empty stdin,
and a working directory put back after it. :func:`run_process` runs the console script itself, for
tests of what only a process shows (start-up imports, signals, the environment, a terminal).
"""

import contextlib
import io
import logging
import os
import shutil
import subprocess
import sys
import warnings
from types import SimpleNamespace

import numpy as np

from drumstroke.cli import main

EXE = shutil.which("drumstroke")

# Python's filters when no -W option and no PYTHONWARNINGS is given, as a fresh process starts with.
_DEFAULT_FILTERS = (("default", DeprecationWarning, "__main__"), ("ignore", DeprecationWarning, None),
                    ("ignore", PendingDeprecationWarning, None), ("ignore", ImportWarning, None),
                    ("ignore", ResourceWarning, None))


def run(*args, cwd=None):
    """Run ``drumstroke ARGS`` in this process; return its returncode, stdout, stderr and args (text)."""
    argv = list(map(str, args))
    stdout, stderr = io.StringIO(), io.StringIO()
    with _process_state(argv, stdout, stderr, cwd):
        try:
            code = main(argv)
        except SystemExit as stop:  # as the interpreter turns it into an exit status
            code = stop.code
    if code is not None and not isinstance(code, int):
        stderr.write(f"{code}\n")
        code = 1
    return SimpleNamespace(args=["drumstroke", *argv], returncode=code or 0, stdout=stdout.getvalue(),
                           stderr=stderr.getvalue())


@contextlib.contextmanager
def _process_state(argv, stdout, stderr, cwd):
    """What a fresh process of the command would have, and this one gets back afterwards."""
    root = logging.getLogger()
    handlers, level = root.handlers[:], root.level
    saved_argv, saved_stdin, here = sys.argv, sys.stdin, os.getcwd()
    sys.argv, sys.stdin = ["drumstroke", *argv], io.StringIO()
    try:
        if cwd is not None:
            os.chdir(cwd)
        with (warnings.catch_warnings(), np.errstate(divide="warn", over="warn", under="ignore", invalid="warn"), contextlib.redirect_stdout(stdout),
              contextlib.redirect_stderr(stderr)):
            warnings.resetwarnings()
            for action, category, module in reversed(_DEFAULT_FILTERS):
                warnings.filterwarnings(action, category=category, module=module or "")
            warnings.showwarning = _show_on_stderr
            yield
    finally:
        os.chdir(here)
        sys.argv, sys.stdin = saved_argv, saved_stdin
        root.handlers[:], root.level = handlers, level


def _show_on_stderr(message, category, filename, lineno, file=None, line=None):
    """Print a warning on the current sys.stderr, as Python does (pytest's capture is bypassed)."""
    sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


def run_process(*args, cwd=None, timeout=120):
    """Run ``drumstroke ARGS`` as a subprocess (the console script); return the CompletedProcess (text output)."""
    command = [EXE] if EXE else [sys.executable, "-m", "drumstroke.cli"]
    return subprocess.run([*command, *map(str, args)], check=False, capture_output=True, text=True, cwd=cwd,
                          timeout=timeout)


def assert_one_line_error(result, *needles):
    """Exit status 2, one line on stderr containing every needle, no traceback."""
    assert result.returncode == 2, result
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.stderr
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
