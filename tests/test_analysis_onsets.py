"""Onsets from audio and the onsets CSV: round trips with known impact times, hostile files."""

import json
import math

import numpy as np
import pytest
import soundfile

from _cli import assert_one_line_error, run
from _recordings import RATE, random_strokes, render, room_response, score
from drumstroke.analysis import (OnsetConfig, Onsets, find_onsets, find_recording_onsets, read_onsets, read_recording,
                                 write_onsets)
from drumstroke.errors import ParameterError
from drumstroke.formats import onsets_csv

# ---------------------------------------------------------------------------------------------- the onsets CSV


def test_onsets_csv_round_trip_is_exact(tmp_path):
    """Times and levels come back bit for bit (full precision); source, threshold and info through the JSON."""
    rng = np.random.default_rng(1)
    t = np.cumsum(rng.uniform(1e-3, 0.2, 50))
    level = -rng.uniform(0.0, 60.0, 50)
    level -= level.max()
    onsets = Onsets(t, level, threshold_db=-47.25, source="take 3.wav", info={"rate": 48000})
    path = tmp_path / "o.csv"
    write_onsets(path, onsets)
    back = read_onsets(path)
    assert np.array_equal(back.t, t) and np.array_equal(back.level_db, level)
    assert back.threshold_db == -47.25 and back.source == "take 3.wav" and back.info == {"rate": 48000}
    assert path.read_text().splitlines()[0] == "t,level_db"
    meta = json.loads(path.with_suffix(".json").read_text())["csv"]
    assert meta["units"] == {"t": "s", "level_db": "dB re the loudest onset"} and meta["drumstroke"]
    # any CSV reader reads it as it is
    data = np.genfromtxt(path, delimiter=",", names=True)
    assert np.array_equal(data["t"], t) and np.array_equal(data["level_db"], level)


def test_onsets_given_not_detected_keep_an_infinite_threshold(tmp_path):
    """-inf is not JSON: written as null, read back as -inf; no JSON at all reads as the file's name, -inf."""
    path = tmp_path / "given.csv"
    write_onsets(path, Onsets([0.5], [0.0]))
    assert json.loads(path.with_suffix(".json").read_text())["csv"]["threshold_db"] is None
    assert read_onsets(path).threshold_db == -math.inf
    bare = tmp_path / "bare.csv"
    bare.write_text("\ufefft,level_db\n0.25,0\n0.5,-6\n")  # a spreadsheet's byte-order mark
    back = read_onsets(bare)
    assert back.t.tolist() == [0.25, 0.5] and back.source == "bare.csv" and back.threshold_db == -math.inf


def test_an_empty_onsets_file_is_no_onsets(tmp_path):
    path = tmp_path / "none.csv"
    write_onsets(path, Onsets([], []))
    assert len(read_onsets(path)) == 0 and path.read_text() == "t,level_db\n"


def test_onsets_with_peaks_round_trip_and_any_csv_reader_reads_the_column(tmp_path):
    """peak_db as a third column, bit for bit back; pandas reads the three columns; the JSON says what each is."""
    import pandas

    rng = np.random.default_rng(2)
    t = np.cumsum(rng.uniform(1e-3, 0.2, 20))
    level, peak = -rng.uniform(0.0, 40.0, 20), -rng.uniform(0.0, 40.0, 20)
    level, peak = level - level.max(), peak - peak.max()
    path = tmp_path / "p.csv"
    write_onsets(path, Onsets(t, level, threshold_db=-40.0, source="take.wav", peak_db=peak))
    back = read_onsets(path)
    assert np.array_equal(back.t, t) and np.array_equal(back.level_db, level) and np.array_equal(back.peak_db, peak)
    table = pandas.read_csv(path)
    assert list(table.columns) == ["t", "level_db", "peak_db"]
    assert np.array_equal(table["peak_db"].to_numpy(), peak) and np.array_equal(table["t"].to_numpy(), t)
    meta = json.loads(path.with_suffix(".json").read_text())["csv"]
    assert meta["columns"] == ["t", "level_db", "peak_db"] and meta["units"]["peak_db"] == "dB re the loudest onset's peak"
    assert set(meta["meanings"]) == {"t", "level_db", "peak_db"}


