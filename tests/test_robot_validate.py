"""Validation before hardware: each defect is named by sample, quantity, value and limit; the library passes."""

import math

import numpy as np
import pytest

from drumstroke.compose import compose
from drumstroke.errors import ParameterError, TrajectoryError
from drumstroke.formats.sidecar import write_sidecar
from drumstroke.formats.trajectory_csv import columns_text as csv_text
from drumstroke.formats.trajectory_csv import metadata
from drumstroke.model import Stick
from drumstroke.palette.library import DEMO_PATTERN, build_library
from drumstroke.palette.motion import Limits
from drumstroke.render.data import write_composition_csv
from drumstroke.robot.validate import read_limits, validate, validate_file
from drumstroke.score import read_pattern

RATE = 1000.0
HEAD = Stick().theta_max


def quintic(theta0=0.3, theta1=HEAD + 0.05, duration=0.5, rate=RATE):
    """A rest-to-rest quintic move: peak speed 1.875·Δ/T, acceleration 5.77·Δ/T², jerk 60·Δ/T³."""
    t = np.arange(round(duration * rate) + 1) / rate
    s = t / duration
    delta = theta1 - theta0
    theta = theta0 + delta * (10 * s**3 - 15 * s**4 + 6 * s**5)
    omega = delta / duration * (30 * s**2 - 60 * s**3 + 30 * s**4)
    return t, theta, omega


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    return build_library(tmp_path_factory.mktemp("lib"))


@pytest.fixture
def move():
    return quintic()


def test_a_smooth_move_passes_and_its_peaks_are_the_arrays_maxima(move):
    t, theta, omega = move
    checked = validate(t, theta, omega, start=(theta[0], omega[0]))
    assert checked.rate == RATE and checked.head == HEAD
    assert np.array_equal(checked.theta, theta) and np.array_equal(checked.omega, omega)
    assert checked.peak_speed == pytest.approx(1.875 * abs(HEAD + 0.05 - 0.3) / 0.5, rel=1e-12)  # s = 1/2 is a sample
    assert checked.alpha.shape == (500,) and checked.jerk.shape == (499,)
    with pytest.raises(ValueError, match="read-only"):
        checked.theta[0] = 0.0


# --- 1. finite -----------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name, index", [("t", 7), ("theta", 123), ("omega", 400)])
def test_a_nan_is_named_by_array_and_sample(move, name, index):
    arrays = dict(zip(("t", "theta", "omega"), (a.copy() for a in move)))
    arrays[name][index] = np.nan
    with pytest.raises(TrajectoryError, match=rf"^sample {index}: {name} is nan; t, theta and omega must be finite"):
        validate(arrays["t"], arrays["theta"], arrays["omega"])


def test_an_infinity_is_refused(move):
    t, theta, omega = move
    omega = omega.copy()
    omega[33] = -np.inf
    with pytest.raises(TrajectoryError, match="^sample 33: omega is -inf"):
        validate(t, theta, omega)


# --- 2. time -------------------------------------------------------------------------------------------------------

def test_a_repeated_time_is_named(move):
    t, theta, omega = move
    t = t.copy()
    t[200] = t[199]
    with pytest.raises(TrajectoryError, match=r"^sample 200: time 0\.199 s repeats the time of sample 199 "):
        validate(t, theta, omega)


def test_a_time_going_back_is_named(move):
    t, theta, omega = move
    t = t.copy()
    t[50] = 0.0485
    with pytest.raises(TrajectoryError, match=r"^sample 50: time 0\.0485 s goes back in time from sample 49"):
        validate(t, theta, omega)


def test_a_skipped_sample_is_a_gap(move):
    t, theta, omega = (np.delete(a, 300) for a in move)
    with pytest.raises(TrajectoryError, match=r"^sample 300: time 0\.301 s comes 0\.002 s after sample 299: a gap "
                                              r"of 1 missing sample\(s\) at the control period 0\.001 s"):
        validate(t, theta, omega)


def test_three_skipped_samples_are_counted(move):
    t, theta, omega = (np.delete(a, [10, 11, 12]) for a in move)
    with pytest.raises(TrajectoryError, match=r"^sample 10: .* a gap of 3 missing sample\(s\)"):
        validate(t, theta, omega)


