"""The fit (analysis.fit): strokes simulated from random recipes, their audible impacts fitted back.

Known answers: the impacts of a simulated stroke above -30 dB re its loudest are the onsets a perfect
detector would report (exact times, levels re the loudest; some jittered by up to 0.2 ms and 0.3 dB
as a real one would). The fitted recipe, written to TOML, read back and simulated again, must make
every onset within 2 ms and 1 dB (after the fitted offset) and no other impact at or above -30 dB;
under one constant force the fit must find the stroke's own offset, start and c. Hostile onsets get
one clear error, or a clear report of the onsets left out.
"""

import math

import numpy as np
import pytest

import drumstroke
from drumstroke.analysis import Onsets, fit_stroke
from drumstroke.analysis.fit import FORCES, MAX_ONSETS, TOLERANCE
from drumstroke.dynamics import CEILING_DB

THRESHOLD = -30.0
KINDS = ("constant", "low-high", "high-low", "pulses")


def random_recipe(rng, kind, model):
    """A stroke from rest at a random height under a random force of ``kind`` (human range, 0-250 m/s^2)."""
    u = rng.uniform
    if kind == "constant":
        force = drumstroke.Constant(u(0.0, 240.0))
    elif kind == "low-high":
        switch = u(0.2, 1.0)
        force = drumstroke.PiecewiseLinear([(0.0, u(0, 60)), (switch, u(0, 60)), (switch + 0.05, u(120, 250))])
    elif kind == "high-low":
        switch = u(0.2, 1.0)
        force = drumstroke.PiecewiseLinear([(0.0, u(120, 250)), (switch, u(120, 250)), (switch + 0.05, u(0, 60))])
    else:
        force = drumstroke.Pulses(amplitude=u(50, 250), period=u(0.15, 0.5), duty=u(0.03, 0.3), phase=u(0, 0.2))
    return drumstroke.Recipe(force=force, model=model, theta0=u(0.1, 0.9), cor=u(0.6, 0.92), t_end=4.0)


def stroke_of(rng, kind, model):
    """A random stroke the model's level map holds (loudest ≤ 12 dB), clear of the vertical, with ≥ 2 onsets."""
    for _ in range(100):
        recipe = random_recipe(rng, kind, model)
        try:
            stroke = drumstroke.simulate(recipe)
        except drumstroke.SimulationError:  # over the vertical: not a drum stroke
            continue
        levels = stroke.impacts.level_db
        if (levels.max() <= CEILING_DB and stroke.sample(1000.0).theta.max() < 1.2
                and np.sum(levels >= levels.max() + THRESHOLD) >= 2):
            return recipe, stroke
    raise AssertionError("no stroke drawn")  # pragma: no cover


def onsets_of(stroke, rng=None, *, threshold=THRESHOLD):
    """The stroke's impacts at or above ``threshold`` re the loudest, as a detector reports them."""
    impacts = stroke.impacts
    loud = impacts.level_db >= impacts.level_db.max() + threshold
    t, level = impacts.t[loud], impacts.level_db[loud]
    if rng is not None:
        t = t + rng.uniform(-2e-4, 2e-4, len(t))
        level = level + rng.uniform(-0.3, 0.3, len(t))
    return Onsets(t, level - level.max(), threshold_db=threshold, source="simulated")


def replayed(fit, tmp_path):
    """The fitted recipe through its TOML file, simulated again: impact times (recording's clock) and levels re
    the loudest onset."""
    path = tmp_path / "fitted.toml"
    fit.recipe.to_toml(path)
    stroke = drumstroke.simulate(drumstroke.Recipe.from_toml(path))
    return stroke.impacts.t + fit.release, stroke.impacts.level_db - fit.offset


