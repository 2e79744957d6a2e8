"""A real browser — Debian's Chromium driven by Playwright — through a whole listening-test session."""

import threading

import pytest
from playwright.sync_api import sync_playwright

from drumstroke.evaluation.app import Config, Store, make_server, plan
from drumstroke.render.audio import render_wav

CHROMIUM = "/usr/bin/chromium"
PAIRS = 3


@pytest.fixture()
def served(tmp_path):
    for i in range(PAIRS):
        for side, speed in (("human", 1.0), ("robot", 0.7)):
            render_wav(tmp_path / f"{side}-{i}.wav", [0.01, 0.12], [speed, 0.5 * speed], duration=0.3)
    pairs = "".join(f'[[pair]]\nid = "p{i}"\nhuman = "human-{i}.wav"\nrobot = "robot-{i}.wav"\n'
                    for i in range(PAIRS))
    (tmp_path / "test.toml").write_text(f'admin_token = "browser-token"\nseed = 11\n{pairs}')
    config = Config.from_toml(tmp_path / "test.toml")
    store = Store(tmp_path / "results.sqlite")
    server = make_server(config, store, port=0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    yield f"http://127.0.0.1:{server.server_address[1]}", config, store
    server.shutdown()
    server.server_close()


def test_a_whole_session_in_chromium_is_stored_as_clicked(served):
    base, config, store = served
    clicked = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True,
                                    args=["--no-sandbox", "--autoplay-policy=no-user-gesture-required"])
        page = browser.new_page()
        page.goto(base + "/")
        page.check("#consent")
        page.click("#start")
        page.wait_for_url("**/pair/0")
        participant = page.url.split("/")[4]
        for k in range(PAIRS):
            assert page.is_disabled("#submit")  # nothing can be answered before both are played
            page.evaluate("document.getElementById('audio-A').play()")
            assert page.is_disabled("#submit")
            page.evaluate("document.getElementById('audio-B').play()")
            page.wait_for_selector("#submit:not([disabled])")
            answer, confidence, similarity = "AB"[k % 2], 1 + k, 5 - k
            page.check(f"input[name=answer][value={answer}]")
            page.check(f"input[name=confidence][value='{confidence}']")
            page.check(f"input[name=similarity][value='{similarity}']")
            page.dblclick("#submit")  # a double click stores one answer
            page.wait_for_url(f"**/pair/{k + 1}" if k + 1 < PAIRS else "**/done")
            clicked.append((answer, confidence, similarity))
        assert "saved" in page.inner_text("#finished")
        page.go_back()  # back and reload an answered pair: nothing more is stored
        page.reload()
        browser.close()
    rows = store.rows()
    steps = plan(config, participant)
    assert len(rows) == PAIRS
    by_pair = {r[1]: r for r in rows}
    for k, (pair, robot) in enumerate(steps):
        assert by_pair[pair] == (participant, pair, robot, *clicked[k])
