"""The template stages' compiled loops (drumstroke.analysis._templates) against the numpy code they stand for: to the
bit (the same operations in the same order; a median is the same values whatever sorts them, but for the sign of a
zero where +0 and -0 tie, which no peak, product or energy after it sees)."""

import numpy as np
import pytest
from numpy.lib.stride_tricks import sliding_window_view

from _recordings import uneven_noise
from drumstroke.analysis import _templates


@pytest.fixture
def rng():
    return np.random.default_rng(20261127)


def _layer_median_numpy(x, at, scales, whole, clean):
    """The median by parts with np.median, as onsets._layer_template took it before it was compiled."""
    rows = [x[a:a + n] / s for a, s, n in zip(at, scales, whole)]
    bounds = np.unique(np.concatenate(([0], whole, clean)))
    parts = []
    for low, high in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
        voted = whole >= high
        chosen = voted if np.count_nonzero(voted) >= 3 else clean >= high
        if not chosen.any():
            break
        parts.append(np.median([row[low:high] for row, use in zip(rows, chosen) if use], axis=0))
    return np.concatenate(parts) if parts else np.empty(0)


def test_layer_median_is_numpys_median_by_parts(rng):
    x = uneven_noise(rng, 30000)
    x[1000:1400] = np.round(x[1000:1400], 1)  # ties between the waveforms
    for _ in range(300):
        count = int(rng.integers(1, 24))  # odd and even counts, the transposition network of each
        at = rng.integers(0, 20000, count)
        at[rng.random(count) < 0.3] = 1000  # the same samples, ties in every column
        whole = np.minimum(rng.integers(0, 2000, count), len(x) - at)
        whole[rng.random(count) < 0.2] = 0
        clean = np.minimum(whole, rng.integers(0, 2000, count))
        scales = np.exp(rng.standard_normal(count))
        scales[rng.random(count) < 0.3] = 1.0
        got = _templates.layer_median(x, at, scales, whole, clean)
        want = _layer_median_numpy(x, at, scales, whole, clean)
        np.testing.assert_array_equal(got, want, strict=True)


def _next_attack_numpy(x, head, low, high, pre, reach, base, width, energy, rise, likeness, least):
    """The first window that rises, is scaled and correlates, moved to the best correlation within ``reach`` after:
    running sums by np.cumsum (in order), the windows' products and energies as numpy sums sliding windows."""
    count, size = high - base, len(head)
    power = np.concatenate(([0.0], np.cumsum(x[base:high] ** 2)))
    n = np.arange(low, high) - base
    after = (power[np.minimum(n + width, count)] - power[n]) / width
    before = (power[n] - power[np.maximum(n - 4 * width, 0)]) / (4 * width)
    windows = sliding_window_view(x[low - pre:high - pre + size - 1], size)
    dots = windows @ head
    like = dots / (np.sqrt(np.einsum("ij,ij->i", windows, windows) * energy) + 1e-300)
    passing = np.flatnonzero((after >= rise * before) & (dots >= least * energy) & (like >= likeness))
    if not len(passing):
        return -1
    first = passing[0]
    return low + first + int(np.argmax(like[first:min(first + reach + 1, high - low)]))


