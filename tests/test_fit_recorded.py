"""fit on recorded drums: drops played by FluidSynth on two General MIDI SoundFonts, found by the detector, fitted.

The recordings are the corpus's (``_recorded_drums``, set ``drop``, seed 0): FluidR3 and TimGM6mb, snares 38
and 40, two drops a recording (intervals x0.86 from 0.25 s, the velocity's level falling 1.3 dB a bounce),
each cut into its single drops. A drop's true bounces are the notes' true starts; an onset is a true bounce
when it is within 2 ms of one (mir_eval's matching), and false when it is more than 10 ms from every note.
"""

import numpy as np
import pytest

import drumstroke
from _recorded_drums import FONTS, RATE, match, recordings
from drumstroke.analysis import Onsets, find_onsets
from drumstroke.analysis.fit import TOLERANCE, find_suspects, fit_stroke
from drumstroke.design import HUMAN_FORCE

COR = 0.86
CUT = 2.2  # s: between a recording's two drops (the first ends by 2.0 s, the second starts at 2.3 s)

pytestmark = pytest.mark.skipif(not all(path.is_file() for path in FONTS.values()), reason="SoundFonts not installed")


@pytest.fixture(scope="module")
def drops():
    """The 8 single drops: (name, onsets found, true times s)."""
    out = []
    for recording in recordings(sets=("drop",), conditions=("dry",)):
        for start, end in ((0.0, CUT), (CUT, None)):
            signal = recording.signal[int(start * RATE):None if end is None else int(end * RATE)]
            inside = (recording.t >= start) & (recording.t < (np.inf if end is None else end))
            name = f"{recording.name} from {start:g} s"
            out.append((name, find_onsets(signal, RATE, source=name), recording.t[inside] - start))
    return out


def test_recorded_drops_are_played_exactly_on_what_is_kept(drops):
    """With --drop-suspects every kept onset is played within 2 ms and 1 dB under the human thumb's strength, at
    least 90 % of the true bounces found are kept, and no false onset is."""
    kept_true = found_true = 0
    for name, onsets, truth in drops:
        fit = fit_stroke(onsets, cor=COR, drop_suspects=True)
        true = np.zeros(len(onsets), bool)
        true[[j for _, j in match(truth, onsets.t, 2e-3)]] = True
        false = np.abs(onsets.t[:, None] - truth[None, :]).min(axis=1) > 10e-3
        assert fit.within and not fit.unmatched, name
        assert fit.levels == "peak", name  # the modes' levels are read off by 3-17 dB where notes overlap
        assert -HUMAN_FORCE <= fit.design.min_force and fit.design.max_force <= HUMAN_FORCE, name
        assert not np.any(fit.played & false), name
        kept_true += int(np.sum(fit.played & true))
        found_true += int(true.sum())
        # the oracle: the recipe simulated afresh has an impact within 2 ms and 1 dB of every kept onset
        impacts = drumstroke.simulate(fit.recipe).impacts
        t, level = impacts.t + fit.release, impacts.level_db - fit.offset
        for i in np.flatnonzero(fit.played):
            j = int(np.argmin(np.abs(t - onsets.t[i])))
            assert abs(t[j] - onsets.t[i]) <= TOLERANCE[0], (name, i)
            assert abs(level[j] - onsets.peak_db[i]) <= TOLERANCE[1], (name, i)
    assert kept_true >= 0.9 * found_true, (kept_true, found_true)


def test_an_injected_extra_onset_and_a_removed_bounce_are_found_by_time(drops):
    """A drop's onsets with an onset as loud as its neighbours added mid-flight and a bounce taken out: the first
    is dropped as off the sequence of bounces, the second filled within 2 ms of its true time, by time alone."""
    name, onsets, truth = next(d for d in drops if d[0].startswith("TimGM6mb 38"))
    pairs = dict((j, i) for i, j in match(truth, onsets.t, 2e-3))
    assert len(pairs) == len(onsets)  # every onset of this drop is a bounce
    extra_at = onsets.t[5] + 0.4 * (onsets.t[6] - onsets.t[5])
    removed = 12
    keep = np.arange(len(onsets)) != removed
    t = np.sort(np.append(onsets.t[keep], extra_at))
    peak = np.insert(onsets.peak_db[keep], 6, onsets.peak_db[5])
    spoiled = Onsets(t, peak, source=f"{name}, spoiled")
    suspects = {s.onset: s for s in find_suspects(spoiled, level_tolerance=48.0)}  # the levels cannot judge
    assert suspects[6].action == "drop" and "off the sequence of bounces" in suspects[6].reason
    (fill,) = [s for s in suspects.values() if s.action == "fill"]
    assert fill.onset == removed + 1  # the onset after the missed bounce (one added before it, one taken out)
    assert abs(fill.t - truth[pairs[removed]]) <= 2e-3
    fit = fit_stroke(spoiled, cor=COR, drop_suspects=True)
    assert fit.within and not fit.played[6] and len(fit.filled_t) >= 1
