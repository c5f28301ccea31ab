"""The stencil drawn over the 2D canvas: its image, half transparent, where it masks dabs.

The picture is the stencil's own gray (white: paint passes) tinted so the
blocked parts read as a dark sheet over the texture; a dashed frame shows
its edge (outside it nothing is masked). Large stencils are reduced once for
display (the mask itself is sampled from the full image), and the stencil is
rendered over the widget once per place: a repaint is a copy.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QRectF, QSize, Qt
from PySide6.QtGui import QColor, QImage, QPainter, QPen, QTransform

from ..tools.tip_settings import StencilSettings

#: how much of the stencil shows over the texture
OPACITY = 0.5
#: longest side of the picture drawn (the mask is sampled from the full image)
DISPLAY_PX = 1024
FRAME = QColor(255, 190, 60, 230)


def stencil_transform(settings: StencilSettings) -> QTransform:
    """Stencil pixels (origin at its top-left corner) -> canvas widget pixels."""
    assert settings.stencil is not None
    h, w = settings.stencil.image.shape
    transform = QTransform()
    transform.translate(*settings.centre)
    transform.rotate(-settings.angle_deg)  # Qt turns clockwise on screen; ours is counter-clockwise
    transform.scale(settings.scale, settings.scale)
    transform.translate(-w / 2.0, -h / 2.0)
    return transform


class StencilOverlay:
    """Draws ``settings``' stencil; keeps its display picture until the image changes."""

    def __init__(self, settings: StencilSettings) -> None:
        self.settings = settings
        self._source: object = None
        self._picture: QImage | None = None
        self._layer: QImage | None = None  # the stencil rendered over the widget
        self._key: tuple | None = None

    def picture(self) -> QImage | None:
        stencil = self.settings.stencil
        if stencil is None:
            self._source, self._picture = None, None
            return None
        if stencil.image is not self._source:
            gray = stencil.image
            step = max(1, int(np.ceil(max(gray.shape) / DISPLAY_PX)))
            if step > 1:  # a box reduction, as the mask's own pyramid does
                h, w = (gray.shape[0] // step) * step, (gray.shape[1] // step) * step
                gray = gray[:h, :w].reshape(h // step, step, w // step, step).mean(axis=(1, 3))
            # white lets paint through: transparent there; black blocks: an opaque dark sheet
            rgba = np.empty((*gray.shape, 4), np.uint8)
            rgba[..., :3] = np.array([40, 14, 60], np.uint8)
            rgba[..., 3] = np.round((1.0 - gray) * 255).astype(np.uint8)
            self._buffer = np.ascontiguousarray(rgba)
            height, width = gray.shape
            self._picture = QImage(
                self._buffer.data, width, height, width * 4, QImage.Format.Format_RGBA8888
            )
            self._source = stencil.image
        return self._picture

    def draw(self, painter: QPainter, size: QSize) -> None:
        """Draw over a widget of ``size``: a blit of the stencil rendered for this place.

        Rendered once per place (size, centre, scale, angle, placing), so the
        repaints a stroke causes copy pixels instead of resampling the picture.
        """
        picture = self.picture()
        stencil = self.settings.stencil
        if picture is None or stencil is None:
            self._layer = None
            return
        s = self.settings
        key = (id(picture), size.width(), size.height(), s.centre, s.scale, s.angle_deg, s.placing)
        if key != self._key:
            self._layer = self._render(picture, stencil.image.shape, size)
            self._key = key
        painter.drawImage(0, 0, self._layer)

    def _render(self, picture: QImage, shape: tuple[int, ...], size: QSize) -> QImage:
        h, w = shape
        layer = QImage(size, QImage.Format.Format_ARGB32_Premultiplied)
        layer.fill(Qt.GlobalColor.transparent)
        painter = QPainter(layer)
        painter.setTransform(stencil_transform(self.settings))
        painter.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, True)
        painter.setOpacity(OPACITY if not self.settings.placing else 0.7)
        painter.drawImage(QRectF(0, 0, w, h), picture)
        painter.setOpacity(1.0)
        pen = QPen(FRAME, 0, Qt.PenStyle.DashLine)
        pen.setWidthF(1.5 if self.settings.placing else 1.0)
        pen.setCosmetic(True)  # the same width at any scale
        painter.setPen(pen)
        painter.setBrush(Qt.BrushStyle.NoBrush)
        painter.drawRect(QRectF(0, 0, w, h))
        painter.end()
        return layer
