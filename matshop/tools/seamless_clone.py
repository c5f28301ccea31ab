"""Seamless clone: lasso or polygon a source region, drag it to a new place, release.

Two phases. *Selecting*: a drag draws a freehand lasso, single clicks add
polygon vertices and a click back on the first vertex closes the polygon.
The closed outline becomes a :class:`~matshop.ops.clone.CloneCoordinates`
(built once: its cost depends on the shape only). *Placing*: every drag
re-clones the region at the drag's offset with mean-value coordinates (one
gather and two sparse products per move) and shows the result live through
an open :class:`~matshop.layers.PaintTransaction`, so every view and the
status bar read the real composite; the release commits it as one undo
step. Alt/Ctrl-click or Escape drops the selection.

The cloned values land in the active paint layer, or in a new paint layer
added in the same undo step, with coverage 1 on the region (its boundary
pixels keep the target's values exactly: that is what makes the seam
invisible). Source and target are the flattened edit values read when the
drag starts.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..layers import AddLayer, CompoundEdit, Edit, PaintLayer, PaintTransaction, Rect
from ..ops.clone import CloneCoordinates, CloneError
from .base import Tool, ToolEvent, ToolHost

#: A lasso shorter than this (texels of path) was a click: it adds a polygon vertex.
CLICK_TRAVEL = 1.5
#: Lasso points closer than this to the previous one are skipped (texels).
LASSO_STEP = 0.75
LABEL = "Seamless clone"


class _Drag:
    """One placement in progress: the source read at its start and the open preview."""

    def __init__(self, start: tuple[float, float], values: np.ndarray) -> None:
        self.start = start
        self.values = values  # flattened edit values: source and target of the clone
        self.offset = (0, 0)
        self.layer_id: int | None = None
        self.added: AddLayer | None = None  # the paint layer this drag created
        self.tx: PaintTransaction | None = None


class SeamlessCloneTool(Tool):
    """Lasso/polygon a region, then drag to paste it seamlessly (mean-value cloning)."""

    name = "seamless_clone"
    label = "Seamless clone"
    shortcut = "Shift+S"
    tip = (
        "Drag a lasso (or click polygon points, then the first one again) around a source, "
        "then drag it to its new place. Alt-click or Esc starts over"
    )
    uses_brush = False

    def __init__(self, host: ToolHost) -> None:
        super().__init__(host)
        self.path: list[tuple[float, float]] = []  # the outline being drawn
        self._lasso = False  # the button is down drawing the path freehand
        self._travel = 0.0
        self.polygon: np.ndarray | None = None  # (N, 2) closed outline, texels
        self.coords: CloneCoordinates | None = None
        self._mask: np.ndarray | None = None  # region over coords.bbox
        self._drag: _Drag | None = None
        #: seconds of the last preview (re-clone + write), for the status bar and benchmarks
        self.last_preview_s = 0.0

    @property
    def busy(self) -> bool:
        return self._lasso or self._drag is not None

    # -- selecting -------------------------------------------------------------

    def _close_radius(self) -> float:
        doc = self.host.doc
        size = 512 if doc is None else max(doc.width, doc.height)
        return max(3.0, 0.012 * size)

    def press(self, event: ToolEvent) -> None:
        doc = self.host.doc
        if doc is None or self.busy:
            return
        if event.pick:
            self.cancel()
            self.host.message("Selection dropped: draw a new source region")
            return
        if self.coords is not None:
            self._start_drag(event)
            return
        point = (event.x, event.y)
        if len(self.path) >= 3 and math.dist(point, self.path[0]) <= self._close_radius():
            self._select(self.path)  # clicked back on the first vertex
            return
        self.path.append(point)
        self._lasso, self._travel = True, 0.0

    def move(self, event: ToolEvent) -> None:
        if self._drag is not None:
            self._preview(event)
        elif self._lasso:
            point = (event.x, event.y)
            step = math.dist(point, self.path[-1])
            if step >= LASSO_STEP:
                self.path.append(point)
                self._travel += step

    def release(self, event: ToolEvent) -> None:
        if self._drag is not None:
            self._preview(event)
            self._commit()
        elif self._lasso:
            self.move(event)
            self._lasso = False
            if self._travel >= CLICK_TRAVEL and len(self.path) >= 3:
                self._select(self.path)  # a freehand lasso closes itself

    def _select(self, path: list[tuple[float, float]]) -> None:
        doc = self.host.doc
        self.path = []
        if doc is None:
            return
        polygon = np.asarray(path, dtype=np.float64) - 0.5  # texel centres sit at +0.5
        try:
            coords = CloneCoordinates.from_region(polygon, doc.size)
        except CloneError as exc:
            self.host.message(str(exc))
            return
        x0, y0, x1, y1 = coords.bbox
        mask = np.zeros((y1 - y0, x1 - x0), dtype=bool)
        for pixels in (coords.boundary, coords.interior):
            mask[pixels[:, 1] - y0, pixels[:, 0] - x0] = True
        self.polygon, self.coords, self._mask = np.asarray(path), coords, mask
        self.host.message(
            f"Source selected ({int(mask.sum())} texels): drag it to where it should go"
        )

    # -- placing ---------------------------------------------------------------

    def _start_drag(self, event: ToolEvent) -> None:
        doc = self.host.doc
        assert doc is not None
        if not self.host.flatten_ready():  # the clone reads the flattened material
            self.host.message("The material is still being computed: clone in a moment")
            return
        self._drag = _Drag((event.x, event.y), doc.flatten_edit())

    def _clamped_offset(self, event: ToolEvent) -> tuple[int, int]:
        """The drag's offset, kept so the region stays on the image (no wrapped writes)."""
        doc, drag = self.host.doc, self._drag
        assert doc is not None and drag is not None and self.coords is not None
        x0, y0, x1, y1 = self.coords.bbox
        dx = round(event.x - drag.start[0])
        dy = round(event.y - drag.start[1])
        return min(max(dx, -x0), doc.width - x1), min(max(dy, -y0), doc.height - y1)

    def _layer(self, drag: _Drag) -> int:
        """The active paint layer, or a new one above the active layer (same undo step)."""
        doc = self.host.doc
        assert doc is not None
        active = self.host.active_layer()
        if active is not None and isinstance(doc.layer(active), PaintLayer):
            return active
        layer = doc.new_paint_layer("Clone")
        index = None if active is None else doc.index_of(active) + 1
        drag.added = AddLayer(layer, index)
        drag.added.apply(doc)
        return layer.id

    def _preview(self, event: ToolEvent) -> None:
        drag, coords, mask = self._drag, self.coords, self._mask
        assert drag is not None and coords is not None and mask is not None
        offset = self._clamped_offset(event)
        if offset == drag.offset and drag.tx is not None:
            return
        began = time.perf_counter()
        drag.offset = offset
        doc = self.host.doc
        assert doc is not None
        if drag.layer_id is None:
            drag.layer_id = self._layer(drag)
        if drag.tx is not None:
            drag.tx.cancel()  # put the previous placement back
        x0, y0, x1, y1 = coords.bbox
        dx, dy = offset
        rect = Rect(x0 + dx, y0 + dy, x1 + dx, y1 + dy)
        # the target cropped to the placement: the clone touches only that block
        target = drag.values[rect.y0 : rect.y1, rect.x0 : rect.x1]
        cloned = coords.clone(target, drag.values, (dx - rect.x0, dy - rect.y0), "clamp")
        layer = doc.layer(drag.layer_id)
        assert isinstance(layer, PaintLayer) and layer.pixels is not None
        block = layer.pixels.read(rect)
        block[mask, :-1] = cloned[mask]
        block[mask, -1] = 1.0
        drag.tx = PaintTransaction(doc, drag.layer_id, "pixels", LABEL)
        drag.tx.write(rect, block)
        self.last_preview_s = time.perf_counter() - began

    def _commit(self) -> None:
        drag, self._drag = self._drag, None
        if drag is None or drag.tx is None:
            return  # a click without a move places nothing
        paint = drag.tx.commit()
        edit: Edit = paint if drag.added is None else CompoundEdit([drag.added, paint], LABEL)
        self.host.push(edit)
        dx, dy = drag.offset
        self.host.message(
            f"Cloned at offset {dx}, {dy} ({self.last_preview_s * 1000:.0f} ms per re-clone)"
        )

    def cancel(self) -> None:
        drag, self._drag = self._drag, None
        if drag is not None:
            if drag.tx is not None:
                drag.tx.cancel()
            if drag.added is not None:
                drag.added.revert(self.host.doc)  # type: ignore[arg-type]
        self.path, self._lasso = [], False
        self.polygon = self.coords = self._mask = None

    # -- drawing ---------------------------------------------------------------

    def outlines(self) -> list[tuple[list[tuple[float, float]], bool]]:
        if self.polygon is not None:
            dx, dy = (0, 0) if self._drag is None else self._drag.offset
            return [([(x + dx, y + dy) for x, y in self.polygon.tolist()], True)]
        return [(list(self.path), False)] if self.path else []
