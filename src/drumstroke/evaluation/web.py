"""The listening test on the web (Starlette): pages, stimuli, plays, answers and the export, each request checked.

Imported when serving (:func:`drumstroke.evaluation.app.make_server`; Starlette comes with the
``listen`` extra). What a request meets:

- **Headers**: every response carries :data:`~drumstroke.evaluation.pages.SECURITY_HEADERS` and, but for
  the static files, ``Cache-Control: no-store``; over TLS also ``Strict-Transport-Security``. A request
  whose line and headers exceed :data:`~drumstroke.evaluation.limits.MAX_HEAD` is answered 431.
- **Paths**: a participant is 32 hexadecimal digits, a pair's position 1-6 digits 0-9, a side A or B;
  anything else is answered 400 with a message (404 for a well-formed participant or pair that does not
  exist).
- **Forms** (start, played, answer): urlencoded UTF-8 of at most ``max_body`` bytes, refused with 413 by
  their ``Content-Length`` before being read, whole within ``body_timeout`` (else 408), each field once
  and none unknown (else 400); both ``Content-Length`` and ``Transfer-Encoding`` is 400. A refusal made
  before the whole body was read closes the connection.
- **Cross-site requests**: a form is refused (403, nothing stored) when ``Sec-Fetch-Site`` is not
  same-origin, when ``Origin`` is another origin, or without its token in the ``csrf`` field. The
  consent page's token is random and signed, and also set as a cookie (``SameSite=Strict``,
  ``HttpOnly``, ``Secure`` over TLS) that the start must carry; a pair page's is derived from the
  participant (HMAC-SHA256 under a key derived from the admin token), so nothing is stored and a
  restarted server still accepts it.
- **New sessions** are limited per client (``[limits]``): one more is answered 429 with ``Retry-After``.
  Beyond the limit for all clients together, a client that has started one in the last minute is
  refused, one that has not is still admitted: no flood shuts out a newcomer.
- **The export** takes the admin token in an ``Authorization: Bearer`` header only, compared in constant
  time (as SHA-256 digests: its length is not told either); a URL with a query is refused (400, the token
  not echoed). After 10 wrong tokens in a minute from a client, the export answers that client 429 until
  the minute has passed; no count is kept over all clients, so others' wrong tokens never lock the admin out.
- **Host**: exactly a name and an optional port (``127.0.0.1:80@evil.example`` is 400), and, when the
  server names its hosts, one of them.
- **Failures**: a stimulus that cannot be read is answered 500 with a message and its reason logged;
  any other error 500 with a message, its traceback logged by uvicorn.
"""

import base64
import hashlib
import hmac
import logging
import os
import re
import secrets
import stat
from http import HTTPStatus
from urllib.parse import parse_qsl

import anyio
from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.datastructures import MutableHeaders
from starlette.exceptions import HTTPException
from starlette.responses import HTMLResponse, PlainTextResponse, RedirectResponse, Response
from starlette.routing import Route

from .._checks import shown
from . import pages
from .limits import MAX_HEAD, Window, client_key, host_name

log = logging.getLogger(__name__)

COOKIE = "drumstroke_csrf"
"""The cookie holding the consent page's token."""

ADMIN_FAILURES = 10
"""Wrong admin tokens allowed per minute from one client (none is counted over all clients)."""

_CLOSE = {"Connection": "close"}
_PARTICIPANT = re.compile(r"[0-9a-f]{32}")
_POSITION = re.compile(r"[0-9]{1,6}")
_SCALE = ("1", "2", "3", "4", "5")
_CHUNK = 1 << 16
_UNPLAYABLE = ("this stimulus cannot be played: the server cannot read its file (the reason is logged for the "
               "experimenter)")


def make_app(config, store, *, hosts=None):
    """The ASGI application serving ``config``'s test from ``store`` (a :class:`~drumstroke.evaluation.app.Store`).

    ``hosts``: the names a request's ``Host`` header may give (see
    :func:`~drumstroke.evaluation.limits.served_hosts`); None, any.
    """
    site = _Site(config, store)
    routes = [
        Route("/", site.consent),
        Route("/start", site.start, methods=["POST"]),
        Route("/p/{participant}/pair/{position}", site.pair),
        Route("/p/{participant}/pair/{position}/played", site.played, methods=["POST"]),
        Route("/p/{participant}/pair/{position}/answer", site.answer, methods=["POST"]),
        Route("/p/{participant}/audio/{position}/{side}", site.audio),
        Route("/p/{participant}/done", site.done),
        Route("/admin/export.csv", site.export),
        Route("/static/{name}", site.static),
    ]
    return Guard(Starlette(routes=routes, exception_handlers={HTTPException: _refused, Exception: _failed}), hosts)


