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
regression of the levels (dB re the loudest) on n gives c from the levels and its interval.
It is rougher (a drum's brightness and the mics' placement colour levels, not times).

Which impacts: a drop's first impact is its first onset within :data:`START_DB` of the loudest;
each next one is the loudest onset between 0.2 and 1.1 times the previous flight after it and at
most :data:`STEP_DB` quieter (a bounce never lasts longer than the one before; ringing and
rattle detected as onsets are quieter than the impact they follow). The sequence ends at the
first flight without one, or shorter than :data:`MIN_FLIGHT`.

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
from ..errors import ParameterError
from ..model import MODELS, Stick, coefficients
from .onsets import Onsets

MIN_FLIGHT = 4e-3
"""The shortest flight used (s): shorter ones are too few milliseconds for their times' errors."""

START_DB = 3.0
"""A drop starts at its first onset within this of the loudest (dB): the first impact, read a little low or not."""

STEP_DB = 15.0
"""The most a drop's impact may be quieter than the one before (dB; c ≥ 0.18): quieter onsets are not its impacts."""

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
        How many flights were used.
    times : ndarray [shape=(flights + 1,)]
        The impacts used (s).
    residuals : ndarray [shape=(flights,)]
        Measured minus fitted flight times (s).
    launch_speed : float
        ω₁, the stick's angular speed just after the first impact used (rad/s).
    model : str
        The model whose exact flights were fitted.
    confidence : float
        Of both intervals.
    source : str
        The onsets' source.
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

    @property
    def method(self):
        """How c and its interval were found, in words."""
        return (f"least squares of {self.flights} flight times on the {self.model} model's exact flights under "
                f"gravity (T_n = F(c^(n-1) w1)); a {self.confidence:.0%} t-interval from the fit's Jacobian; the "
                "levels' cross-check from the regression of the impacts' levels on their number")

    def to_dict(self):
        """Plain data for JSON (NaN as None)."""
        plain = lambda x: None if isinstance(x, float) and not math.isfinite(x) else x
        return {"cor": self.cor, "interval": list(self.interval), "confidence": self.confidence,
                "cor_levels": plain(self.cor_levels), "levels_interval": [plain(x) for x in self.levels_interval],
                "flights": self.flights, "times": self.times.tolist(), "residuals": self.residuals.tolist(),
                "launch_speed": self.launch_speed, "model": self.model, "method": self.method,
                "source": self.source}


def drop_impacts(onsets):
    """The indices of a drop's impacts among ``onsets`` (see the module's docstring), in time order."""
    if not isinstance(onsets, Onsets):
        raise ParameterError(f"onsets must be an Onsets, got {type(onsets).__name__}")
    if len(onsets) == 0:
        return np.empty(0, dtype=np.int64)
    t, level = onsets.t, onsets.level_db
    chosen = [int(np.flatnonzero(level >= -START_DB)[0])]
    previous = None
    while True:
        last = t[chosen[-1]]
        low, high = (MIN_FLIGHT, np.inf) if previous is None else (0.2 * previous, 1.1 * previous)
        window = np.flatnonzero((t >= last + max(low, MIN_FLIGHT)) & (t <= last + high)
                                & (level >= level[chosen[-1]] - STEP_DB))
        if not len(window):
            break
        best = int(window[np.argmax(level[window])])
        previous = t[best] - last
        chosen.append(best)
    return np.array(chosen, dtype=np.int64)


