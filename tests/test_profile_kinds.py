"""Profile kinds register themselves: a kind defined here, outside the package, works wherever a built-in does.

Kinds defined by a test live in a private copy of the registry (the ``registry`` fixture), so the
built-in list that other tests check ("must be one of 'constant', ...") is the same after them.
"""

import dataclasses
import inspect
import math
import re
import textwrap
import tomllib

import numpy as np
import pytest

import drumstroke
import drumstroke.profiles
from drumstroke import Constant, ParameterError, PiecewiseLinear, Profile, Pulses, Recipe, Samples, Sum
from drumstroke.profiles import KINDS, Parameter, kinds, profile_from_dict

BUILT_IN = (Constant, PiecewiseLinear, Pulses, Samples, Sum)
BUILT_IN_NAMES = "'constant', 'piecewise-linear', 'pulses', 'samples', 'sum'"


@pytest.fixture
def registry(monkeypatch):
    """A copy of the kind registry for one test: kinds it defines are gone after it."""
    monkeypatch.setattr(drumstroke.profiles, "_REGISTRY", dict(drumstroke.profiles._REGISTRY))


def define_triangle():
    """Define (and so register) the kind ``triangle-test``; returns its class."""

    @dataclasses.dataclass(frozen=True)
    class Triangle(Profile):
        """A triangle wave: from ``base`` up to ``base + amplitude`` over half a ``period`` and back down.

        Parameters
        ----------
        amplitude : float
            Peak above ``base`` (m/s²).
        period : float in (0, 3600]
            s; the wave starts at ``base`` at t = 0.
        base : float
            Value at the wave's troughs (m/s²).
        """

        amplitude: float
        period: float
        base: float = 0.0
        kind = "triangle-test"
        parameters = (
            Parameter("amplitude", unit="m/s^2", description="peak above base"),
            Parameter("period", unit="s", description="trough to trough, in (0, 3600]"),
            Parameter("base", unit="m/s^2", required=False, description="value at the troughs; 0"),
        )

        def __post_init__(self):
            if not 0.0 < self.period <= 3600.0:
                raise ParameterError(f"triangle-test.period must be in (0, 3600] s, got {self.period!r}",
                                     parameter="triangle-test.period", value=self.period, allowed="(0, 3600] s")

        def __call__(self, t):
            phase = np.mod(np.asarray(t, dtype=float) / self.period, 1.0)
            return self.base + self.amplitude * (1.0 - np.abs(2.0 * phase - 1.0))

        def _breaks(self, t_end):
            half = self.period / 2.0
            return np.arange(math.floor(t_end / half) + 1) * half

        def _start_and_slope(self, left, tol):
            rising = np.floor((left + tol) / (self.period / 2.0)) % 2 == 0
            return self(left), np.where(rising, 1.0, -1.0) * 2.0 * self.amplitude / self.period

    return Triangle


@pytest.fixture
def triangle(registry):
    """The class of the kind ``triangle-test``, registered for one test."""
    return define_triangle()


TRIANGLE = {"kind": "triangle-test", "amplitude": 200.0, "period": 0.5}


def corners(amplitude, period, t_end):
    """The triangle wave of ``define_triangle`` as piecewise-linear points up to t_end (s)."""
    half = period / 2.0
    return [(k * half, amplitude * (k % 2)) for k in range(math.floor(t_end / half) + 1)]


# -- a kind defined outside the package ------------------------------------------------------


def test_a_new_kind_builds_from_a_recipe_table(triangle):
    recipe = Recipe.from_dict({"t_end": 2.0, "force": TRIANGLE})
    assert recipe.force == triangle(amplitude=200.0, period=0.5)
    assert "triangle-test" in kinds() and kinds()[: len(KINDS)] == KINDS


def test_a_new_kind_reads_from_a_recipe_file_also_inside_a_sum(triangle, tmp_path):
    path = tmp_path / "triangle.toml"
    path.write_text(
        textwrap.dedent("""\
            t_end = 2.0
            [force]
            kind = "triangle-test"
            amplitude = 200.0
            period = 0.5
            [gravity]
            kind = "sum"
            parts = [{ kind = "constant", value = 9.8 }, { kind = "triangle-test", amplitude = 1.0, period = 0.25 }]
        """)
    )
    recipe = Recipe.from_toml(path)
    assert recipe.force == triangle(amplitude=200.0, period=0.5)
    assert recipe.gravity == Sum([Constant(9.8), triangle(amplitude=1.0, period=0.25)])


