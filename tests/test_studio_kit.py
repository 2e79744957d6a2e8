"""The part editor's kit mode over real HTTP: a part played on the whole kit answers what ``drumstroke compose --kit``
writes (its JSON's hits and notes, its CSV read with pandas, its MIDI read with mido, its WAV, its warnings), the
grid's rows are the shipped kit's pieces (read from its TOML), and bad kit inputs are refused naming the field."""

import base64
import io
import json
import tomllib
import wave
from importlib import resources

import mido
import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from _studio import Client
from drumstroke.cli import main
from drumstroke.studio.app import make_studio

GROOVE = "".join(["tempo 110\n"] + [f"{k / 2:g} auto {116 if k % 4 == 0 else 90} auto hihat{':open' * (k == 7)}\n"
                                    for k in range(8)]
                 + ["0 auto 100 auto kick\n", "2 auto 100 auto kick\n", "2.5 auto 90 auto kick\n",
                    "1 auto 116 auto snare\n", "3 auto 116 auto snare\n", "3.75 auto 40 auto snare\n"])
"""A bar of rock groove: the hi-hat's 8ths (the last open), the kick on 1, 3 and 3-and, the snare's backbeat and a
ghost note."""

CLASH = ("tempo 160\n0 auto 100 auto crash\n0 auto 100 auto hihat\n0.25 auto 100 auto floor-tom\n"
         "0.25 auto 100 auto crash\n1 auto 100 auto kick\n1.02 auto 100 auto kick\n")
"""Notes no limb can play: a hi-hat beside a crash with the other hand due on the floor tom, a kick 9 ms after a
kick."""


@pytest.fixture(scope="module")
def client():
    served = make_studio(port=0).start()
    yield Client(served.url)
    served.stop()


def cli(tmp_path, pattern, *options, name="part.pattern"):
    """``drumstroke compose PATTERN --kit --quiet OPTIONS`` run through drumstroke.cli.main."""
    path = tmp_path / name
    path.write_text(pattern)
    assert main(["compose", str(path), "--kit", "--quiet", *options]) == 0
    return path


def file(client, body):
    reply = client.ask("download", body)
    assert reply.status == 200, reply.body[:300]
    return reply.body


def hits_of(planned):
    """Every hit of the plan's lanes, in time order as the JSON lists them: (t, piece, limb, state, note)."""
    rows = [(t, piece, limb, state, note) for piece, lane in planned["lanes"].items()
            for t, limb, state, note in zip(lane["t"], lane["limb"], lane["state"], lane["note"], strict=True)]
    return sorted(rows, key=lambda row: (row[0], row[2]))


