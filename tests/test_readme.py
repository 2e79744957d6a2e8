"""The README stays a front door: its two set-up commands are what CI runs and what the package provides.

Its examples (the quick tour's commands and Python) run in tests/test_docs.py with the docs pages'.
"""

import re
from pathlib import Path

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
    assert 'drumstroke = "drumstroke.cli:main"' in pyproject


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
