"""c from a drop: a stick let fall on the head bounces under gravity alone (the paper's method, its Section 3.3).

Each impact turns the arrival speed ω into a launch speed c·ω, and under gravity alone the
flight that follows is an exact pendulum arc whose duration F(ω) depends only on ω (docs/model.md:
F(ω) = 2[K(m) − F(ψ(θ_max) | m)]/√C, :func:`drumstroke.solver.elliptic.flight_time`). So
successive flights last

    T_n = F(c^(n−1) · ω₁),   n = 1 … N,

with ω₁ the first launch speed. :func:`measure_cor` fits ω₁ and c to the measured flights (the
intervals between successive impacts) by least squares in seconds, on the exact flight times
of the model (``paper`` by default) — not the small-flight limit T ∝ ω, which misreads c by up
to a few hundredths when the stick flies high. The interval is the fit's: c ± t(N − 2)·SE(c),
SE from the Jacobian and the residuals' variance (a regression's interval; timing errors are
alike for every impact, so the fit weighs every flight alike).

The levels cross-check it: the tip speed at impact n is c^(n−1) times the first one, and a
drum's sound grows in proportion to it, so the levels fall by 20·log10(c) dB an impact. The
Theil–Sen line of the levels (dB re the loudest) on the impacts' numbers (missed ones counted) gives
c from the levels and its interval (the median of the pairwise slopes: one misread level does not
move it). It is rougher (a drum's brightness and the mics' placement colour levels, not times).
When the two intervals lie farther apart than :data:`LEVELS_SLACK`, the result says so (:attr:`Drop.warning`), with
both values.

Which impacts: every onset is a candidate (a detector adds ringing, rattle and doubled triggers,
and may miss a quiet or merged bounce), so the impacts are chosen by the model over all of them.
Under the model a drop's impact times follow from one impact, one launch speed and c (each flight
F(c·ω) after one of F(ω); for short flights T_(n+1) ≈ c·T_n, a geometric sequence). Every three
onsets close in time (each next among the :data:`NEIGHBOURS` onsets after the one before) taken as
successive impacts give such a sequence, forwards and backwards; each of its impacts is matched to
the nearest onset within ``tolerance`` (and within :data:`SPAN_SHARE` of its flight). The sequence
scores its run of impacts (first to last matched) with the most matched ones less
:data:`MISS_COST` for each it misses; the best (ties: the smallest squared residuals) is refitted on
its matched onsets and matched again until it settles (RANSAC over triples). Onsets inside the run
not matched are *extra* (a doubled trigger, a ghost, ringing), the run's impacts without an onset
*missed* (a flight then lasts two of the model's, T_n + T_(n+1) = T_n·(1 + c) for short flights), and
c is fitted on the intervals between the matched onsets, each the sum of the model's flights it spans.
Flights shorter than :data:`MIN_FLIGHT` are not sought.

Examples
--------
>>> import numpy as np
>>> from drumstroke.stroke import simulate
>>> stroke = simulate(theta0=0.5, cor=0.8, t_end=3.0)
>>> impacts = stroke.impacts
>>> onsets = Onsets(impacts.t[:12], 20 * np.log10(impacts.tip_speed[:12] / impacts.tip_speed[0]))
>>> drop = measure_cor(onsets)
>>> round(drop.cor, 6), drop.flights, round(drop.cor_levels, 6)
(0.8, 8, 0.8)
"""

import math
from dataclasses import dataclass, field

import numpy as np

from .._checks import check_choice, check_real
from ..budget import check_time, drop_seconds
from ..errors import ParameterError
from ..model import MODELS, Stick, coefficients
from .onsets import Onsets

MIN_FLIGHT = 4e-3
"""The shortest flight sought (s): shorter ones are too few milliseconds for their times' errors."""

TOLERANCE = 5e-3
"""The default ``tolerance`` (s): how far an onset may be from the model's impact and still be it."""

SPAN_SHARE = 0.3
"""The most an onset may be from the model's impact, as a share of the shorter flight beside it (so that
one onset is never two impacts, and a bounce's doubled trigger is never the next bounce)."""

MISS_COST = 1.0
"""What a missed bounce costs a candidate sequence, in matched onsets: a sequence through ringing,
which misses most of its impacts, loses to the drop's."""

