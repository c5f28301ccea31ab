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
from numba import get_num_threads, njit, prange

from ._kernels import _PIO2_1, _PIO2_1T, atan2_upper, cos_small, sin_small

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


# --------------------------------------------------------------------------- PCHIP


@njit(cache=True, nogil=True)
def _edge_slope(h0, h1, m0, m1):
    """scipy's one-sided three-point end-point derivative (Moler, pchiptx)."""
    d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > 3.0 * abs(m0):
        return 3.0 * m0
    return d


@njit(cache=True, nogil=True, error_model="numpy")
def _pchip_slopes(x, y, n, dk, m):
    """Derivatives at the first ``n`` knots into ``dk`` (scipy PchipInterpolator rules).

    ``m`` is scratch (at least ``n - 1``) for the secant slopes. Written as
    loops with no value carried from one knot to the next and no branch (a
    select picks zero or the weighted harmonic mean), so LLVM vectorises them
    and their divisions; each knot's arithmetic is the textbook formula's in
    the same order, so the bits are the same as a plain loop's.
    """
    for i in range(n - 1):
        m[i] = (y[i + 1] - y[i]) / (x[i + 1] - x[i])
    if n == 2:
        dk[0] = m[0]
        dk[1] = m[0]
        return
    for i in range(1, n - 1):
        h_prev = x[i] - x[i - 1]
        h = x[i + 1] - x[i]
        w1 = 2.0 * h + h_prev
        w2 = h + 2.0 * h_prev
        # zero at a local extremum or a flat side (and for NaN): same sign or nothing
        same = ((m[i] > 0.0) & (m[i - 1] > 0.0)) | ((m[i] < 0.0) & (m[i - 1] < 0.0))
        harmonic = (w1 + w2) / (w1 / m[i - 1] + w2 / m[i])
        dk[i] = harmonic if same else 0.0
    h0 = x[1] - x[0]
    h1 = x[2] - x[1]
    dk[0] = _edge_slope(h0, h1, (y[1] - y[0]) / h0, (y[2] - y[1]) / h1)
    h0 = x[n - 1] - x[n - 2]
    h1 = x[n - 2] - x[n - 3]
    dk[n - 1] = _edge_slope(h0, h1, (y[n - 1] - y[n - 2]) / h0, (y[n - 2] - y[n - 3]) / h1)


@njit(cache=True, nogil=True, error_model="numpy")
def _pchip_eval_sorted(x, y, dk, n, xq, out, index):
    """Evaluate the Hermite cubic at increasing ``xq`` by a merge walk.

    Queries outside ``[x[0], x[n-1]]`` are extrapolated with the end cubic,
    like scipy's default ``extrapolate=True``. ``index`` is integer scratch
    (``len(xq)``): the walk only finds each query's interval, the evaluation
    runs as a separate loop whose divisions no branch holds up.
    """
    i = 0
    for j in range(xq.shape[0]):
        t_x = xq[j]
        while i < n - 2 and t_x > x[i + 1]:
            i += 1
        index[j] = i
    for j in range(xq.shape[0]):
        i = index[j]
        h = x[i + 1] - x[i]
        t = (xq[j] - x[i]) / h
        t2 = t * t
        t3 = t2 * t
        h00 = 2.0 * t3 - 3.0 * t2 + 1.0
        h10 = t3 - 2.0 * t2 + t
        h01 = -2.0 * t3 + 3.0 * t2
        h11 = t3 - t2
        out[j] = h00 * y[i] + h10 * h * dk[i] + h01 * y[i + 1] + h11 * h * dk[i + 1]


@njit(cache=True, nogil=True)
def _pchip_kernel(x, y, xq, out):
    n = x.shape[0]
    dk = np.empty(n)
    _pchip_slopes(x, y, n, dk, np.empty(n))
    _pchip_eval_sorted(x, y, dk, n, xq, out, np.empty(xq.shape[0], dtype=np.int64))


def pchip(x: np.ndarray, y: np.ndarray, xq: np.ndarray) -> np.ndarray:
    """The numba PCHIP on one curve: knots ``x`` strictly increasing, queries ``xq`` sorted.

    Exposed for tests (it must agree with ``scipy.interpolate.PchipInterpolator``).
    """
    x = np.ascontiguousarray(x, dtype=np.float64)
    y = np.ascontiguousarray(y, dtype=np.float64)
    xq = np.ascontiguousarray(xq, dtype=np.float64)
    if x.ndim != 1 or x.shape != y.shape or x.shape[0] < 2:
        raise ValueError("pchip: x and y must be 1-D of the same length >= 2")
    if np.any(np.diff(x) <= 0) or np.any(np.diff(xq) < 0):
        raise ValueError("pchip: x must be strictly increasing and xq sorted")
    out = np.empty(xq.shape[0])
    _pchip_kernel(x, y, xq, out)
    return out


