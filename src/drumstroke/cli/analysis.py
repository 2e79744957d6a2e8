"""``drumstroke onsets`` and ``measure-cor``: a recording's impacts, and c from a drop."""

import sys
from dataclasses import replace

from .._atomic import Bundle
from ..errors import ParameterError, located
from ..formats import json, onsets_csv
from ..render import plot
from ._common import add_model, print_recording_notes, print_written, recording_name
from ._options import Output, add_mkdir, existing_file, number


def add_onsets(ons):
    """Give ``onsets``'s parser ``ons`` its description and options."""
    from ..analysis.drums import DRUMS

    ons.description = ("Find the impacts in a recording (WAV, FLAC, OGG, ...; several channels are mixed down): their "
                       "times to a fraction of a millisecond, their levels in dB re the loudest (the drum's lowest "
                       "modes: in proportion to the stick's speed) and their peaks in dB re the loudest peak (each "
                       "note's loudest sample, the earlier notes' sound taken off). The ringing of the drum and the "
                       "room is predicted away (a linear predictor) and each attack placed on its change point. Prints "
                       "them and the threshold used; writes them as an onsets CSV (t,level_db,peak_db, its metadata "
                       "in the JSON beside it).")
    ons.add_argument("recording", type=existing_file, metavar="RECORDING", help="an audio file")
    _add_detection(ons)
    ons.add_argument("--drum", choices=("all", *DRUMS), default="all",
                     help="keep only the onsets whose attack is this drum's (its band's energy the loudest over "
                          "the first 30 ms; levels then re the loudest kept), e.g. a groove's snare (default all)")
    ons.add_argument("--out", action=Output, suffixes=onsets_csv.SUFFIXES, metavar="ONSETS",
                     help="write the onsets as .csv (t in s, level_db in dB re the loudest, peak_db in dB re the "
                          "loudest peak), the JSON beside it")
    ons.add_argument("--plot", action=Output, suffixes=plot.SUFFIXES, metavar="PATH",
                     help=f"draw the waveform with the onsets over their levels: {', '.join(plot.SUFFIXES)}")
    add_mkdir(ons)
    ons.set_defaults(run=_onsets)


def add_measure_cor(cor):
    """Give ``measure-cor``'s parser ``cor`` its description and options."""
    cor.description = ("c from a stick dropped on the head (the paper's method): the flights between successive "
                       "impacts fitted by the model's exact flights under gravity, T_n = F(c^(n-1) w1), with a "
                       "confidence interval; the impacts chosen among the onsets by the model over all of them "
                       "(extra onsets passed over, missed bounces allowed for); the impacts' levels (falling "
                       "20 log10 c dB an impact) as a cross-check, with a warning when the two disagree.")
    cor.add_argument("drop", type=existing_file, metavar="DROP",
                     help="a recording of the drop (WAV, FLAC, OGG, ...) or its onsets CSV")
    add_model(cor, what="whose exact flights")
    cor.add_argument("--tolerance", type=number(low=0.0, high=0.1, low_open=True), default=5e-3, metavar="S",
                     help="how far an onset may be from the model's impact and still be it, in s (default 0.005)")
    cor.add_argument("--confidence", type=number(low=0.0, high=1.0, low_open=True, high_open=True), default=0.95,
                     help="of the intervals, in (0, 1) (default 0.95)")
    _add_detection(cor)
    cor.add_argument("--json", action=Output, suffixes=json.SUFFIXES, metavar="OUT",
                     help="write c, its interval, the cross-check, the impacts used and the residuals as .json")
    add_mkdir(cor)
    cor.set_defaults(run=_measure_cor)


def _add_detection(parser):
    from ..analysis.onsets import OnsetConfig

    default = OnsetConfig()
    parser.add_argument("--threshold", type=number(low=-120.0, high=0.0, unit="dB"), default=default.threshold_db,
                        metavar="DB", help=f"report no onset quieter than this, dB re the loudest, in [-120, 0] "
                                           f"(default {default.threshold_db:g}; the noise floor may raise it)")
    parser.add_argument("--min-interval", type=number(low=0.5e-3, high=1.0, unit="s"), default=default.min_interval,
                        metavar="S", help=f"the shortest time between two onsets, s, in [0.0005, 1] "
                                          f"(default {default.min_interval:g})")


