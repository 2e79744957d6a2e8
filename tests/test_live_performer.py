"""The live performer on a manual clock: notes planned into the running motion, setpoints that never jump, a
session reproduced by its replay, bad notes dropped with their reasons."""

import numpy as np
import pytest

import drumstroke
from drumstroke.dynamics import velocity_to_level
from drumstroke.design import Setup
from drumstroke.live import ManualClock, Performer
from drumstroke.palette.motion import Limits
from drumstroke.robot.validate import validate

HEAD = drumstroke.Stick().theta_max
GROOVE = [(0.0, "right", 100), (0.125, "left", 90), (0.25, "right", 110), (0.3, "right", 60), (0.375, "left", 90),
          (0.5, "right", 110), (0.55, "left", 40), (0.6, "right", 100), (1.0, "right", 30), (1.1, "right", 110),
          (1.15, "left", 80), (1.2, "left", 80), (1.3, "right", 20)]


def perform(notes, *, until, model="paper", step=0.01):
    """Run a performer on a manual clock: the clock advances in ``step`` s, samples are taken as it goes and each
    note is given when its arrival time comes (heard 50 ms later). Returns (performer, setpoints, outcomes)."""
    clock = ManualClock()
    performer = Performer(clock=clock, setup=Setup(model=model, moves=Limits()))
    chunks, outcomes, pending = [], [], sorted(notes)
    t = 0.0
    while t <= until + 1e-12:
        clock.set(t)
        chunks.append(performer.setpoints(t))
        while pending and pending[0][0] <= t + 1e-12:
            _, stick, velocity = pending.pop(0)
            outcomes.append(performer.note(stick, velocity))
        t = round(t + step, 9)
    columns = [np.concatenate([getattr(c, name) for c in chunks]) for name in ("t", "theta", "omega", "alpha")]
    return performer, columns, outcomes


@pytest.mark.parametrize("model", drumstroke.MODELS)
def test_every_note_is_heard_at_its_time_and_level(model):
    performer, (t, theta, omega, alpha), outcomes = perform(GROOVE, until=2.0, model=model)
    assert all(o.planned for o in outcomes), [o.reason for o in outcomes if not o.planned]
    for outcome in outcomes:
        note, made = outcome.note, outcome.design
        assert note.at == pytest.approx(note.arrived + 0.05, abs=1e-12)
        i = int(np.argmin(np.abs(made.impacts.t - note.at)))
        assert made.impacts.t[i] == pytest.approx(note.at, abs=1e-8)
        assert made.impacts.level_db[i] == pytest.approx(velocity_to_level(note.velocity), abs=1e-5)
        # and the stream has the stick on the head there, at the sample nearest the note
        j = performer.sticks.index(note.stick)
        k = round(note.at * performer.rate)
        assert theta[k, j] - HEAD <= np.abs(omega[:, j]).max() / performer.rate + 1e-9
    assert t == pytest.approx(np.arange(len(t)) / performer.rate, abs=1e-12)  # one sample a period, no gap


def test_the_setpoints_never_jump_and_keep_the_joints_limits():
    performer, (t, theta, omega, alpha), _ = perform(GROOVE, until=2.0)
    for j, stick in enumerate(performer.sticks):
        validate(t, theta[:, j], omega[:, j], rate=performer.rate, limits=Limits())  # speed, acceleration, jerk, head
        steps = np.abs(np.diff(theta[:, j]))
        assert np.all(steps <= np.maximum(np.abs(omega[1:, j]), np.abs(omega[:-1, j])) / performer.rate
                      + 0.5 * Limits().max_acceleration / performer.rate**2)
    assert np.all(np.isfinite(alpha)) and np.abs(alpha).max() <= Limits().max_acceleration


def test_a_replay_of_the_log_gives_the_same_setpoints_sample_for_sample():
    performer, (t, theta, omega, alpha), _ = perform(GROOVE, until=2.0, step=0.0037)
    again = Performer.replay(performer.log, until=t[-1])
    assert np.array_equal(again.t, t)
    assert np.abs(again.theta - theta).max() <= 1e-9 and np.abs(again.omega - omega).max() <= 1e-9
    assert np.abs(again.alpha - alpha).max() <= 1e-6


