"""The lit display drawn by OpenGL on its own thread (:mod:`matshop.viewport.gl.swatch`).

A :class:`GLLitWorker` is a thread holding an offscreen OpenGL context and
a :class:`~matshop.viewport.gl.swatch.SwatchRenderer`. The GUI thread hands
it requests and never waits for it:

- ``set_document(snapshot, keys)``: the material changed; the worker uploads
  the snapshot's shading textures (all of them, or only the dirty tiles
  ``keys``), flattening the snapshot there, off the GUI thread;
- ``set_lighting(environment, exposure_stops)``: the artist's lighting
  (:mod:`.lighting`); the environment's textures are uploaded there;
- ``request(generation, light)``: draw this light. Only uniforms change.
  When the full-resolution pass is predicted to take longer than the
  budgets of :data:`COARSE_BUDGETS_S`, coarser passes (mip levels of the
  same material) come first and are shown as "refining"; the full pass runs in bands
  of about :data:`BAND_BUDGET_S` and is dropped between bands as soon as a
  newer request arrives, so a light drag is never more than one band behind.

Results come back as :class:`LitFrame` through the ``frame`` signal (queued
to the GUI thread). The speed model (seconds per pixel) is measured on every
pass, so the quick level and band height follow the machine's load.
"""

from __future__ import annotations

import atexit
import math
import threading
import time
from collections import deque
from dataclasses import dataclass

import numpy as np
from PySide6.QtCore import QCoreApplication, QThread, Signal

from ..layers import Document
from ..layers.geometry import TileKey
from ..render.environment import Environment
from ..viewport.band_speed import follow_speed
from . import lit_scene
from .work import yield_to_the_gui_thread

#: longest the coarse passes should take: the first follows the drag, the second is a
#: sharper picture while the full one is drawn
COARSE_BUDGETS_S = (0.05, 0.5)
#: about how long one band of the full pass takes (the most a newer light waits)
BAND_BUDGET_S = 0.05
#: rows of a pass's first band, which measures the speed for the rest
PROBE_ROWS = 8
#: the first guess of the shader's speed, before anything was measured (llvmpipe, 2 cores)
INITIAL_S_PER_PIXEL = 3e-7


@dataclass
class LitFrame:
    """A finished pass: ``image`` (H, W, 4) uint8 of ``generation``'s light and material."""

    generation: int
    image: np.ndarray
    level: int
    seconds: float


class GLUnavailableHere(RuntimeError):
    """No OpenGL context for the lit display (the message says why)."""


def _offscreen_context():
    try:
        from ..viewport.gl.context import GLUnavailable, OffscreenContext
    except ImportError as exc:  # PyOpenGL missing (the 'gui' extra)
        raise GLUnavailableHere(f"the OpenGL modules are not installed ({exc.name})") from exc
    try:
        return OffscreenContext()
    except GLUnavailable as exc:
        raise GLUnavailableHere(str(exc)) from exc


#: running workers, kept alive until stopped: a QThread destroyed while it runs aborts
_LIVE: set[GLLitWorker] = set()


def _stop_all() -> None:
    for worker in list(_LIVE):
        worker.stop()


atexit.register(_stop_all)  # also where Qt never quits (scripts, test sessions)


