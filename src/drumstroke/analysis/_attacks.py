"""The compiled loop of :func:`.onsets._template_search`: attacks found by fitting the recording's own attack.

A module of its own (as :mod:`._kernels`) so that importing :mod:`drumstroke.analysis` does not import numba;
:mod:`.onsets` imports it where it runs it. Its sums run in another order than numpy's (``np.correlate``, ``@``):
the same to rounding.
"""

import math

import numpy as np

from .._jit import jit
from ._kernels import window_dots


@jit(error_model="numpy")
def template_search(remainder, template, head, times, shifts, refused, offset, layer_at, layer_size, pre, gap,
                    shortest, fit, bounce, echo, signature, reach, likeness, refused_likeness, ratio_low, ratio_high,
                    least, burst, earlier, unclear, weak, start_likeness, layer_likeness, bursts=1, unfitted=0.0,
                    layer_whole=1.0, flight=0, layer_start=0, layer_joint=1.0, joint_flight=0, joint_train=0,
                    past=0, train=0, jitter=0, train_found=0, found_bursts=0, train_refit=0, skipped_search=0):
    """:func:`.onsets._template_search`'s loop over the attacks at ``times`` (full-rate samples, in order).

    ``remainder`` (the band, changed in place) less each attack's fitted ``template`` (``pre`` samples before its
    attack; ``head`` its start), each at ``times`` less ``shifts`` (rounded: an attack the template timed at its
    fit's sample, ``offset`` the template's attack less its whole sample); ``refused`` the onsets step 4 refused
    (samples, in order); ``gap``, ``shortest`` (the shortest fit), ``fit``, ``bounce``, ``echo``, ``signature`` and
    ``reach`` in samples. The attack ``layer_at`` (an index in ``times``; -1 for none) is another velocity layer's:
    what is left there when the loop reaches it, its own ``layer_size`` samples from ``pre`` before it, continued by
    the template (:func:`continued`), is the layer's template, and each attack from there on is taken off by the
    one of the two that fits it better (:func:`_take_off`); the search after it is the template's still. A
    detection within ``bounce`` after an attack that neither fits (what is left of the earlier sound, or an attack
    the modes' band placed early) ends neither that attack's fit nor the search after it: a bounce found up to
    ``echo`` after the detection is that attack, and the detection is dropped; so is a detection that taking off the
    attack before it (fitted up to it, or up to the one after) leaves less than ``burst`` of the energy over the
    ``shortest`` samples after it (its own second burst: FluidR3's electric snare bursts again 3.4 ms into a note;
    0: none is), and after it up to ``bursts`` in a row within ``earlier`` samples of the attack (:func:`_later_bursts`;
    where the attack's fit cut at the first correlates under ``likeness``, by the template alone, fitted past them;
    ``bursts`` 1, its default: the first only); after those, the next detection, ``unclear`` and within ``bounce``,
    where the attack's sound correlates under ``unfitted`` (0, its default: not tested), ends not its fit either (fitted
    up to the one after, as for the first). A detection of ``times`` flagged ``unclear`` (over earlier sound), not one the template timed, may
    be its sound's later burst, its start not detected: up to ``earlier`` samples before it (0: not sought), where
    the template fits better (:func:`_earlier_start`, its start correlating by ``weak`` there), the attack is put,
    the detection dropped. The search for a bounce after an attack asks the template's start to correlate by
    ``start_likeness`` only and the template over ``fit`` samples by ``likeness`` (a quiet velocity layer's start is
    unlike the loud one's); after an attack ``layer`` took off, within ``bounce`` after the attack before it, where the
    template finds none, the search is made with ``layer`` (its first ``fit`` samples by ``layer_likeness``, its start
    by ``weak``, scaled re that attack's fit by the layer; ``layer_likeness`` 1: not made; where that finds none either,
    or one past the next bounce's time, after a flight of ``flight`` samples or less, the layer's first ``fit`` samples
    alone by ``layer_whole`` a half to one and a half times that flight on, :func:`_whole_after`; ``layer_whole`` 1,
    its default: not sought; where that finds none, after a flight of ``joint_train`` samples or less, the attack
    fitted again with ``layer`` at each sample, ``joint_flight`` samples on or more, by ``layer_joint``,
    :func:`_joint_after`, not after an attack so found; ``layer_joint`` 1, its default: not sought), and before the
    loop reaches
    ``layer_at`` the layer is its sound as recorded (not yet what is left there; with ``layer_likeness`` 1 there is
    none before it). A detection flagged ``unclear``, not one the template timed, within ``bounce`` after the attack
    before it, is put where ``layer`` fits best up to ``layer_start`` samples before it (:func:`_layer_start`; 0, its
    default: not sought), and one up to ``layer_start`` samples after a bounce found is that bounce (dropped). A
    bounce is sought past ``bounce`` after an attack (``past`` 0 and ``train`` 0, their defaults, or ``bounce`` 0:
    not): up to ``past`` after a detection the attack's fit looked past or dropped as its own sound; and where none
    is found, after a bounce of a train (the flight before ``train`` samples or less, no longer than the flight
    before it nor shorter than two thirds of it, the bounce's fitted scale at most 1 dB over the one before), from
    0.7 times that flight on to the flight plus ``jitter`` samples on (a drop's flights shrink). With
    ``train_refit`` (0, its default: none), once the next bounce is found the last ``train_refit`` bounces ``layer``
    took off, each ``flight`` samples or less after the one before, are fitted again together with it up to one
    flight after it (:func:`_refit`); with ``train_found`` (0, its default: not), a bounce ``layer``'s searches
    found is taken off by ``layer`` and the next one's window reads the mean of the two flights before where that is
    longer; with ``skipped_search`` (0, its default: not), where the template's search finds a bounce past a
    detection this attack's fit skipped, after an attack ``layer`` took off, ``layer``'s search is made first up to
    that detection; with ``found_bursts`` (0, its default: not), a detection ``unclear``, not timed, within
    ``earlier`` after a bounce the search found after one ``layer`` took off, where the cut fit correlates under
    ``likeness``, is dropped where ``layer`` fitted past it correlates by ``likeness`` and at the detection does
    not. Returns the attacks found (their
    times, in order), each one's correlation and which of ``times`` are dropped [shape=(len(times),)].
    """
    n, size = len(remainder), len(template)
    head_energy, layer = _dot(head, 0, head, len(head)), np.zeros(0)
    if layer_at >= 0 and layer_likeness < 1.0:
        # the layer's sound as recorded, for the attacks before the loop reaches it (a drop's first train of close
        # bounces may come before its quietest clear attack)
        q = int(np.rint(times[layer_at] - shifts[layer_at]))
        if q >= pre:
            layer = continued(remainder[q - pre:q - pre + min(layer_size, n - q + pre)].copy(), template, fit)
    most = n // max(gap, 1) + 1 + len(times)  # each new one gap after, each moved one of times
    found, likes, count = np.empty(most), np.empty(most), 0
    dropped = np.zeros(len(times), dtype=np.bool_)
    i, pending, last, joined, by_joint = 0, -1, -n, False, False
    previous = -n
    loudness = 0.0  # the attack before's fitted scale
    kept, train_at, train_scale = 0, np.zeros(max(train_refit, 1), dtype=np.int64), np.zeros(max(train_refit, 1))
    layered, by_layer_search, searched, was_layer, by_layer = False, False, False, False, False
    while True:
        joined, by_joint = by_joint, False  # whether this attack is one the joint fit found
        layered, by_layer_search = by_layer_search, False  # whether this attack is one the layer's searches found
        was_layer, searched = by_layer, pending >= 0
        if pending >= 0:
            c, pending = pending, -1  # where the template's attack fell
        elif i < len(times):
            c, i = int(np.rint(times[i] - shifts[i])), i + 1
            if i - 1 == layer_at and c >= pre:
                layer = continued(remainder[c - pre:c - pre + min(layer_size, n - c + pre)], template, fit)
            if earlier > 0 and unclear[i - 1]:
                following = int(np.rint(times[i] - shifts[i])) if i < len(times) else n
                start, like = _earlier_start(remainder, template, head, head_energy, c, max(last + gap, c - earlier),
                                             c - gap, following, pre, shortest, fit, reach, likeness, weak)
                if start >= 0:  # the detection was the attack's own later burst, its start hidden
                    dropped[i - 1], c = True, start
                    found[count], likes[count], count = start + offset, like, count + 1
                elif layer_start > 0 and len(layer) > 0 and shifts[i - 1] == 0.0 and c - last <= bounce:
                    # a train's quiet bounce detected on its main rise (FluidR3's snare 40: 0.9 ms late): the layer's
                    # sound, not the loud template's, fits it best where it starts
                    start, like = _layer_start(remainder, layer, c, max(last + gap, c - layer_start), following, pre,
                                               shortest, fit, likeness)
                    if start >= 0:
                        dropped[i - 1], c = True, start
                        found[count], likes[count], count = start + offset, like, count + 1
        else:
            break
        earlier_c, previous, last = previous, last, c
        following = int(np.rint(times[i] - shifts[i])) if i < len(times) else n
        detection = following
        if c < pre or min(max(pre + shortest, min(pre + fit, following - c)), size, n - c + pre) <= pre:
            continue
        close = i < len(times) and following < c + bounce
        if close and earlier > 0 and unclear[i] and following - c <= earlier:
            # a detection this attack's own later burst: the attack's template fits over it better than one there
            after = int(np.rint(times[i + 1] - shifts[i + 1])) if i + 1 < len(times) else n
            span = min(max(pre + shortest, min(pre + fit, after - c)), size, n - c + pre)
            whole = _likeness(remainder, c - pre, template, span)
            if (whole >= likeness and following - pre - reach >= 0
                    and not _fits_near(remainder, template, following, after, pre, shortest, fit, reach, whole)):
                dropped[i], i, following = True, i + 1, after
                detection = following
                close = i < len(times) and following < c + bounce
        heard = _energy(remainder, following, shortest) if close and burst > 0.0 else 0.0
        own, at_c, scale, measured, fitted, by_layer = _take_off(remainder, template, layer, c, following, pre, shortest,
                                                                 fit)
        skipped = False
        if fitted < likeness and close and burst > 0.0 and bursts > 1:
            # a reverberant room's sound under the attack: its fit cut at a detection on its own main rise reads low
            # (FluidR3's snare 40 with reverb: 0.62 over 1.5 ms, 0.96 over 10 ms); fitted past it instead, where that
            # explains the detection (by the template alone: the layer's sound, cut at a detection placed early,
            # fits a note of its layer as well there as at its start: a FluidR3 flam's grace note, 2 ms early)
            more, following, own, at_c, scale, measured, fitted, by_layer = _later_bursts(
                remainder, template, layer[:0], times, shifts, i, c, following, own, at_c, scale, measured, fitted,
                by_layer, pre, shortest, fit, min(bounce - 1, earlier), likeness, burst, bursts)
            if more > 0:
                dropped[i:i + more], i, detection, heard = True, i + more, following, 0.0
                close = i < len(times) and following < c + bounce
        if (found_bursts and searched and was_layer and fitted < likeness and close and len(layer) > 0
                and unclear[i] and shifts[i] == 0.0 and following - c <= earlier):
            # a train's bounce the search found, a detection on its rise: the layer fitted past it
            after = int(np.rint(times[i + 1] - shifts[i + 1])) if i + 1 < len(times) else n
            _add(remainder, own, at_c, scale, pre)
            tried = _take_off(remainder, template, layer, c, after, pre, shortest, fit)
            _add(remainder, tried[0], tried[1], tried[2], pre)
            here = min(max(pre + shortest, min(pre + fit, after - following)), len(layer))
            if tried[4] >= likeness and _layer_fit(remainder, layer, following, pre, here)[1] < likeness:
                _add(remainder, tried[0], tried[1], -tried[2], pre)
                own, at_c, scale, measured, fitted, by_layer = tried
                dropped[i], i, following = True, i + 1, after
                detection = following
                close = i < len(times) and following < c + bounce
            else:
                _add(remainder, own, at_c, -scale, pre)
        if fitted >= likeness and close:
            # a detection close after that neither template fits is no end to this attack's sound: fitted up to the
            # one after instead (a FluidR3 drop's fit cut at 3.7 ms left a bounce at -21 dB two-thirds on); nor is
            # one that taking this attack off leaves burst or less of (a recorded sample's second burst)
            after = int(np.rint(times[i + 1] - shifts[i + 1])) if i + 1 < len(times) else n
            width = min(max(pre + shortest, min(pre + fit, after - following)), len(own), n - following + pre)
            own_burst = _energy(remainder, detection, shortest) < heard * burst
            if width > pre and (own_burst or _likeness(remainder, following - pre, own, width) < likeness):
                _add(remainder, own, at_c, scale, pre)
                own, at_c, scale, measured, fitted, by_layer = _take_off(remainder, template, layer, c, after, pre,
                                                                         shortest, fit)
                skipped, following = True, after
                if own_burst or _energy(remainder, detection, shortest) < heard * burst:
                    dropped[i], i, skipped = True, i + 1, False  # the detection was this attack's own second burst
                    more, following, own, at_c, scale, measured, fitted, by_layer = _later_bursts(
                        remainder, template, layer, times, shifts, i, c, following, own, at_c, scale, measured,
                        fitted, by_layer, pre, shortest, fit, min(bounce - 1, earlier), likeness, burst, bursts - 1)
                    dropped[i:i + more], i = True, i + more
                    if unfitted > 0.0 and i < len(times) and following < c + bounce and unclear[i]:
                        # the next detection, over earlier sound and not timed by the template, tested as the first
                        # was: one the attack's sound does not fit ends not its fit (FluidR3's snare 40 with reverb:
                        # the next bounce's detection in the modes' band, 1.3 ms late, fits by 0.0)
                        after = int(np.rint(times[i + 1] - shifts[i + 1])) if i + 1 < len(times) else n
                        width = min(max(pre + shortest, min(pre + fit, after - following)), len(own), n - following + pre)
                        if width > pre and _likeness(remainder, following - pre, own, width) < unfitted:
                            _add(remainder, own, at_c, scale, pre)
                            own, at_c, scale, measured, fitted, by_layer = _take_off(remainder, template, layer, c,
                                                                                     after, pre, shortest, fit)
                            skipped, detection, following = True, following, after
        if train_found and layered and not by_layer and len(layer) > 0 and c >= pre:
            # a bounce the layer's search found is the layer's: taken off by it, the train's search goes on with it
            _add(remainder, own, at_c, scale, pre)
            lspan = min(max(pre + shortest, min(pre + fit, following - c)), len(layer), n - c + pre)
            lag, _ = _layer_fit(remainder, layer, c, pre, lspan)
            lspan = min(lspan, n - c - lag + pre)
            own, at_c, by_layer = layer, c + lag, True
            scale = _dot(remainder, at_c - pre, own, lspan) / _dot(own, 0, own, lspan)
            _add(remainder, own, at_c, -scale, pre)
        c = at_c
        at, like = -1, 0.0
        if measured > 0.0:
            high = min(following - gap, c + bounce, n - len(head) + pre)
            if past > 0 and bounce > 0 and detection < following:
                # the detection looked past or dropped was this attack's sound, or the next bounce placed early
                # (FluidR3's snare 38 with reverb: 6 ms early, 23 ms after the attack; the bounce 29 ms after it)
                high = min(following - gap, max(c + bounce, detection + past), n - len(head) + pre)
            at, like = _bounce_after(remainder, template, head, head_energy, c + gap, high, following, pre, shortest,
                                     fit, reach, measured, likeness, ratio_low, ratio_high, start_likeness)
            if at < 0 and by_layer and layer_likeness < 1.0 and c - previous <= bounce:
                # a quiet note taken off by the layer's template: the next bounce is likely that layer's too, whose
                # start the loud template's does not fit (FluidR3's snare 38: 0.62 at a drop's bounce, 6.7 ms on)
                at, like = _bounce_after(remainder, layer, layer[:len(head)], _dot(layer, 0, layer, len(head)),
                                         c + gap, high, following, pre, shortest, fit, reach, scale, layer_likeness,
                                         ratio_low, ratio_high, weak)
                by_layer_search = at >= 0
            elif (skipped_search and skipped and at > detection and by_layer and layer_likeness < 1.0
                    and c - previous <= bounce):
                # the template's bounce past a detection this attack's fit skipped (which would be dropped as that
                # bounce placed early): the layer's own search up to the detection first, the detection a quiet
                # bounce's later burst whose start the template's does not fit (FluidR3's snare 40 with reverb:
                # a detection 3.8 ms into a bounce, the template's next 9.3 ms on)
                early, early_like = _bounce_after(remainder, layer, layer[:len(head)], _dot(layer, 0, layer, len(head)),
                                                  c + gap, min(high, detection - gap), following, pre, shortest, fit,
                                                  reach, scale, layer_likeness, ratio_low, ratio_high, weak)
                if early >= 0:
                    at, like, by_layer_search = early, early_like, True
            longest = c - previous  # the flight the next one's is read against
            if train_found and earlier_c > -n and c - earlier_c <= 2 * flight:
                longest = max(longest, (c - earlier_c) // 2)  # two flights: one's block jitter undone by the next
            if (layer_whole < 1.0 and by_layer and layer_likeness < 1.0 and c - previous <= flight
                    and (at < 0 or at > c + (3 * longest) // 2)):
                # none found, or one past the next bounce's time: the next one's start under the room's sound or the
                # earlier bounce's (the quiet layer peaks 9.4 ms in), a half to one and a half times the flight
                # before on (a drop's flights shrink, FluidSynth's blocks jitter them by 1.3 ms)
                early, early_like = _whole_after(remainder, layer, max(c + gap, c + (c - previous) // 2),
                                                 min(high, c + (3 * longest) // 2 + 1), following, pre, fit,
                                                 reach, scale, layer_whole, ratio_low, ratio_high)
                if early >= 0:
                    at, like, by_layer_search = early, early_like, True
                elif layer_joint < 1.0 and not joined and c - previous <= joint_train:
                    # the bounce before's sound fitted again with the next one's, least squares (its own fit, over
                    # the layer's first fit samples, took in some of the next bounce's)
                    early, early_like = _joint_after(remainder, own, at_c, scale, layer,
                                                     max(c + gap, c + (c - previous) // 2, c + joint_flight),
                                                     min(high, c + (3 * longest) // 2 + 1), following, pre,
                                                     fit, reach, layer_joint, ratio_low, ratio_high)
                    if early >= 0:
                        at, like, by_joint, by_layer_search = early, early_like, True, True
        if (at < 0 and measured > 0.0 and bounce > 0 and c - previous <= train and c - previous <= previous - earlier_c
                and 2 * (previous - earlier_c) <= 3 * (c - previous) and measured <= 1.12 * loudness):
            # a train's next bounce past the usual reach, where the flight before says it is (a drop's flights
            # shrink, its bounces fade: a flam's main note is louder than its grace note, and a room's returns
            # are not so spaced); step 4 found none there (FluidR3's snare 38 with reverb: 26-30 ms flights)
            low = max(c + gap, c + bounce, c + (7 * (c - previous)) // 10)
            high = min(following - gap, c + (c - previous) + jitter, n - len(head) + pre)
            if high > low:
                at, like = _bounce_after(remainder, template, head, head_energy, low, high, following, pre, shortest,
                                         fit, reach, measured, likeness, ratio_low, ratio_high, start_likeness)
        loudness = measured
        if skipped and at > detection:
            if at - detection <= echo:  # the detection was this bounce placed early
                dropped[i], i = True, i + 1
            else:
                at = -1
        if at < 0:
            at, like = _refused_fit(remainder, template, head, head_energy, refused, c + signature,
                                    min(detection - gap, n - len(head) + pre), pre, fit, reach, refused_likeness,
                                    least)
        if (layer_start > 0 and at >= 0 and i < len(times) and unclear[i] and shifts[i] == 0.0
                and 0 < int(np.rint(times[i])) - at <= layer_start):
            dropped[i], i = True, i + 1  # the next detection is this bounce on its main rise: no attack of its own
        if train_refit:
            # the train of close bounces the layer took off, this one last
            if not (by_layer and at_c >= pre):
                kept = 0
            else:
                if not (kept > 0 and at_c - train_at[kept - 1] <= flight):
                    kept = 0
                if kept == len(train_at):
                    train_at[:-1], train_scale[:-1], kept = train_at[1:].copy(), train_scale[1:].copy(), kept - 1
                train_at[kept], train_scale[kept], kept = at_c, scale, kept + 1
            if at >= 0 and kept > 0 and at - at_c <= flight:
                # the next bounce found: the train's scales fitted again together with it (least squares from the
                # first one's window to the end of the next one's first fit samples, up to one flight after it, where
                # the bounce after it may sound: each one's own fit took in some of the next one's sound)
                _refit(remainder, layer, train_at[:kept], train_scale[:kept], at, min(following, at + (at - at_c)),
                       pre, fit)
        if at >= 0:
            pending = at
            found[count], likes[count], count = at + offset, like, count + 1
    return found[:count].copy(), likes[:count].copy(), dropped


@jit(error_model="numpy")
def _refit(remainder, layer, at, scales, after, following, pre, fit):
    """The attacks at ``at`` (``layer`` times ``scales``, taken off ``remainder``) taken off again with their scales
    fitted together with ``layer`` at ``after`` (least squares from ``pre`` before the first to the end of
    ``layer``'s first ``fit`` samples at ``after``, up to ``following``), in place, ``scales`` updated; kept as they
    were where a scale so fitted is not positive."""
    n, m = len(remainder), len(at) + 1
    start = at[0] - pre
    end = min(after - pre + min(pre + fit, len(layer)), following, n)
    if end - start <= 0 or end - start > len(layer) or start < 0:
        return
    y = remainder[start:end].copy()
    for i in range(m - 1):
        for j in range(at[i] - pre - start, end - start):
            y[j] += scales[i] * layer[j - (at[i] - pre - start)]
    basis = np.zeros((m, end - start))
    for i in range(m):
        first = (at[i] if i < m - 1 else after) - pre - start
        for j in range(first, end - start):
            basis[i, j] = layer[j - first]
    gram = basis @ basis.T
    if np.linalg.det(gram) <= 0.0:
        return
    x = np.linalg.solve(gram, basis @ y)
    for i in range(m - 1):
        if not x[i] > 0.0:
            return
    for i in range(m - 1):
        _add(remainder, layer, at[i], scales[i] - x[i], pre)
        scales[i] = x[i]


@jit(error_model="numpy")
def _later_bursts(remainder, template, layer, times, shifts, i, c, following, own, at_c, scale, measured, fitted,
                  by_layer, pre, shortest, fit, reach, likeness, burst, most):
    """After a detection dropped as the attack at ``c``'s own sound (its fit, ``own`` at ``at_c`` times ``scale``,
    taken off ``remainder`` up to ``following``, the detection ``times[i]`` there): how many of the next detections
    up to ``reach`` samples after it, up to ``most``, are its own sound too (each: taking off the attack fitted past
    it, by ``likeness``, leaves under ``burst`` of the energy over the ``shortest`` samples after it; FluidR3's
    electric snare: a detection on the note's main rise, 1 ms in, then its second burst, 3.4 ms in). Returns that
    count, and the fit's end and :func:`_take_off`'s outputs past them (as given for none)."""
    n, count = len(remainder), 0
    low, high = max(0, c - pre - _LAYER_LAG), min(n, c - pre + _LAYER_LAG + len(template))
    while count < most and i + count < len(times) and following - c <= reach:
        j = i + count
        after = int(np.rint(times[j + 1] - shifts[j + 1])) if j + 1 < len(times) else n
        saved = remainder[low:high].copy()
        _add(remainder, own, at_c, scale, pre)
        heard = _energy(remainder, following, shortest)
        tried = _take_off(remainder, template, layer, c, after, pre, shortest, fit)
        if not (tried[4] >= likeness and _energy(remainder, following, shortest) < heard * burst):
            remainder[low:high] = saved
            break
        own, at_c, scale, measured, fitted, by_layer = tried
        following, count = after, count + 1
    return count, following, own, at_c, scale, measured, fitted, by_layer


@jit(error_model="numpy")
def continued(own, template, settle):
    """An attack's sound ``own`` (samples) continued to ``template``'s length by the template's samples, scaled to it
    by least squares over their common part after ``settle`` samples (``own`` cut there when longer).

    A recorded sample's velocity layers differ in their first 10 ms (FluidR3's snares: 0.92-0.96 correlated there,
    0.99 after, the drum's modes): a note's own sound, cut by the next note 50-100 ms on, is still -23 dB re its first
    10 ms at 100 ms, as loud as a drop's last bounces 4-8 ms apart under it."""
    out = template.copy()
    common = min(len(own), len(template))
    out[:common] = own[:common]
    if settle < common < len(template):
        energy = _dot(template[settle:], 0, template[settle:], common - settle)
        scale = _dot(own[settle:], 0, template[settle:], common - settle) / energy if energy > 0.0 else 0.0
        for j in range(common, len(template)):
            out[j] = scale * template[j]
    return out


_BOUNCE_CHUNK = 64  # windows summed at a time by _bounce_after's scan

_LAYER_LAG = 2  # samples: two velocity layers' attacks, each at its template's sample, may differ by a sample or two


@jit(error_model="numpy")
def _take_off(remainder, template, layer, c, following, pre, shortest, fit):
    """The attack at ``c`` fitted (least squares over ``fit`` samples up to ``following``, ``shortest`` or more) and
    taken off ``remainder`` by ``template`` or, where it correlates better, by ``layer`` (within ``_LAYER_LAG``
    samples). Returns what was taken off (the samples, its attack's sample, its scale), the template's own scale
    there (what a bounce after is compared with), the fit's correlation and whether ``layer`` took it off."""
    n = len(remainder)
    span = min(max(pre + shortest, min(pre + fit, following - c)), len(template), n - c + pre)
    dot, own_energy, energy = _sums(remainder, c - pre, template, span)
    fitted = dot / math.sqrt(max(own_energy * energy, 1e-300))  # _likeness's
    measured = dot / energy
    own, at, scale, by_layer = template, c, measured, False
    lag, like = _layer_fit(remainder, layer, c, pre, min(span, len(layer)))
    # the template's correlation over as many samples (the fit's, summed already, where the layer is as long)
    if like > (fitted if len(layer) >= span else _likeness(remainder, c - pre, template, min(span, len(layer)))):
        own, at, fitted, by_layer = layer, c + lag, like, True
        span = min(span, len(layer), n - at + pre)
        scale = _dot(remainder, at - pre, own, span) / _dot(own, 0, own, span)
    _add(remainder, own, at, -scale, pre)
    return own, at, scale, measured, fitted, by_layer


@jit(error_model="numpy")
def _add(remainder, own, c, scale, pre):
    """``remainder`` plus ``own`` times ``scale``, its attack (``pre`` samples in) at ``c``, in place."""
    for j in range(min(len(own), len(remainder) - c + pre)):
        remainder[c - pre + j] += scale * own[j]


@jit(error_model="numpy")
def _layer_fit(remainder, layer, c, pre, span):
    """``layer``'s best correlation with ``remainder`` at ``c`` (its attack ``pre`` samples in) within ``_LAYER_LAG``
    samples over ``span`` samples: (lag, correlation), or (0, -1) for no layer.

    Each lag's correlation is :func:`_likeness`'s (its sums each in order), the five lags' sums side by side in one
    pass (their additions do not wait on each other; the layer's energy, the same at each lag, summed once)."""
    if span <= pre or c - pre - _LAYER_LAG < 0 or c - pre + _LAYER_LAG + span > len(remainder):
        return 0, -1.0
    start = c - pre - _LAYER_LAG  # lag -2 (_LAYER_LAG: 2)
    d0, d1, d2, d3, d4 = 0.0, 0.0, 0.0, 0.0, 0.0
    o0, o1, o2, o3, o4 = 0.0, 0.0, 0.0, 0.0, 0.0
    energy = 0.0
    for j in range(span):
        b = layer[j]
        a0, a1, a2, a3, a4 = (remainder[start + j], remainder[start + j + 1], remainder[start + j + 2],
                              remainder[start + j + 3], remainder[start + j + 4])
        d0 += a0 * b
        d1 += a1 * b
        d2 += a2 * b
        d3 += a3 * b
        d4 += a4 * b
        o0 += a0 * a0
        o1 += a1 * a1
        o2 += a2 * a2
        o3 += a3 * a3
        o4 += a4 * a4
        energy += b * b
    dots, owns = np.array((d0, d1, d2, d3, d4)), np.array((o0, o1, o2, o3, o4))
    best, best_like = 0, -1.0
    for lag in range(-_LAYER_LAG, _LAYER_LAG + 1):
        like = dots[lag + _LAYER_LAG] / math.sqrt(max(owns[lag + _LAYER_LAG] * energy, 1e-300))
        if like > best_like:
            best, best_like = lag, like
    return best, best_like


@jit(error_model="numpy")
def _likeness(x, start, t, count):
    """The correlation of ``t[:count]`` with ``x`` from ``start`` (0 for no samples)."""
    if count <= 0:
        return 0.0
    dot, own, energy = _sums(x, start, t, count)
    return dot / math.sqrt(max(own * energy, 1e-300))


@jit(error_model="numpy")
def _bounce_after(remainder, template, head, head_energy, low, high, following, pre, shortest, fit, reach, scale,
                  likeness, ratio_low, ratio_high, start_likeness):
    """The first sample in ``[low, high)`` where ``head`` fits ``remainder`` (by ``start_likeness``, scaled
    ``ratio_low`` to ``ratio_high`` times ``scale``) and the template over ``fit`` samples (up to ``following``) does
    too (by ``likeness``), moved to the start's best correlation within ``reach`` samples after: (sample,
    correlation), or (-1, 0)."""
    if high <= low:
        return -1, 0.0
    count = high - low
    own = _energies(remainder, low - pre, count, len(head))
    floor = (ratio_low * scale) ** 2 * head_energy  # the energy a fit so scaled needs (Cauchy-Schwarz)
    if not own.max() >= floor:
        return -1, 0.0
    # and the most a window may hold: its product reaches start_likeness times its norm and the head's only where
    # that is under ratio_high times the head's energy scaled (a margin far over the rounding of either test)
    ceiling = (ratio_high / start_likeness) ** 2 * scale * scale * head_energy * (1.0 + 1e-6) if (
        scale > 0.0 and start_likeness > 0.0) else np.inf
    # the head's products with the windows, summed as the scan reaches them (_BOUNCE_CHUNK windows at a time from the
    # first over the floor not summed yet; past the first that fits, as far as the best start is sought): the windows
    # under the floor (most of a quiet stretch) and past the bounce found are not summed
    dots, done = np.empty(count), 0
    for k in range(count):
        if own[k] < floor or own[k] > ceiling:
            continue
        if k >= done:
            done = min(count, k + _BOUNCE_CHUNK)
            dots[k:done] = _correlations(remainder, low - pre + k, head, done - k)
        like = dots[k] / math.sqrt(max(own[k] * head_energy, 1e-300))
        ratio = dots[k] / (head_energy * scale)
        if like < start_likeness or ratio < ratio_low or ratio > ratio_high:
            continue
        at = low + k
        span = min(max(pre + shortest, min(pre + fit, following - at)), len(template), len(remainder) - at + pre)
        whole, own_energy, energy = _sums(remainder, at - pre, template, span)
        if whole < likeness * math.sqrt(max(own_energy * energy, 1e-300)):
            continue  # the start alone is often met in a drum's beating modes
        if min(k + reach + 1, count) > done:
            dots[done:min(k + reach + 1, count)] = _correlations(remainder, low - pre + done, head,
                                                                 min(k + reach + 1, count) - done)
        best = k
        for m in range(k + 1, min(k + reach + 1, count)):
            if dots[m] / math.sqrt(max(own[m] * head_energy, 1e-300)) > dots[best] / math.sqrt(
                    max(own[best] * head_energy, 1e-300)):
                best = m
        return low + best, dots[best] / math.sqrt(max(own[best] * head_energy, 1e-300))
    return -1, 0.0


@jit(error_model="numpy")
def _whole_after(remainder, layer, low, high, following, pre, fit, reach, scale, likeness, ratio_low, ratio_high):
    """The first sample in ``[low, high)`` (whose ``fit`` samples end by ``following``) where ``layer``'s first ``fit``
    samples (from ``pre`` before its attack) correlate with ``remainder`` by ``likeness`` and scale (least squares)
    ``ratio_low`` to ``ratio_high`` times ``scale``, moved to their best correlation within ``reach`` samples after:
    (sample, correlation), or (-1, 0). No start is asked: a quiet layer's first 3 ms carry a tenth of its first
    10 ms' energy (FluidR3's snare 38 peaks 9.4 ms in), and under a reverberant room's sound or what is left of the
    bounce before, their correlation is 0.2-0.3 at a drop's last bounces whose whole fits 0.81-0.84."""
    n = len(remainder)
    span = min(pre + fit, len(layer))
    high = min(high, following - fit, n - span + pre)
    count = high - low
    if count <= 0 or low < pre:
        return -1, 0.0
    energy = _dot(layer, 0, layer, span)
    own = _energies(remainder, low - pre, count, span)
    floor = (ratio_low * scale) ** 2 * energy  # the energy a fit so scaled needs (Cauchy-Schwarz)
    if not own.max() >= floor:
        return -1, 0.0
    dots = _correlations(remainder, low - pre, layer[:span], count)
    for k in range(count):
        if own[k] < floor:
            continue
        like = dots[k] / math.sqrt(max(own[k] * energy, 1e-300))
        ratio = dots[k] / (energy * scale)
        if like < likeness or ratio < ratio_low or ratio > ratio_high:
            continue
        best = k
        for m in range(k + 1, min(k + reach + 1, count)):
            if dots[m] / math.sqrt(max(own[m] * energy, 1e-300)) > dots[best] / math.sqrt(
                    max(own[best] * energy, 1e-300)):
                best = m
        return low + best, dots[best] / math.sqrt(max(own[best] * energy, 1e-300))
    return -1, 0.0


@jit(error_model="numpy")
def _earlier_start(remainder, template, head, head_energy, c, low, high, following, pre, shortest, fit, reach,
                   likeness, weak):
    """Where in ``[low, high)`` the attack detected at ``c`` starts, when it is its sound's later burst: of the samples
    where ``head`` correlates with ``remainder`` by ``weak`` or more, at a peak of that correlation, the one where the
    template over ``fit`` samples (up to ``following``) correlates best, by ``likeness`` and better than at ``c``
    (within ``reach`` samples each way): (sample, correlation), or (-1, 0)."""
    count = high - low
    if count < 3 or low < pre or c - pre - reach < 0 or high - pre + len(head) > len(remainder):
        return -1, 0.0
    own = _energies(remainder, low - pre, count, len(head))
    dots = _correlations(remainder, low - pre, head, count)
    starts = np.empty(count)
    for k in range(count):
        starts[k] = dots[k] / math.sqrt(max(own[k] * head_energy, 1e-300))
    best, best_like = -1, likeness
    for k in range(1, count - 1):
        if starts[k] < weak or starts[k] < starts[k - 1] or starts[k] < starts[k + 1]:
            continue
        at = low + k
        span = min(max(pre + shortest, min(pre + fit, following - at)), len(template), len(remainder) - at + pre)
        whole = _likeness(remainder, at - pre, template, span)
        if whole >= best_like:
            best, best_like = at, whole
    if best < 0:
        return -1, 0.0
    if _fits_near(remainder, template, c, following, pre, shortest, fit, reach, best_like):
        return -1, 0.0
    return best, best_like


@jit(error_model="numpy")
def _joint_after(remainder, own, at_c, scale, layer, low, high, following, pre, fit, reach, likeness, ratio_low,
                 ratio_high):
    """:func:`_whole_after`'s search with the attack at ``at_c`` (``own`` times ``scale``, taken off ``remainder``)
    fitted again together with ``layer`` at each sample: the first sample in ``[low, high)`` where ``layer``'s first
    ``fit`` samples (from ``pre`` before its attack) correlate by ``likeness`` or more with what ``remainder``, the
    attack put back, less the attack so fitted leaves there (two scales, least squares from the attack's window to the
    end of ``layer``'s), ``layer``'s scale ``ratio_low`` to ``ratio_high`` times ``scale``, moved to the best within
    ``reach`` samples after: (sample, correlation), or (-1, 0). Each sample's sums from the running sums of the
    attack's sound and of its products, and two sliding dot products with ``layer``."""
    n = len(remainder)
    span = min(pre + fit, len(layer))
    high = min(high, following - fit, n - span + pre)
    if high <= low or low < pre or at_c < pre:
        return -1, 0.0
    start, count = low - at_c, high - low  # the first window's start in the samples from at_c - pre
    size = start + count - 1 + span
    a, y = np.zeros(size), np.empty(size)
    for j in range(size):
        if j < len(own):
            a[j] = own[j]
        y[j] = remainder[at_c - pre + j] + scale * a[j]  # the attack put back
    aa, ay = np.zeros(size + 1), np.zeros(size + 1)  # running sums from the attack's window on
    for j in range(size):
        aa[j + 1] = aa[j] + a[j] * a[j]
        ay[j + 1] = ay[j] + a[j] * y[j]
    ab = _correlations(a, start, layer[:span], count)
    by = _correlations(y, start, layer[:span], count)
    yy = _energies(y, start, count, span)
    bb = _dot(layer, 0, layer, span)
    likes, ratios = np.empty(count), np.empty(count)
    for k in range(count):
        w, end = start + k, start + k + span
        det = aa[end] * bb - ab[k] * ab[k]
        if det <= 0.0 or bb <= 0.0 or scale <= 0.0:
            likes[k], ratios[k] = -1.0, 0.0
            continue
        x = (ay[end] * bb - by[k] * ab[k]) / det  # the attack's scale so fitted
        z = (aa[end] * by[k] - ab[k] * ay[end]) / det  # layer's
        left = max(yy[k] - 2.0 * x * (ay[end] - ay[w]) + x * x * (aa[end] - aa[w]), 1e-300)
        likes[k], ratios[k] = (by[k] - x * ab[k]) / math.sqrt(left * bb), z / scale
    for k in range(count):
        if likes[k] < likeness or ratios[k] < ratio_low or ratios[k] > ratio_high:
            continue
        best = k
        for m in range(k + 1, min(k + reach + 1, count)):
            if likes[m] > likes[best]:
                best = m
        return low + best, likes[best]
    return -1, 0.0


@jit(error_model="numpy")
def _layer_start(remainder, layer, c, low, following, pre, shortest, fit, likeness):
    """Where in ``[low, c)`` the attack detected at ``c`` starts by ``layer``: the sample where ``layer``'s first
    ``fit`` samples (up to ``following``, ``shortest`` or more) correlate best with ``remainder`` within ``low`` to
    ``c``, when that is ``likeness`` or more, better than at ``c`` and more than ``_LAYER_LAG`` samples before it
    (nearer, :func:`_take_off` finds it): (sample, correlation), or (-1, 0)."""
    span = min(max(pre + shortest, min(pre + fit, following - c)), len(layer), len(remainder) - c + pre)
    count = c - low + 1
    if count <= _LAYER_LAG + 1 or low < pre or span <= pre:
        return -1, 0.0
    energy = _dot(layer, 0, layer, span)
    own = _energies(remainder, low - pre, count, span)
    dots = _correlations(remainder, low - pre, layer[:span], count)
    best, best_like = -1, likeness
    for k in range(count):
        like = dots[k] / math.sqrt(max(own[k] * energy, 1e-300))
        if like >= best_like:
            best, best_like = k, like
    if best < 0 or best >= count - 1 - _LAYER_LAG:
        return -1, 0.0
    return low + best, best_like


@jit(error_model="numpy")
def _fits_near(remainder, template, c, following, pre, shortest, fit, reach, like):
    """Whether the template over ``fit`` samples (up to ``following``) correlates by ``like`` or more with
    ``remainder`` at an attack within ``reach`` samples of ``c``."""
    here = min(max(pre + shortest, min(pre + fit, following - c)), len(template), len(remainder) - c - reach + pre)
    lags = 2 * reach + 1
    dots = _correlations(remainder, c - reach - pre, template[:here], lags)
    own = _energies(remainder, c - reach - pre, lags, here)
    energy = _dot(template, 0, template, here)
    for k in range(lags):
        if dots[k] >= like * math.sqrt(max(own[k] * energy, 1e-300)):
            return True
    return False


@jit(error_model="numpy")
def _refused_fit(remainder, template, head, head_energy, refused, low, high, pre, fit, reach, refused_likeness, least):
    """The first of ``refused`` in ``[low, high)`` where the template's first ``fit`` samples, at their best lag within
    ``reach`` samples, correlate by ``refused_likeness`` and scale ``least`` or more, and ``head`` there correlates
    so too: (that lag's sample, the fit's correlation), or (-1, 0)."""
    span = min(pre + fit, len(template))
    energy = _dot(template, 0, template, span)
    lags = 2 * reach + 1
    for r in range(len(refused)):
        if refused[r] < max(low, pre + reach) or refused[r] >= high - reach:
            continue
        c = int(np.rint(refused[r]))
        if c - pre + reach + span > len(remainder):
            continue
        start = c - pre - reach
        own = _energies(remainder, start, lags, len(head))
        dots = _correlations(remainder, start, head, lags)
        starts = np.empty(lags)
        for k in range(lags):
            starts[k] = dots[k] / math.sqrt(max(own[k] * head_energy, 1e-300))
        if not starts.max() >= refused_likeness:
            continue  # the start's correlations first: cheaper, and they seldom pass where no note starts
        whole = _correlations(remainder, start, template[:span], lags)
        wide = _energies(remainder, start, lags, span)
        best, best_like = 0, -np.inf
        for k in range(lags):
            like = whole[k] / math.sqrt(max(wide[k] * energy, 1e-300))
            if like > best_like:
                best, best_like = k, like
        if best_like >= refused_likeness and whole[best] / energy >= least and starts[best] >= refused_likeness:
            return c - reach + best, best_like
    return -1, 0.0


@jit(error_model="numpy")
def _energy(x, start, count):
    """The energy of ``x`` over ``count`` samples from ``start`` (fewer at its end)."""
    total = 0.0
    for j in range(start, min(start + count, len(x))):
        total += x[j] * x[j]
    return total


@jit(error_model="numpy")
def _dot(x, start, t, count):
    """``x[start:start + count] @ t[:count]``, summed in order."""
    total = 0.0
    for j in range(count):
        total += x[start + j] * t[j]
    return total


@jit(error_model="numpy")
def _sums(x, start, t, count):
    """``x[start:start + count]``'s dot product with ``t[:count]``, its own energy and ``t[:count]``'s, each summed in
    order as :func:`_dot` sums it: the three side by side, so that one sum's additions wait not for the others'."""
    dot, own, energy = 0.0, 0.0, 0.0
    for j in range(count):
        a, b = x[start + j], t[j]
        dot += a * b
        own += a * a
        energy += b * b
    return dot, own, energy


@jit(error_model="numpy")
def _correlations(x, start, t, count):
    """The dot products of ``t`` with the ``count`` windows of ``x`` from ``start`` (one sample apart), each summed in
    order of ``t``'s samples: :func:`._kernels.window_dots` (all windows a term at a time, eight terms a pass: each
    window's sum loaded and stored once for eight products), the same sums as a loop over ``t``'s samples adding one
    product to every window's sum at a time, in 0.57 of its time (1104 windows of 168 samples: 6.6 against 11.6 us)."""
    return window_dots(x, start, t, count)


@jit(error_model="numpy")
def _energies(x, start, count, size):
    """The energies of the ``count`` windows of ``size`` samples of ``x`` from ``start`` (running sums)."""
    out = np.empty(count)
    total = 0.0
    for j in range(size):
        total += x[start + j] * x[start + j]
    out[0] = total
    for k in range(1, count):
        total += x[start + k + size - 1] * x[start + k + size - 1] - x[start + k - 1] * x[start + k - 1]
        out[k] = max(total, 0.0)
    return out
