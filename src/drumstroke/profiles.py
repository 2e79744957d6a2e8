"""Time profiles for the thumb's acceleration a(t) and for gravity g(t).

Every kind is piecewise linear in time, so every profile reduces to
:class:`Pieces`: edges 0 = e₀ < e₁ < … < eₙ = t_end and, on each [eᵢ, eᵢ₊₁),
a start value and a slope. The solver treats every edge (a breakpoint, a pulse
edge, a sample) as a step boundary and never integrates across one.

Kinds (values in m/s², times in s):

``constant``          one value for all t.
``piecewise-linear``  linear through breakpoints, constant beyond the end points.
``pulses``            a square wave: ``base`` plus ``amplitude`` during the first
                      ``duty`` fraction of each ``period``, pulses starting at
                      ``phase`` + k·``period``.
``samples``           a recorded signal, a CSV file of ``t,value`` rows, linear
                      between samples and constant beyond them.
``sum``               the sum of other profiles (sums nest at most :data:`MAX_SUM_DEPTH` deep;
                      ``a + b + c`` is one sum of three parts).

A recipe's table names its kind (``kind = "pulses"``); :func:`profile_from_dict`
finds the class registered under that name and builds it with the class's
:meth:`Profile.from_table`.

Adding a kind
-------------
A kind is a subclass of :class:`Profile` that sets ``kind`` and declares its
``parameters``; defining the class registers it, and recipes, sums, sweeps and
``simulate`` take it at once. Nothing else in the package is edited. Ranges are
checked in ``__post_init__``, raising a ParameterError about the parameter named
with the kind's name (``parameter="ramp.duration"``, which the message starts
with), so that an error in a recipe names the table (``force.duration must be ...``).
A ramp from ``start`` to ``end`` (m/s²) over the first ``duration`` (s), constant
after it::

    from dataclasses import dataclass

    import numpy as np

    from drumstroke import ParameterError
    from drumstroke.profiles import Parameter, Profile

    @dataclass(frozen=True)
    class Ramp(Profile):
        start: float
        end: float
        duration: float
        kind = "ramp"
        parameters = (
            Parameter("start", unit="m/s^2", description="value at t = 0"),
            Parameter("end", unit="m/s^2", description="value from t = duration on"),
            Parameter("duration", unit="s", description="length of the ramp, > 0"),
        )

        def __post_init__(self):
            if not self.duration > 0:
                raise ParameterError(f"ramp.duration must be > 0 s, got {self.duration!r}",
                                     parameter="ramp.duration", value=self.duration, allowed="> 0 s")

        def __call__(self, t):
            return np.interp(t, [0.0, self.duration], [self.start, self.end])

        def _breaks(self, t_end):
            return np.array([self.duration])

        def _start_and_slope(self, left, tol):
            slope = (self.end - self.start) / self.duration
            return self(left), np.where(left + tol < self.duration, slope, 0.0)

after which a recipe may say::

    [force]
    kind = "ramp"
    start = 10.0
    end = 220.0
    duration = 1.5

The default :meth:`Profile.from_table` refuses unknown and missing keys and
calls ``cls(**table)``; the default :meth:`Profile.to_dict` writes ``kind`` and
the declared parameters. Override either when the table is not the
constructor's arguments (``samples`` resolves its file, ``sum`` builds parts).

Examples
--------
>>> ramp = PiecewiseLinear([(0.0, 10.0), (1.0, 10.0), (2.0, 220.0)])
>>> float(ramp(1.5))
115.0
>>> pulses = Pulses(amplitude=189.0, period=0.4, duty=0.05)
>>> [float(v) for v in pulses([0.0, 0.019, 0.021, 0.4])]
[189.0, 189.0, 0.0, 189.0]
>>> profile_from_dict({"kind": "constant", "value": 9.8})
Constant(value=9.8)
>>> kinds()
('constant', 'piecewise-linear', 'pulses', 'samples', 'sum')
"""

import bisect
import functools
import itertools
import math
import os
from contextlib import contextmanager
from dataclasses import KW_ONLY, dataclass, field
from pathlib import Path

import numpy as np

from ._checks import check_keys, check_real, shown
from .budget import BREAK_VALUES, check_memory, values_bytes
from .errors import ParameterError
from .formats.signal_csv import read_signal

ACCELERATION_LIMIT = 1.0e6
"""Largest |value| of any profile (m/s²), some 4000 times the human range."""

