"""The part editor's kit mode in a real browser (Debian's Chromium driven by Playwright): a groove on hi-hat, snare
and kick clicked on the kit's grid, planned, heard, drawn a lane per piece, its CSV ``drumstroke compose --kit``'s;
a note no limb can play shown beside itself with compose --kit's reason; the sticks' grid kept while the kit is on."""

import json

import numpy as np
import pandas as pd
import pytest

from _studio import WAIT, part_editor, planned, screenshot
from drumstroke.cli import main


def groove_text():
    """What the clicks below build: 2 bars at 100 bpm, the hi-hat's 8ths, the snare's accents on 2 and 4, the kick on
    1 and 3 (the text lists a step's notes in the grid's order: the hi-hat over the snare over the kick)."""
    lines = ["tempo 100"]
    for step in range(0, 32, 2):  # 16ths steps: an 8th every 2
        beat = step / 4
        lines.append(f"{beat:g} auto 100 auto hihat")
        if beat % 2 == 1:
            lines.append(f"{beat:g} auto 116 auto snare")
        if beat % 2 == 0:
            lines.append(f"{beat:g} auto 100 auto kick")
    return "\n".join(lines) + "\n"


@pytest.fixture()
def page():
    with part_editor() as tab:
        yield tab


def cell(row, step):
    return f".cell[data-row='{row}'][data-step='{step}']"


def test_a_groove_clicked_on_the_kit_grid_is_planned_heard_drawn_and_its_csv_is_compose_kits(page, tmp_path):
    page.check("#part-kit")
    page.wait_for_selector(cell("hihat:pedal", 0))  # the kit's rows
    page.click("#part-clear")
    page.fill("#part-tempo", "100")
    page.press("#part-tempo", "Enter")
    for step in range(0, 32, 2):
        page.click(cell("hihat", step))
        beat = step / 4
        if beat % 2 == 1:  # a second click makes the accent
            page.click(cell("snare", step))
            page.focus(cell("snare", step))
            page.keyboard.press("Enter")
        if beat % 2 == 0:
            page.click(cell("kick", step))
    text = groove_text()
    planned(page, text.count("\n") - 1)
    assert page.input_value("#part-text") == text
    # a lane per piece, as drum notation stacks them, each note's limb written in it
    lanes = page.locator(".kit-lane")
    assert [lanes.nth(k).get_attribute("data-piece") for k in range(lanes.count())] == ["hihat", "snare", "kick"]
    path = tmp_path / "groove.pattern"
    path.write_text(text)
    assert main(["compose", str(path), "--kit", "--quiet", "--json", str(tmp_path / "cli.json"),
                 "--csv", str(tmp_path / "cli.csv")]) == 0
    written = json.loads((tmp_path / "cli.json").read_text())
    letters = {"right": "R", "left": "L", "right-foot": "RF", "left-foot": "LF"}
    velocities = [int(line.split()[2]) for line in text.splitlines()[1:]]  # the accents: 116, past 108
    for piece in ("hihat", "snare", "kick"):
        marks = page.locator(f".kit-lane[data-piece='{piece}'] text.mark").evaluate_all(
            "marks => marks.map((m) => m.firstChild.nodeValue)")  # without its tooltip
        expected = [letters[n["limb"]] + (">" if velocity >= 108 else "")
                    for n, velocity in zip(written["notes"], velocities, strict=True) if n["piece"] == piece]
        assert marks == expected
        hits = [h for h in written["hits"] if h["piece"] == piece]
        assert page.locator(f".kit-lane[data-piece='{piece}'] circle.hit").count() == len(hits)
    assert page.locator("#part-problems li").count() == 0
    # the grid's cells written as the planner plays them: the kick's right foot, the backbeat's accented hand
    steps = {(n["piece"], round(n["time"] * 100 / 60 * 4)): n["limb"] for n in written["notes"]}
    assert page.inner_text(cell("kick", 0)) == letters[steps[("kick", 0)]] == "RF"
    assert page.inner_text(cell("snare", 4)) == letters[steps[("snare", 4)]] + ">"
    assert page.inner_text(cell("hihat", 2)) == letters[steps[("hihat", 2)]]
    thetas = [c for c in pd.read_csv(tmp_path / "cli.csv").columns if c.endswith(".theta")]  # every limb's, the
    assert page.locator(".kit-limbs path.theta").count() == len(thetas) == 4  # idle left foot's too
    page.click("#part-play")
    page.wait_for_selector("body[data-playing] .kit-lane line.cursor", state="attached", timeout=WAIT)
    page.evaluate("window.scrollTo(0, document.querySelector('#part-grid').offsetTop - 56)")  # the grid, the lanes
    screenshot(page, "studio-kit.png", tmp_path)
    page.wait_for_selector("body[data-played]", timeout=WAIT)
    with page.expect_download() as waiting:
        page.click("#part-download-csv")
    got, expected = pd.read_csv(waiting.value.path()), pd.read_csv(tmp_path / "cli.csv")
    assert list(got.columns) == list(expected.columns)
    np.testing.assert_allclose(got.to_numpy(), expected.to_numpy(), rtol=0, atol=1e-12)


def test_a_note_no_limb_plays_shows_compose_kits_reason_beside_it(page, tmp_path, capsys):
    page.check("#part-kit")
    planned(page, 16 + 4 + 4)  # the kit's groove first: 2 bars of the hi-hat's 8ths, the snare on 2, 4, the kick 1, 3
    text = "tempo 120\n0 auto 100 auto kick\n0.02 auto 100 auto kick\n1 auto 116 auto snare\n"
    page.fill("#part-text", text)
    planned(page, 3)
    assert "does not fit the grid" in page.inner_text("#part-fits")  # 0.02 is no step of the grid
    path = tmp_path / "close.pattern"
    path.write_text(text)
    capsys.readouterr()
    assert main(["compose", str(path), "--kit", "--verbose", "--json", str(tmp_path / "close.json")]) == 0
    (reason,) = [n["reason"] for n in json.loads((tmp_path / "close.json").read_text())["notes"] if not n["played"]]
    item = page.locator("#part-problems li")
    assert item.count() == 1 and reason in item.inner_text() and "kick" in item.inner_text()
    beside = page.locator(".kit-lane[data-piece='kick'] .problem-mark[data-note='1']")
    assert beside.count() == 1 and beside.locator("title").text_content() == reason
    assert page.locator(".kit-lane[data-piece='kick'] text.mark.missed").count() == 1


def test_the_sticks_grid_is_kept_while_the_kit_plays(page):
    sticks = page.input_value("#part-text")
    page.check("#part-kit")
    page.wait_for_function("document.querySelector('#part-text').value.includes(' auto hihat')")
    assert page.locator("#part-download-ros").is_hidden() and page.locator("#part-download-plot").is_visible()
    page.click(cell("crash", 0))
    page.wait_for_function("document.querySelector('#part-text').value.includes(' auto crash')")
    page.uncheck("#part-kit")
    page.wait_for_selector(".lane[data-stick='right']")
    assert page.input_value("#part-text") == sticks and page.locator(".kit-lane").count() == 0
    page.check("#part-kit")  # the kit's grid as it was left
    page.wait_for_function("document.querySelector('#part-text').value.includes(' auto crash')")
