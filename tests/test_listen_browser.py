"""A real browser — Debian's Chromium driven by Playwright — through a whole listening-test session, real server."""

import pytest
from playwright.sync_api import sync_playwright

from _listen import start_test
from drumstroke.evaluation.app import plan

CHROMIUM = "/usr/bin/chromium"
PAIRS = 3


@pytest.fixture()
def served(tmp_path):
    server, config, store = start_test(tmp_path, pairs=PAIRS, token="browser-token-0123456789", seed=11)
    yield server.url.rstrip("/"), config, store
    server.stop()


def test_a_whole_session_in_chromium_is_stored_as_clicked(served):
    base, config, store = served
    clicked = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True,
                                    args=["--no-sandbox", "--autoplay-policy=no-user-gesture-required"])
        page = browser.new_page()
        refused = []  # a script or style the Content-Security-Policy blocked, or a script's error
        page.on("console", lambda message: refused.append(message.text) if "Content Security" in message.text else None)
        page.on("pageerror", lambda error: refused.append(str(error)))
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
        (cookie,) = page.context.cookies()
        browser.close()
    assert refused == []
    assert cookie["httpOnly"] and cookie["sameSite"] == "Strict" and not cookie["secure"]  # plain HTTP here
    rows = store.rows()
    steps = plan(config, participant)
    assert len(rows) == PAIRS
    by_pair = {r[1]: r for r in rows}
    for k, (pair, robot) in enumerate(steps):
        assert by_pair[pair] == (participant, pair, robot, *clicked[k])
