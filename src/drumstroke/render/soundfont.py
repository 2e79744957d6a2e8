"""The kit's impacts through a General MIDI SoundFont: real drum samples, played by FluidSynth.

Needs the ``midi`` and ``audio`` extras (mido, soundfile) and the ``fluidsynth`` program, run as a
subprocess (Debian: ``apt-get install fluidsynth``; a General MIDI SoundFont with it:
``fluid-soundfont-gm``, whose :data:`DEBIAN_SOUNDFONT` is FluidR3_GM).

The hits are written as a General MIDI file (:func:`write_kit_midi`): one track per piece (or limb), every note
on channel 10 (General MIDI percussion), at its time to half a tick, the key it played, velocity
``level_to_velocity(20 log10(v / 1 m/s))`` (:mod:`drumstroke.dynamics`, as every MIDI file drumstroke
writes). FluidSynth renders the file offline, without reverb or chorus (the sound as dry as
:mod:`.kit_audio`'s), at the rate asked; the stereo it writes is mixed to mono (the mean of its
channels, a kit's panning folded in) and written as :func:`~drumstroke.formats.wav.write_wav` writes.

Examples
--------
>>> import pathlib, tempfile
>>> hits = [(0.0, "kick", 36, 2.0), (0.5, "snare", 38, 1.0)]
>>> with tempfile.TemporaryDirectory() as folder:
...     notes = write_kit_midi(pathlib.Path(folder) / "kit.mid", hits)
>>> [(note.time, note.note, note.velocity, note.channel) for note in notes]
[(0.0, 36, 111, 10), (0.5, 38, 95, 10)]
"""

import os
import shutil
import struct
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from .._checks import check_real, shown
from ..errors import ParameterError
from ..formats.midi import PERCUSSION_CHANNEL, Track, write_midi
from ..formats.wav import audio_format, read_audio, write_wav
from ..trajectory import LEVEL_REFERENCE
from .audio import SAMPLE_RATE, limit_peak
from .kit_audio import KitHits

DEBIAN_SOUNDFONT = Path("/usr/share/sounds/sf2/FluidR3_GM.sf2")
"""Where Debian's ``fluid-soundfont-gm`` puts its General MIDI SoundFont (FluidR3_GM, MIT licence)."""

FLUIDSYNTH = "fluidsynth"
"""The FluidSynth program run (Debian's package ``fluidsynth``), looked up on the PATH."""

FLUIDSYNTH_GAIN = 0.5
"""FluidSynth's master gain (its ``-g``; its own default is 0.2): a loud hit on FluidR3_GM peaks near half scale."""

GM_SOUNDS = {23: 46}
"""Keys outside General MIDI's percussion map played as a General MIDI key on a SoundFont: the shipped kit's
half-open hi-hat (23; General MIDI has no half-open hi-hat) sounds as the open one (46). Files drumstroke writes
keep the kit's keys."""

TIMEOUT = 600.0
"""How long FluidSynth may take (s) before it is stopped: it renders a minute of a kit in about a second."""


def write_kit_midi(path, hits, *, limbs=None, tempo_map=None, title="drumstroke kit", bundle=None):
    """Write ``hits`` as a General MIDI file, atomically: notes on channel 10, a track per limb (or per piece).

    Parameters
    ----------
    path : str or path-like
        The ``.mid`` file to write.
    hits : KitHits or sequence of (time s, piece, key, speed m/s)
        The pieces are not checked against a kit: a key is all FluidSynth plays.
    limbs : sequence of str, optional
        The limb that played each hit: the file then has a track per limb, named by it (a drummer's sticking,
        the piece told by the key); default a track per piece.
    tempo_map : TempoMap, optional
        The score's tempo changes and time signatures, written in track 0 (default 120 bpm, 4/4); the hits' times
        (s) do not depend on it.
    title : str
        Track 0's name.
    bundle : Bundle or None
        Put the file in place with this :class:`drumstroke._atomic.Bundle`'s others (default: at once).

    Returns
    -------
    list of Note
        The notes written, in time order (see :func:`~drumstroke.formats.midi.write_midi`: hits slower
        than velocity 1's level are left out, those of one track on one tick and key merge into the louder).
    """
    hits = hits if isinstance(hits, KitHits) else KitHits.from_rows(hits)
    if limbs is not None and (isinstance(limbs, (str, bytes)) or len(limbs) != len(hits)
                              or not all(isinstance(x, str) for x in limbs)):
        raise ParameterError(f"limbs must name the limb of each of the {len(hits)} hits, got {shown(limbs)}")
    with np.errstate(divide="ignore"):
        levels = 20.0 * np.log10(hits.speed / LEVEL_REFERENCE)
    groups = np.array(hits.piece if limbs is None else list(limbs), dtype=object)
    tracks = []
    for name in dict.fromkeys(groups):
        chosen = np.flatnonzero(groups == name)
        chosen = chosen[np.argsort(hits.t[chosen], kind="stable")]
        tracks.append(Track(name, hits.t[chosen], levels[chosen], hits.key[chosen]))
    if not tracks:
        tracks = [Track("kit", [], [], 0)]
    written = write_midi(path, tracks, tempo_map=tempo_map, channel=PERCUSSION_CHANNEL, title=title, bundle=bundle)
    return sorted((note for notes in written for note in notes), key=lambda note: (note.time, note.track))


