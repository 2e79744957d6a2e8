"""Which limb plays each note of a part that names none: the assignment a drummer makes, as an optimisation.

A MIDI part says which piece each note is on, not which hand plays it. :func:`assign_limbs` chooses,
for all the notes at once, the limb of each: the feet play their pedals (the kick the foot the kit
names, the hi-hat's pedal the other), and for the hands a dynamic programme over the notes grouped
by time (notes within ``simultaneous`` s are one group) finds the assignment of least total cost. Its
state is where each hand is (the piece it last played) and when each last played; the costs are

- travel: the time (s) the hand's positioning joints take to move to the next piece, rest to rest,
  time-optimal within their limits (:func:`move_time`), times ``Costs.travel``; a move that does
  not fit in the time since the hand's last note is impossible;
- repeat: a hand playing again sooner than ``Costs.comfort`` s after its last note (so fast
  passages alternate the hands);
- lead: a time-keeping piece (the hi-hat, the ride) played by the hand that does not keep time —
  the lead hand, or, open-handed, the hand on the piece's side;
- backbeat: the snare played by the time-keeping hand, on beats 2 and 4 (when the notes' beats
  are known) or whenever that hand is on a time-keeping piece;
- cross: the hands crossed (the right hand left of the left), unless the lead hand is on a cymbal
  (the usual crossed-arms hi-hat, a crash across) and the drummer does not play open-handed;
- other: a small cost for the other hand playing at all, so that of two equal choices the lead
  plays.

Crashes and other accents get no cost of their own: the hand that is free (near, rested, not keeping
time) is the cheapest. A note no hand can play — a third hand note at one time, a move faster than
the joints allow — is dropped at a cost far above every other, so the fewest notes are dropped, and
is returned with the reason. A limb ``given`` for a note is never changed.

The programme is exact: a hand's last note time matters only while it is recent (within the longest
move between two pieces and ``comfort``); older, it is "rested" and merged. A 3-minute part of 3000
notes is assigned in a fraction of a second.

Examples
--------
>>> from drumstroke.kit.pieces import default_kit
>>> kit = default_kit()
>>> beat = 0.6  # 100 bpm
>>> notes = [KitNote(0.0, "hihat"), KitNote(0.0, "kick"), KitNote(0.3, "hihat"),
...          KitNote(0.6, "hihat"), KitNote(0.6, "snare", beat=1.0), KitNote(0.9, "hihat")]
>>> assign_limbs(notes, kit).limbs
('right', 'right-foot', 'right', 'right', 'left', 'right')
"""

import math
from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np

from .._checks import check_choice, check_real, shown
from ..errors import ParameterError
from .pieces import FEET, HANDS, YAW, Kit, Piece

SIMULTANEOUS = 0.001
"""Default: notes closer than this (s) are played at one time."""


class KitNote(NamedTuple):
    """A note of a kit part: when, on which piece, and (the hi-hat) how.

    Attributes
    ----------
    time : float
        s from the part's start.
    piece : str
        The piece's name in the kit.
    state : str or None
        The hi-hat's: "closed", "open" (a hand) or "pedal" (a foot); None on other pieces.
    beat : float or None
        Quarter notes from the start (a whole odd number is beat 2 or 4 of a 4/4 bar: the backbeat);
        None when not known.
    """

    time: float
    piece: str
    state: str | None = None
    beat: float | None = None


@dataclass(frozen=True)
class Costs:
    """The weights of the limb assignment's costs (see :mod:`drumstroke.kit.limbs`).

    Parameters
    ----------
    travel : float ≥ 0
        Per second of a hand's positioning move.
    repeat : float ≥ 0
        For a hand's note right after its last; falls linearly to 0 at ``comfort`` s.
    comfort : float in (0, 10]
        s: the shortest gap a hand plays notes at without strain (0.2 s: a single stroke per hand
        of 16th notes at 150 bpm alternating).
    lead : float ≥ 0
        For a time-keeping piece played by the hand that does not keep time.
    backbeat : float ≥ 0
        For the backbeat played by the time-keeping hand.
    cross : float ≥ 0
        Per group of notes played with the hands crossed (unless allowed).
    other : float ≥ 0
        Per note of the hand that does not lead.
    overhead : float in [0, 1]
        s of a hand's time between two notes on different pieces that its positioning move cannot use: the
        stick's rise from the first piece's surface and the throw onto the second (a move between pieces is
        planned from the rise after the first note's impact to the second note's throw).
    drop : float > 0
        Per note left unplayed; far above every other cost, so the fewest are. A given note its hand
        cannot reach in time costs more than dropping every other note: it is played all the same.
    """

    travel: float = 5.0
    repeat: float = 4.0
    comfort: float = 0.2
    lead: float = 3.0
    backbeat: float = 3.0
    cross: float = 3.0
    other: float = 0.05
    overhead: float = 0.07
    drop: float = 1.0e6

    def __post_init__(self):
        for f in fields(self):
            if f.name == "comfort":
                value = check_real("costs.comfort", self.comfort, low=0.0, high=10.0, low_open=True, unit="s")
            elif f.name == "overhead":
                value = check_real("costs.overhead", self.overhead, low=0.0, high=1.0, unit="s")
            else:
                value = check_real(f"costs.{f.name}", getattr(self, f.name), low=0.0, high=1e12,
                                   low_open=f.name == "drop")
            object.__setattr__(self, f.name, value)


