"""Whole-image filters (bilateral, detail) and generated masks flattened on a worker thread.

The design, in one paragraph: the GUI thread owns the live document and
keeps editing it; the worker only ever flattens a *snapshot* (see
:meth:`Document.snapshot`), an independent document sharing nothing mutable with the
live one. After every change of the live document, :meth:`Document.stale_global_layers` says
whether flattening it would recompute a whole-image filter. If so the
document is *pending*: the canvas holds its last picture and nothing on the
GUI thread reads the flatten (readers ask :attr:`BackgroundFlatten.ready`),
and a worker flattens a snapshot. When it finishes and the live document is
unchanged since the snapshot (a generation counter bumped by every document
event), its caches are adopted and the canvas catches up; if the document
changed meanwhile (a slider tick, an undo), the result is dropped and the
latest state is flattened next: latest wins, one worker at a time.

A reader that forgets to ask only costs a freeze (it flattens synchronously
on the GUI thread), never a race: the threads share no mutable object.
Snapshots are not taken during a stroke (its working tiles are written in
place); the stroke's end starts the worker.

Cancel makes the document cheap to flatten again, as one undo step: if the
last step added the slow filter, it is undone; otherwise the slow filters
are hidden (undo shows them again). The numba kernel under way cannot be
interrupted: it finishes in the background and its result is dropped.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

from PySide6.QtCore import QObject, QThreadPool, QTimer, Signal

from ..layers import AddLayer, CompoundEdit, Document, SetProperty
from .session import DocumentSession
from .work import start_worker


@dataclass
class _Job:
    """One flatten of a snapshot on the worker."""

    generation: int
    doc: Document
    label: str
    started: float
    error: BaseException | None = None
    seconds: float = 0.0


class _Relay(QObject):
    """Lives on the GUI thread; the worker emits ``done`` and Qt queues it over."""

    done = Signal(object)


class BackgroundFlatten(QObject):
    """Keeps the session's document flattened by a worker when that is slow."""

    #: True while the flatten is pending (the GUI must not read it), False when ready
    busyChanged = Signal(bool)
    #: (what is computing, seconds so far) about every 100 ms while pending
    progress = Signal(str, float)
    message = Signal(str)

    def __init__(
        self,
        session: DocumentSession,
        tool_busy: Callable[[], bool] = lambda: False,
        pool: QThreadPool | None = None,
    ) -> None:
        super().__init__()
        self.session = session
        self.tool_busy = tool_busy
        self.pool = pool or QThreadPool.globalInstance()
        self.generation = 0
        self.pending = False
        self.job: _Job | None = None
        #: seconds of the last adopted flatten (status bar, benchmarks)
        self.last_seconds = 0.0
        self._doc: Document | None = None
        self._relay = _Relay()
        self._relay.done.connect(self._finished)
        self._start_timer = QTimer(self)
        self._start_timer.setSingleShot(True)
        self._start_timer.setInterval(0)
        self._start_timer.timeout.connect(self._start)
        self._ticker = QTimer(self)
        self._ticker.setInterval(100)
        self._ticker.timeout.connect(self._tick)
        #: names of the slow filters being computed (the status bar shows them)
        self.label = ""
        self._since = 0.0
        session.documentReplaced.connect(self._document_replaced)
        session.historyChanged.connect(self._schedule)  # a stroke ended: snapshots allowed
        self._document_replaced()

    @property
    def ready(self) -> bool:
        """Reading the flatten on the GUI thread is cheap now."""
        return not self.pending

    # -- watching the document ------------------------------------------------------

    def _document_replaced(self) -> None:
        if self._doc is not None:
            for signal in self._signals(self._doc):
                signal.disconnect(self._changed)
        self._doc = self.session.doc
        if self._doc is not None:
            for signal in self._signals(self._doc):
                signal.connect(self._changed)
        self._changed()

    @staticmethod
    def _signals(doc: Document):
        events = doc.events
        return (events.dirty, events.layers, events.layer, events.content)

    def _changed(self, *_args) -> None:
        """Any change of the live document: older snapshots are stale; is it slow now?"""
        self.generation += 1
        doc = self.session.doc
        slow = [] if doc is None else doc.stale_global_layers()
        self._set_pending(bool(slow))
        if slow:
            self.label = ", ".join(layer.name for layer in slow)
            self._schedule()

    def _set_pending(self, pending: bool) -> None:
        if pending == self.pending:
            return
        self.pending = pending
        if pending:
            self._since = time.perf_counter()
            self._ticker.start()
        else:
            self._ticker.stop()
        self.busyChanged.emit(pending)

    def _tick(self) -> None:
        self.progress.emit(self.label, time.perf_counter() - self._since)

    # -- the worker ---------------------------------------------------------------------

    def _schedule(self) -> None:
        if self.pending and self.job is None:
            self._start_timer.start()

    def _start(self) -> None:
        doc = self.session.doc
        if not self.pending or self.job is not None or doc is None or self.tool_busy():
            return  # the stroke's end (historyChanged) schedules again
        job = _Job(self.generation, doc.snapshot(), self.label, time.perf_counter())
        self.job = job

        def run() -> None:  # on the worker thread: touches the snapshot only
            try:
                job.doc.update()
            except BaseException as exc:  # reported on the GUI thread
                job.error = exc
            job.seconds = time.perf_counter() - job.started
            self._relay.done.emit(job)

        start_worker(self.pool, run)

    def _finished(self, job: _Job) -> None:
        self.job = None
        doc = self.session.doc
        if job.error is not None:
            self.message.emit(f"{job.label}: {job.error}")
        if job.error is None and job.generation == self.generation and doc is not None:
            doc.adopt_caches(job.doc)
            self.last_seconds = job.seconds
            self.message.emit(f"{job.label} computed in {job.seconds:.1f} s")
            self._changed()  # now cached: not pending any more
        elif job.error is not None and job.generation == self.generation:
            self._set_pending(False)  # let the GUI's own flatten raise where it is shown
        else:
            self._schedule()  # the document moved on: flatten its latest state

    def wait(self, timeout_s: float = 30.0) -> bool:
        """Block (processing events) until the flatten is ready; for tests and scripts."""
        from PySide6.QtWidgets import QApplication

        end = time.perf_counter() + timeout_s
        while self.pending and time.perf_counter() < end:
            QApplication.processEvents()
            time.sleep(0.005)
        return not self.pending

    # -- cancel ----------------------------------------------------------------------------

    def cancel(self) -> None:
        """Make the document cheap to flatten again, as one undo step (see the module doc)."""
        doc, history = self.session.doc, self.session.history
        if doc is None or history is None or not self.pending:
            return
        slow = doc.stale_global_layers()
        top = self.session.last_edit
        if isinstance(top, AddLayer) and any(layer is top.layer for layer in slow):
            self.session.undo()
            self.message.emit(f"Cancelled: {top.layer.name} not added")
            return
        hide = [SetProperty(layer.id, "visible", False) for layer in slow]
        self.session.seal()
        self.session.push(CompoundEdit(hide, label="Cancel filter (hide)"))
        self.session.seal()
        names = ", ".join(layer.name for layer in slow)
        self.message.emit(f"Cancelled: {names} hidden (undo shows it again)")
