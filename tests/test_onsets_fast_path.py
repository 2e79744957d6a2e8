"""find_onsets made faster finds the same onsets: against the outputs of the slower code it replaced.

tests/data/onsets_reference.npz holds, for each recording of :func:`cases`, the times (s), levels (dB re
the loudest), threshold and noise floor that ``find_onsets`` returned BEFORE its hot paths were made
faster (vectorised loops, no recomputation): it was written by the older code with
``python tests/test_onsets_fast_path.py --write`` (commit e900400, on the code of 64cbfb4), and written again
when Burg's sums were added in four lanes and the prediction error filter compiled (its sums in another order:
every onset kept, times within 1.1e-12 relative, levels within 3.3e-5 dB of the earlier reference; the recorded
corpus's figures unchanged); and written again when the search for close bounces (`_template_search`) was added (a change of the detector by
design: with ``bounce_reach=0`` every output equals the earlier reference; with it, FluidR3's snare 38 drop with
reverb has 46 onsets instead of 42, its drop's close last bounces found, and every other recording is unchanged);
and when that stage took a second opinion on the onsets step 4 refused (by design: with ``refused_likeness=1`` every
output equals the reference before; with it, FluidR3's snare 38 roll with reverb has 26 onsets instead of 24, two
ghost notes found, and every other recording is unchanged); and when that stage fitted the attacks the template had
timed at the template's own sample (FluidR3's snare 38 drop with reverb: 47 onsets, one more close bounce; every
other recording unchanged); and when a room's reflections were left out (`_without_reflections`, by design: with
``reflection_pairs=0`` every output equals the reference before; with it, FluidR3's snare 38 drop with reverb has 44
onsets instead of 47, its three reflections 83.5 ms after a note gone, and every other recording is unchanged); and
when a detection on the electric snare's second burst, 3.4 ms into an attack the template timed, became that attack
(by design: with ``burst_db=-120`` every output equals the reference before; with it, FluidR3's snare 40 roll at
-72 dBFS has 28 onsets instead of 29, a false one gone, and every other recording is unchanged); and when the
search for close bounces took each attack off by its own velocity layer's template, continued by the longest clear
attack's sound, and looked past a detection neither template fits (by design: FluidR3's snare 38 drop with reverb has
43 onsets instead of 44, an onset 1.4 ms early on the close bounce of 4.0274 s gone; its roll with reverb 25
instead of 26, a false onset at 2.027 s (no note within 50 ms) gone; our
drum's stroke 2 without snares one onset at 1.5888 s instead of 1.5914 s, not an impact either way; every other
recording unchanged); and when the
modes' band's normal equations were added up over blocks of 256 lagged rows and the room's tail correlated its
impulses by sums instead of FFTs (their sums' order: every onset kept, times within 8.9e-11 relative, levels
within 5.7e-10 dB, thresholds and floors within 2.5e-11 dB of the reference before; the 64 corpus recordings'
counts unchanged, their times within 1e-15 s, levels within 4.4e-12 dB); and when the search for close bounces
dropped a detection that taking off the attack before it explains (its own second burst, ``found_burst_db``), sought
the start of a detection over earlier sound up to 5 ms before it (``earlier_reach``), took a bounce whose start
correlates by 0.7 with the template (``bounce_likeness``), and an attack the template timed or found was no longer
asked to rise out of the earlier sound (``found_decay_db``) (by design: with ``found_burst_db=-120, earlier_reach=0,
found_decay_db=-32, bounce_likeness=0.8`` every output equals the reference before, ``bounce_ratio_low`` and
``found_echo_rise_db`` (an attack the template found not tested by its rise, added after) changing none of these
recordings; with them, our drum's stroke 0
without snares has a false onset at 0.8358 s (17 ms after an impact) gone and one at 2.5022 s (7.4 ms after one)
added, its stroke 2 without snares a false one at 1.0931 s (17 ms after one) gone, FluidR3's snare 40 roll at -72 dBFS
its notes of 1.0950 and 4.2990 s at their start instead of on their sample's second burst 3.7 ms in, FluidR3's snare
38 drop with reverb 44 onsets instead of 43 (its bounce of 4.0261 s found, within 0.06 ms) and five of its last
bounces' levels moved by 0.07-1.15 dB (their windows), every other recording unchanged); and when a quiet attack of
the modes' band alone in a reverberant recording that the sound at the same delay after another note explains alike
before and after it became a room's echo (`_room_echoes`, by design: with ``room_decay_db=-120`` every output equals
the reference before; with it, FluidR3's snare 38 drop with reverb has 42 onsets instead of 44, three false ones
(10-76 ms from a note) gone and one (74 ms from a note) added, the level of its onset of 4.026 s 0.11 dB lower; its
roll with reverb 24 instead of 25, a false one (23 ms from a note) gone; every other recording unchanged); and when the search for
close bounces looked, after an attack the quiet velocity layer's template took off in a train of close attacks, with
that layer's template too, where the recording replays a sample (by design: with ``layer_bounce_likeness=1`` every
output equals the reference before; with it, FluidR3's snare 38 drop with reverb has 47 onsets instead of 44, its
second drop's close last bounces of 4.0353-4.0487 s found, and every other recording, the synthetic ones included
(they replay no sample, ``replay_likeness``), is unchanged); and when that layer's template was its sound as recorded
for the attacks before the loop reaches it (with ``layer_bounce_likeness=1`` every output equals the reference
before the quiet layer's search; with it, FluidR3's snare 38 roll with reverb has 26 onsets instead of 25, a ghost
note at 1.7633 s found, 1.2 ms after its truth; every other recording unchanged); and when that layer's fit asked
0.75 instead of 0.8 (``layer_bounce_likeness``; FluidR3's snare 38 drop with reverb has 48 onsets instead of 47, a
last bounce at 4.0594 s found; every other recording unchanged).
The two last entries were made side by side and written again on the merged code: its reference differs from each
one's only where the other's changed it (FluidR3's snare 38 drop with reverb 46 onsets: the room's three false ones
gone and one added, the quiet layer's four close bounces found; its roll with reverb 25: one false one gone, a ghost
note found).
And when a room's return the template timed, and then the returns of the modes' band alone once more, were tried
on the reported onsets (`_room_returns`, by design: with ``room_found_fit_db=-120`` every output equals the reference
before; with it, FluidR3's snare 38 roll with reverb has 24 onsets instead of 25, a false one at 4.286 s (13.4 ms from
a note) gone; every other recording unchanged). The ghost notes sought under an accent once its layer-mates are taken off (``ghost_rise_db``; 120
gives the outputs before it) change none of these recordings: the reference stands; nor do the ghost notes one
layer-mate alone reaches (``ghost_own_db``; 120 gives the outputs before it), nor those sought in a recording
step 4 finds reverberant (``ghost_room_own_db``; 120 gives the outputs before it).
And when a quiet attack of the modes' band alone that the sound at the same delays after other notes explains
together became the earlier notes' own sound (`_layer_echoes`, by design: with ``layer_echo_db=-120`` every output
equals the reference before; with it, FluidR3's snare 38 roll with reverb has 23 onsets instead of 24, a false one at
2.5833 s (27.9 ms from a note) gone, the levels of three onsets moved by 0.0001-0.096 dB (their windows); every other
recording unchanged).
Nor do an attack's own detections dropped in a row by the template search (``found_bursts``; 1 gives the outputs
before it), nor the detection no template fits after a dropped one (``burst_unfitted_likeness``; 0 gives the outputs
before it). Nor does ``peak_realign`` (issue 28's levels: a template fit of ``peak_db``'s that leaves over 30 % unexplained
sought again within 1 ms, a template's waveform ended where the next note's attack already rises; 0 gives the outputs
before it): it moves ``peak_db`` alone (33 of the 78 recordings of the corpus's seed 0 and :func:`cases`), which this
reference does not hold; tests/test_recorded_levels.py holds it against the corpus's truth.
And when, in a recording step 4 finds reverberant, a ghost note under an accent was also sought where what a
layer-mate leaves rises 4 dB over 5 ms and the quietest clear attack's first 5 ms fit it by 0.8 (`_room_ghost_notes`,
by design: with ``ghost_room_fit=1`` every output equals the reference before; with it, FluidR3's snare 38 roll with
reverb has 26 onsets instead of 23, its ghost notes of 0.2727, 1.0954 and 3.5541 s found within 0.07 ms and its
onset 1.2 ms late on the one of 3.8714 s moved to within 0.07 ms, the levels of its other onsets within 0.03 dB; every
other recording unchanged).
Nor do a drop's last bounces sought by the quiet layer's first 10 ms alone (``layer_whole_likeness``; 1 gives the
outputs before it) and a partner's own return at the delay tried let lie in its window (``layer_echo_partners``; 0
gives the outputs before it): the reference stands (on the corpus, seed 0, FluidR3's drops with reverb gain two
last bounces; tests/test_recorded_drop_rooms.py).
Nor do the ghost notes' rules under white noise (``ghost_rise_gap``: a rise read also against the 10 ms before a
1-ms gap; ``ghost_noise_start``: a new note's onset where the noise's power changes; each 0 gives the outputs before
it): the reference stands (its recordings' rises in what is left are over the drum's or a room's sound, not white
noise, or found as before).
And the loudest clear attack's time, as the template that times the attacks over earlier sound, may be moved to where
it rises out of what comes before it (``template_start_db``, -40; 0 gives the outputs before it): the reference stands,
none of these cases moves; on the corpus TimGM6mb's snare 40 drop at -60 dBFS has its template-timed notes 0.02 ms
late instead of 0.49 (seed 2: 55 loud notes within 1 ms instead of 4; tests/test_recorded_noise_timing.py).
Where a sample player replays one sample at every velocity, a layer-mate's next note of the accent's waveform is
taken off the mate's remainder, which then reaches past it (``ghost_mate_notes``, 0.99; 1 gives the outputs before
it): the reference stands, none of these cases moves; on the corpus TimGM6mb's snare 38 roll finds its ghost note
120 ms after its accent, dry and with reverb (tests/test_recorded_mate_notes.py).
And when the room's ghost-note search fitted the quiet attack from 2 ms before a rise instead of 1
(``ghost_room_reach``), an accent with no layer-mate took the attacks that correlate with it by 0.99 as its mates
(``ghost_room_spare_likeness``), and step 5's test of a room's echo tried an attack it kept again with each partner
clear up to its next attack less than 15 dB under it (``room_partner_under_db``) (issue 28, by design: with
``ghost_room_reach=1e-3``, ``ghost_room_spare_likeness=1`` and ``room_partner_under_db=120`` every output equals the
reference before; with them, FluidR3's snare 38 drop with reverb has 44 onsets instead of 46, two false ones (0.3644
and 2.4655 s) gone (``room_partner_under_db``); its roll with reverb 27 instead of 26, a ghost note of 1.5154 s
found within 0.04 ms (``ghost_room_reach``); every other recording unchanged; tests/test_recorded_room_rolls.py).
The ghost notes sought by a matched filter of their layer's own head, learned from the ghost notes found
(``ghost_matched_fit``; 1 gives the outputs before it), move none of these cases (in none does it find a note); on
the corpus, seed 0, FluidR3's snare 38 roll at -60 dBFS gains its ghost notes of 0.7874 and 2.8007 s and has 3.9647
s within 1 ms (tests/test_recorded_matched_ghosts.py), and TimGM6mb's snare 40 roll at -72 dBFS has its note of
1.5256 s 0.04 ms early instead of 0.01 late.
And a drop's last bounces were sought by a fit of the quiet layer together with the bounce before
(``layer_joint_likeness``) and a train's bounce detected on its main rise put at its start by that layer
(``layer_start_reach``; by design: with ``layer_joint_likeness=1`` and ``layer_start_reach=0`` every output equals
the reference before; with them, FluidR3's snare 38 drop with reverb has 45 onsets instead of 44 (the reference the
rules above wrote), a bounce of 4.0554 s at -25.9 dB found within 0.05 ms, the levels of its other onsets within
0.02 dB; every other recording unchanged; on the corpus, seed 0, FluidR3's drops with reverb gain two last bounces;
tests/test_recorded_drop_joint.py).
``peak_learn`` (issue 28's peak levels: the layers no clear note makes a template of learned from their quietest
notes with room, and a window the next onset cuts short read from its fit; 0 gives the outputs before it) moves
``peak_db`` alone (34 of the 78 recordings of the corpus's seed 0 and :func:`cases`, the times, ``level_db`` and
thresholds the same to the bit), which this reference does not hold; tests/test_recorded_peak_levels.py holds it
against the corpus's truth.
The room test's second pass (``room_partner_under_db``) only refuses: step 5's layer test sees the attacks its first
pass left, its refusals taken off after (a bug fix of that rule, no switch): the reference stands, none of these cases
moves; on the corpus, seeds 0-4, only FluidR3's snare 38 drop with reverb, seed 0, moves, its false 4.1281 s gone
(tests/test_recorded_room_passes.py).
Nor does a detection before the template's attack that is not an attack (in the noise, or on the note's own lead-in)
stop its start being sought (``template_start_past_db``, 0; 120 gives the outputs before it): the reference stands,
none of these cases moves, nor does the corpus's seed 0; on seed 5 TimGM6mb's snare 40 drop at -72 dBFS has 52 of 53
loud notes within 1 ms instead of 7 (tests/test_recorded_noise_timing.py).
Nor does step 5's search for a close bounce reaching past ``bounce_reach`` (``train_reach``, 35 ms: up to
``echo_reach`` past a detection it dropped, and after a bounce of a train of shrinking flights and fading bounces to
where the flight before says the next one is; by design: with ``train_reach=0`` every output equals the reference
before): the reference was written again, FluidR3's snare 38 drop with reverb having 57 onsets instead of 45, its two
drops' last 12 bounces found (all 56 loud notes within 1 ms instead of 44), every other recording unchanged, nor the
corpus's seed 0; on seed 8 its drop with reverb has all 54 loud notes within 1 ms instead of 30
(tests/test_recorded_drop_trains.py).
Ghost notes found late on their sample's own later rises (``ghost_matched_back``: the matched search aligns its
notes up to 4.5 ms earlier; ``reflection_drop_spread``: where step 4 finds no room, a reflection's pairs alike in
drop too; ``ghost_late_reach``, off, and removed a round later: the ghost search moving an attack up to so long after its
onset): the
reference stands, none of these cases moves, nor any output on the corpus's seed 0; on seeds 1-4 9 notes more
within 1 ms and on seeds 5-9 8 (FluidR3's and TimGM6mb's rolls), none lost, no false detection more
(tests/test_recorded_late_ghosts.py).
``ghost_span`` (ghost notes sought and the ghost layer's head learned up to 0.18 s after their accents; 0.13 gives
the outputs before it) and ``ghost_white_rise_db`` (a rise of 6 dB over white noise, where the note is the accent's
own; 120 gives the outputs before it) wrote the reference again (by design: with both at their values before every
output equals the reference before, to the bit): FluidR3's snare 40 roll at -72 dBFS has 29 onsets instead of 28, its
ghost note of 1.5150 s (-27.8 dB) found within 0.05 ms, and every other case is unchanged; on the corpus, seed 0,
only FluidR3's snare 38 roll at -72 dBFS moves, its onset of 1.7621 s two samples earlier (0.02 ms off the truth
either way); held-out seeds 1-4 gain 11 notes within 5 ms, 8 within 1 ms, no recording losing a note or gaining a
false detection (tests/test_recorded_ghost_span.py, tests/test_recorded_white_rise.py).
A drop's last bounces sought as one train of the quiet layer (``layer_train_found``, ``layer_found_bursts``,
``layer_skipped_search``; 0 each gives the outputs before them, to the bit): the reference stands, none of these
cases moves; on the corpus, seed 0, only FluidR3's snare 40 drop at -72 dBFS moves (an onset a sample earlier, a peak
level by 0.001 dB); seeds 1-2 gain 6 loud notes of FluidR3's drops (tests/test_recorded_drop_layer_train.py).
The entries of this round (``template_start_past_db``, ``train_reach``, the late ghost notes', ``ghost_span`` and
``ghost_white_rise_db``, the drop's layer train) were made side by side and the reference written again on the merged
code: it differs from each one's only where another changed it (FluidR3's snare 38 drop with reverb 57 onsets, its
snare 40 roll at -72 dBFS 29).
An attack found on a ghost note's later step, more than 2 ms and up to ``ghost_step_reach`` (4.6 ms) after the note
the room or matched search finds, moved onto it once every stage is done (0 gives the outputs before it, to the bit):
the reference stands, none of these cases moves; on the corpus, seed 0, only FluidR3's snare 40 roll at -72 dBFS
moves, its note of 3.6004 s found 3.6 ms earlier (within 1 ms); seeds 0-9 gain 14 notes within 1 ms, no recording
losing a note or gaining a false detection (tests/test_recorded_ghost_steps.py).
The matched ghost search's spare layer-mates (``ghost_spare_mates``, tests/test_recorded_spare_mates.py) count only
past where the first three stop reaching: no output here moves (the reference stands; seeds 1-9 gain 3 notes).
A room's reflections told from a roll's ghost notes at one delay by chance (``reflection_excess``, 0.15: a delay's
pairs' later onsets like their notes by more than the other loud notes' D later are no room's; 1 gives the outputs
before it, to the bit): the reference stands, none of these cases moves, nor any output on the corpus's seed 0; seeds
4 and 8 gain 22 notes within 1 ms (TimGM6mb's snare 38 roll, FluidR3's snare 40 roll), no recording of seeds 0-9
losing one or gaining a false detection (tests/test_recorded_reflection_share.py).
The recordings are rebuilt here (seeded): our synthesis with and without the snare wires, another
drum's, a room and noise (tests/_recordings.py), the paper's free bounce of benchmarks/analysis.py, and
some of tests/_recorded_drums.py's SoundFont recordings (dry, noise, FluidSynth's reverb).

Times must agree to 1e-12 s relative (the same samples, the same fractions), levels to 1e-9 dB. A change
of what onsets are found (a change of the detector's accuracy) must write the reference again, from
the code before the change, and say so. The synthetic recordings are rendered from simulated strokes, so a
change of the solver's last bits (its flight-time table: impact times within 1e-14 s, the signals within
1e-12) changes them too, and in a room a marginal decision can flip: the reference is then written
again with the detector unchanged (checked by running the detector of both versions on the same signals).
"""

