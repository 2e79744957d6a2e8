"""A small listening test for the app's tests: stimuli, a config, a store, the real server, a browser-like client."""

import http.client
import re
import urllib.parse
from collections import namedtuple

from drumstroke.evaluation.app import Config, Store, make_server
from drumstroke.render.audio import render_wav

Reply = namedtuple("Reply", "status headers body")


def write_test(folder, *, pairs, token, seed, limits=""):
    """Write stimuli and a config (``limits``: the lines of its [limits] table) into ``folder``; the config's path."""
    for i in range(pairs):
        for side, speed in (("human", 1.0), ("robot", 0.7)):
            render_wav(folder / f"{side}-{i}.wav", [0.01, 0.12], [speed, 0.5 * speed], duration=0.3)
    tables = "".join(f'[[pair]]\nid = "p{i}"\nhuman = "human-{i}.wav"\nrobot = "robot-{i}.wav"\n' for i in range(pairs))
    (folder / "test.toml").write_text(f'title = "Robot or human?"\nadmin_token = "{token}"\nseed = {seed}\n{tables}'
                                      + (f"[limits]\n{limits}\n" if limits else ""))
    return folder / "test.toml"


def start_test(folder, *, pairs, token, seed, limits="", proxies=(), hosts=()):
    """:func:`write_test`, then serve it with uvicorn on a free loopback port in a thread, as ``listen serve`` does.

    Returns (server, config, store); ``server.url`` is its address."""
    config = Config.from_toml(write_test(folder, pairs=pairs, token=token, seed=seed, limits=limits))
    store = Store(folder / "results.sqlite")
    server = make_server(config, store, port=0, forwarded_allow_ips=proxies, allowed_hosts=hosts).start()
    return server, config, store


class Client:
    """One browser over real HTTP/1.1: a new connection per request from ``source``, cookies kept, each
    participant's form token read from their page, ``Origin`` and ``Sec-Fetch-Site`` sent with a form as a
    browser sends them (unless ``browser`` is False), redirects not followed."""

    def __init__(self, url, *, source="127.0.0.1", browser=True):
        parts = urllib.parse.urlsplit(url)
        self.host, self.port, self.origin = parts.hostname, parts.port, f"http://{parts.netloc}"
        self.source, self.browser = source, browser
        self.cookies, self.tokens = {}, {}

    def request(self, method, path, form=None, headers=None):
        """A request; the form (a dict, sent in its order) urlencoded. Returns the Reply."""
        body = urllib.parse.urlencode(form).encode() if form is not None else None
        sent = {"Content-Type": "application/x-www-form-urlencoded"} if form is not None else {}
        if self.cookies:
            sent["Cookie"] = "; ".join(f"{name}={value}" for name, value in self.cookies.items())
        if self.browser and method == "POST":
            sent.update({"Origin": self.origin, "Sec-Fetch-Site": "same-origin"})
        sent.update(headers or {})
        connection = http.client.HTTPConnection(self.host, self.port, timeout=30, source_address=(self.source, 0))
        try:
            connection.request(method, path, body=body, headers=sent)
            response = connection.getresponse()
            reply = Reply(response.status, response.headers, response.read())
        finally:
            connection.close()
        for cookie in reply.headers.get_all("Set-Cookie") or []:
            name, _, rest = cookie.partition("=")
            self.cookies[name] = rest.split(";")[0]
        return reply

    def get(self, path, headers=None):
        return self.request("GET", path, headers=headers)

    def post(self, path, form, headers=None):
        return self.request("POST", path, form, headers)

    def start(self):
        """Consent and start a session, as the first page's form does; the participant's id."""
        reply = self.post("/start", {"consent": "yes", "csrf": token_of(self.get("/").body)})
        assert reply.status == 303, reply
        participant = reply.headers["Location"].split("/")[2]
        self.tokens[participant] = token_of(self.get(reply.headers["Location"]).body)
        return participant

    def play_and_answer(self, participant, position, answer, confidence, similarity, *, repeats=1):
        """Play A and B and answer the pair ``repeats`` times over; the answers' replies."""
        token = self.tokens[participant]
        for side in ("A", "B"):
            assert self.post(f"/p/{participant}/pair/{position}/played", {"side": side, "csrf": token}).status == 204
        form = {"answer": answer, "confidence": str(confidence), "similarity": str(similarity), "csrf": token}
        return [self.post(f"/p/{participant}/pair/{position}/answer", form) for _ in range(repeats)]


def token_of(page):
    """The form token of a page (bytes)."""
    return re.search(rb'name="csrf" value="([^"]+)"', page).group(1).decode()
