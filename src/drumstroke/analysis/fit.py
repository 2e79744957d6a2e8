"""A recipe fitted to a recorded stroke: analysis by synthesis through the inverse design.

A recording gives a stroke's impacts: their times and their levels up to one gain
(:class:`~drumstroke.analysis.onsets.Onsets`, dB re the loudest). Taken as the notes of one stick,
they are what :func:`drumstroke.design.design` plays exactly: the first a throw from above, the
others consecutive bounces, each flight under one force on the way up and one on the way down. What
the recording does not say is chosen:

- **the level offset** (the loudest onset's level, dB re 1 m/s tip speed; the notes' levels are the
  onsets' plus it) and, with ``fit_cor``, **c**: those whose designed force is the *simplest*, the
  closest to constant over the stroke. The criterion is the force's relative change: the total
  variation of the torque rate C = (k·g + k′·a)/D over the flights' pieces, divided by its mean
  (time-weighted). A stroke played under one constant force is fitted at its own offset and c with
  a change of 0 (to round-off); a force that steps or ramps is fitted where its steps are least in
  proportion. Offsets whose design stays within the human thumb (0–250 m/s²) come first; among the
  others, the least beyond it (a slight pull, a < 0, only when no offset plays the onsets without
  one: :data:`FORCES`). Without ``fit_cor``, c is given (default 0.86, the paper's).
- **the start**: the stick held at rest at the height from which the first flight's rising force
  throws it onto the first onset (a stroke under one force starts where it was let go);
- **the end**: after the last onset the stick bounces on under gravity alone (a Zeno tail whose
  impacts the recording's detection would not hear) when its next impact would be below the
  onsets' detection threshold; otherwise (or when the onsets were given, not detected) it is caught
  at the apex of its last rebound, so the fit adds no impact the recording would have had.

The recipe chosen is simulated forwards by the solver, and its impacts are matched to the onsets
one to one (within :data:`MATCH_WINDOW`): per onset, the time (s) and level (dB, after the offset)
residuals. An onset the design cannot play — closer to the one before than a flight within the
forces allows, or not reachable in one chain — is left out and reported with the design's reason
(its :class:`~drumstroke.design.Unreachable` message), and so is one that looks like a false
detection (:data:`FALSE_ONSET_DB`); the model's impacts that match no onset are reported when they
are at or above the detection threshold, not when below (the tail).

Before fitting, the onsets are checked against one stick's bounces under a constant force
(:func:`find_suspects`): extra onsets, missed bounces and bounces off the trend are listed as suspects,
and ``drop_suspects`` fits without them (dropped, merged, or their bounces played on the trend);
``drop`` and ``merge`` leave out onsets by hand. What is kept is played within :data:`TOLERANCE`.

Examples
--------
>>> import numpy as np
>>> from drumstroke import Constant, Recipe, simulate
>>> truth = simulate(Recipe(force=Constant(100.0), t_end=3.0))
>>> impacts = truth.impacts
>>> loud = impacts.level_db >= impacts.level_db.max() - 30.0
>>> onsets = Onsets(impacts.t[loud], impacts.level_db[loud] - impacts.level_db.max(), threshold_db=-30.0)
>>> fit = fit_stroke(onsets, cor=0.86)
>>> fit.within, bool(abs(fit.offset - impacts.level_db.max()) < 1e-3)   # the offset found: the true one
(True, True)
>>> bool(np.nanmax(np.abs(fit.time_residual)) < 1e-6), fit.model
(True, 'paper')
"""

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar

from .._checks import check_choice, check_int, check_real
from ..design import FORCE_LIMIT, HUMAN_FORCE, ForceRange, Setup, Start, Unreachable, design, design_pieces
from ..design.chain import HIGHEST, MIN_GAP
from ..dynamics import CEILING_DB, FLOOR_DB
from ..errors import ParameterError
from ..model import MODELS, Stick, coefficients
from ..recipe import COR_RANGE, DEFAULT_COR, STANDARD_GRAVITY
from ..robot.metrics import WIDE_WINDOW, match_onsets
from ..trajectory import LEVEL_REFERENCE
from .onsets import Onsets

TOLERANCE = (2e-3, 1.0)
"""What a fit promises (s, dB): every onset it plays is within 2 ms and 1 dB of the recording's."""

MATCH_WINDOW = WIDE_WINDOW
"""s: an onset and an impact of the fitted stroke further apart than this are not paired (±10 ms)."""

FORCES = ForceRange(-HUMAN_FORCE, FORCE_LIMIT)
"""The thumb accelerations a fit may use by default (m/s²): a pull as strong as the human press, up to the design's
limit. Measured levels are noisy: where a stroke's force is near 0, a few tenths of a dB can ask a flight for a
slight pull, which the criterion chooses only when no offset plays the onsets without one."""

FALSE_ONSET_DB = 10.0
"""dB: an onset this much quieter than both onsets beside it, which only a force beyond the human thumb plays as a
bounce (and without which the criterion is less than half), is left out as a false detection."""

MAX_ONSETS = 500
"""Most onsets one fit takes: one stroke (a throw and its bounces; a 5-s buzz at 40 a second is 200)."""

LEVEL_SPAN = CEILING_DB - FLOOR_DB
"""dB: the model's levels span 48 dB (MIDI velocity 1 to 127); onsets further below the loudest are left out."""

SUSPECT_TIME = 2e-3
"""s: a bounce further than this from its stroke's trend is a suspect (:func:`find_suspects`): the fit's promise."""

