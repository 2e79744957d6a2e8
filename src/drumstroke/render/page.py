"""The demo's web page: every stroke's picture and sound on one static HTML page.

The page links its files by relative paths, so the folder can be moved or
served as it is (``python -m http.server``). Written atomically.
"""

import html
import re
from dataclasses import dataclass

from .._atomic import write_atomic
from .._version import __version__


@dataclass(frozen=True)
class Card:
    """One stroke (or the groove, or a figure) on the page; paths relative to the page.

    Attributes
    ----------
    title, subtitle, description : str
    image : str
        The picture.
    audio : str or None
        The sound, if any.
    links : tuple of (str, str)
        Other files, as (label, path): ``(("MIDI", "strokes/single.mid"),)``.
    facts : str
    sticking : str
        The notes as a drummer writes them (:func:`drumstroke.render.sticking.sticking`), for a part; shown
        under the picture and in its alternative text.
    """

    title: str
    subtitle: str
    description: str
    image: str
    audio: str | None = None
    links: tuple = ()
    facts: str = ""
    sticking: str = ""


def plural(count, noun):
    """``count`` and ``noun``, plural unless the count is one: ``"1 impact"``, ``"2 impacts"``."""
    return f"{count} {noun}{'' if count == 1 else 's'}"


_STYLE = """
body { font-family: system-ui, sans-serif; margin: 2rem auto; max-width: 1100px; color: #222; padding: 0 1rem; }
h1 { margin-bottom: 0.2rem; } .lead { color: #555; margin-top: 0; }
section { border-top: 1px solid #ddd; padding: 1rem 0; }
section h2 { margin: 0; font-size: 1.15rem; } .category { color: #666; font-weight: normal; }
img { width: 100%; height: auto; border: 1px solid #eee; }
audio { width: 100%; margin: 0.4rem 0; } .facts { color: #555; font-size: 0.9rem; }
figure { margin: 0; } figcaption { font-size: 0.9rem; color: #333; margin-top: 0.3rem; }
.sticking { font-family: ui-monospace, monospace; font-size: 1rem; }
"""


def write_index(path, *, title, intro, cards, bundle=None):
    """Write the page to ``path``: a heading, an introduction and one section per :class:`Card` (in ``bundle``, a
    :class:`drumstroke._atomic.Bundle`, if given)."""
    sections = "\n".join(_section(card) for card in cards)
    page = f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{html.escape(title)}</title>
<style>{_STYLE}</style>
</head>
<body>
<h1>{html.escape(title)}</h1>
<p class="lead">{html.escape(intro)} Made by drumstroke {__version__}.</p>
{sections}
</body>
</html>
"""
    write_atomic(path, page, bundle=bundle)


def _section(card):
    e = html.escape
    anchor = re.sub(r"[^a-z0-9]+", "-", card.title.lower()).strip("-")
    audio = f'\n<audio controls preload="none" src="{e(card.audio)}"></audio>' if card.audio else ""
    links = " ".join(f'<a href="{e(href)}">{e(label)}</a>' for label, href in card.links)
    if card.sticking:
        alt = f"θ(t) of each stick of {card.title} with its impacts and its sticking: {card.sticking}"
        caption = f'\n<figcaption>Sticking: <span class="sticking">{e(card.sticking)}</span></figcaption>'
    else:
        alt, caption = f"θ(t) of {card.title}", ""
    return f"""<section id="{anchor}">
<h2>{e(card.title)} <span class="category">— {e(card.subtitle)}</span></h2>
<p>{e(card.description)}</p>{audio}
<p class="facts">{e(card.facts)} {links}</p>
<figure>
<img src="{e(card.image)}" alt="{e(alt)}" loading="lazy">{caption}
</figure>
</section>"""
