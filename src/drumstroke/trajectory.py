"""The one sampled-motion type every layer passes on: a :class:`Trajectory` of one stick or several.

A trajectory is where each stick is at every time of one timeline, [start, t_end] (s),
and the impacts it makes on the head. It is sampled at its ``rate`` (Hz), the robot's
control rate: samples at t = start + k/rate, read as arrays (:attr:`Trajectory.t`,
:attr:`~Trajectory.theta`, :attr:`~Trajectory.omega`, :attr:`~Trajectory.alpha`) or
unpacked, ``t, theta, omega = trajectory``. Behind the samples is each stick's curve:

- made from a simulated stroke (:meth:`Trajectory.from_stroke`, or ``Stroke.sample``), the
  curve is the solver's exact arcs, so the samples are exact at any rate and
  :meth:`Trajectory.state` is exact at any time;
- made from samples (:meth:`Trajectory.from_samples`: a file, a robot log, a stream), the curve
  is the piecewise cubic Hermite curve through the samples' θ and ω, broken at every impact so
  the velocity jump is kept; the samples are stored as given;
- post-processed or composed (:mod:`drumstroke.palette`, :mod:`drumstroke.compose`), the curve
  is a map of those curves, so a stretched or reversed stroke is sampled from the original.

Several sticks share one timeline and one rate (:meth:`Trajectory.from_sticks`;
:meth:`Trajectory.stick` picks one). A trajectory is immutable; :meth:`Trajectory.extend`
appends validated samples in chunks and returns the longer trajectory (the stepping seam a
live runtime streams through), in amortised constant time per sample.

Examples
--------
>>> import drumstroke
>>> trajectory = drumstroke.simulate("free-bounce").sample(1000.0)
>>> trajectory.model, trajectory.rate, len(trajectory.impacts), trajectory.t.shape
('paper', 1000.0, 98, (5001,))
>>> t, theta, omega = trajectory
>>> theta, omega = trajectory.state(trajectory.impacts.t[:2])
>>> bool(abs(theta - trajectory.theta_max).max() < 1e-12)
True
>>> head = trajectory.samples(0, 3)
>>> longer = Trajectory.from_samples(*head[:3], rate=1000.0).extend(*trajectory.samples(3, 10)[:3])
>>> bool(np.abs(longer.theta - trajectory.theta[:10]).max() < 1e-12)  # chunks of the exact curve, to round-off
True
"""

import functools
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path

import numpy as np

from ._atomic import bundled
from ._checks import as_vector, check_real
from ._version import __version__
from .budget import check_memory, check_time, csv_seconds, samples_bytes
from .curve import Curve, Segment
from .errors import ParameterError, SampledImpactsWarning, TrajectoryError
from .formats import trajectory_csv
from .formats.sidecar import sidecar_for, write_sidecar
from .model import Stick
from .solver.arcs import Arcs

DEFAULT_RATE = 1000.0
"""Sampling rate (Hz): the robot's control rate."""

LEVEL_REFERENCE = 1.0
"""Tip speed (m/s) of a 0 dB impact: ``level_db = 20·log10(tip_speed / 1 m/s)``."""

THETA_TOP = math.pi / 2
"""The highest angle a trajectory may reach (rad): the stick upright."""

MAX_SAMPLES = 50_000_000
"""Most samples one trajectory may hold."""

_CSV_CHUNK = 1 << 20  # numbers sampled and formatted at a time when a CSV is written: bounds the memory, not a tuning

DEFAULT_STICK = "stick"
"""The name of a lone stick (a stroke's): a composition names its sticks (``right``, ``left``, …)."""

TIME_TOLERANCE = 1e-9
"""Relative tolerance of a sample time against its place on the rate's grid (× max(1, |t|))."""

@dataclass(frozen=True, repr=False)
class Impacts:
    """The impacts of a stick on the head.

    Attributes
    ----------
    t : ndarray [shape=(n,)]
        Impact times (s), strictly increasing.
    omega : ndarray [shape=(n,)]
        Angular speed just before each impact (rad/s, ≤ 0).
    tip_distance : float
        x, fulcrum to tip (m).
    """

    t: np.ndarray
    omega: np.ndarray
    tip_distance: float

    @classmethod
    def _of(cls, t, omega, tip_distance):
        """The Impacts of these fields, made without the frozen dataclass's ``__init__`` (which sets each field by
        ``object.__setattr__``); the same object."""
        impacts = object.__new__(cls)
        fields = impacts.__dict__
        fields["t"], fields["omega"], fields["tip_distance"] = t, omega, tip_distance
        return impacts

    def __len__(self):
        return len(self.t)

    def __repr__(self):
        if not len(self):
            return f"Impacts(none; tip distance {self.tip_distance:g} m)"
        speed = self.tip_speed
        return (f"Impacts({len(self)} over [{self.t[0]:.6g}, {self.t[-1]:.6g}] s, tip speed {speed.min():.3g} to "
                f"{speed.max():.3g} m/s)")

    @property
    def tip_speed(self):
        """|ω⁻|·x, the tip's speed at each impact (m/s) [shape=(n,)]."""
        return np.abs(self.omega) * self.tip_distance

    @property
    def level_db(self):
        """20·log10(tip speed / 1 m/s), the dynamic level of each impact (dB) [shape=(n,)]."""
        with np.errstate(divide="ignore"):
            return 20.0 * np.log10(self.tip_speed / LEVEL_REFERENCE)


@dataclass(frozen=True, eq=False)
class Motion:
    """One stick's part of a trajectory: its curve and its impacts.

    Attributes
    ----------
    path : callable or None
        ``path(t) -> (theta, omega)`` (rad, rad/s) for times t (s) in the trajectory's span;
        at an impact time the state just after it. None: the Hermite curve through the
        trajectory's stored samples (see :attr:`Trajectory.path`).
    impacts : Impacts
    omega_after : ndarray [shape=(len(impacts),)]
        Angular speed just after each impact (rad/s, ≥ 0).
    theta_max : float
        The head this stick lands on (rad).
    """

    path: Callable | None = field(repr=False)
    impacts: Impacts
    omega_after: np.ndarray
    theta_max: float


@dataclass(frozen=True, eq=False)
class Samples:
    """Samples as given, read-only: t (s) [shape=(n,)], θ (rad) and ω (rad/s) [shape=(n, sticks)], α (rad/s²) like
    θ or None."""

    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray | None = None

    def __post_init__(self):
        for array in (self.t, self.theta, self.omega, self.alpha):
            if array is not None:
                array.flags.writeable = False

    def __len__(self):
        return len(self.t)