SUSPECT_LEVEL = 3.0
"""dB: a bounce further than this from its stroke's trend of levels is a suspect (a drum's levels are rougher than its
times: the velocity a sample is played at, the detector's reading)."""

_WINDOW = 0.35
"""Of the expected flight: the onset nearest a bounce's expected time, and within this of it, is that bounce."""

_MOST_SUSPECT = 1.0 / 3.0
"""The largest share of suspects among the onsets: with more, the onsets follow no one constant force's trend."""

_MOST_MISSED = 3
"""Bounces missed in a row after which the trend is not followed further (the onsets after are not judged)."""

_GRID = 2.0
"""dB between the offsets tried first; the best is then refined to :data:`_XTOL`."""

_XTOL = 1e-3
"""dB (and, for c, that much in c) to which the offset and c are refined."""

_COR_GRID = 15
"""How many values of c are tried first with ``fit_cor`` (then refined)."""

_HUMAN_FIRST = 10.0
"""Added to the criterion of an offset whose forces leave the human range (plus the excess / 250 m/s²)."""


@dataclass(frozen=True, repr=False)
class Fit:
    """A recipe fitted to a recording's onsets, simulated and measured against them.

    Attributes
    ----------
    recipe : Recipe
        The fitted stroke (its t = 0 is ``release`` on the recording's clock).
    stroke : Stroke
        The recipe simulated by the solver.
    onsets : Onsets
        What was fitted.
    cor : float
        c, given or fitted (see ``fitted_cor``).
    offset : float
        dB re 1 m/s tip speed: the loudest onset's level in the model (the onsets' levels plus this).
    release : float
        s on the recording's clock: the recipe's t = 0 (the stick let go from rest).
    time_residual : ndarray [shape=(n,)]
        s, per onset: its impact's time − the onset's (NaN where none was played).
    level_residual : ndarray [shape=(n,)]
        dB, per onset: its impact's level − offset − the onset's level (NaN where none was played).
    unmatched : tuple of (int, str)
        The onsets kept but not played (index, the reason).
    extra_t, extra_level : ndarray [shape=(m,)]
        The fitted stroke's impacts that match no onset and are at or above the detection threshold:
        s on the recording's clock, dB re the loudest onset.
    change : float
        The criterion at the fit: the relative total variation of the torque rate over the flights.
    fitted_cor : bool
        Whether c was fitted (``fit_cor``) rather than given.
    design : Design
        The inverse design behind the recipe (its notes are the onsets played, on the recording's clock).
    suspects : tuple of Suspect
        The onsets the stroke's trend doubts (:func:`find_suspects`), whether dropped or not.
    dropped : tuple of (int, str)
        The onsets not fitted because they were dropped or merged (by hand, or as suspects): index, why.
    filled_t, filled_level : ndarray [shape=(k,)]
        Bounces the fit played where a missed onset was suspected (s, dB re the loudest onset): notes of
        the trend, not of the recording.
    """

    recipe: object
    stroke: object
    onsets: Onsets
    cor: float
    offset: float
    release: float
    time_residual: np.ndarray
    level_residual: np.ndarray
    unmatched: tuple
    extra_t: np.ndarray
    extra_level: np.ndarray
    change: float
    fitted_cor: bool
    design: object = field(compare=False)
    suspects: tuple = ()
    dropped: tuple = ()
    filled_t: np.ndarray = field(default_factory=lambda: np.empty(0))
    filled_level: np.ndarray = field(default_factory=lambda: np.empty(0))

    def __repr__(self):
        played = len(self.onsets) - len(self.unmatched) - len(self.dropped)
        return (f"Fit({played} of {len(self.onsets)} onsets, {len(self.dropped)} dropped, model={self.model!r}, "
                f"c={self.cor:.4g}{' (fitted)' if self.fitted_cor else ''}, offset {self.offset:.2f} dB, "
                f"errors {self.time_error:.2g} s / {self.level_error:.2g} dB, {len(self.extra_t)} extra)")

    @property
    def model(self):
        """The model that made the fitted stroke."""
        return self.recipe.model

    @property
    def played(self):
        """Which onsets the fitted stroke plays (bool) [shape=(n,)]."""
        return ~np.isnan(self.time_residual)

    @property
    def time_error(self):
        """Largest |time residual| of the onsets played (s); 0 when none."""
        played = self.time_residual[self.played]
        return float(np.abs(played).max()) if len(played) else 0.0

    @property
    def level_error(self):
        """Largest |level residual| of the onsets played (dB); 0 when none."""
        played = self.level_residual[self.played]
        return float(np.abs(played).max()) if len(played) else 0.0

    @property
    def within(self):
        """Whether every onset kept is played within :data:`TOLERANCE` and no impact above the threshold is added.

        The onsets dropped (:attr:`dropped`) are not judged; the bounces filled at suspected missed onsets are
        not counted as added."""
        return (not self.unmatched and not len(self.extra_t) and self.time_error <= TOLERANCE[0]
                and self.level_error <= TOLERANCE[1])

    @property
    def beyond_human(self):
        """Whether the fitted force leaves the human thumb's range, 0–250 m/s²."""
        return self.design.beyond_human

    def to_dict(self):
        """The fit as plain data (JSON): what was fitted, what was chosen, the residuals, the recipe."""
        def values(array):
            return [None if math.isnan(x) else float(x) for x in array]

        return {"model": self.model, "source": self.onsets.source, "cor": self.cor, "fitted_cor": self.fitted_cor,
                "offset_db": self.offset, "release": self.release, "change": self.change,
                "force_min": self.design.min_force, "force_max": self.design.max_force,
                "beyond_human": self.beyond_human, "end": self.design.end,
                "threshold_db": None if math.isinf(self.onsets.threshold_db) else self.onsets.threshold_db,
                "tolerance": {"time": TOLERANCE[0], "level": TOLERANCE[1]}, "within": self.within,
                "time_error": self.time_error, "level_error": self.level_error,
                "onsets": {"t": self.onsets.t.tolist(), "level_db": self.onsets.level_db.tolist()},
                "time_residual": values(self.time_residual), "level_residual": values(self.level_residual),
                "unmatched": [{"onset": i, "reason": reason} for i, reason in self.unmatched],
                "extra": {"t": self.extra_t.tolist(), "level_db": self.extra_level.tolist()},
                "suspects": [suspect.to_dict() for suspect in self.suspects],
                "dropped": [{"onset": i, "reason": reason} for i, reason in self.dropped],
                "filled": {"t": self.filled_t.tolist(), "level_db": self.filled_level.tolist()},
                "recipe": self.recipe.to_dict()}


