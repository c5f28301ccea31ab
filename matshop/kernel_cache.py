"""Loading numba's cached kernels without first setting its compiler up.

numba's cache load (``numba.core.caching.Cache.load_overload``) starts with
``target_context.refresh()``: it imports numba's implementation modules and
installs every typing and lowering registry, 0.25-0.3 s of Python holding the
GIL, once per process, although only typing and lowering use them. A process
whose kernels are all in the cache compiles nothing: the command's verbs, and
the editor once ``matshop warm-up`` has run (its first tip or stencil kernel
took 0.30-0.38 s to load, 0.03-0.05 s this way).

A process that owns itself (the command, the editor) runs inside
:func:`cached_kernels_without_compiler_set_up`; a library import leaves numba
as it is.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def cached_kernels_without_compiler_set_up() -> Iterator[None]:
    """Inside, kernels load from numba's on-disk cache without setting its compiler up.

    A cached kernel is machine code: rebuilding it needs the code generator
    and the NRT runtime it calls (allocations), which this load initialises.
    A kernel that is not in the cache is compiled as before: numba's compiler
    refreshes the contexts itself. A load that fails this way is retried
    numba's own way. numba is left alone where its cache class lacks the
    parts this relies on, or where it is not imported yet (the command's verbs
    import it while the command line is parsed, the editor with its window),
    and restored afterwards (tests and scripts call ``main()`` in their own
    process).
    """
    if "numba" not in sys.modules:  # a process that needs no kernel does not import it here
        yield
        return
    from numba.core import caching
    from numba.core.runtime import nrt

    cache = caching.Cache
    full_load = cache.load_overload
    needed = ("_load_overload", "_guard_against_spurious_io_errors")
    usable = all(hasattr(cache, name) for name in needed) and callable(
        getattr(nrt.rtsys, "initialize", None)
    )
    if not usable or getattr(full_load, "lean", False):  # or already inside
        yield
        return

    def load_overload(self, sig, target_context):
        try:
            nrt.rtsys.initialize(target_context)
            with self._guard_against_spurious_io_errors():
                return self._load_overload(sig, target_context)
        except Exception:  # noqa: BLE001 - numba's own load decides what to report
            return full_load(self, sig, target_context)
        return None  # the guard swallowed a spurious I/O error: a cache miss

    load_overload.lean = True  # type: ignore[attr-defined]
    cache.load_overload = load_overload
    try:
        yield
    finally:
        cache.load_overload = full_load
