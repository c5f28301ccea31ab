"""The tool panel's Tip and Stencil boxes.

Tip: the tip (round, the built-in noise / scratches / spots with their seed,
or an image file), its rotation (fixed, follow the stroke, random), angle,
size and angle jitter, scatter along and across. Stencil: load, place (drag
moves, wheel scales, Shift+wheel turns), scale and angle, clear. Reading a
file is the editor's business (a dialog, a worker thread): the boxes ask for
it with :attr:`TipPanel.loadRequested` / :attr:`StencilPanel.loadRequested`.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QImage, QPixmap
from PySide6.QtWidgets import (
    QComboBox,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from .tip_settings import DYNAMICS_SETTINGS, TIP_KINDS, StencilSettings, TipSettings
from .widgets import FloatSlider

_KIND_LABELS = {
    "round": "Round",
    "noise": "Noise",
    "scratches": "Scratches",
    "spots": "Spots",
    "image": "Image file",
}
_ROTATION_LABELS = {"fixed": "Fixed angle", "follow": "Follow stroke", "random": "Random"}
PREVIEW_PX = 40


def tip_pixmap(image: np.ndarray | None, size: int = PREVIEW_PX) -> QPixmap:
    """The tip's gray as a small picture (a disc for the round dab)."""
    if image is None:
        t = (np.arange(size) + 0.5) / size * 2.0 - 1.0
        image = np.clip((0.9 - np.hypot(t[None, :], t[:, None])) * 8.0, 0.0, 1.0)
    codes = np.ascontiguousarray(np.round(np.asarray(image) * 255).astype(np.uint8))
    height, width = codes.shape
    picture = QImage(codes.data, width, height, width, QImage.Format.Format_Grayscale8).copy()
    return QPixmap.fromImage(picture).scaled(
        size, size, Qt.AspectRatioMode.KeepAspectRatio, Qt.TransformationMode.SmoothTransformation
    )


def _row(label: str, widget: QWidget) -> QHBoxLayout:
    row = QHBoxLayout()
    text = QLabel(label)
    text.setMinimumWidth(64)
    row.addWidget(text)
    row.addWidget(widget, 1)
    return row


class TipPanel(QGroupBox):
    """Which tip the brush stamps and how its dabs vary."""

    #: the user asked to read a tip image (the editor shows a dialog and reads it)
    loadRequested = Signal()

    def __init__(self, settings: TipSettings, parent: QWidget | None = None) -> None:
        super().__init__("Tip", parent)
        self.settings = settings
        layout = QVBoxLayout(self)
        layout.setSpacing(2)
        self.kind = QComboBox()
        for kind in TIP_KINDS:
            self.kind.addItem(_KIND_LABELS[kind], kind)
        self.kind.setToolTip("The dab's shape: round, a built-in pattern or a gray image")
        self.kind.activated.connect(self._kind_chosen)
        top = _row("Tip", self.kind)
        self.preview = QLabel()
        self.preview.setFixedSize(PREVIEW_PX, PREVIEW_PX)
        self.preview.setToolTip("The tip as it stamps (white paints)")
        top.addWidget(self.preview)
        layout.addLayout(top)
        extra = QHBoxLayout()
        self.seed = QSpinBox()
        self.seed.setRange(0, 2**31 - 1)
        self.seed.setPrefix("seed ")
        self.seed.setToolTip("Another seed, another pattern (the same seed, the same tip)")
        self.seed.valueChanged.connect(settings.set_tip_seed)
        self.load = QPushButton("Load tip…")
        self.load.setToolTip("Use a gray image as the tip (white paints)")
        self.load.clicked.connect(self.loadRequested)
        self.image_name = QLabel("")
        self.image_name.setObjectName("hint")
        extra.addWidget(self.seed)
        extra.addWidget(self.load)
        extra.addWidget(self.image_name, 1)
        layout.addLayout(extra)
        self.rotation = QComboBox()
        for rotation, label in _ROTATION_LABELS.items():
            self.rotation.addItem(label, rotation)
        self.rotation.setToolTip("The tip's angle: fixed, along the stroke, or random per dab")
        self.rotation.activated.connect(
            lambda index: settings.set_rotation(self.rotation.itemData(index))
        )
        layout.addLayout(_row("Rotation", self.rotation))
        self.sliders: dict[str, FloatSlider] = {}
        for spec in DYNAMICS_SETTINGS:
            slider = FloatSlider(
                spec.label,
                spec.lo,
                spec.hi,
                settings.values[spec.name],
                unit=spec.unit,
                tip=spec.tip,
                decimals=0 if spec.unit == "°" else 2,
            )
            slider.edited.connect(lambda value, name=spec.name: settings.set(name, value))
            layout.addWidget(slider)
            self.sliders[spec.name] = slider
        settings.changed.connect(self._sync)
        self._sync()

    def _kind_chosen(self, index: int) -> None:
        kind = self.kind.itemData(index)
        if kind == "image" and self.settings.image is None:
            self._sync()  # stays as it was until an image is read
            self.loadRequested.emit()
        else:
            self.settings.set_kind(kind)

    def _sync(self) -> None:
        s = self.settings
        self.kind.setCurrentIndex(TIP_KINDS.index(s.kind))
        self.seed.blockSignals(True)
        self.seed.setValue(s.tip_seed)
        self.seed.blockSignals(False)
        self.seed.setVisible(s.kind not in ("round", "image"))
        self.image_name.setText(s.image.name if s.image is not None and s.kind == "image" else "")
        self.rotation.setCurrentIndex(list(_ROTATION_LABELS).index(s.rotation))
        tip = s.tip()
        self.preview.setPixmap(tip_pixmap(None if tip is None else tip.image))
        for name, slider in self.sliders.items():
            slider.set_value(s.values[name])


