"""Validation before hardware: every export and every stream goes through :func:`validate`.

A trajectory for a robot joint is three arrays sampled at the control rate:
times t (s), angles θ (rad) and angular speeds ω (rad/s). It is accepted only
when, in this order,

1. every value is finite;
2. the times step by exactly one control period, t[k] = t[0] + k/rate within
   1e-9·max(1, |t[k]|) s (a repeated time, a gap and a wrong rate are told apart);
3. θ never goes below the drumhead nor outside the joint's range
   [theta_low, theta_high];
4. the speed |ω| stays within the joint's limit at every sample, and the acceleration
   α_k = (ω[k+1] − ω[k])·rate and the jerk j_k = (α[k+1] − α[k])·rate within theirs at
   every step whose finite difference spans no impact (see below);
5. it starts where the joint is (when the joint's state is given).

The first failure raises :class:`TrajectoryError` naming the sample, the
quantity, its value and the limit, e.g. ``sample 1203: speed 41.2 rad/s exceeds
max_speed 40 rad/s``. Acceleration and jerk are forward differences: the
acceleration of sample k is the step from sample k to k + 1.

An impact reverses the stick within one control period: the finite-difference acceleration
across it is about (1 + c)·|ω|·rate and the jerk beside it that times the rate, the strike's
and not the joint's, growing without bound with the rate. So the steps that span an impact
(:func:`impact_steps`: one of the trajectory's impacts falls in the step, or the stick turns
from down to up in it on the head) are bounded in angle and speed only, and every other step in
acceleration and jerk too: the same trajectory passes or fails alike at every rate. A
trajectory given as arrays has its impacts found on the head; a
:class:`~drumstroke.trajectory.Trajectory` brings its own too.

:func:`validate_kit` checks every joint of a kit's trajectory (a song on the kit) the same
way, each against its own limits, a limb's hits as its impacts.

Examples
--------
>>> import numpy as np
>>> t = np.arange(501) / 1000.0
>>> theta = 0.2 * (1 - np.cos(2 * np.pi * t / 0.5))
>>> omega = 0.2 * 2 * np.pi / 0.5 * np.sin(2 * np.pi * t / 0.5)
>>> checked = validate(t, theta, omega)
>>> round(checked.peak_speed, 3), round(checked.highest_angle, 3)
(2.513, 0.4)
>>> validate(t, theta, 20 * omega)
Traceback (most recent call last):
...
drumstroke.errors.TrajectoryError: sample 51: speed 30.054 rad/s exceeds max_speed 30 rad/s
"""

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .._checks import as_vector, check_keys, check_real, shown
from ..errors import ParameterError, TrajectoryError
from ..formats.toml import reading_toml
from ..formats.trajectory_csv import KitSamples, range_only, read_kit, read_stick
from ..kit.play import THETA
from ..palette.motion import Limits
from ..trajectory import (
    DEFAULT_RATE,
    THETA_TOP,
    TIME_TOLERANCE,
    Trajectory,
    check_grid,
    check_samples,
    reversals_on_head,
)

ANGLE_TOLERANCE = 1e-9
"""rad a kit's joint may pass its range by in :func:`validate_kit`: round-off (a pedal's beater, held at rest by
its closed-form swing, lies 1.5e-13 rad past it)."""


def read_limits(path):
    """The :class:`~drumstroke.palette.motion.Limits` of the ``[limits]`` table of the TOML file at ``path``."""
    where = f"limits file {str(path)!r}"
    with reading_toml(path, "limits file") as data:
        check_keys(where, data, ("limits",))
        if "limits" not in data:
            raise ParameterError(f"{where} needs a [limits] table")
        return Limits.from_dict(data["limits"])


