"""The robot's side of a listening test: strokes played by the simulated robot, as WAV files.

:func:`make_stimuli` plays library strokes; :func:`fit_stimuli` plays the robot's version of recorded
human strokes. Each stroke is played with the impedance controller on the simulated joint, the onsets
it played are rendered as audio, and a listening-test config
(:class:`drumstroke.evaluation.app.Config`) names one pair per stroke: ``robot-NAME.wav``, written,
and ``human-NAME.wav``, to be recorded (library strokes) or the recording itself (recorded strokes).
Each config gets a new random admin token and is readable by its owner only.

The robot's version of a recorded stroke (analysis by synthesis): the recording's onsets
are found (:func:`drumstroke.analysis.onsets.find_onsets`), a recipe is fitted to them
(:func:`drumstroke.analysis.fit.fit_stroke`, written as ``NAME.toml``), the robot plays the fitted
stroke, and its onsets are rendered on the recording's clock (the fitted stroke's release where the
recording's is), over the recording's duration, with its peak at the recording's peak: a pair differs
in how the stick moved, not in when it starts, how long it lasts or how loud it is.
"""

import secrets
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._atomic import Bundle
from ..errors import ParameterError

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
        The WAV file (mono; 48 kHz for a library stroke, the recording's rate for a recorded one).
    onsets : int
        How many onsets the simulated robot played (the impacts heard).
    fit : drumstroke.analysis.fit.Fit or None
        For a recorded stroke: the recipe fitted to it, with its residuals.
    recipe : Path or None
        For a recorded stroke: the fitted recipe's file (``NAME.toml``).
    """

    name: str
    path: Path
    onsets: int
    fit: object = None
    recipe: Path = None


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
    return Stimuli(tuple(made), _write_config(out, pairs))


def fit_stimuli(recordings, out, *, model="paper", cor=None, fit_cor=False, progress=None):
    """The robot's version of each recorded human stroke: fitted, played by the simulated robot, rendered.

    Parameters
    ----------
    recordings : sequence of str or Path
        Recordings of one human stroke each (WAV, FLAC or OGG; mono or stereo). A pair is named by the
        file's name without its extension and a leading ``human-``. Every file is read, and every stroke
        fitted, before anything is written.
    out : str or Path
        The folder to write ``human-NAME.wav`` (the recording as a mono WAV at its own rate),
        ``robot-NAME.wav`` (at the same rate), ``NAME.toml`` (the fitted recipe) and
        ``listening-test.toml`` to (created if missing).
    model : {"paper", "geometry"}
        The model the strokes are fitted on.
    cor : float in [0, 1) or None
        c, when it is known (e.g. measured from a drop); default the paper's 0.86; or fitted (``fit_cor``).
    fit_cor : bool
        Fit c to each recording too.
    progress : callable or None
        Called with the fraction done, in [0, 1].

    Returns
    -------
    Stimuli
        Each with its fit and recipe; the config is written last, atomically, with a new admin token.
    """
    from ..analysis.fit import fit_stroke
    from ..analysis.onsets import find_onsets, read_recording
    from ..formats.wav import write_wav
    from ..recipe import DEFAULT_COR
    from ..render.audio import synthesize
    from ..robot.controllers import controller
    from ..robot.track import reference, track

    recordings = [Path(path) for path in recordings]
    if not recordings:
        raise ParameterError("recordings must name at least one recording of a human stroke")
    names = [_pair_name(path) for path in recordings]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise ParameterError(f"recordings {str(recordings[names.index(name)])!r} and {str(recordings[i])!r} both "
                                 f"make the pair {name!r}: give each stroke its own name")
    fits, sounds = [], []
    for i, path in enumerate(recordings):
        signal, rate, notes = read_recording(path)
        sounds.append((signal, rate))
        options = {"fit_cor": True} if fit_cor else {"cor": DEFAULT_COR if cor is None else cor}
        fits.append(fit_stroke(find_onsets(signal, rate, source=path.name, notes=notes), model=model, **options))
        if progress:
            progress(0.5 * (i + 1) / len(recordings))
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)  # the folder the stimuli go in, as asked
    pairs, made = [], []
    with Bundle() as bundle:  # the recordings, the robot's versions and the recipes appear together
        for i, (name, fit, (signal, rate)) in enumerate(zip(names, fits, sounds)):
            human, robot, recipe = out / f"human-{name}.wav", out / f"robot-{name}.wav", out / f"{name}.toml"
            played = track(reference(fit.stroke), controller(CONTROLLER))
            sound = synthesize(played.onsets + fit.release, played.onset_speed, duration=len(signal) / rate,
                               rate=rate)
            peak, robot_peak = float(np.max(np.abs(signal))), float(np.max(np.abs(sound), initial=0.0))
            write_wav(robot, sound * (peak / robot_peak) if robot_peak > 0.0 else sound, rate=rate, bundle=bundle)
            write_wav(human, signal, rate=rate, bundle=bundle)
            fit.recipe.to_toml(recipe, bundle=bundle)
            made.append(Stimulus(name, robot, len(played.onsets), fit=fit, recipe=recipe))
            pairs.append({"id": name, "human": human.name, "robot": robot.name})
            if progress:
                progress(0.5 + 0.5 * (i + 1) / len(recordings))
    return Stimuli(tuple(made), _write_config(out, pairs))


def _pair_name(path):
    """A pair's name from its recording's file name: without the extension and a leading ``human-``."""
    stem = path.stem.removeprefix("human-")
    if not stem:
        raise ParameterError(f"recording {str(path)!r} needs a name besides 'human-' (it names its pair)")
    return stem


def _write_config(out, pairs):
    """Write ``out``/``listening-test.toml`` naming ``pairs``, with a new admin token, readable by its owner only."""
    from ..formats.toml import write_toml

    config = out / CONFIG_NAME
    token = secrets.token_urlsafe(32)  # 256 random bits: each new config its own secret
    # it holds the export's token: its owner's only from its creation, over an older config's mode too
    write_toml(config, {"title": "Robot or human?", "admin_token": token, "seed": 1, "pair": pairs}, mode=0o600)
    return config
