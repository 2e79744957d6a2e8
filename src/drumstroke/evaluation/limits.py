"""What the listening-test server allows, and how it counts: clients, trusted proxies, sliding windows.

:class:`Limits` is a config's ``[limits]`` table. A client is counted under :func:`client_key`: its
IPv4 address, or its IPv6 /64 network (one host is usually given a whole /64, so counting single IPv6
addresses would let it start sessions without end). :class:`Window` admits events (new sessions, wrong
admin tokens) per client within a sliding minute; its limit for all clients together holds back only
clients that have had an event in the window, so no flood from some addresses shuts out a newcomer.
"""

import ipaddress
import math
import re
import time
from collections import deque
from dataclasses import dataclass

from .._checks import check_int, check_real
from ..errors import ParameterError

MAX_HEAD = 16 * 1024
"""The largest request line and headers accepted, in bytes: more is answered 400 while it comes, 431 once whole."""


@dataclass(frozen=True)
class Limits:
    """What the server allows: new sessions, connections, time and size (a config's optional ``[limits]`` table).

    Attributes
    ----------
    sessions_per_minute_per_client : int in [1, 100000]
        New sessions one client may start in any 60 s (default 10); more are answered 429 with ``Retry-After``.
    sessions_per_minute : int in [1, 100000]
        New sessions all clients together may start in any 60 s (default 120) before only a client's first
        of the minute is admitted: beyond it a client that has started one in the last 60 s is answered 429,
        a client that has not is still admitted (a flood from many addresses never shuts out a newcomer).
    connections_per_client : int in [1, 100000]
        Open connections from one client (default 100; a trusted proxy's are not counted): one more is
        answered 503 and closed at once.
    connections : int in [1, 100000]
        Open connections in all (default 20000; fewer if the open-file limit, raised to its hard limit,
        cannot hold them). At the cap a new connection takes the place of the one that has waited longest
        without delivering a whole request (it is closed, with 503 if part of a request had come); only
        when none is waiting is the new one answered 503 and closed.
    head_timeout : float in [0.1, 600] s
        A request's line and headers must arrive whole within this of the connection opening or of the
        previous response (default 10 s): else 408 and the connection is closed.
    body_timeout : float in [0.1, 600] s
        A request's body must arrive whole within this of its head (default 10 s; else 408), and a client
        that reads nothing of a response for this long is dropped.
    max_body : int in [256, 1048576] bytes
        The largest form accepted (default 4096 bytes; the app's largest is under 200): a larger one is
        refused with 413, by its ``Content-Length`` before it is read.
    """

    sessions_per_minute_per_client: int = 10
    sessions_per_minute: int = 120
    connections_per_client: int = 100
    connections: int = 20000
    head_timeout: float = 10.0
    body_timeout: float = 10.0
    max_body: int = 4096

    def __post_init__(self):
        for name in ("sessions_per_minute_per_client", "sessions_per_minute", "connections_per_client", "connections"):
            object.__setattr__(self, name, check_int(f"limits {name}", getattr(self, name), low=1, high=100_000))
        for name in ("head_timeout", "body_timeout"):
            object.__setattr__(self, name, check_real(f"limits {name}", getattr(self, name), low=0.1, high=600.0,
                                                      unit="s"))
        object.__setattr__(self, "max_body", check_int("limits max_body", self.max_body, low=256, high=1 << 20,
                                                       unit="bytes"))


def client_key(host):
    """The key a client's address ``host`` (str or None) is counted under: an IPv4 address or an IPv6 /64.

    Examples
    --------
    >>> client_key("192.0.2.7"), client_key("::ffff:192.0.2.7")
    ('192.0.2.7', '192.0.2.7')
    >>> client_key("2001:db8::1") == client_key("2001:db8::ffff:1") == "2001:db8::/64"
    True
    """
    try:
        address = ipaddress.ip_address(host)
    except ValueError:
        return str(host)  # not an address (a Unix socket): one client
    if address.version == 6 and address.ipv4_mapped is None:
        return str(ipaddress.ip_network((address, 64), strict=False))
    return str(getattr(address, "ipv4_mapped", None) or address)


def trusted_networks(entries):
    """The trusted proxies ``entries`` (addresses or networks, e.g. ``"10.0.0.0/8"``) as a tuple of networks.

    Raises
    ------
    ParameterError
        An entry that is not an address or a network; ``*`` (trusting every client would let any of them
        choose the address it is counted under).
    """
    networks = []
    for entry in entries:
        text = str(entry).strip()
        if text == "*":
            raise ParameterError("forwarded_allow_ips '*' would trust every client's X-Forwarded-For: name the "
                                 "proxy's addresses (e.g. 127.0.0.1)")
        try:
            networks.append(ipaddress.ip_network(text, strict=False))
        except ValueError:
            raise ParameterError(f"forwarded_allow_ips entry {text!r} is not an IP address or network") from None
    return tuple(networks)


LOOPBACK_NAMES = frozenset({"localhost", "127.0.0.1", "[::1]"})
"""The names a browser on the server's own machine reaches it by."""

