"""What the robot played, measured against the reference, as onset detection is scored.

- Reference onsets are the reference trajectory's audible impacts: tip speed at or above
  MIDI velocity 1's level (:data:`drumstroke.dynamics.FLOOR_DB`, 1.6 cm/s).
  Played onsets are the plant's contacts with the head at or above the same level.
- Onsets are matched one to one within a window ±w, as ``mir_eval.onset`` matches them: a
  maximum matching (as many pairs as can be made, each onset in at most one pair), so
  precision, recall and F-measure equal ``mir_eval.onset.f_measure``'s. Among the maximum
  matchings it takes the one with the least total |played − reference|, so a played onset
  pairs with the nearest reference onset it can (mir_eval's own pairing is any maximum one;
  a farther pair would inflate the timing errors, not the counts).
- Two windows are scored (:data:`WINDOWS`). ±2 ms (:data:`WINDOW`) is two control periods at
  1 kHz: what a controller at the control rate can place, and what the paper's finding is
  about. ±10 ms (:data:`WIDE_WINDOW`) is about what a listener hears as on time: the smallest
  displacement listeners notice in a regular sequence is about 6 ms for onsets under 240 ms
  apart and 2.5 % of the interval above (Friberg & Sundberg 1995), 10 ms at 400 ms apart.
  (mir_eval's default, ±50 ms, is for onsets detected in audio and annotated by hand, far
  coarser than a simulated contact.)
- Per window (:class:`OnsetScores`): matched pairs; precision = matched / played, recall =
  matched / reference (each 1 when nothing was to be counted: no played onset is wrong, no
  reference onset missed), F = 2PR/(P + R); extra onsets (played, not matched) and missed
  onsets (reference, not matched); the timing error of the pairs, played − reference (s):
  median and 95th percentile of its magnitude, and its mean (> 0: late); the level error,
  20·log10(played tip speed / reference tip speed) (dB): median and 95th percentile of its
  magnitude, and its mean (> 0: louder). mir_eval scores 0 when either list is empty; the
  figures here differ from its only then.
- The fields kept from before are those of the first window (±2 ms): kept (= matched),
  kept_fraction (= recall), tail_kept_fraction (the tail = the later half of the reference
  onsets, by count), timing_mean and timing_p95 (|timing error|: mean, 95th percentile), the
  tail-length shortfall (the time from the last reference onset kept to the last reference
  onset, s; all of the reference's span when none was kept: extra onsets of a stick
  chattering on the head do not make a tail longer).
- RMS tracking error: θ against θ_ref over the control periods. Peak torque: max |τ| against
  the plant's limit.

Examples
--------
>>> import numpy as np
>>> match_onsets(np.array([1.0, 1.003]), np.array([0.9985, 1.0012]), window=0.002)
array([0, 1])
"""

import math
from dataclasses import dataclass, field, fields

import numpy as np

from .._checks import check_real, check_vector
from ..dynamics import FLOOR_DB
from ..errors import ParameterError

WINDOW = 0.002
"""The tight window (s): onsets match within ±2 ms, two control periods at 1 kHz."""

WIDE_WINDOW = 0.010
"""The wide window (s): ±10 ms, about what a listener hears as on time."""

WINDOWS = (WINDOW, WIDE_WINDOW)
"""The windows :func:`metrics` scores by default (s)."""

AUDIBLE_SPEED = 10.0 ** (FLOOR_DB / 20.0)
"""Tip speed of the quietest onset counted (m/s)."""


def match_onsets(reference, played, *, window=WINDOW):
    """For each reference onset, the index of the played onset it is matched with, or −1.

    A maximum one-to-one matching of onsets at most ``window`` apart (mir_eval's
    criterion, ``reference ∈ [played − window, played + window]``), with the least
    total |played − reference| among the maximum ones.

    Parameters
    ----------
    reference, played : ndarray [shape=(n,), (m,)]
        Onset times (s), non-decreasing, ≥ 0.
    window : float in (0, 1]
        s.

    Returns
    -------
    ndarray of int [shape=(n,)]
    """
    reference = _onsets("reference", reference)
    played = _onsets("played", played)
    window = check_real("window", window, low=0.0, high=1.0, low_open=True, unit="s")
    match = np.full(len(reference), -1)
    low = np.searchsorted(reference, played - window, side="left")
    high = np.searchsorted(reference, played + window, side="right")
    for first, last in _clusters(low, high):
        _match_cluster(reference, played, low, high, first, last, window, match)
    return match