def assert_plays(times, levels, onsets, *, time_tol=TOLERANCE[0], level_tol=TOLERANCE[1]):
    """Each onset has an impact within the tolerances; no other impact is at or above the threshold."""
    used = np.zeros(len(times), bool)
    for t, level in zip(onsets.t, onsets.level_db):
        j = int(np.argmin(np.abs(times - t)))
        assert abs(times[j] - t) <= time_tol and abs(levels[j] - level) <= level_tol, (t, level, times[j], levels[j])
        used[j] = True
    heard = ~used & (levels >= onsets.threshold_db)
    assert not np.any(heard), times[heard]


@pytest.mark.parametrize("model", drumstroke.MODELS)
@pytest.mark.parametrize("kind", KINDS)
def test_random_strokes_are_fitted_back(kind, model, tmp_path):
    rng = np.random.default_rng([KINDS.index(kind), drumstroke.MODELS.index(model), 18])
    for case in range(3):
        recipe, stroke = stroke_of(rng, kind, model)
        jitter = rng if case == 2 else None
        onsets = onsets_of(stroke, jitter)
        fit = fit_stroke(onsets, model=model, cor=recipe.cor)
        assert fit.within and fit.model == model and not fit.unmatched and not len(fit.extra_t)
        times, levels = replayed(fit, tmp_path)
        assert_plays(times, levels, onsets)
        if jitter is not None:  # and the true impacts, within the jitter
            assert_plays(times, levels, onsets_of(stroke), time_tol=TOLERANCE[0] + 2e-4,
                         level_tol=TOLERANCE[1] + 0.6)


@pytest.mark.parametrize("model", drumstroke.MODELS)
def test_under_one_constant_force_the_offset_and_start_are_the_strokes_own(model, tmp_path):
    rng = np.random.default_rng([7, drumstroke.MODELS.index(model)])
    for _ in range(4):
        recipe, stroke = stroke_of(rng, "constant", model)
        fit = fit_stroke(onsets_of(stroke), model=model, cor=recipe.cor)
        assert fit.offset == pytest.approx(stroke.impacts.level_db.max(), abs=0.01)
        assert fit.release == pytest.approx(0.0, abs=1e-4)  # let go when the recipe was, from its height
        assert fit.recipe.theta0 == pytest.approx(recipe.theta0, abs=1e-3)
        assert fit.design.max_force == pytest.approx(recipe.force.value, rel=1e-3, abs=0.1)
        assert fit.change < 1e-3


@pytest.mark.parametrize(("kind", "model", "jittered", "within"), [
    ("free", "paper", False, 1e-3), ("free", "paper", True, 0.01), ("constant", "geometry", True, 0.01)])
def test_fit_cor_recovers_c(kind, model, jittered, within):
    rng = np.random.default_rng([11, jittered])
    for _ in range(2):
        if kind == "free":
            recipe = drumstroke.Recipe(force=drumstroke.Constant(0.0), model=model, theta0=rng.uniform(0.0, 0.6),
                                       cor=rng.uniform(0.6, 0.92), t_end=5.0)
            stroke = drumstroke.simulate(recipe)
        else:
            recipe, stroke = stroke_of(rng, kind, model)
        fit = fit_stroke(onsets_of(stroke, rng if jittered else None), model=model, fit_cor=True)
        assert fit.fitted_cor and fit.within
        assert fit.cor == pytest.approx(recipe.cor, abs=within)


def test_the_zeno_tail_below_the_threshold_is_not_an_error_and_loud_ends_are_caught():
    recipe = drumstroke.Recipe(force=drumstroke.Constant(80.0), theta0=0.4, t_end=4.0)
    stroke = drumstroke.simulate(recipe)
    onsets = onsets_of(stroke)
    fit = fit_stroke(onsets, cor=recipe.cor)
    # bounces on under the threshold, to rest: more impacts than onsets, none of them counted
    assert fit.design.end == "bounce" and len(fit.stroke.impacts) > len(onsets) + 5
    assert fit.within and fit.stroke.rest_time is not None
    assert np.all(fit.stroke.impacts.level_db[len(onsets):] - fit.offset < THRESHOLD)
    # the same stroke cut after its 5 loudest impacts, with a -30 dB threshold: the 6th would be heard, so the
    # stick is caught after the 5th (the recording had no 6th above its threshold)
    cut = Onsets(onsets.t[:5], onsets.level_db[:5], threshold_db=THRESHOLD)
    fit = fit_stroke(cut, cor=recipe.cor)
    assert fit.design.end == "catch" and len(fit.stroke.impacts) == 5 and fit.within
    # onsets given, not detected (no threshold): every impact counts, so the stick is caught
    given = Onsets(onsets.t, onsets.level_db)
    assert fit_stroke(given, cor=recipe.cor).design.end == "catch"


