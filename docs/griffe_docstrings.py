"""A griffe extension that reads drumstroke's docstrings as mkdocstrings needs them (loaded by mkdocs.yml).

Two things the numpy-style docstrings do that mkdocstrings does not render by itself:

- Sphinx roles (``:class:`~drumstroke.trajectory.Trajectory```, ``:func:`simulate```) become links to the
  object's page when the name resolves in the docstring's scope, and code otherwise (an optional
  cross-reference: a name on a page the site does not have, e.g. in a private module, is not an error);
- a doctest (``>>>``) that is not under an ``Examples`` heading (one left at the end of a Parameters
  section, or in a module's summary) gets that heading, so it renders as code and not as a quotation.

The source files are not changed: this only rewrites the docstrings griffe hands to mkdocstrings.
"""

import html
import re

import griffe

ROLE = re.compile(r":(?:py:)?(?:class|func|meth|attr|mod|data|exc|obj|const):`(?P<target>[^`]+)`")
HEADING = re.compile(r"^\s*-{3,}\s*$")


class SphinxRolesAndDoctests(griffe.Extension):
    def on_package(self, *, pkg, **kwargs):
        for obj in _walk(pkg):
            if obj.docstring is not None:
                obj.docstring.value = with_examples_heading(with_links(obj.docstring.value, obj))


def _walk(obj):
    yield obj
    for member in obj.members.values():
        if not member.is_alias:
            yield from _walk(member)


def with_links(text, obj):
    """Replace each Sphinx role by an optional cross-reference to the object it names."""

    def link(match):
        target = match["target"].strip()
        short = target.startswith("~")
        target = target.lstrip("~").lstrip(".")
        if "<" in target:  # :class:`title <path>`
            title, target = (part.strip() for part in target[:-1].split("<", 1))
        else:
            title = target.rsplit(".", 1)[-1] if short else target
        path = _resolve(obj, target)
        code = f"<code>{html.escape(title)}</code>"
        return f'<autoref identifier="{path}" optional>{code}</autoref>' if path else code

    return ROLE.sub(link, text)


def _resolve(obj, target):
    """The full path of the object ``target`` names from inside ``obj``, or None."""
    head, _, rest = target.partition(".")
    for scope in (obj, *_parents(obj)):
        try:
            found = scope.resolve(head)
        except (griffe.NameResolutionError, AttributeError, KeyError, ValueError):
            continue
        return _canonical(obj, f"{found}.{rest}" if rest else found)
    return _canonical(obj, target) if target.startswith("drumstroke.") else None


def _canonical(obj, path):
    """Where the object at ``path`` is defined (a re-export like drumstroke.Impacts leads to its module)."""
    try:
        found = obj.modules_collection[path]
        return found.final_target.path if found.is_alias else found.path
    except (KeyError, ValueError, AttributeError, griffe.AliasResolutionError, griffe.CyclicAliasError):
        return path


def _parents(obj):
    while obj.parent is not None:
        obj = obj.parent
        yield obj


def with_examples_heading(text):
    """Put an ``Examples`` heading before the first doctest of a run that is under another heading or none."""
    lines = text.splitlines()
    out, section = [], None
    for i, line in enumerate(lines):
        if i + 1 < len(lines) and HEADING.match(lines[i + 1]) and line.strip():
            section = line.strip().lower()
        if line.startswith(">>>") and section != "examples":
            if out and out[-1].strip():
                out.append("")
            out += ["Examples", "--------"]
            section = "examples"
        out.append(line)
    return "\n".join(out)
