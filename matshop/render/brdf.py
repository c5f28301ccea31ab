"""The microfacet BRDF of MATH.md "Rendering", vectorised over arrays of directions.

``rho(i, o) = kd / pi + F(ks, i.h) D(h) G(i, o) / (4 |i.n| |o.n|)``

with Schlick's Fresnel ``F = ks + (1 - ks) (1 - i.h)^5`` and Cook-Torrance's
shadowing-masking ``G = min(1, 2 (n.h)(n.o) / (o.h), 2 (n.h)(n.i) / (o.h))``.

Directions are unit vectors in the *local shading frame* (tangent x, bitangent
y, normal z), given as separate component arrays so that callers can keep
``(pixels, samples)`` shapes without a trailing axis. ``D`` is normalised over
the projected hemisphere, ``integral D(h) (h.n) dw = 1``, the same convention as
the closed forms in :mod:`matshop.spaces.lobes` (``D(h) = d(theta_h)``).

Lobe parameters per family (shapes broadcast against the directions):

- ``"ggx"``: ``alpha`` (the engines' ``roughness ** 2``);
- ``"beckmann"``: ``m``;
- ``"phong"``: exponent ``n``;
- ``"ashikhmin_shirley"``: ``(nu, nv)`` exponents along the tangent and bitangent;
- ``"sampled"``: a tabulated ``d`` with ``N`` bins uniform in ``theta`` on the last
  axis, each bin keeping exactly its mass (the sampled space's model), read
  linearly in ``sin^2 theta`` inside it (:func:`sampled_d`).
"""

from __future__ import annotations

import numpy as np

from ..spaces import lobes

HALF_PI = 0.5 * np.pi
FAMILIES = ("ggx", "beckmann", "phong", "ashikhmin_shirley", "sampled")
#: cosines below this are treated as grazing (keeps divisions finite)
_EPS = 1e-6


def distribution(
    family: str, hx: np.ndarray, hy: np.ndarray, hz: np.ndarray, params: np.ndarray
) -> np.ndarray:
    """``D(h)`` for a unit half vector ``h = (hx, hy, hz)`` in the shading frame.

    ``params`` holds the lobe parameter(s) on its last axis (1 for the
    isotropic analytic families, 2 for Ashikhmin-Shirley, ``N`` bins for
    ``"sampled"``); its leading shape broadcasts against ``hz``. Zero below the
    horizon.
    """
    hz = np.asarray(hz)
    cos_t = np.clip(hz, 0.0, 1.0)
    theta = np.arccos(cos_t)
    p = np.asarray(params)
    if family == "ggx":
        d = lobes.ggx_d(theta, p[..., 0])
    elif family == "beckmann":
        d = lobes.beckmann_d(theta, p[..., 0])
    elif family == "phong":
        d = lobes.phong_d(theta, p[..., 0])
    elif family == "ashikhmin_shirley":
        d = ashikhmin_shirley_d(hx, hy, hz, p[..., 0], p[..., 1])
    elif family == "sampled":
        d = sampled_d(theta, p)
    else:
        raise ValueError(f"unknown microfacet family {family!r} (known: {', '.join(FAMILIES)})")
    return np.where(hz > 0.0, d, 0.0)


def ashikhmin_shirley_d(
    hx: np.ndarray, hy: np.ndarray, hz: np.ndarray, nu: np.ndarray, nv: np.ndarray
) -> np.ndarray:
    """Anisotropic Phong lobe ``sqrt((nu+2)(nv+2)) / (2 pi) (h.n)^(nu cos^2 phi + nv sin^2 phi)``.

    ``phi`` is the azimuth of ``h`` from the tangent. The constant normalises it
    exactly over the projected hemisphere: the azimuthal integral of
    ``1 / ((nu+2) cos^2 + (nv+2) sin^2)`` is ``2 pi / sqrt((nu+2)(nv+2))``. With
    ``nu == nv`` it is the Phong lobe.
    """
    hx, hy, hz = (np.asarray(a, dtype=np.float64) for a in (hx, hy, hz))
    nu = np.asarray(nu, dtype=np.float64)
    nv = np.asarray(nv, dtype=np.float64)
    sin2 = hx * hx + hy * hy
    with np.errstate(divide="ignore", invalid="ignore"):
        exponent = np.where(sin2 > 1e-12, (nu * hx * hx + nv * hy * hy) / sin2, 0.5 * (nu + nv))
    norm = np.sqrt((nu + 2.0) * (nv + 2.0)) / (2.0 * np.pi)
    return norm * np.clip(hz, 0.0, 1.0) ** exponent


