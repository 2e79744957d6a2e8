"""The listening-test app on the real server (uvicorn on a loopback socket): sessions, exactly-once answers, the guards.

Every request goes over a real socket to the server as ``listen serve`` runs it; the client is a browser's
stand-in (``_listen.Client``: cookies, the pages' form tokens, ``Origin`` and ``Sec-Fetch-Site`` as a
browser sends them). Raw-socket tests of the connection limits are in ``test_listen_server.py``.
"""

import csv
import io
import json
import logging
import os
import re
import signal
import socket
import sqlite3
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

from _cli import run
from _listen import Client, start_test, token_of, write_test
from drumstroke.cli import main
from drumstroke.errors import ParameterError
from drumstroke.evaluation.app import EXAMPLE_TOKENS, Config, Store, plan
from drumstroke.evaluation.limits import Window
from drumstroke.evaluation.pages import SECURITY_HEADERS
from drumstroke.evaluation.stats import parse_responses

PAIRS = 4
TOKEN = "s3cret-token-for-the-tests"
DOCS = Path(__file__).resolve().parents[1] / "docs"


@pytest.fixture()
def app(tmp_path):
    server, config, store = start_test(tmp_path, pairs=PAIRS, token=TOKEN, seed=7)
    yield server, config, store, tmp_path
    server.stop()


def export(client, token=TOKEN):
    reply = client.get("/admin/export.csv", headers={"Authorization": f"Bearer {token}"})
    return reply.status, reply.body.decode()


# --- a participant's session ---------------------------------------------------------------------------------------

def test_a_whole_session_is_stored_exactly_as_answered(app):
    server, config, _, folder = app
    client = Client(server.url)
    reply = client.get("/")
    assert reply.status == 200 and b"consent" in reply.body
    participant = client.start()
    steps = plan(config, participant)
    assert sorted(p for p, _ in steps) == [f"p{i}" for i in range(PAIRS)]
    given = []
    for k in range(PAIRS):
        reply = client.get(f"/p/{participant}/pair/{k}")
        assert reply.status == 200 and f"Pair {k + 1} of {PAIRS}".encode() in reply.body
        pair, robot = steps[k]  # the robot's file is on the planned side
        assert client.get(f"/p/{participant}/audio/{k}/{robot}").body == (folder / f"robot-{pair[1:]}.wav").read_bytes()
        answer = "AB"[k % 2]
        (result,) = client.play_and_answer(participant, k, answer, k + 1, 5 - k)
        assert result.status == 303
        given.append((participant, pair, robot, answer, k + 1, 5 - k))
    assert result.headers["Location"] == f"/p/{participant}/done"
    assert client.get(f"/p/{participant}/done").status == 200
    status, text = export(client)
    assert status == 200
    rows = [tuple(r) for r in csv.reader(io.StringIO(text))][1:]
    assert sorted(rows) == sorted(tuple(str(v) for v in g) for g in given)
    parse_responses([list(r) for r in rows])  # the export is what `drumstroke stats` reads


def test_an_answer_needs_both_stimuli_played(app):
    server, _, store, _ = app
    client = Client(server.url)
    participant = client.start()
    form = {"side": "A", "csrf": client.tokens[participant]}
    assert client.post(f"/p/{participant}/pair/0/played", form).status == 204
    reply = client.post(f"/p/{participant}/pair/0/answer",
                        {"answer": "A", "confidence": "3", "similarity": "3", "csrf": client.tokens[participant]})
    assert reply.status == 409 and b"play both" in reply.body
    assert store.rows() == []


def test_resubmissions_reloads_and_double_clicks_store_once(app):
    server, _, store, _ = app
    client = Client(server.url)
    participant = client.start()
    results = client.play_and_answer(participant, 0, "B", 4, 2, repeats=3)
    assert [r.status for r in results] == [303, 303, 303]
    # a different answer afterwards does not replace the first
    client.post(f"/p/{participant}/pair/0/answer",
                {"answer": "A", "confidence": "1", "similarity": "1", "csrf": client.tokens[participant]})
    reply = client.get(f"/p/{participant}/pair/0")  # reloading an answered pair moves on
    assert reply.status == 303 and reply.headers["Location"].endswith("/pair/1")
    rows = store.rows()
    assert len(rows) == 1 and rows[0][3:] == ("B", 4, 2)


