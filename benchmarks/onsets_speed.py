"""The onset detector's time against librosa's, in one process: ``python benchmarks/onsets_speed.py``.

Recordings (48 kHz, 5 s): benchmarks/analysis.py's (the paper's free bounce with snares at 30 dB SNR,
as samples: no file read) and four of tests/_recorded_drums.py's corpus (FluidR3 snare 38 drop with
FluidSynth's reverb, FluidR3 40 roll at -72 dBFS noise, TimGM6mb 38 flams dry, TimGM6mb 40 singles at
-60 dBFS noise). Each is timed ``find_onsets(signal, 48000)`` against
``librosa.onset.onset_detect(y=signal as float32, sr=48000, backtrack=True)``, the two calls in turn,
15 times each after a warm-up: the median and the best of each (on a shared host the best is the time
undisturbed), and their ratios, ours over librosa's. Prints the table and writes it with the machine and
date to benchmarks/onsets_speed_results.json.
"""

import json
import statistics
import sys
import time
from pathlib import Path

import librosa
import numpy as np
from _timing import machine

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
from _recorded_drums import RATE, recordings
from _recordings import render
from drumstroke.analysis import find_onsets
from drumstroke.stroke import simulate

REPEATS = 15
CORPUS = [("FluidR3", 38, "drop", "reverb"), ("FluidR3", 40, "roll", "noise72"), ("TimGM6mb", 38, "flams", "dry"),
          ("TimGM6mb", 40, "singles", "noise60")]


def cases():
    stroke = simulate("free-bounce", t_end=5.0)
    signal, _ = render(stroke.impacts.t, stroke.impacts.tip_speed, snares=True, snr=30, tail=5.0 - stroke.impacts.t[-1])
    yield "free bounce, snares, SNR 30 dB (benchmarks/analysis.py)", signal
    for font, key, set_name, condition in CORPUS:
        for recording in recordings(fonts=(font,), keys=(key,), sets=(set_name,), conditions=(condition,)):
            yield recording.name, recording.signal


def timed(signal):
    ours, theirs = [], []
    find_onsets(signal, RATE)
    librosa.onset.onset_detect(y=signal.astype(np.float32), sr=RATE, backtrack=True)
    for _ in range(REPEATS):
        start = time.perf_counter()
        find_onsets(signal, RATE)
        ours.append(time.perf_counter() - start)
        start = time.perf_counter()
        librosa.onset.onset_detect(y=signal.astype(np.float32), sr=RATE, backtrack=True)
        theirs.append(time.perf_counter() - start)
    return ours, theirs


def main():
    rows = []
    print("| recording | ours (ms) | librosa (ms) | ratio | best: ours (ms) | librosa (ms) | ratio |\n"
          "|---|---:|---:|---:|---:|---:|---:|")
    for name, signal in cases():
        ours, theirs = timed(signal)
        median, median_theirs, best, best_theirs = (statistics.median(ours), statistics.median(theirs), min(ours),
                                                    min(theirs))
        rows.append({"recording": name, "ours": median, "librosa": median_theirs, "ratio": median / median_theirs,
                     "ours_best": best, "librosa_best": best_theirs, "ratio_best": best / best_theirs})
        print(f"| {name} | {median * 1e3:.1f} | {median_theirs * 1e3:.1f} | {median / median_theirs:.2f} | "
              f"{best * 1e3:.1f} | {best_theirs * 1e3:.1f} | {best / best_theirs:.2f} |")
    (HERE / "onsets_speed_results.json").write_text(json.dumps({"machine": machine(), "repeats": REPEATS, "rows": rows},
                                                               indent=1) + "\n")


if __name__ == "__main__":
    main()