@dataclass(frozen=True, eq=False, repr=False)
class Checked:
    """A trajectory that passed :func:`validate`, its finite differences and its peaks.

    The arrays are read-only copies.

    Attributes
    ----------
    t, theta, omega : ndarray [shape=(n,)]
        s, rad, rad/s.
    alpha : ndarray [shape=(n-1,)]
        α_k = (ω[k+1] − ω[k])·rate (rad/s²).
    jerk : ndarray [shape=(n-2,)]
        j_k = (α[k+1] − α[k])·rate (rad/s³).
    rate : float
        The control rate (Hz).
    head : float
        The drumhead angle it was checked against (rad).
    limits : Limits
    lowest_angle, highest_angle : float
        min θ and max θ (rad).
    peak_speed : float
        max |ω| (rad/s).
    peak_acceleration : float
        max |α| (rad/s²), over the steps that span no impact (:func:`impact_steps`).
    peak_jerk : float
        max |j| (rad/s³), likewise; 0 for two samples.
    """

    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    jerk: np.ndarray
    rate: float
    head: float
    limits: Limits
    lowest_angle: float
    highest_angle: float
    peak_speed: float
    peak_acceleration: float
    peak_jerk: float

    def __repr__(self):
        return (f"Checked({len(self.t)} samples at {self.rate:g} Hz over [{self.t[0]:g}, {self.t[-1]:g}] s, theta "
                f"{self.lowest_angle:.4g} to {self.highest_angle:.4g} rad, peak speed {self.peak_speed:.3g} rad/s)")

    def peaks(self):
        """The peak values as a dict (for reports)."""
        return {"lowest_angle": self.lowest_angle, "highest_angle": self.highest_angle,
                "peak_speed": self.peak_speed, "peak_acceleration": self.peak_acceleration,
                "peak_jerk": self.peak_jerk}


def validate(trajectory, theta=None, omega=None, *, rate=None, head=None, limits=None, start=None, stick=None,
             impacts=None):
    """Check a joint trajectory before it goes to hardware; return it as :class:`Checked`.

    Parameters
    ----------
    trajectory : Trajectory or ndarray
        A :class:`~drumstroke.trajectory.Trajectory` (one stick, or name its ``stick``), or the
        sample times t (s) [shape=(n,)] of a chunk given as arrays with ``theta`` and ``omega``.
    theta, omega : ndarray [shape=(n,)] or None
        With times: the joint angles (rad) and speeds (rad/s).
    rate : float in (0, 1e6] or None
        The control rate (Hz): the samples must be 1/rate apart. Default the trajectory's;
        for arrays :data:`~drumstroke.trajectory.DEFAULT_RATE`.
    head : float in [-π/2, π/2] or None
        The drumhead angle (rad) θ may not go below; default ``limits.theta_low``.
    limits : Limits or None
        Default ``Limits()``.
    start : (float, float) or None
        The joint's angle (rad) and speed (rad/s) now: the trajectory must start
        there, within the limits' start tolerances.
    stick : str or None
        The stick to check of a trajectory with several.
    impacts : ndarray or None
        The times (s) of the impacts in the samples [shape=(m,)], beside the reversals found on the
        head (:func:`impact_steps`); default a Trajectory's own, none for arrays.

    Returns
    -------
    Checked

    Raises
    ------
    TrajectoryError
        The first check that fails, naming the sample, the quantity, the value and the limit.
    ParameterError
        Malformed input (arrays of different lengths, a bad rate, …).
    """
    limits = _check_limits(limits)
    if rate is not None:
        rate = check_real("rate", rate, low=0.0, high=1e6, low_open=True, unit="Hz")
    head = limits.theta_low if head is None else check_real("head", head, low=-THETA_TOP, high=THETA_TOP, unit="rad")
    if start is not None:
        start = _check_start(start)
    t, theta, omega, own_rate, own_impacts = _columns(trajectory, theta, omega, rate, stick)
    impacts = own_impacts if impacts is None else _check_impacts(impacts)
    rate = own_rate if rate is None else rate
    if rate != own_rate:
        check_grid(t, rate)
    return _checked(t, theta, omega, rate, head, limits, start, impacts=impacts)


