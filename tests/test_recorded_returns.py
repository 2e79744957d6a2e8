"""A quiet attack that the earlier notes' own sound explains is none (``_layer_echoes``), and its compiled loops.

On recorded drums (tests/_recorded_drums.py's corpus, seed 0): a return of FluidSynth's reverb and swells of a sample's
own decay, each the sound at the same delay after other notes, are refused; every note found before is still found.
The compiled loops (drumstroke.analysis._rooms.layer_echoes, joint_novelty, _best_window) against plain numpy.
"""

import math

import numpy as np
import pytest

from _recorded_drums import RATE, recordings, score
from drumstroke.analysis import OnsetConfig, _rooms, find_onsets

# FluidSynth and both SoundFonts are needed (scripts/install-system-packages.sh installs them): without them
# these tests fail with render_soundfont's error, they never skip

_OFF = OnsetConfig(layer_echo_db=-120.0)  # the rule off: the outputs before it


def _corpus_recording(name, condition):
    """The benchmark's recording ``name`` (font key set) in ``condition``, with the corpus's seeds."""
    return next(r for r in recordings(sets=("singles", "drop", "roll"), conditions=(condition,))
                if f"{r.font} {r.key} {r.set}" == name)


def _near(times, t, window=5e-3):
    return bool(np.any(np.abs(np.asarray(times) - t) <= window))


@pytest.mark.parametrize("name, condition, false_t", [
    ("FluidR3 38 singles", "reverb", [3.7935]),  # a return of the room 83.4 ms after a -3.8 dB note
    ("FluidR3 38 drop", "reverb", [2.0359, 4.1281]),  # returns 67 ms after a bounce, over the drop's sound
    ("FluidR3 40 roll", "reverb", [1.0245]),  # 57.4 ms after a ghost note, over an accent's sound
    ("TimGM6mb 40 roll", "dry", [3.0236]),  # a swell of the sample's own decay 54.1 ms after a ghost note
])
def test_a_quiet_attack_the_earlier_notes_sound_explains_is_none(name, condition, false_t):
    """The false detections at ``false_t`` s (no note within 5 ms) that the rule's switch (``layer_echo_db=-120``)
    shows are gone, no other false detection added, and the loud notes found within 1 and 5 ms are as many."""
    recording = _corpus_recording(name, condition)
    now = find_onsets(recording.signal, RATE)
    before = find_onsets(recording.signal, RATE, config=_OFF)
    for t in false_t:
        assert not _near(recording.t, t)
        assert _near(before.t, t) and not _near(now.t, t)
    kept, was = score(recording, now.t), score(recording, before.t)
    assert (kept["within_1ms"], kept["within_5ms"]) == (was["within_1ms"], was["within_5ms"])
    assert kept["found"] - kept["correct_5ms"] == was["found"] - was["correct_5ms"] - len(false_t)


def test_ghost_notes_under_an_accents_sound_are_kept():
    """A roll's ghost notes (-20 to -27 dB, 50-120 ms after an accent) look like a return but bring a sound no other
    note's at the same delays holds: on FluidR3's and TimGM6mb's snare 38 rolls, every note found without the rule
    is found with it, at the same time."""
    for name in ("FluidR3 38 roll", "TimGM6mb 38 roll"):
        recording = _corpus_recording(name, "dry")
        now, before = find_onsets(recording.signal, RATE), find_onsets(recording.signal, RATE, config=_OFF)
        for t in recording.t:
            if _near(before.t, t):
                assert np.min(np.abs(now.t - t)) == np.min(np.abs(before.t - t)), (name, t)


def test_the_rules_switch_is_validated():
    with pytest.raises(Exception, match="layer_echo_db"):
        OnsetConfig(layer_echo_db=61.0)
    with pytest.raises(Exception, match="layer_decay_db"):
        OnsetConfig(layer_decay_db=1.0)


# ---- the compiled loops against numpy


@pytest.fixture
def rng():
    return np.random.default_rng(20261127)


def _best_window_in_numpy(x, at, centres, before, after, reach):
    width, start = before + after, at - before
    if start < 0 or start + width > len(x):
        return -1
    own = x[start:start + width]
    least, best = math.inf, -1
    for centre in centres:
        low = centre - reach - before
        if low < 0 or low + width + 2 * reach > len(x):
            continue
        for lag in range(2 * reach + 1):
            other = x[low + lag:low + lag + width]
            scale = np.linalg.lstsq(other[:, None], own, rcond=None)[0][0]
            left = float(np.sum((own - scale * other) ** 2))
            if left < least - 1e-12 * float(own @ own):
                least, best = left, low + lag
    return best


def _joint_novelty_in_numpy(x, at, starts, before, after, most_left):
    width, start = before + after, at - before
    if start < 0 or start + width > len(x):
        return math.inf
    own = x[start:start + width]
    basis = np.stack([x[s:s + width] for s in starts], axis=1)
    left = own - basis @ np.linalg.lstsq(basis, own, rcond=None)[0]
    if left @ left > most_left * (own @ own):
        return math.inf
    return float(np.mean(left[before:] ** 2) / max(np.mean(left[:before] ** 2), 1e-300))


