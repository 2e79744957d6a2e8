"""Notes as a drummer writes them: the sticking (R/L) with accents, grace notes and ghost notes, and the bars.

A note's mark comes from its stick and its MIDI velocity, in the notation of the rudiment sheet
(:attr:`drumstroke.palette.rudiments.Rudiment.sticking`): ``R``/``L`` the right and left stick (any other
stick by its name), ``>`` after it an accent, ``z`` a buzz, lowercase a grace note (written before its main
note, ``lR``), and, as drum charts write ghost notes, in parentheses a ghost note: ``(L)``. The levels:

=================  ==================  ============================================================
velocity           written             why
=================  ==================  ============================================================
108 and above      ``R>`` accent       halfway (3 dB) between the rudiments' normal stroke, 100 (a 6 in
                                       stick height), and their accent, 116 (12 in)
57 to 76           ``r`` grace level   between the ghosts and the rudiments' taps (84, 3 in): their
                                       grace notes (69, 1.5 in) and what is played as softly beside them
56 and below       ``(R)`` ghost       halfway between p (49) and mp (64) of notation programs' MIDI
                                       dynamics: a ghost note is played p and softer, 17 dB and more
                                       under a normal stroke
=================  ==================  ============================================================

Each threshold is a keyword of the functions here; the levels are on :mod:`drumstroke.dynamics`'
scale (0.38 dB a velocity step). Bars come from the score's tempo map and the notes' beats
(:func:`bar_times`), so a rudiment's lead-in for its grace notes comes before its first bar.

Examples
--------
>>> from drumstroke.formats.midi import TempoMap
>>> from drumstroke.score import ScoreNote
>>> notes = [ScoreNote(0.47, "auto", 69, "left", beat=None), ScoreNote(0.5, "auto", 116, "right", beat=0.0),
...          ScoreNote(0.75, "auto", 40, "left", beat=0.5), ScoreNote(1.0, "buzz", 100, "right", beat=1.0)]
>>> [mark(n.stick, n.velocity, buzz=n.stroke == "buzz") for n in notes]
['l', 'R>', '(L)', 'Rz']
>>> sticking(notes, TempoMap.constant(120, meter=(1, 4)))  # a bar a beat
'lR> (L) | Rz'
"""

from itertools import pairwise

import numpy as np

from .._checks import check_int, check_real
from ..errors import ParameterError

ACCENT_VELOCITY = 108
"""The softest velocity written as an accent, ``R>`` (see the module's table for why)."""

GRACE_VELOCITY = 76
"""The loudest velocity written lowercase, as a grace note: ``r`` (down to the ghosts)."""

GHOST_VELOCITY = 56
"""The loudest velocity written as a ghost note, in parentheses: ``(R)``."""

GRACE_WINDOW = 0.1
"""Seconds: a grace-level note this close before the next note is written joined to it (``lR``), as the rudiment
sheet writes flams and drags; the rudiments' earliest grace note comes 100 ms before its main note."""

LETTERS = {"right": "R", "left": "L"}
"""The sticking letter of each stick named so; any other stick is written by its name."""


def stick_letter(stick):
    """The letter a drummer writes for ``stick``: ``"R"`` for ``right``, ``"L"`` for ``left``, else the name itself."""
    if not isinstance(stick, str) or not stick:
        raise ParameterError(f"stick must be a stick's name (a non-empty string), got {stick!r}")
    return LETTERS.get(stick, stick)


def mark(stick, velocity, *, buzz=False, accent=ACCENT_VELOCITY, grace=GRACE_VELOCITY, ghost=GHOST_VELOCITY):
    """One note as the sticking writes it: ``"R"``, ``"R>"``, ``"Rz"``, ``"r"`` or ``"(R)"``.

    Parameters
    ----------
    stick : str
        The stick's name (``right`` and ``left`` are R and L).
    velocity : int in [1, 127]
        The note's MIDI velocity.
    buzz : bool
        Whether it is a buzz (multiple-bounce) stroke: ``z``.
    accent, grace, ghost : int in [1, 127], ghost < grace < accent
        The softest accent, the loudest grace-level note and the loudest ghost note (velocities).
    """
    velocity = check_int("velocity", velocity, low=1, high=127)
    _check_levels(accent, grace, ghost)
    letter = stick_letter(stick)
    if velocity <= ghost:
        return f"({letter}{'z' if buzz else ''})"
    if velocity <= grace:
        return letter.lower() + ("z" if buzz else "")
    return letter + (">" if velocity >= accent else "") + ("z" if buzz else "")


def bar_times(notes, tempo_map):
    """The start of every bar the notes fall in, and the end of the last, on the score's time (s) [shape=(bars + 1,)].

    The notes' beats (quarter notes, :attr:`drumstroke.score.ScoreNote.beat`) place the bars: the first note with
    a beat fixes where beat 0 falls (at time 0 for a pattern or a MIDI file, after the lead-in of a rudiment's
    grace notes), the tempo map's time signatures give each bar's length. Notes without beats: no bars (an empty
    array).
    """
    timed = [n for n in notes if n.beat is not None]
    if not timed:
        return np.empty(0)
    origin = timed[0].time - float(tempo_map.seconds(timed[0].beat))
    last = max(n.beat for n in timed)
    starts = []
    meters = [*tempo_map.meters, (np.inf, 1, 1)]
    for (beat, numerator, denominator), (following, _, _) in pairwise(meters):
        length = 4.0 * numerator / denominator  # quarter notes a bar
        while beat < following and beat <= last:
            starts.append(beat)
            beat += length
        if beat <= last:  # a new time signature starts a new bar
            continue
        starts.append(min(beat, following))  # the end of the last bar
        break
    return origin + tempo_map.seconds(np.array(starts))


def sticking(notes, tempo_map=None, *, accent=ACCENT_VELOCITY, grace=GRACE_VELOCITY, ghost=GHOST_VELOCITY,
             window=GRACE_WINDOW):
    """The notes' sticking as one line: marks (:func:`mark`) in time order, bars separated by ``" | "``.

    Parameters
    ----------
    notes : sequence of ScoreNote
        In time order.
    tempo_map : TempoMap or None
        The score's, for the bars (:func:`bar_times`); None: no bar lines.
    accent, grace, ghost : int
        The levels of :func:`mark`.
    window : float >= 0
        s: a grace-level note at most this long before the next note is joined to it (``lR``).

    Returns
    -------
    str
    """
    window = check_real("window", window, low=0.0, high=10.0, unit="s")
    words, graces = [], ""
    for note, following in zip(notes, [*notes[1:], None]):
        text = mark(note.stick, note.velocity, buzz=note.stroke == "buzz", accent=accent, grace=grace, ghost=ghost)
        if ghost < note.velocity <= grace and following is not None and following.time - note.time <= window:
            graces += text
            continue
        words.append((note.time, graces + text))
        graces = ""
    bars = bar_times(notes, tempo_map) if tempo_map is not None else np.empty(0)
    line, bar = [], None
    for time, word in words:
        at = int(np.searchsorted(bars[:-1], time + 1e-9, side="right")) if bars.size else 0
        if bar is not None and at != bar:
            line.append("|")
        line.append(word)
        bar = at
    return " ".join(line)


def _check_levels(accent, grace, ghost):
    for name, value in (("accent", accent), ("grace", grace), ("ghost", ghost)):
        check_int(name, value, low=1, high=127)
    if not ghost < grace < accent:
        raise ParameterError(f"the levels must rise: ghost < grace < accent, got ghost {ghost}, grace {grace}, "
                             f"accent {accent}")
