"""render.kit_audio and render.soundfont: the whole kit's hits as audio, both ways, against third-party tools.

* drumstroke's own synthesis: the snare through the kit is today's snare sample for sample; the mix is
  the sum of its pieces; each tom sounds at the ideal membrane's f_1 for its diameter (numpy's FFT
  against j_01 from the literature); a cymbal's spectral centroid is far above the kick's, whose energy
  lies below 150 Hz; a closed hi-hat dies far sooner than an open one; faster hits are louder;
* both renderings: librosa's onset detector finds every hit of a well-spaced pattern on every piece
  (mir_eval's F-measure in a ±5 ms window);
* the SoundFont path: the MIDI file, read back by mido, holds each hit's key, velocity and time on
  channel 10; FluidSynth's audio has energy at each note and grows with the velocity;
* bad input — a hit on no piece, a missing, foreign, truncated or corrupt SoundFont, no FluidSynth,
  a timeout — is one ParameterError naming what is wrong.
"""

import re
import shutil
import struct

import numpy as np
import pytest

from drumstroke import ParameterError
from drumstroke.dynamics import level_to_velocity
from drumstroke.kit.pieces import default_kit
from drumstroke.render.audio import SAMPLE_RATE, Drum, synthesize
from drumstroke.render.kit_audio import (
    HEAD_WAVE_SPEED,
    HIHAT,
    INCH,
    KitHits,
    kit_voice,
    render_kit_wav,
    synthesize_kit,
)
from drumstroke.render.soundfont import (
    DEBIAN_SOUNDFONT,
    check_soundfont,
    render_soundfont,
    render_soundfont_wav,
    write_kit_midi,
)

J01 = 2.404825557695773
"""The first zero of J_0 (Abramowitz & Stegun, Table 9.5)."""

EVERY_PIECE = [("kick", 36), ("snare", 38), ("hihat", 42), ("tom1", 50), ("hihat", 46), ("tom2", 47),
               ("hihat", 44), ("floor-tom", 43), ("ride", 51), ("ride-bell", 53), ("crash", 49)]
"""Each piece of the default kit, and each state of its hi-hat, once."""

PATTERN = KitHits.from_rows([(0.1 + 0.3 * i, name, key, 1.5) for i, (name, key) in enumerate(EVERY_PIECE)])
"""A simple, well-spaced pattern: each piece once, 0.3 s apart, at 1.5 m/s."""

HOP = 64
"""librosa's hop (samples): 1.3 ms at 48 kHz."""


@pytest.fixture(scope="module")
def soundfont():
    """Debian's FluidR3 soundfont; without FluidSynth and it the tests fail (CI installs both), they never skip."""
    assert shutil.which("fluidsynth") is not None and DEBIAN_SOUNDFONT.is_file(), (
        "needs fluidsynth and fluid-soundfont-gm: sh scripts/install-system-packages.sh")
    return DEBIAN_SOUNDFONT


def names(*parts):
    """A pattern for a message that contains every one of ``parts`` (literally), in any order."""
    return "(?s)" + "".join(f"(?=.*{re.escape(part)})" for part in parts)


def kit_piece(name):
    return default_kit().piece(name)


def one(name, key, speed=1.0, duration=2.0):
    return synthesize_kit([(0.0, name, key, speed)], duration=duration)


def power_spectrum(signal):
    return np.abs(np.fft.rfft(signal)) ** 2, np.fft.rfftfreq(len(signal), 1.0 / SAMPLE_RATE)


def centroid(signal):
    power, frequencies = power_spectrum(signal)
    return float(np.sum(power * frequencies) / np.sum(power))


def decay_time(signal, drop_db=20.0):
    """Seconds from the peak of the 5-ms RMS envelope until it first falls ``drop_db`` below it."""
    window = round(0.005 * SAMPLE_RATE)
    envelope = np.sqrt(np.convolve(signal**2, np.ones(window) / window, mode="same"))
    peak = int(envelope.argmax())
    below = np.flatnonzero(envelope[peak:] < envelope[peak] * 10 ** (-drop_db / 20))
    return below[0] / SAMPLE_RATE