def test_onsets_the_design_cannot_chain_are_left_out_with_the_reason(tmp_path):
    recipe = drumstroke.Recipe(force=drumstroke.Constant(120.0), theta0=0.3, t_end=4.0)
    onsets = onsets_of(drumstroke.simulate(recipe))
    t, level = list(onsets.t), list(onsets.level_db)
    t.insert(4, t[3] + 4e-4)  # an echo 0.4 ms after onset 3: closer than one stick's impacts can be
    level.insert(4, -12.0)
    t.insert(7, t[6] + 3e-3)  # a loud onset 3 ms after onset 5 (now 6): no flight within the forces makes it
    level.insert(7, -1.0)
    noisy = Onsets(np.array(t), np.array(level), threshold_db=THRESHOLD)
    fit = fit_stroke(noisy, cor=recipe.cor)
    reasons = dict(fit.unmatched)
    assert sorted(reasons) == [4, 7]
    assert "at least 1 ms apart" in reasons[4]
    assert "force limit" in reasons[7] and "nearest reachable" in reasons[7]
    assert np.isnan(fit.time_residual[[4, 7]]).all() and not fit.within
    others = np.delete(np.arange(len(noisy)), [4, 7])
    assert np.nanmax(np.abs(fit.time_residual[others])) < TOLERANCE[0]
    assert np.nanmax(np.abs(fit.level_residual[others])) < TOLERANCE[1]
    assert_plays(*replayed(fit, tmp_path), onsets)  # the real impacts are all played


def test_a_false_onset_between_two_impacts_is_left_out_as_such(tmp_path):
    stroke = drumstroke.simulate(drumstroke.Recipe(force=drumstroke.Constant(100.0), theta0=0.3, cor=0.8, t_end=4.0))
    onsets = onsets_of(stroke)
    # a faint onset (noise, a ring of the drum) 7 ms before impact 9: a bounce only if the thumb pulls it down
    t = np.insert(onsets.t, 9, onsets.t[9] - 7e-3)
    level = np.insert(onsets.level_db, 9, onsets.level_db[9] - 14.0)
    fit = fit_stroke(Onsets(t, level, threshold_db=THRESHOLD), cor=0.8)
    assert [i for i, _ in fit.unmatched] == [9] and "a false detection" in fit.unmatched[0][1]
    assert not fit.beyond_human and fit.offset == pytest.approx(stroke.impacts.level_db.max(), abs=0.01)
    assert_plays(*replayed(fit, tmp_path), onsets)


def test_the_fits_check_reports_an_impact_above_the_threshold_that_no_onset_has():
    """The re-simulation's check, which a correct design never trips through fit_stroke: a stroke designed for
    all the onsets, measured against the onsets less one, has that one as an extra impact, so it is not within."""
    from drumstroke.analysis.fit import _Edits, _Search

    recipe = drumstroke.Recipe(force=drumstroke.Constant(100.0), theta0=0.3, cor=0.8, t_end=4.0)
    onsets = onsets_of(drumstroke.simulate(recipe))
    fit = fit_stroke(onsets, cor=0.8)
    assert fit.within and not len(fit.extra_t)
    fewer = Onsets(np.delete(onsets.t, 3), np.delete(onsets.level_db, 3), threshold_db=THRESHOLD)
    search = _Search(_Edits.made(fewer, (), (), (), apply=False), model="paper", stick=drumstroke.Stick(), forces=FORCES,
                     highest=None, progress=None)
    checked = search.measure(fit.design, fit.offset, 0.8, False)
    assert checked.extra_t == pytest.approx([onsets.t[3]], abs=TOLERANCE[0])
    assert checked.extra_level == pytest.approx([onsets.level_db[3]], abs=TOLERANCE[1])
    assert not checked.within and not checked.unmatched


