"""The canvas' "Lit" display: the flattened material lit as a flat swatch, one pixel per texel.

Two renderers, one picture (:mod:`.lit_scene` holds the scene and light):

- **OpenGL** where a context can be made (:mod:`.lit_gl`): the 3D viewport's
  shader in texture space, on its own thread. A light move only changes
  uniforms; the material is uploaded when the document changes (only its
  dirty tiles after the first time). A coarse pass comes first when the full
  resolution would take longer than the drag can wait, and the note says
  "refining" until the full-resolution picture of the current light is up.
- **the reference renderer** otherwise (no display, no driver): progressive
  passes of 128 px, 512 px and the full resolution on a worker, each dropped
  as soon as the light or the material moves on; the note says which
  renderer draws and why.

Both work on document *snapshots*, never during a stroke (its open
transaction writes tiles in place); a generation counter bumped by every
change marks pictures that are out of date. A right-button drag on the
canvas moves the light (the cursor's direction from the image centre tilts it);
the environment and exposure are the editor's lighting choice (:mod:`.lighting`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from PySide6.QtCore import QEventLoop, QObject, QThreadPool, QTimer, Signal
from PySide6.QtGui import QAction, QImage

from ..layers import Document
from ..layers.events import DirtyRegion
from ..layers.geometry import TileKey
from ..render.environment import Environment
from ..render.environment_choice import EnvironmentChoice
from ..viewport.canvas import TextureCanvas
from . import lit_scene
from .lit_scene import light_direction
from .session import DocumentSession
from .work import start_worker

__all__ = ["QUICK_SIZE", "REFERENCE_SIZES", "LitPreview", "light_direction"]

#: Sides of the reference renderer's passes before the full resolution.
REFERENCE_SIZES = (128, 512)
QUICK_SIZE = REFERENCE_SIZES[0]


class _Superseded(Exception):
    """A reference pass stopped because the light or the material moved on."""


@dataclass
class _Job:
    generation: int
    doc: Document
    light: tuple[float, float, float]
    shape: tuple[int, int]
    environment: Environment | None = None
    exposure_stops: float = 0.0
    image: np.ndarray | None = None
    error: BaseException | None = None
    seconds: float = 0.0


class _Relay(QObject):
    done = Signal(object)


class LitPreview(QObject):
    """Keeps a lit picture of the session's document on the canvas while enabled."""

    #: a picture was shown (seconds it took to render)
    rendered = Signal(float)
    message = Signal(str)

    def __init__(
        self,
        session: DocumentSession,
        canvas: TextureCanvas,
        action: QAction | None = None,
        ready: Callable[[], bool] = lambda: True,
        tool_busy: Callable[[], bool] = lambda: False,
        pool: QThreadPool | None = None,
    ) -> None:
        super().__init__()
        self.session, self.canvas, self.action = session, canvas, action
        self.ready, self.tool_busy = ready, tool_busy
        self.pool = pool or QThreadPool.globalInstance()
        self.enabled = False
        #: draw with OpenGL when a context can be made (False: the reference renderer only)
        self.prefer_gl = True
        #: why the reference renderer draws (None: OpenGL does, or nothing was tried yet)
        self.gl_problem: str | None = None
        self.gl = None  # the GLLitWorker, made on first use
        self.light = light_direction(-0.45, -0.55)  # upper left, like most product shots
        #: the artist's environment (None: the studio) and exposure (:mod:`.lighting`)
        self.environment: Environment | None = None
        self.exposure_stops = 0.0
        self.generation = 0
        self.job: _Job | None = None
        self.last_seconds = 0.0
        #: tiles changed since the renderer last had the material (None: all of it)
        self._dirty: set[TileKey] | None = None
        #: the light is the only change since the material went out (GL: no snapshot needed)
        self._material_sent = False
        #: generation and sharpness of the picture on the canvas (-1: none)
        self._shown_generation = -1
        self._shown_sharp = False
        self._watched: Document | None = None
        self._relay = _Relay()
        self._relay.done.connect(self._reference_finished)
        self._timer = QTimer(self)  # coalesces bursts (a stroke's dabs, several signals)
        self._timer.setSingleShot(True)
        self._timer.setInterval(30)
        self._timer.timeout.connect(self._start)
        session.documentReplaced.connect(self._document_replaced)
        canvas.lightDragged.connect(self.set_light_at)
        if action is not None:
            action.setCheckable(True)
            action.toggled.connect(self.set_enabled)
        self._document_replaced()

    # -- switching and the light --------------------------------------------

    def toggle(self) -> None:
        self.set_enabled(not self.enabled)

    def set_enabled(self, on: bool) -> None:
        if on == self.enabled:
            return
        self.enabled = on
        if self.action is not None and self.action.isChecked() != on:
            self.action.setChecked(on)
        if on and self.gl is None and self.gl_problem is None:
            self._start_gl()
        self.canvas.set_overlay(None, lit=on)
        self.canvas.lit_label = self.label
        self._material_changed(None)

    @property
    def label(self) -> str:
        """Which renderer draws the picture, for the canvas note."""
        if self.gl is not None:
            return "Lit (OpenGL)"
        return "Lit (reference renderer)" if not self.prefer_gl else "Lit (reference: no OpenGL)"

    def set_light_at(self, u: float, v: float) -> None:
        """Point the light from image position (u, v) in [-1, 1] (the right-drag)."""
        self.light = light_direction(u, v)
        self.generation += 1
        if not self.enabled:
            return
        self.canvas.set_refining(True)
        if self.gl is not None and self._material_sent:
            self.gl.request(self.generation, self.light)  # uniforms only: at once
        else:
            self._timer.start()

    def set_lighting(self, choice: EnvironmentChoice, environment: Environment) -> None:
        """Light with the editor's choice (:class:`.lighting.LightingController`)."""
        self.environment, self.exposure_stops = environment, choice.exposure_stops
        if self.gl is not None:
            self.gl.set_lighting(environment, self.exposure_stops)
        self.generation += 1
        if not self.enabled:
            return
        self.canvas.set_refining(True)
        if self.gl is not None and self._material_sent:
            self.gl.request(self.generation, self.light)
        else:
            self._timer.start()

    def close(self) -> None:
        """Stop the OpenGL thread (the window is closing)."""
        if self.gl is not None:
            self.gl.stop()
            self.gl = None

    # -- the material ---------------------------------------------------------

    def _document_replaced(self) -> None:
        if self._watched is not None:
            self._watched.events.dirty.disconnect(self._material_changed)
        self._watched = self.session.doc
        if self._watched is not None:
            self._watched.events.dirty.connect(self._material_changed)
        self._material_changed(None)

    def _material_changed(self, region: DirtyRegion | None) -> None:
        """The flattened material changed in ``region`` (None: anywhere, or a new document)."""
        if region is None or self._dirty is None:
            self._dirty = None
        else:
            self._dirty |= region.keys
        self._material_sent = False
        self.generation += 1
        if self.enabled:
            self.canvas.set_refining(True)
            self._timer.start()

    def _start(self) -> None:
        doc = self.session.doc
        if not self.enabled or doc is None:
            return
        if self.tool_busy() or not self.ready():
            self._timer.start(150)  # a stroke or a heavy flatten: try again shortly
            return
        if self.gl is not None:
            if not self._material_sent:
                self.gl.set_document(doc.snapshot(), self._dirty)
                self._dirty, self._material_sent = set(), True
            self.gl.request(self.generation, self.light)
        else:
            self._start_reference(doc)

    # -- OpenGL ---------------------------------------------------------------

    def _start_gl(self) -> None:
        if not self.prefer_gl:
            self.gl_problem = "OpenGL switched off"
            return
        from .lit_gl import GLLitWorker, GLUnavailableHere

        try:
            self.gl = GLLitWorker()
        except GLUnavailableHere as exc:
            self.gl_problem = f"no OpenGL: {exc}"
            self.message.emit(f"Lit preview: {self.gl_problem}; the reference renderer draws it")
            return
        self.gl.frame.connect(self._gl_frame)
        self.gl.failed.connect(self._gl_failed)
        if self.environment is not None:
            self.gl.set_lighting(self.environment, self.exposure_stops)
        self.gl.start()
        self._dirty, self._material_sent = None, False

    def _gl_frame(self, frame) -> None:
        self._show(frame.image, frame.generation, frame.level == 0, frame.seconds)

    def _gl_failed(self, problem: str) -> None:
        """The GL thread died: the reference renderer takes over (said aloud)."""
        if self.gl is not None:
            self.gl.stop()
        self.gl = None
        self.gl_problem = f"OpenGL failed: {problem}"
        self.message.emit(f"Lit preview: {self.gl_problem}; the reference renderer draws it")
        self.canvas.lit_label = self.label
        self._material_changed(None)

    # -- the reference renderer ------------------------------------------------

    def _reference_shape(self) -> tuple[int, int]:
        """The next reference pass: the first of :data:`REFERENCE_SIZES` finer than the
        picture shown (a change starts again from the first), else the full resolution."""
        doc = self.session.doc
        assert doc is not None
        full = max(doc.width, doc.height)
        shown = self.canvas.overlay
        current = self._shown_generation == self.generation and shown is not None
        have = max(shown.width(), shown.height()) if current else 0
        for side in REFERENCE_SIZES:
            if have < side < full:
                scale = side / full
                return max(1, round(doc.height * scale)), max(1, round(doc.width * scale))
        return doc.height, doc.width

    def _start_reference(self, doc: Document) -> None:
        if self.job is not None:
            return  # the running job reschedules when it ends
        job = _Job(
            self.generation,
            doc.snapshot(),
            self.light,
            self._reference_shape(),
            self.environment,
            self.exposure_stops,
        )
        self.job = job

        def progress(_done: int, _total: int) -> None:
            if job.generation != self.generation:
                raise _Superseded

        def run() -> None:  # worker thread: the snapshot only
            began = time.perf_counter()
            try:
                material = job.doc.flatten_physical()
                job.image = lit_scene.reference_image(
                    material,
                    job.light,
                    job.shape,
                    progress,
                    environment=job.environment,
                    exposure_stops=job.exposure_stops,
                )
            except _Superseded:
                pass
            except BaseException as exc:  # reported on the GUI thread
                job.error = exc
            job.seconds = time.perf_counter() - began
            try:
                self._relay.done.emit(job)
            except RuntimeError:  # the window (and the relay) went away while rendering
                pass

        start_worker(self.pool, run)

    def _reference_finished(self, job: _Job) -> None:
        self.job = None
        doc = self.session.doc
        if job.error is not None:
            self.message.emit(f"Lit preview: {job.error}")
            return
        if job.image is not None and doc is not None:
            sharp = job.shape == (doc.height, doc.width)
            self._show(job.image, job.generation, sharp, job.seconds)
        if self.enabled and not self.up_to_date():
            self._timer.start()  # moved on meanwhile, or a finer pass is still to come

    # -- showing ----------------------------------------------------------------

    def _show(self, pixels: np.ndarray, generation: int, sharp: bool, seconds: float) -> None:
        if not self.enabled:
            return
        height, width = pixels.shape[:2]
        image = QImage(pixels.data, width, height, width * 4, QImage.Format.Format_RGBA8888).copy()
        self._shown_generation, self._shown_sharp = generation, sharp
        self.canvas.set_overlay(image, lit=True, refining=not self.up_to_date())
        self.last_seconds = seconds
        self.rendered.emit(seconds)

    def up_to_date(self) -> bool:
        """The picture shown is the full-resolution one of the current light and material."""
        return self._shown_generation == self.generation and self._shown_sharp

    def wait(self, timeout_s: float = 30.0) -> bool:
        """Run the event loop until the full-resolution picture of the current state is up."""
        end = time.perf_counter() + timeout_s
        while time.perf_counter() < end:
            loop = QEventLoop()  # not processEvents(): see matshop.app.testing.spin
            QTimer.singleShot(5, loop.quit)
            loop.exec()
            if self.canvas.overlay is not None and self.up_to_date():
                return True
        return False
