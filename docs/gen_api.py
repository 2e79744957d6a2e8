"""Write the API reference, one page per public module, by walking src/drumstroke (run by mkdocs-gen-files).

Private modules (``_*.py``) are skipped. The pages follow the source tree as modules move: a module's
page is its docstrings rendered by mkdocstrings; a package's page is its docstring, a table of the names
it re-exports (each linked to the page of the module that defines it) and a table of its modules. The
script also fills the "API reference" entry of the site's navigation with the pages it wrote.
"""

import re
from pathlib import Path

import griffe
import mkdocs_gen_files

ROOT = Path(mkdocs_gen_files.config.config_file_path).resolve().parent
SOURCE = ROOT / "src"
PACKAGE = "drumstroke"
NAV_TITLE = "API reference"
ROLE = re.compile(r":(?:py:)?[a-z]+:`~?\.?(?:[\w.]*\.)?([\w]+)`")


def is_public(obj):
    return not any(part.startswith("_") for part in obj.path.split("."))


def modules(package):
    """The package and its public modules and sub-packages, depth first, in name order."""
    yield package
    for name in sorted(package.members):
        member = package.members[name]
        if not member.is_alias and member.is_module and is_public(member):
            yield from modules(member) if member.is_init_module else [member]


def page_path(module):
    *folders, name = module.path.split(".")
    if module.is_init_module:
        return Path("reference", *folders, name, "index.md")
    return Path("reference", *folders, f"{name}.md")


def summary(obj):
    """The first line of an object's docstring, Sphinx roles as code, ready for a table cell."""
    text = obj.docstring.value.strip().splitlines()[0] if obj.docstring and obj.docstring.value.strip() else ""
    return ROLE.sub(r"`\1`", text).replace("|", "&#124;")


def link(path, title):
    """A cross-reference that is plain code, not an error, when the target has no page (a private module)."""
    return f'<autoref identifier="{path}" optional><code>{title}</code></autoref>'


def package_page(package):
    lines = [f"::: {package.path}", "    options:", "      members: false", ""]
    exported = [m for name, m in package.members.items() if m.is_alias and not name.startswith("_")]
    rows = []
    for alias in exported:
        try:
            rows.append(f"| {link(alias.target_path, alias.name)} | {summary(alias.final_target)} |")
        except (griffe.AliasResolutionError, griffe.CyclicAliasError):
            continue
    if rows:
        lines += ["## Names it exports", "", "| name | what it is |", "|---|---|", *rows, ""]
    children = [m for m in modules(package) if m is not package and m.parent is package]
    if children:
        lines += ["## Modules", "", "| module | what it is |", "|---|---|"]
        for child in children:
            target = page_path(child).relative_to(page_path(package).parent).as_posix()
            lines.append(f"| [`{child.path}`]({target}) | {summary(child)} |")
        lines.append("")
    return "\n".join(lines)


def main():
    package = griffe.load(PACKAGE, search_paths=[str(SOURCE)], resolve_aliases=True, resolve_external=False)
    index = [
        "# API reference",
        "",
        "Generated from the numpy-style docstrings when the site is built: one page per public module,",
        "following the source tree. The names most programs need are exported by `drumstroke` itself",
        "(`drumstroke.simulate`, `drumstroke.Recipe`, ...). Units are SI and radians throughout; options",
        "are keyword-only.",
        "",
        "| module | what it is |",
        "|---|---|",
    ]
    nav = {}
    for module in modules(package):
        path = page_path(module)
        with mkdocs_gen_files.open(path, "w") as out:
            out.write(package_page(module) if module.is_init_module else f"::: {module.path}\n")
        index.append(f"| [`{module.path}`]({path.relative_to('reference').as_posix()}) | {summary(module)} |")
        parts = module.path.split(".")
        group = parts[1] if len(parts) > 2 or (module.is_init_module and len(parts) == 2) else ""
        nav.setdefault(group, []).append({module.path: path.as_posix()})
    with mkdocs_gen_files.open("reference/index.md", "w") as out:
        out.write("\n".join(index) + "\n")
    _fill_nav(nav)


def _fill_nav(groups):
    """Replace the nav's "API reference" entry by a section: the index, the top-level modules, one section a package."""
    entries = [{"Overview": "reference/index.md"}, *groups.pop("", [])]
    for group, pages in groups.items():
        entries.append({f"{PACKAGE}.{group}": pages})

    def replace(items):
        for i, item in enumerate(items or []):
            if isinstance(item, dict):
                for key, value in item.items():
                    if key == NAV_TITLE:
                        items[i] = {key: entries}
                        return True
                    if isinstance(value, list) and replace(value):
                        return True
        return False

    replace(mkdocs_gen_files.config.nav)


main()
