"""The studio's part operations over real HTTP (http.client): what they answer against the command line's files, the
planner's own problems, mido and pandas, and the inputs they refuse (400, naming the field)."""

import base64
import http.client
import io
import json
import urllib.parse
import wave

import mido
import numpy as np
import pandas as pd
import pytest

from drumstroke.cli import main
from drumstroke.design import Setup, Target, plan_stick
from drumstroke.dynamics import velocity_to_level
from drumstroke.formats.ros_json import read_ros_json
from drumstroke.studio.app import make_studio

GROOVE = "".join(["tempo 120\n"] + [f"{k / 2:g} auto {116 if k % 4 == 2 else 100} {'right' if k % 2 == 0 else 'left'}\n"
                                    for k in range(16)])  # 2 bars of 8ths, the hands alternating, accents on 2 and 4
CLOSE = "tempo 60\n0.5 auto 100 right\n0.51 auto 60 right\n0.52 auto 60 right\n1 auto 100 left\n"  # 10 ms apart


@pytest.fixture(scope="module")
def server():
    served = make_studio(port=0).start()
    yield served
    served.stop()


def post(server, name, body, *, raw=None):
    """POST /api/NAME: (status, media type, bytes)."""
    url = urllib.parse.urlsplit(server.url)
    connection = http.client.HTTPConnection(url.hostname, url.port, timeout=60)
    try:
        connection.request("POST", f"/api/{name}", body=raw if raw is not None else json.dumps(body),
                           headers={"Content-Type": "application/json"})
        response = connection.getresponse()
        return response.status, response.getheader("Content-Type"), response.read()
    finally:
        connection.close()


def answer(server, name, body):
    code, media, data = post(server, name, body)
    assert code == 200, data
    return json.loads(data) if media.startswith("application/json") and name != "download" else data


def column(impacts, key):
    """One field of a composition JSON's impacts, as an array."""
    return np.array([impact[key] for impact in impacts])


def cli(tmp_path, pattern, *options):
    path = tmp_path / "part.pattern"
    path.write_text(pattern)
    assert main(["compose", str(path), "--quiet", *options]) == 0
    return path


def test_a_plan_is_the_command_lines_composition(server, tmp_path):
    planned = answer(server, "plan", {"pattern": GROOVE})
    cli(tmp_path, GROOVE, "--json", str(tmp_path / "cli.json"))
    written = json.loads((tmp_path / "cli.json").read_text())
    assert [n["played"] for n in planned["notes"]] == [n["played"] for n in written["notes"]]
    offset = written["offset"]
    assert planned["offset"] == offset
    for stick, impacts in written["impacts"].items():
        np.testing.assert_allclose(planned["sticks"][stick]["impacts"]["t"], column(impacts, "t") - offset,
                                   rtol=0, atol=1e-12)
        np.testing.assert_allclose(planned["sticks"][stick]["impacts"]["level_db"], column(impacts, "level_db"),
                                   rtol=0, atol=1e-12)
    # every note's first impact at its time, each written as a drummer reads it: R, L, R> on 2 and 4
    assert [n["impact"]["t"] for n in planned["notes"]] == pytest.approx([k * 0.25 for k in range(16)], abs=1e-9)
    assert planned["sticking"] == "R L R> L R L R> L | R L R> L R L R> L"
    assert planned["bars"] == pytest.approx([0.0, 2.0, 4.0])
    assert planned["problems"] == []


@pytest.mark.parametrize("kind", ["csv", "midi", "wav", "json", "ros", "pattern"])
def test_each_download_is_what_compose_writes(server, tmp_path, kind):
    data = answer(server, "download", {"pattern": GROOVE, "kind": kind})
    cli(tmp_path, GROOVE, "--csv", str(tmp_path / "cli.csv"), "--json", str(tmp_path / "cli.json"),
        "--midi", str(tmp_path / "cli.mid"), "--audio", str(tmp_path / "cli.wav"))
    if kind == "csv":
        got, expected = pd.read_csv(io.BytesIO(data)), pd.read_csv(tmp_path / "cli.csv")
        assert list(got.columns) == list(expected.columns)
        assert sorted(got.columns) == ["omega_left", "omega_right", "t", "theta_left", "theta_right"]
        np.testing.assert_allclose(got.to_numpy(), expected.to_numpy(), rtol=0, atol=1e-12)
    elif kind == "midi":
        got, expected = mido.MidiFile(file=io.BytesIO(data)), mido.MidiFile(tmp_path / "cli.mid")
        notes = [[(m.note, m.velocity, m.time) for m in track if m.type == "note_on"] for track in got.tracks]
        assert notes == [[(m.note, m.velocity, m.time) for m in track if m.type == "note_on"]
                         for track in expected.tracks]
        assert sum(map(len, notes)) >= 16
    elif kind == "wav":
        with wave.open(io.BytesIO(data)) as got, wave.open(str(tmp_path / "cli.wav")) as expected:
            assert got.getparams() == expected.getparams()
            assert got.readframes(got.getnframes()) == expected.readframes(expected.getnframes())
    elif kind == "json":
        got, expected = json.loads(data), json.loads((tmp_path / "cli.json").read_text())
        assert got["impacts"] == expected["impacts"] and len(got["notes"]) == 16
    elif kind == "ros":
        (tmp_path / "part.ros.json").write_bytes(data)
        ros = read_ros_json(tmp_path / "part.ros.json")
        csv = pd.read_csv(tmp_path / "cli.csv")
        assert sorted(ros.joint_names) == ["left_joint", "right_joint"]
        for k, name in enumerate(ros.joint_names):
            np.testing.assert_array_equal(ros.positions[:, k], csv[f"theta_{name.removesuffix('_joint')}"])
    else:
        assert data.decode() == GROOVE


