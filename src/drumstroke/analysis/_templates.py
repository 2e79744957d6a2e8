"""The compiled loops of the onset detector's template stages (:mod:`.onsets`: the template fit, ``peak_db``'s
templates and fits): each gives what the code it replaced gave, to the bit. Where one sums in another order, the
sums only skip work whose outcome their bounds already tell (its docstring says how); a median's values are the
same whatever sorts them.

A module of its own (as :mod:`._kernels`) so that importing :mod:`drumstroke.analysis` does not import numba;
:mod:`.onsets` imports it where it runs it.
"""

import math

import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from .._jit import jit
from ._front import _load, _plus_times, _quad, _sum_of_lanes
from ._kernels import (
    best_lag,
    eight_dots,
    eight_squares,
    least_unexplained_by,
    likeness_at,
    peaks_around,
    running_power,
    window_largest,
)
from ._modes import _contiguous, _load_vector, _wide_vectors


@jit
def template_attacks(d, times, span, gap, pre, clear, below, least_room, tail):
    """:func:`.onsets._template_attacks`' choice: the loudest, the quietest and the roomiest clear attacks (indices of
    ``times``, -1 for none).

    An attack is clear when ``d``'s peak over the ``span`` samples before it (up to ``gap`` before it) is ``clear``
    times its peak over the ``span`` after or less (:func:`._kernels.peaks_around`, at ``times`` rounded), and it is
    ``pre`` samples or more into ``d`` and ``least_room`` samples or more before the next (or the end). The loudest
    (the first of equals; none when no peak is over 0), the quietest of those ``below`` times the loudest peak of all
    or louder (the first of equals), and of those with the most room (up to ``tail`` samples) the loudest (the first).
    """
    centres = np.rint(times).astype(np.int64)
    peaks, priors = peaks_around(d, centres, span, span, gap)
    floor = (peaks.max() if len(peaks) else 0.0) * below
    loudest, quietest, roomiest = -1, -1, -1
    most = 0.0  # the most room (as room.max(initial=0.0))
    for i in range(len(times)):
        end = times[i + 1] if i + 1 < len(times) else float(len(d))
        if not (centres[i] >= pre and end - times[i] >= least_room and priors[i] <= peaks[i] * clear):
            continue
        if loudest < 0 or peaks[i] > peaks[loudest]:
            loudest = i
        if peaks[i] >= floor and (quietest < 0 or peaks[i] < peaks[quietest]):
            quietest = i
        room = min(end - times[i], tail)
        if room > most or (room == most and roomiest >= 0 and peaks[i] > peaks[roomiest]):
            most, roomiest = room, i
        elif room == most and roomiest < 0:
            roomiest = i
    if loudest >= 0 and not peaks[loudest] > 0.0:
        loudest = -1
    if quietest >= 0 and not peaks[quietest] < np.inf:
        quietest = -1
    return loudest, quietest, roomiest