@dataclass(frozen=True)
class Suspect:
    """An onset that one stick's trend of bounces doubts, and what to do with it (:func:`find_suspects`).

    Attributes
    ----------
    onset : int
        The onset's index; for ``"fill"``, the index of the onset after the missed bounce.
    action : {"drop", "merge", "fill", "replace"}
        Drop the onset (no bounce is near it); merge it into onset ``into`` (the same impact heard twice:
        that onset's time, the louder level); fill a bounce the onsets missed; or replace the onset by its
        bounce on the trend (a bounce heard off its time or level).
    reason : str
        Why, in numbers.
    t : float
        s: the onset's time; for ``"fill"``, the trend's time of the missed bounce.
    level : float
        dB re the loudest onset: the onset's level; for ``"fill"``, the trend's level of the missed bounce.
    into : int
        For ``"merge"``, the onset it merges into; else -1.
    filled : tuple of float
        For ``"fill"`` and ``"replace"``, the bounce played instead: (s, dB re the loudest onset); else ().
    """

    onset: int
    action: str
    reason: str
    t: float
    level: float
    into: int = -1
    filled: tuple = ()

    def to_dict(self):
        """The suspect as plain data (JSON)."""
        return {"onset": self.onset, "action": self.action, "reason": self.reason, "t": self.t,
                "level_db": self.level, "into": None if self.into < 0 else self.into,
                "filled": {"t": self.filled[0], "level_db": self.filled[1]} if self.filled else None}


def find_suspects(onsets, *, model="paper", stick=None, time_tolerance=SUSPECT_TIME, level_tolerance=SUSPECT_LEVEL):
    """The onsets that do not fit one stick's bounces under a constant force: extra, missed, shifted, too loud.

    Under a constant force (a drop: gravity alone) every flight lands as fast as it left, so bounce m's
    level is the first's plus 20·m·log10 c dB and its flight is the exact pendulum arc of a launch at
    c^m times the first flight's (:func:`drumstroke.solver.elliptic.flight_time`). The check:

    1. the trend of the flights: flight after an onset against the onset's time, a line by Theil–Sen's
       median of slopes (under a constant force and small flights, a flight is (1 − c)·(t∞ − t), exactly;
       median slopes let a quarter of the flights be wrong);
    2. a walk along it numbering the bounces: the onset nearest the next bounce's expected time, within
       :data:`_WINDOW` of its flight, is that bounce; onsets before it are extra (merged into their
       neighbour within :data:`MATCH_WINDOW`, a double detection; else dropped: closer than the flight the
       trend allows there), and a bounce without one is missed (filled at the trend);
    3. the exact model (the first time, first launch speed, the torque rate C and c) fitted to the numbered
       bounces by a robust least squares (soft L1 at ``time_tolerance``): a bounce further from it than
       ``time_tolerance`` is dropped (shifted), and so is one whose level is further than ``level_tolerance``
       from the levels' trend (the first's plus 20·m·log10 c, the first taken as the median).

    The check assumes one constant force: a stroke whose force changes on purpose (a low→high stroke)
    has flights off one trend that are not errors. When more than a third of the onsets are off the
    trend in time (extra, missed or shifted), none is named: the onsets follow no one constant force.
    The levels are judged only against times that follow it, however many are off.

    Parameters
    ----------
    onsets : Onsets
    model : {"paper", "geometry"}
    stick : Stick, optional
    time_tolerance : float in (0, 0.05]
        s: how far a bounce may be from the trend's time.
    level_tolerance : float in (0, 48]
        dB: how far a bounce may be from the trend's level.

    Returns
    -------
    tuple of Suspect
        In the order of the onsets; empty for fewer than 5 onsets, or when no trend holds.

    Examples
    --------
    >>> import numpy as np
    >>> from drumstroke import simulate
    >>> impacts = simulate(theta0=0.5, cor=0.86, t_end=6.0).impacts
    >>> t, level = impacts.t[:14].copy(), impacts.level_db[:14] - impacts.level_db.max()
    >>> t[5] += 0.004                                                   # a bounce heard 4 ms late
    >>> [(s.onset, s.action) for s in find_suspects(Onsets(t, level))]
    [(5, 'replace')]
    """
    if not isinstance(onsets, Onsets):
        raise ParameterError(f"onsets must be a drumstroke.analysis.Onsets, got {type(onsets).__name__}")
    check_choice("model", model, MODELS)
    stick = Stick() if stick is None else stick
    if not isinstance(stick, Stick):
        raise ParameterError(f"stick must be a drumstroke.Stick, got {stick!r}")
    time_tolerance = check_real("time_tolerance", time_tolerance, low=0.0, high=0.05, low_open=True, unit="s")
    level_tolerance = check_real("level_tolerance", level_tolerance, low=0.0, high=LEVEL_SPAN, low_open=True, unit="dB")
    if len(onsets) < 5:
        return ()
    from scipy.stats import theilslopes

    t, coeffs = onsets.t, coefficients(model, stick)
    slope, intercept = theilslopes(np.diff(t), t[:-1])[:2]
    bounces, extra, missed = _walk(t, lambda at: intercept + slope * at)
    if missed and sum(m < missed[0][0] for _, m in bounces) >= 4:  # the line drifts: trust it up to its first miss
        bounces = [(k, m) for k, m in bounces if m < missed[0][0]]
    for _ in range(2):  # the line of flights numbers the first bounces; the exact trend, all of them
        if len(bounces) < 4:
            return ()
        trend = _Trend.fitted(t[[k for k, _ in bounces]], np.array([m for _, m in bounces]), coeffs, time_tolerance)
        bounces, extra, missed = _walk(t, trend.flight_after(t[-1]))
    suspects = _extra_suspects(onsets, trend, bounces, extra) + _missed_suspects(onsets, trend, bounces, missed)
    merged = {s.onset for s in suspects if s.action == "merge"}
    off = [s for s in _off_trend(onsets, trend, bounces, time_tolerance, level_tolerance) if s.onset not in merged]
    if len(suspects) + sum("ms " in s.reason for s in off) > _MOST_SUSPECT * len(onsets):
        return ()  # the times follow no one trend; the levels, rougher, are judged only against times that do
    suspects += off
    return tuple(sorted(suspects, key=lambda s: (s.onset, s.t)))