def measure_cor(onsets, *, model="paper", stick=None, gravity=9.8, confidence=CONFIDENCE):
    """c from a drop's onsets: the ratio of successive flights on the model's exact flights, and of levels.

    Parameters
    ----------
    onsets : Onsets
        A drop's impacts (:func:`drumstroke.analysis.find_recording_onsets` of its recording); other onsets
        (ringing, rattle) are passed over (:func:`drop_impacts`).
    model : {"paper", "geometry"}
        Whose flight times (:mod:`drumstroke.model`).
    stick : Stick or None
        The stick (default: the paper's Table 1).
    gravity : float in (0, 100]
        g (m/s²).
    confidence : float in (0, 1)
        Of the intervals.

    Returns
    -------
    Drop

    Raises
    ------
    ParameterError
        When fewer than :data:`MIN_FLIGHTS` flights are found (naming how many impacts were).
    """
    from scipy import stats
    from scipy.optimize import least_squares

    check_choice("model", model, MODELS)
    stick = Stick() if stick is None else stick
    if not isinstance(stick, Stick):
        raise ParameterError(f"stick must be a Stick, got {type(stick).__name__}")
    gravity = check_real("gravity", gravity, low=0.0, high=100.0, low_open=True, unit="m/s^2")
    confidence = check_real("confidence", confidence, low=0.0, high=1.0, low_open=True, high_open=True)
    index = drop_impacts(onsets)
    times = onsets.t[index]
    flights = np.diff(times)
    if len(flights) and np.any(flights < MIN_FLIGHT):
        cut = int(np.argmax(flights < MIN_FLIGHT))
        index, times, flights = index[:cut + 1], times[:cut + 1], flights[:cut]
    if len(flights) < MIN_FLIGHTS:
        raise ParameterError(f"a drop needs at least {MIN_FLIGHTS} flights ({MIN_FLIGHTS + 1} impacts) to measure c "
                             f"with an interval; found {len(times)} impact(s) in {onsets.source or 'the onsets'}"
                             f"{' (' + onsets.info['found'] + ')' if 'found' in onsets.info else ''}")
    coeffs = coefficients(model, stick)
    rate = coeffs.torque_rate(gravity, 0.0)
    sin_head = math.sin(coeffs.theta_max)
    flight = _flight_times(rate, sin_head)
    n = np.arange(len(flights))

    def residuals(p):
        return flight(p[0] * np.exp(n * p[1])) - flights

    slope = np.polyfit(n, np.log(flights), 1)[0]
    start = np.array([_launch_for(flights[0], flight), slope])
    fit = least_squares(residuals, start, x_scale=np.abs(start) + 1e-3, xtol=1e-15, ftol=1e-15, gtol=1e-15)
    omega1, log_c = fit.x
    cor = float(np.exp(log_c))
    dof = len(flights) - 2
    spread = float(np.sum(fit.fun ** 2) / dof) if dof > 0 else math.nan
    jac = fit.jac
    try:
        covariance = np.linalg.inv(jac.T @ jac) * spread
        se = math.sqrt(max(covariance[1, 1], 0.0))
    except np.linalg.LinAlgError:
        se = math.inf
    quantile = float(stats.t.ppf(0.5 + confidence / 2.0, dof)) if dof > 0 else math.inf
    interval = (float(np.exp(log_c - quantile * se)), float(np.exp(log_c + quantile * se)))
    cor_levels, levels_interval = _from_levels(onsets.level_db[index], confidence)
    return Drop(cor=cor, interval=interval, cor_levels=cor_levels, levels_interval=levels_interval,
                flights=len(flights), times=times, residuals=np.asarray(fit.fun), launch_speed=float(omega1),
                model=model, confidence=confidence, source=onsets.source)


def _flight_times(rate, sin_head):
    """F(ω): the flight time (s) after a launch at ω (rad/s) under gravity's torque rate, element-wise."""
    from ..solver.elliptic import flight_time

    def flight(omega):
        return np.array([flight_time(float(w), rate, sin_head)[0] if w > 0.0 else 0.0 for w in np.atleast_1d(omega)])

    return flight


def _launch_for(duration, flight):
    """The launch speed (rad/s) whose flight lasts ``duration`` s (bisection on the increasing F)."""
    low, high = 0.0, 1.0
    while flight(high)[0] < duration and high < 1e4:
        high *= 2.0
    for _ in range(200):
        middle = 0.5 * (low + high)
        if flight(middle)[0] < duration:
            low = middle
        else:
            high = middle
    return 0.5 * (low + high)


def _from_levels(levels, confidence):
    """c from the regression of the levels (dB) on the impact's number, and its interval."""
    from scipy import stats

    if len(levels) < 3:
        return math.nan, (math.nan, math.nan)
    n = np.arange(len(levels), dtype=float)
    result = stats.linregress(n, levels)
    if not result.slope < 0.0:
        return math.nan, (math.nan, math.nan)
    quantile = float(stats.t.ppf(0.5 + confidence / 2.0, len(levels) - 2))
    to_cor = lambda slope: float(10.0 ** (slope / 20.0))
    return to_cor(result.slope), (to_cor(result.slope - quantile * result.stderr),
                                  to_cor(result.slope + quantile * result.stderr))
