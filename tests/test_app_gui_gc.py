"""While an editor window is open, cycles are collected on the GUI thread, never on a worker.

Truth: ``gc.callbacks`` reports every collection with the thread it runs on.
Workers allocate enough cyclic garbage to pass the first generation's threshold
many times over (which, with automatic collection, collects on the worker);
with a window open none of those collections may run on a worker, and the
garbage is collected once the GUI thread's event loop turns.
"""

from __future__ import annotations

import gc
import threading
import weakref

import pytest

pytest.importorskip("pytestqt")

from matshop.app.main_window import MainWindow  # noqa: E402


class _Node:
    def __init__(self) -> None:
        self.me = self  # a cycle: only the cyclic collector frees it


def _collections_by_thread():
    seen: list[int] = []

    def record(phase, info) -> None:
        if phase == "start":
            seen.append(threading.get_ident())

    gc.callbacks.append(record)
    return seen, lambda: gc.callbacks.remove(record)


def _make_garbage_on_a_worker(count: int) -> weakref.ref:
    last: list[weakref.ref] = []

    def work() -> None:
        for _ in range(count):
            node = _Node()
        last.append(weakref.ref(node))

    worker = threading.Thread(target=work)
    worker.start()
    worker.join()
    return last[0]


def test_workers_collect_cycles_when_no_window_is_open() -> None:
    """The control: without a window, the worker's allocations do trigger collections there."""
    if not gc.isenabled():
        pytest.skip("automatic collection is off in this process")
    seen, stop = _collections_by_thread()
    try:
        _make_garbage_on_a_worker(50 * gc.get_threshold()[0])
    finally:
        stop()
    assert any(ident != threading.main_thread().ident for ident in seen)


def test_with_a_window_open_cycles_are_collected_on_the_gui_thread_only(qtbot) -> None:
    was_enabled = gc.isenabled()
    window = MainWindow()  # deleted here, not by pytest-qt: its deletion is under test
    seen, stop = _collections_by_thread()
    try:
        assert not gc.isenabled()
        last = _make_garbage_on_a_worker(50 * gc.get_threshold()[0])
        assert last() is not None  # nothing collected it yet
        assert seen == []
        qtbot.waitUntil(lambda: last() is None, timeout=5000)
    finally:
        stop()
        window.close()
        window.deleteLater()
    assert seen and set(seen) == {threading.main_thread().ident}
    qtbot.waitUntil(lambda: gc.isenabled() == was_enabled, timeout=5000)
