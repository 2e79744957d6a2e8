"""fit's suspects: onsets off one constant force's trend of bounces, named, and dropped, merged or filled on request."""

import json
from pathlib import Path

import numpy as np
import pytest

from _cli import run
from drumstroke import simulate
from drumstroke.analysis import Onsets, find_onsets, write_onsets
from drumstroke.analysis.fit import MATCH_WINDOW, TOLERANCE, find_suspects, fit_stroke
from drumstroke.design import HUMAN_FORCE
from drumstroke.errors import ParameterError

COR = 0.86
SOUNDFONT = Path("/usr/share/sounds/sf2/FluidR3_GM.sf2")


@pytest.fixture(scope="module")
def drop():
    """A stick dropped from 0.5 rad (gravity alone, c = 0.86): its impacts above -30 dB, exact."""
    impacts = simulate(theta0=0.5, cor=COR, t_end=10.0).impacts
    level = impacts.level_db - impacts.level_db.max()
    loud = level >= -30.0
    return impacts.t[loud], level[loud], impacts.level_db.max()


@pytest.fixture(scope="module")
def spoiled(drop):
    """The drop's onsets with bounce 7 missed, bounce 10 heard 4 ms late and an extra onset 20 ms after bounce 2."""
    t, level, _ = drop
    times, levels = list(t), list(level)
    times[10] += 4e-3
    del times[7], levels[7]
    times.insert(3, t[2] + 0.020)
    levels.insert(3, level[2] - 12.0)
    return Onsets(np.array(times), np.array(levels), threshold_db=-30.0, source="spoiled drop")


def test_exact_drop_has_no_suspects(drop):
    t, level, _ = drop
    assert find_suspects(Onsets(t, level)) == ()


def test_suspects_named(drop, spoiled):
    t, level, _ = drop
    suspects = {s.onset: s for s in find_suspects(spoiled)}
    assert sorted((i, s.action) for i, s in suspects.items()) == [(3, "drop"), (8, "fill"), (10, "replace")]
    assert "extra onset" in suspects[3].reason
    assert "between onsets 7 and 8" in suspects[8].reason
    assert suspects[8].filled == pytest.approx((t[7], level[7]), abs=1e-6)  # the missed bounce, from the trend
    assert "4 ms late" in suspects[10].reason
    assert suspects[10].filled == pytest.approx((t[10], level[10]), abs=1e-6)


def test_dropping_suspects_fits_the_drop(drop, spoiled):
    _, _, loudest = drop
    kept = fit_stroke(spoiled, cor=COR, drop_suspects=True)
    assert [i for i, _ in kept.dropped] == [3, 10] and not kept.unmatched
    assert kept.within and kept.time_error <= TOLERANCE[0] and kept.level_error <= TOLERANCE[1]
    assert kept.played.sum() == len(spoiled) - 2
    assert 0.0 <= kept.design.min_force and kept.design.max_force <= HUMAN_FORCE and not kept.beyond_human
    assert kept.offset == pytest.approx(loudest, abs=1e-3)  # a free drop: the fit finds its level
    data = kept.to_dict()
    assert [d["onset"] for d in data["dropped"]] == [3, 10] and len(data["suspects"]) == 3
    assert len(data["filled"]["t"]) == 2
    # without dropping: the suspects are listed, nothing is dropped, and the fit is not within
    plain = fit_stroke(spoiled, cor=COR)
    assert len(plain.suspects) == 3 and not plain.dropped and not plain.within


def test_drop_and_merge_by_hand(drop):
    t, level, _ = drop
    doubled = Onsets(np.insert(t, 4, t[3] + 0.003), np.insert(level, 4, level[3] - 2.0))
    (suspect,) = find_suspects(doubled)
    assert (suspect.onset, suspect.action, suspect.into) == (4, "merge", 3)
    merged = fit_stroke(doubled, cor=COR, merge=[3])
    assert merged.within and merged.dropped == ((4, "merged by hand into onset 3"),)
    dropped = fit_stroke(doubled, cor=COR, drop=[4])
    assert dropped.within and np.isnan(dropped.time_residual[4]) and not dropped.beyond_human


def test_an_onset_that_makes_the_thumb_press_beyond_the_human_is_named_and_dropped():
    """A stroke under 240 m/s² (near the human 250) with one bounce's level read 1 dB high, its loudest level given:
    playing that bounce needs a press beyond 250 m/s², and it alone does. It is named (kept without
    --drop-suspects, dropped with it), and what is kept is played within 2 ms and 1 dB under the human press.
    (The trend of levels cannot judge: its tolerance is opened to 48 dB.)"""
    from drumstroke import Constant, Recipe

    impacts = simulate(Recipe(force=Constant(240.0), theta0=0.5, cor=COR, t_end=3.0)).impacts
    level = impacts.level_db[:16].copy()
    spoiled_at = 8
    level[spoiled_at] += 1.0
    onsets = Onsets(impacts.t[:16], level - level.max(), source="pressed")
    options = {"cor": COR, "offset": float(level.max()), "suspect_level": 48.0}
    named = fit_stroke(onsets, **options)
    pressing = [s for s in named.suspects if "press beyond the human" in s.reason]
    assert [(s.onset, s.action) for s in pressing] == [(spoiled_at, "drop")]
    assert named.played[spoiled_at] and named.design.max_force > HUMAN_FORCE
    kept = fit_stroke(onsets, drop_suspects=True, **options)
    assert (spoiled_at, f"a suspect: {pressing[0].reason}") in kept.dropped and not kept.played[spoiled_at]
    assert kept.within and not kept.unmatched and kept.design.max_force <= HUMAN_FORCE
    assert kept.played.sum() == len(onsets) - len(kept.dropped)


