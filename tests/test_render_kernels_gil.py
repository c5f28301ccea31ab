"""The reference renderer's rasterizer releases the GIL: a worker rendering a mesh for the
lit display or a thumbnail does not freeze the editor's event loop.

A serial kernel compiled without ``nogil=True`` holds the GIL for its whole call, so the
GUI thread cannot run a single Python slot until it returns (``parallel=True`` kernels,
such as the environment lookups, already let go of it in their parallel loops: measured,
a ticking thread kept ticking through them). Measured here as the editor
would feel it: the kernel runs on a plain thread while a 10 ms heartbeat timer ticks on
the Qt event loop; the longest gap the process itself caused (wall gap less the time the
GUI thread waited for a CPU, :class:`~matshop.app.testing.Heartbeat`) must be a small
part of the call, which is made long enough (checked) that holding the GIL could not
hide.
"""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from matshop.app.testing import Heartbeat  # noqa: E402
from matshop.render.mesh import _rasterize  # noqa: E402

#: a call must last this long for a GIL held throughout to show beyond doubt
MIN_CALL_S = 0.3


def _gil_stall(call) -> tuple[float, float]:
    """(seconds ``call`` took on a worker thread, the event loop's longest own gap)."""
    took: list[float] = []

    def run() -> None:
        began = time.perf_counter()
        call()
        took.append(time.perf_counter() - began)

    worker = threading.Thread(target=run)
    beat = Heartbeat()
    beat.measure(worker.start, lambda: not worker.is_alive(), timeout_s=120.0)
    worker.join()
    return took[0], beat.own_stall


def _long_call_stall(make_call) -> tuple[float, float]:
    """:func:`_gil_stall` of the first call of doubling sizes that lasts MIN_CALL_S."""
    make_call(1 << 10)()  # loads (or compiles) the kernel first: not part of any timing
    size = 1 << 18
    while True:
        took, stall = _gil_stall(make_call(size))
        if took >= MIN_CALL_S or size >= 1 << 26:
            return took, stall
        size *= 2


@pytest.mark.serial
def test_rasterizing_a_mesh_on_a_worker_leaves_the_event_loop_running(qapp) -> None:
    rng = np.random.default_rng(1)

    def make_call(size: int):
        side = 1024
        count = size // 64  # triangles of ~ 200 texels each
        corners = rng.random((count, 2)) * (side - 20)
        sx = np.concatenate([corners[:, 0], corners[:, 0] + 20, corners[:, 0]])
        sy = np.concatenate([corners[:, 1], corners[:, 1], corners[:, 1] + 20])
        depth = 1.0 + rng.random(3 * count)
        tris = np.arange(3 * count).reshape(3, count).T.copy()
        zbuf = np.full((side, side), np.inf)  # each call gets fresh buffers (made once)
        tri_id = np.full((side, side), -1, dtype=np.int64)
        bary = np.zeros((side, side, 3))
        return lambda: _rasterize(sx, sy, depth, tris, side, side, zbuf, tri_id, bary)

    took, stall = _long_call_stall(make_call)
    print(
        f"rasterizing: {took:.2f} s on a worker, longest own event-loop gap {1000 * stall:.0f} ms"
    )
    assert took >= MIN_CALL_S, "the call is too short to tell"
    assert stall < min(0.25, took / 3)
