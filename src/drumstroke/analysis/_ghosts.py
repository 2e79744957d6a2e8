"""Ghost notes under a replayed sample's sound: :func:`.onsets._ghost_notes`' search.

A sample player replays a velocity layer's waveform sample for sample; an accent's own sound is then known from
another note of the same layer, and what is left once it is taken off is the notes that came after it alone.
"""

import numpy as np

from .._jit import jit
from ._kernels import window_peaks
from ._templates import blas_lag_dots


@jit(error_model="numpy")
def remainder_blocks(band, start, mates, scales, valid, blocks, block, window, fewest=2, gains=None, lags=None,
                     lead=0):
    """What is left of ``band`` from ``start`` once each mate (``band`` from ``mates[m]``, times ``scales[m]``) is
    taken off: its energy over ``window`` blocks of ``block`` samples from each block, the least over the mates that
    reach there (block ``j`` under ``valid[m]``), and which mate that is; infinite where fewer than ``fewest`` reach.
    With ``gains`` and ``lags`` (per mate; a gain 0 for none), the mate's next note taken off too: ``band`` from
    ``start`` ``lags[m]`` samples on, times ``gains[m]``, added from ``lead`` samples before that lag
    (:func:`mates_notes`).
    Returns the energies and the mates [shape=(blocks - window + 1,)]."""
    power = np.empty((len(mates), blocks))
    block_powers(band, start, mates, scales, valid, blocks, block, window, power, np.zeros(len(mates), np.int64),
                 gains, lags, lead)
    return least_remainders(power, valid, blocks, window, fewest)


@jit(error_model="numpy")
def block_powers(band, start, mates, scales, valid, blocks, block, window, power, done, gains=None, lags=None,
                 lead=0):
    """:func:`remainder_blocks`' energy of each mate's remainder over each block, ``power[m, j]``, for the blocks it
    reads (under ``valid[m] + window - 1``) from ``done[m]`` on (those before in ``power`` already: the same remainder
    read over other windows, :func:`_shared_powers`); ``done`` moved past them. ``gains``, ``lags``, ``lead``: as
    :func:`remainder_blocks`' (a mate's next note taken off)."""
    for m in range(len(mates)):
        gain, lag = (gains[m], lags[m]) if gains is not None else (0.0, 0)
        need = min(blocks, max(0, valid[m] + window - 1))  # past a mate's reach its power is not read
        for j in range(done[m], need):
            total = 0.0
            for k in range(j * block, (j + 1) * block):
                v = band[start + k] - scales[m] * band[mates[m] + k]
                if gain != 0.0 and k >= lag - lead:
                    v += gain * band[start + k - lag]
                total += v * v
            power[m, j] = total
        done[m] = max(done[m], need)


@jit(error_model="numpy")
def least_remainders(power, valid, blocks, window, fewest):
    """:func:`remainder_blocks`' least energy over ``window`` blocks from each block, and whose, from the mates'
    ``power`` over each block."""
    count = len(valid)
    size = blocks - window + 1
    least = np.full(size, np.inf)
    pick = np.zeros(size, dtype=np.int64)
    reach = np.zeros(size, dtype=np.int64)
    energy = np.empty(size)
    for m in range(count):
        reached = min(size, max(0, valid[m]))
        # each block's window summed from its first block on, as one running sum would, but a window's block at a
        # time over all the blocks: the additions side by side (vector instructions), the same bits
        energy[:reached] = 0.0
        for i in range(window):
            for j in range(reached):
                energy[j] += power[m, j + i]
        for j in range(reached):
            reach[j] += 1
            if energy[j] < least[j]:
                least[j], pick[j] = energy[j], m
    for j in range(size):
        if reach[j] < fewest:
            least[j] = np.inf
    return least, pick


@jit(error_model="numpy")
def rising(e, low, high, back, span, rise):
    """The blocks ``j`` in [``low``, ``high``) where ``e[j]`` is positive and ``rise`` times or more the most of
    ``e`` over the ``span`` blocks from ``j - back``."""
    out = np.empty(max(high - low, 0), dtype=np.int64)
    found = 0
    # the window's most kept by a queue of the blocks that may still be its most (values falling): each block in and
    # out once, instead of ``span`` reads a block
    queue = np.empty(max(high - low + span, 1), dtype=np.int64)
    first, last, top = 0, 0, low - back  # the queue's span [first, last); the next block to take in
    for j in range(low, high):
        while top < j - back + span:
            while last > first and e[queue[last - 1]] <= e[top]:
                last -= 1
            queue[last] = top
            last += 1
            top += 1
        while queue[first] < j - back:
            first += 1
        most = max(0.0, e[queue[first]])
        if e[j] > 0.0 and e[j] >= rise * most:
            out[found] = j
            found += 1
    return out[:found].copy()


@jit(error_model="numpy")
def mates_notes(band, c, which, ends, accents, first, count, mate, shifts, scales, span, size, before, pre, reach,
                head, likeness):
    """Each layer-mate's next note, where it is the accent's own waveform (another note of the one sample, as
    TimGM6mb's snare 38 replays at every velocity), fitted so as to be taken off the mate's remainder beyond it: for
    each of ``accents`` (as :func:`accent_rises`') and each of its mates, what is left once the mate is taken off,
    over ``pre + size`` samples from ``pre`` before the mate's next attack (placed within ``reach`` samples, the best
    lag by correlation over its first ``head`` samples), against the accent's own sound over its first ``pre +
    size`` samples: where they correlate by ``likeness`` or more, negated (the mate's note is taken off with the
    mate), the least-squares gain and the lag (samples after the accent's onset) where the accent's sound, so
    scaled, is added back [each shape=(len(mate),); gain 0 where none]. The mate's next note must lie past its
    first ``size + before`` samples and its fit within the accent's window, be no louder than the mate (its gain
    at most 1: a louder one, a flam's main note after its grace note as mate, would add back what is left under
    the mate many times over) and not be the accent itself."""
    gains = np.zeros(len(mate))
    lags = np.zeros(len(mate), dtype=np.int64)
    if likeness >= 1.0:
        return gains, lags
    n = pre + size
    left = np.empty(2 * reach + pre + head)
    dots, energies = np.empty(2 * reach + 1), np.empty(2 * reach + 1)
    for k in range(len(accents)):
        b = which[accents[k]]
        length = min(span, ends[b] - c[b])
        own = 0.0  # the accent's own sound over its first ``n`` samples (from ``pre`` before it): its energy
        for i in range(n):
            own += band[c[b] - pre + i] * band[c[b] - pre + i]
        if not own > 0.0:
            continue
        for q in range(first[k], first[k] + count[k]):
            a = which[mate[q]]
            if a + 1 >= len(c) or a + 1 == b:  # (a mate just before the accent: its next note is the accent)
                continue
            start = c[a] + shifts[q]
            nominal = c[a + 1] - start
            if nominal - reach < size + before or nominal + reach + size > length:
                continue
            best, at = -2.0, -1
            low = nominal - reach - pre  # what is left over the lags' heads, once
            for i in range(2 * reach + pre + head):
                left[i] = band[c[b] + low + i] - scales[q] * band[start + low + i]
            # the lag, on the note's first samples: each lag's sums in the order of its samples, the lags side by
            # side (vector instructions; the same additions per lag, the same bits)
            dots[:], energies[:] = 0.0, 0.0
            for i in range(pre + head):
                w = band[c[b] - pre + i]
                for j in range(2 * reach + 1):
                    v = left[j + i]
                    dots[j] -= v * w
                    energies[j] += v * v
            for j in range(2 * reach + 1):
                if energies[j] > 0.0 and dots[j] / np.sqrt(energies[j]) > best:
                    best, at = dots[j] / np.sqrt(energies[j]), nominal - reach + j
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


