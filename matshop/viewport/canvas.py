"""The 2D texture canvas: one parameter of the flattened material, zoomable, paintable.

A QWidget painting a QImage that wraps the :class:`DisplayCache` buffer (no
copy). The document's ``dirty`` notifications mark tiles stale; a zero-delay
timer converts them in slices of about a frame, visible tiles first, and
repaints just those. Mouse and tablet input goes to the current tool in
texel coordinates; the wheel zooms around the cursor, the middle button or
Space+drag pans. A stencil (:class:`~matshop.tools.tip_settings.StencilSettings`)
is drawn over the texture, fixed on the screen; while it is being placed, a
drag moves it, the wheel scales it and Shift+wheel turns it.
"""

from __future__ import annotations

import math

from PySide6.QtCore import QEvent, QPointF, QRect, QRectF, Qt, QTimer, Signal
from PySide6.QtGui import (
    QColor,
    QImage,
    QMouseEvent,
    QPainter,
    QPaintEvent,
    QPen,
    QPolygonF,
    QTabletEvent,
    QWheelEvent,
)
from PySide6.QtWidgets import QWidget

from ..layers import DirtyRegion, Document, Rect
from ..paint.stencil import Stencil
from ..paint.symmetry import Symmetry
from ..tools.base import Tool, ToolEvent
from ..tools.tip_settings import StencilSettings
from .display_cache import DisplayCache
from .mipmaps import level_for_zoom
from .stencil_overlay import StencilOverlay
from .view import ViewTransform

BACKGROUND = QColor(30, 31, 34)
FRAME = QColor(0, 0, 0, 110)
#: the mirror lines of symmetric painting (light dashes over a dark line)
MIRROR_LINE = QColor(90, 200, 255, 235)
#: radius of the round handle that moves the mirror centre, in widget pixels
MIRROR_HANDLE_PX = 7
#: Wheel zoom per 1/8 degree: one 15 degree notch zooms by ~1.2.
WHEEL_STEP = 1.2 ** (1.0 / 120.0)


