"""Two strokes side by side: how many bounces, how they space out, how the volume fades.

The paper's listening test asks whether a robot's stroke sounds like a human's; this is the objective side
of that question ("how similar are the number of bounces and how the volume fades"). Each stroke is its
:class:`~.onsets.Onsets`: found in a recording, read from an onsets CSV, or a recipe's simulated impacts.

- **Aligned at the first onset.** A recording's start is arbitrary: times are compared from each
  stroke's first onset.
- **Counted above one threshold.** Audio finds impacts only above its detection threshold and a
  simulation has every bounce of its Zeno tail, so both strokes are counted above the same level re
  their own loudest: the higher of their detection thresholds and ``threshold_db`` (default
  :data:`FLOOR_DB`, −48 dB: the span of MIDI velocities 1–127, :mod:`drumstroke.dynamics`).
- **By bounce** (index k from the first onset): interval differences t_b[k+1] − t_b[k] − (t_a[k+1] −
  t_a[k]) (s) and level differences (dB), over the bounces both strokes have.
- **By time**: the level envelope (B's levels interpolated in time at A's onsets, dB) and the bounce
  rate, 1 / interval at each interval's midpoint (Hz), both interpolated onto :data:`GRID_POINTS`
  times over the span both strokes cover.

Examples
--------
>>> from drumstroke.analysis import Onsets
>>> a = Onsets([0.0, 0.1, 0.18, 0.24], [0.0, -1.3, -2.6, -3.9])
>>> b = Onsets([1.0, 1.11, 1.2, 1.27], [0.0, -1.0, -2.0, -3.0])
>>> result = compare(a, b)
>>> result.counts, [round(float(x) * 1e3, 3) for x in result.interval_difference]
((4, 4), [10.0, 10.0, 10.0])
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._checks import check_real
from ..errors import ParameterError
from .onsets import Onsets

FLOOR_DB = -48.0
"""Default level (dB re a stroke's loudest onset) above which onsets are counted: MIDI velocity 1 re 127."""

GRID_POINTS = 200
"""How many times the envelope and the bounce rate are compared at."""


@dataclass(frozen=True, repr=False)
class Comparison:
    """Stroke B against stroke A (differences are B − A).

    Attributes
    ----------
    a, b : Onsets
        The onsets compared: those at or above ``threshold_db``, times from each one's first onset (s).
    threshold_db : float
        The level both are counted above (dB re each one's loudest onset).
    interval_difference : ndarray [shape=(m - 1,)]
        B's interval minus A's, bounce by bounce (s), m = the smaller count.
    level_difference : ndarray [shape=(m,)]
        B's level minus A's, bounce by bounce (dB).
    envelope_t : ndarray [shape=(GRID_POINTS,)]
        Times from the first onset (s) where the envelopes and rates are compared (empty when a stroke
        has fewer than two onsets).
    envelope_a, envelope_b : ndarray [shape=(GRID_POINTS,)]
        Each stroke's level envelope (dB re its loudest), linear between its onsets.
    rate_a, rate_b : ndarray [shape=(GRID_POINTS,)]
        Each stroke's bounce rate (Hz), linear between its intervals' midpoints, constant beyond them.
    """

    a: Onsets
    b: Onsets
    threshold_db: float
    interval_difference: np.ndarray
    level_difference: np.ndarray
    envelope_t: np.ndarray
    envelope_a: np.ndarray
    envelope_b: np.ndarray
    rate_a: np.ndarray
    rate_b: np.ndarray

    def __repr__(self):
        return (f"Comparison({self.counts[0]} vs {self.counts[1]} onsets above {self.threshold_db:g} dB; "
                f"durations {self.durations[0]:.4g} vs {self.durations[1]:.4g} s)")

    @property
    def counts(self):
        """How many onsets each stroke has above the threshold (A, B)."""
        return len(self.a), len(self.b)

    @property
    def durations(self):
        """First to last onset of each stroke (s) (A, B)."""
        return tuple(float(s.t[-1]) if len(s) else 0.0 for s in (self.a, self.b))

    def summary(self):
        """The figures of the comparison as a plain dict (JSON-ready; times in s, levels in dB, rates in Hz)."""
        def largest(values):
            return float(np.max(np.abs(values))) if len(values) else None

        def median(values):
            return float(np.median(np.abs(values))) if len(values) else None

        def rms(values):
            return float(np.sqrt(np.mean(np.square(values)))) if len(values) else None

        return {
            "threshold_db": self.threshold_db,
            "count_a": self.counts[0], "count_b": self.counts[1],
            "count_difference": self.counts[1] - self.counts[0],
            "duration_a_s": self.durations[0], "duration_b_s": self.durations[1],
            "duration_difference_s": self.durations[1] - self.durations[0],
            "bounces_compared": len(self.level_difference),
            "interval_difference_median_s": median(self.interval_difference),
            "interval_difference_max_s": largest(self.interval_difference),
            "level_difference_median_db": median(self.level_difference),
            "level_difference_max_db": largest(self.level_difference),
            "envelope_difference_rms_db": rms(self.envelope_b - self.envelope_a),
            "rate_difference_rms_hz": rms(self.rate_b - self.rate_a),
            "source_a": self.a.source, "source_b": self.b.source,
        }


def compare(a, b, *, threshold_db=FLOOR_DB):
    """Compare stroke ``b`` with stroke ``a``: counts, intervals, levels, envelope and bounce rate.

    Parameters
    ----------
    a, b : Onsets
        The two strokes (e.g. a human's recording and the robot's, or a recording and a recipe).
    threshold_db : float in [-200, 0]
        Count onsets at or above this level (dB re each stroke's loudest); a stroke detected with a
        higher threshold raises it for both.

    Returns
    -------
    Comparison
    """
    for name, onsets in (("a", a), ("b", b)):
        if not isinstance(onsets, Onsets):
            raise ParameterError(f"{name} must be Onsets (drumstroke.analysis.Onsets), got {type(onsets).__name__}")
    threshold = max(check_real("threshold_db", threshold_db, low=-200.0, high=0.0, unit="dB"),
                    a.threshold_db, b.threshold_db)
    a, b = _counted(a, threshold), _counted(b, threshold)
    m = min(len(a), len(b))
    grid = np.linspace(0.0, min(a.t[-1], b.t[-1]), GRID_POINTS) if m >= 2 else np.empty(0)
    return Comparison(
        a=a, b=b, threshold_db=float(threshold),
        interval_difference=np.diff(b.t[:m]) - np.diff(a.t[:m]),
        level_difference=b.level_db[:m] - a.level_db[:m],
        envelope_t=grid,
        envelope_a=np.interp(grid, a.t, a.level_db) if m >= 2 else np.empty(0),
        envelope_b=np.interp(grid, b.t, b.level_db) if m >= 2 else np.empty(0),
        rate_a=_rate(a, grid), rate_b=_rate(b, grid),
    )


def stroke_onsets(path):
    """The onsets of the stroke in a file: a recipe (``.toml``, simulated), an onsets CSV or a recording.

    Parameters
    ----------
    path : str or Path
        A recipe is simulated (its impacts, exact); an onsets CSV is read (:func:`.onsets.read_onsets`);
        any other file is a recording whose impacts are found (:func:`.onsets.find_recording_onsets`).

    Returns
    -------
    Onsets
        With ``info["model"]`` the model that made a recipe's impacts.
    """
    path = Path(path)
    if path.suffix.lower() == ".toml":
        from ..recipe import Recipe
        from ..stroke import simulate

        stroke = simulate(Recipe.from_toml(path))
        onsets = Onsets.from_impacts(stroke.impacts, source=path.name)
        onsets.info["model"] = stroke.recipe.model
        return onsets
    from .onsets import find_recording_onsets, read_onsets

    return read_onsets(path) if path.suffix.lower() == ".csv" else find_recording_onsets(path)


def _counted(onsets, threshold):
    """``onsets`` at or above ``threshold`` (dB re the loudest), times from the first of them."""
    keep = onsets.level_db >= threshold
    t = onsets.t[keep]
    return Onsets(t - t[0] if len(t) else t, onsets.level_db[keep], threshold_db=threshold, source=onsets.source)


def _rate(onsets, grid):
    """Bounce rate (Hz) at ``grid``: 1 / interval at each interval's midpoint, linear between them."""
    if not len(grid):
        return np.empty(0)
    return np.interp(grid, *onsets.bounce_rate())
