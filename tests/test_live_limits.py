"""drumstroke live's bounds: a horizon, a stop that ends soon, every field of a wire message bounded, the record and
the messages bounded under a flood (the console script over real sockets; benchmarks/live_flood.py floods it for 5
minutes)."""

import json
import signal
import socket
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from pythonosc.udp_client import SimpleUDPClient

import drumstroke
from drumstroke.errors import ParameterError
from drumstroke.live import KitPerformer, ManualClock, Performer, Runtime, replay_session
from drumstroke.live import performer as performer_module
from drumstroke.live import runtime as runtime_module
from drumstroke.live.inputs import MESSAGE, NAME, OscInput, Request, osc_request
from drumstroke.robot.validate import validate

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from live_flood import Child  # the benchmark's own flood, at the suite's scale

HEAD = drumstroke.Stick().theta_max


# --- the horizon ------------------------------------------------------------------------------------------------

def test_a_note_beyond_the_horizon_is_dropped_and_the_horizon_is_an_option():
    performer = Performer(clock=ManualClock())
    assert performer.horizon == 4.0 and Performer(latency=5.0).horizon == 5.0  # at least the latency
    far = performer.note("right", 100, at=3600.0)
    assert not far.planned and "further ahead than the horizon, 4 s" in far.reason
    assert performer.note("right", 100, at=3.9).planned  # within it
    near = Performer(clock=ManualClock(), horizon=0.5)
    assert "horizon, 0.5 s" in near.note("left", 100, at=0.6).reason and near.note("left", 100, at=0.4).planned
    for horizon in (0.01, 61.0, float("nan")):
        with pytest.raises(ParameterError, match="horizon must be"):
            Performer(horizon=horizon)
    with pytest.raises(ParameterError, match="horizon must be"):
        KitPerformer(horizon=0.01)
    runtime = Runtime(near)
    record = runtime.session()
    assert record["horizon"] == 0.5
    near.clock.set(1.0)
    assert np.array_equal(replay_session(record, until=1.0).theta, near.setpoints(1.0).theta)


# --- the stop ---------------------------------------------------------------------------------------------------

def _stream(performer, closing):
    """Setpoints up to ``closing`` (s), the performer closed there, then the rest: t, θ, ω."""
    performer.clock.set(closing)
    before = performer.setpoints()
    done = performer.close()
    after = performer.setpoints(done + 0.01)
    return (np.concatenate([getattr(before, k), getattr(after, k)]) for k in ("t", "theta", "omega"))


@pytest.mark.parametrize("closing", np.arange(0.03, 0.6, 0.047))
def test_a_stop_finishes_the_stroke_in_progress_and_gives_up_the_notes_not_begun(closing):
    performer = Performer(clock=ManualClock())
    performer.note("right", 110)  # heard at 0.05 s
    performer.clock.set(0.02)
    performer.note("left", 80, stroke="buzz", duration=3.0)  # a press roll of 3 s from 0.07 s
    performer.clock.set(0.03)
    ahead = performer.note("right", 90, at=2.0)
    assert ahead.planned
    t, theta, omega = _stream(performer, closing)
    for j in range(2):  # continuous, within the joint's limits, through the stop
        validate(t, theta[:, j], omega[:, j], rate=performer.rate, head=HEAD)
    assert np.all(theta[-1] == performer.rest) and np.all(omega[-1] == 0.0)
    assert performer.done - performer.closed < 0.2  # s on the session's clock: not the 3 s buzz, nor the 2 s note
    buzz_begun = np.any(theta[t >= 0.069, 1] - HEAD < 1e-3)  # its first bounce heard (the rest cut at an apex)
    assert performer.given_up == (1 if buzz_begun else 2)  # and the note at 2 s: its stick never comes down for it
    assert buzz_begun or performer.closed < 0.07
    assert theta[round(0.05 * performer.rate), 0] - HEAD < 0.02  # the note in flight (or played) is heard
    record = Runtime(performer).session()
    assert record["given_up"] == performer.given_up
    again = replay_session(record, until=t[-1])
    assert np.array_equal(again.theta, theta)


def test_a_kit_stops_with_a_hand_moving_and_a_foot_pressing():
    performer = KitPerformer(clock=ManualClock(), latency=0.3)
    runtime = Runtime(performer)
    runtime.schedule([Request(0.1, "auto", 100, source="test", piece="floor-tom"),
                      Request(0.1, "auto", 100, source="test", piece="kick"),
                      Request(0.2, "auto", 100, at=3.0, source="test", piece="crash")])
    chunks = list(runtime.chunks(duration=0.35))  # every chunk validated on the way, per joint
    record = runtime.session()
    assert record["done"] - record["closed"] < 1.0 and record["given_up"] >= 1
    last = chunks[-1]
    assert np.all(last.omega[-1] == 0.0) and record["sent"]["last"] >= record["done"]


