"""What was detected in a texture set, shown before it is loaded.

One row per file the detection looked at: the maps it will load (which
parameter slot, the file, its size and depth from the header, hints such as
a normal map's convention), the alternates it will not use (a DirectX normal
beside an OpenGL one) and the images whose names matched no slot.

It is a confirmation view: ``load_material`` runs its own detection from a
path and cannot take a corrected set yet, so a wrong assignment is fixed by
renaming the file, as the note in the dialog says. (The engine hook that
would let this dialog reassign or drop files: ``load_material`` accepting a
``TextureSet`` in place of the path.)
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import (
    QDialog,
    QDialogButtonBox,
    QLabel,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from ..errors import MatshopError
from ..io.images import probe_image
from ..io.textureset import SLOTS, TextureSet

#: Columns of the table.
COLUMNS = ("Parameter", "File", "Image", "Notes")


def _header(path: Path) -> str:
    """``2048x2048 uint8 RGB`` from the file header, or why it cannot be read."""
    try:
        info = probe_image(path)
    except (MatshopError, OSError) as exc:
        return f"unreadable: {exc}"
    return f"{info.width}x{info.height} {info.bit_depth} {info.channels} ch"


def texture_set_rows(ts: TextureSet) -> list[tuple[str, str, str, str]]:
    """(parameter, file, image, notes) per file, maps first: what the dialog lists."""
    rows = []
    for slot, path in sorted(ts.maps.items()):
        hints = ", ".join(f"{k}: {v}" for k, v in ts.hints.get(slot, {}).items())
        notes = SLOTS[slot].description if slot in SLOTS else ""
        rows.append((slot, path.name, _header(path), "; ".join(n for n in (hints, notes) if n)))
    for slot, paths in sorted(ts.alternates.items()):
        for path in paths:
            rows.append((f"({slot})", path.name, _header(path), f"alternate {slot}: not loaded"))
    for path in ts.unrecognised:
        rows.append(("—", path.name, _header(path), "name matches no slot: not loaded"))
    return rows


class TextureSetDialog(QDialog):
    """Lists a detected texture set; Open loads it, Cancel keeps the current document."""

    def __init__(self, ts: TextureSet, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle(f"Open texture set — {ts.name}")
        layout = QVBoxLayout(self)
        summary = QLabel(
            f"<b>{ts.name}</b> in {ts.folder}: {len(ts.maps)} maps"
            + (f", {len(ts.unrecognised)} not recognised" if ts.unrecognised else "")
        )
        summary.setWordWrap(True)
        layout.addWidget(summary)
        self.table = QTreeWidget()
        self.table.setRootIsDecorated(False)
        self.table.setHeaderLabels(list(COLUMNS))
        for row in texture_set_rows(ts):
            item = QTreeWidgetItem(list(row))
            item.setToolTip(1, str(ts.folder / row[1]))
            self.table.addTopLevelItem(item)
        for column in range(len(COLUMNS) - 1):
            self.table.resizeColumnToContents(column)
        layout.addWidget(self.table, 1)
        note = QLabel(
            "A file in the wrong slot or missing? Rename it to end in the slot's name "
            "(e.g. <i>_roughness</i>, <i>_normal_gl</i>) and open the set again."
        )
        note.setObjectName("hint")
        note.setWordWrap(True)
        layout.addWidget(note)
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Open | QDialogButtonBox.StandardButton.Cancel
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        self.resize(760, 380)