REFITTED = 20
"""How many of the best candidate sequences are refitted on their onsets before the best is chosen."""

NEIGHBOURS = 6
"""A candidate's next impact is sought among this many onsets after its last (extras between are few)."""

COR_RANGE = (0.15, 0.99)
"""The c a candidate sequence may have (a drumstick on a drum is well inside it)."""

MIN_FLIGHTS = 3
"""The fewest flights an interval is given from (two parameters are fitted)."""

CONFIDENCE = 0.95
"""The default confidence of the intervals."""


@dataclass(frozen=True)
class Drop:
    """c measured from a drop recording.

    Attributes
    ----------
    cor : float
        c, the coefficient of restitution, from the flight times (dimensionless).
    interval : tuple of float
        Its confidence interval (low, high).
    cor_levels : float
        c from the impacts' levels (the cross-check), NaN when the levels cannot tell (fewer than
        3 impacts, or levels that do not fall).
    levels_interval : tuple of float
        Its confidence interval (NaN, NaN when none).
    flights : int
        How many intervals between successive impacts were fitted (one that spans a missed bounce
        counts once).
    times : ndarray [shape=(flights + 1,)]
        The impacts used (s).
    residuals : ndarray [shape=(flights,)]
        Measured minus fitted intervals (s).
    launch_speed : float
        ω₁, the stick's angular speed just after the first impact used (rad/s).
    model : str
        The model whose exact flights were fitted.
    confidence : float
        Of both intervals.
    source : str
        The onsets' source.
    used : ndarray of int [shape=(flights + 1,)]
        The impacts' indices among the onsets.
    bounces : ndarray of int [shape=(flights + 1,)]
        Each impact's number in the drop (0 for the first used; a missed bounce's number is skipped).
    extra : ndarray of int
        The indices of the onsets between the first and the last impact that are not impacts
        (a doubled trigger, a ghost, ringing).
    missed : ndarray [shape=(bounces[-1] - flights,)]
        The fitted times (s) of the bounces no onset was found for.
    warning : str
        Empty, or why the result should not be trusted as it stands: the times' and the levels'
        c disagree by more than their intervals (both values given).
    """

    cor: float
    interval: tuple
    cor_levels: float
    levels_interval: tuple
    flights: int
    times: np.ndarray = field(repr=False)
    residuals: np.ndarray = field(repr=False)
    launch_speed: float
    model: str
    confidence: float = CONFIDENCE
    source: str = ""
    used: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64), repr=False)
    bounces: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64), repr=False)
    extra: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64), repr=False)
    missed: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    warning: str = ""

    @property
    def method(self):
        """How c and its interval were found, in words."""
        return (f"the impacts chosen among the onsets by the model over all of them (RANSAC over triples); least "
                f"squares of {self.flights} intervals between them on the {self.model} model's exact flights under "
                f"gravity (T_n = F(c^(n-1) w1)); a {self.confidence:.0%} t-interval from the fit's Jacobian; the "
                "levels' cross-check from the Theil-Sen line of the impacts' levels on their number")

    def to_dict(self):
        """Plain data for JSON (NaN as None)."""
        plain = lambda x: None if isinstance(x, float) and not math.isfinite(x) else x
        return {"cor": self.cor, "interval": list(self.interval), "confidence": self.confidence,
                "cor_levels": plain(self.cor_levels), "levels_interval": [plain(x) for x in self.levels_interval],
                "flights": self.flights, "times": self.times.tolist(), "residuals": self.residuals.tolist(),
                "used": self.used.tolist(), "bounces": self.bounces.tolist(), "extra": self.extra.tolist(),
                "missed": self.missed.tolist(), "warning": self.warning,
                "launch_speed": self.launch_speed, "model": self.model, "method": self.method,
                "source": self.source}


