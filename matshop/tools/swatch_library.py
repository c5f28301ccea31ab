"""The saved swatch library: named materials to paint, kept in one JSON file.

The file (``matshop.paint.save_swatches`` format) lives where the editor's
settings say, so every document shares it. Every change is written at once
(a library is a few kilobytes); a file that cannot be read leaves the
library empty and says why in ``error``, and is not overwritten until the
user adds a swatch.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QObject, Signal

from ..errors import MatshopError
from ..paint import Swatch, load_swatches, save_swatches


class SwatchLibrary(QObject):
    """An ordered list of swatches persisted in ``path``."""

    changed = Signal()

    def __init__(self, path: Path) -> None:
        super().__init__()
        self.path = Path(path)
        self.swatches: list[Swatch] = []
        #: why the last load or save failed ("" when it did not)
        self.error = ""
        self.load()

    def load(self) -> None:
        self.swatches, self.error = [], ""
        if self.path.is_file():
            try:
                self.swatches = load_swatches(self.path)
            except MatshopError as exc:
                self.error = str(exc)
        self.changed.emit()

    def _save(self) -> None:
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            save_swatches(self.path, self.swatches)
            self.error = ""
        except (MatshopError, OSError) as exc:
            self.error = f"cannot save the swatch library {self.path}: {exc}"
        self.changed.emit()

    def unique_name(self, name: str) -> str:
        """``name``, or ``name 2``, ``name 3``... if the library has it already."""
        taken = {s.name for s in self.swatches}
        candidate, number = name, 2
        while candidate in taken:
            candidate, number = f"{name} {number}", number + 1
        return candidate

    def add(self, swatch: Swatch) -> int:
        """Append ``swatch`` (renamed if its name is taken); returns its index."""
        self.swatches.append(Swatch(self.unique_name(swatch.name), dict(swatch.values)))
        self._save()
        return len(self.swatches) - 1

    def remove(self, index: int) -> None:
        if 0 <= index < len(self.swatches):
            del self.swatches[index]
            self._save()
