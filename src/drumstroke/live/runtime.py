"""The live loop: requests in, the performer planning them, setpoints out on time, a session's record.

A :class:`Runtime` runs a :class:`~drumstroke.live.performer.Performer` against its clock:

- **notes in**: :meth:`Runtime.submit` (thread-safe: OSC and MIDI threads call it) queues a
  :class:`~drumstroke.live.inputs.Request`, stamped with its arrival; :meth:`Runtime.schedule` holds
  requests (a score's) until their arrival time comes. A planner thread gives each to the performer
  (with a :class:`~drumstroke.live.performer.ManualClock` the loop plans them itself: a run faster
  than real time, the same every time). A dropped note is one line for ``report`` and the record.
- **setpoints out**: the loop computes the setpoints a little ahead (up to the performer's ``guard``:
  no note changes those), checks every chunk with :func:`drumstroke.robot.validate.validate` against the
  performer's limits (the last two setpoints sent before it included, so speed, acceleration and jerk
  are checked across chunks), then sends each at its time: it sleeps until just before and spins
  the rest (:data:`SPIN`). Late setpoints (a busy host) are sent at once, in order, none skipped.
- **the end**: :meth:`Runtime.stop` (a signal handler may call it) closes the performer at once: each
  stick finishes the stroke in progress up to its rebound's apex and moves to rest above the head, the
  notes not yet begun given up; the loop ends once they rest, the last setpoints sent (well within a
  second of the stop). :meth:`Runtime.session` is the record: notes in, strokes planned, problems, timing.
- **bounded**: the record keeps at most :data:`PROBLEMS` problem lines, each at most :data:`LINE`
  characters, and the performer's log no dropped note past :data:`~drumstroke.live.performer.ROWS`
  rows (then both count); ``report`` is told at most :data:`LINES` lines a second, the rest counted in one line.
"""

import gc
import heapq
import queue
import sys
import threading
import time
from datetime import UTC, datetime

import numpy as np

from .._checks import check_real, shown
from .._version import __version__
from ..errors import DrumstrokeError, TrajectoryError
from ..robot.validate import validate
from .performer import ROWS, Chunk, ManualClock, SystemClock, settle

SPIN = 2e-4
"""s before a setpoint's time when the loop stops sleeping and spins (sleep wakes up to ~0.1 ms late)."""

AHEAD = 0.01
"""s: how far ahead of the clock setpoints are computed and validated (at most the performer's guard less a
control period), again once half of that is left: a few setpoints a time, so that the cost of a chunk is
spread over several (at 1 kHz, 2 ms computed a period at a time took half again the CPU) and sending
never waits for it; a note's planning has the rest of the guard."""

SWITCH = 5e-5
"""s: Python's thread switch interval while the loop runs (default 5 ms): the loop waits this long at most
for a planning thread to let it run."""

QUEUE = 10_000
"""Requests waiting to be planned at most; more are dropped, each with its line."""

PROBLEMS = 10_000
"""Problem lines kept in the record at most (then counted only)."""

LINE = 300
"""Characters of a problem line kept at most (a longer one is cut, its length said)."""

LINES = 20
"""Problem lines told to ``report`` a second at most; the rest are counted, and said as one line when the next is."""

JOIN = 0.5
"""s the end of a run waits for the planning thread (a long buzz's design may still run: its note is refused)."""


class LiveError(DrumstrokeError):
    """The stream cannot go on: a chunk failed validation (a bug: it is reported with the session's record)."""


