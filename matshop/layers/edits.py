"""Reversible edits: every change to a document is one of these objects.

An edit has ``apply(doc)``, ``revert(doc)``, a human-readable ``label`` and,
for slider drags, ``merge_with(other)``. The app wraps each in a
``QUndoCommand``; the CLI and tests apply them directly; :class:`History`
keeps them. Edits refer to layers by id (stable across reordering), never by
index or object, so a replay on another document does the same thing.

Undo never re-runs an operation. Paint edits hold the tile objects from
before and after (tiles are immutable, so holding them costs no copy) and
swap them back, Krita's way; structural edits hold the removed layer object
or the old property value. That makes undo bit-identical and cheap.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from .geometry import TileKey
from .layer import Layer
from .properties import PROPERTIES
from .tiles import TileGrid

if TYPE_CHECKING:
    from .document import Document, Target


class Edit:
    """Base of all edits: a no-op that merges with nothing."""

    label: str = "Edit"

    def apply(self, doc: Document) -> None:
        """Do (or redo) the change."""

    def revert(self, doc: Document) -> None:
        """Undo the change exactly."""

    def merge_with(self, other: Edit) -> bool:
        """Absorb ``other`` (applied just after this one) into this step; True if done."""
        return False

    def arrays(self) -> Iterator[np.ndarray]:
        """Arrays this edit keeps alive (history's memory accounting)."""
        return iter(())

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.label!r}>"


class AddLayer(Edit):
    """Insert a new layer (made by ``doc.new_*_layer``) at ``index`` (default: top)."""

    def __init__(self, layer: Layer, index: int | None = None) -> None:
        self.layer = layer
        self.index = index
        self.label = f"Add layer {layer.name!r}"

    def apply(self, doc: Document) -> None:
        self.index = doc.insert_layer(self.layer, self.index)

    def revert(self, doc: Document) -> None:
        doc.remove_layer(self.layer.id)

    def arrays(self) -> Iterator[np.ndarray]:
        return self.layer.arrays()


class RemoveLayer(Edit):
    """Take a layer out; undo puts the same object (tiles and all) back in place."""

    def __init__(self, layer_id: int) -> None:
        self.layer_id = layer_id
        self.layer: Layer | None = None
        self.index = -1
        self.label = "Remove layer"

    def apply(self, doc: Document) -> None:
        self.layer, self.index = doc.remove_layer(self.layer_id)
        self.label = f"Remove layer {self.layer.name!r}"

    def revert(self, doc: Document) -> None:
        assert self.layer is not None, "revert before apply"
        doc.insert_layer(self.layer, self.index)

    def arrays(self) -> Iterator[np.ndarray]:
        return iter(()) if self.layer is None else self.layer.arrays()


class MoveLayer(Edit):
    """Move a layer to another position in the stack."""

    def __init__(self, layer_id: int, index: int) -> None:
        self.layer_id = layer_id
        self.index = index
        self.old_index = -1
        self.label = "Move layer"

    def apply(self, doc: Document) -> None:
        self.old_index = doc.move_layer(self.layer_id, self.index)

    def revert(self, doc: Document) -> None:
        doc.move_layer(self.layer_id, self.old_index)


class SetProperty(Edit):
    """Change one layer property; consecutive slider moves merge into one step.

    Parameters
    ----------
    layer_id, name, value : which property of which layer, and the new value.
    mergeable : bool, optional
        Whether a following change of the same property of the same layer
        merges into this step. Defaults to True for slider-like properties
        (:attr:`LayerProperty.mergeable`). A drag that ends should push its next change with
        ``History.push(..., merge=False)`` (or call ``History.seal()``).
    """

    def __init__(
        self, layer_id: int, name: str, value: Any, *, mergeable: bool | None = None
    ) -> None:
        self.layer_id = layer_id
        self.name = name
        self.value = value
        self.old: Any = None
        prop = PROPERTIES.get(name)
        self.mergeable = (prop is not None and prop.mergeable) if mergeable is None else mergeable
        self.label = prop.label if prop is not None else f"Set {name}"

    def apply(self, doc: Document) -> None:
        self.old = doc.set_property(self.layer_id, self.name, self.value)

    def revert(self, doc: Document) -> None:
        doc.set_property(self.layer_id, self.name, self.old)

    def merge_with(self, other: Edit) -> bool:
        if (
            self.mergeable
            and isinstance(other, SetProperty)
            and other.mergeable
            and other.layer_id == self.layer_id
            and other.name == self.name
        ):
            self.value = other.value
            return True
        return False

    def arrays(self) -> Iterator[np.ndarray]:
        for value in (self.old, self.value):
            if isinstance(value, np.ndarray):
                yield value


class SetMask(Edit):
    """Add (a grid from ``doc.new_mask``), replace or remove (None) a layer's mask."""

    def __init__(self, layer_id: int, mask: TileGrid | None) -> None:
        self.layer_id = layer_id
        self.mask = mask
        self.old: TileGrid | None = None
        self.label = "Remove mask" if mask is None else "Add mask"

    def apply(self, doc: Document) -> None:
        self.old = doc.set_mask(self.layer_id, self.mask)

    def revert(self, doc: Document) -> None:
        doc.set_mask(self.layer_id, self.old)

    def arrays(self) -> Iterator[np.ndarray]:
        for grid in (self.old, self.mask):
            if grid is not None:
                yield from grid._tiles.values()


class PaintEdit(Edit):
    """Tiles of a layer's pixels or mask, before and after (None: the tile was absent).

    Made by :meth:`PaintTransaction.commit`; apply and revert swap the tile
    objects, so undo and redo are exact and run no op.
    """

    def __init__(
        self,
        layer_id: int,
        target: Target,
        before: dict[TileKey, np.ndarray | None],
        after: dict[TileKey, np.ndarray | None],
        label: str = "Paint",
    ) -> None:
        if before.keys() != after.keys():
            raise ValueError("a paint edit needs the same tiles before and after")
        self.layer_id = layer_id
        self.target = target
        self.before = before
        self.after = after
        self.label = label

    @property
    def keys(self) -> frozenset[TileKey]:
        return frozenset(self.after)

    def apply(self, doc: Document) -> None:
        doc.replace_tiles(self.layer_id, self.target, self.after)

    def revert(self, doc: Document) -> None:
        doc.replace_tiles(self.layer_id, self.target, self.before)

    def arrays(self) -> Iterator[np.ndarray]:
        for tiles in (self.before, self.after):
            yield from (tile for tile in tiles.values() if tile is not None)


class CompoundEdit(Edit):
    """Several edits as one history step (applied in order, reverted in reverse)."""

    def __init__(self, edits: Sequence[Edit], label: str | None = None) -> None:
        self.edits = list(edits)
        self.label = label or (self.edits[0].label if self.edits else "Edit")

    def apply(self, doc: Document) -> None:
        done: list[Edit] = []
        try:
            for edit in self.edits:
                edit.apply(doc)
                done.append(edit)
        except Exception:
            # all or nothing: a half-applied step could be neither undone nor redone
            for edit in reversed(done):
                edit.revert(doc)
            raise

    def revert(self, doc: Document) -> None:
        for edit in reversed(self.edits):
            edit.revert(doc)

    def arrays(self) -> Iterator[np.ndarray]:
        for edit in self.edits:
            yield from edit.arrays()
