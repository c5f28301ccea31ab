"""What was detected in a texture set, shown (and correctable) before it is loaded.

One row per file the detection looked at: the maps it will load (which
parameter slot, the file, its size and depth from the header, hints such as
a normal map's convention), the alternates it will not use (a DirectX normal
beside an OpenGL one), the files it recognised but does not load (masks,
previews, a shallower duplicate: each with the reason) and the images whose
names matched no slot.

Every row has a *Load as* combo box ("not loaded" and every known slot), so
the user can reassign a file detected in the wrong slot, load an unrecognised
or alternate file, or drop one; *Add file...* brings in a map from anywhere
(a shared metallic map in another folder); the *Normal map* control overrides
the convention the loader would decide. Open builds the corrected set with
:func:`~matshop.io.textureset.with_slot` and checks it
(:func:`~matshop.io.textureset.check_texture_set`); a problem (the same slot
chosen twice, no maps left) is shown as one line and the dialog stays open.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from ..errors import MatshopError
from ..io.images import probe_image
from ..io.map_names import parse_map_name
from ..io.textureset import SLOTS, TextureSet, check_texture_set, known_slots, with_slot

#: Columns of the table.
COLUMNS = ("Load as", "Detected", "File", "Image", "Notes")
#: The combo box entry that leaves a file out.
NOT_LOADED = "not loaded"
#: The normal-map control's entries: (label, convention or None for the loader's choice)
NORMAL_CHOICES = (
    ("Automatic: file name, else a confident guess, else OpenGL", None),
    ("OpenGL (+Y: glTF, Blender, Unity, Godot, MaterialX)", "opengl"),
    ("DirectX (-Y: Unreal, some Substance presets)", "directx"),
)
IMAGE_FILES = "Images (*.png *.jpg *.jpeg *.tga *.tif *.tiff *.exr *.hdr *.bmp);;All files (*)"


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
    for path, why, slot in ts.unloaded():
        if slot is not None:
            rows.append((f"({slot})", path.name, _header(path), f"alternate {slot}: not loaded"))
        else:
            rows.append(("—", path.name, _header(path), f"not loaded: {why}"))
    return rows


def _files(ts: TextureSet) -> list[tuple[Path, str | None]]:
    """(file, slot it is loaded as or None) in the order of :func:`texture_set_rows`."""
    files: list[tuple[Path, str | None]] = [(p, s) for s, p in sorted(ts.maps.items())]
    files += [(path, None) for path, _, _ in ts.unloaded()]
    return files


def corrected_set(
    ts: TextureSet, choices: dict[Path, str | None], normal_convention: str | None = None
) -> TextureSet:
    """``ts`` with each file loaded as ``choices[file]`` (None: not loaded).

    Files that ``ts`` does not list (added by the user) may be chosen too.
    ``normal_convention`` overrides the loader's decision (None: keep it).

    Raises MatshopError (one line) when a slot is chosen twice or the result
    cannot be loaded (no maps, a missing file).
    """
    chosen: dict[str, Path] = {}
    for path, slot in choices.items():
        if slot is None:
            continue
        if slot in chosen:
            raise MatshopError(
                f"{slot} is chosen for both {chosen[slot].name} and {path.name}; "
                "pick one (set the other to 'not loaded')",
                ts.folder,
            )
        chosen[slot] = path
    original = {path: slot for slot, path in ts.maps.items()}
    result = ts
    for slot, path in ts.maps.items():  # empty the slots whose file goes elsewhere
        if choices.get(path, slot) != slot:
            result = with_slot(result, slot, None)
    for path, slot in choices.items():
        if slot is not None and original.get(path) != slot:
            result = with_slot(result, slot, path)
    check_texture_set(result)
    return replace(result, normal_convention=normal_convention)


class TextureSetDialog(QDialog):
    """Lists a detected texture set; each file's slot can be changed, files added.

    Open accepts with the corrected set in :attr:`texture_set`; Cancel keeps
    the current document. :attr:`choose_file` asks for a file to add (a file
    dialog; tests replace it).
    """

    def __init__(self, ts: TextureSet, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.detected = ts
        self.texture_set: TextureSet | None = None  #: the corrected set, once accepted
        self.choose_file: Callable[[], Path | None] = self._file_dialog
        self.setWindowTitle(f"Open texture set — {ts.name}")
        layout = QVBoxLayout(self)
        unused = len(ts.unrecognised) + len(ts.not_used)
        summary = QLabel(
            f"<b>{ts.name}</b> in {ts.folder}: {len(ts.maps)} maps"
            + (f", {unused} other files not loaded" if unused else "")
            + "".join(f"<br>{note}" for note in ts.notes)
        )
        summary.setWordWrap(True)
        layout.addWidget(summary)
        self.table = QTreeWidget()
        self.table.setRootIsDecorated(False)
        self.table.setHeaderLabels(list(COLUMNS))
        #: file -> its "Load as" combo box, in row order
        self.combos: dict[Path, QComboBox] = {}
        for (path, slot), row in zip(_files(ts), texture_set_rows(ts), strict=True):
            self._add_row(path, slot, row)
        for column in range(len(COLUMNS) - 1):
            self.table.resizeColumnToContents(column)
        layout.addWidget(self.table, 1)
        row = QHBoxLayout()
        self.add_button = QPushButton("Add file…")
        self.add_button.setToolTip("Load a map from another file (e.g. a shared metallic map)")
        self.add_button.clicked.connect(self._add_clicked)
        row.addWidget(self.add_button)
        row.addStretch(1)
        row.addWidget(QLabel("Normal map:"))
        self.normal_convention = QComboBox()
        for label, convention in NORMAL_CHOICES:
            self.normal_convention.addItem(label, convention)
        named = ts.hints.get("normal", {}).get("convention")
        self.normal_convention.setToolTip(
            "Green channel convention of the normal map"
            + (f"; its file name says {named}" if named else "; its file name does not say")
        )
        if ts.normal_convention is not None:
            self.normal_convention.setCurrentIndex(
                self.normal_convention.findData(ts.normal_convention)
            )
        row.addWidget(self.normal_convention)
        layout.addLayout(row)
        note = QLabel(
            "A file in the wrong slot or missing? Pick what it is under <i>Load as</i>; "
            "<i>not loaded</i> leaves it out; <i>Add file…</i> brings in one from elsewhere."
        )
        note.setObjectName("hint")
        note.setWordWrap(True)
        layout.addWidget(note)
        self.error = QLabel()
        self.error.setObjectName("error")
        self.error.setStyleSheet("color: #e06c6c;")
        self.error.setWordWrap(True)
        self.error.hide()
        layout.addWidget(self.error)
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Open | QDialogButtonBox.StandardButton.Cancel
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        self.resize(860, 420)

    def _add_row(self, path: Path, slot: str | None, row: tuple[str, str, str, str]) -> None:
        item = QTreeWidgetItem(["", *row])
        item.setToolTip(2, str(path))
        self.table.addTopLevelItem(item)
        combo = QComboBox()
        combo.addItem(NOT_LOADED, None)
        for known in known_slots():
            combo.addItem(known, known)
        combo.setCurrentIndex(0 if slot is None else combo.findData(slot))
        combo.setToolTip(f"Which parameter {path.name} is loaded as")
        combo.currentIndexChanged.connect(self._changed)
        self.table.setItemWidget(item, 0, combo)
        self.combos[path] = combo

    def add_file(self, path: Path) -> None:
        """List ``path`` too, loaded as the slot its name suggests if that slot is free."""
        path = Path(path)
        if path in self.combos:
            return
        parsed = parse_map_name(path)
        suggested = parsed.slot if parsed is not None and not parsed.extra else None
        if suggested in self.choices().values():
            suggested = None
        hint = f"added; its name suggests {parsed.slot}" if parsed else "added"
        self._add_row(path, suggested, (suggested or "—", path.name, _header(path), hint))
        self._changed()

    def _add_clicked(self) -> None:
        path = self.choose_file()
        if path is not None:
            self.add_file(path)

    def _file_dialog(self) -> Path | None:
        name, _ = QFileDialog.getOpenFileName(
            self, "Add a map", str(self.detected.folder), IMAGE_FILES
        )
        return Path(name) if name else None

    def choices(self) -> dict[Path, str | None]:
        """file -> the slot chosen for it (None: not loaded)."""
        return {path: combo.currentData() for path, combo in self.combos.items()}

    def set_choice(self, file_name: str, slot: str | None) -> None:
        """Choose ``slot`` (None: not loaded) for the file named ``file_name``."""
        for path, combo in self.combos.items():
            if path.name == file_name:
                combo.setCurrentIndex(combo.findData(slot) if slot else 0)
                return
        raise KeyError(file_name)

    def corrected(self) -> TextureSet:
        """The set as the controls say; MatshopError (one line) when it cannot load."""
        return corrected_set(self.detected, self.choices(), self.normal_convention.currentData())

    def _changed(self) -> None:
        self.error.hide()

    def accept(self) -> None:
        """Open: keep the dialog up with the one-line problem when the choice is not loadable."""
        try:
            self.texture_set = self.corrected()
        except MatshopError as exc:
            self.error.setText(str(exc))
            self.error.show()
            return
        super().accept()
