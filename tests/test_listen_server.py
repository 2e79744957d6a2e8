"""The listening-test server against hostile connections, over raw sockets: lying lengths, trickles, caps, timeouts.

Each test starts the real server (uvicorn in a thread, as ``listen serve`` runs it) on a free loopback
port, with short timeouts where a test waits for one. Loopback has many addresses (127.0.0.0/8), so a
test can be several clients at once. The figures the docs quote are measured here.
"""

import re
import selectors
import socket
import threading
import time
import urllib.parse

import pytest

from _listen import Client, start_test
from drumstroke.errors import ParameterError
from drumstroke.evaluation.app import plan
from drumstroke.evaluation.pages import SECURITY_HEADERS
from drumstroke.evaluation.server import Server
from drumstroke.evaluation.web import make_app

TOKEN = "raw-socket-test-token-0123"
PAIRS = 3


@pytest.fixture()
def served(tmp_path):
    server, config, store = start_test(tmp_path, pairs=PAIRS, token=TOKEN, seed=3,
                                       limits="head_timeout = 1.0\nbody_timeout = 1.0")
    yield server, config, store, tmp_path
    server.stop()


def address(server):
    parts = urllib.parse.urlsplit(server.url)
    return parts.hostname, parts.port


def exchange(server, data, *, wait=5.0, source="127.0.0.1"):
    """Send ``data`` on a new connection and read until the server closes it: (what came back, seconds, closed)."""
    with socket.create_connection(address(server), timeout=wait, source_address=(source, 0)) as connection:
        began = time.monotonic()
        connection.sendall(data)
        chunks, closed = [], True
        try:
            while chunk := connection.recv(65536):
                chunks.append(chunk)
        except TimeoutError:
            closed = False
        except ConnectionResetError:
            pass
        return b"".join(chunks), time.monotonic() - began, closed


def statuses(reply):
    return [int(code) for code in re.findall(rb"^HTTP/1\.1 (\d{3}) ", reply, re.MULTILINE)]


def headers_of(reply):
    head = reply.split(b"\r\n\r\n", 1)[0].decode("latin-1").split("\r\n")[1:]
    return {name.lower(): value for name, _, value in (line.partition(": ") for line in head)}


def ready(server):
    """A participant who has played both stimuli of pair 0: (participant, their form token)."""
    client = Client(server.url)
    participant = client.start()
    for side in ("A", "B"):
        form = {"side": side, "csrf": client.tokens[participant]}
        assert client.post(f"/p/{participant}/pair/0/played", form).status == 204
    return participant, client.tokens[participant]


