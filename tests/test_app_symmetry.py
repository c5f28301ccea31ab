"""Symmetry in the real editor: Shift+X turns mirror painting on (the menu action and the
panel's check box follow, the canvas draws the centre line), a drag on the canvas paints
the stroke and its mirror image, texel for texel the np.flip of the same drag painted
without symmetry, and one undo removes both halves."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import Qt  # noqa: E402

from matshop.app.testing import drag, shown_window  # noqa: E402
from matshop.layers import Rect  # noqa: E402
from matshop.paint import Symmetry  # noqa: E402
from matshop.viewport.canvas import MIRROR_LINE  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = Path(os.environ.get("MATSHOP_SHOTS", "")) if os.environ.get("MATSHOP_SHOTS") else None


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    assert win.open_path(SAMPLE)
    win.canvas.actual_size()
    win.canvas.flush()
    yield win
    win.prompts.save_answer = "discard"  # teardown closes without asking a human


def line_texels(win) -> int:
    """Canvas pixels of the mirror line's colour along the texture's vertical centre line."""
    canvas = win.canvas
    image = canvas.grab().toImage()
    x = round(canvas.to_widget(win.session.doc.width / 2, 0).x())
    top = round(canvas.to_widget(0, 0).y())
    bottom = round(canvas.to_widget(0, win.session.doc.height).y())
    count = 0
    for y in range(max(top, 0), min(bottom, image.height())):
        for dx in (-1, 0, 1):
            c = image.pixelColor(x + dx, y)
            rgb = np.array([c.red(), c.green(), c.blue()])
            count += int(
                np.abs(rgb - [MIRROR_LINE.red(), MIRROR_LINE.green(), MIRROR_LINE.blue()]).max()
                < 40
            )
    return count


def stroke(win) -> None:
    texels = [(60 + 14 * i, 120 + 40 * np.sin(i / 2.5)) for i in range(11)]
    drag(win.canvas, [win.canvas.to_widget(x, y) for x, y in texels])


def test_mirror_x_paints_the_flip_of_the_stroke_in_one_undo_step(window, qtbot) -> None:
    doc = window.session.doc
    window.brush_settings.set("radius_px", 9.0)
    window.brush_settings.set("hardness", 0.5)
    window.brush_settings.set("flow", 0.6)
    window.swatch_model.set_value("base_color", (0.15, 0.35, 0.8))  # blue on the tiles
    assert line_texels(window) < 10  # no line while symmetry is off
    qtbot.keyClick(window.canvas, Qt.Key.Key_X, Qt.KeyboardModifier.ShiftModifier)
    assert window.brush_settings.symmetry == Symmetry(x=True)
    assert window.actions_by_name["mirror_x"].isChecked()
    assert window.tool_panel.brush_panel.mirrors["x"].isChecked()
    assert window.canvas.symmetry == Symmetry(x=True)
    assert window.tool_label.text().endswith("(mirrored left/right)")  # the status bar says so
    assert line_texels(window) > 200  # the centre line is drawn (dashed) down the texture

    stroke(window)  # onto the base fill: a paint layer is added, then the stroke
    layer = window.session.active_layer
    full = Rect(0, 0, doc.width, doc.height)
    mirrored = layer.coverage(full)
    if SHOTS is not None:
        window.canvas.flush()
        window.canvas.grab().save(str(SHOTS / "symmetry_canvas.png"))
    steps = window.session.steps
    qtbot.keyClick(window.canvas, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert window.session.steps == steps - 1
    assert not layer.coverage(full).any()  # both halves went with the one step

    window.tool_panel.brush_panel.mirrors["x"].click()  # the panel's check box: off
    assert not window.brush_settings.symmetry and not window.actions_by_name["mirror_x"].isChecked()
    stroke(window)  # the same drag, into the same layer
    assert window.session.active_layer is layer
    alone = layer.coverage(full)
    assert alone.max() > 0.59 and not alone[:, doc.width // 2 :].any()  # the left half only
    np.testing.assert_allclose(mirrored, alone + np.flip(alone, axis=1), atol=1e-6, rtol=0)


def line_pixels_at(win, x_texel: float) -> int:
    """Canvas pixels of the mirror line's colour down the column of texel ``x_texel``."""
    canvas = win.canvas
    image = canvas.grab().toImage()
    x = round(canvas.to_widget(x_texel, 0).x())
    top = round(canvas.to_widget(0, 0).y())
    bottom = round(canvas.to_widget(0, win.session.doc.height).y())
    target = np.array([MIRROR_LINE.red(), MIRROR_LINE.green(), MIRROR_LINE.blue()])
    count = 0
    for y in range(max(top, 0), min(bottom, image.height())):
        for dx in (-1, 0, 1):
            c = image.pixelColor(x + dx, y)
            count += int(np.abs(np.array([c.red(), c.green(), c.blue()]) - target).max() < 40)
    return count


