"""The studio's stroke and palette operations over real HTTP (http.client against a served studio), each answer
checked against the command line run on the same input, and every bad input answered 400 naming its field."""

import http.client
import io
import json
import tomllib
import wave

import numpy as np
import pandas as pd
import pytest

from _studio import cli
from drumstroke.design.chain import DRIFT
from drumstroke.palette.library import load_library
from drumstroke.presets import PRESETS
from drumstroke.studio.app import make_studio


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    return tmp_path_factory.mktemp("library")


@pytest.fixture(scope="module")
def served(library):
    server = make_studio(port=0, library=library)
    server.start()
    yield server
    server.stop()


def post(server, name, body, *, raw=None, length=None):
    """POST /api/NAME with a JSON body (or ``raw`` bytes; or only a head announcing ``length`` bytes): (status,
    JSON answer or bytes, content type)."""
    host, port = server.url.split("//")[1].rstrip("/").split(":")
    connection = http.client.HTTPConnection(host, int(port), timeout=60)
    try:
        if length is None:
            data = raw if raw is not None else json.dumps(body).encode()
            connection.request("POST", f"/api/{name}", body=data, headers={"Content-Type": "application/json"})
        else:
            connection.putrequest("POST", f"/api/{name}")
            connection.putheader("Content-Type", "application/json")
            connection.putheader("Content-Length", str(length))
            connection.endheaders()
        response = connection.getresponse()
        content = response.read()
        kind = response.getheader("Content-Type", "")
        return response.status, json.loads(content) if kind.startswith("application/json") else content, kind
    finally:
        connection.close()


def ok(server, name, body):
    status, answer, _ = post(server, name, body)
    assert status == 200, answer
    return answer



def impact_times(path):
    return np.array([impact["t"] for impact in json.loads(path.read_text())["impacts"]])


def test_a_simulated_preset_has_the_impacts_drumstroke_simulate_prints(served, tmp_path):
    recipe = ok(served, "presets", {})["presets"][2]["recipe"]  # low-high
    answer = ok(served, "simulate", {"recipe": recipe})
    (tmp_path / "r.toml").write_bytes(post(served, "stroke_file", {"recipe": recipe, "format": "toml"})[1])
    cli("simulate", str(tmp_path / "r.toml"), "--json", str(tmp_path / "r.json"))
    np.testing.assert_allclose(answer["impacts"]["t"], impact_times(tmp_path / "r.json"), rtol=0, atol=1e-12)
    assert tomllib.loads((tmp_path / "r.toml").read_text()) == PRESETS["low-high"].recipe.to_dict()


def test_the_downloads_are_the_files_drumstroke_simulate_writes(served, tmp_path):
    recipe = PRESETS["high-low"].recipe.to_dict()
    (tmp_path / "r.toml").write_bytes(post(served, "stroke_file", {"recipe": recipe, "format": "toml"})[1])
    cli("simulate", str(tmp_path / "r.toml"), "--json", str(tmp_path / "cli.json"))
    cli("simulate", str(tmp_path / "r.toml"), "--csv", str(tmp_path / "data.csv"))
    status, csv, kind = post(served, "stroke_file", {"recipe": recipe, "format": "csv"})
    assert status == 200 and kind.startswith("text/csv")
    assert csv == (tmp_path / "data.csv").read_bytes()
    table = pd.read_csv(io.BytesIO(csv))
    assert list(table.columns) == ["t", "theta", "omega"] and len(table) == 5001
    status, stroke, _ = post(served, "stroke_file", {"recipe": recipe, "format": "json"})
    written = json.loads((tmp_path / "cli.json").read_text())
    assert stroke["impacts"] == written["impacts"] and stroke["rests"] == written["rests"]


def test_the_sound_is_the_wav_drumstroke_simulate_writes(served, tmp_path):
    recipe = PRESETS["free-bounce"].recipe.to_dict()
    stroke = ok(served, "simulate", {"recipe": recipe})
    status, wav, kind = post(served, "stroke_audio", {"times": stroke["impacts"]["t"],
                                                      "tip_speeds": stroke["impacts"]["tip_speed"]})
    assert status == 200 and kind == "audio/wav"
    cli("simulate", "free-bounce", "--audio", str(tmp_path / "cli.wav"))
    assert wav == (tmp_path / "cli.wav").read_bytes()
    with wave.open(io.BytesIO(wav)) as sound:
        assert (sound.getnchannels(), sound.getframerate()) == (1, 48000)


def test_a_designed_diddle_plays_its_notes_and_is_what_drumstroke_design_writes(served, tmp_path):
    answer = ok(served, "design", {"times": [0.5, 0.65], "levels": [0.0, -6.0]})
    design, stroke = answer["design"], answer["stroke"]
    timeline = np.array(stroke["impacts"]["t"][:2]) + design["release"]
    np.testing.assert_allclose(timeline, [0.5, 0.65], rtol=0, atol=DRIFT[0])
    np.testing.assert_allclose(stroke["impacts"]["level_db"][:2], [0.0, -6.0], rtol=0, atol=DRIFT[1])
    cli("design", "--times", "0.5,0.65", "--levels", "0,-6", "--out", str(tmp_path / "d.toml"))
    assert design["recipe"] == tomllib.loads((tmp_path / "d.toml").read_text())