def test_lying_negative_and_oversized_content_lengths_are_answered_and_store_nothing(served):
    server, _, store, _ = served
    participant, token = ready(server)
    form = f"answer=A&confidence=3&similarity=4&csrf={token}".encode()
    head = (f"POST /p/{participant}/pair/0/answer HTTP/1.1\r\nHost: {server.url[7:-1]}\r\n"
            "Content-Type: application/x-www-form-urlencoded\r\n").encode()
    chunk = b"a" * 5000
    cases = {  # what is sent after the head's first lines: the statuses answered, in order
        "a negative length": (b"Content-Length: -1\r\n\r\n" + form, [400]),
        "a length that is not a number": (b"Content-Length: 12abc\r\n\r\n" + form, [400]),
        "a length of 5,000 digits": (b"Content-Length: " + b"9" * 5000 + b"\r\n\r\n" + form, [400]),
        "a length over the limit, no body sent": (b"Content-Length: 1000000000\r\n\r\n", [413]),
        "a length longer than the body": (b"Content-Length: %d\r\n\r\n" % (len(form) + 20) + form, [408]),
        "a body that never arrives": (b"Content-Length: 100\r\n\r\n", [408]),
        # the body read is cut inside the token (refused); the rest is the start of a head that never ends
        "a length shorter than the body": (b"Content-Length: %d\r\n\r\n" % (len(form) - 5) + form, [403, 408]),
        "chunks over the limit": (b"Transfer-Encoding: chunked\r\n\r\n%x\r\n" % len(chunk) + chunk + b"\r\n0\r\n\r\n",
                                  [413]),
        "both Content-Length and Transfer-Encoding": (b"Content-Length: 5\r\nTransfer-Encoding: chunked\r\n\r\n"
                                                      b"%x\r\n" % len(form) + form + b"\r\n0\r\n\r\n", [400]),
    }
    for case, (rest, expected) in cases.items():
        reply, seconds, closed = exchange(server, head + rest)
        assert statuses(reply) == expected and closed, (case, reply[:300])
        assert seconds < 1.0 + 1.0 + 1.0, (case, seconds)  # the body and head timeouts are 1 s each
        for name, value in SECURITY_HEADERS:
            assert headers_of(reply)[name.lower()] == value, (case, name)
    assert store.rows() == []
    quick = exchange(server, head + b"Content-Length: 1000000000\r\n\r\n")
    assert b"at most 4096 bytes" in quick[0] and quick[1] < 0.5  # refused by its length, before any body
    assert b"not valid HTTP/1.1" in exchange(server, head + b"Content-Length: -1\r\n\r\n")[0]
    assert b"did not arrive whole within 1 s" in exchange(server, head + b"Content-Length: 100\r\n\r\n")[0]
    reply, _, _ = exchange(server, head + b"Content-Length: %d\r\nConnection: close\r\n\r\n" % len(form) + form)
    assert statuses(reply) == [303] and len(store.rows()) == 1  # the same form, told truly: stored


def test_a_head_that_trickles_in_is_cut_at_the_head_timeout_and_an_idle_connection_closed(served):
    """A byte every 0.2 s does not put the 1 s deadline off: the head is answered 408 and the connection closed.

    The client waits for the end up to a generous bound (a busy machine is slow, not wrong), reads whatever
    came before a reset (the server may reset a connection whose trickled bytes it left unread), and checks
    that its bytes came closer together than the timeout, so that only a deadline on the whole head cuts it.
    """
    server, _, _, _ = served
    began = time.monotonic()  # before connecting: the server's clock for this connection starts after it
    with socket.create_connection(address(server)) as connection:
        connection.sendall(b"GET / HTTP/1.1\r\nHost: localhost\r\nX-Slow: ")
        reply, sent, ended = read_while_trickling(connection, began + 30.0)
    assert statuses(reply) == [408] and b"did not arrive within 1 s" in reply
    lasted = ended - began
    assert lasted > 0.9 and len(sent) >= 2
    assert max(b - a for a, b in zip([began, *sent], [*sent, ended])) < 1.0, sent  # never idle for the timeout
    began = time.monotonic()
    reply, _, closed = exchange(server, b"", wait=30.0)  # nothing sent: closed without a word
    assert reply == b"" and closed and time.monotonic() - began > 0.9


def read_while_trickling(connection, deadline, interval=0.2):
    """Send a byte every ``interval`` s while reading what comes, until the server ends the connection or
    ``deadline``: (what came, when each byte was sent, when it ended)."""
    connection.settimeout(interval)
    reply, sent = b"", []
    while time.monotonic() < deadline:
        try:
            chunk = connection.recv(4096)
        except TimeoutError:
            try:
                connection.send(b"a")
                sent.append(time.monotonic())
            except OSError:  # the server has closed its end: what it said is read next
                pass
            continue
        except ConnectionResetError:  # after its answer, for the bytes it left unread
            break
        if not chunk:
            break
        reply += chunk
    return reply, sent, time.monotonic()


