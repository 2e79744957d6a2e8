"""Controllers at the control rate: each a class that declares its gains, registers itself and owns its law.

- :class:`PI`, the paper's: position error in, torque out, gains fixed for every stroke (the
  defaults were picked by hand, as the paper's were, for a small tracking error on Figs. 4–7).
- :class:`PIDFeedforward`: PID plus the model's feedforward, J·α_ref + m·g·k·cos θ_ref, the torque
  the reference itself needs.
- :class:`Impedance`: the same feedforward with a PD spring whose stiffness fades near the head,
  so the drumhead bounces the stick as a drummer's loose grip lets it, and the arm only steers the
  flights between contacts.

A new controller is a new :class:`Controller` subclass, anywhere: a frozen dataclass whose
gains are fields declared with :func:`gain` (unit, range, tuning scale), a class attribute
``name``, and a :meth:`~Controller.law`. Defining it registers it in :data:`CONTROLLERS`, so
:func:`controller`, :func:`controller_from_dict`, the control loop and :func:`drumstroke.robot.tune.tune`
take it as they take the built-in ones. The built-in laws run compiled (numba), one call per
control period.

In the laws e = θ_ref − θ̂ and ė = ω_ref − ω̂, with θ̂ the encoder reading and ω̂ the speed
estimate (:mod:`drumstroke.robot.kernel`); an integral is clamped so Ki·∫e stays within the
torque limit (anti-windup).

Examples
--------
>>> controller("impedance", kp=40.0).kp
40.0
>>> declared_gains(PI)["kp"]
Gain(unit='N m/rad', low=0.0, high=10000.0, scale='log', step=1.0)
>>> list(CONTROLLERS)
['pi', 'pid-ff', 'impedance']
"""

import math
from abc import ABC, abstractmethod
from dataclasses import asdict, dataclass, field, fields
from functools import partial

import numpy as np

from .._checks import check_keys, check_real
from .._jit import jit
from ..errors import ParameterError

CONTROLLERS = {}
"""Every controller class by name, in the order they were defined (filled by defining them)."""

SCALES = ("log", "logit", "linear")
"""How a gain is searched when tuned: its logarithm, the logit of its place in its range, or itself in ``step``s."""


@dataclass(frozen=True)
class Gain:
    """The declaration of a gain: its unit, its range and how tuning searches it.

    Parameters
    ----------
    unit : str
        As the messages write it ("N m/rad"); "" for a pure number.
    low, high : float
        The range, ends included.
    scale : {"log", "logit", "linear"}
        "log": tuned through its logarithm (a positive gain whose size matters by ratio);
        "logit": through the logit of (value − low)/(high − low) (a fraction of a finite range);
        "linear": through value/``step``.
    step : float > 0
        The tuning unit of a "linear" gain (1e-3 for seconds searched in ms).
    """

    unit: str
    low: float
    high: float
    scale: str = "log"
    step: float = 1.0

    def __post_init__(self):
        if self.scale not in SCALES:
            raise ParameterError(f"scale must be one of {', '.join(SCALES)}, got {self.scale!r}")
        low = check_real("low", self.low, low=-math.inf)
        check_real("high", self.high, low=low)
        check_real("step", self.step, low=0.0, low_open=True)

    def check(self, label, value):
        """``value`` as a float if it is in range, else a ParameterError naming ``label``."""
        return check_real(label, value, low=self.low, high=self.high, unit=self.unit)

    def to_search(self, value):
        """The tuning search's coordinate of ``value``."""
        if self.scale == "log":
            return math.log(max(value, 1e-6))
        if self.scale == "logit":
            u = min(max((value - self.low) / (self.high - self.low), 1e-4), 1.0 - 1e-4)
            return math.log(u / (1.0 - u))
        return value * (1.0 / self.step)

    def from_search(self, x):
        """The value at the search coordinate ``x`` (a "log" gain may leave its range: the caller checks)."""
        if self.scale == "log":
            return math.exp(min(x, 30.0))
        if self.scale == "logit":
            return self.low + (self.high - self.low) / (1.0 + math.exp(min(-x, 700.0)))
        return min(max(x * self.step, self.low), self.high)


def gain(default, *, unit, low, high, scale="log", step=1.0):
    """A controller's gain: a dataclass field with its default and its :class:`Gain` declaration."""
    return field(default=default, metadata={"gain": Gain(unit, low, high, scale, step)})


def declared_gains(controller):
    """The gains a controller (class or instance) declares: {name: Gain}, in field order."""
    return {f.name: f.metadata["gain"] for f in fields(controller) if "gain" in f.metadata}


