"""The documentation site builds with --strict, and every example in the README and docs/ runs.

Examples run page by page in a fresh folder holding a copy of examples/ (and of tests/data/, real MIDI
files): a page's ```python blocks in order in one namespace, and each `drumstroke ...` line of its ```sh blocks with exit status 0,
no Python warning and no warning or problem in what it prints (tests/_cli.py's `problem_lines`), interleaved in page order (a command may use a file an earlier block wrote). A plain command runs in this process
through `drumstroke.cli.main` (what the console script runs: it saves each one the interpreter's start); a
command with shell syntax (a redirection, a wildcard) and `drumstroke live` (a real-time runtime) run in a shell. The README's set-up
section is left out: CI runs those two commands itself. `drumstroke listen serve` and `drumstroke studio` serve forever, so
each is started in the background, checked to answer HTTP on its port, and stopped. And no file of the repository cites
what its users do not have: the team's internal notes or a path outside the repository.
"""

import argparse
import gc
import os
import re
import shlex
import shutil
import socket
import subprocess
import sys
import sysconfig
import time
import urllib.request
import warnings
from pathlib import Path

import pytest

from _cli import problem_lines

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```[ \t]*$", re.MULTILINE | re.DOTALL)
QUIET = {"NO_MKDOCS_2_WARNING": "1", "DISABLE_MKDOCS_2_WARNING": "true", "MPLBACKEND": "Agg"}


def page_blocks(page):
    """The page's ```python and ```sh blocks in order, as (language, code); the README's set-up section left out."""
    text = page.read_text(encoding="utf-8")
    if page.name == "README.md":
        head, _, rest = text.partition("## Set-up: two commands")
        text = head + ("\n## " + rest.split("\n## ", 1)[1] if "\n## " in rest else "")
    return [(lang, code) for lang, code in FENCE.findall(text) if lang in ("python", "sh")]


def commands(code):
    """The `drumstroke ...` command lines of a shell block (continuation lines joined)."""
    joined = re.sub(r"\\\n\s*", " ", code)
    return [line.strip() for line in joined.splitlines() if line.strip().startswith("drumstroke ")]


def _environment():
    scripts = sysconfig.get_path("scripts")
    return {**os.environ, **QUIET, "PATH": os.pathsep.join([scripts, str(Path(sys.executable).parent),
                                                            os.environ.get("PATH", "")])}


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


SHELL = re.compile(r"[|<>;&$`*?~]")


def _run(command, folder, env, capsys):
    """Run one command of a page: exit status 0, and no warning or problem in what it prints (a Python warning
    raised in this process is one too)."""
    words = shlex.split(command, comments=True)
    if words[1] != "live" and not SHELL.search(command.split("#", 1)[0]):
        from drumstroke.cli import main

        with warnings.catch_warnings(record=True) as raised:
            warnings.simplefilter("always")
            status = main(words[1:])
        out, err = capsys.readouterr()
        assert status == 0, f"{command!r} exited with {status}\n--- stdout\n{out[-3000:]}\n--- stderr\n{err[-3000:]}"
        assert not raised, f"{command!r} raised {[str(w.message) for w in raised]}"
    else:
        result = subprocess.run(command, shell=True, cwd=folder, env={**env, "PYTHONWARNINGS": "always"},
                                capture_output=True, text=True, timeout=300, check=False)
        out, err = result.stdout, result.stderr
        assert result.returncode == 0, (
            f"{command!r} exited with {result.returncode}\n--- stdout\n{out[-3000:]}\n--- stderr\n{err[-3000:]}")
    problems = problem_lines(out + err)
    if words[1] == "live":  # real time: how many notes are planned in time depends on the machine (docs/live.md)
        problems = [line for line in problems if not re.match(r"played \d+ of \d+ notes on the \w+ model;", line)]
    assert not problems, f"{command!r} reported {problems}"