def _walk(t, flight_after):
    """Number the bounces along a trend, ``flight_after(t)`` the flight (s) after a bounce at t (s): a list of
    (onset, bounce number), the extra onsets, and the missed bounces [(bounce number, the onset after)]."""
    bounces, extra, missed = [(0, 0)], [], []
    anchor, m, k, misses = t[0], 0, 1, 0
    while k < len(t) and misses <= _MOST_MISSED:
        flight = flight_after(anchor)
        if not flight > MIN_GAP:
            break  # the trend's end: later onsets are not judged
        off = np.abs(t[k:] - anchor - flight)
        near = np.flatnonzero(off <= _WINDOW * flight)
        if len(near):
            best = k + int(near[np.argmin(off[near])])
            extra += range(k, best)
            bounces.append((best, m + 1))
            anchor, k, misses = t[best], best + 1, 0
        elif t[k] < anchor + flight:
            extra.append(k)
            k += 1
            continue
        else:
            missed.append((m + 1, k))
            anchor, misses = anchor + flight, misses + 1
        m += 1
    return bounces, extra, [(bounce, k) for bounce, k in missed if bounce < bounces[-1][1]]


@dataclass(frozen=True)
class _Trend:
    """One stick's bounces under a constant force: the first at ``start`` (s), launched at ``launch`` (rad/s)."""

    start: float
    launch: float
    rate: float
    cor: float
    sin_head: float

    @classmethod
    def fitted(cls, times, numbers, coeffs, tolerance):
        """The trend through the bounces ``numbers`` at ``times`` (robust: soft L1 at ``tolerance`` s)."""
        from scipy.optimize import least_squares

        sin_head = math.sin(coeffs.theta_max)
        rate = coeffs.torque_rate(STANDARD_GRAVITY, 0.0)
        slope = np.polyfit(numbers[1:] - 0.5, np.log(np.diff(times) / np.diff(numbers)), 1)[0]
        cor = float(np.clip(math.exp(slope), 0.05, 0.99))
        first = (times[1] - times[0]) * (1.0 - cor) / (1.0 - cor ** (numbers[1] - numbers[0]))
        start = np.array([times[0], math.log(rate * first / 2.0), math.log(rate), math.log(cor)])

        def residuals(p):
            return cls(p[0], *np.exp(p[1:]), sin_head).at(numbers) - times

        scale = [tolerance, 0.1, 0.1, 0.01]
        fit = least_squares(residuals, start, x_scale=scale)  # near, then robust, then exact on the bounces near it
        fit = least_squares(residuals, fit.x, loss="soft_l1", f_scale=tolerance, x_scale=scale)
        inside = np.abs(fit.fun) <= tolerance
        if inside.sum() >= 4:
            times, numbers = times[inside], numbers[inside]
            fit = least_squares(residuals, fit.x, x_scale=scale, xtol=1e-12, ftol=1e-12)
        return cls(float(fit.x[0]), *map(float, np.exp(fit.x[1:])), sin_head)

    def flight_after(self, until):
        """The flight (s) after a bounce at t (s), the trend's bounce nearest t, up to the first after ``until``."""
        from ..solver.elliptic import flight_time

        times = [self.start]
        while times[-1] <= until and len(times) < 2 * MAX_ONSETS:
            times.append(times[-1] + flight_time(self.launch * self.cor ** (len(times) - 1), self.rate, self.sin_head)[0])
        times = np.array(times)
        return lambda at: float(np.diff(times)[min(int(np.argmin(np.abs(times[:-1] - at))), len(times) - 2)])

    def at(self, numbers):
        """The times (s) of bounces ``numbers`` (0 the first)."""
        from ..solver.elliptic import flight_time

        most = int(np.max(numbers))
        flights = [flight_time(self.launch * self.cor ** j, self.rate, self.sin_head)[0] for j in range(most)]
        return self.start + np.concatenate(([0.0], np.cumsum(flights)))[np.asarray(numbers)]


