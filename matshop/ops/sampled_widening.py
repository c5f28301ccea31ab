"""Widening a tabulated lobe by a slope variance: its slopes convolved with a Gaussian.

A microfacet lobe is a distribution of facet slopes ``m = tan(theta) (cos phi, sin phi)``,
and bin ``k`` of a tabulated ``d(theta)`` (:mod:`matshop.spaces.sampled`) holds the mass
``d_k * measure_k`` of the slopes with ``|m|`` in ``[tan theta_k, tan theta_k+1]``. The
tilts an averaging removes (slope covariance of trace ``v``, :mod:`matshop.ops.variance`)
are read as an independent Gaussian slope of per-axis variance ``v / 2`` added to every
facet, so the footprint's slope distribution is the lobe's convolved with that Gaussian.
For Beckmann, whose slopes are Gaussian of per-axis variance ``m^2 / 2``, this is Beckmann
again with ``m'^2 = m^2 + v``: exactly the analytic families' rule (docs/variance.md).
For any other shape it is the same widening without the family.

The convolution is radial: a ring of slopes of radius ``r`` convolved with
``N(0, sigma^2 I)`` has the Rice distribution in radius,
``P(|m'| <= t) = chndtr(t^2 / sigma^2, 2, r^2 / sigma^2)`` (noncentral chi-square, two
degrees of freedom). A bin's mass is uniform in ``sin^2 theta`` (the piecewise-constant
reading of ``d``), so it is carried by :data:`SUB_RINGS` rings at the midpoints of equal
``sin^2`` steps; the mass each lands in every bin is an ``N x N`` matrix ``K(v)``. These
are built on a geometric grid of ``v`` (:data:`GRID_STEP`, cached); a texel between two
grid values mixes their two results linearly in ``v`` (below the first grid value, with
the identity). Measured against the exact ``K(v)`` in between: at most 1.7e-3 in CDF,
3.1e-3 below the grid on a lobe 1.6 bins wide (docs/variance.md). Nothing leaves the
hemisphere: ``theta < pi/2`` covers every slope.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from ..spaces.sampled import bin_measure, theta_edges

#: the grid of added slope variances: V_MIN * GRID_STEP**i up to V_MAX (slopes of
#: grazing normals are capped at 20, so v stays below 2 * 20^2)
V_MIN = 1.0e-6
V_MAX = 1.0e3
GRID_STEP = 2.0**0.25
#: rings carrying each bin's mass (midpoints of equal sin^2 steps)
SUB_RINGS = 8
_BAND_SIGMAS = 9.0
#: rows of one matrix product. OpenBLAS spreads a product over every core once
#: rows x N x N > 4 * 65536 (17 rows of 128 bins); for these small products on a busy
#: machine its threads cost 5-10x the CPU of one thread (200 rows: 1.35 ms against
#: 0.14 ms of CPU, measured at load 12 on 2 cores), and the GL viewport widens a
#: dab's tiles on the GUI thread. Below that size a product runs on the calling thread.
ROWS_PER_PRODUCT = 16
_GRID_SIZE = int(np.ceil(np.log(V_MAX / V_MIN) / np.log(GRID_STEP))) + 1


def grid_variance(index: int) -> float:
    """The added slope variance of grid entry ``index``."""
    return V_MIN * GRID_STEP**index


def ring_radii(n: int, sub_rings: int = SUB_RINGS) -> np.ndarray:
    """Slope radii ``tan theta`` ``(n, sub_rings)`` carrying each bin's mass, equal shares."""
    s2 = np.sin(theta_edges(n)) ** 2
    steps = (np.arange(sub_rings) + 0.5) / sub_rings
    u = s2[:-1, None] + steps[None, :] * np.diff(s2)[:, None]
    return np.sqrt(u / (1.0 - u))


