"""Drawing the viewport's frame: the environment backdrop, then the shaded mesh.

:class:`MaterialRenderer` owns every GL object of a view and needs a current
context in every method; the Qt widget (:mod:`.view`) and the offscreen
context (:mod:`.context`) both drive it. Lighting settings mirror the
arguments of :func:`matshop.render.render.render` so a test can pass the same
ones to both.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from OpenGL import GL

from ...layers.geometry import TileKey
from ...render.environment import Environment, load_environment
from ...render.integrator import DirectionalLight
from . import shaders
from .camera import OrbitCamera
from .environment_gpu import STEP_BYTES, EnvironmentTextures
from .fbo import Framebuffer
from .mesh_data import MeshData, uv_sphere
from .mesh_gpu import GpuMesh
from .mirror import MirrorPlane
from .mirror_gpu import MirrorOverlay
from .textures import MaterialTextures

#: the reference's backdrop reads the environment at this level (render.render)
BACKGROUND_LOD = 2.0


@dataclass
class Lighting:
    """What :func:`matshop.render.render.render` calls environment, lights, samples."""

    samples: int = 16
    lod_bias: float = 1.0
    environment_scale: float = 1.0
    specular: bool = True
    lights: Sequence[DirectionalLight] = ()
    exposure: float = 0.0
    tonemap: str = "aces"
    #: "environment" or a linear RGB triple
    background: str | tuple[float, float, float] = "environment"
    #: material texture level: None = per pixel (hardware trilinear), else this level
    texture_lod: float | None = None


class MaterialRenderer:
    """Programs, mesh, material and environment textures of one view."""

    def __init__(self, environment: Environment | str | None = None) -> None:
        self.surface = shaders.Program(shaders.MESH_VERTEX, shaders.SURFACE_FRAGMENT)
        self.background = shaders.Program(shaders.BACKGROUND_VERTEX, shaders.BACKGROUND_FRAGMENT)
        self.camera = OrbitCamera()
        self.lighting = Lighting()
        self.uv_scale = (1.0, 1.0)
        self.mesh: GpuMesh | None = None
        self.textures: MaterialTextures | None = None
        self.environment: EnvironmentTextures | None = None
        #: an environment on its way to the GPU (drawn once complete; until then the
        #: previous one is)
        self._next_environment: EnvironmentTextures | None = None
        self._empty_vao = GL.glGenVertexArrays(1)
        self._pending: set[TileKey] = set()
        #: read no document blocks for a background upload (its owner is recomputing it)
        self.paused = False
        #: the object-space mirror plane to show over the mesh (None: none)
        self.mirror_plane: MirrorPlane | None = None
        self._mirror_overlay: MirrorOverlay | None = None
        self.set_environment(environment)
        self.set_mesh(uv_sphere())

    # -- content -----------------------------------------------------------

    def set_environment(
        self, environment: Environment | str | None, *, incremental: bool = False
    ) -> None:
        """Upload ``environment`` (a name or path is loaded first); the one already
        uploaded is kept (an exposure change hands the same one again).

        ``incremental``: the texels go up over the next frames (:meth:`sync`, a band
        each) while the previous environment stays drawn, so a large HDR does not
        stall the thread that draws; the first environment always goes up at once.
        """
        pending = self._next_environment
        if pending is not None and pending.env is environment:
            return
        if pending is not None:  # superseded before it was complete
            pending.delete()
            self._next_environment = None
        if self.environment is not None and self.environment.env is environment:
            return  # back to the one drawn: nothing to send
        env = environment if isinstance(environment, Environment) else load_environment(environment)
        if incremental and self.environment is not None:
            self._next_environment = EnvironmentTextures(env, incremental=True)
            return
        if self.environment is not None:
            self.environment.delete()
        self.environment = EnvironmentTextures(env)

    def _upload_environment(self, wait: bool) -> int:
        """The next band of an incremental environment (``wait``: all of it); once
        complete it replaces the one drawn. Returns the bytes sent."""
        pending = self._next_environment
        if pending is None:
            return 0
        sent = pending.upload(1 << 62 if wait else STEP_BYTES)
        if pending.complete:
            self.environment.delete()
            self.environment, self._next_environment = pending, None
        return sent

    def set_mesh(self, mesh: MeshData) -> None:
        if self.mesh is not None:
            self.mesh.delete()
        self.mesh = GpuMesh(mesh)

    def set_document(
        self,
        doc,
        *,
        lobe: str | None = None,
        keep_variance: bool = False,
        background: bool = False,
    ) -> None:
        """Upload ``doc``'s shading textures (all of it, once); later only dirty tiles.

        ``keep_variance``: each mip level's lobe is widened by the normals' tilt
        variance it averages away (specular anti-aliasing, :mod:`matshop.ops.variance`).
        ``background``: built on a worker thread and uploaded over the next frames
        (:meth:`.textures.MaterialTextures.reload`); the same document shown with the
        same lobe again (keep variance toggled, another mesh) reloads into the textures
        it has, so the view keeps showing the old contents meanwhile.
        """
        self._pending.clear()
        same = self.textures is not None and self.textures.doc is doc and self.textures.lobe == lobe
        if same:
            self.textures.reload(keep_variance=keep_variance, background=background)
            return
        if self.textures is not None:
            self.textures.delete()
        self.textures = (
            MaterialTextures(doc, lobe=lobe, keep_variance=keep_variance, background=background)
            if doc is not None
            else None
        )

    @property
    def loading(self) -> bool:
        """A background upload is under way (draw again to continue it)."""
        uploading = self.textures is not None and self.textures.loading
        return uploading or self._next_environment is not None

    def mark_dirty(self, keys: Iterable[TileKey]) -> None:
        """Tiles to re-upload before the next frame (the document's dirty signal)."""
        self._pending.update(keys)

    def sync(self, *, wait: bool = False) -> int:
        """Upload the next band of an incremental environment and the next ready block
        of a background upload (``wait``: all of both), then, once none is left, the
        pending dirty tiles; returns the bytes sent.

        Dirty tiles wait for the background upload: a block read before an edit must
        not land over the edit's tiles. While :attr:`paused`, no new block is read.
        """
        sent = self._upload_environment(wait)
        if self.textures is None:
            self._pending.clear()
            return sent
        sent += self.textures.poll(wait=wait, paused=self.paused)
        if self.textures.loading or not self._pending:
            return sent
        keys, self._pending = self._pending, set()
        return sent + self.textures.update_tiles(sorted(keys))

    # -- drawing -----------------------------------------------------------

    def draw(self, width: int, height: int, *, background: bool = True) -> None:
        """Draw into the bound framebuffer (its viewport already ``width x height``).

        ``background=False`` skips the backdrop (a view the surface covers whole).
        """
        self.sync()
        light = self.lighting
        GL.glDisable(GL.GL_CULL_FACE)
        GL.glDisable(GL.GL_DEPTH_TEST)
        GL.glClearColor(0.0, 0.0, 0.0, 1.0)
        GL.glClear(GL.GL_COLOR_BUFFER_BIT | GL.GL_DEPTH_BUFFER_BIT)
        if background:
            self._draw_background(width, height)
        if self.mesh is None or self.textures is None:
            return
        GL.glEnable(GL.GL_DEPTH_TEST)
        GL.glDepthFunc(GL.GL_LESS)
        p = self.surface
        p.use()
        p.set("u_view_proj", self.camera.view_projection(width / height))
        p.set("u_uv_scale", np.asarray(self.uv_scale, dtype=np.float32))
        p.set("u_camera", self.camera.eye())
        p.set("u_exposure", float(light.exposure))
        p.set("u_tonemap", 0 if light.tonemap == "aces" else 1)
        p.set("u_texture_lod", -1.0 if light.texture_lod is None else float(light.texture_lod))
        p.set("u_samples", int(light.samples))
        p.set("u_lod_bias", float(light.lod_bias))
        p.set("u_specular", bool(light.specular))
        p.set("u_env_scale", float(light.environment_scale))
        lights = list(light.lights)[: shaders.MAX_LIGHTS]
        p.set("u_light_count", len(lights))
        if lights:
            p.set("u_light_dir", np.array([lt.unit() for lt in lights]))
            p.set("u_light_irradiance", np.array([lt.irradiance for lt in lights]))
        self.textures.bind(p)
        self.environment.bind(p)
        self.mesh.draw()
        if self.mirror_plane is not None:
            if self._mirror_overlay is None:
                self._mirror_overlay = MirrorOverlay()
            view_proj = self.camera.view_projection(width / height)
            self._mirror_overlay.draw(self.mirror_plane, self.mesh, view_proj, self.uv_scale)

    def _draw_background(self, width: int, height: int) -> None:
        light = self.lighting
        b = self.background
        b.use()
        b.set("u_exposure", float(light.exposure))
        b.set("u_tonemap", 0 if light.tonemap == "aces" else 1)
        flat = not isinstance(light.background, str)
        b.set("u_flat_background", flat)
        b.set("u_background", np.asarray((0, 0, 0) if not flat else light.background, np.float32))
        b.set("u_camera_to_world", self.camera.rotation())
        b.set("u_tan_half_fov", np.asarray(self.camera.tan_half_fov(width / height), np.float32))
        b.set("u_background_lod", BACKGROUND_LOD)
        self.environment.bind(b)
        GL.glBindVertexArray(self._empty_vao)
        GL.glDrawArrays(GL.GL_TRIANGLES, 0, 3)
        GL.glBindVertexArray(0)

    def render_image(self, width: int, height: int | None = None) -> np.ndarray:
        """The frame as ``(height, width, 4)`` uint8 RGBA, top row first (offscreen)."""
        height = width if height is None else height
        previous = GL.glGetIntegerv(GL.GL_FRAMEBUFFER_BINDING)
        fbo = Framebuffer(width, height)
        try:
            self.sync(wait=True)  # an image shows the whole document, uploaded
            fbo.bind()
            self.draw(width, height)
            return fbo.read()
        finally:
            fbo.delete()
            GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, previous)

    def delete(self) -> None:
        things = (self.mesh, self.textures, self.environment, self._next_environment)
        things += (self.surface, self.background)
        for thing in (*things, self._mirror_overlay):
            if thing is not None:
                thing.delete()
        GL.glDeleteVertexArrays(1, [self._empty_vao])
