"""render.audio: the snare synthesis against exact oracles, numpy's FFT, soundfile and librosa.

* the modes ring at f_1 · j_mn / j_01 (scipy's Bessel zeros, checked against the literature's
  ratios) and the FFT of a long render finds exactly those peaks;
* a single impact equals the module docstring's formula, written out here with the half-sine
  pulse's spectrum integrated numerically (scipy.integrate.quad), to 1e-9 full scale;
* superposition, strike position, louder and brighter with speed, snares on and off, no clipping;
* WAV files: 48 kHz, mono, PCM_24, written atomically, read back by soundfile;
* librosa's onset detector finds every impact of real strokes within ±5 ms.
"""

import os
import re
import time

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.signal import find_peaks
from scipy.special import jn_zeros, jv

import drumstroke
from drumstroke import ParameterError
from drumstroke.formats.wav import write_wav
from drumstroke.render.audio import (
    GAIN,
    N_MODES,
    PEAK,
    SAMPLE_RATE,
    SNARE_BAND,
    TAIL_DECAYS,
    Drum,
    membrane_modes,
    render_wav,
    synthesize,
)

LITERATURE_RATIOS = (1.0, 1.593, 2.136, 2.295, 2.653, 2.917)
"""f_mn / f_01 of an ideal membrane for (0,1), (1,1), (2,1), (0,2), (3,1), (1,2) (e.g. Fletcher & Rossing, Table 3.2)."""

QUIET = Drum(snares=False)


@pytest.fixture
def soundfile():
    return pytest.importorskip("soundfile")


@pytest.fixture
def librosa():
    return pytest.importorskip("librosa")


def spectrum(signal, size):
    """|FFT| of ``signal`` zero-padded to ``size`` samples, and its frequencies (Hz)."""
    return np.abs(np.fft.rfft(signal, size)), np.fft.rfftfreq(size, 1.0 / SAMPLE_RATE)


def names(*parts):
    """A pattern for a message that contains every one of ``parts`` (literally), in any order."""
    return "(?s)" + "".join(f"(?=.*{re.escape(part)})" for part in parts)


# -- modes ---------------------------------------------------------------------------------


def test_mode_ratios_match_the_literature():
    ratios, orders = membrane_modes(len(LITERATURE_RATIOS))
    np.testing.assert_allclose(ratios, LITERATURE_RATIOS, rtol=0, atol=1e-3)
    assert orders.tolist() == [[0, 1], [1, 1], [2, 1], [0, 2], [3, 1], [1, 2]]


def test_modes_are_the_lowest_bessel_zeros_in_order():
    ratios, orders = membrane_modes()
    assert len(ratios) == N_MODES >= 12
    assert np.all(np.diff(ratios) > 0)
    np.testing.assert_allclose(ratios, [jn_zeros(m, n)[-1] / jn_zeros(0, 1)[0] for m, n in orders], rtol=1e-15)
    # Every zero below the highest one listed is listed: none skipped.
    every = np.concatenate([jn_zeros(m, N_MODES) for m in range(N_MODES + 1)]) / jn_zeros(0, 1)[0]
    assert np.sum(every <= ratios[-1] * (1 + 1e-12)) == N_MODES


@pytest.mark.parametrize("fundamental", [190.0, 250.0])
def test_fft_peaks_are_at_the_bessel_ratios(fundamental):
    """One off-centre impact, snares off, rung out over 10 s, FFT zero-padded to 2^23 (0.006 Hz a bin).

    The prominent peaks (over 1e-3 of the largest) are exactly the 16 modes; each lies within
    0.02 Hz of f_1 · j_mn / j_01 for the first six and 0.25 Hz for all (the close pair at 4.601 and
    4.610 pulls each other's peak by ~0.1 Hz). Measured: ≤ 0.008 Hz and ≤ 0.16 Hz. The measured
    ratios peak_k / peak_1 match the literature's three decimals to 0.001.
    """
    drum = Drum(fundamental=fundamental, position=0.6, decay=1.0, snares=False)
    magnitude, frequency = spectrum(synthesize([0.0], [1.0], duration=10.0, drum=drum), 2**23)
    below = frequency < 6000.0
    peaks = frequency[find_peaks(magnitude[below], prominence=1e-3 * magnitude.max())[0]]
    ratios, _ = membrane_modes()

    assert len(peaks) == N_MODES
    error = peaks - fundamental * ratios
    assert np.abs(error[:6]).max() < 0.02
    assert np.abs(error).max() < 0.25
    np.testing.assert_allclose(peaks[:6] / peaks[0], LITERATURE_RATIOS, rtol=0, atol=1e-3)


