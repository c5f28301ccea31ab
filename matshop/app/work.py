"""Long file work (open, save, export) on a worker thread while the window stays live.

:func:`run_off_ui` runs a function on Qt's thread pool and waits for it in a
local event loop, so callers keep a plain "call, get the result" shape (menu
actions, scripts and tests alike) while the window goes on repainting and
its timers go on firing: nothing freezes. A window-modal progress dialog
(shown only if the work lasts) says what is happening, shows the progress
the engine reports through its ``progress(done, total)`` callbacks and, when
the work can stop cleanly, offers Cancel; being modal it also keeps the user
from changing the document the worker is reading.

The function must touch nothing the GUI thread changes meanwhile: callers
hand it new objects (a path) or a :meth:`Document.snapshot`.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any, TypeVar

from PySide6.QtCore import QEventLoop, QObject, Qt, QThreadPool, QTimer, Signal
from PySide6.QtWidgets import QProgressDialog, QWidget

T = TypeVar("T")

#: the dialog appears only for work that lasts longer than this
SHOW_AFTER_MS = 400
#: progress reports closer together than this are merged (signals cost GUI time)
_REPORT_EVERY_S = 0.05


class Cancelled(Exception):
    """The user pressed Cancel; the work stopped at its next progress report."""


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

    def progress(self, done: int, total: int) -> None:
        """The engine's ``ProgressCallback``: called on the worker thread."""
        if self.cancelled.is_set():
            raise Cancelled
        now = time.perf_counter()
        if now - self._last >= _REPORT_EVERY_S or done >= total:
            self._last = now
            self._relay.progress.emit(int(done), max(int(total), 1))


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
    meanwhile; the dialog blocks input to ``parent``'s window.
    """
    work = Work()
    loop = QEventLoop()
    dialog = QProgressDialog(label, "Cancel" if cancellable else "", 0, 0, parent)
    dialog.setWindowTitle("matshop")
    dialog.setWindowModality(Qt.WindowModality.WindowModal)
    dialog.setMinimumDuration(SHOW_AFTER_MS)
    dialog.setAutoReset(False)
    dialog.setAutoClose(False)
    if not cancellable:
        dialog.setCancelButton(None)
    dialog.canceled.connect(work.cancelled.set)
    dialog.setValue(0)  # starts the minimum-duration clock

    def report(done: int, total: int) -> None:
        dialog.setMaximum(total)
        dialog.setValue(min(done, total))

    work._relay.progress.connect(report)
    work._relay.done.connect(loop.quit, Qt.ConnectionType.QueuedConnection)

    def run() -> None:  # on the worker thread
        start = time.perf_counter()
        try:
            work.result = fn(work)
        except BaseException as exc:  # re-raised on the GUI thread
            work.error = exc
        work.seconds = time.perf_counter() - start
        work._relay.done.emit()

    (pool or QThreadPool.globalInstance()).start(run)
    # the dialog's own timer shows it after SHOW_AFTER_MS; keep it moving meanwhile
    pulse = QTimer()
    pulse.setInterval(100)
    pulse.timeout.connect(lambda: dialog.setValue(dialog.value()))
    pulse.start()
    loop.exec()
    pulse.stop()
    shown = dialog.isVisible()
    dialog.close()
    dialog.deleteLater()
    if shown and parent is not None:  # without a window manager nobody gives focus back
        parent.window().activateWindow()
    if work.error is not None:
        raise work.error
    return work.result
