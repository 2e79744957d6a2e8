"""A real browser — Debian's Chromium driven by Playwright — through a whole listening-test session."""

import pytest
from playwright.sync_api import sync_playwright

from _listen import start_test, stop
from drumstroke.evaluation.app import plan

CHROMIUM = "/usr/bin/chromium"
PAIRS = 3


@pytest.fixture()
def served(tmp_path):
    base, config, store, server = start_test(tmp_path, pairs=PAIRS, token="browser-token", seed=11)
    yield base, config, store
    stop(server)


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