def test_fifty_concurrent_participants_with_repeats_and_reloads(app, rng):
    """50 browsers, each from its own loopback address (as on the internet), with the default limits."""
    server, config, store, _ = app
    choices = rng.integers(0, 2, size=(50, PAIRS))

    def participant_session(i):
        client = Client(server.url, source=f"127.0.0.{10 + i}")
        participant = client.start()
        for k in range(PAIRS):
            client.get(f"/p/{participant}/pair/{k}")  # load
            client.get(f"/p/{participant}/pair/{k}")  # reload
            client.play_and_answer(participant, k, "AB"[choices[i, k]], 1 + (i + k) % 5, 1 + i % 5, repeats=2)
        return participant

    with ThreadPoolExecutor(max_workers=50) as pool:
        participants = list(pool.map(participant_session, range(50)))
    rows = store.rows()
    assert len(rows) == 50 * PAIRS and len({(r[0], r[1]) for r in rows}) == 50 * PAIRS
    for i, participant in enumerate(participants):
        mine = {r[1]: r for r in rows if r[0] == participant}
        for k, (pair, robot) in enumerate(plan(config, participant)):
            assert mine[pair][2:] == (robot, "AB"[choices[i, k]], 1 + (i + k) % 5, 1 + i % 5)
    orders = {tuple(p for p, _ in plan(config, x)) for x in participants}
    assert len(orders) > 5  # orders really differ between participants
    sides = np.array([s == "A" for x in participants for _, s in plan(config, x)])
    assert 0.3 < sides.mean() < 0.7


# --- what is refused ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("form, needle", [
    ({"answer": "C", "confidence": "3", "similarity": "3"}, b"answer must be A or B"),
    ({"answer": "A", "confidence": "9", "similarity": "3"}, b"confidence must be an integer in [1, 5]"),
    ({"answer": "A", "confidence": "\u00b2", "similarity": "3"}, b"confidence must be an integer in [1, 5]"),
    ({"answer": "A", "confidence": "3"}, b"similarity must be an integer in [1, 5]"),
    ({}, b"answer must be A or B"),
    ({"answer": "A", "confidence": "3", "similarity": "3", "extra": "1"}, b"unknown field 'extra'"),
])
def test_a_malformed_submission_gets_a_4xx_and_stores_nothing(app, form, needle):
    server, _, store, _ = app
    client = Client(server.url)
    participant = client.start()
    client.play_and_answer(participant, 1, "A", 1, 1)  # another pair: the form alone decides
    reply = client.post(f"/p/{participant}/pair/0/answer", {**form, "csrf": client.tokens[participant]})
    assert reply.status == 400 and needle in reply.body, reply
    assert [r[1] for r in store.rows()] == [plan(app[1], participant)[1][0]]


@pytest.mark.parametrize("body, kind, needle", [
    (b"answer=A&answer=B&confidence=3&similarity=3&csrf=x", None, b"the field 'answer' twice"),
    (b"answer=A&confidence=3&similarity=3&csrf=\xff\xfe", None, b"not UTF-8"),
    (b"answer&confidence=3", None, b"name=value fields joined by '&' (answer, confidence, similarity, csrf)"),
    (b"answer=A&confidence=3&similarity=3&csrf=x&a=1&b=2&c=3", None, b"unknown field 'a'"),
    (b'{"answer": "A"}', "application/json", b"application/x-www-form-urlencoded"),
])
def test_a_form_that_is_not_one_is_refused_with_a_message(app, body, kind, needle):
    server, _, store, _ = app
    client = Client(server.url)
    participant = client.start()
    with socket.create_connection((client.host, client.port)) as raw:
        raw.sendall(f"POST /p/{participant}/pair/0/answer HTTP/1.1\r\nHost: {client.origin[7:]}\r\n"
                    f"Content-Type: {kind or 'application/x-www-form-urlencoded'}\r\n"
                    f"Content-Length: {len(body)}\r\nConnection: close\r\n\r\n".encode() + body)
        reply = read_all(raw)
    assert reply.split(b" ", 2)[1] in (b"400", b"415") and needle in reply, reply
    assert store.rows() == []


def read_all(connection):
    chunks = []
    while chunk := connection.recv(65536):
        chunks.append(chunk)
    return b"".join(chunks)


