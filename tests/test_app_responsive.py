"""The editor never freezes: while a 2K set opens, exports, saves and reopens in the real
window, a 10 ms heartbeat timer keeps firing; the longest gap between its ticks (an
event-loop stall) stays under 250 ms.

A stall is measured two ways: the wall-clock gap between ticks, and the CPU time the GUI
thread itself spent between them. The second is what a freeze is made of (work done on the
GUI thread) and does not grow when other processes share the cores, so it is always held
to 250 ms. The wall gap also counts time the OS gave to other processes: it is held to
250 ms only when the machine is not overloaded (load average below the core count), and
printed always.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")


from PySide6.QtCore import Qt, QTimer  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402
from PySide6.QtWidgets import QFrame  # noqa: E402

from matshop.app.testing import Heartbeat, shown_window  # noqa: E402
from matshop.app.work import SHOW_AFTER_MS  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CHESSBOARD = ROOT.parent / "shared" / "data" / "chessboard"
#: glTF's three maps (CONVENTIONS.md), in file-name order
GLTF_MAPS = ("baseColor", "normal", "occlusionRoughnessMetallic")
STALL_LIMIT_S = 0.25

pytestmark = pytest.mark.skipif(
    not CHESSBOARD.is_dir(), reason=f"the shared 2K set is absent: {CHESSBOARD}"
)


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    yield win
    win.prompts.save_answer = "discard"


def _drawn(win) -> Callable[[], bool]:
    return lambda: win.canvas.cache is not None and not win.canvas.cache.busy


@pytest.mark.serial
def test_opening_exporting_saving_and_reopening_a_2k_set_never_stalls(
    window, tmp_path, monkeypatch
):
    beat = Heartbeat()
    report = []
    # how long the window waited on the worker (the panel's promise is about that wait;
    # the drawing after it is incremental on the GUI thread and measured by the heartbeat)
    import matshop.app.files as files_module

    waits: list[float] = []
    real_run_off_ui = files_module.run_off_ui

    def timed_run_off_ui(*args, **kwargs):
        start = time.perf_counter()
        try:
            return real_run_off_ui(*args, **kwargs)
        finally:
            waits.append(time.perf_counter() - start)

    monkeypatch.setattr(files_module, "run_off_ui", timed_run_off_ui)

    def check(what: str, wall: float, cpu: float) -> None:
        noise = beat.idle(0.5)
        load = os.getloadavg()[0]
        report.append(
            f"{what}: longest stall {wall * 1000:.0f} ms wall (idle {noise * 1000:.0f} ms, "
            f"load {load:.1f}), {cpu * 1000:.0f} ms of GUI-thread CPU"
        )
        print(report[-1])
        assert cpu < STALL_LIMIT_S, report[-1]
        if load < (os.cpu_count() or 1):
            assert wall < STALL_LIMIT_S, report[-1]

    # a probe: is the progress panel up while the set opens?
    shown: list[bool] = []
    probe = QTimer()
    probe.setInterval(50)
    probe.timeout.connect(
        lambda: shown.append(
            any(panel.isVisible() for panel in window.findChildren(QFrame, "progressPanel"))
        )
    )
    probe.start()
    start = time.perf_counter()
    opened, wall, cpu = beat.measure(lambda: window.open_path(CHESSBOARD), _drawn(window))
    open_s = time.perf_counter() - start
    probe.stop()
    assert opened and window.session.doc.size == (2048, 2048)
    check("open 2K set", wall, cpu)
    waited_s = max(waits, default=0.0)
    assert any(shown) or waited_s < 2 * SHOW_AFTER_MS / 1000, (
        f"no progress shown while the window waited {waited_s:.2f} s on the worker "
        f"(open took {open_s:.2f} s in all)"
    )
    assert not any(panel.isVisible() for panel in window.findChildren(QFrame, "progressPanel"))

    for op in ("blur", "unsharp", "curves"):  # each filter layer computes off the GUI thread
        _, wall, cpu = beat.measure(
            lambda op=op: window.layer_commands.add_filter_layer(op),
            lambda: window.background.ready and _drawn(window)(),
        )
        check(f"add {op} layer", wall, cpu)
        window.session.undo()

    window.prompts.folder = tmp_path / "export"
    window.prompts.preset = "gltf"
    _, wall, cpu = beat.measure(window.files.export, _drawn(window))
    check("export glTF", wall, cpu)
    # what was written: glTF's files, the base colour the source JPEG's codes
    from oracle import file_codes

    written = sorted(p.name for p in (tmp_path / "export").iterdir())
    assert written == [f"chessboard_{m}.png" for m in GLTF_MAPS], written
    exported = file_codes(tmp_path / "export" / "chessboard_baseColor.png")
    source = file_codes(CHESSBOARD / "chessboard_base_color.jpg")
    assert np.abs(exported[..., :3] - source[..., :3]).max() <= 1

    project = tmp_path / "board.matshop"
    start = time.perf_counter()
    saved, wall, cpu = beat.measure(lambda: window.files.save_to(project), _drawn(window))
    save_s = time.perf_counter() - start
    assert saved
    check("save project", wall, cpu)
    before = window.session.doc.flatten_edit()

    window.session.set_document(None)
    start = time.perf_counter()
    reopened, wall, cpu = beat.measure(lambda: window.open_path(project), _drawn(window))
    reopen_s = time.perf_counter() - start
    assert reopened
    check("reopen project", wall, cpu)
    assert np.array_equal(window.session.doc.flatten_edit(), before)  # nothing lost
    print("\n".join(report) + f"\nsave {save_s:.2f} s, reopen {reopen_s:.2f} s")


def test_cancel_while_a_2k_set_opens_keeps_the_document_that_was_open(window, monkeypatch) -> None:
    """The progress panel's Cancel (clicked by a timer while the worker reads the set; the
    window's other input is held meanwhile, the button's is not):
    open_path returns False, the sample that was open stays, nothing else changed."""
    sample = ROOT / "resources" / "sample"
    assert window.open_path(sample)
    # the worker reads slowly (a big set on a slow disk), so the panel is up when the
    # click comes whatever the machine's speed; without it a quiet machine finishes first
    import matshop.app.files as files_module

    real_load = files_module.load_material

    def slow_load(*args, **kwargs):
        time.sleep(1.5)
        return real_load(*args, **kwargs)

    monkeypatch.setattr(files_module, "load_material", slow_load)
    doc = window.session.doc
    layers = len(doc.layers)
    pressed = []

    def press() -> None:
        panels = [p for p in window.findChildren(QFrame, "progressPanel") if p.isVisible()]
        if panels and panels[0].cancel is not None:
            # held: a new layer now would change the document the user sees
            new_layer = Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier
            QTest.keyClick(window.canvas, Qt.Key.Key_N, new_layer)
            QTest.mouseClick(panels[0].cancel, Qt.MouseButton.LeftButton)  # a real click
            pressed.append(True)
        else:
            QTimer.singleShot(50, press)  # not shown yet: look again

    QTimer.singleShot(SHOW_AFTER_MS + 50, press)
    assert not window.open_path(CHESSBOARD)
    assert pressed and window.session.doc is doc and len(doc.layers) == layers
    assert "Did not open" in window.statusBar().currentMessage()
