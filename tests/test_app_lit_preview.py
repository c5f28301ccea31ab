"""The canvas' lit display: rendered on a worker, the light moved by a right-drag."""

from __future__ import annotations

import os

if not os.environ.get("DISPLAY"):
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop.app.lit_preview import light_direction  # noqa: E402
from matshop.app.testing import drag, make_window  # noqa: E402
from matshop.app.theme import apply_theme  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = ROOT / "test-output" / "screenshots"


def _pixels(image) -> np.ndarray:
    image = image.convertToFormat(image.Format.Format_RGBA8888)
    data = np.frombuffer(image.constBits(), dtype=np.uint8)
    return data.reshape(image.height(), image.bytesPerLine() // 4, 4)[:, : image.width()].copy()


def test_lit_display_renders_off_the_gui_thread_and_follows_the_light(qtbot, tmp_path) -> None:
    apply_theme(QApplication.instance())
    window = make_window(tmp_path)
    qtbot.addWidget(window)
    window.resize(1560, 940)
    window.show()
    qtbot.waitExposed(window)
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow, timeout=3000)  # window shortcuts need the active window
    assert window.open_path(SAMPLE)
    lit, canvas = window.lit_preview, window.canvas
    qtbot.keyClick(canvas, Qt.Key.Key_L)  # the View menu's shortcut
    assert lit.enabled and window.actions_by_name["lit"].isChecked()
    assert lit.wait() and canvas.overlay is not None
    first = _pixels(canvas.overlay)
    assert first.shape[:2] == (512, 512) and first[..., :3].std() > 5  # an image, not a fill
    canvas.flush()
    SHOTS.mkdir(parents=True, exist_ok=True)
    assert window.grab().save(str(SHOTS / "25_lit_preview.png"))

    # a right-drag to the lower right moves the light there: a different picture
    drag(
        canvas,
        [canvas.to_widget(300, 300), canvas.to_widget(500, 500)],
        button=Qt.MouseButton.RightButton,
    )
    assert lit.light == pytest.approx(light_direction(500 / 256 - 1, 500 / 256 - 1))
    assert lit.wait()
    moved = _pixels(canvas.overlay)
    assert np.abs(moved.astype(int) - first.astype(int)).mean() > 2
    assert window.session.steps == 0  # moving the light is no edit

    qtbot.keyClick(canvas, Qt.Key.Key_L)
    assert not lit.enabled and canvas.overlay is None and not canvas.lit
    window.prompts.save_answer = "discard"
