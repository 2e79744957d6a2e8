"""Draw the package's layers as an SVG for the architecture page (run by mkdocs-gen-files).

The layers are read from the import-linter contract the tests check (`.importlinter`, the `layers`
contract: top to bottom, `|` or `:` between siblings), so the drawing is the rule the code is held
to. Modules the `forbidden` contract keeps free of heavy dependencies are drawn as the core.
"""

import ast
import configparser
import io
from pathlib import Path

import matplotlib
import mkdocs_gen_files
from matplotlib.figure import Figure
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch

ROOT = Path(mkdocs_gen_files.config.config_file_path).resolve().parent
PACKAGE = ROOT / "src" / "drumstroke"
CORE, EDGE, BASE = "#dbe9f6", "#fde7c8", "#e6e6e6"

SHORT = {
    "cli": "one thin module per command group; the only place that prints",
    "__main__": "python -m drumstroke",
    "demo": "the paper's figures and the demo as library functions",
    "evaluation": "listening-test statistics, web app, stimuli",
    "render": "audio, plots, the demo page, output bundles",
    "robot": "config, plants, controllers, control loop, metrics, tuning, validation, export",
    "compose": "a score -> one Trajectory of all sticks",
    "design": "the inverse: notes -> forces -> strokes; the planner",
    "sweep": "parameter sweeps",
    "score": "notes, note mappings, read_score",
    "palette": "transforms, moves, Limits, the library, the rudiments",
    "stroke": "Stroke, simulate(), simulate_many()",
    "trajectory": "Impacts, Trajectory: the sampled motion every layer passes on",
    "presets": "the named recipes",
    "recipe": "Recipe: everything that defines one stroke",
    "solver": "the compiled hybrid solver",
    "profiles": "a(t), g(t): kinds that register themselves",
    "model": "the stick; the paper and geometry models",
    "formats": "every file format, one module each, both directions, plain data",
    "dynamics": "level <-> MIDI velocity",
    "budget": "resource budgets: what an input asks for",
    "_checks": "input checks",
    "_atomic": "atomic writes",
    "_jit": "compiled kernels, loaded from numba's cache",
    "errors": "the exception root",
    "_version": "the version",
}


def contract():
    """(layers top to bottom as lists of module names, the set of core modules) from .importlinter."""
    config = configparser.ConfigParser()
    config.read(ROOT / ".importlinter", encoding="utf-8")
    layers, core = [], set()
    for section in config.sections():
        kind = config[section].get("type", "")
        if kind == "layers":
            for line in config[section]["layers"].strip().splitlines():
                names = [n.strip() for n in line.replace(":", "|").split("|")]
                names = [n.strip("()") for n in names if n and _exists(n.strip("()"))]
                if names:
                    layers.append(names)
        elif kind == "forbidden":
            core |= {m.split(".")[1] for m in config[section].get("source_modules", "").split() if "." in m}
    if not layers:
        raise SystemExit(f"no layers contract in {ROOT / '.importlinter'}: nothing to draw")
    return layers, core


def _exists(name):
    return (PACKAGE / name).is_dir() or (PACKAGE / f"{name}.py").is_file()


def label(name):
    return f"{name}/" if (PACKAGE / name).is_dir() else f"{name}.py"


def describe(name):
    if name in SHORT:
        return SHORT[name]
    path = PACKAGE / name / "__init__.py" if (PACKAGE / name).is_dir() else PACKAGE / f"{name}.py"
    doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
    return doc.strip().splitlines()[0].rstrip(".") if doc.strip() else ""


def colour(name, core):
    if name in core:
        return CORE
    base = name == "errors" or (name.startswith("_") and not name.startswith("__"))
    return BASE if base else EDGE


WIDTH, ROW, GAP, LEFT = 12.0, 0.6, 0.15, 0.3


def draw(layers, core):
    with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": "drumstroke", "font.family": "DejaVu Sans"}):
        return _draw(layers, core)


def _draw(layers, core):
    height = len(layers) * ROW + 0.8
    fig = Figure(figsize=(WIDTH, height))
    ax = fig.subplots()
    ax.set_xlim(0, WIDTH)
    ax.set_ylim(0, height)
    ax.axis("off")
    for row, names in enumerate(layers):
        y = height - 0.45 - (row + 1) * ROW
        span = (WIDTH - LEFT - 0.8) / len(names)
        for i, name in enumerate(names):
            x = LEFT + i * span
            ax.add_patch(FancyBboxPatch((x, y), span - 0.1, ROW - GAP, boxstyle="round,pad=0,rounding_size=0.06",
                                        facecolor=colour(name, core), edgecolor="#555555", linewidth=0.8))
            cx = x + (span - 0.1) / 2
            ax.text(cx, y + (ROW - GAP) * 0.68, label(name), ha="center", va="center", fontsize=9.5,
                    family="DejaVu Sans Mono", weight="bold")
            ax.text(cx, y + (ROW - GAP) * 0.27, _fit(describe(name), span), ha="center", va="center",
                    fontsize=7.2, color="#333333")
    top, bottom = height - 0.55, 0.4
    ax.add_patch(FancyArrowPatch((WIDTH - 0.4, top), (WIDTH - 0.4, bottom), arrowstyle="-|>", mutation_scale=16,
                                 linewidth=1.4, color="#333333"))
    ax.text(WIDTH - 0.22, (top + bottom) / 2, "imports point down only", rotation=90, ha="center", va="center",
            fontsize=9)
    legend = [(CORE, "core: numpy, scipy, numba only"), (EDGE, "formats and edges: heavy dependencies only here"),
              (BASE, "base")]
    x = LEFT
    for fill, text in legend:
        ax.text(x, height - 0.22, text, fontsize=8.5, va="center",
                bbox={"facecolor": fill, "edgecolor": "#555555", "boxstyle": "round,pad=0.25"})
        x += 0.075 * len(text) + 0.5
    buffer = io.BytesIO()
    fig.savefig(buffer, format="svg", bbox_inches="tight", metadata={"Date": None, "Creator": None})
    return buffer.getvalue()


def _fit(text, span):
    """Shorten a description to what fits in a box ``span`` inches wide."""
    room = int(span * 15)
    return text if len(text) <= room else text[: room - 1].rsplit(" ", 1)[0] + "…"


with mkdocs_gen_files.open("architecture-layers.svg", "wb") as out:
    out.write(draw(*contract()))
