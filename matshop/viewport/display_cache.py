"""The canvas' 8-bit picture of one parameter, refreshed tile by tile.

The document reports which tiles of its flattened output changed
(``doc.events.dirty``); the cache marks them stale and :meth:`refresh`
converts stale tiles (visible ones first) within a time budget, so a brush
dab re-converts a few 64x64 tiles and a filter-slider drag on a big texture
never blocks the event loop for more than about a frame: the rest is done
on the next turns of the loop. Qt-free; the canvas wraps :attr:`buffer` in a
QImage without copying.
"""

from __future__ import annotations

import time

import numpy as np

from ..layers import DirtyRegion, Document, Rect
from .display import to_display
from .mipmaps import MipPyramid

#: Texels converted per piece: big enough that per-call overhead vanishes,
#: small enough that one piece fits well within a frame on a 2K set.
PIECE_TEXELS = 256 * 256


class DisplayCache:
    """RGBX pixels of ``parameter`` of ``doc``'s flattened physical maps."""

    def __init__(self, doc: Document, parameter: str, normal_convention: str = "opengl") -> None:
        self.doc = doc
        self.buffer = np.zeros((doc.height, doc.width, 4), dtype=np.uint8)
        self.buffer[..., 3] = 255
        #: box-filtered smaller copies of ``buffer`` for zoomed-out drawing
        self.mips = MipPyramid(self.buffer)
        self._convention = normal_convention
        self.parameter = parameter
        self.pending = doc.layout.all_tiles()
        self.seconds = 0.0  # time spent converting, for the status bar and benchmarks

    @property
    def parameter(self) -> str:
        return self._parameter

    @parameter.setter
    def parameter(self, name: str) -> None:
        self._param = self.doc.schema[name]
        self._parameter = name
        self.pending = self.doc.layout.all_tiles()

    @property
    def normal_convention(self) -> str:
        """The normal file's convention: normals are shown as that file shows them."""
        return self._convention

    @normal_convention.setter
    def normal_convention(self, convention: str) -> None:
        if convention != self._convention:
            self._convention = convention
            self.pending = self.doc.layout.all_tiles()

    @property
    def busy(self) -> bool:
        return bool(self.pending.any())

    def mark(self, region: DirtyRegion) -> None:
        """Flattened output changed over ``region``: its tiles are stale."""
        self.pending |= region.tiles

    def refresh(self, budget_s: float | None = 0.012, first: Rect | None = None) -> list[Rect]:
        """Convert stale tiles until ``budget_s`` seconds have passed (None: all of them).

        Pieces meeting ``first`` (the visible area) go first. Returns the
        rectangles converted, for the canvas to repaint.
        """
        if not self.pending.any():
            return []
        layout = self.doc.layout
        pieces = layout.rects_of(self.pending, max_texels=PIECE_TEXELS)
        if first is not None:
            pieces.sort(key=lambda rect: rect.intersect(first).empty)
        start = time.perf_counter()
        done = []
        for rect in pieces:
            phys = self.doc.physical(rect, copy=False)[self._parameter]
            to_display(
                self._param,
                phys,
                out=self.buffer[rect.slices],
                normal_convention=self._convention,
            )
            self.pending &= ~layout.tiles_of(rect)
            self.mips.mark(rect)
            done.append(rect)
            if budget_s is not None and time.perf_counter() - start > budget_s:
                break
        self.seconds += time.perf_counter() - start
        return done