def check_soundfont(soundfont):
    """``soundfont`` as a Path, if it is a whole SoundFont 2 file (a RIFF ``sfbk`` form of the file's length).

    A missing file, a folder, another kind of file or a truncated one is a ParameterError saying so.
    """
    path = Path(soundfont)
    where = f"soundfont {str(soundfont)!r}"
    if not path.is_file():
        hint = (f"; Debian's package fluid-soundfont-gm installs {DEBIAN_SOUNDFONT}"
                if path == DEBIAN_SOUNDFONT else "; give a General MIDI SoundFont (.sf2) file")
        raise ParameterError(f"{where} {'is not a file' if path.exists() else 'is missing'}{hint}",
                             parameter="soundfont", value=soundfont, allowed="a SoundFont 2 (.sf2) file")
    try:
        with path.open("rb") as file:
            header = file.read(12)
        size = path.stat().st_size
    except OSError as error:
        raise ParameterError(f"{where} cannot be read: {error.strerror}", parameter="soundfont",
                             value=soundfont) from None
    if len(header) < 12 or header[:4] != b"RIFF" or header[8:12] != b"sfbk":
        raise ParameterError(f"{where} is not a SoundFont 2 file (it does not begin with a RIFF 'sfbk' header)",
                             parameter="soundfont", value=soundfont, allowed="a SoundFont 2 (.sf2) file")
    declared = struct.unpack("<I", header[4:8])[0] + 8
    if declared != size:
        raise ParameterError(f"{where} is damaged: its header says {declared} bytes, the file has {size}",
                             parameter="soundfont", value=soundfont, allowed="a whole SoundFont 2 (.sf2) file")
    return path