def test_a_wrong_rate_is_named(move):
    t, theta, omega = move
    with pytest.raises(TrajectoryError, match=r"^sample 1: time 0\.001 s is off the control period grid by "
                                              r"-0\.001 s: the time step is 0\.001 s \(1000 Hz\), not the control "
                                              r"period 0\.002 s \(rate 500 Hz\)"):
        validate(t, theta, omega, rate=500.0)


def test_a_slightly_wrong_rate_is_found_where_it_drifts_off(move):
    t, theta, omega = move
    with pytest.raises(TrajectoryError, match=r"^sample 1: .* not the control period .* \(rate 1000\.01 Hz\)"):
        validate(t, theta, omega, rate=1000.01)


def test_a_jittered_sample_is_off_the_grid(move):
    t, theta, omega = move
    t = t.copy()
    t[250] += 2e-7
    with pytest.raises(TrajectoryError, match=r"^sample 250: time 0\.2500002 s is off the control period grid: "
                                              r"expected t\[0\] \+ 250/rate = 0\.25 s"):
        validate(t, theta, omega)


def test_time_within_the_tolerance_passes_and_may_start_anywhere(move):
    _, theta, omega = move
    t = 12.5 + np.arange(len(theta)) / RATE + 5e-9  # 1e-9·t is 1.25e-8 s here
    assert validate(t, theta, omega).t[0] == 12.5 + 5e-9


# --- 3. angles -----------------------------------------------------------------------------------------------------

def test_a_sample_below_the_head(move):
    t, theta, omega = move
    theta = theta.copy()
    theta[150] = HEAD - 0.01
    with pytest.raises(TrajectoryError, match=r"^sample 150: theta -0\.272255159 rad is below the head "
                                              r"-0\.262255159 rad"):
        validate(t, theta, omega)


def test_an_explicit_head_is_checked_before_the_joint_range(move):
    t, theta, omega = move
    first_below = int(np.flatnonzero(theta < -0.1)[0])
    with pytest.raises(TrajectoryError, match=rf"^sample {first_below}: theta .* is below the head -0\.1 rad"):
        validate(t, theta, omega, head=-0.1)


def test_a_sample_below_theta_low_when_the_head_is_lower(move):
    t, theta, omega = move
    theta = theta.copy()
    theta[77] = -0.4
    with pytest.raises(TrajectoryError, match=r"^sample 77: theta -0\.4 rad is below theta_low -0\.262255159 rad"):
        validate(t, theta, omega, head=-0.5)


def test_a_sample_above_theta_high(move):
    t, theta, omega = move
    theta = theta.copy()
    theta[321] = 1.6
    with pytest.raises(TrajectoryError, match=r"^sample 321: theta 1\.6 rad exceeds theta_high 1\.57079633 rad"):
        validate(t, theta, omega)


# --- 4. speed, acceleration, jerk ----------------------------------------------------------------------------------

def test_a_sample_over_max_speed(move):
    t, theta, omega = move
    omega = omega.copy()
    omega[250] = -31.0
    with pytest.raises(TrajectoryError, match=r"^sample 250: speed 31 rad/s exceeds max_speed 30 rad/s$"):
        validate(t, theta, omega)


@pytest.mark.parametrize("step, sign", [(0.2, ""), (-0.2, "-")])
def test_a_sample_over_max_acceleration(move, step, sign):
    t, theta, omega = move
    omega = omega.copy()
    omega[260:] += step  # α_259 = (ω[260] − ω[259])·rate ≈ ±200 rad/s²; the move's own peak is 11.5
    limits = Limits(max_acceleration=100.0)
    with pytest.raises(TrajectoryError, match=rf"^sample 259: acceleration {sign}(19\d|20\d)(\.\d+)? rad/s² exceeds "
                                              r"max_acceleration 100 rad/s² in magnitude$"):
        validate(t, theta, omega, limits=limits)
    validate(t, theta, omega, limits=Limits(max_acceleration=250.0, max_jerk=1e6))


def test_a_sample_over_max_jerk(move):
    t, theta, omega = move
    omega = omega.copy()
    omega[300:] += 5.0 * np.arange(len(omega) - 300) / RATE  # α steps up by 5 rad/s² from α_300: j_299 ≈ 5000
    with pytest.raises(TrajectoryError, match=r"^sample 299: jerk (49|50|51)\d\d(\.\d+)? rad/s³ exceeds max_jerk "
                                              r"1000 rad/s³ in magnitude$"):
        validate(t, theta, omega, limits=Limits(max_jerk=1000.0))
    validate(t, theta, omega, limits=Limits(max_jerk=6000.0))


