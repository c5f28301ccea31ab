"""Outgoing radiance at every covered pixel: environment light plus directional lights.

For a pixel with shading frame ``(t, b, n)`` (the geometric frame rotated by
the material's normal/tangent maps) and view direction ``o``:

- diffuse from the environment: ``kd / pi * E(n) * ao`` with the prefiltered
  irradiance ``E`` (:class:`~matshop.render.environment.Environment`);
- specular from the environment: ``N`` half vectors ``h_j`` drawn from the lobe
  (:mod:`matshop.render.sampling`), ``i_j = reflect(o, h_j)``; with the density
  ``pdf(i) = D(h) (n.h) / (4 (o.h))`` the estimator of
  ``integral F D G / (4 (n.i)(n.o)) L (n.i) di`` is
  ``mean_j F(ks, o.h_j) G_j (o.h_j) / ((n.o)(n.h_j)) L(i_j)`` -- ``D`` cancels, so a
  tabulated lobe needs only its inverse CDF. ``L`` is read from the mip level
  whose texel solid angle matches ``4 (o.h) / (N pdf(h))`` (one level coarser,
  the usual bias of filtered importance sampling);
- each directional light ``(direction, irradiance)``: ``rho(i, o) (n.i) E_light``
  with the full BRDF of :mod:`matshop.render.brdf`;
- ``emissive`` adds.

Pixels are processed in chunks (bounded memory, progress reports).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from . import brdf, sampling
from .environment import Environment
from .scenes import GBuffer
from .surface import Surface, SurfaceMaps

ProgressCallback = Callable[[int, int], None]
#: pixels per chunk, scaled down with the sample count to bound (P, N) temporaries
_CHUNK_LANES = 1 << 18
#: the lower bound of n.o: a normal map may turn a visible point away from the camera
_MIN_COS = 1e-3


@dataclass(frozen=True)
class DirectionalLight:
    """A distant light: ``direction`` towards it (world), RGB ``irradiance`` at normal incidence."""

    direction: tuple[float, float, float]
    irradiance: tuple[float, float, float] = (3.0, 3.0, 3.0)

    def unit(self) -> np.ndarray:
        d = np.asarray(self.direction, dtype=np.float64)
        return d / np.linalg.norm(d)


@dataclass(frozen=True)
class Lighting:
    """What lights a scene: an environment (or none), directional lights, sample count."""

    environment: Environment | None
    lights: Sequence[DirectionalLight] = ()
    samples: int = 16
    lod_bias: float = 1.0
    #: scale of the environment's diffuse and specular light (0 turns it off)
    environment_scale: float = 1.0
    #: False renders the diffuse term alone (Schlick's F is never 0 at grazing,
    #: even for ks = 0, so this is how to see a pure Lambertian)
    specular: bool = True


def shading_frame(g_normal, g_tangent, g_bitangent, surface: Surface):
    """World ``(t, b, n)`` ``(P, 3)`` each, from the geometric frame and the tangent-space maps."""
    nl = surface.normal.astype(np.float64)
    n = g_tangent * nl[:, :1] + g_bitangent * nl[:, 1:2] + g_normal * nl[:, 2:3]
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    if surface.tangent is not None:
        tl = surface.tangent.astype(np.float64)
        t = g_tangent * tl[:, :1] + g_bitangent * tl[:, 1:2] + g_normal * tl[:, 2:3]
    else:
        t = np.array(g_tangent, dtype=np.float64)
    # Gram-Schmidt: the frame stays orthonormal whatever the filtering did
    t = t - n * np.sum(t * n, axis=1, keepdims=True)
    t /= np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-12)
    b = np.cross(n, t)
    return t, b, n


def _to_local(v: np.ndarray, t: np.ndarray, b: np.ndarray, n: np.ndarray) -> np.ndarray:
    return np.stack([np.sum(v * t, 1), np.sum(v * b, 1), np.sum(v * n, 1)], axis=1)


def _half_vectors(surface: Surface, levels, u1, u2):
    if surface.family == "sampled":
        return sampling.sample_quantiles(surface.quantiles, levels, u1, u2)
    if surface.family == "ashikhmin_shirley":
        return sampling.sample_ashikhmin_shirley(surface.lobe, u1, u2)
    return sampling.sample_isotropic(surface.family, surface.lobe, u1, u2)


def environment_specular(
    surface: Surface,
    o_local: np.ndarray,
    frame: tuple[np.ndarray, np.ndarray, np.ndarray],
    env: Environment,
    *,
    samples: int,
    levels: np.ndarray | None,
    lod_bias: float = 1.0,
) -> np.ndarray:
    """Specular radiance ``(P, 3)`` reflected from ``env`` (filtered importance sampling)."""
    u1, u2 = sampling.hammersley(samples)
    hx, hy, hz, pdf = _half_vectors(surface, levels, u1, u2)
    ox, oy, oz = (o_local[:, k : k + 1] for k in range(3))
    o_h = ox * hx + oy * hy + oz * hz
    ix, iy, iz = 2.0 * o_h * hx - ox, 2.0 * o_h * hy - oy, 2.0 * o_h * hz - oz
    valid = (iz > 0.0) & (o_h > 0.0)
    g = brdf.cook_torrance_g(hz, oz, iz, o_h)
    weight = np.where(valid, g * o_h / (oz * np.maximum(hz, 1e-6)), 0.0)
    # Schlick per sample: F = ks + (1 - ks) m^5, so sum w F L = ks S0 + (1 - ks) S5
    m = np.clip(1.0 - o_h, 0.0, 1.0)
    m5 = (m * m) * (m * m) * m
    t, b, n = frame
    wx = (
        ix[..., None] * t[:, None, :]
        + iy[..., None] * b[:, None, :]
        + iz[..., None] * n[:, None, :]
    )
    omega_s = 4.0 * np.maximum(o_h, 1e-6) / (samples * np.maximum(pdf, 1e-12))
    if surface.family == "ashikhmin_shirley":
        # samples of a stretched lobe lie further apart along its long axis
        # than 1 / (N pdf) suggests: widen the filter by the axis ratio
        e = surface.lobe.astype(np.float64) + 2.0
        omega_s = omega_s * np.sqrt(e.max(axis=1) / e.min(axis=1))[:, None]
    lod = 0.5 * np.log2(np.maximum(omega_s / env.texel_solid_angle(), 1.0)) + lod_bias
    radiance = env.lookup(wx[..., 0], wx[..., 1], wx[..., 2], lod)
    s0 = np.einsum("pn,pnc->pc", weight, radiance) / samples
    s5 = np.einsum("pn,pnc->pc", weight * m5, radiance) / samples
    ks = surface.ks.astype(np.float64)
    return ks * s0 + (1.0 - ks) * s5


def direct(
    surface: Surface, o_local, frame, lights: Sequence[DirectionalLight], *, specular: bool = True
) -> np.ndarray:
    """Radiance ``(P, 3)`` from directional lights through the full BRDF (no shadows)."""
    out = np.zeros((o_local.shape[0], 3))
    table = surface.lobe
    for light in lights:
        i_local = _to_local(np.broadcast_to(light.unit(), o_local.shape), *frame)
        if specular:
            rho = brdf.evaluate(
                i_local, o_local, kd=surface.kd, ks=surface.ks, family=surface.family, params=table
            )
        else:
            rho = surface.kd / np.pi
        out += rho * np.clip(i_local[:, 2:3], 0.0, None) * np.asarray(light.irradiance)
    return out


def shade(
    gbuffer: GBuffer,
    maps: SurfaceMaps,
    lighting: Lighting,
    *,
    progress: ProgressCallback | None = None,
    diffuse_override: np.ndarray | None = None,
) -> np.ndarray:
    """Outgoing radiance ``(P, 3)`` float32 at the covered pixels of ``gbuffer``.

    ``diffuse_override`` ``(P, 3)``, when given, replaces the Lambertian term
    (environment and lights): the subsurface module passes its BSSRDF result.
    """
    count = gbuffer.count
    env = lighting.environment
    chunk = max(256, _CHUNK_LANES // max(1, lighting.samples))
    out = np.empty((count, 3), dtype=np.float32)
    starts = list(range(0, count, chunk))
    for done, start in enumerate(starts, 1):
        sl = slice(start, start + chunk)
        surface = maps.sample(gbuffer.uv[sl])
        frame = shading_frame(
            gbuffer.normal[sl], gbuffer.tangent[sl], gbuffer.bitangent[sl], surface
        )
        o_local = _to_local(gbuffer.view[sl], *frame)
        o_local[:, 2] = np.maximum(o_local[:, 2], _MIN_COS)
        o_local /= np.linalg.norm(o_local, axis=1, keepdims=True)
        radiance = np.zeros((o_local.shape[0], 3))
        if env is not None and lighting.environment_scale != 0.0:
            if lighting.specular:
                spec = environment_specular(
                    surface,
                    o_local,
                    frame,
                    env,
                    samples=lighting.samples,
                    levels=maps.levels,
                    lod_bias=lighting.lod_bias,
                )
                radiance += lighting.environment_scale * spec
            if diffuse_override is None:
                n = frame[2]
                e = env.irradiance(n[:, 0], n[:, 1], n[:, 2]).astype(np.float64)
                if surface.ao is not None:
                    e *= surface.ao[:, None]
                radiance += lighting.environment_scale * surface.kd / np.pi * e
        if lighting.lights:
            if diffuse_override is not None:
                surface.kd = np.zeros_like(surface.kd)
            radiance += direct(surface, o_local, frame, lighting.lights, specular=lighting.specular)
        if diffuse_override is not None:
            radiance += diffuse_override[sl]
        if surface.emissive is not None:
            radiance += surface.emissive
        out[sl] = radiance
        if progress:
            progress(done, len(starts))
    return out
