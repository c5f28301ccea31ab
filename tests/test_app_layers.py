"""Layers panel completeness: duplicate, groups (indented members, in and out by edits on
``parent``), masks (add, paint through the thumbnail, invert, remove), thumbnails."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import QItemSelectionModel, Qt  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop.app.layer_model import DEPTH_ROLE, MASK_ROLE  # noqa: E402
from matshop.app.layers_panel import LayerRowDelegate  # noqa: E402
from matshop.app.testing import click, drag, shown_window  # noqa: E402
from matshop.layers import GroupLayer, PaintLayer  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = ROOT / "test-output" / "screenshots"


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    yield win
    win.prompts.save_answer = "discard"


def stroke(win, texels) -> None:
    drag(win.canvas, [win.canvas.to_widget(x, y) for x, y in texels])


def open_and_paint(win):
    assert win.open_path(SAMPLE)
    win.brush_settings.set("radius_px", 14.0)
    win.brush_settings.set("hardness", 1.0)
    win.swatch_model.set_value("base_color", (0.05, 0.35, 0.6))
    stroke(win, [(60, 100), (450, 100)])
    return win.session.doc


def test_duplicate_shares_the_tiles_in_one_step(window, qtbot) -> None:
    doc = open_and_paint(window)
    painted = doc.flatten_edit()
    source = window.session.active_layer
    window.layer_commands.set_property(source.id, "opacity", 0.5)
    qtbot.keyClick(window.canvas, Qt.Key.Key_J, Qt.KeyboardModifier.ControlModifier)
    twin = window.session.active_layer
    assert isinstance(twin, PaintLayer) and twin is not source and twin.name.endswith("copy")
    assert doc.index_of(twin.id) == doc.index_of(source.id) + 1 and twin.opacity == 0.5
    assert set(twin.pixels.keys()) == set(source.pixels.keys())
    assert all(twin.pixels.get(k) is source.pixels.get(k) for k in source.pixels.keys())
    assert window.history_panel.labels()[-1] == f"Add layer '{twin.name}'"
    keys = set(source.pixels.keys())
    stroke(window, [(60, 300), (200, 300)])  # painting the copy leaves the source alone
    assert set(source.pixels.keys()) == keys and len(twin.pixels) > len(keys)
    window.session.undo()
    window.session.undo()
    window.session.undo()
    assert np.array_equal(doc.flatten_edit(), painted)


def test_group_selected_layers_indent_and_move_out(window) -> None:
    doc = open_and_paint(window)
    first = window.session.active_layer_id
    window.layer_commands.add_fill_layer()
    window.layer_commands.add_paint_layer()  # a layer between: the grouped ones are gathered
    window.layer_commands.move_active(1)
    fill = doc.layers[-1].id
    before_ids = [layer.id for layer in doc.layers]
    flat = doc.flatten_edit()
    panel = window.layers_panel
    selection = panel.list.selectionModel()
    for layer_id in (first, fill):
        index = panel.index_of(layer_id)
        selection.select(index, QItemSelectionModel.SelectionFlag.Select)
    steps = window.session.steps
    window.actions_by_name["group"].trigger()
    group = window.session.active_layer
    assert isinstance(group, GroupLayer) and window.session.steps == steps + 1
    assert window.history_panel.labels()[-1] == "Group layers"
    ids = [layer.id for layer in doc.layers]
    assert ids[-3:] == [first, fill, group.id]  # members just below their group
    assert doc.layer(first).parent == group.id and doc.layer(fill).parent == group.id
    assert panel.index_of(fill).data(DEPTH_ROLE) == 1
    assert panel.index_of(group.id).data(DEPTH_ROLE) == 0
    np.testing.assert_allclose(doc.flatten_edit(), flat, atol=1e-6)  # a group passes through
    window.session.set_active_layer(first)
    window.canvas.flush()
    QApplication.processEvents()
    SHOTS.mkdir(parents=True, exist_ok=True)
    assert window.grab().save(str(SHOTS / "13_group_layers.png"))

    window.actions_by_name["ungroup"].trigger()
    assert doc.layer(first).parent is None
    assert doc.index_of(first) == doc.index_of(group.id) + 1  # just above the group
    assert window.session.steps == steps + 2
    window.session.undo()
    window.session.undo()
    assert [layer.id for layer in doc.layers] == before_ids
    assert np.array_equal(doc.flatten_edit(), flat)


def test_paint_a_mask_through_its_thumbnail_invert_and_remove(window, qtbot) -> None:
    doc = open_and_paint(window)
    layer = window.session.active_layer
    painted = doc.flatten_edit()
    window.session.undo()  # the stroke
    underneath = doc.flatten_edit()
    window.session.redo()
    assert not np.array_equal(painted[100, 80:280], underneath[100, 80:280])
    window.actions_by_name["add_mask"].trigger()
    assert layer.mask is not None and np.array_equal(doc.flatten_edit(), painted)
    panel = window.layers_panel
    row = panel.index_of(layer.id)
    assert row.data(MASK_ROLE) is not None
    rect = LayerRowDelegate.mask_rect(panel.list.visualRect(row))
    click(panel.list.viewport(), rect.center())  # select the mask thumbnail
    assert window.session.mask_target
    window.brush_settings.set("radius_px", 30.0)
    stroke(window, [(200, 100), (300, 100)])  # the brush hides the layer under it
    assert window.history_panel.labels()[-1] == "Paint mask"
    flat = doc.flatten_edit()
    np.testing.assert_array_equal(flat[100, 220:280], underneath[100, 220:280])
    np.testing.assert_array_equal(flat[100, 80:150], painted[100, 80:150])
    window.canvas.flush()
    QApplication.processEvents()
    assert window.grab().save(str(SHOTS / "14_painted_mask.png"))
    window.actions_by_name["invert_mask"].trigger()  # now only the masked-out part shows
    flat = doc.flatten_edit()
    np.testing.assert_array_equal(flat[100, 220:280], painted[100, 220:280])
    np.testing.assert_array_equal(flat[100, 80:150], underneath[100, 80:150])
    click(panel.list.viewport(), rect.center())  # back to painting pixels
    assert not window.session.mask_target
    window.actions_by_name["remove_mask"].trigger()
    assert layer.mask is None and np.array_equal(doc.flatten_edit(), painted)
    for _ in range(4):
        window.session.undo()
    assert layer.mask is None and np.array_equal(doc.flatten_edit(), painted)


def test_every_parameter_button_and_swatch_label_shows_its_whole_name(window, tmp_path) -> None:
    """A material with eight parameters: no button text is cut (``emissi``), and the
    layer dock keeps its width (the buttons wrap into rows)."""
    from matshop.io.project import save_project
    from matshop.layers import Document
    from matshop.material import Material, Schema

    names = ["base_color", "metallic", "roughness", "normal", "ao", "emissive", "opacity", "height"]
    schema = Schema.from_names(names)
    maps = {p.name: np.full((64, 64, p.phys_channels), 0.5, np.float32) for p in schema.parameters}
    maps["normal"] = np.broadcast_to(np.float32([0, 0, 1]), (64, 64, 3)).copy()
    path = tmp_path / "many.matshop"
    save_project(Document.from_material(Material("many", schema, maps)), path)
    width = window.layers_dock.width()
    assert window.open_path(path)
    QApplication.processEvents()
    buttons = window.layers_panel.param_buttons
    assert buttons["emissive"].text() == "Emissive"
    for name, button in buttons.items():
        needed = button.fontMetrics().horizontalAdvance(button.text())
        assert needed <= button.contentsRect().width(), f"{name}: {button.text()!r} is cut"
    assert window.layers_dock.width() <= width + 8
    for name, check in window.tool_panel.swatch_editor.checks.items():
        needed = check.fontMetrics().horizontalAdvance(check.text())
        assert needed <= check.width(), f"swatch {name}: {check.text()!r} is cut"