class Runtime:
    """Runs a performer on its clock (see the module's description).

    Parameters
    ----------
    performer : Performer
    outputs : sequence of callable(Chunk)
        Called with each chunk of setpoints as it is sent (:mod:`drumstroke.live.outputs`,
        :class:`~drumstroke.live.monitor.RobotMonitor`, or a host's own).
    report : callable(str), optional
        Told each problem (a dropped note, a malformed message) as one line.
    threaded : bool, optional
        Plan in a thread of its own (default: unless the performer's clock is a ManualClock).
    spin : float in [0, 0.01]
        s, see :data:`SPIN`.
    """

    def __init__(self, performer, *, outputs=(), report=None, threaded=None, spin=SPIN):
        self.performer = performer
        self.outputs = list(outputs)
        self._report = report
        self.threaded = not isinstance(performer.clock, ManualClock) if threaded is None else bool(threaded)
        self.spin = check_real("spin", spin, low=0.0, high=0.01, unit="s")
        self.problems = []
        self.problem_count = 0
        self.queue_full = 0  # notes dropped because QUEUE notes waited to be planned
        self._told = threading.Lock()  # problems come from the input, planner and loop threads
        self._said = (0.0, 0)  # the second (monotonic s) lines were last told in, and how many
        self._unsaid = 0  # lines counted, not told
        self._rows_said = False
        self.failure = None
        self._requests = queue.Queue(QUEUE)
        self._scheduled = []
        self._sequence = 0
        self._closing = threading.Event()
        self._close_done = False
        self._aborted = threading.Event()
        self._lateness = np.zeros(10_001, dtype=np.int64)  # µs bins up to 10 ms, then one for later
        self._latest = 0.0
        self.sent = 0
        self.first = self.last = None  # s: the first and last setpoints sent
        performer.warm_up()
        self._restart()
        self.started = datetime.now(UTC).isoformat(timespec="seconds")

    # --- notes in --------------------------------------------------------------------------------------------------

    def submit(self, request):
        """Queue a request to be planned (any thread); one naming a stick the performer does not have is dropped here,
        with its line (it takes no room in the queue or the record)."""
        reason = self.performer.stick_refusal(request.stick)
        if reason:
            self.problem(f"{request.source}: dropped a note: {reason}")
            return
        try:
            self._requests.put_nowait(request)
        except queue.Full:
            with self._told:
                self.queue_full += 1
            self.problem(f"{request.source}: dropped the note at {request.arrived:.6g} s: {QUEUE} notes wait to be "
                         "planned already")

    def schedule(self, requests):
        """Hold requests until their arrival time comes on the clock (a score's notes)."""
        for request in requests:
            check_real("request.arrived", request.arrived, low=-1e9, high=1e9, unit="s")
            heapq.heappush(self._scheduled, (request.arrived, self._sequence, request))
            self._sequence += 1

    def problem(self, line):
        """Record a problem and tell ``report`` (any thread; one line at a time; see the module for the bounds)."""
        if len(line) > LINE:
            line = f"{line[:LINE]}... ({len(line)} characters)"
        with self._told:
            self.problem_count += 1
            if len(self.problems) < PROBLEMS:
                self.problems.append(line)
            if self._report is None:
                return
            second, told = self._said
            now = time.monotonic()
            if now - second >= 1.0:
                self._say_unsaid()
                second, told = now, 0
            if told < LINES:
                self._report(line)
                told += 1
            else:
                self._unsaid += 1
            self._said = (second, told)

    def _say_unsaid(self):
        """Tell ``report`` how many problems it was not told (holding the lock)."""
        if self._unsaid:
            self._report(f"... and {self._unsaid} more problem(s) not shown (over {LINES} a second; the record's "
                         f"problem_count counts every one)")
            self._unsaid = 0

    def _plan(self, request):
        try:
            outcome = self.performer.note(request.stick, request.velocity, at=request.at, stroke=request.stroke,
                                          duration=request.duration, arrived=request.arrived, piece=request.piece,
                                          key=request.key)
        except DrumstrokeError as error:  # e.g. a host's request that arrived at no time
            self.problem(f"{request.source}: dropped a note: {error}")
            return
        except Exception as error:  # noqa: BLE001 - the planning thread must outlive a bug: it is on the record
            self.problem(f"{request.source}: dropped a note: internal error {type(error).__name__}: {error} (a bug: "
                         "please report it with the session's record)")
            return
        if not outcome.planned:
            where = "" if request.piece is None else f" ({shown(request.piece)})"
            self.problem(f"{request.source}: dropped the note at {outcome.note.at:.6g} s{where} on "
                         f"{shown(request.stick)}: {outcome.reason}")
        if self.performer.unrecorded and not self._rows_said and self._report is not None:
            self._rows_said = True  # said once, not a problem of its own: each note dropped is one already
            with self._told:
                self._report(f"the record holds {ROWS} notes: later dropped ones are counted (unrecorded), not kept")

    def _planner(self):
        while not self._aborted.is_set():
            try:
                request = self._requests.get(timeout=0.05)
            except queue.Empty:
                continue
            self._plan(request)

    def _due(self, now):
        """Hand on the scheduled requests that have arrived by ``now`` (s)."""
        while self._scheduled and self._scheduled[0][0] <= now and not self._closing.is_set():
            request = heapq.heappop(self._scheduled)[2]
            if self.threaded:
                self.submit(request)
            else:
                self._plan(request)
        if not self.threaded:
            while True:
                try:
                    request = self._requests.get_nowait()
                except queue.Empty:
                    break
                self._plan(request)

    # --- the end ---------------------------------------------------------------------------------------------------

    def stop(self):
        """Close the performer (see the module: the stroke in progress finished, the notes not begun given up); the
        loop ends when the sticks rest; requests still queued are dropped, each with its line.

        Safe from a signal handler: it only raises a flag, which the loop acts on.
        """
        self._closing.set()

    def abort(self):
        """End the loop now, whatever the sticks are doing (a second interrupt). Safe from a signal handler."""
        self._aborted.set()

    def _close(self):
        """Act on :meth:`stop` (in the loop): the performer closes now."""
        if not self._close_done:
            self._close_done = True
            done = self.performer.close()
            if self._report is not None:
                self._report(f"stopping: each stick finishes the stroke in progress, then rests by {done:.6g} s; "
                             f"{self.performer.given_up} planned note(s) not yet begun given up")

    # --- setpoints out ---------------------------------------------------------------------------------------------

    def run(self, *, duration=None):
        """Send setpoints to the outputs until the sticks rest after :meth:`stop` (or ``duration`` s on the clock)."""
        for chunk in self.chunks(duration=duration):
            for output in self.outputs:
                output(chunk)
        return self

    def chunks(self, *, duration=None):
        """The setpoints, a validated :class:`Chunk` at a time, each given at its time: for a host's own loop.

        Stops (closing the performer) at ``duration`` s on the clock, if given; else after :meth:`stop`.
        """
        performer, clock = self.performer, self.performer.clock
        period = 1.0 / performer.rate
        ahead = max(min(AHEAD, performer.guard - period), 0.0)
        switch = sys.getswitchinterval()
        settle()  # what exists now is never scanned again: the collector's pauses stay short while it runs
        planner = None
        if self.threaded:
            sys.setswitchinterval(SWITCH)
            planner = threading.Thread(target=self._planner, name="drumstroke-planner", daemon=True)
            planner.start()
        self._restart()
        pending = None  # validated, not yet sent
        self._tail = None  # the last two setpoints validated
        try:
            while not self._aborted.is_set():
                now = clock.now()
                if duration is not None and now >= duration:
                    self.stop()
                if self._closing.is_set():
                    self._close()
                self._due(now)
                if pending is not None and len(pending):  # first what is due: sent on time
                    due = int(np.searchsorted(pending.t, clock.now() + 1e-9, side="right"))
                    if due:
                        chunk = _part(pending, 0, due)
                        pending = _part(pending, due, len(pending))
                        self._time(chunk.t, clock.now())
                        yield chunk
                        if self._closing.is_set() and performer.closed is not None and performer.done <= chunk.t[-1]:
                            return
                now = clock.now()
                if pending is None or not len(pending) or pending.t[-1] < now + max(period, ahead / 2):  # the next
                    fresh = performer.setpoints(now + ahead)
                    if len(fresh):
                        self._validate(fresh)
                        pending = fresh if pending is None else _join(pending, fresh)
                wake = float(pending.t[0]) if pending is not None and len(pending) else clock.now() + period
                if self._scheduled and not self._closing.is_set():
                    wake = min(wake, self._scheduled[0][0])
                _sleep_until(clock, wake, self.spin)
        finally:
            self._aborted.set()
            if planner is not None:
                planner.join(JOIN)
                sys.setswitchinterval(switch)
            gc.unfreeze()
            if self._report is not None:
                with self._told:
                    self._say_unsaid()

    def _restart(self):
        """Start a system clock from 0 now, if nothing was stamped with it yet (the session starts warmed up)."""
        performer = self.performer
        if isinstance(performer.clock, SystemClock) and performer.sent < 0 and not performer.log \
                and self._requests.empty():
            performer.clock.restart()

    def _validate(self, fresh):
        """Check a chunk for each stick, with the two setpoints before it; raise LiveError if it fails."""
        performer = self.performer
        checked = fresh if self._tail is None else _join(self._tail, fresh)
        self._tail = _part(checked, max(len(checked) - 2, 0), len(checked))
        if len(checked) < 2:
            return
        for j, (stick, (head, limits)) in enumerate(zip(performer.columns, performer.checks())):
            try:
                validate(checked.t, checked.theta[:, j], checked.omega[:, j], rate=performer.rate, head=head,
                         limits=limits, impacts=checked.impacts[j] if checked.impacts else None)
            except TrajectoryError as error:
                what = "stick" if stick in performer.sticks else "joint"
                self.failure = f"the {stick} {what}'s setpoints from {fresh.t[0]:.6g} s failed validation: {error}"
                self.problem(self.failure + " (a bug: please report it with the session's record)")
                raise LiveError(self.failure) from None

    def _time(self, t, now):
        """Count how late each setpoint was sent (µs bins)."""
        late = np.clip(np.round((now - t) * 1e6), 0, len(self._lateness) - 1).astype(np.int64)
        np.add.at(self._lateness, late, 1)
        self._latest = max(self._latest, float(now - t[0]))
        self.sent += len(t)
        self.first = float(t[0]) if self.first is None else self.first
        self.last = float(t[-1])

    # --- the record ------------------------------------------------------------------------------------------------

    def timing(self):
        """How late the setpoints were sent (ms: median, p99, largest) and how long notes took to plan (ms)."""
        counts = self._lateness
        total = counts.sum()

        def quantile(q):
            return float(np.searchsorted(np.cumsum(counts), q * total) / 1e3) if total else None

        log = list(self.performer.log)
        planned = np.array([o.compute for o in log if o.planned]) * 1e3
        dropped = np.array([o.compute for o in log if not o.planned]) * 1e3
        return {"setpoints": int(total), "lateness_ms": {"median": quantile(0.5), "p99": quantile(0.99),
                                                          "max": self._latest * 1e3 if total else None},
                "late_over_1ms": int(counts[1001:].sum()),
                "planning_ms": _stats(planned), "dropping_ms": _stats(dropped)}

    def session(self, **extra):
        """The session's record: the performer's options, every note and what became of it, problems, timing."""
        p = self.performer
        record = {
            "drumstroke": __version__, "started": self.started, "clock": "s since the session started (monotonic)",
            **p.options(),
            "closed": p.closed, "done": p.done if p.closed is not None else None, "failure": self.failure,
            "sent": {"count": self.sent, "first": self.first, "last": self.last},
            "given_up": p.given_up, "notes": [o.to_dict() for o in list(p.log)], "unrecorded": p.unrecorded,
            "problems": list(self.problems), "problem_count": self.problem_count, "queue_full": self.queue_full,
            "timing": self.timing()}
        record.update(extra)
        return record


