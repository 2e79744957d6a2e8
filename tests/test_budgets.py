"""Resource budgets (:mod:`drumstroke.budget`): small inputs that ask for a lot are refused before the work.

Each case runs the console script in a process of its own and reads that process's own peak memory
(:mod:`_measured`: from a small process that started it): exit status 2, one line on stderr naming the input (the file or the option) and
the option that raises the budget, nothing written, and a peak far below what the input asks for
(under 1 GB). Then the budget's option letting a larger input through, a long CSV streamed in
bounded memory, and the estimates against what they estimate.
"""

import os
import struct

import numpy as np
import pytest

from _cli import COMMAND
from _measured import measured
from drumstroke import budget
from drumstroke.analysis.drop import _triples, triple_count
from drumstroke.errors import ParameterError
from drumstroke.formats.wav import read_audio, write_wav
from drumstroke.profiles import Pulses, Sum

GB = 1e9
LIMIT = 30.0  # s: a hang guard, far above the second or two a refusal takes


def run_measured(*args, cwd):
    """Run ``drumstroke ARGS`` in a process of its own; return (status, stdout, stderr, its peak memory in bytes)."""
    status, stdout, stderr, peak, _, _, _ = measured([*COMMAND, *args], cwd=cwd, timeout=LIMIT)
    return status, stdout, stderr, peak


def refused(folder, *args, needles):
    """Run a case: exit 2, one line naming every needle, nothing new in ``folder``, under 1 GB at its peak."""
    before = set(os.listdir(folder))
    status, _, stderr, peak = run_measured(*args, cwd=folder)
    lines = stderr.strip().splitlines()
    assert status == 2, stderr
    assert len(lines) == 1 and "Traceback" not in stderr, stderr
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    assert set(os.listdir(folder)) == before
    assert peak < 1 * GB, peak
    return lines[0]


def _wav_header(channels, rate, bits, data_bytes):
    """A PCM WAV header claiming ``data_bytes`` of samples."""
    block = channels * bits // 8
    return (b"RIFF" + struct.pack("<I", 36 + data_bytes) + b"WAVE" + b"fmt "
            + struct.pack("<IHHIIHH", 16, 1, channels, rate, rate * block, block, bits)
            + b"data" + struct.pack("<I", data_bytes))


@pytest.fixture(scope="module")
def sparse_wav(tmp_path_factory):
    """A WAV of a few kB on disk whose header claims 1.8 GB of 8-channel audio (a sparse file: a hole after it)."""
    path = tmp_path_factory.mktemp("sparse") / "huge.wav"
    size = 1_800_000_000
    with open(path, "wb") as handle:
        handle.write(_wav_header(8, 384000, 8, size))  # 586 s: within the 600 s onsets reads
        handle.truncate(44 + size)
    assert os.stat(path).st_blocks * 512 <= 64 * 1024  # a few kB on disk
    return path


@pytest.mark.parametrize("command", [("onsets",), ("measure-cor",), ("fit", "--out", "fit.toml"),
                                     ("compare", "A")])
def test_a_sparse_wav_claiming_gigabytes_is_refused_from_its_header(tmp_path, sparse_wav, command):
    name, *rest = command
    args = [name, sparse_wav, *rest] if name != "compare" else [name, sparse_wav, sparse_wav]
    line = refused(tmp_path, *args, needles=(str(sparse_wav), "225000000 frames of 8 channels", "--budget-gb"))
    assert "over the budget of 1 GB" in line


def test_two_hundred_sticks_for_an_hour(tmp_path):
    rows = [f"{3600 if i % 2 else 0} single 100 s{i}" for i in range(200)]
    (tmp_path / "sticks.pattern").write_text("tempo 60\n" + "\n".join(rows) + "\n")
    refused(tmp_path, "compose", "sticks.pattern", "--csv", "out.csv",
            needles=("'out.csv'", "401 numbers", "--budget-minutes"))


