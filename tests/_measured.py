"""Run a command in a process of its own and measure it: its exit, output, peak memory and CPU time.

The kernel's account of a process's peak resident memory (``ru_maxrss``) keeps the larger of its
size before and after ``exec``: a child forked from a large process (a test run's, 1 GB after a
while) reads at least that large, whatever it then does. So the command is started from this small
script, run as a program of its own: it forks the command, waits for it with ``os.wait4`` and
writes what the kernel says of it (status, peak memory, CPU time) to a report file.

``python _measured.py REPORT COMMAND [ARGS...]``: REPORT gets ``status maxrss_kib utime stime``.
"""

import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

SCRIPT = str(Path(__file__).resolve())


def measured(argv, *, cwd=None, env=None, timeout=60.0):
    """Run ``argv``; return (status, stdout, stderr, peak memory in bytes, CPU s, wall s, killed).

    The command runs in a session of its own; past ``timeout`` s the whole session is killed (status
    -9, killed True). Peak memory and CPU time are the command's own (0 when it was killed).
    """
    with tempfile.TemporaryDirectory() as folder, tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        report = Path(folder) / "usage"
        started = time.monotonic()
        process = subprocess.Popen([sys.executable, SCRIPT, str(report), *map(str, argv)], cwd=cwd, env=env,
                                   stdin=subprocess.DEVNULL, stdout=out, stderr=err, start_new_session=True)
        killed = threading.Event()

        def kill():
            killed.set()
            os.killpg(process.pid, signal.SIGKILL)

        timer = threading.Timer(timeout, kill)
        timer.start()
        try:
            process.wait()
        finally:
            timer.cancel()
        wall = time.monotonic() - started
        out.seek(0)
        err.seek(0)
        stdout, stderr = out.read().decode(errors="replace"), err.read().decode(errors="replace")
        if not report.exists():  # killed before the command ended
            return process.returncode, stdout, stderr, 0.0, 0.0, wall, killed.is_set()
        status, maxrss, utime, stime = report.read_text().split()
        return (os.waitstatus_to_exitcode(int(status)), stdout, stderr, int(maxrss) * 1024.0,
                float(utime) + float(stime), wall, killed.is_set())


def _main(report, argv):
    pid = os.fork()
    if pid == 0:
        try:
            os.execvp(argv[0], argv)
        finally:
            os._exit(127)
    _, status, usage = os.wait4(pid, 0)
    Path(report).write_text(f"{status} {usage.ru_maxrss} {usage.ru_utime} {usage.ru_stime}\n")
    return 0


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1], sys.argv[2:]))
