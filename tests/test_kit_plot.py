"""The kit's picture, read back from its artists: a lane per piece, every hit at its time on its lane in its limb's
colour and shape and sized by its level, the hi-hat's states by fill, the notes not played crossed, the joints'
angles on one time axis and one scale per kind; the window; the PNG; the command line."""

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from _cli import assert_one_line_error, run
from drumstroke.compose import compose_kit
from drumstroke.errors import ParameterError
from drumstroke.kit.pieces import default_kit
from drumstroke.render.kit_plot import check_window, kit_figure, part_span
from drumstroke.render.outputs import write_kit_outputs
from drumstroke.score import ScoreNote

pytest.importorskip("matplotlib")
from matplotlib.colors import to_rgba

KIT = default_kit()
SONGS = Path(__file__).parent / "data" / "midi"
BEAT = 0.5  # s: a quarter note at the default tempo map's 120 bpm
LIMBS = ("right", "left", "right-foot", "left-foot")


@pytest.fixture(scope="module")
def groove():
    """Two bars at 120 bpm: hi-hat 8ths alternating velocities 100 and 50 (open on bar 1's last 8th), kick on 1 and
    3, snare on 2 and 4 (110) with a ghost note (30) before beat 2; the hi-hat's pedal on bar 2's beats 2 and 4; a
    crash and a first tom on the first downbeat with the hi-hat: three hand notes at once, one not played."""
    rows = [(eighth / 2, 46 if eighth == 7 else 42, 100 if eighth % 2 == 0 else 50) for eighth in range(16)]
    rows += [(beat, 36, 100) for beat in (0, 2, 4, 6)] + [(beat, 38, 110) for beat in (1, 3, 5, 7)]
    rows += [(0.75, 38, 30), (5, 44, 90), (7, 44, 90), (0, 49, 120), (0, 48, 100)]
    notes = [ScoreNote(beat * BEAT, "auto", velocity, None, beat=float(beat), piece=KIT.piece_for_key(key)[0].name,
                       key=key) for beat, key, velocity in sorted(rows)]
    piece = compose_kit(notes, KIT)
    return piece, kit_figure(piece, title="groove")


def hit_collections(figure):
    """The lanes' hit markers: {gid: collection}, one per limb and fill ("right hits full")."""
    return {c.get_gid(): c for c in figure.axes[0].collections if " hits " in (c.get_gid() or "")}


def lanes_of(figure):
    """The lanes' pieces, top to bottom."""
    return [label.get_text() for label in figure.axes[0].get_yticklabels()]


def drawn_hits(figure):
    """Every hit marker as (x, lane's piece, limb, fill, area in pt²), by time (to 1e-9 s), lane and limb."""
    lanes = lanes_of(figure)
    return sorted(((float(x), lanes[int(y)], gid.split()[0], gid.split()[-1], float(size))
                   for gid, c in hit_collections(figure).items()
                   for (x, y), size in zip(c.get_offsets(), np.broadcast_to(c.get_sizes(), len(c.get_offsets())))),
                  key=lambda d: (round(d[0], 9), lanes.index(d[1]), d[2]))


def played(piece, figure):
    """The hits in drawn_hits' order: (x, piece, limb, level in dB re 1 m/s)."""
    lanes = lanes_of(figure)
    return sorted(((h.t - piece.offset, h.piece, h.limb, 20.0 * math.log10(h.speed)) for h in piece.performance.hits),
                  key=lambda h: (round(h[0], 9), lanes.index(h[1]), h[2]))


def test_one_lane_per_piece_with_notes_in_the_kit_s_order(groove):
    piece, figure = groove
    lanes = lanes_of(figure)
    assert lanes == ["snare", "kick", "hihat", "tom1", "crash"]  # the kit's order; no lane for a piece without notes
    assert figure.axes[0].get_ylim() == (len(lanes) - 0.5, -0.5)  # the first on top
    assert len(lanes) == len({o.piece for o in piece.performance.outcomes})