def onsets(signal):
    """librosa's spectral-flux onsets (s) at a 1.3-ms hop, 512-sample windows, 32 mel bands, its default peak
    picking in time (a peak tops the last 30 ms, clears the local mean by 0.07, 30 ms after the last)."""
    import librosa
    envelope = librosa.onset.onset_strength(y=signal, sr=SAMPLE_RATE, hop_length=HOP, n_fft=512, n_mels=32)
    frames = round(0.03 * SAMPLE_RATE / HOP)
    return librosa.onset.onset_detect(onset_envelope=envelope, sr=SAMPLE_RATE, hop_length=HOP, units="time",
                                      pre_max=frames, post_max=1, pre_avg=3 * frames, post_avg=frames + 1,
                                      wait=frames, delta=0.07)


def f_measure(reference, estimated):
    import mir_eval
    return mir_eval.onset.f_measure(np.asarray(reference), np.asarray(estimated), window=0.005)[0]


# -- drumstroke's own synthesis ---------------------------------------------------------------------------


def test_the_snare_through_the_kit_is_todays_snare_exactly():
    times, speeds = [0.0, 0.13, 0.4, 0.41], [1.0, 0.2, 3.5, 0.05]
    hits = KitHits(times, ["snare"] * 4, [38, 40, 38, 37], speeds)
    np.testing.assert_array_equal(synthesize_kit(hits), synthesize(times, speeds))
    np.testing.assert_array_equal(synthesize_kit(hits, duration=0.5, rate=44100),
                                  synthesize(times, speeds, duration=0.5, rate=44100))


def test_the_mix_is_the_sum_of_its_pieces():
    """Every hit rings on its own, except the hi-hat's: its state follows the part (a later hit's state sets how
    its modes decay from then on), so its hits are one part."""
    rows = list(zip(PATTERN.t, PATTERN.piece, PATTERN.key, PATTERN.speed))
    parts = [synthesize_kit([row], duration=3.6) for row in rows if row[1] != "hihat"]
    parts.append(synthesize_kit([row for row in rows if row[1] == "hihat"], duration=3.6))
    mix = synthesize_kit(PATTERN, duration=3.6)
    assert np.abs(mix).max() < 0.99  # not scaled down
    np.testing.assert_allclose(mix, np.sum(parts, axis=0), rtol=0, atol=1e-12)


@pytest.mark.parametrize(("piece", "key", "inches"), [("tom1", 50, 10.0), ("tom2", 47, 13.0), ("floor-tom", 43, 16.0)])
def test_each_tom_sounds_at_its_membranes_fundamental(piece, key, inches):
    expected = J01 * HEAD_WAVE_SPEED / (np.pi * inches * INCH)
    signal = one(piece, key, duration=4.0)
    power, frequencies = power_spectrum(np.pad(signal, (0, 4 * len(signal))))  # 0.05 Hz bins
    low = frequencies < 1.3 * expected  # below the second mode (1.593 f_1)
    assert frequencies[low][np.argmax(power[low])] == pytest.approx(expected, abs=0.1)


def test_the_drums_pitches_fall_from_the_high_tom_to_the_kick():
    kit_pitches = [kit_voice(piece, key).fundamental for piece, key in
                   [(kit_piece("tom1"), 50), (kit_piece("tom2"), 45), (kit_piece("floor-tom"), 41), (kit_piece("kick"), 35)]]
    assert kit_pitches == sorted(kit_pitches, reverse=True)
    assert kit_pitches[-1] <= 60.0  # the kick is tuned low


def test_a_cymbals_centroid_is_far_above_the_kicks_whose_energy_is_below_150_hz():
    kick = one("kick", 36)
    power, frequencies = power_spectrum(kick)
    below = power[frequencies < 150.0].sum() / power.sum()
    centroids = {name: centroid(one(name, key)) for name, key in
                 [("kick", 36), ("crash", 49), ("ride", 51), ("ride-bell", 53), ("hihat", 42)]}
    print(f"kick below 150 Hz: {below:.3f}; centroids (Hz): {centroids}")
    assert below >= 0.9
    for name in ("crash", "ride", "ride-bell", "hihat"):
        assert centroids[name] >= 10 * centroids["kick"], name
    assert centroids["crash"] > centroids["ride"]  # the crash's wash is brighter than the ride's ping and ring


def test_a_closed_hihat_dies_far_sooner_than_an_open_one():
    closed, opened, pedal = (decay_time(one("hihat", key)) for key in (42, 46, 44))
    print(f"-20 dB: closed {closed * 1e3:.0f} ms, open {opened * 1e3:.0f} ms, pedal {pedal * 1e3:.0f} ms")
    assert closed <= 0.1 and pedal <= 0.1
    assert opened >= 5 * closed
    # the pedal's chick: the two plates' long contact leaves it darker than a stick's tick on them
    assert centroid(one("hihat", 44)) < 0.5 * centroid(one("hihat", 42))


