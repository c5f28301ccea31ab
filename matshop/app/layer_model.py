"""The layer stack as a Qt list model, kept in step by the document's events.

Rows run top layer first. The model copies nothing from the document but the
row order (the view must be told which row went where); names, visibility,
nesting depth and tooltips are read from the layers when the view asks. Each
document event touches only its rows: a property change repaints one row, an
insert, removal or move is one row operation, and a change of group
membership repaints the rows whose indent changed. Thumbnails (a paint
layer's coverage, a mask) are cached per layer and drawn again only for
layers whose content changed, once the edit that changed it is recorded.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from PySide6.QtCore import QAbstractListModel, QModelIndex, QObject, QPersistentModelIndex, Qt
from PySide6.QtGui import QIcon, QPixmap

from ..layers import Document, FilterLayer, Layer, PaintLayer
from .icons import icon
from .layer_commands import LayerCommands
from .session import DocumentSession
from .thumbnails import THUMB, gray_pixmap, grid_thumbnail

ID_ROLE = Qt.ItemDataRole.UserRole
DEPTH_ROLE = Qt.ItemDataRole.UserRole + 1
MASK_ROLE = Qt.ItemDataRole.UserRole + 2  # the mask thumbnail (QPixmap) or None
TARGET_ROLE = Qt.ItemDataRole.UserRole + 3  # strokes go into this row's mask

_ROW_FLAGS = (
    Qt.ItemFlag.ItemIsSelectable
    | Qt.ItemFlag.ItemIsEnabled
    | Qt.ItemFlag.ItemIsEditable
    | Qt.ItemFlag.ItemIsUserCheckable
    | Qt.ItemFlag.ItemIsDragEnabled
)
_Index = QModelIndex | QPersistentModelIndex


def describe(layer: Layer) -> str:
    """A row's tooltip: the kind, and a filter's op with its settings."""
    if isinstance(layer, FilterLayer):
        values = ", ".join(
            f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
            for k, v in layer.op_params.items()
            if not isinstance(v, tuple | list)
        )
        return f"{layer.kind} layer: {layer.op} ({values})"
    return f"{layer.kind} layer"


class LayerStackModel(QAbstractListModel):
    """The session document's layers, top first; edits go out through ``commands``."""

    def __init__(
        self, session: DocumentSession, commands: LayerCommands, parent: QObject | None = None
    ) -> None:
        super().__init__(parent)
        self.session = session
        self.commands = commands
        self._doc: Document | None = None
        self._ids: list[int] = []  # row -> layer id
        self._depths: dict[int, int] = {}
        self._thumbs: dict[tuple[int, str], QIcon | QPixmap | None] = {}
        self._stale: set[tuple[int, str]] = set()  # content changed, thumbnail not yet redrawn
        self._target: int | None = None  # the layer whose mask thumbnail is highlighted
        #: a document event is being applied (the view's current row moves by itself)
        self.updating = False
        session.documentReplaced.connect(self._document_replaced)
        session.historyChanged.connect(self.redraw_stale)
        session.activeLayerChanged.connect(self._target_changed)
        session.targetChanged.connect(self._target_changed)
        self._document_replaced()

    # -- following the document ---------------------------------------------------

    def _connect(self, doc: Document, on: bool) -> None:
        events = doc.events
        for signal, slot in (
            (events.layers, self._stack_changed),
            (events.layer, self._property_changed),
            (events.content, self._content_changed),
        ):
            (signal.connect if on else signal.disconnect)(slot)

    def _document_replaced(self) -> None:
        if self._doc is not None:
            self._connect(self._doc, False)
        self.beginResetModel()
        self._doc = self.session.doc
        self._ids = [] if self._doc is None else [layer.id for layer in reversed(self._doc.layers)]
        self._thumbs.clear()
        self._stale.clear()
        self._depths = self._all_depths()
        self._target = None
        self.endResetModel()
        if self._doc is not None:
            self._connect(self._doc, True)

    def _stack_changed(self, kind: str, layer_id: int, index: int) -> None:
        assert self._doc is not None
        self.updating = True
        try:
            if kind == "insert":
                row = len(self._ids) - index
                self.beginInsertRows(QModelIndex(), row, row)
                self._ids.insert(row, layer_id)
                self.endInsertRows()
            elif kind == "remove":
                row = self._ids.index(layer_id)
                self.beginRemoveRows(QModelIndex(), row, row)
                del self._ids[row]
                self.endRemoveRows()
                for target in ("pixels", "mask"):
                    self._thumbs.pop((layer_id, target), None)
                    self._stale.discard((layer_id, target))
            else:
                old = self._ids.index(layer_id)
                new = len(self._ids) - 1 - index
                # Qt wants the row the moved one goes before, counted before the move
                self.beginMoveRows(QModelIndex(), old, old, QModelIndex(), new + (new > old))
                self._ids.insert(new, self._ids.pop(old))
                self.endMoveRows()
        finally:
            self.updating = False
        self._update_depths()  # a group came or went: its members' indent changes

    def _property_changed(self, layer_id: int, name: str) -> None:
        if name in ("mask", "mask_inverted", "mask_generator", "generated_mask"):
            self._thumbs.pop((layer_id, "mask"), None)
            self._stale.discard((layer_id, "mask"))
        if name == "parent":
            self._update_depths()
        self._row_changed(layer_id)

    def _content_changed(self, layer_id: int, target: str, _tiles: Any) -> None:
        if (layer_id, target) in self._thumbs:
            self._stale.add((layer_id, target))

    def redraw_stale(self) -> None:
        """Redraw the thumbnails of layers whose content changed (an edit was recorded)."""
        stale, self._stale = self._stale, set()
        for layer_id, target in stale:
            self._thumbs.pop((layer_id, target), None)
        for layer_id in {layer_id for layer_id, _ in stale}:
            self._row_changed(layer_id)

    def _target_changed(self, *_args: Any) -> None:
        target = self.session.active_layer_id if self.session.mask_target else None
        if target != self._target:
            old, self._target = self._target, target
            for layer_id in (old, target):
                if layer_id is not None:
                    self._row_changed(layer_id, [TARGET_ROLE])

    def _all_depths(self) -> dict[int, int]:
        if self._doc is None:
            return {}
        return {layer.id: self.commands.depth(layer) for layer in self._doc.layers}

    def _update_depths(self) -> None:
        depths = self._all_depths()
        changed = [i for i, depth in depths.items() if self._depths.get(i, depth) != depth]
        self._depths = depths
        for layer_id in changed:
            self._row_changed(layer_id, [DEPTH_ROLE])

    def _row_changed(self, layer_id: int, roles: list[int] | None = None) -> None:
        try:
            index = self.index(self._ids.index(layer_id))
        except ValueError:
            return  # not (or no longer) a row
        self.dataChanged.emit(index, index, roles or [])

    # -- thumbnails --------------------------------------------------------------------

    def _thumbnail(self, layer: Layer, target: str) -> QIcon | QPixmap | None:
        key = (layer.id, target)
        if key not in self._thumbs:
            generated = None
            if target == "mask" and self._doc is not None:
                # only a mask at hand: the background flatten makes a stale one
                generated = self._doc.generated_mask(layer.id, compute=False)
            self._thumbs[key] = _draw(layer, target, generated)
        return self._thumbs[key]

    # -- the model -----------------------------------------------------------------------

    def row_of(self, layer_id: int) -> int:
        try:
            return self._ids.index(layer_id)
        except ValueError:
            raise KeyError(layer_id) from None

    def layer_id(self, row: int) -> int:
        return self._ids[row]

    def rowCount(self, parent: _Index = QModelIndex()) -> int:  # noqa: N802, B008 - Qt API
        return 0 if parent.isValid() else len(self._ids)

    def data(self, index: _Index, role: int = Qt.ItemDataRole.DisplayRole) -> Any:
        if self._doc is None or not index.isValid():
            return None
        try:
            layer = self._doc.layer(self._ids[index.row()])
        except KeyError:  # removed from the document; its row goes when the event comes
            return None
        if role in (Qt.ItemDataRole.DisplayRole, Qt.ItemDataRole.EditRole):
            return layer.name
        if role == Qt.ItemDataRole.DecorationRole:
            return self._thumbnail(layer, "pixels") or icon(f"{layer.kind}_layer")
        if role == Qt.ItemDataRole.CheckStateRole:
            return Qt.CheckState.Checked if layer.visible else Qt.CheckState.Unchecked
        if role == Qt.ItemDataRole.ToolTipRole:
            return describe(layer)
        if role == ID_ROLE:
            return layer.id
        if role == DEPTH_ROLE:
            return self._depths.get(layer.id, 0)
        if role == MASK_ROLE:
            return self._thumbnail(layer, "mask")
        if role == TARGET_ROLE:
            return layer.id == self._target
        return None

    def flags(self, index: _Index) -> Qt.ItemFlag:
        if not index.isValid():
            return Qt.ItemFlag.ItemIsDropEnabled  # drops go between rows
        return _ROW_FLAGS

    def setData(self, index: _Index, value: Any, role: int = Qt.ItemDataRole.EditRole) -> bool:  # noqa: N802 - Qt API
        """A rename or a tick from the view: an edit through the commands."""
        if self._doc is None or not index.isValid():
            return False
        layer_id = self._ids[index.row()]
        if role == Qt.ItemDataRole.CheckStateRole:
            visible = Qt.CheckState(value) == Qt.CheckState.Checked
            self.commands.set_property(layer_id, "visible", visible)
            return self._doc.layer(layer_id).visible == visible
        if role == Qt.ItemDataRole.EditRole and isinstance(value, str) and value.strip():
            self.commands.set_property(layer_id, "name", value.strip())
            return self._doc.layer(layer_id).name == value.strip()
        return False

    def supportedDropActions(self) -> Qt.DropAction:  # noqa: N802 - Qt API
        return Qt.DropAction.MoveAction

    def moveRows(  # noqa: N802 - Qt API
        self,
        source_parent: _Index,
        source_row: int,
        count: int,
        destination_parent: _Index,
        destination_child: int,
    ) -> bool:
        """A row dragged to another place: one move edit (the event then moves the row)."""
        if self._doc is None or count != 1 or source_parent.isValid():
            return False
        target_row = destination_child - 1 if destination_child > source_row else destination_child
        layer_id = self._ids[source_row]
        index = len(self._ids) - 1 - target_row
        self.commands.move(layer_id, index)
        return self._doc.index_of(layer_id) == index


def _draw(
    layer: Layer, target: str, generated: np.ndarray | None = None
) -> QIcon | QPixmap | None:
    """A paint layer's coverage as an icon, or the mask (times the ``generated`` one) as a
    pixmap (None: nothing to show)."""
    if target == "mask":
        shown = None
        if layer.mask is not None:
            shown = grid_thumbnail(layer.mask, 0)
            shown = 1.0 - shown if layer.mask_inverted else shown
        if generated is not None:
            step = max(1, math.ceil(max(generated.shape) / THUMB))
            small = generated[::step, ::step]
            shown = small if shown is None else small * shown
        return None if shown is None else gray_pixmap(shown)
    if isinstance(layer, PaintLayer) and layer.pixels is not None and len(layer.pixels):
        return QIcon(gray_pixmap(grid_thumbnail(layer.pixels, -1)))
    return None
