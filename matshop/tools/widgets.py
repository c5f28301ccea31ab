"""Small widgets the panels share: a labelled float slider whose drag is one gesture.

:class:`FloatSlider` reports every change as ``started`` -> ``edited``... ->
``finished``. A drag emits ``started`` on press, ``edited`` per tick and
``finished`` on release; a click, a key or a typed value emits all three at
once. Panels seal the history on ``started``/``finished`` and push merging
edits on ``edited``, so a drag is exactly one undo step.
"""

from __future__ import annotations

import math

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QColor, QPainter
from PySide6.QtWidgets import (
    QDoubleSpinBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSizePolicy,
    QSlider,
    QWidget,
)

_STEPS = 1000


def file_codes_to_qcolor(rgb: tuple[float, ...]) -> QColor:
    """A swatch color (the file's encoded values in [0, 1]) as the QColor of the same codes.

    Swatch colors are physical values, which for colors are already the
    file's sRGB-encoded values: shown and picked as they are, never encoded again.
    """
    return QColor.fromRgbF(*(min(max(c, 0.0), 1.0) for c in rgb[:3]))


def qcolor_to_file_codes(color: QColor) -> tuple[float, float, float]:
    return (color.redF(), color.greenF(), color.blueF())


class FloatSlider(QWidget):
    """Label, slider and number box for one float in ``[lo, hi]`` (optionally log-scaled)."""

    started = Signal()
    edited = Signal(float)
    finished = Signal()

    def __init__(
        self,
        label: str,
        lo: float,
        hi: float,
        value: float,
        *,
        log: bool = False,
        decimals: int = 2,
        unit: str = "",
        tip: str = "",
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        if log and lo <= 0:
            raise ValueError("a log slider needs a positive lower bound")
        self.lo, self.hi, self.log = float(lo), float(hi), log
        self._value = float(value)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 1, 0, 1)
        layout.setSpacing(8)
        self.label = QLabel(label)
        self.label.setMinimumWidth(64)
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setRange(0, _STEPS)
        self.slider.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        self.box = QDoubleSpinBox()
        self.box.setRange(lo, hi)
        self.box.setDecimals(decimals)
        self.box.setSingleStep((hi - lo) / 100.0)
        self.box.setKeyboardTracking(False)  # typing commits on Enter, not per key
        self.box.setFixedWidth(62)
        self.box.setAlignment(Qt.AlignmentFlag.AlignRight)
        if unit:
            self.box.setSuffix(f" {unit}")
            self.box.setFixedWidth(74)
        for widget in (self, self.slider, self.box):
            widget.setToolTip(tip)
        layout.addWidget(self.label)
        layout.addWidget(self.slider, 1)
        layout.addWidget(self.box)
        self._show(self._value)
        self.slider.sliderPressed.connect(self.started)
        self.slider.sliderReleased.connect(self.finished)
        self.slider.valueChanged.connect(self._slider_moved)
        self.box.valueChanged.connect(self._box_changed)

    # -- mapping -------------------------------------------------------------

    def _to_position(self, value: float) -> int:
        if self.log:
            t = math.log(value / self.lo) / math.log(self.hi / self.lo)
        else:
            t = (value - self.lo) / (self.hi - self.lo) if self.hi > self.lo else 0.0
        return int(round(min(max(t, 0.0), 1.0) * _STEPS))

    def _from_position(self, position: int) -> float:
        t = position / _STEPS
        if self.log:
            return self.lo * (self.hi / self.lo) ** t
        return self.lo + t * (self.hi - self.lo)

    # -- value ---------------------------------------------------------------

    def value(self) -> float:
        return self._value

    def set_value(self, value: float) -> None:
        """Show ``value`` without emitting anything (the model changed, not the user)."""
        self._value = min(max(float(value), self.lo), self.hi)
        self._show(self._value)

    def _show(self, value: float) -> None:
        for widget, shown in ((self.slider, self._to_position(value)), (self.box, value)):
            widget.blockSignals(True)
            widget.setValue(shown)
            widget.blockSignals(False)

    def _slider_moved(self, position: int) -> None:
        self._value = self._from_position(position)
        self.box.blockSignals(True)
        self.box.setValue(self._value)
        self.box.blockSignals(False)
        if self.slider.isSliderDown():
            self.edited.emit(self._value)
        else:  # a click on the groove, a key, the wheel: one whole gesture
            self._gesture(self._value)

    def _box_changed(self, value: float) -> None:
        self._value = float(value)
        self.slider.blockSignals(True)
        self.slider.setValue(self._to_position(self._value))
        self.slider.blockSignals(False)
        self._gesture(self._value)

    def _gesture(self, value: float) -> None:
        self.started.emit()
        self.edited.emit(value)
        self.finished.emit()


def discard_widget(widget: QWidget) -> None:
    """Take a widget off screen now and delete it later.

    ``deleteLater`` alone leaves it painted (at a stale place) until the event
    loop runs its deferred deletions, which a rebuild-then-grab never lets happen.
    """
    widget.hide()
    widget.setParent(None)
    widget.deleteLater()


class ColorButton(QPushButton):
    """A flat button showing a color (sRGB-encoded for display)."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._color = QColor(128, 128, 128)
        self.setFixedHeight(24)
        self.setMinimumWidth(48)
        self.setCursor(Qt.CursorShape.PointingHandCursor)

    def set_color(self, color: QColor) -> None:
        self._color = QColor(color)
        self.setToolTip(color.name())
        self.update()

    def color(self) -> QColor:
        return QColor(self._color)

    def paintEvent(self, event) -> None:  # noqa: N802 - Qt override
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        painter.setPen(QColor("#555962") if not self.underMouse() else QColor("#4c8dff"))
        painter.setBrush(self._color)
        painter.drawRoundedRect(self.rect().adjusted(1, 1, -1, -1), 4, 4)
