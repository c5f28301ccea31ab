"""Every modal question the editor asks, in one object tests can replace.

The window never calls QMessageBox or QFileDialog directly: it asks its
``prompts``. Tests swap in an object answering from a script (or monkeypatch
QMessageBox, which these methods use), so no test ever blocks on a dialog.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Literal

from PySide6.QtWidgets import QDialog, QFileDialog, QInputDialog, QMessageBox, QWidget

from ..io.textureset import TextureSet

if TYPE_CHECKING:
    from .export_dialog import ExportChoices

SaveAnswer = Literal["save", "discard", "cancel"]

IMAGE_FILTER = "*.png *.jpg *.jpeg *.tga *.tif *.tiff *.exr *.hdr *.bmp"
MESH_FILTER = "Meshes (*.obj *.gltf *.glb);;All files (*)"
ENVIRONMENT_FILTER = "Equirectangular HDR (*.hdr *.exr);;All files (*)"
RECIPE_FILTER = "Recipes (*.toml);;All files (*)"
OPEN_FILTER = (
    f"Projects and textures (*.matshop {IMAGE_FILTER});;matshop projects (*.matshop);;"
    f"Texture maps ({IMAGE_FILTER});;All files (*)"
)


class Prompts:
    """Message boxes and file dialogs parented to the main window."""

    def __init__(self, parent: QWidget) -> None:
        self.parent = parent

    def error(self, title: str, text: str) -> None:
        """A one-line user error (a MatshopError's text); never a traceback."""
        QMessageBox.critical(self.parent, title, text)

    def info(self, title: str, text: str) -> None:
        QMessageBox.information(self.parent, title, text)

    def ask_save_changes(self, name: str) -> SaveAnswer:
        buttons = QMessageBox.StandardButton
        answer = QMessageBox.question(
            self.parent,
            "Unsaved changes",
            f"Save the changes to {name} before closing it?",
            buttons.Save | buttons.Discard | buttons.Cancel,
            buttons.Save,
        )
        if answer == buttons.Save:
            return "save"
        return "discard" if answer == buttons.Discard else "cancel"

    def ask_restore(self, recovery: Path) -> bool:
        buttons = QMessageBox.StandardButton
        answer = QMessageBox.question(
            self.parent,
            "Restore autosave?",
            "matshop was closed without saving this material. Restore the autosaved "
            f"version from {recovery.name}? (No discards it.)",
            buttons.Yes | buttons.No,
            buttons.Yes,
        )
        return answer == buttons.Yes

    def review_texture_set(self, ts: TextureSet) -> TextureSet | None:
        """Show what was detected in a texture set and let the user correct it.

        The (possibly corrected) set to open, or None when the user cancels.
        """
        from .textureset_dialog import TextureSetDialog  # only built when asked

        dialog = TextureSetDialog(ts, self.parent)
        try:
            if dialog.exec() != QDialog.DialogCode.Accepted:
                return None
            return dialog.texture_set
        finally:
            dialog.deleteLater()

    def choose_material(self, folder: str, choices: list[str]) -> str | None:
        """Which of the materials a folder holds to open; None when the user cancels."""
        name, ok = QInputDialog.getItem(
            self.parent,
            "Several materials",
            f"{Path(folder).name} holds {len(choices)} materials. Open which?",
            choices,
            0,
            False,
        )
        return name if ok and name else None

    def open_file(self, start: str = "") -> Path | None:
        path, _ = QFileDialog.getOpenFileName(self.parent, "Open", start, OPEN_FILTER)
        return Path(path) if path else None

    def open_image(self, start: str = "") -> Path | None:
        path, _ = QFileDialog.getOpenFileName(
            self.parent, "Import image", start, f"Images ({IMAGE_FILTER});;All files (*)"
        )
        return Path(path) if path else None

    def choose_image_use(self, name: str, choices: list[str]) -> str | None:
        """What to make of image ``name``: one of ``choices``; None when the user cancels."""
        choice, ok = QInputDialog.getItem(
            self.parent, "Import image", f"Use {name} as:", choices, 0, False
        )
        return choice if ok and choice else None

    def ask_height_px(self, name: str, default: float) -> float | None:
        """How many texel widths of displacement height image ``name``'s full range spans."""
        value, ok = QInputDialog.getDouble(
            self.parent,
            "Normals from a height image",
            f"Displacement of {name}'s full range (black to white), in texels:",
            default,
            0.01,
            10000.0,
            2,
        )
        return value if ok else None

    def open_mesh(self, start: str = "") -> Path | None:
        path, _ = QFileDialog.getOpenFileName(self.parent, "Open mesh", start, MESH_FILTER)
        return Path(path) if path else None

    def open_environment(self, start: str = "") -> Path | None:
        """An equirectangular .hdr/.exr to light the views with."""
        path, _ = QFileDialog.getOpenFileName(
            self.parent, "Lighting environment", start, ENVIRONMENT_FILTER
        )
        return Path(path) if path else None

    def open_recipe(self, start: str = "") -> Path | None:
        path, _ = QFileDialog.getOpenFileName(self.parent, "Recipe", start, RECIPE_FILTER)
        return Path(path) if path else None

    def open_folder(self, start: str = "") -> Path | None:
        path = QFileDialog.getExistingDirectory(self.parent, "Open texture set folder", start)
        return Path(path) if path else None

    def save_file(self, suggested: str) -> Path | None:
        path, _ = QFileDialog.getSaveFileName(
            self.parent, "Save project", suggested, "matshop projects (*.matshop)"
        )
        if not path:
            return None
        path = Path(path)
        return path if path.suffix == ".matshop" else path.with_name(path.name + ".matshop")

    def choose_preset(self, names: list[str]) -> str | None:
        if not names:
            return None
        name, ok = QInputDialog.getItem(self.parent, "Export", "Preset:", names, 0, False)
        return name if ok else None

    def export_folder(self, start: str = "") -> Path | None:
        path = QFileDialog.getExistingDirectory(self.parent, "Export into folder", start)
        return Path(path) if path else None

    def confirm_export(
        self,
        lines: list[str],
        extras: dict[str, tuple[str, list[str]]] | None = None,
        *,
        size_hw: tuple[int, int] | None = None,
        keep_variance: bool = False,
    ) -> ExportChoices | None:
        """List the files an export will write (existing ones marked), with a checkbox
        per extra (name -> (label, its lines)) and, given the material's ``size_hw``, the
        size to write and whether to keep normal variance (initially ``keep_variance``);
        None: cancelled, else what was chosen."""
        from .export_dialog import ExportDialog  # only built when asked

        dialog = ExportDialog(
            lines, self.parent, extras=extras, size_hw=size_hw, keep_variance=keep_variance
        )
        try:
            accepted = dialog.exec() == QDialog.DialogCode.Accepted
            return dialog.chosen() if accepted else None
        finally:
            dialog.deleteLater()
