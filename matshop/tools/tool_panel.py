"""The tool panel: brush sliders, the mirror toggles, the pen's pressure curve and the
swatch editor.

The swatch editor has one row per parameter of the document: a check box
(does the brush paint it?) and an editor suited to the parameter: a color
button for colors, a slider for scalars, two tilt sliders for normals; wide
parameters (sampled distributions, profiles) are set with the eyedropper.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (
    QCheckBox,
    QColorDialog,
    QDoubleSpinBox,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from ..material import Parameter, Schema
from .curve_editor import CurveEditor
from .curve_points import CurvePoints
from .settings import BRUSH_SETTINGS, PRESSURE_TARGETS, BrushSettings, SwatchModel, short_label
from .swatch_library_panel import SwatchLibraryPanel
from .tip_panel import StencilPanel, TipPanel
from .widgets import (
    ColorButton,
    FloatSlider,
    discard_widget,
    file_codes_to_qcolor,
    qcolor_to_file_codes,
)

if TYPE_CHECKING:
    from .swatch_library import SwatchLibrary

ColorPicker = Callable[[QColor, QWidget], QColor | None]


def _ask_color(initial: QColor, parent: QWidget) -> QColor | None:
    color = QColorDialog.getColor(initial, parent, "Swatch color")
    return color if color.isValid() else None


class PressurePanel(QWidget):
    """What pen pressure drives (size, opacity, flow check boxes) and its curve.

    The curve is edited like the curves dialog's (click adds a point, drag moves
    one, double-click or dragging it off removes it); x is the pen's pressure, y
    the factor on each checked setting. A mouse presses at full pressure.
    """

    def __init__(self, settings: BrushSettings, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.settings = settings
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 4, 0, 0)
        layout.setSpacing(2)
        heading = QLabel("Pen pressure drives:")
        heading.setToolTip("A tablet pen's pressure drives the checked settings through the curve")
        layout.addWidget(heading)
        row = QHBoxLayout()
        self.targets: dict[str, QCheckBox] = {}
        for target in PRESSURE_TARGETS:
            check = QCheckBox(target.capitalize())
            check.setToolTip(f"Pen pressure scales the brush's {target} by the curve")
            check.toggled.connect(lambda on, t=target: settings.set_pressure_target(t, on))
            row.addWidget(check)
            self.targets[target] = check
        row.addStretch(1)
        layout.addLayout(row)
        self.model = CurvePoints(settings.pressure_curve.points)
        self.editor = CurveEditor(self.model, diagonal=False)
        self.editor.setToolTip("Pressure (x) to factor (y)")
        self.editor.setFixedHeight(150)
        self.model.changed.connect(lambda: settings.set_pressure_curve(self.model.points))
        layout.addWidget(self.editor)
        settings.changed.connect(self._sync)
        self._sync()

    def _sync(self) -> None:
        for target, check in self.targets.items():
            check.blockSignals(True)
            check.setChecked(self.settings.pressure_targets[target])
            check.blockSignals(False)
        points = self.settings.pressure_curve.points
        if points != self.model.points and self.model.dragging is None:
            self.model.set_points(points)
            self.editor.view.redraw()


class BrushPanel(QGroupBox):
    """Size, hardness, spacing, opacity and flow sliders; mirror X / Y check boxes; the
    pen pressure's targets and curve."""

    def __init__(self, settings: BrushSettings, parent: QWidget | None = None) -> None:
        super().__init__("Brush", parent)
        self.settings = settings
        layout = QVBoxLayout(self)
        layout.setSpacing(2)
        self.sliders: dict[str, FloatSlider] = {}
        for spec in BRUSH_SETTINGS:
            slider = FloatSlider(
                spec.label,
                spec.lo,
                spec.hi,
                settings.values[spec.name],
                log=spec.log,
                decimals=1 if spec.name == "radius_px" else 2,
                unit=spec.unit,
                tip=spec.tip,
            )
            slider.edited.connect(lambda value, name=spec.name: settings.set(name, value))
            layout.addWidget(slider)
            self.sliders[spec.name] = slider
        mirrors = QHBoxLayout()
        self.mirrors: dict[str, QCheckBox] = {}
        for axis, label, tip in (
            ("x", "Mirror X", "Also paint the mirror image across the vertical centre line"),
            ("y", "Mirror Y", "Also paint the mirror image across the horizontal centre line"),
        ):
            check = QCheckBox(label)
            check.setToolTip(f"{tip} (Shift+{axis.upper()})")
            check.toggled.connect(lambda on, axis=axis: settings.set_mirror(axis, on))
            mirrors.addWidget(check)
            self.mirrors[axis] = check
        layout.addLayout(mirrors)
        layout.addLayout(self._build_centre())
        #: the document's size in texels (the centre's range and where "middle" is)
        self._extent = (0, 0)
        self.pressure = PressurePanel(settings)
        layout.addWidget(self.pressure)
        settings.changed.connect(self._sync)

    def _build_centre(self) -> QHBoxLayout:
        """Where the mirror lines cross: two texel boxes and a button back to the middle."""
        row = QHBoxLayout()
        row.addWidget(QLabel("Centre"))
        self.centre: dict[str, QDoubleSpinBox] = {}
        for axis in ("x", "y"):
            box = QDoubleSpinBox()
            box.setDecimals(1)
            box.setSingleStep(0.5)
            box.setSuffix(" px")
            box.setKeyboardTracking(False)  # one change per finished number, not per digit
            box.setToolTip(
                f"The mirror line's {axis} in texels (half-texel steps); "
                "or drag the line's round handle at the canvas's texture edge"
            )
            box.valueChanged.connect(self._centre_edited)
            row.addWidget(box, 1)
            self.centre[axis] = box
        self.centre_reset = QPushButton("Middle")
        self.centre_reset.setToolTip("Put the mirror lines back through the texture's middle")
        self.centre_reset.clicked.connect(lambda: self.settings.set_mirror_centre(None))
        row.addWidget(self.centre_reset)
        return row

    def set_extent(self, width: int, height: int) -> None:
        """The document's size: the centre boxes' range (0 without a document)."""
        self._extent = (width, height)
        for axis, size in (("x", width), ("y", height)):
            self.centre[axis].blockSignals(True)
            self.centre[axis].setRange(0.0, float(size))
            self.centre[axis].blockSignals(False)
        self._sync()

    def _centre_edited(self) -> None:
        if self._extent != (0, 0):
            self.settings.set_mirror_centre((self.centre["x"].value(), self.centre["y"].value()))

    def _sync(self) -> None:
        for name, slider in self.sliders.items():
            slider.set_value(self.settings.values[name])
        symmetry = self.settings.symmetry
        for axis, on in (("x", symmetry.x), ("y", symmetry.y)):
            self.mirrors[axis].setChecked(on)
        for axis, value in zip("xy", symmetry.centre_in(*self._extent), strict=True):
            box = self.centre[axis]
            box.blockSignals(True)
            box.setValue(value)
            box.setEnabled(getattr(symmetry, axis) and self._extent != (0, 0))
            box.blockSignals(False)
        self.centre_reset.setEnabled(symmetry.centre is not None)


