"""The orbit camera: yaw/pitch around a target, pan, zoom; matrices and projection.

Defaults are the reference renderer's view (:mod:`matshop.render.scenes`):
camera on ``+z`` at distance 4 looking at the origin, ``+y`` up, half field of
view 16 degrees (vertical; the reference is square). Qt- and GL-free.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...render.scenes import CAMERA_DISTANCE, HALF_FOV

MIN_DISTANCE = 1.05
MAX_DISTANCE = 100.0


@dataclass
class OrbitCamera:
    """Where the viewport looks from; angles in degrees."""

    target: np.ndarray = field(default_factory=lambda: np.zeros(3))
    distance: float = CAMERA_DISTANCE
    yaw: float = 0.0
    pitch: float = 0.0
    half_fov: float = math.degrees(HALF_FOV)
    near: float = 0.05
    far: float = 100.0

    # -- placement ---------------------------------------------------------

    def rotation(self) -> np.ndarray:
        """Camera-to-world rotation ``(3, 3)``: columns right, up, backwards (it looks along -z)."""
        y, p = math.radians(self.yaw), math.radians(self.pitch)
        back = np.array([math.sin(y) * math.cos(p), math.sin(p), math.cos(y) * math.cos(p)])
        right = np.array([math.cos(y), 0.0, -math.sin(y)])
        up = np.cross(back, right)
        return np.stack([right, up, back], axis=1)

    def eye(self) -> np.ndarray:
        return np.asarray(self.target, dtype=np.float64) + self.distance * self.rotation()[:, 2]

    def view(self) -> np.ndarray:
        """World-to-camera ``(4, 4)``."""
        rot = self.rotation()
        out = np.eye(4)
        out[:3, :3] = rot.T
        out[:3, 3] = -rot.T @ self.eye()
        return out

    def tan_half_fov(self, aspect: float) -> tuple[float, float]:
        """(x, y) tangents of the half field of view for ``aspect = width / height``."""
        ty = math.tan(math.radians(self.half_fov))
        return ty * aspect, ty

    def projection(self, aspect: float) -> np.ndarray:
        tx, ty = self.tan_half_fov(aspect)
        n, f = self.near, self.far
        return np.array(
            [
                [1.0 / tx, 0.0, 0.0, 0.0],
                [0.0, 1.0 / ty, 0.0, 0.0],
                [0.0, 0.0, -(f + n) / (f - n), -2.0 * f * n / (f - n)],
                [0.0, 0.0, -1.0, 0.0],
            ]
        )

    def view_projection(self, aspect: float) -> np.ndarray:
        return self.projection(aspect) @ self.view()

    # -- pixels <-> world --------------------------------------------------

    def project(self, points: np.ndarray, width: int, height: int) -> np.ndarray:
        """Widget pixel coordinates ``(..., 2)`` of world points (x right, y down, pixel
        ``(i, j)`` spans ``[i, i+1) x [j, j+1)``)."""
        pts = np.asarray(points, dtype=np.float64)
        clip = pts @ self.view_projection(width / height)[:3, :3].T
        clip = clip + self.view_projection(width / height)[:3, 3]
        w = -(pts - self.eye()) @ self.rotation()[:, 2]
        ndc = clip[..., :2] / w[..., None]
        return np.stack([(ndc[..., 0] + 1.0) * 0.5 * width, (1.0 - ndc[..., 1]) * 0.5 * height], -1)

    def ray(self, x: float, y: float, width: int, height: int) -> np.ndarray:
        """Unit world direction of the ray through widget point (x, y)."""
        tx, ty = self.tan_half_fov(width / height)
        local = np.array([(2.0 * x / width - 1.0) * tx, (1.0 - 2.0 * y / height) * ty, -1.0])
        d = self.rotation() @ local
        return d / np.linalg.norm(d)

    # -- navigation --------------------------------------------------------

    def orbit(self, d_yaw: float, d_pitch: float) -> None:
        self.yaw = (self.yaw + d_yaw) % 360.0
        self.pitch = min(max(self.pitch + d_pitch, -89.0), 89.0)

    def pan(self, dx: float, dy: float) -> None:
        """Move the target by (dx, dy) fractions of the view's height, in the view plane."""
        rot = self.rotation()
        scale = 2.0 * self.distance * math.tan(math.radians(self.half_fov))
        self.target = np.asarray(self.target, dtype=np.float64) + scale * (
            -dx * rot[:, 0] + dy * rot[:, 1]
        )

    def zoom(self, factor: float) -> None:
        """Divide the distance by ``factor`` (> 1 moves closer)."""
        self.distance = min(max(self.distance / factor, MIN_DISTANCE), MAX_DISTANCE)
