"""A dense per-tile cache: one lazily allocated array plus which tiles are valid.

The flattened document (in edit space and physically) and the output of
neighbourhood filter layers are cached this way. A dense array rather than a
dict of tiles because a cache is normally full after the first flatten, a
view can hand it out without assembling tiles, and ``np.empty`` commits
memory only for the pages that get written.
"""

from __future__ import annotations

import numpy as np

from .geometry import Rect, TileLayout, TileSet


class TileCache:
    """Cached ``(H, W, channels)`` float32 values, valid per tile of ``layout``."""

    def __init__(self, layout: TileLayout, channels: int) -> None:
        self.layout = layout
        self.channels = channels
        self.valid: TileSet = layout.no_tiles()
        self._data: np.ndarray | None = None

    @property
    def data(self) -> np.ndarray:
        """The backing array (allocated on first use; invalid tiles hold garbage)."""
        if self._data is None:
            shape = (self.layout.height, self.layout.width, self.channels)
            self._data = np.empty(shape, dtype=np.float32)
        return self._data

    def missing(self, rect: Rect) -> TileSet:
        """Tiles touching ``rect`` that must be computed before reading it."""
        return self.layout.tiles_of(rect) & ~self.valid

    def store(self, rect: Rect, block: np.ndarray) -> None:
        """Put computed values for ``rect``, a union of whole tiles, and mark them valid."""
        if self.layout.aligned(rect) != rect:
            raise ValueError(f"{rect} is not made of whole tiles")
        self.data[rect.slices] = block
        self.valid |= self.layout.tiles_of(rect)

    def view(self, rect: Rect) -> np.ndarray:
        """The cached values of ``rect`` (a view; valid only where the tiles are)."""
        return self.data[rect.slices]

    def invalidate(self, tiles: TileSet) -> None:
        self.valid &= ~tiles

    def clear(self) -> None:
        """Drop everything, memory included."""
        self.valid = self.layout.no_tiles()
        self._data = None

    @property
    def nbytes(self) -> int:
        return 0 if self._data is None else self._data.nbytes