@dataclass(frozen=True)
class Assignment:
    """The limb of each note, in the notes' order.

    Attributes
    ----------
    limbs : tuple of str or None
        Each note's limb; None for a note no limb can play.
    reasons : tuple of str or None
        Why a note is not played (its limb None) or why a given limb cannot play it as asked (its limb
        kept); None for a note played as assigned.
    cost : float
        The total cost of the hands' assignment (its unit is the weights', :class:`Costs`).
    """

    limbs: tuple
    reasons: tuple
    cost: float

    @property
    def problems(self):
        """The notes with a reason, as (index, reason) pairs."""
        return tuple((i, reason) for i, reason in enumerate(self.reasons) if reason is not None)


def rest_to_rest_time(distance, limits):
    """The shortest time (s) a joint takes to move ``distance`` rad from rest to rest within ``limits``.

    The time-optimal jerk-limited move: the jerk at ±max_jerk while the acceleration builds and falls,
    the acceleration held at max_acceleration, the speed at max_speed, each phase only as long as the
    distance allows (closed form, the same as ruckig's time-optimal move between two rests).

    Parameters
    ----------
    distance : float ≥ 0
        rad (its sign does not matter).
    limits : Limits
        The joint's max_speed (rad/s), max_acceleration (rad/s²), max_jerk (rad/s³).

    Examples
    --------
    >>> from drumstroke.palette.motion import Limits
    >>> round(rest_to_rest_time(1.0, Limits(max_speed=2.0, max_acceleration=1e9, max_jerk=1e15)), 6)
    0.5
    """
    d = abs(float(distance))
    v, a, j = limits.max_speed, limits.max_acceleration, limits.max_jerk

    def ramp(speed):  # time to reach ``speed`` from rest (and the distance covered is speed * ramp / 2)
        return speed / a + a / j if speed >= a * a / j else 2.0 * math.sqrt(speed / j)

    if d >= v * ramp(v):  # the speed limit is reached: cruise between the two ramps
        return d / v + ramp(v)
    if v >= a * a / j and d >= 2.0 * a**3 / j**2:  # the acceleration limit is reached, not the speed's
        peak = 0.5 * a * (math.sqrt((a / j) ** 2 + 4.0 * d / a) - a / j)
        return 2.0 * (peak / a + a / j)
    peak = (0.5 * d * math.sqrt(j)) ** (2.0 / 3.0)  # jerk alone
    return 4.0 * math.sqrt(peak / j)


def move_time(kit, hand, start, end):
    """The time (s) ``hand``'s positioning joints take to move from piece ``start`` to piece ``end`` (names or
    pieces), rest to rest: the slowest joint's time (the others can move slower, in step with it)."""
    check_choice("hand", hand, kit.hands)
    a, b = (p if isinstance(p, Piece) else kit.piece(p) for p in (start, end))
    return max(rest_to_rest_time(b.place[joint] - a.place[joint], limits)
               for joint, limits in kit.limbs[hand].items())