def _layer_echoes_in_numpy(x, times, levels, clear, tried, attack, which, nearest, farthest, before, after, reach,
                           most_left, novel, partners):
    attack = attack.copy()
    for k in tried:
        at, starts = int(np.rint(times[k])), []
        for i in range(len(times)):
            delay = times[k] - times[i]
            if not (nearest <= delay <= farthest and levels[i] >= levels[k]):
                continue
            others = np.array([j for j in range(len(times)) if j not in (i, k) and clear[j] >= delay + after + reach],
                              dtype=np.int64)
            others = others[np.argsort(np.abs(levels[others] - levels[i]), kind="stable")[:partners]]
            best = _best_window_in_numpy(x, at, np.rint(times[others] + delay).astype(np.int64), before, after, reach)
            if best >= 0:
                starts.append(best)
        if starts and _joint_novelty_in_numpy(x, at, starts, before, after, most_left) <= novel:
            attack[which[k]] = False
    return attack


def _replayed(rng, n=6000):
    """A sample (a click, then a decay with a swell 20 ms in) replayed at four levels, a quiet detection on the
    swell after the third, a ghost note of another waveform after the fourth; the times (samples) and levels (dB)."""
    t = np.arange(1200)
    sample = rng.standard_normal(1200) * np.exp(-t / 300.0) * (1.0 + 2.0 * np.exp(-((t - 200) / 30.0) ** 2))
    x = 1e-4 * rng.standard_normal(n)
    notes = [(300, 1.0), (1700, 0.8), (3100, 0.9), (4500, 0.7)]
    for at, scale in notes:
        x[at:at + 1200] += scale * sample
    x[4600:4900] += 0.05 * rng.standard_normal(300) * np.exp(-np.arange(300) / 80.0)
    times = np.array([300.0, 1700.0, 3100.0, 3300.0, 4500.0, 4600.0])
    levels = np.array([0.0, -1.9, -0.9, -20.0, -3.1, -26.0])
    return x, times, levels


def test_layer_echoes_refuses_the_replayed_swell_and_keeps_the_ghost_note_as_numpy_does(rng):
    x, times, levels = _replayed(rng)
    after = np.searchsorted(times, times + 10.0, side="right")
    clear = np.append(times, np.inf)[after] - times
    attack, which, tried = np.ones(8, bool), np.array([0, 1, 2, 4, 5, 6]), np.array([3, 5])
    args = (x, times, levels, clear, tried, attack, which, 20.0, 2000.0, 40, 40, 3, 0.25, 2.0, 4)
    got = _rooms.layer_echoes(*args)
    assert np.array_equal(got, _layer_echoes_in_numpy(*args))
    assert not got[which[3]] and got[which[5]]  # the swell refused, the ghost note kept
    assert np.array_equal(np.delete(got, which[3]), np.delete(attack, which[3]))
    # a partner's window that would leave the signal's ends is not tried; none at all: nothing refused
    assert np.array_equal(_rooms.layer_echoes(x, times, levels, np.zeros(6), tried, attack, which, 20.0, 2000.0, 40, 40,
                                              3, 0.25, 2.0, 4), attack)


@pytest.mark.parametrize("at", [30, 700, 2990])
def test_best_window_is_the_least_squares_best_as_numpy_finds_it(rng, at):
    x = rng.standard_normal(3000)
    centres = np.array([5, 400, 1500, 2200, 2995], dtype=np.int64)
    assert _rooms._best_window(x, at, centres, 24, 24, 3) == _best_window_in_numpy(x, at, centres, 24, 24, 3)
    x[1500 + 2 - 24:1500 + 2 + 24] = 0.5 * x[at - 24:at + 24] if 24 <= at <= 2976 else 0.0
    assert _rooms._best_window(x, at, centres, 24, 24, 3) == _best_window_in_numpy(x, at, centres, 24, 24, 3)


@pytest.mark.parametrize("count", [1, 3, 8])
def test_joint_novelty_is_numpys_least_squares(rng, count):
    x = rng.standard_normal(4000)
    starts = rng.integers(0, 3900, count).astype(np.int64)
    for at in (2000, 50, 3960):
        want = _joint_novelty_in_numpy(x, at, starts, 50, 50, 1.0)
        got = _rooms.joint_novelty(x, at, starts, 50, 50, 1.0)
        assert got == want if math.isinf(want) else got == pytest.approx(want, rel=1e-9)
    # the same window twice (two notes' partners alike): singular normal equations, the fit as with one
    twice = np.array([starts[0], starts[0]], dtype=np.int64)
    assert _rooms.joint_novelty(x, 2000, twice, 50, 50, 1.0) == pytest.approx(
        _joint_novelty_in_numpy(x, 2000, twice[:1], 50, 50, 1.0), rel=1e-9)
    # a fit that leaves more than most_left: inf
    assert _rooms.joint_novelty(x, 2000, starts, 50, 50, 1e-6) == math.inf
