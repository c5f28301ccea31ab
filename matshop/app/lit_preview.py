"""The canvas' "Lit" display: the flattened material rendered as a flat swatch under a light.

Rendering takes a few hundred milliseconds, so it runs like the heavy
filters (see :mod:`.background`): a worker renders a document *snapshot*,
latest wins (a generation counter bumped by every change drops results that
are out of date), one job at a time, and never during a stroke (its open
transaction writes tiles in place). The canvas shows the last image on top
of the texture while the mode is on; a right-button drag on the canvas
moves the light (the cursor's direction from the image centre tilts it).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from PySide6.QtCore import QObject, QThreadPool, QTimer, Signal
from PySide6.QtGui import QAction, QImage

from ..layers import Document
from ..render.integrator import DirectionalLight
from ..render.render import render
from ..viewport.canvas import TextureCanvas
from .session import DocumentSession
from .work import start_worker

#: Longest side of the rendered swatch (the canvas scales it to the texture).
MAX_SIZE = 512
#: Side of the quick first render after a change (~1/16 of the work of MAX_SIZE): the
#: light follows the drag at once, then the sharp render replaces it.
QUICK_SIZE = 128
#: How far (0..1) the light may lean away from straight above at the image's edge.
MAX_TILT = 0.85


def light_direction(u: float, v: float) -> tuple[float, float, float]:
    """World direction towards the light for a point (u, v) in [-1, 1] of the image.

    The swatch lies in the x-y plane facing +z; image down is -y.
    """
    x, y = MAX_TILT * max(-1.0, min(u, 1.0)), -MAX_TILT * max(-1.0, min(v, 1.0))
    z = math.sqrt(max(1.0 - x * x - y * y, 0.05))
    return (x, y, z)


@dataclass
class _Job:
    generation: int
    doc: Document
    light: tuple[float, float, float]
    size: int
    image: np.ndarray | None = None
    error: BaseException | None = None
    seconds: float = 0.0


class _Relay(QObject):
    done = Signal(object)


class LitPreview(QObject):
    """Keeps a lit render of the session's document for the canvas while enabled."""

    #: a render finished (seconds it took)
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
        self.light = light_direction(-0.45, -0.55)  # upper left, like most product shots
        self.generation = 0
        self.job: _Job | None = None
        self.last_seconds = 0.0
        #: generation and size of the picture on the canvas (-1: none)
        self._shown_generation = -1
        self._shown_size = 0
        self._relay = _Relay()
        self._relay.done.connect(self._finished)
        self._timer = QTimer(self)  # coalesces bursts (a light drag, several signals)
        self._timer.setSingleShot(True)
        self._timer.setInterval(30)
        self._timer.timeout.connect(self._start)
        for signal in (session.historyChanged, session.documentReplaced, session.layersChanged):
            signal.connect(self._changed)
        canvas.lightDragged.connect(self.set_light_at)
        if action is not None:
            action.setCheckable(True)
            action.toggled.connect(self.set_enabled)

    def toggle(self) -> None:
        self.set_enabled(not self.enabled)

    def set_enabled(self, on: bool) -> None:
        if on == self.enabled:
            return
        self.enabled = on
        if self.action is not None and self.action.isChecked() != on:
            self.action.setChecked(on)
        self.canvas.set_overlay(None, lit=on)
        self._changed()

    def set_light_at(self, u: float, v: float) -> None:
        """Point the light from image position (u, v) in [-1, 1] (the right-drag)."""
        self.light = light_direction(u, v)
        self._changed()

    def _changed(self, *_args) -> None:
        self.generation += 1
        if self.enabled:
            self.canvas.set_refining(True)
            self._timer.start()

    def _start(self) -> None:
        doc = self.session.doc
        if not self.enabled or doc is None or self.job is not None:
            return  # a running job reschedules when it ends
        if self.tool_busy() or not self.ready():
            self._timer.start(150)  # a stroke or a heavy flatten: try again shortly
            return
        full = self._full()
        # a change since the last picture: a quick render first, then the full one
        quick = self._shown_generation != self.generation and full > QUICK_SIZE
        size = QUICK_SIZE if quick else full
        job = _Job(self.generation, doc.snapshot(), self.light, size)
        self.job = job

        def run() -> None:  # worker thread: the snapshot only
            began = time.perf_counter()
            try:
                material = job.doc.flatten_physical()
                image = render(
                    material,
                    scene="swatch",
                    size=job.size,
                    lights=(DirectionalLight(job.light, (3.0, 3.0, 3.0)),),
                    environment_scale=0.25,
                    samples=4,
                    background=(0.12, 0.12, 0.13),
                )
                rgba = np.clip(image.display() * 255.0 + 0.5, 0, 255).astype(np.uint8)
                rgba[..., 3] = 255
                job.image = np.ascontiguousarray(rgba)
            except BaseException as exc:  # reported on the GUI thread
                job.error = exc
            job.seconds = time.perf_counter() - began
            try:
                self._relay.done.emit(job)
            except RuntimeError:  # the window (and the relay) went away while rendering
                pass

        start_worker(self.pool, run)

    def _finished(self, job: _Job) -> None:
        self.job = None
        if job.error is not None:
            self.message.emit(f"Lit preview: {job.error}")
        elif self.enabled and job.image is not None:
            height, width = job.image.shape[:2]
            image = QImage(
                job.image.data, width, height, width * 4, QImage.Format.Format_RGBA8888
            ).copy()  # owns its pixels: the array goes away
            current = job.generation == self.generation
            self._shown_generation = job.generation
            self._shown_size = job.size
            sharp = job.size >= self._full()
            self.canvas.set_overlay(image, lit=True, refining=not (current and sharp))
            self.last_seconds = job.seconds
            self.rendered.emit(job.seconds)
        if self.enabled and (job.generation != self.generation or self._shown_size < self._full()):
            self._timer.start()  # moved on meanwhile, or the sharp render is still to come

    def _full(self) -> int:
        """Side of the sharp render of the current document (0: none)."""
        doc = self.session.doc
        return 0 if doc is None else min(MAX_SIZE, max(doc.width, doc.height))

    def wait(self, timeout_s: float = 30.0) -> bool:
        """Process events until an up-to-date image is shown; for tests and scripts."""
        from PySide6.QtWidgets import QApplication

        end = time.perf_counter() + timeout_s
        while time.perf_counter() < end:
            QApplication.processEvents()
            idle = self.job is None and not self._timer.isActive()
            if idle and self.canvas.overlay is not None:
                return True
            time.sleep(0.005)
        return False