def test_a_new_kind_simulates_exactly_like_its_piecewise_linear_equivalent(triangle):
    t_end = 2.0
    wave = triangle(amplitude=200.0, period=0.5)
    equivalent = PiecewiseLinear(corners(200.0, 0.5, t_end))
    t = np.random.default_rng(3).uniform(0.0, t_end, 200)
    assert np.allclose(wave(t), equivalent(t), rtol=0.0, atol=1e-9)

    mine, reference = wave.pieces(t_end), equivalent.pieces(t_end)
    assert np.array_equal(mine.edges, reference.edges)
    assert np.allclose(mine.values, reference.values, rtol=0.0, atol=1e-9)
    assert np.allclose(mine.slopes, reference.slopes, rtol=0.0, atol=1e-9)

    stroke = drumstroke.simulate(Recipe.from_dict({"t_end": t_end, "force": TRIANGLE}))
    expected = drumstroke.simulate(force=equivalent, t_end=t_end)
    assert len(stroke.impacts) >= 3 and len(stroke.impacts) == len(expected.impacts)
    assert np.allclose(stroke.impacts.t, expected.impacts.t, rtol=0.0, atol=1e-12)


def test_a_new_kind_round_trips_through_its_table_and_a_recipe_file(triangle, tmp_path):
    wave = triangle(amplitude=150.0, period=0.3, base=5.0)
    assert wave.to_dict() == {"kind": "triangle-test", "amplitude": 150.0, "period": 0.3, "base": 5.0}
    assert profile_from_dict(wave.to_dict()) == wave

    recipe = Recipe(force=wave, gravity=Sum([Constant(9.8), wave]), t_end=1.0, name="r")
    recipe.to_toml(tmp_path / "r.toml")
    assert tomllib.loads((tmp_path / "r.toml").read_text()) == recipe.to_dict()
    assert Recipe.from_toml(tmp_path / "r.toml") == recipe


@pytest.mark.parametrize(
    ("name", "table", "message"),
    [
        (
            "force",
            {**TRIANGLE, "width": 2.0},
            "force (triangle-test) has unknown key 'width'; allowed keys: amplitude, period, base",
        ),
        ("force", {"kind": "triangle-test", "amplitude": 1.0}, "force (triangle-test) needs the key 'period'"),
        ("gravity", {**TRIANGLE, "period": 0.0}, "gravity.period must be in (0, 3600] s, got 0.0"),
        (
            "force",
            {"kind": "sum", "parts": [{"kind": "constant", "value": 1.0}, {"kind": "triangle-test", "period": 1.0}]},
            "force.parts[1] (triangle-test) needs the key 'amplitude'",
        ),
        ("force", {"kind": "sine"}, f"force.kind must be one of {BUILT_IN_NAMES}, 'triangle-test', got 'sine'"),
    ],
    ids=["unknown-key", "missing-key", "out-of-range", "missing-key-in-a-sum", "unknown-kind"],
)
def test_a_new_kind_gets_the_standard_messages(triangle, name, table, message):
    with pytest.raises(ParameterError, match=f"^{re.escape(message)}$"):
        profile_from_dict(table, name=name)


def test_a_kind_registered_in_a_test_is_gone_after_it():
    """Runs after the tests above (pytest keeps file order), whose kind must not leak into later tests."""
    assert kinds() == KINDS == ("constant", "piecewise-linear", "pulses", "samples", "sum")
    with pytest.raises(ParameterError, match=f"^{re.escape(f'force.kind must be one of {BUILT_IN_NAMES}, got')}"):
        profile_from_dict(TRIANGLE)


# -- registering -----------------------------------------------------------------------------


def test_a_second_class_cannot_take_a_registered_kind(registry):
    with pytest.raises(ParameterError, match=r"^profile kind 'pulses' is already registered by drumstroke\.profiles"
                                             r"\.Pulses; give .*\.Impostor another kind$"):

        class Impostor(Profile):
            kind = "pulses"

    assert kinds() == KINDS
    assert type(profile_from_dict({"kind": "pulses", "amplitude": 1.0, "period": 1.0, "duty": 0.5})) is Pulses


def test_defining_the_same_class_again_replaces_it(registry):
    """As re-running a notebook cell does: the newer class is the kind."""
    first, second = define_triangle(), define_triangle()
    assert first is not second and kinds().count("triangle-test") == 1
    assert type(profile_from_dict(TRIANGLE)) is second


def test_a_subclass_without_its_own_kind_is_not_registered(registry):
    class Louder(Constant):
        pass

    assert kinds() == KINDS and type(profile_from_dict({"kind": "constant", "value": 1.0})) is Constant