# --------------------------------------------------------------------------- row kernels

#: Interpolation coordinates ``u(x)``: the PCHIP runs between ``c`` and ``u``.
#: With ``u`` proportional to the bin measure (``sin^2 theta`` for a lobe,
#: ``r^2`` for a profile) the piecewise-constant density makes ``c`` exactly
#: linear in ``u`` inside every bin, so the ``c ~ theta^2`` start at the origin
#: (and the ``1 - c ~ (pi/2 - theta)^2`` end at grazing angles) is reproduced
#: instead of being forced through a cubic in ``x``.
COORDS = {"x": 0, "sin2": 1, "square": 2}


# sin and asin below come from the branch-free float64 helpers of ._kernels
# (about 1e-15 and 1e-11 relative), not libm: they vectorise, a libm call
# per value does not (and cost a quarter of each conversion). numba's cache
# does not see edits there: clear this module's cache after changing them.


@njit(inline="always", error_model="numpy", nogil=True)
def _sin_quarter(x):
    """``sin(x)`` for ``0 <= x <= pi/2``: the fdlibm kernels, about pi/2 - x above pi/4."""
    r = (_PIO2_1 - x) + _PIO2_1T  # pi/2 - x, in two parts
    return sin_small(x, x * x) if x <= 0.25 * np.pi else cos_small(r * r)


@njit(inline="always", error_model="numpy", nogil=True)
def _u_of_x(x, coord):
    """``u(x)`` for ``x`` in the domain (``[0, pi/2]`` for "sin2")."""
    if coord == 1:
        s = _sin_quarter(x)
        return s * s
    if coord == 2:
        return x * x
    return x


@njit(inline="always", error_model="numpy", nogil=True)
def _x_of_u(u, coord, lo, hi):
    """The inverse of :func:`_u_of_x`, clamped to ``[lo, hi]`` (asin(sqrt(u)) for "sin2")."""
    if coord == 1:
        c = min(max(u, 0.0), 1.0)
        x = atan2_upper(np.sqrt(c), np.sqrt(1.0 - c))
    elif coord == 2:
        x = np.sqrt(max(u, 0.0))
    else:
        x = u
    return min(max(x, lo), hi)


