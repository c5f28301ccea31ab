"""Tip and stencil images in the editor: ask for a file, read it on a worker thread, use it.

The tool panel's Load buttons ask for these; a file that cannot be read is
one line in the status bar, and the brush stays as it was.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

from ..errors import MatshopError
from ..paint import load_stencil, load_tip
from .work import run_off_ui

if TYPE_CHECKING:
    from .window_parts import EditorWindow

#: a loaded stencil covers this much of the canvas's shorter side
STENCIL_FIT = 0.8

T = TypeVar("T")


def _read(
    window: EditorWindow, path: Path | None, loader: Callable[[Path], T]
) -> tuple[Path, T] | None:
    """Ask for an image (unless ``path``) and read it with ``loader`` on a worker; ``None``
    when the user cancels or the file cannot be read (said in the status bar)."""
    path = path or window.prompts.open_image()
    if path is None:
        return None
    try:
        return path, run_off_ui(window.canvas, f"Reading {path.name}", lambda work: loader(path))
    except MatshopError as exc:
        window.show_message(str(exc))
        return None


def choose_tip(window: EditorWindow, path: Path | None = None) -> bool:
    """Ask for an image (unless ``path``) and stamp it as the brush's tip."""
    read = _read(window, path, load_tip)
    if read is None:
        return False
    path, tip = read
    window.brush_settings.tips.set_image(tip)
    window.show_message(f"Tip: {path.name} ({tip.image.shape[1]}x{tip.image.shape[0]})")
    return True


def choose_stencil(window: EditorWindow, path: Path | None = None) -> bool:
    """Ask for an image (unless ``path``) and lay it over the middle of the canvas."""
    read = _read(window, path, load_stencil)
    if read is None:
        return False
    path, stencil = read
    canvas = window.canvas
    height, width = stencil.image.shape
    scale = STENCIL_FIT * min(canvas.width() / width, canvas.height() / height)
    window.brush_settings.stencil.set_image(
        stencil, (canvas.width() / 2.0, canvas.height() / 2.0), scale
    )
    window.show_message(
        f"Stencil: {path.name} — paint passes where it is white; Place to move, scale, turn it"
    )
    return True
