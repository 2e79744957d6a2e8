"""Pictures of strokes like the paper's Figs. 4–7 (needs the ``plot`` extra: matplotlib).

θ(t) on top with the drumhead and the impacts marked (marker size grows with
the impact's level), the thumb's acceleration a(t) underneath, and g(t) beside
it when it varies. The title names the stroke and the model that made it. The file's format
follows its extension (:data:`SUFFIXES`); matplotlib is imported when a figure is drawn.
"""

import io
import math
from itertools import pairwise
from pathlib import Path

import numpy as np

from .._atomic import write_atomic
from ..budget import PLOT_BYTES_PER_POINT, check_memory
from ..errors import ParameterError
from ..model import inertia_ratio
from ..score import PLANNED
from ..stroke import Stroke, as_trajectory
from .page import plural
from .sticking import ACCENT_VELOCITY, GHOST_VELOCITY, GRACE_VELOCITY, LETTERS, bar_times, mark

SUFFIXES = (".png", ".pdf", ".svg")
"""The extensions of the pictures written: PNG (110 dpi), PDF and SVG (vector)."""


def stroke_figure(stroke, *, title=None, rate=2000.0):
    """A matplotlib Figure of a Stroke or Trajectory: θ(t) with impacts over a(t) (and g(t)).

    A post-processed trajectory draws its recipe's a(t) on its own time axis
    (stretched, reversed or trimmed with it); one with no recipe has no lower panel.

    Parameters
    ----------
    stroke : drumstroke.Stroke or drumstroke.Trajectory
    title : str or None
        Defaults to the stroke's name.
    rate : float > 0
        Samples per second drawn (Hz).
    """
    rests = stroke.rests if isinstance(stroke, Stroke) else np.empty((0, 2))
    rest_time = stroke.rest_time if isinstance(stroke, Stroke) else None
    trajectory = as_trajectory(stroke)
    recipe = trajectory.recipe
    forced = recipe is not None and trajectory.recipe_time is not None
    t, theta, _ = trajectory.sample(rate)
    figure = new_figure(figsize=(9.0, 5.6 if forced else 4.0), layout="constrained")
    if forced:
        top, bottom = figure.subplots(2, 1, sharex=True, height_ratios=(2.2, 1.0))
    else:
        top, bottom = figure.subplots(1, 1), None
    _draw_theta(top, t, theta, trajectory)
    for start, end in rests:
        top.axvspan(start, end, color="C2", alpha=0.12, lw=0)
    if rest_time is not None:
        top.axvline(rest_time, color="C2", lw=1.0, label=f"at rest from {rest_time:.4f} s")
    top.legend(loc="upper right", fontsize=8)
    if bottom is not None:
        source = trajectory.recipe_time(t)
        bottom.plot(t, recipe.force(source), color="C1", lw=1.2, label="a(t), thumb")
        bottom.set_ylabel("a (m/s²)")
        bottom.grid(alpha=0.25)
        gravity = recipe.gravity(source)
        if np.ptp(gravity) > 0:
            twin = bottom.twinx()
            twin.plot(t, gravity, color="C4", lw=1.0, ls="-.", label="g(t)")
            twin.set_ylabel("g (m/s²)")
            twin.legend(loc="lower right", fontsize=8)
        bottom.legend(loc="upper right", fontsize=8)
    (bottom or top).set_xlabel("t (s)")
    top.set_xlim(0.0, trajectory.t_end)
    name = title or trajectory.name or "stroke"
    if recipe is not None:
        d = inertia_ratio(recipe.model, recipe.stick)
        detail = f"model: {trajectory.model} (D = {d:.4f} m², c = {recipe.cor:g})"
    else:
        detail = f"model: {trajectory.model}"
    steps = list(trajectory.history[1:])
    suffix = f"\n{' → '.join(steps)}" if steps else ""
    figure.suptitle(f"{name} — {detail}{suffix}", fontsize=11)
    return figure