def decay_from_wav(path, drop_db=30.0):
    """Seconds from the peak of a WAV file's 5-ms RMS envelope (numpy over soundfile's samples) until its last
    sample at or above ``drop_db`` below that peak."""
    import soundfile

    signal, rate = soundfile.read(path)
    window = round(0.005 * rate)
    envelope = np.sqrt(np.convolve(signal**2, np.ones(window) / window, mode="same"))
    peak = int(envelope.argmax())
    above = np.flatnonzero(envelope[peak:] >= envelope[peak] * 10 ** (-drop_db / 20))
    return above[-1] / rate


def test_the_hi_hat_rings_longer_the_more_open_it_is(tmp_path):
    """A hit on each state, written as a WAV and read back: its -30 dB decay grows closed < half < open, and the
    foot's chick is as short as a closed tick."""
    decays = {}
    for state, key in {"closed": 42, "half": 23, "open": 46, "pedal": 44}.items():
        assert kit_piece("hihat").state(key) == state
        render_kit_wav(tmp_path / f"{state}.wav", [(0.0, "hihat", key, 1.0)], duration=3.0)
        decays[state] = decay_from_wav(tmp_path / f"{state}.wav")
    print({state: f"{1e3 * t:.0f} ms" for state, t in decays.items()})
    assert decays["closed"] < decays["half"] < decays["open"]
    assert 2 * decays["closed"] < decays["half"] and 2 * decays["half"] < decays["open"]  # well apart, not a nudge
    assert decays["pedal"] < decays["half"]


@pytest.mark.parametrize("closing", [42, 44])
def test_closing_the_hi_hat_chokes_its_open_ring(closing):
    """An open hit's wash is cut when the hi-hat closes (a closed note, or the foot's chick): 0.2 s after the close
    it is 30 dB below the same open hit left ringing, as far down as the close's own tick alone."""
    opened = synthesize_kit([(0.0, "hihat", 46, 1.0)], duration=1.0)
    closed_alone = synthesize_kit([(0.3, "hihat", closing, 1.0)], duration=1.0)
    choked = synthesize_kit([(0.0, "hihat", 46, 1.0), (0.3, "hihat", closing, 1.0)], duration=1.0)
    late = slice(round(0.5 * SAMPLE_RATE), round(0.7 * SAMPLE_RATE))

    def rms(signal):
        return float(np.sqrt(np.mean(signal[late] ** 2)))

    assert rms(choked) < 10 ** (-30 / 20) * rms(opened)
    assert rms(choked) < 2 * rms(closed_alone) + 1e-9
    np.testing.assert_array_equal(choked[: round(0.3 * SAMPLE_RATE)], opened[: round(0.3 * SAMPLE_RATE)])


def test_opening_the_hi_hat_leaves_what_rings_ringing_longer():
    """A closed tick, then an open hit: from the open hit on, the tick's remains decay at the open rate, so the pair
    differs from the two hits rendered apart only by that remainder, tiny beside the open hit's wash."""
    pair = synthesize_kit([(0.0, "hihat", 42, 1.0), (0.3, "hihat", 46, 1.0)], duration=1.0)
    apart = (synthesize_kit([(0.0, "hihat", 42, 1.0)], duration=1.0)
             + synthesize_kit([(0.3, "hihat", 46, 1.0)], duration=1.0))
    after = slice(round(0.3 * SAMPLE_RATE), None)
    assert np.abs(pair[after] - apart[after]).max() < 1e-3 * np.abs(apart[after]).max()


@pytest.mark.parametrize(("piece", "key"), EVERY_PIECE)
def test_faster_hits_are_louder(piece, key):
    speeds = [0.1, 0.25, 0.5, 1.0, 2.0]
    signals = [one(piece, key, speed, duration=1.0) for speed in speeds]
    assert max(np.abs(s).max() for s in signals) < 0.99  # none scaled down
    rms = np.array([np.sqrt(np.mean(s**2)) for s in signals])
    assert np.all(np.diff(rms) > 0)
    # about in proportion to v: the amplitude is, the contact's spectrum adds a little brightness
    assert np.all((rms[1:] / rms[:-1] >= 1.8) & (rms[1:] / rms[:-1] <= 3.0 * np.array(speeds[1:]) / speeds[:-1]))


