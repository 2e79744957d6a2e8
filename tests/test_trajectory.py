"""The one trajectory type: its samples, its sticks, the stepping seam, and round trips through every format it has.

Oracles: the exact stroke the samples come from (the solver's arcs), numpy's and json's own readers of the
files, and the invariants of the stepping seam (chunks put end to end equal the whole).
"""

import itertools
import json

import numpy as np
import pytest

import drumstroke
from drumstroke.errors import ParameterError, SampledImpactsWarning, TrajectoryError
from drumstroke.formats.ros_json import read_ros_json
from drumstroke.palette.library import build_library, load_library, read_palette
from drumstroke.robot.export import export_csv, export_ros_json
from drumstroke.trajectory import DEFAULT_RATE, Impacts, Stream, Trajectory

RATE = 1000.0


@pytest.fixture(scope="module")
def bounce():
    return drumstroke.simulate("finger-pulses").sample(RATE)


@pytest.fixture(scope="module")
def pair(bounce):
    """Two sticks on one timeline: the finger pulses on the right, the free bounce on the left."""
    left = drumstroke.simulate("free-bounce").sample(RATE)
    return Trajectory.from_sticks({"right": bounce, "left": left}, name="pair")


# --- samples -------------------------------------------------------------------------------------------------------

def test_samples_are_the_exact_curve_at_the_rate(bounce):
    stroke = drumstroke.simulate("finger-pulses")
    t = np.arange(5001) / RATE
    theta, omega = stroke.state(t)
    assert np.array_equal(bounce.t, t) and bounce.rate == RATE == DEFAULT_RATE
    np.testing.assert_allclose(bounce.theta, theta, rtol=0, atol=3e-14)
    np.testing.assert_allclose(bounce.omega, omega, rtol=0, atol=3e-12)
    t_, theta_, omega_ = bounce  # it unpacks as its columns
    assert t_ is bounce.t and theta_ is bounce.theta and omega_ is bounce.omega
    with pytest.raises(ValueError, match="read-only"):
        bounce.theta[0] = 1.0


def test_alpha_is_the_flight_acceleration(bounce):
    """In flight dω/dt = −cos θ · (k g + k′ a(t)) / D, the model's own right-hand side (away from impacts)."""
    recipe = bounce.recipe
    c = recipe.coefficients
    expected = -np.cos(bounce.theta) * c.torque_rate(9.8, recipe.force(bounce.t))
    impact = np.min(np.abs(bounce.t[:, None] - bounce.impacts.t[None, :]), axis=1)
    edge = np.min(np.abs(((bounce.t - 0.08) % 0.4)[:, None] - np.array([0.0, 0.02, 0.4])[None, :]), axis=1)
    flying = (impact > 2e-6) & (edge > 2e-6) & (bounce.theta > bounce.theta_max + 1e-9)
    assert flying.sum() > 4000
    np.testing.assert_allclose(bounce.alpha[flying], expected[flying], rtol=1e-6, atol=1e-6)


def test_chunks_of_an_exact_curve_put_end_to_end_equal_the_whole(bounce):
    cuts = [0, 1, 7, 128, 129, 1000, 2500, 4999, 5001]
    parts = [bounce.samples(a, b) for a, b in itertools.pairwise(cuts)]
    for k, whole in enumerate(bounce.samples()):
        joined = np.concatenate([p[k] for p in parts])
        np.testing.assert_allclose(joined, whole, rtol=0, atol=1e-12)
    assert np.array_equal(np.concatenate([p[0] for p in parts]), bounce.t)
    with pytest.raises(ParameterError, match=r"first and stop must be sample indices with 0 <= first <= stop <= 5001"):
        bounce.samples(10, 5)


def test_another_rate_is_the_same_motion(bounce):
    fast = bounce.sample(10_000.0)
    assert len(fast) == 50_001 and fast.rate == 10_000.0
    np.testing.assert_allclose(fast.theta[::10], bounce.theta, rtol=0, atol=3e-14)
    assert bounce.sample() is bounce


# --- sticks --------------------------------------------------------------------------------------------------------