def _checked(t, theta, omega, rate, head, limits, start=None, *, impacts=None, dynamics=True, tolerance=0.0):
    """Checks 3 to 5 of samples on the grid (new arrays, made read-only), as :class:`Checked`.

    The accelerations and jerks whose steps span an impact (:func:`impact_steps`) are not bounded; without
    ``dynamics`` only the angles are; they may pass their bounds by ``tolerance`` (rad).
    """
    _check_angles(theta, head, limits, tolerance)
    alpha = np.diff(omega) * rate
    jerk = np.diff(alpha) * rate
    struck = impact_steps(t, theta, omega, head, impacts)
    steady_alpha, steady_jerk = np.abs(alpha) * ~struck, np.abs(jerk) * ~(struck[:-1] | struck[1:])
    if dynamics:
        _check_bound(np.abs(omega), omega, "speed", "max_speed", limits.max_speed, "rad/s")
        _check_bound(steady_alpha, alpha, "acceleration", "max_acceleration", limits.max_acceleration, "rad/s²")
        _check_bound(steady_jerk, jerk, "jerk", "max_jerk", limits.max_jerk, "rad/s³")
    if start is not None:
        _check_start_state(theta[0], omega[0], start, limits)
    for array in (t, theta, omega, alpha, jerk):
        array.flags.writeable = False
    return Checked(t=t, theta=theta, omega=omega, alpha=alpha, jerk=jerk, rate=rate, head=head, limits=limits,
                   lowest_angle=float(theta.min()), highest_angle=float(theta.max()),
                   peak_speed=float(np.abs(omega).max()), peak_acceleration=float(steady_alpha.max()),
                   peak_jerk=float(steady_jerk.max()) if len(jerk) else 0.0)


def _columns(trajectory, theta, omega, rate, stick):
    """One stick's t, θ, ω (new arrays), the rate they are sampled at and its impacts' times (s; None for arrays),
    from a Trajectory or from arrays (checked: finite, on the time grid; no Trajectory is built for arrays: a
    live stream validates each chunk)."""
    if isinstance(trajectory, Trajectory):
        if theta is not None or omega is not None:
            raise ParameterError("give a Trajectory, or the arrays t, theta and omega, not both")
        one = trajectory if stick is None and len(trajectory.sticks) == 1 else trajectory.stick(
            stick if stick is not None else _one_stick(trajectory))
        return (*(np.array(a) for a in one.columns()), one.rate, one.impacts.t)
    t, theta, omega = (as_vector(name, values) for name, values in (("t", trajectory), ("theta", theta),
                                                                   ("omega", omega)))
    t, theta, omega, _, rate = check_samples(t, theta, omega, None, DEFAULT_RATE if rate is None else rate)
    return t, theta[:, 0], omega[:, 0], rate, None


def _check_impacts(impacts):
    times = as_vector("impacts", impacts)
    if not np.isfinite(times).all():
        raise ParameterError(f"impacts must be finite times (s), got {shown(impacts)}", parameter="impacts",
                             value=impacts, allowed="finite times (s)")
    return times


def _one_stick(trajectory):
    raise ParameterError(f"the trajectory has the sticks {', '.join(trajectory.sticks)}; name one (stick)")


def validate_file(path, *, stick=None, rate=None, head=None, limits=None, start=None):
    """Validate the trajectory of a CSV file (a stroke, a library stroke, a composition or an export).

    Parameters
    ----------
    path : str or Path
        A CSV with the columns ``t,theta,omega`` (or ``theta_<stick>,omega_<stick>``); the impacts the JSON
        beside it records, if it does, are the trajectory's (see :func:`impact_steps`).
    stick : str or None
        Which stick of a composition with several (its column suffix).
    rate : float or None
        The control rate (Hz); default the rate of the first time step. Either
        way it must agree with the rate the file states, when it states one (in
        the JSON beside it, or in the comment line of an older drumstroke's file).
    head, limits, start
        As for :func:`validate`.

    Returns
    -------
    Checked
    """
    t, theta, omega, _, info, impacts = read_stick(path, stick=stick)
    where = f"trajectory file {str(path)!r}"
    stated = info["rate"] if info["rate_from"] != "its t column" else None
    if rate is not None:
        rate = check_real("rate", rate, low=0.0, high=1e6, low_open=True, unit="Hz")
    elif t[1] > t[0]:
        rate = 1.0 / (t[1] - t[0])
    else:
        raise TrajectoryError(f"{where}: sample 1: time {float(t[1])!r} s does not come after sample 0 "
                              f"({float(t[0])!r} s); times must increase strictly")
    if stated is not None and abs(rate - stated) > 1e-6 * stated:
        raise TrajectoryError(f"{where}: rate {rate:.9g} Hz (its time step is {t[1] - t[0]:.9g} s) disagrees with "
                              f"the rate {stated:g} Hz of its {info['rate_from']}")
    try:
        return validate(t, theta, omega, rate=stated if stated is not None else rate, head=head, limits=limits,
                        start=start, impacts=impacts)
    except TrajectoryError as error:
        raise TrajectoryError(f"{where}: {error}") from None


