"""The editor's lighting: one :class:`~matshop.render.environment_choice.EnvironmentChoice`
shared by the 3D view and the canvas' lit display, as ``matshop render`` reads it.

:class:`LightingController` holds the current choice and its loaded
:class:`~matshop.render.environment.Environment`. A new choice is loaded on a
worker (:func:`.work.start_worker`): reading an 8K HDR and prefiltering it take
seconds, and the event loop must go on; the status bar shows the progress. Only
the latest request counts (choosing again while a file loads drops the older
one when it ends). The unturned environment of the current source is kept, so
a new turn only rolls and prefilters it again (on the worker too); a new
exposure needs no work at all. A file that cannot be used is one line in the
status bar and the previous lighting stays.

The choice is remembered in the editor's settings (the next session starts
with it) and saved in projects (:meth:`MainWindow.editor_state`).
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from PySide6.QtCore import QEventLoop, QObject, QThreadPool, QTimer, Signal

from ..errors import MatshopError
from ..render.environment import Environment
from ..render.environment_choice import EnvironmentChoice
from .settings import AppSettings
from .work import start_worker


@dataclass
class _Load:
    generation: int
    choice: EnvironmentChoice
    base: Environment | None  # the unturned environment, when already loaded
    environment: Environment | None = None
    error: BaseException | None = None
    seconds: float = 0.0


class _Relay(QObject):
    done = Signal(object)
    progress = Signal(int, int)


def _source_key(source: str) -> tuple[str, float]:
    """The cache key of a source: a file's path and modification time (edited: reloaded)."""
    try:
        return source, os.stat(source).st_mtime
    except OSError:
        return source, 0.0


class LightingController(QObject):
    """The lighting both views show (see the module doc)."""

    #: the lighting changed: (EnvironmentChoice, Environment)
    changed = Signal(object, object)
    #: a one-line message for the status bar
    message = Signal(str)
    #: loading started (True) or ended (False)
    busyChanged = Signal(bool)
    #: a choice could not be used (its one line); the current one stays
    failed = Signal(str)

    def __init__(self, settings: AppSettings | None = None, pool: QThreadPool | None = None):
        super().__init__()
        self.settings = settings
        self.pool = pool or QThreadPool.globalInstance()
        self.choice = EnvironmentChoice()
        self.environment: Environment | None = None
        #: what is being loaded (None: nothing)
        self.pending: EnvironmentChoice | None = None
        self.generation = 0
        self.last_seconds = 0.0
        self._base: tuple[tuple[str, float], Environment] | None = None
        self._relay = _Relay()
        self._relay.done.connect(self._finished)
        self._relay.progress.connect(self._progress)

    # -- choosing ------------------------------------------------------------

    def choose(self, choice: EnvironmentChoice) -> None:
        """Light with ``choice`` once it is loaded (on a worker)."""
        self.generation += 1
        same_map = (choice.source, choice.rotation_deg) == (
            self.choice.source,
            self.choice.rotation_deg,
        )
        exposure_only = same_map and self.environment is not None and self.pending is None
        if exposure_only:  # the same map: the views only change a uniform
            self._apply(choice, self.environment)
            return
        key = _source_key(choice.source)
        base = self._base[1] if self._base is not None and self._base[0] == key else None
        job = _Load(self.generation, choice, base)
        if self.pending is None:
            self.busyChanged.emit(True)
        self.pending = choice
        relay = self._relay

        def progress(done: int, total: int) -> None:
            relay.progress.emit(done, total)

        def run() -> None:  # worker thread: only the job's own objects
            began = time.perf_counter()
            try:
                if job.base is None:
                    job.base = choice.load_base(progress)
                job.environment = choice.turn(job.base)
            except BaseException as exc:  # reported on the GUI thread
                job.error = exc
            job.seconds = time.perf_counter() - began
            try:
                relay.done.emit(job)
            except RuntimeError:  # the window went away meanwhile
                pass

        start_worker(self.pool, run)

    def choose_source(self, source: str | os.PathLike[str]) -> bool:
        """A preset name or an .hdr/.exr path, keeping the turn and exposure; False (and the
        reason in the status bar) when it cannot be used."""
        return self._try(lambda: self.target().changed(source=os.fspath(source)))

    def set_rotation(self, degrees: float) -> bool:
        return self._try(lambda: self.target().changed(rotation_deg=degrees))

    def set_exposure(self, stops: float) -> bool:
        return self._try(lambda: self.target().changed(exposure_stops=stops))

    def restore(self, data: Any) -> bool:
        """A choice saved by :meth:`EnvironmentChoice.to_json` (settings, a project)."""
        return self._try(lambda: EnvironmentChoice.from_json(data))

    def target(self) -> EnvironmentChoice:
        """The choice being loaded, else the current one: what a further change starts from."""
        return self.pending or self.choice

    def _try(self, make) -> bool:
        try:
            choice = make()
        except MatshopError as exc:
            self.message.emit(f"Lighting: {exc}")
            self.failed.emit(str(exc))
            return False
        self.choose(choice)
        return True

    # -- results (GUI thread) --------------------------------------------------

    def _progress(self, done: int, total: int) -> None:
        if self.pending is not None and self.pending.is_file:
            name = Path(self.pending.source).name
            self.message.emit(f"Loading the environment {name}… {100 * done // max(total, 1)}%")

    def _finished(self, job: _Load) -> None:
        if job.error is None:  # kept even when outdated: a newer turn of it reuses it
            self._base = (_source_key(job.choice.source), job.base)
        if job.generation != self.generation:
            return  # a newer choice is on its way
        self.pending = None
        self.busyChanged.emit(False)
        if job.error is not None:
            text = (
                str(job.error)
                if isinstance(job.error, MatshopError)
                else f"{job.choice.source}: {type(job.error).__name__}: "
                + " ".join(str(job.error).split())
            )
            self.message.emit(f"Lighting: {text}; still lit by {self.choice.label}")
            self.failed.emit(text)
            return
        self.last_seconds = job.seconds
        if job.choice.is_file:
            self.message.emit(f"Lit by {job.choice.label} ({job.seconds:.1f} s to load)")
        self._apply(job.choice, job.environment)

    def _apply(self, choice: EnvironmentChoice, environment: Environment) -> None:
        self.choice, self.environment = choice, environment
        if self.settings is not None:
            self.settings.save_lighting(choice.to_json())
        self.changed.emit(choice, environment)

    def wait(self, timeout_s: float = 60.0) -> bool:
        """Run the event loop until nothing is loading (tests and scripts)."""
        end = time.perf_counter() + timeout_s
        while self.pending is not None and time.perf_counter() < end:
            loop = QEventLoop()
            QTimer.singleShot(5, loop.quit)
            loop.exec()
        return self.pending is None
