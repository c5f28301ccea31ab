"""New output arrays for the pointwise kernels, with their pages already mapped.

A fresh array of tens of MB is not memory yet: each page is zeroed by the
kernel on the first write. Taken inside a numba kernel's row loop, those
faults cost twice what they cost up front (2K x 3 channels, one thread: the
curves kernel 26.5 ms into a fresh array, 7.7 ms to touch every page of one
plus 11.3 ms into it; two threads likewise). So the kernels' outputs come
from :mod:`matshop.buffers` (memory an earlier result left, already mapped)
or, when there is none, are touched once, one store per page, before the
kernel writes them -- on a thread of their own while the caller does other
work (the curves read their ranges meanwhile), so on two cores the faults
mostly leave the wall time.
"""

from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor

import numpy as np

from .. import buffers

#: one thread: the faults of two arrays at once only contend for the same memory
_TOUCHER = ThreadPoolExecutor(max_workers=1, thread_name_prefix="matshop-touch")


def empty_touched_soon(shape: tuple[int, ...], dtype=np.float32) -> Future[np.ndarray]:
    """``np.empty(shape, dtype)`` with its pages mapped (reused, or one zero written per
    page), made on a background thread."""
    return _TOUCHER.submit(buffers.empty, shape, dtype, touched=True)