def test_an_onsets_csv_without_peaks_still_reads(tmp_path):
    """A file written before the column (t,level_db, with or without its JSON) reads as onsets without peaks."""
    old = tmp_path / "old.csv"
    old.write_text("t,level_db\n0.25,0\n0.5,-6\n")
    back = read_onsets(old)
    assert back.peak_db is None and back.level_db.tolist() == [0.0, -6.0]
    write_onsets(old, back)  # written again as it was: two columns
    assert old.read_text().splitlines()[0] == "t,level_db" and read_onsets(old).peak_db is None
    mixed = tmp_path / "mixed.csv"
    mixed.write_text("t,level_db,peak_db\n0.25,0,0\n0.5,-6\n")
    with pytest.raises(ParameterError, match="line 3 must be 't,level_db,peak_db' with three finite numbers"):
        read_onsets(mixed)


@pytest.mark.parametrize(("peak", "message"), [
    ([0.0], "as many as the times"), ([0.0, 1.0], "peak_db"), ([-1.0, -2.0], "re the loudest peak"),
    ([0.0, math.nan], "peak_db"),
])
def test_onset_peaks_are_checked(peak, message):
    with pytest.raises(ParameterError, match=message):
        Onsets([0.1, 0.2], [0.0, -3.0], peak_db=peak)