def test_malformed_heads_are_answered_400_with_a_message(served):
    server, _, _, _ = served
    for head in (b"GET /p/\xb2/pair/0 HTTP/1.1\r\nHost: localhost\r\n\r\n",  # a raw byte in the path
                 b"GET / HTTP/1.1\r\nHost: localhost\r\nX-Big: " + b"a" * 17000,  # 16 KiB and the head not over
                 b"GET / HTTP/1.1\r\nHost: localhost\r\nBad Header\r\n\r\n",
                 b"NOT HTTP AT ALL\r\n\r\n"):
        reply, seconds, closed = exchange(server, head)
        assert statuses(reply) == [400] and b"not valid HTTP/1.1" in reply and closed and seconds < 0.5, reply
        assert headers_of(reply)["x-content-type-options"] == "nosniff"
    # a whole head over 16 KiB, come at once
    reply, seconds, closed = exchange(server, b"GET / HTTP/1.1\r\nHost: localhost\r\nX-Big: " + b"a" * 17000 + b"\r\n\r\n")
    assert statuses(reply) == [431] and b"at most 16384 bytes" in reply and closed and seconds < 0.5, reply


def test_a_client_that_stops_reading_a_response_is_dropped(served):
    server, config, _, folder = served
    participant, _ = ready(server)
    size = 32 << 20
    for side in ("human", "robot"):  # a stimulus far larger than the socket buffers
        (folder / f"{side}-{config.pairs[0].id[1:]}.wav").write_bytes(bytes(size))
    position = [pair for pair, _ in plan(config, participant)].index("p0")
    with socket.socket() as connection:
        connection.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        connection.connect(address(server))
        connection.sendall(f"GET /p/{participant}/audio/{position}/A HTTP/1.1\r\nHost: localhost\r\n\r\n".encode())
        time.sleep(1.0 + 1.5)  # reading nothing for longer than body_timeout
        connection.settimeout(5.0)
        received = 0
        try:  # what the kernels had buffered, then the end: the server has let the rest go
            while chunk := connection.recv(1 << 20):
                received += len(chunk)
        except ConnectionResetError:
            pass
    assert 0 < received < size / 2


def test_over_the_per_client_cap_is_503_and_at_the_cap_the_longest_waiting_make_room(tmp_path):
    """One connection over a client's cap is answered 503 at once; at the cap in all, each newcomer takes the
    place of the connection that has waited longest without a whole request (503 if it had sent part of one)."""
    server, _, _ = start_test(tmp_path, pairs=1, token=TOKEN, seed=1, proxies=["127.0.0.9"],
                              limits="connections_per_client = 5\nconnections = 20\nhead_timeout = 10.0")
    host_port = address(server)

    def connect(source):
        return socket.create_connection(host_port, source_address=(source, 0))

    try:
        assert server.connections == 20
        held = [connect("127.0.0.2") for _ in range(5)]
        sixth = connect("127.0.0.2")
        reply = answered_at_once(sixth, wait=5.0)
        assert statuses(reply) == [503] and b"from your address" in reply
        assert headers_of(reply)["retry-after"] == "5" and headers_of(reply)["x-frame-options"] == "DENY"
        held += [connect("127.0.0.9") for _ in range(10)]  # a trusted proxy's are not counted per client
        held += [connect("127.0.0.3") for _ in range(5)]  # 20 open in all
        assert all(answered_at_once(c, wait=0.01) is None for c in held)
        held[0].sendall(b"GET / HTTP/1.1\r\nHost: local")  # the first trickles: still waiting the longest
        newcomers = [connect("127.0.0.4"), connect("127.0.0.4")]
        reply = answered_at_once(held[0], wait=5.0)
        assert statuses(reply) == [503] and b"this request had not arrived whole" in reply
        assert answered_at_once(held[1], wait=5.0) == b""  # idle, the next longest: closed without a word
        assert all(answered_at_once(c, wait=0.01) is None for c in held[2:] + newcomers)
        for connection in (held[7], newcomers[1]):
            connection.setblocking(True)
            connection.sendall(b"GET / HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n")
            assert statuses(connection.recv(4096)) == [200]
        for connection in held + newcomers:
            connection.close()
        time.sleep(0.3)
        assert Client(server.url, source="127.0.0.4").get("/").status == 200  # room again
    finally:
        server.stop()


