"""Time the analysis of recordings, in one process: ``python benchmarks/analysis.py``.

Cases (48 kHz; the median of 7 runs after a warm-up):

- onsets of a 5-s recording: the paper's free bounce (gravity only, c = 0.86; 98 impacts, 23 louder
  than −30 dB) rendered by ``render.audio`` with the snare wires on, white noise at 30 dB SNR, a
  WAV file: ``find_recording_onsets`` (reading the file included) against librosa's own onset detector as a
  user would call it (``librosa.onset.onset_detect`` with ``backtrack=True``, its default 512-sample
  hops), both scored against the struck times: the impacts louder than −30 dB found within 1 ms.
- c from that drop: ``measure_cor`` on the onsets, and ``drumstroke measure-cor``'s work
  (reading, onsets, c) from the WAV.

Prints a table and writes it with the machine and date to benchmarks/analysis_results.json.
"""

import datetime
import json
import platform
import sys
import tempfile
from pathlib import Path

import librosa
import numpy as np
import scipy
import soundfile
from _timing import median_time

import drumstroke
from drumstroke.analysis import find_recording_onsets, measure_cor
from drumstroke.robot.metrics import match_onsets
from drumstroke.stroke import simulate

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
from _recordings import RATE, render

REPEATS = 7



def scored(found, truth, level):
    loud = level >= -30.0
    pairs = match_onsets(truth[loud], np.asarray(found), window=1e-3)
    errors = np.abs(np.asarray(found)[pairs[pairs >= 0]] - truth[loud][pairs >= 0])
    return {"found": int(np.count_nonzero(pairs >= 0)), "of": int(loud.sum()),
            "median_error_ms": float(np.median(errors) * 1e3) if len(errors) else None}


def main():
    stroke = simulate("free-bounce", t_end=5.0)
    times, speeds = stroke.impacts.t, stroke.impacts.tip_speed
    level = 20.0 * np.log10(np.maximum(speeds, 1e-300) / speeds.max())
    signal, truth = render(times, speeds, snares=True, snr=30, tail=5.0 - times[-1])
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "free-bounce.wav"
        soundfile.write(str(path), signal, RATE, subtype="PCM_24")
        ours = median_time(lambda: find_recording_onsets(path))
        onsets = find_recording_onsets(path)

        def reference():
            y, sr = librosa.load(str(path), sr=None)
            return librosa.onset.onset_detect(y=y, sr=sr, units="time", backtrack=True)

        theirs = median_time(reference)
        found_theirs = reference()
        drop_time = median_time(lambda: measure_cor(onsets))
        drop = measure_cor(onsets)
        whole = median_time(lambda: measure_cor(find_recording_onsets(path)))
    rows = [
        {"case": "onsets of a 5-s recording (48 kHz WAV, snares, SNR 30 dB)", "ours": ours, "reference": theirs,
         "ratio": theirs / ours, "ours_scored": scored(onsets.t, truth, level),
         "reference_scored": scored(found_theirs, truth, level), "onsets": len(onsets)},
        {"case": "c from the drop's onsets (measure_cor)", "ours": drop_time, "reference": None, "ratio": None,
         "cor": drop.cor, "interval": list(drop.interval), "flights": drop.flights, "true_cor": 0.86},
        {"case": "c from the drop's WAV (read, onsets, c)", "ours": whole, "reference": None, "ratio": None},
    ]
    print(f"{'case':<62}{'ours':>10}{'reference':>11}{'ratio':>8}")
    for row in rows:
        reference_text = f"{row['reference'] * 1e3:.1f} ms" if row["reference"] else "-"
        ratio = f"{row['ratio']:.2f}x" if row["ratio"] else "-"
        print(f"{row['case']:<62}{row['ours'] * 1e3:>7.1f} ms{reference_text:>11}{ratio:>8}")
    a, b = rows[0]["ours_scored"], rows[0]["reference_scored"]
    print(f"impacts above -30 dB found within 1 ms: ours {a['found']}/{a['of']} (median error {a['median_error_ms']:.3f} "
          f"ms), librosa's onset_detect {b['found']}/{b['of']}")
    print(f"c = {drop.cor:.4f} ({drop.interval[0]:.4f} to {drop.interval[1]:.4f}), true 0.86, {drop.flights} flights")
    results = {"date": datetime.date.today().isoformat(), "machine": f"{platform.system()} {platform.release()} "
               f"{platform.machine()}, {platform.processor() or 'cpu'}", "python": platform.python_version(),
               "numpy": np.__version__, "scipy": scipy.__version__, "librosa": librosa.__version__,
               "drumstroke": drumstroke.__version__, "repeats": REPEATS, "rows": rows}
    (HERE / "analysis_results.json").write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
