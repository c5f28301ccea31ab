"""Box-filtered half-size copies of the canvas picture, for drawing it zoomed out.

Drawing a 2K texture at 25% with bilinear sampling reads 4 of every 16
texels: fine detail aliases into moire that shimmers as the view pans. The
canvas instead draws level ``k`` (each texel the mean of a ``2^k x 2^k``
block) with at most a 2x bilinear reduction left, as a GPU mipmap would.

Levels are brought up to date lazily and only where the picture changed:
:meth:`MipPyramid.mark` records changed rectangles (level-0 texels) and
:meth:`MipPyramid.level` re-averages just those blocks, so a brush dab at
"fit" zoom costs a few small reductions, not a whole pyramid. Qt-free.
"""

from __future__ import annotations

import cv2
import numpy as np

from ..layers import Rect

#: beyond this many separate changed rectangles per level, keep their bounding box
_MAX_RECTS = 64


def level_for_zoom(zoom: float) -> int:
    """The finest level whose texels are still no smaller than half a screen pixel."""
    level = 0
    while zoom * (1 << (level + 1)) <= 1.0 + 1e-9:
        level += 1
    return level


def _half(block: np.ndarray) -> np.ndarray:
    """Mean of each 2x2 block of ``(h, w, C)`` uint8, rounded half up (odd edges repeat
    their last texel).

    OpenCV's area resize to exactly half size computes this mean, ``(sum + 2) >> 2``, for
    up to 4 channels (more take another rounding), hence groups of 4. A 2K picture's
    level 1 takes ~1 ms there against ~65 ms in numpy (widen, add, narrow): the GUI
    thread paid that whenever the whole picture changed.
    """
    h, w, channels = block.shape
    if h % 2 or w % 2:
        block = np.pad(block, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
    if channels > 4:
        groups = [_half(block[:, :, first : first + 4]) for first in range(0, channels, 4)]
        return np.concatenate(groups, axis=2)
    half_h, half_w = block.shape[0] // 2, block.shape[1] // 2
    half = cv2.resize(block, (half_w, half_h), interpolation=cv2.INTER_AREA)
    return half.reshape(half_h, half_w, channels)  # OpenCV drops a lone channel's axis


class MipPyramid:
    """Levels 1, 2, ... of an ``(H, W, C)`` uint8 picture (``base``, not copied)."""

    def __init__(self, base: np.ndarray) -> None:
        self.base = base
        self._levels: list[np.ndarray] = []
        #: per level: changed rectangles (level-0 texels) not yet averaged into it
        self._stale: list[list[Rect]] = []

    def mark(self, rect: Rect) -> None:
        """``rect`` of the base picture changed."""
        for stale in self._stale:
            stale.append(rect)
            if len(stale) > _MAX_RECTS:
                box = stale[0]
                for other in stale[1:]:
                    box = box.union(other)
                stale[:] = [box]

    def level(self, k: int) -> np.ndarray:
        """Level ``k`` (0 is the base), up to date."""
        for j in range(1, k + 1):
            if j > len(self._levels):  # level j-1 is up to date: average all of it
                self._levels.append(_half(self.base if j == 1 else self._levels[j - 2]))
                self._stale.append([])
            else:
                self._update(j)
        return self.base if k == 0 else self._levels[k - 1]

    def _update(self, j: int) -> None:
        stale = self._stale[j - 1]
        if not stale:
            return
        below = self.base if j == 1 else self._levels[j - 2]
        level = self._levels[j - 1]
        scale = 1 << j
        for rect in stale:
            # the level-j texels this rect touches, and the level-(j-1) block under them
            x0, y0 = rect.x0 // scale, rect.y0 // scale
            x1 = min(-(-rect.x1 // scale), level.shape[1])
            y1 = min(-(-rect.y1 // scale), level.shape[0])
            if x1 > x0 and y1 > y0:
                level[y0:y1, x0:x1] = _half(below[2 * y0 : 2 * y1, 2 * x0 : 2 * x1])
        stale.clear()