def test_the_checks_run_in_order(move):
    t, theta, omega = (a.copy() for a in move)
    theta[400] = HEAD - 1.0  # angle (check 3) at a later sample than the speed defect (check 4)
    omega[100] = 99.0
    with pytest.raises(TrajectoryError, match="^sample 400: theta"):
        validate(t, theta, omega)
    omega[450] = np.nan
    with pytest.raises(TrajectoryError, match="^sample 450: omega is nan"):
        validate(t, theta, omega)


# --- 5. start ------------------------------------------------------------------------------------------------------

def test_a_start_far_from_the_joints_angle(move):
    t, theta, omega = move
    with pytest.raises(TrajectoryError, match=r"^sample 0: theta 0\.3 rad is 0\.05 rad from the joint's angle "
                                              r"0\.35 rad, beyond start_angle_tolerance 0\.01 rad"):
        validate(t, theta, omega, start=(0.35, 0.0))


def test_a_start_far_from_the_joints_speed(move):
    t, theta, omega = move
    with pytest.raises(TrajectoryError, match=r"^sample 0: omega -?0 rad/s is 1 rad/s from the joint's speed -1 rad/s, "
                                              r"beyond start_speed_tolerance 0\.5 rad/s"):
        validate(t, theta, omega, start=(0.3, -1.0))


def test_a_start_within_the_tolerances_passes(move):
    t, theta, omega = move
    validate(t, theta, omega, start=(0.3 + 0.0099, 0.49))
    validate(t, theta, omega, start=(0.3, 0.0), limits=Limits(start_angle_tolerance=0.0,
                                                                   start_speed_tolerance=0.0))


# --- malformed input -----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("change, message", [
    (lambda t, th, om: (t[:-1], th, om), r"same length >= 2, got 500, 501 and 501"),
    (lambda t, th, om: (t[:1], th[:1], om[:1]), r"same length >= 2, got 1, 1 and 1"),
    (lambda t, th, om: (t, np.column_stack((th, th)), om), r"theta must be a 1-D array"),
    (lambda t, th, om: (t, th, "fast"), r"omega must be a 1-D array of numbers"),
])
def test_malformed_arrays_are_refused(move, change, message):
    with pytest.raises(ParameterError, match=message):
        validate(*change(*move))


@pytest.mark.parametrize("options, message", [
    ({"rate": 0.0}, r"rate must be in \(0, 1e\+06\] Hz"),
    ({"rate": math.nan}, r"rate must be a finite number"),
    ({"head": math.nan}, r"head must be a finite number"),
    ({"limits": {"max_speed": 3}}, r"limits must be a Limits"),
    ({"start": 0.3}, r"start must be the joint's \(angle rad, speed rad/s\)"),
    ({"start": (0.3, math.inf)}, r"start speed must be a finite number"),
])
def test_bad_options_are_refused(move, options, message):
    with pytest.raises(ParameterError, match=message):
        validate(*move, **options)


# --- limits --------------------------------------------------------------------------------------------------------

def test_default_limits():
    limits = Limits()
    assert limits.theta_low == Stick().theta_max and limits.theta_high == math.pi / 2
    assert (limits.max_speed, limits.max_acceleration, limits.max_jerk) == (30.0, 6e4, 6e7)
    assert (limits.start_angle_tolerance, limits.start_speed_tolerance) == (0.01, 0.5)


@pytest.mark.parametrize("options, message", [
    ({"max_speed": -1.0}, r"limits\.max_speed must be in \(0, inf\) rad/s, got -1\.0"),
    ({"max_acceleration": 0}, r"limits\.max_acceleration must be in \(0, inf\) rad/s\^2, got 0\.0"),
    ({"max_jerk": math.nan}, r"limits\.max_jerk must be a finite number in \(0, inf\) rad/s\^3, got nan"),
    ({"max_speed": True}, r"limits\.max_speed must be a number"),
    ({"theta_low": -2.0}, r"limits\.theta_low must be in \[-1\.5708, 1\.5708\) rad, got -2\.0"),
    ({"theta_high": -0.3}, r"limits\.theta_high must be in \(-0\.262255, 1\.5708\] rad, got -0\.3"),
    ({"start_angle_tolerance": -0.01}, r"limits\.start_angle_tolerance must be in \[0, inf\) rad"),
    ({"start_speed_tolerance": math.inf}, r"limits\.start_speed_tolerance must be a finite number"),
])
def test_bad_limits_are_refused(options, message):
    with pytest.raises(ParameterError, match=message):
        Limits(**options)


