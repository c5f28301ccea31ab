"""Shared machinery: binned densities <-> inverse CDFs at fixed quantile levels.

Both the sampled microfacet distribution (``sampled.py``) and the SubEdit
subsurface profile (``subsurface.py``) store a density sampled on ``N`` bins of
some coordinate ``x`` (the angle ``theta`` or the radius ``r``) and edit its
inverse CDF sampled at ``M`` fixed levels ``y``. They differ only in the bin
edges and the measure of each bin (``pi (sin^2 b - sin^2 a)`` for a lobe,
``(b^2 - a^2) / 2`` for a profile), so the conversion lives here once.

Model: the density is piecewise constant per bin, so the bin *mass* is
``pdf_k * weight_k`` and the CDF at the ``N + 1`` bin edges is an exact
cumulative sum. The inverse CDF is the monotone cubic (PCHIP, Fritsch-Carlson
with scipy's end-point rule) through ``(cdf(edge), u(edge))``, evaluated at the
``y`` grid and mapped back to ``x``; ``u`` is ``x`` itself or a coordinate in
which the bin measure is uniform (``COORDS``). Back: the PCHIP through
``(u(x_lo), 0), (u(q_j), y_j), (u(x_hi), 1)`` evaluated at the bin edges gives
exact bin masses, hence bin-average densities (no division by ``sin theta`` or
``r`` at a single point, so nothing blows up at the origin). Quantiles past
``x_hi`` (a lobe widened past pi/2, a profile past r_max) are mass leaving the
domain: they are dropped and the CDF renormalised (``_domain_knots``).

The per-row knots differ, so the merge walk and the PCHIP live in numba
kernels over flattened ``(P, N)`` rows with per-row scratch buffers: a
``1024 x 1024 x 128`` map needs no temporaries beyond its input and output.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numba import njit, prange

from .. import buffers
from ..parallel_chunks import next_chunk
from ._kernels import _PIO2_1, _PIO2_1T, _chunk_bounds, chunks
from ._pchip import eval_pieces, find_intervals, pchip_pieces

YGrid = Literal["cosine", "uniform"]
Coord = Literal["x", "sin2", "square"]

#: Blend weight of the strictly increasing ramp mixed into knot abscissae so
#: flat CDF stretches (empty bins, repeated edit values) stay invertible.
_KNOT_EPS = 1e-10
#: Below this fraction of the mass left inside the domain a row is read as empty.
_MIN_KEPT = 1e-9
#: Quantiles within this fraction of the domain past its end are at the end
#: (float32 rounds pi/2 up by 4e-8 rad).
_EDGE_TOL = 1e-6


def y_grid(n: int, kind: YGrid = "cosine") -> tuple[np.ndarray, np.ndarray]:
    """Read-only quantile levels ``y`` (``n``, increasing in (0, 1)) and weights ``dy``.

    ``"cosine"``: ``y_k = 0.5 - 0.5 cos(pi (k + 1/2) / n)`` (dense near 0 and 1,
    where sharp lobes and long tails need it); ``dy_k`` is the width of the cell
    ``[y(k/n), y((k+1)/n)]`` around it. ``"uniform"``: ``y_k = (k + 1/2) / n``,
    ``dy_k = 1 / n``. In both cases ``dy`` sums to 1, so ``sum(dy * q)`` is the
    midpoint quadrature of ``integral_0^1 q(y) dy`` (the mean of the distribution).
    """
    if n < 2:
        raise ValueError(f"need at least 2 quantile samples, got {n}")
    k = np.arange(n, dtype=np.float64)
    if kind == "cosine":
        y = 0.5 - 0.5 * np.cos(np.pi * (k + 0.5) / n)
        cell_edges = 0.5 - 0.5 * np.cos(np.pi * np.arange(n + 1, dtype=np.float64) / n)
        dy = np.diff(cell_edges)
    elif kind == "uniform":
        y = (k + 0.5) / n
        dy = np.full(n, 1.0 / n)
    else:
        raise ValueError(f"unknown y grid {kind!r} (use 'cosine' or 'uniform')")
    y.flags.writeable = False
    dy.flags.writeable = False
    return y, dy


# --------------------------------------------------------------------------- row kernels

#: Interpolation coordinates ``u(x)``: the PCHIP runs between ``c`` and ``u``.
#: With ``u`` proportional to the bin measure (``sin^2 theta`` for a lobe,
#: ``r^2`` for a profile) the piecewise-constant density makes ``c`` exactly
#: linear in ``u`` inside every bin, so the ``c ~ theta^2`` start at the origin
#: (and the ``1 - c ~ (pi/2 - theta)^2`` end at grazing angles) is reproduced
#: instead of being forced through a cubic in ``x``.
COORDS = {"x": 0, "sin2": 1, "square": 2}


# sin^2 and asin(sqrt) below are polynomials, not libm: they vectorise, a libm
# call per value does not. numba's cache does not see edits in ._kernels or
# ._pchip: clear this module's cache after changing them.

# asin(sqrt(w)) / sqrt(w) for w in [0, 1/2], a polynomial in t = 4 w - 1: the
# degree-12 Chebyshev interpolant (mpmath values), relative error 1.2e-12
_ASIN_SQRT_0 = 1.0471975511967635
_ASIN_SQRT_1 = 0.05375149357738585
_ASIN_SQRT_2 = 0.007798902222872402
_ASIN_SQRT_3 = 0.0015196689264759657
_ASIN_SQRT_4 = 0.0003408639785892685
_ASIN_SQRT_5 = 8.302012109931382e-05
_ASIN_SQRT_6 = 2.134404177223403e-05
_ASIN_SQRT_7 = 5.712071669519685e-06
_ASIN_SQRT_8 = 1.571194861030178e-06
_ASIN_SQRT_9 = 4.235680878770447e-07
_ASIN_SQRT_10 = 1.1983761072925678e-07
_ASIN_SQRT_11 = 4.900394873044276e-08
_ASIN_SQRT_12 = 1.479715353745806e-08


@njit(inline="always", error_model="numpy", nogil=True)
def asin_sqrt(u):
    """``asin(sqrt(u))`` for ``0 <= u <= 1`` with one square root and no division.

    ``sqrt(u) P(u)`` up to 1/2, ``pi/2 - sqrt(1 - u) P(1 - u)`` above (where
    ``1 - u`` is exact); ``atan2(sqrt(u), sqrt(1 - u))`` took two roots and a
    division, the largest cost of the sampled space's ``to_edit`` after the PCHIP.
    """
    above = u > 0.5
    w = 1.0 - u if above else u
    t = 4.0 * w - 1.0
    p = _ASIN_SQRT_12
    p = p * t + _ASIN_SQRT_11
    p = p * t + _ASIN_SQRT_10
    p = p * t + _ASIN_SQRT_9
    p = p * t + _ASIN_SQRT_8
    p = p * t + _ASIN_SQRT_7
    p = p * t + _ASIN_SQRT_6
    p = p * t + _ASIN_SQRT_5
    p = p * t + _ASIN_SQRT_4
    p = p * t + _ASIN_SQRT_3
    p = p * t + _ASIN_SQRT_2
    p = p * t + _ASIN_SQRT_1
    p = p * t + _ASIN_SQRT_0
    r = np.sqrt(w) * p
    return (_PIO2_1 - r) + _PIO2_1T if above else r


# sin^2(w) / w^2 for w^2 in [0, (pi/4)^2], a polynomial in w^2: the degree-8
# Chebyshev fit (mpmath), 2e-20 relative
_SIN2_0 = 1.0
_SIN2_1 = -0.3333333333333333
_SIN2_2 = 0.04444444444444421
_SIN2_3 = -0.0031746031745992507
_SIN2_4 = 0.0001410934743940764
_SIN2_5 = -4.275559677700142e-06
_SIN2_6 = 9.396792533708783e-08
_SIN2_7 = -1.5654600342553736e-09
_SIN2_8 = 1.98825305273285e-11


@njit(inline="always", error_model="numpy", nogil=True)
def sin2(x):
    """``sin(x)^2`` for ``0 <= x <= pi/2`` (within 2 float64 ulps), one polynomial.

    ``w^2 S(w^2)`` with ``w = x`` up to pi/4 and ``1 - w^2 S(w^2)`` with ``w = pi/2 -
    x`` above: half the work of squaring a sine that evaluates both fdlibm kernels.
    """
    below = x <= 0.25 * np.pi
    w = x if below else (_PIO2_1 - x) + _PIO2_1T  # pi/2 - x, in two parts
    z = w * w
    p = _SIN2_8
    p = p * z + _SIN2_7
    p = p * z + _SIN2_6
    p = p * z + _SIN2_5
    p = p * z + _SIN2_4
    p = p * z + _SIN2_3
    p = p * z + _SIN2_2
    p = p * z + _SIN2_1
    p = p * z + _SIN2_0
    s = z * p
    return s if below else 1.0 - s


# u(x) and its inverse branch on the coordinate once, outside the loop over a
# row: a branch inside keeps LLVM from vectorising it (measured 4x slower).
# Their polynomials are fused multiply-adds ("contract"): they are bound by
# floating-point throughput, and an FMA rounds once instead of twice.
_POLY_LOOP = {"cache": True, "nogil": True, "error_model": "numpy", "fastmath": {"contract"}}


@njit(**_POLY_LOOP)
def _to_u(v, n, coord):
    """``v[k] = u(v[k])`` for ``k < n``, ``v`` in the domain (``[0, pi/2]`` for "sin2")."""
    if coord == 1:
        for k in range(n):
            v[k] = sin2(v[k])
    elif coord == 2:
        for k in range(n):
            v[k] = v[k] * v[k]


@njit(**_POLY_LOOP)
def _store_x(u, coord, lo, hi, out):
    """``out[j] = x(u[j])``, the inverse of ``u(x)`` clamped to ``[lo, hi]``."""
    if coord == 1:
        for j in range(out.shape[0]):
            out[j] = min(max(asin_sqrt(min(max(u[j], 0.0), 1.0)), lo), hi)
    elif coord == 2:
        for j in range(out.shape[0]):
            out[j] = min(max(np.sqrt(max(u[j], 0.0)), lo), hi)
    else:
        for j in range(out.shape[0]):
            out[j] = min(max(u[j], lo), hi)


# A running sum or maximum along a row is one chain of dependent operations
# (about 4 cycles each); four chains over the row's quarters, joined after,
# keep the core busy. The maximum is exact in any order; the sum rounds in a
# different order than a left-to-right sum (a few float64 ulps).


@njit(inline="always", error_model="numpy", nogil=True)
def _running_sum(v, n, out):
    """``out[0] = 0``, ``out[k + 1] = v[0] + ... + v[k]`` for ``k < n``."""
    q = n // 4
    s0 = s1 = s2 = s3 = 0.0
    out[0] = 0.0
    for k in range(q):
        s0 += v[k]
        out[k + 1] = s0
        s1 += v[q + k]
        out[q + k + 1] = s1
        s2 += v[2 * q + k]
        out[2 * q + k + 1] = s2
        s3 += v[3 * q + k]
        out[3 * q + k + 1] = s3
    for k in range(4 * q, n):
        s3 += v[k]
        out[k + 1] = s3
    carry = s0
    for k in range(q + 1, 2 * q + 1):
        out[k] += carry
    carry += s1
    for k in range(2 * q + 1, 3 * q + 1):
        out[k] += carry
    carry += s2
    for k in range(3 * q + 1, n + 1):
        out[k] += carry


@njit(inline="always", error_model="numpy", nogil=True)
def _sum(v, n):
    """``v[0] + ... + v[n - 1]`` in four chains."""
    q = n // 4
    s0 = s1 = s2 = s3 = 0.0
    for k in range(q):
        s0 += v[k]
        s1 += v[q + k]
        s2 += v[2 * q + k]
        s3 += v[3 * q + k]
    for k in range(4 * q, n):
        s3 += v[k]
    return (s0 + s1) + (s2 + s3)


@njit(inline="always", error_model="numpy", nogil=True)
def _running_max(v, n, start, out):
    """``out[k] = max(start, v[0], ..., v[k])`` for ``k < n`` (``v`` without NaN)."""
    q = n // 4
    m0 = m1 = m2 = m3 = start
    for k in range(q):
        m0 = max(m0, v[k])
        out[k] = m0
        m1 = max(m1, v[q + k])
        out[q + k] = m1
        m2 = max(m2, v[2 * q + k])
        out[2 * q + k] = m2
        m3 = max(m3, v[3 * q + k])
        out[3 * q + k] = m3
    for k in range(4 * q, n):
        m3 = max(m3, v[k])
        out[k] = m3
    carry = m0
    for k in range(q, 2 * q):
        out[k] = max(out[k], carry)
    carry = max(carry, m1)
    for k in range(2 * q, 3 * q):
        out[k] = max(out[k], carry)
    carry = max(carry, m2)
    for k in range(3 * q, n):
        out[k] = max(out[k], carry)


@njit(cache=True, parallel=True, nogil=True, error_model="numpy")
def _rows_to_quantiles(pdf, weights, edges, coord, y, out, total, n_chunks, workers, taken):
    rows, nb = pdf.shape
    nk = nb + 1
    m = y.shape[0]
    lo = edges[0]
    hi = edges[nb]
    ue = edges.copy()
    _to_u(ue, nk, coord)
    inv_due = np.empty(nk)
    for k in range(nb):
        inv_due[k] = 1.0 / (ue[k + 1] - ue[k])
    ramp = np.empty(nk)
    for k in range(nk):
        ramp[k] = _KNOT_EPS * k / (nk - 1)
    # a row without mass reads as the density constant over the measure
    flat = np.empty(nk)
    _running_sum(weights, nb, flat)
    # rows are independent: chunks of rows go to whichever worker asks next
    # (matshop.parallel_chunks), each worker with its own scratch
    for _worker in prange(workers):
        mass = np.empty(nb)
        cdf = np.empty(nk)
        inv_h = np.empty(nk)
        a = np.empty(nk)
        b = np.empty(nk)
        c = np.empty(nk)
        dk = np.empty(nk)
        uq = np.empty(m)
        index = np.empty(m, dtype=np.uint64)
        chunk = next_chunk(taken)
        while chunk < n_chunks:
            start, stop = _chunk_bounds(chunk, rows, n_chunks)
            for p in range(start, stop):
                for k in range(nb):
                    v = np.float64(pdf[p, k])
                    # negative and non-finite densities carry no mass
                    mass[k] = v * weights[k] if (v > 0.0) & (v < np.inf) else 0.0
                _running_sum(mass, nb, cdf)
                total[p] = cdf[nb]
                src = cdf if cdf[nb] > 0.0 else flat
                # normalised, blended with the ramp that keeps flat stretches invertible
                scale = (1.0 - _KNOT_EPS) / src[nb]
                for k in range(nk):
                    cdf[k] = src[k] * scale + ramp[k]
                cdf[nb] = (1.0 - _KNOT_EPS) + _KNOT_EPS
                pchip_pieces(cdf, ue, inv_due, nk, inv_h, a, b, c, dk)
                find_intervals(cdf, nk, y, index)
                eval_pieces(cdf, ue, inv_h, a, b, c, y, index, uq)
                _store_x(uq, coord, lo, hi, out[p])
            chunk = next_chunk(taken)


@njit(cache=True, nogil=True, error_model="numpy")
def _domain_knots(q_row, y, lo, hi, coord, inv_dlevel, vals, us, ys, inv_dy):
    """Knots ``(u, y)`` of one row's CDF inside ``[lo, hi]``; returns their count.

    NaN repeats the previous quantile, a running maximum (from ``lo``) makes the
    row monotone. Quantiles past ``hi`` are mass leaving the domain (a lobe
    widened past pi/2, a profile past r_max): they are dropped, the level
    ``y_cut`` where the quantile function crosses ``hi`` (linear in ``x``
    between the last level inside and the first outside) ends the CDF, and the
    levels are divided by it, so what remains is renormalised instead of being
    folded into the last bin (MATH.md "Widening past the domain").
    ``inv_dy`` gets the reciprocal level steps: ``inv_dlevel`` (those of
    ``0, y_0, ..., y_{m-1}, 1``) scaled by the cut. ``vals`` is scratch.
    """
    m = y.shape[0]
    edge_tol = _EDGE_TOL * (hi - lo)
    for j in range(m):
        v = np.float64(q_row[j])
        # float32 rounding of the edge itself (pi/2 stored as float32) is the edge
        v = hi if (v > hi) & (v <= hi + edge_tol) else v
        vals[j] = -np.inf if v != v else v  # NaN repeats the previous quantile
    us[0] = lo
    _running_max(vals, m, lo, us[1:])
    inside = 0  # the maximum is monotone: the levels inside come first
    for j in range(m):
        inside += us[1 + j] <= hi
    y_cut = 1.0
    if inside < m:
        prev = us[inside]
        prev_y = y[inside - 1] if inside > 0 else 0.0
        v = us[inside + 1]
        t = (hi - prev) / (v - prev) if v < np.inf else 0.0
        y_cut = prev_y + t * (y[inside] - prev_y)
    n = inside + 2
    us[n - 1] = hi
    ys[0] = 0.0
    for j in range(inside):
        ys[1 + j] = y[j]
    ys[n - 1] = y_cut
    _to_u(us, n, coord)
    if not (y_cut > _MIN_KEPT):
        # (almost) everything left the domain: what remains has no shape to keep,
        # read it as the density constant over the measure
        us[1] = us[n - 1]
        ys[1] = 1.0
        inv_dy[0] = 1.0
        return 2
    for j in range(inside):
        inv_dy[j] = inv_dlevel[j] * y_cut
    last_y = y[inside - 1] if inside > 0 else 0.0
    inv_dy[inside] = y_cut / (y_cut - last_y)
    if y_cut != 1.0:  # the common case divides by one: skip it
        for k in range(n):
            ys[k] /= y_cut
    return n


@njit(cache=True, parallel=True, nogil=True, error_model="numpy")
def _rows_to_pdf(q, y, edges, weights, coord, out, n_chunks, workers, taken):
    rows, m = q.shape
    nb = weights.shape[0]
    lo = edges[0]
    hi = edges[nb]
    ue = edges.copy()
    _to_u(ue, nb + 1, coord)
    u_lo = ue[0]
    u_span = ue[nb] - ue[0]
    inv_w = np.empty(nb)
    for k in range(nb):
        inv_w[k] = 1.0 / weights[k]
    inv_dlevel = np.empty(m + 1)
    inv_dlevel[0] = 1.0 / y[0]
    for j in range(1, m):
        inv_dlevel[j] = 1.0 / (y[j] - y[j - 1])
    inv_dlevel[m] = 1.0 / (1.0 - y[m - 1])
    for _worker in prange(workers):  # as in _rows_to_quantiles
        vals = np.empty(m)
        us = np.empty(m + 2)
        ys = np.empty(m + 2)
        inv_dy = np.empty(m + 2)
        inv_h = np.empty(m + 2)
        a = np.empty(m + 2)
        b = np.empty(m + 2)
        c = np.empty(m + 2)
        dk = np.empty(m + 2)
        cdf = np.empty(nb + 1)
        mass = np.empty(nb)
        index = np.empty(nb + 1, dtype=np.uint64)
        chunk = next_chunk(taken)
        while chunk < n_chunks:
            start, stop = _chunk_bounds(chunk, rows, n_chunks)
            for p in range(start, stop):
                nk = _domain_knots(q[p], y, lo, hi, coord, inv_dlevel, vals, us, ys, inv_dy)
                step = u_span / (nk - 1)
                for k in range(nk):
                    us[k] = (1.0 - _KNOT_EPS) * us[k] + _KNOT_EPS * (u_lo + step * k)
                pchip_pieces(us, ys, inv_dy, nk, inv_h, a, b, c, dk)
                find_intervals(us, nk, ue, index)
                eval_pieces(us, ys, inv_h, a, b, c, ue, index, cdf)
                # PCHIP is monotone and hits the anchors; clamp against round-off anyway
                cdf[0] = 0.0
                cdf[nb] = 1.0
                for k in range(nb):
                    step_mass = cdf[k + 1] - cdf[k]
                    mass[k] = step_mass if step_mass > 0.0 else 0.0
                inv_total = 1.0 / _sum(mass, nb)
                for k in range(nb):
                    out[p, k] = mass[k] * inv_w[k] * inv_total
            chunk = next_chunk(taken)


def pdf_to_quantiles(
    pdf: np.ndarray,
    *,
    edges: np.ndarray,
    weights: np.ndarray,
    y: np.ndarray,
    coord: Coord = "x",
    out: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Binned densities -> inverse CDF at ``y``, plus each row's total mass.

    Parameters
    ----------
    pdf : (P, N) ndarray
        Density per bin (any float dtype; negative / non-finite values count as 0).
    edges : (N + 1,) ndarray
        Increasing bin edges in the coordinate ``x``.
    weights : (N,) ndarray
        Measure of each bin, so bin mass is ``pdf * weights``.
    y : (M,) ndarray
        Increasing quantile levels in (0, 1).
    coord : {"x", "sin2", "square"}
        Coordinate ``u(x)`` the PCHIP interpolates against the CDF (see ``COORDS``).
    out : (P, M) float32 ndarray, optional
        Written in place (may be a strided view, e.g. columns of a wider array).

    Returns
    -------
    quantiles : (P, M) float32 ndarray
        ``x`` below which a fraction ``y`` of the mass lies. A row without mass
        gets the quantiles of the density constant over the measure.
    total : (P,) float64 ndarray
        ``sum(pdf * weights)`` per row (negatives clamped to 0).
    """
    rows = np.asarray(pdf)
    if rows.ndim != 2:
        raise ValueError(f"pdf_to_quantiles: expected (P, N), got {rows.shape}")
    if out is None:
        out = buffers.empty((rows.shape[0], len(y)))
    total = np.empty(rows.shape[0], dtype=np.float64)
    _rows_to_quantiles(
        rows,
        np.asarray(weights, dtype=np.float64),
        np.asarray(edges, dtype=np.float64),
        COORDS[coord],
        np.asarray(y, dtype=np.float64),
        out,
        total,
        *chunks(rows.shape[0]),
    )
    return out, total


