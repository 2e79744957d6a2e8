"""A whole live session, inputs to outputs: what ``drumstroke live`` runs, for a host that wants all of it.

:func:`perform` opens the inputs (OSC, MIDI, a score) and the outputs (OSC, CSV, a simulated robot)
around a :class:`~drumstroke.live.runtime.Runtime`, runs it until the score ends, ``duration`` s pass
or an interrupt comes (SIGINT or SIGTERM, when called from the main thread: the first brings the sticks
to rest, a second stops at once), closes everything and returns the session's record.
"""

import signal
import threading

from .inputs import COUNT_IN, MidiInput, OscInput, score_requests
from .monitor import RobotMonitor
from .outputs import CsvOutput, OscOutput
from .runtime import LiveError, Runtime

TAIL = 0.5
"""s after a score's last note is heard before a session that plays only the score closes."""


def perform(performer, *, osc_in=None, midi_in=None, midi_virtual=None, score=None, count_in=COUNT_IN,
            osc_out=None, csv=None, robot=None, duration=None, report=None, listening=None):
    """Play live from the inputs given to the outputs given; return ``(record, status)``.

    Parameters
    ----------
    performer : Performer
        A :class:`~drumstroke.live.kit.KitPerformer` plays a kit: MIDI is read with its kit's keys, a score's
        notes on their pieces, the CSV names every joint.
    osc_in : (str, int), optional
        Host and port to listen on for OSC notes (port 0: any free one, told to ``listening``).
    midi_in, midi_virtual : str, optional
        A MIDI input port to read, or a virtual one to open.
    score : Score, optional
        Played against the clock after ``count_in`` s.
    osc_out : (str, int), optional
        Where to send the setpoints as OSC.
    csv : text stream, optional
        Where to write them as CSV.
    robot : dict, optional
        Keyword arguments of a :class:`~drumstroke.live.monitor.RobotMonitor` (engine, control, plant).
    duration : float, optional
        s; default: until interrupted, or (with a score as the only input) when its last note is heard
        and caught.
    report : callable(str), optional
        Told each problem and each robot onset.
    listening : callable(host, port), optional
        Told where the OSC input listens.

    Returns
    -------
    (dict, int)
        The session's record (:meth:`Runtime.session`, with the robot's summary and the inputs) and the
        status: 0, 3 if a chunk failed validation, 130 if a second interrupt stopped it at once.
    """
    runtime = Runtime(performer, report=report)
    inputs, closers, monitor, status = [], [], None, 0
    try:
        if robot is not None:
            monitor = RobotMonitor(performer, report=report, **robot)
            runtime.outputs.append(monitor)
            closers.append(monitor)
        if osc_out is not None:
            closers.append(OscOutput(*osc_out))
            runtime.outputs.append(closers[-1])
        kit = getattr(performer, "kit", None)
        if csv is not None:
            runtime.outputs.append(CsvOutput(csv, performer.columns, joints=kit is not None))
        requests = []
        if score is not None:
            requests, dropped = score_requests(score, source="score", count_in=count_in, kit=kit is not None)
            for line in dropped:
                runtime.problem(line)
            runtime.schedule(requests)
        options = {"submit": runtime.submit, "report": runtime.problem, "clock": performer.clock}
        if osc_in is not None:
            inputs.append(OscInput(*osc_in, **options).start())
            if listening is not None:
                listening(inputs[-1].host, inputs[-1].port)
        if midi_in is not None:
            inputs.append(MidiInput(midi_in, kit=kit, **options).start())
        if midi_virtual is not None:
            inputs.append(MidiInput(midi_virtual, virtual=True, kit=kit, **options).start())
        if duration is None and score is not None and not inputs:
            duration = max((r.arrived for r in requests), default=count_in) + performer.latency + TAIL
        with _Interrupts(runtime) as interrupts:
            try:
                runtime.run(duration=duration)
            except LiveError:
                status = 3
        if interrupts.count > 1:
            status = status or 130
    finally:
        for part in inputs + closers:
            part.close()
    record = runtime.session(robot=monitor.summary() if monitor else None,
                             inputs={"osc": list(osc_in) if osc_in else None, "midi": midi_in,
                                     "midi_virtual": midi_virtual, "score": score is not None})
    return record, status


class _Interrupts:
    """SIGINT and SIGTERM while the loop runs (from the main thread): the first stops it gently, a second at once.

    The handlers raise flags only: one that printed or queued could meet the main thread inside the same lock.
    """

    def __init__(self, runtime):
        self.runtime, self.count, self.previous = runtime, 0, {}

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self.previous = {sig: signal.signal(sig, self._handle) for sig in (signal.SIGINT, signal.SIGTERM)}
        return self

    def _handle(self, number, frame):
        self.count += 1
        if self.count == 1:
            self.runtime.stop()
        else:
            self.runtime.abort()

    def __exit__(self, *exc):
        for sig, handler in self.previous.items():
            signal.signal(sig, handler)
