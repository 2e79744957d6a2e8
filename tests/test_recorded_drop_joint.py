"""A drop's last bounces found by a joint fit with the bounce before (``layer_joint_likeness``), each bounce detected
on its main rise put at its start by the quiet layer (``layer_start_reach``).

On recorded drums (tests/_recorded_drums.py's corpus, seed 0): FluidR3's snares dropped with FluidSynth's reverb end
in bounces 4-8 ms apart of the quiet velocity layer. The bounce before's fit over the layer's first 10 ms takes in
some of the next bounce's sound, and taken off it leaves too little of it: the layer's first 10 ms correlate 0.70
(snare 38, 1.9687 s) and 0.65 (snare 40, 1.9537 s) with what is left, where ``layer_whole_likeness`` asks 0.8. Fitted
again together with the next bounce (two scales, least squares from the bounce before to the next one's 10 ms), the
layer correlates 0.73 and 0.72 there: ``layer_joint_likeness`` (0.7) takes them. On snare 40 the two bounces before
(1.9390 and 1.9470 s) were detected on their main rise, 0.94 ms late, and the template search took each off there,
which left what hid the next: the layer's first 10 ms fit each best 1.0 ms earlier (0.84 against -0.16 at the
detection), where ``layer_start_reach`` puts them.
"""


import pytest

from _recorded_drums import RATE, score
from drumstroke.analysis import OnsetConfig, find_onsets
from test_recorded_drop_rooms import _drop, _near  # FluidR3's drops with reverb, the corpus's seeds

# FluidSynth and both SoundFonts are needed (scripts/install-system-packages.sh installs them): without them
# these tests fail with render_soundfont's error, they never skip

_OFF = OnsetConfig(layer_start_reach=0.0, layer_joint_likeness=1.0)  # both rules off: the outputs before them


@pytest.mark.parametrize("key, missed", [
    (38, 1.9687),  # 5.3 ms after the bounce before: the layer's first 10 ms 0.70 alone, 0.73 fitted with it
    (40, 1.9537),  # 6.7 ms after it, once that bounce is put at its start: 0.65 and 0.72
])
def test_a_drops_last_bounce_is_found_by_a_joint_fit_with_the_bounce_before(key, missed):
    """The bounce at ``missed`` s, found by neither rule before, is found within 1 ms; no loud note found before is
    lost, no false detection is added."""
    recording = _drop(key)
    now, before = find_onsets(recording.signal, RATE), find_onsets(recording.signal, RATE, config=_OFF)
    assert _near(recording.t, missed, 0.1e-3)
    assert not _near(before.t, missed, 5e-3) and _near(now.t, missed, 1e-3)
    kept, was = score(recording, now.t), score(recording, before.t)
    assert kept["within_1ms"] == was["within_1ms"] + 1
    assert kept["within_5ms"] == was["within_5ms"] + 1
    assert kept["found"] - kept["correct_5ms"] <= was["found"] - was["correct_5ms"]


def test_a_bounce_detected_on_its_main_rise_is_put_at_its_start():
    """FluidR3's snare 40 drop with reverb: the bounces at 1.9390 and 1.9470 s, detected 0.94 ms late, are put within
    0.1 ms of their start by the layer's fit (the joint rule alone leaves them late)."""
    recording = _drop(40)
    now = find_onsets(recording.signal, RATE)
    # the drop train's rules off too (tests/test_recorded_drop_layer_train.py: without layer_start_reach they find these
    # bounces at their start as well)
    late = find_onsets(recording.signal, RATE, config=OnsetConfig(layer_start_reach=0.0, layer_train_found=0,
                                                                  layer_found_bursts=0, layer_skipped_search=0))
    for t in (1.9390, 1.9470):
        assert _near(recording.t, t, 0.1e-3)
        assert _near(now.t, t, 0.1e-3)
        assert not _near(late.t, t, 0.8e-3) and _near(late.t, t + 0.94e-3, 0.1e-3)


def test_the_rules_switches_are_validated():
    with pytest.raises(Exception, match="layer_start_reach"):
        OnsetConfig(layer_start_reach=0.01)
    with pytest.raises(Exception, match="layer_joint_likeness"):
        OnsetConfig(layer_joint_likeness=1.5)
