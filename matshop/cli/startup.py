"""What the command does to start faster; it owns its process, a library import does not.

Measured on `matshop apply` of the 2K chessboard set (one thread, CPU time):
Python's cyclic collector walked the ~10^5 objects of numpy, numba, OpenImageIO
and cv2 again and again (0.13 s of collections, 0.04 s left), and numba's check
for scipy's BLAS imported all of scipy.linalg (0.13-0.17 s).
"""

from __future__ import annotations

import gc
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


def numba_without_scipy_blas() -> None:
    """Import numba's array maths with ``scipy.linalg`` hidden, once numba is imported.

    The first compiled kernel a process calls (even one from numba's on-disk
    cache) imports ``numba.np.arraymath``, which checks at import time whether
    scipy's BLAS is there: that imports all of scipy.linalg, and through scipy's
    array-API layer numpy.f2py and numpy.testing. The answer only decides whether
    ``np.convolve`` / ``np.correlate`` in compiled code call BLAS or a plain loop
    (matshop's kernels call neither); numba's linear algebra imports scipy when
    it is compiled, as before. Called before any thread of the command starts.
    """
    if "numba" not in sys.modules or "numba.np.arraymath" in sys.modules:
        return
    if "scipy.linalg" in sys.modules:
        return  # already paid for
    sys.modules["scipy.linalg"] = None  # an import of it, or of a module in it, raises ImportError
    try:
        import numba.np.arraymath  # noqa: F401
    except ImportError:
        pass  # a numba that needs scipy.linalg itself: its first kernel imports both as usual
    finally:
        del sys.modules["scipy.linalg"]