class GLLitWorker(QThread):
    """The lit display's OpenGL thread (see the module doc)."""

    #: a pass finished (LitFrame)
    frame = Signal(object)
    #: the worker failed (its message); it has stopped
    failed = Signal(str)

    def __init__(self) -> None:
        super().__init__()
        self._offscreen = _offscreen_context()  # created here: the surface needs the GUI thread
        self._offscreen.done_current()
        self._offscreen.context.moveToThread(self)
        self._cond = threading.Condition()
        self._snapshot: Document | None = None
        self._keys: set[TileKey] | None = set()  # the tiles it changed (None: all)
        self._light: tuple[int, tuple[float, float, float]] | None = None
        self._lighting: tuple[Environment, float] | None = None
        self._stopping = False
        self.s_per_pixel = INITIAL_S_PER_PIXEL
        #: the latest material uploads: ("all" or "tiles", bytes sent)
        self.uploads: deque[tuple[str, int]] = deque(maxlen=32)
        _LIVE.add(self)
        app = QCoreApplication.instance()
        if app is not None and len(_LIVE) == 1:
            app.aboutToQuit.connect(_stop_all)

    # -- requests (GUI thread) ----------------------------------------------

    def set_document(self, snapshot: Document, keys: set[TileKey] | None) -> None:
        """The material is now ``snapshot``; only ``keys`` changed (None: all of it)."""
        with self._cond:
            self._keys = None if keys is None or self._keys is None else self._keys | keys
            self._snapshot = snapshot
            self._cond.notify()

    def set_lighting(self, environment: Environment, exposure_stops: float) -> None:
        """Light with ``environment`` at ``exposure_stops`` (drawn at the next request)."""
        with self._cond:
            self._lighting = (environment, exposure_stops)
            self._cond.notify()

    def request(self, generation: int, light: tuple[float, float, float]) -> None:
        """Draw ``light`` (replaces a request not yet started)."""
        with self._cond:
            self._light = (generation, light)
            self._cond.notify()

    def stop(self, timeout_s: float = 10.0) -> None:
        """End the thread (a pass under way finishes its band first)."""
        with self._cond:
            self._stopping = True
            self._cond.notify()
        self.wait(int(timeout_s * 1000))
        _LIVE.discard(self)

    # -- the thread ----------------------------------------------------------

    def run(self) -> None:  # noqa: D102 - QThread's entry point
        from ..viewport.gl.swatch import SwatchRenderer

        yield_to_the_gui_thread()

        if not self._offscreen.make_current():
            self.failed.emit("cannot make the lit display's OpenGL context current")
            return
        renderer = None
        uploaded = False
        try:
            renderer = SwatchRenderer(tilt_deg=lit_scene.TILT_DEG)
            light = renderer.lighting
            light.samples = lit_scene.SAMPLES
            light.environment_scale = lit_scene.ENVIRONMENT_SCALE
            light.background = lit_scene.BACKGROUND
            while True:
                with self._cond:
                    while (
                        not self._stopping
                        and self._snapshot is None
                        and self._lighting is None
                        and (self._light is None or not uploaded)
                    ):
                        self._cond.wait()
                    if self._stopping:
                        return
                    snapshot, keys = self._snapshot, self._keys
                    self._snapshot, self._keys = None, set()
                    request, self._light = self._light, None
                    lighting, self._lighting = self._lighting, None
                if lighting is not None:
                    renderer.set_environment(lighting[0])
                    light.exposure = lighting[1]
                if snapshot is not None:
                    if keys is None or not uploaded:
                        self.uploads.append(("all", renderer.set_document(snapshot)))
                    elif keys:
                        self.uploads.append(("tiles", renderer.update_tiles(snapshot, keys)))
                    uploaded = True
                if request is not None:
                    self._render(renderer, *request)
        except Exception as exc:  # reported on the GUI thread; the thread ends
            self.failed.emit(f"{type(exc).__name__}: {exc}")
        finally:
            if renderer is not None:
                renderer.delete()
            self._offscreen.done_current()

    def _newer(self) -> bool:
        with self._cond:
            return (
                self._stopping
                or self._light is not None
                or self._snapshot is not None
                or self._lighting is not None
            )

    def _render(self, renderer, generation: int, direction: tuple[float, float, float]) -> None:
        renderer.lighting.lights = lit_scene.lights(direction)
        width, height = renderer.size(0)
        for level in [*self._coarse_levels(width * height), 0]:
            seconds = self._draw_in_bands(renderer, level)
            if seconds is None:
                return  # the light moved on: this picture would be out of date
            self._emit(renderer, generation, level, seconds)
            if level and self._newer():
                return

    def _draw_in_bands(self, renderer, level: int) -> float | None:
        """Draw ``level`` in bands of about :data:`BAND_BUDGET_S`; its seconds, or None when
        a newer request came between two bands.

        Every pass is banded, the coarse ones too: llvmpipe rasterizes the scenes of all
        the process's contexts on one set of threads, so while a band draws here the
        window's own frames on the GUI thread wait for it (a whole 0.5 s coarse pass
        stalled the event loop for as long). The first band is a few rows: the speed
        measured before may not hold (a new environment or material, the 3D view drawing
        on the same threads), and that band measures it."""
        width, height = renderer.size(level)
        began = time.perf_counter()
        top = 0
        while top < height:
            if top > 0 and self._newer():
                return None
            band = PROBE_ROWS if top == 0 else int(BAND_BUDGET_S / (self.s_per_pixel * width))
            bottom = min(top + max(PROBE_ROWS, band), height)
            self._timed(renderer, level, (top, bottom))
            top = bottom
        return time.perf_counter() - began

    def _coarse_levels(self, pixels: int) -> list[int]:
        """The coarse passes to show before the full one, coarsest first: the finest level
        predicted to draw within each of :data:`COARSE_BUDGETS_S` (none where the full pass
        itself does)."""
        levels: list[int] = []
        for budget in COARSE_BUDGETS_S:
            ratio = pixels * self.s_per_pixel / budget
            level = 0 if ratio <= 1.0 else math.ceil(0.5 * math.log2(ratio))
            if level > 0 and level not in levels:
                levels.append(level)
        return levels

    def _timed(self, renderer, level: int, rows: tuple[int, int] | None = None) -> float:
        width, height = renderer.size(level)
        pixels = width * (height if rows is None else rows[1] - rows[0])
        began = time.perf_counter()
        renderer.draw(level, rows)
        seconds = time.perf_counter() - began
        self.s_per_pixel = follow_speed(self.s_per_pixel, seconds / max(pixels, 1))
        return seconds

    def _emit(self, renderer, generation: int, level: int, seconds: float) -> None:
        self.frame.emit(LitFrame(generation, renderer.read(level), level, seconds))