def test_a_single_impact_matches_the_documented_formula():
    """x(t) = G·v·W_k·H(f_k, τ)·exp(-(t - t0)/T_k)·sin(2π f_k (t - t0)), summed over the modes.

    H is the pulse's Fourier magnitude integrated here numerically, and t0 falls between samples,
    so this also checks the sub-sample timing.
    """
    drum = Drum(fundamental=203.0, position=0.37, decay=0.2, contact_time=1.3e-3, snares=False)
    t0, speed = 0.0101 + 0.37 / SAMPLE_RATE, 2.2
    signal = synthesize([t0], [speed], duration=0.3, drum=drum)

    ratios, orders = membrane_modes()
    shape = np.abs([jv(m, jn_zeros(m, n)[-1] * drum.position) for m, n in orders])
    shape /= shape.sum()
    contact = drum.contact_time * speed**-0.2

    def pulse(frequency):
        """|∫ sin(π t/τ) e^{-2πift} dt| over the contact, over its value at f = 0 (2τ/π)."""
        w = 2 * np.pi * frequency
        real = quad(lambda t: np.sin(np.pi * t / contact) * np.cos(w * t), 0, contact)[0]
        imaginary = quad(lambda t: np.sin(np.pi * t / contact) * np.sin(w * t), 0, contact)[0]
        return np.hypot(real, imaginary) / (2 * contact / np.pi)

    t = np.arange(len(signal)) / SAMPLE_RATE - t0
    expected = np.zeros_like(t)
    for ratio, weight in zip(ratios, shape):
        frequency = drum.fundamental * ratio
        ring = np.exp(-t * ratio / drum.decay) * np.sin(2 * np.pi * frequency * t)
        expected += GAIN * speed * weight * pulse(frequency) * np.where(t >= 0, ring, 0.0)

    assert np.abs(signal).max() < PEAK  # not scaled down: the fixed gain applies
    np.testing.assert_allclose(signal, expected, rtol=0, atol=1e-9)


@pytest.mark.parametrize("drum", [QUIET, Drum()], ids=["snares off", "snares on"])
def test_impacts_superpose(drum, rng):
    times, speeds = rng.uniform(0.0, 0.4, 6), rng.uniform(0.05, 0.5, 6)
    alone = [synthesize([t], [v], duration=0.5, drum=drum) for t, v in zip(times, speeds)]
    together = synthesize(times, speeds, duration=0.5, drum=drum)
    assert np.abs(together).max() < PEAK
    np.testing.assert_allclose(together, np.sum(alone, axis=0), rtol=0, atol=1e-12)


def test_defaults_ring_out_after_the_last_impact():
    signal = synthesize([0.5, 0.2], [1.0, 1.0])
    assert len(signal) == round((0.5 + TAIL_DECAYS * Drum().decay) * SAMPLE_RATE)
    assert np.all(signal[: int(0.2 * SAMPLE_RATE)] == 0.0)
    assert synthesize([], []).tolist() == [0.0] * round(TAIL_DECAYS * Drum().decay * SAMPLE_RATE)
    assert len(synthesize([], [], duration=0.25)) == 12000


def test_renders_are_deterministic():
    times, speeds = [0.0, 0.1, 0.13], [0.5, 1.0, 0.2]
    np.testing.assert_array_equal(synthesize(times, speeds), synthesize(times, speeds))
    assert not np.array_equal(synthesize(times, speeds), synthesize(times, speeds, drum=Drum(seed=1)))