def test_the_mirror_centre_moves_by_its_handle_and_the_panel(window, qtbot) -> None:
    from matshop.tools.settings import BrushSettings

    doc, canvas = window.session.doc, window.canvas
    panel = window.tool_panel.brush_panel
    window.brush_settings.set("radius_px", 9.0)
    window.brush_settings.set("flow", 0.6)
    window.swatch_model.set_value("base_color", (0.9, 0.75, 0.1))
    qtbot.keyClick(canvas, Qt.Key.Key_X, Qt.KeyboardModifier.ShiftModifier)
    middle = (doc.width / 2, doc.height / 2)
    assert panel.centre["x"].value() == middle[0] and not panel.centre_reset.isEnabled()
    assert line_pixels_at(window, middle[0]) > 200

    # the line's round handle sits above the texture's top edge, on the line
    handle = canvas.mirror_handles()["x"]
    assert set(canvas.mirror_handles()) == {"x"}
    assert abs(handle.x() - canvas.to_widget(*middle).x()) < 1e-6
    assert handle.y() < canvas.to_widget(0, 0).y()
    # a press on the middle of the line paints (the handle is out of the way) ...
    steps = window.session.steps
    drag(canvas, [canvas.to_widget(*middle)])
    added = window.session.steps - steps
    assert added in (1, 2)  # the dab (and the paint layer it made over the fill)
    for _ in range(added):
        qtbot.keyClick(canvas, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert window.session.steps == steps
    # ... and dragging the handle to texel x = 150.3 moves the line: snapped to 150.5
    path = [handle, canvas.to_widget(120, 300), canvas.to_widget(150.3, 9)]
    drag(canvas, path)
    cx = 150.5
    assert window.brush_settings.symmetry == Symmetry(True, False, (cx, middle[1]))
    assert canvas.symmetry.centre == (cx, middle[1])
    assert panel.centre["x"].value() == cx and panel.centre_reset.isEnabled()
    assert window.session.steps == steps  # the handle moved, nothing was painted
    assert line_pixels_at(window, cx) > 200 and line_pixels_at(window, middle[0]) < 10
    assert window.tool_label.text().endswith("(mirrored left/right about x = 150.5)")

    def stroke() -> None:
        texels = [(40 + 9 * i, 120 + 40 * np.sin(i / 2.5)) for i in range(11)]
        drag(canvas, [canvas.to_widget(x, y) for x, y in texels])

    stroke()
    layer = window.session.active_layer
    full = Rect(0, 0, doc.width, doc.height)
    mirrored = layer.coverage(full)
    if SHOTS is not None:
        canvas.flush()
        canvas.grab().save(str(SHOTS / "symmetry_centre_canvas.png"))
    qtbot.keyClick(canvas, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert not layer.coverage(full).any()
    window.tool_panel.brush_panel.mirrors["x"].click()  # off, the centre kept
    stroke()
    alone = layer.coverage(full)
    assert alone.max() > 0.59 and not alone[:, 150:].any()
    # texel column j shows the stroke's column 2 cx - 1 - j (the dab at x lands at 2 cx - x)
    columns = np.arange(doc.width)
    source = (round(2 * cx) - 1 - columns) % doc.width
    np.testing.assert_allclose(mirrored, alone + alone[:, source], atol=1e-6, rtol=0)

    # the panel sets it too (half-texel steps), Middle puts it back; the project keeps it
    window.tool_panel.brush_panel.mirrors["x"].click()
    panel.centre["x"].setValue(300.0)
    assert window.brush_settings.symmetry.centre == (300.0, middle[1])
    assert line_pixels_at(window, 300.0) > 200
    saved = BrushSettings()
    saved.load_json(window.brush_settings.to_json())
    assert saved.symmetry == window.brush_settings.symmetry
    panel.centre_reset.click()
    assert window.brush_settings.symmetry == Symmetry(True)
    assert panel.centre["x"].value() == middle[0]