def test_a_sum_of_two_hundred_fast_pulses_for_an_hour(tmp_path):
    parts = ",\n".join(f'  {{ kind = "pulses", amplitude = 150.0, period = 0.001, duty = 0.5, phase = {i * 1e-6:.6f} }}'
                       for i in range(200))
    (tmp_path / "pulses.toml").write_text(f't_end = 3600.0\ncor = 0.8\n[force]\nkind = "sum"\nparts = [\n{parts}\n]\n')
    assert (tmp_path / "pulses.toml").stat().st_size < 20_000
    refused(tmp_path, "simulate", "pulses.toml", "--csv", "out.csv",
            needles=("recipe 'pulses.toml': force (sum)", "1440000002 breakpoints", "--budget-gb"))


def test_a_megahertz_rate_on_a_four_line_recipe(tmp_path):
    (tmp_path / "r.toml").write_text('t_end = 3600.0\ncor = 0.5\n[force]\nkind = "constant"\nvalue = 20.0\n')
    refused(tmp_path, "simulate", "r.toml", "--rate", "1e6", "--csv", "out.csv", needles=("rate = 1e+06 Hz",))


def test_a_ten_million_point_grid_from_81_bytes(tmp_path):
    (tmp_path / "grid.toml").write_text('base = "constant"\n[parameters]\ncor = { start = 0.1, stop = 0.9, '
                                        'num = 10000000 }\n')
    assert (tmp_path / "grid.toml").stat().st_size == 81
    refused(tmp_path, "sweep", "grid.toml", "--out", "out.csv",
            needles=("sweep 'grid.toml'", "10000000 points", "--budget-gb"))


def test_measure_cor_on_hundreds_of_thousands_of_onsets(tmp_path):
    t = np.cumsum(np.full(400_000, 0.01))
    level = -1e-5 * np.arange(len(t))
    np.savetxt(tmp_path / "many.csv", np.column_stack([t, level]), delimiter=",", header="t,level_db", comments="",
               fmt="%.6f")
    line = refused(tmp_path, "measure-cor", "many.csv", needles=("'many.csv'", "400000 onsets", "--budget-minutes"))
    read = np.loadtxt(tmp_path / "many.csv", delimiter=",", skiprows=1)[:, 0]
    assert f"{triple_count(read)} triples" in line


def test_the_budget_option_lets_a_larger_recording_through(tmp_path):
    """A 10 s stereo recording asks for some 19 MB (two channels and three working copies): refused under 15 MB,
    analysed under 30 MB, its onsets where its hits are."""
    rate, hits = 48000, np.arange(0.5, 10.0, 0.5)
    t = np.arange(10 * rate) / rate
    mono = sum(0.5 * np.where(t >= t0, np.exp(-(t - t0) / 0.03) * np.sin(2 * np.pi * 300 * (t - t0)), 0.0)
               for t0 in hits)
    import soundfile

    soundfile.write(tmp_path / "stereo.wav", np.column_stack([mono, mono]), rate, subtype="PCM_24")
    refused(tmp_path, "onsets", "stereo.wav", "--budget-gb", "0.015",
            needles=("'stereo.wav'", "480000 frames of 2 channels", "over the budget of 0.015 GB", "--budget-gb"))
    status, _, stderr, _ = run_measured("onsets", "stereo.wav", "--budget-gb", "0.03", "--out", "o.csv", cwd=tmp_path)
    assert status == 0, stderr
    found = np.loadtxt(tmp_path / "o.csv", delimiter=",", skiprows=1, ndmin=2)[:, 0]
    assert len(found) == len(hits) and np.abs(found - hits).max() < 1e-3


