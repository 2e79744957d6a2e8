"""Validation before hardware (SPEC §5): every export and every stream goes through :func:`validate`.

A trajectory for a robot joint is three arrays sampled at the control rate:
times t (s), angles θ (rad) and angular speeds ω (rad/s). It is accepted only
when, in this order,

1. every value is finite;
2. the times step by exactly one control period, t[k] = t[0] + k/rate within
   1e-9·max(1, |t[k]|) s (a repeated time, a gap and a wrong rate are told apart);
3. θ never goes below the drumhead nor outside the joint's range
   [theta_low, theta_high];
4. the speed |ω|, the acceleration α_k = (ω[k+1] − ω[k])·rate and the jerk
   j_k = (α[k+1] − α[k])·rate stay within the joint's limits;
5. it starts where the joint is (when the joint's state is given).

The first failure raises :class:`TrajectoryError` naming the sample, the
quantity, its value and the limit, e.g. ``sample 1203: speed 41.2 rad/s exceeds
max_speed 40 rad/s``. Acceleration and jerk are forward differences: the
acceleration of sample k is the step from sample k to k + 1.

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
drumstroke.robot.validate.TrajectoryError: sample 51: speed 30.054 rad/s exceeds max_speed 30 rad/s
"""

import re
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from .._checks import as_vector, check_keys, check_real, read_toml
from ..errors import ParameterError
from ..model import Stick
from ..palette.trajectory import THETA_TOP, read_trajectory_csv

DEFAULT_RATE = 1000.0
"""The control rate the default limits are set for (Hz)."""

_TIME_TOLERANCE = 1e-9
"""Relative tolerance of a sample time against its place on the control period grid."""


class TrajectoryError(ParameterError):
    """A trajectory breaks a check of :func:`validate`; the message names the sample, quantity, value and limit."""


@dataclass(frozen=True)
class JointLimits:
    """What the robot joint can do: its range and its speed, acceleration and jerk limits.

    The defaults are those of a strong joint that can play the shipped palette
    at 1 kHz, composed at any velocity. Impacts are velocity reversals within
    one control period, so the finite-difference acceleration and jerk at an
    impact are about (1 + c)·|ω|·rate and that times the rate; the defaults are
    set at least twice the largest values measured at 1 kHz: the shipped
    library reaches 12.12 rad/s, 22 544 rad/s² and 2.283e7 rad/s³
    (``superhuman-press``), compositions at velocity 127 (a 4 m/s tip speed)
    14.81 rad/s, 27 458 rad/s² and 2.756e7 rad/s³. At another rate r the
    impacts' acceleration scales with r/1000 and their jerk with (r/1000)².

    Parameters
    ----------
    theta_low : float in [-π/2, π/2)
        The lowest angle the joint may reach (rad). Default: the paper stick's
        head, ``Stick().theta_max`` ≈ −0.2623 rad.
    theta_high : float in (theta_low, π/2]
        The highest angle (rad). Default π/2, the stick upright.
    max_speed : float > 0
        |ω| limit (rad/s). Default 30.
    max_acceleration : float > 0
        |α| limit (rad/s²). Default 60 000.
    max_jerk : float > 0
        |j| limit (rad/s³). Default 6e7.
    start_angle_tolerance : float ≥ 0
        How far the first sample's θ may be from the joint's angle (rad). Default 0.01.
    start_speed_tolerance : float ≥ 0
        How far the first sample's ω may be from the joint's speed (rad/s). Default 0.5.

    Examples
    --------
    >>> JointLimits().max_speed
    30.0
    >>> JointLimits(max_speed=-1)
    Traceback (most recent call last):
    ...
    drumstroke.errors.ParameterError: limits.max_speed must be in (0, inf) rad/s, got -1.0
    """

    theta_low: float = Stick().theta_max
    theta_high: float = THETA_TOP
    max_speed: float = 30.0
    max_acceleration: float = 6.0e4
    max_jerk: float = 6.0e7
    start_angle_tolerance: float = 0.01
    start_speed_tolerance: float = 0.5

    def __post_init__(self):
        low = check_real("limits.theta_low", self.theta_low, low=-THETA_TOP, high=THETA_TOP, high_open=True,
                         unit="rad")
        values = {
            "theta_low": low,
            "theta_high": check_real("limits.theta_high", self.theta_high, low=low, high=THETA_TOP, low_open=True,
                                     unit="rad"),
            "max_speed": check_real("limits.max_speed", self.max_speed, low=0.0, low_open=True, unit="rad/s"),
            "max_acceleration": check_real("limits.max_acceleration", self.max_acceleration, low=0.0,
                                           low_open=True, unit="rad/s^2"),
            "max_jerk": check_real("limits.max_jerk", self.max_jerk, low=0.0, low_open=True, unit="rad/s^3"),
            "start_angle_tolerance": check_real("limits.start_angle_tolerance", self.start_angle_tolerance,
                                                low=0.0, unit="rad"),
            "start_speed_tolerance": check_real("limits.start_speed_tolerance", self.start_speed_tolerance,
                                                low=0.0, unit="rad/s"),
        }
        for name, value in values.items():
            object.__setattr__(self, name, value)

    @classmethod
    def from_dict(cls, table):
        """Limits from a TOML ``[limits]`` table (a dict); keys as the parameters, missing ones default."""
        if not isinstance(table, dict):
            raise ParameterError(f"limits must be a table, got {table!r}")
        check_keys("limits", table, [f.name for f in fields(cls)])
        return cls(**table)

    def to_dict(self):
        """The limits as a plain dict, keys as in a ``[limits]`` table."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


def read_limits(path):
    """The :class:`JointLimits` of the ``[limits]`` table of the TOML file at ``path``."""
    data = read_toml(path, "limits file")
    where = f"limits file {str(path)!r}"
    try:
        check_keys(where, data, ("limits",))
        if "limits" not in data:
            raise ParameterError(f"{where} needs a [limits] table")
        return JointLimits.from_dict(data["limits"])
    except ParameterError as error:
        text = str(error)
        raise ParameterError(text if where in text else f"{where}: {text}") from None


@dataclass(frozen=True, eq=False)
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
    limits : JointLimits
    lowest_angle, highest_angle : float
        min θ and max θ (rad).
    peak_speed : float
        max |ω| (rad/s).
    peak_acceleration : float
        max |α| (rad/s²).
    peak_jerk : float
        max |j| (rad/s³); 0 for two samples.
    """

    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    jerk: np.ndarray
    rate: float
    head: float
    limits: JointLimits
    lowest_angle: float
    highest_angle: float
    peak_speed: float
    peak_acceleration: float
    peak_jerk: float

    def peaks(self):
        """The peak values as a dict (for reports)."""
        return {"lowest_angle": self.lowest_angle, "highest_angle": self.highest_angle,
                "peak_speed": self.peak_speed, "peak_acceleration": self.peak_acceleration,
                "peak_jerk": self.peak_jerk}