def test_a_note_over_an_earlier_ones_ringing_has_its_own_peak():
    """Three notes of one waveform (a 2-ms rise, ringing modes and a noise burst), the last 12-30 ms after the
    second: peak_db is each one's own scale (the earlier note's continuation taken off by the first, clear, note's
    waveform), where the peak read as it is over the last one's 10 ms is 3-5 dB too loud."""
    rng = np.random.default_rng(3)
    t = np.arange(round(0.3 * RATE)) / RATE
    note = np.exp(-t / 0.05) * (np.sin(2 * np.pi * 190 * t) + 0.6 * np.sin(2 * np.pi * 330 * t + 1.0)
                                + 0.4 * rng.standard_normal(len(t)) * np.exp(-t / 0.01)) * np.minimum(1.0, t / 2e-3)
    for gap, scale in [(0.012, 0.7), (0.02, 0.5), (0.03, 0.3)]:
        signal = np.zeros(RATE)
        for start, size in [(0.1, 1.0), (0.5, 0.9), (0.5 + gap, scale)]:
            k = round(start * RATE)
            signal[k:k + len(t)] += size * note[:len(signal) - k]
        onsets = find_onsets(signal, RATE)
        assert len(onsets) == 3
        assert onsets.peak_db == pytest.approx(20.0 * np.log10([1.0, 0.9, scale]), abs=0.1)
        first, k = round(0.1 * RATE), round((0.5 + gap) * RATE)
        read_as_is = np.abs(signal[k:k + RATE // 100]).max() / np.abs(signal[first:first + RATE // 100]).max()
        assert 20.0 * np.log10(read_as_is / scale) > 2.5


@pytest.mark.parametrize(("text", "message"), [
    ("", "line 1 must be the header t,level_db"),
    ("time,level\n0,0\n", "line 1 must be the header t,level_db"),
    ("t,level_db\n0.1,0\n0.2\n", "line 3 must be 't,level_db' with two finite numbers"),
    ("t,level_db\n0.1,0\n0.2,loud\n", "line 3 must be 't,level_db' with two finite numbers"),
    ("t,level_db\n0.1,nan\n", "line 2 must be 't,level_db' with two finite numbers"),
    ("t,level_db\n0.2,0\n0.1,-3\n", "strictly increasing"),
    ("t,level_db\n0.1,3\n", "level_db"),
    ("t,level_db\n0.1,-1\n0.2,-3\n", "re the loudest"),
    ("t,level_db\n-0.1,0\n", "onset times t"),
])
def test_a_bad_onsets_csv_is_named_with_its_line(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ParameterError, match=message) as error:
        read_onsets(path)
    assert str(path) in str(error.value)


def test_unreadable_onsets_files_are_refused(tmp_path, monkeypatch):
    with pytest.raises(ParameterError, match="cannot be read"):
        read_onsets(tmp_path / "missing.csv")
    (tmp_path / "folder.csv").mkdir()
    with pytest.raises(ParameterError, match="not a regular file"):
        read_onsets(tmp_path / "folder.csv")
    binary = tmp_path / "binary.csv"
    binary.write_bytes(b"\xff\xfe\x00\x81garbage")
    with pytest.raises(ParameterError, match="not a UTF-8 text file"):
        read_onsets(binary)
    big = tmp_path / "big.csv"
    big.write_text("t,level_db\n0.1,0\n")
    monkeypatch.setattr(onsets_csv, "MAX_BYTES", 10)
    with pytest.raises(ParameterError, match="larger than 10 bytes, the most an onsets file may be"):
        read_onsets(big)


def test_writing_refuses_another_programs_json_and_other_suffixes(tmp_path):
    (tmp_path / "o.json").write_text('{"theirs": 1}')
    with pytest.raises(ParameterError, match="already there"):
        write_onsets(tmp_path / "o.csv", Onsets([0.1], [0.0]))
    assert not (tmp_path / "o.csv").exists() and json.loads((tmp_path / "o.json").read_text()) == {"theirs": 1}
    with pytest.raises(ParameterError, match=r"must end in \.csv"):
        write_onsets(tmp_path / "o.txt", Onsets([0.1], [0.0]))


# ------------------------------------------------------------------------ onsets from audio: known answers


STROKES = 6
"""Random strokes per condition (their impacts: 228 in all, 74 louder than −30 dB re each stroke's loudest)."""

# condition: (render options, least recall of the impacts above −30 dB, above −20 dB, most extra onsets in all,
# largest median level error (dB) of the impacts above −20 dB)
# Measured (docs/analysis.md): recall −30 dB / −20 dB, extras, level error: 0.99/1.00, 7, 0.47 | 1.00/1.00, 23, 0.46 |
# 0.99/1.00, 5, 0.42 | 0.97/0.96, 7, 0.34 | 1.00/1.00, 20, 0.44 | 1.00/1.00, 7, 0.80 | 0.99/1.00, 18, 0.79.
# The issue asks 0.95 at −30 dB: asserted in every condition, above it where more was measured.
CONDITIONS = {
    "ours, snares": ({"snares": True}, 0.97, 0.95, 10, 0.7),
    "ours, no snares": ({"snares": False}, 0.97, 0.98, 30, 1.0),
    "ours, snares, SNR 30 dB": ({"snares": True, "snr": 30}, 0.97, 0.95, 8, 0.7),
    "ours, no snares, SNR 20 dB": ({"snares": False, "snr": 20}, 0.95, 0.9, 10, 0.6),
    "ours, snares, room, SNR 40 dB": ({"snares": True, "snr": 40, "room": "room"}, 0.95, 0.95, 26, 0.6),
    "other drum, SNR 30 dB": ({"kind": "other", "snr": 30}, 0.95, 0.95, 8, 1.1),
    "other drum, room, SNR 30 dB": ({"kind": "other", "snr": 30, "room": "room"}, 0.95, 0.95, 25, 1.1),
}


@pytest.fixture(scope="module")
def strokes():
    return random_strokes(STROKES, seed=7)


@pytest.fixture(scope="module")
def room():
    return room_response()


@pytest.mark.parametrize("condition", list(CONDITIONS))
def test_onsets_of_rendered_strokes_are_within_a_millisecond(strokes, room, condition):
    """Impacts of random strokes, rendered (our drum or another), noised, in a room: found where they were struck.

    Of the onsets matched to impacts louder than −20 dB within 5 ms, 95 % or more are within 1 ms
    of it and none beyond 2.5 ms (the median well under 0.2 ms); the impacts louder than −30 and −20 dB re each stroke's
    loudest are found within 1 ms at least as often as measured (less a margin); few extra onsets; levels (of the
    impacts above −20 dB) within a median of 0.3-1 dB (levels from the lowest modes, whose amplitude is in proportion to the
    tip speed).
    mir_eval's onset matching (an independent implementation) counts the same found impacts.
    """
    import mir_eval

    options, least_30, least_20, most_extra, most_level = CONDITIONS[condition]
    options = {**options, "room": room if options.get("room") else None}
    loud = found = loud_20 = found_20 = extra = 0
    errors, level_errors = [], []
    for i, (times, speeds) in enumerate(strokes):
        signal, truth = render(times, speeds, seed=i, **options)
        onsets = find_onsets(signal, RATE)
        assert onsets.threshold_db >= -40.0 and onsets.level_db.max() == 0.0
        wide = score(onsets, truth, speeds, loudest_db=-20.0, window=5e-3)
        errors += list(wide["errors"])
        tight = score(onsets, truth, speeds)
        loud, found, extra = loud + tight["loud"], found + tight["found"], extra + tight["extra"]
        strong = score(onsets, truth, speeds, loudest_db=-20.0)
        loud_20, found_20 = loud_20 + strong["loud"], found_20 + strong["found"]
        level_errors += list(strong["level_errors"])
        level = 20 * np.log10(speeds / speeds.max())
        reference = truth[level >= -30.0]
        _, _, recall = mir_eval.onset.f_measure(reference, onsets.t, window=1e-3)
        assert round(recall * len(reference)) == tight["found"]
    errors = np.abs(errors)
    assert np.mean(errors < 1e-3) >= 0.95 and errors.max() < 2.5e-3 and np.median(errors) < 2e-4, (
        errors.max(), np.median(errors))
    assert found / loud >= least_30 and found_20 / loud_20 >= least_20, (found, loud, found_20, loud_20)
    assert extra <= most_extra
    assert np.median(np.abs(level_errors)) < most_level, np.median(np.abs(level_errors))


@pytest.mark.parametrize(("condition", "seed", "least_found", "most_extra"), [
    ("ours, snares, room, SNR 40 dB", 23, 66, 25), ("other drum, room, SNR 30 dB", 23, 67, 25),
    ("ours, snares, room, SNR 40 dB", 13, 58, 20), ("other drum, room, SNR 30 dB", 13, 58, 26),
    ("ours, snares", 31, 63, 15), ("ours, snares", 36, 55, 15), ("ours, no snares", 42, 62, 30)])
def test_quiet_impacts_on_other_strokes(room, condition, seed, least_found, most_extra):
    """Other sets of six random strokes: the impacts above −30 dB (of 70, 60, 65, 56 and 64) found within 1 ms.

    Measured (docs/analysis.md), in the room: seed 23, 67 and 68 (21 and 22 extras), 65 and 66 before
    the search for quiet attacks after louder ones (step 4), 63 each before the retry in a room and the
    last round, and before two merged groups' choices 0.03 ms apart were made one; seed 13, 59 each
    (16 and 23 extras), 55 each before that search. Without a room, our drum with its snares (their
    rattle hides quiet impacts as a room's tail does): seed 31, 64 (12 extras), 60 before that search
    ran in every recording; seed 36, 56 (12 extras), 53 before. Our drum without snares (its modes'
    beating makes broadband jumps near a sharp attack): seed 42, 63 (24 extras), 60 before a tonal
    onset rising 10 times was trusted over a broadband one more than 0.5 ms away (three impacts of
    −12 to −16 dB had been placed 1.6–2 ms off).
    """
    options = {**CONDITIONS[condition][0], "room": room if CONDITIONS[condition][0].get("room") else None}
    found = extra = 0
    for i, (times, speeds) in enumerate(random_strokes(STROKES, seed=seed)):
        signal, truth = render(times, speeds, seed=i, **options)
        result = score(find_onsets(signal, RATE), truth, speeds)
        found, extra = found + result["found"], extra + result["extra"]
    assert found >= least_found and extra <= most_extra, (found, extra)


@pytest.mark.parametrize(("scale", "found"), [(0.6, True), (1.0, True), (0.2, False), (0.0, False)])
def test_a_quiet_attack_in_a_louder_ones_signature_is_found_by_its_whole_signature(scale, found):
    """Step 4's search after louder attacks, on an innovation made of known signatures (2 kHz, 50 ms).

    A signature (a spike and 50 ms of decaying noise) twice as loud alone at sample 100 (the pursuit's
    template), once at 600 and ``scale`` times 25 ms later, in white noise 40 dB under the spike: the
    last is found at its sample (within half of one) when it is 0.35-1.5 times the one before, and
    nothing else is; a scale of 0.2 (what is left of a louder attack, not a bouncing stick's next impact)
    or none adds no onset.
    """
    from drumstroke.analysis.onsets import _after_louder, _Candidates, _Modes

    rng = np.random.default_rng(3)
    signature = rng.standard_normal(102) * np.exp(-np.arange(102) / 30.0)
    signature[2] = 10.0  # the spike, 2 samples in (as the pursuit takes it)
    e = 0.1 * rng.standard_normal(2000)
    e[98:200] += 2.0 * signature
    e[598:700] += signature
    e[648:750] += scale * signature
    modes = _Modes(e, 1, 0.0, 2000.0)
    known = np.array([100.0, 600.0])
    candidates = _Candidates(known, np.array([1, 1]), np.array([True, True]), np.array([1.0, 1.0]))
    found_now = _after_louder(modes, candidates, 2000, OnsetConfig(min_interval=2e-3))
    times, kinds, attack, likeness = found_now.times, found_now.kinds, found_now.attack, found_now.likeness
    if found:
        assert len(times) == 3 and np.all(attack) and kinds[2] == 2 and abs(times[2] - 650.0) < 0.5, times
        assert likeness[2] > 0.9
    else:
        assert times.tolist() == known.tolist()


def test_an_innovation_without_a_signature_to_fit_is_left_as_it_is():
    """All zeros (no attack to take a signature from): nothing is taken off, and every step still gets its values.

    The pursuit's normal equations are singular there; its record holds the same values as when it
    fits, for each caller (the room's tail, the search after louder attacks).
    """
    from drumstroke.analysis.onsets import _after_louder, _Candidates, _Modes, _pursue

    e = np.zeros(400)
    found = _pursue(e, [100.0, 250.0], 2000.0, OnsetConfig())
    assert np.array_equal(found.residual, e) and found.where.tolist() == [100.0, 250.0]
    assert len(found.jumps) == len(found.likeness) == 2
    assert found.at.tolist() == [100, 250] and not found.amplitude.any() and not found.template.any()
    modes = _Modes(e, 1, 0.0, 2000.0)
    candidates = _Candidates(np.array([100.0, 250.0]), np.array([1, 1]), np.array([True, True]), np.array([1.0, 1.0]))
    after = _after_louder(modes, candidates, 2000, OnsetConfig(min_interval=2e-3))
    assert after.times.tolist() == [100.0, 250.0] and after.attack.all()


def test_onsets_at_8_khz_and_other_rates(strokes):
    """8, 11.025 and 16 kHz recordings (another drum, SNR 30 dB): the impacts above −20 dB within 1 ms."""
    for rate in (8000, 11025, 16000):
        for i, (times, speeds) in enumerate(strokes[:3]):
            signal, truth = render(times, speeds, kind="other", snr=30, rate=rate, seed=i)
            result = score(find_onsets(signal, rate), truth, speeds, loudest_db=-20.0)
            assert result["found"] == result["loud"] and np.abs(result["errors"]).max() < 1e-3


def test_a_lower_rate_is_refused_by_name():
    with pytest.raises(ParameterError, match=r"rate must be an integer in \[8000, 768000\] Hz, got 4000"):
        find_onsets(np.zeros(4000), 4000)


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"threshold_db": 3.0}, r"threshold_db must be in \[-120, 0\] dB"),
    ({"min_interval": 0.0}, r"min_interval must be in \[0.0005, 1\] s"),
    ({"signal": [0.0, np.nan]}, r"signal\[1\] must be a finite number"),
])
def test_bad_detection_options_are_named(kwargs, message):
    options = {name: value for name, value in kwargs.items() if name != "signal"}
    with pytest.raises(ParameterError, match=message):
        find_onsets(kwargs.get("signal", np.zeros(48000)), 48000, config=OnsetConfig(**options))


