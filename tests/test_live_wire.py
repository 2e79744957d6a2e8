"""drumstroke live over real sockets: python-osc clients send notes, the setpoints come back over UDP (parsed by
python-osc) or as CSV (read by pandas), and equal, sample for sample, the offline performer given the same notes at
the same times; bad input on the wire is dropped with one line each; a flood does not stop the stream.

MIDI: there is no MIDI system on the CI machines (no ALSA sequencer), so no port can carry notes there; the notes
a MIDI port would carry are tested through the score mode (`--score`, the same notes against the clock), MIDI
messages through mido's own message objects, and opening a port for the clear error it gives without one.
"""

import json
import math
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import mido
import numpy as np
import pandas as pd
import pytest
from pythonosc.osc_message_builder import OscMessageBuilder
from pythonosc.osc_packet import OscPacket
from pythonosc.udp_client import SimpleUDPClient

import drumstroke
from drumstroke.errors import ParameterError
from drumstroke.live import ManualClock, Performer, Runtime, replay_session
from drumstroke.live.inputs import MidiInput, OscInput, Request, midi_request, score_requests
from drumstroke.live.monitor import RobotMonitor
from drumstroke.live.outputs import OscOutput
from drumstroke.robot.controllers import controller
from drumstroke.robot.track import track
from drumstroke.robot.validate import validate
from drumstroke.score import read_score

ROOT = Path(__file__).resolve().parent.parent
RUDIMENTS = ROOT / "examples" / "rudiments.pattern"
HEAD = drumstroke.Stick().theta_max


class Receiver:
    """A UDP socket on loopback collecting /drum/setpoint messages (parsed by python-osc) in a thread."""

    def __init__(self):
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.socket.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 8 << 20)
        self.socket.bind(("127.0.0.1", 0))
        self.socket.settimeout(0.2)
        self.port = self.socket.getsockname()[1]
        self.messages = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    def _read(self):
        while not self._stop.is_set():
            try:
                data, _ = self.socket.recvfrom(65535)
            except TimeoutError:
                continue
            for timed in OscPacket(data).messages:
                self.messages.append((timed.message.address, timed.message.params))

    def close(self):
        time.sleep(0.3)  # the last datagrams in flight
        self._stop.set()
        self._thread.join()
        self.socket.close()

    def stream(self, sticks):
        """t and (θ, ω, α) per stick [shape=(n, sticks)] of the setpoints received, in the order sent."""
        assert all(address == "/drum/setpoint" for address, _ in self.messages)
        rows = {stick: [params[1:] for _, params in self.messages if params[0] == stick] for stick in sticks}
        arrays = {stick: np.array(rows[stick], dtype=float) for stick in sticks}
        t = arrays[sticks[0]][:, 0]
        for stick in sticks:
            assert np.array_equal(arrays[stick][:, 0], t)
        return t, *(np.column_stack([arrays[s][:, k] for s in sticks]) for k in (1, 2, 3))


def assert_same_as_offline(t, theta, omega, alpha, record):
    """The stream received is the offline performer's for the session's notes, sample for sample."""
    rate = record["rate"]
    assert t[0] == 0.0 and np.array_equal(t, np.arange(len(t)) / rate)  # every period once, none missing
    offline = replay_session(record, until=t[-1])
    assert np.array_equal(offline.t, t)
    assert np.abs(offline.theta - theta).max() <= 1e-9 and np.abs(offline.omega - omega).max() <= 1e-9
    assert np.abs(offline.alpha - alpha).max() <= 1e-6
    for j in range(theta.shape[1]):
        validate(t, theta[:, j], omega[:, j], rate=rate, head=HEAD)  # continuous, within the joint's limits


def assert_notes_are_heard(t, theta, record):
    """Each planned note has its stick on the head at the setpoint nearest its time."""
    sticks = record["sticks"]
    for note in record["notes"]:
        if note["planned"]:
            k = round(note["at"] * record["rate"])
            if k < len(t):
                assert theta[k, sticks.index(note["stick"])] - HEAD < 0.02, note


