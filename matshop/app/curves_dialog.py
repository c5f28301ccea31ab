"""The curves dialog: a tone curve drawn and dragged on a pyqtgraph plot.

The curve drawn is the engine's own PCHIP table (:func:`~matshop.ops.curves.curve_lut`),
over a histogram of the chosen parameter's edit values mapped to [0, 1] the
way the op maps them. Click the plot to add a point, drag a point to move it,
drag it off the plot or double-click it to remove it.

The dialog edits a *curves filter layer* through edits only: opening it on a
curves layer edits that layer; opening it elsewhere adds one (its own undo
step). A point drag is one undo step: ``started`` seals the history, each
tick pushes ``SetProperty(op_params)`` with ``merge=True`` (live preview on
the canvas), ``finished`` seals again. Cancel goes back to the history step
the dialog opened at, so the document is bit-identical to before.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from ..layers import FilterLayer
from ..ops.curves import IDENTITY_POINTS, curve_ranges
from ..tools.curve_editor import CurveEditor
from ..tools.curve_points import CurvePoints
from ..tools.settings import short_label
from .curve_units import PhysicalAxis, physical_axis
from .histogram import edit_histogram
from .layer_commands import LayerCommands
from .session import DocumentSession

HISTOGRAM_BINS = 128
#: Texels of the flatten kept for histograms (strided; plenty for 128 bins).
HISTOGRAM_TEXELS = 1 << 19
LINKED = ""  # combo data of "all parameters, one curve"


class CurvesDialog(QDialog):
    """Edit (or add) a curves filter layer of the session's document."""

    def __init__(
        self,
        session: DocumentSession,
        commands: LayerCommands,
        flatten_ready: Callable[[], bool] = lambda: True,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.setWindowTitle("Curves")
        self.session = session
        self.commands = commands
        self.flatten_ready = flatten_ready
        self.model = CurvePoints()
        self.layer_id: int | None = None
        self.start_steps = 0
        self._sample: np.ndarray | None = None
        #: physical labels of the axes (None: all parameters linked, or no data yet)
        self.axis: PhysicalAxis | None = None

        layout = QVBoxLayout(self)
        row = QHBoxLayout()
        row.addWidget(QLabel("Parameter"))
        self.parameter = QComboBox()
        self.parameter.setToolTip("The curve acts on one parameter, or on all of them (linked)")
        self.parameter.activated.connect(self._parameter_chosen)
        row.addWidget(self.parameter, 1)
        layout.addLayout(row)
        row = QHBoxLayout()
        row.addWidget(QLabel("0 → 1 spans"))
        self.remap = QComboBox()
        self.remap.addItem("the values in this image", "data")
        self.remap.addItem("the parameter's full range", "space")
        self.remap.setToolTip(
            "The values in this image: median at the middle, outliers left out, so an "
            "S-curve raises the contrast of what is there. Full range: the space's fixed range"
        )
        self.remap.activated.connect(self._remap_chosen)
        row.addWidget(self.remap, 1)
        layout.addLayout(row)
        self.editor = CurveEditor(self.model)
        self.editor.setMinimumSize(360, 340)
        layout.addWidget(self.editor, 1)
        self.readout = QLabel("")
        self.readout.setObjectName("hint")
        layout.addWidget(self.readout)
        # what [0, 1] stands for (the op's remap: the values' own range by default)
        self.range_label = QLabel("")
        self.range_label.setObjectName("hint")
        self.range_label.setWordWrap(True)
        layout.addWidget(self.range_label)
        hint = QLabel("Click to add a point; drag it; drag it off or double-click to remove it.")
        hint.setObjectName("hint")
        layout.addWidget(hint)
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel
        )
        self.reset_button = QPushButton("Reset")
        buttons.addButton(self.reset_button, QDialogButtonBox.ButtonRole.ResetRole)
        self.reset_button.clicked.connect(self.reset)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        self.buttons = buttons
        layout.addWidget(buttons)

        self.model.started.connect(session.seal)
        self.model.changed.connect(self._points_changed)
        self.model.finished.connect(session.seal)
        session.historyChanged.connect(self._history_changed)

    # -- opening ------------------------------------------------------------------------

    def begin(self) -> bool:
        """Bind to the active curves layer, or add one above the active layer; False if no doc."""
        doc = self.session.doc
        if doc is None:
            return False
        self.start_steps = self.session.steps
        self._sample = self._read_sample()
        layer = self.session.active_layer
        if isinstance(layer, FilterLayer) and layer.op == "curves":
            self.layer_id = layer.id
        else:
            self.layer_id = self.commands.add_filter_layer("curves")
            if self.layer_id is None:
                return False
        self.session.seal()
        self.parameter.clear()
        self.parameter.addItem("All parameters (linked)", LINKED)
        for param in doc.schema.parameters:
            self.parameter.addItem(short_label(param.name), param.name)
        self._sync_from_layer()
        return True

    def _read_sample(self) -> np.ndarray | None:
        """A strided copy of the flatten (None while a heavy filter is still computing)."""
        doc = self.session.doc
        if doc is None or not self.flatten_ready():
            return None
        step = max(1, int(np.ceil(np.sqrt(doc.width * doc.height / HISTOGRAM_TEXELS))))
        return np.ascontiguousarray(doc.flatten_edit(copy=False)[::step, ::step])

    def layer(self) -> FilterLayer | None:
        doc = self.session.doc
        if doc is None or self.layer_id is None:
            return None
        try:
            layer = doc.layer(self.layer_id)
        except KeyError:
            return None
        return layer if isinstance(layer, FilterLayer) else None

    def _sync_from_layer(self) -> None:
        layer = self.layer()
        if layer is None:
            return
        self.model.set_points(layer.op_params.get("points", IDENTITY_POINTS))
        params = layer.parameters
        chosen = params[0] if params is not None and len(params) == 1 else LINKED
        self.parameter.setCurrentIndex(max(self.parameter.findData(chosen), 0))
        self.remap.setCurrentIndex(max(self.remap.findData(layer.op_params.get("remap")), 0))
        self._update_histogram()
        self.editor.view.redraw()
        self._update_readout()

    def _update_histogram(self) -> None:
        doc = self.session.doc
        name = self.parameter.currentData()
        layer = self.layer()
        remap = {k: layer.op_params[k] for k in ("remap", "clip_percent")} if layer else {}
        counts = None
        text = ""
        self.axis = None
        if doc is not None and self._sample is not None:
            params = None if not name else [name]
            counts = edit_histogram(self._sample, doc.schema, params, HISTOGRAM_BINS, **remap)
            ranges = curve_ranges(self._sample, schema=doc.schema, params=params, **remap)
            how = remap.get("remap", "data")
            if name and len(ranges) == 1:  # one parameter, one group: its physical units
                self.axis = physical_axis(doc.schema[name], ranges[0])
                text = (
                    f"0 → 1 spans {self.axis.text(0.0)} … {self.axis.text(1.0)}, "
                    f"{self.axis.unit} ({how}; edit values {ranges[0].describe()})"
                )
            else:
                text = f"0 → 1 spans ({how}): " + "; ".join(r.describe() for r in ranges)
        self.range_label.setText(text)
        self.editor.view.set_histogram(counts)
        self.editor.set_axes(self.axis)

    # -- changes -----------------------------------------------------------------------

    def _points_changed(self) -> None:
        layer = self.layer()
        if layer is not None:
            params = {**layer.op_params, "points": self.model.points}
            self.commands.set_property(layer.id, "op_params", params, merge=True)
        self._update_readout()

    def _update_readout(self) -> None:
        index = self.model.dragging
        if index is None:
            self.readout.setText(f"{len(self.model)} points")
            return
        x, y = self.model.points[index]
        if self.axis is None:
            self.readout.setText(f"Input {x:.3f}  →  Output {y:.3f}")
        else:
            self.readout.setText(
                f"Input {self.axis.text(x)}  →  Output {self.axis.text(y)}  ({self.axis.unit})"
            )

    def _parameter_chosen(self, index: int) -> None:
        layer = self.layer()
        if layer is None:
            return
        name = self.parameter.itemData(index)
        self.session.seal()
        self.commands.set_property(layer.id, "parameters", None if not name else (name,))
        self.session.seal()
        self._update_histogram()

    def _remap_chosen(self, index: int) -> None:
        layer = self.layer()
        if layer is None:
            return
        self.session.seal()
        params = {**layer.op_params, "remap": self.remap.itemData(index)}
        self.commands.set_property(layer.id, "op_params", params)
        self.session.seal()
        self._update_histogram()

    def _history_changed(self) -> None:
        # an undo while the dialog is open: show what the layer holds now
        if self.model.dragging is None and self.isVisible():
            layer = self.layer()
            if layer is not None and tuple(layer.op_params.get("points", ())) != self.model.points:
                self.model.set_points(layer.op_params["points"])
                self.editor.view.redraw()
            if layer is not None and layer.op_params.get("remap") != self.remap.currentData():
                self.remap.setCurrentIndex(max(self.remap.findData(layer.op_params["remap"]), 0))
                self._update_histogram()

    def reset(self) -> None:
        """Back to the straight line (one undo step)."""
        self.model.started.emit()
        self.model.set_points(IDENTITY_POINTS)
        self.model.changed.emit()
        self.model.finished.emit()

    # -- closing ------------------------------------------------------------------------

    def accept(self) -> None:
        self.session.seal()
        self._disconnect()
        super().accept()

    def reject(self) -> None:
        """Cancel: undo everything the dialog did (the added layer included)."""
        self._disconnect()
        self.session.jump_to(self.start_steps)
        super().reject()

    def _disconnect(self) -> None:
        try:
            self.session.historyChanged.disconnect(self._history_changed)
        except (RuntimeError, TypeError):
            pass  # already disconnected
