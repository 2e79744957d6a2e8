"""Bad input, from the public API, raises ParameterError naming the parameter, the value and the range.

Every validation error is a :class:`drumstroke.ParameterError` (a
ValueError) whose message names the bad parameter, the value it got and what is allowed; never an
``assert`` (``python -O`` strips those), never a bare numpy/csv/TypeError. A valid recipe that asks
for motion the model does not cover raises :class:`drumstroke.SimulationError` instead.
"""

import math
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import drumstroke
from drumstroke import Constant, ParameterError, PiecewiseLinear, Pulses, Recipe, Samples, SimulationError, Stick, Sum
from drumstroke.profiles import profile_from_dict

THETA_MAX = Stick().theta_max
THETA0_RANGE = f"[{THETA_MAX:g}, {math.pi / 2:g}) rad"
LEVEL_RANGE = "[-1e+06, 1e+06] m/s^2"
NOT_NUMBERS = [
    pytest.param(math.nan, "got nan", id="nan"),
    pytest.param(math.inf, "got inf", id="inf"),
    pytest.param(-math.inf, "got -inf", id="-inf"),
    pytest.param("1.0", "got '1.0'", id="string"),
    pytest.param(True, "got True", id="bool"),
    pytest.param(None, "got None", id="none"),
]


def names(*parts):
    """A pattern for a message that contains every one of ``parts`` (literally), in any order."""
    return "(?s)" + "".join(f"(?=.*{re.escape(part)})" for part in parts)


def rejects(*parts):
    """``pytest.raises(ParameterError)`` whose message must contain every one of ``parts``."""
    return pytest.raises(ParameterError, match=names(*parts))


def write(tmp_path, name, content):
    path = tmp_path / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(textwrap.dedent(content))
    return path


def test_parameter_error_is_a_value_error():
    assert issubclass(ParameterError, ValueError)
    assert issubclass(ParameterError, drumstroke.DrumstrokeError)
    assert not issubclass(SimulationError, ValueError)


@pytest.mark.parametrize(("make", "parameter", "value", "allowed"), [
    (lambda: Constant(2e6), "constant.value", 2e6, "[-1e+06, 1e+06] m/s^2"),
    (lambda: Stick(length=-1.0), "stick.length", -1.0, None),
    (lambda: profile_from_dict({"kind": "constant", "value": float("inf")}), "force.value", float("inf"),
     "[-1e+06, 1e+06] m/s^2"),
    (lambda: profile_from_dict({"kind": "sum", "parts": [{"kind": "constant", "value": "x"}]}, name="thumb"),
     "thumb.parts[0].value", "x", "[-1e+06, 1e+06] m/s^2"),
    (lambda: profile_from_dict({"kind": "ramp"}), "force.kind", "ramp", None),
])
def test_an_error_about_one_parameter_carries_it_as_its_message_names_it(make, parameter, value, allowed):
    """parameter, value and allowed are what the message says: it starts with the parameter and says what is allowed."""
    with pytest.raises(ParameterError) as raised:
        make()
    error = raised.value
    assert error.parameter == parameter and str(error).startswith(f"{parameter} must ")
    assert error.value == value
    assert error.allowed in str(error) and (allowed is None or error.allowed == allowed)
    assert str(error.renamed("--x")) == "--x " + error.reason


# -- Recipe fields ------------------------------------------------------------------------

RECIPE_RANGES = {
    "t_end": "[1e-06, 3600] s",
    "theta0": THETA0_RANGE,
    "omega0": "[-1000, 1000] rad/s",
    "cor": "[0, 1]",
}

OUT_OF_RANGE = [
    ("t_end", 0.0),
    ("t_end", -1.0),
    ("t_end", 1e-7),
    ("t_end", 3600.5),
    ("theta0", THETA_MAX - 0.01),
    ("theta0", math.pi / 2),
    ("theta0", 2.0),
    ("omega0", -1000.5),
    ("omega0", 1000.5),
    ("cor", -0.1),
    ("cor", 1.1),
]


def _recipe(**fields):
    return Recipe(force=Constant(0.0), **fields)


