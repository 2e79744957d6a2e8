"""Notes in: OSC messages, MIDI messages and score files, each a :class:`Request` or one line saying why not.

OSC (UDP, :class:`OscInput`), the addresses a live performer answers (every other is dropped):

``/drum/note stick velocity [stroke [duration] [piece]]``
    A note heard ``latency`` s after it arrives. ``stick`` is a stick's name (on a kit, a limb's:
    ``right``, ``left``, ``right-foot``, ``left-foot``) or ``auto``; ``velocity`` 1-127 (int or
    float); ``stroke`` ``auto`` (default) or ``buzz``; ``duration`` s, a buzz's length; ``piece``
    the kit's piece it is played on (default the snare).
``/drum/note/at time stick velocity [stroke [duration] [piece]]``
    A note heard at ``time`` (s on the session's clock, the clock of the ``t`` of every
    ``/drum/setpoint``): scheduled ahead, at least ``guard`` s after it arrives.

MIDI (:class:`MidiInput`, ``mido`` with ``python-rtmidi``): a note-on with a velocity on channel 10 on
one of the drum map's snare keys (37, 38, 40: :data:`drumstroke.score.DRUM_MAP`) is a note on the
stick the performer chooses, heard ``latency`` s later; with a kit, on any key the kit answers, on its
piece (:meth:`~drumstroke.kit.pieces.Kit.piece_for_key`: 42 the hi-hat closed, 46 open, 36 the kick…),
the limb the performer chooses. Note-offs, clocks and controllers are not notes and pass silently;
other keys and channels are dropped with a line.

A score (:func:`score_requests`, a MIDI file or a text pattern): each planned note (``auto``,
``buzz``) arrives at its time in the score after a count-in (:data:`COUNT_IN`, 1 s on the session's
clock) and is heard ``latency`` s later: a rehearsal, played against the clock as a drummer would be
sent it.
"""

import contextlib
import math
import os
import socket
import sys
import threading
from dataclasses import dataclass

from .._checks import shown
from ..errors import ParameterError
from ..score import AUTO_STICK, DRUM_MAP, PLANNED
from .performer import STROKES

NOTE = "/drum/note"
"""The OSC address of a note heard ``latency`` after it arrives."""

NOTE_AT = "/drum/note/at"
"""The OSC address of a note heard at a time it names."""

MIDI_CHANNEL = 9
"""The MIDI channel read, counted from 0 as mido does: General MIDI's percussion channel 10."""

DATAGRAM = 65_507
"""The largest UDP payload (bytes): a datagram is read whole or not at all."""

MESSAGE = 8192
"""The largest datagram read as notes (bytes): a note's message is at most about 200 bytes, a bundle of notes a few of
them; a larger datagram is dropped unparsed, with its line."""

NAME = 64
"""The longest text a note's field may hold (characters): a stick's, a stroke's or a piece's name."""


@dataclass(frozen=True)
class Request:
    """A note asked for: when it arrived (s, the session's clock), where from, what.

    ``at`` is None for a note heard ``latency`` after it arrives; ``piece`` None for the snare; ``key`` the
    MIDI key it came as, if it did.
    """

    arrived: float
    stick: str
    velocity: float
    at: float | None = None
    stroke: str = "auto"
    duration: float | None = None
    source: str = ""
    piece: str | None = None
    key: int | None = None


_FORM = "stick velocity [stroke [duration] [piece]]"


