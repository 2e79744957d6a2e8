"""The studio's server as an attacker and a careless page meet it: real sockets, real HTTP (``drumstroke studio``)."""

import json
import socket
import threading

import numpy as np
import pytest

import drumstroke
from _studio import Client
from drumstroke.errors import ParameterError, SimulationError
from drumstroke.evaluation.limits import Limits
from drumstroke.evaluation.server import Server
from drumstroke.studio import web
from drumstroke.studio.app import MAX_BODY, make_studio
from drumstroke.studio.session import Studio

RECIPE = {"model": "paper", "t_end": 1.5, "cor": 0.8, "force": {"kind": "constant", "value": -20.0}}


@pytest.fixture(scope="module")
def studio():
    server = make_studio(port=0).start()
    yield server, Client(server.url)
    server.stop()


def test_it_listens_on_loopback_only_unless_told(studio):
    server, _ = studio
    assert server.url.startswith("http://127.0.0.1:")


def test_the_page_and_its_files_are_served_with_the_security_headers(studio):
    _, client = studio
    page = client.request("GET", "/")
    assert page.status == 200 and b'<script type="module" src="/static/studio.js">' in page.body
    assert "script-src 'self'" in page.headers["Content-Security-Policy"]
    assert page.headers["X-Frame-Options"] == "DENY"
    for name, media in web.STATIC.items():
        reply = client.request("GET", f"/static/{name}")
        assert reply.status == 200 and reply.headers["Content-Type"] == media and reply.body
    for path in ("/static/../app.py", "/static/app.py", "/static/%2e%2e%2fweb.py", "/api", "/nothing"):
        assert client.request("GET", path).status == 404, path


@pytest.mark.parametrize("host", ["evil.example", "evil.example:80", "127.0.0.1:80@evil.example", "127.0.0.2"])
def test_another_host_is_refused_as_dns_rebinding_would_send_it(studio, host):
    _, client = studio
    reply = client.ask("rudiments", {}, headers={"Host": host})
    assert reply.status == 400 and b"Host" in reply.body or b"host" in reply.body


@pytest.mark.parametrize("host", ["localhost", "127.0.0.1", "LOCALHOST:8765"])
def test_the_loopback_names_are_served(studio, host):
    _, client = studio
    assert client.ask("rudiments", {}, headers={"Host": host, "Origin": f"http://{host}"}).status == 200


@pytest.mark.parametrize("headers, status", [
    ({"Sec-Fetch-Site": "cross-site"}, 403),
    ({"Sec-Fetch-Site": "same-site"}, 403),
    ({"Origin": "http://evil.example"}, 403),
    ({"Content-Type": "text/plain"}, 415),  # what a page elsewhere can send without asking the browser first
    ({"Content-Type": "application/x-www-form-urlencoded"}, 415),
])
def test_a_request_a_page_elsewhere_could_send_is_refused(studio, headers, status):
    _, client = studio
    assert "cannot" in client.error("simulate", {"recipe": RECIPE}, status=status, headers=headers) or status == 415


