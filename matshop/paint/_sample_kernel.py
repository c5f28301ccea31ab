"""The compiled inner loop of :func:`matshop.paint.sampling.sample_placed`.

numpy spent ~15 full-size temporaries a dab (coordinates, floors, four
gathers); one pass here keeps a large tip dab at a few milliseconds.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def sample_block(
    padded, x0, y0, cx, cy, m00, m01, m10, m11, half_w, half_h, factor, clamp, values, inside
):  # pragma: no cover - compiled
    """Fill ``values`` / ``inside`` ``(h, w)`` for texels from (x0, y0).

    ``padded``: a pyramid level with a one-pixel border (zeros, or its edge
    when ``clamp``); ``m``: texel offset -> image pixels (turn and scale);
    ``half_w, half_h``: half the image's size in level-0 pixels; ``factor``:
    level-0 pixels per level pixel.
    """
    ph, pw = padded.shape
    lo_x, hi_x = (1.0, pw - 2.0) if clamp else (0.0, pw - 1.0)
    lo_y, hi_y = (1.0, ph - 2.0) if clamp else (0.0, ph - 1.0)
    height, width = values.shape
    # factor is a power of two: multiplying by its inverse is the division, bit for bit,
    # without two float divisions a texel (the loop's slowest instructions)
    inv_factor = 1.0 / factor
    for row in range(height):
        dy = y0 + row + 0.5 - cy
        dx = x0 + 0.5 - cx
        # image position of the row's first texel, then one step a texel (affine: exact enough,
        # each row restarts from its own start)
        u = m00 * dx + m01 * dy + half_w
        v = m10 * dx + m11 * dy + half_h
        for col in range(width):
            if col:
                u += m00
                v += m10
            inside[row, col] = 0.0 <= u <= 2.0 * half_w and 0.0 <= v <= 2.0 * half_h
            x = u * inv_factor + 0.5  # -0.5 to pixel centres, +1 for the border
            y = v * inv_factor + 0.5
            if not clamp and (x <= lo_x or x >= hi_x or y <= lo_y or y >= hi_y):
                values[row, col] = 0.0  # on or past the zero border
                continue
            x = min(max(x, lo_x), hi_x)
            y = min(max(y, lo_y), hi_y)
            i0 = int(math.floor(x))
            j0 = int(math.floor(y))
            fx = x - i0
            fy = y - j0
            i1 = min(i0 + 1, pw - 1)
            j1 = min(j0 + 1, ph - 1)
            top = padded[j0, i0] * (1.0 - fx) + padded[j0, i1] * fx
            bottom = padded[j1, i0] * (1.0 - fx) + padded[j1, i1] * fx
            values[row, col] = np.float32(top * (1.0 - fy) + bottom * fy)
