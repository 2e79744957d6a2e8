"""Table 1, Eq. 1, Eq. 5 and Eq. 7 of the paper."""

import math

import numpy as np
import pytest

from drumstroke import Stick
from drumstroke.model import PAPER_INERTIA_RATIO, coefficients, inertia_ratio


def test_table_1_drumhead_angle():
    assert Stick().theta_max == pytest.approx(-0.2623, abs=5e-5)
    assert Stick().theta_max == -math.asin(0.07 / 0.27)


def test_eq_1_inertia_of_a_rod_about_its_fulcrum():
    """I/m = (x³ − (x − L)³)/(3L) = (3x² − 3xL + L²)/3, checked against a numerical integral."""
    stick = Stick(length=0.41, pivot_to_tip=0.30)
    s = np.linspace(stick.pivot_to_tip - stick.length, stick.pivot_to_tip, 400_001)  # along the rod
    numeric = np.trapezoid(s**2, s) / stick.length
    assert inertia_ratio("geometry", stick) == pytest.approx(numeric, rel=1e-9)
    assert inertia_ratio("geometry", Stick()) == pytest.approx(0.0183, abs=5e-5)


@pytest.mark.parametrize("a", [0.0, 10.0, 189.0, 250.0, -30.0])
def test_paper_model_is_eq_7_as_printed(a):
    c = coefficients("paper", Stick())
    assert c.torque_rate(9.8, a) == pytest.approx((0.735 + 0.01 * a) / 0.0714, rel=1e-14)
    assert c.inertia_ratio == PAPER_INERTIA_RATIO == 0.0714


def test_the_two_models_differ_by_the_papers_known_factor():
    ratio = inertia_ratio("paper", Stick()) / inertia_ratio("geometry", Stick())
    assert 3.85 < ratio < 3.95


def test_geometry_model_follows_the_stick_and_paper_model_does_not():
    long = Stick(length=0.5, pivot_to_tip=0.35, pivot_height=0.07)
    assert inertia_ratio("geometry", long) != inertia_ratio("geometry", Stick())
    assert inertia_ratio("paper", long) == 0.0714
