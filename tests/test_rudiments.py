"""The 40 PAS rudiments: PAS's order and families, the figures that define each family, playable
at both ends of every tempo range, the text pattern, and the loader's errors.

The expectations are written from the PAS International Drum Rudiments sheet, not read from the data: the
titles in order, the stickings, and each family's figures — single strokes alternate; a multiple bounce
roll is buzzes, hand to hand, closed; an n-stroke roll is diddles and accented singles adding up to n; a
flam is one grace note on the other stick 15-50 ms early and 10-20 dB softer (docs/design.md); a drag is two on
one stick. The ends of the tempo ranges are checked against human drummers' limits.
"""

import dataclasses
import math
import re
from fractions import Fraction
from itertools import pairwise
from pathlib import Path

import pytest

from drumstroke import ParameterError
from drumstroke.dynamics import velocity_to_level
from drumstroke.formats.pattern import parse_pattern
from drumstroke.palette import rudiments as rudiments_module
from drumstroke.palette.rudiments import (
    DYNAMICS,
    RUDIMENTS_FILE,
    Note,
    Rudiment,
    read_rudiments,
    rudiment,
    rudiments,
)

ROOT = Path(__file__).resolve().parents[1]

PAS_TITLES = [
    "Single Stroke Roll", "Single Stroke Four", "Single Stroke Seven", "Multiple Bounce Roll", "Triple Stroke Roll",
    "Double Stroke Open Roll", "Five Stroke Roll", "Six Stroke Roll", "Seven Stroke Roll", "Nine Stroke Roll",
    "Ten Stroke Roll", "Eleven Stroke Roll", "Thirteen Stroke Roll", "Fifteen Stroke Roll", "Seventeen Stroke Roll",
    "Single Paradiddle", "Double Paradiddle", "Triple Paradiddle", "Single Paradiddle-Diddle",
    "Flam", "Flam Accent", "Flam Tap", "Flamacue", "Flam Paradiddle", "Single Flammed Mill", "Flam Paradiddle-Diddle",
    "Pataflafla", "Swiss Army Triplet", "Inverted Flam Tap", "Flam Drag",
    "Drag", "Single Drag Tap", "Double Drag Tap", "Lesson 25", "Single Dragadiddle", "Drag Paradiddle #1",
    "Drag Paradiddle #2", "Single Ratamacue", "Double Ratamacue", "Triple Ratamacue",
]

# One cycle as PAS writes it (right hand lead): R/L main notes, > accent, z buzz, l/r grace notes before their note.
STICKINGS = {
    1: "R L R L",
    2: "R L R L L R L R",
    3: "R L R L R L R L R L R L R L",
    4: "Rz Lz Rz Lz",
    5: "R R R L L L",
    6: "R R L L",
    7: "R R L L R> L L R R L>",
    8: "R> L L R R L>",
    9: "R R L L R R L> L L R R L L R>",
    10: "R R L L R R L L R> L L R R L L R R L>",
    11: "R R L L R R L L R> L>",
    12: "R R L L R R L L R R L> L L R R L L R R L L R>",
    13: "R R L L R R L L R R L L R> L L R R L L R R L L R R L>",
    14: "R R L L R R L L R R L L R R L> L L R R L L R R L L R R L L R>",
    15: "R R L L R R L L R R L L R R L L R> L L R R L L R R L L R R L L R R L>",
    16: "R> L R R L> R L L",
    17: "R> L R L R R L> R L R L L",
    18: "R> L R L R L R R L> R L R L R L L",
    19: "R> L R R L L",
    20: "lR rL",
    21: "lR> L R rL> R L",
    22: "lR> R rL> L",
    23: "lR L> R L lR",
    24: "lR> L R R rL> R L L",
    25: "lR> R L R rL> L R L",
    26: "lR> L R R L L rL> R L L R R",
    27: "lR> L R rL>",
    28: "lR> R L",
    29: "lR> L rL> R",
    30: "lR> L L R rL> R R L",
    31: "llR rrL",
    32: "llR L> rrL R>",
    33: "llR llR L> rrL rrL R>",
    34: "llR L R>",
    35: "R> R> L R R L> L> R L L",
    36: "R> llR L R R L> rrL R L L",
    37: "R> llR llR L R R L> rrL rrL R L L",
    38: "llR L R L> rrL R L R>",
    39: "llR llR L R L> rrL rrL R L R>",
    40: "llR llR llR L R L> rrL rrL rrL R L R>",
}