class Controller(ABC):
    """What every controller is: gains checked against their declarations, a law, a steering hook.

    A subclass with a class attribute ``name`` registers itself in :data:`CONTROLLERS` under it.
    """

    name = ""

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        name = cls.__dict__.get("name")
        if name is None:
            return  # a shared base, not a controller one can pick
        if not isinstance(name, str) or not name:
            raise ParameterError(f"{cls.__qualname__}.name must be a non-empty string, got {name!r}")
        taken = CONTROLLERS.get(name)
        if taken is not None and (taken.__module__, taken.__qualname__) != (cls.__module__, cls.__qualname__):
            raise ParameterError(f"controller name {name!r} is taken by {taken.__module__}.{taken.__qualname__}")
        CONTROLLERS[name] = cls

    def __post_init__(self):
        for name, declared in declared_gains(self).items():
            object.__setattr__(self, name, declared.check(f"{self.name}.{name}", getattr(self, name)))

    @abstractmethod
    def law(self, plant, rate):
        """The control law for one run: ``command(ref_theta, ref_omega, ref_alpha, theta_hat, omega_hat) -> torque``.

        Called once per control period with the reference (rad, rad/s, rad/s²), the encoder
        reading θ̂ (rad) and the speed estimate ω̂ (rad/s); returns the torque command (N·m).
        Each call of ``law`` starts a fresh run (its own integral, filters).

        Parameters
        ----------
        plant : Plant
            The joint's parameters (the model for a feedforward, the torque limit).
        rate : float
            The control rate (Hz).
        """

    def steer(self, reference):
        """θ (rad), ω (rad/s), α (rad/s²) to steer by for ``reference`` (a Trajectory): by default the reference."""
        return reference.theta, reference.omega, reference.alpha


@jit
def _feedforward(inertia, mgk, ref_theta, ref_alpha):
    """J·α_ref + m·g·k·cos θ_ref (N·m): the torque the reference itself needs."""
    return inertia * ref_alpha + mgk * math.cos(ref_theta)


@jit
def _integrate(state, e, dt, ki, tau_max):
    """∫e (rad·s) after this period, kept in ``state[0]`` and clamped so Ki·∫e stays within ±τ_max."""
    integral = state[0]
    if ki > 0.0:
        integral = min(max(integral + e * dt, -tau_max / ki), tau_max / ki)
        state[0] = integral
    return integral


@jit
def _pi_law(params, state, ref_theta, ref_omega, ref_alpha, measured, omega_hat):
    kp, ki, dt, tau_max = params[0], params[1], params[2], params[3]
    e = ref_theta - measured
    return kp * e + ki * _integrate(state, e, dt, ki, tau_max)


@jit
def _pid_ff_law(params, state, ref_theta, ref_omega, ref_alpha, measured, omega_hat):
    kp, ki, kd, dt, tau_max, inertia, mgk = params[0], params[1], params[2], params[3], params[4], params[5], params[6]
    e = ref_theta - measured
    de = ref_omega - omega_hat
    integral = _integrate(state, e, dt, ki, tau_max)
    return _feedforward(inertia, mgk, ref_theta, ref_alpha) + kp * e + ki * integral + kd * de


@jit
def _impedance_law(params, state, ref_theta, ref_omega, ref_alpha, measured, omega_hat):
    kp, kd, band, floor, inertia, mgk, head = params[0], params[1], params[2], params[3], params[4], params[5], params[6]
    e = ref_theta - measured
    de = ref_omega - omega_hat
    s = floor + (1.0 - floor) * min(1.0, max(0.0, (ref_theta - head) / band))
    return _feedforward(inertia, mgk, ref_theta, ref_alpha) + s * (kp * e + kd * de)


def _compiled(law, *params, state=1):
    """``law`` bound to its parameters and a fresh state (both small arrays, so a period allocates nothing)."""
    return partial(law, np.array(params, dtype=float), np.zeros(state))


@dataclass(frozen=True)
class PI(Controller):
    """τ = Kp·e + Ki·∫e (the paper's controller).

    Parameters
    ----------
    kp : float in [0, 1e4]
        N·m/rad.
    ki : float in [0, 1e6]
        N·m/(rad·s).
    """

    name = "pi"
    kp: float = gain(3.0, unit="N m/rad", low=0.0, high=1e4)
    ki: float = gain(2.0, unit="N m/(rad s)", low=0.0, high=1e6)

    def law(self, plant, rate):
        return _compiled(_pi_law, self.kp, self.ki, 1.0 / rate, plant.max_torque)


@dataclass(frozen=True)
class PIDFeedforward(Controller):
    """τ = J·α_ref + m·g·k·cos θ_ref + Kp·e + Ki·∫e + Kd·ė.

    Parameters
    ----------
    kp : float in [0, 1e4]
        N·m/rad.
    ki : float in [0, 1e6]
        N·m/(rad·s).
    kd : float in [0, 1e3]
        N·m·s/rad.
    """

    name = "pid-ff"
    kp: float = gain(30.0, unit="N m/rad", low=0.0, high=1e4)
    ki: float = gain(100.0, unit="N m/(rad s)", low=0.0, high=1e6)
    kd: float = gain(0.3, unit="N m s/rad", low=0.0, high=1e3)

    def law(self, plant, rate):
        return _compiled(_pid_ff_law, self.kp, self.ki, self.kd, 1.0 / rate, plant.max_torque, plant.inertia,
                         plant.gravity_torque)


