"""The properties panel: the active layer's settings, built from the op's declaration,
and its generated mask (:mod:`.generator_panel`).

A filter layer's controls come from its :class:`~matshop.ops.ParamSpec` s
(kind, default, UI range, choices, doc), never from code per op, so a new
op gets its panel for free. Every change is a ``SetProperty(op_params)``
edit; a slider drag merges into one undo step. The widgets are rebuilt only
when the active layer or its op changes, never mid-drag.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFormLayout,
    QLabel,
    QLineEdit,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from ..errors import MatshopError
from ..layers import FillLayer, FilterLayer, Layer, PaintLayer
from ..ops import ParamSpec, get_op
from ..tools.widgets import FloatSlider
from .generator_panel import GeneratorPanel
from .layer_commands import LayerCommands
from .session import DocumentSession


class PropertiesPanel(QWidget):
    """Controls for the active layer (filter parameters; a summary for other kinds)."""

    def __init__(
        self, session: DocumentSession, commands: LayerCommands, parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self.session = session
        self.commands = commands
        outer = QVBoxLayout(self)
        outer.setContentsMargins(8, 8, 8, 8)
        outer.setSpacing(6)
        self.title = QLabel("")
        self.title.setObjectName("heading")
        self.summary = QLabel("")
        self.summary.setObjectName("hint")
        self.summary.setWordWrap(True)
        self.form_host = QWidget()
        self.form = QFormLayout(self.form_host)
        self.form.setContentsMargins(0, 4, 0, 0)
        self.form.setVerticalSpacing(6)
        outer.addWidget(self.title)
        outer.addWidget(self.summary)
        outer.addWidget(self.form_host)
        self.generator = GeneratorPanel(session, commands)
        outer.addWidget(self.generator)
        outer.addStretch(1)
        #: parameter name -> function showing a value without emitting
        self.setters: dict[str, Any] = {}
        self.controls: dict[str, QWidget] = {}
        self._shown: tuple[int, str] | None = None
        session.activeLayerChanged.connect(self.refresh)
        session.layersChanged.connect(self.refresh)
        session.documentReplaced.connect(self.refresh)
        session.historyChanged.connect(self.refresh)  # strokes change the tile count
        self.refresh()

    # -- showing ---------------------------------------------------------------

    def refresh(self) -> None:
        layer = self.session.active_layer
        key = None if layer is None else (layer.id, getattr(layer, "op", layer.kind))
        if key != self._shown:
            self._shown = key
            self._build(layer)
        elif isinstance(layer, FilterLayer):
            for name, setter in self.setters.items():
                setter(layer.op_params[name])
        if layer is not None:
            self.title.setText(layer.name)
            self.summary.setText(_summary(layer))
        self.generator.refresh()

    def _build(self, layer: Layer | None) -> None:
        while self.form.rowCount():
            self.form.removeRow(0)
        self.setters.clear()
        self.controls.clear()
        if layer is None:
            self.title.setText("No layer")
            self.summary.setText("")
            return
        if isinstance(layer, FilterLayer):
            for spec in get_op(layer.op).params:
                widget = self._control(layer, spec)
                if widget is not None:
                    label = spec.name.removesuffix("_px").replace("_", " ").capitalize()
                    self.form.addRow(label, widget)
                    self.controls[spec.name] = widget

    def _control(self, layer: FilterLayer, spec: ParamSpec) -> QWidget | None:
        value = layer.op_params.get(spec.name, spec.default)
        tip = spec.doc + (f" ({spec.unit})" if spec.unit else "")
        if spec.kind == "float":
            lo, hi = spec.ui_range or spec.hard_range or (0.0, 1.0)
            slider = FloatSlider("", lo, hi, float(value), unit=spec.unit, tip=tip)
            slider.label.hide()
            slider.started.connect(self.session.seal)
            slider.edited.connect(lambda v, n=spec.name: self._set(n, v, merge=True))
            slider.finished.connect(self.session.seal)
            self.setters[spec.name] = slider.set_value
            return slider
        if spec.kind == "int":
            box = QSpinBox()
            lo, hi = spec.ui_range or spec.hard_range or (0, 100)
            box.setRange(int(lo), int(hi))
            box.setValue(int(value))
            box.setKeyboardTracking(False)
            box.valueChanged.connect(lambda v, n=spec.name: self._set(n, int(v)))
            self.setters[spec.name] = _quiet(box.setValue)
            box.setToolTip(tip)
            return box
        if spec.kind == "bool":
            check = QCheckBox()
            check.setChecked(bool(value))
            check.toggled.connect(lambda v, n=spec.name: self._set(n, bool(v)))
            self.setters[spec.name] = _quiet(check.setChecked)
            check.setToolTip(tip)
            return check
        if spec.kind == "choice":
            combo = QComboBox()
            combo.addItems(list(spec.choices))
            combo.setCurrentText(str(value))
            combo.activated.connect(lambda i, n=spec.name, c=combo: self._set(n, c.itemText(i)))
            self.setters[spec.name] = _quiet(lambda v, c=combo: c.setCurrentText(str(v)))
            combo.setToolTip(tip)
            return combo
        if spec.kind == "points":
            line = QLineEdit(spec.format(value))
            line.setToolTip(tip + " — x,y;x,y;... (Enter applies)")
            line.editingFinished.connect(lambda n=spec.name, e=line, s=spec: self._parse(n, e, s))
            self.setters[spec.name] = lambda v, e=line, s=spec: e.setText(s.format(v))
            return line
        return None  # regions, offsets, paths: not filter-layer material

    # -- changing --------------------------------------------------------------

    def _set(self, name: str, value: Any, *, merge: bool = False) -> None:
        layer = self.session.active_layer
        if not isinstance(layer, FilterLayer):
            return
        params = {**layer.op_params, name: value}
        self.commands.set_property(layer.id, "op_params", params, merge=merge)
        if not merge:
            self.session.seal()

    def _parse(self, name: str, line: QLineEdit, spec: ParamSpec) -> None:
        layer = self.session.active_layer
        if not isinstance(layer, FilterLayer):
            return
        try:
            value = spec.parse(line.text(), layer.op)
        except MatshopError as exc:
            self.commands.message.emit(str(exc))
            line.setText(spec.format(layer.op_params[name]))
            return
        self._set(name, value)


def _quiet(setter):
    """A setter that does not emit the widget's change signals."""

    def call(value: Any) -> None:
        widget = getattr(setter, "__self__", None)
        if widget is not None:
            widget.blockSignals(True)
        try:
            setter(value)
        finally:
            if widget is not None:
                widget.blockSignals(False)

    return call


def _summary(layer: Layer) -> str:
    shows = "all parameters" if layer.parameters is None else ", ".join(layer.parameters)
    base = f"{layer.blend} blend, {layer.opacity:.0%} opacity, affects {shows}"
    if layer.mask_generator is not None:
        base += f", {layer.mask_generator.kind} mask"
    if isinstance(layer, FilterLayer):
        spec = get_op(layer.op)
        linear = "linear" if spec.linear else "not linear"
        what = spec.label if spec.label.lower().endswith("filter") else f"{spec.label} filter"
        return f"{what} ({linear}): {spec.summary}\n{base}"
    if isinstance(layer, PaintLayer):
        painted = 0 if layer.pixels is None else len(layer.pixels)
        return f"Paint layer, {painted} painted tiles\n{base}"
    if isinstance(layer, FillLayer):
        what = "texture" if layer.source is not None else "constant value"
        return f"Fill layer ({what})\n{base}"
    return f"{layer.kind.capitalize()} layer\n{base}"