def _replace(**fields):
    return drumstroke.preset("free-bounce").replace(**fields)


def _simulate(**fields):
    return drumstroke.simulate(**fields)


ENTRY_POINTS = [
    pytest.param(_recipe, id="Recipe"),
    pytest.param(_replace, id="replace"),
    pytest.param(_simulate, id="simulate"),
]


@pytest.mark.parametrize("make", ENTRY_POINTS)
@pytest.mark.parametrize(("field", "value"), OUT_OF_RANGE)
def test_recipe_field_out_of_range(make, field, value):
    with rejects(field, f"got {value!r}", RECIPE_RANGES[field]):
        make(**{field: value})


@pytest.mark.parametrize("make", ENTRY_POINTS)
@pytest.mark.parametrize(("value", "shown"), [case for case in NOT_NUMBERS if case.id != "none"])
@pytest.mark.parametrize("field", sorted(RECIPE_RANGES))
def test_recipe_field_not_a_finite_number(make, field, value, shown):
    with rejects(field, shown, RECIPE_RANGES[field]):
        make(**{field: value})


@pytest.mark.parametrize("make", [_recipe, _replace], ids=["Recipe", "replace"])  # simulate: None = unchanged
@pytest.mark.parametrize("field", sorted(RECIPE_RANGES))
def test_recipe_field_none(make, field):
    with rejects(field, "got None", RECIPE_RANGES[field]):
        make(**{field: None})


@pytest.mark.parametrize("make", ENTRY_POINTS)
@pytest.mark.parametrize("model", ["newton", "PAPER", ""])
def test_unknown_model(make, model):
    with rejects("model", f"got {model!r}", "'paper', 'geometry'"):
        make(model=model)


@pytest.mark.parametrize("field", ["force", "gravity"])
@pytest.mark.parametrize("value", [9.8, "9.8", None, [(0.0, 1.0)]])
def test_recipe_profile_must_be_a_profile(field, value):
    fields = {"force": Constant(0.0), field: value}
    with rejects(field, f"got {value!r}", "profile"):
        Recipe(**fields)


@pytest.mark.parametrize("value", [{"length": 0.39}, "stick", None])
def test_recipe_stick_must_be_a_stick(value):
    with rejects("stick", f"got {value!r}", "drumstroke.Stick"):
        Recipe(force=Constant(0.0), stick=value)


# -- Stick fields ---------------------------------------------------------------------------

STICK_CASES = [
    ("length", 0.0, "(0, 10] m"),
    ("length", -0.39, "(0, 10] m"),
    ("length", 10.5, "(0, 10] m"),
    ("pivot_to_tip", 0.0, "(0, 0.39] m"),
    ("pivot_to_tip", 0.5, "(0, 0.39] m"),
    ("pivot_to_com", -0.01, "[0, 0.39) m"),
    ("pivot_to_com", 0.39, "[0, 0.39) m"),
    ("pivot_to_thumb", -0.01, "[0, 0.39) m"),
    ("pivot_to_thumb", 0.39, "[0, 0.39) m"),
    ("pivot_height", 0.0, "(0, 10] m"),
    ("pivot_height", -0.07, "(0, 10] m"),
    ("pivot_height", 0.27, "(0, pivot_to_tip = 0.27) m"),
    ("pivot_height", 0.3, "(0, pivot_to_tip = 0.27) m"),
    ("mass", 0.0, "(0, 100] kg"),
    ("mass", -1.0, "(0, 100] kg"),
    ("mass", 100.5, "(0, 100] kg"),
]

STICK_RANGES = {
    "length": "(0, 10] m",
    "pivot_to_tip": "(0, 0.39] m",
    "pivot_to_com": "[0, 0.39) m",
    "pivot_to_thumb": "[0, 0.39) m",
    "pivot_height": "(0, 10] m",
    "mass": "(0, 100] kg",
}


@pytest.mark.parametrize(("field", "value", "allowed"), STICK_CASES)
def test_stick_field_out_of_range(field, value, allowed):
    with rejects(f"stick.{field}", f"got {value!r}", allowed):
        Stick(**{field: value})


