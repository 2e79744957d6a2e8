"""Compiled loops written to make the onset detector faster (drumstroke.analysis._templates and its neighbours) against
the numpy code they stand for: to the bit, each computing what that code computed in the same operations.

np.dot's sums are OpenBLAS's ddot kernel's where numpy's BLAS is OpenBLAS for x86-64 with AVX2 (its Haswell kernel,
on Intel and AMD processors since 2013: what the detector ran); with another BLAS they are in another order, and the
compiled sums are held to them within rounding (and the loop that decides on them is not compared)."""

import numpy as np
import pytest

from drumstroke.analysis import _templates


@pytest.fixture
def rng():
    return np.random.default_rng(20261127)


def _haswell_dot():
    """Whether numpy's BLAS is OpenBLAS's Haswell kernels (threadpoolctl's names)."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    return any(library["user_api"] == "blas" and "numpy" in library["filepath"]
               and (library["internal_api"], library.get("architecture")) == ("openblas", "Haswell")
               for library in threadpoolctl.threadpool_info())


def test_lag_dots_are_numpys_dots_of_each_window(rng):
    """blas_lag_dots gives np.dot's bits (OpenBLAS's ddot, on one thread as the detector runs it) for every length: the
    16 lanes, the products left over, a window count that is no multiple of the lags side by side."""
    from threadpoolctl import threadpool_limits

    exact = _haswell_dot()
    with threadpool_limits(1, user_api="blas"):
        for _ in range(600):
            length = int(rng.integers(1, 3000))
            count, first = int(rng.integers(1, 20)), int(rng.integers(0, 9))
            x = rng.standard_normal(first + count + length + 3) * 10.0 ** rng.uniform(-30, 30)
            x[rng.random(len(x)) < 0.05] = 0.0
            y = rng.standard_normal(length + int(rng.integers(0, 5))) * 10.0 ** rng.uniform(-3, 3, 1)
            got = np.full(count + 1, np.nan)
            _templates.blas_lag_dots(x, first, count, y, length, got)
            want = [np.dot(x[first + k:first + k + length], y[:length]) for k in range(count)]
            if exact:
                np.testing.assert_array_equal(got[:count], want)
            else:
                scale = [np.abs(x[first + k:first + k + length]) @ np.abs(y[:length]) for k in range(count)]
                assert np.all(np.abs(got[:count] - want) <= 4 * length * np.finfo(float).eps * np.array(scale))
            assert np.isnan(got[count])  # nothing written past the windows asked for


def test_squares_bound_the_running_sums(rng):
    """_squares sums in its own order: within the few ulps of the exact sum that _surely_least's bounds allow."""
    from numba import njit

    squares = njit(lambda x, first, last: _templates._squares(x, first, last))
    for _ in range(300):
        x = rng.standard_normal(int(rng.integers(1, 2000))) * 10.0 ** rng.uniform(-100, 100)
        first = int(rng.integers(0, len(x)))
        last = int(rng.integers(first, len(x) + 1))
        exact = float(np.sum(np.asarray(x[first:last], dtype=np.longdouble) ** 2))
        assert abs(squares(x, first, last) - exact) <= 4.0 * (last - first + 1) * np.finfo(float).eps * exact


def _fitted_attacks_python(remainder, template, head, times, kinds, likeness, lead_clear, start_clear, pre, reach, gap,
                           shortest, longest, offset, fit_likeness, precise, burst_width, echo, burst_least, width,
                           back, rise, least, head_energy):
    """onsets._fit_template's loop as it was in Python (its queue a list, its fits by numpy and the kernels)."""
    from drumstroke.analysis._kernels import best_lag
    from drumstroke.analysis._templates import next_attack

    energies = {}
    queue = [(t, i) for i, t in enumerate(times.tolist())]
    known_kinds, known_likeness = kinds.tolist(), likeness.tolist()
    out_t, out_k, out_l, out_f = [], [], [], []
    while queue:
        t, i = queue.pop(0)
        c = round(t)
        following = len(remainder)
        for u, _ in queue:
            if u > t + gap:
                following = round(u)
                break
        span = min(max(shortest, min(longest, following - c)), len(template))
        start = c - pre
        low, high = max(0, start - reach), min(len(remainder), start + reach + span)
        lag, scale, like = 0, 0.0, 0.0
        if high - low >= span:
            part = template[:span]
            energy = energies.setdefault(span, part @ part)
            k, dot, like = best_lag(remainder, part, low, high - low - span + 1, energy)
            lag, scale, like = low + k - start, float(dot / energy), float(like)
        fitted = like >= fit_likeness and scale > 0.0
        timed = fitted and (i < 0 or not lead_clear[i] or (like >= precise and not start_clear[i]))
        out_t.append(c + lag + offset if timed else t)
        out_k.append(3 if timed else known_kinds[i])
        out_l.append(like if i < 0 else known_likeness[i])
        out_f.append(fitted)
        if not fitted:
            continue
        start = c + lag - pre
        near = [round(u) for u, j in queue if j >= 0 and c + lag < u <= c + lag + echo] if timed else []
        before = {k: float(remainder[k:k + burst_width] @ remainder[k:k + burst_width]) for k in near}
        n = min(len(template), len(remainder) - start)
        remainder[start:start + n] += -scale * template[:n]
        if before:
            own = {k for k, e in before.items()
                   if remainder[k:k + burst_width] @ remainder[k:k + burst_width] < e * burst_least}
            queue = [(u, j) for u, j in queue if j < 0 or round(u) not in own]
        while timed and queue and queue[0][0] < c + lag + gap + (reach if i < 0 else 0):
            queue.pop(0)
        low, high = c + lag + gap, min(following - gap, start + len(template))
        high = min(high, len(remainder) - len(head) + pre)
        if high > low >= pre:
            new = next_attack(remainder, head, low, high, pre, reach, max(0, low - back), width, head_energy, rise,
                              fit_likeness, least)
            if new >= 0:
                queue.insert(0, (new + offset, -1))
    return np.array(out_t), np.array(out_k, dtype=np.int64), np.array(out_l), np.array(out_f)