@dataclass(frozen=True)
class Impedance(Controller):
    """τ = J·α_ref + m·g·k·cos θ_ref + s(θ_ref)·(Kp·e + Kd·ė), s fading to ``floor`` at the head.

    s = floor + (1 − floor)·min(1, (θ_ref − θ_head)/band): a stiff arm in the air and a soft
    one near the head, so the contact bounces the stick, not the motor.

    Parameters
    ----------
    kp : float in [0, 1e4]
        N·m/rad, in the air.
    kd : float in [0, 1e3]
        N·m·s/rad, in the air.
    band : float in [1e-4, 1]
        Height above the head (rad) below which the spring softens.
    floor : float in [0, 1]
        What is left of it on the head.
    lead : float in [0, 0.02]
        How long the head holds the stick at each impact (s): each flight is
        steered to leave that much later and land on time (:meth:`steer`,
        :func:`lead_in_contact`); 0 follows the reference as it is.
    """

    name = "impedance"
    kp: float = gain(100.0, unit="N m/rad", low=0.0, high=1e4)
    kd: float = gain(2.0, unit="N m s/rad", low=0.0, high=1e3)
    band: float = gain(0.05, unit="rad", low=1e-4, high=1.0)
    floor: float = gain(0.5, unit="", low=0.0, high=1.0, scale="logit")
    lead: float = gain(0.002, unit="s", low=0.0, high=0.02, scale="linear", step=1e-3)

    def law(self, plant, rate):
        return _compiled(_impedance_law, self.kp, self.kd, self.band, self.floor, plant.inertia,
                         plant.gravity_torque, plant.head)

    def steer(self, reference):
        """The reference with each flight held ``lead`` on the head and replayed faster (:func:`lead_in_contact`)."""
        return lead_in_contact(reference, self.lead)


def lead_in_contact(ref, lead, *, t=None):
    """θ, ω, α to steer by when the head holds the stick ``lead`` seconds at each impact.

    A real head keeps the stick for a few milliseconds where the model's impact is
    instantaneous, so a stick that follows the reference leaves every impact late
    and lands late. Flight by flight (impact i to i+1, duration d > 2·lead), the
    stick is held on the head for ``lead`` and the flight is replayed
    d/(d − lead) times faster: θ_w(t) = θ(t_i + (t − t_i − lead)·d/(d − lead)),
    so it leaves when the head lets go and lands on the reference's next impact.
    Shorter flights are left as they are.

    Parameters
    ----------
    ref : Trajectory
        One stick.
    lead : float
        s.
    t : ndarray or None
        Times to steer at (s) [shape=(n,)]; default the reference's sample times.

    Returns
    -------
    theta, omega, alpha : ndarray [shape=(n,)]
        rad, rad/s, rad/s² (new arrays).
    """
    if t is None:
        t = ref.t
        theta, omega, alpha = ref.theta.copy(), ref.omega.copy(), ref.alpha.copy()
    else:
        t = np.asarray(t, dtype=float)
        theta, omega = ref.path(t)
        alpha = ref.flight_acceleration(t)
    impacts = ref.impacts.t
    if lead <= 0.0 or len(impacts) < 2:
        return theta, omega, alpha
    i = np.searchsorted(impacts, t, side="right") - 1
    inside = (i >= 0) & (i < len(impacts) - 1)
    i = np.clip(i, 0, len(impacts) - 2)
    start, d = impacts[i], impacts[i + 1] - impacts[i]
    warp = inside & (d > 2.0 * lead)
    held = warp & (t < start + lead)
    flying = warp & ~held
    speed = np.where(warp, d / np.maximum(d - lead, 1e-12), 1.0)
    source = np.clip(start + (t - start - lead) * speed, ref.start, ref.t_end)
    if flying.any():
        th, om = ref.path(source[flying])
        theta[flying], omega[flying] = th, om * speed[flying]
        alpha[flying] = ref.flight_acceleration(source[flying]) * speed[flying] ** 2
    theta[held], omega[held], alpha[held] = ref.theta_max, 0.0, 0.0
    return theta, omega, alpha


def controller(name, **gains):
    """The controller ``name`` (see :data:`CONTROLLERS`) with some gains changed."""
    if name not in CONTROLLERS:
        raise ParameterError(f"controller must be one of {', '.join(CONTROLLERS)}, got {name!r}")
    cls = CONTROLLERS[name]
    check_keys(f"controller {name}", gains, [f.name for f in fields(cls)])
    return cls(**gains)


def controller_from_dict(name, table):
    """A controller from a TOML ``[controller.NAME]`` table of gains."""
    if not isinstance(table, dict):
        raise ParameterError(f"controller.{name} must be a table of gains, got {table!r}")
    return controller(name, **table)


def to_dict(controller):
    """The controller's gains as a table."""
    return asdict(controller)
