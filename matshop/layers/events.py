"""Change notifications: plain Python callbacks, no Qt.

The document emits; views subscribe (the napari way: the model never knows
who listens). :class:`DirtyRegion` says which tiles of the flattened output
changed, as tile keys and as a bounding texel rectangle, so a canvas can
re-upload just those.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .geometry import Rect, TileKey, TileLayout, TileSet, keys_of


class Signal:
    """A list of callbacks called in connection order with the emitted arguments."""

    def __init__(self, name: str) -> None:
        self.name = name
        self._callbacks: list[Callable[..., Any]] = []

    def connect(self, callback: Callable[..., Any]) -> Callable[..., Any]:
        """Subscribe (returns the callback, so it works as a decorator)."""
        self._callbacks.append(callback)
        return callback

    def disconnect(self, callback: Callable[..., Any]) -> None:
        self._callbacks.remove(callback)

    def emit(self, *args: Any) -> None:
        for callback in list(self._callbacks):
            callback(*args)

    def __len__(self) -> int:
        return len(self._callbacks)


@dataclass(frozen=True)
class DirtyRegion:
    """Tiles of the flattened document whose values may have changed."""

    layout: TileLayout
    tiles: TileSet

    @property
    def keys(self) -> frozenset[TileKey]:
        return keys_of(self.tiles)

    @property
    def rect(self) -> Rect:
        """Bounding texel rectangle of the dirty tiles."""
        rect = Rect(0, 0, 0, 0)
        for key in self.keys:
            rect = rect.union(self.layout.tile_rect(key))
        return rect

    def rects(self) -> list[Rect]:
        """A few rectangles covering exactly the dirty tiles (for partial uploads)."""
        return self.layout.rects_of(self.tiles)

    @property
    def everything(self) -> bool:
        return bool(self.tiles.all())


class DocumentEvents:
    """The document's signals.

    - ``dirty(DirtyRegion)``: flattened output changed over these tiles.
    - ``layers(kind, layer_id, index)``: a layer was inserted, removed or moved
      (``kind`` is ``"insert"``, ``"remove"`` or ``"move"``).
    - ``layer(layer_id, property)``: a layer property changed (``"mask"`` for
      adding or removing the mask; ``"generated_mask"`` when a worker's flatten
      brought the layer's generated mask).
    - ``content(layer_id, target, keys)``: tiles of a layer's ``"pixels"`` or
      ``"mask"`` changed (thumbnails; also emitted for hidden layers).
    """

    def __init__(self) -> None:
        self.dirty = Signal("dirty")
        self.layers = Signal("layers")
        self.layer = Signal("layer")
        self.content = Signal("content")