def test_a_note_left_out_is_reported_beside_it_with_the_planners_nearest(server, tmp_path):
    planned = answer(server, "plan", {"pattern": CLOSE})
    notes = planned["notes"]
    out = [k for k, n in enumerate(notes) if not n["played"]]
    assert out and {p["note"] for p in planned["problems"]} >= set(out)
    path = tmp_path / "close.pattern"
    path.write_text(CLOSE)
    composed = main(["compose", str(path), "--verbose"])
    assert composed == 0
    # the planner's own problems for the right stick's notes, as compose plans them: the nearest time it reports
    targets = [Target.from_velocity(t, v, key=k) for k, (t, v) in enumerate([(0.5, 100), (0.51, 60), (0.52, 60)])]
    problems = {p.key: p for p in plan_stick(targets, setup=Setup()).problems}
    assert problems
    for problem in planned["problems"]:
        note = notes[problem["note"]]
        assert problem["reason"].startswith(note["source"] + ":")
        k = [0.5, 0.51, 0.52].index(note["time"])
        assert problem["nearest_time"] == problems[k].nearest_time
        assert problems[k].reason in problem["reason"]


def test_the_command_lines_warnings_are_the_problems(server, tmp_path, capsys):
    planned = answer(server, "plan", {"pattern": CLOSE})
    path = cli(tmp_path, CLOSE)
    capsys.readouterr()
    main(["compose", str(path), "--verbose"])
    warned = [line.removeprefix(f"warning: {path}") for line in capsys.readouterr().err.splitlines()
              if line.startswith("warning: ")]
    assert warned == [p["reason"].removeprefix("pattern") for p in planned["problems"]]


@pytest.mark.parametrize(("pattern", "note", "says"), [
    ("tempo 100\n0 high-drop 127\n1 tap 127 left\n", 0, "past upright; played at velocity"),  # out of reach
    ("tempo 100\n0 double 127\n0.25 single 100\n", 1, "too soon after 'double'"),  # a library stroke too soon
])
def test_library_strokes_problems_sit_beside_their_notes(server, tmp_path, capsys, pattern, note, says):
    planned = answer(server, "plan", {"pattern": pattern})
    (problem,) = planned["problems"]
    assert problem["note"] == note and says in problem["reason"]
    path = cli(tmp_path, pattern)
    capsys.readouterr()
    main(["compose", str(path), "--verbose"])
    assert capsys.readouterr().err.strip() == f"warning: {path}" + problem["reason"].removeprefix("pattern")
    if "played at velocity" in says:  # the nearest level: the loudest it played, the velocity the reason names
        loudest = int(problem["reason"].split("played at velocity ")[1].split(",")[0])
        assert problem["nearest_level"] == planned["notes"][note]["impact"]["level_db"]
        assert abs(problem["nearest_level"] - velocity_to_level(loudest)) <= 0.5 * (
            velocity_to_level(loudest + 1) - velocity_to_level(loudest))
    else:
        assert problem["nearest_level"] is None


def test_a_rudiment_is_planned_as_drumstroke_rudiment_plays_it(server, tmp_path):
    planned = answer(server, "plan", {"rudiment": "flam-tap", "tempo": 90, "bars": 2})
    assert main(["rudiment", "flam-tap", "--tempo", "90", "--bars", "2", "--json", str(tmp_path / "r.json")]) == 0
    written = json.loads((tmp_path / "r.json").read_text())
    for stick, impacts in written["impacts"].items():
        np.testing.assert_allclose(planned["sticks"][stick]["impacts"]["t"],
                                   column(impacts, "t") - written["offset"], rtol=0, atol=1e-12)
    assert planned["sticking"].split(" | ")[0].split() == ["lR>", "R", "rL>", "L"] * 4
    # its text is the same notes: planned again from the text, the same impacts
    again = answer(server, "plan", {"pattern": planned["pattern"]})
    for stick in written["impacts"]:
        np.testing.assert_allclose(again["sticks"][stick]["impacts"]["t"], planned["sticks"][stick]["impacts"]["t"],
                                   rtol=0, atol=1e-9)


