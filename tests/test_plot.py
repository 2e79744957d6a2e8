"""The picture of a composed part, read back from its artists: lanes, shared scale, sticking, accents, title."""

import numpy as np
import pytest

from drumstroke.compose import compose, rudiment_score
from drumstroke.render.plot import composition_figure
from drumstroke.render.sticking import ACCENT_VELOCITY
from drumstroke.score import read_score

pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def paradiddle():
    score, _ = rudiment_score("single-paradiddle", 100.0, bars=2)
    piece = compose(score)
    return piece, composition_figure(piece, title="single-paradiddle")


def lanes(figure):
    """The figure's lanes: its axes with a θ label, top to bottom."""
    return [ax for ax in figure.axes if ax.get_ylabel().startswith("θ")]


def marks(ax):
    """The sticking texts of a lane: (time, text, bold) in time order."""
    return sorted((t.xy[0], t.get_text(), t.get_fontweight() == "bold") for t in ax.texts if t.get_gid() == "sticking")


def test_one_lane_per_stick_right_on_top_on_one_theta_scale(paradiddle):
    piece, figure = paradiddle
    right, left = lanes(figure)
    assert [right.get_ylabel(), left.get_ylabel()] == ["θ right stick (rad)", "θ left stick (rad)"]
    assert right.get_shared_y_axes().joined(right, left)
    assert right.get_ylim() == left.get_ylim()
    low, high = right.get_ylim()
    for stick in piece.sticks.values():  # every curve and the head inside the one scale
        assert low < stick.theta_max and stick.sample(1000.0).theta.max() <= high


def test_the_sticking_reads_as_the_paradiddle_with_its_accents(paradiddle):
    piece, figure = paradiddle
    written = sorted(m for ax in lanes(figure) for m in marks(ax))
    assert " ".join(text for _, text, _ in written) == " ".join(["R> L R R L> R L L"] * 4)
    notes = sorted((p.note.time, p.note.velocity) for p in piece.placements)
    np.testing.assert_allclose([t for t, _, _ in written], [t for t, _ in notes], atol=1e-12)
    # bold, with '>', exactly at the notes at or above the accent velocity
    assert [bold for _, _, bold in written] == [v >= ACCENT_VELOCITY for _, v in notes]
    assert [text.endswith(">") for _, text, _ in written] == [v >= ACCENT_VELOCITY for _, v in notes]


def test_the_impacts_are_dots_on_one_level_scale_larger_when_louder(paradiddle):
    piece, figure = paradiddle
    dots = [ax.collections[0] for ax in lanes(figure)]
    assert dots[0].norm.vmin == dots[1].norm.vmin and dots[0].norm.vmax == dots[1].norm.vmax
    for lane, stick in zip(dots, ("right", "left")):
        level = piece.sticks[stick].impacts.level_db
        np.testing.assert_allclose(lane.get_array(), level)
        order = np.argsort(level)
        assert np.all(np.diff(lane.get_sizes()[order]) >= 0)  # size grows with the level
        assert lane.get_sizes()[order[-1]] > 2 * lane.get_sizes()[order[0]]  # an accent stands out from a tap
    legend = lanes(figure)[0].get_legend()
    assert "impacts: size and colour" in legend.get_title().get_text()
    assert any("dB re 1 m/s" in text.get_text() for text in legend.get_texts())


def test_the_title_and_the_time_axis_are_words(paradiddle):
    piece, figure = paradiddle
    title = figure.get_suptitle()
    assert title.startswith("single-paradiddle — 100 bpm, 2 bars, model: paper\n32 of 32 notes played")
    assert "score time 0" not in title
    right, left = lanes(figure)
    assert left.get_xlabel().startswith("time from the score's start (s)")
    assert right.get_xlim() == (-piece.offset, piece.t_end - piece.offset)
    bars = sorted({round(line.get_xdata()[0], 9) for line in right.lines
                   if line.get_linestyle() == "-" and line.get_color() == "0.45"})
    np.testing.assert_allclose(bars, [0.0, 2.4, 4.8])  # two bars of 4/4 at 100 bpm


def test_a_groove_marks_its_ghosts_names_its_library_strokes_and_says_its_tempo(tmp_path, library_single_and_tap):
    pattern = tmp_path / "ghosts.pattern"
    pattern.write_text("tempo 90\nmeter 3/4\n0 single 120 right\n1 tap 40 left\n2 single 90 right\n3 tap 70 left\n")
    piece = compose(read_score(pattern), library_single_and_tap)
    figure = composition_figure(piece, title=pattern.name)
    right, left = lanes(figure)
    assert [text for _, text, _ in marks(right)] == ["R>", "R"]
    assert [text for _, text, _ in marks(left)] == ["(L)", "l"]
    names = sorted((t.xy[0], t.get_text()) for ax in (right, left) for t in ax.texts if t.get_gid() != "sticking")
    assert [name for _, name in names] == ["single", "tap", "single", "tap"]
    assert figure.get_suptitle().startswith("ghosts.pattern — 90 bpm, 2 bars, model: paper")


@pytest.fixture(scope="module")
def library_single_and_tap(tmp_path_factory):
    from drumstroke.palette.library import build_library, read_palette

    return build_library(tmp_path_factory.mktemp("library"),
                         palette=[e for e in read_palette() if e.name in ("single", "tap")])