class StencilPanel(QGroupBox):
    """Load, place, scale, turn and clear the stencil over the canvas."""

    loadRequested = Signal()

    def __init__(self, settings: StencilSettings, parent: QWidget | None = None) -> None:
        super().__init__("Stencil", parent)
        self.settings = settings
        layout = QVBoxLayout(self)
        layout.setSpacing(2)
        buttons = QHBoxLayout()
        self.load = QPushButton("Load…")
        self.load.setToolTip("Lay a gray image over the canvas: paint passes where it is white")
        self.load.clicked.connect(self.loadRequested)
        self.place = QPushButton("Place")
        self.place.setCheckable(True)
        self.place.setToolTip(
            "While on, dragging on the canvas moves the stencil, the wheel scales it and "
            "Shift+wheel turns it"
        )
        self.place.toggled.connect(settings.set_placing)
        self.clear = QPushButton("Clear")
        self.clear.setToolTip("Remove the stencil")
        self.clear.clicked.connect(settings.clear)
        for button in (self.load, self.place, self.clear):
            buttons.addWidget(button)
        layout.addLayout(buttons)
        self.name = QLabel("No stencil")
        self.name.setObjectName("hint")
        layout.addWidget(self.name)
        self.scale = FloatSlider(
            "Scale", 0.01, 100.0, 1.0, log=True, tip="Screen pixels per stencil pixel"
        )
        self.scale.edited.connect(settings.set_scale)
        self.angle = FloatSlider(
            "Angle", -180.0, 180.0, 0.0, unit="°", decimals=0, tip="Counter-clockwise"
        )
        self.angle.edited.connect(settings.set_angle)
        layout.addWidget(self.scale)
        layout.addWidget(self.angle)
        settings.changed.connect(self._sync)
        self._sync()

    def _sync(self) -> None:
        s = self.settings
        on = s.stencil is not None
        for widget in (self.place, self.clear, self.scale, self.angle):
            widget.setEnabled(on)
        self.place.blockSignals(True)
        self.place.setChecked(s.placing)
        self.place.blockSignals(False)
        self.name.setText(s.stencil.source.rsplit("/", 1)[-1] if on else "No stencil")
        self.scale.set_value(s.scale)
        self.angle.set_value(s.angle_deg)
