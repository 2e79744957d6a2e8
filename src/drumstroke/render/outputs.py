"""Output bundles: every file a stroke or a composition can be written as, in one call.

Each function writes the files it is given paths for and returns those paths in the order written;
it prints nothing. Plots need matplotlib, WAV files soundfile and MIDI files mido (the extras
``plot``, ``audio`` and ``midi``); they are imported only when such a file is asked for.
"""

from pathlib import Path

import numpy as np

from ..score import BOUNCE_NOTE, FIRST_IMPACT_NOTE
from ..trajectory import DEFAULT_RATE
from . import data


def write_stroke_outputs(stroke, *, json=None, csv=None, plot=None, wav=None, midi=None, rate=DEFAULT_RATE,
                         title=None, snares=True):
    """Write a stroke's files: its data, its plot, its sound.

    Parameters
    ----------
    stroke : Stroke or Trajectory
    json : str, Path or None
        The recipe (if any), impacts and rests as JSON.
    csv : str, Path or None
        t (s), θ (rad), ω (rad/s) sampled at ``rate``.
    plot : str, Path or None
        A PNG of θ(t) with the impacts (and a(t) for a Stroke).
    wav : str, Path or None
        48 kHz mono audio of the impacts on a synthesized snare drum.
    midi : str, Path or None
        The impacts as General MIDI percussion on channel 10, at their own times (the stroke's start
        is time 0) on one track: the first on key 38, the later ones (bounces) on 40
        (:data:`drumstroke.score.DRUM_MAP`).
    rate : float > 0
        Samples per second of ``csv`` (Hz).
    title : str or None
        The plot's title (default: the stroke's name).
    snares : bool
        Whether the drum of ``wav`` has its snare wires on.

    Returns
    -------
    list of Path
        The files written: json, csv, plot, wav, midi, those given.
    """
    written = []
    if json:
        data.write_json(stroke, json)
        written.append(Path(json))
    if csv:
        data.write_csv(stroke, csv, rate=rate)
        written.append(Path(csv))
    if plot:
        from .plot import save_stroke_plot

        save_stroke_plot(stroke, plot, title=title)
        written.append(Path(plot))
    impacts = stroke.impacts
    if wav:
        written.append(_write_wav(wav, impacts.t, impacts.tip_speed, snares))
    if midi:
        from ..formats.midi import Track, write_midi

        name = f"{stroke.name} (model {stroke.model})"
        write_midi(midi, [Track(name, impacts.t, impacts.level_db, _keys(np.arange(len(impacts)) == 0))], title=name)
        written.append(Path(midi))
    return written


def write_composition_outputs(piece, *, title, csv=None, json=None, plot=None, wav=None, midi=None, snares=True):
    """Write a composition's files: its trajectories, notes and placements, its plot, its sound.

    Parameters
    ----------
    piece : Composition
        What :func:`drumstroke.compose.compose` returns.
    title : str
        Names the plot and the MIDI track (e.g. the score file's stem).
    csv : str, Path or None
        t (s) and θ (rad), ω (rad/s) per stick at the composition's rate.
    json : str, Path or None
        The notes, their placements and the impacts.
    plot : str, Path or None
        A PNG of θ(t) per stick with the notes.
    wav : str, Path or None
        Every stick's impacts as 48 kHz mono audio, on the composition's timeline.
    midi : str, Path or None
        The impacts as General MIDI percussion on channel 10, on the score's time and its tempo map
        and time signatures, one track per stick (named after it): each stroke's first impact on
        key 38, its bounces on 40 (:data:`drumstroke.score.DRUM_MAP`).
    snares : bool
        Whether the drum of ``wav`` has its snare wires on.

    Returns
    -------
    list of Path
        The files written: csv, json, plot, wav, midi, those given.
    """
    written = []
    if csv:
        data.write_composition_csv(piece, csv)
        written.append(Path(csv))
    if json:
        data.write_composition_json(piece, json)
        written.append(Path(json))
    if plot:
        from .plot import composition_figure, save_figure

        save_figure(composition_figure(piece, title=title), plot)
        written.append(Path(plot))
    if wav:
        times, speeds, _ = piece.impacts()
        written.append(_write_wav(wav, times, speeds, snares))
    if midi:
        from ..formats.midi import Track, write_midi

        tracks = [Track(stick, t, level, _keys(first)) for stick, (t, level, first) in piece.stick_impacts().items()]
        write_midi(midi, tracks, tempo_map=piece.tempo_map, title=f"{title} (model {piece.model})")
        written.append(Path(midi))
    return written


def _write_wav(path, times, tip_speeds, snares):
    from .audio import Drum, render_wav

    render_wav(path, times, tip_speeds, drum=Drum(snares=snares))
    return Path(path)


def _keys(first):
    """The MIDI key of each impact: a stroke's first impact on one, its bounces on another (the drum map's)."""
    return np.where(first, FIRST_IMPACT_NOTE, BOUNCE_NOTE)
