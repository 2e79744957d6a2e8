"""A studio served for the tests, a client that asks it as the page does (real HTTP/1.1 over a socket), the command
line run as a user runs it, and the screenshots."""

import contextlib
import http.client
import io
import json
import urllib.parse
from collections import namedtuple

Reply = namedtuple("Reply", "status headers body")


def cli(*argv):
    """Run ``drumstroke ARGV`` in this process, as the console script runs it; what it printed (it must succeed)."""
    from drumstroke.cli import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(list(argv))
    assert code in (0, None), out.getvalue()
    return out.getvalue()


class Client:
    """Requests to a studio at ``url``, a new connection each; ``ask`` sends JSON as the page's ``fetch`` does
    (``Origin`` and ``Sec-Fetch-Site: same-origin``)."""

    def __init__(self, url):
        parts = urllib.parse.urlsplit(url)
        self.host, self.port, self.origin = parts.hostname, parts.port, f"http://{parts.netloc}"

    def request(self, method, path, body=None, headers=None):
        connection = http.client.HTTPConnection(self.host, self.port, timeout=60)
        try:
            connection.request(method, path, body=body, headers=headers or {})
            response = connection.getresponse()
            return Reply(response.status, response.headers, response.read())
        finally:
            connection.close()

    def ask(self, operation, data=None, *, raw=None, headers=None):
        """POST /api/OPERATION with ``data`` as JSON (or the bytes ``raw``); the Reply."""
        body = raw if raw is not None else json.dumps(data if data is not None else {}).encode()
        sent = {"Content-Type": "application/json", "Origin": self.origin, "Sec-Fetch-Site": "same-origin"}
        sent.update(headers or {})
        return self.request("POST", f"/api/{operation}", body, sent)

    def answer(self, operation, data=None):
        """The JSON answer of a request that must succeed."""
        reply = self.ask(operation, data)
        assert reply.status == 200, (reply.status, reply.body[:300])
        return json.loads(reply.body)

    def error(self, operation, data=None, *, status=400, **options):
        """The one-line error of a request that must be refused with ``status``."""
        reply = self.ask(operation, data, **options)
        assert reply.status == status, (reply.status, reply.body[:300])
        message = json.loads(reply.body)["error"]
        assert "\n" not in message
        return message


def screenshot(page, name, tmp_path):
    """Save the page as PNG ``name``: into the folder ``$DRUMSTROKE_SCREENSHOTS`` names (the docs' pictures are
    taken with ``DRUMSTROKE_SCREENSHOTS=docs/images``), else into ``tmp_path``, so a test run changes no file of
    the repository. Returns the path, checked to be a PNG of the page's viewport."""
    import os
    import struct
    from pathlib import Path

    folder = Path(os.environ.get("DRUMSTROKE_SCREENSHOTS") or tmp_path)
    path = folder / name
    page.screenshot(path=str(path))
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert struct.unpack(">II", data[16:24]) == (page.viewport_size["width"], page.viewport_size["height"])
    return path


CHROMIUM = "/usr/bin/chromium"


@contextlib.contextmanager
def browser_tab(url):
    """Debian's Chromium (through Playwright) on the studio page ``url`` at 1366 x 768, downloads accepted, sound
    allowed without a gesture; the test fails if a script or style was blocked by the Content-Security-Policy or
    a script raised."""
    from playwright.sync_api import sync_playwright

    refused = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True,
                                    args=["--no-sandbox", "--autoplay-policy=no-user-gesture-required"])
        tab = browser.new_page(viewport={"width": 1366, "height": 768}, accept_downloads=True)
        tab.set_default_timeout(120000)  # a generous bound on every wait: a busy machine is slower, never wrong
        tab.on("console", lambda message: refused.append(message.text) if "Content Security" in message.text else None)
        tab.on("pageerror", lambda error: refused.append(str(error)))
        tab.goto(url)
        yield tab
        browser.close()
    assert refused == []


WAIT = 120000
"""ms: the longest a browser test waits for a page state (a cold cache compiles the planner on a busy machine)."""


@contextlib.contextmanager
def part_editor():
    """A studio served on a free port and Chromium on its part editor, once the editor's first plan is drawn and its
    Kit switch can be used."""
    from drumstroke.studio.app import make_studio

    server = make_studio(port=0).start()
    try:
        with browser_tab(server.url.rstrip("/") + "/#part") as tab:
            tab.wait_for_selector("body[data-planned]")
            tab.wait_for_selector("#part-kit:not([disabled])")
            yield tab
    finally:
        server.stop()


def planned(page, notes):
    """Wait until the part editor has drawn a plan of ``notes`` notes."""
    page.wait_for_selector(f"body[data-planned='{notes}']", timeout=WAIT)