@njit(cache=True, parallel=True, nogil=True, error_model="numpy")
def _rows_to_quantiles(pdf, weights, edges, coord, y, out, total, n_blocks):
    rows, nb = pdf.shape
    nk = nb + 1
    lo = edges[0]
    hi = edges[nb]
    ue = np.empty(nk)
    for k in range(nk):
        ue[k] = _u_of_x(edges[k], coord)
    # rows are independent: blocks of rows run in parallel, each with its own scratch
    for block in prange(n_blocks):
        cdf = np.empty(nk)
        dk = np.empty(nk)
        secant = np.empty(nk)
        uq = np.empty(y.shape[0])
        index = np.empty(y.shape[0], dtype=np.int64)
        for p in range(block * rows // n_blocks, (block + 1) * rows // n_blocks):
            acc = 0.0
            cdf[0] = 0.0
            for k in range(nb):
                v = np.float64(pdf[p, k])
                # negative and non-finite densities carry no mass
                if not (v > 0.0) or v == np.inf:
                    v = 0.0
                acc += v * weights[k]
                cdf[k + 1] = acc
            total[p] = acc
            if acc > 0.0:
                for k in range(nk):
                    cdf[k] /= acc
            else:
                # no mass: fall back to a density constant over the measure
                s = 0.0
                for k in range(nb):
                    s += weights[k]
                    cdf[k + 1] = s
                for k in range(nk):
                    cdf[k] /= s
            cdf[nk - 1] = 1.0
            for k in range(nk):
                cdf[k] = (1.0 - _KNOT_EPS) * cdf[k] + _KNOT_EPS * k / (nk - 1)
            _pchip_slopes(cdf, ue, nk, dk, secant)
            _pchip_eval_sorted(cdf, ue, dk, nk, y, uq, index)
            for j in range(y.shape[0]):
                out[p, j] = _x_of_u(uq[j], coord, lo, hi)


@njit(cache=True, nogil=True, error_model="numpy")
def _domain_knots(q_row, y, lo, hi, coord, us, ys):
    """Knots ``(u, y)`` of one row's CDF inside ``[lo, hi]``; returns their count.

    NaN repeats the previous quantile, a running maximum (from ``lo``) makes the
    row monotone. Quantiles past ``hi`` are mass leaving the domain (a lobe
    widened past pi/2, a profile past r_max): they are dropped, the level
    ``y_cut`` where the quantile function crosses ``hi`` (linear in ``x``
    between the last level inside and the first outside) ends the CDF, and the
    levels are divided by it, so what remains is renormalised instead of being
    folded into the last bin (MATH.md "Widening past the domain").
    """
    m = y.shape[0]
    edge_tol = _EDGE_TOL * (hi - lo)
    us[0] = lo
    ys[0] = 0.0
    prev = lo
    prev_y = 0.0
    y_cut = 1.0
    n = 1
    for j in range(m):
        v = np.float64(q_row[j])
        # float32 rounding of the edge itself (pi/2 stored as float32) is the edge; this
        # clamp is monotone and idempotent, so clamping before the running maximum gives
        # what clamping after it gave, and the only chain from texel to texel is the max
        v = hi if (v > hi) & (v <= hi + edge_tol) else v
        v = -np.inf if v != v else v  # NaN repeats the previous quantile
        v = max(v, prev)
        if v > hi:
            t = (hi - prev) / (v - prev) if v < np.inf else 0.0
            y_cut = prev_y + t * (y[j] - prev_y)
            break
        us[n] = v  # u(v) below, in a loop that vectorises
        ys[n] = y[j]
        n += 1
        prev = v
        prev_y = y[j]
    us[n] = hi
    ys[n] = y_cut
    n += 1
    for k in range(n):
        us[k] = _u_of_x(us[k], coord)
    if not (y_cut > _MIN_KEPT):
        # (almost) everything left the domain: what remains has no shape to keep,
        # read it as the density constant over the measure
        us[1] = us[n - 1]
        ys[1] = 1.0
        return 2
    if y_cut != 1.0:  # the common case divides by one: skip it
        for k in range(n):
            ys[k] /= y_cut
    return n


@njit(cache=True, parallel=True, nogil=True, error_model="numpy")
def _rows_to_pdf(q, y, edges, weights, coord, out, n_blocks):
    rows, m = q.shape
    nb = weights.shape[0]
    lo = edges[0]
    hi = edges[nb]
    ue = np.empty(nb + 1)
    for k in range(nb + 1):
        ue[k] = _u_of_x(edges[k], coord)
    u_lo = ue[0]
    u_span = ue[nb] - ue[0]
    for block in prange(n_blocks):
        us = np.empty(m + 2)
        ys = np.empty(m + 2)
        dk = np.empty(m + 2)
        secant = np.empty(m + 2)
        cdf = np.empty(nb + 1)
        index = np.empty(nb + 1, dtype=np.int64)
        for p in range(block * rows // n_blocks, (block + 1) * rows // n_blocks):
            nk = _domain_knots(q[p], y, lo, hi, coord, us, ys)
            for k in range(nk):
                ramp = u_lo + u_span * k / (nk - 1)
                us[k] = (1.0 - _KNOT_EPS) * us[k] + _KNOT_EPS * ramp
            _pchip_slopes(us, ys, nk, dk, secant)
            _pchip_eval_sorted(us, ys, dk, nk, ue, cdf, index)
            # PCHIP is monotone and hits the anchors; clamp against round-off anyway
            cdf[0] = 0.0
            cdf[nb] = 1.0
            acc = 0.0
            for k in range(nb):
                mass = cdf[k + 1] - cdf[k]
                if not (mass > 0.0):
                    mass = 0.0
                acc += mass
                cdf[k] = mass
            for k in range(nb):
                out[p, k] = cdf[k] / (acc * weights[k])


def _blocks(rows: int) -> int:
    # a few blocks per thread balance the load; passed in because numba cannot
    # cache a kernel that reads the thread count itself
    return max(1, min(rows, 8 * get_num_threads()))


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
        out = np.empty((rows.shape[0], len(y)), dtype=np.float32)
    total = np.empty(rows.shape[0], dtype=np.float64)
    _rows_to_quantiles(
        rows,
        np.asarray(weights, dtype=np.float64),
        np.asarray(edges, dtype=np.float64),
        COORDS[coord],
        np.asarray(y, dtype=np.float64),
        out,
        total,
        _blocks(rows.shape[0]),
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
        out = np.empty((rows.shape[0], weights.shape[0]), dtype=np.float32)
    _rows_to_pdf(
        rows,
        np.asarray(y, dtype=np.float64),
        np.asarray(edges, dtype=np.float64),
        weights,
        COORDS[coord],
        out,
        _blocks(rows.shape[0]),
    )
    return out