class SwatchEditor(QGroupBox):
    """Which parameters the brush paints, and their physical values."""

    def __init__(
        self,
        model: SwatchModel,
        parent: QWidget | None = None,
        pick_color: ColorPicker = _ask_color,
    ) -> None:
        super().__init__("Swatch", parent)
        self.model = model
        self.pick_color = pick_color  # replaceable: tests must not open a modal dialog
        self._grid = QGridLayout(self)
        self._grid.setHorizontalSpacing(8)
        self._grid.setVerticalSpacing(4)
        self._grid.setColumnStretch(1, 1)
        self.checks: dict[str, QCheckBox] = {}
        self._syncers: list[Callable[[], None]] = []
        self._empty = QLabel("No document")
        self._empty.setObjectName("hint")
        self._grid.addWidget(self._empty, 0, 0)
        model.changed.connect(self._sync)

    def set_schema(self, schema: Schema | None) -> None:
        while self._grid.count():
            item = self._grid.takeAt(0)
            if item.widget() is not None and item.widget() is not self._empty:
                discard_widget(item.widget())
        self.checks.clear()
        self._syncers.clear()
        if schema is None:
            self._grid.addWidget(self._empty, 0, 0)
            self._empty.show()
            return
        self._empty.hide()
        row = 0
        for param in schema.parameters:
            check = QCheckBox(short_label(param.name))
            check.setToolTip(f"Paint {param.label} ({param.space.name} editing space)")
            check.toggled.connect(lambda on, name=param.name: self.model.set_enabled(name, on))
            self.checks[param.name] = check
            self._grid.addWidget(check, row, 0)
            row = self._add_editor(param, row)
        hint = QLabel("Alt-click with the brush or use the eyedropper (I) to pick all values.")
        hint.setObjectName("hint")
        hint.setWordWrap(True)
        self._grid.addWidget(hint, row, 0, 1, 2)
        self._sync()

    def _add_editor(self, param: Parameter, row: int) -> int:
        """Put the value editor of ``param`` on ``row``; returns the next free row."""
        name = param.name
        space = param.space.name
        if space in ("srgb", "gamma22"):
            button = ColorButton()
            button.clicked.connect(lambda _=False, n=name, b=button: self._choose_color(n, b))
            self._grid.addWidget(button, row, 1)
            self._syncers.append(lambda n=name, b=button: b.set_color(self._qcolor(n)))
            return row + 1
        if space.startswith("normal"):
            return self._add_normal(name, row)
        if param.phys_channels == 1:
            exponent = space.startswith("phong")
            slider = FloatSlider(
                "", 1.0 if exponent else 0.0, 10000.0 if exponent else 1.0, 0.5, log=exponent
            )
            slider.label.hide()
            slider.edited.connect(lambda v, n=name: self.model.set_value(n, (v,)))
            self._grid.addWidget(slider, row, 1)
            self._syncers.append(lambda n=name, s=slider: s.set_value(self.model.values[n][0]))
            return row + 1
        note = QLabel(f"{param.phys_channels} values (eyedropper)")
        note.setObjectName("hint")
        self._grid.addWidget(note, row, 1)
        return row + 1

    def _add_normal(self, name: str, row: int) -> int:
        sliders = []
        for axis, label in ((0, "Tilt X"), (1, "Tilt Y")):
            slider = FloatSlider(label, -0.95, 0.95, 0.0, tip="Normal tilt (unit vector)")
            slider.label.setMinimumWidth(40)
            slider.edited.connect(lambda v, a=axis, n=name: self._tilt(n, a, v))
            self._grid.addWidget(slider, row + axis, 1)
            sliders.append(slider)

        def sync(n: str = name) -> None:
            for axis, slider in enumerate(sliders):
                slider.set_value(self.model.values[n][axis])

        self._syncers.append(sync)
        return row + 2

    def _tilt(self, name: str, axis: int, value: float) -> None:
        vector = list(self.model.values[name])
        vector[axis] = value
        x, y = vector[0], vector[1]
        z = math.sqrt(max(1.0 - x * x - y * y, 1e-4))
        norm = float(np.linalg.norm([x, y, z]))
        self.model.set_value(name, (x / norm, y / norm, z / norm, *vector[3:]))

    def _qcolor(self, name: str) -> QColor:
        return file_codes_to_qcolor(self.model.values[name])

    def _choose_color(self, name: str, button: ColorButton) -> None:
        color = self.pick_color(self._qcolor(name), self)
        if color is not None:
            self.model.set_value(name, qcolor_to_file_codes(color))

    def _sync(self) -> None:
        for name, check in self.checks.items():
            check.blockSignals(True)
            check.setChecked(name in self.model.enabled)
            check.blockSignals(False)
        for sync in self._syncers:
            sync()