_HOST_NAME = re.compile(r"(?:\[[0-9a-f:.]+\]|[a-z0-9](?:[a-z0-9.-]{0,251}[a-z0-9])?)")
_HOST_PORT = re.compile(f"({_HOST_NAME.pattern})(?::([0-9]{{1,5}}))?")


def served_hosts(listen, allowed):
    """The names the ``Host`` header may give (lower case, no port), or None for any.

    ``allowed`` names (e.g. ``["study.example.org"]``, an IPv6 address in brackets) are served, with the
    loopback names; with none, a server listening on loopback (``listen``) serves its loopback names only
    (a page elsewhere cannot reach it through a name of its own: DNS rebinding), one listening on another
    address any name.

    Raises
    ------
    ParameterError
        A name that is not a host name or a bracketed IPv6 address.
    """
    names = set()
    for entry in allowed:
        name = str(entry).strip().lower()
        if not _HOST_NAME.fullmatch(name):
            raise ParameterError(f"allowed host {str(entry)!r} is not a host name (letters, digits, dots and hyphens; "
                                 "an IPv6 address in brackets; no port)")
        names.add(name)
    if names:
        return frozenset(names | LOOPBACK_NAMES)
    try:
        loopback = ipaddress.ip_address(listen.strip("[]")).is_loopback
    except ValueError:
        loopback = listen.lower() == "localhost"
    return LOOPBACK_NAMES if loopback else None


def host_name(header):
    """The name a ``Host`` header gives (lower case, its port taken off), or None if it is not exactly a name
    and an optional port (a host name or a bracketed IPv6 address, then ``:`` and 1-5 digits up to 65535).

    Examples
    --------
    >>> host_name("LocalHost:8765"), host_name("[::1]:80"), host_name("study.example.org")
    ('localhost', '[::1]', 'study.example.org')
    >>> [host_name(h) for h in ("127.0.0.1:80@evil.example", "localhost:", "localhost:99999", "a b", "[::1]x")]
    [None, None, None, None, None]
    """
    match = _HOST_PORT.fullmatch(header.strip().lower())
    if match is None or (match[2] is not None and int(match[2]) > 65535):
        return None
    return match[1]


class Window:
    """At most ``per_key`` events of one key in any ``seconds``; beyond ``overall`` events of all keys in that
    time, only a key that has had none is admitted.

    The overall limit holds back the keys already counted, never a newcomer: a flood from many keys cannot
    shut out one that comes for the first time. Only admitted events are kept, at most ``most`` (the
    oldest are forgotten beyond it), so refused ones cost no memory.

    Parameters
    ----------
    per_key : int >= 1
    overall : int >= 1 or None
        None: no limit over all keys.
    seconds : float > 0 [s]
    clock : callable
        The time in seconds (default :func:`time.monotonic`).
    most : int >= 1
        The most events remembered (default 100,000).

    Examples
    --------
    >>> now = [0.0]
    >>> window = Window(2, 3, seconds=60.0, clock=lambda: now[0])
    >>> [window.admit("a"), window.admit("a"), window.admit("a"), window.admit("b"), window.admit("c")]
    [0, 0, 60, 0, 0]
    >>> window.admit("b"), window.admit("d")  # 4 in the window: b has had one, d none
    (60, 0)
    >>> now[0] = 59.5
    >>> window.wait("a"), window.wait("b")
    (1, 1)
    >>> now[0] = 60.0
    >>> window.admit("a"), window.admit("b")
    (0, 0)
    """

    def __init__(self, per_key, overall, *, seconds=60.0, clock=time.monotonic, most=100_000):
        self.per_key, self.overall, self.seconds, self.clock, self.most = per_key, overall, seconds, clock, most
        self._all = deque()  # (time, key) of every admitted event, oldest first
        self._by_key = {}  # key -> deque of its admitted events' times, oldest first

    def wait(self, key):
        """Whole seconds until an event of ``key`` would be admitted: 0 if now."""
        now = self.clock()
        self._expire(now)
        mine = self._by_key.get(key)
        if mine is None:
            return 0
        oldest = []
        if self.overall is not None and len(self._all) >= self.overall:  # until fewer than overall remain
            oldest.append(self._all[len(self._all) - self.overall][0])
        if len(mine) >= self.per_key:
            oldest.append(mine[len(mine) - self.per_key])
        return max(1, math.ceil(max(oldest) + self.seconds - now)) if oldest else 0

    def admit(self, key):
        """Admit an event of ``key`` if :meth:`wait` is 0 (it is then counted); return what :meth:`wait` said."""
        wait = self.wait(key)
        if not wait:
            if len(self._all) >= self.most:
                self._forget_oldest()
            now = self.clock()
            self._all.append((now, key))
            self._by_key.setdefault(key, deque()).append(now)
        return wait

    def _expire(self, now):
        while self._all and self._all[0][0] <= now - self.seconds:
            self._forget_oldest()

    def _forget_oldest(self):
        _, key = self._all.popleft()
        times = self._by_key[key]
        times.popleft()  # the same event: both queues are in admission order
        if not times:
            del self._by_key[key]
