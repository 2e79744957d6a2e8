"""Bounces paired by a maximum one-to-one matching on times: an extra onset, mir_eval's counts, bad input, real files."""

import json
import math

import mir_eval
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import drumstroke
from _cli import assert_one_line_error, run
from drumstroke.analysis import Onsets
from drumstroke.analysis.compare import FLOOR_DB, WINDOW, compare
from drumstroke.errors import ParameterError

TICK = 2.0**-12
"""Time step (s) of the random onsets: dyadic, so t − t0 and |t_b − t_a| ≤ window are exact in both codes."""


def drop(cor=0.86):
    """A free bounce's impacts at or above compare's default threshold (37 of them for c = 0.86)."""
    onsets = Onsets.from_impacts(drumstroke.simulate("free-bounce", cor=cor).impacts)
    keep = onsets.level_db >= FLOOR_DB
    return Onsets(onsets.t[keep], onsets.level_db[keep], source=f"c = {cor}")


def with_extra(onsets, position, fraction, level_db):
    """``onsets`` with one more between onset ``position`` and the next, ``fraction`` of the way."""
    t = onsets.t[position] + fraction * (onsets.t[position + 1] - onsets.t[position])
    return Onsets(np.insert(onsets.t, position + 1, t), np.insert(onsets.level_db, position + 1, level_db),
                  source="with an extra onset")


@settings(max_examples=60, deadline=None)
@given(position=st.integers(0, 35), fraction=st.floats(0.05, 0.95), level_db=st.floats(-40.0, -0.5),
       extra_in_b=st.booleans())
def test_one_extra_onset_is_unmatched_and_every_other_pair_differs_by_nothing(position, fraction, level_db,
                                                                               extra_in_b):
    """Inserted anywhere after the first impact (the Zeno tail included, where it falls within the window of both
    neighbours): index pairing would shift every pair after it; the matching pairs the rest exactly."""
    same = drop()
    extra = with_extra(same, position, fraction, level_db)
    a, b = (same, extra) if extra_in_b else (extra, same)
    result = compare(a, b)
    n = len(same)
    assert result.counts == ((n, n + 1) if extra_in_b else (n + 1, n))
    shifted = [k + (k > position) for k in range(n)]
    expected = [[k, s] for k, s in zip(range(n), shifted)] if extra_in_b else [[s, k] for k, s in zip(range(n), shifted)]
    assert result.pairs.tolist() == expected
    assert (result.unmatched_a.tolist(), result.unmatched_b.tolist()) == (([], [position + 1]) if extra_in_b
                                                                          else ([position + 1], []))
    assert np.all(result.time_difference == 0.0) and np.all(result.level_difference == 0.0)
    assert np.all(result.interval_difference == 0.0)
    summary = result.summary()
    assert summary["pairs"] == n and summary["intervals_compared"] == n - 1
    assert summary["time_difference_max_s"] == 0.0 and summary["level_difference_max_db"] == 0.0


def test_index_pairing_would_have_shifted_every_pair_after_the_extra_onset():
    """The case the matching fixes: after an extra onset, the next ten index pairs are more than the window apart."""
    same = drop()
    extra = with_extra(same, 1, 0.5, -6.0)
    index_pairs = extra.t[:len(same)] - same.t
    assert np.all(np.abs(index_pairs[2:12]) > 0.010)
    assert compare(same, extra).summary()["time_difference_max_s"] == 0.0


ticks = st.lists(st.integers(0, 4000), max_size=40, unique=True).map(sorted)


