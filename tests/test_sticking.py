"""The sticking of notes as a drummer writes it: against the PAS sheet of the 40 rudiments, and the thresholds."""

import numpy as np
import pytest

from drumstroke.compose import rudiment_score
from drumstroke.errors import ParameterError
from drumstroke.formats.midi import TempoMap
from drumstroke.palette.rudiments import DYNAMICS, rudiments
from drumstroke.render.sticking import ACCENT_VELOCITY, GHOST_VELOCITY, GRACE_VELOCITY, bar_times, mark, sticking
from drumstroke.score import ScoreNote, parse_pattern


@pytest.mark.parametrize("chosen", rudiments(), ids=lambda r: r.name)
def test_every_rudiment_played_is_written_as_its_sheet_cycle_repeated(chosen):
    # The sheet's sticking is data written from the PAS sheet; the played notes carry only sticks, velocities,
    # times and kinds: the marks must rebuild the sheet from those alone.
    score, _ = rudiment_score(chosen.name, sum(chosen.tempo) / 2, bars=2)
    written = sticking(score.notes).replace(" ", "")
    cycle = chosen.sticking.replace(" ", "")
    assert len(written) % len(cycle) == 0 and written == cycle * (len(written) // len(cycle))


def test_the_rudiments_dynamics_fall_in_the_levels_they_are_written_at():
    assert DYNAMICS["accent"] >= ACCENT_VELOCITY > DYNAMICS["normal"]
    assert DYNAMICS["tap"] > GRACE_VELOCITY >= DYNAMICS["grace"] > GHOST_VELOCITY


@pytest.mark.parametrize(("velocity", "written"), [(127, "R>"), (108, "R>"), (107, "R"), (77, "R"), (76, "r"),
                                                    (57, "r"), (56, "(R)"), (1, "(R)")])
def test_the_thresholds_are_inclusive_where_the_docs_say(velocity, written):
    assert mark("right", velocity) == written


def test_buzzes_other_sticks_and_other_thresholds():
    assert [mark("left", 116, buzz=True), mark("left", 60, buzz=True), mark("left", 30, buzz=True)] == \
        ["L>z", "lz", "(Lz)"]
    assert mark("hihat", 100) == "hihat" and mark("hihat", 120) == "hihat>"
    assert mark("right", 90, accent=90, grace=60, ghost=30) == "R>"


@pytest.mark.parametrize(("call", "match"), [
    (lambda: mark("right", 0), r"velocity must be an integer in \[1, 127\], got 0"),
    (lambda: mark("right", 64.0), "velocity must be an integer"),
    (lambda: mark("", 64), "stick must be a stick's name"),
    (lambda: mark("right", 64, accent=50, grace=60, ghost=40), "ghost < grace < accent, got ghost 40, grace 60"),
    (lambda: sticking([], window=-1.0), "window must be"),
])
def test_bad_input_is_refused_by_name(call, match):
    with pytest.raises(ParameterError, match=match):
        call()


def test_bars_follow_time_signature_changes_and_the_notes_beats():
    # 4/4 then 3/4 from beat 4, at 120 bpm (0.5 s a beat): bars at beats 0, 4, 7 and 10 (the end of the bar of
    # the note at beat 8.5)
    tempo_map = TempoMap(tempi=((0.0, 500_000.0),), meters=((0.0, 4, 4), (4.0, 3, 4)))
    notes = [ScoreNote(b * 0.5, "auto", 100, "right", beat=b) for b in (0.0, 3.5, 4.0, 8.5)]
    np.testing.assert_allclose(bar_times(notes, tempo_map), [0.0, 2.0, 3.5, 5.0])
    assert sticking(notes, tempo_map) == "R R | R | R"
    assert bar_times([ScoreNote(0.0, "auto", 100, "right", beat=None)], tempo_map).size == 0


def test_a_pattern_is_written_bar_by_bar_with_its_ghosts():
    text = "tempo 120\n0 auto 110 right\n0.5 auto 40 left\n1 auto 100 right\n4 auto 100 left\n"
    assert sticking(parse_pattern(text), TempoMap.constant(120)) == "R> (L) R | L"
