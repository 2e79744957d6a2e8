"""Step 5's test of a room's echo tried twice (``room_partner_under_db``): the second pass only refuses.

On recorded drums (tests/_recorded_drums.py's corpus, seed 0), FluidR3's snare 38 drop with FluidSynth's reverb: the
room's return 67.4 ms after the second train's last bounce (4.0607 s, missed), at 4.1281 s, is refused by the layer's
test (:func:`drumstroke.analysis.onsets._layer_echoes`) by a hair: the windows at the same delays after the partner
notes explain it to 0.24 dB less after it than before, a partner's being 78.1 ms after 0.3736 s (a room's return
itself, refused in step 6 otherwise). The room test's second pass refuses 0.3736 s in step 5; the layer's test,
seeing the attacks without it, took another partner there and left 0.09 dB more after than before: 4.1281 s kept, a
false detection. The layer's test now sees the attacks as the room's first pass left them, the second pass's
refusals taken off after it: with the rule or without, the layer's test is the same.
"""

from functools import cache

import numpy as np

from _recorded_drums import RATE, recordings
from drumstroke.analysis import OnsetConfig, find_onsets

# FluidSynth and both SoundFonts are needed (scripts/install-system-packages.sh installs them): without them
# these tests fail with render_soundfont's error, they never skip


@cache
def _drop():
    """FluidR3's snare 38 drop with reverb, with the corpus's seeds (``recordings`` seeds each by its indices in the
    tuples it is given: those of the whole corpus's)."""
    return next(r for r in recordings(fonts=("FluidR3",), keys=(38, 40), sets=("singles", "drop"),
                                      conditions=("reverb",)) if r.key == 38 and r.set == "drop")


def _near(times, t, window):
    return bool(np.any(np.abs(np.asarray(times) - t) <= window))


def test_the_second_pass_changes_no_partner_of_the_layers_test():
    """The return at 4.1281 s is no onset, with the second pass or without; 0.3736 s is none either way."""
    recording = _drop()
    now = find_onsets(recording.signal, RATE)
    once = find_onsets(recording.signal, RATE, config=OnsetConfig(room_partner_under_db=120.0))
    assert not _near(recording.t, 4.1281, 20e-3)
    for onsets in (now, once):
        assert not _near(onsets.t, 4.1281, 1e-3)
        assert not _near(onsets.t, 0.3736, 1e-3)
