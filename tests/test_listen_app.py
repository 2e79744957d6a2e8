"""The listening-test app over real HTTP on loopback: sessions, exactly-once answers, faults, the export."""

import csv
import io
import urllib.error
import urllib.parse
import urllib.request
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from _listen import start_test, stop
from drumstroke.errors import ParameterError
from drumstroke.evaluation.app import Config, Store, plan
from drumstroke.evaluation.stats import parse_responses

PAIRS = 4


class NoRedirect(urllib.request.HTTPRedirectHandler):
    def redirect_request(self, *args, **kwargs):
        return None


OPENER = urllib.request.build_opener(NoRedirect)


def request(url, data=None):
    """(status, headers, body) of a GET, or a POST of the form ``data``; redirects are not followed."""
    body = urllib.parse.urlencode(data).encode() if data is not None else None
    try:
        with OPENER.open(urllib.request.Request(url, data=body), timeout=30) as response:
            return response.status, response.headers, response.read()
    except urllib.error.HTTPError as error:
        return error.code, error.headers, error.read()


@pytest.fixture()
def app(tmp_path):
    base, config, store, server = start_test(tmp_path, pairs=PAIRS, token="s3cret-token", seed=7)
    yield base, config, store, tmp_path
    stop(server)


def start(base):
    status, headers, _ = request(base + "/start", {"consent": "yes"})
    assert status == 303
    return headers["Location"].split("/")[2]


def play_and_answer(base, participant, position, answer, confidence, similarity, *, repeats=1):
    for side in ("A", "B"):
        assert request(f"{base}/p/{participant}/pair/{position}/played", {"side": side})[0] == 204
    form = {"answer": answer, "confidence": str(confidence), "similarity": str(similarity)}
    return [request(f"{base}/p/{participant}/pair/{position}/answer", form) for _ in range(repeats)]


def export(base, token="s3cret-token"):
    status, _, body = request(f"{base}/admin/export.csv?token={token}")
    return status, body.decode()


def test_a_whole_session_is_stored_exactly_as_answered(app):
    base, config, _, _ = app
    status, _, page = request(base + "/")
    assert status == 200 and b"consent" in page
    participant = start(base)
    steps = plan(config, participant)
    assert sorted(p for p, _ in steps) == [f"p{i}" for i in range(PAIRS)]
    given = []
    for k in range(PAIRS):
        status, _, page = request(f"{base}/p/{participant}/pair/{k}")
        assert status == 200 and f"Pair {k + 1} of {PAIRS}".encode() in page
        # the robot's file is on the planned side
        pair, robot = steps[k]
        assert request(f"{base}/p/{participant}/audio/{k}/{robot}")[2] == (app[3] / f"robot-{pair[1:]}.wav").read_bytes()
        answer = "AB"[k % 2]
        (result,) = play_and_answer(base, participant, k, answer, k + 1, 5 - k)
        assert result[0] == 303
        given.append((participant, pair, robot, answer, k + 1, 5 - k))
    assert result[1]["Location"] == f"/p/{participant}/done"
    assert request(f"{base}/p/{participant}/done")[0] == 200
    status, text = export(base)
    assert status == 200
    rows = [tuple(r) for r in csv.reader(io.StringIO(text))][1:]
    assert sorted(rows) == sorted(tuple(str(v) for v in g) for g in given)
    parse_responses([list(r) for r in rows])  # the export is what `drumstroke stats` reads


def test_an_answer_needs_both_stimuli_played(app):
    base, _, store, _ = app
    participant = start(base)
    assert request(f"{base}/p/{participant}/pair/0/played", {"side": "A"})[0] == 204
    status, _, body = request(f"{base}/p/{participant}/pair/0/answer",
                              {"answer": "A", "confidence": "3", "similarity": "3"})
    assert status == 409 and b"play both" in body
    assert store.rows() == []


def test_resubmissions_reloads_and_double_clicks_store_once(app):
    base, _, store, _ = app
    participant = start(base)
    results = play_and_answer(base, participant, 0, "B", 4, 2, repeats=3)
    assert [r[0] for r in results] == [303, 303, 303]
    # a different answer afterwards does not replace the first
    request(f"{base}/p/{participant}/pair/0/answer", {"answer": "A", "confidence": "1", "similarity": "1"})
    status, headers, _ = request(f"{base}/p/{participant}/pair/0")  # reloading an answered pair moves on
    assert status == 303 and headers["Location"].endswith("/pair/1")
    rows = store.rows()
    assert len(rows) == 1 and rows[0][3:] == ("B", 4, 2)