def test_limits_from_a_table_and_a_file(tmp_path):
    assert Limits.from_dict({"max_speed": 40, "theta_low": -0.3}) == Limits(max_speed=40.0, theta_low=-0.3)
    assert Limits.from_dict(Limits().to_dict()) == Limits()
    path = tmp_path / "joint.toml"
    path.write_text("[limits]\nmax_speed = 12.5\nmax_jerk = 1e8\n")
    assert read_limits(path) == Limits(max_speed=12.5, max_jerk=1e8)


def test_a_limits_table_with_an_unknown_key_is_refused(tmp_path):
    with pytest.raises(ParameterError, match=r"^limits has unknown key 'max_sped'; allowed keys: theta_low, "):
        Limits.from_dict({"max_sped": 3.0})
    path = tmp_path / "joint.toml"
    path.write_text("[limits]\nmax_sped = 3.0\n")
    with pytest.raises(ParameterError, match=r"^limits file '.*joint\.toml': limits has unknown key 'max_sped'"):
        read_limits(path)


@pytest.mark.parametrize("text, message", [
    ("[limits\nmax_speed = 3\n", r"limits file '.*bad\.toml' is not valid TOML"),
    ("max_speed = 3\n", r"limits file '.*bad\.toml' has unknown key 'max_speed'; allowed keys: limits"),
    ("", r"limits file '.*bad\.toml' needs a \[limits\] table"),
    ("limits = 3\n", r"limits file '.*bad\.toml': limits must be a table, got 3"),
    ("[limits]\nmax_speed = -3\n", r"limits file '.*bad\.toml': limits\.max_speed must be in \(0, inf\)"),
    ("[limits]\nmax_speed = \"fast\"\n", r"limits file '.*bad\.toml': limits\.max_speed must be a number"),
])
def test_bad_limits_files_are_refused(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ParameterError, match=message):
        read_limits(path)


def test_a_missing_limits_file_is_refused(tmp_path):
    with pytest.raises(ParameterError, match=r"limits file '.*none\.toml' cannot be read"):
        read_limits(tmp_path / "none.toml")


# --- the shipped library and compositions --------------------------------------------------------------------------

def test_every_library_stroke_passes_the_default_limits(library):
    files = sorted(library.path.glob("strokes-*/*.csv"))
    assert len(files) == len(library) == 20
    for path in files:
        checked = validate_file(path)
        assert checked.rate == RATE
        trajectory = library[path.stem].trajectory
        t, theta, omega = trajectory.sample(RATE)
        validate(t, theta, omega, start=(trajectory.state(0.0)[0], trajectory.state(0.0)[1]))
        assert np.array_equal(checked.theta, theta)


def test_the_defaults_keep_a_twofold_margin_over_the_library(library):
    speed = acceleration = jerk = 0.0
    for stroke in library.values():
        _, _, omega = stroke.trajectory.sample(RATE)
        speed = max(speed, np.abs(omega).max())
        acceleration = max(acceleration, np.abs(np.diff(omega)).max() * RATE)
        jerk = max(jerk, np.abs(np.diff(omega, n=2)).max() * RATE**2)
    limits = Limits()
    assert 2.0 * speed <= limits.max_speed and 2.0 * acceleration <= limits.max_acceleration
    assert 2.0 * jerk <= limits.max_jerk
    assert speed > 12.0 and acceleration > 22_000.0 and jerk > 2.2e7  # the figures the docstring quotes


def test_the_peaks_are_the_maxima_of_the_arrays_away_from_impacts(library):
    for name in ("single", "press-roll", "superhuman-press", "whisper-roll"):
        trajectory = library[name].trajectory.sample(RATE)
        t, theta, omega = trajectory
        checked = validate(trajectory)
        assert checked.lowest_angle == theta.min() and checked.highest_angle == theta.max()
        assert checked.peak_speed == np.max(np.abs(omega))
        impacts = trajectory.impacts.t
        struck = ((t[:-1, None] <= impacts) & (impacts <= t[1:, None])).any(axis=1)  # the steps an impact falls in
        slopes = (omega[1:] - omega[:-1]) / (t[1:] - t[:-1])  # by the times, not the rate
        assert checked.peak_acceleration == pytest.approx(np.max(np.abs(slopes[~struck])), rel=1e-9)
        jerks = np.abs(np.diff(omega, n=2)) * RATE**2
        assert checked.peak_jerk == pytest.approx(np.max(jerks[~(struck[:-1] | struck[1:])]), rel=1e-9)
        assert checked.peaks()["peak_jerk"] == checked.peak_jerk
        assert np.abs(checked.jerk).max() == pytest.approx(jerks.max(), rel=1e-9)
        assert jerks.max() > 10 * checked.peak_jerk  # the strikes', unbounded