def _stats(values):
    if not len(values):
        return None
    return {"median": float(np.median(values)), "p99": float(np.percentile(values, 99)), "max": float(values.max())}


def _part(chunk, first, last):
    """Setpoints first to last (excluded), with the impacts in their steps and the one into the first."""
    low = chunk.t[first - 1] if first > 0 else -np.inf
    high = chunk.t[last - 1] if last > first else -np.inf
    return Chunk(chunk.t[first:last], chunk.theta[first:last], chunk.omega[first:last], chunk.alpha[first:last],
                 chunk.sticks, tuple(times[(times >= low) & (times <= high)] for times in chunk.impacts))


def _join(a, b):
    impacts = tuple(np.concatenate(pair) for pair in zip(a.impacts, b.impacts))
    return Chunk(*(np.concatenate((getattr(a, name), getattr(b, name))) for name in ("t", "theta", "omega", "alpha")),
                 a.sticks, impacts)


def _sleep_until(clock, t, spin):
    """Wait until ``t`` on the clock: a manual clock is set there; a system clock sleeps, then spins the last ``spin`` s."""
    if isinstance(clock, ManualClock):
        clock.set(max(t, clock.now()))
        return
    while True:
        left = t - clock.now()
        if left <= 0.0:
            return
        if left > spin:
            time.sleep(left - spin)
        # else spin: the interpreter still hands a waiting thread the GIL every switch interval, while a sleep,
        # even of 0 s, may give the core to another process for a whole time slice