def _onsets(name, values):
    times = check_vector(name, values, low=0.0, unit="s")
    down = np.flatnonzero(np.diff(times) < 0)
    if len(down):
        i = int(down[0]) + 1
        raise ParameterError(f"{name}[{i}] must not come before {name}[{i - 1}] (onsets in time order), got "
                             f"{times[i]!r} after {times[i - 1]!r} s")
    return times


def _clusters(low, high):
    """Runs of played onsets [first, last] whose windows chain through shared reference onsets.

    Played onset j may match the reference onsets low[j] to high[j] − 1; both bounds rise
    with j, so no pair can join two runs and each run is matched on its own.
    """
    j, n = 0, len(low)
    while j < n:
        if low[j] == high[j]:
            j += 1
            continue
        first, top = j, high[j]
        while j + 1 < n and low[j + 1] < top:
            j += 1
            top = max(top, high[j])
        yield first, j
        j += 1


def _match_cluster(reference, played, low, high, first, last, window, match):
    """The least-cost maximum matching of one run: an assignment where an impossible pair costs more than all others."""
    from scipy.optimize import linear_sum_assignment

    rows = np.arange(low[first], high[last])
    columns = np.arange(first, last + 1)
    allowed = (rows[:, None] >= low[columns]) & (rows[:, None] < high[columns])
    # one more pair saves an impossible one's cost, more than any set of possible pairs adds (each ≤ window)
    impossible = 2.0 * (min(len(rows), len(columns)) + 1) * window
    cost = np.where(allowed, np.abs(reference[rows][:, None] - played[columns]), impossible)
    r, c = linear_sum_assignment(cost)
    kept = allowed[r, c]
    match[rows[r[kept]]] = columns[c[kept]]


@dataclass(frozen=True)
class OnsetScores:
    """Onsets scored within one window (see the module docstring). Times in s, levels in dB; NaN when no pair.

    ``timing_errors`` and ``level_errors`` are the pairs' own errors (played − reference, s and
    dB, in reference order), for pooling (:func:`pool`); they are not part of the report.
    """

    window: float
    matched: int
    precision: float
    recall: float
    f_measure: float
    extra: int
    missed: int
    timing_median: float
    timing_p95: float
    timing_mean_signed: float
    level_median: float
    level_p95: float
    level_mean_signed: float
    timing_errors: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False, compare=False)
    level_errors: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False, compare=False)

    @classmethod
    def from_pairs(cls, window, timing, level, *, played, reference):
        """The scores of ``played`` onsets against ``reference`` ones (counts) with these pairs' errors (s, dB)."""
        matched = len(timing)
        precision = matched / played if played else 1.0
        recall = matched / reference if reference else 1.0
        return cls(
            window=window,
            matched=matched,
            precision=precision,
            recall=recall,
            f_measure=2.0 * precision * recall / (precision + recall) if precision + recall else 0.0,
            extra=played - matched,
            missed=reference - matched,
            timing_median=_percentile(np.abs(timing), 50),
            timing_p95=_percentile(np.abs(timing), 95),
            timing_mean_signed=float(np.mean(timing)) if matched else math.nan,
            level_median=_percentile(np.abs(level), 50),
            level_p95=_percentile(np.abs(level), 95),
            level_mean_signed=float(np.mean(level)) if matched else math.nan,
            timing_errors=timing,
            level_errors=level,
        )

    def to_dict(self):
        """Plain data for JSON (NaN as None), without the pairs' errors."""
        return {f.name: _plain(getattr(self, f.name)) for f in fields(self) if f.compare}


def pool(scores):
    """One :class:`OnsetScores` of many strokes scored within one window: counts summed, pairs pooled.

    Precision, recall and F are those of the summed counts (each onset weighs the same,
    whichever stroke it is in); the timing and level statistics are over every pair.
    """
    scores = list(scores)
    windows = {s.window for s in scores}
    if len(windows) != 1:
        raise ParameterError(f"scores must be of one window, got windows {sorted(windows)} s")
    return OnsetScores.from_pairs(scores[0].window, np.concatenate([s.timing_errors for s in scores]),
                                  np.concatenate([s.level_errors for s in scores]),
                                  played=sum(s.matched + s.extra for s in scores),
                                  reference=sum(s.matched + s.missed for s in scores))


