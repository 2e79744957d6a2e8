"""The stream played on a simulated robot as it is sent: each stick a control loop on a joint, each note's onset told.

:class:`RobotMonitor` is an output (a callable taking a :class:`~drumstroke.live.performer.Chunk`), played in
a thread of its own so that the stream is not held up: every setpoint steps each stick's :class:`~drumstroke.robot.loop.ControlLoop` one control period on the
simple joint or MuJoCo's; once a note's time is past by :data:`SETTLE`, the joint's contact nearest it
(within :data:`WINDOW`) is its onset, told by one line: when, and how far from the note.
"""

import math
import queue
import threading

import numpy as np

from ..errors import ParameterError
from ..robot.controllers import CONTROLLERS, Controller, controller
from ..robot.loop import ControlLoop
from ..robot.plant import Plant, SimpleJoint
from ..robot.track import ENGINES

SETTLE = 0.03
"""s after a note's time before its onset is looked for."""

WINDOW = 0.02
"""s: the farthest a contact may be from its note to be its onset."""


def live_controllers():
    """The controllers that can play a stream as it comes: those that steer by the reference itself.

    (The impedance controller replays each whole flight faster, which needs the flight's end.)"""
    return tuple(name for name, cls in CONTROLLERS.items() if cls.steer is Controller.steer)


class RobotMonitor:
    """Each stick of ``performer`` played by ``control`` on the ``engine``'s joint, as the stream is sent.

    Parameters
    ----------
    performer : Performer
        Its sticks, rate, head, rest angle and notes (its log).
    engine : {"simple", "mujoco"}
    control : str or Controller
        One of :func:`live_controllers` (default "pid-ff").
    plant : Plant, optional
        Default :class:`~drumstroke.robot.plant.Plant`; its head must be the performer's.
    report : callable(str), optional
        Told each note's onset.
    """

    def __init__(self, performer, *, engine="simple", control="pid-ff", plant=None, report=None):
        if engine not in ENGINES:
            raise ParameterError(f"engine must be one of {', '.join(ENGINES)}, got {engine!r}")
        control = controller(control) if isinstance(control, str) else control
        if not isinstance(control, Controller) or control.name not in live_controllers():
            raise ParameterError(f"a live robot's controller must be one of {', '.join(live_controllers())}, got "
                                 f"{getattr(control, 'name', control)!r}")
        if performer.columns != performer.sticks:
            raise ParameterError("a simulated robot plays sticks, one joint each; a kit's limbs have several "
                                 "(--simulate-robot does not play --kit)")
        plant = Plant() if plant is None else plant
        if abs(plant.head - performer.head) > 1e-9:
            raise ParameterError(f"the plant's head ({plant.head:.6g} rad) is not the performer's stick's "
                                 f"({performer.head:.6g} rad)")
        self.performer, self.engine, self.controller = performer, engine, control.name
        cor = performer.setup.cor
        self._loops = {}
        for stick in performer.sticks:
            start = {"theta0": performer.rest, "omega0": 0.0, "start": performer.sent + 1.0 / performer.rate}
            if engine == "mujoco":
                from ..robot.mujoco_plant import MujocoJoint
                joint = MujocoJoint(plant, cor, rate=performer.rate, **start)
            else:
                joint = SimpleJoint(plant, cor, **start)
            self._loops[stick] = ControlLoop(joint, control, performer.rate, record=False)  # it may play for hours
        self._report = report
        self._seen = dict.fromkeys(performer.sticks, 0)  # each stick's contacts too early for any note to come
        self._told = 0  # notes of the performer's log looked at so far
        self._waiting = []  # (time, stick) of planned notes not yet told
        self.onsets = []  # (note time, stick, onset or nan)
        self._now = -math.inf
        for loop in self._loops.values():  # compiled code loaded before the stream starts
            scratch = ControlLoop(SimpleJoint(plant, cor, theta0=performer.rest), control, performer.rate)
            scratch.run(np.full(2, performer.rest), np.zeros(2), np.zeros(2))
            scratch.joint.contacts()
            break
        self._chunks = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._play, name="drumstroke-robot", daemon=True)
        self._thread.start()

    def __call__(self, chunk):
        """Hand a chunk to the robot's thread (the loop that sends the stream does not wait for it)."""
        self._chunks.put(chunk)

    def _play(self):
        while True:
            chunk = self._chunks.get()
            if chunk is None:
                return
            for j, stick in enumerate(chunk.sticks):
                self._loops[stick].run(chunk.theta[:, j], chunk.omega[:, j], chunk.alpha[:, j])
            if len(chunk):
                self._now = float(chunk.t[-1])
                self._tell()

    def close(self):
        """Play what was handed over, tell the notes it reached; then :meth:`summary` is final."""
        if self._thread.is_alive():
            self._chunks.put(None)
            self._thread.join()

    def _tell(self):
        log = self.performer.log
        read = len(log)  # the planner's thread may add notes meanwhile: those are read next time
        for outcome in log[self._told:read]:
            if outcome.planned:
                self._waiting.extend((float(t), outcome.note.stick) for t, _ in outcome.impacts)
        self._told = read
        due = [w for w in self._waiting if w[0] + SETTLE <= self._now]
        if not due:
            return
        self._waiting = [w for w in self._waiting if w[0] + SETTLE > self._now]
        contacts = {stick: self._loops[stick].joint.contacts(self._seen[stick]).t for stick in {s for _, s in due}}
        for t, stick in sorted(due):
            found = contacts[stick]
            near = found[np.abs(found - t) <= WINDOW] if len(found) else found
            onset = float(near[np.argmin(np.abs(near - t))]) if len(near) else math.nan
            self.onsets.append((t, stick, onset))
            if self._report:
                self._report(f"robot: note at {t:.4f} s on {stick}: " + (
                    f"onset {1e3 * (onset - t):+.2f} ms" if math.isfinite(onset) else
                    f"no onset within {1e3 * WINDOW:g} ms"))
        for stick, found in contacts.items():  # a note still to be told is later than the earliest waiting or due now
            earliest = min([t for t, s in self._waiting if s == stick] + [self._now - SETTLE])
            self._seen[stick] += int(np.searchsorted(found, earliest - WINDOW))

    def summary(self):
        """The onsets told so far: how many, how many within 2 and 5 ms, the median and largest |error| (ms)."""
        errors = np.array([onset - t for t, _, onset in self.onsets])
        found = errors[np.isfinite(errors)]
        return {"engine": self.engine, "controller": self.controller, "notes": len(errors),
                "onsets": len(found), "within_2ms": int(np.sum(np.abs(found) <= 2e-3)),
                "within_5ms": int(np.sum(np.abs(found) <= 5e-3)),
                "median_error_ms": float(np.median(np.abs(found)) * 1e3) if len(found) else None,
                "largest_error_ms": float(np.max(np.abs(found)) * 1e3) if len(found) else None}
