"""The ``drumstroke`` console script (and ``python -m drumstroke``): the command in a process of its own."""

import sys

from . import main as cli_main

COMPILED = {"simulate", "figures", "sweep", "library", "compose", "design", "rudiment", "live", "robot", "fit",
            "compare", "listen", "demo"}
"""The commands that run numba's kernels (simulate, design or track a stroke): :func:`main` sets numba up quickly
for them."""


def main():
    """The ``drumstroke`` console script: :func:`drumstroke.cli.main` in a process of its own, numba set up first.

    When numba loads its first kernel it sets up its CPU target, and with it imports scipy.linalg
    (to see whether a BLAS is there for ``np.dot`` and ``np.linalg``) and cffi's C parser (to type
    cffi functions): 0.15 s of a warm ``drumstroke simulate`` of 0.65 s, for two features no kernel
    of drumstroke uses. In the command's own process, before a command that runs kernels, the
    target is set up with those two modules hidden, then they are importable again (soundfile's
    cffi, scipy's linalg). A program that calls :func:`drumstroke.cli.main` itself keeps numba as numba sets
    it up.
    """
    argv = sys.argv[1:]
    command = next((word for word in argv if not word.startswith("-")), None)
    if command in COMPILED and "--help" not in argv and "-h" not in argv:
        _set_up_numba(("cffi", "scipy.linalg.cython_blas", "scipy.linalg.cython_lapack"))
    return cli_main(argv)


def _set_up_numba(hidden):
    """numba's CPU target set up with the modules ``hidden`` (not yet imported) unimportable meanwhile."""
    hidden = [name for name in hidden if name not in sys.modules]
    sys.modules.update(dict.fromkeys(hidden))  # None: ``import name`` raises ImportError, which numba expects
    try:
        from numba.core.registry import cpu_target

        cpu_target.typing_context.refresh()
        cpu_target.target_context.refresh()
    finally:
        for name in hidden:
            if sys.modules.get(name, "") is None:
                del sys.modules[name]
