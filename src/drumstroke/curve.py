"""The one exact motion type: a :class:`Curve`, segments of exact motion end to end on one clock.

Every layer that moves a stick builds its motion as a curve: a simulated stroke (the solver's
arcs), a jerk-limited move between strokes, a hold, a composed part, the live performer's running
motion. A curve is a path, ``curve(t) -> (theta, omega)``, so a curve can be a segment of another.

A :class:`Segment` is one exact piece: a path on its own clock (local time = t − ``offset``), used
on [``start``, ``end``] of the curve's clock (s), with the impacts it makes (local times). Each time
is evaluated by the segment that holds it (at a boundary, the later one), clamped to the segment's
span, so a curve holds its first state before it starts and its last after it ends.

A curve moves one joint or several: a segment's path returns arrays shaped like ``t`` for one
joint, ``t.shape + (joints,)`` for several (a limb that carries a stick over a kit), and the curve's
are shaped as its segments'.

Examples
--------
>>> import numpy as np
>>> rise = Segment(0.5, 1.0, lambda t: (2.0 * t, np.full(np.shape(t), 2.0)), offset=0.5)
>>> curve = Curve.hold(0.0).spliced(rise).spliced(Segment.hold(1.0, 1.0))
>>> theta, omega = curve(np.array([0.25, 0.75, 2.0]))
>>> theta.tolist(), omega.tolist()
([0.0, 0.5, 1.0], [0.0, 2.0, 0.0])
>>> curve.state(0.75)
(0.5, 2.0)
"""

import bisect
import functools
import inspect
import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .errors import ParameterError

STEP = 1e-6
"""s: the half-step of the central difference of ω that gives the flight acceleration α."""


def _no_impacts():
    return np.empty(0)


@dataclass(frozen=True, eq=False)
class Segment:
    """One exact piece of a curve.

    Parameters
    ----------
    start, end : float
        s on the curve's clock: the span it is used on (``end`` may be inf).
    path : callable
        ``path(local t) -> (theta, omega)`` (rad, rad/s), vectorised, each time on its own (a curve
        groups and joins the times it evaluates as it likes); at an impact time the state just after it.
    offset : float
        s: the curve's time of the path's local 0 (local t = t − offset).
    impacts : ndarray [shape=(m,)]
        Local times (s) of the impacts it makes, increasing: α is one-sided across them.
    source : object
        What made it (a designed stroke, a move...), for the callers that ask.
    still : bool
        Whether it holds still (θ constant, ω and α 0): its acceleration is not differenced.
    """

    start: float
    end: float
    path: Callable = field(repr=False)
    offset: float = 0.0
    impacts: np.ndarray = field(default_factory=_no_impacts, repr=False)
    source: object = field(default=None, repr=False)
    still: bool = field(default=False, repr=False)

    def __post_init__(self):
        if not (math.isfinite(self.start) and self.end >= self.start and not math.isnan(self.end)):
            raise ParameterError(f"a segment's end must be at or after its start (s), got start {self.start!r} and "
                                 f"end {self.end!r}")

    @classmethod
    def _of(cls, start, end, path, offset, impacts=None, source=None, still=False):
        """The Segment of these fields (``impacts`` None: none), checked, made without the frozen dataclass's
        ``__init__`` (which sets each field by ``object.__setattr__``): a live note makes several; the same object."""
        segment = object.__new__(cls)
        segment.__dict__.update(start=start, end=end, path=path, offset=offset,
                                impacts=_no_impacts() if impacts is None else impacts, source=source, still=still)
        segment.__post_init__()
        return segment

    @classmethod
    def hold(cls, theta, start, end=math.inf):
        """The stick (or the joints) held still at ``theta`` (rad) on [``start``, ``end``] s."""
        start = float(start)
        return cls._of(start, float(end), still(theta), start, still=True)

    def local(self, t):
        """Local times of curve times ``t`` (s), clamped to the segment's span."""
        return np.minimum(np.maximum(t, self.start), self.end) - self.offset  # np.clip costs more on short runs

    def _until(self, end):
        """This segment used up to ``end`` (s, after its start), unchecked: the cut of a segment already checked."""
        cut = object.__new__(Segment)
        cut.__dict__.update(self.__dict__, end=end)
        return cut


