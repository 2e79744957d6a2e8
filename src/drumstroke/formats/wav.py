"""Audio files, both ways, mono (needs the ``audio`` extra: soundfile, imported when called).

The format follows the file's extension (:data:`FORMATS`): WAV and FLAC as 24-bit PCM, OGG as
Vorbis (lossy).

Examples
--------
>>> import pathlib, tempfile
>>> import numpy as np
>>> path = pathlib.Path(tempfile.mkdtemp()) / "click.wav"
>>> write_wav(path, np.array([0.0, 0.5, -0.5, 0.0]), rate=48000)
>>> signal, rate = read_wav(path)
>>> rate, signal.round(6).tolist()
(48000, [0.0, 0.5, -0.5, 0.0])
>>> read_audio(path)[0].shape  # any number of channels: (samples, channels)
(4, 1)
"""

import io
import os
from pathlib import Path

import numpy as np

from .._atomic import note_input, write_atomic
from .._checks import check_int, check_vector
from ..budget import audio_bytes, check_memory
from ..errors import ParameterError
from .reading import MIB, check_regular, read_bytes

MAX_BYTES = 1024 * MIB
"""The largest audio file read (bytes): some two hours of 48 kHz 24-bit mono."""

FORMATS = {".wav": ("WAV", "PCM_24"), ".flac": ("FLAC", "PCM_24"), ".ogg": ("OGG", "VORBIS")}
"""The audio files written, by extension: soundfile's format and subtype."""


def write_wav(path, signal, *, rate, bundle=None):
    """Write ``signal`` as a mono audio file in the format of ``path``'s extension, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Where to write, in an existing folder: ``.wav``, ``.flac`` or ``.ogg`` (see :data:`FORMATS`).
    signal : array_like [shape=(n,)]
        Samples, finite and in [-1, 1] (full scale).
    rate : int > 0
        Samples per second (Hz).
    bundle : Bundle or None
        Put the file in place with this :class:`drumstroke._atomic.Bundle`'s others (default: at once).
    """
    file_format, subtype = audio_format(path)
    soundfile = _soundfile()
    signal = check_vector("signal", signal, low=-1.0, high=1.0)
    check_int("rate", rate, low=1, unit="Hz")
    buffer = io.BytesIO()
    soundfile.write(buffer, signal, rate, subtype=subtype, format=file_format)
    write_atomic(path, buffer.getvalue(), bundle=bundle)


def audio_format(path):
    """soundfile's format and subtype for ``path``, from its extension (see :data:`FORMATS`)."""
    kind = Path(path).suffix.lower()
    if kind not in FORMATS:
        raise ParameterError(f"path must end in one of {', '.join(FORMATS)} (the audio formats written), "
                             f"got {str(path)!r}")
    return FORMATS[kind]


def read_wav(path):
    """The samples (full scale, float64, mono) [shape=(n,)] and the rate (Hz) of the WAV file at ``path``."""
    soundfile = _soundfile()
    data = read_bytes(path, "WAV file", limit=MAX_BYTES)
    try:
        signal, rate = soundfile.read(io.BytesIO(data), dtype="float64", always_2d=True)
    except (OSError, RuntimeError, soundfile.LibsndfileError) as error:
        raise ParameterError(f"WAV file {str(path)!r} cannot be read: {error}") from None
    if signal.shape[1] != 1:
        raise ParameterError(f"WAV file {str(path)!r} has {signal.shape[1]} channels; drumstroke reads mono")
    return signal[:, 0], int(rate)


def read_audio(path, *, max_seconds=None, working=0):
    """The samples (full scale, float64) [shape=(n, channels)] and the rate (Hz) of the audio file at ``path``.

    Any channel count and any format soundfile reads (WAV, FLAC, OGG, AIFF, …). The length is
    checked from the header before any sample is read, so a file too long is refused at once; so
    is a file whose samples, as the header counts them (libsndfile counts no more frames than an
    uncompressed file's size holds), are more than the memory budget (:mod:`drumstroke.budget`):
    a sparse file of a few kilobytes on disk claiming gigabytes of 8-channel audio is refused in
    milliseconds.

    Parameters
    ----------
    path : str or os.PathLike
    max_seconds : float or None
        The longest file read (s); None reads any.
    working : int >= 0
        Values a frame the caller goes on to hold besides the file's samples (its working
        copies), counted in the memory estimate.

    Raises
    ------
    ParameterError
        Naming the file: missing, not a regular file, not audio soundfile reads, longer than
        ``max_seconds``, beyond the memory budget, or holding a sample that is not finite (a float file's
        NaN or infinity).
    """
    soundfile = _soundfile()
    where = f"audio file {str(path)!r}"
    if not Path(path).is_file():
        reason = "is not a regular file" if Path(path).exists() else "is missing"
        if os.path.lexists(path) and not Path(path).exists():  # a link that leads nowhere, or in a loop: say which
            check_regular(path, "audio file")
        raise ParameterError(f"{where} {reason}")
    try:
        info = soundfile.info(str(path))
        if max_seconds is not None and info.frames > max_seconds * info.samplerate:
            raise ParameterError(f"{where} lasts {info.frames / info.samplerate:.6g} s; at most {max_seconds:g} s "
                                 "are read: cut it into parts")
        check_memory(where, audio_bytes(info.frames, info.channels, working),
                     f"{info.frames} frames of {info.channels} channel{'s' * (info.channels != 1)} at "
                     f"{info.samplerate} Hz as its header counts them, and {working} working copies")
        signal, rate = soundfile.read(str(path), dtype="float64", always_2d=True)
        note_input(path)
    except (OSError, RuntimeError, soundfile.LibsndfileError) as error:
        raise ParameterError(f"{where} cannot be read as audio: {error}") from None
    bad = np.argwhere(~np.isfinite(signal))  # a float file can hold NaN or infinities; what reads it must not see them
    if len(bad):
        frame, channel = (int(i) for i in bad[0])
        raise ParameterError(f"{where}: sample {frame} (channel {channel + 1}) is {float(signal[frame, channel])!r}; "
                             f"audio samples must be finite ({len(bad)} are not)")
    return signal, int(rate)


def _soundfile():
    try:
        import soundfile
    except ImportError as error:  # pragma: no cover - exercised only without the extra
        raise ImportError("drumstroke audio needs soundfile: pip install 'drumstroke[audio]'") from error
    return soundfile
