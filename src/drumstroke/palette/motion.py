"""Moving the stick between strokes: returns, holds and joins, within one joint-limits type.

:class:`Limits` is what a joint may do — its range, speed, acceleration and jerk — and how near
its state a trajectory must start; the robot (:mod:`drumstroke.robot`) validates trajectories
against it, and the moves here are planned within it. ``Limits()`` is a strong drumming joint
that plays the shipped palette at 1 kHz; :data:`RETURN_LIMITS` is the gentler default budget of
the moves between strokes.

- :func:`plan_return`: from where one stroke ends to where the next begins in a given time —
  a move to the target angle at rest, a hold, a wind-up into the target speed — every move
  time-optimal and jerk-limited (ruckig, the standard online trajectory generator), with zero
  acceleration at its ends, within the limits, never below the head; :func:`plan_move`, one such
  move of a given duration; :func:`synchronised_move`, several joints moving together (a hand carrying
  its stick from one piece of a kit to another), every joint arriving at once.
- :func:`assemble`: trajectories placed on one timeline with the returns between them;
  :func:`concat`: one after another with given gaps.

Examples
--------
>>> import drumstroke
>>> single = drumstroke.simulate("free-bounce", t_end=0.5).sample(1000.0)
>>> twice = concat([single, single], 0.4)
>>> round(twice.t_end, 6), len(twice.impacts) == 2 * len(single.impacts)
(1.4, True)
>>> Limits().max_speed, RETURN_LIMITS.max_speed
(30.0, 20.0)
"""

import functools
import itertools
import math
import threading
from dataclasses import dataclass, field, fields, replace

import numpy as np

from .._checks import check_keys, check_real
from ..curve import Cubic, Curve, Segment, placed, still
from ..errors import ParameterError
from ..model import Stick
from ..stroke import Stroke, as_trajectory
from ..trajectory import THETA_TOP, Impacts, Trajectory


