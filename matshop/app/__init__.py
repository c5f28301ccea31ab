"""The desktop editor (Qt): main window, panels, menus, files, settings.

``from matshop.app import MainWindow`` imports Qt; importing the package
itself does not.
"""

from __future__ import annotations

from typing import Any

__all__ = ["MainWindow"]


def __getattr__(name: str) -> Any:
    if name == "MainWindow":
        from .main_window import MainWindow

        return MainWindow
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
