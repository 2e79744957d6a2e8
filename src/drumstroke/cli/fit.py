"""``drumstroke fit``: a recipe fitted to a recorded stroke (its onsets), analysis by synthesis."""

import math

from .._atomic import Bundle
from ..dynamics import CEILING_DB, FLOOR_DB
from ..errors import located
from ..formats import json, toml
from ..recipe import COR_RANGE
from ..render import plot
from ._common import (
    Bar,
    add_cor,
    add_model,
    add_sound_options,
    print_recording_notes,
    print_written,
    recording_name,
    thumb_range,
)
from ._options import Output, add_mkdir, existing_file, number, whole

LEVELS = ("auto", "peak", "modes")
"""``--levels``' choices: :data:`drumstroke.analysis.fit.LEVELS` (not imported here: scipy.optimize is slow to load)."""


def add_fit(fit):
    """Give ``fit``'s parser ``fit`` its description and options."""
    fit.description = ("Fit, through the inverse design, the start, c (with --fit-cor) and the force profile whose "
                       "impacts match a recorded stroke's onsets (times and relative levels); simulate the recipe and "
                       "print each onset's residuals, the level offset, c and the model. The level offset (and c) are "
                       "those whose force is closest to constant (see docs/fit.md).")
    fit.add_argument("recording", type=existing_file, metavar="RECORDING",
                     help="a recording of one stroke (.wav, .flac) or its onsets (.csv, as `drumstroke onsets` writes)")
    add_model(fit)
    cor = fit.add_mutually_exclusive_group()
    add_cor(cor, hint="; measure it with measure-cor")
    cor.add_argument("--fit-cor", action="store_true", help=f"fit c too, in [{COR_RANGE[0]:g}, {COR_RANGE[1]:g}]")
    fit.add_argument("--level", type=number(low=FLOOR_DB, high=CEILING_DB, unit="dB re 1 m/s"), metavar="DB",
                     help="the loudest onset's level, dB re 1 m/s tip speed, when known (default: fitted)")
    fit.add_argument("--levels", choices=LEVELS, default="auto",
                     help="which of the onsets' levels to play: their broadband peak, the drum's lowest modes, or "
                          "(auto, the default) the one smoother over the bounces; printed")
    edits = fit.add_argument_group("onsets to leave out (the indices printed, from 0)")
    edits.add_argument("--drop", type=whole(low=0), nargs="+", default=[], metavar="I",
                       help="leave these onsets out (or edit the onsets' CSV and fit that)")
    edits.add_argument("--merge", type=whole(low=0), nargs="+", default=[], metavar="I",
                       help="merge onset I with onset I+1 (one impact heard twice): I's time, the louder level")
    edits.add_argument("--drop-suspects", action="store_true",
                       help="fit without the suspects (the onsets off one constant force's trend of bounces, always "
                            "listed): drop extra onsets, merge doubles, play missed or misplaced bounces on the trend; "
                            "the way to fit a recorded drum")
    edits.add_argument("--suspect-ms", type=number(low=0.0, high=50.0, low_open=True, unit="ms"), default=2.0,
                       metavar="MS", help="a bounce further than this from the trend's time is a suspect (default 2)")
    edits.add_argument("--suspect-db", type=number(low=0.0, high=48.0, low_open=True, unit="dB"), default=3.0,
                       metavar="DB", help="a bounce further than this from its levels' trend is a suspect (default 3)")
    fit.add_argument("--out", action=Output, suffixes=toml.SUFFIXES, metavar="RECIPE", required=True,
                     help="write the fitted recipe as .toml (its t = 0 is the release, printed)")
    fit.add_argument("--json", action=Output, suffixes=json.SUFFIXES, metavar="PATH",
                     help="write the fit (onsets, residuals, offset, c, left-out onsets, recipe) as .json")
    fit.add_argument("--plot", action=Output, suffixes=plot.SUFFIXES, metavar="PATH",
                     help=f"draw theta(t) and a(t) with the onsets and the fitted impacts: {', '.join(plot.SUFFIXES)}")
    add_sound_options(fit)
    add_mkdir(fit)
    fit.set_defaults(run=_fit)