@pytest.mark.parametrize(
    ("attributes", "message"),
    [
        ({"kind": 3}, r"Bad\.kind must be a string, got 3"),
        ({"kind": "bad", "parameters": ["x"]}, r"Bad\.parameters must be a tuple of Parameter, got \['x'\]"),
        ({"kind": "bad", "parameters": ("x",)}, r"Bad\.parameters must be a tuple of Parameter"),
        ({"kind": "bad", "parameters": (Parameter("x"), Parameter("x"))}, r"distinct names other than 'kind'"),
        ({"kind": "bad", "parameters": (Parameter("kind"),)}, r"distinct names other than 'kind', got \['kind'\]"),
    ],
    ids=["kind-number", "parameters-list", "parameters-names", "repeated-name", "named-kind"],
)
def test_a_bad_declaration_is_refused_when_the_class_is_defined(registry, attributes, message):
    with pytest.raises(ParameterError, match=message):
        type("Bad", (Profile,), attributes)
    assert kinds() == KINDS


def test_the_documented_example_kind_works(registry):
    """The module docstring's Ramp and recipe table, run as written."""
    code, table = literal_blocks(drumstroke.profiles.__doc__)[:2]
    namespace = {"__name__": __name__}
    exec(code, namespace)  # noqa: S102 -- our own documentation
    ramp = namespace["Ramp"]
    recipe = Recipe.from_dict({"t_end": 3.0, **tomllib.loads(table)})
    assert recipe.force == ramp(start=10.0, end=220.0, duration=1.5) and recipe.force(0.75) == 115.0

    expected = drumstroke.simulate(force=PiecewiseLinear([(0.0, 10.0), (1.5, 220.0)]), t_end=3.0)
    stroke = drumstroke.simulate(recipe)
    assert len(stroke.impacts) >= 3 and len(stroke.impacts) == len(expected.impacts)
    assert np.allclose(stroke.impacts.t, expected.impacts.t, rtol=0.0, atol=1e-12)
    with pytest.raises(ParameterError, match=r"^force\.duration must be > 0 s, got 0\.0$"):
        profile_from_dict({"kind": "ramp", "start": 0.0, "end": 1.0, "duration": 0.0})


def literal_blocks(doc):
    """The indented ``::`` blocks of a docstring, dedented, in order."""
    blocks = []
    for chunk in doc.split("::\n")[1:]:
        lines = chunk.splitlines()
        end = next((i for i, line in enumerate(lines) if line and not line[0].isspace()), len(lines))
        blocks.append(textwrap.dedent("\n".join(lines[:end])))
    return blocks


# -- the built-in kinds declare what they read -----------------------------------------------


def test_the_built_in_kinds_are_registered_in_the_documented_order():
    assert tuple(cls.kind for cls in BUILT_IN) == KINDS == kinds()
    assert ", ".join(map(repr, KINDS)) == BUILT_IN_NAMES


@pytest.mark.parametrize("cls", BUILT_IN, ids=[cls.kind for cls in BUILT_IN])
def test_declared_parameters_are_the_constructors_arguments(cls):
    arguments = list(inspect.signature(cls).parameters.values())
    assert [p.name for p in cls.parameters] == [a.name for a in arguments]
    assert [p.required for p in cls.parameters] == [a.default is inspect.Parameter.empty for a in arguments]
    assert all(isinstance(p.unit, str) and p.description for p in cls.parameters)


@pytest.mark.parametrize("cls", BUILT_IN, ids=[cls.kind for cls in BUILT_IN])
def test_from_table_accepts_exactly_the_declared_parameters(cls):
    names = [p.name for p in cls.parameters]
    unknown = f"force ({cls.kind}) has unknown key 'zzz'; allowed keys: {', '.join(names)}"
    with pytest.raises(ParameterError, match=f"^{re.escape(unknown)}$"):
        cls.from_table({"zzz": 1.0}, name="force", base_dir=None)
    for missing in (p.name for p in cls.parameters if p.required):
        table = {p.name: None for p in cls.parameters if p.required and p.name != missing}
        with pytest.raises(ParameterError, match=f"^{re.escape(f'force ({cls.kind}) needs the key {missing!r}')}$"):
            cls.from_table(table, name="force", base_dir=None)


def test_a_table_with_every_declared_parameter_builds_each_built_in_kind(tmp_path):
    (tmp_path / "thumb.csv").write_text("0,1\n1,3\n")
    tables = {
        "constant": {"value": 9.8},
        "piecewise-linear": {"points": [[0.0, 1.0], [1.0, 3.0]]},
        "pulses": {"amplitude": 189.0, "period": 0.4, "duty": 0.05, "phase": 0.1, "base": 2.0},
        "samples": {"file": "thumb.csv"},
        "sum": {"parts": [{"kind": "constant", "value": 1.0}]},
    }
    for cls in BUILT_IN:
        assert list(tables[cls.kind]) == [p.name for p in cls.parameters]
        profile = profile_from_dict({"kind": cls.kind, **tables[cls.kind]}, base_dir=tmp_path)
        assert type(profile) is cls and list(profile.to_dict()) == ["kind", *tables[cls.kind]]
