"""Painting in the real editor window without traps: a stroke paints exactly the parameters
its swatch enables (whatever the layer), masks read as in Photoshop after Invert too, the
status bar says what the tool will do, a stroke that changes nothing adds no undo step, and
a dab lands where the pointer was at a known zoom and offset (within half a texel)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import QPointF, Qt  # noqa: E402

from matshop.app.testing import click, drag, shown_window  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    assert win.open_path(SAMPLE)
    win.canvas.actual_size()
    win.canvas.flush()
    yield win
    win.prompts.save_answer = "discard"  # teardown closes without asking a human


def stroke(win, texels) -> None:
    drag(win.canvas, [win.canvas.to_widget(x, y) for x, y in texels])


def edit_channels(doc, names) -> list[int]:
    return [c for n in names for c in range(*doc.schema.edit_slices[n].indices(doc.channels))]


def test_a_new_layer_and_a_swatch_without_normal_paint_only_what_is_enabled(window, qtbot):
    doc = window.session.doc
    qtbot.keyClick(
        window.canvas,
        Qt.Key.Key_N,
        Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier,
    )
    layer = window.session.active_layer
    assert layer.kind == "paint" and layer.parameters is None  # Ctrl+Shift+N: affects all
    checks = window.tool_panel.swatch_editor.checks
    for name in ("normal", "metallic", "ao"):
        checks[name].click()  # the real check boxes
    window.swatch_model.set_value("base_color", (0.2, 0.55, 0.85))
    window.swatch_model.set_value("roughness", (0.9,))
    assert window.tool_label.text() == (
        f"Brush: paints base color, roughness into layer {layer.name!r}"
    )
    before = doc.flatten_edit()
    steps = window.session.steps
    window.brush_settings.set("radius_px", 10.0)
    window.brush_settings.set("hardness", 1.0)
    stroke(window, [(100 + 10 * i, 200) for i in range(21)])
    after = doc.flatten_edit()
    others = edit_channels(doc, ("normal", "metallic", "ao"))
    assert np.array_equal(after[..., others], before[..., others])  # left as they are
    phys = doc.physical()
    np.testing.assert_allclose(phys["base_color"][200, 150], (0.2, 0.55, 0.85), atol=2e-5)
    np.testing.assert_allclose(phys["roughness"][200, 150], (0.9,), atol=2e-5)
    assert window.session.steps == steps + 1
    assert window.session.active_layer.parameters == ("base_color", "roughness")
    # a second swatch (roughness only) on the now painted layer: a new layer above takes it
    checks["base_color"].click()
    assert "into a new layer above" in window.tool_label.text()
    before = doc.flatten_edit()
    stroke(window, [(150, 170 + 6 * i) for i in range(11)])
    after = doc.flatten_edit()
    others = edit_channels(doc, ("base_color", "normal", "metallic", "ao"))
    assert np.array_equal(after[..., others], before[..., others])
    assert window.session.active_layer.parameters == ("roughness",)
    assert window.session.steps == steps + 2


def test_mask_invert_white_reveals_black_hides_and_the_status_bar_agrees(window, qtbot):
    doc = window.session.doc
    window.swatch_model.set_value("base_color", (0.2, 0.55, 0.85))
    window.brush_settings.set("radius_px", 40.0)
    window.brush_settings.set("hardness", 1.0)
    underneath = doc.flatten_edit()[250, 250].copy()
    stroke(window, [(250, 250), (251, 250)])  # onto the base fill: a paint layer is added
    layer = window.session.active_layer
    painted = doc.flatten_edit()[250, 250].copy()
    window.actions_by_name["add_mask"].trigger()
    window.actions_by_name["invert_mask"].trigger()
    assert layer.mask_inverted
    hidden = doc.flatten_edit()[250, 250].copy()
    # a new (white) mask inverted hides the whole layer: what was underneath shows
    np.testing.assert_allclose(hidden, underneath, atol=1e-6)
    assert not np.allclose(hidden, painted)
    window.session.set_mask_target(True)  # the mask thumbnail is selected
    window.brush_settings.set("radius_px", 6.0)
    assert (
        window.tool_label.text() == f"Brush: hides layer {layer.name!r} where it paints (its mask)"
    )
    window.set_tool("eraser")
    assert window.tool_label.text().startswith(f"Eraser: reveals layer {layer.name!r}")
    stroke(window, [(250, 250), (252, 250)])
    np.testing.assert_allclose(doc.flatten_edit()[250, 250], painted, atol=1e-6)  # revealed
    window.set_tool("brush")
    stroke(window, [(250, 250), (252, 250)])
    np.testing.assert_allclose(doc.flatten_edit()[250, 250], hidden, atol=1e-6)  # hidden
    # strokes that change nothing add no undo step: the brush hiding where the inverted
    # mask already hides, the eraser on layer pixels where nothing was painted
    steps = window.session.steps
    stroke(window, [(450, 450), (460, 450)])
    assert window.session.steps == steps
    window.session.set_mask_target(False)
    window.set_tool("eraser")
    assert window.tool_label.text() == f"Eraser: erases paint from layer {layer.name!r}"
    stroke(window, [(450, 450), (460, 450)])
    assert window.session.steps == steps


def test_a_dab_lands_under_the_pointer_at_a_known_zoom_and_offset(window) -> None:
    """Zoom 2.5, offset (37, -12): the pointer at widget (400.0, 300.0) is texel
    ((400 - 37) / 2.5, (300 + 12) / 2.5) = (145.2, 124.8); the dab's coverage centroid
    (texel centres at i + 0.5) lies within half a texel of it."""
    canvas = window.canvas
    canvas.view.zoom = 2.5
    canvas.view.offset_x, canvas.view.offset_y = 37.0, -12.0
    window.layer_commands.add_paint_layer()
    window.brush_settings.set("radius_px", 5.0)
    window.brush_settings.set("hardness", 1.0)
    click(canvas, QPointF(400.0, 300.0))
    layer = window.session.active_layer
    coverage = layer.coverage(window.session.doc.layout.bounds)
    rows, cols = np.nonzero(coverage)
    weight = coverage[rows, cols]
    cx = float(np.sum((cols + 0.5) * weight) / weight.sum())
    cy = float(np.sum((rows + 0.5) * weight) / weight.sum())
    assert abs(cx - 145.2) <= 0.5 and abs(cy - 124.8) <= 0.5, (cx, cy)
    area = float(weight.sum())
    assert abs(area - np.pi * 25.0) < 0.1 * np.pi * 25.0  # a radius-5 disc, not a smear
