"""Compiled kernels: numba's ``njit``, cached on disk, the cached machine code loaded without numba's compiler.

numba loads a kernel from its on-disk cache only after setting up all it needs to compile
any code: its typing and lowering registries, some 230 modules imported (70 of numba's; its
check for a BLAS imports scipy.linalg, 75 of scipy's and 40 of numpy's; its cffi support
builds a C parser when cffi is installed). Loading machine code needs none of it, only
numba's runtime (what compiled code calls to allocate arrays), and the set-up was some 40 %
of the time ``drumstroke simulate`` took to start. Each kernel declared with :func:`jit` loads from its
cache without it; numba still sets itself up, as it always does, the moment it compiles
anything (a kernel whose cache is missing or out of date, or any other ``njit`` function).

The machine code run is the one numba compiled and cached, so every result is the same to
the bit. What it calls is there: numba's runtime (started here), its math and C helpers
(with its CPU target), and every module the code was compiled from, which numba imports
when it rebuilds the code's environments on load (numba.cpython.hashing, for one, which
gives compiled code Python's hash secret).
"""

from functools import partial

from numba import njit
from numba.core.caching import FunctionCache
from numba.core.runtime import rtsys


class _Cache(FunctionCache):
    """numba's on-disk cache of one kernel (the same files), loading without the compiler's set-up."""

    def load_overload(self, sig, target_context):
        # numba's own method calls target_context.refresh() here (the registries, for compiling)
        rtsys.initialize(target_context)
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)

    def save_overload(self, sig, data):
        # a cache that cannot be written (a full disk, a file-size limit) leaves the kernel compiled, not the command
        # failed with an error that names no file of the user's
        try:
            super().save_overload(sig, data)
        except OSError:
            pass


def jit(function=None, *, inline="never", parallel=False, error_model="python"):
    """``numba.njit(cache=True)``: ``function`` compiled on its first call (or loaded from the cache on disk).

    Parameters
    ----------
    function : callable, optional
        A function in numba's nopython subset; without it, ``jit(...)`` is the decorator.
    inline : {"never", "always"}
        numba's ``inline``: "always" compiles the function into each kernel that calls it.
    parallel : bool
        numba's ``parallel``: ``prange`` loops run on every core.
    error_model : {"python", "numpy"}
        numba's ``error_model``: "numpy" divides by zero as numpy does (inf, nan) instead of raising, so that a
        loop of divisions needs no check per division and may run in vector instructions (the same results).

    Returns
    -------
    numba's dispatcher of ``function``, with a cache that loads without the compiler.
    """
    if function is None:
        return partial(jit, inline=inline, parallel=parallel, error_model=error_model)
    dispatcher = njit(inline=inline, parallel=parallel, error_model=error_model)(function)
    if dispatcher is not function:  # (NUMBA_DISABLE_JIT=1 gives the function back)
        dispatcher._cache = _Cache(function)  # what cache=True does (numba's enable_caching), with this cache
    return dispatcher