def test_what_was_sent_stays():
    """A note changes the motion only after what was sent: the setpoints up to then are those without it."""
    clock = ManualClock()
    performer = Performer(clock=clock)
    performer.note("right", 100)  # heard at 0.05 s
    clock.set(0.3)
    before = performer.setpoints(0.3)
    outcome = performer.note("right", 120)  # heard at 0.35 s: the motion from 0.306 s may change, not before
    assert outcome.planned and outcome.note.cut == pytest.approx(0.306)
    after = performer.setpoints(0.4)
    assert after.t[0] == pytest.approx(0.301)
    alone = Performer.replay(performer.log[:1], until=0.4)  # the first note only
    both = np.concatenate([before.theta, after.theta])
    assert np.array_equal(both[: 306], alone.theta[: 306])  # up to and including the sample at 0.305 s
    assert np.abs(both[350:] - alone.theta[350:]).max() > 1e-3  # and the new note did change what came after


@pytest.mark.parametrize("args, reason", [
    (("middle", 100), "stick must be one of right, left"),
    (("right", 0), "velocity must be a finite number in [1, 127]"),
    (("right", float("nan")), "velocity must be a finite number"),
    (("right", 100, {"stroke": "flam"}), "stroke must be one of auto, buzz"),
    (("right", 100, {"at": 0.0}), "too soon"),
    (("right", 100, {"duration": 0.2}), "only a buzz has a duration"),
    (("right", 100, {"stroke": "buzz", "duration": -1.0}), "duration must be"),
])
def test_bad_notes_are_dropped_with_their_reason(args, reason):
    performer = Performer(clock=ManualClock(1.0))
    options = args[2] if len(args) > 2 else {}
    outcome = performer.note(*args[:2], **options)
    assert not outcome.planned and reason in outcome.reason
    assert performer.setpoints(1.2).theta[-1].tolist() == [0.0, 0.0]  # the sticks still hold where they were


def test_a_note_before_the_sticks_last_is_dropped_and_a_buzz_makes_its_bounces():
    clock = ManualClock()
    performer = Performer(clock=clock)
    buzzed = performer.note("right", 90, stroke="buzz", duration=0.2)
    assert buzzed.planned
    outcome = performer.note("right", 90, at=0.1)
    assert not outcome.planned and "not after the right stick's last note" in outcome.reason
    made = buzzed.design
    assert len(made.times) == 6 and np.diff(made.times) == pytest.approx(1 / 30)
    logged = performer.log[0]  # the log keeps the impacts, not the stroke
    assert logged.design is None and [t for t, _ in logged.impacts] == pytest.approx(made.times, abs=1e-8)


def test_an_unreachable_note_is_dropped_and_the_motion_goes_on():
    clock = ManualClock()
    performer = Performer(clock=clock, setup=Setup(forces=drumstroke.design.ForceRange(0.0, 50.0), moves=Limits()))  # a weak thumb
    performer.note("right", 30)
    clock.set(0.045)
    outcome = performer.note("right", 127)  # 50 ms after a soft note, as loud as can be
    assert not outcome.planned and outcome.reason
    chunk = performer.setpoints(1.0)
    validate(chunk.t, chunk.theta[:, 0], chunk.omega[:, 0], rate=performer.rate, limits=Limits())


def test_bad_times_are_refused_with_their_name():
    performer = Performer(clock=ManualClock())
    for call, name in ((lambda: performer.setpoints(float("nan")), "until"),
                       (lambda: performer.note("right", 100, arrived=float("inf")), "arrived"),
                       (lambda: performer.note("right", 100, cut=float("nan")), "cut"),
                       (lambda: performer.close(float("nan")), "cut")):
        with pytest.raises(drumstroke.ParameterError, match=name):
            call()
    with pytest.raises(drumstroke.ParameterError, match="latency must be"):
        Performer(latency=0.0)
    with pytest.raises(drumstroke.ParameterError, match="guard must be"):
        Performer(latency=0.05, guard=0.06)
    with pytest.raises(drumstroke.ParameterError, match="sticks must be distinct"):
        Performer(sticks=("right", "right"))
    with pytest.raises(drumstroke.ParameterError, match="rest must be"):
        Performer(rest=-1.0)


def test_a_setup_whose_moves_are_gentler_than_its_joint_is_refused_live():
    with pytest.raises(drumstroke.ParameterError, match="setup.moves must be setup.limits live"):
        Performer(setup=Setup())
    assert Performer(setup=Setup(model="geometry", moves=Limits())).model == "geometry"