def _extra_suspects(onsets, trend, bounces, extra):
    """Extra onsets: merged into a bounce within :data:`MATCH_WINDOW` (the nearer the trend keeps its time), else dropped."""
    t, level = onsets.t, onsets.level_db
    index = np.array([i for i, _ in bounces])
    number = dict(bounces)
    suspects = []
    for j in extra:
        k = int(index[np.argmin(np.abs(t[index] - t[j]))])
        gap = t[j] - t[k]
        if abs(gap) <= MATCH_WINDOW:
            expected = float(trend.at([number[k]])[0])
            kept, merged = (k, j) if abs(t[k] - expected) <= abs(t[j] - expected) else (j, k)
            suspects.append(Suspect(merged, "merge", f"{abs(gap) * 1e3:.3g} ms {'after' if gap > 0 else 'before'} onset "
                                    f"{k}, one impact heard twice: merged into onset {kept} (the nearer the trend's "
                                    "time; the louder level)", float(t[merged]), float(level[merged]), kept))
        else:
            before = int(index[index < j].max()) if np.any(index < j) else k
            flight = np.diff(trend.at([number[before], number[before] + 1]))[0]
            suspects.append(Suspect(j, "drop", f"{(t[j] - t[before]) * 1e3:.4g} ms after onset {before}, closer than "
                                    f"the {flight * 1e3:.4g}-ms flight the trend allows there: an extra onset",
                                    float(t[j]), float(level[j])))
    return suspects


def _missed_suspects(onsets, trend, bounces, missed):
    """Bounces the trend has between two onsets and the onsets do not: filled at the trend's time and level."""
    levels = _level_trend(onsets, trend, bounces)
    suspects = []
    for bounce, k in missed:
        when = float(trend.at([bounce])[0])
        suspects.append(Suspect(k, "fill", f"no onset at the trend's bounce {when:.4f} s ({levels(bounce):.1f} dB) "
                                f"between onsets {k - 1} and {k}: a missed onset", when, levels(bounce),
                                filled=(when, levels(bounce))))
    return suspects


def _off_trend(onsets, trend, bounces, time_tolerance, level_tolerance):
    """Bounces further from the trend than the tolerances: replaced by the trend's, with how far."""
    t, level = onsets.t, onsets.level_db
    index, numbers = np.array([i for i, _ in bounces]), np.array([m for _, m in bounces])
    times, levels = trend.at(numbers), _level_trend(onsets, trend, bounces)
    suspects = []
    for k, m, expected in zip(index, numbers, times):
        why = []
        if abs(t[k] - expected) > time_tolerance:
            why.append(f"{abs(t[k] - expected) * 1e3:.3g} ms {'late' if t[k] > expected else 'early'} against the "
                       f"trend's bounce (more than {time_tolerance * 1e3:g} ms)")
        off = level[k] - levels(m)
        if abs(off) > level_tolerance:
            rise = " (a rise: a constant force's bounces only fall)" if k and level[k] > level[k - 1] else ""
            why.append(f"{abs(off):.3g} dB {'louder' if off > 0 else 'quieter'} than the trend's level, which falls "
                       f"{-20.0 * math.log10(trend.cor):.3g} dB a bounce{rise}")
        if why:
            suspects.append(Suspect(int(k), "replace", "; ".join(why) + ": replaced by the trend's bounce", float(t[k]),
                                    float(level[k]), filled=(float(expected), levels(m))))
    return suspects


def _level_trend(onsets, trend, bounces):
    """Bounce number → its level on the trend (dB re the loudest onset): 20·log10 c a bounce, the median's start."""
    step = 20.0 * math.log10(trend.cor)
    first = float(np.median([onsets.level_db[k] - step * m for k, m in bounces]))
    return lambda m: float(first + step * m)


