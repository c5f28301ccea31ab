"""Small pictures of a layer's mask or paint coverage, read straight from its tiles.

One texel per ``step`` from each stored tile (absent tiles read as the grid's
fill), so a thumbnail costs a few microseconds per stored tile whatever the
document size, and never assembles the full-size grid.
"""

from __future__ import annotations

import math

import numpy as np
from PySide6.QtGui import QImage, QPixmap

from ..layers import TileGrid

THUMB = 32


def grid_thumbnail(grid: TileGrid, channel: int, size: int = THUMB) -> np.ndarray:
    """Channel ``channel`` of ``grid`` sampled every ``step`` texels: (h, w) float32."""
    layout = grid.layout
    step = max(1, math.ceil(max(layout.height, layout.width) / size))
    out = np.full(
        (math.ceil(layout.height / step), math.ceil(layout.width / step)),
        grid.fill[channel],
        dtype=np.float32,
    )
    for key in grid.keys():
        rect = layout.tile_rect(key)
        tile = grid.get(key)
        assert tile is not None
        ys = np.arange(math.ceil(rect.y0 / step) * step, rect.y1, step)
        xs = np.arange(math.ceil(rect.x0 / step) * step, rect.x1, step)
        if ys.size and xs.size:
            out[np.ix_(ys // step, xs // step)] = tile[np.ix_(ys - rect.y0, xs - rect.x0)][
                ..., channel
            ]
    return out


def gray_pixmap(values: np.ndarray, invert: bool = False) -> QPixmap:
    """[0, 1] values as a gray pixmap (``invert``: 1 - v, an inverted mask)."""
    shown = 1.0 - values if invert else values
    gray = np.ascontiguousarray(np.clip(shown * 255.0 + 0.5, 0, 255).astype(np.uint8))
    height, width = gray.shape
    image = QImage(gray.data, width, height, width, QImage.Format.Format_Grayscale8)
    return QPixmap.fromImage(image.copy())  # the copy owns its pixels