# -- strike position, speed ----------------------------------------------------------------


def test_a_centre_hit_excites_only_the_symmetric_modes():
    """The (1,1) mode at 1.593 f_1: absent at r = 0 (measured −53 dB, the neighbours' tails), present
    at r = 0.3 with the height the weights predict: |J_1(j_11 r)|/|J_0(j_01 r)| · H ratio · T ratio
    (a damped sine's spectral peak is proportional to amplitude × decay time); measured within 0.3 dB."""
    fundamental = 190.0
    ratios, _ = membrane_modes()

    def level(drum, frequency):
        magnitude, f = spectrum(synthesize([0.0], [1.0], duration=4.0, drum=drum), 2**22)
        peak = magnitude[np.abs(f - fundamental) < 1.0].max()
        return 20 * np.log10(magnitude[np.abs(f - frequency) < 1.0].max() / peak)

    centre, off = Drum(position=0.0, snares=False), Drum(position=0.3, snares=False)
    assert level(centre, fundamental * ratios[1]) < -45.0
    assert level(centre, fundamental * ratios[3]) > -15.0  # (0,2), symmetric, still rings

    j01, j11 = jn_zeros(0, 1)[0], jn_zeros(1, 1)[0]
    tau = 1e-3
    h = [abs(np.cos(np.pi * f * tau) / (1 - (2 * f * tau) ** 2)) for f in fundamental * ratios[:2]]
    predicted = 20 * np.log10(abs(jv(1, j11 * 0.3) / jv(0, j01 * 0.3)) * h[1] / h[0] / ratios[1])
    assert level(off, fundamental * ratios[1]) == pytest.approx(predicted, abs=1.0)


def test_faster_impacts_are_louder_and_brighter():
    """Snares off, one impact per speed: RMS, peak and spectral centroid all strictly increase."""
    speeds = [0.05, 0.1, 0.2, 0.5, 1.0, 2.0]
    signals = [synthesize([0.0], [v], duration=1.5, drum=QUIET) for v in speeds]
    rms = [np.sqrt(np.mean(s**2)) for s in signals]
    peak = [np.abs(s).max() for s in signals]
    power, frequency = [], None
    for s in signals:
        magnitude, frequency = spectrum(s, 2**17)
        power.append(magnitude**2)
    centroid = [np.sum(frequency * p) / np.sum(p) for p in power]

    assert max(peak) < PEAK  # none scaled down
    assert np.all(np.diff(rms) > 0)
    assert np.all(np.diff(peak) > 0)
    assert np.all(np.diff(centroid) > 0)


# -- snares --------------------------------------------------------------------------------


def band_energy(signal, low, high):
    magnitude, frequency = spectrum(signal, len(signal))
    return np.sum(magnitude[(frequency >= low) & (frequency <= high)] ** 2)


def test_snares_off_adds_exactly_nothing():
    times, speeds = [0.0, 0.2], [1.0, 0.4]
    off = synthesize(times, speeds, drum=Drum(snares=False))
    np.testing.assert_array_equal(off, synthesize(times, speeds, drum=Drum(snare_level=0.0)))
    np.testing.assert_array_equal(off, synthesize(times, speeds, drum=Drum(snares=False, seed=7)))


def test_snares_add_band_limited_noise_that_follows_the_impacts():
    """on − off is the snare part alone: exactly proportional to the tip speed, with ≥ 90 % of its energy
    in 2–9 kHz (measured 92.8 %: a 4th-order Butterworth's skirts) and ≥ 99.5 % in 1.5–12 kHz
    (measured 99.7 %). Without snares the 2–9 kHz band holds < 1e-3 of the energy it holds with them
    (measured 1.1e-4, −40 dB: the tails of the modes' spectra)."""
    low, high = SNARE_BAND
    on, off = synthesize([0.05], [1.0], duration=0.5), synthesize([0.05], [1.0], duration=0.5, drum=QUIET)
    snare = on - off
    total = band_energy(snare, 0.0, SAMPLE_RATE / 2)
    assert band_energy(snare, low, high) > 0.90 * total
    assert band_energy(snare, 1500.0, 12000.0) > 0.995 * total
    assert band_energy(off, low, high) < 1e-3 * band_energy(on, low, high)
    assert np.all(snare[: int(0.05 * SAMPLE_RATE)] == 0.0)

    softer = synthesize([0.05], [0.4], duration=0.5) - synthesize([0.05], [0.4], duration=0.5, drum=QUIET)
    assert np.abs(on).max() < PEAK  # not scaled down, so the difference is the snare part
    np.testing.assert_allclose(softer, 0.4 * snare, rtol=0, atol=1e-12)


