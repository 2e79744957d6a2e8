"""Running the ``drumstroke`` command in tests.

:func:`run` calls :func:`drumstroke.cli.main` in this process as the console script does: the
same argv, working folder, stdout and stderr, and warnings and log records shown on stderr as a
fresh interpreter shows them. It spares a Python start-up per call; :func:`run_process` runs the
console script in a subprocess, for the tests where the process itself is what is tested (its
start-up, its environment, its exit on a signal or a closed pipe).
"""

import contextlib
import io
import logging
import os
import re
import shutil
import subprocess
import sys
import warnings
from unittest import mock

from drumstroke import cli

EXE = shutil.which("drumstroke")
COMMAND = [EXE] if EXE else [sys.executable, "-m", "drumstroke.cli"]


def run(*args, cwd=None):
    """Run ``drumstroke ARGS`` in-process; return a CompletedProcess (returncode, stdout, stderr as text)."""
    argv = list(map(str, args))
    out, err = io.StringIO(), io.StringIO()
    with contextlib.ExitStack() as stack:
        stack.enter_context(contextlib.redirect_stdout(out))
        stack.enter_context(contextlib.redirect_stderr(err))
        stack.enter_context(_as_a_fresh_interpreter(err))
        stack.enter_context(mock.patch.object(sys, "argv", [COMMAND[0], *argv]))
        stack.enter_context(mock.patch.object(sys, "stdin", io.StringIO()))  # as subprocess.DEVNULL: nothing to read
        # a process writing into a pipe has no terminal: help is wrapped at COLUMNS or 80 characters
        stack.enter_context(mock.patch.dict(os.environ, {"COLUMNS": os.environ.get("COLUMNS", "80")}))
        if cwd is not None:
            stack.enter_context(contextlib.chdir(cwd))
        returncode = _exit_status(cli.main(argv), err)
    return subprocess.CompletedProcess([*COMMAND, *argv], returncode, out.getvalue(), err.getvalue())


def run_process(*args, cwd=None):
    """Run ``drumstroke ARGS`` in a subprocess (the console script); return the CompletedProcess (text output)."""
    return subprocess.run([*COMMAND, *map(str, args)], check=False, capture_output=True, text=True, cwd=cwd,
                          stdin=subprocess.DEVNULL, timeout=120)


def _exit_status(code, err):
    """The exit status ``sys.exit(code)`` gives a process (a message is printed on stderr, status 1)."""
    if code is None or isinstance(code, int):
        return code or 0
    print(code, file=err)
    return 1


@contextlib.contextmanager
def _as_a_fresh_interpreter(err):
    """Warnings filtered and shown on ``err``, and log records of WARNING and above written there, as in a new
    process: pytest records both otherwise (and turns RuntimeWarnings into errors), which a process does not."""
    handler = logging.StreamHandler(err)  # what logging.lastResort does when nothing is configured
    handler.setLevel(logging.WARNING)
    with warnings.catch_warnings():
        warnings.resetwarnings()
        warnings.filterwarnings("default", category=DeprecationWarning, module="__main__", append=True)
        for category in (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning):
            warnings.filterwarnings("ignore", category=category, append=True)
        warnings.showwarning = lambda message, category, filename, lineno, file=None, line=None: err.write(
            warnings.formatwarning(message, category, filename, lineno, line))
        logging.getLogger().addHandler(handler)
        try:
            yield
        finally:
            logging.getLogger().removeHandler(handler)


def assert_one_line_error(result, *needles):
    """Exit status 2, one line on stderr containing every needle, no traceback."""
    assert result.returncode == 2, result
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.stderr
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])


def problem_lines(text):
    """The lines of a command's output that report a warning or a problem, which a clean run never prints: a
    ``warning:`` line (compose, design, a clipped recording), a Python warning as an interpreter shows it, a library
    stroke cut short, notes left out or not played, problems counted, sweep points that could not be simulated."""
    return [line for line in text.splitlines() if _reports_a_problem(line)]


def _reports_a_problem(line):
    if re.match(r"\s*warning\b", line, re.IGNORECASE) or re.search(r"\w+Warning: ", line):
        return True
    if re.search(r"\bcut [\d.]+ s into it\b|\bleft out\b|\bnot played:|could not be simulated", line):
        return True
    if re.search(r"\b[1-9]\d* (?:\w+ )?(?:not played|problems?)\b", line):  # '2 onsets not played'; '0 problems' is clean
        return True
    return any(done != total for done, total in re.findall(r"\b(\d+) of (\d+) notes\b", line))
