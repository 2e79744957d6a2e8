"""The listening test's HTTP server: uvicorn, with the limits a server on the open internet needs and uvicorn lacks.

uvicorn (h11) answers a malformed request with 400 (a negative, non-numeric or 5,000-digit
``Content-Length``, a raw byte 0xB2 in the path) and a request head still incomplete after 16 KiB (one
that comes whole at once may be larger: the app answers it 431). But, as a socket client shows
(uvicorn 0.54, h11 0.16):

- a connection whose request head trickles in is never timed out: ``timeout_keep_alive`` runs only
  between requests, and any byte received stops it;
- ``limit_concurrency`` counts every open connection, idle and trickling ones too, yet refuses (503)
  only a request whose head has arrived: it bounds nothing while heads trickle in, and with them open
  it refuses the participants instead;
- a response the client does not read is waited on for ever.

So :class:`Server` runs uvicorn's h11 protocol with these added: a deadline for each request head
(``head_timeout`` after the connection opens or after the previous response; then 408 and close), a
cap on open connections per client (one more is answered 503 and closed at once), and a cap in all
sized from the open-file limit, raised to its hard limit. At that cap a new connection takes the place
of the connection that has waited longest without delivering a whole request (its line, headers and
body): trickling and idle connections go first, oldest first, and a visitor who sends a whole request
at once is served; only when no connection is waiting is the new one refused (503). A client that reads
nothing of a response for ``body_timeout`` is dropped. Bodies are bounded and timed by the app
(:mod:`drumstroke.evaluation.web`). An idle connection costs about 5 KB. Access logs are off (they
would keep participants' addresses); uvicorn's errors go to the ``uvicorn.error`` logger.
"""

import ipaddress
import logging
import socket
import threading
import time
from collections import OrderedDict
from http import HTTPStatus

import uvicorn
from uvicorn.protocols.http.h11_impl import H11Protocol

from ..errors import ParameterError
from .limits import MAX_HEAD, client_key, trusted_networks
from .pages import SECURITY_HEADERS

log = logging.getLogger(__name__)

KEEP_ALIVE = 5
"""Seconds an idle connection is kept open between requests (uvicorn's default)."""

GRACE = 5
"""Seconds the requests under way are given to finish when the server is stopped."""

BACKLOG = 2048
"""Connections the kernel may queue before the server accepts them."""

FD_RESERVE = 512
"""Open files kept free of connections (the database, stimuli being sent, the threads' files): the cap on
connections is the open-file limit less this (or half the limit, if that is more)."""


class Server:
    """A listening test served by uvicorn on a socket bound when it is made.

    Made by :func:`drumstroke.evaluation.app.make_server`. :meth:`serve` blocks until Ctrl-C;
    :meth:`start` and :meth:`stop` run it in a thread instead.

    Parameters
    ----------
    app : ASGI application
        :func:`drumstroke.evaluation.web.make_app`'s.
    limits : Limits
        The connection caps and timeouts (:class:`~drumstroke.evaluation.limits.Limits`).
    host : str
        The address or name to listen on.
    port : int in [0, 65535]
        0 picks a free port.
    forwarded_allow_ips : sequence of str
        Trusted proxies (see :func:`~drumstroke.evaluation.limits.trusted_networks`): their connections are
        not counted per client, and their ``X-Forwarded-For``/``X-Forwarded-Proto`` are believed.

    Attributes
    ----------
    url : str
        Where the server listens, e.g. ``http://127.0.0.1:8000/``.
    connections : int
        The most connections it holds open: ``limits.connections``, or fewer if the open-file limit (raised
        to its hard limit) cannot hold them and :data:`FD_RESERVE` files more.
    """

    def __init__(self, app, limits, *, host, port, forwarded_allow_ips=()):
        trusted = trusted_networks(forwarded_allow_ips)
        self.socket = _bind(host, port)
        bound, bound_port = self.socket.getsockname()[:2]
        self.url = f"http://{f'[{bound}]' if ':' in bound else bound}:{bound_port}/"
        self.connections = connection_cap(limits.connections)
        protocol = type("Protocol", (_Guarded,), {"book": _Book(limits, trusted, self.connections)})
        config = uvicorn.Config(app, http=protocol, ws="none", lifespan="off", log_config=None, access_log=False,
                                server_header=False, proxy_headers=bool(trusted),
                                forwarded_allow_ips=[str(n) for n in trusted] or None, timeout_keep_alive=KEEP_ALIVE,
                                timeout_graceful_shutdown=GRACE, h11_max_incomplete_event_size=MAX_HEAD,
                                backlog=BACKLOG)
        self._server = uvicorn.Server(config)
        self._thread = None

    def serve(self):
        """Serve until Ctrl-C or SIGTERM; then let the requests under way finish (up to :data:`GRACE` s) and return."""
        try:
            self._server.run(sockets=[self.socket])
        except KeyboardInterrupt:
            pass  # uvicorn has shut down, then raised the Ctrl-C again for whoever called it

    def start(self):
        """Serve in a background thread; return the server once it accepts connections."""
        self._thread = threading.Thread(target=self._server.run, kwargs={"sockets": [self.socket]}, daemon=True,
                                        name="drumstroke-listen")
        self._thread.start()
        deadline = time.monotonic() + 30.0
        while not self._server.started:
            if not self._thread.is_alive() or time.monotonic() > deadline:
                raise RuntimeError(f"the listening-test server on {self.url} did not start")
            time.sleep(0.01)
        return self

    def stop(self):
        """Stop a server :meth:`start` started: close its connections, let the requests under way finish."""
        self._server.should_exit = True
        self._thread.join(timeout=GRACE + 5.0)