@dataclass(frozen=True)
class Limits:
    """What a robot joint may do: its speed, acceleration and jerk limits, its range, and how near it a start must be.

    What is bounded where: the angle and the speed at every sample; the
    acceleration and the jerk (finite differences at the control rate) at every
    step but those that span an impact (:func:`drumstroke.robot.validate.impact_steps`).
    An impact reverses the stick within one control period, so the finite-difference
    acceleration across it is about (1 + c)·|ω|·rate and the jerk beside it that
    times the rate: the strike's, not the joint's, growing without bound with the
    rate r (by r/1000 and (r/1000)² from their values at 1 kHz). Those steps being
    left out, one motion passes or fails alike at every rate; the jerk where a force
    switches at once (a stroke's pulses) is still the step of α times the rate.

    The defaults are those of a strong joint, at least twice the largest values the
    shipped palette and compositions at any velocity reach at 1 kHz, impacts
    included: the shipped library reaches 12.12 rad/s, 22 544 rad/s² and
    2.283e7 rad/s³ (``superhuman-press``), compositions at velocity 127 (a 4 m/s
    tip speed) 14.81 rad/s, 27 458 rad/s² and 2.756e7 rad/s³. Away from impacts
    the library reaches some 300 rad/s² at any rate, and 2.6e4 rad/s³ at 1 kHz
    (``finger-pulses``, 2.6e6 at 100 kHz). Moves between strokes are planned
    within their speed and acceleration (:data:`RETURN_LIMITS` by default).

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
    >>> Limits().max_speed
    30.0
    >>> Limits(max_speed=-1)
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

    def within(self, joint):
        """A budget within ``joint``'s limits: the joint's range, and the lower of each speed, acceleration and jerk.

        >>> moves = RETURN_LIMITS.within(Limits(theta_high=0.5, max_speed=10.0))
        >>> moves.theta_high, moves.max_speed, moves.max_acceleration
        (0.5, 10.0, 1000.0)
        """
        if not isinstance(joint, Limits):
            raise ParameterError(f"joint must be a drumstroke.palette.motion.Limits, got {joint!r}")
        return replace(self, theta_low=joint.theta_low, theta_high=joint.theta_high,
                       max_speed=min(self.max_speed, joint.max_speed),
                       max_acceleration=min(self.max_acceleration, joint.max_acceleration),
                       max_jerk=min(self.max_jerk, joint.max_jerk))


RETURN_LIMITS = Limits(max_speed=20.0, max_acceleration=1000.0, max_jerk=1.0e5)
"""The default budget of the moves between strokes: 20 rad/s, 1000 rad/s², 1e5 rad/s³ (gentler than the joint can)."""


def concat(strokes, gaps=0.0, *, limits=None, name="concat"):
    """The strokes one after another, the stick returning smoothly in each gap.

    Parameters
    ----------
    strokes : sequence of Trajectory or Stroke
        At least one, all for the same stick (the same head angle).
    gaps : float or sequence of float ≥ 0
        Time (s) between the end of each stroke and the start of the next
        [one, or shape=(len(strokes) - 1,)]. A gap of 0 needs the next stroke
        to start where the previous one ends.
    limits : Limits or None
        Speed and acceleration bounds on the returns (default :data:`RETURN_LIMITS`).
    name : str
    """
    pieces = [as_trajectory(s) for s in strokes] if not isinstance(strokes, (Stroke, Trajectory)) else None
    if not pieces:
        raise ParameterError(f"strokes must be a non-empty sequence of strokes, got {strokes!r}")
    gaps = np.broadcast_to(np.asarray(gaps, dtype=float), (len(pieces) - 1,)) if len(pieces) > 1 else np.empty(0)
    for i, gap in enumerate(gaps):
        check_real(f"gaps[{i}]", float(gap), low=0.0, high=3600.0, unit="s")
    starts = np.concatenate(([0.0], np.cumsum([p.t_end for p in pieces[:-1]] + gaps)))
    return assemble(pieces, starts, limits=limits or RETURN_LIMITS, name=name)


def assemble(pieces, starts, *, limits, name, end=None, home=True, ends=None):
    """Place trajectories at ``starts`` (s) on one timeline, with smooth returns between them.

    Before the first piece the stick holds its start angle (and winds up into
    its start speed); after the last, if ``end`` (s) is given, it returns to the
    last piece's start angle (``home``) or stays where the last piece left it, at
    rest (not ``home``), and holds there until ``end``. Raises
    ParameterError naming ``gaps[i]`` when a return
    does not fit.

    ``ends``, when the caller knows them (a planner's designs), are each piece's states at its start
    and at its ``t_end``, ((θ rad, ω rad/s), (θ rad, ω rad/s)) as the piece's path gives them: the
    pieces are then not evaluated for them.
    """
    head = pieces[0].theta_max
    for i, p in enumerate(pieces):
        if abs(p.theta_max - head) > 1e-12 or p.impacts.tip_distance != pieces[0].impacts.tip_distance:
            raise ParameterError(f"strokes[{i}] is for a different stick (theta_max {p.theta_max:.6g} rad, "
                                 f"strokes[0] has {head:.6g} rad); concatenate strokes of one stick")
    if ends is None:
        ends = [_ends(piece) for piece in pieces]
    starts = [float(start) for start in starts]  # Python's floats: numpy's scalars cost more at each operation
    segments = []
    first = ends[0][0]
    if starts[0] > 0.0:
        plan = plan_return((first[0], 0.0), first, starts[0], head, limits)
        if plan is None:
            raise ParameterError(f"the first stroke needs a lead-in before it starts at {starts[0]:g} s")
        segments += placed(plan, 0.0)
    for i, piece in enumerate(pieces):
        segments.append(Segment(starts[i], starts[i] + piece.t_end, piece.path, starts[i], piece.impacts.t))
        after = starts[i] + piece.t_end
        if i + 1 < len(pieces):
            window = starts[i + 1] - after
            plan = plan_return(ends[i][1], ends[i + 1][0], window, head, limits)
            if plan is None:
                label = f"gaps[{i}]"
                need = return_time(ends[i][1], ends[i + 1][0], head, limits)
                needed = f"at least {need:.4g} s" if math.isfinite(need) else "a different end or start state"
                raise ParameterError(
                    f"{label} = {window:.6g} s is too short for the stick to return from {piece.name!r} to "
                    f"{pieces[i + 1].name!r} within {limits.max_speed:g} rad/s and {limits.max_acceleration:g} "
                    f"rad/s^2 above the head; it needs {needed}")
            segments += placed(plan, after)
    t_end = starts[-1] + pieces[-1].t_end
    if end is not None and end > t_end:
        last = pieces[-1]
        target = (ends[-1][0][0] if home else ends[-1][1][0], 0.0)
        plan = plan_return(ends[-1][1], target, end - t_end, head, limits)
        if plan is None:
            raise ParameterError(f"the last stroke {last.name!r} cannot return home by {end:g} s")
        segments += placed(plan, t_end)
        t_end = end
    impacts_t = np.concatenate([p.impacts.t + s for p, s in zip(pieces, starts)])
    omega = np.concatenate([p.impacts.omega for p in pieces])
    after = np.concatenate([p.omega_after for p in pieces])
    models = sorted({p.model for p in pieces})
    recipes = {id(p.recipe) for p in pieces}
    return Trajectory.single(
        Curve(tuple(segments)), Impacts(impacts_t, omega, pieces[0].impacts.tip_distance), after, theta_max=head,
        t_end=float(t_end), rate=pieces[0].rate, name=name, model=models[0] if len(models) == 1 else "mixed",
        recipe=pieces[0].recipe if len(recipes) == 1 else None,
        history=(f"{name} of " + ", ".join(p.name for p in pieces),))


_COMFORT = 1.5  # returns take this many times their shortest duration within the limits, when there is room


def plan_return(start, target, window, theta_max, limits):
    """How the stick gets from ``start`` to ``target`` (θ rad, ω rad/s) in ``window`` seconds, or None.

    A time-optimal jerk-limited move to the target angle at rest (ruckig), a hold, then (if the
    target moves) a move from rest into the target speed — each starting and ending with zero
    acceleration, velocity continuous throughout, taking :data:`_COMFORT` times their shortest
    duration when there is room — or, when that does not fit, one move stretched over the whole
    window. Every move stays within ``limits`` (speed, acceleration, jerk) and on or above the head.

    Returns
    -------
    list of (duration s, path) or None
    """
    if window < -1e-9:  # a stroke thrown from where the last was caught may start a rounding early
        return None
    window = max(window, 0.0)
    if _meet(start, target):  # the stick is where the next piece starts: it holds
        return [_hold(target[0], window)] if window > 0.0 else []
    rest = (target[0], 0.0)
    still = target[1] == 0.0 and math.isfinite(target[0])  # at rest (a throw's height): no move to wind up into it
    move = _shortest(start, rest, theta_max, limits)
    wind = 0.0 if still else _shortest(rest, target, theta_max, limits)
    for scale in (_COMFORT, 1.0):
        a, b = move * scale, wind * scale
        if a + b <= window + 1e-12:
            parts = [_move(start, rest, a, theta_max, limits), _hold(target[0], window - a - b)]
            if not still:
                parts.append(_move(rest, target, b, theta_max, limits))
            if all(part is not None for part in parts):
                return [part for part in parts if part[0] > 0.0]
    direct = _move(start, target, window, theta_max, limits)
    if direct is not None and _shortest(start, target, theta_max, limits) <= window + 1e-12:
        return [direct] if window > 0.0 else []
    return None


def return_time(start, target, theta_max, limits):
    """The shortest window (s) :func:`plan_return` can use, or inf."""
    rest = (target[0], 0.0)
    if target[1] == 0.0 and math.isfinite(target[0]):  # the target is its own rest: the two ways are one move
        return _shortest(start, rest, theta_max, limits)
    total = _shortest(start, rest, theta_max, limits) + _shortest(rest, target, theta_max, limits)
    return min(total, _shortest(start, target, theta_max, limits))


def plan_move(start, target, duration, *, theta_max, limits):
    """One jerk-limited move from ``start`` to ``target`` (θ rad, ω rad/s, at zero acceleration) in ``duration`` s.

    Returns
    -------
    (duration, path) or None
        ``path(t)`` gives θ and ω at ``t`` s into the move; None when the move cannot take that long
        within ``limits`` and above the head (``theta_max``).
    """
    if duration + 1e-12 < _shortest(start, target, theta_max, limits):
        return None
    return _move(start, target, max(duration, 0.0), theta_max, limits)


@dataclass(frozen=True)
class JointsMove:
    """A move of several joints together: :func:`synchronised_move`'s.

    Attributes
    ----------
    duration : float
        s.
    path : callable
        ``path(t) -> (positions, velocities)`` at ``t`` s into the move (rad, rad/s) [shape=t.shape + (joints,)],
        a :class:`~drumstroke.curve.Segment`'s path.
    turns : ndarray [shape=(k,)]
        s: where a joint's angle is at its highest or lowest (ruckig's position extrema), in [0, ``duration``]:
        with a fine grid, where to look for the move's extremes.
    """

    duration: float
    path: object = field(repr=False)
    turns: np.ndarray = field(repr=False)


def synchronised_move(start, target, limits, *, velocities=None):
    """The time-optimal jerk-limited move of several joints together, to rest, every joint arriving at once.

    ruckig's synchronised move: the slowest joint takes the shortest time its limits allow and the others
    move slower, in step with it; each joint starts and ends at zero acceleration, within its speed,
    acceleration and jerk (a little inside, as every move here) and its range.

    Parameters
    ----------
    start, target : array_like [shape=(joints,)]
        rad: the joints' angles.
    limits : sequence of Limits [joints]
        Each joint's range (rad), max_speed (rad/s), max_acceleration (rad/s²) and max_jerk (rad/s³).
    velocities : array_like [shape=(joints,)], optional
        rad/s at the start; default at rest.

    Returns
    -------
    JointsMove or None
        None when no move keeps every joint within its range.

    Examples
    --------
    >>> move = synchronised_move([0.0, 0.0], [1.0, 0.1], [Limits(theta_low=-1.0), Limits(theta_low=-1.0)])
    >>> positions, _ = move.path(np.array([0.0, move.duration]))
    >>> positions.round(9).tolist()
    [[0.0, 0.0], [1.0, 0.1]]
    """
    start = np.asarray(start, dtype=float)
    target = np.asarray(target, dtype=float)
    velocities = np.zeros_like(start) if velocities is None else np.asarray(velocities, dtype=float)
    if start.ndim != 1 or target.shape != start.shape or velocities.shape != start.shape:
        raise ParameterError(f"start, target and velocities must be one angle (rad) per joint, got shapes "
                             f"{start.shape}, {target.shape} and {velocities.shape}")
    if len(limits) != len(start) or not all(isinstance(joint, Limits) for joint in limits):
        raise ParameterError(f"limits must be a drumstroke.palette.motion.Limits for each of the {len(start)} joints, "
                             f"got {limits!r}")
    solved = _ruckig_joints(list(zip(start, velocities)), [(x, 0.0) for x in target], 0.0, limits)
    if solved is None:
        return None
    extrema = solved.position_extrema
    if any(e.min < joint.theta_low - 1e-12 or e.max > joint.theta_high + 1e-12 for e, joint in zip(extrema, limits)):
        return None
    paths = [_path_of(solved, joint) for joint in range(len(start))]

    def path(t):
        states = [joint(t) for joint in paths]
        return np.stack([s[0] for s in states], axis=-1), np.stack([s[1] for s in states], axis=-1)

    turns = np.clip([t for e in extrema for t in (e.t_min, e.t_max)], 0.0, solved.duration)
    return JointsMove(float(solved.duration), path, np.unique(turns))


def _shortest(start, target, theta_max, limits):
    """The duration (s) of the time-optimal move within the limits, 0 for none needed, inf if none stays above the head."""
    return _shortest_move(tuple(map(float, start)), tuple(map(float, target)), float(theta_max), limits)


@functools.lru_cache(maxsize=4096)
def _shortest_move(start, target, theta_max, limits):
    """:func:`_shortest`, cached: a composition asks for the same moves between the same stroke ends and starts
    again and again."""
    if _meet(start, target):
        return 0.0
    solved = _ruckig(start, target, 0.0, limits)
    if solved is None or not _above(solved, theta_max, limits):
        return math.inf
    return solved.duration


def _meet(start, target):
    """Whether two states are one: the same angle at rest, to the solver's round-off at a caught apex (rad, rad/s).

    A designed stroke is caught at the apex of its last rebound, where ω is 0 to within the errors of
    its impacts (up to ~1e-6 s off in a long chain: ω within 1e-4 rad/s); the next stroke is thrown
    from there.
    """
    return abs(start[0] - target[0]) < 1e-9 and abs(start[1]) < 1e-4 and abs(target[1]) < 1e-4


def _move(start, target, duration, theta_max, limits):
    """(duration, path) of the move taking exactly ``duration`` s, or None (outside the limits or below the head)."""
    if duration <= 0.0:
        if abs(start[0] - target[0]) < 1e-12 and abs(start[1] - target[1]) < 1e-9:
            return 0.0, lambda t: (np.full(np.shape(t), target[0]), np.full(np.shape(t), target[1]))
        return None
    solved = _ruckig(start, target, duration, limits)
    if solved is not None and abs(solved.duration - duration) <= 1e-9 * max(1.0, duration) and _above(solved,
                                                                                                        theta_max, limits):
        return duration, _path_of(solved)
    # ruckig cannot always stretch a move to a given duration (its synchronisation step fails for some short
    # ones): then the time-optimal move, and the target held for the rest, when the target is at rest
    solved = _ruckig(start, target, 0.0, limits)
    if solved is None or solved.duration > duration + 1e-12 or target[1] != 0.0 or not _above(solved, theta_max, limits):
        return None
    moving, rest = _path_of(solved), solved.duration

    def path(t):
        t = np.asarray(t, dtype=float)
        theta, omega = moving(np.minimum(t, rest))
        return np.where(t < rest, theta, target[0]), np.where(t < rest, omega, 0.0)

    return duration, path


def _ruckig(start, target, minimum, limits):
    """ruckig's move (a one-joint jerk-limited trajectory) from ``start`` to ``target`` lasting at least ``minimum`` s."""
    return _generator(1).solve([float(start[0])], [float(start[1])], [float(target[0])], [float(target[1])], minimum,
                               (limits,))