def render_soundfont(hits, soundfont, *, duration=None, rate=SAMPLE_RATE, gain=FLUIDSYNTH_GAIN, timeout=TIMEOUT,
                     fluidsynth=FLUIDSYNTH, reverb=False):
    """Play ``hits`` on a General MIDI SoundFont with FluidSynth: mono audio.

    Parameters
    ----------
    hits : KitHits or sequence of (time s, piece, key, speed m/s)
    soundfont : str or path-like
        A SoundFont 2 file with a General MIDI drum kit (e.g. :data:`DEBIAN_SOUNDFONT`).
    duration : float ≥ max(hits.t) or None
        Length of the signal (s), cut or padded with silence; default: as long as FluidSynth plays
        (until its voices have died away).
    rate : int in [8000, 96000]
        Samples per second (Hz).
    gain : float in (0, 10]
        FluidSynth's master gain. The signal is scaled down as a whole if its peak passes 0.99.
    timeout : float > 0
        Seconds FluidSynth may take before it is stopped (a ParameterError then).
    fluidsynth : str or path-like
        The FluidSynth program: a name on the PATH or a path.
    reverb : bool
        Whether FluidSynth's own reverb (its default room) is on; off by default (the dry sound).

    Returns
    -------
    signal : ndarray [shape=(samples,), dtype=float64]
        Samples in [-0.99, 0.99] (full scale).

    Notes
    -----
    A key General MIDI has no sound for is played as :data:`GM_SOUNDS` says (the half-open hi-hat as the open).
    """
    hits = hits if isinstance(hits, KitHits) else KitHits.from_rows(hits)
    soundfont = check_soundfont(soundfont)
    rate = round(check_real("rate", rate, low=8000.0, high=96000.0, unit="Hz"))
    gain = check_real("gain", gain, low=0.0, high=10.0, low_open=True)
    timeout = check_real("timeout", timeout, low=0.0, low_open=True, unit="s")
    if not isinstance(reverb, bool):
        raise ParameterError(f"reverb must be True or False, got {shown(reverb)}", parameter="reverb", value=reverb)
    last = float(hits.t.max()) if len(hits) else 0.0
    if duration is not None:
        duration = check_real("duration", duration, low=last, unit="s")
    program = shutil.which(os.fspath(fluidsynth)) if isinstance(fluidsynth, (str, os.PathLike)) else None
    if program is None:
        raise ParameterError(f"fluidsynth: the program {shown(fluidsynth)} is not found; install FluidSynth "
                             "(Debian: apt-get install fluidsynth) or give its path",
                             parameter="fluidsynth", value=fluidsynth)
    with tempfile.TemporaryDirectory(prefix="drumstroke-soundfont-") as folder:
        score, played = Path(folder) / "hits.mid", Path(folder) / "played.wav"
        write_kit_midi(score, KitHits(hits.t, hits.piece, [GM_SOUNDS.get(k, k) for k in hits.key], hits.speed))
        _run([program, "-n", "-i", "-q", "-R", str(int(reverb)), "-C", "0", "-g", repr(gain), "-r", str(rate), "-O", "float",
              "-T", "wav", "-F", str(played), str(soundfont), str(score)], soundfont, timeout)
        if not played.is_file():
            raise ParameterError(f"fluidsynth wrote no audio from soundfont {str(soundfont)!r}")
        signal, _ = read_audio(played)
    signal = signal.mean(axis=1)
    if duration is not None:
        size = round(duration * rate)
        signal = np.pad(signal[:size], (0, max(0, size - len(signal))))
    return limit_peak(np.ascontiguousarray(signal))


def render_soundfont_wav(path, hits, soundfont, *, duration=None, rate=SAMPLE_RATE, gain=FLUIDSYNTH_GAIN,
                         timeout=TIMEOUT, fluidsynth=FLUIDSYNTH, bundle=None):
    """Play ``hits`` on a SoundFont (see :func:`render_soundfont`) and write the audio, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Where to write: ``.wav``, ``.flac`` or ``.ogg`` (the format follows the extension).
    hits, soundfont, duration, rate, gain, timeout, fluidsynth
        As :func:`render_soundfont`'s.
    bundle : Bundle or None
        Put the file in place with this :class:`drumstroke._atomic.Bundle`'s others (default: at once).

    Returns
    -------
    signal : ndarray [shape=(samples,)]
        The samples written, before 24-bit quantisation.
    """
    audio_format(path)  # before the work, not after it
    signal = render_soundfont(hits, soundfont, duration=duration, rate=rate, gain=gain, timeout=timeout,
                              fluidsynth=fluidsynth)
    write_wav(path, signal, rate=round(rate), bundle=bundle)
    return signal


def _run(command, soundfont, timeout):
    """Run FluidSynth; its failure (it exits 0 and plays silence when a SoundFont fails to load) is a ParameterError."""
    try:
        done = subprocess.run(command, capture_output=True, text=True, errors="replace", timeout=timeout,
                              check=False, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        raise ParameterError(f"fluidsynth took longer than timeout = {timeout:g} s and was stopped; give a longer "
                             "timeout for a long part", parameter="timeout", value=timeout) from None
    except OSError as error:
        raise ParameterError(f"fluidsynth {command[0]!r} cannot be run: {error.strerror}", parameter="fluidsynth",
                             value=command[0]) from None
    errors = [line.strip() for line in (done.stdout + done.stderr).splitlines()
              if "error" in line.lower() or "failed" in line.lower()]
    if done.returncode != 0 or errors:
        reason = "; ".join(errors[:3]) or f"it exited with status {done.returncode}"
        raise ParameterError(f"fluidsynth could not play soundfont {str(soundfont)!r}: {reason}",
                             parameter="soundfont", value=str(soundfont))
