"""Tone curves as a few polynomial pieces, evaluated in one vectorised pass.

A curve of a handful of control points is a handful of cubics (the PCHIP
between them, straight lines beyond), and levels without gamma is straight
lines: evaluated from those pieces, ``f(t)`` needs no table, so the pass over a
texel row has no lookup and LLVM vectorises it (this CPU's LLVM emits no
gathers, so the table kernel ``_kernels.lut_apply`` runs one value at a time).
Curves with more pieces than :data:`MAX_PIECES` keep the table, and so does
levels with a gamma: a vectorised float32 power was measured no faster than the
table (26 against 21-25 ms on 2K x 3 channels, one thread).

A curve here is :class:`Pieces`: piece 0 holds below ``breaks[1]`` in ``u = t``,
piece ``i >= 1`` from ``breaks[i]`` on in ``u = t - breaks[i]``, each
``c0 + u (c1 + u (c2 + u c3))``; unused pieces start at NaN.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, prange

#: pieces one pass evaluates (a curve of up to five inner control points)
MAX_PIECES = 8


@dataclass(frozen=True)
class Pieces:
    """``f(t)`` over the whole real line as polynomial pieces."""

    #: (MAX_PIECES,) float32: where each piece starts (``breaks[0]`` is unused)
    breaks: np.ndarray
    #: (MAX_PIECES, 4) float32: c0..c3 of each piece in its local ``u``
    coeffs: np.ndarray

    @classmethod
    def build(cls, pieces: list[tuple[float, tuple[float, ...]]]) -> Pieces | None:
        """From ``[(start, (c0, c1, c2, c3)), ...]`` (increasing starts); None when too many."""
        if len(pieces) > MAX_PIECES:
            return None
        # unused pieces start at NaN: no comparison selects them, not even t = inf
        breaks = np.full(MAX_PIECES, np.nan, dtype=np.float32)
        coeffs = np.zeros((MAX_PIECES, 4), dtype=np.float32)
        for i, (start, c) in enumerate(pieces):
            breaks[i] = start
            coeffs[i, : len(c)] = c
        breaks[0] = -np.inf
        return cls(breaks, coeffs)

    def __call__(self, t: np.ndarray) -> np.ndarray:
        """``f(t)`` in float64 with numpy (what the kernel computes, for tests and plots)."""
        t = np.asarray(t, dtype=np.float64)
        index = np.searchsorted(self.breaks[1:].astype(np.float64), t, side="right")
        origin = np.where(index > 0, self.breaks.astype(np.float64)[index], 0.0)
        c = self.coeffs.astype(np.float64)[index]
        u = t - origin
        out = c[..., 0] + u * (c[..., 1] + u * (c[..., 2] + u * c[..., 3]))
        straight = (c[..., 2] == 0) & (c[..., 3] == 0)
        return np.where(straight, c[..., 0] + u * c[..., 1], out)


@njit(inline="always", error_model="numpy", nogil=True)
def _evaluate(t, b, k, count):
    """``f(t)`` of the first ``count`` pieces ``b`` (starts), ``k`` (coefficient rows).

    Selects only; ``count`` is a constant at every call (4 or MAX_PIECES), so
    the loop unrolls.
    """
    c0, c1, c2, c3 = k[0]
    x0 = np.float32(0.0)
    for i in range(1, count):
        on = t >= b[i]
        c0 = k[i][0] if on else c0
        c1 = k[i][1] if on else c1
        c2 = k[i][2] if on else c2
        c3 = k[i][3] if on else c3
        x0 = b[i] if on else x0
    u = t - x0
    # a straight piece skips its zero terms: u * 0 would make t = +-inf give NaN
    line = c0 + u * c1
    cubic = c0 + u * (c1 + u * (c2 + u * c3))
    return line if (c2 == 0.0) & (c3 == 0.0) else cubic


_FLAGS = {"cache": True, "fastmath": {"contract", "arcp"}, "nogil": True, "error_model": "numpy"}


@njit(**_FLAGS)
def _pieces_in_locals(breaks, coeffs):
    """The breaks and cubic coefficients as tuples, so a row loop holds them in registers."""
    b = (
        breaks[0], breaks[1], breaks[2], breaks[3],
        breaks[4], breaks[5], breaks[6], breaks[7],
    )  # fmt: skip
    k = (
        (coeffs[0, 0], coeffs[0, 1], coeffs[0, 2], coeffs[0, 3]),
        (coeffs[1, 0], coeffs[1, 1], coeffs[1, 2], coeffs[1, 3]),
        (coeffs[2, 0], coeffs[2, 1], coeffs[2, 2], coeffs[2, 3]),
        (coeffs[3, 0], coeffs[3, 1], coeffs[3, 2], coeffs[3, 3]),
        (coeffs[4, 0], coeffs[4, 1], coeffs[4, 2], coeffs[4, 3]),
        (coeffs[5, 0], coeffs[5, 1], coeffs[5, 2], coeffs[5, 3]),
        (coeffs[6, 0], coeffs[6, 1], coeffs[6, 2], coeffs[6, 3]),
        (coeffs[7, 0], coeffs[7, 1], coeffs[7, 2], coeffs[7, 3]),
    )
    return b, k


@njit(**_FLAGS)
def _pieces_row(src, lo, inv_span, span, breaks, coeffs, out):
    """One row: the pieces read into locals first, so the value loop is selects only."""
    b, k = _pieces_in_locals(breaks, coeffs)
    # a curve of three points is four pieces: half the selects
    if breaks[4] != breaks[4]:
        for i in range(src.shape[0]):
            t = (src[i] - lo[i]) * inv_span[i]
            out[i] = lo[i] + span[i] * _evaluate(t, b, k, 4)
    else:
        for i in range(src.shape[0]):
            t = (src[i] - lo[i]) * inv_span[i]
            out[i] = lo[i] + span[i] * _evaluate(t, b, k, MAX_PIECES)


@njit(**_FLAGS)
def _vectors_row(src, vectors, bounds, quadrature, ranges, breaks, coeffs, out):
    """Vector groups of one texel row (W, C): each magnitude through the curve.

    Group ``g`` is channels ``vectors[bounds[g]:bounds[g + 1]]``; its magnitude
    ``m = sqrt(sum(q v^2))`` maps to ``max(lo + span f((m - lo) / span), 0)``
    (``ranges[g]`` = lo, 1 / span, span) and the vector is scaled by that
    over ``m`` (a zero vector stays zero, a magnitude never turns negative).
    """
    b, k = _pieces_in_locals(breaks, coeffs)
    zero = np.float32(0.0)
    q32 = quadrature.astype(np.float32)
    gain = np.empty(src.shape[0], dtype=np.float32)
    for g in range(bounds.shape[0] - 1):
        first, stop = bounds[g], bounds[g + 1]
        vlo, vinv, vspan = ranges[g, 0], ranges[g, 1], ranges[g, 2]
        # three passes, so the middle one (the curve) runs on contiguous values and
        # vectorises: squared magnitudes, gains, scaled vectors
        c0 = vectors[first]
        # a frame (three adjacent channels of unit weight) without the index lists
        frame = stop - first == 3 and vectors[first + 1] == c0 + 1 and vectors[first + 2] == c0 + 2
        frame = frame and q32[first] == 1 and q32[first + 1] == 1 and q32[first + 2] == 1
        if frame:
            for col in range(src.shape[0]):
                v0, v1, v2 = src[col, c0], src[col, c0 + 1], src[col, c0 + 2]
                gain[col] = v0 * v0 + v1 * v1 + v2 * v2
        else:
            for col in range(src.shape[0]):
                sq = zero
                for i in range(first, stop):
                    v = src[col, vectors[i]]
                    sq += q32[i] * v * v
                gain[col] = sq
        if breaks[4] != breaks[4]:  # four pieces: half the selects, as in _pieces_row
            for col in range(src.shape[0]):
                m = np.sqrt(gain[col])
                mapped = max(vlo + vspan * _evaluate((m - vlo) * vinv, b, k, 4), zero)
                gain[col] = mapped / m if m > zero else zero
        else:
            for col in range(src.shape[0]):
                m = np.sqrt(gain[col])
                mapped = max(vlo + vspan * _evaluate((m - vlo) * vinv, b, k, MAX_PIECES), zero)
                gain[col] = mapped / m if m > zero else zero
        if frame:
            for col in range(src.shape[0]):
                out[col, c0] = src[col, c0] * gain[col]
                out[col, c0 + 1] = src[col, c0 + 1] * gain[col]
                out[col, c0 + 2] = src[col, c0 + 2] * gain[col]
        else:
            for col in range(src.shape[0]):
                for i in range(first, stop):
                    c = vectors[i]
                    out[col, c] = src[col, c] * gain[col]


@njit(parallel=True, **_FLAGS)
def pieces_apply(src, lo, inv_span, span, vectors, bounds, quadrature, ranges, breaks, coeffs, out):
    """A curve of pieces through every channel group of ``src`` (H, W, C), into ``out``.

    Per channel: ``out = lo + span * f((src - lo) / span)`` with each texel
    row read as W x C values (``lo``, ``inv_span``, ``span`` tiled to that
    length; ``src`` and ``out`` C-contiguous), a loop LLVM vectorises. Then
    the vector groups of the same row, while it is in cache
    (:func:`_vectors_row`, which overwrites their channels). ``breaks`` and
    ``coeffs`` are a :class:`Pieces`.
    """
    height, width, channels = src.shape
    flat_src = src.reshape(height, width * channels)
    flat_out = out.reshape(height, width * channels)
    for row in prange(height):
        _pieces_row(flat_src[row], lo, inv_span, span, breaks, coeffs, flat_out[row])
        if bounds.shape[0] > 1:
            _vectors_row(src[row], vectors, bounds, quadrature, ranges, breaks, coeffs, out[row])
