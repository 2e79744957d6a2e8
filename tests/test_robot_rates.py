"""The joint's limits at every control rate: what compose, simulate and live make at 250 Hz to 10 kHz is valid and
exports, the strikes' own accelerations unbounded; a motion that breaks the limits away from impacts is refused."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from _cli import run
from drumstroke.errors import TrajectoryError
from drumstroke.formats.trajectory_csv import read_columns, read_stick
from drumstroke.model import Stick
from drumstroke.palette.motion import Limits
from drumstroke.robot.validate import validate, validate_kit

RATES = [250.0, 1000.0, 2000.0, 10000.0]
HEAD = Stick().theta_max
ROOT = Path(__file__).resolve().parent.parent
RUDIMENTS = ROOT / "examples" / "rudiments.pattern"
KIT_PART = """tempo 120
0 auto 100 auto kick
0 auto 90 auto hihat
0.5 auto 90 auto hihat
1 auto 110 auto
1.5 auto 100 auto tom1
2 auto 120 auto crash
2 auto 127 auto kick
"""


def assert_valid_and_exported(path, tmp_path, *, stick=None):
    """``robot validate`` accepts the CSV and ``robot export`` writes it as a ROS 2 JointTrajectory."""
    choice = ["--stick", stick] if stick else []
    checked = run("robot", "validate", path, *choice)
    assert checked.returncode == 0 and ": valid: " in checked.stdout, checked.stderr
    out = tmp_path / f"{Path(path).stem}{f'-{stick}' if stick else ''}.ros.json"
    exported = run("robot", "export", path, "--format", "ros-json", "--out", out, *choice)
    assert exported.returncode == 0, exported.stderr
    return json.loads(out.read_text())


def strikes_exceed_the_limits(omega, rate):
    """Whether the finite-difference acceleration or jerk passes ``Limits()`` somewhere (at the impacts)."""
    alpha = np.diff(omega) * rate
    return np.abs(alpha).max() > Limits().max_acceleration or np.abs(np.diff(alpha) * rate).max() > Limits().max_jerk


# --- compose, simulate, the kit, live: through the command ---------------------------------------------------------

@pytest.mark.parametrize("rate", RATES)
def test_a_composition_at_any_rate_validates_and_exports(rate, tmp_path):
    path = tmp_path / "rudiments.csv"
    done = run("compose", RUDIMENTS, "--rate", rate, "--csv", path, "--json", tmp_path / "notes.json", "-q")
    assert done.returncode == 0, done.stderr
    _, columns = read_columns(path)
    assert np.diff(columns["t"]) == pytest.approx(1.0 / rate, rel=1e-6)
    for stick in ("right", "left"):
        message = assert_valid_and_exported(path, tmp_path, stick=stick)
        assert len(message["points"]) == len(columns["t"])
    if rate >= 2000.0:  # the strikes pass the limits there: the steps across them are left unbounded
        assert strikes_exceed_the_limits(columns["omega_right"], rate)
    again = tmp_path / "right.csv"  # an export has no impacts beside it: they are found on the head
    assert run("robot", "export", path, "--stick", "right", "--format", "csv", "--out", again).returncode == 0
    assert_valid_and_exported(again, tmp_path)


@pytest.mark.parametrize("rate", RATES)
@pytest.mark.parametrize("name", ["superhuman-press", "press-roll"])
def test_a_library_stroke_at_any_rate_validates_and_exports(name, rate, tmp_path):
    known, found = tmp_path / "known.csv", tmp_path / "found.csv"  # with its impacts beside it, without
    assert run("simulate", name, "--rate", rate, "--csv", known, "--json", tmp_path / "known.json").returncode == 0
    assert run("simulate", name, "--rate", rate, "--csv", found).returncode == 0
    assert len(read_stick(known)[5]) > 10 and read_stick(found)[5] is None
    for path in (known, found):
        assert_valid_and_exported(path, tmp_path)
    if rate == RATES[-1]:
        assert strikes_exceed_the_limits(read_columns(found)[1]["omega"], rate)


@pytest.mark.parametrize("rate", RATES)
def test_a_kit_part_at_any_rate_validates_and_exports(rate, tmp_path):
    (tmp_path / "part.pattern").write_text(KIT_PART)
    path = tmp_path / "kit.csv"
    done = run("compose", tmp_path / "part.pattern", "--kit", "--rate", rate, "--csv", path, "-q")
    assert done.returncode == 0, done.stderr
    message = assert_valid_and_exported(path, tmp_path)
    assert "right.theta" in validate_kit(path) and len(message["joint_names"]) == 8


def live(*args, cwd):
    """``drumstroke live ARGS`` as the live tests run it: a process of its own, on the clock."""
    done = subprocess.run([sys.executable, "-m", "drumstroke", "live", *map(str, args)], check=False,
                          capture_output=True, text=True, timeout=300, cwd=cwd)
    assert done.returncode == 0, done.stderr
    return done


@pytest.mark.parametrize("rate", RATES)
def test_live_plays_at_any_rate_and_its_stream_validates_and_exports(rate, tmp_path):
    (tmp_path / "two.pattern").write_text("tempo 120\n0 auto 110 right\n0.5 auto 90 left\n")
    # a latency of 3 s: planning on a busy machine must not make the notes late (the rates are what is tested)
    done = live("--score", "two.pattern", "--latency", 3000, "--rate", rate, "--csv", "--log", "session.json",
                cwd=tmp_path)
    record = json.loads((tmp_path / "session.json").read_text())
    assert sum(note["planned"] for note in record["notes"]) >= 1, record["problems"]
    assert not any("failed validation" in line for line in record["problems"])
    (tmp_path / "stream.csv").write_text(done.stdout)
    frame = pd.read_csv(tmp_path / "stream.csv")
    assert len(frame) == record["sent"]["count"] and np.diff(frame["t"]) == pytest.approx(1.0 / rate, rel=1e-6)
    for stick in ("right", "left"):
        assert_valid_and_exported(tmp_path / "stream.csv", tmp_path, stick=stick)


@pytest.mark.parametrize("rate", RATES)
def test_live_plays_a_kit_at_any_rate(rate, tmp_path):
    (tmp_path / "part.pattern").write_text(KIT_PART)
    live("--kit", "--score", "part.pattern", "--latency", 3000, "--rate", rate, "--csv", "--log", "session.json",
         cwd=tmp_path)
    record = json.loads((tmp_path / "session.json").read_text())
    assert sum(note["planned"] for note in record["notes"]) >= 1, record["problems"]
    assert not any("failed validation" in line for line in record["problems"])


# --- the rule itself: an exact motion with impacts ------------------------------------------------------------------

PERIOD, HEIGHT, FIRST = 0.1, 0.2, 0.01234  # s, rad, s: a bounce every 0.1 s, off the sample grid


def bouncing(rate, bump=0.0, *, width=0.01):
    """θ = head + HEIGHT·|sin(π(t − FIRST)/PERIOD)| (an impact at FIRST + k·PERIOD reverses ω within a step), plus
    ``bump``·exp(−((t − top)/width)²/2) at the top of the third flight. Returns t, θ, ω and the impact times."""
    t = np.arange(round(0.5 * rate) + 1) / rate
    phase = np.pi * (t - FIRST) / PERIOD
    theta = HEAD + HEIGHT * np.abs(np.sin(phase))
    omega = HEIGHT * np.pi / PERIOD * np.cos(phase) * np.sign(np.sin(phase))
    s = (t - (FIRST + 2.5 * PERIOD)) / width
    theta = theta + bump * np.exp(-s**2 / 2)
    omega = omega - bump * s / width * np.exp(-s**2 / 2)
    return t, theta, omega, FIRST + PERIOD * np.arange(5)


GENTLE = Limits(max_speed=30.0, max_acceleration=1000.0, max_jerk=1e5)


@pytest.mark.parametrize("rate", RATES)
@pytest.mark.parametrize("impacts", ["found", "given"])
def test_impacts_are_unbounded_in_acceleration_and_jerk_at_any_rate(rate, impacts):
    t, theta, omega, times = bouncing(rate)
    alpha = np.diff(omega) * rate
    assert np.abs(alpha).max() > GENTLE.max_acceleration  # the strikes: (1 + 1)·6.28 rad/s·rate
    # exactly: 19.7 rad/s² and 6201 rad/s³ between the impacts (HEIGHT·(π/PERIOD)² and ³)
    head = HEAD if impacts == "found" else HEAD - 1.0  # given: none is found on a head far below
    checked = validate(t, theta, omega, rate=rate, head=head, limits=GENTLE,
                       impacts=times if impacts == "given" else None)
    assert checked.peak_acceleration == pytest.approx(HEIGHT * (np.pi / PERIOD) ** 2, rel=0.02)
    assert checked.peak_jerk < 1.05 * HEIGHT * (np.pi / PERIOD) ** 3


@pytest.mark.parametrize("rate", RATES)
@pytest.mark.parametrize("quantity, limits", [
    ("acceleration", GENTLE), ("jerk", Limits(max_acceleration=1e4, max_jerk=1e5))])
def test_a_motion_over_the_limits_away_from_impacts_is_refused_at_any_rate(rate, quantity, limits):
    # the bump: 3000 rad/s² (0.3/width²) and 4.1e5 rad/s³ (1.38·0.3/width³) at the top of a flight
    t, theta, omega, times = bouncing(rate, bump=0.3)
    validate(*bouncing(rate)[:3], rate=rate, limits=limits, impacts=times)  # without the bump it passes
    with pytest.raises(TrajectoryError, match=rf"^sample (\d+): {quantity} -?[\d.e+]+ rad/s. exceeds") as error:
        validate(t, theta, omega, rate=rate, limits=limits, impacts=times)
    k = int(str(error.value).split()[1].rstrip(":"))
    assert abs(t[k] - (FIRST + 2.5 * PERIOD)) < 0.03  # at the bump, between the impacts