class _Flights:
    """F(ω), the exact flight time (s) after a launch at ω (rad/s), of one model, stick and g.

    Tabulated once (and inverted by interpolation on the increasing F) for choosing the impacts, where
    many candidate sequences are tried; :meth:`exact` for the fit.
    """

    def __init__(self, model, stick, gravity):
        coeffs = coefficients(model, stick)
        self.rate = coeffs.torque_rate(gravity, 0.0)
        self.sin_head = math.sin(coeffs.theta_max)
        # a launch at the top speed reaches the vertical (m = 1): a flight never ends
        self.top_speed = math.sqrt(2.0 * self.rate * (1.0 - self.sin_head))
        share = np.concatenate([np.geomspace(1e-7, 0.5, 1500), 1.0 - np.geomspace(0.5, 1e-9, 1500)[1:]])
        self.grid = np.concatenate([[0.0], self.top_speed * share])
        self.table = self.exact(self.grid)

    def exact(self, omega):
        """F(ω) element-wise (s)."""
        from ..solver.elliptic import flight_time

        return np.array([flight_time(float(w), self.rate, self.sin_head)[0] if w > 0.0 else 0.0
                         for w in np.atleast_1d(omega)])

    def of(self, omega):
        """F(ω) from the table (s)."""
        return np.interp(omega, self.grid, self.table)

    def launch(self, duration):
        """The launch speed (rad/s) whose flight lasts ``duration`` s, from the table."""
        return np.interp(duration, self.table, self.grid)

    def impacts(self, time, omega, cor, first, last):
        """A drop's impacts through one at ``time`` launched at ``omega``, within [first, last] s.

        Returns
        -------
        times : ndarray
            The impacts (s), in order, ending where a flight would be shorter than :data:`MIN_FLIGHT`.
        numbers : ndarray of int
            Their numbers, 0 at ``time``.
        """
        log_c = math.log(cor)
        ahead = int(max(math.log(self.launch(MIN_FLIGHT) / omega) / log_c, 0.0)) + 1
        forward = self.of(omega * np.exp(log_c * np.arange(ahead)))
        forward = forward[forward >= MIN_FLIGHT]
        behind = int(math.log(self.top_speed / omega) / -log_c)  # launches below the top speed only
        backward = self.of(omega * np.exp(-log_c * np.arange(1, behind + 1)))
        times = np.concatenate([time - np.cumsum(backward)[::-1], [time], time + np.cumsum(forward)])
        numbers = np.arange(-len(backward), len(forward) + 1)
        keep = (times >= first) & (times <= last)
        return times[keep], numbers[keep]


@dataclass(frozen=True)
class _Choice:
    """Which onsets are a drop's impacts, and the model that chose them."""

    used: np.ndarray
    bounces: np.ndarray
    extra: np.ndarray
    loudest: np.ndarray  # the onset whose level is each impact's
    score: float = -math.inf
    squares: float = math.inf
    omega: float = math.nan
    cor: float = math.nan


def drop_impacts(onsets, *, model="paper", stick=None, gravity=9.8, tolerance=TOLERANCE):
    """The indices of a drop's impacts among ``onsets`` (see the module's docstring), in time order."""
    return drop_chain(onsets, model=model, stick=stick, gravity=gravity, tolerance=tolerance)[0]


def drop_chain(onsets, *, model="paper", stick=None, gravity=9.8, tolerance=TOLERANCE):
    """A drop's impacts among ``onsets``, numbered, and the onsets among them that are not impacts.

    The choice of the module's docstring (RANSAC over triples on the model's geometric sequence of flights);
    :func:`measure_cor` and :func:`drumstroke.analysis.fit.find_suspects` both number a stroke's bounces so.

    Returns
    -------
    used : ndarray of int
        The impacts' indices among the onsets, in time order.
    bounces : ndarray of int [shape=used.shape]
        Each impact's number in the drop (0 the first used; a missed bounce's number is skipped).
    extra : ndarray of int
        The onsets between the first and the last impact that are not impacts.

    Examples
    --------
    >>> from drumstroke.stroke import simulate
    >>> t = simulate(theta0=0.5, cor=0.8, t_end=3.0).impacts.t[:10]
    >>> used, bounces, extra = drop_chain(Onsets(np.delete(np.insert(t, 3, t[2] + 0.02), 6), np.zeros(9)))
    >>> used.tolist(), bounces.tolist(), extra.tolist()   # an extra onset (3) and a missed bounce (5)
    ([0, 1, 2, 4, 5, 6, 7, 8], [0, 1, 2, 3, 4, 6, 7, 8], [3])
    """
    choice = _choose(onsets, _Flights(*_checked(model, stick, gravity)), _check_tolerance(tolerance))
    return choice.used, choice.bounces, choice.extra


