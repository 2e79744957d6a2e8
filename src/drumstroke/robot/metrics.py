"""What the robot played, measured against the reference (SPEC §5).

- Reference onsets are the reference trajectory's audible impacts: tip speed at or above
  MIDI velocity 1's level (:data:`drumstroke.dynamics.FLOOR_DB`, 1.6 cm/s).
  Played onsets are the plant's contacts with the head at or above the same level.
- An onset is kept when a played onset lies within ``window`` (±2 ms) of it;
  matching is one-to-one, in time order, nearest first.
- The tail is the later half of the reference onsets (by count).
- Timing error: |played − reference| of the kept onsets (mean, 95th percentile).
- RMS tracking error: θ against θ_ref over the control periods.
- Tail-length shortfall: how much of the reference's tail was not played, the time
  from the last reference onset that was kept to the last reference onset (s; all
  of the reference's span when none was kept). Extra onsets (a stick chattering on
  the head) do not make a tail longer.
- Peak torque: max |τ| against the plant's limit.

Examples
--------
>>> import numpy as np
>>> match_onsets(np.array([0.1, 0.2, 0.3]), np.array([0.1005, 0.2031, 0.2995]), window=0.002)
array([ 0, -1,  2])
"""

from dataclasses import asdict, dataclass

import numpy as np

from .._checks import check_real, check_vector
from ..dynamics import FLOOR_DB

WINDOW = 0.002
"""Onsets match within ±2 ms (s)."""

AUDIBLE_SPEED = 10.0 ** (FLOOR_DB / 20.0)
"""Tip speed of the quietest onset counted (m/s)."""


def match_onsets(reference, played, *, window=WINDOW):
    """For each reference onset (s, increasing), the index of its played onset within ``window`` (s), or −1.

    One-to-one: each played onset serves at most one reference onset; in time
    order, each reference onset takes the nearest free played onset.
    """
    reference = check_vector("reference", reference, low=0.0, unit="s")
    played = check_vector("played", played, low=0.0, unit="s")
    window = check_real("window", window, low=0.0, high=1.0, low_open=True, unit="s")
    match = np.full(len(reference), -1)
    used = np.zeros(len(played), dtype=bool)
    for i, t in enumerate(reference):
        lo, hi = np.searchsorted(played, t - window), np.searchsorted(played, t + window, side="right")
        free = [j for j in range(lo, hi) if not used[j]]
        if free:
            j = min(free, key=lambda j: abs(played[j] - t))
            match[i] = j
            used[j] = True
    return match


@dataclass(frozen=True)
class Metrics:
    """Scores of one played stroke (see the module docstring)."""

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

    def to_dict(self):
        """Plain data for JSON."""
        return asdict(self)


def metrics(played, *, window=WINDOW):
    """The :class:`Metrics` of a :class:`~drumstroke.robot.track.Played`."""
    ref = played.reference
    impacts = ref.impacts
    ref_t = impacts.t[impacts.tip_speed >= AUDIBLE_SPEED]
    got_t = played.onsets[played.onset_speed >= AUDIBLE_SPEED]
    match = match_onsets(ref_t, got_t, window=window)
    kept = match >= 0
    errors = np.abs(got_t[match[kept]] - ref_t[kept])
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
        kept_fraction=float(kept.mean()) if len(kept) else 1.0,
        tail_kept_fraction=float(tail.mean()) if len(tail) else 1.0,
        timing_mean=float(errors.mean()) if len(errors) else float("nan"),
        timing_p95=float(np.percentile(errors, 95)) if len(errors) else float("nan"),
        rms_error=float(np.sqrt(np.mean((played.theta - ref.theta) ** 2))),
        tail_shortfall=float(shortfall),
        peak_torque=float(np.abs(played.torque).max()),
        torque_limit=played.max_torque,
    )