def _read(args, path):
    from ..analysis.onsets import OnsetConfig, find_onsets, read_onsets, read_recording

    if path.suffix.lower() == ".csv":
        onsets, sound = read_onsets(path), None
    else:
        signal, rate, notes = read_recording(path)
        config = OnsetConfig(threshold_db=args.threshold, min_interval=args.min_interval)
        onsets = find_onsets(signal, rate, config=config, source=path.name, notes=notes)
        sound = signal, rate
    print_recording_notes(onsets)  # an onsets CSV keeps its recording's notes in its metadata
    return onsets, sound


def _onsets(args):
    from ..analysis.onsets import write_onsets

    if args.recording.suffix.lower() == ".csv":
        raise ParameterError(f"RECORDING must be an audio file (WAV, FLAC, OGG, ...), got the CSV {str(args.recording)!r}")
    onsets, (signal, rate) = _read(args, args.recording)
    if args.drum != "all":
        from ..analysis.drums import keep_drum

        every = len(onsets)
        onsets = keep_drum(signal, rate, onsets, args.drum)
        print(f"kept the {len(onsets)} of {every} onsets whose attack is the {args.drum}'s")
    onsets = replace(onsets, info={**onsets.info, "drum": args.drum})  # the JSON says which drum was kept
    floor = onsets.info.get("floor_db")
    floor_text = "none measured (no noise)" if floor is None else f"{floor:.1f} dB re the loudest"
    print(f"{args.recording.name}: {len(signal) / rate:.6g} s at {rate} Hz; noise floor {floor_text}; threshold "
          f"{onsets.threshold_db:.1f} dB re the loudest")
    if not len(onsets):
        print(onsets.info.get("found", "no impacts found"))
    else:
        print(f"{len(onsets)} onsets:")
        print(f"{'#':>4} {'t (s)':>11} {'level (dB)':>11} {'peak (dB)':>10}")
        for i, (t, level, peak) in enumerate(zip(onsets.t, onsets.level_db, onsets.peak_db)):
            print(f"{i:>4} {t:>11.6f} {level:>11.2f} {peak:>10.2f}")
    written = []
    with Bundle() as bundle:
        if args.out:
            write_onsets(args.out, onsets, bundle=bundle)
            written += [args.out, args.out.with_suffix(".json")]
        if args.plot:
            plot.save_figure(plot.onsets_figure(signal, rate, onsets.t, onsets.level_db,
                                                threshold_db=onsets.threshold_db, title=args.recording.name),
                             args.plot, bundle=bundle)
            written.append(args.plot)
    print_written(written)


def _measure_cor(args):
    from ..analysis.drop import measure_cor

    where = recording_name(args.drop)
    onsets, _ = _read(args, args.drop)
    if not len(onsets):
        raise ParameterError(f"no impacts found in {where}: {onsets.info.get('found', 'none')}")
    with located(where):
        drop = measure_cor(onsets, model=args.model, confidence=args.confidence, tolerance=args.tolerance)
    low, high = drop.interval
    print(f"c = {drop.cor:.4f} ({drop.confidence:.0%} interval {low:.4f} to {high:.4f}) from {drop.flights} flights "
          f"({drop.flights + 1} impacts, {drop.times[0]:.4f} to {drop.times[-1]:.4f} s) on the {drop.model} model's "
          "exact flights under gravity")
    if drop.cor_levels == drop.cor_levels:  # not NaN
        lo, hi = drop.levels_interval
        print(f"levels cross-check: c = {drop.cor_levels:.3f} ({lo:.3f} to {hi:.3f}) from the impacts' levels "
              f"(dB re the loudest; a drum's brightness and the microphone colour them)")
    else:
        print("levels cross-check: none (the levels do not fall from impact to impact)")
    print(f"largest flight residual {abs(drop.residuals).max() * 1e3:.3f} ms; first launch speed "
          f"{drop.launch_speed:.4g} rad/s")
    print(f"impacts used: onsets {_listed(drop.used)}")
    if len(drop.extra):
        print(f"extra onsets passed over (doubled triggers, ghosts, ringing): {_listed(drop.extra)} at "
              f"{_listed(onsets.t[drop.extra], '{:.4f}')} s")
    if len(drop.missed):
        print(f"missed bounces (no onset near the model's impact): {len(drop.missed)}, at "
              f"{_listed(drop.missed, '{:.4f}')} s")
    if drop.warning:
        print(f"warning: {drop.warning}", file=sys.stderr)
    if args.json:
        json.write_json(args.json, {**drop.to_dict(), "threshold_db": onsets.threshold_db})
        print_written([args.json])


def _listed(values, form="{}"):
    """``values`` comma-separated, each in ``form``."""
    return ", ".join(form.format(value) for value in values)
