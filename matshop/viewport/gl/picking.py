"""The picking pass: which surface point, and which texture coordinate, is under the cursor.

One draw of the mesh into three float attachments (uv after the uv scale,
world position, normal facing the camera), read back whole and kept for as
long as the view does not change, so cursor lookups during a stroke are numpy
indexing, not a GPU round trip per mouse event.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from OpenGL import GL

from . import shaders
from .fbo import Framebuffer


@dataclass(frozen=True)
class SurfaceHit:
    """A surface point under the cursor: world ``position``, unit ``normal``, texture ``uv``
    (after the uv scale; ``v`` up, values past 1 repeat)."""

    position: np.ndarray
    normal: np.ndarray
    uv: np.ndarray

    def texel(self, width: int, height: int) -> tuple[float, float]:
        """Continuous texel coordinates (x right, y down; texel (i, j) centred at +1/2)."""
        u, v = np.mod(self.uv, 1.0)
        return float(u * width), float((1.0 - v) * height)


class PickBuffer:
    """Per-pixel uv / position / normal of one view of a renderer's mesh."""

    def __init__(self, renderer) -> None:
        self.renderer = renderer
        self.program = shaders.Program(shaders.MESH_VERTEX, shaders.PICK_FRAGMENT)
        self._key: tuple | None = None
        self.uv = self.position = self.normal = np.zeros((0, 0, 4), np.float32)

    def _view_key(self, width: int, height: int) -> tuple:
        cam = self.renderer.camera
        return (
            width,
            height,
            cam.yaw,
            cam.pitch,
            cam.distance,
            tuple(np.asarray(cam.target)),
            cam.half_fov,
            tuple(self.renderer.uv_scale),
            id(self.renderer.mesh),
        )

    def update(self, width: int, height: int) -> None:
        """Re-render the buffers if the view changed since the last call (needs a context)."""
        key = self._view_key(width, height)
        if key == self._key:
            return
        r = self.renderer
        previous = GL.glGetIntegerv(GL.GL_FRAMEBUFFER_BINDING)
        fbo = Framebuffer(width, height, (GL.GL_RGBA32F,) * 3)
        try:
            fbo.bind()
            GL.glClearColor(0.0, 0.0, 0.0, 0.0)
            GL.glClear(GL.GL_COLOR_BUFFER_BIT | GL.GL_DEPTH_BUFFER_BIT)
            GL.glEnable(GL.GL_DEPTH_TEST)
            GL.glDepthFunc(GL.GL_LESS)
            self.program.use()
            self.program.set("u_view_proj", r.camera.view_projection(width / height))
            self.program.set("u_uv_scale", np.asarray(r.uv_scale, dtype=np.float32))
            r.mesh.draw()
            self.uv, self.position, self.normal = (fbo.read(k) for k in range(3))
        finally:
            fbo.delete()
            GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, previous)
        self._key = key

    def hit(self, x: float, y: float) -> SurfaceHit | None:
        """The surface under widget point (x, y) (pixels, y down), or None (background)."""
        h, w = self.uv.shape[:2]
        col, row = int(np.floor(x)), int(np.floor(y))
        if not (0 <= col < w and 0 <= row < h) or self.uv[row, col, 2] <= 0.0:
            return None
        return SurfaceHit(
            position=self.position[row, col, :3].astype(np.float64),
            normal=self.normal[row, col, :3].astype(np.float64),
            uv=self.uv[row, col, :2].astype(np.float64),
        )

    def uv_at(self, x: float, y: float) -> tuple[float, float] | None:
        found = self.hit(x, y)
        return None if found is None else (float(found.uv[0]), float(found.uv[1]))

    def delete(self) -> None:
        self.program.delete()
