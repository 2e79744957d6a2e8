"""Setpoints out: to OSC, to a CSV stream; each is a callable taking a :class:`~drumstroke.live.performer.Chunk`.

OSC (:class:`OscOutput`): for each setpoint, one message per stick,

``/drum/setpoint stick t theta omega alpha``
    ``stick`` a string; ``t`` (s, the session's clock), ``theta`` (rad), ``omega`` (rad/s) and
    ``alpha`` (rad/s², the flight acceleration) as 64-bit floats (OSC type ``d``): exact, as
    computed.

CSV (:class:`CsvOutput`): the header ``t,theta_<stick>,omega_<stick>,alpha_<stick>,...`` (as
:func:`drumstroke.formats.trajectory_csv.column_names` names them), then a row per setpoint at full
precision (17 significant digits), flushed as it is written. A kit's joints (``joints=True``) are named
as a composed kit's CSV names them: ``t``, each ``LIMB.JOINT`` (rad), each ``LIMB.JOINT.velocity``
(rad/s), then each ``LIMB.JOINT.acceleration`` (rad/s²).

On a kit the OSC message's ``stick`` is the joint's column name (``right.yaw``).
"""

import socket

import numpy as np

from ..errors import ParameterError
from ..formats.trajectory_csv import column_names

SETPOINT = "/drum/setpoint"
"""The OSC address of a setpoint."""


class OscOutput:
    """Setpoints to ``host``:``port`` over UDP, a message per stick per setpoint (see the module)."""

    def __init__(self, host, port):
        if not isinstance(port, int) or isinstance(port, bool) or not 1 <= port <= 65535:
            raise ParameterError(f"port must be an integer in [1, 65535], got {port!r}")
        try:
            from pythonosc.osc_message_builder import OscMessageBuilder
        except ImportError:
            raise ImportError("OSC needs python-osc: pip install 'drumstroke[live]'") from None
        self._builder = OscMessageBuilder
        try:
            family, _, _, _, address = socket.getaddrinfo(host, port, type=socket.SOCK_DGRAM)[0]
        except (OSError, UnicodeError) as error:
            raise ParameterError(f"cannot send OSC to {host}:{port}: {error}") from None
        self._socket = socket.socket(family, socket.SOCK_DGRAM)
        self._address = address
        self.host, self.port = host, port
        self.dropped = 0  # datagrams the system would not send (a full buffer, nobody listening)

    def __call__(self, chunk):
        for k in range(len(chunk)):
            for j, stick in enumerate(chunk.sticks):
                message = self._builder(address=SETPOINT)
                message.add_arg(stick, "s")
                for value in (chunk.t[k], chunk.theta[k, j], chunk.omega[k, j], chunk.alpha[k, j]):
                    message.add_arg(float(value), "d")
                try:
                    self._socket.sendto(message.build().dgram, self._address)
                except OSError:
                    self.dropped += 1

    def close(self):
        self._socket.close()


class CsvOutput:
    """Setpoints as CSV rows to a text stream (stdout by default): the header first, then a row per setpoint."""

    def __init__(self, stream, sticks, *, joints=False):
        self._stream = stream
        self._joints = joints
        self._names = ["t", *sticks, *(f"{name}.{what}" for what in ("velocity", "acceleration") for name in sticks)] \
            if joints else column_names(sticks, alpha=True)
        self._header = False

    def __call__(self, chunk):
        if not self._header:
            self._stream.write(",".join(self._names) + "\n")
            self._header = True
        if len(chunk):
            if self._joints:  # every angle, then every speed, then every acceleration
                columns = [chunk.t[:, None], chunk.theta, chunk.omega, chunk.alpha]
            else:  # each stick's angle, speed and acceleration together
                columns = [chunk.t[:, None]] + [np.stack([chunk.theta[:, j], chunk.omega[:, j], chunk.alpha[:, j]],
                                                         axis=1) for j in range(len(chunk.sticks))]
            rows = np.concatenate(columns, axis=1) + 0.0  # no negative zeros
            self._stream.write("".join(",".join(f"{v:.17g}" for v in row) + "\n" for row in rows))
        self._stream.flush()

    def close(self):
        self._stream.flush()
