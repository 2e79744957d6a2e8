"""The formats both ways: what drumstroke writes, independent readers read, and drumstroke reads back the same.

Oracles: the shipped example files, numpy's and the csv module's readers, tomllib, and soundfile.
"""

import csv
import tomllib
from pathlib import Path

import numpy as np
import pytest
import soundfile

import drumstroke
from drumstroke.errors import ParameterError
from drumstroke.formats.pattern import parse_pattern, read_pattern_file, write_pattern
from drumstroke.formats.responses_csv import COLUMNS, read_responses_csv, write_responses_csv
from drumstroke.formats.signal_csv import read_signal, write_signal
from drumstroke.formats.toml import read_toml, write_toml
from drumstroke.formats.wav import read_wav, write_wav
from drumstroke.palette.library import DEMO_PATTERN
from drumstroke.score import read_pattern

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_a_recorded_signal_round_trips_at_full_precision(tmp_path):
    rows = read_signal(EXAMPLES / "thumb-recording.csv", "samples.file")
    t, values = np.array(rows).T
    path = tmp_path / "thumb.csv"
    write_signal(path, t, values)
    data = np.loadtxt(path, delimiter=",", skiprows=1)  # numpy's reader: a header line, then numbers
    assert np.array_equal(data[:, 0], t) and np.array_equal(data[:, 1], values)
    assert read_signal(path, "samples.file") == rows


def test_the_demo_pattern_round_trips_to_the_same_notes(tmp_path):
    pattern = read_pattern_file(DEMO_PATTERN)
    path = tmp_path / "groove.pattern"
    write_pattern(path, *pattern)
    again = read_pattern(path)
    original = read_pattern(DEMO_PATTERN)
    assert len(again) == len(original) == 29
    assert [(n.time, n.stroke, n.velocity, n.stick) for n in again] == \
           [(n.time, n.stroke, n.velocity, n.stick) for n in original]


def test_a_pattern_line_that_is_not_a_note_is_named():
    with pytest.raises(ParameterError, match=r"^p line 3: velocity must be an integer in \[1, 127\], got '300'"):
        parse_pattern("tempo 100\n0 single 90\n1 tap 300\n", name="p")


def test_responses_round_trip_through_the_csv_module(tmp_path):
    rows = [("s1", "p1", "A", "B", 3, 4), ("s1", "p2", "B", "B", 5, 1), ("s 2", "p,1", "A", "A", 1, 5)]
    path = tmp_path / "responses.csv"
    write_responses_csv(path, rows)
    with path.open(newline="") as handle:
        read = list(csv.DictReader(handle))  # the standard reader, keyed by the header
    assert tuple(read[0]) == COLUMNS and read[2]["pair"] == "p,1"  # a comma in a field is quoted, not a column
    assert read_responses_csv(path) == [[str(v) for v in row] for row in rows]


def test_wav_round_trips_through_soundfile(tmp_path):
    signal = np.sin(np.linspace(0.0, 40.0, 4800)) * 0.9
    path = tmp_path / "tone.wav"
    write_wav(path, signal, rate=48_000)
    info = soundfile.info(str(path))
    assert (info.samplerate, info.channels, info.subtype) == (48_000, 1, "PCM_24")
    theirs, rate = soundfile.read(str(path))
    ours, our_rate = read_wav(path)
    assert rate == our_rate == 48_000 and np.array_equal(ours, theirs)
    assert np.abs(ours - signal).max() <= 2.0**-23  # 24-bit quantisation


def test_a_file_that_is_not_wav_is_named(tmp_path):
    path = tmp_path / "not.wav"
    path.write_text("RIFF? no")
    with pytest.raises(ParameterError, match=r"WAV file '.*not\.wav' cannot be read"):
        read_wav(path)


# --- TOML, written by tomli-w, read by tomllib ---------------------------------------------------------------------

AWKWARD = 'a "quoted" word, a back\\slash, a\nnew line, a\ttab, \x01 a control, é, 🥁, and [brackets] = "="'


def test_toml_round_trips_through_tomllib(rng, tmp_path):
    floats = rng.normal(size=8) * 10.0 ** rng.integers(-300, 300, size=8)  # every bit of the mantissa matters
    data = {
        "name": AWKWARD,
        "cor": 0.1 + 0.2,  # 0.30000000000000004, not 0.3
        "tiny": 5e-324,
        "count": np.int64(7),  # numpy numbers are written as the numbers they are
        "values": np.array(floats),
        "force": {"kind": "sum", "parts": [{"kind": "constant", "value": float(floats[0])},
                                           {"kind": "piecewise-linear",
                                            "points": [[0.0, 10.0], [1.0, float(floats[1])], [1.05, 220.0]]},
                                           {"kind": "pulses", "amplitude": 189.0, "period": 0.4, "duty": 0.05}]},
        "parameters": {"force.value": {"start": 0.0, "stop": 250.0, "num": 11}, "cor": [0.6, 0.86]},
        "pair": [{"id": "free-bounce", "human": "human free bounce.wav", "robot": "robot-free-bounce.wav"}],
        "deep": {"er": {"still": {"value": -0.0, "flag": True, "empty": []}}},
    }
    path = tmp_path / "awkward.toml"
    write_toml(path, data)
    expected = {**data, "count": 7, "values": floats.tolist()}
    read = tomllib.loads(path.read_text())  # the standard library's reader, not drumstroke's
    assert read == expected and read["name"] == AWKWARD
    assert [x.hex() for x in read["values"]] == [x.hex() for x in floats.tolist()]  # bit for bit
    assert read_toml(path, "test") == expected


def test_a_recipe_with_nested_profiles_round_trips(tmp_path):
    force = drumstroke.Sum([drumstroke.PiecewiseLinear([(0.0, 10.0), (1.0, 1 / 3), (1.05, 220.0)]),
                            drumstroke.Pulses(amplitude=189.0, period=0.4, duty=0.05, phase=0.08)])
    recipe = drumstroke.Recipe(force=force, gravity=drumstroke.PiecewiseLinear([(0.0, 9.8), (2.0, -1.5)]),
                               theta0=0.1 + 0.2, omega0=-2.0, cor=0.86, t_end=2.5, name="nested")
    path = tmp_path / "nested.toml"
    recipe.to_toml(path)
    assert tomllib.loads(path.read_text()) == recipe.to_dict()
    again = drumstroke.Recipe.from_toml(path)
    assert again == recipe
    assert np.array_equal(drumstroke.simulate(again).impacts.t, drumstroke.simulate(recipe).impacts.t)