def kit_notes(times, keys, kit, *, beats=None):
    """The notes of a part given as MIDI keys, on ``kit``'s pieces, and the indices of the keys it does not answer.

    Parameters
    ----------
    times : array_like [shape=(n,)]
        s.
    keys : sequence of int [n]
        General MIDI percussion keys.
    kit : Kit
    beats : array_like [shape=(n,)], optional
        Quarter notes from the start.

    Returns
    -------
    (list of KitNote, list of int)
        The notes of the answered keys in order, and the indices of the others (for the caller to report).
    """
    times = np.asarray(times, dtype=float)
    if len(keys) != len(times) or (beats is not None and len(beats) != len(times)):
        raise ParameterError(f"keys and beats must have one entry per time ({len(times)}), got {len(keys)} keys"
                             + ("" if beats is None else f" and {len(beats)} beats"))
    notes, unanswered = [], []
    for i, (t, key) in enumerate(zip(times, keys)):
        found = kit.piece_for_key(key)
        if found is None:
            unanswered.append(i)
            continue
        piece, state = found
        notes.append(KitNote(float(t), piece.name, state, None if beats is None else float(beats[i])))
    return notes, unanswered


def assign_limbs(notes, kit, *, lead="right", open_handed=False, given=None, costs=None, simultaneous=SIMULTANEOUS):
    """The limb of each note, as a drummer assigns them (the optimisation of :mod:`drumstroke.kit.limbs`).

    Parameters
    ----------
    notes : sequence of KitNote
        Any order; each on a piece of ``kit``.
    kit : Kit
    lead : {"right", "left"}
        The hand that keeps time (on the hi-hat, the ride) and plays when the choice is otherwise free.
    open_handed : bool
        Whether each time-keeping piece is played by the hand on its side (the hi-hat, on the left,
        by the left hand) with the hands never crossed, instead of by the lead hand, crossing over.
    given : sequence of str or None [len(notes)], optional
        A limb for a note, kept whatever it costs (None where the part names none).
    costs : Costs, optional
        The weights; default ``Costs()``.
    simultaneous : float in [0, 0.1]
        s: notes closer than this are one group, played at one time.

    Returns
    -------
    Assignment
    """
    if not isinstance(kit, Kit):
        raise ParameterError(f"kit must be a drumstroke.kit.pieces.Kit, got {shown(kit)}")
    check_choice("lead", lead, HANDS)
    if not isinstance(open_handed, bool):
        raise ParameterError(f"open_handed must be True or False, got {shown(open_handed)}")
    costs = Costs() if costs is None else costs
    if not isinstance(costs, Costs):
        raise ParameterError(f"costs must be a drumstroke.kit.limbs.Costs, got {shown(costs)}")
    simultaneous = check_real("simultaneous", simultaneous, low=0.0, high=0.1, unit="s")
    part = _Part.of(notes, kit, given)
    limbs = list(part.given)
    reasons = [None] * len(part.notes)
    groups = _groups(part.times, simultaneous)
    _assign_feet(part, groups, limbs, reasons, costs.comfort)
    total = _Hands(part, kit, lead, open_handed, costs).assign(groups, limbs, reasons)
    return Assignment(tuple(limbs), tuple(reasons), total)


@dataclass(frozen=True)
class _Part:
    """The notes checked and indexed: their times, pieces (as indices into the kit), limbs they may take."""

    notes: tuple
    times: np.ndarray
    pieces: tuple
    choices: tuple
    given: tuple
    on_backbeat: tuple

    @classmethod
    def of(cls, notes, kit, given):
        if isinstance(notes, (str, bytes)) or not hasattr(notes, "__len__"):
            raise ParameterError(f"notes must be a sequence of KitNote, got {shown(notes)}")
        notes = tuple(KitNote(*note) if not isinstance(note, KitNote) else note for note in notes)
        given = (None,) * len(notes) if given is None else tuple(given)
        if len(given) != len(notes):
            raise ParameterError(f"given must name a limb (or None) for each of the {len(notes)} notes, "
                                 f"got {len(given)}")
        index = {piece.name: i for i, piece in enumerate(kit.pieces)}
        times, pieces, choices, backbeats = [], [], [], []
        for i, note in enumerate(notes):
            times.append(check_real(f"notes[{i}].time", note.time, low=0.0, high=1e6, unit="s"))
            if note.piece not in index:
                raise ParameterError(f"notes[{i}].piece must be one of the kit's pieces ({', '.join(index)}), "
                                     f"got {shown(note.piece)}")
            piece = kit.piece(note.piece)
            if note.state is not None and note.state not in piece.states.values():
                allowed = ", ".join(repr(s) for s in dict.fromkeys(piece.states.values())) or "none"
                raise ParameterError(f"notes[{i}].state must be a state of {piece.name!r} ({allowed}), "
                                     f"got {shown(note.state)}")
            limbs = piece.limbs_for(note.state)
            if given[i] is not None and given[i] not in limbs:
                raise ParameterError(f"given[{i}] must be a limb that plays {piece.name!r}"
                                     f"{'' if note.state is None else ' ' + note.state} ({', '.join(limbs)}), "
                                     f"got {shown(given[i])}")
            beat = None if note.beat is None else check_real(f"notes[{i}].beat", note.beat, low=0.0, high=1e7)
            pieces.append(index[note.piece])
            choices.append(limbs)
            backbeats.append(None if beat is None else _on_backbeat(beat))
        return cls(notes, np.array(times), tuple(pieces), tuple(choices), given, tuple(backbeats))


