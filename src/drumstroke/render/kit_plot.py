"""The picture of a song played on the whole kit, as a drummer reads it (needs the ``plot`` extra: matplotlib).

:func:`kit_figure` draws a :class:`~drumstroke.compose.KitComposition`. On top, a lane per piece (the kit's
order, the pieces the part has notes on): each impact a marker at its time, coloured and shaped by the limb
that struck it, its area growing with its level on one scale for every limb; the hi-hat's state told by the
marker's fill (closed filled, open hollow, the pedal half filled); each note not played a grey cross in its
lane. Underneath, on the same time axis, the joints' angles: each hand's positioning joints (yaw, lift) and
its stick's θ, each foot's beater θ, one scale per kind of joint set by the whole part, so a quiet passage
drawn alone looks as quiet as it is. The time axis is the score's time (s from its start), with its bars; a
``window`` draws a stretch of a long song.
"""

import math

import numpy as np

from .._checks import check_real
from ..dynamics import FLOOR_DB, FOOT_CEILING_DB
from ..errors import ParameterError
from ..kit.pieces import FEET, PEDAL_STATE
from .page import plural
from .plot import check_points, draw_bars, new_figure, tempo_text
from .sticking import bar_times

LIMB_STYLES = {"right": ("C0", "o"), "left": ("C1", "s"), "right-foot": ("C2", "v"), "left-foot": ("C4", "^")}
"""Each limb's marker colour and shape (matplotlib's names); its joints' curves are drawn in its colour."""

LIMB_NAMES = {"right": "right hand", "left": "left hand", "right-foot": "right foot", "left-foot": "left foot"}

FILLS = {"closed": "full", "open": "none", PEDAL_STATE: "bottom"}
"""The marker's fill of each hi-hat state (matplotlib's fill styles); every other piece's markers are filled."""

LEVELS = (FLOOR_DB, FOOT_CEILING_DB)
"""dB re 1 m/s: the levels drawn smallest and largest, a stick's at velocity 1 (−36 dB) to a foot's at 127
(+17 dB); a bounce softer still is drawn as small as the softest."""

BAR_LINES = 32
"""The most bar lines drawn: a longer window draws every 2nd, 4th, 8th… bar (of the song's count from its first)."""

BEAT_LINES = 16
"""The most bars a window may span for its beats to be drawn (dotted): more, and they grey the lanes over."""

_KEY_HEIGHT = 2.8  # in: the lanes are at least as tall as their key beside them, so no gap opens under a few lanes


def kit_figure(composition, *, title="kit", window=None, rate=1000.0, sizes=(2.0, 30.0)):
    """A matplotlib Figure of a song played on the kit: a lane per piece over the joints' angles, on the score's time.

    Parameters
    ----------
    composition : KitComposition
        What :func:`drumstroke.compose.compose_kit` returns.
    title : str
        What it is: the score file's name.
    window : (float, float) or None
        (start, end), s of the score's time: the stretch drawn (:func:`check_window`); default the whole part
        (:func:`part_span`).
    rate : float in [1, 100000]
        Samples per second of the joints' curves (Hz).
    sizes : (float, float)
        pt², 0 < smallest < largest: the markers' areas at the levels :data:`LEVELS`, linear in dB between.

    Returns
    -------
    matplotlib.figure.Figure
        Its first axes the lanes (y: the lane's index, top 0), then one axes per kind of joint.
    """
    from ..compose import KitComposition

    if not isinstance(composition, KitComposition):
        raise ParameterError(f"composition must be a drumstroke.compose.KitComposition, got {type(composition)}")
    if not isinstance(title, str):
        raise ParameterError(f"title must be a str, got {title!r}")
    start, end = check_window(part_span(composition) if window is None else window, span=part_span(composition))
    rate = check_real("rate", rate, low=1.0, high=1e5, unit="Hz")
    area = _Area(sizes)
    outcomes = composition.performance.outcomes
    shift = composition.offset  # the timeline's time of the score's 0
    lanes = [p.name for p in composition.kit.pieces if any(o.piece == p.name for o in outcomes)]
    check_points(f"drawing {title!r} on the kit", composition.t_end, rate, len(composition.columns))
    t, columns = composition.sample(rate)
    kinds = _kinds(columns)
    heights = [max(_KEY_HEIGHT, 0.45 + 0.3 * len(lanes))] + [1.25] * len(kinds)  # in
    figure = new_figure(figsize=(12.0, 1.0 + sum(heights)), layout="constrained")
    axes = figure.subplots(len(heights), 1, sharex=True, squeeze=False, height_ratios=heights)[:, 0]
    top = axes[0]
    _draw_hits(top, composition, lanes, (start, end), area)
    _draw_not_played(top, outcomes, lanes, shift, (start, end))
    for ax, (label, curves) in zip(axes[1:], kinds.items()):
        _draw_joints(ax, t - shift, curves, label, (start, end))
    bars, every = _bar_lines([o.note._replace(time=o.note.time - shift) for o in outcomes], composition.tempo_map,
                             (start, end))
    beats = every == 1 and len(bars) - 1 <= BEAT_LINES
    for ax in axes:
        draw_bars(ax, bars, composition.tempo_map, beats=beats)
    top.set_xlim(start, end)
    lines = "bars solid" if every == 1 else f"every {_ordinal(every)} bar solid"
    axes[-1].set_xlabel(f"time from the score's start (s); {lines}{', beats dotted' if beats else ''}")
    _legend(top, composition, lanes, area)
    played = sum(o.played for o in outcomes)
    low, high = part_span(composition)
    stretch = (f"the whole part, {high - low:.0f} s" if (start, end) == (low, high)
               else f"{start:g} s to {end:g} s of the part's {high - low:.0f} s")
    figure.suptitle(f"{title} on the kit — {tempo_text(composition.tempo_map)}, model: {composition.model}; "
                    f"{stretch}\n{played} of {plural(len(outcomes), 'note')} played", fontsize=11)
    return figure


