"""A motor-angle trajectory with its impacts: what the palette stores, transforms and sequences.

A :class:`Trajectory` is θ(t), ω(t) on [0, t_end] plus the impacts on the head.
Made from a simulated :class:`~drumstroke.Stroke` it is exact at every time (it
reads the solver's arcs); read back from samples (a library file) it is the
piecewise cubic Hermite curve through the samples' θ and ω, broken at every
impact so the velocity jump is kept, which is exact for parabolic flights and
within ~1e-9 rad of the physics at 1 kHz. Transforms wrap the time and angle
maps around that curve, so a stretched or reversed stroke is sampled from the
original, never resampled from resampled data.

Examples
--------
>>> import drumstroke
>>> trajectory = Trajectory.from_stroke(drumstroke.simulate("free-bounce"))
>>> trajectory.model, len(trajectory.impacts)
('paper', 98)
>>> theta, omega = trajectory.state(trajectory.impacts.t[:2])
>>> bool(abs(theta - trajectory.theta_max).max() < 1e-12)
True
"""

import io
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from .._checks import check_real
from .._version import __version__
from ..errors import ParameterError
from ..recipe import Recipe
from ..stroke import DEFAULT_RATE, MAX_SAMPLES, Impacts

THETA_TOP = math.pi / 2
"""The highest angle a trajectory may reach (rad): the stick upright."""