def test_every_hit_is_drawn_at_its_time_on_its_piece_s_lane_in_its_limb_s_colour(groove):
    piece, figure = groove
    hits = piece.performance.hits
    drawn = drawn_hits(figure)
    assert len(drawn) == len(hits) == 28  # 29 notes, one left out, no bounce
    np.testing.assert_allclose([d[0] for d in drawn], [h[0] for h in played(piece, figure)], atol=1e-12)
    assert [d[1:3] for d in drawn] == [h[1:3] for h in played(piece, figure)]
    colours = {}
    for gid, collection in hit_collections(figure).items():
        limb, _, fill = gid.split()
        colour = collection.get_edgecolor()[0] if fill == "none" else collection.get_facecolor()[0]
        assert colours.setdefault(limb, tuple(colour)) == tuple(colour)  # one colour a limb
    assert set(colours) == {"right", "left", "right-foot", "left-foot"}
    assert len(set(colours.values())) == 4  # and each limb its own
    legend = {text.get_text(): handle for text, handle in
              zip(figure.axes[0].get_legend().get_texts(), figure.axes[0].get_legend().legend_handles)}
    for limb, name in zip(LIMBS, ("right hand", "left hand", "right foot", "left foot")):
        assert to_rgba(legend[name].get_color()) == colours[limb]  # the key says which colour is which limb


def test_louder_hits_are_bigger_markers(groove):
    piece, figure = groove
    drawn = drawn_hits(figure)
    pairs = sorted((level, d[4]) for (*_, level), d in zip(played(piece, figure), drawn, strict=True))
    assert all(b[1] >= a[1] for a, b in itertools.pairwise(pairs))  # the area never shrinks as the level grows
    assert pairs[-1][0] > pairs[0][0] + 20.0 and pairs[-1][1] > 2.0 * pairs[0][1]  # a kick stands out from a ghost
    hats = [(level, d[4]) for (_, name, limb, level), d in zip(played(piece, figure), drawn)
            if name == "hihat" and limb == "right"]
    loud, soft = max(hats), min(hats)
    assert loud[0] > soft[0] + 6.0 and loud[1] > 1.3 * soft[1]  # a hi-hat at 100 stands out from one at 50
    assert all(2.0 <= size <= 30.0 for _, size in pairs)  # the default sizes, pt²


def test_the_hi_hat_s_states_are_told_apart_by_the_fill(groove):
    piece, figure = groove
    collections = hit_collections(figure)
    shift = piece.offset
    fills = {}
    for x, _, _, fill, _ in drawn_hits(figure):
        fills.setdefault(fill, set()).add(round(x, 9))
    for h in piece.performance.hits:
        if h.piece == "hihat":
            state = {42: "closed", 46: "open", 44: "pedal"}[h.key]
            expected = {"closed": "full", "open": "none", "pedal": "bottom"}[state]
            assert round(h.t - shift, 9) in fills[expected], (h, state)
    assert {h.key for h in piece.performance.hits if h.piece == "hihat"} == {42, 44, 46}
    open_ = collections["right hits none"]
    assert len(open_.get_facecolor()) == 0 and open_.get_edgecolor()[0][3] == 1.0  # hollow
    pedal = collections["left-foot hits bottom"]
    outline = next(c for c in figure.axes[0].collections if c.get_gid() == "left-foot outline")
    np.testing.assert_array_equal(outline.get_offsets(), pedal.get_offsets())
    half, whole = pedal.get_paths()[0].vertices, outline.get_paths()[0].vertices
    assert half[:, 1].max() <= 1e-9 < whole[:, 1].max()  # the lower half filled inside the whole outline
    assert half[:, 1].min() == pytest.approx(whole[:, 1].min())


def test_a_note_not_played_is_a_grey_cross_at_its_time_in_its_lane(groove):
    piece, figure = groove
    (missed,) = [o for o in piece.performance.outcomes if not o.played]
    assert missed.piece in ("tom1", "crash") and missed.note.time - piece.offset == 0.0  # a third hand at once
    lanes = lanes_of(figure)
    crosses = next(c for c in figure.axes[0].collections if c.get_gid() == "not played")
    np.testing.assert_allclose(crosses.get_offsets(), [[0.0, lanes.index(missed.piece)]])
    assert crosses.get_facecolor()[0][:3] == pytest.approx(to_rgba("0.5")[:3])
    assert any(t.get_text() == "note not played" for t in figure.axes[0].get_legend().get_texts())