@pytest.mark.parametrize(("value", "shown"), NOT_NUMBERS)
@pytest.mark.parametrize("field", sorted(STICK_RANGES))
def test_stick_field_not_a_finite_number(field, value, shown):
    with rejects(f"stick.{field}", shown, STICK_RANGES[field]):
        Stick(**{field: value})


def test_stick_range_follows_the_other_fields():
    # With a longer stick the fulcrum may sit further from the tip.
    with rejects("stick.pivot_to_tip", "got 0.6", "(0, 0.5] m"):
        Stick(length=0.5, pivot_to_tip=0.6)
    with rejects("stick.pivot_height", "got 0.1", "(0, pivot_to_tip = 0.1) m"):
        Stick(pivot_to_tip=0.1, pivot_height=0.1)


# -- profiles ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("value", "shown"),
    [*NOT_NUMBERS, pytest.param(2e6, "got 2000000.0", id="above"), pytest.param(-2e6, "got -2000000.0", id="below")],
)
def test_constant_value(value, shown):
    with rejects("constant.value", shown, LEVEL_RANGE):
        Constant(value)


@pytest.mark.parametrize(
    ("points", "shown", "allowed"),
    [
        ([(1.0, 0.0), (1.0, 2.0)], "point 1 has t = 1.0 s after t = 1.0 s", "t >= 1.000000001"),
        ([(2.0, 0.0), (1.0, 2.0)], "point 1 has t = 1.0 s after t = 2.0 s", "t >= 2.000000001"),
        ([(0.0, 0.0), (1.0, 1.0), (0.5, 2.0)], "point 2 has t = 0.5 s after t = 1.0 s", "t >= 1.000000001"),
        ([(1.0, 0.0), (1.0 + 1e-12, 2.0)], "point 1 has t = 1.000000000001 s", "at least 1e-09 s apart"),
    ],
    ids=["repeated", "decreasing", "decreasing-later", "closer-than-1ns"],
)
def test_piecewise_linear_times_must_increase(points, shown, allowed):
    with rejects("piecewise-linear.points", "strictly increasing", shown, allowed):
        PiecewiseLinear(points)


@pytest.mark.parametrize(
    "points",
    [[], (), [1.0, 2.0], [(0.0, 1.0, 2.0)], [[(0.0, 1.0)]], 5, None],
    ids=["empty-list", "empty-tuple", "flat", "three-columns", "nested", "number", "none"],
)
def test_piecewise_linear_shape(points):
    with rejects("piecewise-linear.points", f"got {points!r}", "non-empty list of [t, value] pairs"):
        PiecewiseLinear(points)


@pytest.mark.parametrize(
    ("points", "shown"),
    [
        ([(0.0, 1.0), (1.0,)], "(1.0,)"),
        ([("a", 1.0)], "'a'"),
        ({0.0: 1.0}, "{0.0: 1.0}"),
        ([(0.0, 1j)], "1j"),
    ],
    ids=["ragged", "word", "dict", "complex"],
)
def test_piecewise_linear_not_numbers(points, shown):
    with rejects("piecewise-linear.points", shown, "number"):
        PiecewiseLinear(points)


@pytest.mark.parametrize(
    "points",
    [[(0.0, True)], [(False, 1.0)], [("0", "10")], [(0.0, "1e3")]],
    ids=["bool-value", "bool-time", "string-pair", "string-value"],
)
def test_piecewise_linear_rejects_strings_and_booleans(points):
    """As everywhere else (check_real), a bool or a string is not a number, even if numpy can convert it."""
    with rejects("piecewise-linear.points", "number"):
        PiecewiseLinear(points)