import sys
from pathlib import Path

import numpy as np

from drumstroke.analysis import find_onsets

HERE = Path(__file__).resolve().parent
REFERENCE = HERE / "data" / "onsets_reference.npz"
CORPUS = [("FluidR3", 38, "drop", "reverb"), ("FluidR3", 40, "roll", "noise72"), ("TimGM6mb", 38, "flams", "dry"),
          ("TimGM6mb", 40, "singles", "noise60"), ("FluidR3", 38, "roll", "reverb")]


def cases():
    """Yield (name, signal, rate) of every recording compared."""
    from _recordings import RATE, random_strokes, render, room_response
    from drumstroke.stroke import simulate

    stroke = simulate("free-bounce", t_end=5.0)
    signal, _ = render(stroke.impacts.t, stroke.impacts.tip_speed, snares=True, snr=30,
                       tail=5.0 - stroke.impacts.t[-1])
    yield "free-bounce snares snr30", signal, RATE
    strokes = random_strokes(3, seed=28)
    room = room_response(seed=2)
    variants = [{"snares": False}, {"snares": True, "snr": 40}, {"kind": "other", "snr": 35}, {"snares": True, "room": room}]
    for i, (times, speeds) in enumerate(strokes):
        for j, variant in enumerate(variants):
            if (i + j) % 2 == 0 or j == 3:  # not every pair: the test's time
                signal, _ = render(times, speeds, seed=i, **variant)
                yield f"stroke {i} {sorted(variant)} {j}", signal, RATE
    yield from _corpus()


