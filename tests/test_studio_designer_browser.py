"""The stroke designer and the palette in a real browser — Debian's Chromium driven by Playwright — against a served
studio: a diddle designed by its notes and heard, a breakpoint dragged (the impacts shown are those `drumstroke
simulate` finds for the downloaded recipe), a post-processed stroke saved and listed by `drumstroke library list`."""

import json

import numpy as np
import pytest

from _studio import WAIT, browser_tab, cli, screenshot
from drumstroke.design.chain import DRIFT
from drumstroke.palette.library import load_library
from drumstroke.studio.app import make_studio


@pytest.fixture()
def studio(tmp_path):
    library = tmp_path / "library"
    library.mkdir()
    server = make_studio(port=0, library=library)
    server.start()
    yield server, library
    server.stop()


@pytest.fixture()
def page(studio):
    server, _ = studio
    with browser_tab(server.url) as tab:
        tab.wait_for_selector("body[data-designer-state=drawn]", timeout=WAIT)
        yield tab


def shown_impacts(page):
    """The impacts the page lists: times (s) and levels (dB), as its table holds them."""
    rows = page.query_selector_all("#designer-impacts tr")
    return (np.array([float(r.get_attribute("data-t")) for r in rows]),
            np.array([float(r.get_attribute("data-level")) for r in rows]))


def drawn(page):
    page.wait_for_selector("body[data-designer-state=drawn]", timeout=WAIT)


def test_a_diddle_designed_by_its_notes_plays_them_and_is_heard(page, tmp_path):
    box = page.locator("#designer-theta svg").bounding_box()
    for fraction in (0.3, 0.4):  # two notes clicked on the theta chart, then their times and levels typed exactly
        page.mouse.click(box["x"] + box["width"] * fraction, box["y"] + box["height"] * 0.5)
    assert page.locator("#designer-notes tr").count() == 2
    for row, (t, level) in enumerate([(0.5, 0.0), (0.65, -6.0)]):
        page.locator(".note-t").nth(row).fill(str(t))
        page.locator(".note-t").nth(row).dispatch_event("change")
        page.locator(".note-level").nth(row).fill(str(level))
        page.locator(".note-level").nth(row).dispatch_event("change")
    page.click("#designer-design")
    page.wait_for_selector("body[data-designed=yes]", timeout=WAIT)
    times, levels = shown_impacts(page)
    np.testing.assert_allclose(times[:2], [0.5, 0.65], rtol=0, atol=DRIFT[0])
    np.testing.assert_allclose(levels[:2], [0.0, -6.0], rtol=0, atol=DRIFT[1])
    assert page.locator("#designer-theta circle.note").count() == 2
    page.click("#designer-play")
    page.wait_for_selector("body[data-played=yes]", timeout=WAIT)
    screenshot(page, "studio-designer.png", tmp_path)

    # the second note too soon and too loud: its reason and the nearest reachable time, which then plays
    page.locator(".note-t").nth(1).fill("0.52")
    page.locator(".note-t").nth(1).dispatch_event("change")
    page.click("#designer-design")
    page.wait_for_selector("body[data-designed=unreachable]", timeout=WAIT)
    assert "nearest reachable: t =" in page.inner_text("#designer-problem")
    assert page.locator("#designer-theta line.nearest").count() == 1
    page.click("#designer-use-nearest")
    page.click("#designer-design")
    page.wait_for_selector("body[data-designed=yes]", timeout=WAIT)
    nearest = float(page.locator("#designer-notes tr").nth(1).get_attribute("data-t"))
    assert nearest > 0.52
    np.testing.assert_allclose(shown_impacts(page)[0][1], nearest, rtol=0, atol=DRIFT[0])


def test_a_dragged_breakpoint_moves_the_impacts_to_where_drumstroke_simulate_puts_them(page, tmp_path):
    before, _ = shown_impacts(page)
    handle = page.locator('#designer-force circle.handle[data-point="2"]')  # low-high's rise to 220 m/s^2
    box = handle.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()
    for k in range(1, 11):
        page.mouse.move(x - 12 * k, y + 4 * k)  # earlier and weaker
    page.mouse.up()
    drawn(page)
    after, _ = shown_impacts(page)
    assert len(after) != len(before) or np.abs(after - before).max() > 1e-3
    point = page.locator("#designer-terms tbody tr").nth(2)
    assert float(point.locator(".point-0").input_value()) < 1.05  # the table follows the handle

    # a keyboard move: the focused handle one step later
    t_before = float(point.locator(".point-0").input_value())
    page.locator('#designer-force circle.handle[data-point="2"]').focus()
    page.keyboard.press("ArrowRight")
    drawn(page)
    moved = float(page.locator("#designer-terms tbody tr").nth(2).locator(".point-0").input_value())
    assert moved == pytest.approx(t_before + 0.01, abs=1e-9)

    with page.expect_download() as downloading:
        page.click("#designer-toml")
    recipe = tmp_path / "dragged.toml"
    downloading.value.save_as(recipe)
    cli("simulate", str(recipe), "--json", str(tmp_path / "dragged.json"))
    simulated = [impact["t"] for impact in json.loads((tmp_path / "dragged.json").read_text())["impacts"]]
    shown, _ = shown_impacts(page)
    assert len(shown) == len(simulated)
    np.testing.assert_allclose(shown, simulated, rtol=0, atol=1e-9)


def test_a_post_processed_stroke_saved_from_the_palette_is_listed_by_drumstroke_library_list(page, studio, tmp_path):
    _, library = studio
    page.click("#tab-palette")
    page.wait_for_selector("body[data-palette-cards]", timeout=WAIT)
    page.click('article[data-name="double"] .card-use')
    page.wait_for_selector("body[data-previewed=yes]", timeout=WAIT)
    page.fill("#palette-stretch", "1.5")
    page.click("#palette-add-stretch")
    page.wait_for_selector("body[data-previewed=yes]", timeout=WAIT)
    page.click("#palette-play")
    page.wait_for_selector("body[data-played=yes]", timeout=WAIT)
    page.fill("#palette-name", "slow-double")
    page.fill("#palette-category", "double stroke")
    page.fill("#palette-description", "the diddle, half as slow again")
    screenshot(page, "studio-palette.png", tmp_path)
    page.click("#palette-save")
    page.wait_for_selector("body[data-saved=slow-double]", timeout=WAIT)
    listing = cli("library", "list", str(library))
    assert "slow-double" in listing and "double stroke: the diddle, half as slow again" in listing
    cli("simulate", "double", "--stretch", "1.5", "--json", str(tmp_path / "d.json"))
    expected = [impact["t"] for impact in json.loads((tmp_path / "d.json").read_text())["impacts"]]
    np.testing.assert_allclose(load_library(library)["slow-double"].trajectory.impacts.t, expected, rtol=0, atol=1e-9)
    page.wait_for_selector('article[data-name="slow-double"][data-source="library"]', timeout=WAIT)

    # the same name again is refused, unless replacing is asked
    page.click("#palette-save")
    page.wait_for_selector("#status.error", timeout=WAIT)
    assert "already" in page.inner_text("#status")
    page.check("#palette-replace")
    page.click("#palette-save")
    page.wait_for_selector("body[data-saved=slow-double]", timeout=WAIT)
    assert "saved slow-double" in page.inner_text("#status")
    assert "whole: 1 strokes" in cli("library", "check", str(library))