@dataclass(frozen=True, eq=False)
class Curve:
    """Segments end to end: each starts where the one before it ends.

    Parameters
    ----------
    segments : tuple of Segment
        At least one, in time order, each one's start at the end of the one before (within 1e-9 s).
    """

    segments: tuple

    def __post_init__(self):
        segments = tuple(self.segments)
        refused = not segments
        for segment in segments:  # (loops, not generators: a live note makes a curve)
            refused = refused or not isinstance(segment, Segment)
        if refused:
            raise ParameterError(f"segments must be a non-empty sequence of Segment, got {self.segments!r}")
        end = segments[0].end
        for k in range(1, len(segments)):
            start = segments[k].start
            if abs(start - end) > 1e-9 * max(1.0, abs(start)):
                raise ParameterError(f"segments[{k}] starts at {start!r} s, not where segments[{k - 1}] "
                                     f"ends ({end!r} s): a curve's segments tile its span")
            end = segments[k].end
        object.__setattr__(self, "segments", segments)

    @classmethod
    def _tiled(cls, segments):
        """The curve of ``segments`` (a tuple) unchecked: for segments that tile by construction, cut from curves
        already checked (a live performer splices one per note and forgets the past at every chunk)."""
        curve = object.__new__(cls)
        object.__setattr__(curve, "segments", segments)
        return curve

    @functools.cached_property
    def _starts(self):
        """The segments' starts (s) [shape=(n,)], made when a curve is first evaluated (many are only spliced)."""
        return np.array([s.start for s in self.segments])

    # --- making one ------------------------------------------------------------------------------------------------

    @classmethod
    def hold(cls, theta, start=0.0, end=math.inf):
        """A curve that holds ``theta`` (rad; one value a joint) from ``start`` to ``end`` (s)."""
        return cls((Segment.hold(theta, start, end),))

    @classmethod
    def sequence(cls, pieces, start=0.0):
        """Paths one after another from ``start`` (s): ``pieces`` are (duration s, path) with local time 0 at
        each one's start (a move, a hold, a stroke's arcs)."""
        return cls(placed(pieces, start))

    def spliced(self, new):
        """This motion up to where ``new`` (a Segment or a Curve) starts, then ``new``."""
        if not isinstance(new, (Segment, Curve)):
            raise ParameterError(f"new must be a Segment or a Curve, got {new!r}")
        added = (new,) if isinstance(new, Segment) else new.segments
        cut = added[0].start
        kept = [s for s in self.segments if s.start < cut]
        if kept:
            kept[-1] = kept[-1]._until(cut)
        return Curve._tiled((*kept, *added))  # both checked, joined at the cut

    def since(self, t):
        """The same motion from ``t`` (s) on: the segments that end before it forgotten."""
        keep = next((k for k, s in enumerate(self.segments) if s.end > t), len(self.segments) - 1)
        return self if keep == 0 else Curve._tiled(self.segments[keep:])

    # --- reading it ------------------------------------------------------------------------------------------------

    @property
    def start(self):
        """s: where the first segment starts."""
        return self.segments[0].start

    @property
    def end(self):
        """s: where the last segment ends (inf for a curve that holds on)."""
        return self.segments[-1].end

    @property
    def impacts(self):
        """The curve's impact times (s) [shape=(m,)], of the segments' impacts within their spans."""
        times = [s.impacts + s.offset for s in self.segments]
        return np.concatenate([t[(t >= s.start) & (t <= s.end)] for t, s in zip(times, self.segments)])

    def segment_at(self, t):
        """The segment that holds time ``t`` (s): the last that starts at or before it (the first before the start)."""
        return self.segments[max(bisect.bisect_right(self._starts, t) - 1, 0)]  # a scalar: no numpy call

    def last(self, kind):
        """The last segment whose source is a ``kind`` (a class), or None."""
        return next((s for s in reversed(self.segments) if isinstance(s.source, kind)), None)

    def __call__(self, t, *, spacing=0.0):
        """θ (rad) and ω (rad/s) at times ``t`` (s), each from the segment that holds it.

        ``spacing`` > 0 (s) promises increasing times that far apart (but perhaps the last): a path
        that takes a ``spacing`` of its own (the solver's arcs, which then carry sn, cn, dn from one
        sample to the next) is given it for each run of times within its span.
        """
        if spacing > 0.0:
            spaced = lambda segment, local: (
                segment.path(local, spacing=spacing) if _takes_spacing(segment.path) else segment.path(local))
            t = np.asarray(t, dtype=float)
            flat = t.ravel()
            if self._layout is not None and flat.size > 1 and (flat[1:] >= flat[:-1]).all():
                return _shaped(self._compiled(flat, spacing, spaced), t.shape)
            return self._each(t, lambda segment, local: segment.path(local), 2, spaced=spaced)
        return self._each(t, lambda segment, local: segment.path(local), 2)

    @functools.cached_property
    def _layout(self):
        """The segments as :func:`~drumstroke.solver.kernel.evaluate_runs` reads them, or None for a curve with no
        stroke's arcs (a curve of one stick has them; one of several joints never)."""
        from .solver.arcs import Arcs
        from .solver.kernel import ARCS, CUBIC, HOLD, PATH

        kinds, rows, places, tables, steps, phases = [], [], [], [], [], []
        counts = [0, 0, 0]  # rows of tables, steps and phases so far
        for segment in self.segments:
            path, row, head = segment.path, (0, 0, 0, 0), 0.0
            owner = getattr(path, "__self__", None)
            if type(owner) is Arcs and path.__func__ is Arcs.evaluate:
                kind, head = ARCS, owner.theta_max
                row = (counts[0], counts[0] + len(owner.table), counts[1], counts[1] + len(owner.taylor))
                tables.append(owner.table)
                steps.append(owner.taylor)
                counts[0], counts[1] = row[1], row[3]
            elif type(path) is Still and not path.value.shape:
                kind, head = HOLD, float(path.value)
            elif type(path) is Cubic:
                kind, row = CUBIC, (counts[2], counts[2] + len(path.phases), 0, 0)
                phases.append(path.phases)
                counts[2] = row[1]
            else:
                kind = PATH
            kinds.append(kind)
            rows.append(row)
            places.append((segment.start, segment.end, segment.offset, head))
        if not tables:
            return None
        return (np.array(kinds, dtype=np.int64), np.array(rows, dtype=np.int64), np.array(places),
                np.concatenate(tables), np.concatenate(steps),
                np.concatenate(phases) if phases else np.empty((0, 5)))

    def _compiled(self, flat, spacing, spaced):
        """θ and ω at increasing times ``flat`` (s): the strokes, holds and moves in one compiled call, the other
        segments by their paths (each run of times as :meth:`_each` evaluates it, so the same values to the bit)."""
        from .solver.kernel import PATH, evaluate_runs, finish_runs, runs_of

        kinds, rows, places, tables, steps, phases = self._layout
        first, segment = runs_of(self._starts, flat)
        value, omega, theta = evaluate_runs(flat, first, segment, kinds, rows, places, tables, steps, phases,
                                            float(spacing))
        # θ's last step in flight by numpy's vectorised asin, as a stroke's arcs take it (Arcs.evaluate)
        finish_runs(theta, np.arcsin(value, out=value), first, segment, kinds, places)
        for r in (kinds[segment] == PATH).nonzero()[0].tolist():
            chosen, s = slice(first[r], first[r + 1]), self.segments[segment[r]]
            times = flat[chosen]
            if s.start <= times[0] and times[-1] <= s.end:
                theta[chosen], omega[chosen] = spaced(s, times - s.offset)
            else:
                theta[chosen], omega[chosen] = s.path(s.local(times))
        return theta, omega

    def state(self, t):
        """θ (rad) and ω (rad/s) at one time ``t`` (s), as floats (one joint) or arrays (several)."""
        t = float(t)
        segment = self.segment_at(t)
        if segment.still and type(segment.path) is Still and not segment.path.value.shape:  # a held stick: its angle
            return float(segment.path.value), 0.0
        local = min(max(t, segment.start), segment.end) - segment.offset  # as local() does, on one float
        theta, omega = segment.path(np.array([local]))
        if np.ndim(theta) == 1:
            return float(theta[0]), float(omega[0])
        return theta[0], omega[0]

    def acceleration(self, t):
        """The flight acceleration dω/dt (rad/s²) at times ``t`` (s), impacts excluded.

        A central difference over 2·:data:`STEP` of the segment's exact ω, one-sided where the
        segment's span or one of its impacts lies within the step.
        """
        return self._each(t, lambda segment, local: (_flight_acceleration(segment, local),), 1)[0]

    def evaluate(self, t):
        """θ (rad), ω (rad/s) and the flight acceleration α (rad/s²) at times ``t`` (s), in one pass: a stream's
        setpoints."""
        def all_three(segment, local):
            if segment.still:
                theta, omega = segment.path(local)
                return theta, omega, np.zeros_like(omega)
            lo, hi = _difference_ends(segment, local)
            n = len(local)
            theta, omega = segment.path(np.concatenate((local, hi, lo)))  # one call: its cost is mostly per call
            return theta[:n], omega[:n], _slope(omega[n:], lo, hi)

        return self._each(t, all_three, 3)

    def _each(self, t, evaluate, count, spaced=None):
        """``evaluate(segment, local times)`` of every group of times ``t`` one segment holds, put back in t's order.

        A chunk of setpoints is short: numpy's methods rather than its functions (whose wrappers cost
        more than the work), and increasing times (samples) taken as contiguous runs; ``spaced``, if
        given, evaluates such a run instead when it lies within its segment's span (no time clamped).
        """
        t = np.asarray(t, dtype=float)
        flat = t.ravel()
        if len(self.segments) == 1:
            segment = self.segments[0]
            return _shaped(evaluate(segment, segment.local(flat)), t.shape)
        which = self._starts.searchsorted(flat, side="right") - 1  # at most the last segment's index
        np.maximum(which, 0, out=which)
        if flat.size and (flat[1:] >= flat[:-1]).all():  # increasing (and no NaN): runs as slices
            edges = [0, *((which[1:] != which[:-1]).nonzero()[0] + 1).tolist(), flat.size]
            runs = [slice(a, b) for a, b in itertools.pairwise(edges)]
        else:  # each segment's times in one run: linear in samples + segments
            order = np.argsort(which, kind="stable")
            runs = np.split(order, np.flatnonzero(np.diff(which[order])) + 1) if flat.size else []
        out = None
        for chosen in runs:
            sliced = isinstance(chosen, slice)
            segment = self.segments[which[chosen.start if sliced else chosen[0]]]
            times = flat[chosen]
            if sliced and segment.start <= times[0] and times[-1] <= segment.end:  # increasing, within the span
                values = (spaced or evaluate)(segment, times - segment.offset)  # the clamp would change nothing
            else:
                values = evaluate(segment, segment.local(times))
            if out is None:
                out = tuple(np.empty(flat.shape + np.shape(v)[1:]) for v in values)
            for array, value in zip(out, values):
                array[chosen] = value
        if out is None:  # no times
            return tuple(np.empty(t.shape) for _ in range(count))
        return _shaped(out, t.shape)

    def __repr__(self):
        return f"Curve({len(self.segments)} segments over [{self.start:.6g}, {self.end:.6g}] s)"