@pytest.mark.parametrize("path, needle", [
    ("/p/%B2/pair/0", b"a participant id is 32 hexadecimal digits"),
    ("/p/{p}/pair/%C2%B2", b"a pair's position is a whole number of 1-6 digits 0-9, got '\xc2\xb2'"),
    ("/p/{p}/pair/" + "9" * 5000, b"(5000 characters)"),
    ("/p/{p}/audio/0/C", b"a side is A or B, got 'C'"),
    ("/p/{p}/audio/-1/A", b"a pair's position is a whole number"),
])
def test_a_malformed_path_is_answered_400_with_a_message(app, path, needle):
    server, _, _, _ = app
    client = Client(server.url)
    participant = client.start()
    reply = client.get(path.format(p=participant))
    assert reply.status == 400 and needle in reply.body, reply
    assert client.get(f"/p/{participant}/pair/0").status == 200  # the server goes on


def test_unknown_participants_pairs_and_missing_consent(app):
    server, _, store, _ = app
    client = Client(server.url)
    token = token_of(client.get("/").body)
    reply = client.post("/start", {"csrf": token})
    assert reply.status == 400 and b"consent is needed" in reply.body  # no consent, no participant
    nobody = "0" * 32
    assert client.get(f"/p/{nobody}/pair/0").status == 404
    assert client.post(f"/p/{nobody}/pair/0/answer", {"answer": "A", "csrf": "x"}).status == 403
    participant = client.start()
    reply = client.post(f"/p/{participant}/pair/{PAIRS}/played", {"side": "A", "csrf": client.tokens[participant]})
    assert reply.status == 404 and f"this participant has {PAIRS}".encode() in reply.body
    assert client.get(f"/p/{participant}/pair/{PAIRS}").headers["Location"] == f"/p/{participant}/done"
    assert store.rows() == [] and store.sides_played(participant, PAIRS) == set()


def test_a_cross_site_request_is_refused_and_stores_nothing(app):
    server, _, store, _ = app
    client = Client(server.url)
    token = token_of(client.get("/").body)
    start = {"consent": "yes", "csrf": token}
    refused = {
        "another origin": client.post("/start", start, headers={"Origin": "http://evil.example"}),
        "a sandboxed cross-site frame": client.post("/start", start, headers={"Origin": "null",
                                                                            "Sec-Fetch-Site": "cross-site"}),
        "cross-site fetch": client.post("/start", start, headers={"Sec-Fetch-Site": "cross-site"}),
        "same-site fetch": client.post("/start", start, headers={"Sec-Fetch-Site": "same-site"}),
        "no token": client.post("/start", {"consent": "yes"}),
        "a forged token": client.post("/start", {"consent": "yes", "csrf": "forged.token"}),
        "no cookie": Client(server.url).post("/start", start),
    }
    for case, reply in refused.items():
        assert reply.status == 403, case
    assert b"another origin" in refused["another origin"].body and b"Sec-Fetch-Site" in refused["cross-site fetch"].body
    assert Store(store.path)._read("SELECT COUNT(*) FROM participants") == [(0,)]

    participant = client.start()
    other = client.start()
    mine = client.tokens[participant]
    played = f"/p/{participant}/pair/0/played"
    for headers, form in [({"Origin": "https://evil.example"}, {"side": "A", "csrf": mine}),
                          ({"Sec-Fetch-Site": "cross-site"}, {"side": "A", "csrf": mine}),
                          ({}, {"side": "A"}),
                          ({}, {"side": "A", "csrf": client.tokens[other]})]:  # another participant's token
        assert client.post(played, form, headers=headers).status == 403, (headers, form)
    answer = {"answer": "A", "confidence": "3", "similarity": "3"}
    assert client.post(f"/p/{participant}/pair/0/answer", answer).status == 403
    assert store.sides_played(participant, 0) == set() and store.rows() == []
    # a client that is not a browser sends neither header: the token alone is enough
    assert Client(server.url, browser=False).post(played, {"side": "A", "csrf": mine}).status == 204
    # Chromium's own form under Referrer-Policy: no-referrer: Origin null, Sec-Fetch-Site same-origin
    assert client.post(played, {"side": "B", "csrf": mine}, headers={"Origin": "null"}).status == 204
    assert store.sides_played(participant, 0) == {"A", "B"}


