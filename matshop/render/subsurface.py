"""The SubEdit diffuse BSSRDF, approximated in texture space.

MATH.md: ``Rd(xi, i, xo, o) = (1/pi) Fi(xi, i) sqrt(p_xi(r) p_xo(r)) Fo(xo, o)``
with ``r = |xi - xo|`` and ``p`` the per-texel profile (``N`` bins of width
``r_max / N``, read as constant per bin, the subsurface space's convention).

How it is computed: the surface is taken to be the texture plane (distances
are texel distances times ``texel_size``, in the profile's length unit). With
the profile constant on each radius bin ``k``, the outgoing radiance

    L(xo) = (Fo / pi) sum_k sqrt(p_k(xo)) [ring_k * (sqrt(p_k) Fi E)](xo)

is *exact* for that reading: ``ring_k`` is the annulus ``[a_k, b_k)`` as a
texel kernel (each texel weighted by the fraction of its area inside the
annulus, 4 x 4 subsamples, renormalised to the exact measure
``(b_k^2 - a_k^2) / 2``), applied by FFT with wrap-around (textures tile).
The measure makes a uniform material under uniform light reflect
``A E / pi`` with ``A = integral p r dr``, the profile's albedo: a
Lambertian of albedo ``A`` -- so scaling the profile's radii (the edit of
Fig. 8) spreads light without changing the albedo.

``E`` is the irradiance of each texel with its normal-map normal. On the
swatch it is computed in the swatch's own frame, so light and shadow detail
spreads under the skin. On curved scenes the geometry is not in texture
space: there the light is taken as locally uniform over the profile's reach
(``E`` = the pixel's own irradiance) and only the material's heterogeneity is
blurred. ``Fi`` is Schlick transmission averaged over a diffuse hemisphere,
``1 - ks - (1 - ks)/21``; ``Fo = 1 - F(ks, n.o)``. The result is grey scaled by
the profile; the base/diffuse color tints it (``kd / max(kd)``, so the profile
alone sets how much light comes back).
"""

from __future__ import annotations

import numpy as np

from .environment import Environment
from .integrator import Lighting, _to_local, shading_frame
from .scenes import GBuffer
from .surface import SurfaceMaps

_SUBSAMPLES = 4


def ring_kernels(n_bins: int, r_max: float, texel_size: float) -> np.ndarray:
    """``(N, K, K)`` texel kernels of the radius bins, each summing to ``(b^2 - a^2) / 2``."""
    reach = int(np.ceil(r_max / texel_size)) + 1
    offsets = np.arange(-reach, reach + 1)
    sub = (np.arange(_SUBSAMPLES) + 0.5) / _SUBSAMPLES - 0.5
    # distance of every subsample of every texel, (K, K, S, S)
    dx = (offsets[None, :, None, None] + sub[None, None, None, :]) * texel_size
    dy = (offsets[:, None, None, None] + sub[None, None, :, None]) * texel_size
    dist = np.sqrt(dx * dx + dy * dy)
    edges = np.arange(n_bins + 1) * (r_max / n_bins)
    measure = 0.5 * np.diff(edges**2)
    k = np.floor(dist / (r_max / n_bins)).astype(np.int64)
    kernels = np.zeros((n_bins, offsets.size, offsets.size))
    for b in range(n_bins):
        kernels[b] = np.mean(k == b, axis=(2, 3))
    centre = reach
    for b in range(n_bins):
        total = kernels[b].sum()
        if total > 0:
            kernels[b] *= measure[b] / total
        else:  # a ring thinner than the subsampling: its mass stays at the centre
            kernels[b, centre, centre] = measure[b]
    return kernels


