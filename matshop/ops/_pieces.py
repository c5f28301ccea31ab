"""Tone curves as a few polynomial pieces, evaluated in one vectorised pass.

A curve of a handful of control points is a handful of cubics (the PCHIP
between them, straight lines beyond), and levels is straight lines and one
power: evaluated from those pieces, ``f(t)`` needs no table, so the pass over a
texel row has no lookup and LLVM vectorises it (this CPU's LLVM emits no
gathers, so the table kernel ``_kernels.lut_apply`` runs one value at a time,
2.0 ns a value in cache; levels' pieces, power included, take 1.6 at 2K).
Curves with more pieces than :data:`MAX_PIECES` keep the table. The row
passes ask for 512-bit vectors (:mod:`._vector_width`): levels' power is
bound by arithmetic (2K x 3 channels, two threads: 10.1 -> 7.5 ms).

A curve here is :class:`Pieces`: piece 0 holds below ``breaks[1]`` in ``u = t``,
piece ``i >= 1`` from ``breaks[i]`` on in ``u = t - breaks[i]``, each
``c0 + u (c1 + u (c2 + u c3))``; unused pieces start at NaN. With an
``exponent`` p other than 1 (levels' 1 / gamma) there are three pieces:
lines ``c0 + c1 u`` first and last, and ``c0 + c1 clamp(c2 (u - c3), 0, 1)^p``
between, from 0 to 1, where the clamp holds it flat, so the kernel adds the
lines' slopes as ``c1 min(t, 0)`` and ``c1 max(t - 1, 0)`` instead of choosing
a piece (:func:`_power_curve`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from ..parallel_chunks import next_chunk
from ._vector_width import prefer_512_bit_vectors

#: pieces one pass evaluates (a curve of up to five inner control points)
MAX_PIECES = 8


@dataclass(frozen=True)
class Pieces:
    """``f(t)`` over the whole real line as polynomial pieces."""

    #: (MAX_PIECES,) float32: where each piece starts (``breaks[0]`` is unused)
    breaks: np.ndarray
    #: (MAX_PIECES, 4) float32: c0..c3 of each piece in its local ``u``
    coeffs: np.ndarray
    #: p of the power pieces (1: cubics)
    exponent: float = 1.0

    @classmethod
    def build(
        cls, pieces: list[tuple[float, tuple[float, ...]]], exponent: float = 1.0
    ) -> Pieces | None:
        """From ``[(start, (c0, c1, c2, c3)), ...]`` (increasing starts); None when too many."""
        if len(pieces) > MAX_PIECES:
            return None
        if exponent != 1.0 and not _power_meets_its_lines(pieces):
            raise ValueError(
                "a curve with an exponent is a line, a power from 0 to 1 (its input "
                "clamped at both ends) and a line, meeting where they start"
            )
        # unused pieces start at NaN: no comparison selects them, not even t = inf
        breaks = np.full(MAX_PIECES, np.nan, dtype=np.float32)
        coeffs = np.zeros((MAX_PIECES, 4), dtype=np.float32)
        for i, (start, c) in enumerate(pieces):
            breaks[i] = start
            coeffs[i, : len(c)] = c
        breaks[0] = -np.inf
        return cls(breaks, coeffs, float(exponent))

    def __call__(self, t: np.ndarray) -> np.ndarray:
        """``f(t)`` in float64 with numpy (what the kernel computes, for tests and plots)."""
        t = np.asarray(t, dtype=np.float64)
        index = np.searchsorted(self.breaks[1:].astype(np.float64), t, side="right")
        origin = np.where(index > 0, self.breaks.astype(np.float64)[index], 0.0)
        c = self.coeffs.astype(np.float64)[index]
        u = t - origin
        straight = (c[..., 2] == 0) & (c[..., 3] == 0)
        if self.exponent != 1.0:
            with np.errstate(invalid="ignore"):
                v = np.clip(c[..., 2] * (u - c[..., 3]), 0.0, 1.0)
                power = c[..., 0] + c[..., 1] * v**self.exponent
            return np.where(straight, c[..., 0] + u * c[..., 1], power)
        out = c[..., 0] + u * (c[..., 1] + u * (c[..., 2] + u * c[..., 3]))
        return np.where(straight, c[..., 0] + u * c[..., 1], out)


def _power_meets_its_lines(pieces: list[tuple[float, tuple[float, ...]]]) -> bool:
    """Three pieces, the power's from 0 to 1, its ``clamp(c2 (t - c3), 0, 1)`` at 0
    for t <= 0 and at 1 for t >= 1, the lines starting from its values there
    (what :func:`_power_curve` relies on: it reads only the lines' slopes)."""
    if [start for start, _ in pieces[1:]] != [0.0, 1.0]:
        return False
    c0, c1, c2, c3 = (tuple(pieces[1][1]) + (0.0,) * 4)[:4]
    flat = c2 * -c3 <= 0.0 and c2 * (1.0 - c3) >= 1.0
    return flat and bool(np.isclose(pieces[0][1][0], c0) and np.isclose(pieces[2][1][0], c0 + c1))


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


_ONE = np.float32(1.0)
# the bits of sqrt(1/2) rounded to float32: a float's bits less these, over 2^23
# and floored, are the k with x / 2^k in [sqrt(1/2), sqrt(2)) (musl's logf trick)
_OFFSET = np.float32(0x3F3504F3)
# log2 m = u / ln 2 + u^2 Q(u), u = m - 1 over m in [sqrt(1/2), sqrt(2)): Q of degree 7
# fitted for the least largest error (Lawson's reweighted least squares on Chebyshev
# nodes), 9.3e-9 absolute; no division, unlike the atanh series' form in (m - 1) / (m + 1)
_INV_LN2 = np.float32(1.0 / math.log(2.0))
_Q = tuple(
    np.float32(c)
    for c in (
        -0.7213472723960876,
        0.4809112250804901,
        -0.36070969700813293,
        0.28786978125572205,
        -0.2387997955083847,
        0.2161056399345398,
        -0.2083517611026764,
        0.12599848210811615,
    )
)
# 2^r over |r| <= 1/2, likewise: 1.6e-8 relative
_E = tuple(
    np.float32(c)
    for c in (
        1.0,
        0.69314718246459961,
        0.24022646248340607,
        0.055503290146589279,
        0.0096185198053717613,
        0.0013399859890341759,
        0.00015337577497120947,
    )
)


# 2^23 and 127 2^23: a float32's exponent field, written by a fused multiply-add
_FIELD = np.float32(8388608.0)
_BIAS = np.float32(127.0 * 8388608.0)
#: what the power's input is scaled by: a subnormal x becomes normal (2^24 x)
POWER_SCALE = 16777216.0


@njit(inline="always", error_model="numpy", fastmath={"contract"}, nogil=True)
def _pow_scaled(v, p):
    """``(v / 2^24) ** p`` for float32 ``v`` in [0, 2^25) and ``p = (hi, lo, p)`` of
    :func:`split_exponent`.

    The input comes scaled by :data:`POWER_SCALE` (folded into the caller's
    affine map), so a subnormal ``x`` arrives normal and every value takes the
    same path. Arithmetic, bit casts and selects only (a libm ``pow`` would
    keep the loop scalar), all float32: ``log2 v = k + log2 m`` with m in
    [sqrt(1/2), sqrt(2)) from the bits, ``log2 m`` a polynomial in ``m - 1``,
    then ``2^z = 2^n 2^r``, |r| <= 1/2, by a polynomial. ``p (k - 24)`` is
    summed as ``p_hi (k - 24)`` (exact: p_hi has 12 significant bits) plus the
    rest, so large ``|z|`` loses no bits. The loop is bound by the number of
    vector operations, so every one counts: fitted polynomials one degree
    shorter than Taylor's, no division, no subnormal branch, no integer lanes,
    the exponent fields and offsets as fused multiply-adds, one rounding to
    n. Relative error 1.2 ulp (p = 1/1.4), 1.5 ulp (p = 2); for p up to 100,
    1e-7 of 1 absolute. Results below 2^-127 flush to 0; v = 0 gives 0.
    """
    p_hi, p_lo, p32 = p
    # k from the bits read as a number, in float32 (numba's integer arithmetic is
    # 64-bit: half-width lanes); its rounding (under 2^7 of 2^23) can only move m
    # a few ulp past the interval, where the polynomial still holds
    k = np.floor(
        np.float32(np.float32(v).view(np.int32)) * np.float32(2.0**-23)
        - _OFFSET * np.float32(2.0**-23)
    )
    # m = v 2^-k, 2^-k from its exponent field (exact: an integer times 2^23)
    m = v * np.int32(k * -_FIELD + _BIAS).view(np.float32)
    u = m - _ONE
    u2 = u * u
    # Estrin's scheme: four short chains side by side instead of one of eight steps
    q01 = _Q[0] + u * _Q[1]
    q23 = _Q[2] + u * _Q[3]
    q45 = _Q[4] + u * _Q[5]
    q67 = _Q[6] + u * _Q[7]
    u4 = u2 * u2
    q = (q01 + u2 * q23) + u4 * (q45 + u2 * q67)
    # the leading term rounded once, inside the fused add
    log2_m = u * _INV_LN2 + u2 * q
    # p (k - 24) = p_hi (k - 24) (exact: 12 by 8 significant bits) + p_lo (k - 24);
    # n rounded from the whole, and a - n is exact, so r is rounded once
    a = k * p_hi - np.float32(24.0) * p_hi
    rest = k * p_lo + (p32 * log2_m - np.float32(24.0) * p_lo)
    n = np.rint(a + rest)
    r = (a - n) + rest
    q = _E[6]
    for c in (_E[5], _E[4], _E[3], _E[2], _E[1], _E[0]):
        q = q * r + c
    n = max(n, np.float32(-127.0))
    y = q * np.int32(n * _FIELD + _BIAS).view(np.float32)
    return y if v > np.float32(0.0) else np.float32(0.0)


#: the rows of :func:`power_constants`: a channel's levels curve as one affine map
#: into the power, the power's affine map out, and where the line above starts,
#: all of ``d = x - lo``
POWER_ROWS = ("lo", "a", "b", "p0", "p1", "s2")


@njit(inline="always", error_model="numpy", fastmath={"contract"}, nogil=True)
def _power_curve(x, lo, a, b, p0, p1, s2, below, above, p):
    """``lo + span f((x - lo) / span)`` of a curve with an exponent, from
    :func:`power_constants`: the power, plus the line below 0 (slope ``below``)
    and the line above ``s2`` (slope ``above``) as terms that are 0 elsewhere.

    Sums rather than selects: the power is flat beyond its ends (its input
    clamps there), so adding the lines' slopes gives the same values in fewer
    vector operations and table loads than choosing between three pieces (the
    loop is bound by them; 2K x 3 channels about 10% faster). ``d = x - lo``
    first: the affine maps of ``d`` keep their precision when the range sits
    far from 0 (a map of ``x`` would cancel ``lo`` against ``x`` after rounding
    both). NaN stays NaN (through the line below, as in :func:`_evaluate`).
    """
    zero = np.float32(0.0)
    d = x - lo
    v = min(max(d * a + b, zero), np.float32(POWER_SCALE))
    out = p0 + p1 * _pow_scaled(v, p)
    out = below * (zero if d >= zero else d) + out
    return above * max(d - s2, zero) + out


def power_constants(
    lo: np.ndarray, span: np.ndarray, breaks: np.ndarray, coeffs: np.ndarray
) -> np.ndarray:
    """``(len(lo), len(POWER_ROWS))`` float32: the power piece of a curve with an
    exponent (:class:`Pieces`) mapped from ``t = (x - lo) / span`` to ``d = x - lo``
    and from ``f`` to ``lo + span f``, per range (``lo``, ``span``), in float64.

    What :func:`_power_curve` reads, with the lines' slopes (the same in ``d``
    as in ``t``): one fused multiply-add per map instead of the chain through
    ``t`` (the power loop is bound by its operations).
    """
    lo = np.asarray(lo, dtype=np.float64)
    span = np.asarray(span, dtype=np.float64)
    b = breaks.astype(np.float64)
    k = coeffs.astype(np.float64)
    ones = np.ones_like(lo)
    rows = {
        "lo": lo,
        # the power's input v = c2 ((t - b1) - c3), scaled for _pow_scaled
        "a": ones * (k[1, 2] * POWER_SCALE) / span,
        "b": ones * (-k[1, 2] * (b[1] + k[1, 3]) * POWER_SCALE),
        "p0": lo + span * k[1, 0],
        "p1": span * k[1, 1],
        "s2": span * b[2],
    }
    return np.stack([rows[name] for name in POWER_ROWS], axis=1).astype(np.float32)


#: a tile row's values at least: its loop outlasts the set-up of the next
_TILE_VALUES = 256


def power_tiles(constants: np.ndarray) -> np.ndarray:
    """``(len(POWER_ROWS), L)``: a texel's channels' :func:`power_constants`
    ``(C, rows)`` repeated over L values, L a multiple of C and of 16 (whole
    texels, whole 512-bit vectors)."""
    channels = constants.shape[0]
    period = math.lcm(channels, 16)
    period *= -(-_TILE_VALUES // period)
    return np.ascontiguousarray(np.tile(constants.T, period // channels))


def split_exponent(p: float) -> np.ndarray:
    """``(p_hi, p_lo, p)`` float32 for :func:`_pow_scaled`: p_hi has 12 significant bits."""
    mantissa, exponent = math.frexp(p)
    hi = math.ldexp(round(mantissa * 4096.0) / 4096.0, exponent)
    return np.array([hi, p - hi, p], dtype=np.float32)


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
    prefer_512_bit_vectors()
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
def _power_row(src, tiles, power, below, above, out):
    """One row of a curve with an exponent: ``tiles`` (:data:`POWER_ROWS`, L) are
    :func:`power_constants` repeating every L values (whole texels), so they stay
    in the first-level cache while the row streams past; ``below`` and ``above``
    the end lines' slopes."""
    prefer_512_bit_vectors()
    p = (power[0], power[1], power[2])
    period = tiles.shape[1]
    lo, a, b, p0, p1, s2 = tiles[0], tiles[1], tiles[2], tiles[3], tiles[4], tiles[5]
    for start in range(0, src.shape[0], period):
        x = src[start : start + period]
        y = out[start : start + period]
        for j in range(x.shape[0]):
            y[j] = _power_curve(x[j], lo[j], a[j], b[j], p0[j], p1[j], s2[j], below, above, p)


@njit(inline="always", **_FLAGS)
def _is_frame(vectors, first, stop, quadrature):
    """Three adjacent channels of unit weight: handled without the index lists."""
    if stop - first != 3:
        return False
    c0 = vectors[first]
    adjacent = vectors[first + 1] == c0 + 1 and vectors[first + 2] == c0 + 2
    unit = quadrature[first] == 1.0 and quadrature[first + 1] == 1.0
    return adjacent and unit and quadrature[first + 2] == 1.0


@njit(**_FLAGS)
def _vector_squares(src, vectors, first, stop, quadrature, frame, squares):
    """``squares[col] = sum(q v^2)`` of the group ``vectors[first:stop]`` of a row (W, C)
    (``frame``: :func:`_is_frame`)."""
    channels = np.uint64(src.shape[1])
    flat = src.reshape(-1)
    if frame:
        # unsigned indices: a signed one is checked for wraparound at every load
        at = np.uint64(vectors[first])
        for col in range(src.shape[0]):
            v0, v1, v2 = flat[at], flat[at + np.uint64(1)], flat[at + np.uint64(2)]
            squares[col] = v0 * v0 + v1 * v1 + v2 * v2
            at += channels
        return
    for col in range(src.shape[0]):
        sq = np.float32(0.0)
        for i in range(first, stop):
            v = src[np.uint64(col), np.uint64(vectors[i])]
            sq += np.float32(quadrature[i]) * v * v
        squares[col] = sq


@njit(**_FLAGS)
def _vector_scale(src, vectors, first, stop, frame, gain, out):
    """``out = src * gain`` on the group's channels of a row (W, C) (``frame``:
    :func:`_is_frame`)."""
    channels = np.uint64(src.shape[1])
    if frame:
        flat_src, flat_out = src.reshape(-1), out.reshape(-1)
        at = np.uint64(vectors[first])
        for col in range(src.shape[0]):
            g = gain[col]
            flat_out[at] = flat_src[at] * g
            flat_out[at + np.uint64(1)] = flat_src[at + np.uint64(1)] * g
            flat_out[at + np.uint64(2)] = flat_src[at + np.uint64(2)] * g
            at += channels
        return
    for col in range(src.shape[0]):
        at = np.uint64(col)
        for i in range(first, stop):
            c = np.uint64(vectors[i])
            out[at, c] = src[at, c] * gain[col]


@njit(**_FLAGS)
def _vector_gains(squares, lo, inv_span, span, constants, breaks, coeffs, power, gain):
    """``gain = max(lo + span f((m - lo) / span), 0) / m`` of ``m = sqrt(squares)``
    (a zero vector keeps gain 0, a magnitude never turns negative); a curve with an
    exponent reads its ``constants`` (one row of :func:`power_constants`) instead.
    Out of place: LLVM does not vectorise a loop that writes the array it reads."""
    prefer_512_bit_vectors()
    zero = np.float32(0.0)
    if power[2] != 1.0:
        p = (power[0], power[1], power[2])
        lo_, a, b, p0, p1, s2 = (
            constants[0], constants[1], constants[2], constants[3], constants[4], constants[5]
        )  # fmt: skip
        below, above = coeffs[0, 1], coeffs[2, 1]
        for col in range(gain.shape[0]):
            m = np.sqrt(squares[col])
            mapped = max(_power_curve(m, lo_, a, b, p0, p1, s2, below, above, p), zero)
            gain[col] = mapped / m if m > zero else zero
        return
    b, k = _pieces_in_locals(breaks, coeffs)
    if breaks[4] != breaks[4]:  # four pieces: half the selects, as in _pieces_row
        for col in range(gain.shape[0]):
            m = np.sqrt(squares[col])
            mapped = max(lo + span * _evaluate((m - lo) * inv_span, b, k, 4), zero)
            gain[col] = mapped / m if m > zero else zero
    else:
        for col in range(gain.shape[0]):
            m = np.sqrt(squares[col])
            mapped = max(lo + span * _evaluate((m - lo) * inv_span, b, k, MAX_PIECES), zero)
            gain[col] = mapped / m if m > zero else zero


@njit(**_FLAGS)
def _vectors_row(
    src, vectors, bounds, quadrature, ranges, constants, breaks, coeffs, power, out, scratch
):
    """Vector groups of one texel row (W, C): each magnitude through the curve.

    Group ``g`` is channels ``vectors[bounds[g]:bounds[g + 1]]``; its magnitude
    ``m = sqrt(sum(q v^2))`` maps to ``max(lo + span f((m - lo) / span), 0)``
    (``ranges[g]`` = lo, 1 / span, span; ``constants[g]`` for a curve with an
    exponent) and the vector is scaled by that over ``m``. Three passes, so
    the middle one (the curve) runs on contiguous values (``scratch``, 2 x W)
    and vectorises: squared magnitudes, gains, scaled vectors.
    """
    squares, gain = scratch[0], scratch[1]
    for g in range(bounds.shape[0] - 1):
        first, stop = bounds[g], bounds[g + 1]
        frame = _is_frame(vectors, first, stop, quadrature)
        _vector_squares(src, vectors, first, stop, quadrature, frame, squares)
        _vector_gains(
            squares, ranges[g, 0], ranges[g, 1], ranges[g, 2], constants[g],
            breaks, coeffs, power, gain,
        )  # fmt: skip
        _vector_scale(src, vectors, first, stop, frame, gain, out)


@njit(parallel=True, **_FLAGS)
def pieces_apply(
    src,
    lo,
    inv_span,
    span,
    vectors,
    bounds,
    quadrature,
    ranges,
    constants,
    breaks,
    coeffs,
    power,
    out,
    threads,
    taken,
):
    """A curve of pieces through every channel group of ``src`` (H, W, C), into ``out``.

    Per channel: ``out = lo + span * f((src - lo) / span)`` with each texel
    row read as W x C values, a loop LLVM vectorises: for cubic pieces ``lo``,
    ``inv_span``, ``span`` tiled to that length; for a curve with an exponent
    (``power[2] != 1``) they are unused and ``constants[0]`` holds the
    channels' :func:`power_constants` as tiles (:func:`_power_row`). Then the
    vector groups of the same row, while it is in cache (:func:`_vectors_row`,
    which overwrites their channels; ``ranges`` and ``constants[1]``).
    ``src`` and ``out`` are C-contiguous; ``breaks`` and ``coeffs`` are a
    :class:`Pieces`, ``power`` its :func:`split_exponent`. Rows go in chunks
    to ``threads`` workers as each asks (:mod:`matshop.parallel_chunks`),
    counted in ``taken`` (int64 ``[0]``, made by the caller).
    """
    height, width, channels = src.shape
    flat_src = src.reshape(height, width * channels)
    flat_out = out.reshape(height, width * channels)
    tiles, vector_constants = constants
    rows_per_chunk = (height + 63) // 64
    chunks = (height + rows_per_chunk - 1) // rows_per_chunk
    for _worker in prange(max(1, min(threads, chunks))):
        scratch = np.empty((2, width), dtype=np.float32)
        chunk = next_chunk(taken)
        while chunk < chunks:
            for row in range(chunk * rows_per_chunk, min(height, (chunk + 1) * rows_per_chunk)):
                if power[2] != 1.0:
                    _power_row(
                        flat_src[row], tiles, power, coeffs[0, 1], coeffs[2, 1], flat_out[row]
                    )
                else:
                    _pieces_row(flat_src[row], lo, inv_span, span, breaks, coeffs, flat_out[row])
                if bounds.shape[0] > 1:
                    _vectors_row(
                        src[row], vectors, bounds, quadrature, ranges, vector_constants,
                        breaks, coeffs, power, out[row], scratch,
                    )  # fmt: skip
            chunk = next_chunk(taken)
