"""A dropped stick's last bounces on recorded drums: the template search's rules for them (tests/_recorded_drums.py's
corpus, seed 0), and their compiled kernels against plain numpy."""

import numpy as np
import pytest

from _recorded_drums import RATE, recordings, score
from drumstroke.analysis import OnsetConfig, find_onsets

# the template search as before both rules: a bounce's own detections in a row (found_bursts) and a detection no
# template fits after a dropped one (burst_unfitted_likeness), each of which finds the snare 40 dry drop's bounces;
# and as before a train's bounce detected on its main rise was put at its start by the quiet layer
# (layer_start_reach), which finds them too (with found_bursts=1 the bounce of 4.0204 s is put at its start, and its
# burst's detection is not left an attack of its own)
_BEFORE = {"found_bursts": 1, "burst_unfitted_likeness": 0.0, "layer_start_reach": 0.0}

# FluidSynth and both SoundFonts are needed (scripts/install-system-packages.sh installs them): without them these
# tests fail with render_soundfont's error, they never skip


def _drop(key, condition):
    """FluidR3's drop of snare ``key`` in ``condition``, with the corpus's seeds (its index among the sets kept)."""
    return next(r for r in recordings(fonts=("FluidR3",), keys=(38, 40), sets=("singles", "drop"),
                                      conditions=(condition,)) if (r.key, r.set) == (key, "drop"))


def _false(recording, found):
    figures = score(recording, found)
    return figures["found"] - figures["correct_5ms"]


def test_a_bounces_main_rise_and_second_burst_are_both_its_own_sound():
    """FluidR3's electric snare (40) bursts again 3.4 ms into a note. In its dry drop the bounce at 4.0204 s is detected
    on its main rise 0.9 ms late and at its second burst 3.5 ms on: the first detection is dropped as the attack's own
    sound (``found_burst_db``), and so is the second (``found_bursts`` 2), the attack fitted past both. As before
    (``found_bursts=1`` and ``burst_unfitted_likeness=0``) the burst stays an attack: its fit is no attack's, the search
    after it finds none, and the drop's next three bounces (4.0310, 4.0404 and 4.0470 s, -24 to -28 dB, 6.7-10.7 ms
    apart) are missed. ``found_bursts`` alone finds them."""
    recording = _drop(40, "dry")
    notes = recording.t[[np.argmin(np.abs(recording.t - t)) for t in (4.0310, 4.0404, 4.0470)]]
    found = find_onsets(recording.signal, RATE).t
    alone = find_onsets(recording.signal, RATE, config=OnsetConfig(burst_unfitted_likeness=0.0)).t
    before = find_onsets(recording.signal, RATE, config=OnsetConfig(**_BEFORE)).t
    for t in notes:
        assert max(np.min(np.abs(found - t)), np.min(np.abs(alone - t))) <= 0.1e-3 and np.min(np.abs(before - t)) > 5e-3
    assert np.min(np.abs(found - 4.0239)) > 1e-3 and np.min(np.abs(before - 4.0239)) < 0.1e-3  # the burst
    assert _false(recording, found) == 0 < _false(recording, before)


def test_a_reverberant_bounces_burst_is_dropped_by_its_fit_past_it():
    """With FluidSynth's reverb, the snare 40 drop's bounce at 1.8924 s fits its template by 0.62 only up to its
    detection on its main rise (0.9 ms late), 0.96 over 10 ms: fitted past that detection and the next (its second
    burst, 3.4 ms in), the two are its own sound and dropped; with ``found_bursts=1`` the burst is a false onset.
    The rule's own gain, measured with the drop's last bounces not sought by the quiet layer's whole fit (as before:
    ``layer_whole_likeness``, which with ``found_bursts=1`` finds a last bounce more, 4.0470 s), nor as one train
    (tests/test_recorded_drop_layer_train.py's rules, which with ``found_bursts=1`` drop the burst as well)."""
    recording = _drop(40, "reverb")
    off = {"layer_whole_likeness": 1.0, "layer_echo_partners": 0, "layer_train_found": 0, "layer_found_bursts": 0,
           "layer_skipped_search": 0}  # and the drop train's rules, which drop that burst too
    found = find_onsets(recording.signal, RATE, config=OnsetConfig(burst_unfitted_likeness=0.0, **off)).t
    before = find_onsets(recording.signal, RATE, config=OnsetConfig(**_BEFORE, **off)).t
    assert np.min(np.abs(found - 1.8958)) > 1e-3 and np.min(np.abs(before - 1.8958)) < 0.1e-3
    assert _false(recording, found) < _false(recording, before)
    assert score(recording, found)["within_1ms"] >= score(recording, before)["within_1ms"]


def test_a_bounce_detected_late_after_a_dropped_burst_is_sought_before_its_detection():
    """In the same drop, the bounce of 1.9297 s (-23.4 dB, 10.7 ms after the one before) is detected in the modes' band
    1.29 ms late, where neither template fits (0.0); the one before's late detection was dropped as its own sound. That
    next detection no longer ends the earlier attack's fit (``burst_unfitted_likeness``): the search for a close bounce
    looks past it and finds the bounce at its start. With ``burst_unfitted_likeness=0`` (as before) it stays 1.29 ms
    late, as long as the quiet layer does not put it at its start either (``layer_start_reach=0``, as before it)."""
    recording = _drop(40, "reverb")
    note = recording.t[np.argmin(np.abs(recording.t - 1.9297))]
    found = find_onsets(recording.signal, RATE).t
    before = find_onsets(recording.signal, RATE, config=OnsetConfig(burst_unfitted_likeness=0.0,
                                                                      layer_start_reach=0.0)).t
    assert np.min(np.abs(found - note)) <= 0.1e-3 and np.min(np.abs(before - note)) > 1e-3
    assert _false(recording, found) <= _false(recording, before)


