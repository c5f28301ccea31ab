"""numba's one-time set-up, started on a thread while the caller waits on files.

The first compiled call a process makes, even of a kernel in numba's on-disk
cache, first sets numba up: it fills its typing and lowering registries and
loads LLVM. That is 0.18-0.28 s of Python on the 2K chessboard's
``matshop apply`` (whose kernels then take 0.2 s together). Loading a texture
set starts with reading its files, in decoders that release the GIL, so
:func:`start_in_background` runs the set-up meanwhile on a thread of its own;
the load's first kernel then finds numba ready (or waits for the set-up in
numba's own compiler lock, never doing it twice).
"""

from __future__ import annotations

import threading

from numba import njit

_started = threading.Event()


@njit(cache=True, nogil=True)
def _first_kernel(value):
    """A kernel of no work: calling it is numba's set-up and one cache load."""
    return value + 1


def start_in_background() -> None:
    """Set numba up on a daemon thread, once per process (later calls return at once)."""
    if _started.is_set():
        return
    _started.set()
    threading.Thread(target=_first_kernel, args=(0,), name="matshop-jit-setup", daemon=True).start()
