"""Suite-wide pytest hooks."""

from __future__ import annotations

import gc
import os
import subprocess
import sys
from pathlib import Path

import pytest
from worker_display import start_own_display

# each xdist worker of a parallel run draws on an X server of its own (see worker_display)
_OWN_DISPLAY = start_own_display()

# Qt widgets need a display; without one (a plain `pytest` outside Xvfb) the widget tests
# still run offscreen, and the GL tests, which offscreen cannot serve, skip themselves.
# Set here, before any test module imports PySide6.
if not os.environ.get("DISPLAY"):
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

_exit_status = 0

# PySide6 6.12 on CPython 3.11: every QApplication.processEvents() and QTest.qWait() call
# drops one reference to None that it does not own (measured: sys.getrefcount(None) falls
# by exactly 1 per call); after some 10^5 calls in one process None is "deallocated" and
# the interpreter aborts ("none_dealloc"), even in a bare loop over an empty widget. The
# suite's waiting loops make that many calls, so hold spare references for the session.
_SPARE_NONE_REFERENCES = [None] * 2_000_000


@pytest.fixture(autouse=True)
def _delete_closed_widgets(request):
    """Delete the widgets pytest-qt closed, before the next test.

    pytest-qt closes a test's widgets and calls ``deleteLater()`` outside any event loop,
    so Qt deletes them only when some later test spins one; until then each window holds
    its document, caches and GL textures (measured: ~0.7 GB per 2K window, the suite's
    process grew to 7.5 GB). Only after a test that had ``qtbot``: pytest-qt closes the
    widgets given to it, and the full collection costs up to half a second once the
    suite's heap is large (after every test, the teardowns were 878 s of a 1490 s suite).
    """
    yield
    if "qtbot" not in request.fixturenames or "PySide6" not in sys.modules:
        return
    from PySide6.QtCore import QCoreApplication, QEvent

    if QCoreApplication.instance() is not None:
        QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
        gc.collect()


@pytest.fixture(scope="module")
def gl_context(request):
    """An offscreen OpenGL 3.3 core context for the GL test modules (skips when none)."""
    from matshop.viewport.gl.context import GLUnavailable, OffscreenContext

    request.getfixturevalue("qapp")
    try:
        return OffscreenContext()
    except GLUnavailable as exc:
        pytest.skip(f"no OpenGL 3.3 core context can be created here: {exc}")


@pytest.fixture(scope="session")
def warm_kernels() -> None:
    """numba's on-disk cache holds every kernel: ``matshop warm-up --if-cold`` run once, in a
    child (as ``make test`` and the editor's launch run it), so a stall test measures the
    editor's own work and not first-use compiles (tests/test_first_use.py covers those)."""
    subprocess.run(
        [sys.executable, "-m", "matshop", "warm-up", "--if-cold"],
        cwd=Path(__file__).resolve().parent.parent,
        check=True,
        capture_output=True,
        timeout=1500,
    )


def pytest_addoption(parser) -> None:
    parser.addoption(
        "--long",
        action="store_true",
        help="run the fuzzers long (examples x MATSHOP_FUZZ_FACTOR, default 50)",
    )


def pytest_configure(config) -> None:
    # before test modules are imported: their @settings read it (tests/fuzz_settings.py)
    if config.getoption("--long"):
        os.environ["MATSHOP_FUZZ_LONG"] = "1"


def pytest_runtest_setup(item) -> None:
    if not item.get_closest_marker("serial"):
        return
    # A `serial` test times the GUI thread: beside another test process its wall-gap bound
    # would be skipped (the load average reads high) and its CPU bound judged on shared
    # cores, so on several xdist workers it fails rather than pass weakened.
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    if workers > 1:
        pytest.fail(
            f"marked `serial`: it must not share the cores with {workers - 1} other "
            'worker(s); run it without -n and the rest with -m "not serial" (as `make test` does)',
            pytrace=False,
        )
    # It starts on a collected heap, as when every test's teardown collected: a full
    # collection of a long session's heap (up to half a second; by the interpreter, or by
    # the editor's GUI-thread collector, app/gui_gc.py) is then unlikely to fall into its
    # timing. An editor has no such heap.
    gc.collect()


def pytest_sessionfinish(session, exitstatus) -> None:
    global _exit_status
    _exit_status = int(exitstatus)


def pytest_unconfigure(config) -> None:
    if _OWN_DISPLAY is not None:  # this worker's X server: ended and reaped here
        _OWN_DISPLAY.terminate()
        _OWN_DISPLAY.wait(timeout=30)
    # After a long Qt session (dozens of windows, thousands of signal
    # connections), PySide6 6.12 on CPython 3.11 can abort in the interpreter's
    # final garbage collection ("bool_dealloc: deallocating True or False", a
    # refcount error inside the extension; PySide's dynamic-slot cleanup drops a
    # reference it does not own, see Nuitka issue #4019). Every test has passed
    # or failed and been reported by now, so leave without that collection and
    # keep pytest's own exit status.
    if "PySide6" in sys.modules:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_exit_status)