def composition_figure(composition, *, title="composition", rate=1000.0, accent=ACCENT_VELOCITY,
                       grace=GRACE_VELOCITY, ghost=GHOST_VELOCITY):
    """A matplotlib Figure of a composed part as a drummer reads it: one lane per stick on one θ scale.

    Each lane (``right`` on top, then ``left``, then any other stick) draws the stick's angle θ(t) over
    the drumhead, its impacts as dots whose size and colour show their level (one colour scale for all
    sticks), and under the head each note's sticking (:mod:`drumstroke.render.sticking`): R or L,
    ``>`` an accent (velocity ≥ ``accent``), lowercase a grace-level note (velocity ≤ ``grace``),
    parentheses a ghost note (velocity ≤ ``ghost``), ``z`` a buzz; a note left out is crossed in red.
    A library stroke's name stands above its note. The time axis is seconds from the score's start
    (its time 0), with the bars (solid) and beats (dotted) of its tempo map; the title says what it is,
    the tempo, the bars and the model.

    Parameters
    ----------
    composition : Composition
    title : str
        What it is: a rudiment's or a score file's name.
    rate : float > 0
        Samples per second drawn (Hz).
    accent, grace, ghost : int in [1, 127]
        The velocities of the marks (see :mod:`drumstroke.render.sticking`).
    """
    notes = [p.note for p in composition.placements]
    bars = bar_times(notes, composition.tempo_map)
    parts = composition.sticks
    names = [*(n for n in LETTERS if n in parts), *(n for n in parts if n not in LETTERS)]  # right, left, others
    check_points(f"drawing {title!r}", composition.t_end, rate, len(names))
    sticks = {name: parts[name].sample(rate) for name in names}
    figure = new_figure(figsize=(11.0, 1.8 + 2.6 * len(sticks)), layout="constrained")
    axes = figure.subplots(len(sticks), 1, sharex=True, sharey=True, squeeze=False)[:, 0]
    levels = np.concatenate([s.impacts.level_db for s in sticks.values()])
    scale = _level_scale(levels)
    shift = composition.offset  # the score's time 0 at x = 0
    for ax, (name, trajectory) in zip(axes, sticks.items()):
        _draw_lane(ax, trajectory, shift, scale)
        draw_bars(ax, bars, composition.tempo_map)
        for p in composition.placements:
            if p.note.stick == name:
                _draw_note(ax, p, trajectory.theta_max, mark(name, p.note.velocity, buzz=p.note.stroke == "buzz",
                                                             accent=accent, grace=grace, ghost=ghost))
        ax.set_ylabel(f"θ {name} stick (rad)")
    heads = [s.theta_max for s in sticks.values()]
    top = max(float(np.max(s.theta)) for s in sticks.values())
    room = max(top - min(heads), 0.05)
    axes[0].set_ylim(min(heads) - 0.22 * room, top + 0.08 * room)  # under the head: the sticking
    axes[0].set_xlim(-shift, composition.t_end - shift)
    axes[-1].set_xlabel(f"time from the score's start (s); bars solid, beats dotted\nsticking: R right, L left; "
                        f"R> accent (velocity ≥ {accent}), r grace level (≤ {grace}), (R) ghost (≤ {ghost}), "
                        f"z buzz", fontsize=9)
    _level_legend(axes, scale, any(not p.played for p in composition.placements))
    played = sum(p.played for p in composition.placements)
    bar_count = len(bars) - 1
    length = plural(bar_count, "bar") if bar_count > 0 else f"{composition.t_end - shift:.2f} s"
    figure.suptitle(f"{title} — {tempo_text(composition.tempo_map)}, {length}, model: {composition.model}\n"
                    f"{played} of {plural(len(notes), 'note')} played", fontsize=11)
    return figure


def _draw_lane(ax, trajectory, shift, scale):
    """One stick's θ(t) over the head, its impacts sized and coloured by level."""
    head = trajectory.theta_max
    ax.axhline(head, color="0.55", lw=1.0, ls="--")
    ax.plot(trajectory.t - shift, trajectory.theta, color="C0", lw=1.1)
    impacts = trajectory.impacts
    if len(impacts):
        ax.scatter(impacts.t - shift, np.full(len(impacts), head), s=scale.size(impacts.level_db),
                   c=impacts.level_db, cmap=scale.cmap, norm=scale.norm, zorder=3, edgecolors="none")
    ax.grid(alpha=0.25, axis="y")