def test_the_threshold_rises_over_the_noise_floor():
    """A noise floor at about −40 dB re the loudest attack raises the threshold used over the −60 asked for."""
    rng = np.random.default_rng(3)
    times, speeds = np.array([0.2, 0.6, 0.9]), np.array([1.0, 0.5, 0.25])
    signal, _ = render(times, speeds, kind="other", seed=3)
    signal = signal + rng.standard_normal(len(signal)) * 0.9 * 1e-3
    onsets = find_onsets(signal, RATE, config=OnsetConfig(threshold_db=-60.0))
    assert onsets.threshold_db > -60.0 and onsets.threshold_db == pytest.approx(onsets.info["floor_db"] + 10.0)
    assert np.all(onsets.level_db >= onsets.threshold_db)
    assert score(onsets, times, speeds)["found"] == 3


def test_the_onsets_do_not_depend_on_blas_threads_which_run_one_while_they_are_found(strokes, room, monkeypatch):
    """The same onsets (to the bit) whatever the BLAS libraries' thread count outside; one thread inside, the count
    outside restored after (threadpoolctl reads it)."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    import drumstroke.analysis.onsets as onsets_module

    times, speeds = strokes[0]
    signal, _ = render(times, speeds, snares=True, snr=40, room=room, seed=0)  # reverberant: every fit and solve runs
    seen = []
    lstsq = np.linalg.lstsq

    def counting(*args, **kwargs):  # the normal equations' solve: the BLAS threads it runs with
        seen.append({info["num_threads"] for info in threadpoolctl.threadpool_info() if info["user_api"] == "blas"})
        return lstsq(*args, **kwargs)

    monkeypatch.setattr(onsets_module.np.linalg, "lstsq", counting)
    found = {}
    for threads in (1, 2):
        with threadpoolctl.threadpool_limits(limits=threads, user_api="blas"):
            found[threads] = find_onsets(signal, RATE)
            after = {info["num_threads"] for info in threadpoolctl.threadpool_info() if info["user_api"] == "blas"}
        assert after == {threads}
    assert seen and all(counts == {1} for counts in seen)
    assert np.array_equal(found[1].t, found[2].t) and np.array_equal(found[1].level_db, found[2].level_db)
    assert np.array_equal(found[1].peak_db, found[2].peak_db) and len(found[1]) >= 10  # not an empty comparison


# ------------------------------------------------------------------------------------------ the detector's config


def test_a_higher_threshold_keeps_exactly_the_default_onsets_above_it(strokes):
    """``threshold_db`` only filters: the onsets at −20 dB are the default's at or above it, bit for bit."""
    times, speeds = strokes[0]
    signal, _ = render(times, speeds, snares=True, snr=30, seed=0)
    default = find_onsets(signal, RATE)
    higher = find_onsets(signal, RATE, config=OnsetConfig(threshold_db=-20.0))
    used = max(-20.0, default.info["floor_db"] + 10.0)  # the noise floor's threshold, if higher
    keep = default.level_db >= used
    assert higher.threshold_db == used and 0 < len(higher) < len(default)
    assert np.array_equal(higher.t, default.t[keep]) and np.array_equal(higher.level_db, default.level_db[keep])