def test_a_kit_plan_is_compose_kits_json(client, tmp_path):
    planned = client.answer("plan", {"pattern": GROOVE, "kit": True})
    cli(tmp_path, GROOVE, "--json", str(tmp_path / "cli.json"))
    written = json.loads((tmp_path / "cli.json").read_text())
    assert planned["offset"] == written["offset"]
    assert planned["t_end"] == pytest.approx(written["t_end"] - written["offset"], abs=1e-12)
    got = hits_of(planned)
    assert len(got) == len(written["hits"])
    np.testing.assert_allclose([h[0] for h in got], [h["t"] for h in written["hits"]], rtol=0, atol=1e-12)
    states = {(name, table["keys"]): state for name, piece in written["kit"].items()  # the hi-hat's, by key
              for state, table in piece.get("states", {}).items()}
    assert [(h[1], h[2], h[3], h[4]) for h in got] == [
        (h["piece"], h["limb"], states.get((h["piece"], h["key"])), h["note"]) for h in written["hits"]]
    for h in written["hits"]:  # a hit's level is its striking speed's, dB re 1 m/s
        lane = planned["lanes"][h["piece"]]
        k = next(i for i, (t, limb) in enumerate(zip(lane["t"], lane["limb"])) if t == h["t"] and limb == h["limb"])
        assert lane["level_db"][k] == pytest.approx(20 * np.log10(h["speed"]), abs=1e-9)
    for note, expected in zip(planned["notes"], written["notes"], strict=True):
        assert (note["piece"], note["state"], note["limb"], note["played"]) == (
            expected["piece"], expected["state"], expected["limb"], expected["played"])
        assert note["impact"]["t"] == pytest.approx(expected["impact"], abs=1e-12)
        assert note["impact"]["level_db"] == pytest.approx(expected["impact_level"], abs=1e-12)
    # the lanes: the pieces played, as drum notation stacks them (cymbals over drums, the kick at the bottom)
    assert planned["pieces"] == ["hihat", "snare", "kick"]
    assert planned["problems"] == [] and planned["bars"] == pytest.approx([0.0, 4 * 60 / 110])
    # the marks a drummer writes: the limb's letters, the accents on 116, the ghost, the open hi-hat
    marks = {(n["piece"], n["time"]): n["mark"] for n in planned["notes"]}
    letters = {"right": "R", "left": "L", "right-foot": "RF", "left-foot": "LF"}
    for note in planned["notes"]:
        letter = letters[note["limb"]]
        expected = {116: f"{letter}>", 40: f"({letter})"}.get(note["velocity"], letter)
        assert note["mark"] == expected + (" o" if note["state"] == "open" else "")
    assert marks[("kick", 0.0)] == "RF"
    # every limb's joints, sampled through every hit: each hand's stick at its piece's surface when it strikes
    csv = pd.read_csv(io.BytesIO(file(client, {"pattern": GROOVE, "kit": True, "kind": "csv"})))
    for limb, motion in planned["limbs"].items():
        assert set(motion["joints"]) == {c.split(".")[1] for c in csv.columns if c.startswith(f"{limb}.")
                                         and not c.endswith("velocity")}
        t = np.array(motion["t"]) + planned["offset"]
        for joint, values in motion["joints"].items():  # the CSV's samples where the times meet (its 1 kHz grid)
            on_grid = np.isclose(t * 1000, np.round(t * 1000), atol=1e-6, rtol=0)
            rows = np.round(t[on_grid] * 1000).astype(int)
            rows = rows[rows < len(csv)]
            assert rows.size  # 0 s at least
            np.testing.assert_allclose(np.array(values)[on_grid][:len(rows)], csv[f"{limb}.{joint}"].to_numpy()[rows],
                                       rtol=0, atol=1e-9)


@pytest.mark.parametrize("kind", ["csv", "json", "midi", "wav", "plot", "pattern"])
def test_each_kit_download_is_what_compose_kit_writes(client, tmp_path, kind):
    data = file(client, {"pattern": GROOVE, "kit": True, "kind": kind})
    if kind == "pattern":
        assert data.decode() == GROOVE
        return
    option = {"csv": "--csv", "json": "--json", "midi": "--midi", "wav": "--audio", "plot": "--plot"}[kind]
    ending = {"wav": "wav", "plot": "png", "midi": "mid"}.get(kind, kind)
    cli(tmp_path, GROOVE, option, str(tmp_path / f"cli.{ending}"))
    expected = tmp_path / f"cli.{ending}"
    if kind == "csv":
        got, want = pd.read_csv(io.BytesIO(data)), pd.read_csv(expected)
        assert list(got.columns) == list(want.columns)
        assert "right-foot.theta" in got.columns and "left.yaw" in got.columns
        np.testing.assert_allclose(got.to_numpy(), want.to_numpy(), rtol=0, atol=1e-12)
    elif kind == "json":
        got, want = json.loads(data), json.loads(expected.read_text())
        assert got["hits"] == want["hits"] and got["notes"] == want["notes"] and len(got["notes"]) == 14
    elif kind == "midi":
        got, want = mido.MidiFile(file=io.BytesIO(data)), mido.MidiFile(expected)
        notes = [[(m.note, m.velocity, m.time) for m in track if m.type == "note_on"] for track in got.tracks]
        assert notes == [[(m.note, m.velocity, m.time) for m in track if m.type == "note_on"] for track in want.tracks]
        assert {n for track in notes for n, _, _ in track} >= {35, 38, 42, 46}  # kick, snare, hi-hat closed, open
    elif kind == "wav":
        with wave.open(io.BytesIO(data)) as got, wave.open(str(expected)) as want:
            assert got.getparams() == want.getparams()
            assert got.readframes(got.getnframes()) == want.readframes(want.getnframes())
    else:
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and data == expected.read_bytes()


def test_the_kits_sound_is_compose_kit_audio(client, tmp_path):
    reply = client.ask("audio", {"pattern": GROOVE, "kit": True})
    assert reply.status == 200 and reply.headers["Content-Type"] == "audio/wav"
    cli(tmp_path, GROOVE, "--audio", str(tmp_path / "cli.wav"))
    assert reply.body == (tmp_path / "cli.wav").read_bytes()