def part_span(composition):
    """(start, end), s of the score's time: the part's whole timeline, its lead-in before the score's 0 included."""
    return 0.0 - composition.offset, composition.t_end - composition.offset  # 0.0 -: no "-0" in a message


def check_window(window, *, span=None):
    """``window`` as (start, end), s of the score's time: two finite numbers, end after start.

    With ``span`` (the part's, :func:`part_span`) the start must lie in it, [span start, span end); an end
    past the span's is brought back to it.

    >>> check_window((2, 4.5))
    (2.0, 4.5)
    >>> check_window([10, 300], span=(-0.24, 207.9))
    (10.0, 207.9)
    >>> check_window((5, 3))
    Traceback (most recent call last):
    ...
    drumstroke.errors.ParameterError: window end must be in (5, inf) s, got 3.0
    """
    try:
        start, end = window
    except (TypeError, ValueError):
        raise ParameterError(f"window must be (start, end), two numbers of seconds, got {window!r}",
                             parameter="window", value=window, allowed="(start, end) s") from None
    low, high = (-math.inf, math.inf) if span is None else span
    start = check_real("window start", start, low=low, high=high, high_open=True,
                       unit="s" if span is None else "s, the part's span on the score's time")
    end = check_real("window end", end, low=start, low_open=True, unit="s")
    return start, min(end, high)


def _bar_lines(notes, tempo_map, window):
    """The bar lines drawn in ``window`` (s, the score's time) and how many bars apart they are: every bar, or
    every 2nd, 4th, 8th… (counted from the song's first) so that at most :data:`BAR_LINES` are drawn."""
    bars = bar_times(notes, tempo_map)
    first = max(int(np.searchsorted(bars, window[0], "right")) - 1, 0)
    last = int(np.searchsorted(bars, window[1], "left"))
    every = 1
    while (last - first) / every > BAR_LINES:
        every *= 2
    index = np.arange(first, min(last + 1, len(bars)))
    return bars[index[index % every == 0]], every


def _ordinal(n):
    """2nd, 4th, 8th…: the English ordinal of a power of two."""
    return f"{n}{'nd' if n == 2 else 'th'}"


class _Area:
    """The markers' area (pt²) of a level (dB re 1 m/s): linear from ``smallest`` at LEVELS[0] to ``largest`` at
    LEVELS[1], clipped."""

    def __init__(self, sizes):
        try:
            smallest, largest = sizes
        except (TypeError, ValueError):
            raise ParameterError(f"sizes must be (smallest, largest), two areas in pt², got {sizes!r}",
                                 parameter="sizes", value=sizes, allowed="(smallest, largest) pt²") from None
        self.smallest = check_real("sizes[0]", smallest, low=0.0, high=1e4, low_open=True, unit="pt²")
        self.largest = check_real("sizes[1]", largest, low=self.smallest, high=1e4, low_open=True, unit="pt²")

    def __call__(self, level_db):
        low, high = LEVELS
        return self.smallest + (self.largest - self.smallest) * np.clip((level_db - low) / (high - low), 0.0, 1.0)