def test_without_the_search_after_louder_attacks_fewer_onsets_are_found(strokes):
    """``after_rounds=0`` turns step 4's search after louder attacks off: it only adds attacks, so no more are found."""
    fewer = []
    for i, (times, speeds) in enumerate(strokes[:3]):
        signal, truth = render(times, speeds, snares=True, seed=i)
        default, off = find_onsets(signal, RATE), find_onsets(signal, RATE, config=OnsetConfig(after_rounds=0))
        assert len(off) <= len(default)
        assert score(off, truth, speeds)["found"] <= score(default, truth, speeds)["found"]
        fewer.append(len(off) < len(default))
    assert any(fewer)


@pytest.mark.parametrize(("options", "message"), [
    ({"min_jump": 0.5}, r"min_jump must be in \[1, 100\] \(RMS ratio\), got 0.5"),
    ({"likeness": 1.5}, r"likeness must be in \[0, 1\] \(correlation\), got 1.5"),
    ({"signature": 0.0}, r"signature must be in \[0.001, 0.5\] s, got 0.0"),
    ({"modes_width": 2.5}, r"modes_width must be an integer in \[1, 64\] samples, got 2.5"),
    ({"order": 0}, r"order must be an integer in \[1, 400\], got 0"),
    ({"after_rounds": True}, r"after_rounds must be an integer in \[0, 100\], got True"),
    ({"high_pass": "60"}, r"high_pass must be a number in \[1, 1000\] Hz, got '60'"),
    ({"floor_margin_db": float("nan")}, r"floor_margin_db must be a finite number in \[0, 60\] dB"),
    ({"after_ratio_low": 2.0}, r"after_ratio_low must be at most after_ratio_high \(1.5\), got 2.0"),
])
def test_bad_config_values_are_named_with_their_range_and_unit(options, message):
    with pytest.raises(ParameterError, match=message):
        OnsetConfig(**options)


