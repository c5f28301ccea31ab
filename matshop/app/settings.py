"""What the editor remembers between runs (QSettings): recent files, window layout, autosave.

Tests pass their own QSettings (an INI file in a temporary folder) so they
never read or write the user's settings.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from PySide6.QtCore import QByteArray, QSettings, QStandardPaths

MAX_RECENT = 10
DEFAULT_AUTOSAVE_S = 60


def default_settings() -> QSettings:
    return QSettings("matshop", "matshop")


class AppSettings:
    """Typed access to the editor's QSettings."""

    def __init__(self, qsettings: QSettings | None = None) -> None:
        self.q = qsettings if qsettings is not None else default_settings()

    # -- recent files ---------------------------------------------------------

    def recent_files(self) -> list[Path]:
        value = self.q.value("recent_files", [])
        if isinstance(value, str):  # QSettings returns a lone entry as a string
            value = [value]
        return [Path(v) for v in value or []]

    def add_recent(self, path: Path) -> None:
        path = Path(path).resolve()
        files = [path] + [p for p in self.recent_files() if p != path]
        self.q.setValue("recent_files", [str(p) for p in files[:MAX_RECENT]])

    def clear_recent(self) -> None:
        self.q.setValue("recent_files", [])

    # -- window ------------------------------------------------------------------

    def geometry(self) -> tuple[QByteArray | None, QByteArray | None]:
        return self.q.value("window/geometry"), self.q.value("window/state")

    def save_geometry(self, geometry: QByteArray, state: QByteArray) -> None:
        self.q.setValue("window/geometry", geometry)
        self.q.setValue("window/state", state)

    # -- lighting ------------------------------------------------------------------

    def lighting(self) -> Any:
        """The last lighting choice (EnvironmentChoice.to_json), None if none or unreadable."""
        text = self.q.value("view/lighting")
        try:
            return json.loads(str(text)) if text else None
        except ValueError:
            return None

    def save_lighting(self, data: dict[str, Any]) -> None:
        self.q.setValue("view/lighting", json.dumps(data))

    # -- autosave ------------------------------------------------------------------

    def autosave_seconds(self) -> int:
        try:
            return max(int(self.q.value("autosave_seconds", DEFAULT_AUTOSAVE_S)), 5)
        except (TypeError, ValueError):
            return DEFAULT_AUTOSAVE_S

    def swatch_library_path(self) -> Path:
        """The shared swatch library (JSON); ``swatch_library`` in the settings overrides it."""
        configured = self.q.value("swatch_library")
        if configured:
            return Path(str(configured))
        return self._data_dir() / "swatches.json"

    def _data_dir(self) -> Path:
        base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
        return Path(base or Path.home() / ".matshop")

    def recovery_dir(self) -> Path:
        """Where texture sets that were never saved as a project autosave."""
        configured = self.q.value("recovery_dir")
        if configured:
            return Path(str(configured))
        base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
        return Path(base or Path.home() / ".matshop") / "recovery"
