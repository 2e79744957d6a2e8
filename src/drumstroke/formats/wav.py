"""WAV audio, both ways: mono 24-bit PCM (needs the ``audio`` extra: soundfile, imported when called).

Examples
--------
>>> import pathlib, tempfile
>>> import numpy as np
>>> path = pathlib.Path(tempfile.mkdtemp()) / "click.wav"
>>> write_wav(path, np.array([0.0, 0.5, -0.5, 0.0]), rate=48000)
>>> signal, rate = read_wav(path)
>>> rate, signal.round(6).tolist()
(48000, [0.0, 0.5, -0.5, 0.0])
"""

import io

from .._atomic import write_atomic
from .._checks import check_int, check_vector
from ..errors import ParameterError


def write_wav(path, signal, *, rate):
    """Write ``signal`` as a mono 24-bit PCM WAV file, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Where to write; the parent directory is created if needed.
    signal : array_like [shape=(n,)]
        Samples, finite and in [-1, 1] (full scale).
    rate : int > 0
        Samples per second (Hz).
    """
    soundfile = _soundfile()
    signal = check_vector("signal", signal, low=-1.0, high=1.0)
    check_int("rate", rate, low=1, unit="Hz")
    buffer = io.BytesIO()
    soundfile.write(buffer, signal, rate, subtype="PCM_24", format="WAV")
    write_atomic(path, buffer.getvalue())


def read_wav(path):
    """The samples (full scale, float64, mono) [shape=(n,)] and the rate (Hz) of the WAV file at ``path``."""
    soundfile = _soundfile()
    try:
        signal, rate = soundfile.read(str(path), dtype="float64", always_2d=True)
    except (OSError, RuntimeError, soundfile.LibsndfileError) as error:
        raise ParameterError(f"WAV file {str(path)!r} cannot be read: {error}") from None
    if signal.shape[1] != 1:
        raise ParameterError(f"WAV file {str(path)!r} has {signal.shape[1]} channels; drumstroke reads mono")
    return signal[:, 0], int(rate)


def _soundfile():
    try:
        import soundfile
    except ImportError as error:  # pragma: no cover - exercised only without the extra
        raise ImportError("drumstroke audio needs soundfile: pip install 'drumstroke[audio]'") from error
    return soundfile
