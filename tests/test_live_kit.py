"""drumstroke live on a kit: notes on the kit's pieces over OSC (python-osc's client on a real socket) and MIDI (mido's
messages and a MIDI file mido writes), each on its piece with its limb, a hand moved between pieces; every field
validated; a move too slow dropped with its reason. No assertion on timing: a note a starved host planned too late
says so and is left out of the checks."""

import json
import re
import subprocess
import sys
import threading
import time

import mido
import numpy as np
import pandas as pd
import pytest
from pythonosc.udp_client import SimpleUDPClient

from drumstroke.kit.limbs import move_time
from drumstroke.kit.pieces import default_kit
from drumstroke.live import KitPerformer, ManualClock, Performer, Runtime, replay_session
from drumstroke.live.inputs import OscInput, Request, midi_request, osc_request
from drumstroke.robot.validate import validate

KIT = default_kit()
SETUP_HEADS = {p.name: p.stick(KIT.stick).theta_max for p in KIT.pieces if p.hands}
PLACES = {"right": 0, "left": 3}  # each hand's first column (yaw, lift, theta)


def assert_each_note_on_its_piece(record, t, positions):
    """At each planned note's time its limb is there: a hand's positioning joints at its piece's place, its stick on
    the piece's surface; a foot's beater on its head (θ = −φ_head = 0)."""
    columns = record["columns"]
    for note in record["notes"]:
        if not note["planned"]:
            continue
        k = int(np.argmin(np.abs(t - note["at"])))
        limb, piece = note["stick"], KIT.piece(note["piece"])
        if limb in PLACES:
            yaw, lift, theta = (positions[k, columns.index(f"{limb}.{j}")] for j in ("yaw", "lift", "theta"))
            assert (yaw, lift) == (piece.place["yaw"], piece.place["lift"]), note
            assert 0.0 <= theta - SETUP_HEADS[piece.name] < 0.02, note
        else:
            assert abs(positions[k, columns.index(f"{limb}.theta")]) < 0.03, note


def assert_stream_valid_and_replayed(record, t, positions, velocities):
    """Every column within its joint's limits, and the stream equal to the offline performer's for the same notes."""
    for j, name in enumerate(record["columns"]):
        limb, joint = name.rsplit(".", 1)
        if limb in KIT.hands and joint != "theta":
            validate(t, positions[:, j], velocities[:, j], rate=record["rate"], limits=KIT.limbs[limb][joint])
    again = replay_session(record, until=t[-1])
    assert np.array_equal(again.t, t)
    assert np.abs(again.theta - positions).max() <= 1e-9 and np.abs(again.omega - velocities).max() <= 1e-9