def test_several_sticks_share_one_timeline(pair, bounce):
    assert pair.sticks == ("right", "left") and pair.theta.shape == (5001, 2)
    assert np.array_equal(pair.stick("right").theta, bounce.theta)
    assert len(pair.columns()) == 5 and np.array_equal(pair.columns()[3], pair.theta[:, 1])
    with pytest.raises(ParameterError, match="impacts needs one stick; this trajectory has the sticks right, left"):
        _ = pair.impacts
    with pytest.raises(ParameterError, match="stick must be one of right, left, got 'middle'"):
        pair.stick("middle")


def test_sticks_on_different_timelines_are_refused(bounce):
    short = drumstroke.simulate("free-bounce", t_end=1.0).sample(RATE)
    with pytest.raises(ParameterError, match=r"one timeline needs the same rate, start and end"):
        Trajectory.from_sticks({"a": bounce, "b": short})


# --- the stepping seam ---------------------------------------------------------------------------------------------

def chunks(trajectory, size):
    return [trajectory.samples(k, min(k + size, len(trajectory))) for k in range(0, len(trajectory), size)]


@pytest.mark.parametrize("size", [1, 5, 64, 2500])
def test_a_stream_extended_chunk_by_chunk_equals_the_same_samples_at_once(bounce, size):
    pieces = chunks(bounce, size)
    t, theta, omega, alpha = (np.concatenate([p[k] for p in pieces]) for k in range(4))
    whole = Trajectory.from_samples(t, theta, omega, alpha=alpha, rate=RATE, theta_max=bounce.theta_max)
    head = pieces[0] if size > 1 else tuple(np.concatenate([pieces[0][k], pieces[1][k]]) for k in range(4))
    stream = Trajectory.from_samples(*head[:3], alpha=head[3], rate=RATE, theta_max=bounce.theta_max)
    rest = pieces[1:] if size > 1 else pieces[2:]
    for piece in rest:
        stream = stream.extend(*piece)
    for a, b in zip(stream.samples(), whole.samples()):
        assert np.array_equal(a, b)
    assert np.array_equal(stream.impacts.t, whole.impacts.t)  # impacts found across the joins too
    assert len(stream.impacts) == len(bounce.impacts)
    np.testing.assert_allclose(stream.impacts.t, bounce.impacts.t, rtol=0, atol=2.1e-6)  # within a sample's travel


def test_an_older_trajectory_keeps_its_samples_when_a_newer_one_grows(bounce):
    base = Trajectory.from_samples(*bounce.samples(0, 100)[:3], rate=RATE)
    first, second = bounce.samples(100, 200)[:3], bounce.samples(100, 150)[:3]
    one = base.extend(*first)
    other = base.extend(*second)  # a branch from the same base
    assert len(base) == 100 and len(one) == 200 and len(other) == 150
    assert np.array_equal(one.theta, np.concatenate((base.theta, first[1])))
    assert np.array_equal(other.theta, np.concatenate((base.theta, second[1])))
    assert np.array_equal(base.theta, bounce.samples(0, 100)[1])


@pytest.mark.parametrize("change, message", [
    (lambda t, th, om: (t + 1e-3, th, om), r"^sample 100: time 0\.101 s comes 0\.002 s after sample 99: a gap of 1"),
    (lambda t, th, om: (t, th + 0.05, om), r"^sample 100: theta of 'stick' jumps by 0\.048\d+ rad from the last sample, more than one period's travel"),
    (lambda t, th, om: (t, np.full_like(th, -1.0), om), r"^sample 100: theta is below the head"),
    (lambda t, th, om: (t, th, np.where(np.arange(len(om)) == 3, np.nan, om)), r"^sample 103: omega is not finite"),
    (lambda t, th, om: (t - 0.05, th, om), r"^sample 100: time 0\.05 s does not come after 0\.099 s"),
])
def test_a_chunk_that_does_not_continue_the_motion_is_refused(bounce, change, message):
    base = Trajectory.from_samples(*bounce.samples(0, 100)[:3], rate=RATE)
    with pytest.raises(TrajectoryError, match=message):
        base.extend(*change(*bounce.samples(100, 110)[:3]))