def test_a_long_csv_streams_in_bounded_memory(tmp_path):
    """2,000,000 rows and 200,000 (one chunk) peak within 100 MB of each other: the CSV is written as it is sampled
    (held whole, the longer would take some 300 MB more); and the streamed file is the stroke's samples."""
    (tmp_path / "r.toml").write_text('t_end = 2.0\ntheta0 = 0.3\ncor = 0.8\n[force]\nkind = "constant"\n'
                                     'value = 20.0\n')
    peaks = {}
    for rate in (1e5, 1e6):
        status, _, stderr, peaks[rate] = run_measured("simulate", "r.toml", "--rate", rate, "--csv", f"{rate:g}.csv",
                                                      cwd=tmp_path)
        assert status == 0, stderr
    assert peaks[1e6] - peaks[1e5] < 100e6, peaks
    from drumstroke import Recipe
    from drumstroke.render.data import as_trajectory
    from drumstroke.stroke import simulate

    expected = as_trajectory(simulate(Recipe.from_toml(tmp_path / "r.toml")), rate=1e6)
    written = np.loadtxt(tmp_path / "1e+06.csv", delimiter=",", skiprows=1)
    assert written.shape == (2_000_001, 3)
    np.testing.assert_array_equal(written[:, 0], expected.t)
    np.testing.assert_allclose(written[:, 1:], np.column_stack([expected.theta, expected.omega]), rtol=0, atol=1e-12)


def _recipe(folder, name, t_end):
    (folder / name).write_text(f't_end = {t_end}\ncor = 0.5\n[force]\nkind = "constant"\nvalue = 20.0\n')


def test_a_megahertz_rate_on_a_minute_is_refused_before_the_simulation(tmp_path):
    """60 s at 1 MHz: 60,000,001 samples, over the 50 million a trajectory may hold, refused naming --rate (a
    stretch counted: 1 s stretched 60 times likewise); a minute that fits (40 s) is not refused."""
    _recipe(tmp_path, "r.toml", 60.0)
    _recipe(tmp_path, "one.toml", 1.0)
    refused(tmp_path, "simulate", "r.toml", "--rate", "1e6", "--csv", "out.csv",
            needles=("--rate = 1e+06 Hz over 60 s", "60000001 samples", "at most 50000000"))
    refused(tmp_path, "simulate", "one.toml", "--stretch", "60", "--rate", "1e6", "--csv", "out.csv",
            needles=("--rate = 1e+06 Hz over 60 s", "60000001 samples"))
    line = refused(tmp_path, "simulate", "r.toml", "--rate", "1e6", "--csv", "out.csv", "--budget-minutes", "1",
                   needles=("--rate",))
    assert "50000000" in line  # the count before the time: the limit that no budget raises


def test_the_csv_time_a_rate_asks_for_is_refused_before_the_simulation(tmp_path):
    """30 s at 1 MHz: 30,000,001 rows of 3 numbers, some 2.3 min at 1.5 µs a number, over a 1-minute budget."""
    _recipe(tmp_path, "r.toml", 30.0)
    line = refused(tmp_path, "simulate", "r.toml", "--rate", "1e6", "--csv", "out.csv", "--budget-minutes", "1",
                   needles=("--rate asks for about 2.3 min of work", "30000001 rows of 3 numbers", "--budget-minutes"))
    assert line.startswith("drumstroke simulate: error: --rate")


def test_compose_refuses_a_rate_before_composing(tmp_path):
    (tmp_path / "hour.pattern").write_text("tempo 60\n0 single 100 right\n3600 single 100 right\n")
    refused(tmp_path, "compose", "hour.pattern", "--rate", "1e5", "--csv", "out.csv",
            needles=("--rate = 100000 Hz over 3600 s", "360000001 samples"))


@pytest.fixture(scope="module")
def long_part(tmp_path_factory):
    folder = tmp_path_factory.mktemp("long")
    (folder / "long.pattern").write_text("tempo 60\n0 single 100 right\n3000 single 100 right\n")
    return folder / "long.pattern"