def test_at_the_cap_with_no_connection_waiting_a_newcomer_is_answered_503(tmp_path):
    """Connections whose whole requests are being answered are not dropped for room: the newcomer is refused."""
    server, _, _ = start_test(tmp_path, pairs=1, token=TOKEN, seed=1, limits="connections = 3")
    try:
        participant, _ = ready(server)
        for side in ("human", "robot"):  # responses far larger than the socket buffers, left unread
            (tmp_path / f"{side}-0.wav").write_bytes(bytes(32 << 20))
        time.sleep(0.3)  # the participant's connections have closed
        busy = []
        for _ in range(3):
            connection = socket.socket()
            connection.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            connection.connect(address(server))
            connection.sendall(f"GET /p/{participant}/audio/0/A HTTP/1.1\r\nHost: localhost\r\n\r\n".encode())
            busy.append(connection)
        time.sleep(0.5)
        reply = answered_at_once(socket.create_connection(address(server)), wait=5.0)
        assert statuses(reply) == [503] and b"too many connections are open: try again" in reply
        for connection in busy:
            connection.close()
        time.sleep(0.3)
        assert Client(server.url).get("/").status == 200
    finally:
        server.stop()


def answered_at_once(connection, wait=0.3):
    """What the server said at once (within ``wait`` s; b"" if it closed), or None: held open, waiting."""
    connection.settimeout(wait)
    try:
        return connection.recv(4096)
    except TimeoutError:
        return None
    except ConnectionResetError:
        return b""


def test_a_thousand_trickling_connections_neither_stop_a_participant_nor_stay(tmp_path):
    """1,000 connections from 5 addresses trickle a request head; a participant from a sixth does the whole test.

    The head timeout leaves a busy machine the time to open the flood and take the test while all of it is
    held; each wait polls up to a generous bound, and times are taken so that load can only lengthen them.
    """
    head_timeout = 3.0
    server, _, store = start_test(tmp_path, pairs=PAIRS, token=TOKEN, seed=5, limits=f"head_timeout = {head_timeout}")
    try:
        opened, trickles = {}, []
        for i in range(1000):
            began = time.monotonic()  # before connecting: the server's clock for it starts after
            connection = socket.create_connection(address(server), source_address=(f"127.0.0.{2 + i % 5}", 0))
            opened[connection] = began
            trickles.append(connection)
        # the caps (100 per client by default) answer the other 500 at once: without waiting for a request
        refused = answered(trickles, 500, time.monotonic() + 60.0)
        held = [connection for connection in trickles if connection not in refused]
        for connection in held:
            connection.send(b"GET / HTTP/1.1\r\nHost: localhost\r\nX-Slow: ")
        result = {}
        trickler = threading.Thread(target=lambda: result.update(trickle(held, time.monotonic() + 60.0)))
        trickler.start()

        client = Client(server.url, source="127.0.0.1")
        participant = client.start()
        for k in range(PAIRS):
            assert client.get(f"/p/{participant}/pair/{k}").status == 200
            for side in ("A", "B"):
                assert client.get(f"/p/{participant}/audio/{k}/{side}").status == 200
            assert client.play_and_answer(participant, k, "A", 3, 3)[0].status == 303
        assert client.get(f"/p/{participant}/done").status == 200
        finished = time.monotonic()
        trickler.join()

        assert len(refused) == 500
        assert all(statuses(r) == [503] and b"from your address" in r for r in refused.values())
        assert len(store.rows()) == PAIRS
        closed, replies, sent = result["closed"], result["replies"], result["sent"]
        assert len(closed) == len(held) == 500 and all(statuses(replies[c]) == [408] for c in held)
        lifetimes = [closed[c] - opened[c] for c in held]
        assert min(closed.values()) > finished  # all 500 were open while the participant took the test
        # cut at the deadline of the whole head, though a byte came every 0.25 s: not before it, and not put off
        assert head_timeout - 0.1 < min(lifetimes) and max(lifetimes) < 2 * head_timeout
        assert min(sent[c] for c in held) >= 5  # each kept trickling, a byte every 0.25 s, to the end
    finally:
        for connection in trickles:
            connection.close()
        server.stop()


