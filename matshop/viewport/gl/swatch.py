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
document changes (whole, or only its dirty tiles). The light-independent
terms (the environment's filtered samples, the emission: about half the
shader's work) are drawn once per material change into a float *base*
(only the rows of the tiles that changed), and each light pass reads them
back per pixel and adds the lights: the same sum the one-pass shader makes.
Coarser passes draw a
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
from . import shaders
from .fbo import Framebuffer
from .mesh_data import MeshData
from .renderer import Lighting, MaterialRenderer

#: the eye's height over the swatch: far enough that the view is (0, 0, 1) to 1e-4
_EYE_DISTANCE = 1.0e4
#: the texture unit of the base (the material's and environment's use 0-10)
BASE_UNIT = 15


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
        self._framebuffers: dict[tuple[int, bool], Framebuffer] = {}
        #: per level, the rows whose base is out of date (a level not in it: all of them)
        self._stale: dict[int, np.ndarray] = {}
        self._family: str | None = None  # the family the surface program is compiled for

    @property
    def lighting(self) -> Lighting:
        """Lights, environment scale, samples, tone map (``render()``'s arguments)."""
        return self.renderer.lighting

    def set_document(self, doc) -> int:
        """Upload all of ``doc``'s shading textures (a new document or a whole change); bytes.

        The surface program is compiled for the material's D family alone
        (:func:`.shaders.specialised`), again only when the family changes.
        """
        self.renderer.set_document(doc)
        family = self.renderer.textures.family
        if family != self._family:
            program = shaders.Program(
                shaders.MESH_VERTEX, shaders.specialised(shaders.SURFACE_FRAGMENT, family)
            )
            self.renderer.surface.delete()
            self.renderer.surface, self._family = program, family
        if (doc.width, doc.height) != (self.width, self.height):
            self._drop_framebuffers()
            self.width, self.height = doc.width, doc.height
        self._stale = {}  # every level's base is out of date
        return self.renderer.textures.bytes_uploaded

    def update_tiles(self, doc, keys: Iterable[TileKey]) -> int:
        """Re-upload only ``keys`` from ``doc`` (a later state of the same document); bytes."""
        textures = self.renderer.textures
        if textures is None:
            raise RuntimeError("no document uploaded yet")
        textures.doc = doc
        keys = sorted(keys)
        for level, stale in self._stale.items():
            for key in keys:
                rect = doc.layout.tile_rect(key)
                stale[rect.y0 >> level : -(-rect.y1 >> level)] = True
        return textures.update_tiles(keys)

    def set_environment(self, environment: Environment) -> None:
        """Light with ``environment`` from now on (every level's base is out of date, unless
        it is the environment already in use)."""
        current = self.renderer.environment
        if current is None or current.env is not environment:
            self.renderer.set_environment(environment)
            self._stale = {}

    def size(self, level: int = 0) -> tuple[int, int]:
        """``(width, height)`` of the pass at ``level`` (each level halves both)."""
        return max(1, self.width >> level), max(1, self.height >> level)

    def draw(self, level: int = 0, rows: tuple[int, int] | None = None) -> None:
        """Shade the pass at ``level``, or only its image rows ``[top, bottom)`` (top first).

        The light-independent terms come from the level's base, drawn first where
        the material changed since (see the module doc).
        """
        if self.renderer.textures is None:
            raise RuntimeError("no document uploaded yet")
        height = self.size(level)[1]
        top, bottom = rows if rows is not None else (0, height)
        if level not in self._stale:
            self._stale[level] = np.ones(height, dtype=bool)
        stale = self._stale[level]
        changed = np.flatnonzero(stale[top:bottom])
        if changed.size:
            self._pass(level, (top + changed[0], top + changed[-1] + 1), base=True)
            stale[top + changed[0] : top + changed[-1] + 1] = False
        self._pass(level, (top, bottom), base=False)
        GL.glFinish()  # the caller times and interleaves passes: the work is done here

    def _pass(self, level: int, rows: tuple[int, int], *, base: bool) -> None:
        """The base (environment and emission, unmapped, into a float target) or the lit
        picture (the base plus the lights, tone-mapped) over image rows ``rows``."""
        width, height = self.size(level)
        target = self._framebuffer(level, base=True) if base else self._framebuffer(level)
        target.bind()
        program = self.renderer.surface
        program.use()
        program.set("u_linear", base)
        program.set("u_has_base", not base)
        GL.glActiveTexture(GL.GL_TEXTURE0 + BASE_UNIT)
        # never sampled while drawn into: unbound for the base pass itself
        GL.glBindTexture(GL.GL_TEXTURE_2D, 0 if base else self._base_texture(level))
        program.set("u_base", BASE_UNIT)
        lighting = self.renderer.lighting
        lighting.texture_lod = float(level)
        lights = lighting.lights
        if base:
            lighting.lights = ()
        GL.glEnable(GL.GL_SCISSOR_TEST)  # glClear honours it too
        GL.glScissor(0, height - rows[1], width, rows[1] - rows[0])
        try:
            self.renderer.draw(width, height, background=False)
        finally:
            GL.glDisable(GL.GL_SCISSOR_TEST)
            lighting.lights = lights

    def read(self, level: int = 0) -> np.ndarray:
        """The pass at ``level`` as ``(height, width, 4)`` uint8 RGBA, top row first."""
        return self._framebuffer(level).read()

    def image(self, level: int = 0) -> np.ndarray:
        """Draw and read the whole pass at ``level``."""
        self.draw(level)
        return self.read(level)

    def _framebuffer(self, level: int, *, base: bool = False) -> Framebuffer:
        key = (level, base)
        if key not in self._framebuffers:
            formats = (GL.GL_RGBA32F,) if base else (GL.GL_RGBA8,)
            self._framebuffers[key] = Framebuffer(*self.size(level), formats)
        return self._framebuffers[key]

    def _base_texture(self, level: int) -> int:
        return self._framebuffer(level, base=True).textures[0]

    def _drop_framebuffers(self) -> None:
        for fbo in self._framebuffers.values():
            fbo.delete()
        self._framebuffers = {}
        self._stale = {}

    def delete(self) -> None:
        self._drop_framebuffers()
        self.renderer.delete()
