"""Recordings with known impacts for the analysis tests and benchmark: our renderer, another synthesis, noise, a room.

- :func:`random_strokes`: strokes from random recipes (``simulate_many``: thumb force, start, c).
- :func:`render`: their impacts rendered by ``render.audio`` (snares on or off) or by :func:`other_drum`
  (a damped noise click and six inharmonic modes in cosine phase: not our renderer), then
  reverberated by a room impulse response from pyroomacoustics (:func:`room_response`) and
  noised to an SNR (the mean power of the signal over that of white noise, in dB).
- :func:`score`: the detection against the truth, per impact louder than a level.
"""

import numpy as np

RATE = 48000


def random_strokes(count, *, seed, t_end=2.5):
    """``count`` strokes of random recipes: force 0–60 m/s², θ0 0.05–0.5 rad, c 0.6–0.9 (the ``paper`` model)."""
    from drumstroke.stroke import simulate_many

    rng = np.random.default_rng(seed)
    batch = simulate_many(force=rng.uniform(0.0, 60.0, count), theta0=rng.uniform(0.05, 0.5, count),
                          cor=rng.uniform(0.6, 0.9, count), t_end=t_end)
    return [(impacts.t, impacts.tip_speed) for impacts in batch.impacts]


def other_drum(times, speeds, *, rate=RATE, duration, seed=0):
    """Another drum than ours: each impact a decaying noise click (2 ms) and six inharmonic modes in cosine phase.

    Amplitude in proportion to the tip speed; the modes (Hz) 151, 347, 523, 739, 1046, 1459 decay
    in 0.4 s to 0.06 s; the click is white noise decaying in 2 ms at 0.5 of the modes' amplitude.
    """
    rng = np.random.default_rng(seed)
    size = round(duration * rate)
    out = np.zeros(size)
    modes = np.array([151.0, 347.0, 523.0, 739.0, 1046.0, 1459.0])
    decays = np.array([0.4, 0.25, 0.18, 0.12, 0.09, 0.06])
    weights = np.array([1.0, 0.7, 0.5, 0.45, 0.3, 0.25]) / 3.2
    length = round(1.5 * rate)
    for t0, v in zip(times, speeds):
        start = int(np.ceil(t0 * rate))
        if start >= size:
            continue
        n = min(length, size - start)
        tau = (start + np.arange(n)) / rate - t0  # time since the impact, ≥ 0
        ring = (weights[:, None] * np.exp(-tau / decays[:, None]) * np.cos(2 * np.pi * modes[:, None] * tau)).sum(0)
        click = 0.5 * rng.standard_normal(n) * np.exp(-tau / 0.002)
        out[start:start + n] += v * (ring + click)
    return out


def room_response(*, rate=RATE, rt60=0.35, seed=0):
    """A room's impulse response (pyroomacoustics, image sources: a 6 × 5 × 3 m room, RT60 ``rt60`` s, 1.2 m apart).

    Trimmed to start 2 samples before its direct sound's peak and scaled so that peak is 1; the
    delay to add to the impact times is 2 samples.
    """
    import pyroomacoustics as pra

    absorption, order = pra.inverse_sabine(rt60, [6.0, 5.0, 3.0])
    room = pra.ShoeBox([6.0, 5.0, 3.0], fs=rate, materials=pra.Material(absorption), max_order=min(order, 12))
    room.add_source([2.0, 2.5, 1.0])
    room.add_microphone([3.2, 2.5, 1.0])
    room.compute_rir()
    rir = np.asarray(room.rir[0][0], dtype=float)
    peak = int(np.argmax(np.abs(rir[: rate // 50])))
    rir = rir[peak - 2:]
    return rir / rir[2]


def render(times, speeds, *, kind="ours", snares=True, snr=None, room=None, seed=0, rate=RATE, tail=0.4):
    """A recording of impacts: the signal (full scale) and the times its impacts start (s)."""
    from scipy.signal import fftconvolve

    from drumstroke.render.audio import Drum, synthesize

    duration = float(times[-1]) + tail
    if kind == "ours":
        signal = synthesize(times, speeds, duration=duration, drum=Drum(snares=snares, seed=seed), rate=rate)
    else:
        signal = other_drum(times, speeds, rate=rate, duration=duration, seed=seed)
    onsets = np.asarray(times, dtype=float)
    if room is not None:
        signal = fftconvolve(signal, room)[: len(signal)]
        onsets = onsets + 2.0 / rate
    if snr is not None:
        rng = np.random.default_rng(seed + 1)
        signal = signal + rng.standard_normal(len(signal)) * np.sqrt(np.mean(signal**2) / 10.0 ** (snr / 10.0))
    peak = np.abs(signal).max()
    return signal * (0.9 / peak) if peak > 0.9 else signal, onsets


def score(found, times, speeds, *, loudest_db=-30.0, window=1e-3):
    """Recall (within ``window``) of the impacts louder than ``loudest_db`` re the loudest, timing errors, extras.

    Returns
    -------
    dict
        ``loud`` (how many impacts above the level), ``found`` (of those, matched within the window),
        ``errors`` (found − true, s, of those matched), ``extra`` (found onsets farther than the
        window from every impact, whatever its level), ``level_errors`` (found − true level, dB, of
        those matched; true levels 20·log10(v / v_max)).
    """
    from drumstroke.robot.metrics import match_onsets

    level = 20.0 * np.log10(np.maximum(speeds, 1e-300) / np.max(speeds))
    loud = level >= loudest_db
    pairs = match_onsets(np.asarray(times)[loud], found.t, window=window)
    matched = pairs >= 0
    errors = found.t[pairs[matched]] - np.asarray(times)[loud][matched]
    level_errors = found.level_db[pairs[matched]] - level[loud][matched]
    every = match_onsets(np.asarray(times), found.t, window=window)
    extra = len(found) - int(np.count_nonzero(every >= 0))
    return {"loud": int(loud.sum()), "found": int(matched.sum()), "errors": errors, "extra": extra,
            "level_errors": level_errors}


def uneven_noise(rng, n):
    """Noise whose level wanders over some 60 dB, with a stretch of digital silence (for compiled kernels' tests)."""
    x = rng.standard_normal(n) * np.exp(3.0 * rng.standard_normal(n))
    start = int(rng.integers(0, n))
    x[start:start + n // 5] = 0.0
    return x


def sample_player(ghosts, *, accents=4, ringing=0.03, seed=5, rate=RATE):
    """A sample player's recording: one accent waveform (the same samples, scaled by 1 - 0.02 k; noise ringing down
    with time constant ``ringing`` s) at ``accents`` times 0.45 s apart from 0.1 s, and one ghost waveform 26 dB
    under it ``ghosts[k]`` samples after accent ``k``. Returns the signal, the accents' samples and the ghosts'."""
    rng = np.random.default_rng(seed)
    n = np.arange(round(0.4 * rate))
    accent = rng.standard_normal(len(n)) * np.exp(-n / (ringing * rate)) * 0.5
    ghost = rng.standard_normal(round(0.1 * rate)) * np.exp(-np.arange(round(0.1 * rate)) / (0.02 * rate)) * 0.025
    ghost[0] = 0.025
    band = np.zeros(round((0.1 + 0.45 * accents + 0.4) * rate))
    starts = [round((0.1 + 0.45 * k) * rate) for k in range(accents)]
    for k, at in enumerate(starts):
        band[at:at + len(accent)] += accent * (1.0 - 0.02 * k)
        if k in ghosts:
            band[at + ghosts[k]:at + ghosts[k] + len(ghost)] += ghost
    return band, starts, sorted(starts[k] + g for k, g in ghosts.items())
