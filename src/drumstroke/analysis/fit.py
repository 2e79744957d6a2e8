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
  proportion. Offsets whose design stays within the human thumb (0–250 m/s²) come first; then those
  with a slight pull (a < 0: :data:`FORCES`), the least first; then those pressing beyond 250 m/s²,
  the least beyond first (the thumb can pull; no thumb presses harder). Without ``fit_cor``, c is
  given (default 0.86, the paper's).
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
and ``drop_suspects`` fits without them (dropped, merged, or their bounces played on the trend). So
is the onset (or two successive) that alone makes the thumb press beyond the human 250 m/s² in the
fit, a level or a time read off (``_Search.beyond_press``). ``drop`` and ``merge`` leave out onsets by
hand. What is kept is played within :data:`TOLERANCE`.

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
from dataclasses import dataclass, field, replace
from itertools import pairwise

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
from .drop import TOLERANCE as DROP_TOLERANCE
from .drop import drop_chain
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

CHAIN_TOLERANCE = DROP_TOLERANCE
"""s: how far an onset may be from the sequence of bounces and still be numbered one (then judged at the time
tolerance): a bounce heard a few ms late is replaced by the trend's, not dropped with its bounce filled."""

LEVELS = ("auto", "peak", "modes")
"""The onsets' levels a fit plays (:func:`choose_levels`): their broadband ``peak`` (:attr:`Onsets.peak_db`), the
drum's lowest ``modes`` (:attr:`Onsets.level_db`), or ``auto``: the one smoother over the bounces."""

_MOST_SUSPECT = 1.0 / 3.0
"""The largest share of onsets off the sequence in time: with more, the onsets follow no one constant force's trend."""

_CURVED = 8
"""The fewest bounces whose levels' trend is a quadratic in the bounce's number (a line below)."""

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
        The onsets the stroke's trend doubts (:func:`find_suspects`), and those that alone make the thumb press
        beyond the human (action ``"drop"``), whether dropped or not.
    dropped : tuple of (int, str)
        The onsets not fitted because they were dropped or merged (by hand, or as suspects): index, why.
    filled_t, filled_level : ndarray [shape=(k,)]
        Bounces the fit played where a missed onset was suspected (s, dB re the loudest onset): notes of
        the trend, not of the recording.
    levels : {"peak", "modes"}
        Which of the recording's levels the onsets' ``level_db`` are, and were played (:func:`choose_levels`).
    levels_why : str
        Why: "given", or how they were chosen.
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
    levels: str = "modes"
    levels_why: str = ""

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
                "levels": self.levels, "levels_why": self.levels_why,
                "recipe": self.recipe.to_dict()}


