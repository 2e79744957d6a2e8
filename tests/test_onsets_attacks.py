"""The compiled loop of the onset detector's template search (drumstroke.analysis._attacks): exact oracles."""

import numpy as np

from drumstroke.analysis._attacks import _add, _correlations, _dot, _energies, _sums, continued, template_search

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


def test_taking_a_scaled_template_off_is_numpys_to_the_bit(rng):
    """_add with the scale negated is onsets._fit_template's former ``remainder[start:stop] -= scale * template[...]``
    (a product and a difference, each rounded once), also where the template runs past the remainder's end."""
    template = rng.standard_normal(500)
    for c, scale in [(PRE, 0.37), (1234, -1.9e-3), (2900, 0.5)]:
        x = rng.standard_normal(3000)
        expected = x.copy()
        start = c - PRE
        stop = min(len(x), start + len(template))
        expected[start:stop] -= scale * template[:stop - start]
        _add(x, template, c, -scale, PRE)
        assert np.array_equal(x.view(np.uint64), expected.view(np.uint64))


def test_the_three_sums_side_by_side_are_each_dot_to_the_bit(rng):
    """_sums is _dot's three sums (the window's product with the template, its energy, the template's), the bits."""
    x, t = rng.standard_normal(3000) * np.exp(-np.arange(3000) / 500.0), rng.standard_normal(504)
    for start, count in [(0, 1), (17, 48), (500, 504), (2400, 503)]:
        assert _sums(x, start, t, count) == (_dot(x, start, t, count), _dot(x, start, x[start:], count),
                                             _dot(t, 0, t, count))


def _note(rng):
    """A recorded note's waveform: silence, then a noise burst decaying over 30 ms (0.2 s long)."""
    n = round(0.2 * RATE)
    burst = rng.standard_normal(n - PRE) * np.exp(-np.arange(n - PRE) / (0.03 * RATE))
    return np.concatenate((np.zeros(PRE), burst))


def _search(signal, template, times, refused, bounce=960, layer=(-1, 0), dropped=False, burst=0.0, layer_bounce=1.0):
    found, likes, gone = template_search(signal.copy(), template, template[:PRE + 144], np.asarray(times, dtype=float),
                                         np.zeros(len(times)), np.asarray(refused, dtype=float), 0.0, *layer, PRE, 96,
                                         48, 480, bounce, 384, 2400, 120, 0.8, 0.8, 0.35, 1.5, 0.01, burst, 0, np.zeros(len(times), dtype=bool), 0.5, 0.8,
                                         layer_bounce)
    return (found, likes, gone) if dropped else (found, likes)


def _layers(rng):
    """A loud note's waveform and a quiet velocity layer's: the same but for 3.5-20 ms in, where the quiet one's
    differs by a noise of its own (a recorded sample's layers differ in their first milliseconds)."""
    loud = _note(rng)
    quiet = loud.copy()
    quiet[PRE + 168:PRE + 960] += 0.7 * rng.standard_normal(792) * np.exp(-np.arange(168, 960) / (0.03 * RATE))
    return loud, quiet


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


def test_a_close_bounce_under_a_quieter_layers_note_is_found_at_its_sample(rng):
    """A loud note (the template), a quiet layer's note alone (``layer_at``), then a quiet note and its bounce 12 ms
    after it (0.4 times): taken off by the layer's own sound (learned where the search reaches its note), the note
    leaves nothing and the bounce is found at its very sample, nothing else; taken off by the loud template, what is
    left of the note (its own 3.5-20 ms) hides the bounce."""
    loud, quiet = _layers(rng)
    signal = np.zeros(RATE)
    starts = [4800, 19200, 33600]
    bounce = starts[2] + 576
    signal[starts[0] - PRE:starts[0] - PRE + len(loud)] += loud
    for start, scale in ((starts[1], 0.6), (starts[2], 0.5), (bounce, 0.2)):
        signal[start - PRE:start - PRE + len(quiet)] += scale * quiet
    found, likes = _search(signal, loud, starts, [], layer=(1, len(quiet)))
    assert found.tolist() == [bounce] and likes[0] > 0.999
    assert bounce not in _search(signal, loud, starts, [])[0].tolist()


def test_a_detection_neither_template_fits_is_the_bounce_placed_early(rng):
    """A note, its bounce 12 ms after (0.5 times) and a detection 3 ms before the bounce, on what is left of the note:
    the search looks past it, finds the bounce at its sample and drops the detection; a detection where the template
    fits (the bounce itself) is kept and ends the search."""
    template = _note(rng)
    signal = np.zeros(RATE)
    bounce = 9600 + 576
    for start, scale in ((9600, 1.0), (bounce, 0.5)):
        signal[start - PRE:start - PRE + len(template)] += scale * template
    found, _, gone = _search(signal, template, [9600, bounce - 144], [], dropped=True)
    assert found.tolist() == [bounce] and gone.tolist() == [False, True]
    found, _, gone = _search(signal, template, [9600, bounce], [], dropped=True)
    assert not len(found) and not gone.any()


def test_a_layer_is_continued_by_the_template_scaled_to_it(rng):
    """``continued``: the layer's own samples, then the template's scaled by least squares over their common part after
    ``settle`` samples (exact when the two tails are one waveform scaled); cut to the template's length."""
    template = _note(rng)
    own = 0.3 * template[:2000]
    own[:300] = rng.standard_normal(300)  # a start of its own
    out = continued(own, template, 480)
    np.testing.assert_array_equal(out[:2000], own)
    np.testing.assert_allclose(out[2000:], 0.3 * template[2000:], rtol=1e-12, atol=1e-15)
    assert len(continued(np.ones(len(template) + 5), template, 480)) == len(template)