@functools.lru_cache(maxsize=64)
def _method_takes_spacing(function):
    return "spacing" in inspect.signature(function).parameters


def _takes_spacing(path):
    """Whether ``path`` is a method that takes ``spacing`` (s) (the solver's arcs); a closure never is (it is not
    cached: a curve has many)."""
    function = getattr(path, "__func__", None)
    return function is not None and _method_takes_spacing(function)


def _shaped(arrays, shape):
    """``arrays`` of flat times' values reshaped to times of ``shape`` (each keeps its trailing joints axis)."""
    if len(shape) == 1:  # times already flat: nothing to reshape
        return tuple(arrays)
    return tuple(np.reshape(a, shape + np.shape(a)[1:]) for a in arrays)


def still(theta):
    """The path of the stick (or the joints) held still at ``theta`` (rad): ``path(t) -> (theta, omega)``."""
    return Still(np.asarray(theta, dtype=float))


class Still:
    """The path of the stick (or the joints) held still at ``value`` (rad) [shape=() or (joints,)].

    A class, not a closure: a curve of one stick evaluates its holds with its strokes in one compiled call.
    """

    __slots__ = ("value",)

    def __init__(self, value):
        self.value = value

    def __call__(self, t):
        value = self.value
        shape = np.shape(t) + value.shape
        return (np.full(shape, float(value)) if not value.shape else np.broadcast_to(value, shape).copy(),
                np.zeros(shape))


