"""The seamless clone tool driven by real mouse events: lasso a source, drag it, release.

Checks the pasted region against the engine's clone, the seam (boundary
pixels keep the target), that everything else is untouched, one undo step
that undoes bit-identically, and the polygon (click) selection.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import QEvent, QPointF, Qt  # noqa: E402
from PySide6.QtGui import QMouseEvent  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop.app.testing import click, drag, shown_window  # noqa: E402
from matshop.layers import PaintLayer  # noqa: E402
from matshop.ops.clone import CloneCoordinates  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = ROOT / "test-output" / "screenshots"


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    yield win
    win.prompts.save_answer = "discard"


def shot(win, name: str) -> None:
    win.canvas.flush()
    QApplication.processEvents()
    SHOTS.mkdir(parents=True, exist_ok=True)
    assert win.grab().save(str(SHOTS / f"{name}.png"))


def _send(canvas, kind: QEvent.Type, texel: tuple[float, float], buttons) -> None:
    pos = canvas.to_widget(*texel)
    button = Qt.MouseButton.LeftButton
    event = QMouseEvent(
        kind,
        pos,
        QPointF(canvas.mapToGlobal(pos.toPoint())),
        button,
        buttons,
        Qt.KeyboardModifier.NoModifier,
    )
    QApplication.sendEvent(canvas, event)


def lasso(canvas, centre: tuple[float, float], radius: float) -> list[tuple[float, float]]:
    points = [
        (centre[0] + radius * math.cos(t), centre[1] + radius * math.sin(t))
        for t in np.linspace(0.0, 2.0 * math.pi, 48, endpoint=False)
    ]
    drag(canvas, [canvas.to_widget(x, y) for x, y in points])
    return points


def test_lasso_drag_release_pastes_seamlessly_in_one_undo_step(window, qtbot) -> None:
    assert window.open_path(SAMPLE)
    doc = window.session.doc
    window.actions_by_name["tool_seamless_clone"].trigger()
    tool = window.tool
    assert tool.name == "seamless_clone" and not window.tool_panel.brush_panel.isVisible()
    before = doc.flatten_edit()
    steps = window.session.steps
    canvas = window.canvas

    points = lasso(canvas, (150.0, 160.0), 40.0)
    assert tool.coords is not None and window.session.steps == steps  # selecting is no edit
    shot(window, "20_seamless_clone_selected")

    # drag with a live preview: the document shows the clone before the release
    held = Qt.MouseButton.LeftButton
    _send(canvas, QEvent.Type.MouseButtonPress, (150.0, 160.0), held)
    for i in range(1, 11):
        _send(canvas, QEvent.Type.MouseMove, (150.0 + 20.0 * i, 160.0 + 15.0 * i), held)
    assert tool.busy and window.session.steps == steps
    assert not np.array_equal(doc.flatten_edit(), before)  # the preview is in the composite
    shot(window, "21_seamless_clone_dragging")
    _send(canvas, QEvent.Type.MouseButtonRelease, (350.0, 310.0), Qt.MouseButton.NoButton)
    offset = (200, 150)
    assert not tool.busy and window.session.steps == steps + 1
    assert window.history_panel.labels()[-1] == "Seamless clone"
    assert isinstance(window.session.active_layer, PaintLayer)
    shot(window, "22_seamless_clone_placed")

    after = doc.flatten_edit()
    polygon = np.asarray(points) - 0.5
    coords = CloneCoordinates.from_region(polygon, doc.size)
    expected = coords.clone(before, before, offset, "clamp")
    np.testing.assert_allclose(after, expected, atol=1e-5)  # pasted at the offset
    bx, by = coords.boundary[:, 0] + offset[0], coords.boundary[:, 1] + offset[1]
    np.testing.assert_allclose(after[by, bx], before[by, bx], atol=1e-5)  # the seam
    ix, iy = coords.interior[:, 0], coords.interior[:, 1]
    inside = after[iy + offset[1], ix + offset[0]]
    assert np.abs(inside - before[iy + offset[1], ix + offset[0]]).max() > 0.05  # it moved
    changed = np.any(after != before, axis=-1)
    x0, y0, x1, y1 = coords.bbox
    changed[y0 + offset[1] : y1 + offset[1], x0 + offset[0] : x1 + offset[0]] = False
    assert not changed.any()  # nothing outside the placed region

    window.undo()
    assert np.array_equal(doc.flatten_edit(), before)  # bit-identical, layer and all
    window.redo()
    assert np.array_equal(doc.flatten_edit(), after)


def test_polygon_clicks_select_and_escape_drops_the_selection(window, qtbot) -> None:
    assert window.open_path(SAMPLE)
    doc = window.session.doc
    window.set_tool("seamless_clone")
    tool, canvas = window.tool, window.canvas
    square = [(100.0, 100.0), (180.0, 100.0), (180.0, 180.0), (100.0, 180.0)]
    for point in square:
        click(canvas, canvas.to_widget(*point))
    assert tool.coords is None and len(tool.outlines()[0][0]) == 4
    click(canvas, canvas.to_widget(101.0, 101.0))  # back on the first vertex closes it
    assert tool.coords is not None
    assert tool.coords.bbox == (100, 100, 180, 180)  # texel centres inside the square
    qtbot.keyClick(canvas, Qt.Key.Key_Escape)
    assert tool.coords is None and tool.outlines() == []
    assert window.session.steps == 0 and len(doc.layers) == 1