@jit
def next_attack(x, head, low, high, pre, reach, base, width, energy, rise, likeness, least):
    """The next attack :func:`fitted_attacks` takes: the first sample in ``[low, high)`` where ``head`` (the template's
    start) correlates by ``likeness`` with what is left, rising out of the sound before it, or -1 (its bounds checked
    by the caller: ``pre <= low``, ``base <= low - pre``).

    The window from each sample ``n`` in ``[low, high)`` is ``x[n - pre:n - pre + len(head)]``; its jump is
    :func:`.onsets._windows`' (``width``) over ``x[base:high]``, the power summed in order from ``x[base]``.
    Correlations are computed only where the window rises ``rise`` (power ratio) times, in order, until one passes;
    the products with ``head`` of eight such windows at a time (:func:`._kernels.eight_dots`). A window too quiet for
    its product to scale ``least`` (Cauchy-Schwarz: its energy, bounded from the running sums, under ``least²`` times
    the head's, by a margin far over the sums' rounding) is not scaled whatever its product: none is summed (what the
    template fitted leaves of its own attack is zeros). Which windows may rise and are loud enough is told in one
    pass over them all (:func:`_tried`, in vector instructions) before the scan.
    """
    count, size = high - base, len(head)
    total = max(count, high - pre + size - base)  # the heads' windows too
    power = np.empty(total + 1)
    power[0] = 0.0
    for j in range(total):
        power[j + 1] = power[j] + x[base + j] * x[base + j]
    # a window's energy is under (power[b] - power[a]) + slack (the squares' underflow too), its product with head
    # under the geometric mean of its energy and the head's, to rounding far within the 1e-6 margin: a window quieter
    # than quiet has a product under least × energy (not scaled), whatever it is
    slack = 4.0 * (total + 2) * 2.220446049250313e-16 * power[total] + 1e-300
    scaled_at = least * energy
    quiet = (scaled_at * scaled_at) / (energy * (1.0 + 1e-6)) if scaled_at > 1e-100 else -np.inf
    tried = _tried(power, low - base, high - low, count, width, (1.0 - 1e-9) * rise, pre, size, slack, quiet)
    eights = tried.view(np.uint64)  # eight windows' flags a word
    rising, dots, owns = np.empty(8, dtype=np.int64), np.empty(8), np.empty(8)
    i = 0
    while i < high - low:
        found = 0  # the next eight samples (or fewer) whose windows rise
        while i < high - low and found < 8:
            if i % 8 == 0 and eights[i // 8] == 0:  # none of the next eight tried
                i += 8
                continue
            if tried[i]:
                n = i + low - base
                ahead, behind = power[min(n + width, count)] - power[n], power[n] - power[max(n - 4 * width, 0)]
                after = ahead / width
                before = behind / (4 * width)
                if after >= rise * before:
                    rising[found] = i
                    found += 1
            i += 1
        if found == 0:
            break
        rising[found:] = rising[found - 1]
        if found == 8 and rising[7] - rising[0] == 7:  # eight windows in a row (as most are)
            _eight_in_a_row(x, low - pre + rising[0], head, dots)
        else:
            eight_dots(x, low - pre + rising, head, dots)
        scaled = False
        for f in range(found):
            scaled = scaled or dots[f] >= least * energy
        if not scaled:
            continue
        eight_squares(x, low - pre + rising, len(head), owns)  # each window's energy, as likeness_at sums it
        for f in range(found):
            if not dots[f] >= least * energy:  # (the correlation only where the scale passes)
                continue
            like = dots[f] / (math.sqrt(owns[f] * energy) + 1e-300)  # likeness_at's, its sums side by side
            if like >= likeness:
                best, at = like, rising[f]
                for k in range(rising[f] + 1, min(rising[f] + reach + 1, high - low)):
                    like, _ = likeness_at(x, low - pre + k, head, energy)
                    if like > best:
                        best, at = like, k
                return low + at
    return -1


@jit
def _eight_in_a_row(x, start, t, out):
    """:func:`._kernels.eight_dots` of the eight windows from ``start`` on, into ``out``: each window's products added
    in order, their eight chains side by side on one slice (in vector instructions)."""
    d0 = d1 = d2 = d3 = d4 = d5 = d6 = d7 = 0.0
    w = x[start:start + len(t) + 7]  # a slice: indices the compiler sees are ≥ 0
    for j in range(len(t)):
        v = t[j]
        d0 += w[j] * v
        d1 += w[j + 1] * v
        d2 += w[j + 2] * v
        d3 += w[j + 3] * v
        d4 += w[j + 4] * v
        d5 += w[j + 5] * v
        d6 += w[j + 6] * v
        d7 += w[j + 7] * v
    out[0], out[1], out[2], out[3], out[4], out[5], out[6], out[7] = d0, d1, d2, d3, d4, d5, d6, d7


@jit
def _tried(power, offset, windows, count, width, ratio, pre, size, slack, quiet):
    """Which of :func:`next_attack`'s ``windows`` (the ``i``-th at ``n = offset + i`` in ``power``, its running sums)
    may rise and may be scaled: not when the power over the ``width`` ahead (up to ``count``) is surely under
    ``ratio``/4 times that over the ``4 width`` behind (the running sums never fall, so that test is under the rise's
    by far more than the divisions' rounding: normal numbers, far from underflow), nor when the ``size`` samples from
    ``pre`` before ``n`` have under ``quiet`` less ``slack`` of energy. [shape=(windows,), padded with False to a
    multiple of 8]"""
    tried = np.zeros(-(-windows // 8) * 8, dtype=np.bool_)  # whole words of eight (the last padded with False)
    first = min(max(0, 4 * width - offset, pre - offset), windows)  # from here, no bound clamped
    last = max(first, min(windows, count - width - offset))
    for i in range(first):
        tried[i] = _maybe(power, offset + i, count, width, ratio, pre, size, slack, quiet)
    # the same tests on slices (indices the compiler sees are ≥ 0: in vector instructions)
    now, ahead_end = power[offset + first:], power[offset + first + width:]
    behind_start = power[offset + first - 4 * width:]
    head_start, head_end = power[offset + first - pre:], power[offset + first - pre + size:]
    out = tried[first:]
    for i in range(last - first):
        ahead, behind = ahead_end[i] - now[i], now[i] - behind_start[i]
        out[i] = (((not behind > 1e-280) | (not 4.0 * ahead < ratio * behind))
                  & (head_end[i] - head_start[i] + slack >= quiet))
    for i in range(last, windows):
        tried[i] = _maybe(power, offset + i, count, width, ratio, pre, size, slack, quiet)
    return tried


@jit(inline="always")
def _maybe(power, n, count, width, ratio, pre, size, slack, quiet):
    """:func:`_tried`'s tests of the window at ``n``, its bounds clamped as :func:`next_attack` clamps them."""
    ahead, behind = power[min(n + width, count)] - power[n], power[n] - power[max(n - 4 * width, 0)]
    if behind > 1e-280 and 4.0 * ahead < ratio * behind:
        return False
    return n < pre or power[n - pre + size] - power[n - pre] + slack >= quiet


@jit
def own_peaks(rest, starts, following, ends, bank, offsets, lengths, window, reach, shift, realign=0, poor=1.0,
              learn=0.0, room=0, clear=0.0):
    """:func:`.onsets._own_peaks`' loop: each onset's peak of ``rest`` less the earlier notes' fitted templates (taken
    off ``rest`` in place), and of ``rest`` itself (read first).

    The templates are ``bank[offsets[t]:offsets[t] + lengths[t]]``. At each onset the usable ones (those of
    ``min(following - start + window, reach)`` samples or more, else the last longest) are each fitted from ``shift``
    samples before the onset to ``shift`` after, over up to the next onset, where it leaves the least unexplained
    (:func:`._kernels.least_unexplained`: the windows' energies by running sums of the remainder's squares in order;
    the products with the template, and its energy, numpy's ``np.dot``: the windows' side by side,
    :func:`blas_lag_dots`); the best, scaled by least squares, is taken
    off the remainder. Where the windows' energies summed in another order (:func:`_surely_least`) leave no doubt
    which template and lag leave the least, the running sums (a serial chain of additions as long as the fits)
    are not summed.

    With ``realign`` (samples, > 0), a fit that leaves more than ``poor`` of its window unexplained is sought again
    ``realign`` samples either way of the onset by the template's first ``window // 2`` samples (:func:`_realigned`;
    5 ms at 10 ms windows, as good on the recorded corpus as the whole window, at half the cost): an onset placed a little off its note (0.1-1 ms
    late, as in noise) leaves its template misplaced by more than ``shift``, its note's sound not taken off.

    With ``learn`` (a fraction, > 0; ``peak_learn``), templates of the layers the bank lacks are learned on the way
    (:data:`_LEARNED` at most): where the bank's fit leaves more than ``learn`` of the note's attack (its first
    ``window`` samples, or up to the next onset) unexplained, the learned templates are fitted there too
    (:func:`_learned_fit`) and the best taken off instead; where none leaves ``learn`` or less, or the best learned is
    a louder note's, a note with ``room`` samples or more before the next onset, whose remainder over the ``window``
    before it is ``clear`` times its peak or less, is learned as it is (:func:`_learn`: its own remainder over its
    first ``room`` samples, the bank's fit after: a note missed in a longer room, as a roll's ghost note 64 ms after
    another, would be taken off wherever the template is, 12 dB off a true ghost note's peak) and taken off whole. So a layer a recording has no clear note of (a drop's
    quiet bounces, each over the last one's ringing) gets the template of its quietest note with room, the earlier
    notes' fits taken off. Returns a third array [shape=(n,)]: with ``learn``, at each onset whose window the next
    onset cuts short of ``window``, where the fit leaves ``poor`` or less of it unexplained, the peak over the window
    of the template fitted there (its scale times its largest magnitude: the note's own peak, which may come after
    the next onset: up to 9.4 ms after its start on FluidR3's snare); NaN elsewhere.
    """
    count, templates = len(starts), len(lengths)
    peaks, heard = np.empty(count), np.empty(count)
    model = np.full(count, np.nan)  # with ``learn``, the fitted template's peak over a window cut short
    learned = np.zeros((_LEARNED if learn > 0.0 else 0, max(reach, 1)))
    learned_lengths = np.zeros(len(learned), dtype=np.int64)
    learned_peaks = np.zeros(len(learned))  # the peak of the note each was learned from
    known = 0  # templates learned so far
    for i in range(count):
        heard[i] = window_largest(rest, starts[i], ends[i], True)
    longest = -1  # the last of the longest templates
    for t in range(templates):
        if longest < 0 or lengths[t] >= lengths[longest]:
            longest = t
    crosses, energies = np.empty((templates, 2 * shift + 1)), np.empty(templates)
    sizes = np.zeros(templates, dtype=np.int64)  # each template's length fitted at this onset (0: not fitted)
    for i in range(count):
        start = starts[i]
        peak = window_largest(rest, start, ends[i], True)
        peaks[i] = peak
        need = min(following[i] - start + window, reach)
        any_long = False
        for t in range(templates):
            any_long = any_long or lengths[t] >= need
        low = max(start - shift, 0)
        windows = start + shift - low + 1
        reach_most = 0  # the running sums' length: over the longest part a usable template is fitted to
        for t in range(templates):
            sizes[t] = 0
            if (any_long and lengths[t] < need) or (not any_long and t != longest):
                continue
            length = min(lengths[t], following[i] - start, len(rest) - start - shift)
            reach_most = max(reach_most, start + shift + length - low)
            if length < 16:  # too short to tell a scale
                continue
            head = bank[offsets[t]:offsets[t] + length]
            energy = np.dot(head, head)
            if not energy > 0.0:
                continue
            blas_lag_dots(rest, low, windows, head, length, crosses[t])  # np.dot's of each window, side by side
            sizes[t], energies[t] = length, energy
        chosen, at = _surely_least(rest, low, windows, crosses, energies, sizes)
        if chosen < 0 and np.any(sizes > 0):
            power = running_power(rest[low:], max(reach_most, 0))
            best = np.inf
            for t in range(templates):
                if sizes[t] == 0:
                    continue
                k, unexplained = least_unexplained_by(power, crosses[t, :windows], energies[t], sizes[t])
                if chosen < 0 or unexplained < best:
                    best, at, chosen = unexplained, k, t
        if chosen >= 0:
            scale = crosses[chosen, at] / energies[chosen]
            at += low
            if realign > 0:
                at, scale = _realigned(rest, start, at, scale, bank[offsets[chosen]:offsets[chosen] + lengths[chosen]],
                                       sizes[chosen], energies[chosen], window // 2, realign, poor)
            template = bank[offsets[chosen]:offsets[chosen] + lengths[chosen]]
            if learn > 0.0:
                span = min(window, following[i] - start, len(rest) - at)  # the note's attack: its peak's window
                unexplained = _left(rest, at, scale, template, span)
                if unexplained > learn:  # another layer: one learned before, or this note's own
                    mine, mine_at, mine_scale = -1, at, scale
                    for k in range(known):
                        size = min(learned_lengths[k], span, len(rest) - start - shift)
                        if size < 16:
                            continue
                        at_k, scale_k, left_k = _learned_fit(rest, low, windows, learned[k, :size])
                        if left_k < unexplained:
                            mine, mine_at, mine_scale, unexplained = k, at_k, scale_k, left_k
                    new = unexplained > learn and known < len(learned_lengths)
                    if (new or (mine >= 0 and peak < learned_peaks[mine])) and following[i] - start >= room:
                        prior = window_largest(rest, max(start - window, 0), start, True)
                        if prior <= clear * peak:  # clear of what the earlier notes' fits left: its own waveform
                            if new:
                                mine, known = known, known + 1
                            learned_lengths[mine] = _learn(rest, start, start + room, at, scale, template,
                                                           learned[mine])
                            learned_peaks[mine] = peak
                            mine_at, mine_scale = start, 1.0
                    if mine >= 0:
                        template, at, scale = learned[mine, :learned_lengths[mine]], mine_at, mine_scale
                if following[i] - start < window and unexplained <= poor:  # a window cut short, a fit that explains it
                    top = 0.0
                    for j in range(max(start - at, 0), min(start - at + window, len(template))):
                        top = max(top, abs(template[j]))
                    model[i] = abs(scale) * top
            size = min(len(template), len(rest) - at)
            fitted, template = rest[at:at + size], template[:size]  # slices: indices ≥ 0
            for j in range(size):
                fitted[j] -= scale * template[j]
    return peaks, heard, model


_LEARNED = 4  # the most templates own_peaks learns (``learn``): a SoundFont's snare has some four velocity layers


@jit
def _left(rest, at, scale, template, length):
    """The fraction of ``rest``'s energy over ``length`` samples from ``at`` that ``scale`` times ``template`` leaves."""
    length = min(length, len(rest) - at, len(template))
    own, cross, energy = 0.0, 0.0, 0.0
    for j in range(length):
        own += rest[at + j] * rest[at + j]
        cross += rest[at + j] * template[j]
        energy += template[j] * template[j]
    if not own > 0.0:
        return 0.0
    return max(own - 2.0 * scale * cross + scale * scale * energy, 0.0) / own


@jit
def _learned_fit(rest, low, windows, template):
    """``template`` fitted by least squares at the lag from ``low`` (``windows`` lags) that leaves the least of
    ``rest`` there unexplained (over the template's length): ``(at, scale, the fraction unexplained)``."""
    energy = np.dot(template, template)
    best, at, scale = np.inf, low, 0.0
    m = len(template)
    for k in range(windows):
        if low + k + m > len(rest):
            break
        segment = rest[low + k:low + k + m]
        own = np.dot(segment, segment)
        cross = np.dot(segment, template)
        if not (own > 0.0 and energy > 0.0):
            continue
        fraction = max(own - cross * cross / energy, 0.0) / own
        if fraction < best:
            best, at, scale = fraction, low + k, cross / energy
    return at, scale, best


@jit
def _learn(rest, start, end, at, scale, template, out):
    """A note's own waveform into ``out``: ``rest`` from ``start`` up to ``end`` (``room`` samples on), then the tail of
    ``scale`` times ``template`` placed at ``at`` (the bank's fit of it), up to ``len(out)`` or the recording's end
    (returned: the samples written)."""
    n = min(len(out), len(rest) - start)
    for j in range(n):
        if start + j < end:
            out[j] = rest[start + j]
        else:
            u = start + j - at
            out[j] = scale * template[u] if 0 <= u < len(template) else 0.0
    return n


@jit
def _realigned(rest, start, at, scale, template, length, energy, head, realign, poor):
    """:func:`own_peaks`' fit of ``template`` (its first ``length`` samples, of energy ``energy``) placed at ``at`` with
    ``scale``, or a better one: where it leaves more than ``poor`` of ``rest``'s energy there unexplained, the lag
    from ``start - realign`` to ``start + realign`` whose first ``head`` samples (or ``length``) the template fits
    best (the largest ``cross * |cross| / own``: the least unexplained, the template's sign kept), fitted over
    ``length`` by least squares, if that leaves less unexplained. ``(at, scale)``."""
    tiny = np.finfo(np.float64).tiny
    segment = rest[at:at + length]
    own = np.dot(segment, segment)
    if not own > tiny:
        return at, scale
    cross = scale * energy
    unexplained = (own - cross * scale) / own
    if not unexplained > poor:
        return at, scale
    h = min(head, length)
    first, last = max(start - realign, 0), min(start + realign, len(rest) - length)
    if last < first:
        return at, scale
    top = template[:h]
    best, lag = -np.inf, -1
    power = 0.0  # the head window's energy, running
    for j in range(first, first + h):
        power += rest[j] * rest[j]
    for k in range(first, last + 1):
        if k > first:
            power += rest[k + h - 1] * rest[k + h - 1] - rest[k - 1] * rest[k - 1]
        c = np.dot(rest[k:k + h], top)
        fit = c * abs(c) / max(power, tiny)
        if fit > best:
            best, lag = fit, k
    if lag < 0 or lag == at:
        return at, scale
    segment = rest[lag:lag + length]
    own_there = np.dot(segment, segment)
    cross_there = np.dot(segment, template[:length])
    if not own_there > tiny:
        return at, scale
    if (own_there - cross_there * cross_there / energy) / own_there < unexplained:
        return lag, cross_there / energy
    return at, scale


_DOT_LAGS = 8 if _wide_vectors() else 2  # lags side by side: 16 AVX-512 registers of sums, or 8 AVX ones (more spill)
_EIGHT = ir.VectorType(ir.DoubleType(), 8)


@intrinsic
def _sixteen_lanes(typingctx, x, starts, y, whole, out):
    """OpenBLAS's ``ddot`` kernel for x86-64 with AVX2 (its "Haswell" one, what numpy's and scipy's wheels run on such
    processors) over the first ``whole`` (a multiple of 16) products of ``x`` from each of the :data:`_DOT_LAGS`
    ``starts`` with ``y``: each of its 16 lanes (four vectors of four) adds every 16th product by fused multiply-adds
    in order from 0, into ``out[16 g:16 g + 16]`` for start ``g``. Two of the kernel's vectors are one of eight
    lanes here (each lane's operations its own), ``y`` loaded once for all the starts."""
    if not _contiguous(x, starts, y, out):
        return None
    sig = types.none(x, starts, y, whole, out)

    def codegen(context, builder, signature, args):
        x_data, starts_data, y_data, out_data = (context.make_array(signature.args[n])(context, builder, args[n]).data
                                                 for n in (0, 1, 2, 4))
        whole = context.cast(builder, args[3], signature.args[3], types.intp)

        def constant(n):
            return ir.Constant(whole.type, n)

        fma = cgutils.get_or_insert_function(builder.module, ir.FunctionType(_EIGHT, [_EIGHT] * 3), "llvm.fma.v8f64")
        firsts = [builder.load(builder.gep(starts_data, [constant(g)])) for g in range(_DOT_LAGS)]
        sums = [[cgutils.alloca_once_value(builder, ir.Constant(_EIGHT, [0.0] * 8)) for _ in range(2)]
                for _ in range(_DOT_LAGS)]
        with cgutils.for_range(builder, builder.sdiv(whole, constant(16))) as loop:
            j = builder.mul(loop.index, constant(16))
            heads = [_load_vector(builder, y_data, builder.add(j, constant(8 * h)), _EIGHT) for h in (0, 1)]
            for g in range(_DOT_LAGS):
                at = builder.add(firsts[g], j)
                for h in (0, 1):
                    values = _load_vector(builder, x_data, builder.add(at, constant(8 * h)), _EIGHT)
                    builder.store(builder.call(fma, [values, heads[h], builder.load(sums[g][h])]), sums[g][h])
        for g in range(_DOT_LAGS):
            for h in (0, 1):
                pointer = builder.bitcast(builder.gep(out_data, [constant(16 * g + 8 * h)]), _EIGHT.as_pointer())
                builder.store(builder.load(sums[g][h]), pointer, align=8)
        return context.get_dummy_value()

    return sig, codegen


@jit
def blas_lag_dots(x, first, count, y, length, out):
    """``out[k] = np.dot(x[first + k:first + k + length], y[:length])`` for ``k`` below ``count``, as OpenBLAS's
    Haswell ``ddot`` (on one thread) sums it: its kernel's 16 lanes over the first multiple of 16 products
    (:func:`_sixteen_lanes`), the lanes added as its vectors' halves, then its pairs, then the two; the products
    left over added one by one. :data:`_DOT_LAGS` windows a pass over ``y`` (numba's ``np.dot`` calls OpenBLAS's
    ``ddot``; tests/test_onsets_speed_kernels.py holds these against it)."""
    whole = length - length % 16
    sums, starts = np.empty(16 * _DOT_LAGS), np.empty(_DOT_LAGS, dtype=np.int64)
    for k in range(0, count, _DOT_LAGS):
        for g in range(_DOT_LAGS):  # past the last window: the last again (its sums not read)
            starts[g] = first + min(k + g, count - 1)
        if whole:
            _sixteen_lanes(x, starts, y, whole, sums)
        for g in range(min(_DOT_LAGS, count - k)):
            dot = 0.0
            if whole:
                s = sums[16 * g:16 * g + 16]
                even = ((s[0] + s[2]) + (s[4] + s[6])) + ((s[8] + s[10]) + (s[12] + s[14]))
                odd = ((s[1] + s[3]) + (s[5] + s[7])) + ((s[9] + s[11]) + (s[13] + s[15]))
                dot = even + odd
            for j in range(whole, length):
                dot += y[j] * x[starts[g] + j]
            out[k + g] = dot


@jit
def _surely_least(rest, low, windows, crosses, energies, sizes):
    """The template and lag (from ``low``) :func:`own_peaks`' running sums would choose, when windows' energies summed
    in another order tell it beyond doubt: ``(t, k)``, else ``(-1, 0)``.

    Template ``t`` (``sizes[t]`` > 0 samples) leaves ``(own - q) / own`` of the window from ``low + k`` unexplained
    (``q = cross² / energy``; ``own`` its energy), rising with ``own``. The running sums give ``own`` within
    ``4 n ε`` times the ``n`` samples' energy of its exact sum (sums of squares: every term ≥ 0), and so does any
    other order; with twice that bound each way and a margin far over the quotients' rounding, each window's
    fraction has bounds, and where one window's upper bound is under every other's lower bound it is the least
    whatever the sums' order: the first least of the first template that leaves the least, as the running sums'
    choice is.
    """
    eps, tiny = 2.220446049250313e-16, np.finfo(np.float64).tiny
    chosen, at, least_high = -1, 0, np.inf
    lows = np.full((len(sizes), windows), np.inf)
    summed, middle = -1, 0.0  # the length the middle was summed over (templates cut at the next onset share it)
    for t in range(len(sizes)):
        length = sizes[t]
        if length == 0:
            continue
        if length < windows:
            return -1, 0
        # the windows share the samples from low + windows - 1 to low + length: summed once, in vector lanes
        if length != summed:
            summed, middle = length, _squares(rest, low + windows - 1, low + length)
        total = middle  # over all the windows' samples
        for j in range(windows - 1):
            total += rest[low + j] * rest[low + j] + rest[low + length + j] * rest[low + length + j]
        slack = 8.0 * (length + windows + 2) * eps * total + 1e-290
        for k in range(windows):
            own = _window_energy(rest, low, k, windows, length, middle)
            q = crosses[t, k] * crosses[t, k] / energies[t]
            below, above = own - slack, own + slack
            if not (below > 2.0 * tiny and np.isfinite(above) and np.isfinite(q)):
                return -1, 0
            margin = 1e-12 * (1.0 + q / below)
            low_bound, high_bound = (below - q) / below - margin, (above - q) / above + margin
            lows[t, k] = low_bound
            if high_bound < least_high:
                chosen, at, least_high = t, k, high_bound
    if chosen < 0:
        return -1, 0
    for t in range(len(sizes)):
        for k in range(windows):
            if (t != chosen or k != at) and not lows[t, k] > least_high:
                return -1, 0
    return chosen, at


@jit(inline="always")
def _window_energy(rest, low, k, windows, length, middle):
    """The energy of ``rest`` over ``length`` samples from ``low + k``: ``middle`` (its samples from
    ``low + windows - 1`` to ``low + length``) and the few before and after."""
    own = middle
    for j in range(low + k, low + windows - 1):
        own += rest[j] * rest[j]
    for j in range(low + length, low + length + k):
        own += rest[j] * rest[j]
    return own


@jit(inline="always")
def _squares(x, first, last):
    """The sum of ``x[first:last]``'s squares in 32 lanes (an order of its own: eight vectors of four side by side, the
    samples left over in a chain of their own)."""
    s0 = s1 = s2 = s3 = s4 = s5 = s6 = s7 = _quad(0.0)
    j = first
    while j + 32 <= last:
        v0, v1, v2, v3 = _load(x, j), _load(x, j + 4), _load(x, j + 8), _load(x, j + 12)
        v4, v5, v6, v7 = _load(x, j + 16), _load(x, j + 20), _load(x, j + 24), _load(x, j + 28)
        s0, s1 = _plus_times(s0, v0, v0), _plus_times(s1, v1, v1)
        s2, s3 = _plus_times(s2, v2, v2), _plus_times(s3, v3, v3)
        s4, s5 = _plus_times(s4, v4, v4), _plus_times(s5, v5, v5)
        s6, s7 = _plus_times(s6, v6, v6), _plus_times(s7, v7, v7)
        j += 32
    rest = 0.0
    while j < last:
        rest += x[j] * x[j]
        j += 1
    return (((_sum_of_lanes(s0) + _sum_of_lanes(s1)) + (_sum_of_lanes(s2) + _sum_of_lanes(s3)))
            + ((_sum_of_lanes(s4) + _sum_of_lanes(s5)) + (_sum_of_lanes(s6) + _sum_of_lanes(s7)))) + rest


_BLOCK = 256  # samples a time: a dozen notes' waveforms over them stay in the first-level cache


@jit
def layer_median(x, at, scales, whole, clean):
    """:func:`.onsets._layer_template`'s median: note ``i``'s waveform is ``x[at[i]:at[i] + whole[i]] / scales[i]``
    (``at`` ≥ 0, ``at + whole`` ≤ ``len(x)``), clean over its first ``clean[i]`` samples (``clean`` ≤ ``whole``).

    Over each part between the sorted, distinct values of 0, ``whole`` and ``clean``, the waveforms that last past
    it (three or more), else the clean ones that do, are the part's; at each sample the median of theirs (the
    middle one, or the mean of the middle two as ``np.median`` takes it); up to the first part none lasts over.
    """
    count = len(at)
    bounds = np.unique(np.concatenate((np.zeros(1, dtype=np.int64), whole, clean)))
    out = np.empty(bounds[-1])
    chosen, buffer = np.empty(count, dtype=np.int64), np.empty((count, _BLOCK))
    size = 0
    for p in range(len(bounds) - 1):
        low, high = bounds[p], bounds[p + 1]
        voted = 0
        for i in range(count):
            voted += whole[i] >= high
        m = 0
        for i in range(count):
            if (whole[i] >= high) if voted >= 3 else (clean[i] >= high):
                chosen[m] = i
                m += 1
        if m == 0:
            break
        for first in range(low, high, _BLOCK):
            _block_median(x, at, scales, chosen[:m], first, min(first + _BLOCK, high), buffer, out)
        size = high
    return out[:size].copy()


@jit
def _block_median(x, at, scales, chosen, first, last, buffer, out):
    """``out[first:last]``: at each sample the median of the waveforms ``chosen`` (:func:`layer_median`'s), their values
    sorted by an odd-even transposition network (each comparator a pass over the block, in vector instructions)."""
    m, width = len(chosen), last - first
    for r in range(m):
        i = chosen[r]
        row, scale = buffer[r], scales[i]
        for j in range(width):
            row[j] = x[at[i] + first + j] / scale
    for step in range(m):
        for r in range(step % 2, m - 1, 2):
            lower, upper = buffer[r], buffer[r + 1]
            for j in range(width):
                u, v = lower[j], upper[j]
                swap = v < u  # swapped only when out of order: the values are kept, the signs of zero too
                lower[j], upper[j] = (v, u) if swap else (u, v)
    middle = buffer[m // 2]
    if m % 2:
        for j in range(width):
            out[first + j] = middle[j]
    else:
        below = buffer[m // 2 - 1]
        for j in range(width):
            out[first + j] = (below[j] + middle[j]) / 2.0


@jit
def fitted_attacks(remainder, template, head, times, kinds, likeness, lead_clear, start_clear, pre, reach, gap,
                   shortest, longest, offset, fit_likeness, precise, burst_width, echo, burst_least, width, back, rise,
                   least, head_energy):
    """:func:`.onsets._fit_template`'s loop over the attacks at ``times`` (full-rate samples, increasing; their
    ``kinds``, ``likeness`` and whether each is clear by ``lead_clear_db`` and ``start_clear_db``), the template fitted
    and taken off ``remainder`` (the band, in place) in time order: each attack's time, kind, likeness and whether the
    template fitted it [each shape=(m,)].

    A queue of attacks to fit (its front last here). Each is fitted where :func:`._kernels.best_lag` puts the
    template's first ``span`` samples (``shortest`` to ``longest``, up to the next detection more than ``gap`` after
    it) within ``reach`` either way, and timed there (``offset`` on) as :func:`.onsets._fit_template` says; the
    detections of ``times`` within ``echo`` samples after an attack it timed whose energy over ``burst_width`` samples
    taking it off leaves under ``burst_least`` of what was there are that attack's own bursts, dropped, and so are the
    detections within ``gap`` after it (and ``reach`` more after one found here); then the first sample after it
    where the remainder rises and the ``head`` fits (:func:`next_attack`: ``width``, ``back``, ``rise``,
    ``fit_likeness``, ``least``, ``head_energy``) is a new attack to fit next. The energies are numpy's ``@``
    (:func:`blas_lag_dots`); tests/test_onsets_speed_kernels.py holds the loop against it in Python.
    """
    count = len(times)
    # the queue, its front at the end: (time, index in times or -1 for an attack found here)
    queue_t, queue_i = np.empty(count + 1), np.empty(count + 1, dtype=np.int64)
    for n in range(count):
        queue_t[count - 1 - n], queue_i[count - 1 - n] = times[n], n
    size = count
    out_t, out_k, out_l = np.empty(2 * count + 1), np.empty(2 * count + 1, dtype=np.int64), np.empty(2 * count + 1)
    out_f = np.empty(2 * count + 1, dtype=np.bool_)
    found = 0
    one = np.empty(1)
    burst_at, burst_energy = np.empty(count, dtype=np.int64), np.empty(count)
    while size > 0:
        size -= 1
        t, i = queue_t[size], queue_i[size]
        c = int(np.rint(t))
        following = len(remainder)
        for q in range(size - 1, -1, -1):
            if queue_t[q] > t + gap:
                following = int(np.rint(queue_t[q]))
                break
        span = min(max(shortest, min(longest, following - c)), len(template))
        # the template's fit: its best lag, scale and correlation
        lag, scale, like = 0, 0.0, 0.0
        start = c - pre
        low, high = max(0, start - reach), min(len(remainder), start + reach + span)
        if high - low >= span:
            blas_lag_dots(template, 0, 1, template, span, one)
            energy = one[0]
            k, dot, like = best_lag(remainder, template[:span], low, high - low - span + 1, energy)
            lag, scale = low + k - start, dot / energy
        fitted = like >= fit_likeness and scale > 0.0
        # clear by start_clear_db, its first transient was sought; clear by lead_clear_db only, it was not, and the
        # template times it when the fit is precise (noise as loud as that sound before makes fits imprecise)
        timed = fitted and (i < 0 or not lead_clear[i] or (like >= precise and not start_clear[i]))
        if found == len(out_t):  # more attacks found here than the room made for them
            out_t, out_k = np.concatenate((out_t, out_t)), np.concatenate((out_k, out_k))
            out_l, out_f = np.concatenate((out_l, out_l)), np.concatenate((out_f, out_f))
        out_t[found] = c + lag + offset if timed else t
        out_k[found] = 3 if timed else kinds[i]  # (kinds[-1] for a new one unfitted, as the list's index took it)
        out_l[found] = like if i < 0 else likeness[i]
        out_f[found] = fitted
        found += 1
        if not fitted:
            continue
        at = c + lag
        start = at - pre
        bursts = 0  # the detections close after an attack it timed: their energy before it is taken off
        if timed:
            for q in range(size - 1, -1, -1):
                u = queue_t[q]
                if queue_i[q] >= 0 and at < u <= at + echo:
                    k = int(np.rint(u))
                    blas_lag_dots(remainder, k, 1, remainder[k:], max(0, min(burst_width, len(remainder) - k)), one)
                    burst_at[bursts], burst_energy[bursts] = k, one[0]
                    bursts += 1
        fit = remainder[start:start + min(len(template), len(remainder) - start)]  # taken off, in place
        for j in range(len(fit)):
            fit[j] += -scale * template[j]
        if bursts:  # those whose energy taking it off explains are its own bursts, dropped
            kept = 0
            for q in range(size):
                own = False
                if queue_i[q] >= 0:
                    k = int(np.rint(queue_t[q]))
                    for b in range(bursts):
                        if burst_at[b] == k:
                            blas_lag_dots(remainder, k, 1, remainder[k:], max(0, min(burst_width, len(remainder) - k)),
                                          one)
                            own = one[0] < burst_energy[b] * burst_least
                            break
                if not own:
                    queue_t[kept], queue_i[kept] = queue_t[q], queue_i[q]
                    kept += 1
            size = kept
        # the same attack found twice; a detection after an attack only the template found is its late time up to the
        # reach the template seeks over (as in onsets._one_attack_each), the gap after it
        while timed and size > 0 and queue_t[size - 1] < at + gap + (reach if i < 0 else 0):
            size -= 1
        # a new attack after it, where the remainder rises and the head fits
        low, high = at + gap, min(following - gap, start + len(template))
        high = min(high, len(remainder) - len(head) + pre)
        if high > low >= pre:
            new = next_attack(remainder, head, low, high, pre, reach, max(0, low - back), width, head_energy, rise,
                              fit_likeness, least)
            if new >= 0:
                queue_t[size], queue_i[size] = new + offset, -1
                size += 1
    return out_t[:found].copy(), out_k[:found].copy(), out_l[:found].copy(), out_f[:found].copy()