def _ruckig_joints(starts, targets, minimum, limits):
    """ruckig's move of several joints together, from ``starts`` to ``targets`` ((θ, ω) each, at zero acceleration),
    synchronised in time (every joint arrives at once), lasting at least ``minimum`` s; None when ruckig finds none."""
    return _generator(len(starts)).solve([float(s[0]) for s in starts], [float(s[1]) for s in starts],
                                         [float(s[0]) for s in targets], [float(s[1]) for s in targets], minimum,
                                         tuple(limits))


class _Generator:
    """ruckig's calculator for some joints and its input, made once a thread (making a calculator costs ten times a
    move's calculation), the input's limits set when they change: a move sets only its states."""

    __slots__ = ("calculator", "joints", "limits", "parameters", "ruckig")

    def __init__(self, joints):
        ruckig = self.ruckig = _ruckig_module()
        self.calculator, self.parameters = ruckig.Ruckig(joints), ruckig.InputParameter(joints)
        self.parameters.current_acceleration = [0.0] * joints
        self.parameters.target_acceleration = [0.0] * joints
        self.parameters.synchronization = ruckig.Synchronization.Time
        self.joints, self.limits = joints, None

    def solve(self, position, velocity, target_position, target_velocity, minimum, limits):
        """ruckig's trajectory from the joints' positions and velocities (rad, rad/s, lists) to the targets', at
        least ``minimum`` s long, within ``limits`` (a tuple of Limits, one a joint), or None if ruckig finds none."""
        ruckig, parameters = self.ruckig, self.parameters
        if limits != self.limits:  # (Limits are equal when their values are; the same ones are the same object)
            parameters.max_velocity = [_MARGIN * joint.max_speed for joint in limits]
            parameters.max_acceleration = [_MARGIN * joint.max_acceleration for joint in limits]
            parameters.max_jerk = [_MARGIN * joint.max_jerk for joint in limits]
            self.limits = limits
        parameters.current_position, parameters.current_velocity = position, velocity
        parameters.target_position, parameters.target_velocity = target_position, target_velocity
        parameters.minimum_duration = minimum if minimum > 0.0 else None
        trajectory = ruckig.Trajectory(self.joints)
        try:
            result = self.calculator.calculate(parameters, trajectory)
        except ruckig.RuckigError:  # no profile found (ruckig says why in its message)
            return None
        return trajectory if result is ruckig.Result.Working or result is ruckig.Result.Finished else None


