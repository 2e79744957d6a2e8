"""Two strokes side by side: how many bounces, how they space out, how the volume fades.

The paper's listening test asks whether a robot's stroke sounds like a human's; this is the objective side
of that question ("how similar are the number of bounces and how the volume fades"). Each stroke is its
:class:`~.onsets.Onsets`: found in a recording, read from an onsets CSV, or a recipe's simulated impacts.

- **Aligned at the first onset.** A recording's start is arbitrary: times are compared from each
  stroke's first onset, the stroke's first impact (its loudest and most surely found). Not at the
  shift that matches the most bounces: once the intervals of a bouncing stroke's tail fall below the
  window, any shift that lays one tail over the other matches most of them, however far apart the
  first impacts are.
- **Counted above one threshold.** Audio finds impacts only above its detection threshold and a
  simulation has every bounce of its Zeno tail, so both strokes are counted above the same level re
  their own loudest: the higher of their detection thresholds and ``threshold_db`` (default
  :data:`FLOOR_DB`, −48 dB: the span of MIDI velocities 1–127, :mod:`drumstroke.dynamics`).
- **Bounces paired by their times**, not by their index (one extra onset would shift every pair
  after it): a maximum one-to-one matching of A's and B's onsets at most ``window`` apart (default
  :data:`WINDOW`, ±10 ms), as ``mir_eval.util.match_events`` matches events, and among the maximum
  matchings the one with the least total |t_b − t_a| (:func:`drumstroke.robot.metrics.match_onsets`).
  The onsets left without a partner are each stroke's unmatched bounces.
- **By pair** (the matched pairs in time order): time differences t_b − t_a (s), level differences
  (dB), and interval differences between successive pairs, t_b[j'] − t_b[j] − (t_a[i'] − t_a[i]) (s),
  so an unmatched onset between two pairs changes nothing.
- **By time**: the level envelope (B's levels interpolated in time at A's onsets, dB) and the bounce
  rate, 1 / interval at each interval's midpoint (Hz), both interpolated onto :data:`GRID_POINTS`
  times over the span both strokes cover.

Examples
--------
>>> from drumstroke.analysis import Onsets
>>> a = Onsets([0.0, 0.1, 0.18, 0.24], [0.0, -1.3, -2.6, -3.9])
>>> b = Onsets([1.0, 1.11, 1.2, 1.27], [0.0, -1.0, -2.0, -3.0])
>>> result = compare(a, b)  # B drifts 10 ms a bounce: beyond ±10 ms after the first pair
>>> result.counts, result.pairs.tolist(), result.unmatched_b.tolist()
((4, 4), [[0, 0]], [1, 2, 3])
>>> result = compare(a, b, window=0.05)
>>> [round(float(x) * 1e3, 3) for x in result.interval_difference]
[10.0, 10.0, 10.0]
>>> extra = Onsets([0.0, 0.05, 0.1, 0.18, 0.24], [0.0, -20.0, -1.3, -2.6, -3.9])
>>> result = compare(a, extra)
>>> result.pairs.tolist(), result.unmatched_a.tolist(), result.unmatched_b.tolist()
([[0, 0], [1, 2], [2, 3], [3, 4]], [], [1])
>>> result.time_difference.tolist(), result.level_difference.tolist()
([0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0])
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._checks import check_real
from ..errors import ParameterError
from ..robot.metrics import WIDE_WINDOW, match_onsets
from .onsets import Onsets

FLOOR_DB = -48.0
"""Default level (dB re a stroke's loudest onset) above which onsets are counted: MIDI velocity 1 re 127."""

WINDOW = WIDE_WINDOW
"""Default matching window (s): bounces pair at most ±10 ms apart, about what a listener hears as on time."""

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
    window : float
        How far apart (s) two onsets may be and still pair.
    pairs : ndarray of int [shape=(m, 2)]
        The matched bounces in time order: (index in ``a``, index in ``b``).
    unmatched_a, unmatched_b : ndarray of int
        The indices of each stroke's onsets that pair with none of the other's.
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
    window: float
    pairs: np.ndarray
    unmatched_a: np.ndarray
    unmatched_b: np.ndarray
    envelope_t: np.ndarray
    envelope_a: np.ndarray
    envelope_b: np.ndarray
    rate_a: np.ndarray
    rate_b: np.ndarray

    def __repr__(self):
        return (f"Comparison({self.counts[0]} vs {self.counts[1]} onsets above {self.threshold_db:g} dB, "
                f"{len(self.pairs)} paired within {self.window * 1e3:g} ms; "
                f"durations {self.durations[0]:.4g} vs {self.durations[1]:.4g} s)")

    @property
    def time_difference(self):
        """B's time minus A's, pair by pair (s) [shape=(m,)]."""
        return self.b.t[self.pairs[:, 1]] - self.a.t[self.pairs[:, 0]]

    @property
    def level_difference(self):
        """B's level minus A's, pair by pair (dB) [shape=(m,)]."""
        return self.b.level_db[self.pairs[:, 1]] - self.a.level_db[self.pairs[:, 0]]

    @property
    def interval_difference(self):
        """B's interval minus A's between successive pairs (s) [shape=(m - 1,)]."""
        return np.diff(self.time_difference)

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
            "window_s": self.window,
            "pairs": len(self.pairs),
            "unmatched_a": self.unmatched_a.tolist(), "unmatched_b": self.unmatched_b.tolist(),
            "time_difference_median_s": median(self.time_difference),
            "time_difference_max_s": largest(self.time_difference),
            "intervals_compared": len(self.interval_difference),
            "interval_difference_median_s": median(self.interval_difference),
            "interval_difference_max_s": largest(self.interval_difference),
            "level_difference_median_db": median(self.level_difference),
            "level_difference_max_db": largest(self.level_difference),
            "envelope_difference_rms_db": rms(self.envelope_b - self.envelope_a),
            "rate_difference_rms_hz": rms(self.rate_b - self.rate_a),
            "source_a": self.a.source, "source_b": self.b.source,
        }