def _fit(args):
    from ..analysis import find_recording_onsets, fit_stroke, read_onsets
    from ..analysis.fit import TOLERANCE
    from ..render.outputs import write_stroke_outputs

    csv = args.recording.suffix.lower() == ".csv"
    onsets = read_onsets(args.recording) if csv else find_recording_onsets(args.recording)
    print_recording_notes(onsets)
    with Bar("fitting", delay=0.5) as bar, located(recording_name(args.recording)):
        fitted = fit_stroke(onsets, model=args.model, cor=args.cor, fit_cor=args.fit_cor, offset=args.level,
                            drop=args.drop, merge=args.merge, drop_suspects=args.drop_suspects,
                            suspect_time=args.suspect_ms * 1e-3, suspect_level=args.suspect_db, levels=args.levels,
                            progress=bar.update)
    threshold = "given" if math.isinf(onsets.threshold_db) else f"{onsets.threshold_db:g} dB"
    print(f"fitted {len(onsets)} onsets of {onsets.source} (threshold {threshold}) on the {fitted.model} model: "
          f"c = {fitted.cor:.4f}{' (fitted)' if fitted.fitted_cor else ''}, loudest onset at {fitted.offset:.2f} dB "
          f"re 1 m/s (offset), released at {fitted.release:.6f} s")
    print(f"levels played: the onsets' {fitted.levels} ({fitted.levels_why})")
    human = thumb_range(fitted.design.min_force, fitted.design.max_force)
    print(f"forces {fitted.design.min_force:.4g} to {fitted.design.max_force:.4g} m/s^2, {human}; relative change "
          f"{fitted.change:.4g}; ends {fitted.design.end}")
    print(f"{'#':>4} {'onset (s)':>11} {'onset (dB)':>10} {'dt (ms)':>9} {'dlevel (dB)':>11}")
    reasons, dropped = dict(fitted.unmatched), dict(fitted.dropped)
    for i, (t, level) in enumerate(zip(onsets.t, onsets.level_db)):
        if i in dropped:
            print(f"{i:>4} {t:>11.6f} {level:>10.2f}  dropped: {dropped[i]}")
        elif i in reasons:
            print(f"{i:>4} {t:>11.6f} {level:>10.2f}  not played: {reasons[i]}")
        else:
            print(f"{i:>4} {t:>11.6f} {level:>10.2f} {fitted.time_residual[i] * 1e3:>9.4f} "
                  f"{fitted.level_residual[i]:>11.4f}")
    for t, level in zip(fitted.filled_t, fitted.filled_level):
        print(f"   = {t:>11.6f} {level:>10.2f}  a bounce played on the trend, where an onset was missed or misplaced")
    for t, level in zip(fitted.extra_t, fitted.extra_level):
        print(f"   + {t:>11.6f} {level:>10.2f}  an impact the recording does not have (above its threshold)")
    _print_suspects(fitted.suspects, acted=args.drop_suspects)
    verdict = "within" if fitted.within else "NOT within"
    dropped = f"{len(fitted.dropped)} dropped, " if fitted.dropped else ""
    print(f"largest residuals {fitted.time_error * 1e3:.4g} ms, {fitted.level_error:.4g} dB; {len(fitted.unmatched)} "
          f"onsets not played, {dropped}{len(fitted.extra_t)} impacts added: {verdict} {TOLERANCE[0] * 1e3:g} ms and "
          f"{TOLERANCE[1]:g} dB")
    written = []
    with Bundle() as bundle:
        fitted.recipe.to_toml(args.out, bundle=bundle)
        written.append(args.out)
        if args.json:
            json.write_json(args.json, fitted.to_dict(), bundle=bundle)
            written.append(args.json)
        if args.plot:
            plot.save_figure(plot.fit_figure(fitted), args.plot, bundle=bundle)
            written.append(args.plot)
        written += write_stroke_outputs(fitted.stroke, audio=args.audio, midi=args.midi, snares=not args.no_snares,
                                        bundle=bundle)
    print_written(written)


def _print_suspects(suspects, *, acted):
    """The onsets one constant force's trend doubts, or that make the thumb press beyond the human, and whether the
    fit acted on them."""
    if not suspects:
        return
    done = "acted on (--drop-suspects)" if acted else "kept: --drop-suspects fits without them"
    print(f"{len(suspects)} suspect onsets (against the trend of one constant force's bounces, or making the thumb "
          f"press beyond the human), {done}:")
    for suspect in suspects:
        into = f" into {suspect.into}" if suspect.into >= 0 else ""
        print(f"  {suspect.onset:>4} {suspect.action}{into}: {suspect.reason}")
