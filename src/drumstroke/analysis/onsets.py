"""A recording's impacts: when the stick struck the head and how loud, relative to the loudest.

Audio tells levels only up to one gain (the microphone's distance, the preamp): levels here are in
dB re the loudest onset (0 dB is the loudest, the others below). The model's levels are absolute (dB re
1 m/s tip speed, :mod:`drumstroke.dynamics`); a fit finds the offset (:mod:`.fit`).
"""

from dataclasses import dataclass, field

import numpy as np

from .._checks import check_vector
from ..errors import ParameterError


@dataclass(frozen=True, repr=False)
class Onsets:
    """The impacts found in one recording (or given as times and levels).

    Attributes
    ----------
    t : ndarray [shape=(n,)]
        Onset times (s from the recording's start), finite, ≥ 0, strictly increasing.
    level_db : ndarray [shape=(n,)]
        Each onset's level (dB re the loudest onset: ≤ 0, finite; the loudest is 0).
    threshold_db : float
        The detection threshold used (dB re the loudest onset; onsets below it are not reported), or
        -inf when the onsets were given rather than detected.
    source : str
        What they came from (a file's name, or a description).
    """

    t: np.ndarray
    level_db: np.ndarray
    threshold_db: float = -np.inf
    source: str = ""
    info: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        t = check_vector("onset times t", self.t, low=0.0, unit="s")
        level = check_vector("onset levels level_db", self.level_db, high=0.0, unit="dB")
        if len(t) != len(level):
            raise ParameterError(f"onset times and levels must be as many, got {len(t)} times and {len(level)} levels")
        if len(t) > 1 and not np.all(np.diff(t) > 0.0):
            i = int(np.flatnonzero(np.diff(t) <= 0.0)[0]) + 1
            raise ParameterError(f"onset times t must be strictly increasing, got t[{i}] = {t[i]!r} after {t[i - 1]!r} s")
        if len(level) and level.max() != 0.0:
            raise ParameterError(f"onset levels level_db must be re the loudest (its level 0 dB), got a largest of "
                                 f"{level.max()!r} dB")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "level_db", level)

    def __len__(self):
        return len(self.t)

    def __repr__(self):
        if not len(self):
            return f"Onsets(none{'; ' + self.source if self.source else ''})"
        return (f"Onsets({len(self)} over [{self.t[0]:.6g}, {self.t[-1]:.6g}] s, levels {self.level_db.min():.3g} to "
                f"0 dB{'; ' + self.source if self.source else ''})")

    @property
    def intervals(self):
        """Times between successive onsets (s) [shape=(n - 1,)]."""
        return np.diff(self.t)