class _Site:
    """The endpoints, over one config and store."""

    def __init__(self, config, store):
        self.config, self.store, self.limits = config, store, config.limits
        self.pairs = {p.id: p for p in config.pairs}
        self.tokens = _Tokens(config.admin_token)
        self.sessions = Window(self.limits.sessions_per_minute_per_client, self.limits.sessions_per_minute)
        self.admin_failures = Window(ADMIN_FAILURES, None)
        self.files = {name: pages.static(name) for name in pages.STATIC}

    # --- the participant's pages -------------------------------------------------------------------------------
    async def consent(self, request):
        token = request.cookies.get(COOKIE, "")
        if not self.tokens.is_browser(token):
            token = self.tokens.browser()
        response = HTMLResponse(pages.consent(self.config, token))
        response.set_cookie(COOKIE, token, path="/", httponly=True, samesite="strict",
                            secure=request.url.scheme == "https")
        return response

    async def start(self, request):
        form = await self._form(request, ("consent", "csrf"))
        cookie = request.cookies.get(COOKIE, "")
        if not (self.tokens.is_browser(cookie) and _same(cookie, form.get("csrf", ""))):
            raise HTTPException(403, "the consent form's token is missing or does not match its cookie: reload the "
                                     "first page (this site's cookies must be allowed)")
        if form.get("consent") != "yes":
            raise HTTPException(400, "consent is needed to take part")
        wait = self.sessions.admit(client_key(request.client.host if request.client else None))
        if wait:
            raise HTTPException(429, f"too many new sessions: try again in {wait} s",
                                headers={"Retry-After": str(wait)})
        participant = await run_in_threadpool(self.store.new_participant, self.config)
        return RedirectResponse(f"/p/{participant}/pair/0", status_code=303)

    async def pair(self, request):
        participant, position = _path(request)
        steps = await self._plan(participant)
        if position >= len(steps):
            return RedirectResponse(f"/p/{participant}/done", status_code=303)
        answered = await run_in_threadpool(self.store.answered, participant)
        if position in answered:
            return RedirectResponse(_next(participant, steps, answered), status_code=303)
        token = self.tokens.session(participant)
        return HTMLResponse(pages.pair_page(self.config, participant, position, len(steps), token))

    async def done(self, request):
        participant = _participant(request)
        await self._plan(participant)
        return HTMLResponse(pages.finish(self.config, participant))

    async def audio(self, request):
        participant, position = _path(request)
        side = request.path_params["side"]
        if side not in ("A", "B"):
            raise HTTPException(400, f"a side is A or B, got {_shown(side)}")
        pair_id, robot = _step(await self._plan(participant), position)
        pair = self.pairs.get(pair_id)
        if pair is None:  # the config lost a pair since this participant started
            log.error("participant %s, pair %r: the pair is not in the config any more", participant, pair_id)
            raise HTTPException(500, _UNPLAYABLE)
        file = pair.robot if side == robot else pair.human
        try:
            handle, size = await anyio.to_thread.run_sync(_open_regular, file)
        except OSError as error:
            log.error("participant %s, pair %r, side %s: cannot read the stimulus %s: %s", participant, pair_id, side,
                      file, error.strerror or error)
            raise HTTPException(500, _UNPLAYABLE) from None
        return _Stimulus(handle, size)

    # --- what a participant does -------------------------------------------------------------------------------
    async def played(self, request):
        form = await self._form(request, ("side", "csrf"))
        participant, position = _path(request)
        self._check_session(participant, form)
        _step(await self._plan(participant), position)
        side = form.get("side")
        if side not in ("A", "B"):
            raise HTTPException(400, f"side must be A or B, got {_shown(side)}")
        await run_in_threadpool(self.store.played, participant, position, side)
        return Response(status_code=204)

    async def answer(self, request):
        form = await self._form(request, ("answer", "confidence", "similarity", "csrf"))
        participant, position = _path(request)
        self._check_session(participant, form)
        steps = await self._plan(participant)
        _step(steps, position)
        answer = form.get("answer")
        if answer not in ("A", "B"):
            raise HTTPException(400, f"answer must be A or B, got {_shown(answer)}")
        values = []
        for key in ("confidence", "similarity"):
            value = form.get(key, "")
            if value not in _SCALE:
                raise HTTPException(400, f"{key} must be an integer in [1, 5], got {_shown(value)}")
            values.append(int(value))
        location = await run_in_threadpool(self._store_answer, participant, position, steps, answer, *values)
        return RedirectResponse(location, status_code=303)

    def _store_answer(self, participant, position, steps, answer, confidence, similarity):
        answered = self.store.answered(participant)
        if position not in answered:
            if self.store.sides_played(participant, position) != {"A", "B"}:
                raise HTTPException(409, "play both stimuli, A and B, before answering")
            pair_id, robot = steps[position]
            self.store.answer(participant, position, pair_id, robot, answer, confidence, similarity)
            answered = self.store.answered(participant)
        return _next(participant, steps, answered)

    # --- the experimenter's and the static files ---------------------------------------------------------------
    async def export(self, request):
        if request.url.query:
            raise HTTPException(400, "the export takes no query: send the admin token in an 'Authorization: Bearer' "
                                     "header, never in a URL (URLs are logged and kept in histories); a token that "
                                     "was in one should be changed")
        client = client_key(request.client.host if request.client else None)
        wait = self.admin_failures.wait(client)
        if wait:
            raise HTTPException(429, f"too many wrong admin tokens: try again in {wait} s",
                                headers={"Retry-After": str(wait)})
        scheme, _, token = request.headers.get("authorization", "").partition(" ")
        if scheme.lower() != "bearer" or not _same_digest(token.strip(), self.config.admin_token):
            self.admin_failures.admit(client)
            raise HTTPException(401, "the export needs the admin token in a header: 'Authorization: Bearer TOKEN'",
                                headers={"WWW-Authenticate": 'Bearer realm="drumstroke"'})
        text = await run_in_threadpool(self.store.export_csv)
        return Response(text, media_type="text/csv; charset=utf-8",
                        headers={"Content-Disposition": 'attachment; filename="answers.csv"'})

    async def static(self, request):
        name = request.path_params["name"]
        if name not in self.files:
            raise HTTPException(404, "no such file")
        return Response(self.files[name], media_type=pages.STATIC[name], headers={"Cache-Control": "no-cache"})

    # --- checks ------------------------------------------------------------------------------------------------
    async def _plan(self, participant):
        steps = await run_in_threadpool(self.store.plan_of, participant)
        if steps is None:
            raise HTTPException(404, "unknown participant")
        return steps

    def _check_session(self, participant, form):
        if not _same(form.get("csrf", ""), self.tokens.session(participant)):
            raise HTTPException(403, "the form's token is missing or is not this participant's: reload the page")

    async def _form(self, request, fields):
        """The request's form as {field: value}, after the cross-site, size, time and syntax checks."""
        body = await changing_body(request, "application/x-www-form-urlencoded", self.limits, "a form")
        return _fields(body, fields)


