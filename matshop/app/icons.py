"""Icons from ``resources/icons`` (SVG line icons drawn for the dark theme).

A missing file gives an empty icon rather than an error: actions keep their
text, so an installation without the resources folder still works.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

from PySide6.QtGui import QIcon

ICON_DIR = Path(__file__).resolve().parents[2] / "resources" / "icons"


@cache
def icon(name: str) -> QIcon:
    path = ICON_DIR / f"{name}.svg"
    return QIcon(str(path)) if path.is_file() else QIcon()