def test_samples_off_the_grid_or_not_finite_are_named():
    t = np.arange(10) / RATE
    with pytest.raises(TrajectoryError, match=r"^sample 4: time 0\.003 s repeats the time of sample 3"):
        Trajectory.from_samples(np.where(np.arange(10) == 4, t[3], t), np.zeros(10), np.zeros(10))
    with pytest.raises(TrajectoryError, match=r"^sample 2: theta is nan"):
        Trajectory.from_samples(t, np.where(np.arange(10) == 2, np.nan, 0.0), np.zeros(10))


# --- round trips through every format it has -----------------------------------------------------------------------

def test_csv_round_trip_one_stick(bounce, tmp_path):
    path = tmp_path / "pulses.csv"
    meta = bounce.write_csv(path)
    data = np.loadtxt(path, delimiter=",", skiprows=1)  # numpy's own reader, past the header
    assert np.array_equal(data[:, 1], bounce.theta) and np.array_equal(data[:, 2], bounce.omega)
    assert json.loads((tmp_path / "pulses.json").read_text()) == {"csv": meta}  # the JSON beside it
    assert (meta["model"], meta["name"], meta["rate"]) == ("paper", "finger-pulses", RATE)
    back = _read_sampled(path)
    assert back.model == "paper" and back.rate == RATE and back.sticks == ("stick",)
    assert np.array_equal(back.t, bounce.t) and np.array_equal(back.theta, bounce.theta)
    assert len(back.impacts) == len(bounce.impacts)
    np.testing.assert_allclose(back.impacts.t, bounce.impacts.t, rtol=0, atol=2.1e-6)


def test_csv_round_trip_several_sticks_and_alpha(pair, tmp_path):
    path = tmp_path / "pair.csv"
    pair.write_csv(path)
    header = path.read_text().splitlines()[0]
    assert header == "t,theta_right,omega_right,theta_left,omega_left"
    meta = json.loads((tmp_path / "pair.json").read_text())["csv"]
    assert meta["sticks"] == ["right", "left"] and meta["columns"] == header.split(",")
    assert meta["units"]["theta_left"] == "rad" and meta["units"]["omega_right"] == "rad/s"
    back = _read_sampled(path)
    assert back.sticks == ("right", "left") and np.array_equal(back.theta, pair.theta)
    left = _read_sampled(path, stick="left")
    assert np.array_equal(left.omega, pair.stick("left").omega)
    one = pair.stick("right")
    one.write_csv(tmp_path / "alpha.csv", alpha=True)
    names = (tmp_path / "alpha.csv").read_text().splitlines()[0]
    assert names == "t,theta,omega,alpha"
    assert np.array_equal(_read_sampled(tmp_path / "alpha.csv").alpha, one.alpha)


def test_ros_json_round_trip(pair, tmp_path):
    path = tmp_path / "pair.json"
    export_ros_json(path, pair, limits=drumstroke.palette.Limits(max_speed=50.0))
    document = json.loads(path.read_text())  # the standard library's reader
    assert document["joint_names"] == ["right_joint", "left_joint"] and len(document["points"]) == 5001
    back = read_ros_json(path)
    assert np.array_equal(back.positions, pair.theta) and np.array_equal(back.velocities, pair.omega)
    again = Trajectory.from_samples(back.t, back.positions, back.velocities, rate=RATE, sticks=("right", "left"))
    np.testing.assert_allclose(again.t, pair.t, rtol=0, atol=5e-10)  # whole nanoseconds
    assert np.array_equal(again.theta, pair.theta)


def test_export_csv_round_trip(bounce, tmp_path):
    path = tmp_path / "export.csv"
    export_csv(path, bounce)
    back = _read_sampled(path)
    assert back.name == "export" and back.model == "paper"
    assert np.array_equal(back.theta, bounce.theta)
    forward = np.append(np.diff(bounce.omega) * RATE, 0.0)  # the exported alpha is the forward difference
    assert np.array_equal(back.alpha, forward)


