"""A recording's impacts: when the stick struck the head and how loud, relative to the loudest.

Audio tells levels only up to one gain (the microphone's distance, the preamp): levels here are in
dB re the loudest onset (0 dB is the loudest, the others below). The model's levels are absolute (dB re
1 m/s tip speed, :mod:`drumstroke.dynamics`); a fit finds the offset (:mod:`.fit`).

Onsets go to and come from an onsets CSV (:mod:`drumstroke.formats.onsets_csv`: ``t,level_db``
rows, the source and threshold in the JSON beside it): :func:`write_onsets`, :func:`read_onsets`.

Examples
--------
>>> import pathlib, tempfile
>>> path = pathlib.Path(tempfile.mkdtemp()) / "onsets.csv"
>>> write_onsets(path, Onsets([0.1, 0.35], [0.0, -4.5], threshold_db=-40.0, source="drop.wav"))
>>> read_onsets(path)
Onsets(2 over [0.1, 0.35] s, levels -4.5 to 0 dB; drop.wav)
>>> read_onsets(path).threshold_db
-40.0
"""

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._checks import check_vector
from ..errors import ParameterError
from ..formats.onsets_csv import read_onsets_csv, write_onsets_csv


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

    @classmethod
    def from_impacts(cls, impacts, *, source=""):
        """The onsets of a simulated stroke: its impacts' times and levels re the loudest (exact, no threshold).

        Parameters
        ----------
        impacts : drumstroke.trajectory.Impacts
            E.g. ``stroke.impacts`` of a :class:`drumstroke.Stroke`; impacts at zero speed are left out.
        source : str
            What they came from (a recipe's name).
        """
        level = impacts.level_db
        audible = np.isfinite(level)
        level = level[audible]
        return cls(impacts.t[audible], level - level.max() if len(level) else level, source=source,
                   info={"tip_speed_max": float(impacts.tip_speed.max()) if len(level) else 0.0})

    @property
    def intervals(self):
        """Times between successive onsets (s) [shape=(n - 1,)]."""
        return np.diff(self.t)


def write_onsets(path, onsets):
    """Write ``onsets`` to the onsets CSV at ``path`` (``t,level_db``) and the JSON beside it, atomically.

    The JSON holds the source, the detection threshold (dB re the loudest; null when the onsets
    were given) and ``info`` (how they were found).

    Parameters
    ----------
    path : str or os.PathLike
        Ending in ``.csv``, in an existing folder.
    onsets : Onsets
    """
    if not isinstance(onsets, Onsets):
        raise ParameterError(f"onsets must be an Onsets, got {type(onsets).__name__}")
    write_onsets_csv(path, onsets.t, onsets.level_db,
                     fields={"source": onsets.source, "threshold_db": onsets.threshold_db, "info": onsets.info})


def read_onsets(path):
    """The onsets of the file at ``path``: an onsets CSV (``t,level_db``, :func:`write_onsets`).

    Parameters
    ----------
    path : str or os.PathLike
        An onsets CSV; its source and threshold come from the JSON beside it when there is one
        (else the source is the file's name and the threshold -inf).

    Returns
    -------
    Onsets

    Raises
    ------
    ParameterError
        Naming the file (and the line) of what it refuses.
    """
    path = Path(path)
    if path.suffix.lower() != ".csv":
        raise ParameterError(f"path must be an onsets CSV (.csv), got {str(path)!r}")
    t, level_db, meta = read_onsets_csv(path)
    info = meta.get("info")
    try:
        return Onsets(t, level_db, threshold_db=meta.get("threshold_db", -np.inf),
                      source=str(meta.get("source") or path.name), info=info if isinstance(info, dict) else {})
    except ParameterError as error:
        raise ParameterError(f"onsets file {str(path)!r}: {error}") from None