def test_a_midi_file_is_read_as_compose_reads_it(server, tmp_path):
    track = mido.MidiTrack([mido.MetaMessage("set_tempo", tempo=500_000)])
    for k in range(8):
        track += [mido.Message("note_on", channel=9, note=38, velocity=90 + 4 * k, time=0 if k == 0 else 240),
                  mido.Message("note_off", channel=9, note=38, velocity=0, time=0)]
    track.append(mido.Message("note_on", channel=9, note=42, velocity=80, time=10))  # a hi-hat: skipped
    midi = mido.MidiFile(ticks_per_beat=480)
    midi.tracks.append(track)
    midi.save(tmp_path / "song.mid")
    data = base64.b64encode((tmp_path / "song.mid").read_bytes()).decode()
    planned = answer(server, "plan", {"midi": data, "name": "song.mid"})
    assert [n["time"] for n in planned["notes"]] == pytest.approx([k * 0.25 for k in range(8)], abs=1e-12)
    assert [n["velocity"] for n in planned["notes"]] == [90 + 4 * k for k in range(8)]
    assert all(n["source"].startswith("song.mid note 38") for n in planned["notes"])
    got = pd.read_csv(io.BytesIO(answer(server, "download", {"midi": data, "name": "song.mid", "kind": "csv"})))
    assert main(["compose", str(tmp_path / "song.mid"), "--quiet", "--csv", str(tmp_path / "song.csv")]) == 0
    np.testing.assert_allclose(got.to_numpy(), pd.read_csv(tmp_path / "song.csv").to_numpy(), rtol=0, atol=1e-12)


def test_the_robot_keeps_what_drumstroke_robot_track_keeps(server, tmp_path):
    played = answer(server, "robot", {"pattern": GROOVE, "controller": "impedance"})
    cli(tmp_path, GROOVE, "--csv", str(tmp_path / "part.csv"))
    for stick, lane in played["sticks"].items():
        report = tmp_path / f"{stick}.json"
        assert main(["robot", "track", str(tmp_path / "part.csv"), "--stick", stick, "--controller", "impedance",
                     "--report", str(report)]) == 0
        metrics = json.loads(report.read_text())["controllers"][0]["metrics"]
        assert (lane["kept"], lane["total"]) == (metrics["kept"], metrics["reference_onsets"])
        assert sum(lane["onsets"]["kept"]) == lane["kept"] and len(lane["onsets"]["t"]) == lane["total"]


def test_the_options_name_the_palette_and_the_controllers(server):
    options = answer(server, "part_options", {})
    assert "single" in options["strokes"] and options["controllers"] == ["pi", "pid-ff", "impedance"]


BAD = [
    ("plan", {"rudiment": "flam-tap", "tempo": "90"}, "tempo"),
    ("plan", {"rudiment": "flam-tap", "tempo": 0}, "tempo"),
    ("plan", {"rudiment": "flam-tap", "bars": 10**6}, "bars"),
    ("plan", {"rudiment": "paradiddle"}, "rudiment"),
    ("plan", {"pattern": "tempo 0\n0 auto 100\n"}, "tempo"),
    ("plan", {"pattern": "tempo 100\n" + "0 auto 100\n" * 5000}, "pattern"),
    ("plan", {"pattern": GROOVE, "samples": "many"}, "samples"),
    ("plan", {"pattern": GROOVE, "colour": "red"}, "colour"),
    ("plan", {"pattern": GROOVE, "model": "string"}, "model"),
    ("plan", {"pattern": "tempo 100\n200 auto 100\n"}, "pattern"),
    ("plan", {"pattern": 12}, "pattern"),
    ("plan", {"midi": "not base64!", "name": "song.mid"}, "midi"),
    ("plan", {"midi": base64.b64encode(b"RIFF this is no MIDI file").decode()}, "midi"),
    ("plan", {"pattern": GROOVE, "midi": "TVRoZA=="}, "pattern, midi"),
    ("plan", {}, "pattern, midi or rudiment"),
    ("audio", {"pattern": GROOVE, "tempo": 100}, "tempo"),
    ("audio", {"pattern": "tempo 100\n0 auto 300\n"}, "velocity"),
    ("download", {"pattern": GROOVE}, "kind"),
    ("download", {"pattern": GROOVE, "kind": "exe"}, "kind"),
    ("download", {"pattern": GROOVE, "kind": "csv", "extra": 1}, "extra"),
    ("robot", {"pattern": GROOVE}, "controller"),
    ("robot", {"pattern": GROOVE, "controller": "magic"}, "controller"),
    ("robot", {"pattern": "tempo 100\n0 auto 100\n40 auto 100\n", "controller": "pi"}, "pattern: the part lasts"),
    ("robot", {"pattern": GROOVE, "controller": "pi", "samples": 10**9}, "samples"),
    ("rudiments", {"all": True}, "all"),
    ("part_options", {"x": 1}, "x"),
]


@pytest.mark.parametrize(("operation", "body", "named"), BAD, ids=[f"{o}-{n}" for o, _, n in BAD])
def test_bad_inputs_are_refused_naming_the_field(server, operation, body, named):
    code, media, data = post(server, operation, body)
    assert code == 400, data
    assert media.startswith("application/json")
    message = json.loads(data)["error"]
    assert named in message and "\n" not in message