def test_a_composition_validates_per_stick(library, tmp_path):
    piece = compose(read_pattern(DEMO_PATTERN), library)
    path = tmp_path / "groove.csv"
    write_composition_csv(piece, path)
    assert sorted(piece.sticks) == ["left", "right"]
    for stick, trajectory in piece.sticks.items():
        checked = validate_file(path, stick=stick)
        assert np.array_equal(checked.theta, trajectory.sample(RATE).theta)
        # the validator saw the fast part: at least the speed of the stick's loudest impact (within a sample)
        assert checked.peak_speed >= 0.95 * np.abs(trajectory.impacts.omega).max() > 5.0
    with pytest.raises(ParameterError, match="has the sticks right, left; name one"):
        validate_file(path)


# --- files ---------------------------------------------------------------------------------------------------------

def _write(path, t, theta, omega, *, rate=None):
    """A trajectory CSV as drumstroke writes it: header first; with a ``rate``, the JSON beside it stating it."""
    path.write_text(csv_text(("t", "theta", "omega"), (t, theta, omega)))
    if rate is not None:
        block = metadata(path, ("t", "theta", "omega"), model="paper", name=path.stem, rate=rate, sticks=("stick",))
        write_sidecar(path.with_suffix(".json"), block)
    return path


def _write_old(path, comment, t, theta, omega):
    """A trajectory CSV as drumstroke 0.1.0 wrote it: a # comment line, then the header and the rows."""
    path.write_text(f"# {comment}\n" + csv_text(("t", "theta", "omega"), (t, theta, omega)))
    return path


def test_a_file_whose_rate_disagrees_with_its_metadata(move, tmp_path):
    path = _write(tmp_path / "move.csv", *move, rate=500.0)
    with pytest.raises(TrajectoryError, match=r"^trajectory file '.*move\.csv': rate 1000 Hz \(its time step is "
                                              r"0\.001 s\) disagrees with the rate 500 Hz of its metadata "
                                              r"'.*move\.json'$"):
        validate_file(path)
    with pytest.raises(TrajectoryError, match=r"rate 250 Hz .* disagrees with the rate 500 Hz of its metadata"):
        validate_file(path, rate=250.0)


def test_an_old_file_whose_rate_disagrees_with_its_comment(move, tmp_path):
    comment = "drumstroke 0.1.0; model=paper; stroke=move; rate=500 Hz; units s, rad, rad/s"
    path = _write_old(tmp_path / "move.csv", comment, *move)
    with pytest.raises(TrajectoryError, match=r"^trajectory file '.*move\.csv': rate 1000 Hz \(its time step is "
                                              r"0\.001 s\) disagrees with the rate 500 Hz of its comment line$"):
        validate_file(path)
    assert validate_file(_write_old(tmp_path / "ok.csv", comment.replace("500", "1000"), *move)).rate == 1000.0


def test_a_file_without_a_rate_takes_its_time_step(move, tmp_path):
    t, theta, omega = move
    for path in (_write(tmp_path / "hand.csv", t * 2, theta, omega),
                 _write_old(tmp_path / "old.csv", "made by hand", t * 2, theta, omega)):
        assert validate_file(path).rate == pytest.approx(500.0, rel=1e-12)
        with pytest.raises(TrajectoryError, match=r"^trajectory file '.*\.csv': sample 1: .*rate 1000 Hz"):
            validate_file(path, rate=1000.0)


def test_a_defect_in_a_file_names_the_file_and_the_sample(move, tmp_path):
    t, theta, omega = (a.copy() for a in move)
    omega[42] = 45.0
    path = _write(tmp_path / "fast.csv", t, theta, omega, rate=RATE)
    with pytest.raises(TrajectoryError, match=r"^trajectory file '.*fast\.csv': sample 42: speed 45 rad/s exceeds "
                                              r"max_speed 30 rad/s$"):
        validate_file(path)
    assert validate_file(path, limits=Limits(max_speed=50.0, max_acceleration=1e5, max_jerk=1e8)).peak_speed == 45
