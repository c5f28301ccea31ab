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


@njit(cache=True, inline="always", nogil=True)
def _lut_at(lut, t, tail):
    # linear interpolation in a uniform table over [0, 1], extended linearly
    # beyond it so out-of-range intermediates keep their meaning: with the end
    # segments' slope (tail < 0), or with slope ``tail``
    last = lut.shape[0] - 1
    pos = t * last
    if pos <= 0.0:
        if tail >= 0.0:
            return lut[0] + t * tail
        return lut[0] + pos * (lut[1] - lut[0])
    if pos >= last:
        if tail >= 0.0:
            return lut[last] + (t - 1.0) * tail
        return lut[last] + (pos - last) * (lut[last] - lut[last - 1])
    i = int(pos)
    frac = pos - i
    return lut[i] + frac * (lut[i + 1] - lut[i])


@njit(cache=True, parallel=True, fastmath=True, nogil=True)
def lut_channels(src, channels, lo, span, lut, tail, out):
    """For each listed channel c: ``out = lo[c] + span[c] * lut((src - lo[c]) / span[c])``.

    Beyond [0, 1] the table continues with its end segments (``tail < 0``) or
    with slope ``tail``. float32 arithmetic, divisions hoisted and one channel
    at a time along a row (constants in registers): 2-3x faster than texel-major.
    """
    height, width, _ = src.shape
    last = lut.shape[0] - 1
    lut32 = lut.astype(np.float32)
    slope32 = np.empty(last, np.float32)
    for i in range(last):
        # from the float64 table: near flat ends the float32 difference of two
        # rounded values would be off by whole ulps, and extrapolation scales it
        slope32[i] = np.float32(lut[i + 1] - lut[i])
    own_tails = tail >= 0.0
    tail32 = np.float32(tail / last)  # per table step
    for row in prange(height):
        for k in range(channels.shape[0]):
            c = channels[k]
            lo32 = np.float32(lo[k])
            span32 = np.float32(span[k])
            to_pos = np.float32(last / span[k])
            for col in range(width):
                pos = (src[row, col, c] - lo32) * to_pos
                # int(pos + 1) - 1 is floor(pos) wherever the clamp does not act
                # (clamping the segment, not the position, extends the end segments)
                i = min(max(int(pos + np.float32(1.0)) - 1, 0), last - 1)
                value = lut32[i] + (pos - np.float32(i)) * slope32[i]
                if own_tails:
                    if pos < np.float32(0.0):
                        value = lut32[0] + pos * tail32
                    elif pos > np.float32(last):
                        value = lut32[last] + (pos - np.float32(last)) * tail32
                out[row, col, c] = lo32 + span32 * value


@njit(cache=True, parallel=True, nogil=True)
def lut_vector(src, channels, quadrature, lut, lo, span, tail, out):
    """The listed channels as one vector, its magnitude through the table over ``[lo, lo + span]``.

    ``v * m' / |v|`` with ``m' = max(lo + span * lut((|v| - lo) / span), 0)`` and
    ``|v|^2 = sum(q v^2)``: a magnitude cannot go negative (that would flip the
    vector), so an extrapolated curve below ``lo`` stops at zero. ``tail``: as in
    :func:`lut_channels`.
    """
    height, width, _ = src.shape
    inv = 1.0 / span
    for row in prange(height):
        for col in range(width):
            sq = 0.0
            for k in range(channels.shape[0]):
                v = src[row, col, channels[k]]
                sq += quadrature[k] * v * v
            magnitude = np.sqrt(sq)
            if magnitude > 0.0:
                mapped = lo + span * _lut_at(lut, (magnitude - lo) * inv, tail)
                gain = max(mapped, 0.0) / magnitude
            else:
                gain = 0.0  # a zero vector has no direction to stretch
            for k in range(channels.shape[0]):
                c = channels[k]
                out[row, col, c] = src[row, col, c] * gain