def test_librosa_finds_every_hit_of_the_own_synthesis():
    found = onsets(synthesize_kit(PATTERN, duration=3.8))
    score = f_measure(PATTERN.t, found)
    print(f"own synthesis: F = {score:.3f}, onsets {np.round(found, 4).tolist()}")
    assert score >= 0.9


def test_the_wav_file_holds_the_signal(tmp_path):
    import soundfile
    path = tmp_path / "kit.wav"
    signal = render_kit_wav(path, PATTERN, duration=3.5)
    written, rate = soundfile.read(path)
    assert rate == SAMPLE_RATE and written.shape == signal.shape == (round(3.5 * SAMPLE_RATE),)
    np.testing.assert_allclose(written, signal, rtol=0, atol=2.0**-23)
    assert [p.name for p in tmp_path.iterdir()] == ["kit.wav"]


def test_the_default_length_rings_out_and_empty_is_silence():
    assert len(synthesize_kit([(0.0, "snare", 38, 1.0)])) == len(synthesize([0.0], [1.0]))
    assert len(synthesize_kit([(0.0, "crash", 49, 1.0)])) > len(synthesize([0.0], [1.0]))  # a cymbal rings longer
    silence = synthesize_kit([], duration=0.1)
    assert silence.shape == (4800,) and not silence.any()


@pytest.mark.parametrize(("hits", "message"), [
    ([(0.0, "cowbell", 56, 1.0)], ("hit 0", "piece must be one of", "'cowbell'")),
    ([(0.0, "snare", 38, 1.0), (0.5, "snare", 42, 1.0)], ("hit 1", "t = 0.5 s", "pieces.snare's keys", "42")),
    ([(0.0, "snare", 38)], ("rows must be",)),
    ([(-1.0, "snare", 38, 1.0)], ("t[0]", "[0, inf) s", "-1.0")),
    ([(0.0, "snare", 38, float("nan"))], ("speed[0]", "m/s", "nan")),
    ([(0.0, "snare", 38.5, 1.0)], ("key[0]", "integer in [0, 127]", "38.5")),
    ([(0.0, "snare", 128, 1.0)], ("key[0]", "[0, 127]", "128")),
    ([(0.0, 38, 38, 1.0)], ("piece[0]", "38")),
])
def test_bad_hits_are_refused(hits, message):
    with pytest.raises(ParameterError, match=names(*message)):
        synthesize_kit(hits, duration=1.0)


def test_hits_of_unequal_lengths_are_refused():
    with pytest.raises(ParameterError, match=names("t, piece, key and speed", "same length", "1, 1, 2 and 1")):
        KitHits([0.0], ["snare"], [38, 40], [1.0])


def test_bad_options_are_refused(tmp_path):
    with pytest.raises(ParameterError, match=names("duration", "0.5")):
        synthesize_kit([(0.5, "snare", 38, 1.0)], duration=0.4)
    with pytest.raises(ParameterError, match=names("rate", "Hz")):
        synthesize_kit([(0.0, "snare", 38, 1.0)], rate=8000)
    with pytest.raises(ParameterError, match=names("kit", "Kit")):
        synthesize_kit([(0.0, "snare", 38, 1.0)], kit="default")
    with pytest.raises(ParameterError, match=names("path", ".wav")):
        render_kit_wav(tmp_path / "kit.mp3", PATTERN)
    assert not list(tmp_path.iterdir())
    assert kit_voice(kit_piece("hihat"), 44) == HIHAT["pedal"] and kit_voice(kit_piece("snare"), 40) == Drum()


# -- through a SoundFont ------------------------------------------------------------------------------------


def test_the_midi_file_holds_each_hits_key_velocity_and_time(tmp_path):
    import mido
    path = tmp_path / "kit.mid"
    write_kit_midi(path, PATTERN)
    heard, now = [], 0.0
    for message in mido.MidiFile(path):  # mido's own clock: seconds from the tempo map
        now += message.time
        if message.type == "note_on" and message.velocity > 0:
            heard.append((now, message.channel, message.note, message.velocity))
    assert [h[1] for h in heard] == [9] * len(PATTERN)  # channel 10, counted from 1
    assert [h[2] for h in heard] == PATTERN.key.tolist()
    assert [h[3] for h in heard] == [level_to_velocity(20 * np.log10(v)) for v in PATTERN.speed] == [105] * len(PATTERN)
    np.testing.assert_allclose([h[0] for h in heard], PATTERN.t, rtol=0, atol=5e-4)


