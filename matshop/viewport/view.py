"""The canvas' view transform: widget pixels <-> continuous texel coordinates.

``widget = offset + zoom * texel``. Kept Qt-free so zoom-around-the-cursor,
fit and 1:1 are plain arithmetic with tests of their own.
"""

from __future__ import annotations

from dataclasses import dataclass

MIN_ZOOM = 1.0 / 64.0
MAX_ZOOM = 64.0
#: Padding around the image when fitting it into the widget, in widget pixels.
FIT_MARGIN = 24.0


@dataclass
class ViewTransform:
    """Zoom (widget pixels per texel) and offset (widget position of texel (0, 0))."""

    zoom: float = 1.0
    offset_x: float = 0.0
    offset_y: float = 0.0

    def to_texel(self, wx: float, wy: float) -> tuple[float, float]:
        return (wx - self.offset_x) / self.zoom, (wy - self.offset_y) / self.zoom

    def to_widget(self, tx: float, ty: float) -> tuple[float, float]:
        return self.offset_x + tx * self.zoom, self.offset_y + ty * self.zoom

    def zoom_at(self, factor: float, wx: float, wy: float) -> None:
        """Multiply the zoom by ``factor`` keeping the texel under (wx, wy) in place."""
        tx, ty = self.to_texel(wx, wy)
        self.zoom = min(max(self.zoom * factor, MIN_ZOOM), MAX_ZOOM)
        self.offset_x = wx - tx * self.zoom
        self.offset_y = wy - ty * self.zoom

    def set_zoom_at(self, zoom: float, wx: float, wy: float) -> None:
        self.zoom_at(zoom / self.zoom, wx, wy)

    def pan(self, dx: float, dy: float) -> None:
        self.offset_x += dx
        self.offset_y += dy

    def fit(self, image_w: int, image_h: int, widget_w: int, widget_h: int) -> None:
        """Largest zoom showing the whole image, centred."""
        room_w = max(widget_w - 2 * FIT_MARGIN, 16.0)
        room_h = max(widget_h - 2 * FIT_MARGIN, 16.0)
        self.zoom = min(max(min(room_w / image_w, room_h / image_h), MIN_ZOOM), MAX_ZOOM)
        self.center(image_w, image_h, widget_w, widget_h)

    def actual_size(self, image_w: int, image_h: int, widget_w: int, widget_h: int) -> None:
        """One texel per widget pixel, centred."""
        self.zoom = 1.0
        self.center(image_w, image_h, widget_w, widget_h)

    def center(self, image_w: int, image_h: int, widget_w: int, widget_h: int) -> None:
        # whole pixels keep 1:1 crisp (no half-texel resampling)
        self.offset_x = float(round((widget_w - image_w * self.zoom) / 2))
        self.offset_y = float(round((widget_h - image_h * self.zoom) / 2))