# -- level ---------------------------------------------------------------------------------


def test_loud_strokes_are_scaled_down_not_clipped():
    times = np.linspace(0.0, 1.0, 100)
    signal = synthesize(times, np.full(100, 10.0))
    assert np.all(np.isfinite(signal))
    assert np.abs(signal).max() == pytest.approx(PEAK, rel=1e-12)
    assert np.all(np.abs(signal) <= PEAK)
    # The same stroke at a tenth of the speed is not scaled and keeps its own, lower level.
    quiet = synthesize(times, np.full(100, 0.1))
    assert np.abs(quiet).max() < 0.5 * PEAK


def test_a_long_render_is_fast(rng):
    """5 s with 200 impacts: measured ~0.1 s; required under 1 s (best of three)."""
    times, speeds = np.sort(rng.uniform(0.0, 4.9, 200)), rng.uniform(0.05, 2.0, 200)
    elapsed = []
    for _ in range(3):
        start = time.perf_counter()
        synthesize(times, speeds, duration=5.0)
        elapsed.append(time.perf_counter() - start)
    assert min(elapsed) < 1.0


# -- WAV files -----------------------------------------------------------------------------


def test_wav_round_trip(tmp_path, soundfile):
    path = tmp_path / "stroke.wav"
    signal = render_wav(path, [0.0, 0.1, 0.25], [1.0, 3.0, 0.4])
    info = soundfile.info(path)
    assert (info.samplerate, info.channels, info.format, info.subtype) == (48000, 1, "WAV", "PCM_24")
    back, rate = soundfile.read(path, dtype="float64")
    assert rate == SAMPLE_RATE and back.shape == signal.shape
    assert np.abs(back - signal).max() <= 2.0**-23
    assert np.abs(back - signal).max() > 0  # 24-bit quantisation did happen


def test_full_scale_is_written_without_wrapping(tmp_path, soundfile):
    path = tmp_path / "edges.wav"
    write_wav(path, [1.0, -1.0, 0.0, 0.5], rate=SAMPLE_RATE)
    back, _ = soundfile.read(path, dtype="float64")
    np.testing.assert_allclose(back, [1.0, -1.0, 0.0, 0.5], rtol=0, atol=2.0**-23)


@pytest.mark.parametrize("failure", ["encoder", "disk"])
def test_a_failed_write_leaves_the_old_file_whole(tmp_path, soundfile, monkeypatch, failure):
    path = tmp_path / "stroke.wav"
    write_wav(path, synthesize([0.0], [1.0], duration=0.1), rate=SAMPLE_RATE)
    old = path.read_bytes()

    def boom(*args, **kwargs):
        raise OSError("simulated failure")

    # The encoder fails before anything is written; the disk fails after the new bytes are in the
    # temporary file, before the rename.
    monkeypatch.setattr(*((soundfile, "write") if failure == "encoder" else (os, "fsync")), boom)
    with pytest.raises(OSError, match="simulated failure"):
        write_wav(path, synthesize([0.0], [2.0], duration=0.2), rate=SAMPLE_RATE)
    assert path.read_bytes() == old
    assert [p.name for p in tmp_path.iterdir()] == ["stroke.wav"]


# -- onsets: librosa on real strokes -------------------------------------------------------

HOP = 64
"""librosa's hop (samples): 1.3 ms at 48 kHz."""

