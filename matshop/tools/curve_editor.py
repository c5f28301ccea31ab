"""A curve through control points, drawn and dragged on a small pyqtgraph plot.

The curves dialog edits a tone curve with it, the tool panel the pen's pressure
curve. Click the plot to add a point, drag a point to move it, drag it off the
plot or double-click it to remove it; every gesture goes to a
:class:`~.curve_points.CurvePoints` model, which draws the engine's own PCHIP table.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QPointF, Qt
from PySide6.QtWidgets import QWidget

from ..app import theme
from .curve_points import CurvePoints

if TYPE_CHECKING:
    from ..app.curve_units import PhysicalAxis

#: Pixels within which a press grabs a point.
GRAB_PX = 9.0
#: How far past the plot (in curve units) a point must be dragged to be removed.
REMOVE_MARGIN = 0.06


class CurveView(pg.ViewBox):
    """The [0, 1]^2 plot area; turns mouse gestures into :class:`CurvePoints` calls."""

    def __init__(self, model: CurvePoints) -> None:
        super().__init__(enableMenu=False)
        self.model = model
        self.setMouseEnabled(x=False, y=False)
        self.setRange(xRange=(0.0, 1.0), yRange=(0.0, 1.0), padding=0.02)
        self.hist = pg.PlotCurveItem(
            [0.0, 1.0],
            [0.0],
            stepMode="center",
            fillLevel=0.0,
            brush=pg.mkBrush(120, 124, 134, 70),
            pen=None,
        )
        self.diagonal = pg.PlotCurveItem(
            [0.0, 1.0], [0.0, 1.0], pen=pg.mkPen(theme.BORDER, width=1, style=Qt.PenStyle.DashLine)
        )
        self.curve = pg.PlotCurveItem(pen=pg.mkPen(theme.ACCENT, width=2))
        self.scatter = pg.ScatterPlotItem(
            size=10, pen=pg.mkPen("#ffffff", width=1.5), brush=pg.mkBrush(theme.BASE)
        )
        for item in (self.hist, self.diagonal, self.curve, self.scatter):
            self.addItem(item)
        for q in (0.25, 0.5, 0.75):
            for angle in (0, 90):
                line = pg.InfiniteLine(q, angle=angle, pen=pg.mkPen(theme.RAISED, width=1))
                line.setZValue(-10)
                self.addItem(line)
        model.changed.connect(self.redraw)
        self.redraw()

    def set_histogram(self, counts: np.ndarray | None) -> None:
        if counts is None or not counts.size:
            self.hist.setData([0.0, 1.0], [0.0])
            return
        edges = np.linspace(0.0, 1.0, counts.size + 1)
        self.hist.setData(edges, np.sqrt(counts))  # sqrt: one spike hides nothing else

    def redraw(self) -> None:
        x, y = self.model.curve()
        self.curve.setData(x, np.clip(y, -0.05, 1.05))
        points = np.array(self.model.points)
        self.scatter.setData(points[:, 0], points[:, 1])

    # -- hit testing ---------------------------------------------------------------

    def widget_point(self, x: float, y: float) -> QPointF:
        """Scene position of curve coordinates (x, y) (tests aim mouse events with it)."""
        return self.mapViewToScene(QPointF(x, y))

    def _hit(self, scene_pos: QPointF) -> int | None:
        best, best_d = None, GRAB_PX
        for index, (x, y) in enumerate(self.model.points):
            d = (self.widget_point(x, y) - scene_pos).manhattanLength()
            if d < best_d:
                best, best_d = index, d
        return best

    # -- gestures --------------------------------------------------------------------

    def mouseClickEvent(self, ev) -> None:  # noqa: N802 - pyqtgraph override
        if ev.button() != Qt.MouseButton.LeftButton:
            ev.ignore()
            return
        ev.accept()
        hit = self._hit(ev.scenePos())
        if ev.double():
            if hit is not None:
                self.model.remove(hit)
            return
        if hit is None:
            p = self.mapSceneToView(ev.scenePos())
            self.model.add(p.x(), p.y())

    def mouseDragEvent(self, ev, axis=None) -> None:  # noqa: N802 - pyqtgraph override
        if ev.button() != Qt.MouseButton.LeftButton:
            ev.ignore()
            return
        ev.accept()
        p = self.mapSceneToView(ev.scenePos())
        if ev.isStart():
            hit = self._hit(ev.buttonDownScenePos())
            if hit is None:
                start = self.mapSceneToView(ev.buttonDownScenePos())
                self.model.begin_new_drag(start.x(), start.y())
            else:
                self.model.begin_drag(hit)
        if self.model.dragging is None:
            return
        self.model.drag_to(p.x(), p.y())
        if ev.isFinish():
            off = not (
                -REMOVE_MARGIN <= p.x() <= 1 + REMOVE_MARGIN
                and -REMOVE_MARGIN <= p.y() <= 1 + REMOVE_MARGIN
            )
            self.model.end_drag(remove=off)


class CurveEditor(pg.PlotWidget):
    """The plot widget: a :class:`CurveView` with small 0..1 axes."""

    def __init__(
        self, model: CurvePoints, parent: QWidget | None = None, *, diagonal: bool = True
    ) -> None:
        self.view = CurveView(model)
        self.view.diagonal.setVisible(diagonal)
        super().__init__(parent, viewBox=self.view, background=theme.BASE)
        item = self.getPlotItem()
        item.hideButtons()
        item.setMenuEnabled(False)
        for side in ("left", "bottom"):
            axis = item.getAxis(side)
            axis.setPen(pg.mkPen(theme.BORDER))
            axis.setTextPen(pg.mkPen(theme.DIM))
            axis.setTicks([[(v, f"{v:g}") for v in (0.0, 0.25, 0.5, 0.75, 1.0)]])
        self.setMinimumSize(160, 140)

    def set_axes(self, axis: PhysicalAxis | None) -> None:
        """Label both axes with physical values (None: the curve's own 0..1)."""
        item = self.getPlotItem()
        ticks = (
            [(t, f"{t:g}") for t in (0.0, 0.25, 0.5, 0.75, 1.0)] if axis is None else axis.ticks(5)
        )
        for side, what in (("left", "output"), ("bottom", "input")):
            item.getAxis(side).setTicks([ticks])
            item.setLabel(side, what if axis is None else f"{what}: {axis.unit}")

    def to_widget(self, x: float, y: float) -> QPointF:
        """Viewport pixel of curve coordinates (x, y)."""
        return QPointF(self.mapFromScene(self.view.widget_point(x, y)))