def test_notes_left_out_are_compose_kits_warnings_beside_their_notes(client, tmp_path, capsys):
    planned = client.answer("plan", {"pattern": CLASH, "kit": True})
    path = tmp_path / "clash.pattern"
    path.write_text(CLASH)
    capsys.readouterr()
    assert main(["compose", str(path), "--kit", "--verbose", "--json", str(tmp_path / "clash.json")]) == 0
    warned = [line.removeprefix("warning: ") for line in capsys.readouterr().err.splitlines()
              if line.startswith("warning: ")]
    assert len(warned) == 2
    assert [p["message"] for p in planned["problems"]] == warned
    written = json.loads((tmp_path / "clash.json").read_text())["notes"]
    for problem in planned["problems"]:
        note = planned["notes"][problem["note"]]
        assert not note["played"] and note["impact"] is None
        assert problem["reason"] == written[problem["note"]]["reason"]
    assert {planned["notes"][p["note"]]["piece"] for p in planned["problems"]} == {"hihat", "kick"}


def test_the_grids_rows_are_the_shipped_kits_pieces(client):
    kit = tomllib.loads(resources.files("drumstroke.kit").joinpath("default.toml").read_text())
    rows = client.answer("part_options", {})["kit_rows"]
    names = [row["name"] for row in rows]
    assert len(names) == len(set(names))
    assert {row["piece"] for row in rows} == set(kit["pieces"])
    hihat = kit["pieces"]["hihat"]["states"]
    assert {row["state"] for row in rows if row["piece"] == "hihat"} == set(hihat)
    assert names[-2:] == ["kick", "hihat:pedal"] and names.index("hihat") < names.index("snare")
    # each row, written in the piece column, is played on its piece in its state by a limb it allows
    pattern = "tempo 60\n" + "".join(f"{2 * k} auto 100 auto {name}\n" for k, name in enumerate(names))
    planned = client.answer("plan", {"pattern": pattern, "kit": True})
    for row, note in zip(rows, planned["notes"], strict=True):
        assert (note["piece"], note["state"]) == (row["piece"], row["state"])
        assert note["played"] and note["limb"] in row["limbs"]
        assert set(row["limbs"]) <= set(kit["pieces"][row["piece"]]["limbs"])


def midi_of(notes):
    """A MIDI file as base64: ``notes`` (key, velocity) an 8th apart at 120 bpm on channel 10."""
    track = mido.MidiTrack([mido.MetaMessage("set_tempo", tempo=500_000)])
    for k, (key, velocity) in enumerate(notes):
        track += [mido.Message("note_on", channel=9, note=key, velocity=velocity, time=0 if k == 0 else 240),
                  mido.Message("note_off", channel=9, note=key, velocity=0, time=0)]
    song = mido.MidiFile(ticks_per_beat=480)
    song.tracks.append(track)
    data = io.BytesIO()
    song.save(file=data)
    return base64.b64encode(data.getvalue()).decode()


def test_a_midi_file_on_the_kit_is_read_as_compose_kit_reads_it(client, tmp_path):
    data = midi_of([(36, 110), (42, 90), (38, 116), (46, 90), (36, 100), (42, 90), (38, 116),
                    (81, 90)])  # 81 (open triangle): not on the kit, skipped
    (tmp_path / "song.mid").write_bytes(base64.b64decode(data))
    planned = client.answer("plan", {"midi": data, "name": "song.mid", "kit": True})
    assert main(["compose", str(tmp_path / "song.mid"), "--kit", "--quiet", "--json", str(tmp_path / "s.json")]) == 0
    written = json.loads((tmp_path / "s.json").read_text())
    assert [(n["piece"], n["state"], n["limb"]) for n in planned["notes"]] == [
        (n["piece"], n["state"], n["limb"]) for n in written["notes"]]
    np.testing.assert_allclose([h[0] for h in hits_of(planned)], [h["t"] for h in written["hits"]], rtol=0, atol=1e-12)
    assert planned["pattern"].splitlines()[4] == "1.5 auto 90 auto hihat:open"  # its text names the pieces


@pytest.mark.parametrize(("options", "body"), [(["--lead", "left"], {"lead": "left"}),
                                               (["--open-handed"], {"open_handed": True})])
