"""Long file work (open, save, export) on a worker thread while the window stays live.

:func:`run_off_ui` runs a function on Qt's thread pool and waits for it in a
local event loop, so callers keep a plain "call, get the result" shape (menu
actions, scripts and tests alike) while the window goes on repainting and
its timers go on firing: nothing freezes. A progress panel over the window
(shown only if the work lasts) says what is happening, shows the progress
the engine reports through its ``progress(done, total)`` callbacks and, when
the work can stop cleanly, offers Cancel. Input to the window (shortcuts
included) is held meanwhile, so the user cannot change the document the
worker is reading. The panel is a child widget, not a dialog window: the
main window keeps its activation and shortcuts, which nothing gives back
without a window manager.

The function must touch nothing the GUI thread changes meanwhile: callers
hand it new objects (a path) or a :meth:`Document.snapshot`.

Every task goes to the pool through :func:`start_worker`, which makes sure the
worker thread never drops the last reference to what the task holds (Qt objects
among them): a Qt object released on a worker disconnects its signals there,
which takes Qt's connection lock and then waits for Python's; the GUI thread,
holding Python's lock while it connects a signal, waits for Qt's: the editor
froze that way when a window closed while its background flatten ran.
"""

from __future__ import annotations

import contextlib
import os
import queue
import sys
import threading
import time
from collections.abc import Callable
from typing import Any, TypeVar