class TextureCanvas(QWidget):
    """Shows ``parameter`` of the document and routes pointer input to ``tool``."""

    #: texel under the cursor (continuous), or NaN, NaN when it left the widget
    cursorMoved = Signal(float, float)
    #: zoom or pan changed
    viewChanged = Signal()
    #: right-drag in the lit display: where the light should come from, (u, v) in [-1, 1]
    lightDragged = Signal(float, float)
    #: the mirror centre's handle was dragged to texel (x, y) (the owner moves the symmetry)
    mirrorCentreDragged = Signal(float, float)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setMouseTracking(True)
        self.setTabletTracking(True)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setAttribute(Qt.WidgetAttribute.WA_OpaquePaintEvent)
        self.setMinimumSize(320, 240)
        self.view = ViewTransform()
        self.doc: Document | None = None
        self.cache: DisplayCache | None = None
        self.tool: Tool | None = None
        self._image: QImage | None = None
        self._mips: dict[int, QImage] = {}  # QImages over the display cache's mip levels
        self._fitted = False  # fit again on resize until the user zooms or pans
        self._pan_from: QPointF | None = None
        self._space = False
        self._cursor: QPointF | None = None
        self._had_outlines = False
        #: the brush's mirror axes: their lines are drawn, and the cursor's mirror images
        self.symmetry = Symmetry()
        #: the stencil over the canvas (its settings; none until :meth:`set_stencil`)
        self.stencil: StencilOverlay | None = None
        self._stencil_from: QPointF | None = None  # a drag moving the stencil
        #: the lit display: a rendered image drawn over the texture (None: not yet rendered)
        self.lit = False
        self.overlay: QImage | None = None
        self.refining = False
        #: the note's name for the lit picture (which renderer draws it)
        self.lit_label = "Lit"
        self._overlay_levels: dict[int, QImage] = {}  # reductions of the overlay for zoom-out
        self._lighting = False
        #: the axis whose mirror handle is being dragged (None: none)
        self._dragging_centre: str | None = None
        #: while set, the flatten is being computed elsewhere: keep the last picture
        self._held: str | None = None
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(0)
        self._timer.timeout.connect(self._refresh_some)

    # -- document ------------------------------------------------------------

    def set_document(self, doc: Document | None, parameter: str | None = None) -> None:
        if self.tool is not None:
            self.tool.cancel()
        if self.doc is not None:
            self.doc.events.dirty.disconnect(self._on_dirty)
        self.doc = doc
        self.cache = None
        self._image = None
        self._mips: dict[int, QImage] = {}
        if doc is not None:
            name = parameter if parameter in doc.schema else doc.schema.names[0]
            self.cache = DisplayCache(doc, name, doc.normal_convention)
            buffer = self.cache.buffer
            height, width = buffer.shape[:2]
            self._image = QImage(
                buffer.data, width, height, width * 4, QImage.Format.Format_RGBX8888
            )
            doc.events.dirty.connect(self._on_dirty)
            self.fit()
            self._timer.start()
        self.update()

    @property
    def parameter(self) -> str | None:
        return None if self.cache is None else self.cache.parameter

    def set_parameter(self, name: str) -> None:
        if self.cache is not None and name != self.cache.parameter:
            self.cache.parameter = name
            self._timer.start()

    def set_normal_convention(self, convention: str) -> None:
        """Show normals as a file of ``convention`` stores them (the document's choice)."""
        if self.cache is not None and convention != self.cache.normal_convention:
            self.cache.normal_convention = convention
            self._timer.start()

    def set_overlay(self, image: QImage | None, lit: bool, refining: bool = False) -> None:
        """Show ``image`` (a render of the whole texture) over the texture while ``lit``.

        ``refining``: a newer or sharper render is on its way (the note says so).
        """
        self.lit = lit
        self.overlay = image if lit else None
        self._overlay_levels = {}
        self.refining = refining
        self.update()

    def set_refining(self, refining: bool) -> None:
        """The lit picture is out of date (the light or the material moved): say so."""
        if refining != self.refining:
            self.refining = refining
            self.update(QRect(0, 0, self.width(), 64))

    def set_symmetry(self, symmetry: Symmetry) -> None:
        """Draw the mirror line(s) of ``symmetry`` (none: no line)."""
        if symmetry != self.symmetry:
            self.symmetry = symmetry
            self.update()

    def set_stencil(self, settings: StencilSettings) -> None:
        """Draw ``settings``' stencil over the texture and place it with the pointer."""
        self.stencil = StencilOverlay(settings)
        settings.changed.connect(self.update)

    def texel_stencil(self) -> Stencil | None:
        """The stencil where it lies over the texture now, in texel space (for a stroke)."""
        if self.stencil is None:
            return None
        return self.stencil.settings.in_texels(self.view.to_texel, self.view.zoom)

    def _placing(self) -> bool:
        return self.stencil is not None and self.stencil.settings.placing

    def _mirror_images(self, x: float, y: float) -> list[tuple[float, float]]:
        """Where a dab at texel (x, y) is mirrored to (without (x, y) itself)."""
        if self.doc is None or not self.symmetry or not self.tool or not self.tool.mirrors:
            return []
        return self.symmetry.mirror_point(x, y, self.doc.width, self.doc.height)[1:]

    def mirror_handles(self) -> dict[str, QPointF]:
        """Widget points of the mirror lines' round handles, by axis (none: no symmetry).

        Each sits at its line's end, just outside the texture (the top edge for the
        x line, the left edge for the y line), kept inside the widget: out of the
        way of strokes, which often start on the line itself.
        """
        if self.doc is None or not self.symmetry:
            return {}
        cx, cy = self.symmetry.centre_in(self.doc.width, self.doc.height)
        gap = MIRROR_HANDLE_PX + 4
        handles = {}
        if self.symmetry.x:
            top = self.to_widget(cx, 0)
            y = min(max(top.y() - gap, gap), self.height() - gap)
            handles["x"] = QPointF(top.x(), y)
        if self.symmetry.y:
            left = self.to_widget(0, cy)
            x = min(max(left.x() - gap, gap), self.width() - gap)
            handles["y"] = QPointF(x, left.y())
        return handles

    def _mirror_handle_at(self, pos: QPointF) -> str | None:
        """The axis whose handle is under ``pos``, or None."""
        for axis, handle in self.mirror_handles().items():
            if math.hypot(pos.x() - handle.x(), pos.y() - handle.y()) <= MIRROR_HANDLE_PX + 2:
                return axis
        return None

    def _drag_centre(self, pos: QPointF) -> None:
        """Move the dragged handle's mirror line to the cursor (the other one stays)."""
        assert self.doc is not None
        x, y = self.to_texel(pos)
        cx, cy = self.symmetry.centre_in(self.doc.width, self.doc.height)
        x = min(max(x, 0.0), self.doc.width) if self._dragging_centre == "x" else cx
        y = min(max(y, 0.0), self.doc.height) if self._dragging_centre == "y" else cy
        self.mirrorCentreDragged.emit(x, y)

    def _light_at(self, pos: QPointF) -> None:
        if self.doc is not None:
            x, y = self.to_texel(pos)
            u = 2.0 * x / self.doc.width - 1.0
            v = 2.0 * y / self.doc.height - 1.0
            self.lightDragged.emit(u, v)

    def _on_dirty(self, region: DirtyRegion) -> None:
        if self.cache is not None:
            self.cache.mark(region)
            self._timer.start()

    def set_held(self, note: str | None) -> None:
        """Hold the picture (do not read the document) while ``note`` is set; shown on top.

        The flatten is being computed off the GUI thread; reading it here would
        compute it again, synchronously. Clearing the note catches up.
        """
        was, self._held = self._held, note
        if note is None:
            self._timer.start()
        if (was is None) != (note is None):
            self.update()
        else:  # only the note's text changed
            self.update(QRect(0, 0, self.width(), 64))

    @property
    def held(self) -> bool:
        return self._held is not None

    def _refresh_some(self) -> None:
        if self.cache is None or self._held is not None:
            return
        done = self.cache.refresh(first=self._visible_texels())
        for rect in done:
            self.update(self._widget_rect(rect))
        if self.cache.busy:
            self._timer.start()

    def flush(self) -> None:
        """Convert every stale tile now (tests, screenshots), unless the picture is held."""
        if self.cache is not None and self._held is None:
            self.cache.refresh(budget_s=None)
            self.update()

    # -- view ----------------------------------------------------------------

    def fit(self) -> None:
        if self.doc is not None:
            self.view.fit(self.doc.width, self.doc.height, self.width(), self.height())
            self._fitted = True
            self._view_changed()

    def actual_size(self) -> None:
        if self.doc is not None:
            self.view.actual_size(self.doc.width, self.doc.height, self.width(), self.height())
            self._fitted = False
            self._view_changed()

    def zoom_by(self, factor: float, anchor: QPointF | None = None) -> None:
        anchor = anchor or QPointF(self.width() / 2, self.height() / 2)
        self.view.zoom_at(factor, anchor.x(), anchor.y())
        self._fitted = False
        self._view_changed()

    def _view_changed(self) -> None:
        self.update()
        self.viewChanged.emit()

    def to_texel(self, pos: QPointF) -> tuple[float, float]:
        return self.view.to_texel(pos.x(), pos.y())

    def to_widget(self, x: float, y: float) -> QPointF:
        return QPointF(*self.view.to_widget(x, y))

    def _widget_rect(self, rect: Rect) -> QRect:
        x0, y0 = self.view.to_widget(rect.x0, rect.y0)
        x1, y1 = self.view.to_widget(rect.x1, rect.y1)
        return QRect(
            math.floor(x0) - 1, math.floor(y0) - 1, math.ceil(x1 - x0) + 3, math.ceil(y1 - y0) + 3
        )

    def _visible_texels(self) -> Rect | None:
        if self.doc is None:
            return None
        x0, y0 = self.view.to_texel(0, 0)
        x1, y1 = self.view.to_texel(self.width(), self.height())
        visible = Rect(math.floor(x0), math.floor(y0), math.ceil(x1), math.ceil(y1))
        return visible.intersect(self.doc.layout.bounds)

    def resizeEvent(self, event) -> None:  # noqa: N802 - Qt override
        super().resizeEvent(event)
        if self._fitted:
            self.fit()

    # -- painting ------------------------------------------------------------

    def paintEvent(self, event: QPaintEvent) -> None:  # noqa: N802 - Qt override
        painter = QPainter(self)
        painter.fillRect(event.rect(), BACKGROUND)
        if self._image is None or self.doc is None:
            self._paint_empty(painter)
            return
        visible = self._visible_texels()
        if visible is not None and not visible.empty:
            view = self.view
            outline = QRectF(
                view.offset_x,
                view.offset_y,
                self.doc.width * view.zoom,
                self.doc.height * view.zoom,
            )
            painter.setPen(QPen(FRAME, 6))
            painter.drawRect(outline.adjusted(-3, -3, 3, 3))
            x0, y0 = view.to_widget(visible.x0, visible.y0)
            target = QRectF(x0, y0, visible.width * view.zoom, visible.height * view.zoom)
            self._draw_texture(painter, target, visible)
        if self.lit and self.overlay is not None and visible is not None and not visible.empty:
            self._draw_overlay(painter, target, visible)
        if self.stencil is not None:
            self.stencil.draw(painter, self.size())
        self._paint_outlines(painter)
        self._paint_mirror_lines(painter)
        self._paint_cursor(painter)
        if self._held is not None:
            self._paint_note(painter, self._held)
        elif self.lit:
            if self.overlay is None:
                self._paint_note(painter, "Rendering…")
            else:
                label = self.lit_label
                self._paint_note(painter, f"{label} — refining…" if self.refining else label)

    def _draw_texture(self, painter: QPainter, target: QRectF, visible: Rect) -> None:
        """Draw texels ``visible`` onto ``target``: crisp squares when magnified, filtered when not.

        Zoomed out, the box-filtered mip level with at most a 2x bilinear
        reduction left is drawn (no moire shimmer while panning).
        """
        assert self.cache is not None and self._image is not None
        zoom = self.view.zoom
        painter.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, zoom < 1.0)
        level = level_for_zoom(zoom)
        if level == 0:
            image = self._image
            scale = 1.0
        else:
            image = self._mip_image(level)
            scale = 1.0 / (1 << level)
        source = QRectF(
            visible.x0 * scale, visible.y0 * scale, visible.width * scale, visible.height * scale
        )
        painter.drawImage(target, image, source)

    def _draw_overlay(self, painter: QPainter, target: QRectF, visible: Rect) -> None:
        """Draw the part of the lit picture over texels ``visible`` (it covers the texture,
        at the texture's resolution or a coarser one): a 2K picture is not scaled whole."""
        assert self.overlay is not None and self.doc is not None
        image = self.overlay
        level = level_for_zoom(self.view.zoom)
        width, height = max(1, self.doc.width >> level), max(1, self.doc.height >> level)
        if image.width() > width:
            # zoomed out: the texture's mip size, area-averaged once per picture and level
            if level not in self._overlay_levels:
                self._overlay_levels[level] = image.scaled(
                    width,
                    height,
                    Qt.AspectRatioMode.IgnoreAspectRatio,
                    Qt.TransformationMode.SmoothTransformation,
                )
            image = self._overlay_levels[level]
        sx = image.width() / self.doc.width
        sy = image.height() / self.doc.height
        source = QRectF(visible.x0 * sx, visible.y0 * sy, visible.width * sx, visible.height * sy)
        smooth = self.view.zoom < 1.0 or sx < 1.0  # magnified 1:1 texels stay crisp squares
        painter.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, smooth)
        painter.drawImage(target, image, source)

    def _mip_image(self, level: int) -> QImage:
        """A QImage over mip ``level`` (brought up to date), made once per level and document.

        Levels are updated in place, so the image wrapping one stays valid.
        """
        assert self.cache is not None
        pixels = self.cache.mips.level(level)
        image = self._mips.get(level)
        if image is None:
            height, width = pixels.shape[:2]
            image = QImage(pixels.data, width, height, width * 4, QImage.Format.Format_RGBX8888)
            self._mips[level] = image
        return image

    def _paint_empty(self, painter: QPainter) -> None:
        painter.setPen(QColor(140, 143, 150))
        font = painter.font()
        font.setPointSizeF(font.pointSizeF() * 1.25)
        painter.setFont(font)
        painter.drawText(
            self.rect(),
            Qt.AlignmentFlag.AlignCenter,
            "Open a texture set or a .matshop project\n(Ctrl+O, or drop files here)",
        )

    def _paint_note(self, painter: QPainter, text: str) -> None:
        """A pill at the top centre saying why the picture is not up to date."""
        font = painter.font()
        metrics = painter.fontMetrics()
        width = metrics.horizontalAdvance(text) + 28
        pill = QRectF((self.width() - width) / 2, 12, width, metrics.height() + 12)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        painter.setPen(Qt.PenStyle.NoPen)
        painter.setBrush(QColor(20, 21, 24, 215))
        painter.drawRoundedRect(pill, pill.height() / 2, pill.height() / 2)
        painter.setPen(QColor(220, 221, 224))
        painter.setFont(font)
        painter.drawText(pill, Qt.AlignmentFlag.AlignCenter, text)

    def _paint_outlines(self, painter: QPainter) -> None:
        """The tool's selection outlines: dark under light dashes (marching-ants style)."""
        if self.tool is None:
            return
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        painter.setBrush(Qt.BrushStyle.NoBrush)
        for points, closed in self.tool.outlines():
            if len(points) < 2:
                continue
            polygon = QPolygonF([self.to_widget(x, y) for x, y in points])
            draw = painter.drawPolygon if closed else painter.drawPolyline
            painter.setPen(QPen(QColor(0, 0, 0, 200), 2.5))
            draw(polygon)
            dashes = QPen(QColor(255, 255, 255, 235), 1.2, Qt.PenStyle.DashLine)
            painter.setPen(dashes)
            draw(polygon)

    def _paint_mirror_lines(self, painter: QPainter) -> None:
        """The texture's centre line(s) that strokes mirror across, while symmetry is on."""
        if self.doc is None or not self.symmetry:
            return
        width, height = self.doc.width, self.doc.height
        cx, cy = self.symmetry.centre_in(width, height)
        lines = []
        if self.symmetry.x:
            lines.append((self.to_widget(cx, 0), self.to_widget(cx, height)))
        if self.symmetry.y:
            lines.append((self.to_widget(0, cy), self.to_widget(width, cy)))
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        for start, end in lines:
            painter.setPen(QPen(QColor(0, 0, 0, 170), 4))
            painter.drawLine(start, end)
            painter.setPen(QPen(MIRROR_LINE, 2, Qt.PenStyle.DashLine))
            painter.drawLine(start, end)
        # the handles that drag the lines: a ring in the line's colour over a dark disc
        for handle in self.mirror_handles().values():
            painter.setPen(QPen(QColor(0, 0, 0, 190), 4))
            painter.setBrush(QColor(0, 0, 0, 120))
            painter.drawEllipse(handle, MIRROR_HANDLE_PX, MIRROR_HANDLE_PX)
            painter.setPen(QPen(MIRROR_LINE, 2))
            painter.setBrush(Qt.BrushStyle.NoBrush)
            painter.drawEllipse(handle, MIRROR_HANDLE_PX, MIRROR_HANDLE_PX)

    def _tool_input(self) -> None:
        """After the tool saw an event: repaint if it draws outlines (they may have changed)."""
        outlines = bool(self.tool is not None and self.tool.outlines())
        if outlines or self._had_outlines:
            self.update()
        self._had_outlines = outlines

    def _paint_cursor(self, painter: QPainter) -> None:
        if self._cursor is None or self.tool is None or self._pan_from is not None:
            return
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        radius = self.tool.cursor_radius()
        centre = self._cursor
        if radius is not None:
            r = max(radius * self.view.zoom, 2.0)
            # two rings (dark under light) read on bright and dark textures alike
            painter.setBrush(Qt.BrushStyle.NoBrush)
            painter.setPen(QPen(QColor(0, 0, 0, 160), 3))
            painter.drawEllipse(centre, r, r)
            painter.setPen(QPen(QColor(255, 255, 255, 220), 1))
            painter.drawEllipse(centre, r, r)
            # where the stroke's mirror images will land: thinner rings in the line's colour
            painter.setPen(QPen(MIRROR_LINE, 1, Qt.PenStyle.DashLine))
            for mx, my in self._mirror_images(*self.to_texel(centre)):
                painter.drawEllipse(self.to_widget(mx, my), r, r)
        tx, ty = self.to_texel(centre)
        for mx, my in self.tool.markers(tx, ty):
            point = self.to_widget(mx, my)
            painter.setPen(QPen(QColor(255, 255, 255, 220), 1))
            painter.drawLine(point + QPointF(-7, 0), point + QPointF(7, 0))
            painter.drawLine(point + QPointF(0, -7), point + QPointF(0, 7))

    # -- input ---------------------------------------------------------------

    def _tool_event(self, pos: QPointF, pressure: float, modifiers) -> ToolEvent:
        x, y = self.to_texel(pos)
        mods = Qt.KeyboardModifier
        return ToolEvent(
            x,
            y,
            pressure,
            alt=bool(modifiers & mods.AltModifier),
            ctrl=bool(modifiers & mods.ControlModifier),
            shift=bool(modifiers & mods.ShiftModifier),
        )

    def _starts_pan(self, button: Qt.MouseButton) -> bool:
        return button == Qt.MouseButton.MiddleButton or (
            button == Qt.MouseButton.LeftButton and self._space
        )

    def mousePressEvent(self, event: QMouseEvent) -> None:  # noqa: N802 - Qt override
        self.setFocus(Qt.FocusReason.MouseFocusReason)
        if self._starts_pan(event.button()):
            self._pan_from = event.position()
            self.setCursor(Qt.CursorShape.ClosedHandCursor)
        elif event.button() == Qt.MouseButton.RightButton and self.lit:
            self._lighting = True
            self._light_at(event.position())
        elif event.button() == Qt.MouseButton.LeftButton and self._placing():
            self._stencil_from = event.position()
        elif event.button() == Qt.MouseButton.LeftButton and self._mirror_handle_at(
            event.position()
        ):
            self._dragging_centre = self._mirror_handle_at(event.position())  # not a stroke
        elif event.button() == Qt.MouseButton.LeftButton and self.tool is not None:
            self.tool.press(self._tool_event(event.position(), 1.0, event.modifiers()))
            self._tool_input()
        event.accept()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:  # noqa: N802 - Qt override
        pos = event.position()
        self._track(pos)
        if self._pan_from is not None:
            delta = pos - self._pan_from
            self._pan_from = pos
            self.view.pan(delta.x(), delta.y())
            self._fitted = False
            self._view_changed()
        elif self._lighting:
            self._light_at(pos)
        elif self._stencil_from is not None and self.stencil is not None:
            delta = pos - self._stencil_from
            self._stencil_from = pos
            self.stencil.settings.move_by(delta.x(), delta.y())
        elif self._dragging_centre:
            self._drag_centre(pos)
        elif self.tool is not None and self.tool.busy:
            self.tool.move(self._tool_event(pos, 1.0, event.modifiers()))
            self._tool_input()
        event.accept()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:  # noqa: N802 - Qt override
        if self._pan_from is not None and self._starts_pan(event.button()):
            self._pan_from = None
            self.unsetCursor()
        elif event.button() == Qt.MouseButton.RightButton and self._lighting:
            self._lighting = False
        elif event.button() == Qt.MouseButton.LeftButton and self._stencil_from is not None:
            self._stencil_from = None
        elif event.button() == Qt.MouseButton.LeftButton and self._dragging_centre:
            self._drag_centre(event.position())
            self._dragging_centre = None
        elif event.button() == Qt.MouseButton.LeftButton and self.tool is not None:
            self.tool.release(self._tool_event(event.position(), 1.0, event.modifiers()))
            self._tool_input()
        event.accept()

    def tabletEvent(self, event: QTabletEvent) -> None:  # noqa: N802 - Qt override
        """Pen input with pressure; accepted, so Qt synthesises no mouse events."""
        kind = event.type()
        pos = event.position()
        on_handle = kind == QEvent.Type.TabletPress and self._mirror_handle_at(pos) is not None
        placing = self._placing() or self._dragging_centre
        if self.tool is None or self._space or on_handle or placing:
            # panning, the mirror handle and placing the stencil go through the mouse path
            event.ignore()
            return
        self._track(pos)
        tool_event = self._tool_event(pos, float(event.pressure()), event.modifiers())
        if kind == QEvent.Type.TabletPress:
            self.tool.press(tool_event)
        elif kind == QEvent.Type.TabletMove and self.tool.busy:
            self.tool.move(tool_event)
        elif kind == QEvent.Type.TabletRelease:
            self.tool.release(tool_event)
        self._tool_input()
        event.accept()

    def wheelEvent(self, event: QWheelEvent) -> None:  # noqa: N802 - Qt override
        steps = event.angleDelta().y()
        if steps and self._placing() and self.stencil is not None:
            settings = self.stencil.settings
            if event.modifiers() & Qt.KeyboardModifier.ShiftModifier:
                settings.set_angle(settings.angle_deg + steps / 8.0)  # a notch: 15 degrees
            else:
                settings.set_scale(settings.scale * WHEEL_STEP**steps)
        elif steps:
            self.zoom_by(WHEEL_STEP**steps, event.position())
        event.accept()

    def keyPressEvent(self, event) -> None:  # noqa: N802 - Qt override
        if event.key() == Qt.Key.Key_Space and not event.isAutoRepeat():
            self._space = True
            self.setCursor(Qt.CursorShape.OpenHandCursor)
        elif event.key() == Qt.Key.Key_Escape and self.tool is not None:
            self.tool.cancel()
            self._tool_input()
        else:
            super().keyPressEvent(event)

    def keyReleaseEvent(self, event) -> None:  # noqa: N802 - Qt override
        if event.key() == Qt.Key.Key_Space and not event.isAutoRepeat():
            self._space = False
            self.unsetCursor()
        else:
            super().keyReleaseEvent(event)

    def leaveEvent(self, event) -> None:  # noqa: N802 - Qt override
        self._update_cursor_area()
        self._cursor = None
        self.cursorMoved.emit(math.nan, math.nan)
        super().leaveEvent(event)

    def _track(self, pos: QPointF) -> None:
        # repaint only around the old and new cursor: a full repaint per mouse
        # move would rescale the whole visible image
        self._update_cursor_area()
        self._cursor = QPointF(pos)
        self._update_cursor_area()
        x, y = self.to_texel(pos)
        self.cursorMoved.emit(x, y)

    def _update_cursor_area(self) -> None:
        if self._cursor is None or self.tool is None:
            return
        radius = (self.tool.cursor_radius() or 0.0) * self.view.zoom + 10.0
        tx, ty = self.to_texel(self._cursor)
        rings = [self._cursor] + [self.to_widget(mx, my) for mx, my in self._mirror_images(tx, ty)]
        markers = [self.to_widget(mx, my) for mx, my in self.tool.markers(tx, ty)]
        for points, r in ((rings, radius), (markers, 10.0)):
            for point in points:
                self.update(QRectF(point.x() - r, point.y() - r, 2 * r, 2 * r).toAlignedRect())
