"""New output arrays for the pointwise kernels, with their pages already mapped.

A fresh array of tens of MB is not memory yet: each page is zeroed by the
kernel on the first write. Taken inside a numba kernel's row loop, those
faults cost twice what they cost up front (2K x 3 channels, one thread: the
curves kernel 26.5 ms into a fresh array, 7.7 ms to touch every page of one
plus 11.3 ms into it; two threads likewise), so the kernels' outputs are
touched once, one store per 4 KiB page, before the kernel writes them --
on a thread of their own while the caller does other work (the curves read
their ranges meanwhile: a serial sort leaves a core free), so on two cores the
faults mostly leave the wall time.
"""

from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor

import numpy as np

#: bytes per page (with transparent huge pages one store per 2 MiB would do)
_PAGE = 4096


def empty_touched(shape: tuple[int, ...], dtype=np.float32) -> np.ndarray:
    """``np.empty(shape, dtype)`` whose pages are mapped (one zero written per page)."""
    out = np.empty(shape, dtype=dtype)
    out.reshape(-1)[:: max(1, _PAGE // out.itemsize)] = 0
    return out


#: one thread: the faults of two arrays at once only contend for the same memory
_TOUCHER = ThreadPoolExecutor(max_workers=1, thread_name_prefix="matshop-touch")


def empty_touched_soon(shape: tuple[int, ...], dtype=np.float32) -> Future[np.ndarray]:
    """:func:`empty_touched` on a background thread (numpy lets go of the GIL while it writes)."""
    return _TOUCHER.submit(empty_touched, shape, dtype)