def test_the_config_must_be_an_onset_config():
    with pytest.raises(ParameterError, match="config must be an OnsetConfig, got dict"):
        find_onsets(np.zeros(48000), 48000, config={"threshold_db": -30.0})


def test_every_config_field_is_validated_and_documented_with_its_default():
    """Each field has a range, a line in the class's docstring and a row (name, default) in docs/analysis.md."""
    import dataclasses
    import pathlib

    from drumstroke.analysis.onsets import _RANGES

    docs = (pathlib.Path(__file__).parent.parent / "docs" / "analysis.md").read_text()
    fields = dataclasses.fields(OnsetConfig)
    assert [f.name for f in fields] == list(_RANGES)
    for f in fields:
        assert f"\n    {f.name} : " in OnsetConfig.__doc__, f.name
        row = docs.split(f"| `{f.name}` |")[1].split("\n")[0] if f"| `{f.name}` |" in docs else ""
        assert f"| {f.default:g} |" in row, f.name


def test_read_onsets_reads_csvs_only_and_names_the_detector(tmp_path):
    path = _wav(tmp_path / "take.wav", np.zeros(RATE))
    with pytest.raises(ParameterError, match=r"read_onsets reads onsets CSVs \(.csv\) only, got .*take.wav.*"
                                             r"find_recording_onsets\(path\)"):
        read_onsets(path)