class _Tokens:
    """The forms' tokens: HMAC-SHA256 under a key derived from the admin token (no token is stored)."""

    def __init__(self, admin_token):
        self._key = hmac.new(admin_token.encode(), b"drumstroke listening-test form tokens", hashlib.sha256).digest()

    def _mac(self, text):
        digest = hmac.new(self._key, text.encode(), hashlib.sha256).digest()
        return base64.urlsafe_b64encode(digest).rstrip(b"=").decode()

    def browser(self):
        """A new consent-page token: a random nonce and its signature."""
        nonce = secrets.token_urlsafe(18)
        return f"{nonce}.{self._mac('browser:' + nonce)}"

    def is_browser(self, token):
        """Whether ``token`` is a consent-page token this server signed."""
        nonce, dot, mac = token.partition(".")
        return bool(dot) and _same(mac, self._mac("browser:" + nonce))

    def session(self, participant):
        """The token of the participant's pair pages."""
        return self._mac("session:" + participant)


class Guard:
    """The application behind a check of the head's size and its ``Host`` (exactly a name and an optional port;
    one of ``hosts``, unless None), with the security headers on every response.

    ``Cache-Control: no-store`` is added to a response that does not set its own (the static files do).
    """

    def __init__(self, app, hosts=None):
        self.app, self.hosts = app, hosts

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        tls = scope.get("scheme") == "https"
        size = len(scope.get("raw_path", b"")) + len(scope["query_string"]) + sum(len(k) + len(v) + 4
                                                                                  for k, v in scope["headers"])
        app = self.app if size <= MAX_HEAD else PlainTextResponse(
            f"431 Request Header Fields Too Large: a request's line and headers may hold at most {MAX_HEAD} bytes\n",
            status_code=431, headers=_CLOSE)
        if app is self.app:
            app = self._host_refused(scope) or app

        async def guarded(message):
            if message["type"] == "http.response.start":
                headers = MutableHeaders(scope=message)
                for name, value in pages.SECURITY_HEADERS:
                    headers[name] = value
                if "cache-control" not in headers:
                    headers["Cache-Control"] = "no-store"
                if tls:
                    headers["Strict-Transport-Security"] = "max-age=31536000"
            await send(message)

        return await app(scope, receive, guarded)

    def _host_refused(self, scope):
        """A 400 response if the request's ``Host`` is not exactly one name this server serves, else None."""
        given = [v.decode("latin-1") for k, v in scope["headers"] if k == b"host"]
        if not given and self.hosts is None:  # HTTP/1.0 may leave it out, and any name is served
            return None
        if len(given) != 1:  # a browser never leaves it out nor sends two
            return _bad_request(f"a request names the host it is for in one Host header, got {len(given)}")
        name = host_name(given[0])
        if name is None:  # e.g. 127.0.0.1:80@evil.example, which a looser parse would take for 127.0.0.1
            return _bad_request(f"the Host header must be a host name or a bracketed IPv6 address and an optional "
                                f"port, got {_shown(given[0], 128)}")
        if self.hosts is not None and name not in self.hosts:  # a page elsewhere reaching us by a name of its own
            return _bad_request(f"this server does not serve the host {_shown(name, 128)} (the command's "
                                f"--allowed-host names the hosts served)")
        return None


