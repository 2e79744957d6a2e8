"""What the command modules share: the parser class, the progress bar, sound options and printers."""

import sys
from pathlib import Path

from ..formats import midi, wav
from ..model import MODELS, inertia_ratio
from ..recipe import DEFAULT_COR
from ..render.page import plural
from ..score import BOUNCE_NOTE, FIRST_IMPACT_NOTE
from ._options import Output, number
from ._parser import OPTIONS, Parser, named_option  # noqa: F401 (the commands' modules take them from here)


class Bar:
    """A progress bar (tqdm) on stderr, drawn only on a terminal and only after ``delay`` seconds.

    ``update(fraction)`` moves it to ``fraction`` done, in [0, 1]; ``close()`` clears it, so what
    the command prints next starts on a clean line. Also a context manager that closes it.
    """

    def __init__(self, label, *, delay=0.0):
        self._bar = None
        if sys.stderr.isatty():  # off a terminal nothing is drawn, and tqdm is not imported (a piped command starts sooner)
            from tqdm import tqdm

            self._bar = tqdm(total=1.0, desc=label, delay=delay, file=sys.stderr, leave=False,
                             bar_format="{desc}: {percentage:3.0f}%|{bar}| {elapsed}<{remaining}")

    def update(self, fraction):
        if self._bar is not None:
            self._bar.update(min(max(fraction, 0.0), 1.0) - self._bar.n)

    def close(self):
        if self._bar is not None:
            self._bar.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def add_cor(parser, *, default=DEFAULT_COR, hint=""):
    """Add ``--cor C`` to ``parser`` (or a group of it): the coefficient of restitution, in [0, 1).

    ``default`` None leaves the option unset when not given (the library then uses
    :data:`~drumstroke.recipe.DEFAULT_COR`); ``hint`` ends its help.
    """
    return parser.add_argument("--cor", type=number(low=0.0, high=1.0, high_open=True), default=default,
                               metavar="C", help=f"coefficient of restitution, in [0, 1) (default {DEFAULT_COR:g}{hint})")


def add_model(parser, *, default="paper", what="the model"):
    """Add ``--model {paper,geometry}`` to ``parser``: ``what`` the command does with it, default paper.

    ``default`` None leaves it unset when not given (a command that refuses it in some uses).
    """
    return parser.add_argument("--model", choices=MODELS, default=default, help=f"{what} (default paper)")


def print_recording_notes(onsets):
    """On stderr, what reading a recording noted in its onsets' ``info``: channels mixed down, clipped samples."""
    info = onsets.info
    if info.get("mixed_down"):
        print(f"note: {onsets.source} has {info['channels']} channels, mixed down to one", file=sys.stderr)
    if info.get("clipped"):
        print(f"warning: {onsets.source} has {info['clipped']} clipped samples (|x| >= 0.999 full scale): the loudest "
              "levels read low", file=sys.stderr)


def recording_name(path):
    """A recording or an onsets CSV as errors name it: its kind and its path as the user gave it."""
    return f"{'onsets file' if Path(path).suffix.lower() == '.csv' else 'recording'} {str(path)!r}"


def add_sound_options(parser):
    """--audio (alias --wav), --no-snares and --midi, for the commands that write a stroke's or a composition's sound."""
    parser.add_argument("--audio", "--wav", action=Output, suffixes=tuple(wav.FORMATS), metavar="PATH",
                        help="write 48 kHz mono audio of the impacts on a synthesized snare drum; the format follows "
                             f"the extension: {', '.join(wav.FORMATS)}")
    parser.add_argument("--no-snares", action="store_true", help="render --audio with the snare wires off")
    parser.add_argument("--midi", action=Output, suffixes=midi.SUFFIXES, metavar="PATH",
                        help=f"write the impacts as General MIDI percussion (channel 10: a stroke's first impact on "
                             f"key {FIRST_IMPACT_NOTE}, its bounces on {BOUNCE_NOTE}), .mid or .midi")


def thumb_range(min_force, max_force):
    """How a design's forces (m/s²) stand against the human thumb's 0–HUMAN_FORCE: within, pulling, pressing beyond."""
    from ..design import HUMAN_FORCE

    human = f"the human thumb (0-{HUMAN_FORCE:g} m/s^2)"
    beyond = [f"pulls the stick down to {min_force:.4g} m/s^2"] if min_force < 0.0 else []
    beyond += [f"presses up to {max_force:.4g} m/s^2"] if max_force > HUMAN_FORCE else []
    return f"within {human}" if not beyond else f"beyond {human}: it {' and '.join(beyond)}"


def print_written(paths):
    """``wrote PATH`` for each file; the JSON beside a CSV of the same run says it holds that CSV's metadata."""
    described = {Path(p).with_suffix(".json"): Path(p) for p in paths if Path(p).suffix == ".csv"}
    for path in paths:
        csv = described.get(Path(path))
        print(f"wrote {path}" + (f" (with the metadata of {csv.name})" if csv else ""))


def print_summary(stroke, *, rows=10):
    """What a stroke is on one line (its recipe, the transforms after it), then its impacts: the first ``rows``.

    ``stroke`` is a Stroke or a one-stick Trajectory: the table is of the stroke given, transformed or not.
    """
    recipe = stroke.recipe
    line = f"stroke {stroke.name or 'custom'}: model {stroke.model}"
    if recipe is not None:
        d = inertia_ratio(recipe.model, recipe.stick)
        line += f" (D = {d:.4f} m^2), theta_max = {recipe.theta_max:.4f} rad, c = {recipe.cor:g}"
    history = getattr(stroke, "history", ())[1:]
    print(f"{line}, {stroke.t_end:g} s" + (f"; after {', '.join(history)}" if history else ""))
    impacts = stroke.impacts
    rest = f"at rest from {stroke.rest_time:.6f} s" if stroke.rest_time is not None else "still moving at the end"
    print(f"{plural(len(impacts), 'impact')}; {rest}")
    if len(impacts):
        print(f"{'#':>5} {'t (s)':>11} {'omega (rad/s)':>14} {'tip (m/s)':>10} {'level (dB)':>10}")
        for i in range(min(rows, len(impacts))):
            print(
                f"{i + 1:>5} {impacts.t[i]:>11.6f} {impacts.omega[i]:>14.6f} "
                f"{impacts.tip_speed[i]:>10.6f} {impacts.level_db[i]:>10.2f}"
            )
        if len(impacts) > rows:
            print(f"{'...':>5} ({len(impacts) - rows} more; level re 1 m/s tip speed)")


def robot_config(path):
    """The robot config of ``--config`` (a TOML file), or the default one."""
    from ..robot.config import RobotConfig

    return RobotConfig.from_toml(path) if path else RobotConfig()