@pytest.mark.parametrize("trial", range(40))
def test_fitted_attacks_are_the_python_loops(trial):
    """The compiled template fit of onsets._fit_template against its Python loop: a recorded sample's notes (one
    waveform, bursting again 3 ms in) at random levels and spacings, half with a bounce 8-45 ms after, detections at
    most notes (the others for the template to find), at their second bursts and at random; kinds, likeness and
    clearness at random."""
    if not _haswell_dot():
        pytest.skip("numpy's BLAS sums its dot products in another order than OpenBLAS's Haswell kernel")
    rng = np.random.default_rng(trial)
    rate, n = 48_000, 48_000
    t = np.arange(int(0.1 * rate)) / rate
    sound = np.exp(-t / 0.03) * (np.sin(2 * np.pi * 190 * t) + 0.5 * np.sin(2 * np.pi * 330 * t + 1.0))
    sound += 0.8 * np.exp(-t / 0.01) * rng.standard_normal(len(t))
    burst = int(3e-3 * rate)
    sound[burst:] += 0.6 * sound[:len(sound) - burst]  # a second burst
    band = 1e-4 * rng.standard_normal(n)
    notes = np.sort(rng.choice(np.arange(2000, n - 6000), size=int(rng.integers(3, 10)), replace=False))
    bounces = notes[rng.random(len(notes)) < 0.5] + rng.integers(int(8e-3 * rate), int(45e-3 * rate), 1)
    notes = np.unique(np.concatenate((notes, bounces)))
    for at, level in zip(notes, 10.0 ** rng.uniform(-1.5, 0, len(notes))):
        m = min(len(sound), n - at)
        band[at:at + m] += level * sound[:m]
    heard = notes[(rng.random(len(notes)) < 0.7) | (notes == notes[0])]  # some notes found by the template only
    detections = np.concatenate((heard + rng.integers(-20, 20, len(heard)), heard[rng.random(len(heard)) < 0.5] + burst,
                                 rng.integers(2000, n - 2000, int(rng.integers(0, 5)))))
    times = np.unique(detections).astype(float) + rng.choice([0.0, 0.25, 0.5], len(np.unique(detections)))
    count = len(times)
    pre = round(0.5e-3 * rate)
    template = band[notes[0] - pre:notes[0] + int(0.05 * rate)].copy()
    head = template[:pre + round(3e-3 * rate)]
    args = (template, head, times, rng.integers(0, 3, count), rng.random(count), rng.random(count) < 0.5,
            rng.random(count) < 0.5, pre, round(3e-3 * rate), round(2e-3 * rate), pre + round(1e-3 * rate),
            pre + round(10e-3 * rate), float(rng.choice([0.0, 0.3])), 0.8, 0.9, round(1e-3 * rate), 8e-3 * rate,
            10.0 ** (-6.0 / 10.0), round(1e-3 * rate), 4 * round(1e-3 * rate), 4.0, 1e-2, float(head @ head))
    want_band, got_band = band.copy(), band.copy()
    want = _fitted_attacks_python(want_band, *args)
    got = _templates.fitted_attacks(got_band, *args)
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g, w)
    np.testing.assert_array_equal(got_band, want_band)


@pytest.mark.parametrize("trial", range(6))
def test_peaks_over_a_level_are_librosas(trial):
    """_front.peak_pick_over gives librosa.util.peak_pick's peaks at least the level asked, where the stretches under
    it are skipped: ties, flat stretches, peaks a window apart in a chain (a saw rising), short signals, levels none
    and all pass."""
    librosa = pytest.importorskip("librosa")
    from drumstroke.analysis._front import peak_pick_over

    rng = np.random.default_rng(trial)
    for case in range(400):
        n = int(rng.integers(1, 500))
        kind = case % 5
        if kind == 0:
            x = rng.standard_normal(n)
        elif kind == 1:
            x = rng.integers(0, 4, n).astype(float)
        elif kind == 2:
            x = np.repeat(rng.integers(0, 5, n), rng.integers(1, 8))[:n].astype(float)
        elif kind == 3:
            x = np.abs(rng.standard_normal(n)) * (rng.random(n) < 0.05) * 10.0
        else:
            x = np.arange(n) % int(rng.integers(1, 12)) + 0.1 * np.arange(n)
        gap = int(rng.integers(1, 25))
        least = float(rng.choice([np.quantile(x, rng.random()), -np.inf, np.inf, 0.0, 1.0]))
        want = librosa.util.peak_pick(x, pre_max=gap, post_max=gap, pre_avg=1, post_avg=1, delta=0.0, wait=gap)
        want = want[x[want] >= least]
        np.testing.assert_array_equal(peak_pick_over(x, gap, np.nextafter(least, -np.inf)), want,
                                      err_msg=f"kind={kind}, n={n}, gap={gap}, least={least}")


def test_rising_blocks_are_the_python_loop(rng):
    """_ghosts.rising against its definition read plainly: each block's value against the most over its span before."""
    from drumstroke.analysis._ghosts import rising

    for _ in range(300):
        e = rng.standard_normal(int(rng.integers(40, 200))) * (rng.random() < 0.5 or 1.0)
        e[rng.random(len(e)) < 0.2] = 0.0
        back = int(rng.integers(1, 20))
        span = int(rng.integers(1, back + 1))
        low = int(rng.integers(back, len(e) - 1))
        high = int(rng.integers(low, len(e)))
        rise = float(rng.uniform(0.5, 4.0))
        want = [j for j in range(low, high) if e[j] > 0.0 and e[j] >= rise * max(0.0, e[j - back:j - back + span].max())]
        np.testing.assert_array_equal(rising(e, low, high, back, span, rise), np.array(want, dtype=np.int64))