class _Stimulus(Response):
    """A WAV file opened before the response starts, sent in chunks: deleting it afterwards changes nothing."""

    media_type = "audio/wav"

    def __init__(self, handle, size):
        super().__init__(headers={"Content-Length": str(size)})
        self.handle = handle

    async def __call__(self, scope, receive, send):
        try:
            await send({"type": "http.response.start", "status": self.status_code, "headers": self.raw_headers})
            more = scope["method"] != "HEAD"
            while more:
                chunk = await anyio.to_thread.run_sync(self.handle.read, _CHUNK)
                more = bool(chunk)
                await send({"type": "http.response.body", "body": chunk, "more_body": more})
            if scope["method"] == "HEAD":
                await send({"type": "http.response.body", "body": b"", "more_body": False})
        finally:
            self.handle.close()


def _bad_request(message):
    return PlainTextResponse(f"400 Bad Request: {message}\n", status_code=400, headers=_CLOSE)


def _open_regular(path):
    """An open binary file and its size; a path that is not a regular file is an OSError (never blocks on a FIFO)."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):
        os.close(fd)
        raise OSError(f"{path} is not a regular file")
    return os.fdopen(fd, "rb"), info.st_size


def cross_site(request):
    """Why a state-changing request counts as cross-site, or None.

    ``Sec-Fetch-Site``, which no page can set, must say same-origin when a browser sends it. ``Origin``
    must be the server's own when given; ``null`` says nothing either way (a browser sends it with its
    own form under ``Referrer-Policy: no-referrer``): the form's token decides then.
    """
    site = request.headers.get("sec-fetch-site")
    if site is not None and site not in ("same-origin", "none"):
        return "a request from another site cannot change anything here (Sec-Fetch-Site)"
    origin = request.headers.get("origin")
    own = f"{request.url.scheme}://{request.headers.get('host', '')}"
    if origin is not None and origin != "null" and origin.lower() != own.lower():
        return "a request from another origin cannot change anything here (Origin)"
    return None


async def changing_body(request, media_type, limits, what):
    """The body of a request that changes something: refused (403) when cross-site (:func:`cross_site`), (400)
    with both ``Content-Length`` and ``Transfer-Encoding``, (415) when not of ``media_type``; then read within
    ``limits.max_body`` bytes and ``limits.body_timeout`` s (:func:`read_body`). ``what`` names it ("a form")."""
    headers = request.headers
    reason = cross_site(request)
    if reason:
        raise HTTPException(403, reason, headers=_CLOSE)
    if "transfer-encoding" in headers and "content-length" in headers:
        raise HTTPException(400, "a request cannot have both Content-Length and Transfer-Encoding", headers=_CLOSE)
    if headers.get("content-type", "").partition(";")[0].strip().lower() != media_type:
        raise HTTPException(415, f"{what} must be sent as {media_type}", headers=_CLOSE)
    return await read_body(request, limits.max_body, limits.body_timeout, what)


async def read_body(request, limit, timeout, what):
    """The request's body (bytes): at most ``limit`` bytes, refused with 413 by its ``Content-Length`` before it
    is read, whole within ``timeout`` s of its head (else 408); ``what`` names it in the messages ("a form")."""
    length = request.headers.get("content-length", "0")
    if not length.isascii() or not length.isdigit() or len(length) > 9 or int(length) > limit:
        raise HTTPException(413, f"{what} may hold at most {limit} bytes; this one's Content-Length is "
                                 f"{_shown(length)}", headers=_CLOSE)
    body = bytearray()
    try:
        with anyio.fail_after(timeout):
            more = True
            while more:
                message = await request.receive()
                if message["type"] == "http.disconnect":
                    raise HTTPException(400, f"the connection closed before {what} arrived", headers=_CLOSE)
                body += message.get("body", b"")
                more = message.get("more_body", False)
                if len(body) > limit:
                    raise HTTPException(413, f"{what} may hold at most {limit} bytes", headers=_CLOSE)
    except TimeoutError:
        raise HTTPException(408, f"{what} did not arrive whole within {timeout:g} s", headers=_CLOSE) from None
    return bytes(body)


def _fields(body, allowed):
    """The urlencoded ``body`` as {field: value}: UTF-8, each field once and among ``allowed``."""
    try:
        text = body.decode("utf-8")
    except UnicodeDecodeError:
        raise HTTPException(400, "the form is not UTF-8 text") from None
    try:
        pairs = parse_qsl(text, keep_blank_values=True, strict_parsing=True) if text else []  # max_body bounds it
    except ValueError:
        raise HTTPException(400, f"the form must be name=value fields joined by '&' ({', '.join(allowed)})") from None
    form = {}
    for name, value in pairs:
        if name not in allowed:
            raise HTTPException(400, f"the form has an unknown field {_shown(name)}; its fields: {', '.join(allowed)}")
        if name in form:
            raise HTTPException(400, f"the form gives the field {name!r} twice")
        form[name] = value
    return form


def _participant(request):
    participant = request.path_params["participant"]
    if not _PARTICIPANT.fullmatch(participant):
        raise HTTPException(400, f"a participant id is 32 hexadecimal digits (0-9, a-f), got {_shown(participant)}")
    return participant


def _path(request):
    """The participant and the pair's position named by the path, checked for form only."""
    participant, position = _participant(request), request.path_params["position"]
    if not _POSITION.fullmatch(position):
        raise HTTPException(400, f"a pair's position is a whole number of 1-6 digits 0-9, got {_shown(position)}")
    return participant, int(position)