@pytest.mark.parametrize("form, needle", [
    ({"answer": "C", "confidence": "3", "similarity": "3"}, b"answer must be A or B"),
    ({"answer": "A", "confidence": "9", "similarity": "3"}, b"confidence must be an integer in [1, 5]"),
    ({"answer": "A", "confidence": "3"}, b"similarity must be an integer in [1, 5]"),
    ({}, b"answer must be A or B"),
])
def test_a_malformed_submission_gets_a_4xx_and_stores_nothing(app, form, needle):
    base, _, store, _ = app
    participant = start(base)
    for side in ("A", "B"):
        request(f"{base}/p/{participant}/pair/0/played", {"side": side})
    status, _, body = request(f"{base}/p/{participant}/pair/0/answer", form)
    assert 400 <= status < 500 and needle in body
    assert store.rows() == []


def test_unknown_participants_consent_and_the_export_token(app):
    base, _, _, _ = app
    assert request(base + "/start", {})[0] == 400  # no consent, no participant
    assert request(base + "/p/nobody/pair/0")[0] == 404
    assert request(base + "/p/nobody/pair/0/answer", {"answer": "A"})[0] == 404
    assert export(base, token="")[0] == 403 and export(base, token="wrong")[0] == 403


def test_fifty_concurrent_participants_with_repeats_and_reloads(app, rng):
    base, config, store, _ = app
    choices = rng.integers(0, 2, size=(50, PAIRS))

    def participant_session(i):
        participant = start(base)
        for k in range(PAIRS):
            request(f"{base}/p/{participant}/pair/{k}")  # load
            request(f"{base}/p/{participant}/pair/{k}")  # reload
            play_and_answer(base, participant, k, "AB"[choices[i, k]], 1 + (i + k) % 5, 1 + i % 5, repeats=2)
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


def test_bad_configs_are_refused(tmp_path):
    (tmp_path / "a.wav").write_bytes(b"RIFF")
    cases = {
        'admin_token = "short"\nseed = 1\n[[pair]]\nid = "x"\nhuman = "a.wav"\nrobot = "a.wav"\n': "admin_token",
        'admin_token = "long-enough"\nseed = 1\n[[pair]]\nid = "x"\nhuman = "a.wav"\nrobot = "b.wav"\n': "does not exist",
        'admin_token = "long-enough"\nseed = "x"\n[[pair]]\nid = "x"\nhuman = "a.wav"\nrobot = "a.wav"\n': "seed",
        'admin_token = "long-enough"\nseed = 1\n': "at least one [[pair]]",
    }
    for text, needle in cases.items():
        (tmp_path / "c.toml").write_text(text)
        with pytest.raises(ParameterError, match=needle.replace("[", r"\[").replace("]", r"\]")):
            Config.from_toml(tmp_path / "c.toml")


def test_the_listen_commands(app, tmp_path):
    import json
    import socket
    import subprocess
    import sys
    import time

    from _cli import run

    base, config, _, folder = app
    participants = [start(base) for _ in range(6)]
    for i, participant in enumerate(participants):
        for k in range(PAIRS):
            play_and_answer(base, participant, k, "AB"[(i + k) % 2], 1 + k, 1 + i % 5)
    result = run("listen", "analyze", "--db", folder / "results.sqlite", "--json", tmp_path / "a.json")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "a.json").read_text())
    expected = sorted(sum(1 for k, (_, robot) in enumerate(plan(config, p)) if "AB"[(i + k) % 2] != robot)
                      for i, p in enumerate(participants))
    assert sorted(data["incorrect"]) == expected

    with socket.socket() as probe:  # a free port for a real `drumstroke listen serve`
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    server = subprocess.Popen([sys.executable, "-m", "drumstroke.cli", "listen", "serve", folder / "test.toml",
                               "--db", tmp_path / "served.sqlite", "--port", str(port)],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        for _ in range(100):
            try:
                status = request(f"http://127.0.0.1:{port}/")[0]
                break
            except OSError:
                time.sleep(0.1)
        assert status == 200
        participant = start(f"http://127.0.0.1:{port}")
        (answer,) = play_and_answer(f"http://127.0.0.1:{port}", participant, 0, "A", 2, 3)
        assert answer[0] == 303
        assert Store(tmp_path / "served.sqlite").rows()[0][3:] == ("A", 2, 3)
    finally:
        server.terminate()
        server.wait(timeout=10)
