"""Sparse tiled storage: a dict of immutable square tiles over a fill value.

A :class:`TileGrid` holds ``channels`` float32 values per texel (all edit
channels of a texel together, so one dab or one undo step touches one tile
object, not one per parameter). A tile that was never written is simply
absent from the dict and reads as the fill value, so an empty layer on a 4K
document costs a dict and a fill vector: memory grows with painted area, not
with resolution x layers.

Tiles are copy-on-write, Krita's way: a stored tile is a read-only numpy array
and a change *replaces* it with a new array instead of mutating it. History
can therefore keep the old tile objects themselves (no copies) and undo is a
dict swap, bit-identical by construction. The only writable tiles are the
private working copies of an open paint transaction
(:class:`~matshop.layers.edits.PaintTransaction`), frozen when it commits.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator, Mapping

import numpy as np

from .geometry import Rect, TileKey, TileLayout, TileSet


def freeze(array: np.ndarray) -> np.ndarray:
    """Mark an array read-only so it can be shared between the grid and history."""
    array.setflags(write=False)
    return array


class TileGrid:
    """Sparse ``(height, width, channels)`` float32 storage in tiles of one layout.

    Parameters
    ----------
    layout : TileLayout
        The document's tiling; every grid of a document shares it.
    channels : int
        Values per texel.
    fill : float or (channels,) array_like
        What absent tiles read as.
    """

    def __init__(self, layout: TileLayout, channels: int, fill: float | np.ndarray = 0.0) -> None:
        if channels < 1:
            raise ValueError(f"a tile grid needs at least one channel, got {channels}")
        self.layout = layout
        self.channels = channels
        fill_vector = np.broadcast_to(np.asarray(fill, dtype=np.float32), (channels,))
        self.fill: np.ndarray = freeze(np.array(fill_vector, dtype=np.float32))
        self._tiles: dict[TileKey, np.ndarray] = {}

    # -- construction ------------------------------------------------------

    @classmethod
    def from_array(
        cls, array: np.ndarray, layout: TileLayout, fill: float | np.ndarray = 0.0
    ) -> TileGrid:
        """Cut a full ``(H, W, C)`` array into tiles; tiles equal to the fill stay absent."""
        array = np.asarray(array, dtype=np.float32)
        if array.ndim == 2:
            array = array[..., None]
        if array.shape[:2] != (layout.height, layout.width):
            raise ValueError(
                f"array is {array.shape[1]}x{array.shape[0]}, the layout "
                f"{layout.width}x{layout.height}"
            )
        grid = cls(layout, array.shape[2], fill)
        for key in layout.keys_in(layout.bounds):
            block = array[layout.tile_rect(key).slices]
            if not (block == grid.fill).all():
                grid._tiles[key] = freeze(np.array(block, dtype=np.float32))
        return grid

    def copy(self) -> TileGrid:
        """A new grid sharing this one's (immutable) tiles: O(tiles), no pixel copies."""
        twin = TileGrid(self.layout, self.channels, self.fill)
        twin._tiles = dict(self._tiles)
        return twin

    # -- tiles -------------------------------------------------------------

    def __contains__(self, key: object) -> bool:
        return key in self._tiles

    def __len__(self) -> int:
        return len(self._tiles)

    def keys(self) -> Iterator[TileKey]:
        """Keys of the stored tiles, in no particular order."""
        return iter(self._tiles)

    def get(self, key: TileKey) -> np.ndarray | None:
        """The stored tile (read-only unless a transaction owns it), or None when absent."""
        return self._tiles.get(key)

    def fill_tile(self, key: TileKey) -> np.ndarray:
        """A new writable tile at ``key`` holding the fill value."""
        rect = self.layout.tile_rect(key)
        return np.tile(self.fill, (rect.height, rect.width, 1))

    def replace(
        self, changes: Mapping[TileKey, np.ndarray | None]
    ) -> dict[TileKey, np.ndarray | None]:
        """Put tile objects in place (None removes); return the ones they replaced.

        The arrays are stored as given, not copied: that is what makes undo a
        swap. They must have the tile's shape and float32 dtype.
        """
        previous: dict[TileKey, np.ndarray | None] = {}
        for key, tile in changes.items():
            previous[key] = self._tiles.get(key)
            if tile is None:
                self._tiles.pop(key, None)
                continue
            rect = self.layout.tile_rect(key)
            expected = (rect.height, rect.width, self.channels)
            if tile.shape != expected or tile.dtype != np.float32:
                raise ValueError(
                    f"tile {key} must be {expected} float32, got {tile.shape} {tile.dtype}"
                )
            self._tiles[key] = tile
        return previous

    def present(self) -> TileSet:
        """The stored tiles as a tile set."""
        return self.layout.tiles_from_keys(self._tiles)

    def any_in(self, rect: Rect) -> bool:
        """Whether any stored tile touches ``rect``."""
        tiles = self._tiles
        if not tiles:
            return False
        return any(key in tiles for key in self.layout.keys_in(rect))

    def keys_in(self, rect: Rect) -> list[TileKey]:
        """Stored tiles touching ``rect``."""
        tiles = self._tiles
        return [key for key in self.layout.keys_in(rect) if key in tiles] if tiles else []

    # -- pixels ------------------------------------------------------------

    def read(self, rect: Rect) -> np.ndarray:
        """A new ``(h, w, channels)`` array of the texels in ``rect`` (inside the document)."""
        if not self.layout.bounds.contains(rect):
            raise ValueError(
                f"{rect} reaches outside the {self.layout.width}x{self.layout.height} grid"
            )
        out = np.empty((rect.height, rect.width, self.channels), dtype=np.float32)
        if not self._tiles:
            out[...] = self.fill
            return out
        for key in self.layout.keys_in(rect):
            tile_rect = self.layout.tile_rect(key)
            part = tile_rect.intersect(rect)
            tile = self._tiles.get(key)
            if tile is None:
                out[part.relative_to(rect)] = self.fill
            else:
                out[part.relative_to(rect)] = tile[part.relative_to(tile_rect)]
        return out

    def write(self, rect: Rect, block: np.ndarray) -> dict[TileKey, np.ndarray | None]:
        """Replace the texels of ``rect`` with ``block`` (new tiles); return the old tiles."""
        block = np.asarray(block, dtype=np.float32)
        if block.ndim == 2:
            block = block[..., None]
        if block.shape != (rect.height, rect.width, self.channels):
            raise ValueError(
                f"block is {block.shape}, {rect} needs "
                f"({rect.height}, {rect.width}, {self.channels})"
            )
        changes: dict[TileKey, np.ndarray | None] = {}
        for key in self.layout.keys_in(rect):
            tile_rect = self.layout.tile_rect(key)
            part = tile_rect.intersect(rect)
            old = self._tiles.get(key)
            tile = self.fill_tile(key) if old is None else old.copy()
            tile[part.relative_to(tile_rect)] = block[part.relative_to(rect)]
            changes[key] = freeze(tile)
        return self.replace(changes)

    def to_array(self) -> np.ndarray:
        """The whole grid as one new array."""
        return self.read(self.layout.bounds)

    # -- memory ------------------------------------------------------------

    @property
    def nbytes(self) -> int:
        """Bytes of tile payload (0 for an untouched grid)."""
        return sum(tile.nbytes for tile in self._tiles.values())

    def footprint(self) -> int:
        """Bytes this grid keeps alive: payload plus the dict, array headers and fill."""
        # getsizeof counts the data of arrays that own it; views add their payload
        tiles = sum(
            sys.getsizeof(tile) + (tile.nbytes if tile.base is not None else 0)
            for tile in self._tiles.values()
        )
        own = sys.getsizeof(self) + sys.getsizeof(self.__dict__)
        return own + sys.getsizeof(self._tiles) + tiles + sys.getsizeof(self.fill)

    def __repr__(self) -> str:
        return (
            f"TileGrid({self.layout.width}x{self.layout.height}x{self.channels}, "
            f"tile {self.layout.tile_size}, {len(self._tiles)} tiles, {self.nbytes} bytes)"
        )
