"""Paint transactions: many dabs on a layer's tiles, one undo step.

Krita's transaction life (begin, change, ``commit`` or ``cancel``): the first
time a dab touches a tile, the transaction remembers the stored tile (the
"before" of undo) and installs a private writable copy; later dabs change that
copy in place, so a stroke of a hundred dabs copies each tile once. The
document is notified after every dab, so views follow the stroke. ``commit``
freezes the copies and returns a :class:`~matshop.layers.edits.PaintEdit`
that is already applied: push it with ``History.push(edit, applied=True)``.

The dab arithmetic here is the storage side of painting (straight-alpha over,
erase, mask lerp); spacing, pressure and brush shapes belong to
:mod:`matshop.paint`.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np

from .edits import PaintEdit
from .geometry import Rect, TileKey
from .tiles import freeze

if TYPE_CHECKING:
    from .document import Document, Target


class PaintTransaction:
    """Open changes to the pixels or mask of one layer.

    Parameters
    ----------
    doc : Document
    layer_id : int
    target : {"pixels", "mask"}
        A paint layer's pixels, or any layer's mask.
    label : str
        The history label of the resulting edit.
    """

    def __init__(
        self, doc: Document, layer_id: int, target: Target = "pixels", label: str = "Paint"
    ) -> None:
        self.doc = doc
        self.layer_id = layer_id
        self.target = target
        self.label = label
        self.grid = doc.grid(layer_id, target)
        self._before: dict[TileKey, np.ndarray | None] = {}
        self._working: dict[TileKey, np.ndarray] = {}
        self._open = True

    @property
    def keys(self) -> frozenset[TileKey]:
        """Tiles touched so far."""
        return frozenset(self._working)

    def _tile(self, key: TileKey) -> np.ndarray:
        tile = self._working.get(key)
        if tile is None:
            old = self.grid.get(key)
            tile = self.grid.fill_tile(key) if old is None else old.copy()
            self._before[key] = old
            self._working[key] = tile
            self.grid.replace({key: tile})
        return tile

    def _parts(self, rect: Rect) -> Iterator[tuple[np.ndarray, tuple[slice, slice], np.ndarray]]:
        """Per tile of ``rect``: (writable part of the tile, matching slices of an
        array covering ``rect``, the same texels as they were before this transaction)."""
        if not self._open:
            raise RuntimeError("this paint transaction is already committed or cancelled")
        layout = self.doc.layout
        for key in layout.keys_in(rect):
            tile_rect = layout.tile_rect(key)
            part = tile_rect.intersect(rect)
            in_tile = part.relative_to(tile_rect)
            working = self._tile(key)[in_tile]
            before = self._before[key]
            if before is None:
                original = np.broadcast_to(self.grid.fill, working.shape)
            else:
                original = before[in_tile]
            yield working, part.relative_to(rect), original

    def _changed(self, rect: Rect) -> None:
        self.doc.tiles_changed(self.layer_id, self.target, self.doc.layout.tiles_of(rect))

    def write(self, rect: Rect, block: np.ndarray) -> None:
        """Replace texels of ``rect`` with ``block`` ``(h, w, channels)`` (clipped to the image)."""
        block = np.asarray(block, dtype=np.float32)
        if block.ndim == 2:
            block = block[..., None]
        channels = self.grid.channels
        if block.shape != (rect.height, rect.width, channels):
            raise ValueError(
                f"block is {block.shape}, {rect} needs ({rect.height}, {rect.width}, {channels})"
            )
        for tile, where, _ in self._parts(rect):
            tile[...] = block[where]
        self._changed(rect)

    def paint(
        self,
        rect: Rect,
        values: np.ndarray | float,
        alpha: np.ndarray,
        *,
        channels: np.ndarray | None = None,
        over_original: bool = False,
    ) -> None:
        """Composite a dab over ``rect`` with weight ``alpha`` ``(h, w)`` in [0, 1].

        Pixels: ``values`` is an edit vector ``(C,)`` or ``(h, w, C)``, painted
        straight-alpha over (coverage ``c' = a + c (1 - a)``, value moves
        toward the dab by ``a / c'``), so a soft dab on empty texels paints the
        dab's value, not a darkened one; ``channels`` (indices into the edit
        vector) limits which values move, the others keep what the layer held.
        Masks: ``values`` is the mask value (scalar or ``(h, w)``),
        ``m' = m + a (v - m)``.

        ``over_original`` composites over what the texels held before this
        transaction instead of their current state: a brush that accumulates
        its own stroke alpha uses it so a stroke never exceeds its opacity.
        """
        alpha = self._check_alpha(rect, alpha)
        width = self.grid.channels - 1 if self.target == "pixels" else 1
        dab = np.asarray(values, dtype=np.float32)
        if self.target == "mask" and dab.ndim == 2:
            dab = dab[..., None]
        dab = np.broadcast_to(dab, (rect.height, rect.width, width))
        one = np.float32(1.0)
        for tile, where, original in self._parts(rect):
            a = alpha[where]
            base = original if over_original else tile
            if self.target == "mask":
                mask = base[..., 0]
                tile[..., 0] = mask + a * (dab[where][..., 0] - mask)
                continue
            coverage = base[..., -1]
            new_coverage = a + coverage * (one - a)
            share = np.divide(a, new_coverage, out=np.zeros_like(a), where=new_coverage > 0)
            old = base[..., :-1]
            moved = old + share[..., None] * (dab[where] - old)
            if channels is None:
                tile[..., :-1] = moved
            else:
                if over_original:
                    tile[..., :-1] = old
                tile[..., channels] = moved[..., channels]
            tile[..., -1] = new_coverage
        self._changed(rect)

    def erase(self, rect: Rect, alpha: np.ndarray, *, over_original: bool = False) -> None:
        """Remove coverage (pixels) or hide (mask): ``c' = c (1 - a)``."""
        alpha = self._check_alpha(rect, alpha)
        for tile, where, original in self._parts(rect):
            base = original if over_original else tile
            tile[..., -1] = base[..., -1] * (np.float32(1.0) - alpha[where])
        self._changed(rect)

    @staticmethod
    def _check_alpha(rect: Rect, alpha: np.ndarray) -> np.ndarray:
        alpha = np.asarray(alpha, dtype=np.float32)
        if alpha.shape != (rect.height, rect.width):
            raise ValueError(f"alpha is {alpha.shape}, {rect} needs ({rect.height}, {rect.width})")
        return alpha

    @property
    def changed(self) -> bool:
        """Whether any touched texel now differs from what it held before the transaction."""
        for key, tile in self._working.items():
            before = self._before[key]
            if before is None:
                before = np.broadcast_to(self.grid.fill, tile.shape)
            if not np.array_equal(tile, before):
                return True
        return False

    def commit(self) -> PaintEdit:
        """Freeze the touched tiles and return the (already applied) edit."""
        if not self._open:
            raise RuntimeError("this paint transaction is already committed or cancelled")
        self._open = False
        after: dict[TileKey, np.ndarray | None] = {
            key: freeze(tile) for key, tile in self._working.items()
        }
        return PaintEdit(self.layer_id, self.target, dict(self._before), after, self.label)

    def cancel(self) -> None:
        """Put every touched tile back as it was."""
        if not self._open:
            return
        self._open = False
        if self._before:
            self.doc.replace_tiles(self.layer_id, self.target, dict(self._before))