@pytest.mark.parametrize("options, needles", [
    (("--audio", "out.wav"), ("audio file 'out.wav'", "of audio asks for about 6.9 GB", "--budget-gb")),
    (("--kit", "--audio", "out.wav"), ("audio file 'out.wav'", "of audio asks for about 6.9 GB", "--budget-gb")),
    (("--kit", "--plot", "out.png"), ("picture 'out.png'", "10 curves of 3000.", "--budget-gb")),
    (("--kit", "--rate", "1e4", "--csv", "out.csv"), ("the kit's 5 joints at rate = 10000 Hz", "--budget-gb")),
])
def test_a_long_part_s_sound_picture_and_kit_csv_are_refused(tmp_path, long_part, options, needles):
    """50 minutes: 144 million samples of audio (some 40 bytes each to synthesize), 30 million points of the kit's
    joints drawn, the kit's 5 joints at 10 kHz sampled whole: each over 1 GB, refused naming its file or option."""
    refused(tmp_path, "compose", long_part, *options, needles=needles)


@pytest.mark.parametrize("source, options, needles", [
    ("r.toml", (), ("--rate asks for about 1.1 GB", "6000001 control periods of 1 joint, 3 runs", "--budget-gb")),
    ("r.toml", ("--controller", "pi", "--budget-minutes", "0.5"),
     ("--rate asks for about 1 min of work", "6000001 control periods of 1 joint, 1 run", "--budget-minutes")),
    ("long.pattern", ("--kit", "--plant", "simple"), ("--rate", "control periods of 5 joints, 3 runs")),
])
def test_robot_track_refuses_the_periods_a_rate_asks_for(tmp_path, long_part, source, options, needles):
    """60 s at 100 kHz with three controllers holds some 1.1 GB (measured 1.13 GB at its peak before this check); with
    one, some 1 min of control periods; the kit's long part at 10 kHz far more: each refused before the run."""
    _recipe(tmp_path, "r.toml", 60.0)
    (tmp_path / "long.pattern").write_text(long_part.read_text())
    rate = "1e4" if "--kit" in options else "1e5"
    refused(tmp_path, "robot", "track", source, "--rate", rate, *options, needles=needles)


def test_measure_cor_on_a_million_onsets_reads_them_at_once(tmp_path):
    """A million rows: read as one array (the same numbers as row by row), refused for its triples' time."""
    t = np.cumsum(np.full(1_000_000, 0.01))
    np.savetxt(tmp_path / "many.csv", np.column_stack([t, -1e-5 * np.arange(len(t))]), delimiter=",",
               header="t,level_db", comments="", fmt="%.6f")
    refused(tmp_path, "measure-cor", "many.csv", needles=("onsets file 'many.csv'", "1000000 onsets", "--budget-minutes"))
    from drumstroke.formats.onsets_csv import read_onsets_csv

    times, levels, peaks, _ = read_onsets_csv(tmp_path / "many.csv")
    expected = np.loadtxt(tmp_path / "many.csv", delimiter=",", skiprows=1)
    assert peaks is None
    np.testing.assert_array_equal(np.column_stack([times, levels]), expected)


@pytest.mark.parametrize("text, needle", [
    ("t,level_db\n0.1,0\n0.2,-1\n0.15,-2\n", "line 4: t = 0.15 s comes after 0.2 s"),
    ('t,level_db\n0.1,0\n"0.2",-1\n0.3,nan\n', "line 4 must be 't,level_db' with two finite numbers"),
    ("t,level_db\r\n0.1,0\r\n0.2\r\n", "line 3 must be 't,level_db' with two finite numbers"),
    ("t,level_db\n0.1,0,3\n", "line 2 must be 't,level_db' with two finite numbers"),
])
def test_an_onsets_csv_at_fault_is_named_by_its_line_however_it_is_read(tmp_path, text, needle):
    from drumstroke.formats.onsets_csv import read_onsets_csv

    (tmp_path / "on.csv").write_bytes(text.encode())
    with pytest.raises(ParameterError, match=needle):
        read_onsets_csv(tmp_path / "on.csv")