def answered(connections, count, deadline):
    """{connection: what the server sent} for those it answered, once ``count`` have answered (or ``deadline``)."""
    for connection in connections:
        connection.setblocking(False)
    replies = {}
    while len(replies) < count and time.monotonic() < deadline:
        for connection in connections:
            if connection not in replies:
                try:
                    replies[connection] = connection.recv(4096)
                except BlockingIOError:
                    pass
        time.sleep(0.05)
    return replies


def trickle(held, deadline, interval=0.25):
    """Send a byte on each socket every ``interval`` s until the server closes it (or ``deadline``).

    Returns {"closed": {socket: when}, "replies": {socket: bytes}, "sent": {socket: bytes sent}}.
    """
    selector = selectors.DefaultSelector()
    for connection in held:
        selector.register(connection, selectors.EVENT_READ)
    closed, replies, sent = {}, dict.fromkeys(held, b""), dict.fromkeys(held, 0)
    next_byte = time.monotonic() + interval
    while len(closed) < len(held) and time.monotonic() < deadline:
        for key, _ in selector.select(timeout=0.02):
            try:
                data = key.fileobj.recv(4096)
            except ConnectionResetError:
                data = b""
            replies[key.fileobj] += data
            if not data:
                closed[key.fileobj] = time.monotonic()
                selector.unregister(key.fileobj)
        if time.monotonic() >= next_byte:
            next_byte += interval
            for connection in held:
                if connection not in closed and not replies[connection]:
                    try:
                        sent[connection] += connection.send(b"a")
                    except OSError:
                        pass
    return {"closed": closed, "replies": replies, "sent": sent}


def test_a_host_the_server_does_not_serve_is_answered_400_and_starts_nothing(served, tmp_path):
    """DNS rebinding: a page elsewhere reaching a server on loopback through a name of its own is refused; the
    loopback names (any port) and, when named, the proxy's are served."""
    server, config, store, _ = served
    port = address(server)[1]
    for host in ("evil.example", "evil.example:80", "127.0.0.1.evil.example", "[::2]"):
        reply, _, closed = exchange(server, f"POST /start HTTP/1.1\r\nHost: {host}\r\nContent-Length: 0\r\n\r\n".encode())
        assert statuses(reply) == [400] and b"does not serve the host" in reply and closed, (host, reply)
        assert headers_of(reply)["x-content-type-options"] == "nosniff"
    for host in (f"127.0.0.1:{port}@evil.example", f"localhost:{port}:{port}", "localhost:", "localhost:99999",
                 f"localhost:{port}/x", "local host", "[::1]evil", "évil.example"):  # loopback names, but not exactly
        reply, _, closed = exchange(server, f"POST /start HTTP/1.1\r\nHost: {host}\r\nContent-Length: 0\r\n\r\n"
                                            .encode("latin-1"))
        assert statuses(reply) == [400] and b"must be a host name" in reply and closed, (host, reply)
    reply, _, closed = exchange(server, b"GET / HTTP/1.0\r\n\r\n")  # no Host: HTTP/1.0 allows it
    assert statuses(reply) == [400] and b"in one Host header, got 0" in reply and closed, reply
    reply, _, closed = exchange(server, b"GET / HTTP/1.1\r\nHost: localhost\r\nHost: evil.example\r\n\r\n")
    assert statuses(reply) == [400] and closed, reply  # two: the HTTP parser refuses it first
    for host in (f"localhost:{port}", f"127.0.0.1:{port}", "LOCALHOST", f"[::1]:{port}"):
        reply, _, _ = exchange(server, f"GET / HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n".encode())
        assert statuses(reply) == [200], (host, reply[:300])
    assert store.rows() == []
    (tmp_path / "named").mkdir()
    named, _, _ = start_test(tmp_path / "named", pairs=PAIRS, token=TOKEN, seed=3, hosts=["Study.Example.org"])
    try:
        for host, status in (("study.example.org", 200), ("study.example.org:443", 200), (f"localhost:{port}", 200),
                             ("other.example.org", 400)):
            reply, _, _ = exchange(named, f"GET / HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n".encode())
            assert statuses(reply) == [status], (host, reply[:300])
    finally:
        named.stop()
    anywhere = Server(make_app(config, store, hosts=None), config.limits, host="127.0.0.1", port=0).start()
    try:  # serving any name (as on a public address without --allowed-host): the syntax is still exact
        for host, status in (("anything.example:8080", 200), ("[2001:db8::1]", 200), ("a.example:80@b.example", 400),
                             ("a.example:80:80", 400)):
            reply, _, _ = exchange(anywhere, f"GET / HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n".encode())
            assert statuses(reply) == [status], (host, reply[:300])
        assert statuses(exchange(anywhere, b"GET / HTTP/1.0\r\n\r\n")[0]) == [200]  # HTTP/1.0 may leave it out
    finally:
        anywhere.stop()
    (tmp_path / "bad").mkdir()
    with pytest.raises(ParameterError, match=r"allowed host 'study.example.org/x' is not a host name"):
        start_test(tmp_path / "bad", pairs=PAIRS, token=TOKEN, seed=3, hosts=["study.example.org/x"])