def _on_backbeat(beat):
    """Whether ``beat`` (quarter notes from the start) is beat 2 or 4 of a 4/4 bar: an odd whole number."""
    whole = round(beat)
    return abs(beat - whole) < 1e-6 and whole % 2 == 1


def _groups(times, simultaneous):
    """The notes' indices in time order, in groups played at one time (each within ``simultaneous`` of its first)."""
    order = np.argsort(times, kind="stable")
    groups, start = [], -math.inf
    for i in order:
        if times[i] - start > simultaneous or not groups:
            groups.append([])
            start = times[i]
        groups[-1].append(int(i))
    return groups


def _assign_feet(part, groups, limbs, reasons, comfort):
    """The feet's notes: each to the first foot its piece names that is free at that time, or, when that foot
    played less than ``comfort`` s before, to another foot that rested longer (a double pedal alternates)."""
    last = dict.fromkeys(FEET, -math.inf)
    for group in groups:
        busy = {}
        for i in group:
            if part.choices[i][0] not in FEET:
                continue
            t = part.times[i]
            if part.given[i] is not None:
                foot = part.given[i]
                if foot in busy:
                    reasons[i] = f"the {foot} (given) plays note {busy[foot]} at the same time"
                    continue
            else:
                free = [f for f in part.choices[i] if f not in busy]
                if not free:
                    reasons[i] = ("no foot is free at that time: " + ", ".join(f"the {f} plays note {busy[f]}"
                                                                                for f in part.choices[i]))
                    continue
                foot = free[0]
                if t - last[foot] < comfort:
                    foot = min(free, key=lambda f: last[f])
                limbs[i] = foot
            busy[foot] = i
            last[foot] = t