def assert_notes_planned_on_time_are_played(record):
    """Every note planned as soon as it arrived (its cut the guard after its arrival) was played: a note is
    dropped for want of time only when a starved host planned it late (each such drop has its line)."""
    if record["timing"]["late_over_1ms"] or any("planned too late" in line for line in record["problems"]):
        return  # a starved host: the stick's motion then depends on which notes it had time for
    for note in record["notes"]:
        on_time = note["cut"] is not None and note["cut"] <= note["arrived"] + record["guard"] + 1e-9
        assert note["planned"] or not on_time, note
    assert sum(note["planned"] for note in record["notes"]) >= len(record["notes"]) / 2, record["problems"]


def live_command(*args):
    return [sys.executable, "-m", "drumstroke", "live", *map(str, args)]


# --- OSC in, OSC out, in one process ---------------------------------------------------------------------------

def test_osc_notes_in_give_the_offline_performers_setpoints_out():
    performer = Performer()
    lines = []
    runtime = Runtime(performer, report=lines.append)
    receiver = Receiver()
    runtime.outputs.append(OscOutput("127.0.0.1", receiver.port))
    osc_in = OscInput("127.0.0.1", 0, submit=runtime.submit, report=runtime.problem, clock=performer.clock).start()
    groove = [("right", 100), ("left", 60), ("right", 120), ("left", 80), ("auto", 90), ("right", 40),
              ("left", 100), ("auto", 70)]

    def play():
        client = SimpleUDPClient("127.0.0.1", osc_in.port)
        time.sleep(0.2)
        for stick, velocity in groove:
            client.send_message("/drum/note", [stick, velocity])
            time.sleep(0.15)
        client.send_message("/drum/note", ["left", 90, "buzz", 0.2])
        time.sleep(0.1)
        client.send_message("/drum/note/at", [performer.clock.now() + 0.3, "right", 110])
        time.sleep(0.5)
        runtime.stop()

    threading.Thread(target=play).start()
    runtime.run()
    osc_in.close()
    receiver.close()
    record = json.loads(json.dumps(runtime.session()))  # as a log file holds it
    t, theta, omega, alpha = receiver.stream(performer.sticks)
    assert len(t) == record["sent"]["count"] and t[-1] == record["sent"]["last"]
    assert_same_as_offline(t, theta, omega, alpha, record)
    assert len(record["notes"]) == len(groove) + 2, lines
    assert_notes_planned_on_time_are_played(record)
    assert_notes_are_heard(t, theta, record)
    assert np.allclose(theta[-1], performer.rest) and np.all(omega[-1] == 0.0)  # at rest at the end


# --- bad input on the wire ----------------------------------------------------------------------------------------

def _message(address, *args):
    builder = OscMessageBuilder(address=address)
    for arg in args:
        builder.add_arg(arg)
    return builder.build().dgram


BAD = [
    (_message("/drum/nope", "right", 100), "unknown address"),
    (_message("/drum/note", "right", "loud"), "velocity must be a number"),
    (_message("/drum/note", 3, 100), "stick must be a name"),
    (_message("/drum/note", "right", float("nan")), "velocity must be a number"),
    (_message("/drum/note", "right", float("inf")), "velocity must be a number"),
    (_message("/drum/note", "right", 200), "velocity must be a finite number in [1, 127]"),
    (_message("/drum/note", "right", 0), "velocity must be a finite number in [1, 127]"),
    (_message("/drum/note", "middle", 100), "stick must be one of right, left, auto"),
    (_message("/drum/note", "right", 100, "flam"), "stroke must be one of auto, buzz"),
    (_message("/drum/note", "right", 100, "buzz", -1.0), "duration must be"),
    (_message("/drum/note", "right"), "needs stick velocity"),
    (_message("/drum/note", "right", 100, "auto", 1.0, 5), "needs stick velocity"),
    (_message("/drum/note/at"), "needs time stick velocity"),
    (_message("/drum/note/at", "soon", "right", 100), "time must be a number"),
    (_message("/drum/note/at", 0.001, "right", 100), "too soon"),  # a note in the past
    (b"\x00\x01\x02 not OSC at all", "not an OSC packet"),
    (b"/drum/note\x00\x00,si\x00", "not an OSC packet"),  # a message cut short
]


