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
from pathlib import Path

import matplotlib.image
import mido
import soundfile

from _cli import run
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
    """Every command of the tour, in order, in a folder holding examples/."""
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    written = []
    for words in _tour_commands():
        assert words[0] == "drumstroke", words
        result = run(*words[1:], cwd=tmp_path)
        assert result.returncode == 0, (words, result.stderr[-2000:])
        outputs = [value for option, value in zip(words, words[1:]) if option in OUTPUT_OPTIONS]
        outputs += [words[3]] if words[1:3] == ["library", "build"] else []
        for name in outputs:
            assert f"wrote {name}" in result.stdout, (name, result.stdout[-2000:])
        written += outputs
    assert {Path(name).suffix for name in written} >= {".png", ".json", ".csv", ".wav", ".mid", ".flac", ".ogg", ""}
    for name in written:
        _check_file(tmp_path / name)