class Cubic:
    """The path of one joint through phases of constant jerk (a jerk-limited move): θ and ω cubic in time.

    Parameters
    ----------
    phases : ndarray [shape=(k, 5)]
        Each phase's start (s, from 0, increasing; the first 0), its jerk (rad/s³), and the acceleration
        (rad/s²), speed (rad/s) and angle (rad) it starts from. The last phase holds on past its end, and
        the first before 0 (from 0).
    """

    __slots__ = ("phases",)

    def __init__(self, phases):
        self.phases = phases

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        phases = self.phases
        k = np.clip(phases[:, 0].searchsorted(t, side="right") - 1, 0, len(phases) - 1)
        dt = np.clip(t - phases[k, 0], 0.0, None)
        jerk, acceleration, speed, position = phases[k, 1], phases[k, 2], phases[k, 3], phases[k, 4]
        theta = position + dt * (speed + dt * (acceleration / 2.0 + dt * jerk / 6.0))
        return theta, speed + dt * (acceleration + dt * jerk / 2.0)


def placed(pieces, start=0.0):
    """Segments of paths one after another from ``start`` (s): ``pieces`` are (duration s, path), each path's local
    time 0 at its start."""
    segments, t = [], float(start)
    for duration, path in pieces:
        segments.append(Segment._of(t, t + duration, path, t))
        t += duration
    return tuple(segments)


