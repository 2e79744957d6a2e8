"""Output bundles: every file a stroke or a composition can be written as, in one call.

Each function writes the files it is given paths for and returns those paths in the order written;
it prints nothing; the folders must exist. The files of one call are one bundle
(:class:`drumstroke._atomic.Bundle`, the caller's if given): each is written under a temporary name
and all are renamed into place at the end, so a call killed at any point leaves the previous set or
the new one. Plots need matplotlib, audio files soundfile and MIDI
files mido (the extras ``plot``, ``audio`` and ``midi``); they are imported only when such a file
is asked for. A plot's format follows its extension (PNG, PDF or SVG), and so does an audio
file's (WAV, FLAC or OGG/Vorbis).
"""

from pathlib import Path

import numpy as np

from .._atomic import bundled
from ..errors import located
from ..formats.sidecar import sidecar_for
from ..score import BOUNCE_NOTE, FIRST_IMPACT_NOTE
from ..trajectory import DEFAULT_RATE
from . import data


def write_stroke_outputs(stroke, *, json=None, csv=None, plot=None, audio=None, midi=None, rate=DEFAULT_RATE,
                         title=None, snares=True, extra=None, bundle=None):
    """Write a stroke's files: its data, its plot, its sound.

    Parameters
    ----------
    stroke : Stroke or Trajectory
    json : str, Path or None
        The recipe (if any), impacts and rests as JSON.
    csv : str, Path or None
        t (s), θ (rad), ω (rad/s) sampled at ``rate``, header first; its metadata goes into ``json``
        when that is the JSON beside it (``X.json`` for ``X.csv``), else into a JSON of its own there.
    plot : str, Path or None
        A picture of θ(t) with the impacts (and a(t) for a Stroke): .png, .pdf or .svg.
    audio : str, Path or None
        48 kHz mono audio of the impacts on a synthesized snare drum: .wav, .flac or .ogg.
    midi : str, Path or None
        The impacts as General MIDI percussion on channel 10, at their own times (the stroke's start
        is time 0) on one track: the first on key 38, the later ones (bounces) on 40
        (:data:`drumstroke.score.DRUM_MAP`).
    rate : float > 0 or None
        Samples per second of ``csv`` (Hz); None: a Trajectory's own rate (a Stroke's 1 kHz).
    title : str or None
        The plot's title (default: the stroke's name).
    snares : bool
        Whether the drum of ``audio`` has its snare wires on.
    extra : dict or None
        More fields for ``json``, beside the stroke's own (a design's, say).
    bundle : Bundle or None
        The caller's bundle to put the files in place with (default: a bundle of their own).

    Returns
    -------
    list of Path
        The files written: json, csv, the JSON beside csv if it is not json, plot, audio, midi, those given.

    Raises
    ------
    ParameterError
        Before writing anything, when the JSON beside ``csv`` is another of the files or a file
        already there that is not the CSV's metadata.
    """
    side = sidecar_for(csv, json=json, others={"plot": plot, "audio": audio, "midi": midi}) if csv else None
    written = []
    with bundled(bundle) as files:
        block = data.write_csv(stroke, csv, rate=rate, sidecar=side is not None, bundle=files) if csv else None
        if json:
            data.write_json(stroke, json, csv=block if side is None else None, extra=extra, bundle=files)
            written.append(Path(json))
        if csv:
            written += [Path(csv), *([side] if side else [])]
        if plot:
            from .plot import save_stroke_plot

            save_stroke_plot(stroke, plot, title=title, bundle=files)
            written.append(Path(plot))
        impacts = stroke.impacts
        if audio:
            written.append(_write_audio(audio, impacts.t, impacts.tip_speed, snares, files))
        if midi:
            from ..formats.midi import Track, write_midi

            name = f"{stroke.name} (model {stroke.model})"
            write_midi(midi, [Track(name, impacts.t, impacts.level_db, _keys(np.arange(len(impacts)) == 0))],
                       title=name, bundle=files)
            written.append(Path(midi))
    return written


def write_composition_outputs(piece, *, title, csv=None, json=None, plot=None, audio=None, midi=None, snares=True,
                              bundle=None):
    """Write a composition's files: its trajectories, notes and placements, its plot, its sound.

    Parameters
    ----------
    piece : Composition
        What :func:`drumstroke.compose.compose` returns.
    title : str
        Names the plot and the MIDI track (e.g. the score file's stem).
    csv : str, Path or None
        t (s) and θ (rad), ω (rad/s) per stick at the composition's rate, header first; its metadata
        goes into ``json`` when that is the JSON beside it, else into a JSON of its own there.
    json : str, Path or None
        The notes, their placements and the impacts.
    plot : str, Path or None
        A picture of the part as a drummer reads it (:func:`drumstroke.render.plot.composition_figure`): θ(t)
        per stick on one scale with the impacts and each note's sticking; .png, .pdf or .svg.
    audio : str, Path or None
        Every stick's impacts as 48 kHz mono audio (.wav, .flac or .ogg), on the composition's timeline.
    midi : str, Path or None
        The impacts as General MIDI percussion on channel 10, on the score's time and its tempo map
        and time signatures, one track per stick (named after it): each stroke's first impact on
        key 38, its bounces on 40 (:data:`drumstroke.score.DRUM_MAP`).
    snares : bool
        Whether the drum of ``audio`` has its snare wires on.
    bundle : Bundle or None
        The caller's bundle to put the files in place with (default: a bundle of their own).

    Returns
    -------
    list of Path
        The files written: csv, the JSON beside it if it is not json, json, plot, audio, midi, those given.

    Raises
    ------
    ParameterError
        Before writing anything, when the JSON beside ``csv`` is another of the files or a file
        already there that is not the CSV's metadata.
    """
    side = sidecar_for(csv, json=json, others={"plot": plot, "audio": audio, "midi": midi}) if csv else None
    written = []
    block = None
    with bundled(bundle) as files:
        if csv:
            block = data.write_composition_csv(piece, csv, sidecar=side is not None, bundle=files)
            written += [Path(csv), *([side] if side else [])]
        if json:
            data.write_composition_json(piece, json, csv=block if side is None else None, bundle=files)
            written.append(Path(json))
        if plot:
            from .plot import composition_figure, save_figure

            with located(f"picture {str(plot)!r}"):
                figure = composition_figure(piece, title=title)
            save_figure(figure, plot, bundle=files)
            written.append(Path(plot))
        if audio:
            times, speeds, _ = piece.impacts()
            written.append(_write_audio(audio, times, speeds, snares, files))
        if midi:
            from ..formats.midi import Track, write_midi

            tracks = [Track(stick, t, level, _keys(first))
                      for stick, (t, level, first) in piece.stick_impacts().items()]
            write_midi(midi, tracks, tempo_map=piece.tempo_map, title=f"{title} (model {piece.model})", bundle=files)
            written.append(Path(midi))
    return written


