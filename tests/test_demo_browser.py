"""The demo page in a real browser — Debian's Chromium driven by Playwright: the rudiments and the groove show their
pictures and their sticking with accents and ghost notes.

The screenshot test saves (into ``DRUMSTROKE_SCREENSHOTS=DIR`` when it is set) the groove's and a rudiment's sections as
``DIR/demo-groove.png`` and ``DIR/demo-rudiments.png`` (the docs show those of ``docs/images``).
"""

import os
import re
from pathlib import Path

import pytest
from playwright.sync_api import sync_playwright

from drumstroke.demo import RUDIMENTS
from drumstroke.palette.rudiments import rudiment
from drumstroke.render.sticking import ACCENT_VELOCITY, GHOST_VELOCITY
from drumstroke.score import read_score

CHROMIUM = "/usr/bin/chromium"
SCREENSHOTS = "DRUMSTROKE_SCREENSHOTS"
SHOWN = "flam-accent"  # the rudiment of the screenshot: grace notes and accents


def section(name):
    """The CSS selector of a rudiment's section (its id starts with its number, so ``#id`` cannot select it)."""
    return f'[id="{rudiment(name).number}-{name}"]'


@pytest.fixture(scope="module")
def browser_page(demo):
    result, out = demo
    assert result.returncode == 0, result.stderr
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=["--no-sandbox"])
        page = browser.new_page(viewport={"width": 1200, "height": 900})
        errors = []
        page.on("pageerror", lambda error: errors.append(str(error)))
        page.goto((out / "index.html").as_uri())
        yield page, out, errors
        browser.close()


def shown(page, selector):
    """The section's picture scrolled into view and loaded (the page loads pictures lazily): its alt text and
    caption."""
    section = page.locator(selector)
    image = section.locator("img")
    image.scroll_into_view_if_needed()
    page.wait_for_function("image => image.complete && image.naturalWidth > 0", arg=image.element_handle())
    assert image.evaluate("image => image.naturalWidth") >= 800
    return image.get_attribute("alt"), section.locator("figcaption .sticking").inner_text()


@pytest.mark.parametrize("name", [name for name, _ in RUDIMENTS])
def test_each_rudiment_shows_its_picture_and_the_sheet_sticking_it_played(browser_page, name):
    page, _, errors = browser_page
    alt, caption = shown(page, section(name))
    # the sheet's cycle (data written from the PAS sheet), repeated over the two bars played
    cycle = rudiment(name).sticking.replace(" ", "")
    played = re.sub(r"[ |]", "", caption)
    assert played == cycle * (len(played) // len(cycle)) and len(played) >= 2 * len(cycle)
    assert caption.count("|") == 1  # two bars
    assert caption in alt and name.replace("-", " ") in alt.lower()
    assert errors == []


def test_the_groove_shows_its_picture_and_its_accents_and_ghost_notes(browser_page):
    page, out, errors = browser_page
    alt, caption = shown(page, "#groove")
    notes = read_score(out / "groove.pattern").notes
    words = caption.replace("|", " ").split()
    assert len(words) == len(notes)  # the groove has no grace notes joined to a main note
    assert [w.strip("()>").upper() for w in words] == [{"right": "R", "left": "L"}[n.stick] for n in notes]
    assert [w.endswith(">") for w in words] == [n.velocity >= ACCENT_VELOCITY for n in notes]
    assert [w.startswith("(") for w in words] == [n.velocity <= GHOST_VELOCITY for n in notes]
    assert caption.count("|") == 4  # four bars and a closing downbeat
    assert caption in alt
    assert errors == []


def test_screenshots_of_the_groove_and_a_rudiment_for_the_docs(browser_page, tmp_path):
    """The sections photographed as the docs show them: into ``$DRUMSTROKE_SCREENSHOTS`` when set, else a scratch folder."""
    page, _, _ = browser_page
    folder = Path(os.environ.get(SCREENSHOTS) or tmp_path)
    folder.mkdir(parents=True, exist_ok=True)
    for selector, name in ((section(SHOWN), "demo-rudiments.png"), ("#groove", "demo-groove.png")):
        shown(page, selector)
        page.locator(selector).screenshot(path=str(folder / name))
        png = (folder / name).read_bytes()
        width, height = int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")
        assert png[:8] == b"\x89PNG\r\n\x1a\n" and width >= 800 and height >= 400, (name, width, height)