def test_behind_a_trusted_proxy_the_cookie_is_secure_and_clients_are_counted_by_x_forwarded_for(tmp_path):
    """A trusted proxy (here, loopback) says https (Secure cookie, HSTS, the Origin's scheme) and who the client is."""
    server, _, store = start_test(tmp_path, pairs=1, token=TOKEN, seed=1, proxies=["127.0.0.1"],
                                  limits="sessions_per_minute_per_client = 1")
    try:
        client = Client(server.url)
        plain = client.get("/").headers["Set-Cookie"]
        assert {"HttpOnly", "Path=/", "SameSite=strict"} <= set(plain.split("; ")) and "Secure" not in plain
        https = client.get("/", headers={"X-Forwarded-Proto": "https"})
        assert "Secure" in https.headers["Set-Cookie"].split("; ")
        assert https.headers["Strict-Transport-Security"] == "max-age=31536000"
        # the Origin check follows the proxy's scheme: https://host is this server's own origin then
        form = {"consent": "yes", "csrf": token_of(https.body)}
        proxied = {"X-Forwarded-Proto": "https", "Origin": "https" + client.origin[4:]}
        reply = client.post("/start", form, headers={**proxied, "X-Forwarded-For": "203.0.113.1"})
        assert reply.status == 303 and store.plan_of(reply.headers["Location"].split("/")[2]) is not None
        # one session a minute per client: the proxy's own address is not the client
        assert client.post("/start", form, headers={**proxied, "X-Forwarded-For": "203.0.113.1"}).status == 429
        assert client.post("/start", form, headers={**proxied, "X-Forwarded-For": "203.0.113.2"}).status == 303
    finally:
        server.stop()


def test_the_admin_token_is_taken_from_the_authorization_header_only(app):
    server, _, _, _ = app
    client = Client(server.url)
    status, text = export(client)
    assert status == 200 and text.startswith("subject,pair,robot")
    reply = client.get(f"/admin/export.csv?token={TOKEN}")
    assert reply.status == 400 and b"Authorization: Bearer" in reply.body and TOKEN.encode() not in reply.body
    for headers in ({}, {"Authorization": "Bearer wrong-token-wrong-token"}, {"Authorization": f"Basic {TOKEN}"},
                    {"Authorization": f"Bearer {TOKEN}x"}, {"Authorization": "Bearer \u00e9\u00e9"}):
        reply = client.get("/admin/export.csv", headers=headers)
        assert reply.status == 401 and reply.headers["WWW-Authenticate"].startswith("Bearer"), headers
    for _ in range(5):  # 10 wrong tokens a minute from one client: then 429, even for the right one
        client.get("/admin/export.csv", headers={"Authorization": "Bearer guess-guess-guess-guess"})
    reply = client.get("/admin/export.csv", headers={"Authorization": f"Bearer {TOKEN}"})
    assert reply.status == 429 and 1 <= int(reply.headers["Retry-After"]) <= 60
    assert export(Client(server.url, source="127.0.0.2"))[0] == 200  # another client is not locked out


def test_new_sessions_are_rate_limited_per_client_and_in_all(tmp_path):
    server, _, store = start_test(tmp_path, pairs=1, token=TOKEN, seed=1,
                                  limits="sessions_per_minute_per_client = 3\nsessions_per_minute = 5")
    try:
        first = Client(server.url, source="127.0.0.2")
        for _ in range(3):
            first.start()
        token = token_of(first.get("/").body)
        reply = first.post("/start", {"consent": "yes", "csrf": token}, headers={"X-Forwarded-For": "198.51.100.7"})
        assert reply.status == 429 and b"too many new sessions" in reply.body  # no proxy is trusted: not believed
        assert 55 <= int(reply.headers["Retry-After"]) <= 60
        second = Client(server.url, source="127.0.0.3")
        second.start()
        second.start()  # 5 in all
        reply = Client(server.url, source="127.0.0.4").post("/start", {"consent": "yes", "csrf": token})
        assert reply.status == 403  # the token is not this browser's: refused before counting
        reply = second.post("/start", {"consent": "yes", "csrf": token_of(second.get("/").body)})
        assert reply.status == 429 and int(reply.headers["Retry-After"]) >= 55  # 5 in all: its third waits
        third = Client(server.url, source="127.0.0.4")
        third.start()  # a newcomer is admitted beyond the limit in all: no flood shuts the first session out
        reply = third.post("/start", {"consent": "yes", "csrf": token_of(third.get("/").body)})
        assert reply.status == 429 and int(reply.headers["Retry-After"]) >= 55  # its second waits
        assert store._read("SELECT COUNT(*) FROM participants") == [(6,)]
    finally:
        server.stop()


