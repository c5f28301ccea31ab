"""Importance sampling of microfacet normals, one lobe per pixel.

Every pixel draws the same ``N`` stratified points ``(u1, u2)`` (a Hammersley
set), mapped through its own lobe: ``theta_h = c^-1(u1)`` (the lobe's inverse
CDF, MATH.md), ``phi_h = 2 pi u2``. The same points for every pixel make the
image deterministic and free of pixel noise; the environment lookup is
prefiltered to each sample's footprint (see :mod:`matshop.render.integrator`),
so the residual error is a slight blur rather than noise.

The sampled family needs no closed form at all: its inverse CDF *is* its edit
value (``SampledDistributionSpace.to_edit``), given here as quantiles at fixed
levels ``y``, so texel lobes are interpolated the way the paper interpolates
distributions (Read 1999) and sampled by reading those quantiles at ``u1``.

Each sampler returns ``(hx, hy, hz, pdf)`` with shape ``(P, N)``: unit half
vectors in the shading frame and their density per steradian,
``pdf = D(h) cos(theta_h)``.
"""

from __future__ import annotations

import numpy as np

from .brdf import ashikhmin_shirley_d

HALF_PI = 0.5 * np.pi


def hammersley(n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` points ``(u1, u2)``: ``u1 = (j + 1/2) / n``, ``u2`` the base-2 radical inverse of j."""
    j = np.arange(n, dtype=np.uint32)
    bits = j.copy()
    bits = ((bits << 16) | (bits >> 16)) & 0xFFFFFFFF
    bits = ((bits & 0x55555555) << 1) | ((bits & 0xAAAAAAAA) >> 1)
    bits = ((bits & 0x33333333) << 2) | ((bits & 0xCCCCCCCC) >> 2)
    bits = ((bits & 0x0F0F0F0F) << 4) | ((bits & 0xF0F0F0F0) >> 4)
    bits = ((bits & 0x00FF00FF) << 8) | ((bits & 0xFF00FF00) >> 8)
    u2 = bits.astype(np.float64) / 2.0**32
    u1 = (j.astype(np.float64) + 0.5) / n
    return u1, u2


def _polar(theta: np.ndarray, phi: np.ndarray):
    s = np.sin(theta)
    return s * np.cos(phi), s * np.sin(phi), np.cos(theta)


def _from_tan2(tan2: np.ndarray, u2: np.ndarray):
    """Half vectors from ``tan^2 theta`` ``(P, N)`` and the azimuths ``2 pi u2`` ``(N,)``."""
    cos2 = 1.0 / (1.0 + tan2)
    cos_t = np.sqrt(cos2)
    sin_t = np.sqrt(np.clip(1.0 - cos2, 0.0, 1.0))
    phi = 2.0 * np.pi * u2
    return sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t, cos2


def sample_isotropic(
    family: str, params: np.ndarray, u1: np.ndarray, u2: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Half vectors of an analytic isotropic lobe; ``params`` is ``(P, 1)``.

    The closed-form inverse CDFs of :mod:`matshop.spaces.lobes`, written for
    ``tan^2 theta`` (GGX ``alpha^2 y / (1 - y)``, Beckmann ``-m^2 ln(1 - y)``) or
    ``cos theta`` (Phong ``(1 - y)^(1 / (n + 2))``) so no angle is formed.
    """
    p = np.asarray(params, dtype=np.float64)[:, :1]
    y = u1[None, :]
    if family == "ggx":
        a2 = p * p
        hx, hy, hz, cos2 = _from_tan2(a2 * (y / (1.0 - y)), u2)
        pdf = a2 / (np.pi * (a2 * cos2 + (1.0 - cos2)) ** 2) * hz
    elif family == "beckmann":
        m2 = p * p
        tan2 = -m2 * np.log1p(-y)
        hx, hy, hz, cos2 = _from_tan2(tan2, u2)
        pdf = np.exp(-tan2 / m2) / (np.pi * m2 * cos2 * cos2) * hz
    elif family == "phong":
        cos_t = np.clip((1.0 - y) ** (1.0 / (p + 2.0)), 1e-6, 1.0)
        hx, hy, hz, _ = _from_tan2(1.0 / (cos_t * cos_t) - 1.0, u2)
        pdf = (p + 2.0) / (2.0 * np.pi) * cos_t ** (p + 1.0)
    else:
        raise ValueError(f"no closed-form sampler for {family!r}")
    return hx, hy, hz, pdf


def sample_quantiles(
    quantiles: np.ndarray, levels: np.ndarray, u1: np.ndarray, u2: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Half vectors of tabulated lobes given by their inverse CDF.

    ``quantiles`` is ``(P, M)``: ``theta`` at the increasing ``levels`` (M,)
    (the sampled space's edit value); the ends ``c^-1(0) = 0`` and
    ``c^-1(1) = pi/2`` are implied. ``theta(u1)`` is read by linear
    interpolation, and ``pdf = c'(theta) / (2 pi sin theta)`` from the slope of
    the bracketing segment (only the environment prefilter uses it).
    """
    q = np.asarray(quantiles, dtype=np.float64)
    rows = q.shape[0]
    y = np.concatenate([[0.0], np.asarray(levels, dtype=np.float64), [1.0]])
    # non-monotone intermediates are legal in edit space; sorting is the
    # space's own "enforce monotonicity" step
    q = np.sort(np.clip(q, 0.0, HALF_PI), axis=1)
    q = np.concatenate([np.zeros((rows, 1)), q, np.full((rows, 1), HALF_PI)], axis=1)
    k = np.clip(np.searchsorted(y, u1, side="right") - 1, 0, y.size - 2)
    t = (u1 - y[k]) / (y[k + 1] - y[k])
    lo, hi = q[:, k], q[:, k + 1]
    theta = np.clip(lo + t * (hi - lo), 0.0, HALF_PI - 1e-6)
    slope = (y[k + 1] - y[k]) / np.maximum(hi - lo, 1e-9)  # dc / dtheta
    pdf = slope / (2.0 * np.pi * np.maximum(np.sin(theta), 1e-6))
    hx, hy, hz = _polar(theta, np.broadcast_to(2.0 * np.pi * u2, theta.shape))
    return hx, hy, hz, pdf


def sample_ashikhmin_shirley(
    params: np.ndarray, u1: np.ndarray, u2: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Half vectors of the anisotropic lobe (``params`` ``(P, 2)`` = nu, nv).

    With ``a = nu + 2``, ``b = nv + 2``, the azimuth density is proportional to
    ``1 / (a cos^2 phi + b sin^2 phi)``, inverted by
    ``tan phi = sqrt(a / b) tan(psi)`` with ``psi`` uniform (per quadrant);
    then ``cos theta = (1 - u1)^(1 / (e + 2))`` with the azimuth's exponent
    ``e = nu cos^2 phi + nv sin^2 phi``.
    """
    p = np.asarray(params, dtype=np.float64)
    nu, nv = p[:, :1], p[:, 1:2]
    quarter = np.floor(4.0 * u2)[None, :]
    frac = 4.0 * u2[None, :] - quarter
    psi = np.clip(frac, 1e-6, 1.0 - 1e-6) * HALF_PI
    phi = np.arctan(np.sqrt((nu + 2.0) / (nv + 2.0)) * np.tan(psi))
    # the four quadrants: phi, pi - phi, pi + phi, 2 pi - phi
    phi = np.where(quarter == 1, np.pi - phi, phi)
    phi = np.where(quarter == 2, np.pi + phi, phi)
    phi = np.where(quarter == 3, 2.0 * np.pi - phi, phi)
    exponent = nu * np.cos(phi) ** 2 + nv * np.sin(phi) ** 2
    cos_t = np.clip((1.0 - u1[None, :]) ** (1.0 / (exponent + 2.0)), 1e-6, 1.0)
    theta = np.arccos(cos_t)
    hx, hy, hz = _polar(theta, phi)
    return hx, hy, hz, ashikhmin_shirley_d(hx, hy, hz, nu, nv) * hz
