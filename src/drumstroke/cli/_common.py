"""What the command modules share: the parser class, the progress bar, sound options and printers."""

import argparse
import math
import sys
import time
from pathlib import Path

from ..model import inertia_ratio
from ..score import BOUNCE_NOTE, FIRST_IMPACT_NOTE


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit status 2, without the usage text."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


class Bar:
    """A progress bar on stderr, drawn only on a terminal and only after ``delay`` seconds."""

    def __init__(self, label, *, delay=0.0):
        self.label = label
        self.start = time.monotonic()
        self.delay = delay
        self.drawn = False
        self.enabled = sys.stderr.isatty()

    def update(self, fraction):
        if not self.enabled or time.monotonic() - self.start < self.delay:
            return
        filled = math.floor(30 * min(max(fraction, 0.0), 1.0))
        sys.stderr.write(f"\r{self.label} [{'#' * filled}{'.' * (30 - filled)}] {100 * fraction:5.1f}%")
        sys.stderr.flush()
        self.drawn = True

    def close(self):
        if self.drawn:
            sys.stderr.write("\n")
            sys.stderr.flush()


def add_sound_options(parser):
    """--wav, --no-snares and --midi, for the commands that write a stroke's or a composition's sound."""
    parser.add_argument("--wav", type=Path, metavar="PATH", help="write 48 kHz mono audio of the impacts")
    parser.add_argument("--no-snares", action="store_true", help="render --wav with the snare wires off")
    parser.add_argument("--midi", type=Path, metavar="PATH",
                        help=f"write the impacts as General MIDI percussion (channel 10: a stroke's first impact on "
                             f"key {FIRST_IMPACT_NOTE}, its bounces on {BOUNCE_NOTE})")


def print_written(paths):
    for path in paths:
        print(f"wrote {path}")


def print_summary(stroke, *, rows=10):
    """The stroke's recipe on one line, then its impacts: the first ``rows`` as a table."""
    recipe = stroke.recipe
    d = inertia_ratio(recipe.model, recipe.stick)
    print(
        f"stroke {recipe.name or 'custom'}: model {recipe.model} (D = {d:.4f} m^2), "
        f"theta_max = {recipe.theta_max:.4f} rad, c = {recipe.cor:g}, {recipe.t_end:g} s"
    )
    impacts = stroke.impacts
    rest = f"at rest from {stroke.rest_time:.6f} s" if stroke.rest_time is not None else "still moving at the end"
    print(f"{len(impacts)} impacts; {rest}")
    if len(impacts):
        print(f"{'#':>5} {'t (s)':>11} {'omega (rad/s)':>14} {'tip (m/s)':>10} {'level (dB)':>10}")
        for i in range(min(rows, len(impacts))):
            print(
                f"{i + 1:>5} {impacts.t[i]:>11.6f} {impacts.omega[i]:>14.6f} "
                f"{impacts.tip_speed[i]:>10.6f} {impacts.level_db[i]:>10.2f}"
            )
        if len(impacts) > rows:
            print(f"{'...':>5} ({len(impacts) - rows} more; level re 1 m/s tip speed)")