def draw_bars(ax, bars, tempo_map, *, beats=True):
    """Bar lines (solid) and, with ``beats``, quarter-note beat lines (dotted) at the score's ``bars`` (s, the
    score's time)."""
    for start, end in pairwise(bars):
        ax.axvline(start, color="0.45", lw=0.9, zorder=0)
        if not beats:
            continue
        first, last = tempo_map.beats([start, end])
        for beat in tempo_map.seconds(np.arange(first + 1.0, last - 1e-9)):
            ax.axvline(beat, color="0.6", lw=0.6, ls=":", zorder=0)
    if bars.size:
        ax.axvline(bars[-1], color="0.45", lw=0.9, zorder=0)


def _draw_note(ax, placement, head, text):
    """A note's sticking under the head at its time; a left-out note crossed in red; a library stroke named above."""
    note = placement.note
    color = "0.1" if placement.played else "C3"
    ax.annotate(text, (note.time, head), xytext=(0, -4), textcoords="offset points", ha="center", va="top",
                fontsize=8, color=color, fontweight="bold" if text.endswith(">") else "normal", gid="sticking")
    if not placement.played:
        ax.plot([note.time], [head], marker="x", ms=7, mew=1.5, color="C3", zorder=4)
    if note.stroke not in PLANNED:  # a library stroke: its name, above the lane where no curve runs
        ax.annotate(note.stroke, (note.time, 1.0), xycoords=("data", "axes fraction"), xytext=(0, 2),
                    textcoords="offset points", rotation=90, fontsize=7, va="bottom", ha="center", color="0.35")


class _LevelScale:
    """The impacts' level (dB re 1 m/s tip speed) as dot size and colour, one scale for every stick."""

    cmap = "viridis"

    def __init__(self, low, high):
        from matplotlib.colors import Normalize

        self.norm = Normalize(low, high)

    def size(self, level_db):
        """Dot area (points²): 8 for the softest impact to 64 for the loudest."""
        return 8.0 + 56.0 * np.clip(self.norm(level_db), 0.0, 1.0)


def _level_scale(levels, *, span=40.0):
    """The scale of the impacts' ``levels`` (dB): from the loudest down ``span`` dB (a roll's last bounces, softer
    still, are drawn as the softest)."""
    finite = levels[np.isfinite(levels)]
    high = float(finite.max()) if finite.size else 0.0
    low = max(float(finite.min()), high - span) if finite.size else high - span
    return _LevelScale(low, max(high, low + 1.0))


def _level_legend(axes, scale, left_out):
    """The key to the lanes: the head, θ, impacts at three levels (their sizes and colours), left-out notes."""
    from matplotlib import colormaps
    from matplotlib.lines import Line2D

    cmap = colormaps[scale.cmap]
    handles = [Line2D([], [], color="0.55", ls="--", label="drumhead"),
               Line2D([], [], color="C0", label="θ(t), the stick's angle")]
    for k, level in enumerate(np.linspace(scale.norm.vmin, scale.norm.vmax, 3)):
        handles.append(Line2D([], [], ls="", marker="o", markeredgecolor="none", color=cmap(scale.norm(level)),
                              markersize=float(np.sqrt(scale.size(level))),
                              label=f"impact at {'≤ ' if k == 0 else ''}{level:.0f} dB re 1 m/s"))
    if left_out:
        handles.append(Line2D([], [], ls="", marker="x", color="C3", mew=1.5, label="note left out"))
    axes[0].legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8,
                   title="impacts: size and colour\nshow the level (tip speed)", title_fontsize=8)


def tempo_text(tempo_map):
    """``"100 bpm"``, or ``"96–120 bpm"`` for a tempo that changes."""
    bpm = sorted({round(60e6 / tempo, 1) for _, tempo in tempo_map.tempi})
    return f"{bpm[0]:g} bpm" if len(bpm) == 1 else f"{bpm[0]:g}–{bpm[-1]:g} bpm"