def test_found_bursts_is_checked():
    with pytest.raises(ValueError, match="found_bursts"):
        OnsetConfig(found_bursts=0)
    with pytest.raises(ValueError, match="burst_unfitted_likeness"):
        OnsetConfig(burst_unfitted_likeness=1.5)


def _oracle_later_bursts(remainder, template, c, pre, detections, shortest, fit, reach, likeness, burst, most):
    """numpy's count of :func:`_later_bursts`: the attack at ``c`` fitted by least squares (no layer) up to each next
    detection in turn, starting with the fit up to ``detections[0]`` taken off."""
    def taken_off(x, end):
        span = min(max(pre + shortest, min(pre + fit, end - c)), len(template), len(x) - c + pre)
        window = x[c - pre:c - pre + span]
        t = template[:span]
        scale = np.linalg.lstsq(t[:, None], window, rcond=None)[0][0]
        like = window @ t / np.sqrt(window @ window * (t @ t))
        out = x.copy()
        out[c - pre:c - pre + len(template)] -= scale * template
        return out, like

    ends = list(detections) + [len(remainder)]
    count = 0
    while count < most and count < len(detections) and ends[count] - c <= reach:
        following = ends[count]
        heard = remainder[following:following + shortest] @ remainder[following:following + shortest]
        left, like = taken_off(remainder, ends[count + 1])
        if not (like >= likeness and left[following:following + shortest] @ left[following:following + shortest]
                < heard * burst):
            break
        count += 1
    return count


@pytest.mark.parametrize("seed", range(6))
def test_later_bursts_against_numpy(seed):
    """The compiled chain of own bursts counts as numpy's least squares and energies do, and leaves ``remainder`` as
    it found it where it drops none."""
    from drumstroke.analysis._attacks import _later_bursts, _take_off

    rng = np.random.default_rng(seed)
    pre, shortest, fit, size = 24, 48, 480, 1200
    template = rng.standard_normal(size) * np.exp(-np.arange(size) / 300.0)
    template[pre + 160:pre + 200] += 3.0 * rng.standard_normal(40)  # its own later burst
    c, scale = 2000, float(rng.uniform(0.2, 1.0))
    remainder = 1e-3 * rng.standard_normal(6000)
    remainder[c - pre:c - pre + size] += scale * template
    reach = round(rng.uniform(100, 600))
    if seed % 3:  # a note of its own after the burst, or at the first detection: not the attack's sound
        note = c + (300 if seed % 3 == 1 else 45)
        remainder[note - pre:note - pre + size] += 0.8 * scale * template
    detections = np.array([c + 45.0, c + 162.0, c + 300.0])
    shifts = np.zeros(3)
    original = remainder.copy()
    own, at_c, scale_c, measured, fitted, by_layer = _take_off(remainder, template, np.zeros(0), c, c + 45, pre,
                                                               shortest, fit)
    taken = remainder.copy()
    more, following, *_ = _later_bursts(remainder, template, np.zeros(0), detections, shifts, 0, c, c + 45, own, at_c,
                                        scale_c, measured, fitted, by_layer, pre, shortest, fit, reach, 0.8, 0.25, 3)
    assert more == _oracle_later_bursts(original, template, c, pre, [int(u) for u in detections], shortest, fit,
                                        reach, 0.8, 0.25, 3)
    assert following == ([c + 45, c + 162, c + 300, len(remainder)][more])
    if more == 0:
        assert np.array_equal(remainder, taken)
    else:  # the attack's fit past the dropped detections taken off
        again = original.copy()
        _take_off(again, template, np.zeros(0), c, following, pre, shortest, fit)
        assert np.allclose(remainder, again, rtol=0, atol=1e-12)


def test_two_close_bounces_both_fitted_by_the_template_stay_two_attacks():
    """FluidR3's snare 38 dry drop: the bounces of 1.9594 s (-24.7 dB) and 1.9634 s (-27.2 dB, 4 ms on) are both found
    by the template search, within 0.05 ms. Their quiet velocity layer peaks 9.4 ms into a note, 5 dB over its first
    4 ms: the earlier's level, read up to the later, reads low, the later's, over the earlier's rise, 8 dB louder, and
    step 5 took the earlier for a swell before the later (``lead_db``), the bounce 3.95 ms late and the next missed.
    Two attacks the template fitted apart stay two (``fitted_lead_db`` 120); with ``fitted_lead_db=6`` (as before) the
    earlier is dropped."""
    recording = _drop(38, "dry")
    notes = recording.t[[np.argmin(np.abs(recording.t - t)) for t in (1.9594, 1.9634)]]
    found = find_onsets(recording.signal, RATE).t
    before = find_onsets(recording.signal, RATE, config=OnsetConfig(fitted_lead_db=6.0)).t
    for t in notes:
        assert np.min(np.abs(found - t)) <= 0.1e-3
    assert np.min(np.abs(before - notes[0])) > 1e-3 and np.sum(np.abs(before - notes.mean()) < 5e-3) == 1
    now, then = score(recording, found), score(recording, before)
    assert (now["within_1ms"], now["within_5ms"]) == (then["within_1ms"] + 1, then["within_5ms"] + 1) == (56, 56)
    assert _false(recording, found) == _false(recording, before) == 0


def test_fitted_lead_db_is_checked():
    with pytest.raises(ValueError, match="fitted_lead_db"):
        OnsetConfig(fitted_lead_db=-1.0)