def impact_steps(t, theta, omega, head, impacts=None):
    """True for each step from sample k to k+1 that spans an impact [shape=(n-1,)].

    A step spans an impact when one of ``impacts`` falls in it, or when the stick turns from down to
    up in it on the head (:func:`~drumstroke.trajectory.reversals_on_head`): samples alone show
    where a stick struck. An impact at a sample's time (within the time grid's tolerance) may fall on
    either side of it, so both steps beside that sample are taken as spanning it. The acceleration
    of a step that spans an impact, and the jerks beside it, are the strike's; :func:`validate` and
    :func:`validate_kit` bound only those of the other steps.

    Parameters
    ----------
    t, theta, omega : ndarray [shape=(n,)]
        Samples on a time grid: s, rad, rad/s.
    head : float or None
        The angle (rad) the stick strikes; None: a joint that strikes nothing (a hand's positioning joint).
    impacts : ndarray or None
        The impacts' times (s) [shape=(m,)], known beside the samples.

    Examples
    --------
    >>> t = np.arange(5) * 1e-3
    >>> impact_steps(t, [0.03, 0.02, 0.01, 0.005, 0.02], [-10.0, -10.0, -10.0, 10.0, 10.0], 0.0)
    array([False, False,  True, False])
    >>> impact_steps(t, [0.5] * 5, [0.0] * 5, 0.0, impacts=[0.002])
    array([False,  True,  True, False])
    """
    struck = np.zeros(len(t) - 1, dtype=bool) if head is None else reversals_on_head(t, theta, omega, head)
    if impacts is not None and len(impacts):
        impacts = np.asarray(impacts, dtype=float)
        tolerance = TIME_TOLERANCE * np.maximum(1.0, np.abs(impacts))
        first = np.clip(np.searchsorted(t, impacts - tolerance) - 1, 0, len(struck))
        last = np.clip(np.searchsorted(t, impacts + tolerance) - 1, -1, len(struck) - 1)
        marks = np.zeros(len(struck) + 1, dtype=int)
        np.add.at(marks, first, 1)
        np.add.at(marks, last + 1, -1)
        struck |= np.cumsum(marks[:-1]) > 0
    return struck


def validate_kit(source, *, limits=None, tolerance=ANGLE_TOLERANCE):
    """Check every joint of a kit's trajectory against its limits before it goes to hardware.

    Each joint is checked as :func:`validate` checks a stick's joint, against its own limits (as
    :meth:`drumstroke.compose.KitComposition.samples` records them): a hand's positioning joints
    against the kit's; a stick's θ against the sticks' joint limits over the range from the lowest
    surface its hand plays; a pedal's beater for its range alone (no motor drives it: its spring and
    the foot do). The surface a stick or beater strikes reverses it within one control period, so
    the finite-difference acceleration and jerk across an impact are the strike's, not the joint's,
    and grow with the rate without bound: the steps that span one of the limb's hits (or a reversal
    on its lowest surface, :func:`impact_steps`) are not bounded, and the rest are, at any rate.

    Parameters
    ----------
    source : KitComposition, KitSamples, str or Path
        A composition (:func:`drumstroke.compose.compose_kit`), its samples, or a kit trajectory CSV
        with the JSON beside it (:func:`drumstroke.formats.trajectory_csv.read_kit`).
    limits : Limits or None
        The sticks' joint limits, for those recorded (θ's speed, acceleration, jerk and highest angle;
        its lowest stays its hand's lowest surface).
    tolerance : float in [0, 0.01]
        rad an angle may pass its range by: the round-off of exact motions (default
        :data:`ANGLE_TOLERANCE`).

    Returns
    -------
    dict of str to Checked
        Every joint's, by its column name (``LIMB.JOINT``), in order.

    Raises
    ------
    TrajectoryError
        Naming each joint that fails and its first failure (the sample, the quantity, the value, the limit).
    """
    samples, where = kit_samples(source)
    tolerance = check_real("tolerance", tolerance, low=0.0, high=0.01, unit="rad")
    if limits is not None:
        limits = _check_limits(limits)
    try:
        check_grid(samples.t, samples.rate)
    except TrajectoryError as error:
        raise TrajectoryError(f"{where}{error}") from None
    checked, failures = {}, []
    for column in samples.positions:
        try:
            checked[column] = _kit_joint(samples, column, limits, tolerance)
        except (TrajectoryError, ParameterError) as error:
            failures.append(f"joint {column!r}: {error}")
    if failures:
        count = "" if len(failures) == 1 else f"{len(failures)} of {len(samples.positions)} joints fail: "
        raise TrajectoryError(f"{where}{count}{'; '.join(failures)}")
    return checked