def fit_stroke(onsets, *, model="paper", cor=DEFAULT_COR, fit_cor=False, offset=None, stick=None, forces=None,
               highest=None, drop=(), merge=(), drop_suspects=False, suspect_time=SUSPECT_TIME,
               suspect_level=SUSPECT_LEVEL, progress=None):
    """Fit the start, c (optionally) and the force profile whose impacts match the recorded onsets.

    Parameters
    ----------
    onsets : Onsets
        One stroke's impacts: at least 2, at most :data:`MAX_ONSETS`.
    model : {"paper", "geometry"}
    cor : float in [0, 1)
        Coefficient of restitution c, when it is not fitted.
    fit_cor : bool
        Fit c too (within :data:`~drumstroke.recipe.COR_RANGE`), by the same criterion as the offset.
    offset : float, optional
        dB re 1 m/s: the loudest onset's level, when known (e.g. from a calibrated microphone);
        default: fitted.
    stick : Stick, optional
    forces : ForceRange, optional
        The thumb accelerations the fitted force may use (m/s²; default :data:`FORCES`, −250 to 3000: the
        criterion keeps to the human 0–250 whenever an offset allows it).
    highest : float, optional
        rad, the highest the fitted stroke may take the stick (default the design's, 1.25).
    drop : sequence of int
        Onsets (indices) to leave out, e.g. those a look at the recording shows are not the stick's.
    merge : sequence of int
        Onsets i to merge with onset i + 1 (one impact heard twice): i's time, the louder level.
    drop_suspects : bool
        Fit without the suspects (:func:`find_suspects`): drop or merge them, and play a bounce where an
        onset was missed (at the trend's time and level, reported in ``filled_t``).
    suspect_time : float in (0, 0.05]
        s: how far from the trend's time a bounce is a suspect.
    suspect_level : float in (0, 48]
        dB: how far from the trend's level a bounce is a suspect.
    progress : callable, optional
        Called with the fraction done, in [0, 1].

    Returns
    -------
    Fit
        Its residuals, ``unmatched`` and ``dropped`` indexed by the onsets given; its offset is the level of
        the loudest onset given, whether fitted or not.

    Raises
    ------
    ParameterError
        Bad parameters, fewer than two onsets (or fewer than two that one stroke can play), too many.
    """
    if not isinstance(onsets, Onsets):
        raise ParameterError(f"onsets must be a drumstroke.analysis.Onsets, got {type(onsets).__name__}")
    check_choice("model", model, MODELS)
    cor = check_real("cor", cor, low=0.0, high=1.0, high_open=True)
    if offset is not None:
        offset = check_real("offset", offset, low=FLOOR_DB, high=CEILING_DB, unit="dB re 1 m/s")
    if len(onsets) > MAX_ONSETS:
        raise ParameterError(f"a fit takes one stroke, at most {MAX_ONSETS} onsets, got {len(onsets)}: cut the "
                             "recording to one stroke")
    drop = _indices("drop", drop, len(onsets))
    merge = _indices("merge", merge, len(onsets) - 1)
    check_choice("drop_suspects", drop_suspects, (True, False))
    stick = Stick() if stick is None else stick
    suspects = find_suspects(onsets, model=model, stick=stick, time_tolerance=suspect_time,
                             level_tolerance=suspect_level)
    edits = _Edits.made(onsets, drop, merge, suspects, apply=drop_suspects)
    if offset is not None:
        offset -= edits.shift
    onsets = edits.fitted
    if len(onsets) < 2:
        raise ParameterError(f"a fit needs at least 2 onsets (a throw and a bounce), got {len(onsets)}"
                             + (" (no impacts found)" if not len(onsets) else ""))
    search = _Search(edits, model=model, stick=stick, forces=FORCES if forces is None else forces, highest=highest,
                     progress=progress)
    return search.run(cor=cor, fit_cor=fit_cor, offset=offset)