def test_an_unreachable_note_answers_its_reason_and_a_nearest_time_that_can_be_played(served, tmp_path):
    answer = ok(served, "design", {"times": [0.5, 0.52], "levels": [10.0, 10.0]})
    far = answer["unreachable"]
    assert far["note"] == 1 and "force limit" in far["reason"] and far["nearest_time"] > 0.52
    nearer = f"{far['nearest_time'] + 1e-6:.9f}"  # just past the nearest: reachable, as drumstroke design finds
    cli("design", "--times", f"0.5,{nearer}", "--levels", "10,10", "--out", str(tmp_path / "near.toml"))
    assert (tmp_path / "near.toml").exists()


def test_a_post_processed_card_is_the_stroke_drumstroke_simulate_post_processes(served, tmp_path):
    cards = ok(served, "palette", {})["strokes"]
    assert {"single", "double", "finger-pulses"} <= {c["name"] for c in cards}
    answer = ok(served, "transform", {"parts": [{"stroke": {"shipped": "double"},
                                                 "steps": [{"stretch": 1.5}, {"compress": 0.8}]}]})
    cli("simulate", "double", "--stretch", "1.5", "--compress", "0.8", "--json", str(tmp_path / "d.json"))
    np.testing.assert_allclose(answer["impacts"]["t"], impact_times(tmp_path / "d.json"), rtol=0, atol=1e-12)
    joined = ok(served, "transform", {"parts": [{"stroke": {"shipped": "single"}}, {"stroke": {"shipped": "double"}}],
                                      "gap": 0.3})
    assert len(joined["impacts"]["t"]) == 3 and joined["recipe"] is None


def test_a_saved_stroke_is_listed_by_drumstroke_library_list(served, library, tmp_path):
    body = {"name": "slow-double", "category": "double stroke", "description": "the diddle, slower",
            "parts": [{"stroke": {"shipped": "double"}, "steps": [{"stretch": 1.5}]}]}
    assert ok(served, "save", body)["strokes"][-1] == "slow-double"
    listing = cli("library", "list", str(library))
    assert "slow-double" in listing and "double stroke: the diddle, slower" in listing
    assert "whole" in cli("library", "check", str(library))
    cli("simulate", "double", "--stretch", "1.5", "--json", str(tmp_path / "d.json"))
    saved = load_library(library)["slow-double"].trajectory
    np.testing.assert_allclose(saved.impacts.t, impact_times(tmp_path / "d.json"), rtol=0, atol=1e-9)
    status, refused, _ = post(served, "save", body)
    assert status == 400 and "already" in refused["error"]
    assert ok(served, "save", body | {"replace": True, "description": "replaced"})["strokes"] == ["slow-double"]
    assert "double stroke: replaced" in cli("library", "list", str(library))
    cards = ok(served, "palette", {})["strokes"]
    assert [c["name"] for c in cards if c["source"] == "library"] == ["slow-double"]


def test_without_a_library_saving_says_how_to_enable_it():
    server = make_studio(port=0)
    server.start()
    try:
        status, answer, _ = post(server, "save", {"name": "x", "parts": [{"stroke": {"shipped": "double"}}]})
    finally:
        server.stop()
    assert status == 400 and "--library DIR" in answer["error"]


RECIPE = PRESETS["low-high"].recipe.to_dict()
SHIPPED = [{"stroke": {"shipped": "double"}}]