def test_bad_input_on_the_wire_is_dropped_with_one_line_each_and_the_stream_keeps_its_rate():
    performer = Performer()
    runtime = Runtime(performer)
    receiver = Receiver()
    runtime.outputs.append(OscOutput("127.0.0.1", receiver.port))
    osc_in = OscInput("127.0.0.1", 0, submit=runtime.submit, report=runtime.problem, clock=performer.clock).start()

    def play():
        sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        time.sleep(0.2)
        for datagram, _ in BAD:
            sender.sendto(datagram, ("127.0.0.1", osc_in.port))
            time.sleep(0.03)
        sender.sendto(_message("/drum/note", "right", 100), ("127.0.0.1", osc_in.port))  # and a good one
        time.sleep(0.4)
        runtime.stop()

    threading.Thread(target=play).start()
    runtime.run()
    osc_in.close()
    receiver.close()
    # a host starved of the processor (a pause of the test process) may plan the good note too late: it is then
    # dropped with its own line, which is not a line about bad input
    starved = [line for line in runtime.problems if "planned too late" in line]
    bad = [line for line in runtime.problems if line not in starved]
    assert len(bad) == len(BAD) and len(runtime.problems) == runtime.problem_count
    for line, (_, reason) in zip(bad, BAD):
        assert reason in line, (line, reason)
    assert [note.planned for note in performer.log].count(True) == 1 - len(starved)
    t, theta, omega, alpha = receiver.stream(performer.sticks)
    assert_same_as_offline(t, theta, omega, alpha, runtime.session())