@pytest.mark.parametrize("how", ["SIGINT", "SIGTERM", "--duration"])
def test_the_command_stops_soon_with_a_note_an_hour_ahead(tmp_path, how):
    """The issue's case: /drum/note/at 3600 right 100, then a stop; and a note 3 s ahead, given up."""
    options = ("--duration", "3") if how == "--duration" else ()
    child = Child(tmp_path / "session.json", *options)
    client = SimpleUDPClient("127.0.0.1", child.port)
    time.sleep(0.3)
    client.send_message("/drum/note/at", [3600, "right", 100])
    client.send_message("/drum/note/at", [3.2, "left", 100])  # the session's clock: within the horizon
    time.sleep(0.7)
    if how == "--duration":
        err = child.process.stderr.read()
        took, status = None, child.process.wait(timeout=60)
    else:
        took, status, err = child.stop(getattr(signal, how))
    assert status == 0, err
    record = json.loads((tmp_path / "session.json").read_text())
    assert [note["planned"] for note in record["notes"]] == [False, True]
    assert "further ahead than the horizon, 4 s" in record["notes"][0]["reason"]
    assert sum("horizon" in line for line in err.splitlines()) == 1
    assert record["given_up"] == 1 and record["sent"]["last"] - record["closed"] < 1.0  # s, the session's clock
    if took is not None:
        assert took < 5.0  # wall time, generous for a busy machine: about 0.3 s on an idle one (docs/live.md)
    assert record["sent"]["last"] < 3.2  # it did not wait for the note 3 s ahead


# --- the wire ---------------------------------------------------------------------------------------------------

def test_every_field_of_a_message_is_bounded():
    long = "x" * 60_000
    for args in ([long, 100], ["right", 100, long], ["right", 100, "buzz", 0.5, "y" * (NAME + 1)]):
        line = osc_request("/drum/note", args, 0.0)
        assert isinstance(line, str) and f"names must be at most {NAME} characters" in line and len(line) < 200
    assert not isinstance(osc_request("/drum/note", ["r" * NAME, 100], 0.0), str)  # refused later: not a stick
    performer = Performer(clock=ManualClock())
    runtime = Runtime(performer)
    runtime.submit(Request(0.0, "r" * NAME, 100, source="osc"))  # not the session's: refused as it comes
    assert "stick must be one of right, left, auto" in runtime.problems[-1] and runtime._requests.empty()
    assert not performer.log
    runtime.problem("z" * 100_000)
    assert len(runtime.problems[-1]) < runtime_module.LINE + 40 and runtime.problems[-1].endswith("(100000 characters)")


def test_a_large_datagram_is_dropped_unread():
    lines, notes = [], []
    osc_in = OscInput("127.0.0.1", 0, submit=notes.append, report=lines.append, clock=ManualClock()).start()
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sender.sendto(b"/drum/note\x00\x00,si\x00" + b"s" * 60_000, ("127.0.0.1", osc_in.port))
    sender.sendto(b"x" * (MESSAGE + 1), ("127.0.0.1", osc_in.port))
    deadline = time.monotonic() + 30
    while len(lines) < 2 and time.monotonic() < deadline:
        time.sleep(0.01)
    osc_in.close()
    sender.close()
    assert len(lines) == 2 and not notes
    assert "dropped a datagram of 60016 bytes unread" in lines[0] and f"{MESSAGE + 1} bytes" in lines[1]


# --- the record and the messages --------------------------------------------------------------------------------

def test_problems_are_told_at_most_lines_a_second_and_every_one_counted():
    told = []
    runtime = Runtime(Performer(clock=ManualClock()), report=told.append)
    start = time.monotonic()
    for i in range(1000):
        runtime.problem(f"problem {i}")
    elapsed = time.monotonic() - start
    runtime.run(duration=0.01)  # the end of a run tells what was counted
    said = [line for line in told if line.startswith("problem ")]
    counted = [int(line.split()[2]) for line in told if line.startswith("... and ")]
    assert len(said) + sum(counted) == 1000 == runtime.problem_count
    assert len(said) <= runtime_module.LINES * (1 + elapsed)


def test_the_log_keeps_rows_dropped_notes_then_counts(monkeypatch):
    monkeypatch.setattr(performer_module, "ROWS", 5)
    monkeypatch.setattr(runtime_module, "ROWS", 5)
    performer = Performer(clock=ManualClock())
    told = []
    runtime = Runtime(performer, report=told.append)
    runtime.schedule([Request(0.1 + 0.001 * i, "right", 100, source="test") for i in range(20)]
                     + [Request(0.5, "left", 100, source="test")])
    list(runtime.chunks(duration=0.7))
    record = runtime.session()
    planned = [row for row in record["notes"] if row["planned"]]
    assert len(planned) == 2 and len(record["notes"]) == 5 + 1 and record["unrecorded"] == 15  # planned ones kept
    assert sum("the record holds 5 notes" in line for line in told) == 1
    assert record["problem_count"] == 15 + 4  # each note dropped one, kept or not


def test_a_flood_of_maximal_messages_keeps_memory_and_the_record_bounded(tmp_path):
    """The benchmark's flood for N and 10N rounds: the child's resident memory after 10N within 40 MB of it after
    N, the record and stderr under their caps (a 60 KB stick name once held 60 KB a note)."""
    child = Child(tmp_path / "flood.json")
    time.sleep(0.3)
    rounds = child.send(200)
    time.sleep(1.0)
    first = child.rss()
    rounds = child.send(1800, rounds)
    time.sleep(1.0)
    last = child.rss()
    _, status, err = child.stop()
    assert status == 0, err[-2000:]
    assert last - first < 40.0, (first, last)
    record = json.loads((tmp_path / "flood.json").read_text())
    assert record["problem_count"] > runtime_module.PROBLEMS >= len(record["problems"])
    assert all(len(line) <= runtime_module.LINE + 30 for line in record["problems"])
    assert len(record["notes"]) - sum(row["planned"] for row in record["notes"]) <= performer_module.ROWS
    assert (tmp_path / "flood.json").stat().st_size < 50e6
    assert all(len(line) < 400 for line in err.splitlines()) and len(err) < 1e6