@dataclass(frozen=True, eq=False)
class Trajectory:
    """θ(t), ω(t) on [0, t_end] and the impacts on the head.

    Attributes
    ----------
    name : str
    model : str
        The model that made it ("paper", "geometry", or "mixed" for a sequence of both).
    theta_max : float
        The head (rad).
    t_end : float
        Duration (s).
    impacts : Impacts
        Times (s), angular speed just before each (rad/s, ≤ 0), tip distance (m).
    omega_after : ndarray [shape=(n,)]
        Angular speed just after each impact (rad/s, ≥ 0).
    path : callable
        ``path(t) -> (theta, omega)`` for times in [0, t_end]; at an impact
        time the state just after it. Use :meth:`state` or :meth:`sample`.
    recipe : Recipe or None
        The recipe of the stroke it came from, if one.
    history : tuple of str
        How it was made: the simulation, then each transform in order.
    recipe_time : callable or None
        Maps a time of this trajectory to the time of the recipe's profiles
        that it plays (s; NaN where it plays none), for drawing a(t).
    """

    name: str
    model: str
    theta_max: float
    t_end: float
    impacts: Impacts
    omega_after: np.ndarray
    path: Callable = field(repr=False)
    recipe: Recipe | None = None
    history: tuple = ()
    recipe_time: Callable | None = field(default=None, repr=False)

    @classmethod
    def from_stroke(cls, stroke, *, name=None):
        """The exact trajectory of a simulated :class:`~drumstroke.Stroke`."""
        recipe = stroke.recipe
        name = name or recipe.name or "custom"
        return cls(
            name=name,
            model=recipe.model,
            theta_max=recipe.theta_max,
            t_end=recipe.t_end,
            impacts=stroke.impacts,
            omega_after=-recipe.cor * stroke.impacts.omega,
            path=stroke.arcs.evaluate,
            recipe=recipe,
            history=(f"simulate {recipe.name or 'custom'} (model {recipe.model})",),
            recipe_time=_identity,
        )

    @classmethod
    def from_samples(cls, t, theta, omega, impacts, omega_after, *, theta_max, name="", model="paper",
                     recipe=None, history=()):
        """A trajectory through samples, Hermite-interpolated between them and broken at each impact.

        Parameters
        ----------
        t : ndarray [shape=(n,)]
            Sample times (s), from 0, strictly increasing, n ≥ 2.
        theta, omega : ndarray [shape=(n,)]
            rad, rad/s; θ ≥ theta_max.
        impacts : Impacts
            Impact times within [0, t[-1]].
        omega_after : ndarray [shape=(len(impacts),)]
            rad/s after each impact.
        theta_max : float
            rad.
        """
        t, theta, omega = (np.asarray(a, dtype=float) for a in (t, theta, omega))
        path = _hermite_path(t, theta, omega, impacts.t, impacts.omega, np.asarray(omega_after, float), theta_max)
        return cls(name=name, model=model, theta_max=theta_max, t_end=float(t[-1]), impacts=impacts,
                   omega_after=np.asarray(omega_after, dtype=float), path=path, recipe=recipe,
                   history=tuple(history))

    def state(self, t):
        """θ (rad) and ω (rad/s) at times ``t`` (s) in [0, t_end]; at an impact, just after it."""
        try:
            t = np.asarray(t, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(f"t must be times in [0, {self.t_end:g}] s, got {t!r}") from None
        good = np.isfinite(t) & (t >= 0.0) & (t <= self.t_end)
        if not np.all(good):
            raise ParameterError(f"t must be in [0, {self.t_end:g}] s, got {float(t[~good].flat[0])!r}")
        return self.path(t)

    def sample(self, rate=DEFAULT_RATE):
        """The trajectory at ``rate`` (Hz): times k/rate up to t_end (s), θ (rad), ω (rad/s)."""
        rate = check_real("rate", rate, low=0.0, high=1e6, low_open=True, unit="Hz")
        n = math.floor(self.t_end * rate * (1.0 + 1e-12)) + 1
        if n > MAX_SAMPLES:
            raise ParameterError(f"rate = {rate:g} Hz over {self.t_end:g} s gives {n} samples; at most "
                                 f"{MAX_SAMPLES} are allowed")
        t = np.minimum(np.arange(n) / rate, self.t_end)
        theta, omega = self.path(t)
        return t, theta, omega

    @cached_property
    def apexes(self):
        """The top of the flight after each impact (s) [shape=(n,)]: where ω turns from up to down.

        NaN after an impact the stick does not rise from (c = 0) and after the
        last impact when the stick is not falling again by t_end.
        """
        n = len(self.impacts)
        lo = self.impacts.t.copy()
        hi = np.append(self.impacts.t[1:], self.t_end)
        if n == 0:
            return np.empty(0)
        _, omega_hi = self.path(hi)
        rising = self.omega_after > 0.0
        falling = omega_hi < 0.0
        falling[:-1] = True  # the next impact is reached moving down
        ok = rising & falling & (hi > lo)
        lo, hi = lo[ok], hi[ok]
        for _ in range(80):  # bisection, keeping ω(lo) ≥ 0 > ω(hi)
            mid = 0.5 * (lo + hi)
            _, omega = self.path(mid)
            up = omega >= 0.0
            lo = np.where(up, mid, lo)
            hi = np.where(up, hi, mid)
        apexes = np.full(n, np.nan)
        apexes[ok] = lo
        return apexes

    def apex_after(self, n):
        """The time (s) of the apex after the ``n``-th impact (1-based)."""
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= len(self.impacts):
            raise ParameterError(f"n must be an impact number in [1, {len(self.impacts)}], got {n!r}")
        apex = self.apexes[n - 1]
        if not np.isfinite(apex):
            raise ParameterError(f"the stick does not rise to an apex after impact {n} of {self.name!r}")
        return float(apex)

    @cached_property
    def rest_time(self):
        """When the stick comes to rest on the head for good (s), or None if it still moves at t_end.

        Found on a sampling at 1 kHz or finer: the first sample after the last one off the head
        (θ − θ_max > 1e-9 rad or |ω| > 1e-6 rad/s).
        """
        t, theta, omega = self.sample(max(1000.0, 2.0 / max(self.t_end, 1e-9)))
        moving = (theta - self.theta_max > 1e-9) | (np.abs(omega) > 1e-6)
        if moving[-1]:
            return None
        last = np.flatnonzero(moving)
        return float(t[last[-1] + 1]) if len(last) else 0.0

    @cached_property
    def peak(self):
        """The highest angle reached (rad): the larger of the start, the apexes and 10 kHz samples."""
        _, theta, _ = self.sample(min(10_000.0, 5e6 / max(self.t_end, 1e-9)))
        apexes = self.apexes[np.isfinite(self.apexes)]
        top = self.path(apexes)[0].max() if len(apexes) else -np.inf
        return float(max(theta.max(), top))

    def to_dict(self):
        """Impacts and provenance as plain data for JSON (the library's impacts file)."""
        impacts = self.impacts
        return {
            "drumstroke": __version__,
            "name": self.name,
            "model": self.model,
            "recipe": self.recipe.to_dict() if self.recipe is not None else None,
            "theta_max": self.theta_max,
            "t_end": self.t_end,
            "tip_distance": impacts.tip_distance,
            "history": list(self.history),
            "impacts": [
                {"t": float(t), "omega": float(w), "omega_after": float(a), "tip_speed": float(v),
                 "level_db": float(db)}
                for t, w, a, v, db in zip(impacts.t, impacts.omega, self.omega_after, impacts.tip_speed,
                                          impacts.level_db)
            ],
        }


def csv_header(model, name, rate):
    """The comment line of a trajectory CSV: the version, the model, the stroke and the rate."""
    return f"drumstroke {__version__}; model={model}; stroke={name or 'custom'}; rate={rate:g} Hz; units s, rad, rad/s"


def csv_text(comment, names, columns):
    """CSV text: one ``#`` comment line, a header of ``names``, then the columns at full precision."""
    buffer = io.StringIO()
    buffer.write(f"# {comment}\n")
    np.savetxt(buffer, np.column_stack(columns), delimiter=",", header=",".join(names), comments="", fmt="%.17g")
    return buffer.getvalue()


def read_csv(path, *, what="trajectory file"):
    """Read a CSV as drumstroke writes them: its ``#`` comment, column names and columns (all finite numbers).

    Returns
    -------
    comment : str
    columns : dict of str to ndarray [shape=(n,)]
        In file order; n ≥ 2.
    """
    where = f"{what} {str(path)!r}"
    try:
        text = Path(path).read_text()
    except (OSError, UnicodeDecodeError) as error:
        reason = error.strerror if isinstance(error, OSError) else "not a UTF-8 text file"
        raise ParameterError(f"{where} cannot be read: {reason}") from None
    lines = text.split("\n", 2)
    if len(lines) < 3 or not lines[0].startswith("#") or not lines[1].startswith("t,"):
        raise ParameterError(f"{where} is corrupt: it must start with a # line and a header such as t,theta,omega")
    names = lines[1].strip().split(",")
    try:
        data = np.loadtxt(io.StringIO(lines[2]), delimiter=",", ndmin=2)
    except ValueError as error:
        raise ParameterError(f"{where} is corrupt: {error}") from None
    if data.shape[1] != len(names) or len(data) < 2:
        raise ParameterError(f"{where} is corrupt: {len(data)} rows of {data.shape[1]} columns under the header "
                             f"{','.join(names)} (at least 2 rows needed)")
    finite = np.isfinite(data).all(axis=1)
    if not finite.all():
        raise ParameterError(f"{where} is corrupt: row {int(np.flatnonzero(~finite)[0])} is not finite")
    return lines[0][1:].strip(), dict(zip(names, data.T))


def read_trajectory_csv(path, *, stick=None):
    """t (s), θ (rad), ω (rad/s) and the model from a stroke, library or composition CSV.

    A composition with several sticks has ``theta_<stick>`` columns: name the
    ``stick`` to read.
    """
    comment, columns = read_csv(path)
    sticks = [name[len("theta_"):] for name in columns if name.startswith("theta_")]
    if stick is None and not sticks:
        keys = ("theta", "omega")
    elif stick is None:
        raise ParameterError(f"trajectory file {str(path)!r} has the sticks {', '.join(sticks)}; name one (stick)")
    elif stick in sticks:
        keys = (f"theta_{stick}", f"omega_{stick}")
    else:
        raise ParameterError(f"stick must be one of {', '.join(sticks) or '(none: one stick)'}, got {stick!r}")
    if not all(key in columns for key in keys):
        raise ParameterError(f"trajectory file {str(path)!r} needs the columns t,{','.join(keys)}")
    model = next((part.split("=", 1)[1] for part in comment.split("; ") if part.startswith("model=")), "unknown")
    return columns["t"], columns[keys[0]], columns[keys[1]], model


def _identity(t):
    return t


def _hermite_path(t, theta, omega, impact_t, omega_before, omega_after, theta_max):
    """θ(s), ω(s) through samples and impacts: cubic Hermite pieces, broken at each impact."""
    near = np.zeros(len(t), dtype=bool)
    if len(impact_t):
        j = np.clip(np.searchsorted(impact_t, t), 1, len(impact_t)) - 1
        k = np.clip(j + 1, 0, len(impact_t) - 1)
        near = (np.abs(t - impact_t[j]) < 1e-9) | (np.abs(t - impact_t[k]) < 1e-9)
    node_t = np.concatenate((t[~near], impact_t))
    order = np.argsort(node_t, kind="stable")
    node_t = node_t[order]
    node_theta = np.concatenate((theta[~near], np.full(len(impact_t), theta_max)))[order]
    left = np.concatenate((omega[~near], omega_before))[order]  # ω arriving at the node
    right = np.concatenate((omega[~near], omega_after))[order]  # ω leaving it

    def path(s):
        s = np.asarray(s, dtype=float)
        i = np.clip(np.searchsorted(node_t, s, side="right") - 1, 0, len(node_t) - 2)
        h = node_t[i + 1] - node_t[i]
        u = (s - node_t[i]) / h
        p0, p1 = node_theta[i], node_theta[i + 1]
        m0, m1 = right[i] * h, left[i + 1] * h
        u2, u3 = u * u, u * u * u
        theta_s = (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 + (3 * u2 - 2 * u3) * p1 + (u3 - u2) * m1
        omega_s = (6 * u2 - 6 * u) * (p0 - p1) / h + (3 * u2 - 4 * u + 1) * right[i] + (3 * u2 - 2 * u) * left[i + 1]
        return np.maximum(theta_s, theta_max), omega_s

    return path