@pytest.mark.parametrize(
    ("points", "name", "shown", "allowed"),
    [
        ([(-1.0, 0.0)], "piecewise-linear.points[0] time", "got -1.0", "[0, 3600] s"),
        ([(0.0, 0.0), (3600.5, 0.0)], "piecewise-linear.points[1] time", "got 3600.5", "[0, 3600] s"),
        ([(math.nan, 0.0)], "piecewise-linear.points[0] time", "got nan", "[0, 3600] s"),
        ([(0.0, 0.0), (1.0, math.nan)], "piecewise-linear.points[1] value", "got nan", LEVEL_RANGE),
        ([(0.0, math.inf)], "piecewise-linear.points[0] value", "got inf", LEVEL_RANGE),
        ([(0.0, 2e6)], "piecewise-linear.points[0] value", "got 2000000.0", LEVEL_RANGE),
    ],
    ids=["negative-time", "late-time", "nan-time", "nan-value", "inf-value", "big-value"],
)
def test_piecewise_linear_point_out_of_range(points, name, shown, allowed):
    with rejects(name, shown, allowed):
        PiecewiseLinear(points)


PULSES = {"amplitude": 189.0, "period": 0.4, "duty": 0.05}


@pytest.mark.parametrize(
    ("field", "value", "allowed"),
    [
        ("duty", 0.0, "(0, 1)"),
        ("duty", 1.0, "(0, 1)"),
        ("duty", -0.5, "(0, 1)"),
        ("duty", math.nan, "(0, 1)"),
        ("period", 0.0, "[0.001, 3600] s"),
        ("period", -0.4, "[0.001, 3600] s"),
        ("period", 1e-4, "[0.001, 3600] s"),
        ("period", 3600.5, "[0.001, 3600] s"),
        ("period", "0.4", "[0.001, 3600] s"),
        ("phase", -0.1, "[0, 3600] s"),
        ("phase", 3600.5, "[0, 3600] s"),
        ("phase", math.inf, "[0, 3600] s"),
        ("amplitude", math.nan, LEVEL_RANGE),
        ("amplitude", 2e6, LEVEL_RANGE),
        ("amplitude", True, LEVEL_RANGE),
        ("base", -2e6, LEVEL_RANGE),
    ],
)
def test_pulses_field(field, value, allowed):
    shown = f"got {value!r}" if isinstance(value, str) or not math.isnan(value) else "got nan"
    with rejects(f"pulses.{field}", shown, allowed):
        Pulses(**{**PULSES, field: value})


def test_pulses_peak_out_of_range():
    with rejects("pulses.base + pulses.amplitude", "got 1200000.0", LEVEL_RANGE):
        Pulses(amplitude=6e5, period=0.4, duty=0.5, base=6e5)


@pytest.mark.parametrize(
    "parts",
    [[], (), [1.0], [Constant(1.0), "x"], Constant(1.0), None],
    ids=["empty", "empty-tuple", "number", "mixed", "one-profile", "none"],
)
def test_sum_parts(parts):
    with rejects("sum.parts", f"got {parts!r}", "non-empty list of profiles"):
        Sum(parts)


def test_too_many_pulses_before_t_end():
    with rejects("pulses", "pieces before t_end = 3600 s", "at most 200000"):
        drumstroke.simulate(force=Pulses(amplitude=1.0, period=0.001, duty=0.5), t_end=3600.0)


# -- samples files ----------------------------------------------------------------------------