MIN_SPACING = 1e-9
"""Closest two breakpoints or samples may be (s); closer is a step, for which use ``pulses`` or a ``sum``."""

MAX_PIECES = 200_000
"""Most pieces a profile may have before t_end (pulse edges, samples, breakpoints)."""

MAX_SUM_DEPTH = 16
"""Most sums a sum may hold one inside another (the profile a sum of sums of … of sums)."""


@dataclass(frozen=True)
class Pieces:
    """A piecewise-linear function of time on [0, t_end].

    Attributes
    ----------
    edges : ndarray [shape=(n + 1,)]
        Strictly increasing, ``edges[0] = 0`` and ``edges[-1] = t_end`` (s).
    values : ndarray [shape=(n,)]
        The value just after each left edge (the right limit).
    slopes : ndarray [shape=(n,)]
        The slope on each piece (per s).
    """

    edges: np.ndarray
    values: np.ndarray
    slopes: np.ndarray

    def __len__(self):
        return len(self.values)

    def at(self, left, t_end):
        """Value and slope of the piece starting at each time in ``left`` (s), as (values, slopes).

        An edge of this function within the merging tolerance of a time counts as at it.
        """
        i = np.searchsorted(self.edges, left + merge_tolerance(t_end), side="right") - 1
        return self.values[i] + self.slopes[i] * (left - self.edges[i]), self.slopes[i]


def merge_tolerance(t_end):
    """Edges closer than this (s) are one edge: round-off in sums of pulse trains, not physics."""
    return 1e-12 * max(1.0, t_end)


def merge_edges(edges, t_end):
    """Sorted edges in [0, t_end], 0 and t_end included, with near-duplicates merged into the first."""
    if len(edges) == 0:
        return np.array([0.0, t_end])
    if len(edges) <= _FEW:
        return np.array(_merged(np.asarray(edges, dtype=float).tolist(), t_end))
    # np.unique's work (sort, keep the first of equals) without its wrappers: this runs at every simulation
    edges = np.concatenate(([0.0, t_end], edges))
    edges.sort()
    edges = edges[np.concatenate(([True], edges[1:] != edges[:-1])) & (edges >= 0.0) & (edges <= t_end)]
    tol = merge_tolerance(t_end)
    if (edges[1:] - edges[:-1] <= tol).any():  # rare: merge each cluster into its first edge
        kept = [edges[0]]
        for edge in edges[1:]:
            if edge - kept[-1] > tol:
                kept.append(edge)
        edges = np.array(kept)
    edges[-1] = t_end
    return edges


_FEW = 64
"""Breakpoints up to this many are worked in plain Python: numpy's cost per call is more than the work (a designed
stroke's profile has a few dozen, and each design is simulated)."""


def _merged(edges, t_end):
    """:func:`merge_edges` of a short list of floats, in plain Python (the same arithmetic, the same edges)."""
    kept = []
    for edge in sorted([0.0, t_end, *edges]):
        if 0.0 <= edge <= t_end and (not kept or edge != kept[-1]):
            kept.append(edge)
    tol = merge_tolerance(t_end)
    if any(b - a <= tol for a, b in itertools.pairwise(kept)):  # rare: merge each cluster into its first edge
        clusters = [kept[0]]
        for edge in kept[1:]:
            if edge - clusters[-1] > tol:
                clusters.append(edge)
        kept = clusters
    kept[-1] = t_end
    return kept


@dataclass(frozen=True)
class Parameter:
    """One key of a profile kind's recipe table, as the kind declares it.

    Parameters
    ----------
    name : str
        The key (``"amplitude"``).
    unit : str
        SI unit of the value (``"m/s^2"``, ``"s"``); ``""`` for a number without one or a non-number.
    required : bool
        Whether a table must give the key; an optional one takes the class's default.
    description : str
        What the value is and its allowed range, for people and generated docs.
    """

    name: str
    _: KW_ONLY
    unit: str = ""
    required: bool = True
    description: str = ""


_REGISTRY = {}
"""Every profile class by its kind, in the order they were defined."""