def _checked(model, stick, gravity):
    check_choice("model", model, MODELS)
    stick = Stick() if stick is None else stick
    if not isinstance(stick, Stick):
        raise ParameterError(f"stick must be a Stick, got {type(stick).__name__}")
    return model, stick, check_real("gravity", gravity, low=0.0, high=100.0, low_open=True, unit="m/s^2")


def _check_tolerance(tolerance):
    return check_real("tolerance", tolerance, low=0.0, high=0.1, low_open=True, unit="s")


def _choose(onsets, flights, tolerance):
    """The best candidate sequence's impacts among ``onsets`` (the module's docstring), refitted until it settles."""
    if not isinstance(onsets, Onsets):
        raise ParameterError(f"onsets must be an Onsets, got {type(onsets).__name__}")
    t = onsets.t
    triples = triple_count(t)
    check_time(f"measuring c from {onsets.source!r}" if onsets.source else "measuring c",
               drop_seconds(triples), f"{triples} triples of {len(t)} onsets to try as a drop's impacts")
    few = np.arange(min(len(t), 2))
    candidates = {(): _Choice(few, few, np.empty(0, dtype=np.int64), few)}
    for a, b, c in _triples(t):
        omega = flights.launch(t[b] - t[a])
        cor = float(flights.launch(t[c] - t[b]) / omega)
        if COR_RANGE[0] <= cor <= COR_RANGE[1]:
            choice = _match(onsets, flights, t[a], omega, cor, tolerance)
            key = tuple(choice.used)
            if key not in candidates or _rank(choice) > _rank(candidates[key]):
                candidates[key] = choice
    # a triple's errors grow as its sequence is extrapolated: the best few are refitted before one is chosen
    best = sorted(candidates.values(), key=_rank)[-REFITTED:]
    return max((_refined(onsets, flights, choice, tolerance) for choice in best), key=_rank)


def _rank(choice):
    """Better sequences rank higher: the higher score, then more impacts matched, then the smaller residuals."""
    return choice.score, len(choice.used), -choice.squares


def _refined(onsets, flights, choice, tolerance):
    """``choice`` refitted on its matched onsets and matched again, until it no longer improves."""
    for _ in range(10):
        if len(choice.used) < 3:
            break
        time, omega, cor = _refit(onsets.t[choice.used], choice.bounces, flights, choice.omega, choice.cor)
        if not COR_RANGE[0] <= cor <= COR_RANGE[1]:
            break
        again = _match(onsets, flights, time, omega, cor, tolerance)
        if np.array_equal(again.used, choice.used) or _rank(again) < _rank(choice):
            return max(choice, again, key=_rank)
        choice = again
    return choice


def _triples(t):
    """Indices (a, b, c) of onsets that may be three successive impacts: each next among the next few."""
    for a in range(len(t)):
        for b in range(a + 1, min(a + 1 + NEIGHBOURS, len(t))):
            if t[b] - t[a] < MIN_FLIGHT:
                continue
            for c in range(b + 1, min(b + 1 + NEIGHBOURS, len(t))):
                if MIN_FLIGHT <= t[c] - t[b] < t[b] - t[a]:
                    yield a, b, c


def triple_count(t):
    """How many triples of onsets at times ``t`` (s, increasing) a drop's impacts are sought from (counted, none made).

    >>> t = np.array([0.0, 0.3, 0.5, 0.51, 0.65])
    >>> triple_count(t) == len(list(_triples(t)))
    True
    """
    total = 0
    for b in range(1, NEIGHBOURS + 1):  # b - a
        first = t[b:] - t[:-b]
        for c in range(1, min(NEIGHBOURS, len(t) - b - 1) + 1):  # c - b, with c < len(t)
            second = t[b + c:] - t[b:len(t) - c]
            total += int(np.count_nonzero((first[:len(second)] >= MIN_FLIGHT) & (second >= MIN_FLIGHT)
                                          & (second < first[:len(second)])))
    return total


