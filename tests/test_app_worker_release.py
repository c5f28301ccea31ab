"""What a worker task holds is released on the GUI thread, never on the worker.

A Qt object released on a worker thread disconnects its signals there, taking
Qt's connection lock and then Python's, while the GUI thread, holding Python's
lock, connects a signal and waits for Qt's: the editor froze so (seen as a hung
test when a window closed while its background flatten ran). The truth here is
the thread a finalizer runs on, read from the interpreter.
"""

from __future__ import annotations

import os
import sys
import threading
import time
import weakref

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import QObject, QThreadPool, Signal  # noqa: E402

from matshop.app.work import WORKER_NICENESS, start_worker  # noqa: E402


class _Holder(QObject):
    ping = Signal()

    def touch(self) -> None:
        self.ping.emit()


class _Plain:
    def touch(self) -> None:
        pass


def _finalized_on(qtbot, start, make) -> int:
    """Start a task holding a fresh object, drop the GUI's reference at once, and
    return the id of the thread its last reference was dropped on."""
    released: list[int] = []
    holder = make()
    weakref.finalize(holder, lambda: released.append(threading.get_ident()))
    ran = threading.Event()

    def task(held=holder) -> None:
        held.touch()
        ran.set()
        time.sleep(0.05)  # the GUI side lets go first, as a closing window does

    start(QThreadPool.globalInstance(), task)
    del task, holder
    qtbot.waitUntil(ran.is_set, timeout=5000)
    qtbot.waitUntil(lambda: bool(released), timeout=5000)
    return released[0]


def test_a_plain_pool_start_releases_on_the_worker(qtbot) -> None:
    # the hazard itself (shown with a plain object: a QObject could hang this test),
    # so the next test is known to be able to fail
    on = _finalized_on(qtbot, lambda pool, task: pool.start(task), _Plain)
    assert on != threading.get_ident()


def test_start_worker_releases_on_the_gui_thread(qtbot) -> None:
    assert _finalized_on(qtbot, start_worker, _Plain) == threading.get_ident()
    assert _finalized_on(qtbot, start_worker, _Holder) == threading.get_ident()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="per-thread niceness is Linux's")
def test_a_worker_runs_below_the_gui_thread(qtbot) -> None:
    """The kernel's own view of each thread's niceness: every task's thread is at
    least WORKER_NICENESS, so on two cores the GUI thread (and the GL rasterizer's
    threads it waits for) get the CPU first; the GUI thread itself is untouched."""
    gui_before = os.getpriority(os.PRIO_PROCESS, threading.get_native_id())
    seen: list[int] = []
    pool = QThreadPool()
    for _ in range(3):
        start_worker(
            pool, lambda: seen.append(os.getpriority(os.PRIO_PROCESS, threading.get_native_id()))
        )
    qtbot.waitUntil(lambda: len(seen) == 3, timeout=10_000)
    pool.waitForDone()
    assert min(seen) >= WORKER_NICENESS
    assert os.getpriority(os.PRIO_PROCESS, threading.get_native_id()) == gui_before