def _draw_hits(ax, composition, lanes, window, area):
    """Every impact in the window on its piece's lane: a limb's colour and shape, the hi-hat's state as the fill."""
    from matplotlib.markers import MarkerStyle

    shift, kit = composition.offset, composition.kit
    hits = [h for h in composition.performance.hits if window[0] <= h.t - shift <= window[1]]
    groups = {}
    for h in hits:
        fill = FILLS.get(kit.piece(h.piece).state(h.key), "full")
        groups.setdefault((h.limb, fill), []).append(h)
    for (limb, fill), group in groups.items():
        color, shape = LIMB_STYLES[limb]
        x = np.array([h.t - shift for h in group])
        y = np.array([lanes.index(h.piece) for h in group], float)
        size = area(20.0 * np.log10([h.speed for h in group]))
        if fill == "none":
            ax.scatter(x, y, s=size, marker=shape, facecolors="none", edgecolors=color, linewidths=0.8, zorder=3,
                       gid=f"{limb} hits {fill}")
            continue
        if fill == "bottom":  # the pedal: the outline, its lower half filled
            ax.scatter(x, y, s=size, marker=shape, facecolors="none", edgecolors=color, linewidths=0.8, zorder=3,
                       gid=f"{limb} outline")
        ax.scatter(x, y, s=size, marker=MarkerStyle(shape, fillstyle=fill), color=color, linewidths=0, zorder=3,
                   gid=f"{limb} hits {fill}")
    ax.set_yticks(range(len(lanes)), lanes, fontsize=8)
    ax.set_ylim(len(lanes) - 0.5, -0.5)  # the kit's first piece on top
    ax.grid(axis="y", color="0.85", lw=0.6)
    ax.set_ylabel("piece")


def _draw_not_played(ax, outcomes, lanes, shift, window):
    """A grey cross in its lane at the time of each note not played."""
    left = [(o.note.time - shift, lanes.index(o.piece)) for o in outcomes
            if not o.played and window[0] <= o.note.time - shift <= window[1]]
    if left:
        x, y = np.array(left).T
        ax.scatter(x, y, s=18, marker="x", color="0.5", linewidths=1.0, zorder=4, gid="not played")


def _kinds(columns):
    """The joints' curves by kind, {axis label: [(limb, values)]}: each positioning joint's, the sticks' θ, the
    beaters' θ, in the columns' order."""
    kinds = {}
    for name, values in columns.items():
        if name.endswith(".velocity"):
            continue
        limb, joint = name.rsplit(".", 1)
        label = ("beater θ" if limb in FEET else "stick θ") if joint == "theta" else joint
        kinds.setdefault(f"{label} (rad)", []).append((limb, values))
    return kinds


def _draw_joints(ax, x, curves, label, window):
    """One kind of joint's curves, a limb's colour each, drawn in the window on the scale of the whole part."""
    step = x[1] - x[0] if len(x) > 1 else 0.0
    shown = (x >= window[0] - step) & (x <= window[1] + step)
    for limb, values in curves:
        ax.plot(x[shown], values[shown], color=LIMB_STYLES[limb][0], lw=1.0, label=LIMB_NAMES[limb])
    low = min(float(values.min()) for _, values in curves)
    high = max(float(values.max()) for _, values in curves)
    room = 0.06 * (high - low) or 0.05
    ax.set_ylim(low - room, high + room)
    ax.set_ylabel(label, fontsize=9)
    ax.grid(alpha=0.25, axis="y")
    ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8)


def _legend(ax, composition, lanes, area):
    """The key to the lanes: the limbs, the hi-hat's states, the notes not played, the level's scale."""
    from matplotlib.lines import Line2D

    limbs = dict.fromkeys(o.limb for o in composition.performance.outcomes if o.limb)
    handles = [Line2D([], [], ls="", marker=LIMB_STYLES[limb][1], color=LIMB_STYLES[limb][0], label=LIMB_NAMES[limb])
               for limb in LIMB_STYLES if limb in limbs]
    hihats = [p.name for p in composition.kit.pieces if p.kind == "hihat" and p.name in lanes]
    if hihats:
        handles += [Line2D([], [], ls="", marker="o", color="0.3", fillstyle=fill, label=f"{hihats[0]} {state}")
                    for state, fill in FILLS.items()]
    if not all(o.played for o in composition.performance.outcomes):
        handles.append(Line2D([], [], ls="", marker="x", color="0.5", label="note not played"))
    for level in np.linspace(*LEVELS, 3):
        handles.append(Line2D([], [], ls="", marker="o", color="0.3", markeredgecolor="none",
                              markersize=float(np.sqrt(area(level))), label=f"{level:+.0f} dB"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, title_fontsize=8,
              title="limb: colour and shape\nlevel (re 1 m/s, tip or\nbeater): marker area")