def _flight_acceleration(segment, local):
    """dω/dt of one segment at its ``local`` times (s, within its span) [shape=(n,)]: central, one-sided at its span's
    ends and its impacts."""
    if segment.still:
        return np.zeros_like(segment.path(local)[1])
    lo, hi = _difference_ends(segment, local)
    _, omega = segment.path(np.concatenate((hi, lo)))  # one call: a path's cost is mostly per call
    return _slope(omega, lo, hi)


def _difference_ends(segment, local):
    """The local times (s) [shape=(n,)] the flight acceleration at ``local`` is the slope of ω between: 2·STEP
    apart, one-sided where the segment's span or one of its impacts lies within the step.

    Worked in the segment's local time, as its path is evaluated: an impact and a time that round to the same
    curve time stay on their sides.
    """
    first, last = segment.start - segment.offset, segment.end - segment.offset
    lo = np.maximum(local - STEP, first)  # local is within [first, last] already
    hi = np.minimum(local + STEP, last)
    impacts = segment.impacts
    if len(impacts):
        j = impacts.searchsorted(local, side="right")
        before = impacts[np.maximum(j - 1, 0)]
        after = impacts[np.minimum(j, len(impacts) - 1)]
        lo = np.where((j > 0) & (before > lo), local, lo)  # an impact just behind: look ahead only
        hi = np.where((j < len(impacts)) & (after < hi), local, hi)
    return lo, hi


def _slope(omega, lo, hi):
    """(ω(hi) − ω(lo)) / (hi − lo), 0 where hi = lo, from ``omega`` = ω at ``hi`` then at ``lo`` [shape=(2n, ...)]."""
    n = len(lo)
    width = hi - lo
    if np.ndim(omega) > 1:
        width = width[:, None]
    positive = width > 0
    return np.where(positive, (omega[:n] - omega[n:]) / np.where(positive, width, 1.0), 0.0)
