"""What the command does to start faster; it owns its process, a library import does not.

Measured on `matshop apply` of the 2K chessboard set (one thread, CPU time):
Python's cyclic collector walked the ~10^5 objects of numpy, numba, OpenImageIO
and cv2 again and again (0.13 s of collections, 0.04 s left), numba's probes
for optional packages imported all of scipy.linalg (0.13-0.17 s) and pycparser,
and the first kernel loaded from numba's cache first set up everything numba
needs to compile (0.25-0.3 s, :mod:`matshop.kernel_cache`), although a command
whose kernels are cached compiles nothing.
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
