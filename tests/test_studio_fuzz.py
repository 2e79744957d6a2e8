"""Whatever JSON a page (or anyone on this machine) sends an operation, the studio answers it or refuses it in one
line: never a 500, never a hang (hypothesis generates the requests; the real server answers them)."""

import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from _studio import Client
from drumstroke.studio.app import make_studio
from drumstroke.studio.web import OPERATIONS

FIELDS = {  # each operation's fields, as its checks name them
    "simulate": ("recipe", "rate"),
    "presets": (),
    "design": ("times", "levels", "end", "model", "cor", "stick", "force_max"),
    "stroke_audio": ("times", "tip_speeds", "duration"),
    "stroke_file": ("recipe", "format"),
    "palette": (),
    "transform": ("parts", "gap"),
    "save": ("name", "parts", "gap", "category", "description", "replace"),
    "rudiments": (),
    "part_options": (),
    "plan": ("pattern", "midi", "name", "rudiment", "tempo", "bars", "model", "samples", "kit"),
    "audio": ("pattern", "midi", "name", "rudiment", "tempo", "bars", "model", "kit"),
    "download": ("kind", "pattern", "midi", "name", "rudiment", "tempo", "bars", "model", "kit"),
    "robot": ("controller", "pattern", "rudiment", "tempo", "bars", "model", "samples"),
}

NUMBERS = st.one_of(st.integers(-10**6, 10**6), st.floats(allow_nan=False, allow_infinity=False, width=64))
SCALARS = st.one_of(st.none(), st.booleans(), NUMBERS, st.text(max_size=20),
                    st.sampled_from(["paper", "geometry", "catch", "csv", "toml", "pi", "double", "flam", "auto",
                                     "tempo 120\n0 auto 100 right\n", "piecewise-linear", "constant"]))
VALUES = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=6) | st.dictionaries(
    st.sampled_from(["kind", "value", "points", "t_end", "cor", "stroke", "steps", "shipped", "op", "length"]),
    inner, max_size=5), max_leaves=20)


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    server = make_studio(port=0, library=tmp_path_factory.mktemp("library")).start()
    yield Client(server.url)
    server.stop()


def test_every_operation_is_listed():
    assert set(FIELDS) <= set(OPERATIONS)


@pytest.mark.parametrize("operation", sorted(FIELDS))
def test_any_json_object_is_answered_or_refused_in_one_line(client, operation):
    keys = st.sampled_from(FIELDS[operation] + ("unknown",)) if FIELDS[operation] else st.just("unknown")

    @settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
    @given(st.dictionaries(keys, VALUES, max_size=4))
    def check(request):
        reply = client.ask(operation, request)
        assert reply.status in (200, 400, 413), (reply.status, request, reply.body[:300])
        if reply.status != 200:
            error = json.loads(reply.body)["error"]
            assert error and "\n" not in error

    check()


def _force():
    number = st.floats(-5000, 5000, allow_nan=False)
    points = st.lists(st.tuples(st.floats(0, 70, allow_nan=False), number).map(list), min_size=1, max_size=8)
    return st.one_of(
        st.fixed_dictionaries({"kind": st.just("constant"), "value": number}),
        st.fixed_dictionaries({"kind": st.just("piecewise-linear"), "points": points}),
        st.fixed_dictionaries({"kind": st.just("pulses"), "amplitude": number, "period": st.floats(1e-4, 2.0),
                               "duty": st.floats(-0.1, 1.1)}),
    )


RECIPES = st.fixed_dictionaries({"force": _force()}, optional={
    "model": st.sampled_from(["paper", "geometry", "other"]), "t_end": st.floats(-1, 70, allow_nan=False),
    "cor": st.floats(-0.5, 1.5, allow_nan=False), "theta0": st.floats(-1, 2, allow_nan=False),
    "omega0": st.floats(-2000, 2000, allow_nan=False)})


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(RECIPES)
def test_any_recipe_is_simulated_or_refused_in_one_line(client, recipe):
    for operation, request in (("simulate", {"recipe": recipe}), ("stroke_file", {"recipe": recipe, "format": "csv"})):
        reply = client.ask(operation, request)
        assert reply.status in (200, 400), (reply.status, request, reply.body[:300])
        if reply.status == 400:
            assert "\n" not in json.loads(reply.body)["error"]


LINES = st.tuples(st.floats(-1, 40, allow_nan=False), st.sampled_from(["auto", "buzz", "double", "nope"]),
                  st.integers(-5, 200), st.sampled_from(["right", "left", "auto", "", "elbow"])).map(
    lambda row: f"{row[0]:g} {row[1]} {row[2]} {row[3]}".strip())
PATTERNS = st.builds(lambda tempo, lines: f"tempo {tempo:g}\n" + "\n".join(lines) + "\n",
                     st.floats(-10, 500, allow_nan=False), st.lists(LINES, max_size=30))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(PATTERNS, st.sampled_from(["plan", "audio"]))
def test_any_pattern_is_planned_or_refused_in_one_line(client, pattern, operation):
    reply = client.ask(operation, {"pattern": pattern})
    assert reply.status in (200, 400), (reply.status, pattern, reply.body[:300])
    if reply.status == 400:
        assert "\n" not in json.loads(reply.body)["error"]