def test_the_joints_share_the_time_axis_each_kind_on_one_scale(groove):
    piece, figure = groove
    lanes, *joints = figure.axes
    assert [ax.get_ylabel() for ax in joints] == ["yaw (rad)", "lift (rad)", "stick θ (rad)", "beater θ (rad)"]
    low, high = part_span(piece)
    for ax in figure.axes:
        assert ax.get_xlim() == pytest.approx((low, high))
        assert ax.get_shared_x_axes().joined(ax, lanes)
    t, columns = piece.sample(1000.0)
    for ax, (joint, limbs) in zip(joints, (("yaw", LIMBS[:2]), ("lift", LIMBS[:2]), ("theta", LIMBS[:2]),
                                           ("theta", LIMBS[2:]))):
        assert [line.get_label() for line in ax.lines if line.get_label()[0] != "_"] == [
            {"right": "right hand", "left": "left hand", "right-foot": "right foot", "left-foot": "left foot"}[limb]
            for limb in limbs]
        curves = [line for line in ax.lines if line.get_label()[0] != "_"]
        for line, limb in zip(curves, limbs):
            np.testing.assert_allclose(line.get_xdata(), t - piece.offset, atol=1e-12)
            np.testing.assert_allclose(line.get_ydata(), columns[f"{limb}.{joint}"], atol=1e-12)
        both = np.concatenate([columns[f"{limb}.{joint}"] for limb in limbs])
        bottom, top = ax.get_ylim()
        assert bottom < both.min() and both.max() < top  # both limbs on the one scale


def test_a_window_draws_its_stretch_on_the_whole_part_s_scales(groove):
    piece, whole = groove
    figure = kit_figure(piece, title="groove", window=(2.0, 3.0))  # bar 2's first half
    for ax in figure.axes:
        assert ax.get_xlim() == (2.0, 3.0)
    expected = sorted(h.t - piece.offset for h in piece.performance.hits if 2.0 <= h.t - piece.offset <= 3.0)
    assert len(expected) >= 8
    np.testing.assert_allclose([d[0] for d in drawn_hits(figure)], expected, atol=1e-12)
    for ax, full in zip(figure.axes[1:], whole.axes[1:]):
        assert ax.get_ylim() == full.get_ylim()  # a quiet stretch is drawn on the loud part's scale
        for line in ax.lines:
            if line.get_label()[0] != "_":
                assert 2.0 - 0.0011 <= line.get_xdata().min() and line.get_xdata().max() <= 3.0 + 0.0011
    assert "2 s to 3 s of the part's" in figure.get_suptitle()


def test_the_title_and_the_time_axis_are_words(groove):
    _, figure = groove
    title = figure.get_suptitle()
    assert title.startswith("groove on the kit — 120 bpm, model: paper; the whole part, ")
    assert title.endswith("28 of 29 notes played")
    assert "score time 0" not in title and "offset" not in title
    assert figure.axes[-1].get_xlabel() == "time from the score's start (s); bars solid, beats dotted"
    bars = sorted({round(float(line.get_xdata()[0]), 9) for line in figure.axes[0].lines
                   if line.get_linestyle() == "-" and line.get_color() == "0.45"})
    np.testing.assert_allclose(bars, [0.0, 2.0, 4.0])  # two bars of 4/4 at 120 bpm
    legend = figure.axes[0].get_legend()
    assert "marker area" in legend.get_title().get_text()
    assert [t.get_text() for t in legend.get_texts()][-3:] == ["-36 dB", "-9 dB", "+17 dB"]


@pytest.mark.parametrize(("window", "match"), [
    ((math.nan, 1.0), r"window start must be a finite number in \[-0.241, 4.\d+\) s, the part's span"),
    ((1.0, math.inf), r"window end must be a finite number in \(1, inf\) s, got inf"),
    ((2.0, 2.0), r"window end must be in \(2, inf\) s, got 2.0"),
    ((3.0, 1.0), r"window end must be in \(3, inf\) s, got 1.0"),
    ((60.0, 70.0), r"window start must be in \[-0.241, 4.\d+\) s, the part's span on the score's time, got 60.0"),
    ((-5.0, 1.0), r"window start must be in \[-0.241, "),
    ((1.0,), r"window must be \(start, end\), two numbers of seconds, got \(1.0,\)"),
    ("1,2", r"window must be \(start, end\)"),
    (("a", 1.0), r"window start must be a number in"),
])
def test_a_bad_window_is_refused_naming_it_and_the_part_s_span(groove, window, match):
    piece, _ = groove
    with pytest.raises(ParameterError, match=match):
        kit_figure(piece, window=window)