def test_the_admin_is_served_after_a_thousand_wrong_tokens_from_a_hundred_addresses(app):
    """10 wrong tokens from each of 100 addresses lock each of them out (its 11th is 429), and only them: the
    admin, from another address, is served, even after a wrong token of their own."""
    server, _, _, _ = app
    wrong = {"Authorization": "Bearer guess-guess-guess-guess"}
    attackers = [Client(server.url, source=f"127.0.1.{1 + i}") for i in range(100)]
    replies = [attacker.get("/admin/export.csv", headers=wrong).status for _ in range(10) for attacker in attackers]
    assert replies == [401] * 1000
    assert {attacker.get("/admin/export.csv", headers=wrong).status for attacker in attackers} == {429}
    assert {export(attacker)[0] for attacker in attackers[:5]} == {429}  # a locked address stays locked
    admin = Client(server.url, source="127.0.0.1")
    assert admin.get("/admin/export.csv", headers=wrong).status == 401  # a typo
    status, text = export(admin)
    assert status == 200 and text.startswith("subject,pair,robot")


def test_participants_are_served_while_a_thousand_sessions_are_attempted_from_a_hundred_addresses(app):
    """1,000 new sessions from 100 addresses, 10 each in turn, with the default limits (10 a minute per client,
    120 in all), and a newcomer after each 100: beyond 120 in all only clients with a session in the last minute
    wait, so the 10 newcomers each start and answer, and the flood gets 119 sessions (the newcomers took one)."""
    server, _, store, _ = app
    attackers = []
    for i in range(100):
        attacker = Client(server.url, source=f"127.0.2.{1 + i}")
        attackers.append((attacker, {"consent": "yes", "csrf": token_of(attacker.get("/").body)}))
    admitted, newcomers = 0, []
    for round_ in range(10):
        for attacker, form in attackers:
            reply = attacker.post("/start", form)
            assert reply.status in (303, 429), reply
            admitted += reply.status == 303
        newcomer = Client(server.url, source=f"127.0.3.{1 + round_}")
        participant = newcomer.start()
        assert newcomer.play_and_answer(participant, 0, "A", 3, 4)[0].status == 303
        newcomers.append(participant)
    assert admitted == 119
    assert [row[0] for row in store.rows()] == sorted(newcomers)
    assert store._read("SELECT COUNT(*) FROM participants") == [(129,)]


def test_the_window_admits_again_as_the_minute_passes():
    now = [0.0]
    window = Window(2, 1000, clock=lambda: now[0])
    assert window.admit("a") == 0
    now[0] = 20.0
    assert [window.admit("a"), window.admit("a"), window.admit("b")] == [0, 40, 0]
    now[0] = 60.0
    assert window.admit("a") == 0 and window.admit("a") == 20  # the first has expired, the second does at 80 s


