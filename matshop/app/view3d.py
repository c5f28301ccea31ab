"""The 3D view dock: the document's material on a mesh beside the 2D canvas, paintable.

:class:`View3DDock` holds a :class:`~matshop.viewport.gl.view.MaterialViewport`
bound to the session's document (it follows File > Open) and a small toolbar
(mesh, open a mesh, reset the camera). The viewport is created the first
time the dock is shown, so the editor never pays for OpenGL it does not use,
and only after a probe context proves OpenGL 3.3 core exists: where it does
not (``QT_QPA_PLATFORM=offscreen``, no driver) the dock shows one line
instead and the editor works as before.

The toolbar's Mirror (X, Y or Z, and an offset) paints every 3D stroke also
across that plane of the mesh's object space, and shows the plane
(:mod:`matshop.viewport.gl.mirror`); the 2D canvas's Mirror X/Y stays the
texture-space symmetry of 2D strokes.

Painting goes through the same pieces as the 2D brush: the active tool
decides what a left drag does (brush: paint the swatch; eraser: erase;
eyedropper: pick the swatch at the texel under the cursor; clone: orbit, with
a message), the tool host decides which layer (a new paint layer when the
active layer cannot take paint, or the active layer's mask) and the stroke's
single edit goes into the session's history, so Ctrl+Z is the same undo.

Texture updates ride on the document's ``dirty`` signal (the viewport
re-uploads only those tiles); while the background flatten is pending the
view holds its last frame and queues the tiles, like the canvas, so the GUI
thread never computes a slow filter for the 3D view.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction
from PySide6.QtWidgets import (
    QComboBox,
    QDockWidget,
    QDoubleSpinBox,
    QLabel,
    QSizePolicy,
    QStackedWidget,
    QToolBar,
    QVBoxLayout,
    QWidget,
)

from ..errors import MatshopError
from ..tools.painting import MASK_HIDE
from .prompts import Prompts

if TYPE_CHECKING:
    from ..render.environment import Environment
    from ..render.environment_choice import EnvironmentChoice
    from .window_parts import EditorWindow

#: the shared meshes (../shared/data/geometry next to the repository), when present
SHARED_GEOMETRY = Path(__file__).resolve().parents[3] / "shared" / "data" / "geometry"
#: how far outside the mesh's bounding sphere the fitted view starts (1: touching)
FIT_MARGIN = 1.3
HINT = "Alt+drag orbit · right-drag pan · wheel zoom"


def mesh_choices() -> list[tuple[str, Path | None]]:
    """(label, path) of the meshes offered; ``None`` is the built-in sphere."""
    shared = [
        (name.capitalize(), SHARED_GEOMETRY / f"{name}.obj")
        for name in ("sphere", "cube", "plane")
        if (SHARED_GEOMETRY / f"{name}.obj").is_file()
    ]
    return shared or [("Sphere", None)]


@functools.cache
def gl_problem() -> str | None:
    """Why no OpenGL 3.3 core context can be made here (None: it can). Probed once."""
    try:
        from PySide6 import QtOpenGLWidgets  # noqa: F401  (the widget module itself)

        from ..viewport.gl.context import GLUnavailable, OffscreenContext
    except ImportError as exc:  # PyOpenGL or the Qt module missing (extra 'gui')
        return f"the OpenGL modules are not installed ({exc.name})"
    try:
        context = OffscreenContext()
    except GLUnavailable as exc:
        return str(exc)
    context.done_current()
    return None


def ask_mesh(prompts: Prompts, start: str = "") -> Path | None:
    """A mesh file from the user, through the window's prompts (tests script them)."""
    return prompts.open_mesh(start)


