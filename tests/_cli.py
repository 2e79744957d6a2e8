"""Running the ``drumstroke`` command in tests, as a user would: a subprocess."""

import shutil
import subprocess
import sys

EXE = shutil.which("drumstroke")


def run(*args, cwd=None):
    """Run ``drumstroke ARGS`` and return the CompletedProcess (text output captured)."""
    command = [EXE] if EXE else [sys.executable, "-m", "drumstroke.cli"]
    return subprocess.run([*command, *map(str, args)], check=False, capture_output=True, text=True, cwd=cwd,
                          timeout=120)


def assert_one_line_error(result, *needles):
    """Exit status 2, one line on stderr containing every needle, no traceback."""
    assert result.returncode == 2, result
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.stderr
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
