"""The files File > Export will write, listed before anything is written.

:func:`plan_export` works out, as :func:`~matshop.export.core.export_material`
does, which outputs of a preset apply to the material (an optional output is
skipped when the material lacks its parameters), the file name of each (from
the preset's template and the material's name), what it holds, its format and
bit depth, and whether a file of that name already exists in the folder (it
would be replaced). :class:`ExportDialog` shows those lines with OK/Cancel,
a checkbox per optional extra (USD: :func:`plan_usd`) whose lines join the
list while it is checked, and the size to write: the material's own or a
smaller power of two (:func:`smaller_sizes`), with the option to keep normal
variance in roughness, enabled only when a smaller size is chosen (the
command line's ``--size N --keep-variance``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QVBoxLayout,
    QWidget,
)

from ..export.core import describe_output, file_safe_name
from ..export.pack import is_written
from ..export.presets import Preset, load_preset
from ..material import Material

#: Ends the line of a file that exists and would be replaced.
REPLACES = "exists, will be replaced"
#: the option's words, as ``matshop export --help`` says them for ``--keep-variance``
KEEP_VARIANCE_LABEL = "Keep normal variance in roughness when downsizing"
#: the smallest size offered
SMALLEST_SIZE = 16


@dataclass(frozen=True)
class ExportChoices:
    """What the user chose in the export dialog."""

    extras: dict[str, bool]  #: each extra option (e.g. ``usd``): checked or not
    size: int | None = None  #: the longest side to write (``--size``); None: as it is
    keep_variance: bool = False  #: ``--keep-variance`` (only with a smaller ``size``)


def smaller_sizes(size_hw: tuple[int, int]) -> list[int]:
    """The powers of two below the material's longest side, largest first, down to
    :data:`SMALLEST_SIZE` (what ``--size N`` accepts as a reduction)."""
    longest = max(size_hw)
    sizes = []
    size = 1 << ((longest - 1).bit_length() - 1) if longest > 1 else 0  # the largest below
    while size >= SMALLEST_SIZE:
        sizes.append(size)
        size //= 2
    return sizes


@dataclass(frozen=True)
class PlannedFile:
    """One file an export will write."""

    name: str
    contents: str  #: e.g. ``R ao, G roughness, B metallic`` or ``base_color (srgb)``
    encoding: str  #: format and bit depth, e.g. ``png uint8``
    exists: bool  #: a file of this name is in the folder already

    def line(self) -> str:
        """``T_BaseColor.png: base_color (srgb) [png uint8]`` (+ ``, exists, ...``)."""
        mark = f" — {REPLACES}" if self.exists else ""
        return f"{self.name}: {self.contents} [{self.encoding}]{mark}"


def export_name(material: Material) -> str:
    """The ``{material}`` of the file names (the material's name made file-safe)."""
    return file_safe_name(material.name)


def plan_export(material: Material, preset: Preset | str, folder: str | Path) -> list[PlannedFile]:
    """The texture files ``export_material(material, preset, folder)`` writes, in order."""
    if isinstance(preset, str):
        preset = load_preset(preset)
    folder = Path(folder)
    name = export_name(material)
    plan = []
    for output in preset.outputs:
        if not is_written(material, output):
            continue
        file_name = output.file_for(name, preset.name)
        plan.append(
            PlannedFile(
                file_name,
                describe_output(output),
                f"{output.extension} {output.bit_depth}",
                (folder / file_name).exists(),
            )
        )
    return plan


def plan_usd(material: Material, folder: str | Path) -> list[PlannedFile]:
    """The ``.usda`` and ``.usdz`` that ``export_material(..., usdz=True)`` adds."""
    name = export_name(material)
    contents = {
        "usda": "mesh, UsdPreviewSurface and MaterialX open_pbr_surface",
        "usdz": "the .usda and its textures, packaged",
    }
    return [
        PlannedFile(f"{name}.{ext}", what, ext, (Path(folder) / f"{name}.{ext}").exists())
        for ext, what in contents.items()
    ]


class ExportDialog(QDialog):
    """The files to write, one line each; OK exports, Cancel writes nothing."""

    def __init__(
        self,
        lines: list[str],
        parent: QWidget | None = None,
        *,
        extras: dict[str, tuple[str, list[str]]] | None = None,
        size_hw: tuple[int, int] | None = None,
        keep_variance: bool = False,
    ) -> None:
        """``extras``: option name -> (checkbox label, the lines it adds); ``size_hw``: the
        material's (height, width), which offers smaller sizes; ``keep_variance``: the
        option's initial state (the preset's ``keepVariance``)."""
        super().__init__(parent)
        self.setWindowTitle("Export")
        layout = QVBoxLayout(self)
        self.summary = QLabel()
        self.summary.setWordWrap(True)
        layout.addWidget(self.summary)
        self.list = QListWidget()
        for line in lines:
            self._add(line)
        layout.addWidget(self.list, 1)
        self.extras: dict[str, QCheckBox] = {}
        for option, (label, extra_lines) in (extras or {}).items():
            box = QCheckBox(label)
            box.toggled.connect(lambda on, more=extra_lines: self._show_extra(more, on))
            layout.addWidget(box)
            self.extras[option] = box
        self.size = QComboBox()
        self.keep_variance = QCheckBox(KEEP_VARIANCE_LABEL)
        self.keep_variance.setChecked(keep_variance)
        if size_hw is not None:
            height, width = size_hw
            self.size.addItem(f"As it is ({width}x{height})", None)
            for side in smaller_sizes(size_hw):
                self.size.addItem(f"{side} (longest side)", side)
            form = QFormLayout()
            form.addRow("Size:", self.size)
            layout.addLayout(form)
            layout.addWidget(self.keep_variance)
        self.size.currentIndexChanged.connect(self._size_changed)
        self._size_changed()
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel
        )
        self.ok = buttons.button(QDialogButtonBox.StandardButton.Ok)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        self.resize(640, 320)
        self._refresh()

    def _add(self, line: str) -> None:
        item = QListWidgetItem(line)
        if line.endswith(REPLACES):
            font = item.font()
            font.setBold(True)
            item.setFont(font)
        self.list.addItem(item)

    def _refresh(self) -> None:
        """The count and the replacement warning, for the lines listed now."""
        lines = [self.list.item(i).text() for i in range(self.list.count())]
        replaced = sum(line.endswith(REPLACES) for line in lines)
        text = f"These {len(lines)} files will be written:"
        if replaced:
            verb = "exists" if replaced == 1 else "exist"
            text += f" <b>{replaced} already {verb} and will be replaced.</b>"
        self.summary.setText(text)
        self.ok.setText("Replace and export" if replaced else "Export")

    def _show_extra(self, lines: list[str], shown: bool) -> None:
        for line in lines:
            if shown:
                self._add(line)
            else:
                for item in self.list.findItems(line, Qt.MatchFlag.MatchExactly):
                    self.list.takeItem(self.list.row(item))
        self._refresh()

    def _size_changed(self) -> None:
        # only a reduction averages normal detail away
        self.keep_variance.setEnabled(self.size.currentData() is not None)

    def chosen(self) -> ExportChoices:
        """The extras checked, the size and whether to keep the normal variance."""
        size = self.size.currentData()
        return ExportChoices(
            {option: box.isChecked() for option, box in self.extras.items()},
            size,
            size is not None and self.keep_variance.isChecked(),
        )