class _Search:
    """The notes tried, the onsets left out and why, and the criterion of a candidate (offset, c)."""

    def __init__(self, edits, *, model, stick, forces, highest, progress):
        if not isinstance(forces, ForceRange):
            raise ParameterError(f"forces must be a drumstroke.design.ForceRange, got {forces!r}")
        self.edits, self.onsets, self.stick = edits, edits.fitted, stick
        self.setup = Setup(model=model, stick=stick, forces=forces)
        self.highest = HIGHEST if highest is None else highest
        self.coefficients = coefficients(model, stick)
        self.progress = progress or (lambda fraction: None)
        self.left_out = {}
        self.keep = self._playable()
        self._changes = {}  # (onsets kept, offset, c) → the criterion: the search asks for some again

    def _playable(self):
        """The onsets the model can take at all: within its 48 dB, at least 1 ms apart."""
        t, level = self.onsets.t, self.onsets.level_db
        keep = []
        for i in range(len(t)):
            if level[i] < -LEVEL_SPAN:
                self.left_out[i] = (f"{-level[i]:.1f} dB below the loudest onset: beyond the model's {LEVEL_SPAN:g}-dB "
                                    "range of levels")
            elif keep and t[i] - t[keep[-1]] < MIN_GAP:
                self.left_out[i] = (f"{(t[i] - t[keep[-1]]) * 1e3:.3g} ms after onset {keep[-1]}: one stick's "
                                    f"impacts are at least {MIN_GAP * 1e3:g} ms apart")
            else:
                keep.append(i)
        return keep

    # -- the criterion ---------------------------------------------------------------------------------------

    def change(self, offset, cor):
        """The criterion at ``offset`` (dB) and ``cor``: (value, the Unreachable if the design fails)."""
        key = (tuple(self.keep), float(offset), float(cor))
        if key not in self._changes:
            self._changes[key] = self._change(offset, cor)
        return self._changes[key]

    def _change(self, offset, cor):
        keep = self.keep
        levels = self.onsets.level_db[keep] + offset
        try:
            pieces, _ = design_pieces(self.onsets.t[keep], np.clip(levels, FLOOR_DB, CEILING_DB),
                                      setup=self.setup.replace(cor=cor), highest=self.highest)
        except Unreachable as error:
            return math.inf, error
        flights = [p for p in pieces if p.phase in ("rise", "fall")]
        forces = np.array([p.force for p in flights])
        rates = self.coefficients.torque_rate(STANDARD_GRAVITY, forces)
        weights = np.array([p.end - p.start for p in flights])
        mean = abs(float(np.sum(rates * weights) / np.sum(weights)))
        value = float(np.abs(np.diff(rates)).sum()) / mean if mean > 0.0 else math.inf
        beyond = max(forces.max() - HUMAN_FORCE, 0.0) + max(-forces.min(), 0.0)
        return (value + _HUMAN_FIRST + beyond / HUMAN_FORCE if beyond > 0.0 else value), None

    def bounds(self):
        """The offsets (dB) that put every onset kept within the model's levels."""
        return FLOOR_DB - float(self.onsets.level_db[self.keep].min()), CEILING_DB

    def best_offset(self, cor):
        """(criterion, offset) minimizing the criterion at ``cor``; (inf, failures) when no offset plays the notes."""
        low, high = self.bounds()
        grid = np.unique(np.append(np.arange(high, low, -_GRID), low))
        tried = [self.change(x, cor) for x in grid]
        values = np.array([value for value, _ in tried])
        if not np.isfinite(values).any():
            return math.inf, [error for _, error in tried]
        i = int(np.argmin(values))
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
        if hi - lo <= _XTOL:
            return float(values[i]), float(grid[i])
        result = minimize_scalar(lambda x: min(self.change(x, cor)[0], 1e9), bounds=(lo, hi), method="bounded",
                                 options={"xatol": _XTOL})
        if result.fun <= values[i]:
            return float(result.fun), float(result.x)
        return float(values[i]), float(grid[i])

    def drop_until_playable(self, cor):
        """Leave out, one at a time, the onset where the design fails at its best offset, until the rest play."""
        while True:
            value, found = self.best_offset(cor)
            if math.isfinite(value):
                return
            # the failure that plays most of the chain before it
            error = max(found, key=lambda e: e.note)
            self.leave_out(error.note, str(error))

    def leave_out(self, note, reason):
        onset = self.keep.pop(note)
        self.left_out[onset] = reason
        self.check_left()

    def check_left(self):
        """Raise, with the first reasons, when fewer than two onsets are left to fit."""
        if len(self.keep) < 2:
            reasons = sorted(self.left_out.items())
            shown = "; ".join(f"onset {i}: {why}" for i, why in reasons[:2])
            more = f"; and {len(reasons) - 2} more" if len(reasons) > 2 else ""
            raise ParameterError(f"no two of the {len(self.onsets)} onsets can be played as one stroke's impacts: "
                                 f"{shown}{more}")

    # -- the fit ---------------------------------------------------------------------------------------------

    def run(self, *, cor, fit_cor, offset):
        self.check_left()
        start_cor = _level_cor(self.onsets.level_db[self.keep]) if fit_cor else cor
        for _ in range(len(self.onsets)):
            if offset is None:
                self.drop_until_playable(start_cor)
            self.progress(0.1)
            if fit_cor:
                cor, offset_at = self.best_cor(offset)
            else:
                offset_at = offset if offset is not None else self.best_offset(cor)[1]
            self.progress(0.9)
            if self.false_onset(cor, offset_at, fixed=offset is not None):
                continue
            try:
                made = self.design(offset_at, cor)
            except Unreachable as error:
                self.leave_out(error.note, str(error))
                continue
            self.progress(1.0)
            return self.measure(made, offset_at, cor, fit_cor)
        raise AssertionError("unreachable: every round leaves an onset out")  # pragma: no cover

    def false_onset(self, cor, offset, *, fixed):
        """Leave out an onset that looks like a false detection; whether one was.

        An onset much quieter than both onsets beside it (:data:`FALSE_ONSET_DB`) is a bounce only if
        the thumb pulls the stick down onto it and then throws it up again: when playing it needs a force
        beyond the human thumb and leaving it out halves the criterion, it is taken for what it most
        likely is — an echo, the snares, noise — and reported as such. (The last onsets are not judged
        so: a stroke's dying bounces and noise after it look alike to the forces.)
        """
        now = self.change(offset, cor)[0]
        if now < _HUMAN_FIRST:
            return False
        levels = self.onsets.level_db[self.keep]
        n = len(self.keep)
        best = None  # (criterion, onset, why): the one whose leaving out leaves the simplest force
        for k in range(1, n - 1):
            below = min(levels[k - 1], levels[k + 1]) - levels[k]
            if below < FALSE_ONSET_DB:
                continue
            kept, self.keep = self.keep, self.keep[:k] + self.keep[k + 1:]
            value = self.change(offset, cor)[0] if fixed else self.best_offset(cor)[0]
            self.keep = kept
            if value < now / 2 and (best is None or value < best[0]):
                best = (value, k, f"{below:.1f} dB quieter than both onsets beside it")
        if best is None:
            return False
        _, k, why = best
        self.leave_out(k, f"{why}, and played only by a force beyond the human thumb: a false detection (an echo, "
                          "the snares, noise)?")
        return True

    def best_cor(self, offset):
        """(c, offset) of the least criterion over :data:`~drumstroke.recipe.COR_RANGE`, the offset given or fitted at each c."""
        def criterion(cor):
            if offset is not None:
                return min(self.change(offset, cor)[0], 1e9), offset
            value, at = self.best_offset(cor)
            return min(value, 1e9), at

        grid = np.linspace(*COR_RANGE, _COR_GRID)
        values = []
        for k, c in enumerate(grid):
            values.append(criterion(c)[0])
            self.progress(0.1 + 0.6 * (k + 1) / len(grid))
        i = int(np.argmin(values))
        if values[i] >= 1e9:
            raise ParameterError(f"no c in [{COR_RANGE[0]:g}, {COR_RANGE[1]:g}] plays the onsets as one stroke within "
                                 "the forces")
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
        result = minimize_scalar(lambda c: criterion(c)[0], bounds=(lo, hi), method="bounded",
                                 options={"xatol": _XTOL * 1e-2})
        cor = float(result.x) if result.fun <= values[i] else float(grid[i])
        return cor, criterion(cor)[1]

    def design(self, offset, cor):
        """The design of the kept onsets at ``offset`` and ``cor``: thrown by its first rising force, its tail unheard."""
        keep = self.keep
        times = self.onsets.t[keep]
        levels = np.clip(self.onsets.level_db[keep] + offset, FLOOR_DB, CEILING_DB)
        end = "catch"
        if math.isfinite(self.onsets.threshold_db) and cor > 0.0:
            next_level = self.onsets.level_db[keep[-1]] + 20.0 * math.log10(cor)
            end = "bounce" if next_level < self.onsets.threshold_db else "catch"
        options = {"setup": self.setup.replace(cor=cor), "highest": self.highest, "end": end, "drift": TOLERANCE}
        start = self.start(times, levels, cor)
        if start is not None:
            try:
                return design(times, levels, start=start, **options)
            except Unreachable:
                pass  # the plain throw below
        return design(times, levels, **options)

    def start(self, times, levels, cor):
        """Rest at the height from which the first flight's rising force throws the stick onto the first onset."""
        pieces, _ = design_pieces(times, levels, setup=self.setup.replace(cor=cor), highest=self.highest)
        rise = next(p.force for p in pieces if p.phase == "rise")
        rate = self.coefficients.torque_rate(STANDARD_GRAVITY, rise)
        speed = 10.0 ** (levels[0] / 20.0) * LEVEL_REFERENCE / self.stick.pivot_to_tip
        height = math.sin(self.stick.theta_max) + speed * speed / (2.0 * rate) if rate > 0.0 else math.inf
        if height >= math.sin(self.highest):
            return None
        return Start(float(times[0]) - 10.0, math.asin(height))

    def measure(self, made, offset, cor, fit_cor):
        """The fitted stroke's impacts against the onsets: residuals, onsets not played, impacts added.

        Measured on the onsets fitted, reported on those given (a filled bounce is not one of them)."""
        edits, onsets, keep = self.edits, self.onsets, np.array(self.keep)
        given, origin, shift = edits.given, edits.origin, edits.shift
        impacts = made.impacts
        played_t, played_level = impacts.t, impacts.level_db - offset
        pairs = match_onsets(onsets.t[keep], np.maximum(played_t, 0.0), window=MATCH_WINDOW)
        time_residual = np.full(len(given), np.nan)
        level_residual = np.full(len(given), np.nan)
        left_out = {int(origin[i]): why for i, why in self.left_out.items()}
        for onset, j in zip(keep, pairs):
            if j < 0:
                left_out[int(origin[onset])] = f"the fitted stroke has no impact within {MATCH_WINDOW * 1e3:g} ms of it"
            elif origin[onset] >= 0:
                time_residual[origin[onset]] = played_t[j] - onsets.t[onset]
                level_residual[origin[onset]] = played_level[j] - onsets.level_db[onset]
        left_out.pop(-1, None)  # a filled bounce the design could not play: not an onset of the recording
        extra = np.ones(len(played_t), bool)
        extra[pairs[pairs >= 0]] = False
        extra &= played_level >= onsets.threshold_db
        filled = origin < 0
        return Fit(made.recipe.replace(name=f"fitted to {given.source}" if given.source else "fitted"), made.stroke,
                   given, cor, float(offset + shift), float(made.release), time_residual, level_residual,
                   tuple(sorted(left_out.items())), played_t[extra], played_level[extra] - shift,
                   self.change(offset, cor)[0], bool(fit_cor), made, edits.suspects, edits.dropped,
                   onsets.t[filled], onsets.level_db[filled] - shift)


