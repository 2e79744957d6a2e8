"""The README stays a front door: its two set-up commands are what CI runs and what the package provides.

Its examples (the quick tour's commands and Python) run in tests/test_docs.py with the docs pages'; here the
tour's commands run once more, word for word as a user types them (through the command's entry point, in this
process), and every file they name is read back.
"""

import csv
import json
import re
import shlex
import shutil
import sys
import tomllib
from pathlib import Path

import matplotlib.image
import mido
import soundfile

from _cli import problem_lines, run
from drumstroke.palette.library import load_library

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def _section(title):
    return README.split(f"## {title}", 1)[1].split("\n## ", 1)[0]


def _setup_commands():
    return re.findall(r"```sh\n(.+?)\n```", _section("Set-up: two commands"))


def test_the_readme_has_exactly_two_setup_commands():
    demo, tests = _setup_commands()
    assert demo.endswith("drumstroke demo out") and "pip install -e '.[all]'" in demo
    assert tests.endswith("python -m pytest") and "pip install -e '.[test]'" in tests


def _listed_pattern(name):
    """A name the README lists (``strokes/NAME.png|.wav|.mid``, ``figN-PRESET.png|.json|.csv``, ``library/``) as a
    regular expression for the paths it stands for."""
    base, *suffixes = name.split("|")
    stem, dot, suffix = base.rpartition(".") if "." in base else (base, "", "")
    alternatives = "|".join(re.escape(s) for s in [dot + suffix, *suffixes]) if dot else ""
    stem = re.escape(stem).replace("NAME", "[a-z0-9-]+").replace("PRESET", "[a-z-]+").replace("N", "[0-9]")
    return f"{stem}({alternatives})"


def test_the_setup_section_lists_exactly_what_the_demo_writes(demo):
    """Each file `drumstroke demo out` writes is one the README's list names, and each name it lists is written."""
    result, out = demo
    assert result.returncode == 0, result.stderr
    listing = _section("Set-up: two commands").split("writes into `out/`:", 1)[1].split("```", 1)[0]
    names = re.findall(r"`([^`]+)`", listing)
    stems = [name for name in names if not re.search(r"[./]", name)]  # the figure cases, named one by one
    patterns = {name: _listed_pattern(name) for name in names if name not in stems}
    written = {path.relative_to(out).as_posix() for path in out.rglob("*") if path.is_file()}
    written = {"library/" if path.startswith("library/") else path for path in written}
    for path in written:
        assert [name for name, pattern in patterns.items() if re.fullmatch(pattern, path)], path
    for name, pattern in patterns.items():
        assert any(re.fullmatch(pattern, path) for path in written), name
    assert sorted({Path(p).stem for p in written if p.startswith("fig")}) == stems
    by_folder = {folder: {Path(p).stem for p in written if p.startswith(f"{folder}/")} for folder in ("strokes",
                                                                                                 "rudiments")}
    assert "library of 20 strokes" in listing and len(by_folder["strokes"]) == 20
    assert "six of the 40 PAS rudiments" in listing and len(by_folder["rudiments"]) == 6
    assert len(written) == 1 + 3 * 20 + 4 * 6 + 6 + 3 * 4 + 1  # index, strokes, rudiments, groove, figures, library


def test_ci_runs_the_readme_test_command_verbatim():
    _, tests = _setup_commands()
    lines = [line for line in (ROOT / ".ci" / "run").read_text().splitlines() if line and not line.startswith("#")]
    assert tests in lines


def test_the_extras_the_commands_install_exist():
    pyproject = (ROOT / "pyproject.toml").read_text()
    for extra in ("all", "test", "docs"):
        assert re.search(rf"^{extra} = \[", pyproject, re.MULTILINE), extra
    test_extra = re.search(r"^test = \[(.*?)^\]", pyproject, re.MULTILINE | re.DOTALL).group(1)
    assert '"drumstroke[all]"' in test_extra and '"drumstroke[docs]"' in test_extra
    assert 'drumstroke = "drumstroke.cli:console"' in pyproject


def _canonical(name):
    return re.sub(r"[-_.]+", "-", name).lower()