def test_fluidsynth_plays_every_hit_where_it_is(soundfont, tmp_path):
    import soundfile
    path = tmp_path / "kit.wav"
    signal = render_soundfont_wav(path, PATTERN, soundfont, duration=3.8)
    written, rate = soundfile.read(path)
    assert rate == SAMPLE_RATE and written.shape == signal.shape == (round(3.8 * SAMPLE_RATE),)
    window = round(0.05 * SAMPLE_RATE)
    level = [20 * np.log10(np.sqrt(np.mean(signal[round(t * SAMPLE_RATE):][:window] ** 2))) for t in PATTERN.t]
    found = onsets(signal)
    # FluidSynth starts a note at the next 64-sample block (up to 1.3 ms late), and FluidR3's drum samples
    # open with 1.7-3.6 ms of near silence before their attack: the onsets come a few ms late, together
    lag = float(np.median([found[np.abs(found - t).argmin()] - t for t in PATTERN.t]))
    score = f_measure(PATTERN.t, found - lag)
    print(f"FluidSynth: lag {lag * 1e3:.1f} ms, F = {score:.3f} after it ({f_measure(PATTERN.t, found):.3f} before), "
          f"onsets {np.round(found, 4).tolist()}; dBFS in the 50 ms after each note {np.round(level, 1).tolist()}")
    assert min(level) > -45.0
    assert 0.0 <= lag <= 0.006
    assert score >= 0.9


def test_a_faster_hit_is_louder_through_the_soundfont(soundfont):
    rms = [np.sqrt(np.mean(render_soundfont([(0.0, "snare", 38, v)], soundfont, duration=0.3) ** 2))
           for v in (0.1, 0.5, 2.0)]
    assert rms[0] < rms[1] < rms[2]


def test_the_half_open_hi_hat_sounds_through_the_soundfont_as_the_open_one(soundfont):
    """General MIDI has no half-open hi-hat: the kit's key 23 plays the open hi-hat's sample (46), not silence."""
    half, open_ = (render_soundfont([(0.0, "hihat", key, 1.0)], soundfont, duration=0.3) for key in (23, 46))
    assert np.sqrt(np.mean(half ** 2)) > 1e-3
    np.testing.assert_array_equal(half, open_)


def test_bad_soundfonts_are_refused(soundfont, tmp_path):
    hits = [(0.0, "snare", 38, 1.0)]
    with pytest.raises(ParameterError, match=names("soundfont", "missing.sf2", "is missing")):
        render_soundfont(hits, tmp_path / "missing.sf2")
    text = tmp_path / "text.sf2"
    text.write_text("not a soundfont")
    with pytest.raises(ParameterError, match=names("text.sf2", "not a SoundFont 2 file")):
        render_soundfont(hits, text)
    truncated = tmp_path / "truncated.sf2"
    truncated.write_bytes(soundfont.read_bytes()[:100_000])
    with pytest.raises(ParameterError, match=names("truncated.sf2", "damaged", "100000")):
        render_soundfont(hits, truncated)
    corrupt = tmp_path / "corrupt.sf2"  # a whole RIFF sfbk form of nothing but zeros: FluidSynth refuses it
    corrupt.write_bytes(b"RIFF" + struct.pack("<I", 4 + 1000) + b"sfbk" + bytes(1000))
    assert check_soundfont(corrupt) == corrupt
    with pytest.raises(ParameterError, match=names("fluidsynth could not play", "corrupt.sf2")):
        render_soundfont(hits, corrupt)
    with pytest.raises(ParameterError, match=names("soundfont", "is not a file")):
        render_soundfont(hits, tmp_path)


def test_fluidsynth_missing_or_slow_is_a_clear_error(soundfont, tmp_path):
    hits = [(0.0, "snare", 38, 1.0)]
    with pytest.raises(ParameterError, match=names("fluidsynth", "no-such-synth", "apt-get install fluidsynth")):
        render_soundfont(hits, soundfont, fluidsynth="no-such-synth")
    with pytest.raises(ParameterError, match=names("timeout = 0.001 s")):
        render_soundfont(hits, soundfont, timeout=0.001)
    with pytest.raises(ParameterError, match=names("gain", "got 0.0")):
        render_soundfont(hits, soundfont, gain=0.0)
    with pytest.raises(ParameterError, match=names("duration", "0.1")):
        render_soundfont([(0.5, "snare", 38, 1.0)], soundfont, duration=0.1)
    with pytest.raises(ParameterError, match=names("path", ".wav")):
        render_soundfont_wav(tmp_path / "kit.mid", hits, soundfont)
    assert not list(tmp_path.iterdir())
