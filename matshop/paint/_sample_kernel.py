"""The compiled inner loop of :func:`matshop.paint.sampling.sample_placed`.

numpy spent ~15 full-size temporaries a dab (coordinates, floors, four
gathers); one pass here keeps a large tip dab at a few milliseconds.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(inline="always", nogil=True)
def _interpolate(padded, x, y):
    """Bilinear between the pixels of ``padded`` at (x, y) in its pixels, within its border
    (0 <= x <= pw - 1, 0 <= y <= ph - 1)."""
    ph, pw = padded.shape
    # x, y >= 0 here: truncation is the floor, and unsigned indices skip numba's
    # wraparound fix-up of each of the four loads
    i0 = np.uint64(np.int64(x))
    j0 = np.uint64(np.int64(y))
    fx = x - np.float64(i0)
    fy = y - np.float64(j0)
    i1 = min(i0 + np.uint64(1), np.uint64(pw - 1))
    j1 = min(j0 + np.uint64(1), np.uint64(ph - 1))
    top = padded[j0, i0] * (1.0 - fx) + padded[j0, i1] * fx
    bottom = padded[j1, i0] * (1.0 - fx) + padded[j1, i1] * fx
    return np.float32(top * (1.0 - fy) + bottom * fy)


@njit(inline="always", nogil=True)
def _bilinear(padded, u, v, inv_factor, lo_x, hi_x, lo_y, hi_y, clamp):
    """The level's bilinear sample at image position (u, v) (level-0 pixels)."""
    x = u * inv_factor + 0.5  # -0.5 to pixel centres, +1 for the border
    y = v * inv_factor + 0.5
    if lo_x < x < hi_x and lo_y < y < hi_y:
        # inside: neither the border test nor the clamps below change anything, so one
        # test does (tip dab / cv2.warpAffine on an AMD EPYC, r=64 3.16-3.20 -> 2.84-2.89,
        # r=256 4.41-4.47 -> 3.92-4.10; stencil mask 3.89-3.92 -> 3.75-3.80)
        return _interpolate(padded, x, y)
    if not clamp and (x <= lo_x or x >= hi_x or y <= lo_y or y >= hi_y):
        return np.float32(0.0)  # on or past the zero border
    return _interpolate(padded, min(max(x, lo_x), hi_x), min(max(y, lo_y), hi_y))


@njit(inline="always", nogil=True)
def _columns_between(start, step, lo, hi, width):
    """``[first, stop)`` holding every column ``col < width`` with ``lo < start + col * step
    < hi``, and at most a column more on each side (the caller still tests each one)."""
    if step == 0.0:
        return (0, width) if lo < start < hi else (0, 0)
    a = (lo - start) / step
    b = (hi - start) / step
    if step < 0.0:
        a, b = b, a
    # clamped while still floats: a step near 0 puts them past any integer
    first = int(math.floor(min(max(a, 0.0), float(width))))
    stop = int(math.ceil(min(max(b, -1.0), float(width))) + 1)
    return first, max(first, min(stop, width))


@njit(cache=True, nogil=True)
def sample_block(
    padded, x0, y0, cx, cy, m00, m01, m10, m11, half_w, half_h, factor, clamp, values, inside
):  # pragma: no cover - compiled
    """Fill ``values`` / ``inside`` ``(h, w)`` for texels from (x0, y0).

    ``padded``: a pyramid level with a one-pixel border (zeros, or its edge
    when ``clamp``); ``m``: texel offset -> image pixels (turn and scale);
    ``half_w, half_h``: half the image's size in level-0 pixels; ``factor``:
    level-0 pixels per level pixel. ``inside`` of shape ``(0, 0)``: not
    wanted (a tip's dab); then, with a zero border, the columns of a row that
    fall past the image are found first and only set to 0 (half a turned tip
    dab's block: r=256 dab / cv2.warpAffine 5.4 -> 4.0 on an AMD EPYC; unsigned
    indices in :func:`_bilinear` then 5.5 -> 4.4 and the stencil 5.1 -> 4.0 to 4.5 on
    a Sapphire Rapids).
    """
    ph, pw = padded.shape
    lo_x, hi_x = (1.0, pw - 2.0) if clamp else (0.0, pw - 1.0)
    lo_y, hi_y = (1.0, ph - 2.0) if clamp else (0.0, ph - 1.0)
    height, width = values.shape
    want_inside = inside.shape[0] > 0
    # factor is a power of two: multiplying by its inverse is the division, bit for bit,
    # without two float divisions a texel (the loop's slowest instructions)
    inv_factor = 1.0 / factor
    for row in range(height):
        dy = y0 + row + 0.5 - cy
        dx = x0 + 0.5 - cx
        # image position of the row's first texel, then one step a texel (affine: exact enough,
        # each row restarts from its own start)
        u0 = m00 * dx + m01 * dy + half_w
        v0 = m10 * dx + m11 * dy + half_h
        if want_inside:
            u, v = u0, v0
            for col in range(width):
                if col:
                    u += m00
                    v += m10
                inside[row, col] = 0.0 <= u <= 2.0 * half_w and 0.0 <= v <= 2.0 * half_h
                values[row, col] = _bilinear(
                    padded, u, v, inv_factor, lo_x, hi_x, lo_y, hi_y, clamp
                )
            continue
        first, stop = 0, width
        if not clamp:
            first_x, stop_x = _columns_between(
                u0 * inv_factor + 0.5, m00 * inv_factor, lo_x, hi_x, width
            )
            first_y, stop_y = _columns_between(
                v0 * inv_factor + 0.5, m10 * inv_factor, lo_y, hi_y, width
            )
            first = max(first_x, first_y)
            stop = max(first, min(stop_x, stop_y))
            values[row, :first] = 0.0
            values[row, stop:] = 0.0
        u = u0 + first * m00
        v = v0 + first * m10
        for col in range(first, stop):
            if col > first:
                u += m00
                v += m10
            values[row, col] = _bilinear(padded, u, v, inv_factor, lo_x, hi_x, lo_y, hi_y, clamp)