def _installed_by(pyproject, extra):
    """The distributions ``pip install '.[extra]'`` asks for: the core's and the extra's, its extras' followed."""
    names, todo = {_canonical(re.split(r"[\s<>=!~;\[]", r)[0]) for r in pyproject["project"]["dependencies"]}, [extra]
    extras = pyproject["project"]["optional-dependencies"]
    while todo:
        for requirement in extras[todo.pop()]:
            name = _canonical(re.split(r"[\s<>=!~;\[]", requirement)[0])
            if name == "drumstroke":
                todo += re.search(r"\[(.*)\]", requirement).group(1).split(",")
            names.add(name)
    return names


def test_the_all_extra_installs_what_the_examples_import():
    """Every module the README's and docs' Python examples import is the standard library's, drumstroke's, or from
    a distribution `pip install '.[all]'` installs (pandas in formats.md, soundfile, rosbags, numpy)."""
    from importlib.metadata import packages_distributions

    from test_docs import PAGES, page_blocks

    installed = _installed_by(tomllib.loads((ROOT / "pyproject.toml").read_text()), "all")
    modules = {module for page in PAGES for language, code in page_blocks(page) if language == "python"
               for module in re.findall(r"^\s*(?:import|from)\s+(\w+)", code, re.MULTILINE)}
    third_party = sorted(modules - set(sys.stdlib_module_names) - {"drumstroke"})
    assert "pandas" in third_party and "numpy" in third_party
    for module in third_party:
        assert {_canonical(d) for d in packages_distributions()[module]} & installed, module


def test_the_quick_tour_has_commands_and_one_python_block():
    tour = _section("A quick tour")
    assert re.findall(r"```sh\n(.+?)\n```", tour, re.DOTALL)
    assert len(re.findall(r"```python\n", tour)) == 1


def test_the_readme_is_a_front_door():
    assert len(README.splitlines()) <= 300
    assert "](docs/fig5-low-high.png)" in README and (ROOT / "docs" / "fig5-low-high.png").is_file()
    assert "mkdocs serve" in README and "mkdocs build --strict" in README


def test_the_readme_links_point_at_files_that_exist():
    links = re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", README)
    local = [link for link in links if "://" not in link]
    assert any(link.startswith("docs/") for link in local)
    for link in local:
        assert (ROOT / link).exists(), link


def _tour_commands():
    (block,) = re.findall(r"```sh\n(.+?)\n```", _section("A quick tour"), re.DOTALL)
    return [shlex.split(line, comments=True) for line in block.splitlines() if line.strip()]


def _check_file(path):
    """``path`` exists and its format's own reader takes it."""
    suffix = path.suffix.lower()
    if path.is_dir():
        assert len(load_library(path)) == 20
    elif suffix == ".png":
        assert matplotlib.image.imread(path).shape[0] > 100
    elif suffix == ".json":
        assert json.loads(path.read_text())["model"] == "paper"
    elif suffix == ".csv":
        with open(path, newline="") as handle:
            rows = list(csv.reader(line for line in handle if not line.startswith("#")))
        assert rows[0][0] == "t" and len(rows) > 100
    elif suffix in (".wav", ".flac", ".ogg"):
        assert soundfile.info(path).format == suffix[1:].upper() and soundfile.info(path).frames > 0
    else:
        assert suffix == ".mid" and mido.MidiFile(path).tracks


OUTPUT_OPTIONS = ("--plot", "--json", "--csv", "--audio", "--wav", "--midi", "--report", "--out")


def test_the_quick_tour_runs_as_written(tmp_path):
    """Every command of the tour, in order, in a folder holding examples/, with no warning and no problem reported."""
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    written = []
    for words in _tour_commands():
        assert words[0] == "drumstroke", words
        result = run(*words[1:], cwd=tmp_path)
        assert result.returncode == 0, (words, result.stderr[-2000:])
        assert not problem_lines(result.stdout + result.stderr), (words, problem_lines(result.stdout + result.stderr))
        outputs = [value for option, value in zip(words, words[1:]) if option in OUTPUT_OPTIONS]
        outputs += [words[3]] if words[1:3] == ["library", "build"] else []
        for name in outputs:
            assert f"wrote {name}" in result.stdout, (name, result.stdout[-2000:])
        written += outputs
    assert {Path(name).suffix for name in written} >= {".png", ".json", ".csv", ".wav", ".mid", ".flac", ".ogg", ""}
    for name in written:
        _check_file(tmp_path / name)