ALL = rudiments()
ENDS = [pytest.param(r, end, id=f"{r.name}-{end}") for r in ALL for end in ("bottom", "top")]


def mains(r):
    return [n for n in r.notes if n.kind != "grace"]


def graces_of(r, main):
    return [n for n in r.notes if n.kind == "grace" and n.beat == main.beat and n.stick != main.stick]


def level(dynamic):
    return velocity_to_level(DYNAMICS[dynamic])


def main_times(r, tempo, cycles=2):
    """(time s, stick) of the main notes (grace notes aside) over a few cycles, in time order."""
    notes = [(float(k * r.cycle + n.beat) * 60.0 / tempo, n.stick) for k in range(cycles) for n in mains(r)]
    return sorted(notes)


# --- PAS's list -------------------------------------------------------------------------------------------------

def test_the_forty_in_pas_order_with_pas_titles_and_unique_names():
    assert [r.number for r in ALL] == list(range(1, 41))
    assert [r.title for r in ALL] == PAS_TITLES
    assert len({r.name for r in ALL}) == 40
    assert all(re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", r.name) for r in ALL)


def test_the_families_are_pas_sections():
    expected = ["roll"] * 15 + ["diddle"] * 4 + ["flam"] * 11 + ["drag"] * 10
    assert [r.family for r in ALL] == expected


@pytest.mark.parametrize("r", ALL, ids=lambda r: r.name)
def test_the_sticking_is_pas(r):
    assert r.sticking == STICKINGS[r.number]


def test_the_data_ships_with_the_package():
    assert RUDIMENTS_FILE.parent == Path(rudiments_module.__file__).parent
    assert read_rudiments() == ALL


# --- each family's figures --------------------------------------------------------------------------------------

@pytest.mark.parametrize("number, group", [(1, None), (2, 4), (3, 7)])
def test_single_stroke_rudiments_alternate_hand_to_hand(number, group):
    """Notes closer than half a beat are on different sticks; a single stroke four or seven is 4 or 7 of them."""
    notes = list(mains(rudiment(number)))
    cycle = rudiment(number).cycle
    pairs = zip(notes, notes[1:] + [notes[0]._replace(beat=notes[0].beat + cycle)])
    groups, size = [], 1
    for a, b in pairs:
        if b.beat - a.beat < Fraction(1, 2):
            assert a.stick != b.stick, (a, b)
            size += 1
        else:
            groups.append(size)
            size = 1
    if group is None:
        assert groups == [] and len(notes) % 2 == 0
    else:
        assert groups == [group, group]


def test_the_multiple_bounce_roll_is_a_closed_roll_of_buzzes_hand_to_hand():
    r = rudiment("multiple-bounce-roll")
    assert all(n.kind == "buzz" for n in r.notes)
    assert [n.stick for n in r.notes] == ["R", "L"] * (len(r.notes) // 2)
    ends = [n.beat + n.value for n in r.notes]
    starts = [n.beat for n in r.notes[1:]] + [r.cycle]
    assert ends == starts  # each buzz lasts until the other hand's: no gap, no overlap


def test_a_buzz_at_the_top_tempo_holds_three_bounces_at_the_human_40_per_second():
    r = rudiment("multiple-bounce-roll")
    shortest = min(n.duration for n in r.notes_at(r.tempo[1]).notes)
    assert shortest >= 3 / 40.0


def test_the_triple_stroke_roll_is_three_even_strokes_a_hand():
    r = rudiment("triple-stroke-roll")
    assert "".join(n.stick for n in r.notes) == "RRRLLL"
    gaps = {b.beat - a.beat for a, b in pairwise(r.notes)} | {r.cycle - r.notes[-1].beat}
    assert len(gaps) == 1


def diddles(notes, spacing):
    """Pairs of consecutive notes on one stick ``spacing`` beats apart (each note in at most one pair)."""
    pairs, i = [], 0
    while i < len(notes) - 1:
        a, b = notes[i], notes[i + 1]
        if a.stick == b.stick and b.beat - a.beat == spacing:
            pairs.append((a, b))
            i += 2
        else:
            i += 1
    return pairs


def test_the_double_stroke_open_roll_is_all_diddles():
    r = rudiment("double-stroke-open-roll")
    assert len(diddles(list(r.notes), Fraction(1, 4))) * 2 == len(r.notes)


@pytest.mark.parametrize("number, strokes", [(7, 5), (8, 6), (9, 7), (10, 9), (11, 10), (12, 11), (13, 13), (14, 15),
                                             (15, 17)])
def test_an_n_stroke_roll_is_diddles_and_accented_singles_adding_up_to_n(number, strokes):
    """Odd rolls: (n-1)/2 diddles and one accented release; the six and ten: two accented singles."""
    r = rudiment(number)
    notes = list(r.notes)
    assert len(notes) % strokes == 0
    groups = len(notes) // strokes
    singles = 2 if strokes in (6, 10) else 1
    pairs = diddles(notes, Fraction(1, 8))
    assert len(pairs) == groups * (strokes - singles) // 2
    in_pairs = {id(n) for pair in pairs for n in pair}
    assert all(n.dynamic == "tap" for n in notes if id(n) in in_pairs)
    assert [n.dynamic for n in notes if id(n) not in in_pairs] == ["accent"] * groups * singles


@pytest.mark.parametrize("number, sticking, accents", [
    (16, "RLRRLRLL", [0, 4]), (17, "RLRLRRLRLRLL", [0, 6]), (18, "RLRLRLRRLRLRLRLL", [0, 8]), (19, "RLRRLL", [0]),
])
def test_diddle_rudiments_are_pas_sticking_with_a_diddle_at_the_subdivision(number, sticking, accents):
    r = rudiment(number)
    assert "".join(n.stick for n in r.notes) == sticking
    assert [i for i, n in enumerate(r.notes) if n.dynamic == "accent"] == accents
    subdivision = min(b.beat - a.beat for a, b in pairwise(r.notes))
    assert diddles(list(r.notes), subdivision)


@pytest.mark.parametrize("r", [r for r in ALL if r.family == "flam"], ids=lambda r: r.name)
def test_every_flam_is_one_grace_note_on_the_other_stick_15_to_50_ms_early_and_10_to_20_db_softer(r):
    flammed = [m for m in mains(r) if graces_of(r, m)]
    assert flammed
    for main in flammed:
        (grace,) = graces_of(r, main)
        assert -50.0 <= grace.value <= -15.0
        assert 10.0 <= level(main.dynamic) - level(grace.dynamic) <= 20.0
    assert all(any(n.kind == "note" and n.beat == g.beat for n in flammed) for g in r.notes if g.kind == "grace")


@pytest.mark.parametrize("r", [r for r in ALL if r.family == "drag" and r.number != 35], ids=lambda r: r.name)
def test_every_drag_is_two_grace_notes_on_one_stick_before_its_note_on_the_other(r):
    dragged = [m for m in mains(r) if graces_of(r, m)]
    assert dragged
    for main in dragged:
        first, second = graces_of(r, main)
        assert first.stick == second.stick != main.stick
        assert first.value < second.value < 0.0
        assert second.value - first.value <= 50.0  # closed: a double bounce, not two strokes
        assert level(main.dynamic) - level("grace") >= 10.0
    assert sum(n.kind == "grace" for n in r.notes) == 2 * len(dragged)


def test_the_single_dragadiddle_drags_with_the_lead_hand_a_diddle_before_the_paradiddle():
    """PAS writes its drag measured, the lead hand's thirty-second-note diddle: RR L RR, LL R LL."""
    r = rudiment("single-dragadiddle")
    assert "".join(n.stick for n in r.notes) == "RRLRRLLRLL"
    first, second = r.notes[0], r.notes[1]
    assert first.stick == second.stick and second.beat - first.beat == Fraction(1, 8)
    assert first.dynamic == second.dynamic == "accent"


def test_no_roll_or_diddle_rudiment_has_grace_notes():
    assert all(n.kind != "grace" for r in ALL if r.family in ("roll", "diddle") for n in r.notes)


# --- played at both ends of the range ---------------------------------------------------------------------------

@pytest.mark.parametrize("r, end", ENDS)
def test_every_rudiment_plays_at_both_ends_of_its_range(r, end):
    tempo = r.tempo[0] if end == "bottom" else r.tempo[1]
    played = r.notes_at(tempo)
    assert played.in_range and played.warning is None
    notes = played.notes
    span = r.cycle * math.ceil(4 / r.cycle) * 2
    assert len(notes) == len(r.notes) * (span / r.cycle)
    beat = 60.0 / tempo
    assert played.downbeat in (0.0, beat) and 0.0 <= notes[0].time < beat  # a lead-in of one beat, if any
    assert [n.time for n in notes] == sorted(n.time for n in notes)
    assert all(isinstance(n.velocity, int) and 1 <= n.velocity <= 127 for n in notes)
    for stick in ("right", "left"):
        mine = [n for n in notes if n.stick == stick]
        for a, b in pairwise(mine):
            assert b.time - a.time >= 0.015, (stick, a, b)  # after the stick's previous note, grace notes included
            assert a.time + a.duration <= b.time + 1e-12  # a buzz ends before the stick plays again


@pytest.mark.parametrize("r", ALL, ids=lambda r: r.name)
def test_the_top_of_each_range_is_human(r):
    """Human: a stick's two notes no closer than a fast diddle (60 ms); both sticks together at most ~20 notes/s."""
    notes = main_times(r, r.tempo[1])
    for stick in ("R", "L"):
        times = [t for t, s in notes if s == stick]
        assert min(b - a for a, b in pairwise(times)) >= 0.060 - 1e-12, stick
    assert min(b[0] - a[0] for a, b in pairwise(notes)) >= 0.050 - 1e-12


@pytest.mark.parametrize("r", [r for r in ALL if any(n.kind == "grace" for n in r.notes)], ids=lambda r: r.name)
def test_nothing_comes_between_a_grace_note_and_its_main_note_at_the_top_tempo(r):
    tempo = r.tempo[1]
    played = r.notes_at(tempo)
    times = [n.time for n in played.notes]
    for main in mains(r):
        for grace in graces_of(r, main):
            t_main = played.downbeat + float(main.beat) * 60.0 / tempo
            t_grace = t_main + grace.value / 1000.0
            between = [t for t in times if t_grace + 1e-9 < t < t_main - 1e-9]
            assert len(between) <= 1  # only a drag's other grace note


def test_grace_notes_before_the_first_note_get_a_lead_in_of_a_beat():
    flam = rudiment("flam").notes_at(100)
    assert flam.downbeat == pytest.approx(0.6)
    assert [round(n.time, 6) for n in flam.notes[:2]] == [0.57, 0.6]
    assert rudiment("single-paradiddle").notes_at(100).downbeat == 0.0


def test_bars_default_to_whole_cycles_of_at_least_four_beats_and_a_cut_bar_drops_whole_notes():
    six = rudiment("six-stroke-roll")  # a cycle of 3/2 beats: three of them make a bar of 4.5 beats
    assert len(six.notes_at(100, bars=1).notes) == 3 * len(six.notes)
    flam = rudiment("flam")  # two flams in two beats
    assert len(flam.notes_at(100, bars=1, beats_per_bar=1).notes) == 2  # the first flam, with its grace note
    assert len(flam.notes_at(100, bars=3, beats_per_bar=1).notes) == 6


def test_a_tempo_outside_the_range_plays_and_says_so():
    r = rudiment("flam-tap")
    fast, slow = r.notes_at(300), r.notes_at(30)
    assert not fast.in_range and "above" in fast.warning and "60-150 bpm" in fast.warning
    assert not slow.in_range and "below" in slow.warning
    assert len(fast.notes) == len(r.notes_at(120).notes)


@pytest.mark.parametrize("kwargs, match", [
    ({"tempo": 0}, r"tempo must be in \[1, 400\]"),
    ({"tempo": 401}, r"tempo must be in \[1, 400\]"),
    ({"tempo": float("nan")}, "tempo must be a finite number"),
    ({"tempo": float("inf")}, "tempo must be a finite number"),
    ({"tempo": "fast"}, "tempo must be a number"),
    ({"tempo": 100, "bars": 0}, r"bars must be an integer in \[1, "),
    ({"tempo": 100, "bars": 1.5}, "bars must be an integer"),
    ({"tempo": 100, "beats_per_bar": 0}, r"beats_per_bar must be in \(0, "),
])
def test_bad_playing_input_is_refused(kwargs, match):
    r = rudiment("flam-tap")
    with pytest.raises(ParameterError, match=match):
        r.notes_at(**kwargs)
    with pytest.raises(ParameterError, match=match):
        r.pattern_text(**kwargs)


def test_a_rudiment_is_found_by_name_title_or_number():
    assert rudiment("double-stroke-open-roll") is rudiment(6) is rudiment("6") is rudiment("Double Stroke Open Roll")
    assert rudiment("Drag Paradiddle #1").number == 36
    allowed = r"rudiment must be a name, title or number in \[1, 40\] of the rudiments rudiments\(\) lists, got "
    with pytest.raises(ParameterError, match=allowed + r"'flam tapp' \(did you mean 'flam-tap'\?\)$"):
        rudiment("flam tapp")
    with pytest.raises(ParameterError, match=allowed + r"'zzz'$"):
        rudiment("zzz")
    for number in (0, 41, "41"):
        with pytest.raises(ParameterError, match=allowed + repr(number)) as raised:
            rudiment(number)
        assert (raised.value.parameter, raised.value.value) == ("rudiment", number)
    with pytest.raises(ParameterError, match=allowed + "None"):
        rudiment(None)


@pytest.mark.parametrize("name, suggested", [
    ("paradiddle", ["single-paradiddle", "double-paradiddle", "triple-paradiddle"]),  # contained: in PAS order
    ("Ratamacue", ["single-ratamacue", "double-ratamacue", "triple-ratamacue"]),
    ("swiss", ["swiss-army-triplet"]),
    ("flam tapp", ["flam-tap"]),  # a misspelling: the closest by difflib's ratio, the first of equals
    ("drag paradidle", ["drag-paradiddle-1"]),
])
def test_a_wrong_name_suggests_the_names_most_like_it_first(name, suggested):
    with pytest.raises(ParameterError) as raised:
        rudiment(name)
    quoted = [repr(n) for n in suggested]
    listed = quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + " or " + quoted[-1]
    assert str(raised.value).endswith(f"(did you mean {listed}?)"), raised.value
    numbers = [rudiment(n).number for n in suggested]
    assert numbers == sorted(numbers)


# --- the text pattern -------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["flam-accent", "double-ratamacue", "five-stroke-roll", "single-stroke-seven"])
def test_the_pattern_gives_the_same_notes_and_reads_with_the_pattern_parser(name):
    r = rudiment(name)
    tempo = r.tempo[1]
    text = r.pattern_text(tempo)
    pattern = parse_pattern(text)
    parsed_tempo, rows = pattern.tempo, pattern.rows
    played = r.notes_at(tempo).notes
    assert parsed_tempo == tempo and len(rows) == len(played)
    for row, note in zip(rows, played):
        assert row.stroke == "auto" and row.stick == note.stick and row.velocity == note.velocity
        assert row.beat * 60.0 / tempo == pytest.approx(note.time, abs=1e-9)


def test_a_buzz_line_carries_its_length_in_beats():
    r = rudiment("multiple-bounce-roll")
    lines = [line.split() for line in r.pattern_text(120, bars=1).splitlines() if not line.startswith(("#", "tempo"))]
    played = r.notes_at(120, bars=1).notes
    assert len(lines) == len(played) == 16
    for fields, note in zip(lines, played):
        assert fields[1] == "buzz" and fields[3] == note.stick and int(fields[2]) == note.velocity
        assert float(fields[4]) * 0.5 == pytest.approx(note.duration)


def test_the_pattern_notes_an_out_of_range_tempo_in_a_comment():
    text = rudiment("flam").pattern_text(250, bars=1)
    assert "# 60-200 bpm is this rudiment's range" in text
    assert "\ntempo 250\n" in text


# --- dynamics ---------------------------------------------------------------------------------------------------

def test_the_dynamics_are_a_drummers():
    """Accent over tap by 10-15 dB; a grace note 10-20 dB under the notes flams decorate (human figures)."""
    assert DYNAMICS["accent"] > DYNAMICS["normal"] > DYNAMICS["tap"] > DYNAMICS["grace"] >= 1
    assert 10.0 <= level("accent") - level("tap") <= 15.0
    for main in ("accent", "normal"):
        assert 10.0 <= level(main) - level("grace") <= 20.0


# --- the dataclass and the loader -------------------------------------------------------------------------------

def test_a_rudiment_is_frozen_with_a_short_repr():
    r = rudiment("flam-tap")
    assert repr(r) == "Rudiment(22, 'flam-tap', flam, 60-150 bpm, 6 notes in 1 beat)"
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.cycle = 2


def test_a_rudiment_normalises_its_beats_to_exact_fractions_and_sorts_its_notes():
    r = Rudiment(1, "test", "Test", "flam", [60, 120], "3/2",
                 [Note(0.1, "R", "normal"), Note("1/3", "L", "tap"), Note(0.1, "L", "grace", "grace", -20)])
    assert r.cycle == Fraction(3, 2)
    assert [n.beat for n in r.notes] == [Fraction(1, 10), Fraction(1, 10), Fraction(1, 3)]
    assert r.notes[0].kind == "grace" and r.tempo == (60.0, 120.0)


def rudiment_table(**changes):
    """A rudiments file of one rudiment, its keys' TOML values changed (None leaves a key out)."""
    table = {"number": 1, "name": '"test"', "title": '"Test"', "family": '"flam"', "tempo": "[60, 120]", "cycle": "1",
             "notes": '[[0, "L", "grace", "grace", -30], [0, "R", "accent"], [0.5, "L", "tap"]]'}
    table.update(changes)
    return "[[rudiment]]\n" + "".join(f"{key} = {value}\n" for key, value in table.items() if value is not None)


@pytest.mark.parametrize("changes, match", [
    ({"notes": '[[0, "R", "loud"]]'}, r"rudiment 1 \(test\): notes\[0\]: dynamic must be one of 'accent'"),
    ({"notes": '[[0, "X", "tap"]]'}, r"notes\[0\]: stick must be one of 'R', 'L', got 'X'"),
    ({"notes": '[["1/0", "R", "tap"]]'}, r"notes\[0\]: beat must be a finite number or a fraction"),
    ({"notes": '[[1, "R", "tap"]]'}, r"notes\[0\]: beat must be in \[0, cycle\) = \[0, 1\) beats, got 1"),
    ({"notes": '[[0, "R", "tap", "grace", -30]]'}, r"a grace note's dynamic must be 'grace'"),
    ({"notes": '[[0, "L", "grace", "grace", -30]]'}, r"needs a main note on R at the same beat"),
    ({"notes": '[[0, "L", "grace", "grace", -5], [0, "R", "tap"]]'}, r"grace offset must be in \[-100, -15\] ms"),
    ({"notes": '[[0, "R", "grace"]]'}, r"dynamic 'grace' is for grace notes"),
    ({"notes": '[[0, "R", "tap", "roll", 1]]'}, r"kind must be one of 'note', 'grace', 'buzz'"),
    ({"notes": '[[0, "R", "tap"], [0, "R", "accent"]]'}, r"a second note on stick R at beat 0"),
    ({"notes": '[[0, "R", "tap", "buzz", 0.75], [0.5, "R", "tap"]]'}, r"runs into the stick's next note at beat 1/2"),
    ({"notes": '[[0, "R", "tap", "buzz", 0]]'}, r"buzz length must be in \(0, cycle\]"),
    ({"notes": '[[0, "R"]]'}, r"notes\[0\] must be \[beat, stick, dynamic\]"),
    ({"notes": "[]"}, "notes must be a non-empty list"),
    ({"family": '"rolls"'}, r"family must be one of 'roll', 'diddle', 'flam', 'drag', got 'rolls'"),
    ({"tempo": "[120, 60]"}, r"tempo top must be in \(120, 400\]"),
    ({"tempo": "[0, 60]"}, r"tempo bottom must be in \[1, 400\]"),
    ({"tempo": "[60]"}, r"tempo must be \[bottom, top\]"),
    ({"cycle": "0"}, r"cycle must be > 0 beats"),
    ({"name": '"Flam Tap"'}, r"rudiment 1: name must be kebab-case"),
    ({"title": '""'}, r"title must be one line of text"),
    ({"number": "0"}, r"rudiment number must be an integer in \[1, 999\]"),
    ({"cycle": None}, r"rudiment 1 \(test\) needs the key 'cycle'"),
    ({"speed": "3"}, r"rudiment\[0\] has unknown key 'speed'"),
])
def test_the_loader_names_the_rudiment_and_the_field_at_fault(tmp_path, changes, match):
    path = tmp_path / "rudiments.toml"
    path.write_text(rudiment_table(**changes))
    with pytest.raises(ParameterError, match=match):
        read_rudiments(path)


def test_the_loader_reads_a_valid_file_and_refuses_repeated_names_and_numbers_out_of_order(tmp_path):
    path = tmp_path / "rudiments.toml"
    path.write_text(rudiment_table())
    (r,) = read_rudiments(path)
    assert r.sticking == "lR> L" and r.notes[0].value == -30.0
    path.write_text(rudiment_table() + rudiment_table(number=2))
    with pytest.raises(ParameterError, match="rudiment 2: name 'test' appears twice"):
        read_rudiments(path)
    path.write_text(rudiment_table(number=2) + rudiment_table(number=1, name='"other"'))
    with pytest.raises(ParameterError, match="numbers must increase through the file"):
        read_rudiments(path)
    path.write_text("[[rudiment]\n")
    with pytest.raises(ParameterError, match="is not valid TOML"):
        read_rudiments(path)
    path.write_text("title = 'x'\n")
    with pytest.raises(ParameterError, match="has unknown key 'title'"):
        read_rudiments(path)


# --- the docs page ----------------------------------------------------------------------------------------------

def test_the_docs_table_is_the_data():
    text = (ROOT / "docs" / "rudiments.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| (\d+) \| `([a-z0-9-]+)` \| (\w+) \| `([^`]+)` \| (\d+)–(\d+) \|", text, re.MULTILINE)
    assert [(int(n), name, family, sticking, float(low), float(high)) for n, name, family, sticking, low, high in rows] \
        == [(r.number, r.name, r.family, r.sticking, *r.tempo) for r in ALL]