def _corpus():
    from _recorded_drums import RATE, recordings

    for font, key, set_name, condition in CORPUS:
        for recording in recordings(fonts=(font,), keys=(key,), sets=(set_name,), conditions=(condition,)):
            yield recording.name, recording.signal, RATE


def _outputs(signal, rate):
    onsets = find_onsets(signal, rate)
    floor = onsets.info.get("floor_db")
    return {"t": onsets.t, "level_db": onsets.level_db,
            "scalars": np.array([onsets.threshold_db, np.nan if floor is None else floor,
                                 onsets.info.get("analysis_rate", np.nan)])}


def test_same_onsets_as_the_slower_code():
    with np.load(REFERENCE) as data:
        reference = {key: data[key] for key in data.files}
    everything = list(cases())
    assert len(everything) == int(reference["count"])
    for case, (name, signal, rate) in enumerate(everything):
        assert str(reference[f"{case}/name"]) == name
        got = _outputs(signal, rate)
        want_t, want_level = reference[f"{case}/t"], reference[f"{case}/level_db"]
        assert len(got["t"]) == len(want_t), name
        np.testing.assert_allclose(got["t"], want_t, rtol=1e-12, atol=0.0, err_msg=name)
        np.testing.assert_allclose(got["level_db"], want_level, rtol=0.0, atol=1e-9, err_msg=name)
        np.testing.assert_allclose(got["scalars"], reference[f"{case}/scalars"], rtol=0.0, atol=1e-9, err_msg=name)


