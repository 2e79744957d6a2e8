"""Compiled kernels: numba's ``njit``, cached on disk, the cached machine code loaded without numba's compiler.

numba loads a kernel from its on-disk cache only after setting up all it needs to compile
any code: its typing and lowering registries, some forty modules whose import includes
numba's check for a BLAS (``import scipy.linalg``) and its cffi support (a C parser, when
cffi is installed). Loading machine code needs none of it, only numba's runtime (what
compiled code calls to allocate arrays), and the set-up was a third of the time
``drumstroke simulate`` took to start. Each kernel declared with :func:`jit` loads from its
cache without it; numba still sets itself up, as it always does, the moment it compiles
anything (a kernel whose cache is missing or out of date, or any other ``njit`` function).

The machine code run is the one numba compiled and cached, so every result is the same to
the bit. Of the symbols compiled code may call, numba's runtime, math and C helpers come
with its CPU target; the one a registry module adds when imported (the hash secret, for
hashing strings) is added here.
"""

from functools import partial

from numba import njit
from numba.core.caching import FunctionCache
from numba.core.runtime import rtsys


class _Cache(FunctionCache):
    """numba's on-disk cache of one kernel (the same files), loading without the compiler's set-up."""

    def load_overload(self, sig, target_context):
        # numba's own method calls target_context.refresh() here: the registries, for compiling.
        import numba.cpython.hashing  # noqa: F401 - registers the hash secret, as the refresh would

        rtsys.initialize(target_context)
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)


def jit(function=None, *, inline="never", parallel=False):
    """``numba.njit(cache=True)``: ``function`` compiled on its first call (or loaded from the cache on disk).

    Parameters
    ----------
    function : callable, optional
        A function in numba's nopython subset; without it, ``jit(...)`` is the decorator.
    inline : {"never", "always"}
        numba's ``inline``: "always" compiles the function into each kernel that calls it.
    parallel : bool
        numba's ``parallel``: ``prange`` loops run on every core.

    Returns
    -------
    numba's dispatcher of ``function``, with a cache that loads without the compiler.
    """
    if function is None:
        return partial(jit, inline=inline, parallel=parallel)
    dispatcher = njit(inline=inline, parallel=parallel)(function)
    if dispatcher is not function:  # (NUMBA_DISABLE_JIT=1 gives the function back)
        dispatcher._cache = _Cache(function)  # what cache=True does (numba's enable_caching), with this cache
    return dispatcher