@dataclass(frozen=True, eq=False, repr=False)
class Trajectory:
    """The motion of one stick or several on one timeline, sampled at a control rate.

    Make one with :meth:`from_stroke` (or ``Stroke.sample``), :meth:`from_samples`,
    :meth:`from_sticks`, or the palette's transforms and composition; the constructor is
    their common ground.

    Attributes
    ----------
    motions : tuple of Motion
        One per stick.
    sticks : tuple of str
        The sticks' names, in column order.
    t_end : float
        The end of the timeline (s).
    rate : float in (0, 1e6]
        Samples per second (Hz).
    name : str
    model : str
        The model that made it ("paper", "geometry", "mixed" for both, "unknown" for samples
        of unknown origin).
    recipe : Recipe or None
        The recipe of the stroke it came from, if one.
    history : tuple of str
        How it was made: the simulation, then each transform in order.
    recipe_time : callable or None
        Maps a time of this trajectory to the time of the recipe's profiles that it plays
        (s; NaN where it plays none), for drawing a(t).
    start : float
        The start of the timeline (s): 0 but for samples that start later.
    carry : bool
        Whether evenly spaced samples of the solver's arcs are carried from one to the next by
        the addition theorem of sn, cn, dn (four times faster; within ~3e-14 rad of evaluating
        each afresh for a stroke, ~1e-13 rad for strokes placed late on a long timeline, whose
        local times carry the rounding of the placement) or each evaluated afresh (what the
        robot's reference does). The strokes of a composed curve are carried too.
    stored : Samples or None
        The samples as given (a file, a robot log, a stream), or None when the samples are the
        curve's at the rate.
    """

    motions: tuple
    sticks: tuple
    t_end: float
    rate: float = DEFAULT_RATE
    name: str = ""
    model: str = "paper"
    recipe: object = None
    history: tuple = ()
    recipe_time: Callable | None = field(default=None, repr=False)
    start: float = 0.0
    carry: bool = True
    stored: Samples | None = field(default=None, repr=False)

    # --- making one --------------------------------------------------------------------------------------------------

    @classmethod
    def single(cls, path, impacts, omega_after, *, theta_max, t_end, rate=DEFAULT_RATE, stick=DEFAULT_STICK, **info):
        """A one-stick trajectory from its curve ``path`` on [0, t_end] (s) and its impacts."""
        motion = Motion(path, impacts, np.asarray(omega_after, dtype=float), float(theta_max))
        return cls((motion,), (stick,), float(t_end), rate, **info)

    @classmethod
    def from_stroke(cls, stroke, *, rate=DEFAULT_RATE, name=None):
        """The exact trajectory of a simulated :class:`~drumstroke.Stroke`, sampled at ``rate`` (Hz)."""
        recipe = stroke.recipe
        rate = _check_rate(rate)
        label = recipe.name or "custom"
        # made without the frozen dataclasses' __init__ (which sets each field by object.__setattr__: 1.6 µs of a
        # stroke's sampling); the same objects
        motion = object.__new__(Motion)
        motion.__dict__.update(path=stroke.arcs.evaluate, impacts=stroke.impacts,
                               omega_after=-recipe.cor * stroke.impacts.omega, theta_max=recipe.theta_max)
        trajectory = object.__new__(cls)
        trajectory.__dict__.update(motions=(motion,), sticks=(DEFAULT_STICK,), t_end=recipe.t_end, rate=rate,
                                   name=name or label, model=recipe.model, recipe=recipe,
                                   history=(f"simulate {label} (model {recipe.model})",), recipe_time=_identity,
                                   start=0.0, carry=True, stored=None)
        return trajectory

    @classmethod
    def from_samples(cls, t, theta, omega, impacts=None, omega_after=None, *, theta_max=None, tip_distance=None,
                     rate=None, alpha=None, sticks=None, name="", model="unknown", recipe=None, history=()):
        """A trajectory through samples: stored as given, Hermite-interpolated between them, broken at impacts.

        Parameters
        ----------
        t : ndarray [shape=(n,)]
            Sample times (s), n ≥ 2, finite, one period 1/rate apart (within
            :data:`TIME_TOLERANCE`); they may start anywhere.
        theta, omega : ndarray [shape=(n,) or (n, sticks)]
            rad, rad/s, finite; one column per stick.
        impacts : Impacts or None
            The impacts (one stick). None finds them in the samples: where ω turns from
            down to up within two periods' travel of the head (:func:`find_impacts`).
        omega_after : ndarray or None
            rad/s after each given impact; default from the samples after it.
        theta_max : float or None
            The head (rad); default the paper's stick's (Table 1).
        tip_distance : float or None
            x (m) for the impacts found; default the paper's stick's.
        rate : float in (0, 1e6] or None
            Hz; default 1 / the first time step.
        alpha : ndarray or None
            rad/s² per sample, where known (shaped like theta).
        sticks : sequence of str or None
            The columns' stick names; default ``("stick",)`` for one column.
        name, model, recipe, history
            Provenance.

        Raises
        ------
        TrajectoryError
            A sample that is not finite or off the time grid, named by its index.
        """
        t, theta, omega, alpha, rate = check_samples(t, theta, omega, alpha, rate)
        sticks = _stick_names(sticks, theta.shape[1])
        head = Stick().theta_max if theta_max is None else check_real("theta_max", theta_max, low=-THETA_TOP,
                                                                       high=0.0, unit="rad")
        tip = Stick().pivot_to_tip if tip_distance is None else check_real("tip_distance", tip_distance, low=0.0,
                                                                           low_open=True, unit="m")
        if impacts is not None and not isinstance(impacts, Impacts):
            raise ParameterError(f"impacts must be a drumstroke.Impacts or None, got {type(impacts).__name__}")
        if impacts is not None and theta.shape[1] != 1:
            raise ParameterError("impacts can be given for one stick only; several sticks' impacts are found")
        motions = []
        for j in range(theta.shape[1]):
            if impacts is None:
                found, after = find_impacts(t, theta[:, j], omega[:, j], theta_max=head, tip_distance=tip)
            else:
                found = impacts
                after = (np.asarray(omega_after, dtype=float) if omega_after is not None
                         else _omega_after(t, omega[:, 0], impacts.t))
            motions.append(Motion(None, found, after, head))
        return cls(tuple(motions), sticks, float(t[-1]), rate, name, model, recipe, tuple(history),
                   start=float(t[0]), stored=Samples(t, theta, omega, alpha))

    @classmethod
    def from_sticks(cls, trajectories, *, name="", history=()):
        """Several one-stick trajectories on one timeline: ``{stick name: Trajectory}``, same rate, start and end."""
        if not isinstance(trajectories, dict) or not trajectories:
            raise ParameterError(f"trajectories must be a non-empty dict of stick name: Trajectory, got "
                                 f"{trajectories!r}")
        parts = list(trajectories.items())
        first = parts[0][1]
        for stick, part in parts:
            if not isinstance(part, Trajectory) or len(part.sticks) != 1:
                raise ParameterError(f"trajectories[{stick!r}] must be a one-stick Trajectory, got {part!r}")
            if (part.rate, part.start, part.t_end) != (first.rate, first.start, first.t_end):
                raise ParameterError(
                    f"trajectories[{stick!r}] runs at {part.rate:g} Hz over [{part.start:g}, {part.t_end:g}] s; "
                    f"{parts[0][0]!r} at {first.rate:g} Hz over [{first.start:g}, {first.t_end:g}] s: one timeline "
                    "needs the same rate, start and end")
        models = sorted({p.model for _, p in parts})
        stored = None
        if all(p.stored is not None for _, p in parts):
            kept = [p.stored for _, p in parts]
            alpha = None if any(k.alpha is None for k in kept) else np.column_stack([k.alpha[:, 0] for k in kept])
            stored = Samples(kept[0].t.copy(), np.column_stack([k.theta[:, 0] for k in kept]),
                             np.column_stack([k.omega[:, 0] for k in kept]), alpha)
        return cls(tuple(p.motions[0] for _, p in parts), tuple(stick for stick, _ in parts), first.t_end,
                   first.rate, name, models[0] if len(models) == 1 else "mixed", None, tuple(history),
                   start=first.start, stored=stored)

    @classmethod
    def read_csv(cls, path, *, stick=None, rate=None, theta_max=None, tip_distance=None):
        """A trajectory CSV (:mod:`drumstroke.formats.trajectory_csv`): one stick, or every stick of the file.

        Its model and rate come from the JSON beside it (``X.json`` for ``X.csv``), or from the
        comment line an older drumstroke wrote first, or (the rate) from the ``t`` column.

        Its impacts come from that JSON when it records them, exactly as they were simulated: a run
        that writes its own JSON with the CSV does (``simulate --json s.json --csv s.csv``, ``compose``,
        ``design``, ``rudiment``, a library's strokes; :func:`~drumstroke.formats.trajectory_csv.recorded_impacts`).
        Otherwise they are found again in the samples (:func:`find_impacts`), with a warning: one per
        sample period at most, its time to a fraction of a period, its ω that of the sample before. So
        the fast tail of a bounce sequence, where bounces come closer than two sample periods, is
        missed (a stroke with 73 impacts read back from 1 kHz samples shows 32), and so is an impact
        that leaves the stick resting on the head.

        Parameters
        ----------
        path : str or Path
        stick : str or None
            The stick to read of a file with several; None reads them all.
        rate : float or None
            Hz; default the file's (see above).
        theta_max, tip_distance : float or None
            The head (rad) and x (m) for the impacts found in the samples, and x for recorded impacts
            when the JSON does not say; default the paper's stick's.

        Warns
        -----
        drumstroke.errors.SampledImpactsWarning
            When the impacts are found again in the samples (the JSON beside the CSV records none).
        """
        comment, columns = trajectory_csv.read_columns(path)
        stated = trajectory_csv.file_metadata(path, comment, columns)
        recorded = trajectory_csv.recorded_impacts(path, columns)
        sticks = trajectory_csv.sticks_in(columns)
        if stick is not None or not sticks:
            t, theta, omega, alpha = trajectory_csv.stick_of(columns, stick, path)
            names, parts = (stick or DEFAULT_STICK,), [(theta, omega, alpha)]
        else:
            t, names = columns["t"], sticks
            parts = [(columns[f"theta_{s}"], columns[f"omega_{s}"], None) for s in sticks]
        if recorded is not None and len(recorded) == 1 and len(parts) == 1:  # a stroke's, or a one-stick piece's
            recorded = dict.fromkeys(names, *recorded.values())
        recorded = [(recorded or {}).get(name) for name in names]
        if any(impacts is None for impacts in recorded):
            warnings.warn(f"{str(path)!r}: its impacts are found again in its samples, as the JSON beside it records "
                          "none; bounces closer than two sample periods are missed (the JSON a run writes with the "
                          "CSV, e.g. --json s.json --csv s.csv, records them all)", SampledImpactsWarning,
                          stacklevel=2)
        read = {"theta_max": theta_max, "tip_distance": tip_distance, "model": stated["model"],
                "rate": rate if rate is not None else stated["rate"], "name": Path(path).stem}
        one = {name: cls._read_stick(t, *part, impacts, stick=name, **read)
               for name, part, impacts in zip(names, parts, recorded)}
        return next(iter(one.values())) if len(one) == 1 else cls.from_sticks(one, name=read["name"])

    @classmethod
    def _read_stick(cls, t, theta, omega, alpha, recorded, *, stick, theta_max, tip_distance, model, rate, name):
        """One stick of a CSV: its samples, with the impacts recorded beside it when there are some."""
        impacts = after = None
        if recorded is not None:
            impact_t, impact_omega, after, tip = recorded
            tip = tip if tip is not None else Stick().pivot_to_tip if tip_distance is None else tip_distance
            impacts = Impacts(impact_t, impact_omega, tip)
        return cls.from_samples(t, theta, omega, impacts, after, theta_max=theta_max, tip_distance=tip_distance,
                                rate=rate, alpha=alpha, sticks=(stick,), name=name, model=model)

    def write_csv(self, path, *, alpha=False, metadata=None, sidecar=True, bundle=None):
        """Write the samples as a trajectory CSV, header first, atomically; its metadata in the JSON beside it.

        The two files are put in place together (a :class:`drumstroke._atomic.Bundle`). A long
        trajectory is sampled and written a chunk at a time, in bounded memory; the time its CSV
        takes is estimated first and refused beyond the budget (:mod:`drumstroke.budget`).

        Parameters
        ----------
        path : str or Path
            The CSV: ``t,theta,omega`` or per stick ``theta_<stick>,omega_<stick>`` (and α if asked).
        alpha : bool
            Add the acceleration (rad/s²).
        metadata : dict or None
            More fields for the metadata (e.g. a composition's ``offset``).
        sidecar : bool
            Write the metadata to the JSON beside the CSV (``X.json`` for ``X.csv``). False leaves
            it to the caller, who puts the returned metadata in a JSON of its own at that path.
        bundle : Bundle or None
            The caller's bundle to put the files in place with (default: a bundle of their own).

        Returns
        -------
        dict
            The metadata (:func:`drumstroke.formats.trajectory_csv.metadata`).

        Raises
        ------
        ParameterError
            Before writing anything, when the JSON beside the CSV is a file already there that
            is not this CSV's metadata (:func:`drumstroke.formats.sidecar.sidecar_for`).
        """
        side = sidecar_for(path) if sidecar else None
        names = trajectory_csv.column_names(self.sticks, alpha=alpha)
        rows = len(self)
        check_time(f"the CSV {str(path)!r}", csv_seconds(rows, len(names)),
                   f"{rows} rows of {len(names)} numbers at rate = {self.rate:g} Hz")
        step = max(1, _CSV_CHUNK // len(names))
        chunks = (self._csv_columns(first, min(first + step, rows), alpha) for first in range(0, rows, step))
        block = self.csv_metadata(path, alpha=alpha, metadata=metadata)
        with bundled(bundle) as files:
            trajectory_csv.write_column_chunks(path, names, chunks, bundle=files)
            if side is not None:
                write_sidecar(side, block, bundle=files)
        return block

    def _csv_columns(self, first, stop, alpha):
        """The columns of a CSV's rows ``first`` to ``stop`` − 1: t, then each stick's θ, ω (and α)."""
        if first == 0 and stop == len(self):  # the whole: as every reader of the samples sees them
            t, theta, omega, acceleration = self.samples() if alpha else (*self._all, None)
        else:
            t, theta, omega, acceleration = self.samples(first, stop) if alpha else (*self._positions(first, stop), None)
        return (t, *trajectory_csv.stick_columns(self.sticks, theta, omega, acceleration)[1])

    def csv_metadata(self, path, *, alpha=False, metadata=None):
        """The metadata of this trajectory written as the CSV ``path`` (see :meth:`write_csv`), as a dict."""
        return trajectory_csv.metadata(path, trajectory_csv.column_names(self.sticks, alpha=alpha), model=self.model,
                                       name=self.name, rate=self.rate, sticks=self.sticks, extra=metadata)

    # --- the samples -------------------------------------------------------------------------------------------------

    def __len__(self):
        """The number of samples at :attr:`rate`."""
        if self.stored is not None:
            return len(self.stored)
        n = math.floor((self.t_end - self.start) * self.rate * (1.0 + 1e-12)) + 1
        if n > MAX_SAMPLES:
            raise ParameterError(f"rate = {self.rate:g} Hz over {self.t_end - self.start:g} s gives {n} samples; at "
                                 f"most {MAX_SAMPLES} are allowed (rate must be at most "
                                 f"{MAX_SAMPLES / (self.t_end - self.start):g} Hz for this stroke)")
        return n

    def __bool__(self):
        return True

    def __repr__(self):
        impacts = ", ".join(f"{stick} {len(m.impacts)}" for stick, m in zip(self.sticks, self.motions))
        return (f"Trajectory({self.name!r}, model={self.model!r}, {len(self)} samples at {self.rate:g} Hz over "
                f"[{self.start:g}, {self.t_end:g}] s; impacts: {impacts})")

    def samples(self, first=0, stop=None):
        """Samples ``first`` to ``stop`` − 1 (all by default): t (s), θ (rad), ω (rad/s), α (rad/s²).

        The chunks a stream sends are slices of the same samples: ``samples(0, n)`` equals the
        chunks ``samples(0, k)``, ``samples(k, n)`` put end to end — stored samples exactly, the
        solver's exact curves to round-off (≈1e-14 rad: a chunk starts the addition theorem of
        sn, cn, dn afresh).

        Returns
        -------
        t : ndarray [shape=(m,)]
        theta, omega, alpha : ndarray [shape=(m,) for one stick, (m, sticks) for several]
        """
        t, theta, omega = self._positions(first, stop)
        if self.stored is not None and self.stored.alpha is not None:
            alpha = self.stored.alpha[first:len(t) + first]
        else:
            alpha = self._alpha_at(t)
        return t, theta, omega, self._shaped(alpha)

    def _positions(self, first=0, stop=None):
        """t, θ, ω of samples ``first`` to ``stop`` − 1 (θ, ω shaped as :attr:`theta`)."""
        n = len(self)
        stop = n if stop is None else stop
        if not (isinstance(first, (int, np.integer)) and isinstance(stop, (int, np.integer)) and 0 <= first <= stop
                <= n):
            raise ParameterError(f"first and stop must be sample indices with 0 <= first <= stop <= {n}, got "
                                 f"{first!r} and {stop!r}")
        if self.stored is not None:
            stored = self.stored
            return stored.t[first:stop], self._shaped(stored.theta[first:stop]), self._shaped(stored.omega[first:stop])
        sticks = len(self.motions)
        check_memory(lambda: f"sampling {self.t_end - self.start:g} s of {sticks} stick{'s' * (sticks > 1)} at rate "
                     f"= {self.rate:g} Hz", samples_bytes(stop - first, sticks), lambda: f"{stop - first} samples")
        t = _sample_times()(first, stop, self.rate, self.start, self.t_end)
        if len(self.motions) == 1:
            return (t, *self._evaluate(0, t))
        pairs = [self._evaluate(j, t) for j in range(len(self.motions))]
        return t, np.column_stack([p[0] for p in pairs]), np.column_stack([p[1] for p in pairs])

    def _evaluate(self, j, t):
        """Stick j's curve at evenly spaced times ``t`` (the solver's arcs, alone or in a curve, carry sn, cn, dn from one
        to the next)."""
        path = self.motions[j].path if self.stored is None else self.curves[j]
        if self.carry and (isinstance(path, Curve) or isinstance(getattr(path, "__self__", None), Arcs)):
            return path(t, spacing=1.0 / self.rate)
        return path(t)

    def _shaped(self, array):
        """A stored (n, sticks) array as the samples' shape: (n,) for one stick."""
        return array[:, 0] if array.ndim == 2 and len(self.motions) == 1 else array

    @property
    def _all(self):
        # Cached by hand: functools.cached_property takes a lock on every first read (Python 3.11), a
        # measurable share of sampling a stroke.
        arrays = self.__dict__.get("_samples_read")
        if arrays is None:
            arrays = self._positions()
            for array in arrays:
                array.flags.writeable = False
            self.__dict__["_samples_read"] = arrays
        return arrays

    @cached_property
    def _alpha(self):
        alpha = self.samples()[3]
        alpha.flags.writeable = False
        return alpha

    @property
    def t(self):
        """Sample times (s) [shape=(n,)]: start + k/rate."""
        return self._all[0]

    @property
    def theta(self):
        """θ at the samples (rad) [shape=(n,) for one stick, (n, sticks) for several]."""
        return self._all[1]

    @property
    def omega(self):
        """ω at the samples (rad/s) [shape like theta]."""
        return self._all[2]

    @property
    def alpha(self):
        """α at the samples (rad/s²) [shape like theta]: as given, or the curve's, away from impacts.

        The curve's is a central difference over 2 µs of its exact ω, one-sided where an impact lies
        within the step: the flight acceleration, impacts excluded.
        """
        return self._alpha

    def columns(self):
        """The sample columns in CSV order: t, then θ and ω of each stick."""
        t, theta, omega = self._all
        if len(self.motions) == 1:
            return t, theta, omega
        return (t, *(c for j in range(len(self.sticks)) for c in (theta[:, j], omega[:, j])))

    def __iter__(self):
        """Unpack as the sample columns: ``t, theta, omega = trajectory`` for one stick (see :meth:`columns`)."""
        return iter(self.columns())

    def sample(self, rate=None):
        """The same motion sampled at ``rate`` (Hz; default its own): a Trajectory.

        Stored samples at another rate are read off the Hermite curve through them.
        """
        rate = self.rate if rate is None else _check_rate(rate)
        if rate == self.rate:
            return self
        motions = tuple(replace(m, path=curve) for m, curve in zip(self.motions, self.curves))
        moved = replace(self, motions=motions, rate=rate, stored=None)
        len(moved)  # checks the count
        return moved

    def state(self, t):
        """θ (rad) and ω (rad/s) at times ``t`` (s) in [start, t_end], exact on exact curves; one stick.

        At an impact time the state just after it.
        """
        self._one("state")
        try:
            t = np.asarray(t, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(f"t must be times in [{self.start:g}, {self.t_end:g}] s, got {t!r}") from None
        good = np.isfinite(t) & (t >= self.start) & (t <= self.t_end)
        if not np.all(good):
            raise ParameterError(f"t must be in [{self.start:g}, {self.t_end:g}] s, got {float(t[~good].flat[0])!r}")
        return self.curves[0](t)

    # --- sticks ------------------------------------------------------------------------------------------------------

    def stick(self, name):
        """The one-stick trajectory of the stick ``name``."""
        if name not in self.sticks:
            raise ParameterError(f"stick must be one of {', '.join(self.sticks)}, got {name!r}")
        if len(self.sticks) == 1:
            return self
        j = self.sticks.index(name)
        stored = self.stored
        if stored is not None:
            stored = Samples(stored.t, stored.theta[:, j:j + 1], stored.omega[:, j:j + 1],
                             None if stored.alpha is None else stored.alpha[:, j:j + 1])
        return replace(self, motions=(self.motions[j],), sticks=(name,), name=self.name or name,
                       model=self.model, stored=stored)

    def _one(self, what):
        if len(self.motions) != 1:
            raise ParameterError(f"{what} needs one stick; this trajectory has the sticks {', '.join(self.sticks)}: "
                                 "pick one with trajectory.stick(name)")
        return self.motions[0]

    @cached_property
    def curves(self):
        """Each stick's curve, ``path(t) -> (theta, omega)``: its motion's, or the Hermite curve through its samples."""
        if self.stored is None:
            return tuple(m.path for m in self.motions)
        stored = self.stored
        return tuple(m.path if m.path is not None else
                     _hermite_path(stored.t, stored.theta[:, j], stored.omega[:, j], m.impacts.t, m.impacts.omega,
                                   m.omega_after, m.theta_max)
                     for j, m in enumerate(self.motions))

    @property
    def path(self):
        """The stick's curve, ``path(t) -> (theta, omega)`` (one stick)."""
        self._one("path")
        return self.curves[0]

    @property
    def impacts(self):
        """The stick's :class:`Impacts` (one stick)."""
        return self._one("impacts").impacts

    @property
    def omega_after(self):
        """Angular speed just after each impact (rad/s, ≥ 0) [shape=(len(impacts),)] (one stick)."""
        return self._one("omega_after").omega_after

    @property
    def theta_max(self):
        """The head (rad); the sticks of one trajectory share it."""
        heads = {m.theta_max for m in self.motions}
        if len(heads) != 1:
            raise ParameterError(f"the sticks {', '.join(self.sticks)} land on different heads")
        return heads.pop()

    # --- events on the curve (one stick) -----------------------------------------------------------------------------

    @cached_property
    def apexes(self):
        """The top of the flight after each impact (s) [shape=(n,)]: where ω turns from up to down.

        NaN after an impact the stick does not rise from (c = 0) and after the
        last impact when the stick is not falling again by t_end.
        """
        motion = self._one("apexes")
        impacts, path = motion.impacts, self.curves[0]
        n = len(impacts)
        if n == 0:
            return np.empty(0)
        lo = impacts.t.copy()
        hi = np.append(impacts.t[1:], self.t_end)
        _, omega_hi = path(hi)
        rising = motion.omega_after > 0.0
        falling = omega_hi < 0.0
        falling[:-1] = True  # the next impact is reached moving down
        ok = rising & falling & (hi > lo)
        lo, hi = lo[ok], hi[ok]
        for _ in range(80):  # bisection, keeping ω(lo) ≥ 0 > ω(hi)
            mid = 0.5 * (lo + hi)
            _, omega = path(mid)
            up = omega >= 0.0
            lo = np.where(up, mid, lo)
            hi = np.where(up, hi, mid)
        apexes = np.full(n, np.nan)
        apexes[ok] = lo
        return apexes

    def apex_after(self, n):
        """The time (s) of the apex after the ``n``-th impact (1-based)."""
        impacts = self.impacts
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= len(impacts):
            raise ParameterError(f"n must be an impact number in [1, {len(impacts)}], got {n!r}")
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
        motion = self._one("rest_time")
        t, theta, omega = self.sample(max(1000.0, 2.0 / max(self.t_end - self.start, 1e-9)))
        moving = (theta - motion.theta_max > 1e-9) | (np.abs(omega) > 1e-6)
        if moving[-1]:
            return None
        last = np.flatnonzero(moving)
        return float(t[last[-1] + 1]) if len(last) else float(t[0])

    @cached_property
    def peak(self):
        """The highest angle reached (rad): the larger of the start, the apexes and 10 kHz samples."""
        self._one("peak")
        _, theta, _ = self.sample(min(10_000.0, 5e6 / max(self.t_end - self.start, 1e-9)))
        apexes = self.apexes[np.isfinite(self.apexes)]
        top = self.curves[0](apexes)[0].max() if len(apexes) else -np.inf
        return float(max(theta.max(), top))

    # --- the stepping seam -------------------------------------------------------------------------------------------

    def extend(self, t, theta, omega, alpha=None, impacts=None, omega_after=None):
        """This trajectory with samples appended: the next chunk of a stream (see :class:`Stream`).

        The chunk must continue the time grid (its first time one period after the last),
        be finite, stay on or above the head, and continue the motion: its first θ within
        what the speeds at the join allow, one period's travel (so the stick never jumps).
        The samples are copied: a host that appends many chunks keeps a :class:`Stream`,
        which appends in amortised O(chunk).

        Parameters
        ----------
        t : ndarray [shape=(m,)]
            s.
        theta, omega : ndarray [shape=(m,) or (m, sticks)]
            rad, rad/s.
        alpha : ndarray or None
            rad/s², if this trajectory stores α.
        impacts : Impacts or None
            One stick: the chunk's impacts (times within the chunk's span), with ``omega_after``.
            None finds them in the samples, across the join too.

        Returns
        -------
        Trajectory

        Raises
        ------
        TrajectoryError
            Naming the sample (counted in the whole trajectory) and what is wrong.
        """
        return Stream(self).extend(t, theta, omega, alpha, impacts, omega_after).trajectory()

    def flight_acceleration(self, t):
        """dω/dt (rad/s²) on the curve at times ``t`` (s) in [start, t_end], impacts excluded (one stick).

        A central difference over 2 µs of the curve's ω, one-sided where an impact lies within the
        step: what :attr:`alpha` holds at the samples, at any times.
        """
        self._one("flight_acceleration")
        return self._alpha_at(np.asarray(t, dtype=float))

    def _alpha_at(self, t):
        columns = [_as_curve(path, m.impacts.t, self.start, self.t_end).acceleration(t)
                   for path, m in zip(self.curves, self.motions)]
        return columns[0] if len(columns) == 1 else np.column_stack(columns)

    # --- provenance --------------------------------------------------------------------------------------------------

    def to_dict(self):
        """Impacts and provenance as plain data for JSON (a library stroke's impacts file, one stick)."""
        motion = self._one("to_dict")
        impacts = motion.impacts
        return {
            "drumstroke": __version__,
            "name": self.name,
            "model": self.model,
            "recipe": self.recipe.to_dict() if self.recipe is not None else None,
            "theta_max": motion.theta_max,
            "t_end": self.t_end,
            "tip_distance": impacts.tip_distance,
            "history": list(self.history),
            "impacts": [
                {"t": float(t), "omega": float(w), "omega_after": float(a), "tip_speed": float(v),
                 "level_db": float(db)}
                for t, w, a, v, db in zip(impacts.t, impacts.omega, motion.omega_after, impacts.tip_speed,
                                          impacts.level_db)
            ],
        }


class Stream:
    """Samples that arrive in chunks: the stepping seam a live host streams through.

    Starts from a trajectory (its samples, or its curve's at its rate) and takes chunks with
    :meth:`extend`, each checked as :meth:`Trajectory.extend` says, in amortised O(chunk): the
    samples grow in place, by doubling. :meth:`trajectory` is what has arrived, an immutable
    :class:`Trajectory` whose samples later chunks never change.

    Examples
    --------
    >>> import drumstroke
    >>> stroke = drumstroke.simulate("free-bounce", t_end=0.5).sample(1000.0)
    >>> stream = Stream(Trajectory.from_samples(*stroke.samples(0, 10)[:3], rate=1000.0))
    >>> for first in range(10, len(stroke), 100):
    ...     _ = stream.extend(*stroke.samples(first, min(first + 100, len(stroke)))[:3])
    >>> received = stream.trajectory()
    >>> len(received) == len(stroke), bool(np.abs(received.theta - stroke.theta).max() < 1e-12)
    (True, True)
    """

    def __init__(self, trajectory):
        if not isinstance(trajectory, Trajectory):
            raise ParameterError(f"trajectory must be a drumstroke.Trajectory, got {trajectory!r}")
        stored = trajectory.stored
        if stored is None:
            t, theta, omega = trajectory._positions()
            shape = (len(t), len(trajectory.sticks))
            stored = Samples(t, theta.reshape(shape), omega.reshape(shape))
        self.base, self.size = trajectory, len(stored)
        self.t, self.theta, self.omega = stored.t.copy(), stored.theta.copy(), stored.omega.copy()
        self.alpha = None if stored.alpha is None else stored.alpha.copy()
        self.motions = [replace(m, path=None) for m in trajectory.motions]

    def extend(self, t, theta, omega, alpha=None, impacts=None, omega_after=None):
        """Append a chunk (see :meth:`Trajectory.extend` for what it must be); returns the stream."""
        if len(self.motions) != 1 and impacts is not None:
            raise ParameterError("impacts can be given for one stick only; several sticks' impacts are found")
        t, theta, omega, alpha = _chunk_arrays(t, theta, omega, alpha, len(self.motions), self.alpha is not None)
        _check_chunk(self, t, theta, omega)
        n, m = self.size, len(t)
        if n + m > len(self.t):
            capacity = max(2 * len(self.t), n + m, 16)
            self.t, self.theta, self.omega = (_grown(a, n, capacity) for a in (self.t, self.theta, self.omega))
            self.alpha = None if self.alpha is None else _grown(self.alpha, n, capacity)
        self.t[n:n + m], self.theta[n:n + m], self.omega[n:n + m] = t, theta, omega
        if alpha is not None:
            self.alpha[n:n + m] = alpha
        self.size = end = n + m
        for j, motion in enumerate(self.motions):
            if impacts is None:  # from the last sample before the chunk on: an impact may straddle the join
                found, after = find_impacts(self.t[n - 1:end], self.theta[n - 1:end, j], self.omega[n - 1:end, j],
                                            theta_max=motion.theta_max, tip_distance=motion.impacts.tip_distance)
                new_t, new_omega = found.t, found.omega
            else:
                new_t, new_omega = np.asarray(impacts.t, dtype=float), np.asarray(impacts.omega, dtype=float)
                after = (np.asarray(omega_after, dtype=float) if omega_after is not None
                         else _omega_after(self.t[:end], self.omega[:end, j], new_t))
            if len(new_t):  # most chunks have none: nothing to join
                joined = Impacts(np.concatenate((motion.impacts.t, new_t)),
                                 np.concatenate((motion.impacts.omega, new_omega)), motion.impacts.tip_distance)
                self.motions[j] = Motion(None, joined, np.concatenate((motion.omega_after, after)),
                                         motion.theta_max)
        return self

    def trajectory(self):
        """The samples so far as a Trajectory (views that later chunks never change)."""
        n = self.size
        stored = Samples(self.t[:n], self.theta[:n], self.omega[:n], None if self.alpha is None else self.alpha[:n])
        return replace(self.base, motions=tuple(self.motions), t_end=float(self.t[n - 1]), stored=stored)


def _grown(array, n, capacity):
    out = np.empty((capacity, *array.shape[1:]))
    out[:n] = array[:n]
    return out


def find_impacts(t, theta, omega, *, theta_max, tip_distance):
    """The impacts in samples: where ω turns from down to up within two periods' travel of the head.

    An impact lies between samples k and k+1 where ω[k] < 0 < ω[k+1] and θ[k] is within
    twice a period's travel of the head (the stick speeds up on its way); its time is where
    sample k's motion reaches the head, t_k + (θ_k − θ_max)/|ω_k| (to a small fraction of a
    period), its speed before ω[k] and after ω[k+1].

    Returns
    -------
    impacts : Impacts
        Times on t's clock (s).
    omega_after : ndarray [shape=(m,)]
    """
    t, theta, omega = (np.asarray(a, dtype=float) for a in (t, theta, omega))
    dt = np.diff(t)
    k = np.flatnonzero(reversals_on_head(t, theta, omega, theta_max))
    when = t[k] + np.clip((theta[k] - theta_max) / -omega[k], 0.0, dt[k])
    return Impacts(when, omega[k].copy(), tip_distance), omega[k + 1].copy()


def reversals_on_head(t, theta, omega, theta_max):
    """True for each step from sample k to k+1 where the stick strikes the head [shape=(n-1,)]: ω turns from down to
    up within it, θ[k] within twice a period's travel of the head θ_max (rad; the stick speeds up on its way).

    >>> reversals_on_head(np.arange(4) * 1e-3, [0.011, 0.001, 0.009, 0.5], [-10.0, -10.0, 8.0, 8.0], 0.0)
    array([False,  True, False])
    """
    t, theta, omega = (np.asarray(a, dtype=float) for a in (t, theta, omega))
    near = theta[:-1] - theta_max <= 2.0 * np.abs(omega[:-1]) * np.diff(t) + 1e-9
    return (omega[:-1] < 0.0) & (omega[1:] > 0.0) & near


def _omega_after(t, omega, impact_t):
    """ω of the first sample after each impact (rad/s): the speed it leaves with, as sampled."""
    k = np.clip(np.searchsorted(t, impact_t, side="right"), 0, len(t) - 1)
    return np.maximum(omega[k], 0.0)


def _check_rate(rate):
    return check_real("rate", rate, low=0.0, high=1e6, low_open=True, unit="Hz")


def _stick_names(sticks, count):
    if sticks is None:
        sticks = (DEFAULT_STICK,) if count == 1 else tuple(f"stick{j}" for j in range(count))
    sticks = tuple(sticks)
    if len(sticks) != count or len(set(sticks)) != count or not all(isinstance(s, str) and s for s in sticks):
        raise ParameterError(f"sticks must be {count} distinct names, one per column, got {sticks!r}")
    return sticks


def _columns(name, values, n):
    array = np.asarray(values, dtype=float) if not isinstance(values, np.ndarray) else values.astype(float)
    if array.ndim == 1:
        array = array[:, None]
    if array.ndim != 2 or array.shape[0] != n:
        raise ParameterError(f"{name} must have shape (n,) or (n, sticks) with n = {n}, got shape {array.shape}")
    return array


def check_sampling(duration, rate, columns, *, name="rate"):
    """Refuse ``rate`` (Hz) over ``duration`` (s) before anything is simulated or sampled.

    Refused: more than :data:`MAX_SAMPLES` samples, or a CSV of ``columns`` numbers a row that the
    budget's time does not allow (:func:`drumstroke.budget.csv_seconds`). ``name`` is the input as
    the message names it (``"--rate"`` on the command line).

    >>> check_sampling(60.0, 1e6, 3, name="--rate")
    Traceback (most recent call last):
    ...
    drumstroke.errors.ParameterError: --rate = 1e+06 Hz over 60 s asks for 60000001 samples; at most 50000000 are allowed (--rate must be at most 833333 Hz here)
    """
    samples = math.floor(duration * rate * (1.0 + 1e-12)) + 1
    if samples > MAX_SAMPLES:
        raise ParameterError(f"{name} = {rate:g} Hz over {duration:g} s asks for {samples} samples; at most "
                             f"{MAX_SAMPLES} are allowed ({name} must be at most {MAX_SAMPLES / duration:g} Hz here)")
    check_time(name, csv_seconds(samples, columns), f"a CSV of {samples} rows of {columns} numbers: {duration:g} s at "
                                                    f"{rate:g} Hz")


def check_samples(t, theta, omega, alpha=None, rate=None):
    """Samples as float arrays (t 1-D; the others 2-D) on one time grid, checked in the validator's words.

    Returns ``(t, theta, omega, alpha, rate)``; ``rate`` (Hz) is the first step's if not given.
    """
    t = np.array(as_vector("t", t), dtype=float)
    for name, values in (("theta", theta), ("omega", omega)):
        try:
            array = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(f"{name} must be a 1-D array of numbers, got {values!r}") from None
        if array.ndim not in (1, 2):
            raise ParameterError(f"{name} must be a 1-D array of numbers, got shape {array.shape}")
    theta, omega = np.asarray(theta, dtype=float), np.asarray(omega, dtype=float)
    if not len(t) == len(theta) == len(omega) or len(t) < 2:
        raise ParameterError(f"t, theta and omega must have the same length >= 2, got {len(t)}, {len(theta)} and "
                             f"{len(omega)}")
    theta, omega = _columns("theta", theta, len(t)).copy(), _columns("omega", omega, len(t)).copy()
    if theta.shape != omega.shape:
        raise ParameterError(f"theta and omega must have the same shape, got {theta.shape} and {omega.shape}")
    alpha = None if alpha is None else _columns("alpha", alpha, len(t)).copy()
    for name, values in (("t", t), ("theta", theta), ("omega", omega)):
        bad = np.flatnonzero(~np.isfinite(values.reshape(len(t), -1)).all(axis=1))
        if len(bad):
            i = int(bad[0])
            value = values[i] if values.ndim == 1 else values[i][~np.isfinite(values[i])][0]
            raise TrajectoryError(f"sample {i}: {name} is {float(value)!r}; t, theta and omega must be finite")
    if alpha is not None and not np.isfinite(alpha).all():
        i = int(np.flatnonzero(~np.isfinite(alpha).all(axis=1))[0])
        raise TrajectoryError(f"sample {i}: alpha is not finite")
    step = np.diff(t)
    back = np.flatnonzero(step <= 0.0)
    if len(back):
        i = int(back[0]) + 1
        how = "repeats the time of" if step[i - 1] == 0.0 else "goes back in time from"
        raise TrajectoryError(f"sample {i}: time {float(t[i])!r} s {how} sample {i - 1} ({float(t[i - 1])!r} s); "
                              "times must increase strictly")
    rate = 1.0 / step[0] if rate is None else _check_rate(rate)
    check_grid(t, rate)
    if len(t) > MAX_SAMPLES:
        raise ParameterError(f"a trajectory may hold at most {MAX_SAMPLES} samples, got {len(t)}")
    return t, theta, omega, alpha, rate


def check_grid(t, rate, *, first=0):
    """Raise :class:`~drumstroke.errors.TrajectoryError` unless t[k] = t[0] + k/rate (within the tolerance).

    A repeated time, a gap of missing samples and a wrong rate are told apart; samples are
    numbered from ``first``.
    """
    step = np.diff(t)
    period = 1.0 / rate
    expected = t[0] + np.arange(len(t)) / rate
    off = np.flatnonzero(np.abs(t - expected) > TIME_TOLERANCE * np.maximum(1.0, np.abs(t)))
    if not len(off):
        return
    i = int(off[0])
    gap = step[i - 1] * rate
    uniform = np.all(np.abs(step - step[0]) <= TIME_TOLERANCE * max(1.0, abs(t[-1])))
    at = first + i
    if uniform:
        raise TrajectoryError(f"sample {at}: time {float(t[i])!r} s is off the control period grid by "
                              f"{t[i] - expected[i]:.3g} s: the time step is {step[0]:.9g} s ({1.0 / step[0]:.9g} Hz), "
                              f"not the control period {period:.9g} s (rate {rate:g} Hz)")
    if round(gap) >= 2 and abs(gap - round(gap)) < 1e-6:
        raise TrajectoryError(f"sample {at}: time {float(t[i])!r} s comes {step[i - 1]:.9g} s after sample {at - 1}: "
                              f"a gap of {round(gap) - 1} missing sample(s) at the control period {period:.9g} s "
                              f"(rate {rate:g} Hz)")
    raise TrajectoryError(f"sample {at}: time {float(t[i])!r} s is off the control period grid: expected "
                          f"t[0] + {i}/rate = {float(expected[i])!r} s (rate {rate:g} Hz)")


def _chunk_arrays(t, theta, omega, alpha, sticks, stores_alpha):
    t = np.array(as_vector("t", t), dtype=float)
    if not len(t):
        raise ParameterError("a chunk must hold at least one sample")
    theta, omega = _columns("theta", theta, len(t)), _columns("omega", omega, len(t))
    if theta.shape[1] != sticks or omega.shape[1] != sticks:
        raise ParameterError(f"theta and omega must have one column per stick ({sticks}), got {theta.shape[1]} and "
                             f"{omega.shape[1]}")
    if stores_alpha != (alpha is not None):
        raise ParameterError("alpha must be given exactly when the trajectory stores it (made from samples with "
                             f"alpha): it {'does' if stores_alpha else 'does not'}")
    alpha = None if not stores_alpha else _columns("alpha", alpha, len(t))
    return t, theta, omega, alpha


def _check_chunk(stream, t, theta, omega):
    """A chunk continues the stream's grid, is finite, stays above the head and does not jump."""
    n = stream.size
    for name, values in (("t", t), ("theta", theta), ("omega", omega)):
        bad = np.flatnonzero(~np.isfinite(values.reshape(len(t), -1)).all(axis=1))
        if len(bad):
            raise TrajectoryError(f"sample {n + int(bad[0])}: {name} is not finite; t, theta and omega must be finite")
    joined = np.concatenate((stream.t[n - 1:n], t))
    back = np.flatnonzero(np.diff(joined) <= 0.0)
    if len(back):
        i = int(back[0])
        raise TrajectoryError(f"sample {n + i}: time {float(joined[i + 1])!r} s does not come after "
                              f"{float(joined[i])!r} s; times must increase strictly")
    check_grid(joined, stream.base.rate, first=n - 1)
    heads = np.array([m.theta_max for m in stream.base.motions])
    below = np.flatnonzero((theta < heads - 1e-12).any(axis=1))
    if len(below):
        i = int(below[0])
        raise TrajectoryError(f"sample {n + i}: theta is below the head")
    dt = 1.0 / stream.base.rate
    last_theta, last_omega = stream.theta[n - 1], stream.omega[n - 1]
    reach = dt * (np.maximum(np.abs(last_omega), np.abs(omega[0])) + np.abs(omega[0] - last_omega)) + 1e-9
    jump = np.abs(theta[0] - last_theta)
    if np.any(jump > reach):
        j = int(np.argmax(jump - reach))
        raise TrajectoryError(f"sample {n}: theta of {stream.base.sticks[j]!r} jumps by {float(jump[j]):.6g} rad "
                              f"from the last sample, more than one period's travel at its speeds "
                              f"({float(reach[j]):.6g} rad): a chunk must continue the motion")


@functools.cache
def _sample_times():
    """The compiled grid of sample times, imported on first use (reading a CSV needs no compiled code)."""
    from .solver.kernel import sample_times

    return sample_times


def _identity(t):
    return t


def _as_curve(path, impacts, start, t_end):
    """A stick's path as a Curve: itself, or one segment over [start, t_end] with its impacts (s)."""
    return path if isinstance(path, Curve) else Curve((Segment(start, t_end, path, 0.0, impacts),))


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