def test_a_flood_of_10000_notes_a_second_for_5_s_loses_no_setpoint(tmp_path):
    """The command under a flood: every note dropped is one line of the record, the stream keeps its rate."""
    receiver = Receiver()
    log = tmp_path / "flood.json"
    process = subprocess.Popen(live_command("--osc-in", "127.0.0.1:0", "--osc-out", f"127.0.0.1:{receiver.port}",
                                            "--duration", 7, "--quiet", "--log", log),
                               stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    port = int(process.stderr.readline().rsplit(":", 1)[1])  # "listening for OSC notes on 127.0.0.1:PORT"
    client = SimpleUDPClient("127.0.0.1", port)
    sent, start = 0, time.monotonic()
    while time.monotonic() - start < 5.0:
        due = int((time.monotonic() - start) * 10_000)
        while sent < due:
            client.send_message("/drum/note", ["right" if sent % 2 else "auto", 1 + sent % 127])
            sent += 1
        time.sleep(0.001)
    assert process.wait(timeout=60) == 0, process.stderr.read()
    receiver.close()
    record = json.loads(log.read_text())
    assert sent >= 45_000
    notes, planned = record["notes"], sum(note["planned"] for note in record["notes"])
    dropped_unplanned = record["problem_count"]
    # each note the runtime read is in the record, planned or dropped with its line (past the record's rows, counted:
    # unrecorded; a datagram the system dropped before it was read never arrived)
    assert len(notes) - planned + record["unrecorded"] + record["queue_full"] == dropped_unplanned
    assert len(notes) > 10_000
    # notes are planned, unless the host was starved of the processor throughout: then each was planned too late
    # or found the planner's queue full, and said so
    assert 0 < planned or record["problems"] and all("planned too late" in line or "wait to be planned" in line
                                                     for line in record["problems"]), record["problems"][:5]
    t, theta, omega, alpha = receiver.stream(record["sticks"])
    assert len(t) == record["sent"]["count"] and t[-1] >= 7.0
    assert_same_as_offline(t, theta, omega, alpha, record)


# --- the command: a score against the clock, CSV out, signals ----------------------------------------------------

def test_a_score_played_live_to_csv_is_the_offline_performers_stream(tmp_path):
    log = tmp_path / "session.json"
    done = subprocess.run(live_command("--score", RUDIMENTS, "--csv", "--log", log), capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    frame = pd.read_csv(pd.io.common.StringIO(done.stdout))
    assert list(frame.columns) == ["t", "theta_right", "omega_right", "alpha_right", "theta_left", "omega_left",
                                   "alpha_left"]
    record = json.loads(log.read_text())
    t = frame["t"].to_numpy()
    theta, omega, alpha = (frame[[f"{k}_right", f"{k}_left"]].to_numpy() for k in ("theta", "omega", "alpha"))
    assert_same_as_offline(t, theta, omega, alpha, record)
    score = read_score(RUDIMENTS)
    assert [note["at"] for note in record["notes"]] == pytest.approx([1.0 + n.time + 0.05 for n in score.notes])
    assert_notes_planned_on_time_are_played(record)
    assert_notes_are_heard(t, theta, record)
    played = sum(note["planned"] for note in record["notes"])
    assert f"played {played} of {len(score.notes)} notes" in done.stderr


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_brings_the_sticks_to_rest_and_writes_the_record(tmp_path, sig):
    log = tmp_path / "session.json"
    process = subprocess.Popen(live_command("--osc-in", "127.0.0.1:0", "--csv", "--log", log),
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    port = int(process.stderr.readline().rsplit(":", 1)[1])
    client = SimpleUDPClient("127.0.0.1", port)
    time.sleep(0.3)
    for velocity in (120, 60, 100):
        client.send_message("/drum/note", ["auto", velocity])
        time.sleep(0.1)
    process.send_signal(sig)  # at once: a note's stroke is still in flight
    out, err = process.communicate(timeout=60)
    assert process.returncode == 0, err
    assert "stopping: each stick finishes the stroke in progress, then rests" in err
    record = json.loads(log.read_text())
    frame = pd.read_csv(pd.io.common.StringIO(out))
    assert len(frame) == record["sent"]["count"]
    last = frame.iloc[-1]
    assert last["theta_right"] == record["rest"] == last["theta_left"] and last["omega_right"] == 0.0
    assert record["closed"] is not None and record["sent"]["last"] >= record["done"]
    assert len(record["notes"]) == 3
    assert_notes_planned_on_time_are_played(record)
    t = frame["t"].to_numpy()
    theta, omega, alpha = (frame[[f"{k}_right", f"{k}_left"]].to_numpy() for k in ("theta", "omega", "alpha"))
    assert_same_as_offline(t, theta, omega, alpha, record)


def test_a_second_interrupt_stops_at_once_and_still_writes_the_record(tmp_path):
    log = tmp_path / "session.json"
    process = subprocess.Popen(live_command("--osc-in", "127.0.0.1:0", "--csv", "--log", log, "--latency", 5000),
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    port = int(process.stderr.readline().rsplit(":", 1)[1])
    client = SimpleUDPClient("127.0.0.1", port)
    time.sleep(0.3)
    client.send_message("/drum/note", ["right", 90])  # heard 5 s later: the first interrupt gives it up
    time.sleep(0.3)
    process.send_signal(signal.SIGINT)  # the second at once, before the sticks are at rest after the first: another
    process.send_signal(signal.SIGTERM)  # signal, as two of one kind pending together are delivered as one
    out, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    record = json.loads(log.read_text())
    assert record["notes"][0]["planned"] and record["sent"]["last"] < 2.0  # it did not wait for the buzz
    frame = pd.read_csv(pd.io.common.StringIO(out))
    assert len(frame) == record["sent"]["count"] and "Traceback" not in err


@pytest.mark.parametrize("args, message", [
    ([], "give the notes in"),
    (["--score", RUDIMENTS], "give where the setpoints go"),
    (["--osc-in", "127.0.0.1:70000", "--csv"], "port must be an integer in [0, 65535]"),
    (["--osc-out", "localhost", "--score", RUDIMENTS], "must be HOST:PORT"),
    (["--score", RUDIMENTS, "--csv", "--latency", "0"], "--latency"),
    (["--score", RUDIMENTS, "--csv", "--sticks", "right,right"], "sticks must be distinct"),
    (["--score", RUDIMENTS, "--simulate-robot", "simple", "--controller", "impedance"],
     "controller must be one of"),
    (["--midi-in", "no such port", "--csv"], "no such port"),
    (["--osc-in", "256.1.1.1:9000", "--csv"], "cannot listen for OSC on 256.1.1.1:9000"),
])
def test_bad_options_end_with_one_line_and_status_2(tmp_path, args, message):
    done = subprocess.run(live_command(*args, "--log", tmp_path / "s.json"), capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 2, done.stderr
    assert message in done.stderr and "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "s.json").exists()


# --- MIDI -------------------------------------------------------------------------------------------------------

def test_midi_messages_become_notes_on_the_drum_maps_snare_keys():
    snare = mido.Message("note_on", channel=9, note=38, velocity=100)
    request = midi_request(snare, 1.5)
    assert (request.arrived, request.stick, request.velocity, request.at, request.stroke) == (1.5, "auto", 100.0,
                                                                                              None, "auto")
    assert midi_request(mido.Message("note_on", channel=9, note=37, velocity=20), 0.0).velocity == 20.0
    assert midi_request(mido.Message("note_off", channel=9, note=38), 0.0) is None
    assert midi_request(mido.Message("note_on", channel=9, note=38, velocity=0), 0.0) is None  # a note-off
    assert midi_request(mido.Message("clock"), 0.0) is None
    assert midi_request(mido.Message("control_change", channel=9, control=7, value=3), 0.0) is None
    assert "note 36 on channel 10 is not a snare note" in midi_request(
        mido.Message("note_on", channel=9, note=36, velocity=100), 0.0)
    assert "note 38 on channel 1 is not a snare note" in midi_request(
        mido.Message("note_on", channel=0, note=38, velocity=100), 0.0)


def test_opening_a_midi_port_that_is_not_there_names_it():
    with pytest.raises(ParameterError, match="no such port"):
        MidiInput("no such port", submit=print, report=print, clock=ManualClock())


# --- in a host's own loop, faster than real time ------------------------------------------------------------------

def test_a_host_iterates_the_chunks_on_a_manual_clock():
    performer = Performer(clock=ManualClock())
    runtime = Runtime(performer)
    requests, dropped = score_requests(read_score(RUDIMENTS), count_in=0.5)
    assert not dropped
    runtime.schedule(requests)
    chunks = list(runtime.chunks(duration=requests[-1].arrived + 1.0))
    t = np.concatenate([c.t for c in chunks])
    assert np.array_equal(t, np.arange(len(t)) / performer.rate)
    assert all(o.planned for o in performer.log), [o.reason for o in performer.log]
    theta = np.concatenate([c.theta for c in chunks])
    again = Performer.replay(performer.log, until=t[-1], closed=performer.closed)
    assert np.array_equal(again.theta, theta)  # no thread, no socket: identical


@pytest.mark.parametrize("engine", ["simple", "mujoco"])
def test_the_simulated_robot_tells_the_onsets_an_offline_track_of_the_stream_finds(engine):
    performer = Performer(clock=ManualClock())
    told = []
    robot = RobotMonitor(performer, engine=engine, report=told.append)
    chunks = []
    runtime = Runtime(performer, outputs=[robot, chunks.append])
    runtime.schedule([Request(0.2 + 0.2 * i, "auto", velocity, source="test") for i, velocity in
                      enumerate((100, 60, 120, 90, 40, 127))])
    runtime.run(duration=1.6)
    robot.close()
    summary = robot.summary()
    assert summary["notes"] == 6 == len(told) and summary["onsets"] == 6 and summary["within_5ms"] == 6
    # the same loop stepped offline over the same stream finds the same contacts
    t = np.concatenate([c.t for c in chunks])
    j = performer.sticks.index("right")
    stream = drumstroke.Trajectory.from_samples(t, np.concatenate([c.theta[:, j] for c in chunks]),
                                                np.concatenate([c.omega[:, j] for c in chunks]),
                                                alpha=np.concatenate([c.alpha[:, j] for c in chunks]),
                                                rate=performer.rate, theta_max=HEAD)
    played = track(stream, controller("pid-ff"), engine=engine, cor=performer.setup.cor)
    live = robot._loops["right"].joint.contacts().t
    assert np.allclose(played.onsets, live, atol=1e-12)
    right = [onset for t0, stick, onset in robot.onsets if stick == "right"]
    assert all(math.isfinite(onset) for onset in right)


def test_over_a_long_stream_the_robot_tells_each_note_the_contact_nearest_it():
    """40 notes on both sticks over 10 s: each told the contact nearest it of all the stick's contacts.

    The monitor looks only at the contacts late enough for a note still to come, and its loops keep
    no per-period log (a live robot plays for hours): what it tells is what a search of every
    contact finds.
    """
    performer = Performer(clock=ManualClock())
    robot = RobotMonitor(performer)
    runtime = Runtime(performer, outputs=[robot])
    rng = np.random.default_rng(3)
    runtime.schedule([Request(0.3 + 0.24 * i, "auto", int(v), source="test") for i, v in
                      enumerate(rng.integers(30, 128, 40))])
    runtime.run(duration=10.3)
    robot.close()
    planned = [(t, o.note.stick) for o in performer.log if o.planned for t, _ in o.impacts]
    assert len(planned) == 40 and {stick for _, stick in planned} == {"right", "left"}
    assert sorted((t, stick) for t, stick, _ in robot.onsets) == sorted(planned)
    for t, stick, onset in robot.onsets:
        every = robot._loops[stick].joint.contacts().t
        assert onset == every[np.argmin(np.abs(every - t))] and abs(onset - t) <= 0.02  # the monitor's window
    assert robot.summary()["onsets"] == 40


def test_the_session_record_is_json_with_every_note_and_replays_from_its_file(tmp_path):
    performer = Performer(clock=ManualClock())
    runtime = Runtime(performer)
    runtime.schedule([Request(0.1, "right", 100, source="test"), Request(0.101, "right", 100, source="test"),
                      Request(0.3, "left", 999, source="test")])
    chunks = list(runtime.chunks(duration=0.6))
    path = tmp_path / "session.json"
    drumstroke.formats.json.write_json(path, runtime.session())
    record = json.loads(path.read_text())
    assert [note["planned"] for note in record["notes"]] == [True, False, False]
    assert len(record["problems"]) == 2 and "999" in record["problems"][1]
    again = replay_session(path)
    assert np.array_equal(again.theta, np.concatenate([c.theta for c in chunks]))
    with pytest.raises(drumstroke.errors.ParameterError, match="request.arrived"):
        runtime.schedule([Request(float("nan"), "right", 100)])
    runtime.submit(Request(float("inf"), "right", 100, source="host"))  # straight to the planner: a line, no crash
    runtime._due(1.0)
    assert "host: dropped a note: arrived must be" in runtime.problems[-1]
    path.write_text("{not json")
    with pytest.raises(drumstroke.errors.DrumstrokeError, match="session record .* is not readable JSON"):
        replay_session(path)
    path.write_text(json.dumps({"sticks": ["right"]}))
    with pytest.raises(drumstroke.errors.DrumstrokeError, match="not a drumstroke live session's"):
        replay_session(path)
    os.remove(path)