class Profile:
    """Base of all profiles: a function of time (s) with values in m/s².

    A subclass that sets ``kind`` is registered under that name (see "Adding a
    kind" in :mod:`drumstroke.profiles`); one that does not, like this base, is
    not.

    Attributes
    ----------
    kind : str
        The name a recipe table gives in its ``kind`` key.
    parameters : tuple of Parameter
        The table's other keys, in the order messages and :meth:`to_dict` list them.
    """

    kind = ""
    parameters = ()

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.__dict__.get("kind"):
            _register(cls)

    @classmethod
    def from_table(cls, table, *, name, base_dir):
        """Build the profile from a recipe table without its ``kind`` key.

        Parameters
        ----------
        table : dict
            The declared parameters by name; :meth:`check_table` says which are allowed.
        name : str
            Where the table came from, for error messages (``"force"``, ``"gravity.parts[1]"``).
        base_dir : Path or None
            Directory that file names in the table are relative to.

        Returns
        -------
        Profile
            An instance of ``cls``.
        """
        cls.check_table(table, name=name)
        return cls(**table)

    @classmethod
    def check_table(cls, table, *, name):
        """Refuse a key of ``table`` that is not a declared parameter, or a required parameter it lacks."""
        check_keys(f"{name} ({cls.kind})", table, [p.name for p in cls.parameters])
        missing = [p.name for p in cls.parameters if p.required and p.name not in table]
        if missing:
            raise ParameterError(f"{name} ({cls.kind}) needs the key {missing[0]!r}")

    def __call__(self, t):
        """The profile's value at times ``t`` (s) [any shape]; right-continuous at jumps."""
        raise NotImplementedError

    def pieces(self, t_end):
        """The profile on [0, t_end] as :class:`Pieces`.

        The breakpoints are counted before they are made (:meth:`check_budget`).
        """
        self.check_budget(t_end)
        edges = merge_edges(self._breaks(t_end), t_end)
        self._check_pieces(len(edges) - 1, t_end)
        values, slopes = self._start_and_slope(edges[:-1], merge_tolerance(t_end))
        return Pieces(edges, np.asarray(values, dtype=float), np.asarray(slopes, dtype=float))

    def _check_pieces(self, count, t_end):
        """Refuse ``count`` pieces before ``t_end`` (s) when they are more than :data:`MAX_PIECES`."""
        if count > MAX_PIECES:
            raise ParameterError(
                f"{self.kind} profile has {count} pieces before t_end = {t_end:g} s; "
                f"at most {MAX_PIECES} are allowed (shorten t_end or lengthen the period)"
            )

    def check_budget(self, t_end, *, what=None):
        """Refuse the profile when its breakpoints before ``t_end`` (s) are more than the memory budget's worth.

        They are counted without being made (:mod:`drumstroke.budget`); ``what`` names the profile
        in the message (default ``KIND profile``).
        """
        count = self._break_count(t_end)
        check_memory(what or (lambda: f"{self.kind} profile"), values_bytes(BREAK_VALUES * count),
                     lambda: f"{count:.0f} breakpoints before t_end = {t_end:g} s")

    def to_dict(self):
        """The profile as a plain dict, in the form a recipe's table takes: ``kind``, then each parameter."""
        return {"kind": self.kind, **{p.name: getattr(self, p.name) for p in self.parameters}}

    def _breaks(self, t_end):
        """Times in [0, t_end] (s) where the profile jumps or bends [shape=(n,)], in any order."""
        raise NotImplementedError

    def _break_count(self, t_end):
        """How many times :meth:`_breaks` gives, found without making them where they may be many (an upper bound)."""
        return len(self._breaks(t_end))

    def _start_and_slope(self, left, tol):
        """Value just after each time in ``left`` (s) and the slope that follows it, as (values, slopes).

        An edge of the profile within ``tol`` (s) after a time counts as at it.
        """
        raise NotImplementedError

    def __add__(self, other):
        """The sum of two profiles, one :class:`Sum` of the terms of both (a sum's parts are its terms)."""
        if not isinstance(other, Profile):
            return NotImplemented
        return Sum([*_terms(self), *_terms(other)])


def _terms(profile):
    return profile.parts if isinstance(profile, Sum) else (profile,)


