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

from .._checks import check_choice, check_real
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
        The onsets not played (index, the reason).
    extra_t, extra_level : ndarray [shape=(m,)]
        The fitted stroke's impacts that match no onset and are at or above the detection threshold:
        s on the recording's clock, dB re the loudest onset.
    change : float
        The criterion at the fit: the relative total variation of the torque rate over the flights.
    fitted_cor : bool
        Whether c was fitted (``fit_cor``) rather than given.
    design : Design
        The inverse design behind the recipe (its notes are the onsets played, on the recording's clock).
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

    def __repr__(self):
        return (f"Fit({len(self.onsets) - len(self.unmatched)} of {len(self.onsets)} onsets, model={self.model!r}, "
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
        """Whether every onset is played within :data:`TOLERANCE` and no impact above the threshold is added."""
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
                "recipe": self.recipe.to_dict()}


def fit_stroke(onsets, *, model="paper", cor=DEFAULT_COR, fit_cor=False, offset=None, stick=None, forces=None,
               highest=None, progress=None):
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
    progress : callable, optional
        Called with the fraction done, in [0, 1].

    Returns
    -------
    Fit

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
    if len(onsets) < 2:
        raise ParameterError(f"a fit needs at least 2 onsets (a throw and a bounce), got {len(onsets)}"
                             + (" (no impacts found)" if not len(onsets) else ""))
    if len(onsets) > MAX_ONSETS:
        raise ParameterError(f"a fit takes one stroke, at most {MAX_ONSETS} onsets, got {len(onsets)}: cut the "
                             "recording to one stroke")
    search = _Search(onsets, model=model, stick=Stick() if stick is None else stick,
                     forces=FORCES if forces is None else forces, highest=highest, progress=progress)
    return search.run(cor=cor, fit_cor=fit_cor, offset=offset)


class _Search:
    """The notes tried, the onsets left out and why, and the criterion of a candidate (offset, c)."""

    def __init__(self, onsets, *, model, stick, forces, highest, progress):
        if not isinstance(stick, Stick):
            raise ParameterError(f"stick must be a drumstroke.Stick, got {stick!r}")
        if not isinstance(forces, ForceRange):
            raise ParameterError(f"forces must be a drumstroke.design.ForceRange, got {forces!r}")
        self.onsets, self.stick = onsets, stick
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
        """The fitted stroke's impacts against the onsets: residuals, onsets not played, impacts added."""
        onsets, keep = self.onsets, np.array(self.keep)
        impacts = made.impacts
        played_t, played_level = impacts.t, impacts.level_db - offset
        pairs = match_onsets(onsets.t[keep], np.maximum(played_t, 0.0), window=MATCH_WINDOW)
        time_residual = np.full(len(onsets), np.nan)
        level_residual = np.full(len(onsets), np.nan)
        left_out = dict(self.left_out)
        for onset, j in zip(keep, pairs):
            if j < 0:
                left_out[int(onset)] = f"the fitted stroke has no impact within {MATCH_WINDOW * 1e3:g} ms of it"
            else:
                time_residual[onset] = played_t[j] - onsets.t[onset]
                level_residual[onset] = played_level[j] - onsets.level_db[onset]
        extra = np.ones(len(played_t), bool)
        extra[pairs[pairs >= 0]] = False
        extra &= played_level >= onsets.threshold_db
        return Fit(made.recipe.replace(name=f"fitted to {onsets.source}" if onsets.source else "fitted"), made.stroke,
                   onsets, cor, float(offset), float(made.release), time_residual, level_residual,
                   tuple(sorted(left_out.items())), played_t[extra], played_level[extra],
                   self.change(offset, cor)[0], bool(fit_cor), made)


def _level_cor(levels):
    """c from the levels alone: the median ratio of successive impacts' speeds (a free bounce lands as it left)."""
    steps = np.diff(levels)
    return float(np.clip(10.0 ** (np.median(steps) / 20.0), *COR_RANGE)) if len(steps) else DEFAULT_COR