def test_library_round_trip(tmp_path):
    entries = [e for e in read_palette() if e.name in ("double", "finger-pulses")]
    built = build_library(tmp_path / "lib", palette=entries)
    loaded = load_library(tmp_path / "lib")
    for name in built:
        a, b = built[name].trajectory, loaded[name].trajectory
        assert b.rate == a.rate == RATE and b.model == a.model
        assert np.array_equal(b.t, a.t) and np.array_equal(b.theta, a.theta) and np.array_equal(b.omega, a.omega)
        assert np.array_equal(b.impacts.t, a.impacts.t) and np.array_equal(b.omega_after, a.omega_after)
        assert b.history == a.history and b.recipe == a.recipe


def test_impacts_given_with_samples_are_kept_exactly(bounce):
    t, theta, omega = bounce
    given = Trajectory.from_samples(t, theta, omega, bounce.impacts, bounce.omega_after, theta_max=bounce.theta_max)
    assert given.impacts is bounce.impacts
    with pytest.raises(ParameterError, match="impacts can be given for one stick only"):
        Trajectory.from_samples(t, np.column_stack((theta, theta)), np.column_stack((omega, omega)),
                                Impacts(np.empty(0), np.empty(0), 0.27))


def test_a_stream_takes_chunks_as_extend_does_and_what_was_read_stays(bounce):
    pieces = chunks(bounce, 7)
    stream = Stream(Trajectory.from_samples(*pieces[0][:3], rate=RATE, theta_max=bounce.theta_max))
    early = None
    for k, piece in enumerate(pieces[1:]):
        stream.extend(*piece[:3])
        if k == 3:
            early = stream.trajectory()
            kept = early.theta.copy()
    received = stream.trajectory()
    whole = Trajectory.from_samples(*(np.concatenate([p[k] for p in pieces]) for k in range(3)), rate=RATE,
                                    theta_max=bounce.theta_max)
    for a, b in zip(received.samples(), whole.samples()):
        assert np.array_equal(a, b)
    assert np.array_equal(received.impacts.t, whole.impacts.t)
    assert len(early) == 5 * 7 and np.array_equal(early.theta, kept)  # the doubling storage never moved under it
    with pytest.raises(ValueError):
        early.stored.theta[0] = 1.0  # read-only
    with pytest.raises(drumstroke.ParameterError, match="trajectory must be a drumstroke.Trajectory"):
        Stream(bounce.samples())
    with pytest.raises(drumstroke.ParameterError, match="impacts must be a drumstroke.Impacts or None"):
        Trajectory.from_samples(*pieces[0], rate=RATE)  # alpha given where the impacts go


def test_a_stream_of_an_exact_curve_starts_from_its_samples(bounce):
    stream = Stream(bounce).extend([bounce.t[-1] + 1.0 / RATE], [bounce.theta[-1]], [0.0])
    received = stream.trajectory()
    assert len(received) == len(bounce) + 1 and np.array_equal(received.theta[:-1], bounce.theta)


def _read_sampled(path, **options):
    """Trajectory.read_csv of a CSV with no JSON recording its impacts: they are found again in the samples, and
    it says so."""
    with pytest.warns(SampledImpactsWarning, match="found again in its samples"):
        return Trajectory.read_csv(path, **options)


def test_sample_times_are_numpys_grid_to_the_bit():
    """The sample times (made in one compiled pass) are start + k/rate as numpy makes them, none past t_end, for
    a stroke's trajectory and for samples that start late read at another rate, whole and in chunks."""
    stroke = drumstroke.simulate("free-bounce", t_end=1.3)
    t = np.linspace(0.25, 0.75, 51)
    late = Trajectory.from_samples(t, 0.2 + 0.1 * np.sin(t), 0.1 * np.cos(t), rate=100.0)
    for trajectory in [stroke.sample(rate) for rate in (1000.0, 977.0, 44100.0, 3.3)] + [
            late.sample(rate) for rate in (977.0, 333.0, 1e4)]:
        k = np.arange(len(trajectory), dtype=float)
        expected = np.minimum(k / trajectory.rate + trajectory.start, trajectory.t_end)
        np.testing.assert_array_equal(trajectory.t, expected)
        middle = len(trajectory) // 3
        np.testing.assert_array_equal(trajectory.samples(middle, len(trajectory))[0], expected[middle:])