def _generator(joints):
    """This thread's :class:`_Generator` for ``joints`` joints."""
    generators = _local.__dict__.get("generators")
    if generators is None:
        generators = _local.generators = {}
    made = generators.get(joints)
    if made is None:
        made = generators[joints] = _Generator(joints)
    return made


_local = threading.local()


@functools.cache
def _ruckig_module():
    """ruckig, imported at the first move (an import statement at every move costs about a microsecond)."""
    try:
        import ruckig
    except ImportError:
        raise ImportError("moving the stick between strokes needs ruckig: pip install ruckig") from None
    return ruckig


_MARGIN = 0.98  # moves plan a little inside the limits, so sampled round-off never crosses them


def _above(trajectory, theta_max, limits):
    """Whether a move stays above the head and within the joint's highest angle."""
    extrema = trajectory.position_extrema[0]
    return extrema.min >= theta_max - 1e-12 and extrema.max <= limits.theta_high + 1e-12


def _path_of(trajectory, joint=0):
    """θ(t), ω(t) of one joint of a ruckig trajectory, evaluated phase by phase (constant jerk: cubic in time),
    vectorised."""
    profile = trajectory.profiles[0][joint]
    if profile.brake.duration > 0.0 or profile.accel.duration > 0.0:  # a start outside the limits: ruckig's own
        def path(t):
            t = np.asarray(t, dtype=float)
            states = [trajectory.at_time(float(x)) for x in t.ravel()]
            return (np.array([s[0][joint] for s in states]).reshape(t.shape),
                    np.array([s[1][joint] for s in states]).reshape(t.shape))
        return path
    durations = profile.t
    starts = [0.0, *itertools.accumulate(durations[:-1])]  # summed in order, as numpy's cumsum sums them
    # row by row as the kernel reads them, straight from the values (no list of rows, no transposed copy); a phase's
    # start state: the states list the end of the last phase too, which zip leaves out
    rows = itertools.chain.from_iterable(zip(starts, profile.j, profile.a, profile.v, profile.p))
    return Cubic(np.fromiter(rows, float, 5 * len(durations)).reshape(-1, 5))


def _hold(theta, duration):
    """A plan's hold: (duration s, path) of the stick still at ``theta`` (rad)."""
    return duration, still(theta)


def _ends(piece):
    """A trajectory's states at its start and at its end: ((θ rad, ω rad/s), (θ rad, ω rad/s)), in one evaluation."""
    theta, omega = piece.path(np.array([0.0, piece.t_end]))
    return (float(theta[0]), float(omega[0])), (float(theta[1]), float(omega[1]))