def tracking_figure(played):
    """A matplotlib Figure of a reference and what each controller played: θ(t) and the onsets of each."""
    ref = played[0].reference
    head = ref.theta_max
    figure = new_figure(figsize=(11.0, 1.6 + 2.4 * len(played)), layout="constrained")
    axes = np.atleast_1d(figure.subplots(len(played), 1, sharex=True, squeeze=False)[:, 0])
    for ax, p in zip(axes, played):
        ax.axhline(head, color="0.55", lw=1.0, ls="--", label="drumhead")
        ax.plot(ref.t, ref.theta, color="0.35", lw=1.0, label="reference θ")
        ax.plot(ref.t, p.theta, color="C0", lw=1.0, alpha=0.85, label=f"played θ ({p.controller})")
        ax.scatter(ref.impacts.t, np.full(len(ref.impacts), head + 0.01), marker="v", s=14, color="0.2",
                   label="reference onsets")
        ax.scatter(p.onsets, np.full(len(p.onsets), head - 0.01), marker="^", s=14, color="C3",
                   label="played onsets")
        ax.set_ylabel("θ (rad)")
        ax.grid(alpha=0.25)
        ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8)
    axes[-1].set_xlabel("t (s)")
    axes[-1].set_xlim(0.0, ref.t[-1])
    figure.suptitle(f"{ref.name} (model {ref.model}) played on the {played[0].plant} plant", fontsize=11)
    return figure


def comparison_figure(comparison, *, labels=None):
    """A matplotlib Figure of two strokes compared (a :class:`drumstroke.analysis.compare.Comparison`).

    Top: each stroke's onsets (stems at their levels, dB re its loudest) and level envelope, from its
    first onset, the unmatched ones crossed; middle: the bounce rate, 1 / interval at each interval's midpoint (Hz,
    log scale); bottom: B's interval minus A's between successive matched pairs (ms).
    """
    a, b = comparison.a, comparison.b
    labels = labels or (a.source or "A", b.source or "B")
    figure = new_figure(figsize=(10.0, 7.2), layout="constrained")
    top, middle, bottom = figure.subplots(3, 1)
    for onsets, label, color, marker in ((a, labels[0], "C0", "o"), (b, labels[1], "C3", "s")):
        top.vlines(onsets.t, comparison.threshold_db, onsets.level_db, color=color, lw=0.8, alpha=0.6)
        top.plot(onsets.t, onsets.level_db, marker=marker, ms=3.5, lw=1.0, color=color,
                 label=f"{label}: {len(onsets)} onsets")
    for onsets, unmatched, label, color in ((a, comparison.unmatched_a, labels[0], "C0"),
                                            (b, comparison.unmatched_b, labels[1], "C3")):
        if len(unmatched):
            top.plot(onsets.t[unmatched], onsets.level_db[unmatched], "x", ms=9, mew=1.8, color=color,
                     label=f"{label}: {len(unmatched)} unmatched")
    top.set_ylim(comparison.threshold_db - 2.0, 2.0)
    top.set_ylabel("level (dB re loudest)")
    top.set_xlabel("t from the first onset (s)")
    top.legend(loc="upper right", fontsize=8)
    for onsets, label, color in ((a, labels[0], "C0"), (b, labels[1], "C3")):
        if len(onsets) >= 2:
            middle.semilogy(*onsets.bounce_rate(), ".-", ms=3.0, color=color, lw=1.0, label=label)
    middle.set_ylabel("bounce rate (Hz)")
    middle.set_xlabel("t from the first onset (s)")
    difference = comparison.interval_difference * 1e3
    bottom.axhline(0.0, color="0.55", lw=1.0)
    bottom.bar(np.arange(1, len(difference) + 1), difference, color="C2", width=0.7)
    bottom.set_ylabel(f"interval: {labels[1]} − {labels[0]} (ms)")
    bottom.set_xlabel(f"interval between successive pairs (matched within ±{comparison.window * 1e3:g} ms)")
    for ax in (top, middle, bottom):
        ax.grid(alpha=0.25)
    figure.suptitle(f"{labels[1]} against {labels[0]}: onsets above {comparison.threshold_db:g} dB re each "
                    f"one's loudest", fontsize=11)
    return figure