def quantiles_to_pdf(
    quantiles: np.ndarray,
    *,
    edges: np.ndarray,
    weights: np.ndarray,
    y: np.ndarray,
    coord: Coord = "x",
    out: np.ndarray | None = None,
) -> np.ndarray:
    """Inverse CDF at ``y`` -> normalised binned density (``sum(pdf * weights) == 1``).

    Any quantile vector is legal: NaN repeats the previous value, then a running
    maximum from ``edges[0]`` makes it a valid quantile function (values below
    ``edges[0]`` sit at it). Quantiles past ``edges[-1]`` are mass that left the
    domain: they are dropped and the rest renormalised (the CDF ends at the level
    ``y_cut`` where the quantiles cross ``edges[-1]``, and is divided by it), never
    folded into the last bin. The CDF is the PCHIP through ``(u(edges[0]), 0),
    (u(q_j), y_j / y_cut), (u(edges[-1]), 1)`` with ``u`` chosen by ``coord``; each
    bin gets its exact mass divided by its measure. ``out`` (P, N) float32 may be
    given.
    """
    rows = np.asarray(quantiles)
    if rows.ndim != 2:
        raise ValueError(f"quantiles_to_pdf: expected (P, M), got {rows.shape}")
    weights = np.asarray(weights, dtype=np.float64)
    if out is None:
        out = buffers.empty((rows.shape[0], weights.shape[0]))
    _rows_to_pdf(
        rows,
        np.asarray(y, dtype=np.float64),
        np.asarray(edges, dtype=np.float64),
        weights,
        COORDS[coord],
        out,
        *chunks(rows.shape[0]),
    )
    return out