BAD = [
    ("simulate", {"recipe": RECIPE | {"t_end": "long"}}, "t_end"),
    ("simulate", {"recipe": RECIPE | {"t_end": -1.0}}, "t_end"),
    ("simulate", {"recipe": RECIPE | {"t_end": 1e4}}, "t_end"),
    ("simulate", {"recipe": RECIPE | {"cor": 1.5}}, "cor"),
    ("simulate", {"recipe": RECIPE | {"theta0": "up"}}, "theta0"),
    ("simulate", {"recipe": RECIPE | {"force": {"kind": "piecewise-linear", "points": [[0, 1], [1, 2], [0.5, 3]]}}},
     "force.points"),
    ("simulate", {"recipe": RECIPE | {"force": {"kind": "piecewise-linear",
                                                "points": [[i * 1e-3, 1.0] for i in range(2001)]}}}, "recipe"),
    ("simulate", {"recipe": RECIPE | {"force": {"kind": "samples", "file": "/etc/passwd"}}}, "force.kind"),
    ("simulate", {"recipe": RECIPE | {"t_end": 20.0, "force": {"kind": "pulses", "amplitude": 1, "period": 1e-3,
                                                             "duty": 0.5}}},
     "force.period"),
    ("simulate", {"recipe": RECIPE | {"colour": "red"}}, "colour"),
    ("simulate", {"recipe": RECIPE, "speed": 2}, "speed"),
    ("simulate", {"recipe": RECIPE, "rate": "fast"}, "rate"),
    ("simulate", {}, "recipe"),
    ("presets", {"all": True}, "all"),
    ("design", {"times": [0.5, 0.4], "levels": [0, 0]}, "times"),
    ("design", {"times": ["soon"], "levels": [0]}, "times"),
    ("design", {"times": [0.5], "levels": [0, 1]}, "levels"),
    ("design", {"times": [0.5], "levels": [40]}, "levels"),
    ("design", {"times": [-0.5], "levels": [0]}, "times"),
    ("design", {"times": [0.5], "levels": [0], "cor": 1.5}, "cor"),
    ("design", {"times": [0.5], "levels": [0], "end": "drop"}, "end"),
    ("design", {"times": [0.5], "levels": [0], "stick": {"length": "long"}}, "stick.length"),
    ("design", {"times": [0.5], "levels": [0], "stick": {"colour": 1}}, "colour"),
    ("design", {"times": list(np.arange(300) * 0.01 + 0.1), "levels": [0] * 300}, "times"),
    ("design", {"times": [0.5], "levels": [0], "tempo": 90}, "tempo"),
    ("stroke_audio", {"times": [0.1, 0.2], "tip_speeds": [1.0]}, "tip_speeds"),
    ("stroke_audio", {"times": [0.1], "tip_speeds": [-1.0]}, "tip_speeds"),
    ("stroke_audio", {"times": [0.1], "tip_speeds": [1.0], "duration": -1}, "duration"),
    ("stroke_audio", {"times": "0.1", "tip_speeds": [1.0]}, "times"),
    ("stroke_file", {"recipe": RECIPE, "format": "exe"}, "format"),
    ("stroke_file", {"recipe": RECIPE | {"t_end": -2}, "format": "csv"}, "t_end"),
    ("palette", {"folder": "/"}, "folder"),
    ("transform", {"parts": []}, "parts"),
    ("transform", {"parts": [{"stroke": {"shipped": "nonesuch"}}]}, "nonesuch"),
    ("transform", {"parts": [{"stroke": {"file": "/etc/passwd"}}]}, "parts[0].stroke"),
    ("transform", {"parts": [{"stroke": {"shipped": "double"}, "steps": [{"stretch": -2}]}]}, "parts[0].steps[0]"),
    ("transform", {"parts": [{"stroke": {"shipped": "double"}, "steps": [{"stretch": 1e6}]}]}, "parts[0].steps[0]"),
    ("transform", {"parts": [{"stroke": {"shipped": "double"}, "steps": [{"catch": "two"}]}]}, "parts[0].steps[0]"),
    ("transform", {"parts": [{"stroke": {"shipped": "double"}, "steps": [{"spin": 1}]}]}, "parts[0].steps[0]"),
    ("transform", {"parts": SHIPPED * 2, "gap": -1}, "gap"),
    ("transform", {"parts": SHIPPED, "extra": 1}, "extra"),
    ("save", {"name": "../escape", "parts": SHIPPED}, "name"),
    ("save", {"name": "a/b", "parts": SHIPPED}, "name"),
    ("save", {"name": "CamelCase", "parts": SHIPPED}, "name"),
    ("save", {"name": "", "parts": SHIPPED}, "name"),
    ("save", {"name": "x" * 65, "parts": SHIPPED}, "name"),
    ("save", {"name": 7, "parts": SHIPPED}, "name"),
    ("save", {"name": "ok-name", "parts": SHIPPED, "replace": "yes"}, "replace"),
    ("save", {"name": "ok-name", "parts": SHIPPED, "category": "two\nlines"}, "category"),
    ("save", {"name": "joined", "parts": SHIPPED * 2}, "parts"),
]


@pytest.mark.parametrize(("operation", "body", "field"), BAD, ids=[f"{op}-{field}-{i}" for i, (op, _, field)
                                                                    in enumerate(BAD)])
def test_a_bad_input_is_answered_400_naming_its_field(served, operation, body, field):
    status, answer, _ = post(served, operation, body)
    assert status == 400, answer
    assert field in answer["error"] and "\n" not in answer["error"]


@pytest.mark.parametrize("raw", [b'{"recipe": {"t_end": NaN, "force": {"kind": "constant", "value": 1}}}',
                                 b'{"times": [Infinity], "levels": [0]}', b"[1, 2]", b"{not json"])
def test_what_is_not_a_json_object_is_refused_400(served, raw):
    status, answer, _ = post(served, "simulate" if b"recipe" in raw else "design", None, raw=raw)
    assert status == 400 and answer["error"]


def test_a_million_breakpoints_are_refused_by_their_size_before_they_are_read(served):
    size = len(",".join("[0.001,1.0]" for _ in range(10 ** 6)))  # the points alone: some 12 MB
    status, answer, _ = post(served, "simulate", None, length=size)
    assert status == 413 and "bytes" in answer["error"]