def osc_request(address, args, arrived, source="osc"):
    """The :class:`Request` of an OSC message (its address and arguments), or a line saying why it is dropped.

    Each field's type is checked here, and the length of its texts (at most :data:`NAME` characters); its value
    against the performer's sticks as it is submitted, against its pieces and ranges when it is planned. A long
    text is shown cut short.
    """
    if address not in (NOTE, NOTE_AT):
        return f"{source}: unknown address {shown(address)} (a note is {NOTE} or {NOTE_AT})"
    args = list(args)
    at = None
    if address == NOTE_AT:
        if not args:
            return f"{source}: {NOTE_AT} needs time {_FORM}, got no arguments"
        at = args.pop(0)
        if not _number(at):
            return f"{source}: {NOTE_AT} time must be a number (s on the session's clock), got {shown(at)}"
    if not 2 <= len(args) <= 5:
        return f"{source}: {address} needs {'time ' if at is not None else ''}{_FORM}, " \
               f"got {len(args)} argument(s) after it"
    long = next((arg for arg in args if isinstance(arg, str) and len(arg) > NAME), None)
    if long is not None:
        return f"{source}: {address} names must be at most {NAME} characters, got {shown(long, most=40)}"
    stick, velocity, *rest = args
    stroke = rest.pop(0) if rest else STROKES[0]
    duration = rest.pop(0) if rest and not isinstance(rest[0], str) else None
    piece = rest.pop(0) if rest and isinstance(rest[0], str) else None
    if rest:
        return f"{source}: {address} needs {'time ' if at is not None else ''}{_FORM}, got {shown(rest[0])} where " \
               "the piece's name goes"
    if not isinstance(stick, str):
        return f"{source}: {address} stick must be a name (a string), got {shown(stick)}"
    if not _number(velocity):
        return f"{source}: {address} velocity must be a number in [1, 127], got {shown(velocity)}"
    if not isinstance(stroke, str):
        return f"{source}: {address} stroke must be one of {', '.join(STROKES)}, got {shown(stroke)}"
    if duration is not None and not _number(duration):
        return f"{source}: {address} duration must be a number of seconds, got {shown(duration)}"
    return Request(arrived, stick, float(velocity), None if at is None else float(at), stroke,
                   None if duration is None else float(duration), source, piece)


def midi_request(message, arrived, source="midi", *, kit=None):
    """The :class:`Request` of a mido message, None for a message that is not a note, or a line saying why not.

    Without a ``kit`` (a :class:`~drumstroke.kit.pieces.Kit`) the snare's keys are notes; with one, every
    key it answers, on its piece.
    """
    if getattr(message, "type", None) != "note_on" or message.velocity == 0:
        return None  # note-offs, clocks, controllers: not notes
    if kit is not None:
        found = kit.piece_for_key(message.note) if message.channel == MIDI_CHANNEL else None
        if found is None:
            return (f"{source}: note {message.note} on channel {message.channel + 1} is not a note of the kit "
                    f"(channel {MIDI_CHANNEL + 1}, keys {', '.join(str(key) for key in kit.keys)})")
        return Request(arrived, AUTO_STICK, float(message.velocity), None, "auto", None, source, found[0].name,
                       message.note)
    if message.channel != MIDI_CHANNEL or message.note not in DRUM_MAP:
        keys = ", ".join(str(key) for key in DRUM_MAP)
        return (f"{source}: note {message.note} on channel {message.channel + 1} is not a snare note (channel "
                f"{MIDI_CHANNEL + 1}, keys {keys})")
    return Request(arrived, AUTO_STICK, float(message.velocity), None, "auto", None, source)


COUNT_IN = 1.0
"""s into the session a score starts (its time 0 arrives then): the runtime is running steadily by then."""


def score_requests(score, source="score", *, count_in=COUNT_IN, kit=False):
    """The :class:`Request` of each note of a :class:`~drumstroke.score.Score`, and a line for each one dropped.

    A note arrives at ``count_in`` s (on the session's clock) plus its time in the score; the planner's
    strokes (``auto``, ``buzz``) are played, a library's are not (live has no library: each note is
    designed as it comes). With ``kit`` (a kit performer's), each note names its piece (the snare when
    the score names none) and its MIDI key.

    Returns
    -------
    (list of Request, list of str)
    """
    requests, dropped = [], []
    for i, note in enumerate(score.notes):
        if note.stroke not in PLANNED:
            dropped.append(f"{source}: note {i} at {note.time:.6g} s: live plays the planner's strokes "
                           f"({', '.join(PLANNED)}), not the library's {note.stroke!r}")
            continue
        piece = (note.piece or "snare", note.key) if kit else (None, None)
        requests.append(Request(count_in + float(note.time), note.stick or AUTO_STICK, float(note.velocity), None, note.stroke,
                                note.duration if note.stroke == "buzz" else None, source, *piece))
    return requests, dropped


def _number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


