"""A flood of maximal messages at ``drumstroke live``: ``python benchmarks/live_flood.py [--seconds 300]``.

Starts the console script (``--osc-in`` on loopback, ``--csv`` to /dev/null, ``--log``) and sends it, round after
round for ``--seconds`` s, the largest messages of each kind a client may send (:func:`round_of_datagrams`): a
datagram of 60 KB naming a stick of 60,000 characters, a bundle of 8 KB of notes naming sticks of 64 characters (not
the session's), a bundle of notes on its sticks (most too close to be played) and a note an hour ahead. Every 5 s
it reads the child's resident memory (``VmRSS`` of /proc), then sends SIGINT and times the exit. Prints the
figures and writes them with the machine and date to benchmarks/live_flood_results.json.
"""

import argparse
import datetime
import json
import platform
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from pythonosc.osc_bundle_builder import IMMEDIATELY, OscBundleBuilder
from pythonosc.osc_message_builder import OscMessageBuilder

HERE = Path(__file__).resolve().parent


def message(address, *args):
    builder = OscMessageBuilder(address=address)
    for arg in args:
        builder.add_arg(arg)
    return builder.build()


def bundle(messages):
    builder = OscBundleBuilder(IMMEDIATELY)
    for one in messages:
        builder.add_content(one)
    return builder.build().dgram


def round_of_datagrams(k):
    """The datagrams of round ``k``: the largest of each kind (see the module)."""
    named = [message("/drum/note/at", 2.0 + i, f"{k:08d}{i:02d}".ljust(64, "x"), 100) for i in range(75)]
    played = [message("/drum/note", "auto" if i % 2 else "right", 1 + (k + i) % 127) for i in range(8)]
    return [message("/drum/note", "s" * 60_000, 100).dgram, bundle(named), bundle(played),
            message("/drum/note/at", 3600.0, "right", 100).dgram]


ROUNDS = [round_of_datagrams(k) for k in range(16)]
"""The rounds sent, made once (making them costs more than sending them)."""


def console_script():
    """The ``drumstroke`` command installed next to this Python."""
    found = shutil.which("drumstroke", path=str(Path(sys.executable).parent)) or shutil.which("drumstroke")
    if found is None:
        raise SystemExit("no drumstroke command: pip install -e .")
    return found


class Child:
    """``drumstroke live`` listening for OSC on a free port of loopback, its setpoints to /dev/null."""

    def __init__(self, log, *options):
        self.process = subprocess.Popen([console_script(), "live", "--osc-in", "127.0.0.1:0", "--csv", "--log",
                                         str(log), *options], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                        text=True)
        self.port = int(self.process.stderr.readline().rsplit(":", 1)[1])  # "listening for OSC notes on HOST:PORT"
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)

    def send(self, rounds, first=0):
        """Send ``rounds`` rounds of datagrams, a millisecond's pause after each (the child reads as they come)."""
        for k in range(first, first + rounds):
            for datagram in ROUNDS[k % len(ROUNDS)]:
                self.socket.sendto(datagram, ("127.0.0.1", self.port))
            time.sleep(0.001)
        return first + rounds

    def rss(self):
        """The child's resident memory (MB)."""
        for line in Path(f"/proc/{self.process.pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
        raise RuntimeError("no VmRSS")

    def stop(self, sig=signal.SIGINT):
        """Signal the child; (seconds to exit, its status, its stderr after the first line)."""
        start = time.monotonic()
        self.process.send_signal(sig)
        err = self.process.stderr.read()
        status = self.process.wait()
        self.socket.close()
        return time.monotonic() - start, status, err


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=300.0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        log = Path(folder) / "flood.json"
        child = Child(log)
        time.sleep(0.5)
        samples, rounds, start = [], 0, time.monotonic()
        while time.monotonic() - start < args.seconds:
            rounds = child.send(200, rounds)
            if not samples or time.monotonic() - start >= 5.0 * len(samples):
                samples.append((round(time.monotonic() - start, 1), rounds, round(child.rss(), 1)))
                print(f"{samples[-1][0]:7.1f} s  {rounds:8d} rounds  {samples[-1][2]:8.1f} MB", file=sys.stderr)
        exit_time, status, err = child.stop()
        record = json.loads(log.read_text())
        results = {
            "drumstroke live flood": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
            "machine": f"{platform.platform()}, python {platform.python_version()}",
            "seconds": args.seconds, "rounds": rounds, "datagrams": 4 * rounds,
            "notes sent": rounds * (75 + 8 + 2), "bytes sent": rounds * sum(map(len, round_of_datagrams(0))),
            "rss_mb": {"first": samples[0][2], "after 10 s": next((s[2] for s in samples if s[0] >= 10), None),
                       "last": samples[-1][2], "largest": max(s[2] for s in samples)},
            "exit_after_sigint_s": round(exit_time, 3), "status": status,
            "record_bytes": log.stat().st_size, "record_notes": len(record["notes"]),
            "record_problems": len(record["problems"]), "problem_count": record["problem_count"],
            "unrecorded": record["unrecorded"], "queue_full": record["queue_full"],
            "stderr_bytes": len(err.encode()), "stderr_lines": len(err.splitlines()), "samples": samples}
    print(json.dumps({k: v for k, v in results.items() if k != "samples"}, indent=1))
    (HERE / "live_flood_results.json").write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