# --- floods of trickling connections: the server holds many and still serves a visitor -----------------------------

class Flood:
    """Connections that trickle a request head from a thread: ``per_source`` from each of ``sources``.

    Each sends the start of a head when it opens, then a byte every ``interval`` s. With ``reconnect``, each
    connection the server closes is opened again at once, as an attacker keeping the server full would.

    Attributes
    ----------
    opened : int
        Connections opened so far.
    closed : list of (str, bytes)
        Each connection the server closed: its source and what the server said before.
    """

    HEAD = b"GET / HTTP/1.1\r\nHost: localhost\r\nX-Slow: "

    def __init__(self, server, sources, per_source, *, interval=1.0, reconnect=False):
        self.target, self.interval, self.reconnect = address(server), interval, reconnect
        self.selector = selectors.DefaultSelector()
        self.opened, self.closed = 0, []
        self._stop = threading.Event()
        for _ in range(per_source):
            for source in sources:  # round robin: each source's connections spread over the opening
                self._open(source)
        self._thread = threading.Thread(target=self._run, daemon=True, name="flood")
        self._thread.start()

    @property
    def open(self):
        return len(self.selector.get_map())

    def stop(self):
        self._stop.set()
        self._thread.join(timeout=30.0)
        for key in list(self.selector.get_map().values()):
            key.fileobj.close()

    def _open(self, source):
        connection = socket.create_connection(self.target, timeout=30.0, source_address=(source, 0))
        connection.setblocking(False)
        connection.send(self.HEAD)
        self.selector.register(connection, selectors.EVENT_READ, [source, b""])
        self.opened += 1

    def _run(self):
        next_byte = time.monotonic() + self.interval
        while not self._stop.is_set():
            for key, _ in self.selector.select(timeout=0.05):
                try:
                    data = key.fileobj.recv(4096)
                except BlockingIOError:
                    continue
                except OSError:  # reset: what the server said may be lost with it
                    data = b""
                if data:
                    key.data[1] += data
                    continue
                self.selector.unregister(key.fileobj)
                key.fileobj.close()
                self.closed.append(tuple(key.data))
                if self.reconnect and not self._stop.is_set():
                    self._open(key.data[0])
            if time.monotonic() >= next_byte:
                next_byte += self.interval
                for key in list(self.selector.get_map().values()):
                    try:
                        key.fileobj.send(b"a")
                    except OSError:
                        pass


def flood_size(sources, per_source):
    """(sources, per_source) for a flood this process can hold both ends of: the open-file limit is raised to
    its hard limit, and the flood made smaller (with a warning) if even that is too low."""
    import resource
    import warnings

    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft != hard:
        resource.setrlimit(resource.RLIMIT_NOFILE, (hard, hard))
    room = (hard - 1000) // 2  # both ends of each connection are in this process, and files besides
    if hard != resource.RLIM_INFINITY and room < sources * per_source:
        warnings.warn(f"the open-file hard limit is {hard}: the flood is {room // sources} connections from each "
                      f"of {sources} addresses, not {per_source}")
        per_source = room // sources
    return [f"127.0.{2 + i // 200}.{2 + i % 200}" for i in range(sources)], per_source