def replay_session(session, *, until=None):
    """The setpoints of a session, computed again offline from its record (a dict, or the path of its JSON).

    Parameters
    ----------
    session : dict or str or Path
        :meth:`Runtime.session`'s record, or the file ``drumstroke live --log`` wrote.
    until : float, optional
        s on the session's clock; default the last setpoint it sent.

    Returns
    -------
    Chunk
        From the session's first setpoint (t = 0), exactly as it sent them.
    """
    from ..design import ForceRange, Setup
    from ..formats.json import read_json
    from ..palette.motion import Limits
    from .performer import LiveNote, Outcome, Performer

    where = "session record"
    if not isinstance(session, dict):
        where = f"session record {str(session)!r}"
        session = read_json(session, "session record")
    try:
        check_keys = ("sticks", "model", "rate", "latency", "guard", "closest", "rest", "cor", "forces", "limits",
                      "notes", "closed", "sent")
        missing = [key for key in check_keys if key not in session]
        if missing:
            raise DrumstrokeError(f"it has no {', '.join(missing)}")
        forces = session["forces"]
        limits = Limits.from_dict(session["limits"])
        setup = Setup(model=session["model"], cor=session["cor"], forces=ForceRange(forces["low"], forces["high"]),
                      limits=limits, moves=limits)
        options = {"setup": setup, "rate": session["rate"], "latency": session["latency"], "guard": session["guard"],
                   "closest": session["closest"], "rest": session["rest"], "horizon": session.get("horizon")}
        performer = Performer
        if "kit" in session:  # drumstroke live --kit's
            from ..kit.pieces import Kit
            from .kit import KitPerformer

            performer = KitPerformer
            options |= {"kit": Kit.from_dict(session["kit"]), "lead": session["lead"]}
        else:
            options["sticks"] = tuple(session["sticks"])
        log = []
        for i, row in enumerate(session["notes"]):
            if not isinstance(row, dict) or not isinstance(row.get("planned"), bool):
                raise DrumstrokeError(f"notes[{i}] must be a note's record, got {row!r}")
            if row["planned"]:
                note = LiveNote(float(row["arrived"]), row["stick"], float(row["velocity"]), float(row["at"]),
                                row["stroke"], None if row["duration"] is None else float(row["duration"]),
                                float(row["cut"]), row.get("piece"), row.get("key"))
                log.append(Outcome(note, True))
        closed = session["closed"]
        end = session["sent"]["last"] if until is None else until
        if end is None:
            raise DrumstrokeError("it sent no setpoint: give until")
        return performer.replay(log, until=float(end), closed=None if closed is None else float(closed), **options)
    except (KeyError, TypeError, ValueError, AttributeError, DrumstrokeError) as error:
        raise DrumstrokeError(f"{where} is not a drumstroke live session's: {error}") from None