def validate(t, theta, omega, *, rate=DEFAULT_RATE, head=None, limits=None, start=None):
    """Check a joint trajectory before it goes to hardware; return it as :class:`Checked`.

    Parameters
    ----------
    t : ndarray [shape=(n,)]
        Sample times (s), n ≥ 2.
    theta : ndarray [shape=(n,)]
        Joint angles (rad).
    omega : ndarray [shape=(n,)]
        Joint angular speeds (rad/s).
    rate : float in (0, 1e6]
        The control rate (Hz): the samples must be 1/rate apart.
    head : float in [-π/2, π/2] or None
        The drumhead angle (rad) θ may not go below; default ``limits.theta_low``.
    limits : JointLimits or None
        Default ``JointLimits()``.
    start : (float, float) or None
        The joint's angle (rad) and speed (rad/s) now: the trajectory must start
        there, within the limits' start tolerances.

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
    rate = check_real("rate", rate, low=0.0, high=1e6, low_open=True, unit="Hz")
    head = limits.theta_low if head is None else check_real("head", head, low=-THETA_TOP, high=THETA_TOP, unit="rad")
    if start is not None:
        start = _check_start(start)
    t, theta, omega = (np.array(as_vector(name, values), dtype=float)
                       for name, values in (("t", t), ("theta", theta), ("omega", omega)))
    if not len(t) == len(theta) == len(omega) or len(t) < 2:
        raise ParameterError(f"t, theta and omega must have the same length >= 2, got {len(t)}, {len(theta)} and "
                             f"{len(omega)}")
    for name, values in (("t", t), ("theta", theta), ("omega", omega)):
        _check_finite(name, values)
    _check_times(t, rate)
    _check_angles(theta, head, limits)
    alpha = np.diff(omega) * rate
    jerk = np.diff(alpha) * rate
    _check_bound(np.abs(omega), omega, "speed", "max_speed", limits.max_speed, "rad/s")
    _check_bound(np.abs(alpha), alpha, "acceleration", "max_acceleration", limits.max_acceleration, "rad/s²")
    _check_bound(np.abs(jerk), jerk, "jerk", "max_jerk", limits.max_jerk, "rad/s³")
    if start is not None:
        _check_start_state(theta[0], omega[0], start, limits)
    for array in (t, theta, omega, alpha, jerk):
        array.flags.writeable = False
    return Checked(t=t, theta=theta, omega=omega, alpha=alpha, jerk=jerk, rate=rate, head=head, limits=limits,
                   lowest_angle=float(theta.min()), highest_angle=float(theta.max()),
                   peak_speed=float(np.abs(omega).max()), peak_acceleration=float(np.abs(alpha).max()),
                   peak_jerk=float(np.abs(jerk).max()) if len(jerk) else 0.0)


def validate_file(path, *, stick=None, rate=None, head=None, limits=None, start=None):
    """Validate the trajectory of a CSV file (a stroke, a library stroke, a composition or an export).

    Parameters
    ----------
    path : str or Path
        A CSV with the columns ``t,theta,omega`` (or ``theta_<stick>,omega_<stick>``).
    stick : str or None
        Which stick of a composition with several (its column suffix).
    rate : float or None
        The control rate (Hz); default the rate of the first time step. Either
        way it must agree with the file's ``rate=… Hz`` comment, when it has one.
    head, limits, start
        As for :func:`validate`.

    Returns
    -------
    Checked
    """
    t, theta, omega, _ = read_trajectory_csv(path, stick=stick)
    where = f"trajectory file {str(path)!r}"
    stated = _stated_rate(path)
    if rate is not None:
        rate = check_real("rate", rate, low=0.0, high=1e6, low_open=True, unit="Hz")
    elif t[1] > t[0]:
        rate = 1.0 / (t[1] - t[0])
    else:
        raise TrajectoryError(f"{where}: sample 1: time {float(t[1])!r} s does not come after sample 0 "
                              f"({float(t[0])!r} s); times must increase strictly")
    if stated is not None and abs(rate - stated) > 1e-6 * stated:
        raise TrajectoryError(f"{where}: rate {rate:.9g} Hz (its time step is {t[1] - t[0]:.9g} s) disagrees with "
                              f"its comment's rate={stated:g} Hz")
    try:
        return validate(t, theta, omega, rate=stated if stated is not None else rate, head=head, limits=limits,
                        start=start)
    except TrajectoryError as error:
        raise TrajectoryError(f"{where}: {error}") from None


def _check_limits(limits):
    if limits is None:
        return JointLimits()
    if not isinstance(limits, JointLimits):
        raise ParameterError(f"limits must be a JointLimits, got {limits!r}")
    return limits


def _check_start(start):
    try:
        theta_now, omega_now = (v.item() if isinstance(v, np.ndarray) and v.ndim == 0 else v for v in start)
    except (TypeError, ValueError):
        raise ParameterError(f"start must be the joint's (angle rad, speed rad/s), got {start!r}") from None
    return (check_real("start angle", theta_now, unit="rad"), check_real("start speed", omega_now, unit="rad/s"))


def _check_finite(name, values):
    bad = np.flatnonzero(~np.isfinite(values))
    if len(bad):
        i = int(bad[0])
        raise TrajectoryError(f"sample {i}: {name} is {float(values[i])!r}; t, theta and omega must be finite")


def _check_times(t, rate):
    step = np.diff(t)
    back = np.flatnonzero(step <= 0.0)
    if len(back):
        i = int(back[0]) + 1
        how = "repeats the time of" if step[i - 1] == 0.0 else "goes back in time from"
        raise TrajectoryError(f"sample {i}: time {float(t[i])!r} s {how} sample {i - 1} ({float(t[i - 1])!r} s); "
                              "times must increase strictly")
    period = 1.0 / rate
    k = np.arange(len(t))
    expected = t[0] + k / rate
    off = np.flatnonzero(np.abs(t - expected) > _TIME_TOLERANCE * np.maximum(1.0, np.abs(t)))
    if not len(off):
        return
    i = int(off[0])
    gap = step[i - 1] * rate
    uniform = np.all(np.abs(step - step[0]) <= _TIME_TOLERANCE * max(1.0, abs(t[-1])))
    if uniform:
        raise TrajectoryError(f"sample {i}: time {float(t[i])!r} s is off the control period grid by "
                              f"{t[i] - expected[i]:.3g} s: the time step is {step[0]:.9g} s ({1.0 / step[0]:.9g} Hz), "
                              f"not the control period {period:.9g} s (rate {rate:g} Hz)")
    if round(gap) >= 2 and abs(gap - round(gap)) < 1e-6:
        raise TrajectoryError(f"sample {i}: time {float(t[i])!r} s comes {step[i - 1]:.9g} s after sample {i - 1}: "
                              f"a gap of {round(gap) - 1} missing sample(s) at the control period {period:.9g} s "
                              f"(rate {rate:g} Hz)")
    raise TrajectoryError(f"sample {i}: time {float(t[i])!r} s is off the control period grid: expected "
                          f"t[0] + {i}/rate = {float(expected[i])!r} s at rate {rate:g} Hz")


def _check_angles(theta, head, limits):
    for bad, text in (
        (theta < head, f"is below the head {head:.9g} rad"),
        (theta < limits.theta_low, f"is below theta_low {limits.theta_low:.9g} rad"),
        (theta > limits.theta_high, f"exceeds theta_high {limits.theta_high:.9g} rad"),
    ):
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


_RATE = re.compile(r"(?:^|; )rate=([^ ;]+) Hz(?:;|$)")


def _stated_rate(path):
    """The rate of a drumstroke CSV's comment line (Hz), or None when it states none."""
    with Path(path).open() as handle:
        match = _RATE.search(handle.readline().lstrip("#").strip())
    if match is None:
        return None
    try:
        return float(match.group(1))
    except ValueError:
        return None
