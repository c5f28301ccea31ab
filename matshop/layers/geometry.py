"""Rectangles and the tile grid they fall on.

Everything in the document is addressed either by a texel rectangle
(:class:`Rect`, half-open, x right and y down like Qt) or by tile keys
``(row, col)`` of one :class:`TileLayout` shared by every layer, mask and
cache of a document, so tiles of different grids line up and a set of dirty
tiles means the same thing everywhere.

Sets of tiles are boolean ``(rows, cols)`` arrays (:data:`TileSet`): dilating
by a filter's reach, unions and "everything" stay cheap array operations even
at 4096 tiles, and they turn into keys or merged rectangles only at the edges
(notifications, recomputation).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from ..errors import InvalidValue

#: A tile key: (tile row, tile column).
TileKey = tuple[int, int]

#: A set of tiles as a boolean (rows, cols) array.
TileSet = np.ndarray


class Rect(NamedTuple):
    """A half-open texel rectangle ``[x0, x1) x [y0, y1)``; may extend past the document."""

    x0: int
    y0: int
    x1: int
    y1: int

    @classmethod
    def from_size(cls, x: int, y: int, width: int, height: int) -> Rect:
        return cls(x, y, x + width, y + height)

    @property
    def width(self) -> int:
        return max(0, self.x1 - self.x0)

    @property
    def height(self) -> int:
        return max(0, self.y1 - self.y0)

    @property
    def empty(self) -> bool:
        return self.width == 0 or self.height == 0

    @property
    def area(self) -> int:
        return self.width * self.height

    @property
    def slices(self) -> tuple[slice, slice]:
        """``(rows, cols)`` slices for indexing an ``(H, W, ...)`` array."""
        return slice(self.y0, self.y1), slice(self.x0, self.x1)

    def intersect(self, other: Rect) -> Rect:
        return Rect(
            max(self.x0, other.x0),
            max(self.y0, other.y0),
            min(self.x1, other.x1),
            min(self.y1, other.y1),
        )

    def union(self, other: Rect) -> Rect:
        if self.empty:
            return other
        if other.empty:
            return self
        return Rect(
            min(self.x0, other.x0),
            min(self.y0, other.y0),
            max(self.x1, other.x1),
            max(self.y1, other.y1),
        )

    def expand(self, margin: int) -> Rect:
        return Rect(self.x0 - margin, self.y0 - margin, self.x1 + margin, self.y1 + margin)

    def translate(self, dx: int, dy: int) -> Rect:
        return Rect(self.x0 + dx, self.y0 + dy, self.x1 + dx, self.y1 + dy)

    def relative_to(self, origin: Rect) -> tuple[slice, slice]:
        """Slices of this rectangle inside an array that covers ``origin``."""
        return (
            slice(self.y0 - origin.y0, self.y1 - origin.y0),
            slice(self.x0 - origin.x0, self.x1 - origin.x0),
        )

    def contains(self, other: Rect) -> bool:
        return (
            self.x0 <= other.x0
            and self.y0 <= other.y0
            and other.x1 <= self.x1
            and other.y1 <= self.y1
        )


@dataclass(frozen=True)
class TileLayout:
    """How a ``height x width`` document is cut into ``tile_size`` square tiles.

    Tiles start at (0, 0); the last row and column are cut short when the size
    is not a multiple of the tile size (no storage is wasted past the edge).
    """

    height: int
    width: int
    tile_size: int = 64

    def __post_init__(self) -> None:
        if self.height <= 0 or self.width <= 0:
            raise InvalidValue(f"document must be at least 1x1, got {self.width}x{self.height}")
        if self.tile_size < 1:
            raise ValueError(f"tile size must be positive, got {self.tile_size}")

    @property
    def rows(self) -> int:
        return -(-self.height // self.tile_size)

    @property
    def cols(self) -> int:
        return -(-self.width // self.tile_size)

    @property
    def grid_shape(self) -> tuple[int, int]:
        return self.rows, self.cols

    @property
    def bounds(self) -> Rect:
        return Rect(0, 0, self.width, self.height)

    def tile_rect(self, key: TileKey) -> Rect:
        row, col = key
        t = self.tile_size
        return Rect(
            col * t, row * t, min(self.width, (col + 1) * t), min(self.height, (row + 1) * t)
        )

    def key_range(self, rect: Rect) -> tuple[range, range]:
        """Tile rows and columns a rectangle (clipped to the document) touches."""
        rect = rect.intersect(self.bounds)
        if rect.empty:
            return range(0), range(0)
        t = self.tile_size
        return range(rect.y0 // t, (rect.y1 - 1) // t + 1), range(
            rect.x0 // t, (rect.x1 - 1) // t + 1
        )

    def keys_in(self, rect: Rect) -> Iterator[TileKey]:
        """Keys of the tiles a rectangle touches, row by row."""
        rows, cols = self.key_range(rect)
        for row in rows:
            for col in cols:
                yield row, col

    def aligned(self, rect: Rect) -> Rect:
        """The smallest union of whole tiles covering ``rect`` (clipped to the document)."""
        rows, cols = self.key_range(rect)
        if not rows:
            return Rect(0, 0, 0, 0)
        first = self.tile_rect((rows[0], cols[0]))
        last = self.tile_rect((rows[-1], cols[-1]))
        return Rect(first.x0, first.y0, last.x1, last.y1)

    # -- tile sets ---------------------------------------------------------

    def no_tiles(self) -> TileSet:
        return np.zeros(self.grid_shape, dtype=bool)

    def all_tiles(self) -> TileSet:
        return np.ones(self.grid_shape, dtype=bool)

    def tiles_of(self, rect: Rect) -> TileSet:
        tiles = self.no_tiles()
        rows, cols = self.key_range(rect)
        if rows:
            tiles[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1] = True
        return tiles

    def tiles_from_keys(self, keys: Iterable[TileKey]) -> TileSet:
        tiles = self.no_tiles()
        for row, col in keys:
            tiles[row, col] = True
        return tiles

    def dilate(self, tiles: TileSet, margin: int, border: str) -> TileSet:
        """Tiles within ``margin`` texels of ``tiles`` (across the seam when ``border="wrap"``).

        Exact in texels, not in whole tiles, so short edge tiles are handled:
        tile j is reached from tile i when j's span meets i's span grown by
        ``margin`` (taken modulo the size for wrap, clipped for clamp).
        """
        if margin <= 0 or not tiles.any():
            return tiles.copy()
        reach_rows = _reach(self.height, self.tile_size, margin, border == "wrap")
        reach_cols = _reach(self.width, self.tile_size, margin, border == "wrap")
        # boolean matrix products: rows reached from any dirty row, then columns
        grown = reach_rows.T.astype(np.int32) @ tiles.astype(np.int32)
        grown = (grown > 0).astype(np.int32) @ reach_cols.astype(np.int32)
        return grown > 0

    def rects_of(self, tiles: TileSet, max_texels: int | None = None) -> list[Rect]:
        """Merge a tile set into few rectangles covering exactly those tiles.

        Runs of consecutive tiles in a row are merged, then identical runs in
        consecutive rows; ``max_texels`` splits tall rectangles into bands so
        the temporaries of compositing one of them stay bounded.
        """
        rows, cols = np.nonzero(tiles)
        return self.rects_of_keys(zip(rows.tolist(), cols.tolist(), strict=True), max_texels)

    def rects_of_keys(self, keys: Iterable[TileKey], max_texels: int | None = None) -> list[Rect]:
        """:meth:`rects_of` for keys (cheap for the handful a dab touches)."""
        by_row: dict[int, list[int]] = {}
        for row, col in keys:
            by_row.setdefault(row, []).append(col)
        open_runs: dict[tuple[int, int], int] = {}  # (col0, col1) -> first row of the block
        blocks: list[tuple[int, int, int, int]] = []  # row0, row1, col0, col1
        previous = None
        for row in sorted(by_row) + [None]:
            if previous is not None and row != previous + 1:
                # a gap of empty rows closes every open block
                blocks.extend((first, previous + 1, *span) for span, first in open_runs.items())
                open_runs = {}
            if row is None:
                break
            current = set(_runs(sorted(by_row[row])))
            for span in [span for span in open_runs if span not in current]:
                blocks.append((open_runs.pop(span), row, *span))
            for span in current:
                open_runs.setdefault(span, row)
            previous = row
        rects = []
        for row0, row1, col0, col1 in sorted(blocks):
            first = self.tile_rect((row0, col0))
            last = self.tile_rect((row1 - 1, col1 - 1))
            rect = Rect(first.x0, first.y0, last.x1, last.y1)
            rects.extend(_bands(rect, self.tile_size, max_texels))
        return rects


def _runs(cols: list[int]) -> Iterator[tuple[int, int]]:
    """Maximal runs of consecutive integers in a sorted list, as half-open spans."""
    start = prev = cols[0]
    for col in cols[1:]:
        if col != prev + 1:
            yield start, prev + 1
            start = col
        prev = col
    yield start, prev + 1


def keys_of(tiles: TileSet) -> frozenset[TileKey]:
    """The keys of a tile set."""
    rows, cols = np.nonzero(tiles)
    return frozenset(zip(rows.tolist(), cols.tolist(), strict=True))


def _bands(rect: Rect, tile_size: int, max_texels: int | None) -> list[Rect]:
    if max_texels is None or rect.area <= max_texels:
        return [rect]
    rows = max(tile_size, (max_texels // max(1, rect.width)) // tile_size * tile_size)
    return [
        Rect(rect.x0, y, rect.x1, min(rect.y1, y + rows)) for y in range(rect.y0, rect.y1, rows)
    ]


@lru_cache(maxsize=64)
def _reach(size: int, tile_size: int, margin: int, wrap: bool) -> np.ndarray:
    """``reach[i, j]``: tile j lies within ``margin`` texels of tile i along one axis."""
    count = -(-size // tile_size)
    reach = np.zeros((count, count), dtype=bool)
    if wrap and 2 * margin + tile_size >= size:
        reach[:] = True
        return reach
    for i in range(count):
        lo = i * tile_size - margin
        hi = min(size, (i + 1) * tile_size) + margin
        texels = np.arange(lo, hi)
        texels = texels % size if wrap else texels[(texels >= 0) & (texels < size)]
        reach[i, np.unique(texels // tile_size)] = True
    reach.setflags(write=False)
    return reach


def periodic_runs(lo: int, hi: int, size: int) -> list[tuple[int, int, int]]:
    """Cut ``[lo, hi)`` into runs inside one period: (offset in the range, source, length)."""
    runs = []
    position = lo
    while position < hi:
        source = position % size
        length = min(hi - position, size - source)
        runs.append((position - lo, source, length))
        position += length
    return runs