class _Book:
    """A server's open connections: how many per client, and which wait for a whole request, longest first."""

    def __init__(self, limits, trusted, cap):
        self.limits, self.trusted, self.cap = limits, trusted, cap
        self.per_client = {}  # client key -> connections open
        self.waiting = OrderedDict()  # connection -> the request it had when it began to wait; longest first
        self.dropping = 0  # connections dropped for room, still in uvicorn's set until their close completes

    def key_of(self, host):
        """The client key ``host`` is counted under, or None for a trusted proxy (not counted)."""
        try:
            address = ipaddress.ip_address(host)
        except ValueError:
            return client_key(host)
        return None if any(address in network for network in self.trusted) else client_key(host)

    def make_room(self):
        """Drop the open connection that has waited longest for a whole request; False if none is waiting."""
        while self.waiting:
            connection, _ = self.waiting.popitem(last=False)
            if not connection.transport.is_closing():  # one closing already makes room by itself
                connection.drop_for_room()
                return True
        return False


class _Guarded(H11Protocol):
    """uvicorn's h11 protocol with a deadline on each request head, on reading responses, and connection caps."""

    book = None  # the server's _Book, set on the subclass a Server makes

    def connection_made(self, transport):
        super().connection_made(transport)
        self._head_deadline = self._write_deadline = self._counted = None
        self._dropped = False
        book, limits = self.book, self.book.limits
        key = book.key_of(self.client[0] if self.client else None)
        if key is not None and book.per_client.get(key, 0) >= limits.connections_per_client:
            self._refuse(" from your address")
            return
        if len(self.connections) - book.dropping > book.cap and not book.make_room():
            self._refuse("")
            return
        if key is not None:
            book.per_client[key] = book.per_client.get(key, 0) + 1
            self._counted = key
        self._arm_head_deadline()

    def connection_lost(self, exc):
        for handle in (self._head_deadline, self._write_deadline):
            if handle is not None:
                handle.cancel()
        book = self.book
        book.waiting.pop(self, None)
        if self._dropped:
            book.dropping -= 1
        if self._counted is not None:
            left = book.per_client[self._counted] - 1
            if left:
                book.per_client[self._counted] = left
            else:
                del book.per_client[self._counted]
            self._counted = None
        super().connection_lost(exc)

    def data_received(self, data):
        cycle = self.cycle
        self._partial = True
        super().data_received(data)
        if self.cycle is not cycle and self._head_deadline is not None:  # a whole head: the app answers it now
            self._head_deadline.cancel()
            self._head_deadline = None
        waited_after = self.book.waiting.get(self, cycle)
        if self.cycle is not waited_after and not self.cycle.more_body:  # a whole request: it waits no more
            self.book.waiting.pop(self, None)

    def on_response_complete(self):
        cycle = self.cycle
        super().on_response_complete()
        if self.cycle is cycle and not self.transport.is_closing():  # no pipelined request started: wait for one
            self._arm_head_deadline()

    def send_400_response(self, msg):
        self.transport.write(_raw(400, "the request is not valid HTTP/1.1: its line, a header, its Content-Length "
                                       "or its size (at most 16 KiB before the body)"))
        self.transport.close()

    def pause_writing(self):
        super().pause_writing()
        if self._write_deadline is None:
            self._write_deadline = self.loop.call_later(self.book.limits.body_timeout, self.transport.abort)

    def resume_writing(self):
        super().resume_writing()
        if self._write_deadline is not None:
            self._write_deadline.cancel()
            self._write_deadline = None

    def drop_for_room(self):
        """Close this connection, which has waited longest for a whole request, to make room for a new one."""
        self.book.dropping += 1
        self._dropped = True
        if self._partial:  # part of a request came: say why it is dropped
            self.transport.write(_raw(503, "the server is full, and this request had not arrived whole: try again",
                                      ("Retry-After", "5")))
        self.transport.close()

    def _refuse(self, whose):
        self.connections.discard(self)  # refused: it counts no more
        self.transport.write(_raw(503, f"too many connections are open{whose}: try again in a moment",
                                  ("Retry-After", "5")))
        self.transport.close()

    def _arm_head_deadline(self):
        if self._head_deadline is not None:
            self._head_deadline.cancel()
        self._partial = bool(self.conn.trailing_data[0])  # bytes of the next request may have come already
        self._head_deadline = self.loop.call_later(self.book.limits.head_timeout, self._head_timed_out)
        self.book.waiting.pop(self, None)
        self.book.waiting[self] = self.cycle  # waiting since now: the longest-waiting stay first

    def _head_timed_out(self):
        self._head_deadline = None
        if self.transport.is_closing():
            return
        if self._partial:  # part of a request came: say why it is dropped
            self.transport.write(_raw(408, f"the request's line and headers did not arrive within "
                                           f"{self.book.limits.head_timeout:g} s"))
        self.transport.close()