def slope_kernel(n: int, variance: float, sub_rings: int = SUB_RINGS) -> np.ndarray:
    """``(n, n)`` float64: column ``k`` is where bin ``k``'s mass lands once every slope
    gets an independent Gaussian of total variance ``variance`` (per axis half of it).

    Columns sum to one (nothing leaves the hemisphere).
    """
    # imported here: scipy.special costs ~0.3 s of CPU, and every op loads this module
    from scipy.special import chndtr

    sigma2 = 0.5 * variance
    r = ring_radii(n, sub_rings)[:, :, None]
    t = np.tan(theta_edges(n)[1:-1])[None, None, :]
    # the added slope is farther than 9 sigma from zero with probability
    # exp(-81 / 2) ~ 3e-18: outside that band the CDF is 0 or 1 (a cheap band
    # for the small variances, where the kernel is nearly diagonal)
    reach = _BAND_SIGMAS * np.sqrt(sigma2)
    r, t = np.broadcast_arrays(r, t)
    inside = (t > r).astype(np.float64)
    band = np.abs(t - r) <= reach
    inside[band] = chndtr(t[band] ** 2 / sigma2, 2.0, r[band] ** 2 / sigma2)
    cdf = np.zeros((n, n + 1))
    cdf[:, 1:-1] = inside.mean(axis=1)
    cdf[:, -1] = 1.0
    # the CDF is monotone in t; clip the last-bit noise of chndtr so no mass is negative
    cdf = np.maximum.accumulate(np.clip(cdf, 0.0, 1.0), axis=1)
    return np.ascontiguousarray(np.diff(cdf, axis=1).T)


@cache
def _grid_kernel(n: int, index: int) -> np.ndarray:
    kernel = slope_kernel(n, grid_variance(index))
    kernel.flags.writeable = False
    return kernel


def _times(mass: np.ndarray, kernel: np.ndarray) -> np.ndarray:
    """``mass @ kernel.T`` as products of :data:`ROWS_PER_PRODUCT` rows."""
    out = np.empty((mass.shape[0], kernel.shape[0]))
    for start in range(0, mass.shape[0], ROWS_PER_PRODUCT):
        stop = start + ROWS_PER_PRODUCT
        np.matmul(mass[start:stop], kernel.T, out=out[start:stop])
    return out


def widen_tabulated(d: np.ndarray, added: np.ndarray) -> np.ndarray:
    """Tabulated lobes ``d`` ``(..., N)`` widened by the total slope variance ``added``
    ``(...)``: float32 ``(..., N)``, normalised like ``d`` (mass is conserved).

    Rows with ``added <= 0`` are ``d``'s own values; ``added`` above :data:`V_MAX`
    is taken as ``V_MAX``.
    """
    d = np.asarray(d)
    n = d.shape[-1]
    out = d.astype(np.float32).reshape(-1, n)
    v = np.broadcast_to(np.asarray(added, dtype=np.float64), d.shape[:-1]).reshape(-1)
    rows = np.flatnonzero(v > 0)
    if rows.size == 0:
        return out.reshape(d.shape)
    measure = bin_measure(n)
    mass = np.clip(out[rows].astype(np.float64), 0.0, None) * measure
    v = np.minimum(v[rows], V_MAX)
    # grid entries i and i + 1 around v (i = -1: the identity, below V_MIN), and
    # the weight of i + 1, linear in v
    pos = np.log(np.maximum(v, V_MIN) / V_MIN) / np.log(GRID_STEP)
    index = np.where(v < V_MIN, -1, np.minimum(np.floor(pos), _GRID_SIZE - 2)).astype(int)
    lower = np.where(index < 0, 0.0, V_MIN * GRID_STEP ** np.maximum(index, 0))
    upper = V_MIN * GRID_STEP ** (index + 1)
    weight = np.clip((v - lower) / (upper - lower), 0.0, 1.0)[:, None]
    widened = np.empty_like(mass)
    for i in np.unique(index):
        sel = np.flatnonzero(index == i)
        lo = mass[sel] if i < 0 else _times(mass[sel], _grid_kernel(n, i))
        hi = _times(mass[sel], _grid_kernel(n, i + 1))
        widened[sel] = lo + weight[sel] * (hi - lo)
    out[rows] = widened / measure
    return out.reshape(d.shape)