def _match(onsets, flights, time, omega, cor, tolerance):
    """The model's impacts (through one at ``time``) matched to the ``onsets``; the best run of them."""
    t = onsets.t
    times, numbers = flights.impacts(time, omega, cor, t[0] - tolerance, t[-1] + tolerance)
    if len(times) < 2:
        none = np.empty(0, dtype=np.int64)
        return _Choice(none, none, none, none)
    gaps = np.diff(times)
    reach = np.minimum(tolerance, SPAN_SHARE * np.minimum(np.r_[gaps[0], gaps], np.r_[gaps, gaps[-1]]))
    after = np.clip(np.searchsorted(t, times), 1, len(t) - 1)
    nearest = np.where(np.abs(t[after] - times) < np.abs(t[after - 1] - times), after, after - 1)
    error = t[nearest] - times
    hit = np.abs(error) <= reach
    start, stop, score = _best_run(np.where(hit, 1.0, -MISS_COST))
    hit[:start] = hit[stop:] = False
    used, bounces = nearest[hit], numbers[hit]
    if not len(used):
        return _Choice(used, bounces, used, used)
    extra = np.setdiff1d(np.arange(used[0], used[-1] + 1), used)
    # an impact's doubled triggers are all within its reach: its level is their loudest's
    low = np.searchsorted(t, times[hit] - reach[hit], side="left")
    high = np.searchsorted(t, times[hit] + reach[hit], side="right")
    loudest = np.array([i + np.argmax(onsets.level_db[i:j]) for i, j in zip(low, high)], dtype=np.int64)
    # number the bounces from the first used one; its launch speed is the model's there
    return _Choice(used, bounces - bounces[0], extra, loudest, score, float(np.sum(error[hit] ** 2)),
                   float(omega * cor ** bounces[0]), cor)


def _best_run(gains):
    """(start, stop, total) of the contiguous run of ``gains`` with the largest total (Kadane's), the longest of equals.

    A run that a miss and a match extend keeps its total: the longer gives the refit more impacts.
    """
    best, total, begin = (0, 0, -math.inf), 0.0, 0
    for i, gain in enumerate(gains):
        if total < 0.0:
            total, begin = 0.0, i
        total += gain
        if total > best[2] or (total == best[2] and begin == best[0]):
            best = (begin, i + 1, total)
    return best


def _refit(times, bounces, flights, omega, cor):
    """(time s, ω, c) of bounce 0 of the model's impacts ``bounces`` fitted to ``times`` (s), on the table."""
    from scipy.optimize import least_squares

    def residuals(p):
        spans = flights.of(np.exp(p[1] + p[2] * np.arange(bounces[-1])))
        return p[0] + np.concatenate([[0.0], np.cumsum(spans)])[bounces] - times

    fit = least_squares(residuals, [times[0], math.log(omega), math.log(cor)], x_scale=[1e-3, 0.1, 0.01])
    return float(fit.x[0]), float(np.exp(fit.x[1])), float(np.exp(fit.x[2]))