def test_check_window_brings_an_end_past_the_part_back_to_it():
    assert check_window((1, 2)) == (1.0, 2.0)
    assert check_window((1.0, 500.0), span=(-0.2, 100.0)) == (1.0, 100.0)
    assert check_window((-0.2, 3.0), span=(-0.2, 100.0)) == (-0.2, 3.0)


def test_other_bad_arguments_are_refused(groove):
    piece, _ = groove
    with pytest.raises(ParameterError, match="composition must be a drumstroke.compose.KitComposition"):
        kit_figure(piece.performance)
    with pytest.raises(ParameterError, match="title must be a str, got 3"):
        kit_figure(piece, title=3)
    with pytest.raises(ParameterError, match=r"rate must be in \[1, 100000\] Hz, got 0.0"):
        kit_figure(piece, rate=0.0)
    with pytest.raises(ParameterError, match=r"sizes\[1\] must be in \(5, 10000\] pt², got 4.0"):
        kit_figure(piece, sizes=(5.0, 4.0))


def test_the_outputs_write_a_png_and_nothing_for_a_bad_window(groove, tmp_path):
    from matplotlib.image import imread
    from PIL import Image

    piece, _ = groove
    written = write_kit_outputs(piece, title="groove", csv=tmp_path / "g.csv", plot=tmp_path / "g.png",
                                window=(0.0, 2.0))
    assert written == [tmp_path / "g.csv", tmp_path / "g.json", tmp_path / "g.png"]
    assert (tmp_path / "g.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with Image.open(tmp_path / "g.png") as image:
        image.verify()
    pixels = imread(tmp_path / "g.png")
    assert pixels.shape[1] == 1320 and pixels.shape[2] == 4  # 12 in at 110 dpi, RGBA
    assert np.ptp(pixels[..., :3]) > 0.5  # drawn, not blank
    with pytest.raises(ParameterError, match="window start"):
        write_kit_outputs(piece, csv=tmp_path / "h.csv", plot=tmp_path / "h.png", window=(50.0, 60.0))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.csv", "g.json", "g.png"]  # nothing more


def test_compose_kit_plots_a_window_of_a_real_song(tmp_path):
    from matplotlib.image import imread

    result = run("compose", SONGS / "In Too Deep.mid", "--kit", "--plot", tmp_path / "deep.png", "--plot-window",
                 "24,30", "--quiet")
    assert result.returncode == 0, result.stderr
    pixels = imread(tmp_path / "deep.png")
    assert pixels.shape[1] == 1320 and np.ptp(pixels[..., :3]) > 0.5


@pytest.mark.parametrize(("window", "needle"), [
    ("5,3", "argument --plot-window: END must be in (5, inf) s, got 3.0"),
    ("nan,4", "argument --plot-window: START must be a finite number in (-inf, inf) s, got nan"),
    ("1,inf", "argument --plot-window: END must be a finite number in (1, inf) s, got inf"),
    ("1,2,3", "argument --plot-window: must be START,END, two numbers of seconds, got '1,2,3'"),
    ("soon", "argument --plot-window: must be START,END, two numbers of seconds, got 'soon'"),
    ("300,310", "--plot-window START must be in [0, 206.264) s, the part's span on the score's time, got 300.0"),
])
def test_compose_kit_refuses_a_bad_window_cleanly(tmp_path, window, needle):
    result = run("compose", SONGS / "Les Yeux Revolvers.mid", "--kit", "--plot", tmp_path / "x.png", "--json",
                 tmp_path / "x.json", "--plot-window", window, "--quiet")
    assert_one_line_error(result, needle)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("options", "needle"), [
    (["--kit"], "--plot-window draws a stretch of --plot's picture: give --plot too"),
    (["--plot", "x.png"], "--plot-window draws a stretch of the kit's picture: give --kit too"),
])
def test_a_window_needs_the_kit_s_plot(tmp_path, options, needle):
    pattern = tmp_path / "bar.pattern"
    pattern.write_text("tempo 120\n0 auto 100 auto kick\n1 auto 100\n")
    result = run("compose", pattern, *options, "--plot-window", "0,1", cwd=tmp_path)
    assert_one_line_error(result, needle)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bar.pattern"]
