"""``drumstroke compare``: two strokes side by side (recordings, onsets CSVs or recipes)."""

from .._atomic import Bundle
from ..analysis.compare import FLOOR_DB, WINDOW
from ..formats import json
from ..render import plot
from ._common import print_recording_notes, print_written
from ._options import Output, add_mkdir, existing_file, number


def add_compare(com):
    """Give ``compare``'s parser ``com`` its description and options."""
    com.description = ("Compare stroke B with stroke A, each a recording (.wav, .flac, .ogg: its impacts detected), an "
                       "onsets CSV or a recipe (.toml: simulated), aligned at their first onsets: how many onsets, "
                       "their bounces paired by time (a maximum one-to-one matching within --window) with the "
                       "unmatched ones of each, the times, intervals and levels pair by pair, the level envelope "
                       "and the bounce rate over time.")
    com.add_argument("a", type=existing_file, metavar="A", help="the first stroke (the reference, e.g. a human's)")
    com.add_argument("b", type=existing_file, metavar="B", help="the second stroke (differences are B - A)")
    com.add_argument("--threshold", type=number(low=-200.0, high=0.0, unit="dB"), default=FLOOR_DB, metavar="DB",
                     help=f"count onsets at or above this level, dB re each stroke's loudest, in [-200, 0] (default "
                          f"{FLOOR_DB:g}; a recording's detection threshold raises it for both)")
    com.add_argument("--window", type=number(low=0.0, high=1000.0, low_open=True, unit="ms"), default=WINDOW * 1e3,
                     metavar="MS", help=f"pair two onsets (times from each stroke's first) at most this far apart, ms "
                                        f"in (0, 1000] (default {WINDOW * 1e3:g})")
    com.add_argument("--json", action=Output, suffixes=json.SUFFIXES, metavar="PATH",
                     help="write the figures, the pairs (index in A, index in B) and both strokes' onsets as .json")
    com.add_argument("--plot", action=Output, suffixes=plot.SUFFIXES, metavar="PATH",
                     help=f"draw the onsets, the bounce rate and the interval differences: {', '.join(plot.SUFFIXES)}")
    add_mkdir(com)
    com.set_defaults(run=_compare)


def _compare(args):
    from ..analysis.compare import compare, stroke_onsets

    a, b = stroke_onsets(args.a), stroke_onsets(args.b)
    print_recording_notes(a)
    print_recording_notes(b)
    result = compare(a, b, threshold_db=args.threshold, window=args.window * 1e-3)
    figures = result.summary()
    for name, onsets in (("A", a), ("B", b)):
        made = f", simulated on the {onsets.info['model']} model" if "model" in onsets.info else ""
        print(f"{name}: {onsets.source}{made}")
    print(f"onsets above {result.threshold_db:g} dB re each one's loudest: A {figures['count_a']}, B "
          f"{figures['count_b']} ({figures['count_difference']:+d})")
    print(f"first to last onset: A {figures['duration_a_s']:.4f} s, B {figures['duration_b_s']:.4f} s "
          f"({figures['duration_difference_s'] * 1e3:+.1f} ms)")
    print(f"paired within {result.window * 1e3:g} ms: {figures['pairs']}; unmatched: "
          f"A {_unmatched(result.a, result.unmatched_a)}, B {_unmatched(result.b, result.unmatched_b)}")
    if figures["pairs"]:
        print(f"pair by pair over {figures['pairs']}: times differ by {figures['time_difference_median_s'] * 1e3:.2f} "
              f"ms (median), {figures['time_difference_max_s'] * 1e3:.2f} ms (largest); levels by "
              f"{figures['level_difference_median_db']:.2f} dB (median), {figures['level_difference_max_db']:.2f} dB "
              f"(largest)")
    if figures["intervals_compared"]:
        print(f"over the {figures['intervals_compared']} intervals between successive pairs: intervals differ by "
              f"{figures['interval_difference_median_s'] * 1e3:.2f} ms (median), "
              f"{figures['interval_difference_max_s'] * 1e3:.2f} ms (largest)")
    if len(result.envelope_t):
        print(f"over time: level envelopes differ by {figures['envelope_difference_rms_db']:.2f} dB rms, bounce rates "
              f"by {figures['rate_difference_rms_hz']:.2f} Hz rms")
    else:
        print("too few onsets to compare envelopes and bounce rates (each stroke needs two)")
    written = []
    with Bundle() as bundle:
        if args.json:
            json.write_json(args.json, {"comparison": figures, "pairs": result.pairs.tolist(),
                                        "a": _onsets_dict(result.a), "b": _onsets_dict(result.b)}, bundle=bundle)
            written.append(args.json)
        if args.plot:
            plot.save_figure(plot.comparison_figure(result), args.plot, bundle=bundle)
            written.append(args.plot)
    print_written(written)


def _unmatched(onsets, indices):
    """The unmatched onsets of one stroke, each as #index at its time (s from the first) and level (dB)."""
    if not len(indices):
        return "none"
    return f"{len(indices)} (" + ", ".join(f"#{i} at {onsets.t[i]:.4f} s, {onsets.level_db[i]:.1f} dB"
                                         for i in indices) + ")"


def _onsets_dict(onsets):
    return {"source": onsets.source, "t_s": onsets.t.tolist(), "level_db": onsets.level_db.tolist()}