def test_osc_kit_notes_are_played_on_their_pieces_by_their_limbs_and_bad_ones_refused():
    performer = KitPerformer(latency=0.4)
    lines, chunks = [], []
    runtime = Runtime(performer, outputs=[chunks.append], report=lines.append)
    osc_in = OscInput("127.0.0.1", 0, submit=runtime.submit, report=runtime.problem, clock=performer.clock).start()
    notes = [("auto", 100, "auto", "hihat"), ("auto", 90, "auto", "snare"), ("auto", 110, "auto", "kick"),
             ("auto", 100, "auto", "floor-tom"), ("auto", 80, "auto", "hihat"), ("left", 90, "auto", "crash"),
             ("left-foot", 70, "auto", "hihat")]
    bad = [(["auto", 90, "auto", "tabla"], "pieces (snare, kick, hihat, tom1, tom2, floor-tom, ride, ride-bell, crash), got 'tabla'"),
           (["auto", 90, "auto", "x" * 5000], "(5000 characters)"),
           (["auto", 300, "auto", "tom1"], "velocity must be a finite number in [1, 127]"),
           (["right", 90, "auto", "kick"], "stick must be a limb that plays kick here (right-foot)"),
           (["auto", 90, "buzz", "kick"], "a foot presses single notes"),
           (["auto", 90, "auto", 1.0, 7], "needs stick velocity [stroke [duration] [piece]]")]

    def play():
        client = SimpleUDPClient("127.0.0.1", osc_in.port)
        time.sleep(0.2)
        for args in notes[:4]:
            client.send_message("/drum/note", list(args))
            time.sleep(0.3)
        for args, _ in bad:
            client.send_message("/drum/note", args)
        for args in notes[4:]:
            client.send_message("/drum/note", list(args))
            time.sleep(0.3)
        client.send_message("/drum/note", ["auto", 90])  # an old message: the snare
        time.sleep(0.6)
        runtime.stop()

    threading.Thread(target=play).start()
    runtime.run()
    osc_in.close()
    record = json.loads(json.dumps(runtime.session()))  # as a log file holds it
    refused = [line for line in runtime.problems if "planned too late" not in line]
    assert len(refused) == len(bad), refused
    for _, reason in bad:  # the input's lines and the planner's come from two threads: in any order
        assert sum(reason in line for line in refused) == 1, (reason, refused)
    assert all(len(line) < 400 for line in refused), refused
    assert len(record["notes"]) == len(notes) + 1 + len(bad) - 2  # every note read, but the two the input refused
    #                                                                 (a name of 5000 characters, a stray argument)
    rows = [row for row in record["notes"] if row["planned"] or "planned too late" in row["reason"]]
    expected = [("hihat", "right"), ("snare", "left"), ("kick", "right-foot"), ("floor-tom", "right"),
                ("hihat", "right"), ("crash", "left"), ("hihat", "left-foot"), ("snare", "left")]
    assert [row["piece"] for row in rows] == [piece for piece, _ in expected]
    if all(row["planned"] for row in rows):  # a note left out changes where the hands are for the next ones
        assert [(row["piece"], row["stick"]) for row in rows] == expected
    by_piece = {(row["piece"], row["stick"]): row for row in rows if row["planned"]}
    if ("floor-tom", "right") in by_piece:  # the right hand left the hi-hat for the floor tom: the move is recorded
        move = by_piece[("floor-tom", "right")]["move"]
        assert (move["from"], move["to"]) == ("hihat", "floor-tom")
        assert move["joints"]["right.yaw"] == [KIT.piece("hihat").place["yaw"], KIT.piece("floor-tom").place["yaw"]]
        assert move["end"] - move["start"] >= move_time(KIT, "right", "hihat", "floor-tom") - 1e-9
    if rows[1]["planned"] and rows[1]["stick"] == "left":
        assert rows[1]["move"] is None  # the left hand starts over the snare
    if rows[-1]["planned"] and rows[5]["planned"] and rows[-1]["stick"] == "left":
        assert (rows[-1]["move"]["from"], rows[-1]["move"]["to"]) == ("crash", "snare")  # back from the crash
    t = np.concatenate([c.t for c in chunks])
    positions, velocities = (np.concatenate([getattr(c, k) for c in chunks]) for k in ("theta", "omega"))
    assert list(chunks[0].sticks) == record["columns"] == [
        "right.yaw", "right.lift", "right.theta", "left.yaw", "left.lift", "left.theta", "right-foot.theta",
        "left-foot.theta"]
    assert_each_note_on_its_piece(record, t, positions)
    assert_stream_valid_and_replayed(record, t, positions, velocities)


def test_an_osc_message_names_its_piece_after_its_stroke_and_duration():
    assert osc_request("/drum/note", ["right", 100, "auto", "tom1"], 0.0).piece == "tom1"
    request = osc_request("/drum/note", ["right", 100, "buzz", 0.2, "tom1"], 0.0)
    assert (request.stroke, request.duration, request.piece) == ("buzz", 0.2, "tom1")
    request = osc_request("/drum/note/at", [1.5, "left-foot", 64, "auto", "hihat"], 0.0)
    assert (request.at, request.stick, request.piece) == (1.5, "left-foot", "hihat")
    assert osc_request("/drum/note", ["right", 100], 0.0).piece is None  # the snare, as before
    assert "needs stick velocity" in osc_request("/drum/note", ["right", 100, "auto", 1.0, 5], 0.0)
    assert "(3006 characters)" in osc_request("/drum/" + "n" * 3000, [], 0.0)


def _midi_file(path):
    """A MIDI file written by mido: channel 10, the kit's keys (and one it does not answer, and one on channel 1)."""
    midi = mido.MidiFile(ticks_per_beat=480)
    track = mido.MidiTrack()
    midi.tracks.append(track)
    track.append(mido.MetaMessage("set_tempo", tempo=500_000))  # 120 bpm: a beat 0.5 s
    for key, channel in ((42, 9), (36, 9), (38, 9), (46, 9), (44, 9), (81, 9), (38, 0), (43, 9)):
        track.append(mido.Message("note_on", channel=channel, note=key, velocity=100, time=0 if key == 36 else 240))
        track.append(mido.Message("note_off", channel=channel, note=key, velocity=0, time=0))
    midi.save(path)
    return mido.MidiFile(path)


