"""What the command does to start faster; it owns its process, a library import does not.

Measured on `matshop apply` of the 2K chessboard set (one thread, CPU time):
Python's cyclic collector walked the ~10^5 objects of numpy, numba, OpenImageIO
and cv2 again and again (0.13 s of collections, 0.04 s left), numba's probes
for optional packages imported all of scipy.linalg (0.13-0.17 s) and pycparser,
and the first kernel loaded from numba's cache first set up everything numba
needs to compile (0.25-0.3 s), although a command whose kernels are cached
compiles nothing.
"""

from __future__ import annotations

import gc
import importlib
import sys
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def fewer_collections() -> Iterator[None]:
    """The cyclic collector runs every 50 000 allocations instead of 700 inside.

    Start-up objects live until the process ends, so the collections found
    nothing; cycles made later are still collected. Restored afterwards: tests
    and scripts call ``main()`` inside their own process.
    """
    thresholds = gc.get_threshold()
    gc.set_threshold(50_000, *thresholds[1:])
    try:
        yield
    finally:
        gc.set_threshold(*thresholds)


#: numba modules that probe optional packages when imported (by the first compiled call),
#: and the packages hidden from them: scipy's BLAS (its check imports all of scipy.linalg
#: and, through scipy's array-API layer, numpy.f2py and numpy.testing: 0.13-0.17 s of
#: CPU) and cffi (an FFI instance parses C declarations with pycparser: ~0.04 s)
_PROBES = {"numba.np.arraymath": "scipy.linalg", "numba.core.typing.cffi_utils": "cffi"}


def numba_without_unused_extras() -> None:
    """Let numba set up as if scipy's BLAS and cffi were absent, once numba is imported.

    numba's compiler set-up imports the modules of :data:`_PROBES`, which look
    for those optional packages, and so does loading a cached kernel whose code
    uses theirs (``np.sort`` lives in ``numba.np.arraymath``); both absences
    are configurations numba supports. Without the BLAS, ``np.convolve`` /
    ``np.correlate`` in compiled code use a plain loop and numba's linear
    algebra imports scipy when it is compiled, as before; without cffi,
    compiled code cannot call cffi functions. matshop's kernels do neither.
    Called before any thread of the command starts (the hidden modules are hidden
    from every thread meanwhile).
    """
    if "numba" not in sys.modules:
        return
    for probe, package in _PROBES.items():
        if probe in sys.modules or package in sys.modules:
            continue  # done, or already paid for
        sys.modules[package] = None  # importing it, or a module in it, raises ImportError
        try:
            importlib.import_module(probe)
        except ImportError:
            pass  # a numba that needs the package: its first kernel imports both as usual
        finally:
            del sys.modules[package]


@contextmanager
def cached_kernels_without_compiler_set_up() -> Iterator[None]:
    """Inside, kernels load from numba's on-disk cache without setting its compiler up.

    numba's cache load starts with ``target_context.refresh()``: it imports
    numba's implementation modules and installs every typing and lowering
    registry (0.25-0.3 s of Python, once per process), which only typing and
    lowering use. A cached kernel is machine code: rebuilding it needs the
    code generator and the NRT runtime it calls (allocations), which this
    load initialises. A kernel that is not in the cache is compiled as
    before: numba's compiler refreshes the contexts itself. A load that fails
    this way is retried numba's own way. numba is left alone where its cache
    class lacks the parts this relies on, or not imported yet (the verbs' modules
    import it while the command line is parsed), and restored afterwards (tests
    and scripts call ``main()`` inside their own process).
    """
    if "numba" not in sys.modules:  # a verb that needs no kernel does not import it here
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