def test_hostile_onsets_get_one_clear_error():
    with pytest.raises(drumstroke.ParameterError, match=r"at least 2 onsets .* got 0 \(no impacts found\)"):
        fit_stroke(Onsets(np.array([]), np.array([])))
    with pytest.raises(drumstroke.ParameterError, match="at least 2 onsets"):
        fit_stroke(Onsets([0.5], [0.0]))
    with pytest.raises(drumstroke.ParameterError, match=r"onset times t\[1\] must be a finite number"):
        Onsets([0.1, math.nan], [0.0, -3.0])
    with pytest.raises(drumstroke.ParameterError, match="strictly increasing"):
        Onsets([0.3, 0.1], [0.0, -3.0])
    with pytest.raises(drumstroke.ParameterError, match="onsets must be a drumstroke.analysis.Onsets"):
        fit_stroke([0.1, 0.2])
    many = Onsets(np.arange(10_000) * 0.01, -(np.arange(10_000) % 20.0))
    with pytest.raises(drumstroke.ParameterError, match=f"at most {MAX_ONSETS} onsets, got 10000"):
        fit_stroke(many)
    with pytest.raises(drumstroke.ParameterError, match=r"no two of the 2 onsets .* onset 1: 0.5 ms after onset 0"):
        fit_stroke(Onsets([0.2, 0.2005], [0.0, -1.0]))
    # 2 ms apart, the bounces are tiny: the fit finds them at the softest level; played loud, no force makes them
    assert fit_stroke(Onsets([0.2, 0.202, 0.204], [0.0, 0.0, 0.0])).within
    with pytest.raises(drumstroke.ParameterError, match=r"no two of the 3 onsets .*force limit"):
        fit_stroke(Onsets([0.2, 0.202, 0.204], [0.0, 0.0, 0.0]), offset=10.0)
    with pytest.raises(drumstroke.ParameterError, match=r"cor must be in \[0, 1\)"):
        fit_stroke(Onsets([0.2, 0.4], [0.0, -2.0]), cor=1.0)
    with pytest.raises(drumstroke.ParameterError, match="offset must be"):
        fit_stroke(Onsets([0.2, 0.4], [0.0, -2.0]), offset=40.0)
    with pytest.raises(drumstroke.ParameterError, match="model must be one of"):
        fit_stroke(Onsets([0.2, 0.4], [0.0, -2.0]), model="spring")


def test_the_smoother_levels_are_played():
    """choose_levels takes the measure whose bounces' levels change more smoothly: on drumstroke's own drum the
    modes (they follow the stick's speed); with every other bounce of the modes read 4 dB low, the peak."""
    from _recordings import RATE, render
    from drumstroke.analysis import find_onsets
    from drumstroke.analysis.fit import choose_levels

    drop = drumstroke.simulate(theta0=0.5, cor=0.86, t_end=3.0).impacts
    signal, _ = render(drop.t + 0.1, 10.0 ** (drop.level_db / 20.0), seed=1)
    onsets = find_onsets(signal, RATE)
    assert choose_levels(onsets)[1] == "modes"
    rough = Onsets(onsets.t, onsets.level_db - 4.0 * (np.arange(len(onsets.t)) % 2), peak_db=onsets.peak_db)
    chosen, name, why = choose_levels(rough)
    assert name == "peak" and "smoother" in why and np.array_equal(chosen.level_db, onsets.peak_db)
    assert choose_levels(onsets, "peak")[1] == "peak" and choose_levels(rough, "modes")[1] == "modes"
