"""The paper's figures and the demo: every shipped stroke drawn and heard on one web page.

:func:`write_figures` simulates the presets that reproduce the paper's Figs. 4–7 and writes their files;
:func:`run_demo` does that, builds the shipped library, renders each stroke as a picture, a sound and
MIDI, plays the :data:`RUDIMENTS` through the planner, composes the demo groove from the library and
writes ``index.html`` linking it all. Both need the
``plot`` extra; the demo also ``audio`` and ``midi``. Each puts its files in place together, as one
:class:`drumstroke._atomic.Bundle`: killed at any point, it leaves the previous files or the new ones
(the demo's library switches on its own, atomically, when it is built).
"""

from dataclasses import dataclass
from pathlib import Path

from ._atomic import Bundle, bundled
from .presets import PRESETS
from .render.page import Card, plural

FIGURES = {p.figure: name for name, p in PRESETS.items() if p.figure}
"""The paper's figures and the presets that reproduce them: {"Fig. 4": "free-bounce", ...}."""

RUDIMENTS = (("single-paradiddle", 120.0), ("double-stroke-open-roll", 100.0), ("flam-accent", 140.0),
             ("multiple-bounce-roll", 100.0), ("single-ratamacue", 100.0), ("triple-stroke-roll", 100.0))
"""The rudiments the demo plays, at these tempi (bpm): a diddle, a double-stroke roll, flams, buzzes, a drag,
an n-stroke roll, each designed note by note by the planner."""

_SUFFIXES = {"json": ".json", "csv": ".csv", "plot": ".png"}
_LABELS = {".mid": "MIDI", ".json": "JSON", ".csv": "CSV"}  # the page's links to a card's other files


@dataclass(frozen=True)
class Figure:
    """One of the paper's figures, simulated and written.

    Attributes
    ----------
    figure : str
        As the paper numbers it ("Fig. 4").
    preset : str
        The preset that reproduces it.
    stroke : Stroke
    paths : tuple of Path
        The files written, in the order json, csv, plot (those asked for).
    """

    figure: str
    preset: str
    stroke: object
    paths: tuple


@dataclass(frozen=True)
class Demo:
    """What :func:`run_demo` made.

    Attributes
    ----------
    outdir : Path
    figures : tuple of Figure
        The paper's figures, with their strokes.
    library : Library
        The shipped library, built in ``outdir / "library"``.
    strokes : tuple of Path
        Every library stroke's picture, sound and MIDI file, in ``outdir / "strokes"``.
    rudiments : tuple of Path
        The picture, sound, MIDI and JSON file of each of :data:`RUDIMENTS`, in ``outdir / "rudiments"``.
    piece : Composition
        The demo groove composed from it.
    played : int
        How many of the groove's notes were played (of ``len(piece.placements)``).
    groove : tuple of Path
        The groove's pattern and the files it composed to.
    index : Path
        The page linking every picture, sound and MIDI file.
    """

    outdir: Path
    figures: tuple
    library: object
    strokes: tuple
    rudiments: tuple
    piece: object
    played: int
    groove: tuple
    index: Path


def figure_stem(figure, preset):
    """The file name, without suffix, of a figure's files: ``figure_stem("Fig. 4", "free-bounce")`` is
    ``"fig4-free-bounce"``."""
    return f"{figure.lower().replace('. ', '').replace(' ', '')}-{preset}"


def write_figures(outdir, *, model=None, outputs=("plot",), progress=None, bundle=None):
    """Simulate the paper's figures (:data:`FIGURES`) and write each one's files to ``outdir``.

    Parameters
    ----------
    outdir : str or Path
        Created if missing; the files are named by :func:`figure_stem`.
    model : str or None
        The model to simulate with (see :data:`drumstroke.model.MODELS`); default each preset's.
    outputs : sequence of {"json", "csv", "plot"}
        Which files to write for each figure: the stroke as JSON, θ(t) as CSV at 1 kHz, a PNG plot.
    progress : callable or None
        Called with the fraction done, in [0, 1].
    bundle : Bundle or None
        The caller's bundle to put the files in place with (default: a bundle of their own).

    Returns
    -------
    list of Figure
    """
    from .errors import ParameterError
    from .render.outputs import write_stroke_outputs
    from .stroke import simulate

    unknown = sorted(set(outputs) - set(_SUFFIXES))
    if unknown:
        raise ParameterError(f"outputs must be among {', '.join(_SUFFIXES)}, got {unknown[0]!r}")
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    figures = []
    with bundled(bundle) as together:
        for i, (figure, preset) in enumerate(FIGURES.items()):
            stroke = simulate(preset, model=model)
            stem = outdir / figure_stem(figure, preset)
            files = {key: stem.with_suffix(suffix) for key, suffix in _SUFFIXES.items() if key in outputs}
            paths = write_stroke_outputs(stroke, **files, title=f"{figure} {preset}", bundle=together)
            figures.append(Figure(figure, preset, stroke, tuple(paths)))
            if progress:
                progress((i + 1) / len(FIGURES))
    return figures


def run_demo(outdir, *, progress=None):
    """Write the demo to ``outdir``: the paper's figures, the shipped library, every stroke and a groove, a page.

    Parameters
    ----------
    outdir : str or Path
        Created if missing. It receives the figures' JSON, CSV and PNG files, ``library/``,
        ``strokes/NAME.png|wav|mid`` for every library stroke, ``rudiments/NAME.png|wav|mid|json``
        for the rudiments the planner plays (:data:`RUDIMENTS`), ``groove.pattern`` and the groove's
        CSV, JSON, PNG, WAV and MIDI files, and ``index.html``, which links the pictures, sounds and
        MIDI files by relative paths.
    progress : callable or None
        Called with the fraction done, in [0, 1].

    Returns
    -------
    Demo
    """
    with Bundle() as bundle:
        return _demo(Path(outdir), progress or (lambda fraction: None), bundle)