def test_a_sequence_no_drop_makes_names_no_suspect():
    """Onsets of pulsed strokes whose chain of bounces starts with a 0.69-s flight and then shrinks fast: gravity's
    launch for such a first flight goes over the top, so no drop's trend holds — no suspect, and the fit runs (it
    raised scipy's "Residuals are not finite")."""
    t = np.array([0.4133, 1.1024, 1.5548, 1.9865, 2.2308, 2.3986, 2.6421, 2.9025, 2.9897, 3.0746, 3.1357, 3.177,
                  3.1901, 3.1993])
    level = np.array([0.0, -2.4, -4.1, -6.1, -11.4, -10.8, -8.7, -11.2, -20.1, -23.1, -25.9, -23.7, -26.7, -29.5])
    assert find_suspects(Onsets(t, level)) == ()
    assert not fit_stroke(Onsets(t, level), drop_suspects=True).suspects


@pytest.mark.parametrize("options, match", [
    ({"drop": [99]}, r"drop\[0\] must be an integer in \[0, 22\], got 99"),
    ({"merge": [22]}, r"merge\[0\] must be an integer in \[0, 21\], got 22"),
    ({"drop": 3}, "drop must be a sequence of onset indices"),
    ({"suspect_time": 0.0}, r"time_tolerance must be in \(0, 0.05\] s"),
    ({"suspect_level": -1.0}, r"level_tolerance must be in \(0, 48\] dB"),
])
def test_bad_edits(drop, options, match):
    t, level, _ = drop
    with pytest.raises(ParameterError, match=match):
        fit_stroke(Onsets(t, level), **options)


def test_cli_drop_suspects(spoiled, tmp_path):
    write_onsets(tmp_path / "drop.csv", spoiled)
    result = run("fit", tmp_path / "drop.csv", "--cor", "0.86", "--drop-suspects", "--out", tmp_path / "f.toml",
                 "--json", tmp_path / "f.json")
    assert result.returncode == 0, result.stderr
    assert "3 suspect onsets" in result.stdout and "2 dropped, 0 impacts added: within 2 ms and 1 dB" in result.stdout
    assert [d["onset"] for d in json.loads((tmp_path / "f.json").read_text())["dropped"]] == [3, 10]
    bad = run("fit", tmp_path / "drop.csv", "--suspect-ms", "0", "--out", tmp_path / "g.toml")
    assert bad.returncode == 2 and "--suspect-ms" in bad.stderr


def test_drop_rendered_through_fluidsynth(drop):
    """The drop played on FluidR3's snare (key 38) and found by drumstroke's onsets: the kept onsets fitted exactly.

    The detector's times and levels are off by a few ms and dB: what must hold is that every onset far from an
    impact is a suspect, and that the fit without the suspects plays what it keeps within 2 ms and 1 dB under
    human forces (the levels judged within 1 dB of the trend)."""
    from drumstroke.render.soundfont import render_soundfont

    t, _, _ = drop
    impacts = simulate(theta0=0.5, cor=COR, t_end=10.0).impacts
    speed = impacts.tip_speed[:len(t)]
    hits = [(float(at) + 0.25, "snare", 38, float(v)) for at, v in zip(t, speed)]
    signal = render_soundfont(hits, SOUNDFONT, duration=float(t[-1]) + 1.25)
    onsets = find_onsets(signal, 48000, source="FluidR3 drop")
    truth = t + 0.25
    far = np.abs(onsets.t[:, None] - truth[None, :]).min(axis=1) > MATCH_WINDOW
    suspects = {s.onset for s in find_suspects(onsets, level_tolerance=1.0) if s.action in ("drop", "merge")}
    assert set(np.flatnonzero(far)) <= suspects
    kept = fit_stroke(onsets, cor=COR, drop_suspects=True, suspect_level=1.0)
    assert kept.within and not kept.beyond_human
    assert kept.played.sum() >= 3
    assert not np.any(far & kept.played)


def test_levels_played_are_chosen_and_said(drop, tmp_path):
    """--levels: the peak levels played when asked for, the modes' when the onsets have no peaks (and peak refused)."""
    t, level, _ = drop
    peak = level * 0.5  # another measure of the same onsets: half the fall
    write_onsets(tmp_path / "both.csv", Onsets(t, level, peak_db=peak))
    write_onsets(tmp_path / "modes.csv", Onsets(t, level))
    result = run("fit", tmp_path / "both.csv", "--levels", "peak", "--out", tmp_path / "p.toml", "--json",
                 tmp_path / "p.json")
    assert result.returncode == 0, result.stderr
    assert "levels played: the onsets' peak (given)" in result.stdout
    data = json.loads((tmp_path / "p.json").read_text())
    assert data["levels"] == "peak" and data["onsets"]["level_db"] == pytest.approx(peak.tolist())
    result = run("fit", tmp_path / "modes.csv", "--out", tmp_path / "m.toml")
    assert "levels played: the onsets' modes (the onsets have no peak levels)" in result.stdout
    with pytest.raises(ParameterError, match="levels 'peak' needs the onsets' peak levels"):
        fit_stroke(Onsets(t, level), levels="peak")
    with pytest.raises(ParameterError, match="levels must be one of"):
        fit_stroke(Onsets(t, level), levels="loud")
