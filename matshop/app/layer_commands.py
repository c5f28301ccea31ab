"""Layer operations as edits, shared by the Layer menu and the layers panel.

Each method builds the edit the engine defines (AddLayer, RemoveLayer,
MoveLayer, SetProperty) and pushes it through the session; engine refusals
(ValueError, MatshopError) become a status message and change nothing.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import Any

from PySide6.QtCore import QObject, Signal

from ..errors import MatshopError
from ..layers import AddLayer, Edit, MoveLayer, RemoveLayer, SetProperty
from ..layers.filters import bind_filter
from ..ops import all_ops
from ..paint import Swatch
from .session import DocumentSession


@cache
def filter_ops() -> tuple[tuple[str, str], ...]:
    """(name, label) of every op that can run as a filter layer with its defaults."""
    usable = []
    for name, spec in all_ops().items():
        try:
            bind_filter(name)
        except MatshopError:
            continue  # needs a second input or a region: not a filter layer
        usable.append((name, spec.label))
    return tuple(usable)


class LayerCommands(QObject):
    """Add, remove, reorder and change layers of the session's document."""

    #: a short message for the status bar
    message = Signal(str)

    def __init__(self, session: DocumentSession, swatch: Callable[[], Swatch]) -> None:
        super().__init__()
        self.session = session
        self.swatch = swatch

    def _push(self, edit: Edit, *, merge: bool = False) -> bool:
        try:
            self.session.push(edit, merge=merge)
        except (ValueError, MatshopError) as exc:
            self.message.emit(str(exc))
            return False
        return True

    def _above_active(self) -> int | None:
        doc, active = self.session.doc, self.session.active_layer_id
        if doc is None or active is None:
            return None
        return doc.index_of(active) + 1

    # -- adding --------------------------------------------------------------

    def add_paint_layer(self, parameters: tuple[str, ...] | None = None) -> int | None:
        """A new empty paint layer above the active one; returns its id."""
        doc = self.session.doc
        if doc is None:
            return None
        layer = doc.new_paint_layer(parameters=parameters)
        return layer.id if self._push(AddLayer(layer, self._above_active())) else None

    def add_fill_layer(self) -> int | None:
        """A fill layer of the current swatch, affecting the parameters it sets."""
        doc = self.session.doc
        if doc is None:
            return None
        try:
            swatch = self.swatch()
            vector, _ = swatch.edit_values(doc.schema)
            layer = doc.new_fill_layer(
                f"Fill {swatch.name}", value=vector, parameters=swatch.parameters
            )
        except (ValueError, MatshopError) as exc:
            self.message.emit(str(exc))
            return None
        return layer.id if self._push(AddLayer(layer, self._above_active())) else None

    def add_filter_layer(self, op: str, params: dict[str, Any] | None = None) -> int | None:
        """A filter layer running ``op`` on everything below it."""
        doc = self.session.doc
        if doc is None:
            return None
        try:
            layer = doc.new_filter_layer(op, op_params=params)
        except (ValueError, MatshopError) as exc:
            self.message.emit(str(exc))
            return None
        return layer.id if self._push(AddLayer(layer, self._above_active())) else None

    # -- changing ------------------------------------------------------------

    def remove_active(self) -> None:
        layer = self.session.active_layer
        if layer is not None and self.session.doc is not None and len(self.session.doc) > 1:
            self._push(RemoveLayer(layer.id))

    def move_active(self, delta: int) -> None:
        """Move the active layer ``delta`` places up (+) or down (-) the stack."""
        doc, layer = self.session.doc, self.session.active_layer
        if doc is None or layer is None:
            return
        self.move(layer.id, doc.index_of(layer.id) + delta)

    def move(self, layer_id: int, index: int) -> None:
        doc = self.session.doc
        if doc is None or not 0 <= index < len(doc) or doc.index_of(layer_id) == index:
            return
        self._push(MoveLayer(layer_id, index))

    def set_property(self, layer_id: int, name: str, value: Any, *, merge: bool = False) -> None:
        """One property change; ``merge`` for the ticks of a slider drag."""
        doc = self.session.doc
        if doc is None:
            return
        current = doc.layer(layer_id).get(name)
        if _same(current, value):
            return
        self._push(SetProperty(layer_id, name, value), merge=merge)

    def can_move(self, delta: int) -> bool:
        doc, layer = self.session.doc, self.session.active_layer
        if doc is None or layer is None:
            return False
        return 0 <= doc.index_of(layer.id) + delta < len(doc)


def _same(a: Any, b: Any) -> bool:
    try:
        return bool(a == b)
    except ValueError:  # arrays compare elementwise: treat as changed
        return False