class ToolPanel(QWidget):
    """The tool's name and hint, the brush settings, the swatch and the swatch library."""

    def __init__(
        self,
        brush: BrushSettings,
        swatch: SwatchModel,
        parent: QWidget | None = None,
        library: SwatchLibrary | None = None,
    ) -> None:
        super().__init__(parent)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(8, 8, 8, 8)
        layout.setSpacing(8)
        self.title = QLabel("Brush")
        self.title.setObjectName("heading")
        self.hint = QLabel("")
        self.hint.setObjectName("hint")
        self.hint.setWordWrap(True)
        self.brush_panel = BrushPanel(brush)
        self.tip_panel = TipPanel(brush.tips)
        self.stencil_panel = StencilPanel(brush.stencil)
        self.swatch_editor = SwatchEditor(swatch)
        layout.addWidget(self.title)
        layout.addWidget(self.hint)
        layout.addWidget(self.brush_panel)
        layout.addWidget(self.tip_panel)
        layout.addWidget(self.stencil_panel)
        layout.addWidget(self.swatch_editor)
        self.library_panel: SwatchLibraryPanel | None = None
        if library is not None:
            self.library_panel = SwatchLibraryPanel(library, swatch)
            layout.addWidget(self.library_panel)
        layout.addStretch(1)

    def show_tool(self, label: str, tip: str, uses_brush: bool, uses_swatch: bool) -> None:
        self.title.setText(label)
        self.hint.setText(tip)
        # settings a tool ignores are hidden, not just greyed: in the dark theme a
        # disabled slider still reads as a setting that matters
        for panel in (self.brush_panel, self.tip_panel, self.stencil_panel):
            panel.setEnabled(uses_brush)
            panel.setVisible(uses_brush)
        self.swatch_editor.setEnabled(uses_swatch)
        if self.library_panel is not None:
            self.library_panel.setEnabled(uses_swatch)