def fit_figure(fit, *, title=None, rate=2000.0):
    """A matplotlib Figure of a stroke fitted to recorded onsets, on the recording's clock.

    θ(t) with the fitted stroke's impacts and the recorded onsets marked on the drumhead (those left
    out crossed), the levels (dB re the loudest onset) of both with the detection threshold, and a(t).

    Parameters
    ----------
    fit : drumstroke.analysis.fit.Fit
        Its stroke (t = 0 at its ``release``, s on the recording's clock), its onsets (s; dB re the
        loudest, with their detection threshold), its ``offset`` (dB re 1 m/s: the loudest onset's
        level in the model; the impacts are drawn that much lower) and the onsets it could not play.
    title : str, optional
        Default: the onsets' source, fitted.
    rate : float
        Hz, at which θ(t) and a(t) are drawn.
    """
    stroke, release, offset = fit.stroke, fit.release, fit.offset
    onset_t, onset_level, threshold_db = fit.onsets.t, fit.onsets.level_db, fit.onsets.threshold_db
    left_out = [i for i, _ in fit.unmatched + fit.dropped]
    title = title or f"{fit.onsets.source or 'a recording'} fitted"
    trajectory = as_trajectory(stroke)
    recipe = trajectory.recipe
    t, theta, _ = trajectory.sample(rate)
    clock = t + release
    figure = new_figure(figsize=(10.0, 7.0), layout="constrained")
    top, middle, bottom = figure.subplots(3, 1, sharex=True, height_ratios=(2.2, 1.2, 1.0))
    head = trajectory.theta_max
    top.axhline(head, color="0.55", lw=1.0, ls="--", label=f"drumhead θ_max = {head:.4f} rad")
    top.plot(clock, theta, color="C0", lw=1.1, label="θ(t), fitted")
    impacts = stroke.impacts
    out = np.zeros(len(onset_t), bool)
    out[list(left_out)] = True
    top.scatter(impacts.t + release, np.full(len(impacts), head), s=14, color="C3", zorder=3,
                label=f"{len(impacts)} fitted impacts")
    top.scatter(onset_t[~out], np.full(int((~out).sum()), head + 0.04), marker="v", s=18, color="0.15", zorder=3,
                label=f"{int((~out).sum())} recorded onsets")
    if out.any():
        top.scatter(onset_t[out], np.full(int(out.sum()), head + 0.04), marker="x", s=30, color="C3", zorder=3,
                    label=f"{int(out.sum())} left out")
    top.set_ylabel("θ (rad)")
    top.grid(alpha=0.25)
    top.legend(loc="upper right", fontsize=8)
    middle.plot(onset_t, onset_level, "v", color="0.15", ms=5, label="recorded")
    middle.plot(impacts.t + release, impacts.level_db - offset, ".", color="C3", ms=6, label="fitted")
    if np.isfinite(threshold_db):
        middle.axhline(threshold_db, color="0.55", lw=1.0, ls=":", label=f"detection threshold {threshold_db:g} dB")
    middle.set_ylim(min(onset_level.min(), threshold_db if np.isfinite(threshold_db) else 0.0) - 6.0, 3.0)
    middle.set_ylabel("level (dB re loudest)")
    middle.grid(alpha=0.25)
    middle.legend(loc="upper right", fontsize=8)
    bottom.plot(clock, recipe.force(t), color="C1", lw=1.2, label="a(t), thumb (fitted)")
    bottom.set_ylabel("a (m/s²)")
    bottom.set_xlabel("t (s, the recording's clock)")
    bottom.grid(alpha=0.25)
    bottom.legend(loc="upper right", fontsize=8)
    top.set_xlim(min(release, onset_t.min()), max(release + trajectory.t_end, onset_t.max()))
    d = inertia_ratio(recipe.model, recipe.stick)
    figure.suptitle(f"{title} — model: {recipe.model} (D = {d:.4f} m², c = {recipe.cor:.4g}), "
                    f"loudest onset {offset:.2f} dB re 1 m/s", fontsize=11)
    return figure


