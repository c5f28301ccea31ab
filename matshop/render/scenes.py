"""Scenes as geometry buffers: what every covered pixel sees, before any material.

A scene is reduced to a :class:`GBuffer`: for each covered pixel its texture
coordinates and its *geometric* frame (tangent, bitangent, normal in world
space, the frame the tangent-space normal and tangent maps are expressed in),
plus the direction towards the camera. Shading never needs to know which
scene it is.

World: ``+y`` up, camera on ``+z`` looking at ``-z`` (the environment's
convention). Texture coordinates follow OpenGL: ``u`` right, ``v`` up, so
image row 0 is ``v = 1``; tangent = direction of increasing ``u``, bitangent =
increasing ``v`` (the tangent-space convention of :mod:`matshop.spaces.frame`).

- **swatch**: the texture itself, one pixel per texel of a ``size x size``
  resampling, lit as a flat patch tilted ``tilt_deg`` towards the sky and seen
  from the camera direction (texture space, no foreshortening);
- **sphere**: a unit sphere seen through a perspective camera, longitude and
  latitude as ``u, v`` (``tiles`` repeats per revolution / per pole-to-pole);
- **mesh**: a user's OBJ, normalised into the unit sphere, rasterised from the
  same camera (:mod:`matshop.render.mesh`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: camera distance and half field of view shared by the sphere and mesh scenes
CAMERA_DISTANCE = 4.0
HALF_FOV = np.radians(16.0)


@dataclass
class GBuffer:
    """Per-pixel geometry of a view; arrays over covered pixels are ``(P, ...)``.

    Attributes
    ----------
    mask : (H, W) bool
        Covered pixels, in row-major order of the ``(P, ...)`` arrays.
    uv : (P, 2) float64
        Texture coordinates (``u`` right, ``v`` up; values outside [0, 1] repeat).
    normal, tangent, bitangent : (P, 3) float64
        Orthonormal geometric frame in world space.
    view : (P, 3) float64
        Unit direction from the surface towards the camera.
    uv_per_pixel : float
        Typical texture-coordinate distance between neighbouring pixels
        (chooses the material's prefilter level).
    rays : (H, W, 3) float64 or None
        Camera ray directions, for showing the environment as background.
    """

    mask: np.ndarray
    uv: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray
    bitangent: np.ndarray
    view: np.ndarray
    uv_per_pixel: float
    rays: np.ndarray | None = None

    @property
    def shape(self) -> tuple[int, int]:
        return self.mask.shape

    @property
    def count(self) -> int:
        return self.uv.shape[0]


def _normalize(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def swatch(
    size: int | tuple[int, int],
    *,
    tilt_deg: float = 30.0,
    tiles: float = 1.0,
) -> GBuffer:
    """A flat texture-space swatch: pixel (row, col) shows ``uv = ((col+1/2)/W, 1-(row+1/2)/H)``."""
    h, w = (size, size) if np.isscalar(size) else size
    rows, cols = np.mgrid[0:h, 0:w]
    u = (cols.reshape(-1) + 0.5) / w * tiles
    v = 1.0 - (rows.reshape(-1) + 0.5) / h * tiles
    count = u.size
    t = np.radians(tilt_deg)
    normal = np.broadcast_to([0.0, np.sin(t), np.cos(t)], (count, 3))
    tangent = np.broadcast_to([1.0, 0.0, 0.0], (count, 3))
    bitangent = np.broadcast_to([0.0, np.cos(t), -np.sin(t)], (count, 3))
    view = np.broadcast_to([0.0, 0.0, 1.0], (count, 3))
    return GBuffer(
        mask=np.ones((h, w), dtype=bool),
        uv=np.stack([u, v], axis=1),
        normal=normal,
        tangent=tangent,
        bitangent=bitangent,
        view=view,
        uv_per_pixel=tiles / max(h, w),
    )


def camera_rays(size: int) -> tuple[np.ndarray, np.ndarray]:
    """Camera origin ``(3,)`` and unit ray directions ``(size, size, 3)`` (perspective)."""
    tan_f = np.tan(HALF_FOV)
    c = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    x = c[None, :] * tan_f
    y = -c[:, None] * tan_f
    d = np.stack(np.broadcast_arrays(x, y, -np.ones_like(x * y)), axis=-1)
    return np.array([0.0, 0.0, CAMERA_DISTANCE]), _normalize(d)


def sphere(size: int, *, tiles: tuple[float, float] = (2.0, 1.0)) -> GBuffer:
    """A unit sphere filling ~90% of a ``size x size`` perspective view."""
    origin, rays = camera_rays(size)
    # |o + t d|^2 = 1 with |d| = 1
    b = rays @ origin
    c = origin @ origin - 1.0
    disc = b * b - c
    mask = disc > 0.0
    d = rays[mask]
    t = -b[mask] - np.sqrt(disc[mask])
    p = origin + t[:, None] * d
    n = _normalize(p)
    phi = np.arctan2(n[:, 0], n[:, 2])
    lat = np.arcsin(np.clip(n[:, 1], -1.0, 1.0))
    uv = np.stack([(0.5 + phi / (2.0 * np.pi)) * tiles[0], (0.5 + lat / np.pi) * tiles[1]], axis=1)
    tangent = np.stack([np.cos(phi), np.zeros_like(phi), -np.sin(phi)], axis=1)
    bitangent = np.cross(n, tangent)
    pixel_world = 2.0 * np.tan(HALF_FOV) * (CAMERA_DISTANCE - 1.0) / size
    return GBuffer(
        mask=mask,
        uv=uv,
        normal=n,
        tangent=tangent,
        bitangent=bitangent,
        view=-d,
        uv_per_pixel=pixel_world * tiles[0] / (2.0 * np.pi),
        rays=rays,
    )
