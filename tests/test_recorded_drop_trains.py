"""A drop's train of bounces past the close-bounce search's reach (onsets' ``_template_search``,
``OnsetConfig.train_reach``).

Step 5 finds a bouncing stick's hidden bounces one after another: after each attack, the template is sought within
``bounce_reach`` (25 ms). A drop's flights shrink by a constant factor, so some are 26-30 ms long; where step 4
found none of those bounces (FluidR3's snare 38 with FluidSynth's reverb, the corpus's seed 8: its first detection
there 6 ms early, dropped as the attack's own sound, and none after), the search ended the train there and every
bounce after it was lost, 12 in each of the recording's two drops. Now the search reaches up to ``echo_reach`` past
a detection it dropped, and after a bounce of a train (flights shrinking, bounces fading) to where the flight before
says the next one is. ``train_reach=0`` gives the search as before.
"""

from _recorded_drums import RATE, recording, score
from drumstroke.analysis import OnsetConfig, find_onsets

_BEFORE = OnsetConfig(train_reach=0.0)


def test_a_reverberant_drops_train_goes_on_past_a_long_flight():
    """FluidR3's snare 38 drop with reverb, seed 8: 54 loud notes, 30 within 5 ms before (the last 12 bounces of each
    drop lost), all 54 within 1 ms now, and no false detection more."""
    truth = recording("FluidR3", 38, "drop", "reverb", seed=8)
    now = score(truth, find_onsets(truth.signal, RATE).t)
    then = score(truth, find_onsets(truth.signal, RATE, config=_BEFORE).t)
    assert then["within_5ms"] <= 32 and now["within_1ms"] == now["loud"] == 54
    assert now["found"] - now["correct_5ms"] <= then["found"] - then["correct_5ms"]


def test_a_flams_main_note_starts_no_train():
    """TimGM6mb's snare 38 flams with reverb, seed 7: without the rule's asking a train's bounces to fade, its
    search took a detection 21.5 ms after the main note of 1.1139 s for a bounce (the flights before it shrinking as
    a drop's do); a main note is louder than its grace note: no false detection, every note found as before."""
    truth = recording("TimGM6mb", 38, "flams", "reverb", seed=7)
    now = score(truth, find_onsets(truth.signal, RATE).t)
    then = score(truth, find_onsets(truth.signal, RATE, config=_BEFORE).t)
    assert now == then and now["found"] == now["correct_5ms"]