def _register(cls):
    """Add ``cls`` to the registry under its kind; a class defined again (a re-run notebook cell) replaces itself."""
    kind, parameters = cls.kind, cls.parameters
    if not isinstance(kind, str):
        raise ParameterError(f"{cls.__qualname__}.kind must be a string, got {kind!r}")
    if not isinstance(parameters, tuple) or not all(isinstance(p, Parameter) for p in parameters):
        raise ParameterError(f"{cls.__qualname__}.parameters must be a tuple of Parameter, got {parameters!r}")
    names = [p.name for p in parameters]
    if len(set(names)) != len(names) or "kind" in names:
        raise ParameterError(f"{cls.__qualname__}.parameters must have distinct names other than 'kind', got {names}")
    known = _REGISTRY.get(kind)
    if known is not None and (known.__module__, known.__qualname__) != (cls.__module__, cls.__qualname__):
        raise ParameterError(
            f"profile kind {kind!r} is already registered by {known.__module__}.{known.__qualname__}; "
            f"give {cls.__module__}.{cls.__qualname__} another kind"
        )
    _REGISTRY[kind] = cls


def kinds():
    """The names of every registered profile kind, built-in ones first, in the order they were defined."""
    return tuple(_REGISTRY)


@dataclass(frozen=True, eq=True)
class Constant(Profile):
    """One value for all time.

    Parameters
    ----------
    value : float, |value| ≤ 1e6
        m/s².
    """

    value: float
    kind = "constant"
    parameters = (Parameter("value", unit="m/s^2", description="the value for all t, |value| <= 1e6"),)

    def __post_init__(self):
        object.__setattr__(self, "value", _check_level("constant.value", self.value))

    def __call__(self, t):
        return np.full(np.shape(t), self.value)

    def _breaks(self, t_end):
        return np.empty(0)

    def _start_and_slope(self, left, tol):
        return np.full(len(left), self.value), np.zeros(len(left))


@dataclass(frozen=True, eq=True)
class PiecewiseLinear(Profile):
    """Linear through breakpoints, constant beyond the first and last.

    Parameters
    ----------
    points : sequence of (t, value) pairs
        t (s) ≥ 0 and strictly increasing; value (m/s²) with |value| ≤ 1e6.
        At least one point.
    """

    points: tuple
    kind = "piecewise-linear"
    parameters = (
        Parameter(
            "points",
            unit="s, m/s^2",
            description="[t, value] pairs: t in [0, 3600], increasing, at least 1e-9 apart; |value| <= 1e6",
        ),
    )
    _t: np.ndarray = field(init=False, repr=False, compare=False)
    _v: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        t, v = _check_points(f"{self.kind}.points", self.points)
        object.__setattr__(self, "points", tuple(zip(t.tolist(), v.tolist())))
        object.__setattr__(self, "_t", t)
        object.__setattr__(self, "_v", v)

    @classmethod
    def _of(cls, times, values):
        """The profile through ``times`` (s) and ``values`` (m/s²), two lists of numbers (a designed stroke's steps):
        the same profile as ``PiecewiseLinear(list(zip(times, values)))``, its usual case made without the pairs'
        checks of their shape and the frozen dataclass's ``__init__``."""
        if not _plain(zip(times, values)):  # the checks that name the fault
            return cls(list(zip(times, values)))
        profile = object.__new__(cls)
        fields = profile.__dict__
        fields["_t"], fields["_v"] = t, v = np.array(times, dtype=float), np.array(values, dtype=float)
        fields["points"] = tuple(zip(t.tolist(), v.tolist()))
        return profile

    def __call__(self, t):
        return np.interp(np.asarray(t, dtype=float), self._t, self._v)

    def _breaks(self, t_end):
        return self._t

    def _start_and_slope(self, left, tol):
        t, v = self._t, self._v
        if len(t) == 1:
            return np.full(len(left), v[0]), np.zeros(len(left))
        if len(t) <= _FEW and len(left) <= _FEW:
            return self._start_and_slope_few(left.tolist(), tol)
        k = np.searchsorted(t, left + tol, side="right") - 1  # the segment each piece lies on
        inside = (k >= 0) & (k < len(t) - 1)
        k = k.clip(0, len(t) - 2)
        slopes = np.where(inside, (v[k + 1] - v[k]) / (t[k + 1] - t[k]), 0.0)
        values = np.where(inside, v[k] + slopes * (left - t[k]), np.where(left < t[0], v[0], v[-1]))
        return values, slopes

    def _start_and_slope_few(self, left, tol):
        """:meth:`_start_and_slope` in plain Python, for a few points and pieces (the same arithmetic, to the bit)."""
        t, v = self._t.tolist(), self._v.tolist()
        values, slopes = [], []
        for x in left:
            k = bisect.bisect_right(t, x + tol) - 1  # the segment the piece lies on
            if 0 <= k < len(t) - 1:
                slope = (v[k + 1] - v[k]) / (t[k + 1] - t[k])
                values.append(v[k] + slope * (x - t[k]))
                slopes.append(slope)
            else:
                values.append(v[0] if x < t[0] else v[-1])
                slopes.append(0.0)
        return np.array(values), np.array(slopes)

    def to_dict(self):
        return {"kind": self.kind, "points": [list(p) for p in self.points]}


