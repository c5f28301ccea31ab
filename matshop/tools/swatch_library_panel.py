"""The swatch library in the tool panel: a list with Add, Apply and Remove.

Add stores the current swatch (the parameters the brush paints) under the
name typed above the list; Apply (or a double-click) loads one into the
brush: its values, and exactly its parameters enabled where the document has
them.
"""

from __future__ import annotations

from PySide6.QtGui import QColor, QIcon, QPixmap
from PySide6.QtWidgets import (
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QListWidget,
    QListWidgetItem,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from ..errors import MatshopError
from ..paint import Swatch
from .settings import SwatchModel, short_label
from .swatch_library import SwatchLibrary
from .widgets import file_codes_to_qcolor

#: Parameters whose value colours a swatch's icon, first found wins.
_COLOR_PARAMETERS = ("base_color", "diffuse", "albedo")


def swatch_icon(swatch: Swatch) -> QIcon:
    """A square of the swatch's color (grey when it paints no color)."""
    pixmap = QPixmap(16, 16)
    value = next((swatch.values[p] for p in _COLOR_PARAMETERS if p in swatch.values), None)
    pixmap.fill(file_codes_to_qcolor(value) if value and len(value) >= 3 else QColor(110, 112, 118))
    icon = QIcon(pixmap)
    icon.addPixmap(pixmap, QIcon.Mode.Selected)  # no selection tint: the color is the point
    return icon


class SwatchLibraryPanel(QGroupBox):
    """Saved swatches; the brush's swatch goes in and comes back out."""

    def __init__(
        self, library: SwatchLibrary, model: SwatchModel, parent: QWidget | None = None
    ) -> None:
        super().__init__("Swatch library", parent)
        self.library = library
        self.model = model
        layout = QVBoxLayout(self)
        layout.setSpacing(4)
        self.name = QLineEdit()
        self.name.setPlaceholderText("Name of the swatch to add")
        layout.addWidget(self.name)
        self.list = QListWidget()
        # a few rows, scrolling: an expanding list would squeeze the swatch editor above
        self.list.setMinimumHeight(90)
        self.list.setMaximumHeight(150)
        self.list.itemDoubleClicked.connect(lambda _item: self.apply_selected())
        layout.addWidget(self.list)
        row = QHBoxLayout()
        self.add_button = QPushButton("Add current")
        self.add_button.setToolTip("Save the swatch (the parameters the brush paints)")
        self.add_button.clicked.connect(self.add_current)
        self.apply_button = QPushButton("Apply")
        self.apply_button.setToolTip("Paint with the selected swatch (or double-click it)")
        self.apply_button.clicked.connect(self.apply_selected)
        self.remove_button = QPushButton("Remove")
        self.remove_button.clicked.connect(lambda: self.library.remove(self.list.currentRow()))
        for button in (self.add_button, self.apply_button, self.remove_button):
            row.addWidget(button)
        layout.addLayout(row)
        self.status = QLabel("")
        self.status.setObjectName("hint")
        self.status.setWordWrap(True)
        layout.addWidget(self.status)
        library.changed.connect(self._rebuild)
        self._rebuild()

    def _rebuild(self) -> None:
        current = self.list.currentRow()
        self.list.clear()
        for swatch in self.library.swatches:
            item = QListWidgetItem(swatch_icon(swatch), swatch.name)
            item.setToolTip(", ".join(short_label(p) for p in swatch.parameters))
            self.list.addItem(item)
        self.list.setCurrentRow(min(current, self.list.count() - 1))
        self.status.setText(self.library.error)
        self.status.setVisible(bool(self.library.error))

    def add_current(self) -> None:
        try:
            swatch = self.model.swatch()
        except MatshopError as exc:  # no parameter enabled
            self.library.error = str(exc)
            self._rebuild()
            return
        name = self.name.text().strip() or self.model.name
        index = self.library.add(Swatch(name, dict(swatch.values)))
        self.name.clear()
        self.list.setCurrentRow(index)

    def apply_selected(self) -> None:
        row = self.list.currentRow()
        if 0 <= row < len(self.library.swatches):
            self.model.apply(self.library.swatches[row])