# ------------------------------------------------------------------------------------------ hostile files

def _wav(path, signal, rate=RATE):
    soundfile.write(str(path), signal, rate, subtype="PCM_16")
    return path


def test_a_stereo_file_is_mixed_down_and_says_so(tmp_path, strokes):
    times, speeds = strokes[0]
    signal, truth = render(times, speeds, kind="other", snr=35)
    path = _wav(tmp_path / "stereo.wav", np.column_stack([signal, 0.5 * signal]))
    mono, rate, notes = read_recording(path)
    assert notes == {"channels": 2, "mixed_down": True, "clipped": 0} and rate == RATE
    assert np.allclose(mono, 0.75 * signal, atol=2.0 / 32768)
    onsets = find_recording_onsets(path)
    assert onsets.info["mixed_down"] and onsets.source == "stereo.wav"
    result = score(onsets, truth, speeds, loudest_db=-20.0)
    assert result["found"] == result["loud"]


def test_a_clipped_file_works_and_counts_its_clipped_samples(tmp_path, strokes):
    times, speeds = strokes[1]
    signal, truth = render(times, speeds, kind="other", snr=40)
    path = _wav(tmp_path / "clipped.wav", np.clip(5.0 * signal, -1.0, 1.0))
    onsets = find_recording_onsets(path)
    assert onsets.info["clipped"] > 100
    result = score(onsets, truth, speeds, loudest_db=-20.0)
    assert result["found"] == result["loud"] and np.abs(result["errors"]).max() < 1e-3