@dataclass(frozen=True, eq=True)
class Pulses(Profile):
    """Square-wave finger pulses (paper Fig. 7: 189 m/s², 0.4 s, 5 %).

    Parameters
    ----------
    amplitude : float, |amplitude| ≤ 1e6
        Added to ``base`` while a pulse is on (m/s²).
    period : float in [0.001, 3600]
        s.
    duty : float in (0, 1)
        Fraction of each period the pulse is on.
    phase : float in [0, 3600]
        Start of the first pulse (s); pulses start at phase + k·period.
    base : float, |base| ≤ 1e6
        Value between pulses (m/s²).
    """

    amplitude: float
    period: float
    duty: float
    phase: float = 0.0
    base: float = 0.0
    kind = "pulses"
    parameters = (
        Parameter("amplitude", unit="m/s^2", description="added to base while a pulse is on, |amplitude| <= 1e6"),
        Parameter("period", unit="s", description="time from one pulse's start to the next, in [0.001, 3600]"),
        Parameter("duty", description="fraction of each period the pulse is on, in (0, 1)"),
        Parameter("phase", unit="s", required=False, description="start of the first pulse, in [0, 3600]; 0"),
        Parameter("base", unit="m/s^2", required=False, description="value between pulses, |base| <= 1e6; 0"),
    )

    def __post_init__(self):
        checked = {
            "amplitude": _check_level("pulses.amplitude", self.amplitude),
            "period": check_real("pulses.period", self.period, low=1e-3, high=3600.0, unit="s"),
            "duty": check_real("pulses.duty", self.duty, low=0.0, high=1.0, low_open=True, high_open=True),
            "phase": check_real("pulses.phase", self.phase, low=0.0, high=3600.0, unit="s"),
            "base": _check_level("pulses.base", self.base),
        }
        if abs(checked["amplitude"] + checked["base"]) > ACCELERATION_LIMIT:
            total = checked["base"] + checked["amplitude"]
            raise ParameterError(f"pulses.base + pulses.amplitude must be in [-1e+06, 1e+06] m/s^2, got {total!r}",
                                 parameter="pulses.base", value=total, allowed="[-1e+06, 1e+06] m/s^2")
        for name, value in checked.items():
            object.__setattr__(self, name, value)

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        k = np.floor((t - self.phase) / self.period)
        # Edges computed exactly as in _breaks, so values and step boundaries agree.
        k -= t < self.phase + k * self.period
        k += t >= self.phase + (k + 1) * self.period
        start = self.phase + k * self.period
        on = (t >= self.phase) & (t < start + self.duty * self.period)
        return np.where(on, self.base + self.amplitude, self.base)

    def pieces(self, t_end):
        # the base class's steps in one compiled call (every simulation of a pulsed stroke makes them)
        self.check_budget(t_end)
        edges, values = _pulse_kernel().pieces(self.amplitude, self.period, self.phase, self.duty, self.base, t_end,
                                               self._break_count(t_end) // 2, merge_tolerance(t_end))
        self._check_pieces(len(values), t_end)
        return Pieces(edges, values, np.zeros(len(values)))

    def _breaks(self, t_end):
        k = np.arange(0, math.floor(max(t_end - self.phase, 0.0) / self.period) + 1)
        rises = self.phase + k * self.period
        return np.concatenate((rises, rises + self.duty * self.period))

    def _break_count(self, t_end):
        return 2 * (math.floor(max(t_end - self.phase, 0.0) / self.period) + 1)

    def _start_and_slope(self, left, tol):
        return _pulse_kernel().values(left + tol, self.amplitude, self.period, self.phase, self.duty,
                                      self.base), np.zeros(len(left))


@functools.cache
def _pulse_kernel():
    """The pulse train's compiled pieces, imported on first use (`import drumstroke` stays light)."""
    from . import _pulses

    return _pulses


@dataclass(frozen=True, eq=True)
class Samples(PiecewiseLinear):
    """A recorded signal read from a CSV file of ``t,value`` rows.

    Linear between samples and constant beyond them. A header row is allowed;
    times (s) must be ≥ 0 and strictly increasing.

    Parameters
    ----------
    file : str or Path
        The CSV file. Read once, when the profile is made; recorded by its absolute path.
    """

    points: tuple = field(init=False, repr=False)  # the file names them
    file: str = ""
    kind = "samples"
    parameters = (
        Parameter("file", description="CSV file of 't,value' rows (s, m/s^2), relative to the recipe's folder"),
    )

    def __init__(self, file):
        object.__setattr__(self, "file", os.path.realpath(file))  # not resolve(): it raises on a link loop
        object.__setattr__(self, "points", _read_samples(Path(file)))
        self.__post_init__()

    @classmethod
    def from_table(cls, table, *, name, base_dir):
        """Build the profile from ``{"file": ...}``; a relative file name is relative to ``base_dir``."""
        cls.check_table(table, name=name)
        file = table["file"]
        if not isinstance(file, str) or not file:
            raise ParameterError(f"{name}.file must be a path to a CSV file, got {file!r}")
        path = Path(file)
        if base_dir is not None and not path.is_absolute():
            path = Path(base_dir) / path
        return cls(path)

    def to_dict(self):
        return {"kind": self.kind, "file": self.file}


@dataclass(frozen=True, eq=True)
class Sum(Profile):
    """The sum of other profiles.

    Parameters
    ----------
    parts : sequence of Profile
        At least one; sums among them nest at most :data:`MAX_SUM_DEPTH` deep in all.

    Attributes
    ----------
    depth : int
        How deeply sums nest in this one: 1 when no part is a sum.
    """

    parts: tuple
    kind = "sum"
    parameters = (Parameter("parts", description="the profiles' tables, each with its own kind; at least one; "
                                                 f"sums nest at most {MAX_SUM_DEPTH} deep"),)
    depth: int = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        parts = tuple(self.parts) if isinstance(self.parts, (list, tuple)) else None
        if not parts or not all(isinstance(p, Profile) for p in parts):
            raise ParameterError(f"sum.parts must be a non-empty list of profiles, got {shown(self.parts)}",
                                 parameter="sum.parts", value=self.parts, allowed="a non-empty list of profiles")
        depth = 1 + max((part.depth for part in parts if isinstance(part, Sum)), default=0)
        if depth > MAX_SUM_DEPTH:
            raise ParameterError(f"sum.parts must nest sums at most {MAX_SUM_DEPTH} deep, got sums {depth} deep",
                                 parameter="sum.parts", value=self.parts, allowed=f"sums at most {MAX_SUM_DEPTH} deep")
        object.__setattr__(self, "parts", parts)
        object.__setattr__(self, "depth", depth)

    def __call__(self, t):
        return sum(part(t) for part in self.parts)

    def _start_and_slope(self, left, tol):
        values, slopes = zip(*(part._start_and_slope(left, tol) for part in self.parts))
        return sum(values), sum(slopes)

    def _breaks(self, t_end):
        return np.concatenate([part._breaks(t_end) for part in self.parts])

    def _break_count(self, t_end):
        return sum(part._break_count(t_end) for part in self.parts)

    @classmethod
    def from_table(cls, table, *, name, base_dir):
        """Build the sum from ``{"parts": [table, ...]}``, each part's table as :func:`profile_from_dict` takes it."""
        cls.check_table(table, name=name)
        parts = table["parts"]
        if not isinstance(parts, list) or not parts:
            raise ParameterError(f"{name}.parts must be a non-empty list of tables, got {parts!r}")
        return cls([profile_from_dict(p, name=f"{name}.parts[{i}]", base_dir=base_dir) for i, p in enumerate(parts)])

    def to_dict(self):
        return {"kind": self.kind, "parts": [part.to_dict() for part in self.parts]}


def profile_from_dict(spec, *, name="force", base_dir=None):
    """Build a profile from a recipe table such as ``{"kind": "constant", "value": 9.8}``.

    Parameters
    ----------
    spec : dict
        The table: ``kind``, one of :func:`kinds`, and that kind's parameters.
    name : str
        Where the table came from, for error messages (e.g. ``"force"``).
    base_dir : Path or None
        Directory that a ``samples`` file name is relative to.

    Returns
    -------
    Profile
        An instance of the class registered under ``kind``.
    """
    if not isinstance(spec, dict):
        raise ParameterError(f"{name} must be a table with a 'kind' key, got {shown(spec)}", parameter=name, value=spec,
                             allowed="a table with a 'kind' key")
    depth = _sum_depth(spec)
    if depth > MAX_SUM_DEPTH:
        raise ParameterError(f"{name} must nest sums at most {MAX_SUM_DEPTH} deep, got sums {depth} deep",
                             parameter=name, value=spec, allowed=f"sums at most {MAX_SUM_DEPTH} deep")
    table = dict(spec)
    kind = table.pop("kind", None)
    if not isinstance(kind, str) or kind not in _REGISTRY:
        allowed = "one of " + ", ".join(map(repr, _REGISTRY))
        raise ParameterError(f"{name}.kind must be {allowed}, got {kind!r}", parameter=f"{name}.kind", value=kind,
                             allowed=allowed)
    with named(name, kind):
        return _REGISTRY[kind].from_table(table, name=name, base_dir=base_dir)


def _sum_depth(spec):
    """How deeply sums nest in a profile table (0: not a sum), counted without recursion."""
    deepest, tables = 0, [(spec, 1)]
    while tables:
        table, depth = tables.pop()
        if isinstance(table, dict) and table.get("kind") == "sum" and isinstance(table.get("parts"), list):
            deepest = max(deepest, depth)
            tables.extend((part, depth + 1) for part in table["parts"])
    return deepest


@contextmanager
def named(name, kind):
    """Re-raise an error about a profile's parameter with the profile's place (``force``) for its kind (``constant``).

    The error about ``constant.value`` is raised as one about ``force.value``.
    """
    try:
        yield
    except ParameterError as error:
        parameter = error.parameter or ""
        if parameter.startswith(kind + "."):
            raise error.renamed(name + parameter[len(kind):]) from None
        raise


KINDS = kinds()
"""The names of the built-in profile kinds; :func:`kinds` also lists those registered since."""


def _check_level(name, value):
    return check_real(name, value, low=-ACCELERATION_LIMIT, high=ACCELERATION_LIMIT, unit="m/s^2")


def _check_points(name, points):
    pairs = "a non-empty list of [t, value] pairs of numbers"
    try:
        rows = [tuple(point) for point in points]
    except TypeError:
        raise ParameterError(f"{name} must be {pairs}, got {points!r}", parameter=name, value=points,
                             allowed=pairs) from None
    if not rows or any(len(row) != 2 for row in rows):
        raise ParameterError(f"{name} must be {pairs}, got {points!r}", parameter=name, value=points, allowed=pairs)
    if _plain(rows):  # every designed stroke's profile comes here: its usual case checked without numpy's costs
        return np.array([row[0] for row in rows], dtype=float), np.array([row[1] for row in rows], dtype=float)
    for i, (ti, vi) in enumerate(rows):
        check_real(f"{name}[{i}] time", ti, low=0.0, high=3600.0, unit="s")
        _check_level(f"{name}[{i}] value", vi)
    array = np.array(rows, dtype=float)
    t, v = array[:, 0], array[:, 1]
    steps = t[1:] - t[:-1]  # np.diff's arithmetic without its wrapper: every designed stroke's profile comes here
    if (steps < MIN_SPACING).any():
        i = int(np.argmax(steps < MIN_SPACING)) + 1
        least = float(t[i - 1]) + MIN_SPACING
        raise ParameterError(
            f"{name} times must be strictly increasing, at least {MIN_SPACING:g} s apart; point {i} has "
            f"t = {float(t[i])!r} s after t = {float(t[i - 1])!r} s (allowed: t >= {least!r})",
            parameter=name, value=points, allowed=f"t >= {least!r} for point {i}")
    return t.copy(), v.copy()


_FLOATS = (float, np.float64)


def _plain(rows):
    """Whether ``rows`` are floats that pass :func:`_check_points` (times in [0, 3600] s, MIN_SPACING apart; values
    within the acceleration limit), found in plain Python: False sends them through the checks that name the fault."""
    last = -math.inf
    for t, v in rows:
        if not (type(t) in _FLOATS and type(v) in _FLOATS and 0.0 <= t <= 3600.0 and t - last >= MIN_SPACING
                and -ACCELERATION_LIMIT <= v <= ACCELERATION_LIMIT):  # NaN fails every comparison
            return False
        last = t
    return True


def _read_samples(path):
    rows = read_signal(path, "samples.file")
    t, v = _check_points(f"samples.file {str(path)!r}", rows)
    return tuple(zip(t.tolist(), v.tolist()))