SNARES_OFF = ("free-bounce", "high-low", "finger-pulses", "constant", "reversed-gravity")
SNARES_ON = ("finger-pulses",)


def detect_onsets(librosa, signal, rate):
    """Onset times (s) from librosa's spectral-flux detector.

    A 512-sample window (10.7 ms) and 32 mel bands; peaks must top the previous 10 ms (librosa's
    default 30 ms, and its 30 ms ``wait``, would drop bounces 17 ms apart by construction), and
    clear the local mean by 0.05 of the envelope's range (librosa's default is 0.07).
    """
    envelope = librosa.onset.onset_strength(y=signal, sr=rate, hop_length=HOP, n_fft=512, n_mels=32)
    return librosa.onset.onset_detect(onset_envelope=envelope, sr=rate, hop_length=HOP, units="time",
                                      pre_max=round(0.010 * rate / HOP), post_max=1, wait=0, delta=0.05)


@pytest.mark.parametrize(("name", "snares"), [(n, False) for n in SNARES_OFF] + [(n, True) for n in SNARES_ON])
def test_librosa_finds_every_impact_of_real_strokes(name, snares, tmp_path, soundfile, librosa):
    """Every impact louder than −30 dB (re the stroke's loudest) has an onset within ±5 ms, and every
    onset lies within ±5 ms of some impact (of any level).

    Which strokes: those whose impacts above −30 dB are at least 10 ms apart (asserted below):
    free-bounce (closest 16.8 ms, the quiet end of its decrescendo), high-low (35 ms), finger-pulses
    (0.38 s), constant (11 ms), reversed-gravity (26 ms). Left out: low-high (5.3 ms), rising-gravity
    (4.7 ms), superhuman-press (3.2 ms) — impacts closer than the ±5 ms tolerance and half the
    10.7 ms analysis window cannot be told apart by any onset detector; librosa merges them.

    With snares: only finger-pulses. The snare noise's spectrum fluctuates by several dB from frame to
    frame (noise periodograms), while an impact at the end of free-bounce's decrescendo, 17 ms and
    1.3 dB after the previous one, raises the ringing snare envelope by about 1.3 dB; librosa then
    misses 2–3 of free-bounce's 23 impacts and reports false onsets in the noise. The membrane's modes
    are deterministic, so with snares off even these small rises are clean flux peaks.
    Measured worst timing errors: ≤ 3.3 ms.
    """
    stroke = drumstroke.simulate(name)
    times, speeds = stroke.impacts.t, stroke.impacts.tip_speed
    checked = times[20 * np.log10(speeds / speeds.max()) > -30.0]
    assert np.diff(checked).min() >= 0.010

    path = tmp_path / f"{name}.wav"
    render_wav(path, times, speeds, drum=Drum(snares=snares))
    signal, rate = soundfile.read(path, dtype="float64")
    onsets = detect_onsets(librosa, signal, rate)

    miss = np.array([np.abs(onsets - t).min() for t in checked])
    assert miss.max() <= 0.005, f"impacts at {checked[miss > 0.005]} s have no onset within 5 ms"
    stray = np.array([np.abs(times - t).min() for t in onsets])
    assert stray.max() <= 0.005, f"onsets at {onsets[stray > 0.005]} s are not within 5 ms of an impact"


# -- bad input -----------------------------------------------------------------------------

NAN, INF = float("nan"), float("inf")


