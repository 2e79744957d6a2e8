"""A controller added from outside the package: declared, registered, played, tuned.

The controller, a PD with a share of the gravity feedforward, is defined here and nowhere else;
defining it registers it. Oracle: held at a constant target θ it settles where
Kp·(θ_ref − θ̂) = (1 − share)·m·g·k·cos θ, θ̂ within half an encoder step of θ (no droop with the
whole feedforward).
"""

import math
from dataclasses import dataclass

import numpy as np
import pytest

import drumstroke
from drumstroke.errors import ParameterError
from drumstroke.robot.controllers import (
    CONTROLLERS,
    Controller,
    controller,
    controller_from_dict,
    declared_gains,
    gain,
    to_dict,
)
from drumstroke.robot.loop import ControlLoop
from drumstroke.robot.metrics import metrics
from drumstroke.robot.plant import Plant, SimpleJoint
from drumstroke.robot.track import reference, track
from drumstroke.robot.tune import score, tune
from drumstroke.trajectory import Impacts, Trajectory

RATE = 1000.0
PLANT = Plant()
NAME = "pd-test"
RUNS = []  # the gains of every run of the new controller's law


@pytest.fixture(scope="module")
def pd():
    """The new controller's class, registered while this module's tests run (so other tests see only the built-ins)."""

    @dataclass(frozen=True)
    class PDGravity(Controller):
        """τ = Kp·e + Kd·ė + share·m·g·k·cos θ_ref; each run's gains are recorded in ``RUNS``."""

        name = NAME
        kp: float = gain(30.0, unit="N m/rad", low=0.0, high=1e3)
        kd: float = gain(0.1, unit="N m s/rad", low=0.0, high=10.0)
        share: float = gain(1.0, unit="", low=0.0, high=1.0, scale="linear", step=0.1)

        def law(self, plant, rate):
            RUNS.append((self.kp, self.kd, self.share))
            kp, kd, weight = self.kp, self.kd, self.share * plant.gravity_torque

            def command(ref_theta, ref_omega, ref_alpha, theta, omega):
                return kp * (ref_theta - theta) + kd * (ref_omega - omega) + weight * math.cos(ref_theta)

            return command

    yield PDGravity
    del CONTROLLERS[NAME]


@pytest.fixture(scope="module")
def double():
    """A short stroke: the first 0.7 s of free-bounce, two impacts."""
    return reference(drumstroke.simulate("free-bounce", t_end=0.7))


def hold(theta, duration):
    """A reference holding the stick still at ``theta`` (rad) for ``duration`` (s)."""
    n = round(duration * RATE) + 1
    t = np.arange(n) / RATE
    return Trajectory.from_samples(t, np.full(n, theta), np.zeros(n), Impacts(np.empty(0), np.empty(0), 0.27),
                                   np.empty(0), theta_max=PLANT.head, rate=RATE, alpha=np.zeros(n), name="hold")


def test_defining_it_registers_it(pd):
    assert CONTROLLERS[NAME] is pd and list(CONTROLLERS)[-1] == NAME
    assert controller(NAME) == pd()
    assert controller(NAME, kp=50).kp == 50.0
    assert controller_from_dict(NAME, {"kd": 0.5, "share": 0.3}) == pd(kd=0.5, share=0.3)
    assert to_dict(pd(kp=12.0)) == {"kp": 12.0, "kd": 0.1, "share": 1.0}
    assert declared_gains(pd)["share"].scale == "linear" and declared_gains(pd)["kp"].unit == "N m/rad"
    with pytest.raises(ParameterError, match=r"^controller must be one of pi, pid-ff, impedance, pd-test, got 'x'"):
        controller("x")