@jit(error_model="numpy")
def accent_rises(band, c, which, ends, accents, first, count, mate, shifts, scales, span, size, before, after, width,
                 block, fewest, rise, power, done, gap=0, gains=None, lags=None, pre=0, white_rise=0.0, quiet=0):
    """:func:`ghost_onsets`' search of each accent's remainders for the blocks where a note rises (:func:`rising`; over
    the 10 ms before a ``gap`` of samples), in one loop: for each of ``accents`` (indices of ``which``, the clear attacks; the onsets ``c``, full-rate samples,
    the search's ``ends``) its mates ``mate[first:first + count]`` (indices of ``which``), each placed ``shifts``
    samples off and scaled by ``scales``. Returns for each rise its accent (index of ``accents``), its block, the
    mate whose remainder is the least there [each shape=(n,)], and each accent's window's length (samples of ``band``
    from its onset) [shape=(len(accents),)]. With ``gap`` (samples), the rises over the 10 ms before a gap so long
    follow, each accent's index plus ``len(accents)``. ``power`` and ``done``: each mate's remainder's energy over
    each block (rows as ``mate``'s; ``(span + after) // block`` columns or more) and how many blocks of it are there,
    :func:`block_powers`' (given again on the same remainders, :func:`_shared_powers`). With ``gains`` and ``lags``
    (:func:`mates_notes`, their ``pre``), a mate's next note of the accent's waveform is taken off its remainder,
    which then reaches on (:func:`mate_reach`). With ``white_rise`` (a ratio, over 0), the rises by so much over the
    10 ms before a ``gap`` follow too, each accent's index plus ``2 len(accents)``, where what the mate picked there
    leaves over the ``quiet`` samples before the gap is white (:func:`_white`'s test, which the caller makes again)."""
    found, blocks, mates = [], [], []
    lengths = np.zeros(len(accents), dtype=np.int64)
    for k in range(len(accents)):
        b = which[accents[k]]
        length = min(span, ends[b] - c[b])
        if length <= size + before:  # no room for a note's rise before the next attack (a drop's later bounces)
            continue
        lengths[k] = length + after
        starts = np.empty(count[k], dtype=np.int64)
        valid = np.empty(count[k], dtype=np.int64)
        for n in range(count[k]):
            a = which[mate[first[k] + n]]
            starts[n] = c[a] + shifts[first[k] + n]
            # a mate's own later notes are not b's: its remainder counts up to its next attack only
            valid[n] = ((c[a + 1] if a + 1 < len(c) else len(band)) - c[a] - width) // block
            if gains is not None and gains[first[k] + n] != 0.0:
                valid[n] = mate_reach(c, len(band), a, b, lags[first[k] + n], width, block)
        rows = slice(first[k], first[k] + count[k])
        if gains is None:
            block_powers(band, c[b], starts, scales[rows], valid, lengths[k] // block, block, width // block,
                         power[rows], done[rows])
        else:
            block_powers(band, c[b], starts, scales[rows], valid, lengths[k] // block, block, width // block,
                         power[rows], done[rows], gains[rows], lags[rows], pre)
        e, pick = least_remainders(power[rows], valid, lengths[k] // block, width // block, fewest)
        # two mates or more at each block: one mate's missed note would be left in its remainder alone (where one
        # reaches, whose the note is says: the accent's, louder in it than in the mate)
        for j in range(len(e)):
            if not np.isfinite(e[j]):
                length = min(length, j * block)
                break
        if length <= size + before:
            continue
        for j in rising(e, (size + before) // block, (length - width) // block, before // block,
                        (before - width) // block, rise):
            found.append(k)
            blocks.append(j)
            mates.append(pick[j])
        if gap > 0:  # and over the 10 ms before a gap, on the same remainders (their accents counted on)
            for j in rising(e, (size + before) // block, (length - width) // block, (before + gap) // block,
                            (before - width) // block, rise):
                found.append(k + len(accents))
                blocks.append(j)
                mates.append(pick[j])
        if white_rise > 0.0:  # and by ``white_rise`` over the 10 ms before a ``gap`` (where what is left before is
            # white noise, the caller's test)
            previous = -2
            for j in rising(e, (size + before) // block, (length - width) // block, (before + gap) // block,
                            (before - width) // block, white_rise):
                # a run of rising blocks is one rise: its first tried alone
                run, previous = j == previous + 1, j
                if run:
                    continue
                # what the mate leaves over the ``quiet`` samples before the gap: its correlation one sample on
                start, scale, low = starts[pick[j]], scales[first[k] + pick[j]], j * block - gap - quiet
                last = band[c[b] + low] - scale * band[start + low]
                energy, lagged = last * last, 0.0
                for i in range(low + 1, low + quiet):
                    v = band[c[b] + i] - scale * band[start + i]
                    energy += v * v
                    lagged += last * v
                    last = v
                if not (energy > 0.0 and abs(lagged) <= 0.6 * energy):
                    continue
                found.append(k + 2 * len(accents))
                blocks.append(j)
                mates.append(pick[j])
    return (np.array(found, dtype=np.int64), np.array(blocks, dtype=np.int64), np.array(mates, dtype=np.int64),
            lengths)


@jit
def mate_reach(c, end, a, b, lag, width, block):
    """How far (blocks) mate ``a``'s remainder reaches once its next note is taken off with the accent ``b``'s own
    sound placed ``lag`` samples on (:func:`mates_notes`): up to the mate's note after that one (``end`` for none),
    and while the accent's sound so placed is its own (up to its next attack, so far on)."""
    later = (c[a + 2] if a + 2 < len(c) else end) - c[a]
    own = (c[b + 1] if b + 1 < len(c) else end) - c[b] + lag
    return (min(later, own) - width) // block


def _kept(shared, name, band, key, make):
    """``make()``, kept in ``shared`` (a dict, or None) as ``name`` and given again for the same ``band`` (the same
    object) and ``key``: what :func:`ghost_onsets` found that :func:`room_ghost_onsets` asks again on the same
    attacks."""
    if shared is not None and name in shared and shared[name][0] is band and shared[name][1] == key:
        return shared[name][2]
    answer = make()
    if shared is not None:
        shared[name] = (band, key, answer)
    return answer


def _partners(band, starts, size, lag, likeness, shared=None):
    """For each attack (``starts``: the samples its ``size``-sample window starts at), its layer-mates: (index,
    shift, scale) of each other attack whose window, shifted within ``lag`` samples, correlates by ``likeness``.
    ``shared``: :func:`_kept`'s (the last answer given again for the same ``band`` and arguments; the correlations
    it was read from kept too, for :func:`_spare_partners`)."""
    return _kept(shared, "mates", band, (starts.tobytes(), size, lag, likeness),
                 lambda: _mates_from(_shared_likes(band, starts, size, lag, shared), lag, likeness))


def _shared_likes(band, starts, size, lag, shared=None):
    """:func:`_mate_likes`, kept in ``shared`` (:func:`_kept`'s) for the same ``band`` and arguments."""
    return _kept(shared, "likes", band, (starts.tobytes(), size, lag), lambda: _mate_likes(band, starts, size, lag))


def _shared_powers(shared, band, c, which, accents, count, mate, shifts, scales, blocks, block, notes=None):
    """The arrays :func:`accent_rises` keeps each mate's remainder's energy over each block in (``power``, ``blocks``
    columns, and ``done``: how many are there), for the accents (indices of ``which``, ``count`` mates each:
    ``mate``, ``shifts``, ``scales``, :func:`_accents_mates`'; ``notes``: the gains and lags of the mates' next notes
    taken off, :func:`mates_notes`', or None). ``shared``: :func:`_kept`'s (the arrays given again, with the blocks
    summed so far, for the same remainders: :func:`ghost_onsets` reads them over 1 ms, :func:`room_ghost_onsets`
    over 5; keyed by each row's accent and mate samples and scale, so other mates, as its spare mates, are new
    arrays)."""
    accent_starts = np.repeat(c[which[np.array(accents, dtype=np.int64)]], count)
    key = (block, blocks, accent_starts.tobytes(), (c[which[mate]] + shifts).tobytes(), scales.tobytes(),
           None if notes is None else (notes[0].tobytes(), notes[1].tobytes()))
    return _kept(shared, "powers", band, key,
                 lambda: (np.empty((len(mate), blocks)), np.zeros(len(mate), dtype=np.int64)))


def _spare_partners(band, starts, size, lag, likeness, rows, shared=None):
    """:func:`_partners` by ``likeness`` of the attacks of ``rows`` (booleans), from the correlations ``shared``
    kept for the same attacks (read again where it holds none)."""
    return _mates_from(_shared_likes(band, starts, size, lag, shared), lag, likeness, rows)


def _mate_likes(band, starts, size, lag):
    """Each attack's window (``starts``, ``size`` samples) against each other's shifted by -``lag`` to ``lag``
    samples: the correlations and the least-squares scales [each shape=(2 lag + 1, n, n): shift, attack, other]."""
    views = windows(band, size)
    own = views[starts]
    norms = np.maximum(np.linalg.norm(own, axis=1), 1e-300)
    likes, scales = [], []
    for shift in range(-lag, lag + 1):
        shifted = views[np.clip(starts + shift, 0, len(views) - 1)]
        energy = np.maximum(np.einsum("ij,ij->i", shifted, shifted), 1e-300)
        cross = own @ shifted.T  # [b, a]: attack b against attack a shifted
        likes.append(cross / (norms[:, None] * np.sqrt(energy)[None, :]))
        scales.append(cross / energy[None, :])
    return np.array(likes), np.array(scales)


def _layer_mates(band, starts, size, lag, likeness):
    """:func:`_partners`' search."""
    return _mates_from(_mate_likes(band, starts, size, lag), lag, likeness)


def _mates_from(likes, lag, likeness, rows=None):
    """:func:`_partners`' lists from :func:`_mate_likes`' correlations: each attack's others by ``likeness``, the
    best first (only those of ``rows``, booleans, where given: the others' lists empty)."""
    like_all, scale_all = likes
    mates = [[] for _ in range(like_all.shape[1])]
    for i, shift in enumerate(range(-lag, lag + 1)):
        like = like_all[i]
        bs, as_ = np.nonzero((like >= likeness) if rows is None else (like >= likeness) & rows[:, None])
        bs, as_ = bs[bs != as_], as_[bs != as_]
        for b, found, a, scale in zip(bs.tolist(), like[bs, as_].tolist(), as_.tolist(),
                                      scale_all[i][bs, as_].tolist()):
            mates[b].append((found, a, shift, scale))
    return [[m[1:] for m in sorted(found, reverse=True)] for found in mates]


def windows(x, size):
    """``sliding_window_view(x, size)`` (the same strides), without its checks' time where ``x`` is contiguous."""
    if not x.flags.c_contiguous:
        return np.lib.stride_tricks.sliding_window_view(x, size)
    return np.ndarray((len(x) - size + 1, size), dtype=x.dtype, buffer=x, strides=(x.itemsize, x.itemsize))


def _own(x, band, mate, scale, t, size, own_db):
    """Whether ``x``'s sound over ``size`` samples from ``t`` is ``own_db`` or more louder than the mate's (``band``
    from ``mate``, times ``scale``) there: a note left in their difference is ``x``'s, not the mate's negated."""
    mine = np.dot(x[t:t + size], x[t:t + size])
    theirs = scale * scale * np.dot(band[mate + t:mate + t + size], band[mate + t:mate + t + size])
    return mine >= theirs * 10.0 ** (own_db / 10.0)


def _mates_notes(shared, mates, *args):
    """:func:`mates_notes` (``args``), its answer kept in ``shared`` (a dict, or None) for the same layer-mates
    (``mates``: :func:`_partners`' list, the same object) and likeness, as :func:`_partners` keeps its own."""
    if shared is not None and shared.get("notes_of") is mates and shared.get("notes_likeness") == args[-1]:
        return shared["notes"]
    notes = mates_notes(*args)
    if shared is not None:
        shared.update(notes_of=mates, notes_likeness=args[-1], notes=notes)
    return notes


def _own_notes_off(v, band, c, b, end, pre, size, likeness, reach, head):
    """``v`` (what is left from the accent ``b``'s onset ``c[b]``) less each later attack's sound before ``end``
    (samples from the onset) that is the accent's own waveform: its first ``pre + size`` samples correlating with
    the accent's by ``likeness`` or more (placed within ``reach`` samples by its first ``head``), taken off with the
    accent's own sound there scaled by least squares (as :func:`mates_notes`)."""
    own = band[c[b] - pre:c[b] + size]
    energy = np.dot(own, own)
    out = v
    for a in range(b + 1, len(c)):
        nominal = c[a] - c[b]
        if nominal + reach + size > end or not energy > 0.0:
            break
        if nominal - reach - pre < 0:
            continue
        low = nominal - reach - pre
        dots = np.correlate(out[low:low + 2 * reach + pre + head], own[:pre + head], "valid")
        sums = np.concatenate(([0.0], np.cumsum(out[low:low + 2 * reach + pre + head] ** 2)))
        norms = np.sqrt(np.maximum(sums[pre + head:] - sums[:-(pre + head)], 1e-300))
        at = nominal - reach + int(np.argmax(dots / norms))
        seg = out[at - pre:at + size]
        dot = np.dot(seg, own)
        if dot / np.sqrt(max(np.dot(seg, seg) * energy, 1e-300)) >= likeness:
            out = out.copy()
            out[at - pre:] -= dot / energy * band[c[b] - pre:c[b] - pre + len(out) - at + pre]
    return out


def _still_rising(v, t, width, before, block, rise):
    """Whether ``v``'s energy over ``width`` samples from ``t`` is ``rise`` times or more its most over the same
    windows every ``block`` samples from ``before`` earlier up to ``width`` before (:func:`rising`'s test)."""
    power = np.concatenate(([0.0], np.cumsum(v[t - before:t + width] ** 2)))
    e = power[width:] - power[:-width]
    most = max(0.0, e[:before - width:block].max()) if before > width else 0.0
    return e[before] > 0.0 and e[before] >= rise * most


def _own_of(x, theirs, t, size, own_db):
    """:func:`_own` with the mate's sound given (``theirs``, as ``x``: the mate scaled, its next note taken off)."""
    mine = np.dot(x[t:t + size], x[t:t + size])
    return mine >= np.dot(theirs[t:t + size], theirs[t:t + size]) * 10.0 ** (own_db / 10.0)


def _loud_and_ends(band, c, rate, quiet_db, shared=None):
    """Each attack's peak over the 5 ms from it (``c``, full-rate samples; the last 5 ms of ``band`` from past its
    end; from before its start, as a negative index reads the windows, counted from the end), and where its sound is
    no longer one attack's: the next attack within ``quiet_db`` dB of it (``len(band)`` for none). ``shared``:
    :func:`_kept`'s."""
    return _kept(shared, "loud", band, (c.tobytes(), rate, quiet_db), lambda: _loud_and_next(band, c, rate, quiet_db))


def _loud_and_next(band, c, rate, quiet_db):
    """:func:`_loud_and_ends`' answer."""
    windows_count = len(band) - round(5e-3 * rate) + 1
    lows = np.minimum(c, windows_count - 1)
    lows = np.where(lows < 0, lows + windows_count, lows)
    loud = window_peaks(band, lows, lows + round(5e-3 * rate))
    later = (loud[None, :] >= loud[:, None] * 10.0 ** (quiet_db / 20.0)) & np.triu(np.ones((len(c), len(c)), bool), 1)
    return loud, np.where(later.any(axis=1), c[np.argmax(later, axis=1)], len(band))


def _accents_mates(mates, mates_used):
    """The accents (indices into ``mates``, :func:`_partners`' lists) with two layer-mates or more, each one's first
    ``mates_used`` mates, and those flat for the compiled search: how many each, the mates' indices, shifts
    (samples) and scales."""
    accents = [i for i in range(len(mates)) if len(mates[i]) >= 2]
    used = [mates[i][:mates_used] for i in accents]
    count = np.array([len(u) for u in used], dtype=np.int64)
    mate = np.array([a for u in used for a, _, _ in u], dtype=np.int64)
    shifts = np.array([shift for u in used for _, shift, _ in u], dtype=np.int64)
    scales = np.array([scale for u in used for _, _, scale in u], dtype=float)
    return accents, used, count, mate, shifts, scales


def ghost_onsets(band, times, clear, rate, *, likeness, rise_db, least, own_db=120.0, own_everywhere=False,
                 skip=10e-3, span=0.13, quiet_db=-10.0, below_db=-30.0, quieter_db=-6.0, mates_used=3, noise_start=0.0,
                 rise_gap=0.0, mate_notes=1.0, white_rise_db=120.0, shared=None):
    """Onsets (full-rate samples) of notes within ``span`` s after a ``clear`` attack at ``times`` (full-rate samples),
    found in what is left of ``band`` once that attack's own sound is taken off, predicted by its layer-mates.

    A layer-mate is another clear attack whose first ``skip`` s (from 0.5 ms before it) correlate by ``likeness``
    within 2 samples; each of up to ``mates_used`` is scaled by least squares there and taken off. Of their
    remainders the quietest over each 1 ms counts (a mate's own later notes are left in its remainder only), each up
    to its mate's next attack, and only where two of them reach; the search ends at the next attack within
    ``quiet_db`` of this one. Where one mate alone reaches (the others' next notes came first: a ghost note late
    after its accent), its remainder counts where the note is the accent's own, not the mate's left negated: its
    sound over the 11 ms from the rise ``own_db`` or more louder in the accent than in the mate scaled (120: never,
    as two mates were needed before); with ``own_everywhere``, wherever it is (in a room: what is left of the
    returns of the notes before the accent and before its mate is in both alike). A note is where that energy over 1 ms (read every 0.25 ms) rises ``rise_db``
    over its most over the 10 ms before (from ``skip`` s after the attack on), its remainder's peak over the next
    11 ms ``least`` or more, within ``below_db`` of the attack's peak and ``quieter_db`` or more under it; its onset
    is the first sample there whose magnitude passes 1 % of that peak and four times the remainder's RMS over the
    5 ms before (one note in 20 ms). With ``rise_gap`` (s), where what is left over the 5 ms before a rise is white
    noise (:func:`_white`), a rise over the 10 ms before a gap so long counts too, its onset sought from the gap's
    start; with ``noise_start`` (s), where that noise, not 1 % of the peak, sets the onset's level and it is white, the
    onset is where the power changes (:func:`noise_change`) up to so long before the rise, returned beside the
    onsets (each as found, or so moved) [each shape=(n,)]. With ``white_rise_db`` under ``rise_db``, a rise so much
    over the 10 ms before that gap counts too where what is left over the 5 ms before is white and the note is the
    accent's own (as ``own_db`` asks where one mate reaches: a mate's missed note left negated rises so). With
    ``mate_notes`` under 1, a mate's next note that is the accent's own waveform by so much (:func:`mates_notes`:
    placed within 0.5 ms by its first 2 ms) is taken off its remainder, which reaches on up to the mate's note after
    it (:func:`mate_reach`); a rise so read past a note found in the accent's window that lag on is not sought (that
    note, in the accent's sound added back, is left there). ``shared`` (a dict, or None): what :func:`room_ghost_onsets` asks again on the same attacks kept there
    (:func:`_kept`: the attacks' peaks and ends, their layer-mates, the remainders' energies over each block; and
    :func:`_mates_notes`).
    """
    pre, size, lag = round(0.5e-3 * rate), round(skip * rate), 2
    width, before, after = round(1e-3 * rate), round(10e-3 * rate), round(10e-3 * rate)
    times = np.asarray(times, dtype=float)
    c = np.rint(times).astype(np.int64)
    starts = c - pre
    ok = np.asarray(clear, dtype=bool) & (starts >= lag) & (starts + round(span * rate) + lag + after < len(band))
    which = np.flatnonzero(ok)
    if len(which) < 3:
        return (np.empty(0), np.empty(0)) if noise_start > 0.0 else np.empty(0)
    loud, ends = _loud_and_ends(band, c, rate, quiet_db, shared)
    mates = _partners(band, starts[which], size + pre, lag, likeness, shared)
    rise, found = 10.0 ** (rise_db / 10.0), []
    # energy over 0.25-ms blocks, over 1 ms from each block (its onset sought at full rate after)
    block = max(1, width // 4)
    accents, _, count, mate, shifts, scales_all = _accents_mates(mates, mates_used)
    first = np.cumsum(count) - count
    notes = None
    if mate_notes < 1.0:  # the mates' next notes of the accent's waveform, taken off them
        notes = _mates_notes(shared, mates, band, c, which, ends, np.array(accents, dtype=np.int64), first, count, mate,
                             shifts, scales_all, round(span * rate), size, before, pre, round(0.5e-3 * rate),
                             round(1e-3 * rate), mate_notes)
    power, done = _shared_powers(shared, band, c, which, accents, count, mate, shifts, scales_all,
                                 (round(span * rate) + after) // block, block, notes)
    args = (band, c, which, ends, np.array(accents, dtype=np.int64), first, count, mate, shifts,
            scales_all, round(span * rate), size, before, after, width, block, 1 if own_db < 120.0 else 2, rise,
            power, done)
    gap = round(rise_gap * rate)
    white = 10.0 ** (white_rise_db / 10.0) if white_rise_db < rise_db else 0.0
    if notes is not None:
        gains, lags = notes
        which_accent, rises, picks, lengths = accent_rises(*args, gap, gains, lags, pre, white, round(5e-3 * rate))
    else:
        gains, lags = np.zeros(len(mate)), np.zeros(len(mate), dtype=np.int64)
        which_accent, rises, picks, lengths = accent_rises(*args, gap, None, None, 0, white, round(5e-3 * rate))
    # each rise's kind: 0 by ``rise_db``, 1 over the 10 ms before a gap, 2 by ``white_rise_db`` (both kept below
    # where what is left before them is white noise)
    kind = which_accent // max(len(accents), 1)
    gapped = kind == 1
    if gap > 0 or white > 0.0:
        which_accent = which_accent - kind * len(accents)
        order = np.lexsort((kind, rises, which_accent))
        which_accent, rises, picks, kind = which_accent[order], rises[order], picks[order], kind[order]
        gapped = kind == 1
    quiet, reach, apart = round(5e-3 * rate), round(0.5e-3 * rate), round(20e-3 * rate)
    starts_at = {}  # the onsets moved to where white noise's power changes (noise_start)
    # each mate's place and reach, for all the accents at once (a mate's own later notes are not the accent's: its
    # remainder counts up to its next attack only)
    mate_at, after_mate = c[which[mate]] + shifts, which[mate] + 1
    reach_all = (np.where(after_mate < len(c), c[np.minimum(after_mate, len(c) - 1)], len(band)) - c[which[mate]]
                 - width) // block
    k = -1
    # the rises in their accents' order (accent_rises' order, or sorted so above)
    for t, m, over_gap, accent, by_white in zip((rises * block).tolist(), picks.tolist(), gapped.tolist(),
                                                which_accent.tolist(), (kind == 2).tolist()):
        if accent != k:  # the next accent's mates
            k = accent
            b = which[accents[k]]
            x = band[c[b]:c[b] + lengths[k]]
            q = first[k]  # the accent's mates' first index in the flat arrays
            starts_m, scales = mate_at[q:q + count[k]], scales_all[q:q + count[k]]
            reaches = reach_all[q:q + count[k]].tolist()
            added = (gains[q:q + count[k]] != 0.0).tolist()  # the mates whose next note is taken off (mate_notes)
            for n_m in range(count[k]):
                if added[n_m]:
                    reaches[n_m] = mate_reach.py_func(c, len(band), which[mate[q + n_m]], b, int(lags[q + n_m]),
                                                      width, block)
            # the bounds of a note's peak, under the accent's (once an accent: the same values at each rise)
            lowest, highest = max(least, loud[b] * 10.0 ** (below_db / 20.0)), loud[b] * 10.0 ** (quieter_db / 20.0)
            found_at = np.inf  # the first note found in the accent's window (samples from its onset)
            cleared = {}  # what is left with the accent's own later notes taken off: for each mate and notes so taken
            last = -np.inf
        if t < last + apart:
            continue
        low = t - gap if over_gap or by_white else t  # the note's lead-in may be in the gap
        # the remainder only where it is read, from the 5 ms before the lead-in to the end of the peak's window
        # (elementwise: the same samples as the whole window's remainder, not made anew at each rise)
        lo, hi = low - quiet, min(t + width + after, len(x))
        v = x[lo:hi] - scales[m] * band[starts_m[m] + lo:starts_m[m] + hi]
        if (over_gap or by_white) and not _white(v[:quiet]):
            continue
        if added[m]:  # the mate's next note taken off, from the start of its fit on
            lag = int(lags[q + m])
            if t + width > found_at + lag - pre:  # a note found before is added back here
                continue
            whole = x - scales[m] * band[starts_m[m]:starts_m[m] + len(x)]  # (read over the whole window)
            whole[lag - pre:] += gains[q + m] * band[c[b] - pre:c[b] - pre + len(x) - lag + pre]
            v = whole[lo:hi]
            peak = np.abs(v[t - lo:]).max()  # (as below: the cheaper test first)
            if not lowest <= peak <= highest:
                continue
            # the accent's own later notes of its waveform taken off too: a rise in their sound is none
            later = int(np.searchsorted(c, c[b] + t - before - size - reach, side="right")) - b - 1
            if (m, later) not in cleared:  # (``whole`` is the mate's, whatever the rise)
                cleared[m, later] = _own_notes_off(whole, band, c, b, t - before, pre, size, mate_notes, reach,
                                                   round(1e-3 * rate))
            if not _still_rising(cleared[m, later], t, width, before, block, white if by_white else rise):
                continue
        peak = np.abs(v[t - lo:]).max()
        if not lowest <= peak <= highest:  # (the cheaper test first: both only refuse)
            continue
        # past where two mates reach over its 1 ms, the note must be the accent's own
        # (a rise by ``white_rise_db`` too: a mate's own note missed, left negated in its remainder alone, rises so)
        alone = own_everywhere or by_white or sum((t + width) // block < reach_m for reach_m in reaches) < 2
        if alone and not (_own_of(x, x - whole, t, width + after, own_db) if added[m]
                          else _own(x, band, starts_m[m], scales[m], t, width + after, own_db)):
            continue
        noise = np.sqrt(np.mean(v[:quiet] ** 2))
        above = np.flatnonzero(np.abs(v[quiet:]) >= max(0.01 * peak, 4.0 * noise))
        if not len(above):
            continue
        onset = low + above[0]
        if noise_start > 0.0 and 4.0 * noise > 0.01 * peak and _white(v[:quiet]):
            starts_at[c[b] + onset] = c[b] + lo + noise_change(v, 0, low - round(noise_start * rate) - lo,
                                                               onset - lo)
        found.append(c[b] + onset)
        found_at = min(found_at, onset)
        last = t
    found = np.unique(np.asarray(found, dtype=float))
    if noise_start > 0.0:
        return found, np.array([starts_at.get(int(g), g) for g in found.tolist()], dtype=float)
    return found


def noise_change(v, low, first, onset):
    """Where ``v``'s power changes, between ``first`` and ``onset`` (samples): the split of ``v[low:onset + 1]`` into
    two stretches, the first ``first - low`` samples or more long and the second four or more, of the most likelihood
    as two white noises (the least ``n1 log p1 + n2 log p2``, ``p`` each stretch's mean power). A note's start under
    white noise, read as the first sample four times its RMS, is late by the note's lead-in under that level."""
    energy = np.concatenate(([0.0], np.cumsum(v[low:onset + 1] ** 2)))
    n = len(energy) - 1
    k = np.arange(max(1, first - low), n - 3)
    if not len(k):
        return onset
    p1 = np.maximum(energy[k] / k, 1e-300)
    p2 = np.maximum((energy[n] - energy[k]) / (n - k), 1e-300)
    cost = k * np.log(p1) + (n - k) * np.log(p2)
    return low + int(k[np.argmin(cost)])


def _white(v, most=0.6):
    """Whether ``v`` looks like white noise: its correlation with itself one sample on within ``most`` of 0 (white
    noise over 5 ms at 48 kHz: 0 +- 0.065; a drum's or a room's sound left over, its low modes: near 1)."""
    energy = np.dot(v, v)
    return energy > 0.0 and abs(np.dot(v[:-1], v[1:])) <= most * energy



def room_ghost_onsets(band, times, clear, rate, head, *, likeness, rise_db, least, fit, skip=10e-3, span=0.13,
                      quiet_db=-10.0, below_db=-30.0, quieter_db=-6.0, mates_used=3, reach=1e-3, energy=5e-3,
                      mate_notes=1.0, spare_likeness=1.0, shared=None):
    """Onsets (full-rate samples) of ghost notes after a ``clear`` attack at ``times`` (full-rate samples) in a
    reverberant recording, each where what is left once a layer-mate is taken off (as :func:`ghost_onsets`: up to
    ``mates_used`` mates, the quietest remainder over each ``energy`` s; here where one mate or more reaches, and with
    no test of whose the note is) has its energy over ``energy`` s (read every 0.25 ms) rise ``rise_db`` over its
    most over the 10 ms before, and a quiet note's own attack fits that remainder there: ``head`` (``band`` from
    0.5 ms before a quiet clear attack, as long as the fit) correlates by ``fit`` or more, its scale positive, with
    the remainder placed the best from ``reach`` s before the rise's block to ``energy`` s after it. The earlier
    notes' returns are a smoothed sound that no attack's waveform fits (on the corpus's recordings step 4 finds
    reverberant, seeds 0-4: 0.77 at most), a ghost note's is its layer's (0.82 or more on the notes missed before).
    Over 5 ms a ghost note's first milliseconds rise 7-10 dB where over 1 ms they rise under 4 dB (FluidR3's snare
    38 roll with reverb, seed 0: its notes of 1.1021 and 3.2034 s). Its peak over the 11 ms from it as
    :func:`ghost_onsets` asks; its onset where the head's starts (one in 20 ms). An accent (a clear attack within
    10 dB of the loudest, no attack within ``quiet_db`` of it for 0.2 s after it: a roll's accents, 0.23-0.47 s
    apart in the corpus, not a drop's bounces, 0.16 s or less) with fewer than two layer-mates takes as its mates
    the attacks that correlate with it by ``spare_likeness`` (under ``likeness``: a velocity between two layers'
    mixes, nearest in level; 1: none). ``mate_notes``: as :func:`ghost_onsets`' (a mate's next note of the
    accent's waveform taken off). ``shared``: as :func:`ghost_onsets`' (what it found, given again on the same
    attacks and mates; a list with spare mates is another list, its mates' notes and energies read anew)."""
    pre, window, lag = round(0.5e-3 * rate), round(skip * rate), 2
    width, before, after = round(1e-3 * rate), round(10e-3 * rate), round(10e-3 * rate)
    n, back, wide = len(head), round(reach * rate), round(energy * rate)
    times = np.asarray(times, dtype=float)
    c = np.rint(times).astype(np.int64)
    starts = c - pre
    ok = np.asarray(clear, dtype=bool) & (starts >= lag) & (starts + round(span * rate) + lag + after < len(band))
    which = np.flatnonzero(ok)
    norm = np.linalg.norm(head)
    if len(which) < 3 or not norm > 0.0:
        return np.empty(0)
    loud, ends = _loud_and_ends(band, c, rate, quiet_db, shared)
    mates = _partners(band, starts[which], window + pre, lag, likeness, shared)
    # an accent (within 10 dB of the loudest clear attack, none as loud for 0.2 s after it) with no layer-mates: the
    # attacks nearest it in level
    lacking = (np.array([len(m) < 2 for m in mates]) & (loud[which] >= loud[which].max() * 10.0 ** (-10.0 / 20.0))
               & (ends[which] - c[which] >= round(0.2 * rate)) if spare_likeness < likeness
               else np.zeros(0, dtype=bool))
    if np.any(lacking):
        spare = _spare_partners(band, starts[which], window + pre, lag, spare_likeness, lacking, shared)
        mates = [spare[i] if lacking[i] else m for i, m in enumerate(mates)]
    block = max(1, width // 4)
    accents, _, count, mate, shifts, scales = _accents_mates(mates, mates_used)
    args = (band, c, which, ends, np.array(accents, dtype=np.int64), np.cumsum(count) - count, count, mate, shifts,
            scales, round(span * rate), window, before, after, wide, block, 1, 10.0 ** (rise_db / 10.0))
    notes = None
    if mate_notes < 1.0:  # the mates' next notes of the accent's waveform, taken off them
        notes = _mates_notes(shared, mates, *args[:11], window, before, pre, round(0.5e-3 * rate),
                             round(1e-3 * rate), mate_notes)
    power, done = _shared_powers(shared, band, c, which, accents, count, mate, shifts, scales,
                                 (round(span * rate) + after) // block, block, notes)
    if notes is not None:
        which_accent, rises, picks, lengths = accent_rises(*args, power, done, 0, notes[0], notes[1], pre)
    else:
        which_accent, rises, picks, lengths = accent_rises(*args, power, done)
    unit = head / norm
    # the rises tried: a rise's window spans ``energy`` s, so the rises in the window of one tried are its own
    chosen = spaced(which_accent, rises * block, wide, back + pre,
                    lengths[which_accent] - max(wide - pre + n, wide + width + after))
    if not len(chosen):
        return np.empty(0)
    k_of, t_of = which_accent[chosen], rises[chosen] * block
    # each rise's remainder from ``reach`` before its block (less the head's lead) to where the last start's head
    # ends, and its energy summed from there (compiled, elementwise as numpy's difference and cumulative sum)
    b_of = which[np.array(accents, dtype=np.int64)[k_of]]  # each rise's accent (an index of c)
    mate_of = (np.cumsum(count) - count)[k_of] + picks[chosen]
    low = t_of - back - pre
    size = back + pre + max(wide - pre + n, wide + width + after)
    if notes is None:
        v, sums = remainders(band, c[b_of] + low, c[which[mate[mate_of]]] + shifts[mate_of] + low,
                             scales[mate_of], size, back + wide + n)
        added, lags = np.zeros(len(chosen), dtype=np.bool_), np.zeros(len(chosen), dtype=np.int64)
    else:  # with each mate's next note taken off from ``pre`` before its lag (:func:`mates_notes`)
        gains, lags = notes[0][mate_of], notes[1][mate_of]
        v, sums = remainders(band, c[b_of] + low, c[which[mate[mate_of]]] + shifts[mate_of] + low,
                             scales[mate_of], size, back + wide + n, gains, c[b_of] + low - lags, lags - pre - low)
        added = gains != 0.0
    # the head's correlation with each remainder from ``reach`` before the block to ``energy`` after, the best start's
    # peak between the accent's bounds (compiled: a rise within 20 ms after a note found in its accent's window is
    # not correlated; one whose mate's next note is taken off, past a note found in the accent's window that lag on
    # less 1 ms, is not sought: that note is added back there with the accent's sound)
    rows, best = fitting_rises(v, sums, unit, back + wide + 1, k_of, t_of, round(20e-3 * rate), pre, width + after,
                               np.maximum(least, loud[b_of] * 10.0 ** (below_db / 20.0)),
                               loud[b_of] * 10.0 ** (quieter_db / 20.0), fit, back, added, lags - pre - width)
    return np.unique((c[b_of[rows]] + t_of[rows] - back + best).astype(float))


@jit(error_model="numpy")
def remainders(band, starts, others, scales, size, summed, gains=None, adds=None, froms=None):
    """``band`` over ``size`` samples from each of ``starts`` less ``scales`` times it from ``others`` [shape=(n,
    size)], as numpy's ``x - scale * y``, and each row's squares summed cumulatively over its first ``summed``
    samples from 0 (as ``concatenate((0, cumsum(v ** 2)))``) [shape=(n, summed + 1)]. With ``gains``, ``band``
    from ``adds`` times it added from the row's sample ``froms`` on (a mate's next note taken off)."""
    v = np.empty((len(starts), size))
    sums = np.empty((len(starts), summed + 1))
    for r in range(len(starts)):
        for i in range(size):
            v[r, i] = band[starts[r] + i] - scales[r] * band[others[r] + i]
            if gains is not None and gains[r] != 0.0 and i >= froms[r]:
                v[r, i] += gains[r] * band[adds[r] + i]
        total = 0.0
        sums[r, 0] = 0.0
        for i in range(summed):
            total += v[r, i] * v[r, i]
            sums[r, i + 1] = total
    return v, sums


@jit(error_model="numpy")
def fitting_rises(v, sums, unit, count, accent, at, apart, pre, span, lows, highs, fit, back, added, past):
    """:func:`room_ghost_onsets`' test of each rise (rows of ``v``, its remainders from ``pre`` before ``count``
    starts; ``sums``, their squares' running sums; ``accent`` and ``at``, its accent and its block's sample, in
    order): the head ``unit``'s correlation with each start's window (``np.correlate``'s sums, :func:`._templates.
    blas_lag_dots`, over the sums' energy: -1 where none), at the best (the first most) ``fit`` or more, and the
    remainder's peak over ``span`` samples from there within ``[lows, highs]`` of the row; each rise tried ``apart``
    or more after the last one found in its accent's window (its correlations not summed otherwise); where ``added``
    (the row's mate's next note taken off), its note (``at - back`` plus the best start) no more than ``past``
    samples after the first found in its accent's window. Returns the rises found and their best starts (from the
    first) [each shape=(n,)]."""
    n = len(unit)
    cross = np.empty(count)
    rows = np.empty(len(at), dtype=np.int64)
    best = np.empty(len(at), dtype=np.int64)
    found, previous, last = 0, -1, -1  # last: the row of the last found in this accent's window (-1: none yet)
    first = np.inf  # the first note found in the accent's window (samples from its onset)
    for i in range(len(at)):
        if accent[i] != previous:
            previous, last, first = accent[i], -1, np.inf
        if last >= 0 and at[i] < at[last] + apart:
            continue
        blas_lag_dots(v[i], 0, count, unit, n, cross)
        start, most = 0, -np.inf
        for s in range(count):
            power = sums[i, s + n] - sums[i, s]
            like = cross[s] / np.sqrt(max(power, 1e-300)) if power > 0.0 else -1.0
            if like > most:
                start, most = s, like
        if not most >= fit:
            continue
        if added[i] and at[i] - back + start > first + past[i]:
            continue
        peak = 0.0
        for j in range(pre + start, pre + start + span):
            peak = max(peak, abs(v[i, j]))
        if not lows[i] <= peak <= highs[i]:
            continue
        rows[found], best[found] = i, start
        found += 1
        last = i
        first = min(first, at[i] - back + start)
    return rows[:found].copy(), best[:found].copy()


@jit
def spaced(accent, at, apart, first, end):
    """The rises tried (indices of ``at``, samples from each one's accent ``accent``, in order): each from
    ``first`` to ``end`` (per rise), ``apart`` or more after the one tried before in the same accent's window."""
    out = np.empty(len(at), dtype=np.int64)
    count, previous, tried = 0, -1, -np.inf
    for i in range(len(at)):
        if accent[i] != previous:
            previous, tried = accent[i], -np.inf
        if at[i] < first or at[i] > end[i] or at[i] < tried + apart:
            continue
        tried = at[i]
        out[count] = i
        count += 1
    return out[:count].copy()



@jit(error_model="numpy")
def matched_search(band, at, low, length, mates, scales, ends, alphas, starts, long, head, block, width, before,
                   rise, back, pre, fewest, after, primary=-1):
    """:func:`matched_ghost_onsets`' search of one accent's window (``band`` from ``at``, samples ``low`` to
    ``length`` after it): what is left once each mate (``band`` from ``mates[m]``, times ``scales[m]``, less its own
    ghost note found: ``alphas[m]`` times ``long`` from ``starts[m]`` samples after it, where ``alphas[m]`` is not 0)
    is taken off, the mean of the mates reaching each sample (up to ``ends[m]``, ``fewest`` or more; the window cut
    at the first sample with fewer); where its energy over ``width`` samples (every ``block``) rises ``rise`` times
    over its most over the ``before`` samples before, the head's best fit (normalized correlation) with it placed
    from ``back`` samples before that block to ``width`` after. Returns each rise's best onset (samples from ``at``,
    the head's start plus ``pre``), fit and the mean's peak magnitude over ``width + after`` samples from that onset
    [each shape=(n,)]. With ``primary`` (0 or more; -1: none), the mates past the first ``primary`` count
    only from where fewer than ``fewest`` of the first reach (the window's cut without them), each to its own
    ``ends``."""
    size = max(0, length - low)
    total = np.zeros(size)
    reach = np.zeros(size, dtype=np.int64)
    # with ``primary`` (0 or more), the mates past the first ``primary`` (spares) count only from where fewer than
    # ``fewest`` of the first reach (the window cut there before), each from that sample to its own reach
    cut, ends = 0, ends.copy()
    if 0 <= primary < len(mates) and primary >= fewest:
        cut = np.sort(ends[:primary])[primary - fewest]
        for m in range(primary, len(mates)):
            if ends[m] <= cut:
                ends[m] = 0
    for m in range(len(mates)):  # each mate over its reach, branch-free loops
        top, scale = max(0, min(size, ends[m] - low)), scales[m]
        begin = min(top, max(0, cut - low)) if 0 <= primary <= m else 0
        here, there = band[at + low:at + low + top], band[mates[m] + low:mates[m] + low + top]  # slices: vectorized
        for i in range(begin, top):
            total[i] += here[i] - scale * there[i]
        for i in range(begin, top):  # a loop: numba's ``reach[:top] += 1`` cost ~2 us a mate
            reach[i] += 1
        if alphas[m] != 0.0:  # its own ghost note found, taken off it
            first, last = max(begin, starts[m] - low), min(top, starts[m] + len(long) - low)
            if last > first:
                part, gain = long[low + first - starts[m]:low + last - starts[m]], scales[m] * alphas[m]
                for i in range(last - first):
                    total[first + i] += gain * part[i]
    if fewest > 0 and size > 0:  # cut at the first sample fewer than ``fewest`` mates reach (their reach falls)
        tops = np.empty(len(mates), dtype=np.int64)
        for m in range(len(mates)):
            tops[m] = max(0, min(size, ends[m] - low))
        size = np.sort(tops)[len(tops) - fewest] if len(tops) >= fewest else 0
    v = np.empty(size)
    for i in range(size):
        v[i] = total[i] / reach[i]
    n = len(head)
    sums = np.zeros(size + 1)  # v's squares summed from 0
    for i in range(size):
        sums[i + 1] = sums[i] + v[i] * v[i]
    blocks = size // block
    energy = np.zeros(max(blocks, 1))
    for j in range(blocks):
        energy[j] = sums[(j + 1) * block] - sums[j * block]
    window = width // block
    e = np.zeros(max(blocks - window + 1, 1))  # the energy over ``width`` samples from each block
    total = 0.0
    for j in range(min(window, blocks)):
        total += energy[j]
    for j in range(blocks - window + 1):
        e[j] = total
        if j + window < blocks:
            total += energy[j + window] - energy[j]
    onsets, fits, peaks = [], [], []
    last = -1
    crosses = np.empty(back + width + 1)
    for j in rising(e, before // block, blocks - window + 1, before // block, (before - width) // block, rise):
        if j <= last:  # the rise's own blocks (its 1 ms and the head's placements)
            continue
        last = j + window + width // block - 1
        best, where = -2.0, -1
        # the placements that fit in the window, their dots in one pass (np.dot's, :func:`blas_lag_dots`)
        low_h, high_h = max(0, j * block - back - pre), min(j * block + width - pre, size - n)
        if high_h >= low_h:
            blas_lag_dots(v, low_h, high_h - low_h + 1, head, n, crosses)
        for h in range(low_h, high_h + 1):
            cross, power = crosses[h - low_h], sums[h + n] - sums[h]
            if power > 0.0 and cross / np.sqrt(power) > best:
                best, where = cross / np.sqrt(power), h
        if where >= 0:
            onsets.append(low + where + pre)
            fits.append(best)
            peak = 0.0
            for q in range(where + pre, min(size, where + pre + width + after)):
                peak = max(peak, abs(v[q]))
            peaks.append(peak)
    return np.array(onsets, dtype=np.int64), np.array(fits), np.array(peaks)


@jit(error_model="numpy")
def matched_searches(band, at, low, lengths, first, count, mates, scales, ends, alphas, starts, long, head, block,
                     width, before, rise, back, pre, fewest, after, primary=-1):
    """:func:`matched_search` on each accent ``k`` (``band`` from ``at[k]``, samples ``low`` to ``lengths[k]`` after
    it; its mates ``first[k]`` to ``first[k] + count[k]`` of the flat ``mates``, ``scales``, ``ends``, ``alphas``,
    ``starts``), in one call. Returns each rise's accent, onset, fit and peak [each shape=(n,)]."""
    accent = [np.int64(0) for _ in range(0)]
    onsets = [np.int64(0) for _ in range(0)]
    fits = [0.0 for _ in range(0)]
    peaks = [0.0 for _ in range(0)]
    for k in range(len(at)):
        f, c = first[k], first[k] + count[k]
        o, fit, peak = matched_search(band, at[k], low, lengths[k], mates[f:c], scales[f:c], ends[f:c], alphas[f:c],
                                      starts[f:c], long, head, block, width, before, rise, back, pre, fewest, after,
                                      primary)
        for i in range(len(o)):
            accent.append(k)
            onsets.append(o[i])
            fits.append(fit[i])
            peaks.append(peak[i])
    return np.array(accent, dtype=np.int64), np.array(onsets, dtype=np.int64), np.array(fits), np.array(peaks)


@jit(error_model="numpy")
def note_remainders(band, accents, mates, scales, first, count, lows, size):
    """For each note ``i``: the mean over its mates ``first[i]`` to ``first[i] + count[i]`` of ``band`` from
    ``accents[p] + lows[i]`` less ``scales[p]`` times it from ``mates[p] + lows[i]``, over ``size`` samples [shape=(
    notes, size)]."""
    out = np.zeros((len(first), size))
    for i in range(len(first)):
        for p in range(first[i], first[i] + count[i]):  # slices: no negative-index branch a read, vectorized
            row, scale = out[i], scales[p]
            here, there = band[accents[p] + lows[i]:accents[p] + lows[i] + size], band[mates[p] + lows[i]:]
            for q in range(size):
                row[q] += here[q] - scale * there[q]
        for q in range(size):
            out[i, q] /= count[i]
    return out


@jit(error_model="numpy")
def long_sound(band, accents, mates, scales, lows, lengths, weights, longest):
    """The sum over pairs ``p`` of ``weights[p]`` times (``band`` from ``accents[p] + lows[p]`` less ``scales[p]``
    times it from ``mates[p] + lows[p]``) over ``lengths[p]`` samples (up to ``longest``), and how many pairs reach
    each sample [each shape=(longest,)]."""
    total, counted = np.zeros(longest), np.zeros(longest, dtype=np.int64)
    for p in range(len(accents)):  # slices: no negative-index branch a read, vectorized
        top, weight, scale = min(lengths[p], longest), weights[p], scales[p]
        here, there = band[accents[p] + lows[p]:], band[mates[p] + lows[p]:]
        for q in range(top):
            total[q] += weight * (here[q] - scale * there[q])
        for q in range(top):
            counted[q] += 1
    return total, counted


@jit
def placed_ghosts(times, kinds, which, ghosts, near, low, high):
    """:func:`.onsets._placed_ghosts`' loop: for each of ``ghosts`` in turn, the attack of ``which`` nearest it within
    ``near`` samples (in ``times``, as moved so far; the first of equals) moved onto it (``kinds`` 3) where it lies
    more than ``low`` and up to ``high`` samples after it. Returns whether each ghost had no attack so near (new)."""
    new = np.empty(len(ghosts), dtype=np.bool_)
    for i in range(len(ghosts)):
        g, best, k = ghosts[i], np.inf, -1
        for j in range(len(which)):
            off = abs(times[which[j]] - g)
            if off <= near and off < best:
                best, k = off, which[j]
        new[i] = k < 0
        if k >= 0 and low < times[k] - g <= high:
            times[k], kinds[k] = g, 3
    return new


@jit(error_model="numpy")
def lag_fits(heads, reference, n, count):
    """Each row of ``heads`` against ``reference`` (``n`` samples) from each of its first ``count`` samples: the
    normalized correlations and the windows' norms (at least 1e-300) [each shape=(rows, count)]; the norms by a
    sliding sum of squares, the dots by :func:`._templates.blas_lag_dots`."""
    like, norms = np.empty((heads.shape[0], count)), np.empty((heads.shape[0], count))
    dots = np.empty(count)
    for i in range(heads.shape[0]):
        x = heads[i]
        blas_lag_dots(x, 0, count, reference, n, dots)
        power = 0.0
        for j in range(n):
            power += x[j] * x[j]
        for lag in range(count):
            if lag:
                power += x[lag + n - 1] * x[lag + n - 1] - x[lag - 1] * x[lag - 1]
            norm = max(np.sqrt(max(power, 0.0)), 1e-300)
            norms[i, lag], like[i, lag] = norm, dots[lag] / norm
    return like, norms


@jit
def ghost_notes_pairs(c, ends, nexts, accents, count, mate, shifts, scales, span, size, reach):
    """:func:`matched_ghost_onsets`' notes after each accent ``c[accents[k]]`` (``count[k]`` mates of the flat
    ``mate``, ``shifts``, ``scales``, all indices into ``c``): each later attack before the accent's ``ends`` and
    ``span`` samples (a float, compared as such) after it, ``size`` or more after it, with a mate whose own next
    attack (``nexts``) lies ``reach`` or more past that note's offset. Returns the notes (attack, accent, first pair,
    pairs) and the pairs (the accent's onset, the mate's shifted, its scale, how far it reaches past the note)
    [each shape=(n,)]."""
    notes = [(np.int64(0), np.int64(0), np.int64(0), np.int64(0)) for _ in range(0)]
    pairs = [(np.int64(0), np.int64(0), 0.0, np.int64(0)) for _ in range(0)]
    first = 0
    for k in range(len(accents)):
        b = accents[k]
        for g in range(b + 1, len(c)):
            off = c[g] - c[b]
            if c[g] >= ends[b] or off > span:
                break
            if off < size:
                continue
            start = len(pairs)
            for m in range(first, first + count[k]):
                a, s = mate[m], shifts[m]
                if nexts[a] - c[a] - s >= off + reach:
                    pairs.append((c[b], c[a] + s, scales[m], nexts[a] - c[a] - s - off))
            if len(pairs) > start:
                notes.append((np.int64(g), b, np.int64(start), np.int64(len(pairs) - start)))
        first += count[k]
    note, accent = np.empty(len(notes), dtype=np.int64), np.empty(len(notes), dtype=np.int64)
    firsts, counts = np.empty(len(notes), dtype=np.int64), np.empty(len(notes), dtype=np.int64)
    for i in range(len(notes)):
        note[i], accent[i], firsts[i], counts[i] = notes[i]
    accent_at, mate_at, scale_of, reach_of = (np.empty(len(pairs), dtype=np.int64), np.empty(len(pairs), dtype=np.int64),
                                              np.empty(len(pairs)), np.empty(len(pairs), dtype=np.int64))
    for p in range(len(pairs)):
        accent_at[p], mate_at[p], scale_of[p], reach_of[p] = pairs[p]
    return note, accent, firsts, counts, accent_at, mate_at, scale_of, reach_of


@jit
def matched_mates(c, nexts, mate, shifts, scales, noted, amplitude, onset, known, pre, length):
    """:func:`matched_ghost_onsets`' mates (``mate``, indices into ``c``; ``shifts``, ``scales``), flat for its
    compiled search: each one's onset (shifted), how far it reaches (samples, to its own next attack, or where that
    is a ghost note found, ``noted``: on to that note's next attack or the longer sound's end, ``known`` samples
    past its onset ``onset``), the gain its note is taken off with (``amplitude``, 0 for none) and where that note
    starts (samples from the mate's onset). ``length``: the band's."""
    n = len(mate)
    at, ends, alphas, starts = (np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64), np.zeros(n),
                                np.zeros(n, dtype=np.int64))
    for m in range(n):
        a, s = mate[m], shifts[m]
        g, end, there = a + 1, nexts[a] - c[a], 0
        if g < len(c) and noted[g]:
            alphas[m], there = amplitude[g], onset[g] - c[a] - pre
            end = min(nexts[g] - c[a], there + known)
        at[m] = c[a] + s
        ends[m] = min(end - s - pre, length - c[a] - s)
        starts[m] = there - s
    return at, ends, alphas, starts


def matched_ghost_onsets(band, times, clear, rate, *, likeness, least, fit, rise_db=6.0, skip=10e-3, span=0.13,
                         quiet_db=-10.0, below_db=-30.0, quieter_db=-6.0, mates_used=3, head=5e-3, lag=0.25e-3,
                         fewest=3, reach=0.5e-3, longest=60e-3, back=0.0, spare_mates=0, shared=None):
    """Onsets (full-rate samples) of ghost notes after a ``clear`` attack at ``times`` (full-rate samples), found by a
    matched filter of their layer's own attack, learned from the ghost notes already found.

    A sample player replays a ghost layer's waveform sample for sample and the notes after an accent add to it
    exactly, so what an accent's layer-mates (as :func:`ghost_onsets`': :func:`_partners`, up to ``mates_used``)
    leave of it after each attack ``skip`` to ``span`` s after it (and before the next within ``quiet_db``) is that
    note alone and the noise of the recordings: their mean over the mates that reach 0.5 ms plus ``head`` s past it,
    aligned within ``lag`` s to the one of the most energy that two mates or more reach and kept where they correlate
    so by ``fit`` or more; those two mates or more reach, averaged, are the head, its onset the median of theirs
    (``fewest`` or more; FluidR3's snare 38 roll at -60 dBFS, seed 0: 8 notes kept, 5 of them so). Each kept note's
    amplitude is its remainder's projection on the head, and its remainders past the head (each mate up to its own
    next attack, up to ``longest`` s), so scaled, averaged where two or more reach, are the layer's longer sound: a mate whose own next attack is such a note is taken off less it, reaching
    on to that note's next attack or the longer sound's end (a ghost note late after its accent, every mate's own next
    note first: FluidR3's 2.8007 s, fits 0.96-0.97 so). In each accent's window (up to its next attack within
    ``quiet_db``) the mean of the reaching mates' remainders (two or more) is read where its energy over 1 ms rises
    ``rise_db`` over its most over the 10 ms before, the head fitted from ``reach`` s before that block to 1 ms after
    (:func:`matched_search`): where it fits by ``fit`` or more, its peak over the 11 ms from it as
    :func:`ghost_onsets` asks, a note at the head's onset (one in 20 ms). Under white noise the head's 5.5 ms gather a
    quiet note's energy where a 1-ms rise reads its first millisecond alone (0.7874 s there: 10.3 dB over 1 ms, fits
    0.98; on the corpus's seed 0 the rises 5 ms or more from every note fit 0.61 at most). With ``back`` (s) over
    ``lag``, the notes are aligned from so long earlier (to ``lag`` later): a note found late on its sample's own
    later rise fits there, and one its lag moves more than 0.5 ms earlier than the median's is returned at the
    head's onset too (``back`` ``lag`` or less: ±``lag``, none so returned). With ``spare_mates``, the search (not
    the learning) takes up to so many more mates, each counting from where fewer than two of the first reach
    (:func:`matched_search`'s ``primary``): a roll's accents' own ghost notes cut the first mates' reach."""
    pre, size, shift = round(0.5e-3 * rate), round(skip * rate), round(lag * rate)
    lead = max(shift, round(back * rate))  # the alignment's reach earlier (samples)
    width, before, after = round(1e-3 * rate), round(10e-3 * rate), round(10e-3 * rate)
    n = pre + round(head * rate)
    c = np.rint(np.asarray(times, dtype=float)).astype(np.int64)
    starts = c - pre
    ok = np.asarray(clear, dtype=bool) & (starts >= 2) & (starts + round(span * rate) + 2 + after < len(band))
    which = np.flatnonzero(ok)
    if len(which) < 3:
        return np.empty(0)
    loud, ends = _loud_and_ends(band, c, rate, quiet_db, shared)
    mates = _partners(band, starts[which], size + pre, 2, likeness, shared)
    accents, _, mates_count, mate, shifts, scales = _accents_mates(mates, mates_used)
    nexts = np.append(c[1:], len(band))
    mate = which[mate]
    # the notes after each accent (before its next within ``quiet_db``), each mate that reaches its head (its own
    # next attack later), as pairs: the accent's onset, the mate's (shifted), its scale and how far it reaches
    note, note_accent, first, count, accent_at, mate_at, scale_of, reach_of = ghost_notes_pairs(
        c, ends, nexts, which[np.array(accents, dtype=np.int64)], mates_count, mate, shifts, scales, span * rate, size,
        n + shift)
    twice = count >= 2
    if twice.sum() < fewest:
        return np.empty(0)
    offsets = c[note] - c[note_accent]
    heads = note_remainders(band, accent_at, mate_at, scale_of, first, count, offsets - pre - lead, n + lead + shift)
    # the reference and the head from the notes two mates or more reach (one mate's remainder may hold its own note)
    energies = np.einsum("ij,ij->i", heads[:, lead:lead + n], heads[:, lead:lead + n])
    reference = heads[int(np.argmax(np.where(twice, energies, -1.0))), lead:lead + n]
    reference = reference / max(np.sqrt(reference.dot(reference)), 1e-300)  # np.linalg.norm's, less its checks
    views = np.ndarray((len(heads), lead + shift + 1, n), dtype=heads.dtype, buffer=heads,
                       strides=(heads.strides[0],) + heads.strides[1:] * 2)  # [note, lag, sample]: as_strided's, less its checks
    if lead > shift:  # many lags: sliding sums (compiled)
        like, norms = lag_fits(np.ascontiguousarray(heads), reference, n, lead + shift + 1)
    else:
        norms = np.maximum(np.sqrt(np.einsum("ijk,ijk->ij", views, views)), 1e-300)
        like = np.einsum("ijk,k->ij", views, reference) / norms
    best = np.argmax(like, axis=1)
    kept = like[np.arange(len(note)), best] >= fit
    if np.sum(kept & twice) < fewest:
        return np.empty(0)
    lags = best - lead
    middle = sorted(lags[kept & twice].tolist())  # their median (np.median's: the two middle ones' mean), truncated
    half = len(middle) // 2
    middle_lag = int(middle[half] if len(middle) % 2 else (middle[half - 1] + middle[half]) / 2)
    chosen = np.flatnonzero(kept & twice)
    template = np.mean(views[chosen, best[chosen]] / norms[chosen, best[chosen], None], axis=0)
    unit = np.zeros(n)  # the head: its onset ``pre`` samples in
    if middle_lag <= 0:
        unit[:n + middle_lag] = template[-middle_lag:]
    else:
        unit[middle_lag:] = template[:n - middle_lag]
    unit /= max(np.sqrt(unit.dot(unit)), 1e-300)
    # each kept note's onset (its found onset moved by its lag less the median's), amplitude (its mean remainder's
    # projection on the head) and longer sound (each mate's remainder up to its own next attack, so scaled)
    kept = np.flatnonzero(kept)
    lows = offsets[kept] + lags[kept] - middle_lag - pre
    alphas = note_remainders(band, accent_at, mate_at, scale_of, first[kept], count[kept], lows, n) @ unit
    positive = alphas > 0.0
    kept, lows, alphas = kept[positive], lows[positive], alphas[positive]
    # a kept note its lag moves earlier by more than 0.5 ms (found late, on its sample's own later rise: the alignment
    # reaching so far with ``lag`` over 0.25 ms) is a note at that onset too
    early = (lags[kept] - middle_lag < -pre)
    moved = (c[note_accent[kept[early]]] + lows[early] + pre).tolist()
    note_of = np.repeat(np.arange(len(kept)), count[kept])  # each kept note's pairs, in turn
    each = np.arange(len(note_of)) - (np.cumsum(count[kept]) - count[kept])[note_of] + first[kept][note_of]
    longest = round(longest * rate)
    total, counted = long_sound(band, accent_at[each], mate_at[each], scale_of[each], lows[note_of],
                                reach_of[each] + pre - (lows[note_of] + pre - offsets[kept][note_of]),
                                1.0 / alphas[note_of], longest)
    known = int(np.argmax(counted < 2)) if np.any(counted < 2) else longest
    long = total[:known] / np.maximum(counted[:known], 1)
    # each accent's mates (a mate whose own next attack is a kept note: less it, on to that note's next attack or
    # the longer sound's end), flat for one compiled search (a note kept twice: its last, as a dict keeps it)
    noted, amplitude, onset = np.zeros(len(c), dtype=bool), np.zeros(len(c)), np.zeros(len(c), dtype=np.int64)
    for i, alpha, low in zip(kept.tolist(), alphas.tolist(), lows.tolist()):
        g = note[i]
        noted[g], amplitude[g], onset[g] = True, alpha, c[note_accent[i]] + low + pre
    mates_at, mate_ends, alphas, long_at = matched_mates(c, nexts, mate, shifts, scales, noted, amplitude, onset,
                                                         known, pre, len(band))
    primary = -1
    if spare_mates > 0:  # more mates, each counting only past where fewer than two of the first reach
        _, _, mates_count, mate, shifts, scales = _accents_mates(mates, mates_used + spare_mates)
        mates_at, mate_ends, alphas, long_at = matched_mates(c, nexts, which[mate], shifts, scales, noted, amplitude,
                                                             onset, known, pre, len(band))
        primary = mates_used
    b = which[np.array(accents, dtype=np.int64)]
    lengths = np.minimum(np.minimum(round(span * rate), ends[b] - c[b]), len(band) - c[b])
    accent_of, onsets, fits, peaks = matched_searches(
        band, c[b], size - before, lengths, np.cumsum(mates_count) - mates_count, mates_count, mates_at, scales,
        mate_ends, alphas,
        long_at, long, unit, max(1, width // 4), width, before,
        10.0 ** (rise_db / 10.0), round(reach * rate), pre, 2, after, primary)
    found, accent, last, apart = [], -1, -np.inf, round(20e-3 * rate)
    lowest = np.maximum(least, loud[b] * 10.0 ** (below_db / 20.0)).tolist()  # each accent's peaks allowed
    highest, onset_of = (loud[b] * 10.0 ** (quieter_db / 20.0)).tolist(), c[b].tolist()
    for k, t, like, peak in zip(accent_of.tolist(), onsets.tolist(), fits.tolist(), peaks.tolist()):
        if k != accent:
            accent, last = k, -np.inf
        if like < fit or t < size or t < last + apart or not lowest[k] <= peak <= highest[k]:
            continue
        found.append(onset_of[k] + t)
        last = t
    found += moved
    return np.unique(np.asarray(found, dtype=float))