def test_the_hands_options_are_compose_kits(client, tmp_path, options, body):
    planned = client.answer("plan", {"pattern": GROOVE, "kit": True, **body})
    cli(tmp_path, GROOVE, "--json", str(tmp_path / "cli.json"), *options)
    written = json.loads((tmp_path / "cli.json").read_text())
    assert [n["limb"] for n in planned["notes"]] == [n["limb"] for n in written["notes"]]
    plain = client.answer("plan", {"pattern": GROOVE, "kit": True})
    assert [n["limb"] for n in planned["notes"]] != [n["limb"] for n in plain["notes"]]


BAD = [
    ("plan", {"pattern": GROOVE, "kit": "yes"}, "kit"),
    ("plan", {"pattern": GROOVE, "kit": 1}, "kit"),
    ("plan", {"pattern": GROOVE, "lead": "left"}, "lead"),
    ("plan", {"pattern": GROOVE, "kit": True, "lead": "middle"}, "lead"),
    ("plan", {"pattern": GROOVE, "kit": False, "open_handed": True}, "open_handed"),
    ("plan", {"pattern": GROOVE, "kit": True, "open_handed": "no"}, "open_handed"),
    ("plan", {"pattern": "tempo 100\n0 auto 100 auto cowbell\n", "kit": True}, "piece"),
    ("plan", {"pattern": "tempo 100\n0 auto 100 auto hihat:wide\n", "kit": True}, "state"),
    ("plan", {"pattern": "tempo 100\n0 auto 100 auto snare\n1 auto 100 left-foot crash\n", "kit": True},
     "pattern line 3: limb must be a limb that plays 'crash' (right, left), got 'left-foot'"),
    ("plan", {"pattern": "tempo 100\n0 auto 100 auto kick\n200 auto 100 auto kick\n", "kit": True}, "pattern"),
    ("plan", {"pattern": "tempo 1000\n" + "".join(f"{k / 4:g} auto 90 auto hihat\n" for k in range(2001)),
              "kit": True}, "pattern"),
    ("plan", {"pattern": GROOVE, "kit": True, "samples": 10**6}, "samples"),
    ("plan", {"midi": midi_of([(81, 90)]), "name": "triangle.mid", "kit": True}, "midi"),
    ("audio", {"pattern": "tempo 100\n0 auto 300 auto kick\n", "kit": True}, "velocity"),
    ("download", {"pattern": GROOVE, "kit": True, "kind": "ros"}, "kind"),
    ("download", {"pattern": GROOVE, "kind": "plot"}, "kind"),
    ("robot", {"pattern": GROOVE, "kit": True, "controller": "pi"}, "kit"),
]


@pytest.mark.parametrize(("operation", "body", "named"), BAD, ids=[f"{o}-{n}-{k}" for k, (o, _, n) in enumerate(BAD)])
def test_bad_kit_inputs_are_refused_naming_the_field(client, operation, body, named):
    assert named in client.error(operation, body)


KIT_LINES = st.tuples(st.floats(-1, 12, allow_nan=False), st.sampled_from(["auto", "buzz", "double"]),
                      st.integers(-5, 200),
                      st.sampled_from(["auto", "right", "left", "right-foot", "left-foot", "elbow"]),
                      st.sampled_from(["", "kick", "snare", "hihat", "hihat:open", "hihat:pedal", "hihat:half", "crash",
                                       "ride", "ride-bell", "tom1", "tom2", "floor-tom", "kick:open", "cowbell"])).map(
    lambda row: f"{row[0]:g} {row[1]} {row[2]} {row[3]} {row[4]}".strip())
KIT_PATTERNS = st.builds(lambda tempo, lines: f"tempo {tempo:g}\n" + "\n".join(lines) + "\n",
                         st.floats(20, 300, allow_nan=False), st.lists(KIT_LINES, min_size=1, max_size=24))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(KIT_PATTERNS, st.sampled_from(["plan", "audio"]))
def test_any_kit_pattern_is_played_or_refused_in_one_line(client, pattern, operation):
    reply = client.ask(operation, {"pattern": pattern, "kit": True})
    assert reply.status in (200, 400), (reply.status, pattern, reply.body[:300])
    if reply.status == 400:
        assert "\n" not in json.loads(reply.body)["error"]