def measure_cor(onsets, *, model="paper", stick=None, gravity=9.8, confidence=CONFIDENCE, tolerance=TOLERANCE):
    """c from a drop's onsets: the ratio of successive flights on the model's exact flights, and of levels.

    Parameters
    ----------
    onsets : Onsets
        A drop's impacts (:func:`drumstroke.analysis.find_recording_onsets` of its recording); other onsets
        (ringing, rattle, doubled triggers) are passed over and missed bounces allowed for (the module's
        docstring).
    model : {"paper", "geometry"}
        Whose flight times (:mod:`drumstroke.model`).
    stick : Stick or None
        The stick (default: the paper's Table 1).
    gravity : float in (0, 100]
        g (m/s²).
    confidence : float in (0, 1)
        Of the intervals.
    tolerance : float in (0, 0.1]
        How far an onset may be from the model's impact and still be it (s); at most
        :data:`SPAN_SHARE` of the flight beside it.

    Returns
    -------
    Drop

    Raises
    ------
    ParameterError
        When fewer than :data:`MIN_FLIGHTS` flights are found (naming how many impacts were).
    """
    flights = _Flights(*_checked(model, stick, gravity))
    confidence = check_real("confidence", confidence, low=0.0, high=1.0, low_open=True, high_open=True)
    choice = _choose(onsets, flights, _check_tolerance(tolerance))
    from scipy import stats  # after the budget's check: a refusal does not wait for scipy to load
    from scipy.optimize import least_squares

    times = onsets.t[choice.used]
    if len(times) < MIN_FLIGHTS + 1:
        raise ParameterError(f"a drop needs at least {MIN_FLIGHTS} flights ({MIN_FLIGHTS + 1} impacts) to measure c "
                             f"with an interval; found {len(times)} impact(s) in {onsets.source or 'the onsets'}"
                             f"{' (' + onsets.info['found'] + ')' if 'found' in onsets.info else ''}")
    measured = np.diff(times)
    n = np.arange(choice.bounces[-1])
    ends = choice.bounces

    def spans(p):
        """The model's impact times from the first (s), at every bounce."""
        return np.concatenate([[0.0], np.cumsum(flights.exact(p[0] * np.exp(n * p[1])))])

    def residuals(p):
        return np.diff(spans(p)[ends]) - measured

    start = np.array([choice.omega, math.log(choice.cor)])
    fit = least_squares(residuals, start, x_scale=np.abs(start) + 1e-3, xtol=1e-15, ftol=1e-15, gtol=1e-15)
    omega1, log_c = fit.x
    cor = float(np.exp(log_c))
    dof = len(measured) - 2
    spread = float(np.sum(fit.fun ** 2) / dof) if dof > 0 else math.nan
    jac = fit.jac
    try:
        covariance = np.linalg.inv(jac.T @ jac) * spread
        se = math.sqrt(max(covariance[1, 1], 0.0))
    except np.linalg.LinAlgError:
        se = math.inf
    quantile = float(stats.t.ppf(0.5 + confidence / 2.0, dof)) if dof > 0 else math.inf
    interval = (float(np.exp(log_c - quantile * se)), float(np.exp(log_c + quantile * se)))
    cor_levels, levels_interval = _from_levels(onsets.level_db[choice.loudest], choice.bounces, confidence)
    missed = np.setdiff1d(np.arange(ends[-1] + 1), ends)
    return Drop(cor=cor, interval=interval, cor_levels=cor_levels, levels_interval=levels_interval,
                flights=len(measured), times=times, residuals=np.asarray(fit.fun), launch_speed=float(omega1),
                model=model, confidence=confidence, source=onsets.source, used=choice.used,
                bounces=choice.bounces, extra=choice.extra, missed=times[0] + spans(fit.x)[missed],
                warning=_disagreement(cor, interval, cor_levels, levels_interval, confidence))


LEVELS_SLACK = 0.02
"""How far (in c) the levels' c may lie beyond the two intervals without a warning: their intervals hold the
levels' scatter, not how a drum colours them (its brightness, the microphone, a sample's velocity layers). On
drumstroke's own drum a drop of c = 0.8 reads 0.790 (0.788 to 0.792) from its levels; a doubled first flight
(0.737 against 0.866) or a missed bounce moves the times' c far more."""


def _disagreement(cor, interval, cor_levels, levels_interval, confidence):
    """A warning, with both values, when the times' and the levels' c disagree by more than their intervals and
    :data:`LEVELS_SLACK`."""
    if not math.isfinite(cor_levels) or (levels_interval[0] - LEVELS_SLACK <= interval[1]
                                         and interval[0] <= levels_interval[1] + LEVELS_SLACK):
        return ""
    return (f"the flights' c = {cor:.4f} ({interval[0]:.4f} to {interval[1]:.4f}) and the levels' c = "
            f"{cor_levels:.3f} ({levels_interval[0]:.3f} to {levels_interval[1]:.3f}) disagree by more than their "
            f"{confidence:.0%} intervals and the {LEVELS_SLACK:g} a drum's colouring of its levels allows: an impact "
            "may be missed, doubled or misplaced among the onsets, or the drum's level not grow with the stick's speed")


def _from_levels(levels, bounces, confidence):
    """c from the Theil-Sen line of the levels (dB) on the impacts' numbers, and its interval."""
    from scipy import stats

    if len(levels) < 3:
        return math.nan, (math.nan, math.nan)
    slope, _, low, high = stats.theilslopes(levels, bounces.astype(float), alpha=confidence)
    if not slope < 0.0:
        return math.nan, (math.nan, math.nan)
    to_cor = lambda slope: float(10.0 ** (slope / 20.0))
    return to_cor(slope), (to_cor(low), to_cor(high))
