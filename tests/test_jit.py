"""Compiled kernels (drumstroke._jit): a cached kernel loads without numba's compiler and computes the same.

Each check runs in fresh processes, as a command does: the first compiles a kernel and caches it,
the next loads it from the cache. numba sets up its compiler (its typing and lowering registries:
``numba.np.arraymath`` among them, with scipy.linalg for its BLAS check) before it compiles, and
:func:`~drumstroke._jit.jit` kernels load without it.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
SET_UP = ("numba.np.arraymath", "scipy.linalg")
"""Modules only numba's compiler set-up imports, in these runs."""

KERNELS = '''
import math

import numpy as np

from drumstroke._jit import jit


@jit
def roots(n):
    out = np.empty(n)  # numba's runtime allocates it
    for i in range(n):
        out[i] = math.sqrt(i + 0.5)
    return out


@jit
def text_hash(text):
    return hash(text)  # with the hash secret numba registers for hashing strings
'''

RUN = '''
import json, math, sys
import kernels
print(json.dumps({
    "hash": kernels.text_hash("drumstick"), "python_hash": hash("drumstick"),  # first: before any array's code
    "roots": [x.hex() for x in kernels.roots(50)],
    "oracle": [math.sqrt(i + 0.5).hex() for i in range(50)],
    "set_up": [m for m in sys.argv[1:] if m in sys.modules],
}))
'''


def _run(code, cwd, env):
    """The output of ``code`` run in a fresh interpreter, given SET_UP as its arguments."""
    result = subprocess.run([sys.executable, "-c", code, *SET_UP], cwd=cwd, env=env, capture_output=True, text=True,
                            timeout=300, check=False)
    assert result.returncode == 0, result.stderr
    return result.stdout


def test_a_cached_kernel_loads_without_the_compiler_and_computes_the_same(tmp_path):
    (tmp_path / "kernels.py").write_text(KERNELS)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(SRC)]),
           "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    compiled, loaded = (json.loads(_run(RUN, tmp_path, env)) for _ in range(2))
    assert any((tmp_path / "cache").rglob("*.nbi")), "the first run cached nothing"
    assert compiled["set_up"] == list(SET_UP)  # it compiled
    assert loaded["set_up"] == []  # it loaded, without the set-up
    for run in (compiled, loaded):
        assert run["roots"] == run["oracle"]  # IEEE square roots: correctly rounded, so exact
        assert run["hash"] == run["python_hash"]


def test_simulate_starts_without_numbas_compiler():
    """`drumstroke simulate free-bounce` with its kernel cached loads it and imports nothing of numba's compiler."""
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    code = ("import io, sys, contextlib\nfrom drumstroke.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()) as out:\n"
            "    status = main(['simulate', 'free-bounce'])\n"
            "print(status, out.getvalue().splitlines()[1], [m for m in sys.argv[1:] if m in sys.modules])")
    _run(code, None, env)  # compiles and caches the kernel if no run has yet
    assert _run(code, None, env).strip() == "0 98 impacts; at rest from 3.050763 s []"