def compare(a, b, *, threshold_db=FLOOR_DB, window=WINDOW):
    """Compare stroke ``b`` with stroke ``a``: counts, bounces paired by time, levels, envelope and bounce rate.

    Parameters
    ----------
    a, b : Onsets
        The two strokes (e.g. a human's recording and the robot's, or a recording and a recipe).
    threshold_db : float in [-200, 0]
        Count onsets at or above this level (dB re each stroke's loudest); a stroke detected with a
        higher threshold raises it for both.
    window : float in (0, 1]
        s: two onsets (times from each stroke's first) pair when at most this far apart.

    Returns
    -------
    Comparison
    """
    for name, onsets in (("a", a), ("b", b)):
        if not isinstance(onsets, Onsets):
            raise ParameterError(f"{name} must be Onsets (drumstroke.analysis.Onsets), got {type(onsets).__name__}")
    threshold = max(check_real("threshold_db", threshold_db, low=-200.0, high=0.0, unit="dB"),
                    a.threshold_db, b.threshold_db)
    window = check_real("window", window, low=0.0, high=1.0, low_open=True, unit="s")
    a, b = _counted(a, threshold), _counted(b, threshold)
    match = match_onsets(a.t, b.t, window=window)
    paired = match >= 0
    # a least-cost matching may cross two pairs at equal cost; pairing the matched onsets in order
    # uncrosses them, keeps every pair within the window and costs no more
    pairs = np.column_stack((np.flatnonzero(paired), np.sort(match[paired]))).astype(int)
    m = min(len(a), len(b))
    grid = np.linspace(0.0, min(a.t[-1], b.t[-1]), GRID_POINTS) if m >= 2 else np.empty(0)
    return Comparison(
        a=a, b=b, threshold_db=float(threshold), window=window, pairs=pairs,
        unmatched_a=np.flatnonzero(~paired), unmatched_b=np.setdiff1d(np.arange(len(b)), pairs[:, 1]),
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
