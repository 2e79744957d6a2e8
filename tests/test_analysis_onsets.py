"""Onsets from audio and the onsets CSV (SPEC §10): round trips with known impact times, hostile files."""

import json
import math

import numpy as np
import pytest

from drumstroke.analysis import Onsets, read_onsets, write_onsets
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
    with pytest.raises(ParameterError, match="at most 10 bytes"):
        read_onsets(big)


def test_writing_refuses_another_programs_json_and_other_suffixes(tmp_path):
    (tmp_path / "o.json").write_text('{"theirs": 1}')
    with pytest.raises(ParameterError, match="already there"):
        write_onsets(tmp_path / "o.csv", Onsets([0.1], [0.0]))
    assert not (tmp_path / "o.csv").exists() and json.loads((tmp_path / "o.json").read_text()) == {"theirs": 1}
    with pytest.raises(ParameterError, match=r"must end in \.csv"):
        write_onsets(tmp_path / "o.txt", Onsets([0.1], [0.0]))
