"""Fused per-texel kernels for the pointwise ops (mask blending, LUT curves).

numpy would make several full-size temporaries for ``a + m * (b - a)`` or a
LUT with linear interpolation; these single passes stay near memory
bandwidth. They run in parallel over rows and accept strided views (a
channel slice of a wider edit array), so callers never copy to feed them.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, parallel=True, nogil=True)
def lerp(a, b, mask, out):
    """``out = (1 - mask) * a + mask * b``, mask ``(H, W)`` broadcast over channels.

    Written with both weights so mask 0 and 1 give ``a`` and ``b`` bit-exactly, and
    in float32 like the layer compositor's normal blend (``layers/blend.py``), so a
    masked op and a masked filter layer give the same bits.
    """
    height, width, channels = a.shape
    one = np.float32(1.0)
    for row in prange(height):
        for col in range(width):
            m = mask[row, col]
            keep = one - m
            for c in range(channels):
                out[row, col, c] = keep * a[row, col, c] + m * b[row, col, c]


@njit(cache=True, parallel=True, nogil=True)
def scale_lerp(a, factor, mask, out):
    """``out = (1 - mask) * a + mask * (factor * a)``: a masked scale in one pass."""
    height, width, channels = a.shape
    one = np.float32(1.0)
    for row in prange(height):
        for col in range(width):
            m = mask[row, col]
            keep = one - m
            for c in range(channels):
                value = a[row, col, c]
                out[row, col, c] = keep * value + m * (factor * value)


def line_tables(
    lut: np.ndarray, lo: float, span: float, tail: float
) -> tuple[np.ndarray, float, float]:
    """``lo + span * lut((x - lo) / span)`` as straight lines ``ab[j, 0] + x * ab[j, 1]``.

    Line 0 continues the table below 0, lines 1..last are its segments, line
    last + 1 continues it above 1: with slope ``tail`` (in the curve's units)
    or, with ``tail < 0``, along the end segments. Returns ``(ab, to_pos,
    shift)``; the line of ``x`` is ``j = clamp(int(x * to_pos + shift), 0,
    last + 1)``. Built in float64 and rounded once, so :func:`lut_apply`
    spends one multiply-add per value, and both coefficients share a cache line.
    """
    lut = np.asarray(lut, dtype=np.float64)
    last = lut.shape[0] - 1
    step = np.diff(lut)  # per table step
    end = (step[0], step[-1]) if tail < 0 else (tail / last, tail / last)
    slope = np.concatenate([[end[0]], step, [end[1]]])
    value = np.concatenate([[lut[0]], lut[:-1], [lut[-1]]])  # where each line is anchored
    anchor = np.concatenate([[0.0], np.arange(last, dtype=np.float64), [float(last)]])
    to_pos = last / span
    offset = -lo * to_pos  # table position pos = x * to_pos + offset
    # on line j: value[j] + (pos - anchor[j]) * slope[j], rescaled to lo + span * (...)
    ab = np.stack([lo + span * (value + (offset - anchor) * slope), span * slope * to_pos], -1)
    return ab.astype(np.float32), to_pos, offset + 1.0


@njit(cache=True, parallel=True, fastmath=True, nogil=True, error_model="numpy")
def lut_apply(src, ab, to_pos, shift, vectors, bounds, quadrature, vab, vpos, out):
    """A curve through every channel group of ``src`` in one pass.

    Channel ``c`` per channel: ``out = ab[c, j, 0] + src * ab[c, j, 1]`` on the
    line ``j`` of :func:`line_tables`. Vector groups, channels
    ``vectors[bounds[g]:bounds[g + 1]]`` (their per-channel lines are ignored):
    the quadrature-weighted magnitude ``m = sqrt(sum(q v^2))`` goes through the
    group's lines ``vab[g]`` (``vpos[g]`` = to_pos, shift) and the vector is
    scaled by ``max(m', 0) / m`` (a magnitude cannot go negative: that would
    flip the vector; a zero vector has no direction to stretch and stays zero).

    float32 throughout. Texel by texel over all channels, then each vector
    group along the row while it is in cache: on CPUs without fast gathers
    (Downfall microcode) nothing here vectorizes, and this order measured 2x
    faster than channel by channel or a list of channels; a contiguous
    3-channel group of unit weights (a frame) has its own unrolled loop.
    """
    height, width, channels = src.shape
    top = ab.shape[1] - 1
    vtop = vab.shape[1] - 1
    scale32 = to_pos.astype(np.float32)
    shift32 = shift.astype(np.float32)
    q32 = quadrature.astype(np.float32)
    zero = np.float32(0.0)
    # clamped as a float (huge values) and as an unsigned index (NaN converts to anything)
    ftop, utop = np.float32(top), np.uint32(top)
    vftop, vutop = np.float32(vtop), np.uint32(vtop)
    # the vector groups' channels are written by their own loop: skip them here
    scalar = np.ones(channels, dtype=np.bool_)
    for i in range(vectors.shape[0]):
        scalar[vectors[i]] = False
    for row in prange(height):
        for col in range(width):
            for c in range(channels):
                if scalar[c]:
                    x = src[row, col, c]
                    j = min(np.uint32(min(max(x * scale32[c] + shift32[c], zero), ftop)), utop)
                    out[row, col, c] = ab[c, j, 0] + x * ab[c, j, 1]
        for g in range(bounds.shape[0] - 1):
            first, stop = bounds[g], bounds[g + 1]
            vscale, vshift = np.float32(vpos[g, 0]), np.float32(vpos[g, 1])
            c0 = vectors[first]
            frame = stop - first == 3 and vectors[first + 2] == c0 + 2
            frame = frame and vectors[first + 1] == c0 + 1
            frame = frame and q32[first] == 1 and q32[first + 1] == 1 and q32[first + 2] == 1
            for col in range(width):
                if frame:
                    v0, v1, v2 = src[row, col, c0], src[row, col, c0 + 1], src[row, col, c0 + 2]
                    m = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
                else:
                    sq = zero
                    for i in range(first, stop):
                        v = src[row, col, vectors[i]]
                        sq += q32[i] * v * v
                    m = np.sqrt(sq)
                gain = zero
                if m > zero:
                    j = min(np.uint32(min(max(m * vscale + vshift, zero), vftop)), vutop)
                    gain = max(vab[g, j, 0] + m * vab[g, j, 1], zero) / m
                if frame:
                    out[row, col, c0] = v0 * gain
                    out[row, col, c0 + 1] = v1 * gain
                    out[row, col, c0 + 2] = v2 * gain
                else:
                    for i in range(first, stop):
                        c = vectors[i]
                        out[row, col, c] = src[row, col, c] * gain