def _step(steps, position):
    if position >= len(steps):
        raise HTTPException(404, f"no pair at position {position}: this participant has {len(steps)} (0 to "
                                 f"{len(steps) - 1})")
    return steps[position]


def _next(participant, steps, answered):
    todo = [k for k in range(len(steps)) if k not in answered]
    return f"/p/{participant}/pair/{todo[0]}" if todo else f"/p/{participant}/done"


def _same(a, b):
    """Whether two texts are equal, compared in constant time."""
    return hmac.compare_digest(a.encode(), b.encode())


def _same_digest(a, b):
    """Whether two texts are equal, in a time that tells neither their bytes nor their lengths."""
    return hmac.compare_digest(hashlib.sha256(a.encode()).digest(), hashlib.sha256(b.encode()).digest())


def _shown(text, size=48):
    """``text`` (or None: "nothing") for a message, as :func:`~drumstroke._checks.shown` shows it."""
    return "nothing" if text is None else shown(text, most=size)


async def _refused(request, error):
    status = HTTPStatus(error.status_code)
    detail = error.detail if error.detail != status.phrase else {404: "no such page"}.get(status, status.description)
    return PlainTextResponse(f"{status.value} {status.phrase}: {detail}\n", status_code=status,
                             headers=error.headers)


async def _failed(request, error):
    # Starlette raises the error again once this is sent, and uvicorn logs it with its traceback
    return PlainTextResponse("500 Internal Server Error: the server failed to answer; the reason is logged for the "
                             "experimenter\n", status_code=500)