def _demo(out, report, bundle):
    """:func:`run_demo`'s work into the folder ``out``, its files in ``bundle``; ``report`` takes the fraction done."""
    from ._atomic import write_atomic
    from .compose import compose, rudiment_score
    from .palette.library import DEMO_PATTERN, build_library
    from .palette.rudiments import rudiment
    from .render.outputs import write_composition_outputs, write_stroke_outputs
    from .render.page import write_index
    from .score import read_score

    figures = write_figures(out, outputs=("json", "csv", "plot"), progress=lambda f: report(0.2 * f), bundle=bundle)
    library = build_library(out / "library", progress=lambda f: report(0.2 + 0.2 * f))
    (out / "strokes").mkdir(exist_ok=True)
    cards, strokes = [], []
    for i, (name, entry) in enumerate(library.items()):
        files = write_stroke_outputs(entry.trajectory, plot=out / "strokes" / f"{name}.png",
                                     audio=out / "strokes" / f"{name}.wav", midi=out / "strokes" / f"{name}.mid",
                                     bundle=bundle)
        cards.append(_card(name, entry.category, entry.description, entry.trajectory, files, out))
        strokes += files
        report(0.4 + 0.4 * (i + 1) / len(library))
    (out / "rudiments").mkdir(exist_ok=True)
    rudiment_cards, rudiment_files = [], []
    for i, (name, tempo) in enumerate(RUDIMENTS):
        chosen = rudiment(name)
        played_rudiment = compose(rudiment_score(name, tempo, bars=2)[0])
        stem = out / "rudiments" / name
        files = write_composition_outputs(played_rudiment, title=chosen.title,
                                          plot=stem.with_suffix(".png"), audio=stem.with_suffix(".wav"),
                                          midi=stem.with_suffix(".mid"), json=stem.with_suffix(".json"),
                                          bundle=bundle)
        rudiment_files += files
        links = {path.suffix: path.relative_to(out).as_posix() for path in files}
        impacts = sum(len(s.impacts) for s in played_rudiment.sticks.values())
        done = sum(p.played for p in played_rudiment.placements)
        rudiment_cards.append(Card(
            f"{chosen.number}. {chosen.title}", f"PAS rudiment at {tempo:g} bpm",
            f"One cycle on the PAS sheet: {chosen.sticking}; two bars, every note designed by the planner "
            f"({len(played_rudiment.designs)} strokes).",
            links.pop(".png"), links.pop(".wav"), tuple((_LABELS[suffix], link) for suffix, link in links.items()),
            f"{done} of {plural(len(played_rudiment.placements), 'note')} played, {plural(impacts, 'impact')}; "
            f"model {played_rudiment.model}.", _sticking(played_rudiment)))
        report(0.8 + 0.1 * (i + 1) / len(RUDIMENTS))
    piece = compose(read_score(DEMO_PATTERN), library)
    write_atomic(out / "groove.pattern", DEMO_PATTERN.read_text(), bundle=bundle)
    groove = [out / "groove.pattern", *write_composition_outputs(
        piece, title="groove", csv=out / "groove.csv", json=out / "groove.json", plot=out / "groove.png",
        audio=out / "groove.wav", midi=out / "groove.mid", bundle=bundle)]
    played = sum(p.played for p in piece.placements)
    facts = (f"{plural(played, 'note')} on the sticks {', '.join(piece.sticks)}; {piece.t_end:.2f} s at "
             f"{piece.rate:g} Hz.")
    groove_card = Card("groove", "composition", "Four bars and a closing downbeat at 96 bpm composed from the "
                       "library (groove.pattern): backbeat singles, ghost taps, a double, a triplet ruff, rolls, a free "
                       "bounce and a swell.",
                       "groove.png", "groove.wav", (("MIDI", "groove.mid"), ("CSV", "groove.csv"),
                                                    ("JSON", "groove.json"), ("pattern", "groove.pattern")), facts,
                       _sticking(piece))
    figure_cards = [_card(f.figure, f"preset {f.preset}", PRESETS[f.preset].description, f.stroke, f.paths, out)
                    for f in figures]
    index = out / "index.html"
    write_index(index, title="drumstroke: the stroke palette",
                intro="Each stroke of the shipped library as the robot's motor angle θ(t) with its impacts, "
                      "and as it sounds on a synthesized snare drum; first a groove composed from them, then PAS "
                      "rudiments whose every note the planner designed, last the paper's Figs. 4–7 as drumstroke "
                      "draws them.",
                cards=[groove_card, *cards, *rudiment_cards, *figure_cards], bundle=bundle)
    report(1.0)
    return Demo(out, tuple(figures), library, tuple(strokes), tuple(rudiment_files), piece, played, tuple(groove),
                index)


def _sticking(piece):
    """A composed part's notes as a drummer writes them, bar by bar (:func:`drumstroke.render.sticking.sticking`)."""
    from .render.sticking import sticking

    return sticking([p.note for p in piece.placements], piece.tempo_map)


def _card(title, subtitle, description, stroke, files, out):
    """The page's card of a stroke whose ``files`` were written: its picture, its sound, links to the rest."""
    impacts = stroke.impacts
    facts = (f"{plural(len(impacts), 'impact')} in {stroke.t_end:.2f} s; first at {impacts.t[0]:.3f} s, "
             f"{impacts.tip_speed[0]:.2f} m/s tip speed; model {stroke.model}.")
    links = {path.suffix: path.relative_to(out).as_posix() for path in files}
    return Card(title, subtitle, description, links.pop(".png"), links.pop(".wav", None),
                tuple((_LABELS[suffix], link) for suffix, link in links.items()), facts)