def sampled_d(theta: np.ndarray, table: np.ndarray) -> np.ndarray:
    """A tabulated lobe (``N`` bins in ``[0, pi/2]`` on the last axis of ``table``) at ``theta``.

    Each bin keeps exactly its mass (the sampled space's reading of the table):
    inside a bin ``D`` is linear in ``u = sin^2 theta`` (the projected solid angle
    is ``pi du``) about the bin's mean, with the smaller of the slopes to its
    neighbours' means (minmod; flat at a local extremum and in the end bins),
    limited so ``D >= 0`` at the bin's ends. So ``integral D (h.n) dw`` is
    exactly the table's mass, and a highlight shows no rings at the bin edges.
    (Linear interpolation between bin centres added mass to narrow lobes: 1.050
    at GGX alpha 0.01; reading the bins as steps drew rings.) The GPU reads the
    same table the same way (``viewport.gl.shaders.SAMPLED_LOBE``).
    """
    table = np.asarray(table)
    n = table.shape[-1]
    theta = np.asarray(theta)
    k = np.clip((theta * (n / HALF_PI)).astype(np.intp), 0, n - 1)
    lead = np.broadcast_shapes(table.shape[:-1], np.shape(k))
    tab = np.broadcast_to(table, (*lead, n))
    k = np.broadcast_to(k, lead)

    def at(index: np.ndarray) -> np.ndarray:
        return np.take_along_axis(tab, np.clip(index, 0, n - 1)[..., None], axis=-1)[..., 0]

    d, d_lo, d_hi = at(k), at(k - 1), at(k + 1)
    u_edges = np.sin(np.arange(n + 1) * (HALF_PI / n)) ** 2
    u_mid = 0.5 * (u_edges[:-1] + u_edges[1:])
    width = np.diff(u_edges)
    mid = u_mid[k]
    with np.errstate(divide="ignore", invalid="ignore"):
        left = (d - d_lo) / (mid - u_mid[np.maximum(k - 1, 0)])
        right = (d_hi - d) / (u_mid[np.minimum(k + 1, n - 1)] - mid)
    inner = (k > 0) & (k < n - 1) & (left * right > 0)
    slope = np.where(inner, np.where(np.abs(left) < np.abs(right), left, right), 0.0)
    limit = 2.0 * np.abs(d) / width[k]
    u = np.sin(theta) ** 2
    return np.maximum(d + np.clip(slope, -limit, limit) * (u - mid), 0.0)


def schlick_fresnel(ks: np.ndarray, cos_ih: np.ndarray) -> np.ndarray:
    """``ks + (1 - ks) (1 - i.h)^5``; ``ks`` (..., 3) pairs with ``cos_ih[..., None]``."""
    m = np.clip(1.0 - cos_ih, 0.0, 1.0)
    return ks + (1.0 - ks) * (m * m) * (m * m) * m


def cook_torrance_g(
    n_h: np.ndarray, n_o: np.ndarray, n_i: np.ndarray, o_h: np.ndarray
) -> np.ndarray:
    """``min(1, 2 (n.h)(n.o) / (o.h), 2 (n.h)(n.i) / (o.h))``; symmetric as ``o.h = i.h``."""
    inv = 2.0 * np.clip(n_h, 0.0, None) / np.maximum(o_h, _EPS)
    return np.clip(np.minimum(inv * n_o, inv * n_i), 0.0, 1.0)


def half_vector(i: np.ndarray, o: np.ndarray) -> np.ndarray:
    """Unit ``(i + o) / |i + o|`` along the last axis (3)."""
    h = np.asarray(i) + np.asarray(o)
    return h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), _EPS)


def evaluate(
    i: np.ndarray,
    o: np.ndarray,
    *,
    kd: np.ndarray,
    ks: np.ndarray,
    family: str,
    params: np.ndarray,
) -> np.ndarray:
    """``rho(i, o)`` (RGB) for unit directions ``i``, ``o`` ``(..., 3)`` in the shading frame.

    ``kd`` and ``ks`` are linear RGB ``(..., 3)``; ``params`` the lobe
    parameters ``(..., P)`` (see the module docstring). Zero when either
    direction is below the horizon.
    """
    i = np.asarray(i, dtype=np.float64)
    o = np.asarray(o, dtype=np.float64)
    h = half_vector(i, o)
    n_i, n_o, n_h = i[..., 2], o[..., 2], h[..., 2]
    o_h = np.sum(o * h, axis=-1)
    d = distribution(family, h[..., 0], h[..., 1], n_h, params)
    g = cook_torrance_g(n_h, n_o, n_i, o_h)
    f = schlick_fresnel(np.asarray(ks), o_h[..., None])
    above = (n_i > 0.0) & (n_o > 0.0)
    denom = 4.0 * np.maximum(np.abs(n_i), _EPS) * np.maximum(np.abs(n_o), _EPS)
    spec = f * (d * g / denom)[..., None]
    return np.where(above[..., None], np.asarray(kd) / np.pi + spec, 0.0)