def test_a_body_too_large_is_refused_by_its_length_before_it_is_read(studio):
    server, _ = studio
    host, port = server.socket.getsockname()[:2]
    with socket.create_connection((host, port), timeout=10) as connection:
        connection.sendall(b"POST /api/simulate HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                           b"Content-Length: %d\r\n\r\n" % (MAX_BODY + 1))  # and no body: it is never waited for
        reply = _until_closed(connection)
    assert reply.startswith(b"HTTP/1.1 413") and b"at most 1048576 bytes" in reply


@pytest.mark.parametrize("raw, needle", [
    (b"{", "not readable JSON"),
    (b"[1, 2]", "must be a JSON object"),
    (b"\xff\xfe", "not UTF-8"),
    (b"[" * 100000 + b"]" * 100000, "nest"),
    (b'{"recipe": 1e999}', "recipe"),
    (b'{"recipe": {"cor": NaN, "force": {"kind": "constant", "value": 0}}}', "cor"),
])
def test_a_body_that_is_not_a_json_object_is_refused_in_one_line(studio, raw, needle):
    _, client = studio
    assert needle in client.error("simulate", raw=raw)


def test_an_operation_checks_its_fields_and_names_the_one_at_fault(studio):
    _, client = studio
    assert "unknown field 'colour'" in client.error("simulate", {"recipe": RECIPE, "colour": 1})
    assert "needs the field 'recipe'" in client.error("simulate", {})
    assert "cor" in client.error("simulate", {"recipe": {**RECIPE, "cor": 1.5}})
    assert "t_end" in client.error("simulate", {"recipe": {**RECIPE, "t_end": -1}})
    assert "rate" in client.error("simulate", {"recipe": RECIPE, "rate": "fast"})
    assert "no operation" in client.error("launch", {}, status=404)
    assert client.request("GET", "/api/simulate").status == 405


def test_motion_the_model_does_not_cover_is_said_as_the_command_line_says_it(studio):
    _, client = studio
    upward = {"t_end": 5.0, "force": {"kind": "constant", "value": -3000.0}}  # the thumb lifts it past the vertical
    message = client.error("simulate", {"recipe": upward})
    with pytest.raises(SimulationError) as raised:
        drumstroke.simulate(drumstroke.Recipe.from_dict(upward))
    assert message == str(raised.value) and "vertical" in message


def test_a_simulation_asked_over_http_is_the_library_s_stroke(studio):
    _, client = studio
    answer = client.answer("simulate", {"recipe": RECIPE, "rate": 500})
    stroke = drumstroke.simulate(drumstroke.Recipe.from_dict(RECIPE))
    assert answer["model"] == "paper"
    np.testing.assert_array_equal(answer["impacts"]["t"], stroke.impacts.t)  # JSON carries doubles exactly
    t, theta, _ = stroke.sample(500)
    np.testing.assert_array_equal(answer["t"], t)
    np.testing.assert_array_equal(answer["theta"], theta)
    assert answer["force"] == [-20.0] * len(t)


def _until_closed(connection):
    chunks = []
    while chunk := connection.recv(65536):
        chunks.append(chunk)
    return b"".join(chunks)


def _blocking_studio(work_timeout):
    """A studio whose extra operation 'wait' blocks until released: (server, client, release)."""
    release = threading.Event()
    started = threading.Semaphore(0)

    def wait(studio, data):
        started.release()
        release.wait(30)
        return {}

    app = web.make_app(Studio(), Limits(max_body=4096, body_timeout=0.5), work_timeout=work_timeout)
    server = Server(app, Limits(), host="127.0.0.1", port=0)
    web.OPERATIONS["wait"] = wait
    return server.start(), Client(server.url), release, started


def test_the_workers_are_bounded_and_each_request_answers_within_its_time():
    server, client, release, started = _blocking_studio(work_timeout=0.5)
    try:
        replies = []
        threads = [threading.Thread(target=lambda: replies.append(client.ask("wait", {}))) for _ in range(web.WORKERS)]
        for thread in threads:
            thread.start()
        for _ in threads:
            assert started.acquire(timeout=30)  # both workers hold a request
        busy = client.error("rudiments", {}, status=503)
        assert "busy" in busy
        for thread in threads:
            thread.join(60)
        assert [r.status for r in replies] == [503] * web.WORKERS  # answered at the work timeout, not held
        assert b"longer than 0.5 s" in replies[0].body
        release.set()
        for _ in range(100):  # the abandoned work ends, and frees its worker
            if client.ask("rudiments", {}).status == 200:
                break
        else:
            raise AssertionError("the workers were not freed")
    finally:
        release.set()
        del web.OPERATIONS["wait"]
        server.stop()


def test_a_body_that_trickles_in_is_cut_off_at_its_deadline():
    server, _, release, _ = _blocking_studio(work_timeout=5)
    try:
        host, port = server.socket.getsockname()[:2]
        with socket.create_connection((host, port), timeout=20) as connection:
            connection.sendall(b"POST /api/rudiments HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                               b"Content-Length: 100\r\n\r\n{")
            reply = _until_closed(connection)
        assert reply.startswith(b"HTTP/1.1 408") and b"within 0.5 s" in reply
    finally:
        release.set()
        del web.OPERATIONS["wait"]
        server.stop()


@pytest.mark.parametrize("options, needle", [
    ({"port": 70000}, "port"),
    ({"work_timeout": 0.0}, "work_timeout"),
    ({"allowed_hosts": ["a b"]}, "allowed host"),
    ({"library": "/nonexistent/folder"}, "not a folder"),
])
def test_bad_options_are_refused_before_anything_is_bound(options, needle):
    with pytest.raises(ParameterError, match=needle):
        make_studio(**options)


def test_an_answer_is_strict_json(studio):
    _, client = studio
    reply = client.ask("rudiments", {})
    assert reply.headers["Content-Type"] == "application/json"
    assert len(json.loads(reply.body, parse_constant=lambda name: pytest.fail(f"{name} in JSON"))["rudiments"]) == 40