def test_next_attack_is_the_first_rising_scaled_correlating_window(rng):
    """Onsets in noise, in silence and in what a fit left of itself (zeros, the windows a quiet bound skips)."""
    hits = 0
    for _ in range(400):
        n, size, pre = int(rng.integers(400, 3000)), int(rng.integers(8, 80)), int(rng.integers(1, 8))
        width = int(rng.integers(2, 20))
        x = uneven_noise(rng, n) * 10.0 ** rng.uniform(-4, 1)
        head = rng.standard_normal(size)
        if rng.random() < 0.3:
            x[int(rng.integers(0, n // 2)):][:int(rng.integers(0, n))] = 0.0
        for _ in range(int(rng.integers(0, 4))):  # the head itself, scaled, over the noise
            at = int(rng.integers(pre, n - size))
            x[at - pre:at - pre + size] += head * 10.0 ** rng.uniform(-3, 1)
        low = int(rng.integers(4 * width + pre, n // 2))
        high = int(rng.integers(low, n - size + pre + 1))
        base = max(0, low - 4 * width) if rng.random() < 0.8 else int(rng.integers(0, low - pre + 1))
        energy = head @ head
        args = (x, head, low, high, pre, int(rng.integers(0, 20)), base, width, energy, float(rng.choice([1.0, 4.0])),
                float(rng.choice([0.3, 0.8])), float(rng.choice([1e-3, 0.01, 0.3])))
        want = _next_attack_numpy(*args)
        assert _templates.next_attack(*args) == want
        hits += want >= 0
    assert 50 < hits < 350  # both answers tried


def test_window_dots_sum_each_window_in_order(rng):
    """The template fit's sliding products, eight terms a pass, are numpy's matmul over the sliding windows (its
    loop adds each row's products in order): to the bit, for every length's last terms fewer than eight."""
    from drumstroke.analysis._kernels import window_dots

    for size in list(range(1, 26)) + [504]:
        count = int(rng.integers(1, 300))
        x, low = uneven_noise(rng, count + size + 20), int(rng.integers(0, 20))
        t = rng.standard_normal(size) * 10.0 ** rng.uniform(-3, 3)
        want = sliding_window_view(x[low:low + count + size - 1], size) @ t
        np.testing.assert_array_equal(window_dots(x, low, t, count), want, strict=True)


def _own_peaks_numpy(x, starts, following, ends, bank, offsets, lengths, window, reach, shift):
    """onsets._own_peaks' loop in numpy: the fits' products and energies by np.dot, the windows' energies by running
    sums (np.cumsum, in order), the first least unexplained of the first template that leaves the least. Returns the
    peaks, those of ``x`` and what is left."""
    rest, peaks, heard = x.copy(), [], []
    longest = max(range(len(lengths)), key=lambda t: (lengths[t], t))
    for start, follow, end in zip(starts, following, ends):
        peaks.append(np.abs(rest[start:end]).max(initial=0.0))
        heard.append(np.abs(x[start:end]).max(initial=0.0))
        need = min(follow - start + window, reach)
        usable = [t for t in range(len(lengths)) if lengths[t] >= need] or [longest]
        low = max(start - shift, 0)
        best, chosen = np.inf, None
        for t in usable:
            length = min(lengths[t], follow - start, len(rest) - start - shift)
            head = bank[offsets[t]:offsets[t] + length]
            if length < 16 or not np.dot(head, head) > 0.0:
                continue
            part = rest[low:start + shift + length]
            cross = np.array([np.dot(part[k:k + length], head) for k in range(len(part) - length + 1)])
            power = np.concatenate(([0.0], np.cumsum(part * part)))
            own = power[length:] - power[:-length]
            unexplained = (own - cross * cross / np.dot(head, head)) / np.maximum(own, np.finfo(float).tiny)
            k = int(np.argmin(unexplained))
            if chosen is None or unexplained[k] < best:
                best, chosen = unexplained[k], (t, low + k, cross[k] / np.dot(head, head))
        if chosen is not None:
            t, at, scale = chosen
            size = min(lengths[t], len(rest) - at)
            rest[at:at + size] -= scale * bank[offsets[t]:offsets[t] + size]
    return np.array(peaks), np.array(heard), rest


@pytest.mark.parametrize("case", ["notes", "ties"])
def test_own_peaks_are_numpys_fits_taken_off_in_turn(rng, case):
    """Notes repeating a few waveforms (scaled, a sample or two off, over noise), each peak read with the earlier
    notes' fits taken off; with ``ties``, two templates the same and silent stretches, where the windows' energies
    alone cannot tell the least (the running sums decide, as numpy's)."""
    from drumstroke.analysis._templates import own_peaks

    for _ in range(40):
        n, shift = 30000, int(rng.integers(1, 5))
        sounds = [rng.standard_normal(m) * np.exp(-np.arange(m) / 600.0) for m in rng.integers(300, 4000, 3)]
        x = 1e-3 * rng.standard_normal(n)
        starts = np.sort(rng.choice(np.arange(10, n - 100, 50), int(rng.integers(2, 30)), replace=False))
        for a in starts:
            s = sounds[int(rng.integers(0, 3))] * rng.uniform(0.05, 1.0)
            a = a + int(rng.integers(-2, 3))
            x[a:a + len(s)] += s[:n - a]
        if case == "ties":
            x[rng.random(n) < 0.5] = 0.0
            x[2000:9000] = 0.0
            sounds.append(sounds[0].copy())
        bank = np.concatenate(sounds)
        lengths = np.array([len(s) for s in sounds], dtype=np.int64)
        offsets = np.cumsum(lengths) - lengths
        following = np.append(starts[1:], n)
        ends = np.maximum(np.minimum(starts + 480, following), starts + 1)
        args = (x, starts.astype(np.int64), following.astype(np.int64), ends.astype(np.int64), bank, offsets, lengths,
                480, int(rng.integers(500, 5000)), shift)
        want = _own_peaks_numpy(*args)
        rest = x.copy()
        got = own_peaks(rest, *args[1:])  # in place
        np.testing.assert_array_equal(got[0], want[0], strict=True)
        np.testing.assert_array_equal(got[1], want[1], strict=True)
        np.testing.assert_array_equal(rest, want[2], strict=True)


def test_a_choice_told_from_bounds_is_the_running_sums(rng):
    """Where the windows' energies summed in another order tell own_peaks' choice, it is the running sums' (the first
    least of the first template that leaves the least); near ties (windows a rounding apart) are left undecided."""
    from drumstroke.analysis._kernels import least_unexplained_by, running_power
    from drumstroke.analysis._templates import _surely_least

    told = undecided = 0
    for _ in range(2000):
        windows, templates = int(rng.integers(1, 8)), int(rng.integers(1, 4))
        sizes = rng.integers(16, 300, templates)
        sizes[rng.random(templates) < 0.2] = 0
        n = windows + sizes.max()
        rest = np.full(n, 0.3) if rng.random() < 0.5 else rng.standard_normal(n)
        rest *= 1.0 + rng.choice([0.0, 1e-15, 1e-13, 1e-6]) * rng.standard_normal(n)  # near ties, or none
        heads = [rest[:size].copy() if rng.random() < 0.5 else rng.standard_normal(size) for size in sizes]
        crosses, energies = np.zeros((templates, windows)), np.ones(templates)
        for t, size in enumerate(sizes):
            if size:
                crosses[t] = [np.dot(rest[k:k + size], heads[t]) for k in range(windows)]
                energies[t] = np.dot(heads[t], heads[t])
        power = running_power(rest, n)
        best, want = np.inf, None
        for t, size in enumerate(sizes):
            if size:
                k, unexplained = least_unexplained_by(power, crosses[t], energies[t], size)
                if want is None or unexplained < best:
                    best, want = unexplained, (t, k)
        got = _surely_least(rest, 0, windows, crosses, energies, sizes.astype(np.int64))
        if got == (-1, 0):
            undecided += 1
        else:
            assert got == want
            told += 1
    assert told > 500 and undecided > 200


def _template_attacks_numpy(d, rate, times, config):
    """onsets._template_attacks in numpy, as it was before it was compiled."""
    import math

    span, gap, pre = round(5e-3 * rate), round(0.5e-3 * rate), round(0.5e-3 * rate)
    centres = np.rint(times).astype(np.int64)
    peaks = np.array([d[c:c + span].max(initial=0.0) for c in centres])
    priors = np.array([d[max(0, c - span):max(1, c - gap)].max(initial=0.0) for c in centres])
    clear = priors <= peaks * 10.0 ** (config.lead_clear_db / 20.0)
    ends = np.append(times[1:], len(d))
    floor = peaks.max(initial=0.0) * 10.0 ** (config.threshold_db / 20.0)
    fit = (np.rint(times) >= pre) & (ends - times >= 20e-3 * rate) & clear
    which = np.flatnonzero(fit)
    chosen = int(which[np.argmax(peaks[which])]) if len(which) and peaks[which].max() > 0.0 else None
    audible = which[peaks[which] >= floor]
    least = int(audible[np.argmin(peaks[audible])]) if len(audible) and peaks[audible].min() < math.inf else None
    room = np.where(fit, np.minimum(ends - times, config.tail * rate), -1.0)
    longest = max(np.flatnonzero(room == room.max(initial=0.0)).tolist(), key=lambda k: peaks[k], default=None)
    return chosen, least, longest


def test_template_attacks_are_numpys_choice(rng):
    """The loudest, quietest and roomiest clear attacks, ties (equal peaks, equal rooms up to the tail) and none."""
    from dataclasses import replace

    from drumstroke.analysis.onsets import OnsetConfig, _template_attacks

    rate = 48000
    for _ in range(300):
        d = np.abs(uneven_noise(rng, 30000))
        if rng.random() < 0.3:
            d = np.round(d, 1)  # equal peaks
        times = np.sort(rng.choice(np.arange(0, 30000), int(rng.integers(0, 30)), replace=False)).astype(float)
        times += rng.uniform(-0.5, 0.5, len(times)) * (rng.random() < 0.5)
        for k in rng.integers(0, len(times), 3) if len(times) else []:
            d[int(np.rint(times[k])):][:200] = 5.0  # loud, clear attacks
        config = replace(OnsetConfig(), tail=float(rng.choice([0.001, 0.02, 0.15])),
                         lead_clear_db=float(rng.choice([-20.0, -3.0, 0.0])))
        assert _template_attacks(d, rate, times, config) == _template_attacks_numpy(d, rate, times, config)


def test_eight_windows_in_a_row_sum_each_in_order(rng):
    """The next attack's products of eight windows in a row are numpy's matmul over the sliding windows: to the bit."""
    from drumstroke.analysis._templates import _eight_in_a_row

    out = np.empty(8)
    for size in list(range(1, 20)) + [168]:
        x, start = uneven_noise(rng, size + 40), int(rng.integers(0, 30))
        t = rng.standard_normal(size)
        _eight_in_a_row(x, start, t, out)
        np.testing.assert_array_equal(out, sliding_window_view(x[start:start + size + 7], size) @ t, strict=True)
