"""Crash safety: SIGKILL at random points of ``library build``, ``compose`` and ``simulate`` (real processes, real files).

A short run of the campaign in benchmarks/robustness_kill.py (which runs at least 100 kills):
after every kill the folder holds the previous result or the new one, whole — the library loads
and checks whole; compose's and simulate's files are all one run's, byte for byte — and the next
run to the end leaves nothing but its result.
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from robustness_kill import WHOLE, Campaign

KILLS = 9


def test_a_kill_at_any_point_leaves_a_whole_result_and_the_next_run_no_debris(tmp_path):
    # No plot: matplotlib's import would double each run's time; the benchmark writes one.
    result = Campaign(tmp_path, outputs=("out.csv", "out.json", "out.wav", "out.mid")).run(kills=KILLS, seed=16)
    assert result["kills"] >= KILLS and result["failures"] == 0, result["trials"]
    for command, figures in result["commands"].items():
        assert figures["kills"] >= KILLS // 3, command
        assert set(figures["outcomes"]) <= set(WHOLE), (command, figures["outcomes"])
        assert figures["debris_after_next_run"] == [0, 0], command
    killed = [t for t in result["trials"] if t["killed"]]
    assert {t["mode"] for t in killed} == {"time", "call"}
    assert all(t["whole_after_next_run"] for t in result["trials"])
    # Some kills landed while files were being written: they left temporaries, which the next run swept.
    assert sum(t["leftover_files"] > 0 for t in killed) >= 2