@dataclass(frozen=True)
class Suspect:
    """An onset that one stick's trend of bounces doubts (:func:`find_suspects`), or that alone makes a fit's thumb
    press beyond the human (:func:`fit_stroke`), and what to do with it.

    Attributes
    ----------
    onset : int
        The onset's index; for ``"fill"``, the index of the onset after the missed bounce.
    action : {"drop", "merge", "fill", "replace"}
        Drop the onset (no bounce is near it, or it makes the thumb press beyond the human); merge it into
        onset ``into`` (the same impact heard twice: that onset's time, the louder level); fill a bounce the
        onsets missed; or replace the onset by its bounce on the trend (a bounce heard off its time or level).
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
    """The onsets that do not fit one stick's bounces under a constant force: extra, missed, shifted, off the levels.

    Under a constant force (a drop: gravity alone) every flight lands as fast as it left: each flight is
    the exact pendulum arc of a launch at c times the one before's, a geometric sequence of flights for
    small ones (:func:`drumstroke.solver.elliptic.flight_time`). The check, by time first:

    1. the bounces numbered on that sequence: :func:`drumstroke.analysis.drop.drop_chain`, the RANSAC over
       triples of onsets that :func:`~drumstroke.analysis.drop.measure_cor` chooses a drop's impacts by
       (within the larger of ``time_tolerance`` and :data:`CHAIN_TOLERANCE`): onsets off the sequence are
       *extra* (merged into a bounce within :data:`MATCH_WINDOW`, a double detection; else dropped), and a
       bounce of the sequence without an onset is *missed* (filled at the trend);
    2. the exact trend (the first bounce's time, its launch speed, the torque rate C and c) fitted to the
       numbered bounces by a robust least squares (soft L1 at ``time_tolerance``): a bounce further from it
       than ``time_tolerance`` is replaced by the trend's;
    3. the levels judged against their own trend over the bounces (:class:`_LevelTrend`: a robust quadratic
       in the bounce's number; a drum's level is not always in proportion to the speed, a sample player's
       peak is not): a bounce further than ``level_tolerance`` from it is replaced by the trend's.

    The check assumes one constant force: a stroke whose force changes on purpose (a low→high stroke)
    has flights off one trend that are not errors. When more than a third of the onsets are off the
    sequence in time (outside its run of bounces, missed or shifted), none is named: the onsets follow no
    one constant force. The levels are judged only against times that follow it.

    Parameters
    ----------
    onsets : Onsets
        Their ``level_db`` judged (give a fit's levels: :func:`choose_levels`).
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
    stick = _checked_stick(onsets, model, stick)
    time_tolerance = check_real("time_tolerance", time_tolerance, low=0.0, high=0.05, low_open=True, unit="s")
    level_tolerance = check_real("level_tolerance", level_tolerance, low=0.0, high=LEVEL_SPAN, low_open=True, unit="dB")
    bounces = _Bounces.numbered(onsets, model, stick, time_tolerance)
    if bounces is None:
        return ()
    suspects = _extra_suspects(onsets, bounces, time_tolerance) + _missed_suspects(onsets, bounces, level_tolerance)
    shifted = _shifted(onsets, bounces, time_tolerance)
    outside = sum(1 for s in suspects if s.action != "fill" and not bounces.inside(s.onset))
    if outside + len(bounces.missed) + len(shifted) > _MOST_SUSPECT * len(onsets):
        return ()  # the times follow no one trend; the levels, rougher, are judged only against times that do
    suspects += _off_trend(onsets, bounces, suspects, shifted, level_tolerance)
    return tuple(sorted(suspects, key=lambda s: (s.onset, s.t)))


def choose_levels(onsets, levels="auto", *, model="paper", stick=None):
    """Which of the onsets' two levels a fit plays (:attr:`Onsets.level_db`, the drum's lowest modes, or
    :attr:`Onsets.peak_db`, the broadband peak), and why.

    ``"auto"`` takes the smoother over the bounces :func:`find_suspects` numbers by time (the median of the
    levels' second difference over three bounces in a row): a stick's speed changes smoothly from bounce to
    bounce; the modes' level follows it on a drum like drumstroke's, a sample player's peak follows its
    velocity curve, and either is read wrong where notes overlap; the one read more consistently is the one to
    play. (A trend over the whole drop judged this before: a sample player's velocity curve bends the levels
    more than a quadratic follows, and a few close last bounces read high bent it further.)

    Parameters
    ----------
    onsets : Onsets
    levels : {"auto", "peak", "modes"}
    model, stick
        As :func:`find_suspects`.

    Returns
    -------
    onsets : Onsets
        The onsets with the levels chosen as ``level_db``.
    name : {"peak", "modes"}
    why : str

    Examples
    --------
    >>> import numpy as np
    >>> onsets = Onsets(np.arange(6) * 0.1, np.zeros(6), peak_db=np.array([0.0, -1, -2, -3, -4, -5]))
    >>> choose_levels(onsets, "peak")[0].level_db.tolist(), choose_levels(onsets, "modes")[1]
    ([0.0, -1.0, -2.0, -3.0, -4.0, -5.0], 'modes')
    """
    stick = _checked_stick(onsets, model, stick)
    check_choice("levels", levels, LEVELS)
    peak = onsets.peak_db
    if levels == "peak" and peak is None:
        raise ParameterError("levels 'peak' needs the onsets' peak levels (peak_db): these have none (given as times "
                             "and levels, or an onsets CSV without the peak_db column); use 'modes'")
    if levels == "modes" or peak is None:
        return onsets, "modes", "given" if levels == "modes" else "the onsets have no peak levels"
    if levels == "peak":
        return replace(onsets, level_db=peak), "peak", "given"
    bounces = _Bounces.numbered(onsets, model, stick, SUSPECT_TIME)
    if bounces is None:
        return onsets, "modes", "no trend of bounces to compare the two levels on"
    off = {name: bounces.level_roughness(values) for name, values in (("modes", onsets.level_db), ("peak", peak))}
    if off["peak"] is None:
        return onsets, "modes", "no three bounces in a row to compare the two levels on"
    name = "peak" if off["peak"] < off["modes"] else "modes"
    other = "modes" if name == "peak" else "peak"
    why = (f"chosen: smoother over the {len(bounces.used)} bounces, their level's slope changing {off[name]:.2g} dB "
           f"(median) from bounce to bounce against {off[other]:.2g} dB for the {other}'")
    return (replace(onsets, level_db=peak) if name == "peak" else onsets), name, why


def _checked_stick(onsets, model, stick):
    if not isinstance(onsets, Onsets):
        raise ParameterError(f"onsets must be a drumstroke.analysis.Onsets, got {type(onsets).__name__}")
    check_choice("model", model, MODELS)
    stick = Stick() if stick is None else stick
    if not isinstance(stick, Stick):
        raise ParameterError(f"stick must be a drumstroke.Stick, got {stick!r}")
    return stick


@dataclass(frozen=True)
class _Bounces:
    """The onsets numbered as one stick's bounces (:func:`~drumstroke.analysis.drop.drop_chain`) and their trend."""

    used: np.ndarray  # the bounces' onsets
    numbers: np.ndarray  # their numbers, 0 the first
    extra: np.ndarray  # the onsets off the sequence: between its bounces, before or after them
    missed: tuple  # (bounce number, the onset after it)
    trend: "_Trend"

    @classmethod
    def numbered(cls, onsets, model, stick, tolerance):
        """The bounces, or None when fewer than 4 of at least 5 onsets follow one sequence (or one no drop makes)."""
        if len(onsets) < 5:
            return None
        used, numbers, _ = drop_chain(onsets, model=model, stick=stick, tolerance=max(CHAIN_TOLERANCE, tolerance))
        if len(used) < 4:
            return None
        extra = np.setdiff1d(np.arange(len(onsets)), used)
        missed = tuple((m, int(used[np.searchsorted(numbers, m)])) for m in np.setdiff1d(np.arange(numbers[-1]), numbers))
        trend = _Trend.fitted(onsets.t[used], numbers, coefficients(model, stick), tolerance)
        return None if trend is None else cls(used, numbers, extra, missed, trend)

    def inside(self, onset):
        """Whether ``onset`` lies between the first bounce and the last."""
        return bool(self.used[0] <= onset <= self.used[-1])

    def level_trend(self, levels, tolerance):
        return _LevelTrend.fitted(self.numbers, np.asarray(levels)[self.used], tolerance)

    def level_roughness(self, levels):
        """dB: the median change of slope of ``levels`` over three successive bounces (their second difference),
        None when no three bounces in a row are numbered.

        A stick's speed changes smoothly from bounce to bounce, so a measure that reads it follows a smooth
        sequence; a global trend cannot judge this, as a sample player's velocity curve bends it more than a
        quadratic follows."""
        levels, numbers = np.asarray(levels)[self.used], self.numbers
        in_row = (numbers[2:] - numbers[:-2]) == 2
        if not in_row.any():
            return None
        second = levels[2:] - 2.0 * levels[1:-1] + levels[:-2]
        return float(np.median(np.abs(second[in_row])))


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
        """The trend through the bounces ``numbers`` at ``times`` (robust: soft L1 at ``tolerance`` s); None when its
        start is no drop (a first flight so long that gravity's launch for it goes over the top)."""
        from scipy.optimize import least_squares

        sin_head = math.sin(coeffs.theta_max)
        rate = coeffs.torque_rate(STANDARD_GRAVITY, 0.0)
        slope = np.polyfit(numbers[1:] - 0.5, np.log(np.diff(times) / np.diff(numbers)), 1)[0]
        cor = float(np.clip(math.exp(slope), 0.05, 0.99))
        first = (times[1] - times[0]) * (1.0 - cor) / (1.0 - cor ** (numbers[1] - numbers[0]))
        start = np.array([times[0], math.log(rate * first / 2.0), math.log(rate), math.log(cor)])

        def residuals(p):
            return cls(p[0], *np.exp(p[1:]), sin_head).at(numbers) - times

        if not np.all(np.isfinite(residuals(start))):
            return None
        scale = [tolerance, 0.1, 0.1, 0.01]
        fit = least_squares(residuals, start, x_scale=scale)  # near, then robust, then exact on the bounces near it
        fit = least_squares(residuals, fit.x, loss="soft_l1", f_scale=tolerance, x_scale=scale)
        inside = np.abs(fit.fun) <= tolerance
        if inside.sum() >= 4:
            times, numbers = times[inside], numbers[inside]
            fit = least_squares(residuals, fit.x, x_scale=scale, xtol=1e-12, ftol=1e-12)
        return cls(float(fit.x[0]), *map(float, np.exp(fit.x[1:])), sin_head)

    def times(self, until):
        """The trend's bounces (s) from the first to the first after ``until`` (or to its flights' end)."""
        from ..solver.elliptic import flight_time

        times = [self.start]
        while times[-1] <= until and len(times) < 2 * MAX_ONSETS:
            flight = flight_time(self.launch * self.cor ** (len(times) - 1), self.rate, self.sin_head)[0]
            if not flight > MIN_GAP:
                break
            times.append(times[-1] + flight)
        return np.array(times)

    def at(self, numbers):
        """The times (s) of bounces ``numbers`` (0 the first)."""
        from ..solver.elliptic import flight_time

        most = int(np.max(numbers))
        flights = [flight_time(self.launch * self.cor ** j, self.rate, self.sin_head)[0] for j in range(most)]
        return self.start + np.concatenate(([0.0], np.cumsum(flights)))[np.asarray(numbers)]


@dataclass(frozen=True)
class _LevelTrend:
    """The bounces' levels (dB) on their numbers: a quadratic (a line below :data:`_CURVED` bounces), fitted
    robustly (soft L1 at the tolerance, then least squares on the bounces within it), evaluated by calling it."""

    coefficients: tuple

    @classmethod
    def fitted(cls, numbers, levels, tolerance):
        from scipy.optimize import least_squares

        x = numbers.astype(float)
        degree = 2 if len(x) >= _CURVED else 1
        start = np.polyfit(x, levels, degree)
        robust = least_squares(lambda p: np.polyval(p, x) - levels, start, loss="soft_l1", f_scale=tolerance)
        inside = np.abs(robust.fun) <= tolerance
        p = np.polyfit(x[inside], levels[inside], degree) if inside.sum() > degree + 2 else robust.x
        return cls(tuple(map(float, p)))

    def __call__(self, number):
        return np.polyval(self.coefficients, number)


def _extra_suspects(onsets, bounces, tolerance):
    """Onsets off the sequence: merged into a bounce within :data:`MATCH_WINDOW` (the nearer the trend keeps its
    time), else dropped."""
    t, level = onsets.t, onsets.level_db
    index, trend = bounces.used, bounces.trend
    number = dict(zip(index.tolist(), bounces.numbers.tolist()))
    expected = trend.times(t[-1])
    suspects = []
    for j in bounces.extra:
        k = int(index[np.argmin(np.abs(t[index] - t[j]))])
        gap = t[j] - t[k]
        if abs(gap) <= MATCH_WINDOW:
            at = float(trend.at([number[k]])[0])
            kept, merged = (k, j) if abs(t[k] - at) <= abs(t[j] - at) else (j, k)
            suspects.append(Suspect(int(merged), "merge", f"{abs(gap) * 1e3:.3g} ms {'after' if gap > 0 else 'before'} "
                                    f"onset {k}, one impact heard twice: merged into onset {kept} (the nearer the "
                                    "trend's time; the louder level)", float(t[merged]), float(level[merged]), int(kept)))
        else:
            off = float(np.min(np.abs(expected - t[j])))
            where = (f"{(t[j] - t[k]) * 1e3:.4g} ms {'after' if gap > 0 else 'before'} onset {k}, "
                     f"{off * 1e3:.3g} ms from the trend's nearest bounce")
            suspects.append(Suspect(int(j), "drop", f"{where}: off the sequence of bounces by more than "
                                    f"{tolerance * 1e3:g} ms, an extra onset", float(t[j]), float(level[j])))
    return suspects


def _missed_suspects(onsets, bounces, tolerance):
    """Bounces the trend has between two onsets and the onsets do not: filled at the trend's time and level."""
    levels = bounces.level_trend(onsets.level_db, tolerance)
    suspects = []
    for bounce, k in bounces.missed:
        when, loud = float(bounces.trend.at([bounce])[0]), float(levels(bounce))
        suspects.append(Suspect(k, "fill", f"no onset at the trend's bounce {when:.4f} s ({loud:.1f} dB) between "
                                f"onsets {k - 1} and {k}: a missed onset", when, loud, filled=(when, loud)))
    return suspects


def _shifted(onsets, bounces, tolerance):
    """{bounce's onset: why} of the bounces further than ``tolerance`` (s) from the trend's time."""
    off = onsets.t[bounces.used] - bounces.trend.at(bounces.numbers)
    return {int(k): f"{abs(d) * 1e3:.3g} ms {'late' if d > 0 else 'early'} against the trend's bounce (more than "
                    f"{tolerance * 1e3:g} ms)" for k, d in zip(bounces.used, off) if abs(d) > tolerance}


def _off_trend(onsets, bounces, suspects, shifted, tolerance):
    """Bounces off the trend in time (``shifted``) or further than ``tolerance`` (dB) from the levels' trend, their
    level the louder of a merge: replaced by the trend's bounce."""
    level = onsets.level_db.copy()
    merged = set()
    for s in suspects:
        if s.action == "merge":
            level[s.into] = max(level[s.into], level[s.onset])
            merged.add(s.onset)
    trend = bounces.level_trend(level, tolerance)
    times = bounces.trend.at(bounces.numbers)
    cor_db = -20.0 * math.log10(bounces.trend.cor)
    replaced = []
    for k, m, expected in zip(bounces.used.tolist(), bounces.numbers.tolist(), times):
        if k in merged:
            continue
        why = [shifted[k]] if k in shifted else []
        off = level[k] - float(trend(m))
        if abs(off) > tolerance:
            why.append(f"{abs(off):.3g} dB {'louder' if off > 0 else 'quieter'} than the levels' trend (more than "
                       f"{tolerance:g} dB; the times' c falls {cor_db:.3g} dB a bounce)")
        if why:
            replaced.append(Suspect(k, "replace", "; ".join(why) + ": replaced by the trend's bounce",
                                    float(onsets.t[k]), float(onsets.level_db[k]),
                                    filled=(float(expected), float(trend(m)))))
    return replaced


def fit_stroke(onsets, *, model="paper", cor=DEFAULT_COR, fit_cor=False, offset=None, stick=None, forces=None,
               highest=None, drop=(), merge=(), drop_suspects=False, suspect_time=SUSPECT_TIME,
               suspect_level=SUSPECT_LEVEL, levels="auto", progress=None):
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
        onset was missed (at the trend's time and level, reported in ``filled_t``); and without the onset
        (or two successive) that alone makes the thumb press beyond :data:`~drumstroke.design.HUMAN_FORCE`
        (named among the suspects, with the forces with it and without, whether dropped or not).
    suspect_time : float in (0, 0.05]
        s: how far from the trend's time a bounce is a suspect.
    suspect_level : float in (0, 48]
        dB: how far from the trend's level a bounce is a suspect.
    levels : {"auto", "peak", "modes"}
        Which of the onsets' levels to play (:func:`choose_levels`): the broadband peak, the drum's lowest modes,
        or the one smoother over the bounces (the levels' second difference).
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
    stick = _checked_stick(onsets, model, stick)
    cor = check_real("cor", cor, low=0.0, high=1.0, high_open=True)
    if offset is not None:
        offset = check_real("offset", offset, low=FLOOR_DB, high=CEILING_DB, unit="dB re 1 m/s")
    if len(onsets) > MAX_ONSETS:
        raise ParameterError(f"a fit takes one stroke, at most {MAX_ONSETS} onsets, got {len(onsets)}: cut the "
                             "recording to one stroke")
    drop = _indices("drop", drop, len(onsets))
    merge = _indices("merge", merge, len(onsets) - 1)
    check_choice("drop_suspects", drop_suspects, (True, False))
    onsets, measure, why = choose_levels(onsets, levels, model=model, stick=stick)
    suspects = find_suspects(onsets, model=model, stick=stick, time_tolerance=suspect_time,
                             level_tolerance=suspect_level)
    edits = _Edits.made(onsets, drop, merge, suspects, apply=drop_suspects, measure=(measure, why))
    if offset is not None:
        offset -= edits.shift
    onsets = edits.fitted
    if len(onsets) < 2:
        raise ParameterError(f"a fit needs at least 2 onsets (a throw and a bounce), got {len(onsets)}"
                             + (" (no impacts found)" if not len(onsets) else ""))
    search = _Search(edits, model=model, stick=stick, forces=FORCES if forces is None else forces, highest=highest,
                     drop_beyond=drop_suspects, progress=progress)
    return search.run(cor=cor, fit_cor=fit_cor, offset=offset)


class _Search:
    """The notes tried, the onsets left out and why, and the criterion of a candidate (offset, c)."""

    def __init__(self, edits, *, model, stick, forces, highest, progress, drop_beyond=False):
        if not isinstance(forces, ForceRange):
            raise ParameterError(f"forces must be a drumstroke.design.ForceRange, got {forces!r}")
        self.edits, self.onsets, self.stick = edits, edits.fitted, stick
        self.setup = Setup(model=model, stick=stick, forces=forces)
        self.highest = HIGHEST if highest is None else highest
        self.coefficients = coefficients(model, stick)
        self.progress = progress or (lambda fraction: None)
        self.left_out = {}
        self.drop_beyond = drop_beyond
        self.beyond = {}  # onset fitted → why it alone makes the thumb press beyond the human (:meth:`beyond_press`)
        self.keep = self._playable()
        self._changes = {}  # (onsets kept, offset, c) → (criterion, failure, forces' range): asked for again

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
        return self._changed(offset, cor)[:2]

    def forces(self, offset, cor):
        """The least and the largest force (m/s²) of the design at ``offset`` and ``cor`` (NaN when it fails)."""
        return self._changed(offset, cor)[2]

    def _changed(self, offset, cor):
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
            return math.inf, error, (math.nan, math.nan)
        flights = [p for p in pieces if p.phase in ("rise", "fall")]
        forces = np.array([p.force for p in flights])
        rates = self.coefficients.torque_rate(STANDARD_GRAVITY, forces)
        weights = np.array([p.end - p.start for p in flights])
        mean = abs(float(np.sum(rates * weights) / np.sum(weights)))
        value = float(np.abs(np.diff(rates)).sum()) / mean if mean > 0.0 else math.inf
        span = (float(forces.min()), float(forces.max()))
        pull, press = max(-span[0], 0.0), max(span[1] - HUMAN_FORCE, 0.0)
        if pull or press:  # a pull before a press beyond the thumb, each the less the better
            value += _HUMAN_FIRST * (1 + (press > 0.0)) + (pull + press) / HUMAN_FORCE
        return value, None, span

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
            if self.beyond_press(cor, offset_at, fixed=offset is not None):
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

    def beyond_press(self, cor, offset, *, fixed):
        """Name the onsets that alone make the thumb press beyond the human, and (``drop_beyond``) leave them out;
        whether any were left out.

        Where the design at the best offset presses harder than :data:`~drumstroke.design.HUMAN_FORCE` (no offset
        plays the onsets kept without it: the criterion prefers a pull), the one onset whose leaving out brings
        the press within it with the least criterion (the simplest force then) is named a suspect, with the
        forces with it and without; failing one, the two successive onsets that do (two close bounces read
        together, their levels a few dB off). Most often a level read a dB off or a time a sample off asks
        two flights for opposite forces (the generalisation of :meth:`false_onset`, whatever the onset's level).
        The first and the last onsets are not tried (the throw; the dying bounces), nor a filled bounce (not the
        recording's); none is named when no such onset or pair does it, or only two onsets would be left.
        """
        if len(self.keep) < 4 or (self.beyond and not self.drop_beyond):
            return False
        low, high = self.forces(offset, cor)
        if not high > HUMAN_FORCE:
            return False
        inner = [k for k in range(1, len(self.keep) - 1) if self.edits.origin[self.keep[k]] >= 0]
        for tried in ([(k,) for k in inner], list(pairwise(inner))):
            best = None  # (criterion, positions left out, the forces without them)
            for out in tried:
                kept, self.keep = self.keep, [i for k, i in enumerate(self.keep) if k not in out]
                value, at = (self.change(offset, cor)[0], offset) if fixed else self.best_offset(cor)
                span = self.forces(at, cor) if math.isfinite(value) else None
                self.keep = kept
                if span is not None and span[1] <= HUMAN_FORCE and (best is None or value < best[0]):
                    best = (value, out, span)
            if best is not None:
                break
        else:
            return False
        _, out, span = best
        names = " and ".join(str(int(self.edits.origin[self.keep[k]])) for k in out)
        why = (f"the forces {low:.4g} to {high:.4g} m/s^2 with {'it' if len(out) == 1 else f'onsets {names}'}, "
               f"{span[0]:.4g} to {span[1]:.4g} without: {'it alone makes' if len(out) == 1 else 'they make'} the "
               f"thumb press beyond the human {HUMAN_FORCE:g} m/s^2 (a level or a time read off?)")
        for k in out:
            self.beyond[self.keep[k]] = why
        if not self.drop_beyond:
            return False
        self.keep = [i for k, i in enumerate(self.keep) if k not in out]
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
        beyond = [Suspect(int(origin[i]), "drop", why, float(given.t[origin[i]]), float(given.level_db[origin[i]]))
                  for i, why in self.beyond.items()]
        suspects = tuple(sorted(edits.suspects + tuple(beyond), key=lambda s: (s.onset, s.t)))
        dropped = edits.dropped + tuple((s.onset, f"a suspect: {s.reason}") for s in beyond if self.drop_beyond)
        return Fit(made.recipe.replace(name=f"fitted to {given.source}" if given.source else "fitted"), made.stroke,
                   given, cor, float(offset + shift), float(made.release), time_residual, level_residual,
                   tuple(sorted(left_out.items())), played_t[extra], played_level[extra] - shift,
                   self.change(offset, cor)[0], bool(fit_cor), made, suspects, tuple(sorted(dropped)),
                   onsets.t[filled], onsets.level_db[filled] - shift, *edits.measure)


@dataclass(frozen=True)
class _Edits:
    """The onsets given, those fitted (some dropped or merged, missed bounces filled) and how they relate."""

    given: Onsets
    fitted: Onsets
    origin: np.ndarray  # per onset fitted: its index among those given; -1 for a filled bounce
    shift: float  # dB: a level fitted (re the loudest fitted) is the level given plus this
    dropped: tuple  # (index given, why)
    suspects: tuple
    measure: tuple  # which of the onsets' levels are played, and why: (name, why)

    @classmethod
    def made(cls, onsets, drop, merge, suspects, *, apply, measure=("modes", "given")):
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
        return cls(onsets, fitted, origin[order], shift, tuple(sorted(removed.items())), tuple(suspects), measure)


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