@dataclass(frozen=True)
class _Edits:
    """The onsets given, those fitted (some dropped or merged, missed bounces filled) and how they relate."""

    given: Onsets
    fitted: Onsets
    origin: np.ndarray  # per onset fitted: its index among those given; -1 for a filled bounce
    shift: float  # dB: a level fitted (re the loudest fitted) is the level given plus this
    dropped: tuple  # (index given, why)
    suspects: tuple

    @classmethod
    def made(cls, onsets, drop, merge, suspects, *, apply):
        """Drop ``drop``, merge each i of ``merge`` with i + 1, and (``apply``) act on the suspects."""
        level = onsets.level_db.copy()
        removed = {i: "dropped by hand" for i in drop}
        for i in merge:
            removed.setdefault(i + 1, f"merged by hand into onset {i}")
            level[i] = max(level[i], level[i + 1])
        acted = suspects if apply else ()
        filled = [s.filled for s in acted if s.action in ("fill", "replace")]
        for s in acted:
            if s.action != "fill" and s.onset not in removed:
                removed[s.onset] = f"a suspect: {s.reason}"
                if s.action == "merge":
                    level[s.into] = max(level[s.into], level[s.onset])
        kept = np.array([i for i in range(len(onsets)) if i not in removed], dtype=np.int64)
        t = np.concatenate((onsets.t[kept], [when for when, _ in filled]))
        levels = np.concatenate((level[kept], [loud for _, loud in filled]))
        origin = np.concatenate((kept, -np.ones(len(filled), np.int64)))
        order = np.argsort(t, kind="stable")
        shift = -float(levels.max()) if len(levels) else 0.0
        fitted = onsets if not removed and not filled else Onsets(
            t[order], levels[order] + shift, threshold_db=onsets.threshold_db + shift, source=onsets.source)
        return cls(onsets, fitted, origin[order], shift, tuple(sorted(removed.items())), tuple(suspects))


def _indices(name, values, count):
    """``values`` as a sorted tuple of distinct onset indices in [0, count)."""
    values = tuple(values) if isinstance(values, list | tuple | np.ndarray) else values
    if not isinstance(values, tuple):
        raise ParameterError(f"{name} must be a sequence of onset indices, got {values!r}")
    return tuple(sorted({check_int(f"{name}[{k}]", value, low=0, high=count - 1) for k, value in enumerate(values)}))


def _level_cor(levels):
    """c from the levels alone: the median ratio of successive impacts' speeds (a free bounce lands as it left)."""
    steps = np.diff(levels)
    return float(np.clip(10.0 ** (np.median(steps) / 20.0), *COR_RANGE)) if len(steps) else DEFAULT_COR