def test_the_security_headers_are_on_every_kind_of_response(app, caplog):
    server, config, _, folder = app
    client = Client(server.url)
    participant = client.start()
    (folder / "robot-0.wav").unlink()
    (folder / "human-0.wav").unlink()
    pair0 = [pair for pair, _ in plan(config, participant)].index("p0")
    with caplog.at_level(logging.ERROR):
        replies = {
            "page": client.get("/"),
            "redirect": client.get(f"/p/{participant}/pair/{PAIRS}"),
            "static script": client.get("/static/listen.js"),
            "static style": client.get("/static/listen.css"),
            "audio": client.get(f"/p/{participant}/audio/{(pair0 + 1) % PAIRS}/A"),
            "export": export_reply(client),
            "no content": client.post(f"/p/{participant}/pair/0/played",
                                      {"side": "A", "csrf": client.tokens[participant]}),
            "400": client.get("/p/x/pair/0"),
            "403": client.post("/start", {"consent": "yes"}),
            "404": client.get("/nothing-here"),
            "405": client.request("DELETE", "/"),
            "500": client.get(f"/p/{participant}/audio/{pair0}/A"),
        }
    for kind, reply in replies.items():
        for name, value in SECURITY_HEADERS:
            assert reply.headers[name] == value, (kind, name)
    csp = replies["page"].headers["Content-Security-Policy"]
    assert "script-src 'self'" in csp and "unsafe-inline" not in csp and "frame-ancestors 'none'" in csp
    for kind, reply in replies.items():
        assert reply.headers["Cache-Control"] == ("no-cache" if kind.startswith("static") else "no-store"), kind
    assert b"<script>" not in replies["page"].body and b"<style>" not in replies["page"].body
    assert replies["static script"].headers["Content-Type"].startswith("text/javascript")
    assert replies["500"].status == 500 and b"cannot be played" in replies["500"].body
    logged = [r.getMessage() for r in caplog.records if r.name == "drumstroke.evaluation.web"]
    assert len(logged) == 1 and "cannot read the stimulus" in logged[0] and "No such file or directory" in logged[0]
    assert str(folder / "robot-0.wav") in logged[0] or str(folder / "human-0.wav") in logged[0]
    assert client.get(f"/p/{participant}/pair/0").status == 200  # the server goes on


def export_reply(client):
    return client.get("/admin/export.csv", headers={"Authorization": f"Bearer {TOKEN}"})


# --- the config ---------------------------------------------------------------------------------------------------

def test_bad_configs_are_refused(tmp_path):
    (tmp_path / "a.wav").write_bytes(b"RIFF")
    pair = '[[pair]]\nid = "x"\nhuman = "a.wav"\nrobot = "a.wav"\n'
    token = f'admin_token = "{TOKEN}"\n'
    cases = {
        'admin_token = "short-token"\nseed = 1\n' + pair: "admin_token must be 16-512 printable ASCII characters",
        'admin_token = "with a space inside it"\nseed = 1\n' + pair: "without spaces",
        'admin_token = "change-this-token"\nseed = 1\n' + pair: "an example printed in the documentation",
        token + "seed = 1\n" + pair.replace('robot = "a.wav"', 'robot = "b.wav"'): "b.wav' cannot be read: No such file or directory",
        token + 'seed = "x"\n' + pair: "seed",
        token + "seed = 1" + "0" * 30 + "\n" + pair: r"seed must be an integer in",
        token + "seed = 1\n": r"at least one \[\[pair\]\]",
        token + "seed = 1\n" + pair + "[limits]\nmax_body = 10\n":
            r"limits max_body must be an integer in \[256, 1048576\]",
        token + "seed = 1\n" + pair + "[limits]\nhead_timeout = 0\n": r"limits head_timeout must be in \[0.1, 600\] s",
        token + "seed = 1\n" + pair + "[limits]\nsessions = 5\n": r"config \[limits\] has unknown key 'sessions'",
    }
    for text, needle in cases.items():
        (tmp_path / "c.toml").write_text(text)
        with pytest.raises(ParameterError, match=needle):
            Config.from_toml(tmp_path / "c.toml")
    (tmp_path / "c.toml").write_text(token + "seed = 1\n" + pair)
    assert TOKEN not in repr(Config.from_toml(tmp_path / "c.toml"))  # a traceback or a log does not show it


def test_every_token_the_docs_print_is_refused():
    printed = {m for page in ("listening-test.md", "formats.md")
               for m in re.findall(r'admin_token = "([^"]+)"', (DOCS / page).read_text())}
    assert printed and printed <= EXAMPLE_TOKENS
    for token in EXAMPLE_TOKENS:
        with pytest.raises(ParameterError, match="example printed in the documentation|16-512"):
            Config("t", token, 1, ())


# --- the commands -------------------------------------------------------------------------------------------------