SAMPLES_CASES = [
    ("empty", "", ("has no 't,value' rows",)),
    ("blank", "\n   \n", ("has no 't,value' rows",)),
    ("header-only", "t,value\n", ("has no 't,value' rows",)),
    ("three-columns", "0,1\n1,2,3\n", ("line 2", "'t,value' with two numbers", "got '1,2,3'")),
    ("three-columns-first", "1,2,3\n", ("line 1", "'t,value' with two numbers", "got '1,2,3'")),
    ("one-column", "0,1\n5\n", ("line 2", "'t,value' with two numbers", "got '5'")),
    ("word-after-first", "0,1\nabc,def\n", ("line 2", "'t,value' with two numbers", "got 'abc,def'")),
    ("word-later", "t,value\n0,1\n1,2\n2,x\n", ("line 4", "'t,value' with two numbers", "got '2,x'")),
    ("repeated-time", "0,1\n0.5,2\n0.5,3\n", ("strictly increasing", "t = 0.5 s after t = 0.5 s", "t >= 0.500000001")),
    ("decreasing-time", "0,1\n2,2\n1,3\n", ("strictly increasing", "t = 1.0 s after t = 2.0 s", "t >= 2.000000001")),
    ("nan-value", "0,1\n1,nan\n", ("[1] value", "got nan", LEVEL_RANGE)),
    ("inf-value", "0,inf\n", ("[0] value", "got inf", LEVEL_RANGE)),
    ("big-value", "0,1\n1,2e6\n", ("[1] value", "got 2000000.0", LEVEL_RANGE)),
    ("negative-time", "-1,1\n", ("[0] time", "got -1.0", "[0, 3600] s")),
    ("binary", bytes(range(256)) * 4, ("cannot be read", "not a UTF-8 text file")),
    ("png", b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe", ("cannot be read", "not a UTF-8 text file")),
]


@pytest.mark.parametrize(("label", "content", "parts"), SAMPLES_CASES, ids=[case[0] for case in SAMPLES_CASES])
def test_samples_file(tmp_path, label, content, parts):
    path = write(tmp_path, f"{label}.csv", content)
    with rejects("samples.file", str(path), *parts):
        Samples(path)


def test_samples_file_missing(tmp_path):
    path = tmp_path / "thumb.csv"
    with rejects("samples.file", str(path), "cannot be read", "No such file"):
        Samples(path)


def test_samples_file_is_a_folder(tmp_path):
    with rejects("samples.file", str(tmp_path), "cannot be read"):
        Samples(tmp_path)


def test_samples_file_with_one_huge_field(tmp_path):
    """Garbage without newlines or commas (here 200 kB of text) is bad input, not a csv.Error."""
    path = write(tmp_path, "garbage.csv", "7" * 200_000)
    with rejects("samples.file", str(path), "'t,value'"):
        Samples(path)


# -- recipe TOML files ------------------------------------------------------------------------

FORCE = '[force]\nkind = "constant"\nvalue = 100.0\n'

TOML_CASES = [
    ("syntax", "cor = = 1\n" + FORCE, ("not valid TOML",)),
    ("unclosed-table", "[force\nkind = 'constant'\n", ("not valid TOML",)),
    (
        "unknown-top-key",
        "tempo = 120\n" + FORCE,
        ("recipe has unknown key 'tempo'", "allowed keys: model, t_end, theta0, omega0, cor, stick, force, gravity"),
    ),
    (
        "unknown-stick-key",
        "[stick]\nlenght = 0.39\n" + FORCE,
        (
            "stick has unknown key 'lenght'",
            "allowed keys: length, pivot_to_tip, pivot_to_com, pivot_to_thumb, pivot_height, mass",
        ),
    ),
    (
        "unknown-force-key",
        "[force]\nkind = 'constant'\nvalue = 1.0\namplitude = 3.0\n",
        ("force (constant) has unknown key 'amplitude'", "allowed keys: value"),
    ),
    (
        "unknown-gravity-key",
        FORCE + "[gravity]\nkind = 'pulses'\namplitude = 1.0\nperiod = 1.0\nduty = 0.5\nwidth = 3\n",
        ("gravity (pulses) has unknown key 'width'", "allowed keys: amplitude, period, duty, phase, base"),
    ),
    ("missing-force", "cor = 0.5\n", ("recipe needs a [force] table",)),
    (
        "unknown-kind",
        "[force]\nkind = 'sine'\nvalue = 1.0\n",
        ("force.kind", "got 'sine'", "'constant', 'piecewise-linear', 'pulses', 'samples', 'sum'"),
    ),
    ("missing-kind", "[force]\nvalue = 1.0\n", ("force.kind", "got None", "'constant', 'piecewise-linear'")),
    ("kind-number", "[force]\nkind = 3\n", ("force.kind", "got 3", "'constant', 'piecewise-linear'")),
    (
        "kind-list",
        "[force]\nkind = ['constant']\n",
        ("force.kind", "got ['constant']", "'constant', 'piecewise-linear'"),
    ),
    ("kind-table", "[force]\nkind = {a = 1}\n", ("force.kind", "got {'a': 1}", "'constant', 'piecewise-linear'")),
    ("missing-value", "[force]\nkind = 'constant'\n", ("force (constant) needs the key 'value'",)),
    (
        "missing-duty",
        "[force]\nkind = 'pulses'\namplitude = 189.0\nperiod = 0.4\n",
        ("force (pulses) needs the key 'duty'",),
    ),
    ("missing-points", "[force]\nkind = 'piecewise-linear'\n", ("force (piecewise-linear) needs the key 'points'",)),
    ("force-not-a-table", "force = 3\n", ("force must be a table with a 'kind' key", "got 3")),
    ("stick-not-a-table", "stick = 3\n" + FORCE, ("stick must be a table", "got 3")),
    ("empty-sum", "[force]\nkind = 'sum'\nparts = []\n", ("force.parts", "non-empty list of tables", "got []")),
    (
        "sum-of-words",
        "[force]\nkind = 'sum'\nparts = ['x']\n",
        ("force.parts[0]", "table with a 'kind' key", "got 'x'"),
    ),
    ("samples-file-number", "[force]\nkind = 'samples'\nfile = 5\n", ("force.file", "got 5", "path to a CSV file")),
    ("cor-too-big", "cor = 1.5\n" + FORCE, ("cor", "got 1.5", "[0, 1]")),
    ("cor-nan", "cor = nan\n" + FORCE, ("cor", "got nan", "[0, 1]")),
    ("t_end-string", "t_end = '5'\n" + FORCE, ("t_end", "got '5'", "[1e-06, 3600] s")),
    ("t_end-too-long", "t_end = 7200.0\n" + FORCE, ("t_end", "got 7200.0", "[1e-06, 3600] s")),
    ("theta0-bool", "theta0 = true\n" + FORCE, ("theta0", "got True", THETA0_RANGE)),
    ("omega0-inf", "omega0 = -inf\n" + FORCE, ("omega0", "got -inf", "[-1000, 1000] rad/s")),
    ("model", "model = 'newton'\n" + FORCE, ("model", "got 'newton'", "'paper', 'geometry'")),
    ("stick-length", "[stick]\nlength = 0.0\n" + FORCE, ("stick.length", "got 0.0", "(0, 10] m")),
    (
        "duty",
        "[force]\nkind = 'pulses'\namplitude = 1.0\nperiod = 0.4\nduty = 1.0\n",
        ("force.duty", "got 1.0", "(0, 1)"),
    ),
    (
        "points",
        "[force]\nkind = 'piecewise-linear'\npoints = [[1.0, 0.0], [0.5, 1.0]]\n",
        ("force.points", "t = 0.5 s after t = 1.0 s", "t >= 1.000000001"),
    ),
]


@pytest.mark.parametrize(("label", "text", "parts"), TOML_CASES, ids=[case[0] for case in TOML_CASES])
def test_recipe_file(tmp_path, label, text, parts):
    path = write(tmp_path, f"{label}.toml", text)
    with rejects(*parts):
        Recipe.from_toml(path)
    with rejects(*parts):
        drumstroke.simulate(path)


@pytest.mark.parametrize(
    ("text", "table"),
    [
        (FORCE + "[gravity]\nkind = 'constant'\nvalue = nan\n", "gravity"),
        ("[force]\nkind = 'constant'\nvalue = inf\n", "force"),
        ("[force]\nkind = 'pulses'\namplitude = 1.0\nperiod = 0.0\nduty = 0.5\n", "force"),
    ],
    ids=["gravity-nan", "force-inf", "force-period"],
)
def test_recipe_file_error_names_the_table(tmp_path, text, table):
    """A recipe has two profiles; 'constant.value must be …' does not say which one is wrong."""
    path = write(tmp_path, "stroke.toml", text)
    with rejects(table):
        Recipe.from_toml(path)


def test_recipe_file_missing(tmp_path):
    path = tmp_path / "stroke.toml"
    with rejects("recipe", str(path), "cannot be read", "No such file"):
        Recipe.from_toml(path)
    with rejects("recipe", str(path), "cannot be read"):
        drumstroke.simulate(path)


def test_recipe_file_is_a_folder(tmp_path):
    with rejects("recipe", str(tmp_path), "cannot be read"):
        Recipe.from_toml(tmp_path)


def test_recipe_file_not_text(tmp_path):
    path = write(tmp_path, "stroke.toml", b"\xff\xfe\x00force")
    with rejects("recipe", str(path), "not a UTF-8 text file"):
        Recipe.from_toml(path)


def test_recipe_file_samples_missing(tmp_path):
    path = write(tmp_path, "stroke.toml", "[force]\nkind = 'samples'\nfile = 'thumb.csv'\n")
    with rejects("force.file", str(tmp_path / "thumb.csv"), "cannot be read"):
        Recipe.from_toml(path)


@pytest.mark.parametrize("data", [[], "force", None, 5])
def test_recipe_from_dict_needs_a_table(data):
    with rejects("recipe must be a table", f"got {data!r}"):
        Recipe.from_dict(data)


# -- Stroke.sample and Stroke.state -------------------------------------------------------------


@pytest.fixture(scope="module")
def stroke():
    return drumstroke.simulate("free-bounce")


@pytest.mark.parametrize(
    ("rate", "shown"),
    [
        (0.0, "got 0.0"),
        (0, "got 0.0"),
        (-1000.0, "got -1000.0"),
        (2e6, "got 2000000.0"),
        *[case for case in NOT_NUMBERS if case.id != "none"],
    ],
)
def test_sample_rate(stroke, rate, shown):
    with rejects("rate", shown, "(0, 1e+06] Hz"):
        stroke.sample(rate)


def test_sample_too_many_samples():
    long = drumstroke.simulate(t_end=3600.0)
    # Names the product and the largest rate allowed for this stroke ...
    with rejects("rate", "360000001 samples", "at most 50000000", "at most 13888.9 Hz"):
        long.sample(1e5)
    # ... and the rate that was asked for.
    with pytest.raises(ParameterError, match=r"(100000(\.0)?|1e\+05) ?Hz|rate = (100000|1e\+05)"):
        long.sample(1e5)


@pytest.mark.parametrize(
    ("t", "shown"),
    [
        (-0.1, "got -0.1"),
        (5.1, "got 5.1"),
        (math.nan, "got nan"),
        (math.inf, "got inf"),
        (-math.inf, "got -inf"),
        ([0.0, 1.0, 6.0], "got 6.0"),
        (np.array([[1.0, -2.0]]), "got -2.0"),
    ],
    ids=["negative", "after-end", "nan", "inf", "-inf", "array", "2d-array"],
)
def test_state_time(stroke, t, shown):
    with rejects("t", shown, "[0, 5] s"):
        stroke.state(t)


def test_state_time_not_a_number(stroke):
    with rejects("t", "got 'x'", "[0, 5] s"):
        stroke.state("x")


# -- simulate() and presets --------------------------------------------------------------------


def test_unknown_preset_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # no file of that name may exist
    with rejects("recipe", "got 'no-such-preset'", "free-bounce", "finger-pulses", ".toml"):
        drumstroke.simulate(recipe="no-such-preset")


@pytest.mark.parametrize("recipe", [5, 1.5, ["free-bounce"], {"force": {"kind": "constant", "value": 1.0}}])
def test_recipe_of_the_wrong_type(recipe):
    with rejects("recipe", f"got {recipe!r}", "Recipe", "preset name", "path"):
        drumstroke.simulate(recipe=recipe)


@pytest.mark.parametrize("method", ["rk4", "Taylor", "", None, 4])
def test_unknown_method(method):
    with rejects("method", f"got {method!r}", "'auto', 'taylor'"):
        drumstroke.simulate(method=method)


@pytest.mark.parametrize("field", ["force", "gravity"])
@pytest.mark.parametrize("value", ["abc", "9.8", True, [9.8], {"kind": "constant", "value": 9.8}])
def test_simulate_profile_of_the_wrong_type(field, value):
    with rejects(field, f"got {value!r}", "a profile or a number", "m/s^2"):
        drumstroke.simulate(**{field: value})


@pytest.mark.parametrize("field", ["force", "gravity"])
@pytest.mark.parametrize(
    ("value", "shown"),
    [
        *(case for case in NOT_NUMBERS if case.id in ("nan", "inf", "-inf")),
        pytest.param(2e6, "got 2000000.0", id="big"),
    ],
)
def test_simulate_profile_number_out_of_range(field, value, shown):
    """simulate(gravity=nan) names gravity, not an internal 'constant.value'."""
    with rejects(field, shown, LEVEL_RANGE):
        drumstroke.simulate(**{field: value})


@pytest.mark.parametrize("value", [np.float32(9.8), np.int64(9), np.float64(9.8), 9])
def test_simulate_takes_numpy_numbers_as_profiles(value):
    """Numbers in; a numpy scalar is a number wherever the API takes one."""
    stroke = drumstroke.simulate(gravity=value, t_end=0.5)
    assert stroke.recipe.gravity == Constant(float(value))


def test_simulate_stick_of_the_wrong_type():
    with rejects("stick", "got 0.39", "drumstroke.Stick"):
        drumstroke.simulate(stick=0.39)


@pytest.mark.parametrize("name", ["nope", "", "Free-Bounce"])
def test_unknown_preset(name):
    with rejects("preset", f"got {name!r}", "free-bounce", "finger-pulses"):
        drumstroke.preset(name)


# -- python -O keeps every check ---------------------------------------------------------------

OPTIMIZED = """
import sys
import drumstroke

if __debug__:
    sys.exit("assertions are still on: not running under -O")
cases = {
    "Recipe cor": lambda: drumstroke.Recipe(force=drumstroke.Constant(0.0), cor=1.5),
    "simulate cor": lambda: drumstroke.simulate(cor=-0.1),
    "simulate t_end": lambda: drumstroke.simulate(t_end=float("nan")),
    "Stick": lambda: drumstroke.Stick(pivot_height=0.5),
    "Constant": lambda: drumstroke.Constant(float("inf")),
    "PiecewiseLinear": lambda: drumstroke.PiecewiseLinear([(1.0, 0.0), (0.0, 0.0)]),
    "Pulses": lambda: drumstroke.Pulses(amplitude=1.0, period=0.4, duty=1.0),
    "Sum": lambda: drumstroke.Sum([]),
    "from_dict": lambda: drumstroke.Recipe.from_dict({"force": {"kind": "sine"}}),
    "method": lambda: drumstroke.simulate(method="rk4"),
    "sample": lambda: drumstroke.simulate(t_end=0.01).sample(0.0),
    "state": lambda: drumstroke.simulate(t_end=0.01).state(1.0),
}
for name, case in cases.items():
    try:
        case()
    except drumstroke.ParameterError:
        continue
    except Exception as error:
        sys.exit(f"{name}: {type(error).__name__}: {error}")
    sys.exit(f"{name}: accepted under python -O")
print("all rejected")
"""


def test_checks_survive_python_dash_o():
    result = subprocess.run(
        [sys.executable, "-O", "-c", OPTIMIZED], capture_output=True, text=True, timeout=120, check=False
    )
    assert result.returncode == 0, result.stderr or result.stdout
    assert result.stdout.strip() == "all rejected"


# -- SimulationError: valid recipes the model does not cover -------------------------------------


def test_stick_driven_past_the_vertical():
    with pytest.raises(SimulationError, match="vertical") as error:
        drumstroke.simulate(gravity=Constant(-50.0), theta0=0.0, omega0=0.0)
    assert not isinstance(error.value, ParameterError)
    assert isinstance(error.value, drumstroke.DrumstrokeError)
    assert re.search(r"at t = [0-9.e+-]+ s", str(error.value)), "the message says when"


def test_stick_thrown_past_the_vertical():
    with pytest.raises(SimulationError, match="vertical"):
        drumstroke.simulate(theta0=1.3, omega0=20.0)


def test_more_impacts_than_the_limit():
    """c = 1, a hard press and a drop of 10 nrad: bounces of ~1 µs each, millions before t_end."""
    with pytest.raises(SimulationError, match=names("impacts", str(drumstroke.solver.MAX_IMPACTS))):
        drumstroke.simulate(force=1e6, cor=1.0, theta0=THETA_MAX + 1e-8, t_end=10.0)