@functools.cache
def _viewport_class() -> type:
    """The editor's viewport subclass (imported late: OpenGL may be missing)."""
    from ..render.integrator import DirectionalLight
    from ..viewport.gl.view import MaterialViewport

    class EditorViewport(MaterialViewport):
        """A :class:`MaterialViewport` whose strokes are the editor's (see the module doc)."""

        def __init__(self, dock: View3DDock) -> None:
            super().__init__()
            self.dock = dock
            self._deferred: set = set()
            # one key light over the left shoulder, so relief and gloss read at a glance
            self.key_light = DirectionalLight((-0.5, 0.7, 0.6), (2.0, 2.0, 2.0))
            self.lighting.lights = (self.key_light,)
            self.setMinimumSize(160, 160)
            self.setFocusPolicy(Qt.FocusPolicy.ClickFocus)
            #: the user orbited, panned or zoomed: resizes no longer reframe the mesh
            self.camera_moved = False

        def show_lighting(self, choice: EnvironmentChoice, environment: Environment) -> None:
            """Light with the editor's choice (:mod:`.lighting`). The studio keeps the
            view's key light; any other environment (the sky's sun, the artist's HDR)
            is the whole light, as ``matshop render --env`` renders it."""
            self.lighting.lights = (self.key_light,) if choice.source == "studio" else ()
            self.lighting.exposure = choice.exposure_stops
            self.set_environment(environment)

        def fit_camera(self) -> None:
            """Front view, backed off so the unit-sphere-sized mesh fits the narrower side."""
            from ..viewport.gl.camera import OrbitCamera

            self.camera = OrbitCamera()
            tx, ty = self.camera.tan_half_fov(self.width() / max(self.height(), 1))
            self.camera.distance = FIT_MARGIN / min(tx, ty)
            self.camera_moved = False
            self.update()

        def resizeGL(self, w: int, h: int) -> None:  # noqa: N802 (Qt's name)
            if not self.camera_moved:  # keep the mesh framed as the split moves
                self.fit_camera()

        def wheelEvent(self, event) -> None:  # noqa: N802
            self.camera_moved = True
            super().wheelEvent(event)

        @property
        def busy(self) -> bool:
            return self.painter.active

        # -- held while the background flatten is pending --------------------

        def _apply(self) -> None:
            if self.renderer is not None:  # a background upload reads no block meanwhile
                self.renderer.paused = self.dock.held()
            if self.dock.held() and self._stale_content:
                stale, self._stale_content = True, False
                super()._apply()  # camera only: uploading would flatten on this thread
                self._stale_content = stale
            else:
                super()._apply()

        def _on_dirty(self, region) -> None:
            if self.dock.held():
                self._deferred.update(region.keys)
                return
            super()._on_dirty(region)

        def release_held(self) -> None:
            """The flatten is ready: upload what was queued while it was not."""
            if self.renderer is not None and self._deferred:
                self.renderer.mark_dirty(self._deferred)
            self._deferred = set()
            self.update()

        def set_document(self, doc) -> None:
            self._deferred = set()
            super().set_document(doc)

        # -- strokes ---------------------------------------------------------

        def mousePressEvent(self, event) -> None:  # noqa: N802 (Qt's name)
            self._brush = None
            left = event.button() == Qt.MouseButton.LeftButton
            alt = bool(event.modifiers() & Qt.KeyboardModifier.AltModifier)
            if left and not alt and self.doc is not None:
                pos = event.position()
                if self.dock.left_press(self, pos.x(), pos.y(), event.modifiers()):
                    return  # a pick, not a stroke or an orbit
            if not self._paints(event):
                self.camera_moved = True  # an orbit or a pan
            try:
                super().mousePressEvent(event)
            except MatshopError as exc:  # the engine's sentence (swatch vs layer...)
                self.painter.stroke = None
                self.dock.message(str(exc))

        def mouseReleaseEvent(self, event) -> None:  # noqa: N802
            if self.painter.active:
                edit = self.painter.release()
                if edit is not None:
                    self.dock.stroke_done(edit)
            super().mouseReleaseEvent(event)

    return EditorViewport