def test_silence_and_too_little_are_no_impacts(tmp_path):
    silent = find_recording_onsets(_wav(tmp_path / "silent.wav", np.zeros(RATE)))
    assert len(silent) == 0 and silent.info["found"] == "no impacts found: the signal is silent"
    empty = find_recording_onsets(_wav(tmp_path / "empty.wav", np.zeros(0)))
    assert len(empty) == 0 and "shorter than 50 ms" in empty.info["found"]
    hum = find_recording_onsets(_wav(tmp_path / "hum.wav", 0.3 * np.sin(2 * np.pi * 220 * np.arange(RATE) / RATE)))
    assert len(hum) <= 1  # a tone starting at the file's start, at most


def _two_hours(path, rate=8000):
    """A WAV header claiming 2 h of 16-bit mono at ``rate``, over a sparse file of that size (made at once)."""
    import struct

    data = 2 * 3600 * rate * 2
    header = (b"RIFF" + struct.pack("<I", 36 + data) + b"WAVEfmt " + struct.pack("<IHHIIHH", 16, 1, 1, rate, 2 * rate,
                                                                                 2, 16) + b"data" + struct.pack("<I", data))
    with open(path, "wb") as handle:
        handle.write(header)
        handle.truncate(len(header) + data)
    return path


@pytest.mark.parametrize(("make", "message"), [
    (lambda p: p.write_bytes(b""), "cannot be read as audio"),
    (lambda p: p.write_text("t,level\nnot audio\n"), "cannot be read as audio"),
    (lambda p: _two_hours(p), "lasts 7200 s; at most 600 s are read"),
    (lambda p: p.mkdir(), "is not a regular file"),
    (lambda p: None, "is missing"),
])
def test_hostile_files_get_one_clear_error(tmp_path, make, message):
    path = tmp_path / "take.wav"
    make(path)
    with pytest.raises(ParameterError, match=message) as error:
        find_recording_onsets(path)
    assert str(path) in str(error.value)


# ------------------------------------------------------------------------------------------ the command



def test_the_onsets_command_prints_and_writes_them(tmp_path, strokes):
    times, speeds = strokes[0]
    signal, truth = render(times, speeds, kind="other", snr=35)
    path = _wav(tmp_path / "take.wav", signal)
    result = run("onsets", path, "--out", tmp_path / "take.csv", "--plot", tmp_path / "take.png")
    assert result.returncode == 0, result.stderr
    assert "threshold" in result.stdout and "onsets:" in result.stdout
    back = read_onsets(tmp_path / "take.csv")
    assert back.source == "take.wav" and back.threshold_db == pytest.approx(-40.0)
    assert score(back, truth, speeds, loudest_db=-20.0)["found"] == score(back, truth, speeds, loudest_db=-20.0)["loud"]
    assert (tmp_path / "take.png").stat().st_size > 1000 and (tmp_path / "take.json").exists()


def test_the_onsets_command_says_no_impacts_and_refuses_hostile_files(tmp_path):
    silent = _wav(tmp_path / "silent.wav", np.zeros(RATE))
    result = run("onsets", silent)
    assert result.returncode == 0 and "no impacts found: the signal is silent" in result.stdout
    stereo = _wav(tmp_path / "stereo.wav", np.zeros((RATE, 2)))
    assert "2 channels, mixed down" in run("onsets", stereo).stderr
    assert_one_line_error(run("onsets", _two_hours(tmp_path / "long.wav")), "lasts 7200 s")
    text = tmp_path / "notes.wav"
    text.write_text("not audio")
    assert_one_line_error(run("onsets", text), "cannot be read as audio")
    assert_one_line_error(run("onsets", silent, "--threshold", "5"), "--threshold")
