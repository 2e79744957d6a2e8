"""The robot's side of a listening test: library strokes played by the simulated robot, as WAV files.

:func:`make_stimuli` plays each stroke with the impedance controller on the simulated joint, renders
the onsets it played as audio and writes a listening-test config
(:class:`drumstroke.evaluation.app.Config`) naming one pair per stroke: ``robot-NAME.wav``, written,
and ``human-NAME.wav``, to be recorded. Each config gets a new random admin token and is readable by
its owner only.
"""

import secrets
from dataclasses import dataclass
from pathlib import Path

CONFIG_NAME = "listening-test.toml"
"""The file name of the config :func:`make_stimuli` writes."""

CONTROLLER = "impedance"
"""The controller the robot plays the stimuli with."""


@dataclass(frozen=True)
class Stimulus:
    """One robot recording.

    Attributes
    ----------
    name : str
        The library stroke (and the pair's id).
    path : Path
        The WAV file (48 kHz mono).
    onsets : int
        How many onsets the simulated robot played (the impacts heard).
    """

    name: str
    path: Path
    onsets: int


@dataclass(frozen=True)
class Stimuli:
    """What :func:`make_stimuli` wrote.

    Attributes
    ----------
    stimuli : tuple of Stimulus
        In the order of the strokes.
    config : Path
        The listening-test config naming every pair.
    """

    stimuli: tuple
    config: Path


def make_stimuli(library, out, *, strokes=None, progress=None):
    """Play library strokes on the simulated robot and write them as a listening test's robot recordings.

    Parameters
    ----------
    library : str, Path or Library
        A stroke library folder or a loaded :class:`~drumstroke.palette.library.Library`.
    out : str or Path
        The folder to write ``robot-NAME.wav`` and ``listening-test.toml`` to (created if missing).
    strokes : sequence of str or None
        The library strokes to play, in order (default: all of them). Every name is checked before
        anything is written.
    progress : callable or None
        Called with the fraction done, in [0, 1].

    Returns
    -------
    Stimuli
        The WAV files with their onset counts, and the config, written atomically last, with a new admin
        token (``secrets.token_urlsafe(32)``: 43 characters) and permissions 0600.
    """
    from ..formats.toml import write_toml
    from ..palette.library import Library, load_library
    from ..render.audio import render_wav
    from ..robot.controllers import controller
    from ..robot.track import reference, track

    library = library if isinstance(library, Library) else load_library(library)
    out = Path(out)
    names = list(library) if strokes is None else list(strokes)
    entries = [library[name] for name in names]
    out.mkdir(parents=True, exist_ok=True)  # the folder the stimuli go in, as asked
    pairs, made = [], []
    for i, (name, entry) in enumerate(zip(names, entries)):
        played = track(reference(entry.trajectory, library.rate), controller(CONTROLLER))
        wav = out / f"robot-{name}.wav"
        render_wav(wav, played.onsets, played.onset_speed)
        made.append(Stimulus(name, wav, len(played.onsets)))
        pairs.append({"id": name, "human": f"human-{name}.wav", "robot": wav.name})
        if progress:
            progress((i + 1) / len(names))
    config = out / CONFIG_NAME
    token = secrets.token_urlsafe(32)  # 256 random bits: each new config its own secret
    write_toml(config, {"title": "Robot or human?", "admin_token": token, "seed": 1, "pair": pairs})
    config.chmod(0o600)  # it holds the export's token
    return Stimuli(tuple(made), config)