class OscInput:
    """Notes from OSC over UDP: a thread reads each datagram, parses it and hands on its notes.

    Every datagram is read whole (at most :data:`DATAGRAM` bytes, into one buffer); one larger than
    :data:`MESSAGE`, one that is not OSC, or an OSC message that is not a note, becomes one line for
    ``report``; a bundle's messages are read one by one (its time tag is not waited for: a note names
    its time with :data:`NOTE_AT`).

    Parameters
    ----------
    host : str
        The address to listen on (default 127.0.0.1: this machine only).
    port : int in [0, 65535]
        0 picks a free port (see :attr:`port`).
    submit : callable(Request)
    report : callable(str)
    clock : object with ``now()``
        Stamps each datagram as it arrives.
    """

    def __init__(self, host, port, *, submit, report, clock):
        if not isinstance(port, int) or isinstance(port, bool) or not 0 <= port <= 65535:
            raise ParameterError(f"port must be an integer in [0, 65535], got {port!r}")
        self._submit, self._report, self._clock = submit, report, clock
        try:
            family = socket.getaddrinfo(host, port, type=socket.SOCK_DGRAM)[0][0]
            self._socket = socket.socket(family, socket.SOCK_DGRAM)
            self._socket.bind((host, port))
        except (OSError, UnicodeError) as error:
            raise ParameterError(f"cannot listen for OSC on {host}:{port}: {error}") from None
        self._socket.settimeout(0.1)
        self.host, self.port = self._socket.getsockname()[:2]
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="drumstroke-osc-in", daemon=True)

    def start(self):
        self._thread.start()
        return self

    def close(self):
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()
        self._socket.close()

    def _serve(self):
        from pythonosc.osc_packet import OscPacket, ParseError

        buffer = bytearray(DATAGRAM)  # one for every datagram: a flood of large ones allocates nothing
        while not self._stop.is_set():
            try:
                size, sender = self._socket.recvfrom_into(buffer)
            except TimeoutError:
                continue
            except OSError as error:  # e.g. an ICMP error for an earlier reply: keep listening
                self._report(f"osc: {error}")
                continue
            arrived = self._clock.now()
            source = f"osc {sender[0]}:{sender[1]}"
            if size > MESSAGE:
                self._report(f"{source}: dropped a datagram of {size} bytes unread: a note's is at most {MESSAGE}")
                continue
            data = bytes(buffer[:size])
            try:
                messages = OscPacket(data).messages
            except (ParseError, ValueError, IndexError, TypeError) as error:
                self._report(f"{source}: not an OSC packet ({len(data)} bytes): {error}")
                continue
            for timed in messages:
                try:
                    request = osc_request(timed.message.address, timed.message.params, arrived, source)
                except Exception as error:  # noqa: BLE001 - a message python-osc parsed oddly must not end the input
                    request = f"{source}: a message that is not a note ({type(error).__name__}: {error})"
                if isinstance(request, str):
                    self._report(request)
                else:
                    self._submit(request)


class MidiInput:
    """Notes from a MIDI input port (mido with python-rtmidi), stamped as they arrive.

    Parameters
    ----------
    name : str
        The port's name (see ``mido.get_input_names()``); with ``virtual``, the name of a virtual
        port this process opens for other programs to play into (where the platform allows).
    kit : Kit, optional
        Read every key the kit answers, on its piece (default: the snare's keys).
    """

    def __init__(self, name, *, virtual=False, submit, report, clock, kit=None):
        try:
            import mido
        except ImportError:
            raise ImportError("MIDI input needs mido and python-rtmidi: pip install 'drumstroke[live]'") from None
        self._submit, self._report, self._clock, self._kit = submit, report, clock, kit
        try:
            with _c_stderr_silenced():  # ALSA's library prints its own lines when there is no MIDI system
                if not virtual:
                    names = mido.get_input_names()
                    if name not in names:
                        raise ParameterError(f"no MIDI input named {name!r}; the inputs are: "
                                             f"{', '.join(map(repr, names)) or 'none'}")
                self._port = mido.open_input(name, virtual=virtual, callback=self._receive)
        except ParameterError:
            raise
        except (OSError, ValueError, RuntimeError) as error:  # rtmidi's: no MIDI system, no such port, …
            raise ParameterError(f"cannot open the MIDI input {name!r}: {error}") from None
        self.name = name

    def start(self):
        return self

    def _receive(self, message):
        request = midi_request(message, self._clock.now(), kit=self._kit)
        if isinstance(request, str):
            self._report(request)
        elif request is not None:
            self._submit(request)

    def close(self):
        self._port.close()


@contextlib.contextmanager
def _c_stderr_silenced():
    """File descriptor 2 to /dev/null for a moment (a C library's own messages; Python's error says it all)."""
    sys.stderr.flush()
    saved = os.dup(2)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)