def _raw(status, message, *headers):
    """A whole plain-text response that closes the connection, with the security headers, as bytes."""
    phrase = HTTPStatus(status).phrase
    body = f"{status} {phrase}: {message}\n".encode()
    lines = [f"HTTP/1.1 {status} {phrase}", "Content-Type: text/plain; charset=utf-8", f"Content-Length: {len(body)}",
             "Connection: close", "Cache-Control: no-store", *(f"{name}: {value}" for name, value in SECURITY_HEADERS),
             *(f"{name}: {value}" for name, value in headers)]
    return ("\r\n".join(lines) + "\r\n\r\n").encode() + body


def _bind(host, port):
    """A listening TCP socket on ``host`` and ``port``; a ParameterError naming them if there can be none."""
    if not isinstance(host, str) or not host:
        raise ParameterError(f"host must be an address or a name, got {host!r}")
    try:
        family, kind, proto, _, address = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM,
                                                             flags=socket.AI_PASSIVE)[0]
    except (OSError, UnicodeError, ValueError) as error:
        raise ParameterError(f"host {host!r} cannot be resolved: {getattr(error, 'strerror', None) or error}") from None
    sock = socket.socket(family, kind, proto)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind(address)
        sock.listen(BACKLOG)
    except OSError as error:
        sock.close()
        raise ParameterError(f"cannot listen on host {host!r} port {port}: {error.strerror or error}") from None
    return sock


def connection_cap(connections):
    """The most connections a server may hold: ``connections``, or fewer if the open-file limit cannot hold them.

    The limit is raised to its hard limit first where the system lets it (to ``connections`` and
    :data:`FD_RESERVE` more where the hard limit is infinite); the cap then leaves :data:`FD_RESERVE`
    files free (or half the limit, if that is more), so that accepting never fails for want of a file.
    """
    try:
        import resource
    except ImportError:  # not on POSIX: the system decides
        return connections
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    want = connections + FD_RESERVE if hard == resource.RLIM_INFINITY else hard
    if soft != resource.RLIM_INFINITY and soft < want:
        try:
            resource.setrlimit(resource.RLIMIT_NOFILE, (want, hard))
            soft = want
        except (ValueError, OSError):  # some systems refuse more than a kernel maximum below the hard limit
            pass
    if soft == resource.RLIM_INFINITY:
        return connections
    cap = max(soft // 2, soft - FD_RESERVE)
    if cap < connections:
        log.warning("the open-file limit is %d (ulimit -n): the server holds at most %d connections, fewer than "
                    "the %d of [limits] connections", soft, cap, connections)
    return min(connections, cap)