def test_accent_rises_are_the_python_loop(rng):
    """_ghosts.accent_rises against the loop it replaced, read plainly (each accent's mates' remainders by
    remainder_blocks, cut where fewer than the mates asked reach, the rises by rising): the same rises, mates and
    windows, over random bands, onsets and mates (windows cut by the next attack, by the remainders, none left)."""
    from drumstroke.analysis._ghosts import accent_rises, remainder_blocks, rising

    for _ in range(200):
        size, before, after, width, block = 40, 40, 40, 16, 4
        span = int(rng.integers(60, 400))
        c = np.sort(rng.choice(np.arange(50, 3000), int(rng.integers(3, 12)), replace=False)).astype(np.int64)
        band = rng.standard_normal(4000) * np.exp(-np.arange(4000) % 300 / 60.0)
        which = np.sort(rng.choice(len(c), int(rng.integers(2, len(c) + 1)), replace=False)).astype(np.int64)
        ends = c + rng.integers(1, 500, len(c))
        accents = np.flatnonzero(rng.random(len(which)) < 0.7).astype(np.int64)
        count = rng.integers(1, 4, len(accents)).astype(np.int64)
        mate = rng.integers(0, len(which), int(count.sum())).astype(np.int64)
        shifts = rng.integers(-2, 3, len(mate)).astype(np.int64)
        scales = rng.uniform(0.5, 1.5, len(mate))
        fewest, rise = int(rng.integers(1, 3)), float(rng.uniform(1.0, 3.0))
        first = np.cumsum(count) - count
        power, done = np.empty((len(mate), (span + after) // block)), np.zeros(len(mate), dtype=np.int64)
        got = accent_rises(band, c, which, ends, accents, first, count, mate, shifts, scales, span, size, before,
                           after, width, block, fewest, rise, power, done)
        want = ([], [], [], np.zeros(len(accents), dtype=np.int64))
        for k, i in enumerate(accents):
            b = which[i]
            length = min(span, ends[b] - c[b])
            if length <= size + before:
                continue
            want[3][k] = length + after
            used = range(first[k], first[k] + count[k])
            starts = np.array([c[which[mate[u]]] + shifts[u] for u in used], dtype=np.int64)
            valid = np.array([((c[which[mate[u]] + 1] if which[mate[u]] + 1 < len(c) else len(band))
                               - c[which[mate[u]]] - width) // block for u in used], dtype=np.int64)
            e, pick = remainder_blocks(band, c[b], starts, scales[first[k]:first[k] + count[k]], valid,
                                       (length + after) // block, block, width // block, fewest)
            short = np.flatnonzero(~np.isfinite(e))
            length = min(length, short[0] * block if len(short) else length)
            if length <= size + before:
                continue
            for j in rising(e, (size + before) // block, (length - width) // block, before // block,
                            (before - width) // block, rise):
                want[0].append(k), want[1].append(j), want[2].append(pick[j])
        for g, w in zip(got, want):
            np.testing.assert_array_equal(g, np.array(w, dtype=np.int64))


def test_remainder_blocks_with_mates_notes_are_the_loop_they_replaced(rng):
    """_ghosts.remainder_blocks (block_powers, least_remainders) with the mates' next notes taken off (gains and lags,
    ghost_mate_notes) against the loop it replaced, read plainly (each block's squares summed in order, each window's
    blocks summed in order, the least over the mates that reach): to the bit."""
    from drumstroke.analysis._ghosts import remainder_blocks

    for _ in range(100):
        count, block, window, lead = int(rng.integers(1, 4)), int(rng.integers(1, 13)), int(rng.integers(1, 6)), 6
        blocks = int(rng.integers(window, 60))
        band = rng.standard_normal(5000)
        start = int(rng.integers(1000, 2000))
        mates = rng.integers(2000, 4000, count).astype(np.int64)
        scales = rng.uniform(0.5, 1.5, count)
        valid = rng.integers(-2, blocks + 3, count).astype(np.int64)
        gains = np.where(rng.random(count) < 0.6, rng.uniform(0.1, 1.0, count), 0.0)
        lags = rng.integers(lead, blocks * block + lead + 1, count).astype(np.int64)
        fewest = int(rng.integers(1, 3))
        least, pick = remainder_blocks(band, start, mates, scales, valid, blocks, block, window, fewest, gains, lags,
                                       lead)
        size = blocks - window + 1
        want, whose = np.full(size, np.inf), np.zeros(size, dtype=np.int64)
        for j in range(size):
            reach = 0
            for m in range(count):
                if j >= valid[m]:
                    continue
                reach += 1
                energy = 0.0
                for i in range(j, j + window):
                    total = 0.0
                    for k in range(i * block, (i + 1) * block):
                        v = band[start + k] - scales[m] * band[mates[m] + k]
                        if gains[m] != 0.0 and k >= lags[m] - lead:
                            v += gains[m] * band[start + k - lags[m]]
                        total += v * v
                    energy += total
                if energy < want[j]:
                    want[j], whose[j] = energy, m
            if reach < fewest:
                want[j] = np.inf
        np.testing.assert_array_equal(least, want)
        np.testing.assert_array_equal(pick[np.isfinite(want)], whose[np.isfinite(want)])


def test_template_search_correlations_are_the_loop_they_replaced(rng):
    """_attacks._correlations (now _kernels.window_dots, eight terms a pass) against the loop it replaced: each window's
    products added in order of the template's samples, one product to every window's sum at a time (to the bit)."""
    from numba import njit

    from drumstroke.analysis._attacks import _correlations

    @njit
    def replaced(x, start, t, count):
        samples = x[start:start + count + len(t) - 1].copy()
        out = np.zeros(count)
        for j in range(len(t)):
            v = t[j]
            window = samples[j:j + count]
            for k in range(count):
                out[k] += window[k] * v
        return out

    for size in list(range(1, 20)) + [168, 504]:
        count = int(rng.integers(1, 1200))
        x = rng.standard_normal(count + size + 30) * 10.0 ** rng.uniform(-30, 30)
        x[rng.random(len(x)) < 0.05] = 0.0
        start = int(rng.integers(0, 30))
        t = rng.standard_normal(size) * 10.0 ** rng.uniform(-3, 3)
        np.testing.assert_array_equal(_correlations(x, start, t, count), replaced(x, start, t, count), strict=True)


def _replaced_echo_novelty():
    """_rooms.echo_novelty as it stood before its products came from _kernels.window_dots: the lags tried each time
    (coarse, then fine about the best) summed four at a time, each in order."""
    import math

    from numba import njit

    @njit
    def crosses_of(x, start, low, lags, width):
        out = np.empty(len(lags))
        n = 0
        while n + 4 <= len(lags):
            a, b, c, e = low + lags[n], low + lags[n + 1], low + lags[n + 2], low + lags[n + 3]
            s0, s1, s2, s3 = 0.0, 0.0, 0.0, 0.0
            for k in range(width):
                v = x[start + k]
                s0 += v * x[a + k]
                s1 += v * x[b + k]
                s2 += v * x[c + k]
                s3 += v * x[e + k]
            out[n], out[n + 1], out[n + 2], out[n + 3] = s0, s1, s2, s3
            n += 4
        for m in range(n, len(lags)):
            total = 0.0
            for k in range(width):
                total += x[start + k] * x[low + lags[m] + k]
            out[m] = total
        return out

    @njit
    def echo_novelty(x, at, centres, before, after, reach, step, most_left):
        width = before + after
        start = at - before
        if start < 0 or start + width > len(x):
            return math.inf
        own = 0.0
        for k in range(width):
            own += x[start + k] * x[start + k]
        least, best, scale = math.inf, -1, 0.0
        for i in range(len(centres)):
            low = centres[i] - reach - before
            if low < 0 or low + width + 2 * reach > len(x):
                continue
            power = np.empty(2 * reach + 1)
            total = 0.0
            for k in range(width):
                total += x[low + k] * x[low + k]
            power[0] = total
            for lag in range(1, 2 * reach + 1):
                total += x[low + lag + width - 1] * x[low + lag + width - 1] - x[low + lag - 1] * x[low + lag - 1]
                power[lag] = total
            first, last, coarse = 0, 2 * reach, step
            while True:
                found = -1
                lags = np.arange(first, last + 1, coarse)
                crosses = crosses_of(x, start, low, lags, width)
                for n in range(len(lags)):
                    lag, cross = lags[n], crosses[n]
                    if power[lag] <= 0.0:
                        continue
                    left = own - cross * cross / power[lag]
                    if left < least:
                        least, best, scale, found = left, low + lag, cross / power[lag], lag
                if coarse == 1 or found < 0:
                    break
                first, last, coarse = max(0, found - step + 1), min(2 * reach, found + step - 1), 1
        if best < 0 or least > most_left * own:
            return math.inf
        early, late = 0.0, 0.0
        for k in range(width):
            r = x[start + k] - scale * x[best + k]
            if k < before:
                early += r * r
            else:
                late += r * r
        return (late / after) / max(early / before, 1e-300)

    return echo_novelty


def test_echo_novelty_is_the_loop_it_replaced(rng):
    """_rooms.echo_novelty, its products with the window at every lag from _kernels.window_dots, against the loop that
    summed only the lags tried: the same bits (repeated notes, centres near the ends, digital silence, steps 1-5)."""
    from drumstroke.analysis._rooms import echo_novelty

    replaced = _replaced_echo_novelty()
    note = rng.standard_normal(600) * np.exp(-np.arange(600) / 120.0)
    for _ in range(200):
        x = 1e-3 * rng.standard_normal(6000) * 10.0 ** rng.uniform(-20, 20)
        for at in rng.integers(0, 5400, 4):
            x[at:at + 600] += note * rng.uniform(0.1, 1.0) * np.abs(x).max() * 100
        x[rng.integers(0, 6000):][:int(rng.integers(0, 700))] = 0.0
        before, after, reach = int(rng.integers(1, 300)), int(rng.integers(1, 300)), int(rng.integers(0, 30))
        at = int(rng.integers(-10, 6010))
        centres = rng.integers(-50, 6050, int(rng.integers(0, 6))).astype(np.int64)
        step, most_left = int(rng.integers(1, 6)), float(rng.choice([0.01, 0.5, 1.0, np.inf]))
        got = echo_novelty(x, at, centres, before, after, reach, step, most_left)
        want = replaced(x, at, centres, before, after, reach, step, most_left)
        assert got == want or (np.isnan(got) and np.isnan(want))


def _replaced_bounce_after():
    """_attacks._bounce_after as it stood before: every window's products with the head summed before the scan."""
    import math

    from numba import njit

    from drumstroke.analysis._attacks import _correlations, _energies, _sums

    @njit
    def bounce_after(remainder, template, head, head_energy, low, high, following, pre, shortest, fit, reach, scale,
                     likeness, ratio_low, ratio_high, start_likeness):
        if high <= low:
            return -1, 0.0
        count = high - low
        own = _energies(remainder, low - pre, count, len(head))
        floor = (ratio_low * scale) ** 2 * head_energy
        if not own.max() >= floor:
            return -1, 0.0
        dots = _correlations(remainder, low - pre, head, count)
        for k in range(count):
            if own[k] < floor:
                continue
            like = dots[k] / math.sqrt(max(own[k] * head_energy, 1e-300))
            ratio = dots[k] / (head_energy * scale)
            if like < start_likeness or ratio < ratio_low or ratio > ratio_high:
                continue
            at = low + k
            span = min(max(pre + shortest, min(pre + fit, following - at)), len(template), len(remainder) - at + pre)
            whole, own_energy, energy = _sums(remainder, at - pre, template, span)
            if whole < likeness * math.sqrt(max(own_energy * energy, 1e-300)):
                continue
            best = k
            for m in range(k + 1, min(k + reach + 1, count)):
                if dots[m] / math.sqrt(max(own[m] * head_energy, 1e-300)) > dots[best] / math.sqrt(
                        max(own[best] * head_energy, 1e-300)):
                    best = m
            return low + best, dots[best] / math.sqrt(max(own[best] * head_energy, 1e-300))
        return -1, 0.0

    return bounce_after


def _notes_sound(rng, template, n=6000):
    """Noise (its level from -300 to +300 dB, stretches of digital silence) with copies of ``template`` (scaled, some
    changed a little), as a band the template searches run over; the copies' starts."""
    scale = 10.0 ** rng.uniform(-15, 15)
    x = rng.standard_normal(n) * scale * 10.0 ** rng.uniform(-6, 0)
    starts = np.sort(rng.choice(np.arange(50, n - len(template) - 50), int(rng.integers(0, 6)), replace=False))
    for at in starts:
        note = template * scale * rng.uniform(0.2, 1.0) * rng.choice([1.0, -1.0, 1.0])
        x[at:at + len(template)] += note + rng.standard_normal(len(template)) * scale * rng.choice([0.0, 0.05, 0.5])
    if rng.random() < 0.3:
        x[int(rng.integers(0, n)):][:int(rng.integers(0, 2000))] = 0.0
    return x, starts


def test_bounce_search_is_the_loop_it_replaced(rng):
    """_bounce_after (the head's products summed as its scan reaches them, a chunk at a time) against the loop that
    summed every window first: the same answers to the bit, over bands of notes (copies of the template, some
    changed) and noise at every level, thresholds such that both answers occur."""
    from drumstroke.analysis._attacks import _bounce_after

    bounce_after = _replaced_bounce_after()
    template = rng.standard_normal(500) * np.exp(-np.arange(500) / 80.0)
    found = 0
    for _ in range(400):
        head = template[:int(rng.choice([40, 130, 168]))].copy()
        x, _ = _notes_sound(rng, template)
        pre, reach = 24, int(rng.integers(1, 100))
        low = int(rng.integers(pre, 3000))
        high = int(rng.integers(low - 5, 5400))
        args = (x, template, head, float(head @ head), low, high, int(rng.integers(high, 6000)), pre, 48, 480, reach,
                float(np.abs(x).max() * rng.uniform(0.01, 3.0)), float(rng.choice([0.3, 0.7, 0.8, 0.95])), 0.3, 1.5,
                float(rng.choice([0.5, 0.7])))
        want = bounce_after(*args)
        assert _bounce_after(*args) == want
        found += want[0] >= 0
    assert 20 < found < 380  # both answers tried


def test_layer_fit_is_the_loop_it_replaced(rng):
    """_layer_fit (the five lags' sums side by side in one pass) against the loop it replaced (each lag's
    _likeness in turn): the same lag and correlation to the bit, at every level, near the band's ends and with no
    room (-1)."""
    from numba import njit

    from drumstroke.analysis._attacks import _LAYER_LAG, _layer_fit, _likeness

    @njit
    def replaced(remainder, layer, c, pre, span):
        if span <= pre or c - pre - _LAYER_LAG < 0 or c - pre + _LAYER_LAG + span > len(remainder):
            return 0, -1.0
        best, best_like = 0, -1.0
        for lag in range(-_LAYER_LAG, _LAYER_LAG + 1):
            like = _likeness(remainder, c - pre + lag, layer, span)
            if like > best_like:
                best, best_like = lag, like
        return best, best_like

    layer = rng.standard_normal(600) * np.exp(-np.arange(600) / 100.0)
    for _ in range(500):
        x = rng.standard_normal(3000) * 10.0 ** rng.uniform(-150, 150)
        c = int(rng.integers(0, 3000))
        if rng.random() < 0.5 and 30 <= c < 2400:
            x[c - 24 + int(rng.integers(-2, 3)):][:600] += layer * np.abs(x).max() * rng.uniform(0.1, 10.0)
        if rng.random() < 0.2:
            x[:] = 0.0
        span = int(rng.integers(0, 600))
        assert _layer_fit(x, layer, c, 24, span) == replaced(x, layer, c, 24, span)


def test_frame_peaks_are_numpys(rng):
    """frame_peaks against the numpy it replaced (each frame's largest magnitude), to the bit: zeros, infinities and
    NaNs (numpy's maximum propagates them) in some frames, one sample a frame, the samples past the last frame."""
    from drumstroke.analysis._kernels import frame_peaks

    for _ in range(300):
        frame, count = int(rng.integers(1, 12)), int(rng.integers(1, 200))
        x = rng.standard_normal(count * frame + int(rng.integers(0, frame))) * 10.0 ** rng.uniform(-300, 300)
        for value in (0.0, -0.0, np.inf, -np.inf, np.nan):
            x[rng.random(len(x)) < 0.02] = value
        want = np.abs(x[:count * frame]).reshape(count, frame).max(axis=1)
        np.testing.assert_array_equal(frame_peaks(x, frame, count), want, strict=True)


def test_room_remainders_are_numpys(rng):
    """_ghosts.remainders gives, for each rise, room_ghost_onsets' remainder ``x - scale * y`` and its squares' sums
    ``concatenate((0, cumsum(v ** 2)))`` to the bit."""
    from drumstroke.analysis._ghosts import remainders

    band = rng.standard_normal(5000) * np.geomspace(1.0, 1e-4, 5000)
    starts = rng.integers(0, 4000, 20)
    others = rng.integers(0, 4000, 20)
    scales = rng.uniform(0.1, 3.0, 20)
    v, sums = remainders(band, starts, others, scales, 900, 552)
    for r in range(20):
        want = band[starts[r]:starts[r] + 900] - scales[r] * band[others[r]:others[r] + 900]
        assert np.array_equal(v[r], want)
        assert np.array_equal(sums[r], np.concatenate((np.zeros(1), np.cumsum(want[:552] ** 2))))


def test_room_rise_fits_are_the_numpy_code_they_replaced(rng):
    """_ghosts.fitting_rises gives the rises and starts room_ghost_onsets' numpy code found: each row's correlations
    with the head as np.correlate's (OpenBLAS's ddot for each lag) over the energy's square root (-1 where none), the
    first most, fit or more, the peak from there within the row's bounds, each 20 ms or more after the last found in
    its accent's window, and where the row's mate's next note is taken off (``added``), its note no more than ``past``
    samples after the first found in its accent's window (ghost_mate_notes). To the bit on OpenBLAS's Haswell kernel
    (else the correlations round otherwise, and the comparisons are not held to them)."""
    from threadpoolctl import threadpool_limits

    from drumstroke.analysis._ghosts import fitting_rises, remainders

    if not _haswell_dot():
        pytest.skip("np.correlate's sums are another BLAS's")
    pre, count, span, apart = 24, 289, 528, 960
    with threadpool_limits(1, user_api="blas"):
        for size in (264, 263, 17):
            for _ in range(20):
                rows = int(rng.integers(1, 30))
                head = rng.standard_normal(size) * np.geomspace(1.0, 1e-2, size)
                band = rng.standard_normal(20000) * 1e-3
                starts = rng.integers(0, 15000, rows)
                for at in starts[rng.random(rows) < 0.5]:  # the head in some rows, scaled, over the rest
                    band[at + int(rng.integers(0, 300)):][:size] += rng.uniform(0.05, 1.0) * head
                band[rng.integers(0, 20000, 50)] = 0.0
                v, sums = remainders(band, starts, rng.integers(0, 15000, rows), rng.uniform(0.0, 0.5, rows),
                                     pre + count + span, count + size - 1)
                v[rng.random(rows) < 0.1, :] = 0.0  # rows of no energy
                sums = np.array([np.concatenate(([0.0], np.cumsum(row[:count + size - 1] ** 2))) for row in v])
                accent = np.sort(rng.integers(0, 4, rows))
                at = np.zeros(rows, dtype=np.int64)
                for a in np.unique(accent):
                    at[accent == a] = np.cumsum(rng.integers(240, 1200, np.sum(accent == a)))
                peaks = np.abs(v).max(axis=1)
                lows, highs = peaks * rng.uniform(0.0, 0.5, rows), peaks * rng.uniform(0.3, 1.2, rows)
                unit = head / np.linalg.norm(head)
                fit = float(rng.uniform(0.3, 0.9))
                back = int(rng.integers(0, 100))
                added = rng.random(rows) < 0.5
                past = rng.integers(-1000, 1000, rows)
                got = fitting_rises(v, sums, unit, count, accent, at, apart, pre, span, lows, highs, fit, back, added,
                                    past)
                # the numpy code
                cross = np.array([np.correlate(row[:count + size - 1], unit, "valid") for row in v])
                power = sums[:, size:] - sums[:, :-size]
                like = np.where(power > 0.0, cross / np.sqrt(np.maximum(power, 1e-300)), -1.0)
                best = np.argmax(like, axis=1)
                fits = like[np.arange(rows), best] >= fit
                want, previous, last = ([], []), -1, -np.inf
                for i in np.flatnonzero(fits).tolist():
                    if accent[i] != previous:
                        previous, last, found_at = accent[i], -np.inf, np.inf
                    if at[i] < last + apart:
                        continue
                    if added[i] and at[i] - back + best[i] > found_at + past[i]:
                        continue
                    peak = np.abs(v[i, pre + best[i]:pre + best[i] + span]).max()
                    if not lows[i] <= peak <= highs[i]:
                        continue
                    want[0].append(i), want[1].append(best[i])
                    last = at[i]
                    found_at = min(found_at, at[i] - back + best[i])
                for g, w in zip(got, want):
                    np.testing.assert_array_equal(g, np.array(w, dtype=np.int64))


def test_block_powers_shared_over_two_windows_are_fresh_ones(rng):
    """_ghosts.accent_rises on the energies over each block another search left (its windows over 1 ms, these over
    5 ms: block_powers sums only the blocks not yet there) finds what it finds on fresh ones, at 48 and 22.05 kHz's
    sizes (where the two windows' reach differs by a block)."""
    from drumstroke.analysis._ghosts import accent_rises

    for _ in range(100):
        block, width, wide = ((12, 48, 240), (5, 22, 110))[int(rng.integers(0, 2))]
        size, before, after = 4 * wide, 4 * wide, 4 * wide
        span = int(rng.integers(size + before, 12 * wide))
        c = np.sort(rng.choice(np.arange(50, 30000), int(rng.integers(3, 12)), replace=False)).astype(np.int64)
        band = rng.standard_normal(40000) * np.exp(-np.arange(40000) % 3000 / 600.0)
        which = np.arange(len(c), dtype=np.int64)
        ends = c + rng.integers(1, 4 * span, len(c))
        accents = np.flatnonzero(rng.random(len(which)) < 0.7).astype(np.int64)
        count = rng.integers(1, 4, len(accents)).astype(np.int64)
        mate = rng.integers(0, len(which), int(count.sum())).astype(np.int64)
        shifts = rng.integers(-2, 3, len(mate)).astype(np.int64)
        scales = rng.uniform(0.5, 1.5, len(mate))
        first = np.cumsum(count) - count
        shared = (np.empty((len(mate), (span + after) // block)), np.zeros(len(mate), dtype=np.int64))
        # the mates' next notes taken off (ghost_mate_notes) on some draws, on some mates
        notes = ()
        if rng.random() < 0.5:
            gains = np.where(rng.random(len(mate)) < 0.5, rng.uniform(0.1, 1.0, len(mate)), 0.0)
            notes = (0, gains, rng.integers(size + before, span, len(mate)).astype(np.int64), 24)
        for window in (width, wide):
            args = (band, c, which, ends, accents, first, count, mate, shifts, scales, span, size, before, after,
                    window, block, 1, 1.5)
            fresh = accent_rises(*args, np.empty((len(mate), (span + after) // block)),
                                 np.zeros(len(mate), dtype=np.int64), *notes)
            for g, w in zip(accent_rises(*args, *shared, *notes), fresh):
                np.testing.assert_array_equal(g, w)


def test_layer_mates_shared_only_on_the_same_attacks(rng):
    """_ghosts._partners with ``shared`` gives the search's answer: kept from the last call on the same band (the
    same object) and arguments, searched again on other attacks or another band."""
    from drumstroke.analysis._ghosts import _layer_mates, _partners

    sound = rng.standard_normal(600) * np.geomspace(1.0, 1e-3, 600)
    band = np.zeros(8000)
    for at, scale in ((500, 1.0), (2000, 0.5), (3500, 0.8), (5000, 0.3)):
        band[at:at + 600] += scale * sound
    band += 1e-4 * rng.standard_normal(len(band))
    starts = np.array([500, 2000, 3500, 5000])
    shared = {}
    first = _partners(band, starts, 500, 2, 0.9, shared)
    assert first == _layer_mates(band, starts, 500, 2, 0.9) and len(first[0]) == 3
    assert _partners(band, starts, 500, 2, 0.9, shared) is first
    assert _partners(band, starts[:3], 500, 2, 0.9, shared) == _layer_mates(band, starts[:3], 500, 2, 0.9)
    other = band.copy()
    other[3500:4100] = rng.standard_normal(600)
    assert _partners(other, starts, 500, 2, 0.9, shared) == _layer_mates(other, starts, 500, 2, 0.9)
    assert len(_partners(other, starts, 500, 2, 0.9, shared)[0]) == 2


def test_mates_notes_lags_side_by_side_are_the_loop_they_replaced(rng):
    """_ghosts.mates_notes sums each lag's correlation over the note's first samples with the lags side by side (vector
    lanes); the gains and lags are the loop's that summed one lag at a time (to the bit), on a one-sample roll (whose
    mates' next notes are taken off) and on it with noise added."""
    from drumstroke.analysis._ghosts import _accents_mates, _partners, mates_notes
    from test_recorded_mate_notes import _one_sample_roll

    def plain(band, c, which, ends, accents, first, count, mate, shifts, scales, span, size, before, pre, reach,
              head, likeness):
        gains, lags = np.zeros(len(mate)), np.zeros(len(mate), dtype=np.int64)
        n = pre + size
        for k in range(len(accents)):
            b = which[accents[k]]
            length = min(span, ends[b] - c[b])
            own = 0.0
            for i in range(n):
                own += band[c[b] - pre + i] * band[c[b] - pre + i]
            if not own > 0.0:
                continue
            for q in range(first[k], first[k] + count[k]):
                a = which[mate[q]]
                if a + 1 >= len(c) or a + 1 == b:
                    continue
                start = c[a] + shifts[q]
                nominal = c[a + 1] - start
                if nominal - reach < size + before or nominal + reach + size > length:
                    continue
                best, at = -2.0, -1
                for lag in range(nominal - reach, nominal + reach + 1):
                    dot, energy = 0.0, 0.0
                    for i in range(pre + head):
                        v = band[c[b] + lag - pre + i] - scales[q] * band[start + lag - pre + i]
                        dot -= v * band[c[b] - pre + i]
                        energy += v * v
                    if energy > 0.0 and dot / np.sqrt(energy) > best:
                        best, at = dot / np.sqrt(energy), lag
                if at < 0:
                    continue
                dot, energy = 0.0, 0.0
                for i in range(n):
                    v = band[c[b] + at - pre + i] - scales[q] * band[start + at - pre + i]
                    dot -= v * band[c[b] - pre + i]
                    energy += v * v
                if energy > 0.0 and dot / np.sqrt(energy * own) >= likeness and dot <= own:
                    gains[q], lags[q] = dot / own, at
        return gains, lags

    band, accents, ghosts = _one_sample_roll()
    c = np.array(sorted(accents + ghosts), dtype=np.int64)
    which = np.flatnonzero(np.isin(c, accents))
    pre, size, before, reach, head = 24, 480, 480, 24, 48
    for noise in (0.0, 1e-3):
        noisy = band + noise * rng.standard_normal(len(band))
        mates = _partners(noisy, c[which] - pre, size + pre, 2, 0.99)
        chosen, _, count, mate, shifts, scales = _accents_mates(mates, 3)
        ends = np.full(len(c), len(band), dtype=np.int64)
        args = (noisy, c, which, ends, np.array(chosen, dtype=np.int64), np.cumsum(count) - count, count, mate, shifts,
                scales, round(0.13 * 48000), size, before, pre, reach, head, 0.99)
        got, want = mates_notes(*args), plain(*args)
        assert noise > 0.0 or np.count_nonzero(want[0]) > 0  # the roll's mates' notes are taken off
        for g, w in zip(got, want):
            np.testing.assert_array_equal(g, w)


def test_spare_partners_from_shared_correlations_are_fresh_ones(rng):
    """_ghosts._spare_partners reads the correlations _partners kept (``shared``, the same band and attacks, another
    likeness) and gives the lists the search by that likeness gives (for its rows only), leaving _partners' kept
    answer as it was."""
    from drumstroke.analysis._ghosts import _layer_mates, _mate_likes, _mates_from, _partners, _spare_partners

    sound = rng.standard_normal(600) * np.geomspace(1.0, 1e-3, 600)
    band = np.zeros(8000)
    for at, scale in ((500, 1.0), (2000, 0.5), (3500, 0.8), (5000, 0.3)):
        band[at:at + 600] += scale * sound
    band[3500:4100] += 0.3 * rng.standard_normal(600) * np.geomspace(1.0, 1e-3, 600)  # one attack less like
    band += 1e-4 * rng.standard_normal(len(band))
    starts = np.array([500, 2000, 3500, 5000])
    shared = {}
    first = _partners(band, starts, 500, 2, 0.999, shared)
    rows = np.array([False, False, True, False])
    spare = _spare_partners(band, starts, 500, 2, 0.5, rows, shared)
    assert spare == _mates_from(_mate_likes(band, starts, 500, 2), 2, 0.5, rows)
    assert len(spare[2]) == 3 and len(first[2]) == 0 and spare[0] == []
    assert _partners(band, starts, 500, 2, 0.999, shared) is first == _layer_mates(band, starts, 500, 2, 0.999)


def test_room_ghost_search_with_spare_mates_and_shared_is_a_fresh_one(monkeypatch):
    """FluidR3's snare 40 roll with reverb (seed 0), whose accent of 3.5083 s takes spare mates in the room's ghost
    search: room_ghost_onsets given what ghost_onsets kept (``shared``: layer-mates, their correlations, mates'
    notes, remainders' energies over each block) finds what it finds with nothing kept (a spare-mates list reads
    its own notes and energies)."""
    from _recorded_drums import RATE
    from drumstroke.analysis import _ghosts, find_onsets
    from drumstroke.analysis._ghosts import room_ghost_onsets
    from test_recorded_room_rolls import _roll

    calls, spares = [], []
    spare_partners = _ghosts._spare_partners

    def spy(*args, **kwargs):
        spares.append(1)
        return spare_partners(*args, **kwargs)

    def room(*args, shared=None, **kwargs):
        kept = room_ghost_onsets(*args, shared=shared, **kwargs)
        calls.append((kept, room_ghost_onsets(*args, shared=None, **kwargs), shared))
        return kept

    monkeypatch.setattr(_ghosts, "_spare_partners", spy)
    monkeypatch.setattr(_ghosts, "room_ghost_onsets", room)
    signal, _, _ = _roll(40)
    find_onsets(signal, RATE)
    assert len(calls) == 1 and spares and calls[0][2]
    kept, fresh, _ = calls[0]
    assert len(kept) and np.array_equal(kept, fresh)


def _old_matched_notes(c, ends, nexts, accents, used, span, size, reach):
    """matched_ghost_onsets' notes loop as it was written in Python (``used``: each accent's (mate, shift, scale))."""
    notes, pairs = [], []
    for b, u in zip(accents, used):
        for g in range(b + 1, len(c)):
            off = c[g] - c[b]
            if c[g] >= ends[b] or off > span:
                break
            reaching = [(c[b], c[a] + s, scale, nexts[a] - c[a] - s - off) for a, s, scale in u
                        if nexts[a] - c[a] - s >= off + reach]
            if off >= size and reaching:
                notes.append((g, b, len(pairs), len(reaching)))
                pairs.extend(reaching)
    return notes, pairs


def test_matched_notes_and_mates_are_the_python_loops(rng):
    """_ghosts.ghost_notes_pairs and matched_mates give matched_ghost_onsets' Python loops' notes, pairs and mates
    (a note kept twice: its last amplitude, as the dict kept it)."""
    from drumstroke.analysis._ghosts import ghost_notes_pairs, matched_mates

    for trial in range(20):
        c = np.cumsum(rng.integers(100, 3000, 40))
        nexts = np.append(c[1:], c[-1] + 5000)
        ends = np.minimum(c + rng.integers(0, 9000, 40), nexts[-1])
        accents = np.sort(rng.choice(40, 8, replace=False))
        used = [[(int(a), int(s), float(rng.uniform(0.5, 2))) for a, s in zip(rng.choice(40, k, replace=False),
                                                                           rng.integers(-2, 3, k))]
                for k in rng.integers(0, 4, 8)]
        count = np.array([len(u) for u in used], dtype=np.int64)
        mate = np.array([a for u in used for a, _, _ in u], dtype=np.int64)
        shifts = np.array([s for u in used for _, s, _ in u], dtype=np.int64)
        scales = np.array([x for u in used for _, _, x in u], dtype=float)
        got = ghost_notes_pairs(c, ends, nexts, accents, count, mate, shifts, scales, 6240.000000000001, 480, 300)
        notes, pairs = _old_matched_notes(c, ends, nexts, accents, used, 6240.000000000001, 480, 300)
        assert [got[0].tolist(), got[1].tolist(), got[2].tolist(), got[3].tolist()] == [list(x) for x in zip(*notes)] \
            or (not notes and not len(got[0]))
        assert [got[4].tolist(), got[5].tolist(), got[6].tolist(), got[7].tolist()] == [list(x) for x in zip(*pairs)] \
            or (not pairs and not len(got[4]))
        amplitude = {int(g): float(rng.uniform(0.1, 1)) for g in rng.choice(40, 6)}
        onset_of = {g: int(c[g] + rng.integers(-50, 50)) for g in amplitude}
        noted, gains, onsets = np.zeros(40, bool), np.zeros(40), np.zeros(40, dtype=np.int64)
        for g, gain in amplitude.items():
            noted[g], gains[g], onsets[g] = True, gain, onset_of[g]
        want = [], [], [], []
        for a, s, _ in (m for u in used for m in u):
            g, end, alpha, at = a + 1, nexts[a] - c[a], 0.0, 0
            if g in amplitude:
                alpha, at = amplitude[g], onset_of[g] - c[a] - 24
                end = min(nexts[g] - c[a], at + 2000)
            for column, x in zip(want, (c[a] + s, min(end - s - 24, 90000 - c[a] - s), alpha, at - s)):
                column.append(x)
        got = matched_mates(c, nexts, mate, shifts, scales, noted, gains, onsets, 2000, 24, 90000)
        for column, x in zip(got, want):
            assert column.tolist() == list(x)


def _old_matched_search(band, at, low, length, mates, scales, ends, alphas, starts, long, head, block, width, before,
                        rise, back, pre, fewest, after):
    """_ghosts.matched_search as first written: the mates' count per sample scanned, each placement's np.dot."""
    from drumstroke.analysis._ghosts import rising

    size = max(0, length - low)
    total, reach = np.zeros(size), np.zeros(size, dtype=np.int64)
    for m in range(len(mates)):
        top = max(0, min(size, ends[m] - low))
        total[:top] += band[at + low:at + low + top] - scales[m] * band[mates[m] + low:mates[m] + low + top]
        reach[:top] += 1
        if alphas[m] != 0.0:
            first, last = max(0, starts[m] - low), min(top, starts[m] + len(long) - low)
            if last > first:
                total[first:last] += scales[m] * alphas[m] * long[low + first - starts[m]:low + last - starts[m]]
    short = np.flatnonzero(reach < fewest)
    size = int(short[0]) if len(short) else size
    v = total[:size] / reach[:size]
    n = len(head)
    sums = np.concatenate((np.zeros(1), np.cumsum(v * v)))
    blocks = size // block
    energy = sums[block:blocks * block + 1:block] - sums[:blocks * block:block]
    window = width // block
    e = np.zeros(max(blocks - window + 1, 1))
    acc = 0.0
    for j in range(min(window, blocks)):
        acc += energy[j]
    for j in range(blocks - window + 1):
        e[j] = acc
        if j + window < blocks:
            acc += energy[j + window] - energy[j]
    onsets, fits, peaks, last = [], [], [], -1
    for j in rising(e, before // block, blocks - window + 1, before // block, (before - width) // block, rise):
        if j <= last:
            continue
        last = j + window + width // block - 1
        best, where = -2.0, -1
        for h in range(j * block - back - pre, j * block + width - pre + 1):
            if h < 0 or h + n > size:
                continue
            cross, power = np.dot(v[h:h + n], head), sums[h + n] - sums[h]
            if power > 0.0 and cross / np.sqrt(power) > best:
                best, where = cross / np.sqrt(power), h
        if where >= 0:
            onsets.append(low + where + pre)
            fits.append(best)
            peaks.append(np.abs(v[where + pre:min(size, where + pre + width + after)]).max(initial=0.0))
    return np.array(onsets, dtype=np.int64), np.array(fits), np.array(peaks)


def test_matched_search_is_the_loop_it_replaced(rng):
    """_ghosts.matched_search (its placements' dots in one pass, its window cut at the fewest-th furthest reach) gives
    the search as first written: the same onsets, the fits and peaks to the bit on OpenBLAS's Haswell kernel (np.dot's
    sums), within rounding on another BLAS."""
    from threadpoolctl import threadpool_limits

    from drumstroke.analysis._ghosts import matched_search

    exact = _haswell_dot()
    head = rng.standard_normal(264)
    head /= np.linalg.norm(head)
    sound = rng.standard_normal(3000) * np.geomspace(1.0, 1e-3, 3000)
    with threadpool_limits(1, user_api="blas"):
        for trial in range(12):
            band = 1e-3 * rng.standard_normal(40000)
            for t in rng.integers(2000, 36000, 12):
                band[t:t + 264] += rng.uniform(0.01, 0.1) * head * 10
            mates = rng.integers(9000, 30000, 3)
            ends = rng.integers(3000, 7000, 3) if trial % 3 else np.full(3, 9000)
            alphas = np.where(rng.random(3) < 0.5, rng.uniform(0.1, 1.0, 3), 0.0)
            starts = rng.integers(0, 5000, 3)
            args = (band, 1000, 240, 6240, mates, rng.uniform(0.3, 2.0, 3), ends, alphas, starts, sound, head, 12,
                    48, 480, 10.0 ** 0.6, 24, 24, 2 + trial % 2, 480)
            got, want = matched_search(*args), _old_matched_search(*args)
            assert len(want[0]) and np.array_equal(got[0], want[0])
            if exact:
                np.testing.assert_array_equal(got[1], want[1])
                np.testing.assert_array_equal(got[2], want[2])
            else:
                np.testing.assert_allclose(got[1], want[1], rtol=1e-12)


def test_note_remainders_and_long_sound_are_numpys(rng):
    """_ghosts.note_remainders and long_sound (band read by slices) give their numpy sums to the bit."""
    from drumstroke.analysis._ghosts import long_sound, note_remainders

    band = rng.standard_normal(20000)
    accents, mates = rng.integers(0, 9000, 12), rng.integers(0, 9000, 12)
    scales, lows = rng.uniform(0.3, 2, 12), rng.integers(0, 3000, 12)
    first, count = np.array([0, 3, 4, 9]), np.array([3, 1, 5, 3])
    got = note_remainders(band, accents, mates, scales, first, count, lows[:4], 300)
    for i in range(4):
        want = np.zeros(300)
        for p in range(first[i], first[i] + count[i]):
            want += band[accents[p] + lows[i]:][:300] - scales[p] * band[mates[p] + lows[i]:][:300]
        assert np.array_equal(got[i], want / count[i])
    lengths, weights = rng.integers(0, 3000, 12), rng.uniform(0.5, 5, 12)
    total, counted = long_sound(band, accents, mates, scales, lows, lengths, weights, 2880)
    want, reach = np.zeros(2880), np.zeros(2880, dtype=np.int64)
    for p in range(12):
        top = min(lengths[p], 2880)
        want[:top] += weights[p] * (band[accents[p] + lows[p]:][:top] - scales[p] * band[mates[p] + lows[p]:][:top])
        reach[:top] += 1
    assert np.array_equal(total, want) and np.array_equal(counted, reach)


def test_loud_and_ends_shared_only_on_the_same_attacks(rng):
    """_ghosts._loud_and_ends with ``shared`` gives its reading: kept for the same band (the same object) and attacks,
    read again on other attacks or another band."""
    from drumstroke.analysis._ghosts import _loud_and_ends, _loud_and_next

    band = rng.standard_normal(48000)
    c = np.array([100, 4000, 9000, 20000], dtype=np.int64)
    shared = {}
    first = _loud_and_ends(band, c, 48000, -10.0, shared)
    assert all(np.array_equal(x, y) for x, y in zip(first, _loud_and_next(band, c, 48000, -10.0)))
    assert _loud_and_ends(band, c, 48000, -10.0, shared) is first
    other = _loud_and_ends(band, c[:3], 48000, -10.0, shared)
    assert other is not first and len(other[0]) == 3
    again = _loud_and_ends(band.copy(), c[:3], 48000, -10.0, shared)
    assert again is not other and all(np.array_equal(x, y) for x, y in zip(again, other))


def test_placed_ghosts_is_the_loop_it_replaced(rng):
    """_ghosts.placed_ghosts moves and marks the attacks as onsets._placed_ghosts' numpy loop did (the nearest within
    5 ms, the first of equals, each ghost in turn on the times moved so far) and finds the same new ghosts."""
    from drumstroke.analysis._ghosts import placed_ghosts

    rate = 48000
    for trial in range(30):
        times = np.sort(rng.choice(np.arange(0, 200000, 48), 30, replace=False)).astype(float)
        kinds = rng.integers(0, 3, 30)
        which = np.flatnonzero(rng.random(30) < 0.7)
        ghosts = np.unique(np.concatenate((times[which][rng.integers(0, len(which), 6)] - rng.integers(-300, 300, 6),
                                           rng.uniform(0, 200000, 4).round())))
        want_times, want_kinds, want_new = times.copy(), kinds.copy(), []
        for g in ghosts:
            near = which[np.abs(want_times[which] - g) <= 5e-3 * rate]
            want_new.append(not len(near))
            if len(near):
                k = near[np.argmin(np.abs(want_times[near] - g))]
                if 0.5e-3 * rate < want_times[k] - g <= 2e-3 * rate:
                    want_times[k], want_kinds[k] = g, 3
        got_times, got_kinds = times.copy(), kinds.copy()
        new = placed_ghosts(got_times, got_kinds, which, ghosts, 5e-3 * rate, 0.5e-3 * rate, 2e-3 * rate)
        assert new.tolist() == want_new
        assert np.array_equal(got_times, want_times) and np.array_equal(got_kinds, want_kinds)


def test_lead_clear_shared_only_on_the_same_attacks(rng):
    """onsets._lead_clear with ``shared`` gives _clear's booleans: kept for the same ``d`` (the same object), times and
    level, read again on other times or another ``d``."""
    from drumstroke.analysis.onsets import _clear, _lead_clear

    d = np.abs(rng.standard_normal(48000)) * np.repeat(rng.uniform(0.01, 1.0, 48), 1000)
    times = np.array([1500.0, 9000.0, 20000.0, 33000.0])
    shared = {}
    first = _lead_clear(d, times, 48000, -20.0, shared)
    assert np.array_equal(first, _clear(d, times, 48000, [-20.0])[1][0])
    assert _lead_clear(d, times, 48000, -20.0, shared) is first
    assert np.array_equal(_lead_clear(d, times[:3], 48000, -20.0, shared), _clear(d, times[:3], 48000, [-20.0])[1][0])
    assert np.array_equal(_lead_clear(d, times, 48000, -6.0, shared), _clear(d, times, 48000, [-6.0])[1][0])
    other = d[::-1].copy()
    assert np.array_equal(_lead_clear(other, times, 48000, -6.0, shared), _clear(other, times, 48000, [-6.0])[1][0])