def kit_samples(source):
    """A kit's samples from a composition, samples or a file, and the words that prefix its errors."""
    from ..compose import KitComposition

    if isinstance(source, KitComposition):
        return source.samples(), ""
    if isinstance(source, KitSamples):
        return source, ""
    if isinstance(source, (str, Path)):
        return read_kit(source), f"kit trajectory file {str(source)!r}: "
    raise ParameterError(f"source must be a KitComposition, KitSamples or a kit trajectory file, got {source!r}")


def _kit_joint(samples, column, sticks, tolerance):
    """One joint of a kit checked against its limits (see :func:`validate_kit`)."""
    limb, _, joint = column.partition(".")
    table = samples.limits[column]
    own = Limits.from_dict(table)
    angle = joint == THETA  # a stick's or a beater's: the surface it strikes is its lowest angle
    dynamics = not range_only(table)
    if angle and dynamics and sticks is not None:
        own = replace(sticks, theta_low=own.theta_low)
    impacts = samples.hits.get(limb) if angle else None
    return _checked(np.array(samples.t), np.array(samples.positions[column]), np.array(samples.velocities[column]),
                    samples.rate, own.theta_low if angle else None, own, impacts=impacts, dynamics=dynamics,
                    tolerance=tolerance)


def _check_limits(limits):
    if limits is None:
        return Limits()
    if not isinstance(limits, Limits):
        raise ParameterError(f"limits must be a Limits, got {limits!r}")
    return limits


def _check_start(start):
    try:
        theta_now, omega_now = (v.item() if isinstance(v, np.ndarray) and v.ndim == 0 else v for v in start)
    except (TypeError, ValueError):
        raise ParameterError(f"start must be the joint's (angle rad, speed rad/s), got {start!r}") from None
    return (check_real("start angle", theta_now, unit="rad"), check_real("start speed", omega_now, unit="rad/s"))


def _check_angles(theta, head, limits, tolerance=0.0):
    checks = [] if head is None else [(theta < head - tolerance, f"is below the head {head:.9g} rad")]
    for bad, text in checks + [
        (theta < limits.theta_low - tolerance, f"is below theta_low {limits.theta_low:.9g} rad"),
        (theta > limits.theta_high + tolerance, f"exceeds theta_high {limits.theta_high:.9g} rad"),
    ]:
        where = np.flatnonzero(bad)
        if len(where):
            i = int(where[0])
            raise TrajectoryError(f"sample {i}: theta {theta[i]:.9g} rad {text}")


def _check_bound(magnitude, values, quantity, limit_name, limit, unit):
    over = np.flatnonzero(magnitude > limit)
    if len(over):
        i = int(over[0])
        value = f"{magnitude[i]:.6g}" if quantity == "speed" else f"{values[i]:.6g}"
        size = "" if quantity == "speed" else " in magnitude"
        raise TrajectoryError(f"sample {i}: {quantity} {value} {unit} exceeds {limit_name} {limit:g} {unit}{size}")


def _check_start_state(theta0, omega0, start, limits):
    theta_now, omega_now = start
    if abs(theta0 - theta_now) > limits.start_angle_tolerance:
        raise TrajectoryError(f"sample 0: theta {theta0:.9g} rad is {abs(theta0 - theta_now):.6g} rad from the "
                              f"joint's angle {theta_now:.9g} rad, beyond start_angle_tolerance "
                              f"{limits.start_angle_tolerance:g} rad")
    if abs(omega0 - omega_now) > limits.start_speed_tolerance:
        raise TrajectoryError(f"sample 0: omega {omega0:.6g} rad/s is {abs(omega0 - omega_now):.6g} rad/s from the "
                              f"joint's speed {omega_now:.6g} rad/s, beyond start_speed_tolerance "
                              f"{limits.start_speed_tolerance:g} rad/s")