@pytest.mark.parametrize("command, name", [
    (("measure-cor", "sub/one.csv"), "onsets file 'sub/one.csv'"),
    (("measure-cor", "sub/silent.wav"), "recording 'sub/silent.wav'"),
    (("fit", "sub/one.csv", "--out", "f.toml"), "onsets file 'sub/one.csv'"),
    (("fit", "sub/silent.wav", "--out", "f.toml"), "recording 'sub/silent.wav'"),
])
def test_an_analysis_names_the_file_by_the_path_given(tmp_path, command, name):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "one.csv").write_text("t,level_db\n0.1,0\n")
    write_wav(tmp_path / "sub" / "silent.wav", np.zeros(48000), rate=48000)
    refused(tmp_path, *command, needles=(name,))


def test_a_live_record_plans_no_note_past_its_size_and_stays_replayable(monkeypatch):
    """Past RECORD_BYTES of rows a note is dropped saying the record is full; the record replays what was sent."""
    from drumstroke.live import ManualClock, Performer, Runtime, replay_session
    from drumstroke.live import performer as performer_module
    from drumstroke.live.inputs import Request

    monkeypatch.setattr(performer_module, "RECORD_BYTES", 1500)  # some five rows
    performer = Performer(clock=ManualClock())
    runtime = Runtime(performer)
    runtime.schedule([Request(0.1 + 0.1 * i, ("right", "left")[i % 2], 100, source="test") for i in range(12)])
    theta = np.concatenate([chunk.theta for chunk in runtime.chunks(duration=2.0)])
    record = runtime.session()
    planned = [row for row in record["notes"] if row["planned"]]
    full = [row for row in record["notes"] if not row["planned"]]
    assert 1500 <= performer.recorded and 4 <= len(planned) < 12 and len(planned) + len(full) == 12
    assert all(row["reason"].startswith("the record is full") for row in full)
    assert all(a["at"] < b["at"] for a, b in zip(planned, full[:1]))  # the first notes played, the later dropped
    np.testing.assert_array_equal(replay_session(record).theta, theta)


# --- the estimates ---------------------------------------------------------------------------------------------------


def test_a_sweep_grid_is_counted_without_making_its_values():
    from drumstroke.sweep import Grid

    grid = Grid.from_dict({"base": "constant", "parameters": {"cor": {"start": 0.1, "stop": 0.9, "num": 5_000_000},
                                                              "theta0": [0.0, 0.1]}})
    assert len(grid) == 10_000_000


def test_triples_are_counted_as_measure_cor_tries_them(rng):
    for n in (0, 1, 2, 3, 5, 7, 8, 13, 200):
        for spacing in (0.002, 0.01, 0.1):
            t = np.sort(rng.uniform(0.0, n * spacing, n))
            assert triple_count(t) == len(list(_triples(t)))


def test_breakpoints_are_counted_as_they_are_made():
    pulses = Pulses(amplitude=100.0, period=0.013, duty=0.3, phase=0.004)
    for t_end in (0.0, 0.003, 0.004, 1.0, 7.77):
        assert pulses._break_count(t_end) == len(pulses._breaks(t_end))
    total = Sum([pulses, Pulses(amplitude=5.0, period=0.5, duty=0.5)])
    assert total._break_count(3.0) == len(total._breaks(3.0))


def test_a_header_is_checked_against_the_budget_in_the_library(tmp_path):
    path = tmp_path / "a.wav"
    write_wav(path, np.zeros(48000), rate=48000)
    refusal = r"audio file '.*a\.wav' asks for about 0\.0015 GB .* memory_gb"
    with budget.allowing(budget.Budget(memory_gb=1e-4)), pytest.raises(ParameterError, match=refusal):
        read_audio(path, working=3)
    assert read_audio(path)[0].shape == (48000, 1)  # the default budget again outside the block


def test_a_budget_must_be_positive():
    with pytest.raises(ParameterError, match=r"memory_gb must be in \(0, inf\) GB, got 0\.0"):
        budget.Budget(memory_gb=0.0)
    with pytest.raises(ParameterError, match=r"minutes must be in \(0, inf\) min, got -1\.0"):
        budget.Budget(minutes=-1.0)
