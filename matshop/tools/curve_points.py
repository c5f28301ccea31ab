"""The control points of a tone curve being edited, as an observable model.

The curves dialog's plot and its tests both drive this object: points are
added, moved and removed here, and each change is reported as one
*gesture* (``started`` -> ``changed``... -> ``finished``), like
:class:`~matshop.tools.widgets.FloatSlider`, so the dialog can seal the
history around a drag and merge the ticks in between into one undo step.

Points stay valid for the engine's ``curves`` op: x strictly increasing in
[0, 1], y in [0, 1], at least two of them.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from PySide6.QtCore import QObject, Signal

from ..ops.curves import IDENTITY_POINTS, curve_lut

#: Smallest x gap between neighbours: the PCHIP needs strictly increasing x.
MIN_GAP = 1.0 / 256.0
#: Samples of the drawn curve (the engine's table has 4096; 257 is smooth on screen).
DRAW_SAMPLES = 257

Point = tuple[float, float]


def _clip(value: float) -> float:
    return min(max(float(value), 0.0), 1.0)


class CurvePoints(QObject):
    """Control points ``[(x, y), ...]`` of a curve in [0, 1]^2."""

    started = Signal()
    #: the points changed (emitted per drag tick)
    changed = Signal()
    finished = Signal()

    def __init__(self, points: Sequence[Point] = IDENTITY_POINTS) -> None:
        super().__init__()
        self._points: list[Point] = [(float(x), float(y)) for x, y in points]
        self._dragging: int | None = None

    @property
    def points(self) -> tuple[Point, ...]:
        return tuple(self._points)

    def __len__(self) -> int:
        return len(self._points)

    def set_points(self, points: Sequence[Point]) -> None:
        """Show ``points`` (the layer changed, e.g. undo) without emitting a gesture."""
        self._points = [(float(x), float(y)) for x, y in points]

    def curve(self, samples: int = DRAW_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) of the curve the engine applies, from its own PCHIP table."""
        return np.linspace(0.0, 1.0, samples), curve_lut(self._points, samples)

    def nearest(self, x: float, y: float) -> int:
        return int(np.argmin([(px - x) ** 2 + (py - y) ** 2 for px, py in self._points]))

    # -- one-shot gestures ------------------------------------------------------

    def add(self, x: float, y: float) -> int | None:
        """Insert a point (one gesture); returns its index, None if too close to a neighbour."""
        index = self._insert(x, y)
        if index is not None:
            self._gesture()
        return index

    def remove(self, index: int) -> bool:
        """Remove a point (one gesture); the curve keeps at least two."""
        if len(self._points) <= 2 or not 0 <= index < len(self._points):
            return False
        del self._points[index]
        self._gesture()
        return True

    def _gesture(self) -> None:
        self.started.emit()
        self.changed.emit()
        self.finished.emit()

    def _insert(self, x: float, y: float) -> int | None:
        x, y = _clip(x), _clip(y)
        xs = [px for px, _ in self._points]
        index = int(np.searchsorted(xs, x))
        if any(abs(px - x) < MIN_GAP for px in xs):
            return None
        self._points.insert(index, (x, y))
        return index

    # -- drags ------------------------------------------------------------------

    def begin_drag(self, index: int) -> None:
        self._dragging = index
        self.started.emit()

    def begin_new_drag(self, x: float, y: float) -> int | None:
        """Press on empty plot: insert a point there and drag it, all one gesture."""
        self.started.emit()
        index = self._insert(x, y)
        if index is None:
            self.finished.emit()
            return None
        self._dragging = index
        self.changed.emit()
        return index

    def drag_to(self, x: float, y: float) -> None:
        """Move the dragged point, kept between its neighbours (x) and in [0, 1] (y)."""
        index = self._dragging
        if index is None:
            return
        lo = self._points[index - 1][0] + MIN_GAP if index > 0 else 0.0
        hi = self._points[index + 1][0] - MIN_GAP if index + 1 < len(self._points) else 1.0
        point = (min(max(_clip(x), lo), hi), _clip(y))
        if point != self._points[index]:
            self._points[index] = point
            self.changed.emit()

    def end_drag(self, remove: bool = False) -> None:
        """Finish the drag; ``remove`` (dragged off the plot) deletes the point in the same step."""
        index, self._dragging = self._dragging, None
        if index is None:
            return
        if remove and len(self._points) > 2:
            del self._points[index]
            self.changed.emit()
        self.finished.emit()

    @property
    def dragging(self) -> int | None:
        return self._dragging
