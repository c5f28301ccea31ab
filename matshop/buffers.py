"""Large result arrays whose memory is reused once nothing refers to them.

A fresh array of tens of MB is not memory yet: the operating system maps and
zeroes each page at its first write. At 2K x 10 channels (168 MB) that costs
as long as copying the array (27 ms here), on every call: a levels
preview while a slider moves, the round trip of a set, each op of a chain. A
pipeline drops its previous result as it makes the next one of the same size,
so :func:`empty` hands out memory that an earlier result left: pages already
mapped, no faults (what a GPU framework's caching allocator does).

Every array :func:`empty` returns is a view of a buffer this module holds. A
buffer is free again when nothing but this module refers to it: no returned
array and no view of one is alive (numpy makes every view refer to the buffer
itself, so counting the buffer's references is enough). Free buffers are kept
up to :data:`IDLE_LIMIT` bytes, the least recently used dropped first; the
memory in use is never more than without the pool. Arrays below
:data:`MIN_BYTES` come from numpy directly.
"""

from __future__ import annotations

import sys
import threading

import numpy as np

#: smaller arrays are not pooled (their faults are cheap, and the pool stays short)
MIN_BYTES = 1 << 20
#: free buffers kept for reuse at most, in bytes
IDLE_LIMIT = 1 << 30
#: bytes per page (with transparent huge pages one store per 2 MiB would do)
_PAGE = 4096


def _touch(out: np.ndarray) -> None:
    """Map every page of ``out`` now (numpy lets go of the GIL while it writes)."""
    out.reshape(-1).view(np.uint8)[::_PAGE] = 0


def _references(buffers: list[np.ndarray], index: int) -> int:
    return sys.getrefcount(buffers[index])


class BufferPool:
    """Buffers handed out as views, reused when none of those views is alive."""

    def __init__(self, idle_limit: int = IDLE_LIMIT) -> None:
        self.idle_limit = idle_limit
        self._buffers: list[np.ndarray] = []  # least recently handed out first
        self._lock = threading.Lock()
        # what _references counts for a buffer only the pool holds (the
        # interpreter's own temporaries included, whatever its version)
        probe = [np.empty(1, dtype=np.uint8)]
        self._idle_count = _references(probe, 0)

    def _idle(self, index: int) -> bool:
        return _references(self._buffers, index) == self._idle_count

    def empty(
        self, shape: tuple[int, ...], dtype=np.float32, *, touched: bool = False
    ) -> np.ndarray:
        """Like ``np.empty(shape, dtype)`` (C order; the values are arbitrary).

        ``touched``: a new buffer gets its pages mapped here (one store per
        page), as a reused one already has them.
        """
        dtype = np.dtype(dtype)
        nbytes = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
        if nbytes < MIN_BYTES:
            out = np.empty(shape, dtype=dtype)
            if touched:
                _touch(out)
            return out
        with self._lock:
            buffer = self._reuse(nbytes)
            new = buffer is None
            if new:
                buffer = np.empty(nbytes, dtype=np.uint8)
            self._buffers.append(buffer)
            self._trim()
        if new and touched:
            _touch(buffer)
        return buffer.view(dtype).reshape(shape)

    def _reuse(self, nbytes: int) -> np.ndarray | None:
        for index in range(len(self._buffers)):
            if self._buffers[index].nbytes == nbytes and self._idle(index):
                return self._buffers.pop(index)
        return None

    def _trim(self) -> None:
        """Drop the least recently used free buffers beyond :attr:`idle_limit` bytes."""
        idle = [i for i in range(len(self._buffers)) if self._idle(i)]
        excess = sum(self._buffers[i].nbytes for i in idle) - self.idle_limit
        dropped = []
        for i in idle:
            if excess <= 0:
                break
            excess -= self._buffers[i].nbytes
            dropped.append(i)
        for i in reversed(dropped):
            del self._buffers[i]

    def release(self) -> int:
        """Drop every free buffer (e.g. after closing a document); returns the bytes freed."""
        with self._lock:
            limit, self.idle_limit = self.idle_limit, 0
            before = sum(b.nbytes for b in self._buffers)
            self._trim()
            self.idle_limit = limit
            return before - sum(b.nbytes for b in self._buffers)

    def idle_bytes(self) -> int:
        """Bytes held by free buffers."""
        with self._lock:
            return sum(self._buffers[i].nbytes for i in range(len(self._buffers)) if self._idle(i))


_POOL = BufferPool()


def empty(shape: tuple[int, ...], dtype=np.float32, *, touched: bool = False) -> np.ndarray:
    """:meth:`BufferPool.empty` of the process' pool."""
    return _POOL.empty(shape, dtype, touched=touched)


def release() -> int:
    """:meth:`BufferPool.release` of the process' pool."""
    return _POOL.release()