def test_peaks_picked_as_librosa_picks_them():
    """The detector's linear-time peak picker against ``librosa.util.peak_pick`` (ties, flat stretches, short signals)."""
    import librosa

    from drumstroke.analysis.onsets import _peak_pick

    rng = np.random.default_rng(5)
    for trial in range(300):
        n, gap = int(rng.integers(1, 2000)), int(rng.integers(1, 120))
        x = rng.standard_normal(n) ** 2
        if trial % 3 == 0:
            x = np.round(x, 1)  # ties
        if trial % 4 == 0:
            x[n // 3:2 * n // 3] = 0.0  # a flat stretch (the jumps are zeros at the start and over digital silence)
        want = librosa.util.peak_pick(x, pre_max=gap, post_max=gap, pre_avg=1, post_avg=1, delta=0.0, wait=gap)
        np.testing.assert_array_equal(_peak_pick(x, gap), want, err_msg=f"n={n}, gap={gap}")


def test_kernels_sum_as_numpy_and_librosa_sum():
    """The compiled kernels give the same bits as the numpy (and librosa) code they replaced, on random signals (Burg's
    method, whose sums are added in four lanes, to 1e-12 of its largest coefficient)."""
    import librosa

    from drumstroke.analysis._front import burg, jump_profile
    from drumstroke.analysis._kernels import jump_at, row_dots

    def windows(x, width):  # the mean squares over the next window and the 4 before, as cumulative sums in numpy
        power = np.concatenate(([0.0], np.cumsum(x * x)))
        n = np.arange(len(x))
        return ((power[np.minimum(n + width, len(x))] - power[n]) / width,
                (power[n] - power[np.maximum(n - 4 * width, 0)]) / (4 * width))

    def jump(x, width):
        after, before = windows(x, width)
        return np.sqrt(after / np.maximum(before, 1e-300 + after * 1e-12))

    rng = np.random.default_rng(11)
    for trial in range(200):
        n = int(rng.integers(20, 3000))
        x = rng.standard_normal(n) * np.exp(rng.standard_normal(n))
        if trial % 5 == 0:
            x[:n // 3] = 0.0  # digital silence first
        order = min(int(rng.integers(1, 50)), max(1, n // 8))
        want_lpc = librosa.lpc(x, order=order)  # its sums added in four lanes: the same to rounding
        np.testing.assert_allclose(burg(x, order), want_lpc, rtol=0.0, atol=1e-12 * np.abs(want_lpc).max())
        width = int(rng.choice([4, 12, 48]))
        want = jump(x, width)
        want[:4 * width] = 0.0
        np.testing.assert_array_equal(jump_profile(x, width), want)
        half = max(1, width // 2)
        for i in rng.integers(0, n, 5):
            low, high = max(0, i - half - 4 * width), min(n, i + half + width + 1)
            k = np.arange(max(i - half, low), min(i + half + 1, high)) - low
            near = jump(x[low:high], width)[k]
            assert jump_at(x, np.array([i]), width, 0.0)[0] == near[k >= min(4 * width, i)].max(initial=0.0)
        size, rows = int(rng.integers(1, 130)), int(rng.integers(1, 6))
        block = np.lib.stride_tricks.sliding_window_view(x[:rows + size - 1], size) if rows + size - 1 <= n else x[None, :size]
        np.testing.assert_array_equal(row_dots(block, block), np.einsum("ij,ij->i", block, block))
        pairs = rng.standard_normal((rows, 2))
        np.testing.assert_array_equal(row_dots(pairs, pairs[::-1].copy()), np.einsum("ij,ij->i", pairs, pairs[::-1]))


def test_windows_summed_side_by_side_as_one_by_one():
    """The kernels that sum several windows' products side by side give each window's sums as the one-window kernels
    add them (the matching pursuit's five alignments, the next attack's eight windows): to the bit."""
    from drumstroke.analysis import _kernels as k

    rng = np.random.default_rng(17)
    for _ in range(300):
        x = rng.standard_normal(int(rng.integers(40, 400))) * np.exp(rng.standard_normal())
        size = int(rng.integers(1, 30))
        first = int(rng.integers(0, len(x) - size - 4))
        last = min(first + int(rng.integers(0, 5)), len(x) - size)  # five alignments or fewer
        t, dots, squares = rng.standard_normal(size), np.empty(5), np.empty(5)
        k.five_dots(x, first, last, t, dots)
        k.five_squares(x, first, last, size, squares)
        for i, s in enumerate(range(first, last + 1)):
            assert dots[i] == k.window_dot(x, s, t) and squares[i] == k.pair_dot(x[s:s + size], x[s:s + size])
        starts, owns = rng.integers(0, len(x) - size + 1, 8), np.empty(8)
        k.eight_squares(x, starts, size, owns)
        assert all(owns[w] == k.pair_dot(x[s:s + size], x[s:s + size]) for w, s in enumerate(starts))
        assert k.largest_magnitude(x) == np.max(np.abs(x), initial=0.0)


def test_all_pole_filters_as_scipy():
    """The compiled all-pole filter gives scipy's ``lfilter([1.0], a, x)`` to the bit (the signs of zero too)."""
    from scipy.signal import lfilter

    from drumstroke.analysis._kernels import all_pole

    rng = np.random.default_rng(13)
    for trial in range(300):
        a = np.concatenate(([1.0], 0.1 * rng.standard_normal(int(rng.integers(1, 50)))))
        x = rng.standard_normal(int(rng.integers(1, 400)))
        if trial % 3 == 0:
            x[:len(x) // 2] = 0.0  # digital silence first
        if trial % 5 == 0:
            x = -np.abs(x)
            x[::3] = -0.0
        want, got = lfilter([1.0], a, x), all_pole(a, x)
        np.testing.assert_array_equal(got, want)
        np.testing.assert_array_equal(np.signbit(got), np.signbit(want))


def _write():
    out = {}
    for i, (name, signal, rate) in enumerate(cases()):
        got = _outputs(signal, rate)
        print(i, name, len(got["t"]), file=sys.stderr)
        out[f"{i}/name"] = np.array(name)
        out.update({f"{i}/{key}": value for key, value in got.items()})
    out["count"] = np.array(sum(1 for key in out if key.endswith("/name")))
    np.savez_compressed(REFERENCE, **out)


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    if "--write" in sys.argv:
        _write()
