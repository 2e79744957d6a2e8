"""Onsets on recorded drums, against librosa's: ``python benchmarks/recorded_onsets.py [--quick]``.

The corpus is tests/_recorded_drums.py's (FluidR3 and TimGM6mb snares 38 and 40 through FluidSynth,
48 kHz, 5-s recordings; sets singles, drop, roll, flams; conditions dry, -72 and -60 dBFS noise,
FluidSynth's reverb), its truth each note's first sample above -40 dB of its own peak when rendered
alone. Per SoundFont × set × condition (both keys pooled): the notes within 30 dB of the recording's
loudest found within 1 ms and within 5 ms, and the precision within 5 ms (detections matched one to one
with a note, mir_eval's matching), for drumstroke's ``find_onsets`` and for
``librosa.onset.onset_detect(backtrack=True)`` (its default 512-sample hops) side by side; the level
error of drumstroke's onsets on the loud notes found within 5 ms, of both measures: ``level_db`` (the lowest
modes' amplitude, dB re the loudest onset) and ``peak_db`` (the broadband peak, the earlier notes' sound taken
off, dB re the loudest onset's), each less the truth (the note's own peak alone, dB re the loudest's); and the
median time of each detector per recording, in the same process.

Prints the table and writes it with the machine and date to benchmarks/recorded_onsets_results.json
(``--quick``: one seed's first recording of each font × set × condition only, not written).
"""

import json
import sys
import time
from collections import defaultdict
from pathlib import Path

import librosa
import numpy as np
from _timing import machine, progress

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
from _recorded_drums import CONDITIONS, FONTS, KEYS, LOUD_DB, RATE, SETS, match, recordings, score  # noqa: E402

from drumstroke.analysis import find_onsets  # noqa: E402


def librosa_onsets(signal):
    return librosa.onset.onset_detect(y=signal.astype(np.float32), sr=RATE, backtrack=True, units="time")


def level_errors(recording, onsets, measure="level_db"):
    """Our ``measure`` (dB re the loudest onset's) less the truth's, on the loud notes found within 5 ms."""
    loud = recording.level_db >= -LOUD_DB
    ours = getattr(onsets, measure)
    return [float(ours[j] - recording.level_db[i]) for i, j in match(recording.t, onsets.t, 5e-3) if loud[i]]


def run(keys=KEYS):
    totals = defaultdict(lambda: defaultdict(int))
    errors, peak_errors, times = defaultdict(list), defaultdict(list), {"ours": [], "librosa": []}
    for recording in recordings(keys=keys):
        progress(recording.name)
        start = time.perf_counter()
        ours = find_onsets(recording.signal, RATE)
        times["ours"].append(time.perf_counter() - start)
        start = time.perf_counter()
        theirs = librosa_onsets(recording.signal)
        times["librosa"].append(time.perf_counter() - start)
        row = (recording.font, recording.set, recording.condition)
        for who, found in (("ours", ours.t), ("librosa", theirs)):
            for name, value in score(recording, found).items():
                totals[row + (who,)][name] += value
        errors[row] += level_errors(recording, ours)
        peak_errors[row] += level_errors(recording, ours, "peak_db")
    return totals, errors, peak_errors, times


def figures(total):
    loud, found = max(total["loud"], 1), max(total["found"], 1)
    return {"loud": total["loud"], "within_1ms": total["within_1ms"] / loud, "within_5ms": total["within_5ms"] / loud,
            "precision_5ms": total["correct_5ms"] / found, "found": total["found"]}


def _quantile_95(errors):
    """The 95th percentile of the errors' magnitudes (dB), NaN for none."""
    return float(np.quantile(np.abs(errors), 0.95)) if len(errors) else float("nan")


def main():
    quick = "--quick" in sys.argv
    totals, errors, peak_errors, times = run(keys=KEYS[:1] if quick else KEYS)
    rows = []
    print("| font | set | condition | loud | ours 1 ms | ours 5 ms | ours precision | level_db error 95 % (dB) "
          "| peak_db error 95 % (dB) | librosa 1 ms | librosa 5 ms | librosa precision |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for font in FONTS:
        for set_name in SETS:
            for condition in CONDITIONS:
                row = (font, set_name, condition)
                ours, theirs = figures(totals[row + ("ours",)]), figures(totals[row + ("librosa",)])
                worst, peak_worst = _quantile_95(errors[row]), _quantile_95(peak_errors[row])
                rows.append({"font": font, "set": set_name, "condition": condition, "ours": ours, "librosa": theirs,
                             "level_error_95_db": worst, "peak_error_95_db": peak_worst})
                print(f"| {font} | {set_name} | {condition} | {ours['loud']} | {ours['within_1ms']:.3f} | "
                      f"{ours['within_5ms']:.3f} | {ours['precision_5ms']:.3f} | {worst:.2f} | {peak_worst:.2f} | "
                      f"{theirs['within_1ms']:.3f} | {theirs['within_5ms']:.3f} | {theirs['precision_5ms']:.3f} |")
    timing = {who: float(np.median(t)) for who, t in times.items()}
    print(f"\nmedian time a 5-s recording: ours {timing['ours'] * 1e3:.1f} ms, librosa {timing['librosa'] * 1e3:.1f} ms "
          f"(ratio {timing['ours'] / timing['librosa']:.2f})")
    if not quick:
        (HERE / "recorded_onsets_results.json").write_text(json.dumps(
            {"machine": machine(), "rows": rows, "median_seconds": timing}, indent=1) + "\n")


if __name__ == "__main__":
    main()
