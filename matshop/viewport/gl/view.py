"""``MaterialViewport``: the QOpenGLWidget showing the document's material on a mesh.

Mouse: with a brush set (:meth:`MaterialViewport.set_brush`) the left button
paints (with a mirror plane, :meth:`MaterialViewport.set_mirror`, also across
it); without one, or with Alt, it orbits. The right or middle button pans,
the wheel zooms. The document's ``dirty`` signal queues tiles; the next frame
uploads just those (:meth:`.renderer.MaterialRenderer.sync`). A whole document
(a new one, keep variance toggled) is built on a worker thread and uploaded a
block a frame (:mod:`.band_loader`), so the event loop keeps running meanwhile;
:meth:`MaterialViewport.render_image` waits for all of it.

Everything GL happens with the widget's context current: Qt makes it current
around ``initializeGL``/``paintGL``; the other methods do it themselves, so
tests and scripts can call :meth:`render_image` and :meth:`uv_at` directly.
Calls made before the widget has a context are remembered and applied in
``initializeGL``.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
from PySide6.QtCore import Qt, QTimer
from PySide6.QtGui import QImage
from PySide6.QtOpenGLWidgets import QOpenGLWidget

from ...layers.events import DirtyRegion
from ...paint.brush import Brush
from ...paint.stencil import Stencil
from ...paint.swatch import Swatch
from ...render.environment import Environment
from .banded_frame import BandedFrames
from .camera import OrbitCamera
from .context import surface_format
from .mesh_data import MeshData, load_mesh, uv_sphere
from .mirror import MeshMirror, MirrorPlane
from .painting import ViewportPainter
from .picking import PickBuffer, SurfaceHit
from .renderer import Lighting, MaterialRenderer
from .screen_stencil import ScreenStencil
from .surface_map import SurfaceMap

ORBIT_DEGREES_PER_PIXEL = 0.4
WHEEL_ZOOM = 1.1
#: frames while textures load in the background: each uploads a block, events run between
LOADING_FRAME_MS = 15
#: the most one paint may draw for: a slower frame (software OpenGL) is drawn in bands
#: over several paints, the last whole frame shown meanwhile (:mod:`.banded_frame`)
FRAME_BUDGET_S = 0.06


class MaterialViewport(QOpenGLWidget):
    """The 3D view of a :class:`~matshop.layers.Document` (see the module docstring)."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        #: the frame drawn in bands within FRAME_BUDGET_S a paint (:mod:`.banded_frame`)
        self.frames = BandedFrames(FRAME_BUDGET_S)
        self._grab = False
        # per widget, so it holds even if the QApplication predates install_default_format
        self.setFormat(surface_format())
        self.camera = OrbitCamera()
        self.lighting = Lighting()
        self._frame_view: tuple[OrbitCamera, Lighting] = (self.camera, self.lighting)
        self.renderer: MaterialRenderer | None = None
        self.doc = None
        self._mesh: MeshData = uv_sphere()
        self._uv_scale = (1.0, 1.0)
        self._lobe: str | None = None
        self._keep_variance = False
        self._environment: Environment | str | None = None
        self._pick: PickBuffer | None = None
        self._surface: SurfaceMap | None = None
        self._stale_content = True
        self._brush: dict | None = None
        self._mirror_plane: MirrorPlane | None = None
        self._mirror: MeshMirror | None = None
        self._stencil: Stencil | None = None
        self._drag: tuple[Qt.MouseButton, float, float] | None = None
        self.painter = ViewportPainter(self._hit, self.surface_map, self._stroke_options)
        self.setMouseTracking(False)

    # -- content -----------------------------------------------------------

    def set_document(self, doc) -> None:
        if self.doc is not None:
            self.doc.events.dirty.disconnect(self._on_dirty)
        self.doc = doc
        if doc is not None:
            doc.events.dirty.connect(self._on_dirty)
        self._surface = None
        self._stale_content = True
        self.update()

    def set_mesh(self, mesh: str | os.PathLike[str] | MeshData) -> None:
        """An .obj/.gltf/.glb path (normalised into the unit sphere) or a :class:`MeshData`."""
        self._mesh = mesh if isinstance(mesh, MeshData) else load_mesh(mesh)
        self._surface = None
        self._mirror = None
        self._stale_content = True
        self.update()

    def set_uv_scale(self, u: float, v: float) -> None:
        """Texture repeats (the reference sphere scene uses 2 around, 1 pole to pole)."""
        self._uv_scale = (float(u), float(v))
        self._surface = None
        self._mirror = None
        if self.renderer is not None:
            self.renderer.uv_scale = self._uv_scale
        self.update()

    def set_lobe(self, family: str | None) -> None:
        """Show the material with this D (ggx, beckmann, phong, ashikhmin_shirley) or its own."""
        self._lobe = family
        self._stale_content = True
        self.update()

    def set_keep_variance(self, on: bool) -> None:
        """Mips widen the lobe by the normals' tilt variance they average away (specular
        anti-aliasing: a bumpy material keeps its highlight's breadth from afar)."""
        self._keep_variance = bool(on)
        self._stale_content = True
        self.update()

    def set_mirror(self, plane: MirrorPlane | None) -> None:
        """Paint symmetrically across ``plane`` (object space; None: no mirror), and show it."""
        if plane != self._mirror_plane:
            self._mirror_plane = plane
            self._mirror = None
            self.update()

    @property
    def drawing(self) -> bool:
        """A frame is being drawn in bands (the last whole one is shown meanwhile)."""
        return self.frames.drawing

    @property
    def mirror_plane(self) -> MirrorPlane | None:
        return self._mirror_plane

    def mesh_mirror(self) -> MeshMirror | None:
        """The mesh's mirror for strokes (built on first use), or None without a plane."""
        if self._mirror_plane is None:
            return None
        if self._mirror is None:
            self._mirror = MeshMirror(self._mesh, self._mirror_plane, uv_scale=self._uv_scale)
        return self._mirror

    def set_environment(self, environment: Environment | str | None) -> None:
        """Light with ``environment``: its textures go up a band a frame (the one
        shown stays until they are all there), so a large HDR never stalls the GUI."""
        self._environment = environment
        if self.renderer is not None:
            with self._current():
                self.renderer.set_environment(environment, incremental=True)
        self.update()

    def set_brush(
        self,
        layer_id: int | None,
        brush: Brush | None = None,
        swatch: Swatch | None = None,
        history=None,
    ) -> None:
        """Paint ``swatch`` with ``brush`` into paint layer ``layer_id`` (None: orbit only)."""
        self._brush = (
            None
            if layer_id is None
            else {
                "layer_id": layer_id,
                "brush": brush or Brush(),
                "swatch": swatch,
                "history": history,
            }
        )

    # -- GL lifecycle ------------------------------------------------------

    @contextmanager
    def _current(self) -> Iterator[None]:
        self.makeCurrent()
        try:
            if self.renderer is None:
                self._initialize()
            self._apply()
            yield
        finally:
            self.doneCurrent()

    def _initialize(self) -> None:
        self.renderer = MaterialRenderer(self._environment)
        self.renderer.camera = self.camera
        self.renderer.lighting = self.lighting
        self._pick = PickBuffer(self.renderer)

    def _apply(self) -> None:
        r = self.renderer
        r.camera = self.camera
        r.lighting = self.lighting
        r.uv_scale = self._uv_scale
        r.mirror_plane = self._mirror_plane
        if self._stale_content:
            r.set_mesh(self._mesh)
            r.set_document(
                self.doc, lobe=self._lobe, keep_variance=self._keep_variance, background=True
            )
            self._stale_content = False

    def initializeGL(self) -> None:  # noqa: N802 (Qt's name)
        # moving the widget to another window (a dock floated or docked) gives it a
        # new context: the GL objects die with the old one and are made again here
        self.context().aboutToBeDestroyed.connect(self._context_lost)
        if self.renderer is None:
            self._initialize()

    def _context_lost(self) -> None:
        if self.renderer is not None:
            self.makeCurrent()
            self.renderer.delete()
            self.frames.delete()
            if self._pick is not None:
                self._pick.delete()
            self.doneCurrent()
        self.renderer = None
        self._pick = None
        self._stale_content = True

    def update(self) -> None:  # noqa: D102 - every change of the picture comes through here
        self.frames.request()
        super().update()

    def _next_band(self) -> None:
        super().update()  # the frame under way goes on

    def grabFramebuffer(self) -> QImage:  # noqa: N802, D102 - Qt's name; a grab shows it whole
        self._grab = True
        try:
            return super().grabFramebuffer()
        finally:
            self._grab = False

    def _begin_frame(self) -> None:
        # every band of a frame shows the view it began with (a drag goes on meanwhile)
        self._frame_view = (copy.deepcopy(self.camera), copy.copy(self.lighting))

    def _draw_band(self, width: int, height: int) -> None:
        self.renderer.camera, self.renderer.lighting = self._frame_view
        self.renderer.draw(width, height)

    def paintGL(self) -> None:  # noqa: N802
        self._apply()
        width, height = self._pixel_size()
        loading = self.renderer.loading
        if loading:  # a background upload sends a block a band: another frame shows them
            self.frames.request()
        self.frames.paint(
            self.defaultFramebufferObject(),
            width,
            height,
            self._begin_frame,
            lambda: self._draw_band(width, height),
            whole=self._grab,
        )
        if self.frames.drawing:  # events run between two bands
            QTimer.singleShot(LOADING_FRAME_MS if loading else 0, self._next_band)

    def _on_dirty(self, region: DirtyRegion) -> None:
        if self.renderer is not None:
            self.renderer.mark_dirty(region.keys)
        self.update()

    # -- images and picking ------------------------------------------------

    def render_image(self, size: int | tuple[int, int]) -> np.ndarray:
        """An offscreen frame ``(H, W, 4)`` uint8 RGBA of the view, pending tiles uploaded."""
        w, h = (size, size) if np.isscalar(size) else size
        with self._current():
            return self.renderer.render_image(int(w), int(h))

    def _pixel_size(self) -> tuple[int, int]:
        dpr = self.devicePixelRatioF()
        return max(1, int(self.width() * dpr)), max(1, int(self.height() * dpr))

    def _hit(self, x: float, y: float) -> SurfaceHit | None:
        """The surface under widget point (x, y) in logical pixels."""
        dpr = self.devicePixelRatioF()
        with self._current():
            self._pick.update(*self._pixel_size())
        return self._pick.hit(x * dpr, y * dpr)

    def uv_at(self, x: float, y: float) -> tuple[float, float] | None:
        """Texture coordinates (after the uv scale) under widget point (x, y), or None."""
        found = self._hit(x, y)
        return None if found is None else (float(found.uv[0]), float(found.uv[1]))

    def surface_map(self) -> SurfaceMap:
        """The UV-space bake of the mesh for the document's texels (built on first use)."""
        if self._surface is None:
            with self._current():
                self._surface = SurfaceMap(self._mesh, self.doc.layout, uv_scale=self._uv_scale)
        return self._surface

    def set_stencil(self, stencil: Stencil | None) -> None:
        """Mask strokes by ``stencil`` placed in widget pixels (fixed on the screen; None: off)."""
        self._stencil = stencil

    def _stroke_options(self) -> dict:
        if self._brush is None or self.doc is None:
            raise RuntimeError("no brush or document: call set_document and set_brush first")
        options = {"doc": self.doc, "mirror": self.mesh_mirror(), **self._brush}
        if self._stencil is not None:
            camera, size = copy.deepcopy(self.camera), (self.width(), self.height())
            options["screen_stencil"] = ScreenStencil(
                self._stencil, lambda points: camera.project(points, *size)
            )
        return options

    # -- mouse -------------------------------------------------------------

    def _paints(self, event) -> bool:
        return (
            self._brush is not None
            and self.doc is not None
            and event.button() == Qt.MouseButton.LeftButton
            and not event.modifiers() & Qt.KeyboardModifier.AltModifier
        )

    def mousePressEvent(self, event) -> None:  # noqa: N802
        pos = event.position()
        if self._paints(event):
            self.painter.press(pos.x(), pos.y(), _pressure(event))
        else:
            self._drag = (event.button(), pos.x(), pos.y())
        self.update()

    def mouseMoveEvent(self, event) -> None:  # noqa: N802
        pos = event.position()
        if self.painter.active:
            self.painter.move(pos.x(), pos.y(), _pressure(event))
        elif self._drag is not None:
            button, x0, y0 = self._drag
            dx, dy = pos.x() - x0, pos.y() - y0
            if button == Qt.MouseButton.LeftButton:
                self.camera.orbit(-dx * ORBIT_DEGREES_PER_PIXEL, dy * ORBIT_DEGREES_PER_PIXEL)
            else:
                self.camera.pan(dx / max(self.height(), 1), dy / max(self.height(), 1))
            self._drag = (button, pos.x(), pos.y())
        self.update()

    def mouseReleaseEvent(self, event) -> None:  # noqa: N802
        if self.painter.active:
            self.painter.release()
        self._drag = None
        self.update()

    def wheelEvent(self, event) -> None:  # noqa: N802
        steps = event.angleDelta().y() / 120.0
        self.camera.zoom(WHEEL_ZOOM**steps)
        self.update()


def _pressure(event) -> float:
    """Tablet pressure when the device reports it, else full pressure (a mouse)."""
    pressure = float(event.pressure()) if hasattr(event, "pressure") else 1.0
    return min(max(pressure if pressure > 0.0 else 1.0, 0.0), 1.0)