@pytest.mark.parametrize("gains, pattern", [
    ({"kp": -1.0}, r"^pd-test.kp must be in \[0, 1000\] N m/rad, got -1.0"),
    ({"kd": math.nan}, r"^pd-test.kd must be a finite number in \[0, 10\] N m s/rad"),
    ({"share": 1.5}, r"^pd-test.share must be in \[0, 1\], got 1.5"),
    ({"kp": "3"}, r"^pd-test.kp must be a number"),
    ({"ki": 1.0}, r"^controller pd-test has unknown key 'ki'; allowed keys: kp, kd, share"),
])
def test_its_gains_are_checked_from_their_declarations(pd, gains, pattern):
    with pytest.raises(ParameterError, match=pattern):
        controller(NAME, **gains)


def test_another_class_cannot_take_a_registered_name(pd):
    with pytest.raises(ParameterError, match=r"^controller name 'pi' is taken by drumstroke.robot.controllers.PI"):
        @dataclass(frozen=True)
        class Impostor(Controller):
            name = "pi"

            def law(self, plant, rate):
                return None
    assert CONTROLLERS["pi"].__module__ == "drumstroke.robot.controllers"


@pytest.mark.parametrize("share", [0.0, 0.5, 1.0])
@pytest.mark.parametrize("theta", [0.1, 0.5])
def test_held_still_it_droops_by_what_its_feedforward_leaves_to_the_spring(pd, share, theta):
    """θ_ref − θ = (1 − share)·m·g·k·cos θ / Kp, to half an encoder step.

    Measured: within 0.5 % of the closed form where it droops, the last 0.5 s within half a step.
    """
    kp = 30.0  # Coulomb friction's band τ_c/Kp is far below the droop
    played = track(hold(theta, 3.0), controller(NAME, kp=kp, share=share), cor=0.86)
    droop = theta - played.theta[played.reference.t >= 2.5]
    expected = (1.0 - share) * PLANT.gravity_torque * math.cos(theta) / kp
    assert np.abs(droop - expected).max() <= PLANT.resolution / 2 + 1e-6
    if share < 1.0:
        assert droop.mean() == pytest.approx(expected, rel=0.05)
        assert expected > 10 * PLANT.resolution  # far above what the encoder can tell apart
    else:
        assert np.abs(droop).max() <= PLANT.resolution


@pytest.mark.parametrize("engine", ["simple", "mujoco"])
def test_it_plays_a_stroke_on_both_plants_through_the_one_loop(pd, double, engine):
    c = controller(NAME, kp=60.0, kd=0.3)
    played = track(double, c, engine=engine)
    assert played.controller == NAME and played.plant == engine
    assert played.theta.shape == (len(double),)
    assert metrics(played).reference_onsets == 2 and len(played.onsets) >= 1
    loop = ControlLoop(SimpleJoint(PLANT, double.recipe.cor, theta0=double.theta[0], omega0=double.omega[0]), c,
                       double.rate)
    if engine == "simple":  # stepped by hand: the same numbers
        loop.run(double.theta, double.omega, double.alpha)
        assert np.array_equal(loop.log().theta, played.theta)


def test_tuning_searches_its_gains_on_their_declared_scales(pd, double):
    """The first simplex: the start, then each gain moved by 0.5 on its scale (log: ×e^0.5; linear: 0.5 steps)."""
    start = controller(NAME, kp=20.0, kd=0.2, share=0.5)
    RUNS.clear()
    tuned = tune([double], start, evaluations=12)
    (found,) = tuned.controllers
    assert type(found) is pd and controller(NAME, **to_dict(found)) == found
    assert score([double], found)[0] <= score([double], start)[0]
    simplex = RUNS[:4]
    assert simplex[0] == pytest.approx((20.0, 0.2, 0.5), rel=1e-12)
    assert simplex[1] == pytest.approx((20.0 * math.exp(0.5), 0.2, 0.5), rel=1e-12)
    assert simplex[2] == pytest.approx((20.0, 0.2 * math.exp(0.5), 0.5), rel=1e-12)
    assert simplex[3] == pytest.approx((20.0, 0.2, 0.55), rel=1e-12)
    assert 1 <= tuned.evaluations <= 15