def write_kit_outputs(piece, *, title="kit", csv=None, json=None, plot=None, window=None, midi=None, audio=None,
                      soundfont=None, bundle=None):
    """Write a kit composition's files (:func:`drumstroke.compose.compose_kit`), put in place together.

    Parameters
    ----------
    piece : KitComposition
    title : str
        Names the plot (e.g. the score file's stem).
    csv : str, Path or None
        t (s) and a column per joint (rad, and rad/s), header first; its metadata in the JSON beside it (``json``
        when that is the one beside it).
    json : str, Path or None
        The kit, every note's outcome and every hit (:func:`~drumstroke.render.data.kit_to_dict`).
    plot : str, Path or None
        A picture of the part as a drummer reads it (:func:`drumstroke.render.kit_plot.kit_figure`): a lane per
        piece with every hit and every note not played, over the joints' angles; .png, .pdf or .svg.
    window : (float, float) or None
        (start, end), s of the score's time: the stretch ``plot`` draws (default the whole part).
    midi : str, Path or None
        Each hit on its piece's General MIDI key (the hi-hat's by its state), channel 10, a track a limb (its
        name), on the score's time and tempo map.
    audio : str, Path or None
        The hits as audio: drumstroke's synthesis of each piece, or through ``soundfont``.
    soundfont : str, Path or None
        A General MIDI SoundFont (.sf2) to render ``audio`` with FluidSynth.
    bundle : Bundle or None

    Returns
    -------
    list of Path
        The files written.

    Raises
    ------
    ParameterError
        Before writing anything, when the JSON beside ``csv`` is another of the files or a file already there
        that is not the CSV's metadata, or when ``window`` is not a stretch of the part
        (:func:`~drumstroke.render.kit_plot.check_window`).
    """
    side = sidecar_for(csv, json=json, others={"plot": plot, "midi": midi, "audio": audio}) if csv else None
    if plot:
        from .kit_plot import check_window, part_span

        window = None if window is None else check_window(window, span=part_span(piece))
    written, block = [], None
    with bundled(bundle) as files:
        if csv:
            block = piece.write_csv(csv, sidecar=side is not None, bundle=files)
            written += [Path(csv), *([side] if side else [])]
        if json:  # the CSV's metadata in it when it is the JSON beside the CSV
            data.write_kit_json(piece, json, csv=block if side is None else None, bundle=files)
            written.append(Path(json))
        if plot:
            from .kit_plot import kit_figure
            from .plot import save_figure

            with located(f"picture {str(plot)!r}"):
                figure = kit_figure(piece, title=title, window=window)
            save_figure(figure, plot, bundle=files)
            written.append(Path(plot))
        if midi or audio:
            from .kit_audio import KitHits, render_kit_wav
            from .soundfont import render_soundfont_wav, write_kit_midi

            hits = KitHits.from_rows([(h.t, h.piece, h.key, h.speed) for h in piece.performance.hits])
            if midi:  # on the score's time and tempo map, a track per limb
                performed = piece.performance.hits
                on_score = KitHits.from_rows([(max(h.t - piece.offset, 0.0), h.piece, h.key, h.speed)
                                              for h in performed])
                write_kit_midi(midi, on_score, limbs=[h.limb for h in performed], tempo_map=piece.tempo_map,
                               title=f"drumstroke kit (model {piece.model})", bundle=files)
                written.append(Path(midi))
            if audio and soundfont:
                render_soundfont_wav(audio, hits, soundfont, bundle=files)
            elif audio:
                render_kit_wav(audio, hits, kit=piece.kit, bundle=files)
            written += [Path(audio)] if audio else []
    return written


def _write_audio(path, times, tip_speeds, snares, bundle):
    from .audio import Drum, render_wav

    render_wav(path, times, tip_speeds, drum=Drum(snares=snares), bundle=bundle)
    return Path(path)


def _keys(first):
    """The MIDI key of each impact: a stroke's first impact on one, its bounces on another (the drum map's)."""
    return np.where(first, FIRST_IMPACT_NOTE, BOUNCE_NOTE)