@settings(max_examples=300, deadline=None)
@given(ticks_a=ticks, ticks_b=ticks, window_ticks=st.integers(1, 120))
def test_random_onsets_pair_as_many_as_mir_eval_matches(ticks_a, ticks_b, window_ticks):
    t_a, t_b, window = np.array(ticks_a) * TICK, np.array(ticks_b) * TICK, window_ticks * TICK
    result = compare(Onsets(t_a, np.zeros(len(t_a))), Onsets(t_b, np.zeros(len(t_b))), window=window)
    ref = t_a - t_a[0] if len(t_a) else t_a
    est = t_b - t_b[0] if len(t_b) else t_b
    theirs = mir_eval.util.match_events(ref, est, window)
    assert len(result.pairs) == len(theirs)
    i, j = result.pairs.T
    # one to one, in time order, each pair within the window, and the rest unmatched
    assert np.all(np.diff(i) > 0) and np.all(np.diff(j) > 0)
    assert np.all(np.abs(est[j] - ref[i]) <= window)
    assert sorted(i.tolist() + result.unmatched_a.tolist()) == list(range(len(t_a)))
    assert sorted(j.tolist() + result.unmatched_b.tolist()) == list(range(len(t_b)))
    # among the maximum matchings, none nearer in all than ours
    assert np.sum(np.abs(est[j] - ref[i])) <= sum(abs(est[q] - ref[p]) for p, q in theirs) + 1e-12


def test_the_default_window_is_ten_ms_and_includes_its_edges():
    assert WINDOW == 0.010
    a = Onsets([0.0, 0.5], [0.0, 0.0])
    assert len(compare(a, Onsets([0.0, 0.625], [0.0, 0.0]), window=0.125).pairs) == 2
    assert len(compare(a, Onsets([0.0, 0.625 + 2**-30], [0.0, 0.0]), window=0.125).pairs) == 1


@pytest.mark.parametrize("window", [0.0, -0.01, math.nan, math.inf, 1.5, "10", True])
def test_a_bad_window_is_refused_by_name(window):
    with pytest.raises(ParameterError, match=r"^window must be"):
        compare(drop(), drop(0.8), window=window)


@pytest.mark.parametrize("value", ["0", "-5", "nan", "inf", "2000"])
def test_a_bad_window_option_is_one_line(tmp_path, value):
    drumstroke.simulate("free-bounce").recipe.to_toml(tmp_path / "a.toml")
    assert_one_line_error(run("compare", tmp_path / "a.toml", tmp_path / "a.toml", "--window", value), "--window")


def test_two_recorded_drops_one_with_an_extra_impact_from_the_command_line(tmp_path):
    """Two WAVs of drumstroke's own drum: a drop (c = 0.8, impacts down to −24 dB) and the same with one more impact
    (−8 dB) halfway between the third and the fourth. Counted above −30 dB, every onset of A pairs with B's within
    0.1 ms and 0.5 dB, and B's extra one, within 1 ms of where it was put, is the only unmatched onset."""
    from drumstroke.render.audio import render_wav

    impacts = drumstroke.simulate("free-bounce", cor=0.8, t_end=3.0).impacts
    keep = impacts.tip_speed >= impacts.tip_speed[0] * 10.0 ** (-24.0 / 20.0)
    t, speed = impacts.t[keep], impacts.tip_speed[keep]
    extra_t = 0.5 * (t[2] + t[3])
    render_wav(tmp_path / "a.wav", t, speed, duration=t[-1] + 0.5)
    render_wav(tmp_path / "b.wav", np.insert(t, 3, extra_t), np.insert(speed, 3, speed[0] * 10.0 ** (-8.0 / 20.0)),
               duration=t[-1] + 0.5)
    result = run("compare", tmp_path / "a.wav", tmp_path / "b.wav", "--threshold", "-30", "--json",
                 tmp_path / "c.json", "--plot", tmp_path / "c.png")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "c.json").read_text())
    figures = data["comparison"]
    assert figures["window_s"] == WINDOW and figures["unmatched_a"] == [] and len(figures["unmatched_b"]) == 1
    (extra,) = figures["unmatched_b"]
    assert data["b"]["t_s"][extra] == pytest.approx(extra_t - t[0], abs=1e-3)
    assert figures["pairs"] == figures["count_a"] == figures["count_b"] - 1 == len(data["pairs"])
    assert figures["time_difference_max_s"] < 1e-4 and figures["level_difference_max_db"] < 0.5
    assert f"paired within 10 ms: {figures['pairs']}; unmatched: A none, B 1 (#{extra} at " in result.stdout
    assert (tmp_path / "c.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