def _convolve_wrap(image: np.ndarray, kernel: np.ndarray) -> np.ndarray:
    """Circular convolution of ``(H, W, C)`` with a centred ``(K, K)`` kernel (FFT)."""
    h, w = image.shape[:2]
    k = kernel.shape[0]
    padded = np.zeros((h, w))
    # fold the kernel onto the torus (kernels larger than the texture wrap around)
    ys = (np.arange(k) - k // 2) % h
    xs = (np.arange(k) - k // 2) % w
    np.add.at(padded, (ys[:, None], xs[None, :]), kernel)
    spectrum = np.fft.rfft2(padded)
    return np.fft.irfft2(
        np.fft.rfft2(image, axes=(0, 1)) * spectrum[..., None], s=(h, w), axes=(0, 1)
    )


def transport(
    profile: np.ndarray, irradiance: np.ndarray, *, r_max: float, texel_size: float
) -> np.ndarray:
    """``sum_k sqrt(p_k) [ring_k * (sqrt(p_k) E)]`` per texel, ``(H, W, 3)``."""
    s = np.sqrt(np.clip(profile.astype(np.float64), 0.0, None))
    kernels = ring_kernels(profile.shape[2], r_max, texel_size)
    out = np.zeros(irradiance.shape, dtype=np.float64)
    for b in range(profile.shape[2]):
        if not np.any(s[..., b]):
            continue
        out += s[..., b : b + 1] * _convolve_wrap(s[..., b : b + 1] * irradiance, kernels[b])
    return out


def _texel_irradiance(maps: SurfaceMaps, lighting: Lighting, gbuf: GBuffer) -> np.ndarray:
    """Irradiance ``(H, W, 3)`` of every texel in the swatch's frame (its normal map applied)."""
    h, w = maps.size
    rows, cols = np.mgrid[0:h, 0:w]
    uv = np.stack([(cols.reshape(-1) + 0.5) / w, 1.0 - (rows.reshape(-1) + 0.5) / h], axis=1)
    surface = maps.sample(uv)
    g = [
        np.broadcast_to(a[:1], (uv.shape[0], 3))
        for a in (gbuf.normal, gbuf.tangent, gbuf.bitangent)
    ]
    _, _, n = shading_frame(g[0], g[1], g[2], surface)
    return _irradiance(n, lighting).reshape(h, w, 3)


def _irradiance(n: np.ndarray, lighting: Lighting) -> np.ndarray:
    e = np.zeros((n.shape[0], 3))
    env: Environment | None = lighting.environment
    if env is not None and lighting.environment_scale != 0.0:
        e += lighting.environment_scale * env.irradiance(n[:, 0], n[:, 1], n[:, 2])
    for light in lighting.lights:
        e += np.clip(n @ light.unit(), 0.0, None)[:, None] * np.asarray(light.irradiance)
    return e


def subsurface_radiance(
    gbuf: GBuffer, maps: SurfaceMaps, lighting: Lighting, *, texel_size: float | None = None
) -> np.ndarray:
    """Radiance ``(P, 3)`` of the BSSRDF term at the covered pixels (replaces the Lambertian)."""
    assert maps.profile is not None
    r_max = maps.profile_r_max
    size = texel_size if texel_size is not None else r_max / 16.0
    h, w = maps.size
    swatch_like = gbuf.rays is None
    if swatch_like:
        e_tex = _texel_irradiance(maps, lighting, gbuf)
    else:
        e_tex = np.ones((h, w, 3))
    per_texel = transport(maps.profile, e_tex, r_max=r_max, texel_size=size)
    from .surface import bilinear

    value = bilinear(per_texel.astype(np.float32), gbuf.uv).astype(np.float64)
    surface = maps.sample(gbuf.uv)
    frame = shading_frame(gbuf.normal, gbuf.tangent, gbuf.bitangent, surface)
    o_local = _to_local(gbuf.view, *frame)
    if not swatch_like:
        value *= _irradiance(frame[2], lighting)
    ks = surface.ks.astype(np.float64)
    m = np.clip(1.0 - o_local[:, 2:3], 0.0, 1.0)
    fo = 1.0 - (ks + (1.0 - ks) * m**5)
    fi = 1.0 - ks - (1.0 - ks) / 21.0
    kd = surface.kd.astype(np.float64)
    tint = kd / np.maximum(kd.max(axis=1, keepdims=True), 1e-6)
    return fi * fo * tint * value / np.pi
