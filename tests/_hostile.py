"""A hostile-input campaign through the console script: each case in a process of its own, measured.

A :class:`Case` makes its files in a folder of its own and names the command line to run there
and the texts its one error line must hold (the file or the option). :func:`run_cases` runs the
``drumstroke`` console script once per case, a few at a time (each a subprocess: threads only
wait), and gives each its :class:`Outcome`: exit status, stdout, stderr, the child's peak
resident memory and CPU time (the kernel's account of that process, taken from a small process that
started it: :mod:`_measured`) and the wall time. A case that runs
past ``timeout`` is killed (its whole process group) and marked so.
"""

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from _cli import COMMAND
from _measured import measured

FIFO, LOOP, FOLDER = object(), object(), object()
"""File contents that are not contents: a FIFO, a symlink to itself, a directory."""


@dataclass(frozen=True)
class Case:
    """One hostile input: ``files`` to make ({name: text, bytes, FIFO, LOOP, FOLDER, a link ``("->", target)`` or a
    callable(path)}), the command line (``{d}`` is the case's folder) and what the error line must name."""

    id: str
    files: dict
    argv: tuple
    needles: tuple = ()

    def make(self, folder):
        """Make the files in ``folder``; return the command line and the needles with ``{d}`` filled in."""
        for name, content in self.files.items():
            path = folder / name
            path.parent.mkdir(parents=True, exist_ok=True)
            if content is FIFO:
                os.mkfifo(path)
            elif content is LOOP:
                os.symlink(path.name, path)
            elif content is FOLDER:
                path.mkdir()
            elif isinstance(content, tuple) and content[0] == "->":
                os.symlink(content[1].format(d=folder), path)
            elif callable(content):
                content(path)
            elif isinstance(content, bytes):
                path.write_bytes(content)
            else:
                path.write_text(content)
        fill = lambda text: text.format(d=folder)
        return [fill(a) for a in self.argv], [fill(n) for n in self.needles]


@dataclass
class Outcome:
    """What one run of the console script did."""

    status: int
    stdout: str
    stderr: str
    peak_mib: float
    cpu_seconds: float
    wall_seconds: float
    killed: bool = False
    needles: list = field(default_factory=list)

    @property
    def lines(self):
        return self.stderr.splitlines()


def run(argv, cwd, *, timeout=60.0):
    """Run ``drumstroke ARGV`` in ``cwd`` (stdin empty); its :class:`Outcome`, measured by :mod:`_measured`."""
    status, stdout, stderr, peak, cpu, wall, killed = measured([*COMMAND, *argv], cwd=cwd, timeout=timeout,
                                                               env={**os.environ, "COLUMNS": "80"})
    return Outcome(status, stdout, stderr, peak / 2**20, cpu, wall, killed)


def run_cases(cases, folder, *, workers=2, timeout=60.0):
    """Make and run every case (each in ``folder / case.id``), ``workers`` at a time; {id: Outcome}."""
    def one(case):
        where = Path(folder) / case.id.replace("/", "_")
        where.mkdir(parents=True)
        argv, needles = case.make(where)
        outcome = run(argv, where, timeout=timeout)
        outcome.needles = needles
        return case.id, outcome

    with ThreadPoolExecutor(workers) as pool:
        return dict(pool.map(one, cases))