@dataclass(frozen=True)
class Metrics:
    """Scores of one played stroke (see the module docstring).

    The first fields are those of the first window (±2 ms by default); ``windows`` holds
    the :class:`OnsetScores` of every window scored, in the order asked for.
    """

    reference_onsets: int
    played_onsets: int
    kept: int
    kept_fraction: float
    tail_kept_fraction: float
    timing_mean: float
    timing_p95: float
    rms_error: float
    tail_shortfall: float
    peak_torque: float
    torque_limit: float
    windows: tuple = ()

    def within(self, window):
        """The :class:`OnsetScores` of ``window`` (s)."""
        for scores in self.windows:
            if scores.window == window:
                return scores
        raise ParameterError(f"window must be one of {', '.join(f'{s.window:g}' for s in self.windows)} s "
                             f"(those scored), got {window!r}")

    def to_dict(self):
        """Plain data for JSON (NaN as None); ``windows`` as a list of :meth:`OnsetScores.to_dict`."""
        data = {f.name: _plain(getattr(self, f.name)) for f in fields(self) if f.name != "windows"}
        return data | {"windows": [s.to_dict() for s in self.windows]}


def metrics(played, *, windows=WINDOWS):
    """The :class:`Metrics` of a :class:`~drumstroke.robot.track.Played`.

    Parameters
    ----------
    played : Played
    windows : sequence of float in (0, 1]
        The matching windows (s), at least one; the fields kept from before are the first's.
    """
    windows = _windows(windows)
    ref = played.reference
    audible = ref.impacts.tip_speed >= AUDIBLE_SPEED
    ref_t, ref_speed = ref.impacts.t[audible], ref.impacts.tip_speed[audible]
    loud = played.onset_speed >= AUDIBLE_SPEED
    got_t, got_speed = played.onsets[loud], played.onset_speed[loud]
    matches = [match_onsets(ref_t, got_t, window=w) for w in windows]
    scores = tuple(_scores(w, m, ref_t, ref_speed, got_t, got_speed) for w, m in zip(windows, matches))
    kept = matches[0] >= 0
    errors = np.abs(got_t[matches[0][kept]] - ref_t[kept])
    tail = kept[len(kept) // 2:]
    if not len(ref_t):
        shortfall = 0.0
    elif kept.any():
        shortfall = ref_t[-1] - ref_t[np.flatnonzero(kept)[-1]]
    else:
        shortfall = ref_t[-1] - ref_t[0]
    return Metrics(
        reference_onsets=len(ref_t),
        played_onsets=len(got_t),
        kept=int(kept.sum()),
        kept_fraction=scores[0].recall,
        tail_kept_fraction=float(tail.mean()) if len(tail) else 1.0,
        timing_mean=float(errors.mean()) if len(errors) else math.nan,
        timing_p95=_percentile(errors, 95),
        rms_error=float(np.sqrt(np.mean((played.theta - ref.theta) ** 2))),
        tail_shortfall=float(shortfall),
        peak_torque=float(np.abs(played.torque).max()),
        torque_limit=played.max_torque,
        windows=scores,
    )


def _windows(windows):
    try:
        windows = tuple(windows)
    except TypeError:
        raise ParameterError(f"windows must be a sequence of windows in (0, 1] s, got {windows!r}") from None
    if not windows:
        raise ParameterError("windows must hold at least one window in (0, 1] s, got none")
    return tuple(check_real(f"windows[{i}]", w, low=0.0, high=1.0, low_open=True, unit="s")
                 for i, w in enumerate(windows))


def _scores(window, match, ref_t, ref_speed, got_t, got_speed):
    kept = match >= 0
    timing = got_t[match[kept]] - ref_t[kept]
    level = 20.0 * np.log10(got_speed[match[kept]] / ref_speed[kept])
    return OnsetScores.from_pairs(window, timing, level, played=len(got_t), reference=len(ref_t))


def _percentile(values, q):
    """The q-th percentile (linear between order statistics), NaN for no values."""
    return float(np.percentile(values, q)) if len(values) else math.nan


def _plain(value):
    return None if isinstance(value, float) and math.isnan(value) else value
