"""A drop's last bounces under a reverberant room's sound (``layer_whole_likeness``, ``layer_echo_partners``).

On recorded drums (tests/_recorded_drums.py's corpus, seed 0): FluidR3's snares dropped with FluidSynth's reverb end
in bounces 5-7 ms apart of the quiet velocity layer, whose first 3 ms (a tenth of its first 10 ms' energy: the layer
peaks 9.4 ms in) lie under the room's sound and what is left of the bounce before: there the layer's start correlates
0.2-0.3 with what is left and its first 10 ms 0.81-0.84. The template search takes such a bounce by the layer's first
10 ms alone (``layer_whole_likeness``), a half to one and a half times the flight before on, after a flight of 10 ms
or less. Two returns of the room, 67 ms after each train's last bounces, then each lie in the window the other's
partner needs (:func:`drumstroke.analysis.onsets._layer_echoes`); ``layer_echo_partners`` lets a partner's own return at
the delay tried (within 1.5 ms, an attack tried so too) lie there.
"""

from functools import cache

import numpy as np
import pytest

from _recorded_drums import RATE, recordings, score
from drumstroke.analysis import OnsetConfig, find_onsets

# FluidSynth and both SoundFonts are needed (scripts/install-system-packages.sh installs them): without them
# these tests fail with render_soundfont's error, they never skip

# the drop's last bounces not sought by a joint fit with the bounce before nor a train's bounce put at its start by
# the quiet layer (tests/test_recorded_drop_joint.py: it finds one more in each drop), as when these rules came
_LATER = {"layer_start_reach": 0.0, "layer_joint_likeness": 1.0}
_ON = OnsetConfig(**_LATER)
_OFF = OnsetConfig(layer_whole_likeness=1.0, layer_echo_partners=0, **_LATER)  # both rules off: the outputs before


@cache
def _drop(key):
    """FluidR3's snare ``key`` drop with reverb, with the corpus's seeds (``recordings`` seeds each by its indices
    in the tuples it is given: those of the whole corpus's)."""
    return next(r for r in recordings(fonts=("FluidR3",), keys=(38, 40), sets=("singles", "drop"),
                                      conditions=("reverb",)) if r.key == key and r.set == "drop")


def _near(times, t, window):
    return bool(np.any(np.abs(np.asarray(times) - t) <= window))


@pytest.mark.parametrize("key, missed", [
    (38, [4.0554]),  # 5.4 ms after the bounce before: the layer's start 0.28, its first 10 ms 0.81
    (40, [4.0470]),  # 6.7 ms after it: 0.27 and 0.84 (the layer's start search took the bounce after it, 20 ms on)
])
def test_a_drops_last_bounce_under_the_rooms_sound_is_found(key, missed):
    """The bounces at ``missed`` s, found by neither before, are found within 1 ms; no loud note found before is lost,
    no false detection is added."""
    recording = _drop(key)
    now, before = find_onsets(recording.signal, RATE, config=_ON), find_onsets(recording.signal, RATE, config=_OFF)
    for t in missed:
        assert _near(recording.t, t, 0.1e-3)
        assert not _near(before.t, t, 5e-3) and _near(now.t, t, 1e-3)
    kept, was = score(recording, now.t), score(recording, before.t)
    assert kept["within_1ms"] == was["within_1ms"] + len(missed)
    assert kept["within_5ms"] == was["within_5ms"] + len(missed)
    assert kept["found"] - kept["correct_5ms"] <= was["found"] - was["correct_5ms"]


def test_two_returns_of_the_room_each_in_the_others_partners_window_are_refused():
    """With the last bounces found, the room's returns 67 ms after each train's last bounces (2.0359 and 4.1281 s,
    no note within 5 ms) stay refused only where a partner's own return at the delay tried may lie in its window."""
    recording = _drop(38)
    now = find_onsets(recording.signal, RATE, config=_ON)
    # room_partner_under_db (a later rule) refuses them too, in step 5's test of a room's echo: off here
    uncleared = find_onsets(recording.signal, RATE,
                            config=OnsetConfig(layer_echo_partners=0, room_partner_under_db=120.0, **_LATER))
    for t in (2.0359, 4.1281):
        assert not _near(recording.t, t, 5e-3)
        assert _near(uncleared.t, t, 1e-3) and not _near(now.t, t, 5e-3)


def test_the_rules_switches_are_validated():
    with pytest.raises(Exception, match="layer_whole_likeness"):
        OnsetConfig(layer_whole_likeness=1.5)
    with pytest.raises(Exception, match="layer_echo_partners"):
        OnsetConfig(layer_echo_partners=2)