def test_midi_kit_keys_become_notes_on_their_pieces_and_limbs(tmp_path):
    midi = _midi_file(tmp_path / "kit.mid")
    performer = KitPerformer(latency=0.4, clock=ManualClock())
    runtime = Runtime(performer)
    requests, lines, now = [], [], 0.2
    for message in midi:  # the messages as a port gives them, in time order, each through the MIDI input's reading
        now += message.time
        request = midi_request(message, now, kit=KIT)
        if isinstance(request, Request):
            requests.append(request)
        elif request is not None:
            lines.append(request)
    assert [(r.piece, r.key) for r in requests] == [("hihat", 42), ("kick", 36), ("snare", 38), ("hihat", 46),
                                                    ("hihat", 44), ("floor-tom", 43)]
    assert len(lines) == 2 and "note 81 on channel 10 is not a note of the kit" in lines[0]
    assert "keys 23, 35, 36, 37, 38" in lines[0] and "note 38 on channel 1" in lines[1]
    runtime.schedule(requests)
    chunks = list(runtime.chunks(duration=3.0))
    record = runtime.session()
    assert [(row["piece"], row["key"], row["stick"], row["planned"]) for row in record["notes"]] == [
        ("hihat", 42, "right", True), ("kick", 36, "right-foot", True), ("snare", 38, "left", True),
        ("hihat", 46, "right", True), ("hihat", 44, "left-foot", True), ("floor-tom", 43, "right", True)]
    assert record["notes"][-1]["move"]["from"] == "hihat"
    t = np.concatenate([c.t for c in chunks])
    positions, velocities = (np.concatenate([getattr(c, k) for c in chunks]) for k in ("theta", "omega"))
    assert_each_note_on_its_piece(record, t, positions)
    assert_stream_valid_and_replayed(record, t, positions, velocities)


def test_a_move_too_slow_is_dropped_with_what_it_needs_and_the_hand_stays():
    performer = KitPerformer(clock=ManualClock())
    assert performer.note("right", 100, at=0.3, piece="crash").planned
    slow = performer.note("right", 100, at=0.36, piece="floor-tom", arrived=0.2)
    assert not slow.planned
    found = re.search(r"the right hand's move from 'crash' to 'floor-tom' needs ([\d.]+) s, ([\d.]+) s available",
                      slow.reason)
    assert found, slow.reason
    need, available = map(float, found.groups())
    assert need >= move_time(KIT, "right", "crash", "floor-tom") - 1e-3 and need > available
    performer.clock.set(1.0)
    chunk = performer.setpoints(1.0)
    assert np.all(chunk.theta[-1, :2] == [KIT.piece("crash").place["yaw"], KIT.piece("crash").place["lift"]])
    assert "too soon" in performer.note("left-foot", 90, at=0.9, piece="hihat", arrived=1.0).reason


def test_without_a_kit_the_snare_is_the_only_piece():
    performer = Performer(clock=ManualClock())
    assert performer.note("right", 100, piece="snare").planned
    assert performer.note("left", 100, piece="tom1").reason.startswith("piece must be snare")


def test_the_command_plays_a_midi_file_on_the_kit_and_names_every_joint(tmp_path):
    _midi_file(tmp_path / "kit.mid")
    log = tmp_path / "session.json"
    done = subprocess.run([sys.executable, "-m", "drumstroke", "live", "--kit", "--score", tmp_path / "kit.mid",
                           "--latency", "400", "--csv", "--log", log], capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    frame = pd.read_csv(pd.io.common.StringIO(done.stdout))
    record = json.loads(log.read_text())
    names = record["columns"]
    assert list(frame.columns) == ["t", *names, *(f"{n}.velocity" for n in names), *(f"{n}.acceleration" for n in names)]
    assert [(row["piece"], row["key"]) for row in record["notes"]] == [  # key 81 is none of the kit's, key 38
        ("hihat", 42), ("kick", 36), ("snare", 38), ("hihat", 46), ("hihat", 44), ("floor-tom", 43)]  # on channel 1
    t = frame["t"].to_numpy()
    positions = frame[names].to_numpy()
    assert_each_note_on_its_piece(record, t, positions)
    assert_stream_valid_and_replayed(record, t, positions, frame[[f"{n}.velocity" for n in names]].to_numpy())


@pytest.mark.parametrize("args, message", [
    (["--kit", "--score", "x.mid", "--simulate-robot", "simple"], "not --kit"),
    (["--kit", "no-such-kit.toml", "--osc-in", "0", "--csv"], "no-such-kit.toml"),
])
def test_bad_kit_options_end_with_one_line(tmp_path, args, message):
    (tmp_path / "x.mid").write_bytes(b"")
    done = subprocess.run([sys.executable, "-m", "drumstroke", "live", *args, "--log", tmp_path / "s.json"],
                          capture_output=True, text=True, timeout=60, cwd=tmp_path, check=False)
    assert done.returncode == 2 and message in done.stderr and "Traceback" not in done.stderr, done.stderr