from PySide6.QtCore import QEvent, QEventLoop, QObject, Qt, QThreadPool, QTimer, Signal
from PySide6.QtWidgets import (
    QApplication,
    QFrame,
    QLabel,
    QProgressBar,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

T = TypeVar("T")

#: the progress panel appears only for work that lasts longer than this
SHOW_AFTER_MS = 400
#: progress reports closer together than this are merged (signals cost GUI time)
_REPORT_EVERY_S = 0.05


class _Reaper(QObject):
    """Releases on the GUI thread what finished worker tasks held."""

    def __init__(self) -> None:
        super().__init__()
        #: tasks handed back by their workers (a plain queue: no Qt on the worker side)
        self.finished: queue.SimpleQueue[Callable[[], None]] = queue.SimpleQueue()
        self.in_flight = 0
        self.timer = QTimer(self)
        self.timer.setInterval(100)
        self.timer.timeout.connect(self.drain)

    def drain(self) -> None:
        while True:
            try:
                task = self.finished.get_nowait()
            except queue.Empty:
                break
            self.in_flight -= 1
            del task  # the last reference, dropped here on the GUI thread
        if self.in_flight == 0:
            self.timer.stop()


_reaper: _Reaper | None = None

#: the niceness of worker threads: CPU time goes to the GUI thread (and the GL
#: rasterizer's threads it waits for) first. Measured on 2 cores under Xvfb while
#: a 4096 x 2048 HDR loaded (tests/test_app_lighting.py, memory made cold first):
#: at the workers' default priority the event loop stalled 279-488 ms in 3 of 13
#: runs (348 ms in a CI run); at this niceness at most 113 ms in 8 runs
WORKER_NICENESS = 10


def yield_to_the_gui_thread() -> None:
    """Lower this worker thread's priority to :data:`WORKER_NICENESS` if it is above
    it (Linux: niceness is per thread, and the threads it starts, numba's OpenMP team
    among them, inherit it; two system calls, nothing beside a task's work)."""
    if not sys.platform.startswith("linux"):
        return
    thread = threading.get_native_id()
    with contextlib.suppress(OSError):
        now = os.getpriority(os.PRIO_PROCESS, thread)
        if now < WORKER_NICENESS:
            os.setpriority(os.PRIO_PROCESS, thread, WORKER_NICENESS)


def start_worker(pool: QThreadPool, task: Callable[[], None]) -> None:
    """Run ``task()`` on ``pool``; what it holds is released on the GUI thread, not the worker's.

    Call from the GUI thread. The worker hands the task back through a plain queue
    when it returns; a timer on the GUI thread drops it from there.
    """
    global _reaper
    if _reaper is None:
        _reaper = _Reaper()
    reaper = _reaper
    held = [task]
    handback = reaper.finished

    def run() -> None:  # on the worker thread; holds no reference once it returns
        try:
            yield_to_the_gui_thread()
            held[-1]()
        finally:
            handback.put(held.pop())

    reaper.in_flight += 1
    reaper.timer.start()
    pool.start(run)


class Cancelled(Exception):
    """The user pressed Cancel; the work stopped at its next progress report or checkpoint."""


class _Relay(QObject):
    """Lives on the GUI thread; the worker's emits are queued over."""

    progress = Signal(int, int)
    done = Signal()


class Work:
    """What the worker reports back: its result or exception, and the cancel flag."""

    def __init__(self) -> None:
        self.result: Any = None
        self.error: BaseException | None = None
        self.cancelled = threading.Event()
        self.seconds = 0.0
        self._relay = _Relay()
        self._last = 0.0

    def checkpoint(self) -> None:
        """Stop here if the user pressed Cancel (between steps that report no progress)."""
        if self.cancelled.is_set():
            raise Cancelled

    def progress(self, done: int, total: int) -> None:
        """The engine's ``ProgressCallback``: called on the worker thread."""
        if self.cancelled.is_set():
            raise Cancelled
        now = time.perf_counter()
        if now - self._last >= _REPORT_EVERY_S or done >= total:
            self._last = now
            self._relay.progress.emit(int(done), max(int(total), 1))


class _Panel(QFrame):
    """What is being done, a progress bar and (maybe) Cancel, centred over the window."""

    def __init__(self, window: QWidget, label: str, cancellable: bool, work: Work) -> None:
        super().__init__(window)
        self.setObjectName("progressPanel")
        self.setFrameShape(QFrame.Shape.StyledPanel)
        self.setAutoFillBackground(True)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(18, 14, 18, 14)
        self.label = QLabel(label)
        self.bar = QProgressBar()
        self.bar.setRange(0, 0)  # busy until the work reports a total
        self.bar.setTextVisible(False)
        self.bar.setMinimumWidth(260)
        layout.addWidget(self.label)
        layout.addWidget(self.bar)
        self.cancel: QPushButton | None = None
        if cancellable:
            self.cancel = QPushButton("Cancel")
            self.cancel.clicked.connect(work.cancelled.set)
            self.cancel.clicked.connect(lambda: self.label.setText(f"{label} (cancelling)"))
            layout.addWidget(self.cancel)
        self.adjustSize()
        self.hide()

    def appear(self) -> None:
        window = self.parentWidget()
        self.move((window.width() - self.width()) // 2, (window.height() - self.height()) // 3)
        self.show()
        self.raise_()

    def report(self, done: int, total: int) -> None:
        self.bar.setRange(0, total)
        self.bar.setValue(min(done, total))


class _HoldInput(QObject):
    """Swallows input to ``window`` (but not to the panel's Cancel) while work runs."""

    _INPUT = {
        QEvent.Type.MouseButtonPress,
        QEvent.Type.MouseButtonRelease,
        QEvent.Type.MouseButtonDblClick,
        QEvent.Type.Wheel,
        QEvent.Type.KeyPress,
        QEvent.Type.KeyRelease,
        QEvent.Type.Shortcut,
        QEvent.Type.ShortcutOverride,
        QEvent.Type.TabletPress,
        QEvent.Type.TabletRelease,
        QEvent.Type.Drop,
        QEvent.Type.Close,
    }

    def __init__(self, window: QWidget, allowed: QWidget | None) -> None:
        super().__init__()
        self.window = window
        self.allowed = allowed

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt override
        if event.type() == QEvent.Type.Shortcut:  # delivered to the QAction, not a widget
            event.ignore()
            return True
        if event.type() not in self._INPUT or not isinstance(watched, QWidget):
            return False
        if self.allowed is not None and watched is self.allowed:
            return False
        if watched.window() is self.window:
            event.ignore()
            return True
        return False


def run_off_ui(
    parent: QWidget | None,
    label: str,
    fn: Callable[[Work], T],
    *,
    cancellable: bool = False,
    pool: QThreadPool | None = None,
) -> T:
    """Run ``fn(work)`` on a worker thread; return its result (or raise its exception).

    ``fn`` may call ``work.progress(done, total)`` (raises :class:`Cancelled`
    after the user pressed Cancel, when ``cancellable``). The event loop runs
    meanwhile; input to ``parent``'s window is held back.
    """
    work = Work()
    loop = QEventLoop()
    window = None if parent is None else parent.window()
    panel = None if window is None else _Panel(window, label, cancellable, work)
    hold = None
    if window is not None and panel is not None:
        hold = _HoldInput(window, panel.cancel)
        QApplication.instance().installEventFilter(hold)
        work._relay.progress.connect(panel.report)
    appear = QTimer()
    appear.setSingleShot(True)
    appear.setInterval(SHOW_AFTER_MS)
    if panel is not None:
        appear.timeout.connect(panel.appear)
    work._relay.done.connect(loop.quit, Qt.ConnectionType.QueuedConnection)

    def run() -> None:  # on the worker thread
        start = time.perf_counter()
        try:
            work.result = fn(work)
        except BaseException as exc:  # re-raised on the GUI thread
            work.error = exc
        work.seconds = time.perf_counter() - start
        work._relay.done.emit()

    appear.start()
    start_worker(pool or QThreadPool.globalInstance(), run)
    try:
        loop.exec()
    finally:
        appear.stop()
        if hold is not None:
            QApplication.instance().removeEventFilter(hold)
        if panel is not None:
            panel.hide()
            panel.deleteLater()
    if work.error is not None:
        raise work.error
    if work.cancelled.is_set():  # finished a step that could not stop: drop its result
        raise Cancelled
    return work.result