def test_five_thousand_trickling_connections_from_fifty_addresses_all_held_and_a_visitor_served(tmp_path):
    """5,000 connections from 50 addresses (100 each, the cap per client) trickle a head, a byte a second each;
    the server holds every one of them (far under its cap, sized from the open-file limit) while a visitor
    from another address loads the first page and starts a session. The times are printed (``-s``); the
    bound on the visitor's is generous, for a busy machine."""
    sources, per_source = flood_size(50, 100)
    server, _, store = start_test(tmp_path, pairs=PAIRS, token=TOKEN, seed=5, limits="head_timeout = 120.0")
    flood = None
    try:
        began = time.monotonic()
        flood = Flood(server, sources, per_source)
        opening = time.monotonic() - began
        time.sleep(2.5)  # every connection trickles: it has sent a byte or two more than its opening
        visitor = Client(server.url, source="127.0.1.250")
        began = time.monotonic()
        first = visitor.get("/")
        page = time.monotonic() - began
        participant = visitor.start()
        session = time.monotonic() - began
        assert first.status == 200 and store.plan_of(participant) is not None
        assert page < 10.0 and session < 10.0
        assert flood.closed == [] and flood.open == flood.opened == len(sources) * per_source
        assert server.connections > flood.opened
        print(f"\n{flood.opened} connections opened in {opening:.2f} s; with all held, the visitor's first page "
              f"in {page * 1e3:.1f} ms, page and session start in {session * 1e3:.1f} ms")
    finally:
        if flood is not None:
            flood.stop()
        server.stop()


def test_reconnecting_trickles_at_the_cap_leave_every_visitor_served(tmp_path):
    """1,000 trickling connections from 10 addresses against a cap of 500, each reconnected as soon as the
    server drops it (the server stays full, as an attacker keeps it): each newcomer takes the place of the
    longest-waiting trickle, so 20 visitors in a row, each sending a whole request, are all served."""
    server, _, _ = start_test(tmp_path, pairs=1, token=TOKEN, seed=5, limits="connections = 500\nhead_timeout = 60.0")
    flood = None
    try:
        flood = Flood(server, [f"127.0.0.{2 + i}" for i in range(10)], 100, interval=0.5, reconnect=True)
        deadline = time.monotonic() + 120.0  # the flood fills the cap and churns: at once on an idle machine
        while len(flood.closed) <= 500:  # more than the cap dropped: the server has been full and stays so
            assert time.monotonic() < deadline, f"only {len(flood.closed)} trickles dropped in 120 s"
            time.sleep(0.05)
        dropped_before = len(flood.closed)
        visits, starved = [], 0
        for i in range(20):
            began = time.monotonic()
            try:
                reply = Client(server.url, source=f"127.0.1.{1 + i}").get("/")
            except ConnectionResetError:  # on a busy machine this thread may stall between connecting and sending
                starved += 1  # its request: its connection then waits longest and makes room; it asks again
                reply = Client(server.url, source=f"127.0.1.{1 + i}").get("/")
            visits.append((reply.status, time.monotonic() - began))
        assert [status for status, _ in visits] == [200] * 20 and starved <= 2
        assert max(seconds for _, seconds in visits) < 10.0
        dropped = flood.closed[:]
        assert len(dropped) > dropped_before > 500  # the server is kept full: the churn goes on throughout
        said = [reply for _, reply in dropped if reply]
        assert said and all(statuses(r) == [503] and b"had not arrived whole" in r for r in said)
        print(f"\n{flood.opened} trickling connections opened, {len(dropped)} dropped for room; 20 visits served in "
              f"{min(s for _, s in visits) * 1e3:.1f} to {max(s for _, s in visits) * 1e3:.1f} ms")
    finally:
        if flood is not None:
            flood.stop()
        server.stop()