def test_the_log_counts_each_rows_bytes_as_the_records_json_writes_them():
    """The count without json's indenting encoder equals the length of the text json_text writes (planned and dropped
    rows, a buzz's many impacts, nested lists and objects, numpy values, empty containers)."""
    from drumstroke.formats.json import json_text
    from drumstroke.live.performer import _json_bytes

    performer, _, _ = perform(GROOVE + [(1.4, "left", 90)], until=2.0)
    performer.note("right", 90, stroke="buzz", duration=0.2)
    performer.note("left", 300)  # dropped: no velocity
    rows = [o.to_dict() for o in performer.log]
    assert any(row["planned"] for row in rows) and any(not row["planned"] for row in rows)
    rows += [{"move": {"from": "hihat", "to": "snare", "joints": {"right.yaw": [0.5, -0.25]}}, "empty": [], "none": {},
              "array": np.array([[1.0, 2.5], [3.0, 4.0]]), "scalar": np.float64(0.1), "count": np.int64(3),
              "nested": [[[]], [{"a": [1, None, True]}]], "text": "a \"quoted\" é"}]
    for row in rows:
        assert _json_bytes(row) == len(json_text(row)), row
    assert performer.recorded == sum(len(json_text(row)) for row in rows[:-1])


def test_a_rows_bytes_counted_from_its_frame_equal_its_json_text():
    """The log's count of a row's bytes from its frame and its values' reprs equals the length of the text json_text
    writes of the row, over a random flow of notes on both models (planned and dropped, buzzes' many impacts, notes
    dropped for values of every kind, a kit's rows with their piece and move)."""
    from drumstroke.formats.json import json_text
    from drumstroke.live import KitPerformer
    from drumstroke.live.performer import _row_bytes

    rng = np.random.default_rng(30)
    outcomes = []
    for model in ("paper", "geometry"):
        clock = ManualClock()
        performer = Performer(clock=clock, setup=Setup(model=model, moves=Limits()))
        for t in np.cumsum(rng.uniform(0.02, 0.3, 150)):
            clock.set(float(t))
            performer.setpoints(clock.now())
            outcomes.append(performer.note(str(rng.choice(["right", "left", "auto"])), int(rng.integers(1, 128)),
                                           stroke=str(rng.choice(["auto", "auto", "buzz"]))))
        now = clock.now()
        for stick, velocity, options in (("left", 300, {}), ("right", 64, {}), ("right", True, {}),
                                         ("drum\u00e9 \"stick\"", 90.0, {}), (3, 90, {}), ("left", float("nan"), {}),
                                         ("left", 90, {"at": float("inf")}), ("left", 90, {"at": now + 10.0}),
                                         ("right", 90, {"stroke": "roll"}), ("left", 90, {"duration": 0.1}),
                                         ("left", 90, {"stroke": "buzz", "duration": 0.3}),
                                         ("right", np.float64(70.0), {"at": np.float64(now + 0.5)})):
            outcomes.append(performer.note(stick, velocity, **options))
    clock = ManualClock()
    kit = KitPerformer(clock=clock)
    for k, piece in enumerate(["snare", "hihat", "snare", "crash", "kick"]):
        clock.set(0.2 * k)
        kit.setpoints(clock.now())
        outcomes.append(kit.note("auto", 100, piece=piece))
    assert sum(o.planned for o in outcomes) > 200 and sum(not o.planned for o in outcomes) > 20
    assert any(len(o.impacts) > 3 for o in outcomes) and any(o.note.piece is not None for o in outcomes)
    for outcome in outcomes:
        assert _row_bytes(outcome) == len(json_text(outcome.to_dict())), outcome


def test_a_live_note_leaves_no_garbage_for_the_collector():
    """Planning a note (its designs tried and refused, its moves, its log row) makes no reference cycle: whatever it
    drops is freed at once, so the garbage collector's pauses stay those of the objects kept."""
    import gc

    clock = ManualClock()
    performer = Performer(clock=clock)
    performer.warm_up()
    gc.collect()
    gc.disable()
    try:
        for k, (t, stick, velocity) in enumerate(GROOVE * 4):
            clock.set(k * 0.11)
            performer.setpoints(clock.now())
            performer.note(stick, velocity)
        clock.set(clock.now() + 1.0)
        late = performer.note("left", 127, at=clock.now() + performer.guard + 0.004)  # no throw fits: Unreachable
        assert not late.planned and late.reason
        assert gc.collect() == 0
    finally:
        gc.enable()


def test_warming_up_freezes_the_process_objects_out_of_the_collections():
    import gc

    Performer(clock=ManualClock()).warm_up()
    try:
        assert gc.get_freeze_count() > 0
    finally:
        gc.unfreeze()


def test_an_outcome_names_the_impacts_of_its_design_on_its_notes():
    performer, _, outcomes = perform(GROOVE, until=2.0)
    buzz = performer.note("right", 90, stroke="buzz", duration=0.2)
    for outcome in [o for o in outcomes if o.planned] + [buzz]:
        made, n = outcome.design, len(outcome.design.times)
        assert outcome.impacts == tuple(zip(made.impacts.t[:n].tolist(), made.impacts.level_db[:n].tolist()))
