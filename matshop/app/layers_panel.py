"""The layers panel: the stack (top first), visibility, names, blend, opacity, parameters.

The rows are a :class:`LayerStackModel` over the document's events, so a
change repaints only the rows it concerns; every user change goes out as an
edit through :class:`LayerCommands`. Drag the
rows to reorder, double-click to rename, tick to show or hide. An opacity
drag is one undo step (sealed on press and release, merged in between).
Members of a group are indented under it. A layer with a mask shows the
mask's thumbnail at the right of its row: click it to paint the mask (it
gets a highlight; click again, or pick another layer, to paint pixels).
Paint layers show their painted coverage as the row icon.
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, QItemSelectionModel, QModelIndex, QRect, QSize, Qt
from PySide6.QtGui import QAction, QColor, QPainter, QPen, QPixmap
from PySide6.QtWidgets import (
    QAbstractItemView,
    QComboBox,
    QGridLayout,
    QHBoxLayout,
    QLabel,
    QListView,
    QSizePolicy,
    QStyledItemDelegate,
    QStyleOptionViewItem,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from ..layers import BLEND_MODES
from ..material import PARAMETER_KINDS
from ..tools.widgets import FloatSlider, discard_widget
from . import theme
from .layer_commands import LayerCommands
from .layer_model import DEPTH_ROLE, ID_ROLE, MASK_ROLE, TARGET_ROLE, LayerStackModel
from .session import DocumentSession

INDENT = 16
MASK_PX = 24
#: parameter buttons per row: the row wraps instead of widening the dock
PARAM_COLUMNS = 4


class LayerRowDelegate(QStyledItemDelegate):
    """Indents group members and draws (and takes clicks on) the mask thumbnail."""

    def __init__(self, mask_clicked, parent=None) -> None:
        super().__init__(parent)
        self.mask_clicked = mask_clicked

    @staticmethod
    def mask_rect(option_rect: QRect) -> QRect:
        top = option_rect.center().y() - MASK_PX // 2
        return QRect(option_rect.right() - MASK_PX - 4, top, MASK_PX, MASK_PX)

    def _shifted(self, option: QStyleOptionViewItem, index: QModelIndex) -> QStyleOptionViewItem:
        shifted = QStyleOptionViewItem(option)
        shifted.rect = option.rect.adjusted(
            INDENT * (index.data(DEPTH_ROLE) or 0), 0, -(MASK_PX + 8), 0
        )
        return shifted

    def paint(self, painter: QPainter, option: QStyleOptionViewItem, index: QModelIndex) -> None:
        super().paint(painter, self._shifted(option, index), index)
        thumb = index.data(MASK_ROLE)
        if isinstance(thumb, QPixmap):
            rect = self.mask_rect(option.rect)
            painter.drawPixmap(rect, thumb)
            chosen = bool(index.data(TARGET_ROLE))
            pen = QPen(QColor(theme.ACCENT if chosen else theme.BORDER), 2 if chosen else 1)
            painter.setPen(pen)
            painter.drawRect(rect.adjusted(0, 0, -1, -1))

    def editorEvent(self, event, model, option, index) -> bool:  # noqa: N802 - Qt override
        if (
            event.type() == QEvent.Type.MouseButtonRelease
            and isinstance(index.data(MASK_ROLE), QPixmap)
            and self.mask_rect(option.rect).contains(event.position().toPoint())
        ):
            self.mask_clicked(index.data(ID_ROLE))
            return True
        return super().editorEvent(event, model, self._shifted(option, index), index)

    def updateEditorGeometry(self, editor, option, index) -> None:  # noqa: N802 - Qt override
        super().updateEditorGeometry(editor, self._shifted(option, index), index)


class LayerList(QListView):
    """The rows; a drag moves one layer (several selected rows are no single move)."""

    def startDrag(self, actions: Qt.DropAction) -> None:  # noqa: N802 - Qt override
        if len(self.selectionModel().selectedRows()) == 1:
            super().startDrag(actions)


class LayersPanel(QWidget):
    """The layer stack of the session's document."""

    def __init__(
        self,
        session: DocumentSession,
        commands: LayerCommands,
        actions: dict[str, QAction],
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.session = session
        self.commands = commands
        layout = QVBoxLayout(self)
        layout.setContentsMargins(8, 8, 8, 8)
        layout.setSpacing(6)

        row = QHBoxLayout()
        row.setSpacing(6)
        self.blend = QComboBox()
        for mode in BLEND_MODES.values():
            self.blend.addItem(mode.label, mode.name)
            tip = f"{mode.formula} in edit space; {'linear' if mode.linear else 'not linear'}"
            self.blend.setItemData(self.blend.count() - 1, tip, Qt.ItemDataRole.ToolTipRole)
        self.blend.activated.connect(self._blend_chosen)
        self.linear = QLabel("")
        self.linear.setObjectName("hint")
        row.addWidget(self.blend, 1)
        row.addWidget(self.linear)
        layout.addLayout(row)

        self.opacity = FloatSlider("Opacity", 0.0, 100.0, 100.0, decimals=0, unit="%")
        self.opacity.started.connect(session.seal)
        self.opacity.edited.connect(self._opacity_edited)
        self.opacity.finished.connect(session.seal)
        layout.addWidget(self.opacity)

        self.params_row = QGridLayout()
        self.params_row.setSpacing(3)
        self.param_buttons: dict[str, QToolButton] = {}
        layout.addLayout(self.params_row)

        self.model = LayerStackModel(session, commands, self)
        self.list = LayerList()
        self.list.setModel(self.model)
        self.list.setIconSize(QSize(22, 22))
        self.list.setSelectionMode(QAbstractItemView.SelectionMode.ExtendedSelection)
        self.list.setItemDelegate(LayerRowDelegate(self._mask_clicked, self.list))
        self.list.setDragDropMode(QAbstractItemView.DragDropMode.InternalMove)
        self.list.setEditTriggers(
            QAbstractItemView.EditTrigger.DoubleClicked
            | QAbstractItemView.EditTrigger.EditKeyPressed
        )
        self.list.selectionModel().currentChanged.connect(self._current_changed)
        for signal in (
            self.model.modelReset,
            self.model.rowsInserted,
            self.model.rowsRemoved,
            self.model.rowsMoved,
        ):
            signal.connect(self._show_active_row)  # Qt moved the current row by itself
        layout.addWidget(self.list, 1)

        buttons = QHBoxLayout()
        buttons.setSpacing(2)
        for name in (
            "add_paint",
            "add_fill",
            "add_filter",
            "duplicate",
            "group",
            "add_mask",
            "move_up",
            "move_down",
            "delete",
        ):
            button = QToolButton()
            button.setDefaultAction(actions[name])
            button.setIconSize(QSize(18, 18))
            button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonIconOnly)
            if name == "add_filter":
                button.setPopupMode(QToolButton.ToolButtonPopupMode.InstantPopup)
            buttons.addWidget(button)
            if name == "add_filter":
                buttons.addStretch(1)
        layout.addLayout(buttons)

        session.layersChanged.connect(self._show_active)
        session.activeLayerChanged.connect(self._show_active_row)
        session.activeLayerChanged.connect(self._show_active)
        session.documentReplaced.connect(self._rebuild_param_buttons)
        self._rebuild_param_buttons()
        self._show_active_row()
        self._show_active()

    # -- showing the document ------------------------------------------------

    def _rebuild_param_buttons(self) -> None:
        while self.params_row.count():
            item = self.params_row.takeAt(0)
            if item.widget() is not None:
                discard_widget(item.widget())
        self.param_buttons.clear()
        doc = self.session.doc
        if doc is None:
            return
        for number, name in enumerate(doc.schema.names):
            button = QToolButton()
            kind = PARAMETER_KINDS.get(name)
            button.setText(kind.button if kind else name.replace("_", " "))
            button.setToolTip(f"Layer affects {kind.label if kind else name}")
            button.setCheckable(True)
            button.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
            button.clicked.connect(lambda _=False, n=name: self._toggle_parameter(n))
            row, column = divmod(number, PARAM_COLUMNS)
            self.params_row.addWidget(button, row, column)
            self.param_buttons[name] = button

    def _show_active_row(self, *_args) -> None:
        """The active layer's row is the current one."""
        layer_id = self.session.active_layer_id
        try:
            index = self.model.index(self.model.row_of(layer_id)) if layer_id is not None else None
        except KeyError:
            return  # inserted into the document, not yet into the model: rowsInserted comes
        if index is None:
            self.list.setCurrentIndex(QModelIndex())
        elif index != self.list.currentIndex():
            # just that row: the view's own choice would follow the keyboard's modifiers
            self.list.selectionModel().setCurrentIndex(
                index, QItemSelectionModel.SelectionFlag.ClearAndSelect
            )

    def _mask_clicked(self, layer_id: int) -> None:
        """The mask thumbnail: paint the mask (again: back to the layer's pixels)."""
        on = not (self.session.mask_target and self.session.active_layer_id == layer_id)
        self.session.set_active_layer(layer_id)
        self.session.set_mask_target(on)

    def selected_ids(self) -> list[int]:
        return [index.data(ID_ROLE) for index in self.list.selectionModel().selectedRows()]

    def _show_active(self) -> None:
        layer = self.session.active_layer
        for widget in (self.blend, self.opacity, *self.param_buttons.values()):
            widget.setEnabled(layer is not None)
        if layer is None:
            self.linear.setText("")
            return
        self.blend.setCurrentIndex(max(self.blend.findData(layer.blend), 0))
        self.linear.setText("linear" if BLEND_MODES[layer.blend].linear else "non-linear")
        self.opacity.set_value(layer.opacity * 100.0)
        affected = layer.parameters or tuple(self.param_buttons)
        for name, button in self.param_buttons.items():
            button.setChecked(name in affected)

    def row_of(self, layer_id: int) -> int:
        return self.model.row_of(layer_id)

    def index_of(self, layer_id: int) -> QModelIndex:
        """The model index of a layer's row (for tests and scripts)."""
        return self.model.index(self.model.row_of(layer_id))

    # -- user changes ----------------------------------------------------------

    def _current_changed(self, current: QModelIndex, _previous: QModelIndex) -> None:
        if not self.model.updating and current.isValid():
            self.session.set_active_layer(current.data(ID_ROLE))

    def _blend_chosen(self, index: int) -> None:
        layer = self.session.active_layer
        if layer is not None:
            self.commands.set_property(layer.id, "blend", self.blend.itemData(index))

    def _opacity_edited(self, percent: float) -> None:
        layer = self.session.active_layer
        if layer is not None:
            self.commands.set_property(layer.id, "opacity", percent / 100.0, merge=True)

    def _toggle_parameter(self, name: str) -> None:
        layer = self.session.active_layer
        if layer is None:
            return
        chosen = tuple(n for n, b in self.param_buttons.items() if b.isChecked())
        everything = len(chosen) == len(self.param_buttons)
        self.commands.set_property(layer.id, "parameters", None if everything else chosen)
        self._show_active()  # a refused change (no parameter left) unticks nothing
