"""The paper's figure claims (its Section 4, Figs. 4–7), as tests on the presets."""

import numpy as np
import pytest

import drumstroke
from drumstroke.presets import PRESETS


def _intervals(stroke, start, end):
    """Inter-impact intervals whose two impacts both lie in [start, end]."""
    t = stroke.impacts.t
    keep = (t[:-1] >= start) & (t[1:] <= end)
    return np.diff(t)[keep]


def test_every_category_of_the_spec_has_a_preset():
    categories = {p.category for p in PRESETS.values()}
    assert {"gravity only", "constant torque", "low to high", "high to low", "sustained finger pulses",
            "un-natural"} <= categories
    assert sum(p.category == "un-natural" for p in PRESETS.values()) >= 2
    assert {p.figure for p in PRESETS.values() if p.figure} == {"Fig. 4", "Fig. 5", "Fig. 6", "Fig. 7"}


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_presets_start_as_the_papers_runs(name):
    recipe = drumstroke.preset(name)
    assert recipe.model == "paper" and recipe.cor == 0.86
    assert recipe.theta0 == 0.0 and recipe.omega0 == 0.0
    assert recipe.name == name and PRESETS[name].description


def test_free_bounce_is_a_bouncing_ball():
    """Fig. 4: successive flight times shrink by the factor c, like a bouncing ball's."""
    stroke = drumstroke.simulate("free-bounce")
    flights = np.diff(stroke.impacts.t)
    ratios = flights[1:] / flights[:-1]
    assert np.all(ratios < 0.87) and np.all(ratios > 0.859)
    assert abs(ratios[-1] - 0.86) < 1e-6  # small bounces: flight ∝ launch speed
    assert stroke.rest_time is not None and 2.5 < stroke.rest_time < 3.5


def test_constant_press_is_free_bounce_under_stronger_gravity():
    free = drumstroke.simulate("free-bounce")
    pressed = drumstroke.simulate("constant")
    assert pressed.rest_time < 0.7 * free.rest_time
    assert pressed.impacts.t[0] < free.impacts.t[0]


def test_low_high_bounce_rate_more_than_doubles_while_the_force_is_high():
    """Fig. 5: audible impacts (within 40 dB of the first) per second, before vs during the high force."""
    stroke = drumstroke.simulate("low-high")
    t, level = stroke.impacts.t, stroke.impacts.level_db
    audible = level >= level[0] - 40.0
    rate_before = np.sum(audible & (t < 1.0)) / 1.0
    rate_high = np.sum(audible & (t >= 1.05) & (t < 2.0)) / 0.95
    assert rate_before > 0 and rate_high > 2.0 * rate_before
    # and the very first bounce under the high force is already over twice as fast
    assert _intervals(stroke, 1.05, 2.0)[0] * 2.0 < _intervals(stroke, 0.0, 1.0)[-1]
    # once at rest, the force dropping back at 2 s changes nothing
    assert stroke.rest_time < 2.0 and stroke.rests[-1, 1] == 5.0


def test_high_low_intervals_after_the_drop_more_than_double():
    """Fig. 6: the first intervals after the grip is released are over twice the last one before."""
    stroke = drumstroke.simulate("high-low")
    before = _intervals(stroke, 0.0, 0.57)
    after = _intervals(stroke, 0.59, 5.0)
    assert len(before) >= 2 and len(after) >= 3
    assert np.all(after[:2] > 2.0 * before[-1])


def test_finger_pulses_sustain_the_bounce_at_the_pulse_period():
    """Fig. 7: bounces go on to t = 5 s and their last intervals are within 5 % of the 0.4 s period."""
    stroke = drumstroke.simulate("finger-pulses")
    t = stroke.impacts.t
    assert stroke.rest_time is None and len(stroke.rests) == 0
    assert t[-1] > 5.0 - 0.4
    last = np.diff(t)[-3:]
    assert np.all(np.abs(last - 0.4) < 0.05 * 0.4)
    # the level does not die away: the last impact is within 3 dB of the first
    assert stroke.impacts.level_db[-1] > stroke.impacts.level_db[0] - 3.0


def test_reversed_gravity_lifts_the_resting_stick_off_and_it_falls_back():
    stroke = drumstroke.simulate("reversed-gravity")
    (rest_start, rest_end), = stroke.rests
    assert rest_end == pytest.approx(3.2, abs=1e-3)  # lift-off the moment g turns negative
    later = stroke.impacts.t[stroke.impacts.t > rest_end]
    assert len(later) >= 3
    t = np.linspace(3.3, later[0] - 0.01, 50)
    theta, _ = stroke.state(t)
    assert theta.max() > stroke.recipe.theta_max + 0.2  # it flew up
    # and the second sequence has bounced back up louder than the end of the first
    first_after = stroke.impacts.level_db[stroke.impacts.t > rest_end][0]
    last_before = stroke.impacts.level_db[stroke.impacts.t <= rest_start][-1]
    assert first_after > last_before + 20.0


def test_rising_gravity_speeds_the_bounces_up():
    stroke = drumstroke.simulate("rising-gravity")
    flights = np.diff(stroke.impacts.t[:8])
    free = np.diff(drumstroke.simulate("free-bounce").impacts.t[:8])
    # the flights shrink faster than a free bounce's factor c per bounce
    assert np.all(flights[1:] / flights[:-1] < free[1:] / free[:-1])


def test_superhuman_press_is_over_quickly():
    stroke = drumstroke.simulate("superhuman-press")
    assert stroke.rest_time < 1.0
    assert stroke.impacts.tip_speed[0] > 2.0 * drumstroke.simulate("free-bounce").impacts.tip_speed[0]