def _exec(code, name, namespace):
    """Run a page's Python block; a warning it raises (an unclosed file's ResourceWarning too) fails it."""
    with warnings.catch_warnings(record=True) as raised:
        warnings.simplefilter("always")
        exec(compile(code, name, "exec"), namespace)  # noqa: S102 - running the docs' examples is the test
        gc.collect()  # an unclosed file warns when it is collected
    assert not raised, f"{name} raised {[f'{w.category.__name__}: {w.message}' for w in raised]}"


def _serve(command, folder, env):
    """Start a serving command, wait until it answers HTTP on its port, and stop it."""
    port = _free_port()
    command = re.sub(r"--port\s+\d+", f"--port {port}", command) if "--port" in command else f"{command} --port {port}"
    server = subprocess.Popen(command, shell=True, cwd=folder, env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        deadline = time.monotonic() + 60.0
        while True:
            assert server.poll() is None, f"{command!r} stopped: {server.communicate()[1][-2000:]}"
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=2.0) as response:
                    assert response.status == 200
                    return
            except OSError:
                assert time.monotonic() < deadline, f"{command!r} did not answer on port {port} within 60 s"
                time.sleep(0.2)
    finally:
        os.killpg(server.pid, 15)
        server.communicate(timeout=30)


@pytest.mark.parametrize("page", PAGES, ids=[p.relative_to(ROOT).as_posix() for p in PAGES])
def test_every_example_on_the_page_runs(page, tmp_path, monkeypatch, capsys):
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    shutil.copytree(ROOT / "tests" / "data", tmp_path / "tests" / "data")  # the real songs the docs play
    monkeypatch.chdir(tmp_path)
    for name, value in QUIET.items():
        monkeypatch.setenv(name, value)
    env = _environment()
    namespace = {"__name__": "__docs__"}
    for number, (language, code) in enumerate(page_blocks(page), start=1):
        if language == "python":
            _exec(code, f"{page.name}, block {number}", namespace)
            continue
        for command in commands(code):
            if command.startswith(("drumstroke listen serve", "drumstroke studio")):
                _serve(command, tmp_path, env)
            else:
                _run(command, tmp_path, env, capsys)


def test_the_song_summary_the_palette_page_quotes_is_what_compose_prints(tmp_path):
    """What the page says compose prints for a real song is what it prints, line for line."""
    from _cli import run

    page = (DOCS / "palette.md").read_text(encoding="utf-8")
    (quoted,) = re.findall(r"the summary is:\n\n```text\n(.*?)```", page, re.DOTALL)
    shutil.copy(ROOT / "tests" / "data" / "midi" / "d6caebd1964d9e4a3c5ea59525230e2a.mid", tmp_path / "song.mid")
    result = run("compose", "song.mid", cwd=tmp_path)
    assert result.returncode == 0 and result.stderr == "", result
    assert result.stdout == quoted


def test_the_backbeat_output_the_palette_page_quotes_is_what_compose_prints(tmp_path):
    """The page's compose of examples/backbeat.pattern prints what it quotes, and nothing on stderr; the pattern it
    quotes for a stroke cut short prints the warning it quotes."""
    from _cli import run
    from drumstroke.palette.library import build_library, read_palette

    page = (DOCS / "palette.md").read_text(encoding="utf-8")
    (quoted,) = re.findall(r"nothing on stderr \(every note is played whole\):\n\n```text\n(.*?)```", page, re.DOTALL)
    (command,) = [line for line in commands(page) if line.startswith("drumstroke compose examples/backbeat")]
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    strokes = {"single", "tap", "double", "triple", "press-roll"}  # the pattern's
    build_library(tmp_path / "lib", palette=[entry for entry in read_palette() if entry.name in strokes])
    result = run(*shlex.split(command)[1:], cwd=tmp_path)
    assert result.returncode == 0 and result.stderr == "", result
    assert result.stdout.splitlines() == quoted.splitlines()

    ((pattern, warning),) = re.findall(r"need \d+ ms\):\n\n```text\n(.*?)```\n\n```text\n(.*?)```", page, re.DOTALL)
    (tmp_path / "cut.pattern").write_text(pattern)
    result = run("compose", "cut.pattern", "--library", "lib", cwd=tmp_path)
    assert result.returncode == 0, result
    assert result.stderr.splitlines() == warning.splitlines()


