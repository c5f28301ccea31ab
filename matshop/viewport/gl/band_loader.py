"""Texture blocks built on a worker thread, handed back to the GL thread a few at a time.

Converting a whole document to shading textures is seconds of CPU for a large set:
a sampled lobe's 128-bin tables need their inverse CDFs at every mip level, and keep
variance widens every level's tables (measured in docs/variance.md, "In the 3D
viewport"). Done inside ``paintGL`` that froze the editor. Here the owner (the GL
thread) reads each block's maps itself -- the document is not thread-safe, and
reading its cached physical tiles is a copy -- one worker thread builds the block
(pure numpy: :meth:`.textures.MaterialTextures.build`), and the owner takes finished
blocks when it polls, in order, and uploads them with its context. At most
:data:`IN_FLIGHT` blocks are read ahead, so memory stays bounded.

No OpenGL or Qt here: the owner calls :meth:`BandLoader.take` from its frame.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any

from ...layers.geometry import Rect

#: blocks read and queued ahead of the one the worker is building
IN_FLIGHT = 2


class BandLoader:
    """Blocks ``rects``: ``read(rect)`` on the owner's thread, ``build(maps)`` on a worker."""

    def __init__(
        self,
        rects: Iterable[Rect],
        read: Callable[[Rect], Any],
        build: Callable[[Any], Any],
    ) -> None:
        self._todo = deque(rects)
        self._read = read
        self._build = build
        self._running: deque[tuple[Rect, Future]] = deque()
        self._executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix="viewport-blocks")
        self.paused = False
        self._fill()

    @property
    def done(self) -> bool:
        return not self._todo and not self._running

    def _fill(self) -> None:
        while self._todo and len(self._running) < IN_FLIGHT and not self.paused:
            rect = self._todo.popleft()
            self._running.append((rect, self._executor.submit(self._build, self._read(rect))))

    def take(self, limit: int | None = 1, *, wait: bool = False) -> list[tuple[Rect, Any]]:
        """Up to ``limit`` finished blocks ``(rect, built)`` in order (None: no limit);
        ``wait``: block until they are built (and read the rest even when paused)."""
        out: list[tuple[Rect, Any]] = []
        if wait:
            self.paused = False
        self._fill()
        while self._running and (limit is None or len(out) < limit):
            rect, future = self._running[0]
            if not (wait or future.done()):
                break
            self._running.popleft()
            out.append((rect, future.result()))
            self._fill()
        if self.done:
            self._executor.shutdown(wait=False)
        return out

    def cancel(self) -> None:
        """Drop everything not yet taken (a block being built finishes and is discarded)."""
        self._todo.clear()
        self._running.clear()
        self._executor.shutdown(wait=False, cancel_futures=True)
