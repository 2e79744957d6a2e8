"""The house: imports point one way (layers, no cycles), the core stays light, the CLI and README stay small."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("matplotlib", "mido", "soundfile", "mujoco", "dask", "pyarrow", "librosa", "scipy.signal", "mir_eval",
         "rosbags", "starlette", "uvicorn")


def test_the_import_contracts_hold():
    """import-linter reads every import, function-level ones included: layers, no cycles, a light core."""
    lint = Path(sys.executable).with_name("lint-imports")
    result = subprocess.run([str(lint), "--config", str(ROOT / ".importlinter"), "--no-cache"], cwd=ROOT,
                            capture_output=True, text=True, timeout=300, check=False)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout and "3 kept" in result.stdout


def test_the_contracts_name_every_module_of_the_package():
    """A new top-level module must be given a layer (import-linter would otherwise let it import anything)."""
    config = (ROOT / ".importlinter").read_text()
    layers = config.split("layers =", 1)[1].split("\n\n", 1)[0]
    named = {name.strip(" ()") for line in layers.splitlines() for name in line.replace(":", "|").split("|")}
    package = ROOT / "src" / "drumstroke"
    present = {p.stem for p in package.glob("*.py") if p.stem != "__init__"} | {
        p.name for p in package.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert present <= named, sorted(present - named)


@pytest.mark.parametrize("modules", [
    "drumstroke",
    "drumstroke.compose, drumstroke.palette.library, drumstroke.score, drumstroke.sweep",
    "drumstroke.formats.midi, drumstroke.formats.wav, drumstroke.formats.trajectory_csv",
    "drumstroke.formats.rosbag, drumstroke.robot.export, drumstroke.robot.metrics",
    "drumstroke.evaluation.app, drumstroke.evaluation.limits, drumstroke.evaluation.pages",  # the test, not served
])
def test_importing_the_core_loads_no_heavy_dependency(modules):
    code = (f"import sys, {modules}; "
            f"print(','.join(m for m in {HEAVY!r} if m in sys.modules))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "", f"{modules} imported {result.stdout.strip()}"


def test_each_command_module_is_thin():
    """The CLI is one module per command group, each parsing, calling the library and printing: under ~200 lines."""
    modules = sorted((ROOT / "src" / "drumstroke" / "cli").glob("*.py"))
    assert {p.stem for p in modules} >= {"simulate", "library", "compose", "robot", "listen", "stats", "demo"}
    sizes = {p.name: len(p.read_text().splitlines()) for p in modules}
    assert max(sizes.values()) <= 200, sizes


def test_the_readme_is_a_front_door():
    lines = (ROOT / "README.md").read_text().splitlines()
    assert len(lines) <= 300, len(lines)
