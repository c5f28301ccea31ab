"""Monotone cubic (PCHIP) row helpers for the inverse-CDF kernels (``_inverse_cdf.py``).

scipy's ``PchipInterpolator`` rules (Fritsch-Carlson weighted harmonic mean at
interior knots, the one-sided three-point rule at the ends), split so that the
per-row work vectorises and divides little:

* :func:`pchip_pieces` turns knots into one cubic per interval, in the form
  ``y_i + t (a_i + t (b_i + t c_i))`` with ``t = (x - x_i) / h_i``, plus
  ``1 / h_i``. One division per knot (``1 / (h D)`` gives both ``1 / h`` and
  the harmonic mean's ``1 / D``), where the textbook formulas take four (the
  secant, two reciprocals of secants, the mean) and a fifth per query
  (``t``). The caller passes ``1 / (y_{i+1} - y_i)``: in the row kernels the
  ``y`` steps are a fixed grid's (the bin edges' ``u``, or the levels scaled
  by the row's cut), so their reciprocals are computed once per call.
* :func:`find_intervals` walks sorted queries along the knots (the only
  branchy part), :func:`eval_pieces` evaluates with no branch and one
  multiply instead of a division.

Products and sums are fused multiply-adds (``"contract"``): these loops are
bound by floating-point throughput, and an FMA rounds once instead of twice.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_ROW = {"cache": True, "nogil": True, "error_model": "numpy", "fastmath": {"contract"}}


@njit(**_ROW)
def _edge_slope(h0, h1, m0, m1):
    """scipy's one-sided three-point end-point derivative (Moler, pchiptx)."""
    d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > 3.0 * abs(m0):
        return 3.0 * m0
    return d


@njit(**_ROW)
def pchip_pieces(x, y, inv_dy, n, inv_h, a, b, c, dk):
    """The ``n - 1`` cubic pieces through ``(x[:n], y[:n])``, ``x`` strictly increasing.

    ``inv_dy[i]`` is ``1 / (y[i + 1] - y[i])`` (``inf`` for a flat step).
    Written: ``inv_h``, ``a``, ``b``, ``c`` (piece ``i``: ``y[i] + t (a + t (b +
    t c))``, ``t = (x - x[i]) inv_h[i]``) and the knot derivatives ``dk``
    (scratch, at least ``n``). The loops carry nothing from one knot to the
    next and select instead of branching, so LLVM vectorises them.
    """
    inv_h[0] = 1.0 / (x[1] - x[0])
    if n == 2:
        m = (y[1] - y[0]) * inv_h[0]
        dk[0] = m
        dk[1] = m
    for i in range(1, n - 1):
        h_prev = x[i] - x[i - 1]
        h = x[i + 1] - x[i]
        dy_prev = y[i] - y[i - 1]
        dy = y[i + 1] - y[i]
        w1 = 2.0 * h + h_prev
        w2 = h + 2.0 * h_prev
        # zero at a local extremum or a flat side (and for NaN): same sign or nothing
        same = ((dy > 0.0) & (dy_prev > 0.0)) | ((dy < 0.0) & (dy_prev < 0.0))
        # w1 / m_prev + w2 / m, the reciprocal secants as h / dy
        denominator = w1 * h_prev * inv_dy[i - 1] + w2 * h * inv_dy[i]
        denominator = denominator if same else 1.0
        # one division gives both 1 / h and 1 / denominator
        r = 1.0 / (h * denominator)
        inv_h[i] = denominator * r
        dk[i] = (w1 + w2) * (h * r) if same else 0.0
    if n > 2:
        h0 = x[1] - x[0]
        h1 = x[2] - x[1]
        dk[0] = _edge_slope(h0, h1, (y[1] - y[0]) / h0, (y[2] - y[1]) / h1)
        h0 = x[n - 1] - x[n - 2]
        h1 = x[n - 2] - x[n - 3]
        dk[n - 1] = _edge_slope(h0, h1, (y[n - 1] - y[n - 2]) / h0, (y[n - 2] - y[n - 3]) / h1)
    for i in range(n - 1):
        h = x[i + 1] - x[i]
        rise = y[i + 1] - y[i]
        start = h * dk[i]
        end = h * dk[i + 1]
        # the Hermite basis regrouped in powers of t: y_i + start t
        # + (3 rise - 2 start - end) t^2 + (start + end - 2 rise) t^3
        a[i] = start
        b[i] = 3.0 * rise - 2.0 * start - end
        c[i] = start + end - 2.0 * rise


# The piece indices are unsigned: numba wraps negative signed indices, and the
# checks and the registers they take cost the evaluation a third of its time.


@njit(**_ROW)
def find_intervals(x, n, xq, index):
    """``index[j]`` (uint64): the piece of ``x[:n]`` holding the sorted query ``xq[j]``.

    Queries outside ``[x[0], x[n-1]]`` get the end pieces (extrapolation, like
    scipy's default).
    """
    one = np.uint64(1)
    last = np.uint64(n - 2)
    i = np.uint64(0)
    for j in range(xq.shape[0]):
        q = xq[j]
        while i < last and q > x[i + one]:
            i += one
        index[j] = i


@njit(**_ROW)
def eval_pieces(x, y, inv_h, a, b, c, xq, index, out):
    """``out[j]``: the piece ``index[j]`` at ``xq[j]`` (see :func:`pchip_pieces`)."""
    for j in range(xq.shape[0]):
        i = np.uint64(index[j])
        t = (xq[j] - x[i]) * inv_h[i]
        out[j] = y[i] + t * (a[i] + t * (b[i] + t * c[i]))


@njit(**_ROW)
def _pchip_kernel(x, y, xq, out):
    n = x.shape[0]
    inv_dy = np.empty(n)
    for i in range(n - 1):
        inv_dy[i] = 1.0 / (y[i + 1] - y[i])
    inv_h, a, b, c, dk = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    pchip_pieces(x, y, inv_dy, n, inv_h, a, b, c, dk)
    index = np.empty(xq.shape[0], dtype=np.uint64)
    find_intervals(x, n, xq, index)
    eval_pieces(x, y, inv_h, a, b, c, xq, index, out)


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
