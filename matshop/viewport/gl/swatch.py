"""The material lit in texture space: the reference's ``swatch`` scene, drawn by the GL shader.

One pixel per texel of the document, the texture seen straight on
(:func:`matshop.render.scenes.swatch`): a flat patch tilted ``tilt_deg``
towards the sky, tangent along ``+x``, viewed from ``+z`` with no
foreshortening. It is drawn as one quad through the 3D viewport's own
programs (:class:`.renderer.MaterialRenderer`: the same surface shader,
material and environment textures), so the BRDF is not written a third
time; only the camera differs. Its projection maps the quad onto the whole
framebuffer (pixel centres on texel centres) and its eye is far up ``+z``,
so every pixel's view direction is the swatch's ``(0, 0, 1)`` to 1e-4.

Moving the light changes uniforms only: the textures are uploaded when the
document changes (whole, or only its dirty tiles). Coarser passes draw a
``2^-level`` framebuffer reading the material's mip ``level`` (the box
filter of the same texels); ``rows`` draws a band of rows, so a long
full-resolution pass can stop between bands.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from OpenGL import GL

from ...layers.geometry import TileKey
from ...render.environment import Environment
from .fbo import Framebuffer
from .mesh_data import MeshData
from .renderer import Lighting, MaterialRenderer

#: the eye's height over the swatch: far enough that the view is (0, 0, 1) to 1e-4
_EYE_DISTANCE = 1.0e4


def _frame(tilt_deg: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Normal, tangent, bitangent of :func:`matshop.render.scenes.swatch`."""
    t = np.radians(tilt_deg)
    return (
        np.array([0.0, np.sin(t), np.cos(t)]),
        np.array([1.0, 0.0, 0.0]),
        np.array([0.0, np.cos(t), -np.sin(t)]),
    )


def swatch_quad(tilt_deg: float) -> MeshData:
    """The unit square of texture space as a tilted quad centred on the origin."""
    normal, tangent, bitangent = _frame(tilt_deg)
    uvs = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], np.float32)
    positions = (uvs[:, :1] - 0.5) * tangent + (uvs[:, 1:] - 0.5) * bitangent
    return MeshData(
        positions=positions.astype(np.float32),
        normals=np.tile(normal, (4, 1)).astype(np.float32),
        tangents=np.tile([1.0, 0.0, 0.0, 1.0], (4, 1)).astype(np.float32),
        uvs=uvs,
        indices=np.array([[0, 1, 2], [0, 2, 3]], np.uint32),  # counter-clockwise: front
        name="swatch",
    )


class SwatchCamera:
    """Orthographic: texture ``(u, v)`` of the quad lands on NDC ``(2u - 1, 2v - 1)``."""

    def __init__(self, tilt_deg: float) -> None:
        self.tilt_deg = tilt_deg

    def view_projection(self, aspect: float) -> np.ndarray:
        # the quad's point (u - 1/2, (v - 1/2) cos t, -(v - 1/2) sin t): x and y scaled
        out = np.zeros((4, 4))
        out[0, 0] = 2.0
        out[1, 1] = 2.0 / np.cos(np.radians(self.tilt_deg))
        out[3, 3] = 1.0
        return out

    def eye(self) -> np.ndarray:
        return np.array([0.0, 0.0, _EYE_DISTANCE])


class SwatchRenderer:
    """A document's material lit as the swatch scene, read back as RGBA8 (needs a current
    OpenGL context in every method)."""

    def __init__(
        self, *, tilt_deg: float = 30.0, environment: Environment | str | None = None
    ) -> None:
        self.renderer = MaterialRenderer(environment)
        self.renderer.set_mesh(swatch_quad(tilt_deg))
        self.renderer.camera = SwatchCamera(tilt_deg)
        self.width = self.height = 0
        self._framebuffers: dict[int, Framebuffer] = {}

    @property
    def lighting(self) -> Lighting:
        """Lights, environment scale, samples, tone map (``render()``'s arguments)."""
        return self.renderer.lighting

    def set_document(self, doc) -> int:
        """Upload all of ``doc``'s shading textures (a new document or a whole change); bytes."""
        self.renderer.set_document(doc)
        if (doc.width, doc.height) != (self.width, self.height):
            self._drop_framebuffers()
            self.width, self.height = doc.width, doc.height
        return self.renderer.textures.bytes_uploaded

    def update_tiles(self, doc, keys: Iterable[TileKey]) -> int:
        """Re-upload only ``keys`` from ``doc`` (a later state of the same document); bytes."""
        textures = self.renderer.textures
        if textures is None:
            raise RuntimeError("no document uploaded yet")
        textures.doc = doc
        return textures.update_tiles(sorted(keys))

    def size(self, level: int = 0) -> tuple[int, int]:
        """``(width, height)`` of the pass at ``level`` (each level halves both)."""
        return max(1, self.width >> level), max(1, self.height >> level)

    def draw(self, level: int = 0, rows: tuple[int, int] | None = None) -> None:
        """Shade the pass at ``level``, or only its image rows ``[top, bottom)`` (top first)."""
        if self.renderer.textures is None:
            raise RuntimeError("no document uploaded yet")
        width, height = self.size(level)
        fbo = self._framebuffer(level)
        fbo.bind()
        self.renderer.lighting.texture_lod = float(level)
        if rows is not None:
            top, bottom = rows
            GL.glEnable(GL.GL_SCISSOR_TEST)  # glClear honours it too
            GL.glScissor(0, height - bottom, width, bottom - top)
        try:
            self.renderer.draw(width, height, background=False)
        finally:
            GL.glDisable(GL.GL_SCISSOR_TEST)
        GL.glFinish()  # the caller times and interleaves passes: the work is done here

    def read(self, level: int = 0) -> np.ndarray:
        """The pass at ``level`` as ``(height, width, 4)`` uint8 RGBA, top row first."""
        return self._framebuffer(level).read()

    def image(self, level: int = 0) -> np.ndarray:
        """Draw and read the whole pass at ``level``."""
        self.draw(level)
        return self.read(level)

    def _framebuffer(self, level: int) -> Framebuffer:
        if level not in self._framebuffers:
            self._framebuffers[level] = Framebuffer(*self.size(level))
        return self._framebuffers[level]

    def _drop_framebuffers(self) -> None:
        for fbo in self._framebuffers.values():
            fbo.delete()
        self._framebuffers = {}

    def delete(self) -> None:
        self._drop_framebuffers()
        self.renderer.delete()