class _Hands:
    """The dynamic programme over the hands' notes (see the module's docstring)."""

    def __init__(self, part, kit, lead, open_handed, costs):
        self.part, self.kit, self.costs = part, kit, costs
        # a given note moved to too fast costs more than dropping every other note: the given come first
        self.forced = costs.drop * (len(part.notes) + 1)
        self.open_handed = open_handed
        pieces = kit.pieces
        n = len(pieces)
        # move[h][a][b]: the time (s) hand h (0 right, 1 left) needs between a note on piece a and one on piece b;
        # inf where it does not play both
        self.move = [[[math.inf] * n for _ in range(n)] for _ in HANDS]
        longest = 0.0
        for h, hand in enumerate(HANDS):
            if hand not in kit.limbs:
                continue
            for a, first in enumerate(pieces):
                for b, second in enumerate(pieces):
                    if hand in first.hands and hand in second.hands:
                        # the move, and the time around it it cannot use (none on one piece)
                        self.move[h][a][b] = move_time(kit, hand, first, second) + costs.overhead * (a != b)
                        longest = max(longest, self.move[h][a][b])
        # past this a hand's last note changes no cost: its time is forgotten, and states merge
        self.rested = max(longest, costs.comfort)
        self.yaw = [p.place.get(YAW) for p in pieces]
        self.role = [p.role for p in pieces]
        self.lead_h = HANDS.index(lead)
        # the hand each time-keeping piece wants: the lead, or open-handed the hand on its side
        self.keeper = [self._keeper(p) for p in pieces]

    def _keeper(self, piece):
        if not self.open_handed or piece.role != "time" or piece.place.get(YAW, 0.0) == 0.0:
            return self.lead_h
        return 1 if piece.place[YAW] > 0.0 else 0

    def assign(self, groups, limbs, reasons):
        """Give the hands' notes of ``groups`` their hands (into ``limbs``, or a reason into ``reasons``);
        returns the total cost."""
        hand_groups = []
        for group in groups:
            notes = [i for i in group if self.part.choices[i][0] in HANDS]
            if notes:
                hand_groups.append((float(self.part.times[group[0]]), self._one_per_given_hand(notes, reasons)))
        # First only the ways that play as many of each group's notes as two hands can, every move in time;
        # only when no path of those is possible, every way: a dropped note (or a given one too fast) costs
        # more than any path with fewer, so the first search's best, when there is one, is the best of all.
        found = self._search(hand_groups, fewest=True) or self._search(hand_groups, fewest=False)
        total, best, trail = found
        self._write_back(best, trail, limbs, reasons)
        return total

    def _search(self, hand_groups, *, fewest):
        """The programme: (total cost, best final state, trail), or None when no state survives."""
        states = {(-1, -1, None, None): (0.0, None, None)}  # (piece R, piece L, time R, time L): cost, back
        trail = []  # per group: its time, its notes, its options, and each state's (previous state, option)
        for t, notes in hand_groups:
            options = self._options(notes, fewest)
            plans = [self._plan(option, len(notes)) for option in options]
            new = {}
            for state, (cost, _, _) in states.items():
                for k, step in enumerate(self._steps(state, plans, t, fewest)):
                    if step is None:
                        continue
                    key, extra = step
                    total = cost + extra
                    if key not in new or total < new[key][0]:
                        new[key] = (total, state, k)
            if not new:
                return None
            states = new
            trail.append((t, notes, options, {key: (back, k) for key, (_, back, k) in new.items()}))
        best = min(states, key=lambda key: states[key][0])
        return states[best][0], best, trail

    def _one_per_given_hand(self, notes, reasons):
        """The group's hand notes, less those given to a hand another given note of the group has (reported)."""
        kept, taken = [], {}
        for i in notes:
            hand = self.part.given[i]
            if hand is not None and hand in taken:
                reasons[i] = f"the {hand} hand (given) plays note {taken[hand]} at the same time"
                continue
            if hand is not None:
                taken[hand] = i
            kept.append(i)
        return kept

    def _options(self, notes, fewest):
        """The ways to give the group's notes to the hands: (note of the right hand or None, of the left or
        None); the notes on neither are dropped (never a given one). ``fewest``: only the ways that drop
        the fewest."""
        can = {i: (self.part.given[i],) if self.part.given[i] else self.part.choices[i] for i in notes}
        forced = [i for i in notes if self.part.given[i] is not None]
        rights = [None] + [i for i in notes if "right" in can[i]]
        lefts = [None] + [i for i in notes if "left" in can[i]]
        options = [(r, l) for r in rights for l in lefts
                   if (r is None or r != l) and all(i in (r, l) for i in forced)]
        if fewest:
            most = max((r is not None) + (l is not None) for r, l in options)
            options = [(r, l) for r, l in options if (r is not None) + (l is not None) == most]
        return options

    def _plan(self, option, count):
        """What playing ``option`` costs whatever the state (the dropped notes, lead, other), and its notes as
        (hand, note, piece, given, backbeat): backbeat True on beat 2 or 4, None when the beat is unknown."""
        part, costs = self.part, self.costs
        fixed = costs.drop * (count - sum(i is not None for i in option))
        moves = []
        for h, i in enumerate(option):
            if i is None:
                continue
            p = part.pieces[i]
            if self.role[p] == "time" and h != self.keeper[p]:
                fixed += costs.lead
            if h != self.lead_h:
                fixed += costs.other
            backbeat = part.on_backbeat[i] if self.role[p] == "backbeat" else False
            moves.append((h, i, p, part.given[i] is not None, backbeat))
        return fixed, tuple(moves)

    def _steps(self, state, plans, t, strict):
        """For each plan, the state after playing it at ``t`` from ``state`` and its cost; None if impossible
        (or, ``strict``, if a given note's move is too fast). The hot loop: plain lists and numbers."""
        costs, move, rested = self.costs, self.move, self.rested
        pieces, times = [state[0], state[1]], [state[2], state[3]]
        for h in (0, 1):  # forget what no longer matters: a hand rested since its last note
            if times[h] is not None and t - times[h] >= rested:
                times[h] = None
        keeper = self._time_hand(pieces)
        keeping = self._on_time(pieces[keeper])
        steps = []
        for fixed, moves in plans:
            extra, after, now = fixed, list(pieces), list(times)
            for h, i, p, given, backbeat in moves:
                before = pieces[h]
                gap = math.inf if times[h] is None else t - times[h]
                if before >= 0 and before != p:
                    need = move[h][before][p]
                    if need > gap + 1e-9:
                        if strict or not given:
                            extra = None
                            break
                        extra += self.forced  # a given note is kept: its move is reported, not refused
                    extra += costs.travel * need
                if gap < costs.comfort:
                    extra += costs.repeat * (1.0 - gap / costs.comfort)
                if h == keeper and (backbeat or (backbeat is None and keeping)):
                    extra += costs.backbeat
                after[h], now[h] = p, t
            if extra is None:
                steps.append(None)
                continue
            if self._crossed(after):
                extra += costs.cross
            steps.append(((after[0], after[1], now[0], now[1]), extra))
        return steps

    def _on_time(self, piece):
        """Whether ``piece`` (an index, -1 for none yet) keeps time."""
        return piece >= 0 and self.role[piece] == "time"

    def _time_hand(self, pieces):
        """The hand keeping time: the one on a time-keeping piece (the lead if both or neither are)."""
        on = [h for h in (0, 1) if self._on_time(pieces[h])]
        return on[0] if len(on) == 1 else self.lead_h

    def _crossed(self, pieces):
        """Whether the hands are crossed (the right left of the left) where that is not the drummer's way: the
        lead hand crosses over to a cymbal (the hi-hat, a crash), unless the drummer plays open-handed."""
        if pieces[0] < 0 or pieces[1] < 0 or self.yaw[pieces[0]] <= self.yaw[pieces[1]]:
            return False
        return self.open_handed or self.role[pieces[self.lead_h]] not in ("time", "accent")

    def _write_back(self, state, trail, limbs, reasons):
        """Follow the best path back, giving each note its hand or the reason it is not played."""
        steps = []
        for t, notes, options, back in reversed(trail):
            previous, k = back[state]
            steps.append((t, notes, options[k], previous))
            state = previous
        steps.reverse()
        following = [None, None]  # each hand's next note after the step at hand (filled in going backwards)
        after = []
        for t, _, option, _ in reversed(steps):
            after.append(tuple(following))
            for h, i in enumerate(option):
                if i is not None:
                    following[h] = (t, i)
        after.reverse()
        for (t, notes, option, previous), next_notes in zip(steps, after):
            for h, i in enumerate(option):
                if i is not None:
                    limbs[i] = HANDS[h]
                    if self.part.given[i] is not None:
                        reasons[i] = self._given_too_fast(i, h, t, previous)
            for i in notes:
                if i not in option:
                    reasons[i] = self._why_not(i, t, option, previous, next_notes)

    def _reach(self, h, start, p, gap):
        """The move of hand ``h`` from piece ``start`` (-1: none yet) to ``p`` in ``gap`` s: (need s, fits)."""
        need = 0.0 if start < 0 or start == p else self.move[h][start][p]
        return need, need <= gap + 1e-9

    def _given_too_fast(self, i, h, t, state):
        start, last = state[h], state[2 + h]
        gap = math.inf if last is None else t - last
        need, fits = self._reach(h, start, self.part.pieces[i], gap)
        if fits:
            return None
        return f"the {HANDS[h]} hand (given) needs {need:.3g} s to move from {self._name(start)} and has {gap:.3g} s"

    def _why_not(self, i, t, option, state, next_notes):
        """Why note ``i`` at ``t`` is left out, the best path having played ``option`` there from ``state``."""
        if all(j is not None for j in option):
            return f"a third hand note at one time: the right hand plays note {option[0]}, the left note {option[1]}"
        p = self.part.pieces[i]
        why = []
        for h, hand in enumerate(HANDS):
            if hand not in self.part.choices[i]:
                continue
            if option[h] is not None:
                why.append(f"the {hand} hand plays note {option[h]} at the same time")
                continue
            start, last = state[h], state[2 + h]
            gap = math.inf if last is None else t - last
            need, fits = self._reach(h, start, p, gap)
            if not fits:
                why.append(f"the {hand} hand needs {need:.3g} s to move from {self._name(start)} to "
                           f"{self._name(p)} and has {gap:.3g} s")
                continue
            if next_notes[h] is not None:  # it could play it, but not then its next note
                t_next, j = next_notes[h]
                need, fits = self._reach(h, p, self.part.pieces[j], t_next - t)
                if not fits:
                    why.append(f"the {hand} hand playing it would not reach its next note ({j}, "
                               f"{self._name(self.part.pieces[j])} at {t_next:.6g} s): it needs {need:.3g} s "
                               f"and has {t_next - t:.3g} s")
                    continue
            why.append(f"the {hand} hand playing it would leave another note unplayed")
        return "; ".join(why)

    def _name(self, piece):
        return repr(self.kit.pieces[piece].name) if piece >= 0 else "where it starts"
