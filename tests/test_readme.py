"""The README's two set-up commands stay what CI runs and what the package provides."""

import re
import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _setup_commands():
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Set-up: two commands", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```sh\n(.+?)\n```", section)


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
    assert re.search(r"^all = \[", pyproject, re.M) and re.search(r"^test = \[", pyproject, re.M)
    assert 'drumstroke = "drumstroke.cli:main"' in pyproject


def test_the_python_tour_runs(tmp_path, monkeypatch):
    readme = (ROOT / "README.md").read_text()
    tour = readme.split("## A quick tour", 1)[1].split("\n## ", 1)[0]
    (code,) = re.findall(r"```python\n(.+?)\n```", tour, re.S)
    monkeypatch.chdir(tmp_path)
    namespace = {}
    exec(compile(code, "README.md", "exec"), namespace)
    assert (tmp_path / "softer-head.toml").exists()
    assert len(namespace["batch"].trajectories) == 2 and namespace["stroke"].model == "geometry"


def test_the_palette_python_runs(tmp_path, monkeypatch):
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## The stroke palette", 1)[1].split("\n## ", 1)[0]
    (code,) = re.findall(r"```python\n(.+?)\n```", section, re.S)
    (tmp_path / "examples").mkdir()
    shutil.copy(ROOT / "examples" / "backbeat.pattern", tmp_path / "examples")
    monkeypatch.chdir(tmp_path)
    namespace = {}
    exec(compile(code, "README.md", "exec"), namespace)
    assert (tmp_path / "lib" / "manifest.json").exists() and namespace["piece"].problems == ()
    assert len(namespace["up"].impacts) == 3 and len(namespace["roll"].impacts) == 4
    assert set(namespace["sticks"]) == {"right", "left"}