class View3DDock(QDockWidget):
    """The "3D View" dock of the main window (see the module docstring)."""

    def __init__(self, window: EditorWindow, action: QAction) -> None:
        super().__init__("3D View", window)
        self.setObjectName("view3d_dock")
        self.window_ = window
        self.action = action
        self.viewport: Any = None  # EditorViewport once shown with a working GL
        self.setFeatures(
            QDockWidget.DockWidgetFeature.DockWidgetMovable
            | QDockWidget.DockWidgetFeature.DockWidgetFloatable
            | QDockWidget.DockWidgetFeature.DockWidgetClosable
        )
        body = QWidget()
        layout = QVBoxLayout(body)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addWidget(self._build_toolbar())
        layout.addWidget(self._build_mirror())
        self.stack = QStackedWidget()
        self.note = QLabel("")
        self.note.setObjectName("hint")
        self.note.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.note.setWordWrap(True)
        self.stack.addWidget(self.note)
        layout.addWidget(self.stack, 1)
        self.setWidget(body)

        # the split view: a full-height column between the tool panel and the canvas
        # (3D left, 2D right, as in Substance Painter)
        window.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, self)
        window.splitDockWidget(window.tool_dock, self, Qt.Orientation.Horizontal)
        self.hide()
        action.toggled.connect(self._action_toggled)
        window.session.documentReplaced.connect(self._document_replaced)
        window.background.busyChanged.connect(self._background_busy)

    def _build_toolbar(self) -> QToolBar:
        bar = QToolBar("3D View")
        bar.setIconSize(bar.iconSize() * 0.8)
        bar.addWidget(QLabel("  Mesh "))
        self.mesh_combo = QComboBox()
        self.mesh_combo.setMinimumWidth(110)
        for label, path in mesh_choices():
            self.mesh_combo.addItem(label, path)
        self.mesh_combo.activated.connect(
            lambda index: self.set_mesh(self.mesh_combo.itemData(index))
        )
        bar.addWidget(self.mesh_combo)
        self.open_mesh_action = bar.addAction("Open Mesh…", self.open_mesh)
        self.open_mesh_action.setToolTip("Show the material on your own OBJ or glTF mesh")
        bar.addAction("Reset View", self.reset_view).setToolTip("Back to the front view")
        self.keep_variance_action = bar.addAction("Keep Variance")
        self.keep_variance_action.setCheckable(True)
        self.keep_variance_action.setToolTip(
            "Widen the roughness by the normal detail the view's smaller mip levels remove, "
            "so the material keeps its look from afar (as export --keep-variance does)"
        )
        self.keep_variance_action.toggled.connect(self._keep_variance_toggled)
        spacer = QWidget()
        spacer.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Preferred)
        bar.addWidget(spacer)
        hint = QLabel(HINT + "  ")
        hint.setObjectName("hint")
        bar.addWidget(hint)
        return bar

    def _build_mirror(self) -> QToolBar:
        """A second row: the object-space mirror, a plane of the mesh (off, X, Y, Z) and
        its offset (the first row is full at the dock's usual width)."""
        bar = QToolBar("3D Mirror")
        bar.setIconSize(bar.iconSize() * 0.8)
        bar.addWidget(QLabel("  Mirror "))
        self.mirror_combo = QComboBox()
        for label, axis in (("Off", None), ("X", "x"), ("Y", "y"), ("Z", "z")):
            self.mirror_combo.addItem(label, axis)
        self.mirror_combo.setToolTip(
            "Strokes in the 3D view also paint their mirror image across this plane of the "
            "mesh's own axes, through its bounding box's centre (the 2D canvas mirrors with "
            "Tools > Mirror X/Y)"
        )
        self.mirror_offset = QDoubleSpinBox()
        self.mirror_offset.setRange(-1.0, 1.0)
        self.mirror_offset.setSingleStep(0.01)
        self.mirror_offset.setDecimals(3)
        self.mirror_offset.setToolTip(
            "Move the mirror plane along its axis from the mesh's centre, in units of the "
            "mesh's bounding radius"
        )
        self.mirror_combo.currentIndexChanged.connect(self._mirror_changed)
        self.mirror_offset.valueChanged.connect(self._mirror_changed)
        bar.addWidget(self.mirror_combo)
        bar.addWidget(QLabel("  Offset "))
        bar.addWidget(self.mirror_offset)
        self._mirror_changed()
        return bar

    def mirror_plane(self) -> Any:
        """The chosen :class:`~matshop.viewport.gl.mirror.MirrorPlane`, or None (off)."""
        axis = self.mirror_combo.currentData()
        if axis is None:
            return None
        from ..viewport.gl.mirror import MirrorPlane  # OpenGL is imported only when used

        return MirrorPlane(axis, self.mirror_offset.value())

    def mirror_state(self) -> dict[str, Any]:
        """The mirror's choice, for the project's editor state."""
        return {"axis": self.mirror_combo.currentData(), "offset": self.mirror_offset.value()}

    def load_mirror_state(self, data: Any) -> None:
        """Choose the mirror a project saved (anything unreadable: the mirror is off)."""
        data = data if isinstance(data, dict) else {}
        index = self.mirror_combo.findData(data.get("axis"))
        offset = data.get("offset", 0.0)
        finite = isinstance(offset, int | float) and math.isfinite(offset)
        self.mirror_offset.setValue(offset if finite else 0.0)
        self.mirror_combo.setCurrentIndex(max(index, 0) if data.get("axis") else 0)

    def _mirror_changed(self) -> None:
        self.mirror_offset.setEnabled(self.mirror_combo.currentData() is not None)
        if self.viewport is not None:
            self.viewport.set_mirror(self.mirror_plane())

    # -- showing -------------------------------------------------------------

    @property
    def busy(self) -> bool:
        """A 3D stroke is under way (undo must wait, like for the canvas's)."""
        return self.viewport is not None and self.viewport.busy

    def held(self) -> bool:
        return not self.window_.background.ready

    def message(self, text: str) -> None:
        self.window_.show_message(text)

    def _action_toggled(self, on: bool) -> None:
        if on and self.isHidden() and not self.isFloating():
            # a split view: half the canvas's width, none taken from the tool panel
            window = self.window_
            widths = [window.tool_dock.width(), max(320, window.canvas.width() // 2)]
            self.show()
            window.resizeDocks([window.tool_dock, self], widths, Qt.Orientation.Horizontal)
        self.setVisible(on)
        if on:
            self.raise_()

    def showEvent(self, event) -> None:  # noqa: N802 (Qt's name)
        super().showEvent(event)
        self.action.setChecked(True)
        self.ensure_viewport()

    def hideEvent(self, event) -> None:  # noqa: N802
        super().hideEvent(event)
        # only when the dock itself was closed: the window hides it too when it
        # minimizes, or while Qt recreates it for OpenGL as the viewport appears
        if self.isHidden():
            self.action.setChecked(False)

    def ensure_viewport(self) -> Any:
        """Create the viewport on first show (None, with the note shown, without OpenGL)."""
        if self.viewport is not None:
            return self.viewport
        problem = gl_problem()
        if problem is not None:
            self.note.setText(f"3D view unavailable: {problem}")
            self.stack.setCurrentWidget(self.note)
            self.mesh_combo.setEnabled(False)
            self.mirror_combo.setEnabled(False)
            return None
        self.viewport = _viewport_class()(self)
        self.stack.addWidget(self.viewport)
        self.stack.setCurrentWidget(self.viewport)
        self.set_mesh(self.mesh_combo.currentData())
        self.viewport.set_keep_variance(self.keep_variance_action.isChecked())
        self.viewport.set_mirror(self.mirror_plane())
        lighting = self.window_.lighting
        if lighting.environment is not None:
            self.viewport.show_lighting(lighting.choice, lighting.environment)
        self._document_replaced()
        return self.viewport

    # -- content -------------------------------------------------------------

    def _keep_variance_toggled(self, on: bool) -> None:
        if self.viewport is not None:
            self.viewport.set_keep_variance(on)

    def show_lighting(self, choice: EnvironmentChoice, environment: Environment) -> None:
        """The editor's lighting changed (:class:`.lighting.LightingController`)."""
        if self.viewport is not None:
            self.viewport.show_lighting(choice, environment)

    def _document_replaced(self) -> None:
        if self.viewport is not None:
            self.viewport.set_document(self.window_.session.doc)

    def _background_busy(self, busy: bool) -> None:
        if not busy and self.viewport is not None:
            self.viewport.release_held()

    def set_mesh(self, path: Path | None) -> bool:
        """Show ``path`` (an OBJ/glTF) or the built-in sphere (None); False if it failed."""
        if self.viewport is None:
            return False
        from ..viewport.gl.mesh_data import load_mesh, uv_sphere

        try:
            mesh = uv_sphere() if path is None else load_mesh(path)
        except Exception as exc:  # noqa: BLE001 - any reader error becomes one line
            self.window_.prompts.error("Open mesh", f"Cannot read {Path(path).name}: {exc}")
            return False
        self.viewport.set_mesh(mesh)
        return True

    def open_mesh(self) -> bool:
        """Ask for a mesh file and show it (added to the mesh list)."""
        path = ask_mesh(self.window_.prompts, str(SHARED_GEOMETRY))
        if path is None or self.ensure_viewport() is None or not self.set_mesh(path):
            return False
        index = self.mesh_combo.findData(path)
        if index < 0:
            self.mesh_combo.addItem(path.name, path)
            index = self.mesh_combo.count() - 1
        self.mesh_combo.setCurrentIndex(index)
        return True

    def reset_view(self) -> None:
        if self.viewport is not None:
            self.viewport.fit_camera()

    # -- strokes (called by the viewport) ---------------------------------------

    def left_press(self, viewport, x: float, y: float, modifiers) -> bool:
        """Arm the viewport for a left press at widget (x, y); True if it was a pick.

        Leaves ``viewport._brush`` set for a stroke, or None for an orbit.
        """
        host = self.window_.host
        tool = self.window_.canvas.tool
        name = getattr(tool, "name", "")
        pick = bool(modifiers & Qt.KeyboardModifier.ControlModifier) or name == "eyedropper"
        if pick:  # Ctrl-click, or the eyedropper: pick the swatch under the cursor
            hit = viewport._hit(x, y)
            if hit is not None:
                doc = viewport.doc
                tx, ty = hit.texel(doc.width, doc.height)
                host.pick_swatch(int(tx), int(ty))
            return True
        if name not in ("brush", "eraser"):
            self.message("The 3D view paints with the brush and the eraser; this drag orbits")
            return False
        options = self._stroke_options(name)
        if options is not None:
            # a fresh seed a stroke, as on the canvas (random tip angles, jitter, scatter)
            viewport._brush = {
                "brush": host.brush(),
                "history": None,
                "seed": host.stroke_seed(),
                **options,
            }
        return False

    def _stroke_options(self, tool: str) -> dict | None:
        """Layer and engine options of a stroke, as the 2D tools decide them (None: none)."""
        host = self.window_.host
        mode = "erase" if tool == "eraser" else "paint"
        if host.stroke_target() == "mask":
            layer_id = host.mask_layer()
            options: dict = {"target": "mask", "mask_value": MASK_HIDE, "mode": mode}
        else:
            swatch = None
            if mode == "paint":
                try:
                    swatch = host.swatch()
                except MatshopError as exc:
                    self.message(str(exc))
                    return None
            layer_id = host.stroke_layer(
                create=mode == "paint",
                parameters=None if swatch is None else swatch.parameters,
            )
            options = {"swatch": swatch, "mode": mode}
        return None if layer_id is None else {"layer_id": layer_id, **options}

    def stroke_done(self, edit) -> None:
        """A 3D stroke ended: its single edit is one undo step, as a 2D stroke's."""
        self.window_.host.push(edit)