def onsets_figure(signal, rate, times, levels, *, threshold_db, title="recording"):
    """A matplotlib Figure of a recording and the onsets found in it: the waveform with the onsets over their levels.

    Parameters
    ----------
    signal : ndarray [shape=(n,)]
        Samples (full scale).
    rate : float
        Hz.
    times, levels : ndarray [shape=(m,)]
        The onsets (s) and their levels (dB re the loudest).
    threshold_db : float
        The detection threshold (dB re the loudest), drawn as a line (none if not finite).
    title : str
        What the recording is.
    """
    figure = new_figure(figsize=(11.0, 5.0), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True, height_ratios=(3, 2))
    step = max(1, len(signal) // 200_000)  # a long file is drawn from every step-th sample
    t = np.arange(0, len(signal), step) / rate
    top.plot(t, signal[::step], color="0.35", lw=0.5)
    for x in times:
        top.axvline(x, color="C3", lw=0.6, alpha=0.7)
    top.set_ylabel("signal (full scale)")
    top.grid(alpha=0.25)
    bottom.stem(times, levels, linefmt="C3-", markerfmt="C3o", basefmt=" ", bottom=min(-60.0, float(np.min(levels,
                initial=0.0)) - 5.0))
    if np.isfinite(threshold_db):
        bottom.axhline(threshold_db, color="0.5", ls="--", lw=1.0, label=f"threshold {threshold_db:.1f} dB")
        bottom.legend(loc="upper right", fontsize=8)
    bottom.set_ylabel("level (dB re the loudest)")
    bottom.set_xlabel("t (s)")
    bottom.grid(alpha=0.25)
    bottom.set_xlim(0.0, max(len(signal) / rate, 1e-3))
    figure.suptitle(f"{title}: {len(times)} onsets", fontsize=11)
    return figure


def _draw_theta(ax, t, theta, trajectory):
    head = trajectory.theta_max
    ax.axhline(head, color="0.55", lw=1.0, ls="--", label=f"drumhead θ_max = {head:.4f} rad")
    ax.plot(t, theta, color="C0", lw=1.1, label="θ(t)")
    impacts = trajectory.impacts
    if len(impacts):
        level = impacts.level_db
        size = np.clip(4.0 + (level - level.max() + 40.0), 1.0, 44.0)
        ax.scatter(impacts.t, np.full(len(impacts), head), s=size, color="C3", zorder=3,
                   label=f"{len(impacts)} impacts")
    ax.set_ylabel("θ (rad)")
    ax.grid(alpha=0.25)


def save_stroke_plot(stroke, path, *, title=None, bundle=None):
    """Draw ``stroke`` (see :func:`stroke_figure`) to a picture file, written atomically (in ``bundle``, if given)."""
    save_figure(stroke_figure(stroke, title=title), path, bundle=bundle)


def save_figure(figure, path, *, bundle=None):
    """Write a Figure to a picture file, atomically: PNG, PDF or SVG by ``path``'s extension (:data:`SUFFIXES`).

    ``bundle``: a :class:`drumstroke._atomic.Bundle` the file is put in place with (default: at once)."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format=picture_format(path), dpi=110)
    write_atomic(path, buffer.getvalue(), bundle=bundle)


def picture_format(path):
    """matplotlib's name of the format of ``path``, from its extension (see :data:`SUFFIXES`)."""
    suffix = Path(path).suffix.lower()
    if suffix not in SUFFIXES:
        raise ParameterError(f"path must end in one of {', '.join(SUFFIXES)} (the pictures written), got {str(path)!r}")
    return suffix[1:]


def check_points(what, duration, rate, curves):
    """Refuse a picture (``what``) of ``curves`` curves over ``duration`` s drawn at ``rate`` Hz beyond the memory budget."""
    points = (math.floor(duration * rate) + 1) * curves
    check_memory(what, points * PLOT_BYTES_PER_POINT, f"{points} points: {curves} curves of {duration:g} s at "
                                                      f"{rate:g} Hz")


def new_figure(**options):
    """A matplotlib Figure (``options`` as Figure takes them), or an ImportError naming the ``plot`` extra."""
    try:
        from matplotlib.figure import Figure
    except ImportError as error:  # pragma: no cover - exercised only without the extra
        raise ImportError("drumstroke plots need matplotlib: pip install 'drumstroke[plot]'") from error
    return Figure(**options)
