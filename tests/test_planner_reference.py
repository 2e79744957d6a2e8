"""The planner made faster plans the same piece: against the outputs of the slower code it replaced.

tests/data/planner_reference.npz holds, for the 1,000-note two-stick piece of benchmarks/design.py (both
models), what the planner and the sampling returned BEFORE their hot paths were made faster: each stick's
stroke releases, every simulated impact (time, ω), every constant force of every design, the notes each
design plays, and the trajectories sampled at 1 kHz (θ every 7th sample, and all of them hashed). It was
written by the older code with ``python tests/test_planner_reference.py --write``.

Impact times and releases must agree to 1e-12 s, forces to 1e-9 m/s² relative, the sampled θ to 1e-10 rad;
the keys played and the problems exactly. The hash says whether the samples are the same to the bit (the
test reports it; the tolerances above are what it holds).
"""

import hashlib
import sys
from pathlib import Path

import numpy as np
import pytest

import drumstroke
from drumstroke.design import Setup, Target, assign_sticks, plan_stick

HERE = Path(__file__).resolve().parent
REFERENCE = HERE / "data" / "planner_reference.npz"
sys.path.insert(0, str(HERE.parent / "benchmarks"))
from design import piece  # the benchmark's own piece: the one its figures are of


def outputs(model):
    """What the planner and the sampling make of the piece: {name: array}."""
    notes = piece()
    times = np.array([n[0] for n in notes])
    beats = np.array([n[1] for n in notes])
    sticks = assign_sticks(times, beats=beats)
    end = times[-1] + 1.0
    out = {}
    for hand in ("right", "left"):
        chosen = [Target.from_velocity(t, v, kind=kind, duration=0.0625 if kind == "buzz" else None, key=k)
                  for k, ((t, _, v, kind), s) in enumerate(zip(notes, sticks)) if s == hand]
        plan = plan_stick(chosen, setup=Setup(model=model))
        theta = plan.trajectory(t_end=end).theta
        name = f"{model} {hand}"
        out[f"{name} release"] = np.array([d.release for d in plan.designs])
        out[f"{name} impacts"] = np.concatenate([d.impacts.t for d in plan.designs])
        out[f"{name} omega"] = np.concatenate([d.impacts.omega for d in plan.designs])
        out[f"{name} forces"] = np.array([p.force for d in plan.designs for p in d.pieces])
        out[f"{name} keys"] = np.array([k for keys in plan.keys for k in keys], dtype=int)
        out[f"{name} strokes"] = np.array([len(keys) for keys in plan.keys], dtype=int)
        out[f"{name} problems"] = np.array([p.key for p in plan.problems], dtype=int)
        out[f"{name} theta"] = theta[::7]
        out[f"{name} theta length"] = np.array([len(theta)])
        out[f"{name} theta sha256"] = np.array([hashlib.sha256(np.ascontiguousarray(theta).tobytes()).hexdigest()])
    return out


@pytest.mark.parametrize("model", drumstroke.MODELS)
def test_the_piece_is_planned_as_before(model):
    reference = np.load(REFERENCE)
    made = outputs(model)
    for name, value in made.items():
        expected = reference[name]
        if name.endswith(("keys", "strokes", "problems", "length")):
            np.testing.assert_array_equal(value, expected, err_msg=name)
        elif name.endswith(("release", "impacts")):
            np.testing.assert_allclose(value, expected, rtol=0, atol=1e-12, err_msg=name)
        elif name.endswith("omega"):
            np.testing.assert_allclose(value, expected, rtol=1e-10, atol=1e-10, err_msg=name)
        elif name.endswith("forces"):
            np.testing.assert_allclose(value, expected, rtol=1e-9, atol=1e-9, err_msg=name)
        elif name.endswith("theta"):
            np.testing.assert_allclose(value, expected, rtol=0, atol=1e-10, err_msg=name)
    same = all(made[n][0] == reference[n][0] for n in made if n.endswith("sha256"))
    print(f"{model}: sampled trajectories {'bitwise equal' if same else 'equal within 1e-10 rad'} to the reference")


if __name__ == "__main__" and "--write" in sys.argv:
    written = {}
    for model in drumstroke.MODELS:
        written.update(outputs(model))
    np.savez_compressed(REFERENCE, **written)
    print(f"wrote {REFERENCE}: {sorted(written)}")
