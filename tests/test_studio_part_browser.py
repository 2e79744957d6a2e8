"""The part editor and the robot view in a real browser (Debian's Chromium driven by Playwright), whole sessions:
a groove built on the grid by clicks, planned, heard and downloaded (its CSV the command line's); a note out of
reach shown beside itself with its reason; a rudiment loaded and planned; the part tracked by the robot."""


import numpy as np
import pandas as pd
import pytest

from _studio import WAIT, part_editor, planned, screenshot
from drumstroke.cli import main

GROOVE = "".join(["tempo 160\n"] + [f"{k / 2:g} auto {116 if k % 4 == 2 else 100} {'right' if k % 2 == 0 else 'left'}\n"
                                    for k in range(16)])  # what the clicks below build: 2 bars of 8ths, accents on 2, 4
@pytest.fixture()
def page():
    with part_editor() as tab:
        yield tab


def test_a_groove_clicked_on_the_grid_is_planned_heard_and_its_csv_is_compose_s(page, tmp_path):
    page.click("#part-clear")
    page.fill("#part-tempo", "160")
    page.press("#part-tempo", "Enter")  # the change, before a click elsewhere
    for k in range(16):  # the 8ths: right on the beat, left between; a second click makes the accent
        cell = f".cell[data-row='{'right' if k % 2 == 0 else 'left'}'][data-step='{2 * k}']"
        page.click(cell)
        if k % 4 == 2:
            page.focus(cell)
            page.keyboard.press("Enter")
    planned(page, 16)
    assert page.input_value("#part-text") == GROOVE
    assert page.inner_text("#part-sticking") == "Sticking: R L R> L R L R> L | R L R> L R L R> L"
    assert page.locator(".lane").count() == 2 and page.locator("#part-problems li").count() == 0
    page.click("#part-play")
    # a cursor follows the sound over the lanes
    page.wait_for_selector("body[data-playing] .lane line.cursor", state="attached", timeout=WAIT)
    screenshot(page, "studio-part.png", tmp_path)
    page.wait_for_selector("body[data-played]", timeout=WAIT)
    with page.expect_download() as waiting:
        page.click("#part-download-csv")
    got = pd.read_csv(waiting.value.path())
    pattern = tmp_path / "groove.pattern"
    pattern.write_text(GROOVE)
    assert main(["compose", str(pattern), "--quiet", "--csv", str(tmp_path / "cli.csv")]) == 0
    expected = pd.read_csv(tmp_path / "cli.csv")
    assert list(got.columns) == list(expected.columns)
    np.testing.assert_allclose(got.to_numpy(), expected.to_numpy(), rtol=0, atol=1e-12)


def test_a_note_out_of_reach_shows_its_reason_beside_it(page, tmp_path, capsys):
    text = "tempo 60\n0.5 auto 100 right\n0.51 auto 60 right\n0.52 auto 60 right\n1 auto 100 left\n"
    page.fill("#part-text", text)
    planned(page, 4)
    path = tmp_path / "close.pattern"
    path.write_text(text)
    capsys.readouterr()
    main(["compose", str(path), "--verbose"])
    warned = [line.removeprefix(f"warning: {path}") for line in capsys.readouterr().err.splitlines()
              if line.startswith("warning: ")]
    assert warned
    items = page.locator("#part-problems li")
    assert items.count() == len(warned)
    for k, reason in enumerate(warned):
        item = items.nth(k)
        assert reason.removesuffix("; left out").split(": ", 1)[1] in item.inner_text()
        note = item.get_attribute("data-note")
        beside = page.locator(f".lane[data-stick='right'] .problem-mark[data-note='{note}']")
        assert beside.count() == 1  # drawn at its note, in its stick's lane
        assert beside.locator("title").text_content() == "pattern" + reason
    assert "nearest playable time" in items.first.inner_text()
    assert "bar 1, beat" in items.first.inner_text()
    assert page.is_hidden("#part-fits") or page.inner_text("#part-fits") != ""  # 0.51 is no step of the grid


def test_a_rudiment_is_loaded_and_planned(page, tmp_path):
    page.wait_for_selector("#part-rudiment option[value='flam-tap']", state="attached")
    page.select_option("#part-rudiment", "flam-tap")
    page.fill("#part-rudiment-tempo", "90")
    page.click("#part-rudiment-load")
    planned(page, 48)
    assert page.inner_text("#part-sticking").startswith("Sticking: lR> R rL> L lR> R rL> L")
    assert page.locator(".lane text.mark").count() == 48
    assert "does not fit the grid" in page.inner_text("#part-fits")  # the flams' grace notes are no steps
    assert main(["rudiment", "flam-tap", "--tempo", "90", "--csv", str(tmp_path / "r.csv")]) == 0
    with page.expect_download() as waiting:
        page.click("#part-download-csv")
    np.testing.assert_allclose(pd.read_csv(waiting.value.path()).to_numpy(), pd.read_csv(tmp_path / "r.csv").to_numpy(),
                               rtol=0, atol=1e-12)


def test_the_robot_tracks_the_part_and_shows_the_onsets_kept_and_missed(page, tmp_path):
    page.click("#tab-robot")
    page.wait_for_selector("#robot-controller option[value='pi']", state="attached")
    page.select_option("#robot-controller", "pi")
    page.click("#robot-track")
    page.wait_for_selector("body[data-tracked]", timeout=WAIT)
    sticks = page.locator("li.robot-stick")
    assert sticks.count() == 2
    missed_any = False
    for k in range(2):
        item = sticks.nth(k)
        stick, kept, total = (item.get_attribute(a) for a in ("data-stick", "data-kept", "data-total"))
        lane = page.locator(f"#robot-lanes .lane[data-stick='{stick}']")
        assert lane.locator(".onset-kept circle").count() == int(kept)
        assert lane.locator(".onset-missed").count() == int(total) - int(kept)
        missed_any |= int(kept) < int(total)
    assert missed_any  # the PI controller, without feedforward, misses some (the paper's finding)
    screenshot(page, "studio-robot.png", tmp_path)


def test_a_midi_file_chosen_is_planned_and_its_notes_shown_as_text(page, tmp_path):
    import mido

    track = mido.MidiTrack([mido.MetaMessage("set_tempo", tempo=600_000)])  # 100 bpm
    for k in range(8):  # 8ths on the acoustic snare, every other one accented
        velocity, time = (116 if k % 2 else 100), (0 if k == 0 else 240)
        track += [mido.Message("note_on", channel=9, note=38, velocity=velocity, time=time),
                  mido.Message("note_off", channel=9, note=38, velocity=0, time=0)]
    song = mido.MidiFile(ticks_per_beat=480)
    song.tracks.append(track)
    song.save(tmp_path / "song.mid")
    page.set_input_files("#part-midi", str(tmp_path / "song.mid"))
    planned(page, 8)
    lines = page.input_value("#part-text").splitlines()
    assert lines[0] == "tempo 100"
    assert [line.split()[:3] for line in lines[1:]] == [[f"{k / 2:g}", "auto", str(116 if k % 2 else 100)]
                                                         for k in range(8)]
    assert page.locator(".lane text.mark").count() == 8