@pytest.mark.parametrize(
    ("call", "parts"),
    [
        pytest.param(lambda: synthesize([0.0, NAN], [1.0, 1.0]), ("times[1]", "nan", "[0, inf) s"), id="nan time"),
        pytest.param(lambda: synthesize([INF], [1.0]), ("times[0]", "inf", "[0, inf) s"), id="inf time"),
        pytest.param(lambda: synthesize([-0.1], [1.0]), ("times[0]", "-0.1", "[0, inf) s"), id="negative time"),
        pytest.param(lambda: synthesize([0, 1, 2, 3], [1, 1, 1, -2.5]), ("tip_speeds[3]", "-2.5", "[0, inf) m/s"),
                     id="negative speed"),
        pytest.param(lambda: synthesize([0.0], [NAN]), ("tip_speeds[0]", "nan", "m/s"), id="nan speed"),
        pytest.param(lambda: synthesize([0.0, 0.1], [1.0]), ("same length", "2", "1"), id="mismatched lengths"),
        pytest.param(lambda: synthesize([[0.0]], [[1.0]]), ("times", "1-D", "(1, 1)"), id="2-D times"),
        pytest.param(lambda: synthesize(["soon"], [1.0]), ("times", "numbers", "'soon'"), id="text times"),
        pytest.param(lambda: synthesize([0.5], [1.0], duration=0.2), ("duration", "[0.5, inf) s", "0.2"),
                     id="duration before the last impact"),
        pytest.param(lambda: synthesize([0.5], [1.0], duration=NAN), ("duration", "nan"), id="nan duration"),
        pytest.param(lambda: synthesize([0.0], [1.0], rate=8000), ("rate", "(18000, inf) Hz", "8000"), id="low rate"),
        pytest.param(lambda: synthesize([0.0], [1.0], drum="snare"), ("drum", "Drum", "'snare'"), id="not a drum"),
        pytest.param(lambda: Drum(fundamental=10.0), ("fundamental", "[20, 1000] Hz", "10.0"), id="fundamental"),
        pytest.param(lambda: Drum(position=1.0), ("position", "[0, 1)", "1.0"), id="position at the rim"),
        pytest.param(lambda: Drum(position=-0.1), ("position", "[0, 1)", "-0.1"), id="negative position"),
        pytest.param(lambda: Drum(decay=0.0), ("decay", "(0, 10] s", "0.0"), id="decay"),
        pytest.param(lambda: Drum(contact_time=NAN), ("contact_time", "(0, 0.01] s", "nan"), id="contact time"),
        pytest.param(lambda: Drum(snares="yes"), ("snares", "True or False", "'yes'"), id="snares"),
        pytest.param(lambda: Drum(snare_level=-1.0), ("snare_level", "[0, 10]", "-1.0"), id="snare level"),
        pytest.param(lambda: Drum(snare_decay=2.0), ("snare_decay", "(0, 1] s", "2.0"), id="snare decay"),
        pytest.param(lambda: Drum(seed=-1), ("seed", "[0, inf)", "-1"), id="negative seed"),
        pytest.param(lambda: Drum(seed=1.5), ("seed", "integer", "1.5"), id="fractional seed"),
        pytest.param(lambda: membrane_modes(0), ("count", "[1, inf)", "0"), id="no modes"),
    ],
)
def test_bad_input_is_a_parameter_error(call, parts):
    with pytest.raises(ParameterError, match=names(*parts)):
        call()


@pytest.mark.parametrize(
    ("signal", "rate", "parts"),
    [
        pytest.param([0.0, 1.5], SAMPLE_RATE, ("signal[1]", "[-1, 1]", "1.5"), id="over full scale"),
        pytest.param([-1.0001], SAMPLE_RATE, ("signal[0]", "[-1, 1]", "-1.0001"), id="under full scale"),
        pytest.param([0.0, 0.0, NAN], SAMPLE_RATE, ("signal[2]", "finite", "nan"), id="nan sample"),
        pytest.param([[0.0, 0.1]], SAMPLE_RATE, ("signal", "1-D", "(1, 2)"), id="two-dimensional"),
        pytest.param(["loud"], SAMPLE_RATE, ("signal", "numbers", "'loud'"), id="text"),
        pytest.param([0.0], 44100.5, ("rate", "integer", "44100.5"), id="fractional rate"),
        pytest.param([0.0], 0, ("rate", "[1, inf) Hz", "0"), id="zero rate"),
    ],
)
def test_bad_signals_are_not_written(tmp_path, soundfile, signal, rate, parts):
    path = tmp_path / "bad.wav"
    with pytest.raises(ParameterError, match=names(*parts)):
        write_wav(path, signal, rate=rate)
    assert not path.exists()
