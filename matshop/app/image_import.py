"""Images as layer content in the editor: Layer > Import Image, and an image dropped on
the canvas, both asking what to make of it (:meth:`LayerCommands.image_uses`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..image_content import HEIGHT_PX
from .layer_commands import HEIGHT_USE

if TYPE_CHECKING:
    from .window_parts import EditorWindow

#: the dropped-image choice that keeps what a drop always did: open it as a material
OPEN_INSTEAD = "Open it as a new material"
IMAGE_SUFFIXES = frozenset(
    (".png", ".jpg", ".jpeg", ".tga", ".tif", ".tiff", ".exr", ".hdr", ".bmp")
)


def import_image(window: EditorWindow, path: Path | None = None, *, dropped: bool = False) -> bool:
    """Ask for an image (unless ``path``) and what it becomes, then make it so (one undo step).

    A dropped image may also be opened as a new material, as a drop did before.
    """
    if path is None:
        path = window.prompts.open_image()
        if path is None:
            return False
    uses = window.layer_commands.image_uses()
    labels = [label for _, label in uses]
    if dropped:
        labels.insert(0, OPEN_INSTEAD)
    choice = window.prompts.choose_image_use(path.name, labels)
    if choice is None:
        return False
    if choice == OPEN_INSTEAD:
        return window.open_path(path)
    use = next(use for use, label in uses if label == choice)
    height_px = None
    if use == HEIGHT_USE:
        height_px = window.prompts.ask_height_px(path.name, HEIGHT_PX)
        if height_px is None:
            return False
    return window.layer_commands.import_image(path, use, height_px=height_px) is not None


def is_image(path: Path) -> bool:
    return path.is_file() and path.suffix.lower() in IMAGE_SUFFIXES
