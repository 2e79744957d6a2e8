"""The compiled loop of the onset detector's template search (drumstroke.analysis._attacks): exact oracles."""

import numpy as np

from drumstroke.analysis._attacks import _correlations, _energies, template_search

RATE = 48000
PRE = 24  # the template starts 0.5 ms before its attack


def test_correlations_and_energies_are_numpys(rng):
    x, t = rng.standard_normal(3000), rng.standard_normal(168)
    for start, count in [(0, 1), (17, 241), (500, 960), (2000, 833)]:
        window = x[start:start + count + len(t) - 1]
        np.testing.assert_allclose(_correlations(x, start, t, count), np.correlate(window, t, "valid"), rtol=1e-12,
                                   atol=1e-12)
        direct = [x[start + k:start + k + len(t)] @ x[start + k:start + k + len(t)] for k in range(count)]
        np.testing.assert_allclose(_energies(x, start, count, len(t)), direct, rtol=1e-9)


def _note(rng):
    """A recorded note's waveform: silence, then a noise burst decaying over 30 ms (0.2 s long)."""
    n = round(0.2 * RATE)
    burst = rng.standard_normal(n - PRE) * np.exp(-np.arange(n - PRE) / (0.03 * RATE))
    return np.concatenate((np.zeros(PRE), burst))


def _search(signal, template, times, refused, bounce=960):
    found, likes, _ = template_search(signal.copy(), template, template[:PRE + 144], np.asarray(times, dtype=float),
                                      np.zeros(len(times)), np.asarray(refused, dtype=float), 0.0, -1, 0, PRE, 96, 48,
                                      480, bounce, 384, 2400, 120, 0.8, 0.8, 0.35, 1.5, 0.01)
    return found, likes


def test_a_close_bounce_and_a_refused_note_are_found_at_their_samples(rng):
    """Notes that are the template scaled add up: the first known, a bounce 12 ms after it (0.8 times) and a note
    90 ms after that (0.1 times, refused 0.4 ms early) are found at their very samples, nothing else."""
    template = _note(rng)
    signal = np.zeros(RATE)
    starts = [4800, 4800 + 576, 4800 + 576 + 4320]
    for start, scale in zip(starts, [1.0, 0.8, 0.1]):
        signal[start - PRE:start - PRE + len(template)] += scale * template
    found, likes = _search(signal, template, [starts[0]], [starts[2] - 19])
    assert found.tolist() == starts[1:] and np.all(likes > 0.999)
    assert not len(_search(signal, template, [starts[0]], [], bounce=0)[0])  # neither sought


def test_what_is_left_of_a_note_is_no_new_note(rng):
    """A note alone, known: what the fit leaves (nothing) and a refused onset in its tail are no attacks."""
    template = _note(rng)
    signal = np.zeros(RATE)
    signal[10000 - PRE:10000 - PRE + len(template)] += 0.7 * template
    found, _ = _search(signal, template, [10000.0], [10000.0 + 3000, 10000.0 + 6000])
    assert not len(found)