def test_the_listen_commands(app, tmp_path):
    server, config, _, folder = app
    client = Client(server.url)
    participants = [client.start() for _ in range(6)]
    for i, participant in enumerate(participants):
        for k in range(PAIRS):
            client.play_and_answer(participant, k, "AB"[(i + k) % 2], 1 + k, 1 + i % 5)
    result = run("listen", "analyze", "--db", folder / "results.sqlite", "--json", tmp_path / "a.json")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "a.json").read_text())
    expected = sorted(sum(1 for k, (_, robot) in enumerate(plan(config, p)) if "AB"[(i + k) % 2] != robot)
                      for i, p in enumerate(participants))
    assert sorted(data["incorrect"]) == expected

    with socket.socket() as probe:  # a free port for a real `drumstroke listen serve`
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    serving = subprocess.Popen([sys.executable, "-m", "drumstroke.cli", "listen", "serve", folder / "test.toml",
                                "--db", tmp_path / "served.sqlite", "--port", str(port)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = serving.stdout.readline()
        assert f"on http://127.0.0.1:{port}/ ;" in line and "Authorization: Bearer" in line, line
        served = Client(f"http://127.0.0.1:{port}/")
        participant = served.start()
        (answer,) = served.play_and_answer(participant, 0, "A", 2, 3)
        assert answer.status == 303
        assert Store(tmp_path / "served.sqlite").rows()[0][3:] == ("A", 2, 3)
        began = time.monotonic()
        serving.send_signal(signal.SIGINT)  # Ctrl-C
        out, err = serving.communicate(timeout=15)
        assert serving.returncode == 0 and time.monotonic() - began < 10, err
        assert "stopped; the answers are in" in out and "Traceback" not in err
    finally:
        serving.kill()
        serving.wait()


def test_serve_and_analyze_check_their_options_before_starting(tmp_path, capsys):
    config = write_test(tmp_path, pairs=1, token=TOKEN, seed=1)
    (tmp_path / "notes.sqlite").write_text("not a database\n")
    os.mkfifo(tmp_path / "fifo.sqlite")
    other = tmp_path / "other.sqlite"
    db = sqlite3.connect(other)
    db.execute("CREATE TABLE songs (name TEXT)")
    db.close()
    cases = [
        (["listen", "serve", config, "--db", tmp_path / "a.sqlite", "--port", "0"],
         "argument --port: must be an integer in [1, 65535], got 0"),
        (["listen", "serve", config, "--db", tmp_path / "a.sqlite", "--port", "99999"], "[1, 65535]"),
        (["listen", "serve", config, "--db", tmp_path / "a.sqlite", "--host", "no-such-host.invalid"],
         "host 'no-such-host.invalid' cannot be resolved"),
        (["listen", "serve", config, "--db", tmp_path / "a.sqlite", "--forwarded-allow-ips", "*"], "'*' would trust"),
        (["listen", "serve", config, "--db", tmp_path / "a.sqlite", "--allowed-host", "study.example.org:443"],
         "allowed host 'study.example.org:443' is not a host name"),
        (["listen", "serve", config, "--db", tmp_path / "a.sqlite", "--forwarded-allow-ips", "proxy"],
         "entry 'proxy' is not an IP address"),
        (["listen", "serve", config, "--db", tmp_path / "notes.sqlite"],
         f"database '{tmp_path / 'notes.sqlite'}' cannot be used as SQLite: file is not a database"),
        (["listen", "serve", config, "--db", tmp_path / "fifo.sqlite"], "fifo.sqlite': it exists and is a FIFO (named pipe), not a regular file"),
        (["listen", "serve", config, "--db", other], "holds other tables (songs)"),
        (["listen", "analyze", "--db", tmp_path / "notes.sqlite"], "notes.sqlite' cannot be used as SQLite"),
        (["listen", "analyze", "--db", other], "is not a listening-test database"),
    ]
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        cases.append((["listen", "serve", config, "--db", tmp_path / "a.sqlite", "--port", port],
                      f"cannot listen on host '127.0.0.1' port {port}: Address already in use"))
        for args, needle in cases:
            assert main([str(a) for a in args]) == 2, args
            err = capsys.readouterr().err
            assert len(err.splitlines()) == 1 and needle in err and "Traceback" not in err, (args, err)
    assert not (tmp_path / "a.sqlite").exists()  # nothing written by a refused command
    assert (tmp_path / "notes.sqlite").read_text() == "not a database\n"
    songs = sqlite3.connect(other)
    assert songs.execute("SELECT name FROM sqlite_master").fetchall() == [("songs",)]  # left as it was
    songs.close()