def test_the_pages_have_examples():
    """The pages that teach by example keep their examples (a broken fence would silently drop them)."""
    for name in ("README.md", "tutorial.md", "model.md", "profiles.md", "palette.md", "robot.md", "listening-test.md"):
        page = ROOT / name if name == "README.md" else DOCS / name
        blocks = page_blocks(page)
        assert any(lang == "sh" and commands(code) for lang, code in blocks), name
        assert any(lang == "python" for lang, _ in blocks), name


def _subcommands(parser, words=()):
    yield " ".join(("drumstroke", *words))
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _subcommands(sub, (*words, name))


def _public_modules():
    package = ROOT / "src" / "drumstroke"
    for path in sorted(package.rglob("*.py")):
        parts = path.relative_to(package.parent).with_suffix("").parts
        if parts[-1] == "__init__" or not any(part.startswith("_") for part in parts):
            yield Path(*parts)


def test_the_site_builds_strictly(tmp_path):
    site = tmp_path / "site"
    result = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-d", str(site)], cwd=ROOT,
                            env={**os.environ, **QUIET}, capture_output=True, text=True, timeout=300, check=False)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-6000:]

    for page in sorted(DOCS.glob("*.md")):
        target = site / "index.html" if page.stem == "index" else site / page.stem / "index.html"
        assert target.is_file(), page.name

    from drumstroke.cli import build_parser

    cli = (site / "cli" / "index.html").read_text(encoding="utf-8")
    for command in _subcommands(build_parser()):
        assert f"<code>{command}</code>" in cli, f"the CLI reference lacks {command!r}"
    assert "usage: drumstroke robot tune" in cli

    for module in _public_modules():
        parts = module.parts[:-1] if module.name == "__init__" else module.parts
        assert (site / "reference" / Path(*parts) / "index.html").is_file(), f"no API page for {'.'.join(parts)}"

    drawing = (site / "architecture-layers.svg").read_text(encoding="utf-8")
    assert drawing.lstrip().startswith("<?xml") and "<svg" in drawing and "compose.py" in drawing
    assert 'src="../architecture-layers.svg"' in (site / "architecture" / "index.html").read_text(encoding="utf-8")


# Built from parts, so that this file does not match itself.
_INTERNAL = re.compile(r"\b(?:" + "SP" + "EC|" + "ST" + r"YLE)\b")  # the team's two notes' names, as words
_OUTSIDE = ("../" + "shared", "/work" + "/shared", "shared" + "/paper")
_SHIPPED = ("docs", "src", "tests", "examples", "benchmarks", "README.md", "mkdocs.yml", "pyproject.toml")


def _shipped_files():
    """The repository's tracked files under _SHIPPED (every file there when git or the checkout is missing)."""
    try:
        listed = subprocess.run(["git", "ls-files", "-z", "--", *_SHIPPED], cwd=ROOT, capture_output=True, check=True,
                                timeout=60).stdout.decode().split("\0")
    except (OSError, subprocess.SubprocessError):
        listed = []
    paths = [ROOT / name for name in listed if name]
    if not paths:  # not a checkout: every file there
        paths = [path for name in _SHIPPED for path in [ROOT / name, *(ROOT / name).rglob("*")]
                 if "__pycache__" not in path.parts]
    return [path for path in paths if path.is_file()]


def test_no_file_cites_what_users_do_not_have():
    """The docs hold every fact they cite: no file names the team's internal notes or a path outside the repository."""
    files = _shipped_files()
    assert len(files) > 100 and ROOT / "docs" / "model.md" in files
    found = []
    for path in files:
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue  # images, audio, binary data
        for number, line in enumerate(text.splitlines(), start=1):
            if _INTERNAL.search(line) or any(needle in line for needle in _OUTSIDE):
                found.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()[:100]}")
    assert not found, "\n".join(found)
