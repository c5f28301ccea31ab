"""The layers panel updates only the rows a change concerns: instrumented by the model's
own signals and a count of thumbnail drawings, and its rows read back against the
document walked independently."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtGui import QImage  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

import matshop.app.layer_model as layer_model  # noqa: E402
from matshop.app.layer_model import DEPTH_ROLE, ID_ROLE, MASK_ROLE  # noqa: E402
from matshop.app.testing import drag, shown_window  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = ROOT / "test-output" / "screenshots"


class Watch:
    """What the model told its view, and which grids were drawn as thumbnails."""

    def __init__(self, model, monkeypatch) -> None:
        self.changed: list[int] = []
        self.structure: list[str] = []
        self.drawn: list[object] = []
        model.dataChanged.connect(
            lambda first, last, _roles=(): self.changed.extend(range(first.row(), last.row() + 1))
        )
        for name in ("modelReset", "rowsInserted", "rowsRemoved", "rowsMoved", "layoutChanged"):
            getattr(model, name).connect(lambda *_a, n=name: self.structure.append(n))
        real = layer_model.grid_thumbnail

        def counted(grid, channel, *args, **kwargs):
            self.drawn.append(grid)
            return real(grid, channel, *args, **kwargs)

        monkeypatch.setattr(layer_model, "grid_thumbnail", counted)

    def clear(self) -> None:
        self.changed.clear()
        self.structure.clear()
        self.drawn.clear()


def settle(window) -> None:
    window.canvas.flush()
    QApplication.processEvents()
    window.layers_panel.list.viewport().repaint()  # thumbnails are drawn as rows paint


def stroke(window, texels) -> None:
    drag(window.canvas, [window.canvas.to_widget(x, y) for x, y in texels])


def rows_from_the_document(doc) -> list[tuple]:
    """What each row must show, walking the stack and the parent links directly."""
    rows = []
    for layer in reversed(doc.layers):
        depth, parent = 0, layer.parent
        while parent is not None and any(other.id == parent for other in doc.layers):
            depth += 1
            parent = doc.layer(parent).parent
        rows.append((layer.id, layer.name, layer.visible, depth, layer.mask is not None))
    return rows


def rows_shown(panel) -> list[tuple]:
    model = panel.model
    rows = []
    for row in range(model.rowCount()):
        index = model.index(row)
        checked = index.data(Qt.ItemDataRole.CheckStateRole) == Qt.CheckState.Checked
        rows.append(
            (
                index.data(ID_ROLE),
                index.data(),
                checked,
                index.data(DEPTH_ROLE),
                index.data(MASK_ROLE) is not None,
            )
        )
    return rows


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    yield win
    win.prompts.save_answer = "discard"


def build_stack(window) -> list[int]:
    """Three painted layers (the middle one masked) over the opened set."""
    assert window.open_path(SAMPLE)
    window.brush_settings.set("radius_px", 20.0)
    window.brush_settings.set("hardness", 1.0)
    painted = []
    for number in range(3):
        painted.append(window.layer_commands.add_paint_layer())
        stroke(window, [(60, 80 + 120 * number), (400, 80 + 120 * number)])
        if number == 1:
            window.layer_commands.add_mask()
    settle(window)
    return painted


def test_an_opacity_change_repaints_one_row_and_draws_no_thumbnail(window, monkeypatch) -> None:
    painted = build_stack(window)
    panel, doc = window.layers_panel, window.session.doc
    watch = Watch(panel.model, monkeypatch)
    SHOTS.mkdir(parents=True, exist_ok=True)
    assert window.layers_dock.grab().save(str(SHOTS / "15_layers_panel_before_opacity.png"))
    shown_before = rows_shown(panel)
    assert shown_before == rows_from_the_document(doc)

    target = painted[1]
    window.session.set_active_layer(target)
    settle(window)
    watch.clear()
    window.layer_commands.set_property(target, "opacity", 0.4)
    settle(window)
    assert watch.changed == [panel.row_of(target)]  # that row, once
    assert watch.structure == [] and watch.drawn == []  # no row rebuilt, no thumbnail drawn
    assert panel.opacity.value() == pytest.approx(40.0)
    assert rows_shown(panel) == shown_before == rows_from_the_document(doc)
    assert window.layers_dock.grab().save(str(SHOTS / "16_layers_panel_after_opacity.png"))


def test_a_stroke_redraws_only_its_layers_thumbnail(window, monkeypatch) -> None:
    painted = build_stack(window)
    panel = window.layers_panel
    target = painted[0]
    window.session.set_active_layer(target)
    settle(window)
    watch = Watch(panel.model, monkeypatch)
    before = panel.index_of(target).data(Qt.ItemDataRole.DecorationRole).pixmap(32, 32).toImage()
    stroke(window, [(60, 450), (400, 450)])  # far below the layer's first stroke
    settle(window)
    layer = window.session.doc.layer(target)
    assert watch.changed == [panel.row_of(target)]
    assert watch.drawn == [layer.pixels] and watch.structure == []
    after = panel.index_of(target).data(Qt.ItemDataRole.DecorationRole).pixmap(32, 32).toImage()
    # the thumbnail is one texel per 16 of the 512-texel sample: the new stroke's row lit up
    y, xs = 450 * 32 // 512, range(60 * 32 // 512 + 2, 400 * 32 // 512 - 1)
    assert all(gray(before, x, y) < 20 and gray(after, x, y) > 200 for x in xs)

    watch.clear()
    window.session.undo()
    settle(window)
    assert watch.changed == [panel.row_of(target)] and watch.drawn == [layer.pixels]
    undone = panel.index_of(target).data(Qt.ItemDataRole.DecorationRole).pixmap(32, 32).toImage()
    assert all(gray(undone, x, y) < 20 for x in xs)


def gray(image: QImage, x: int, y: int) -> int:
    return image.pixelColor(x, y).value()


def test_adding_grouping_and_removing_touch_only_their_rows(window, monkeypatch) -> None:
    painted = build_stack(window)
    panel, doc, commands = window.layers_panel, window.session.doc, window.layer_commands
    watch = Watch(panel.model, monkeypatch)

    window.session.set_active_layer(painted[2])
    watch.clear()
    commands.add_fill_layer()
    settle(window)
    assert watch.structure == ["rowsInserted"] and watch.drawn == []
    assert rows_shown(panel) == rows_from_the_document(doc)
    assert panel.list.currentIndex().data(ID_ROLE) == window.session.active_layer_id

    watch.clear()
    group = commands.group([painted[1], painted[2]])
    settle(window)
    assert watch.drawn == []  # thumbnails stay; the members' rows indent
    assert {panel.row_of(i) for i in painted[1:]} <= set(watch.changed)
    assert panel.row_of(painted[0]) not in watch.changed
    assert rows_shown(panel) == rows_from_the_document(doc)
    assert panel.index_of(group).data(DEPTH_ROLE) == 0

    watch.clear()
    window.session.set_active_layer(painted[0])
    commands.remove_active()
    settle(window)
    assert watch.structure == ["rowsRemoved"] and watch.drawn == []
    assert rows_shown(panel) == rows_from_the_document(doc)
    assert panel.list.currentIndex().data(ID_ROLE) == window.session.active_layer_id


def test_dragging_a_row_is_one_move_edit(window) -> None:
    painted = build_stack(window)
    panel, doc = window.layers_panel, window.session.doc
    root = panel.index_of(painted[2]).parent()
    assert panel.row_of(painted[2]) == 0
    # what QListView's internal move asks of the model: the top row to just above the base
    assert panel.model.moveRow(root, 0, root, 3)
    assert [layer.id for layer in doc.layers][-3:] == [painted[2], painted[0], painted[1]]
    assert window.history_panel.labels()[-1] == "Move layer"
    assert rows_shown(panel) == rows_from_the_document(doc)


def test_the_views_checkbox_and_inline_editor_are_edits(window, qtbot) -> None:
    from PySide6.QtWidgets import QLineEdit, QStyle, QStyleOptionViewItem

    from matshop.app.testing import click

    assert window.open_path(SAMPLE)
    layer_id = window.layer_commands.add_paint_layer()
    panel = window.layers_panel
    settle(window)
    index = panel.index_of(layer_id)
    option = QStyleOptionViewItem()
    option.rect = panel.list.visualRect(index)
    option.features |= QStyleOptionViewItem.ViewItemFeature.HasCheckIndicator
    check = panel.list.style().subElementRect(
        QStyle.SubElement.SE_ItemViewItemCheckIndicator, option, panel.list
    )
    click(panel.list.viewport(), check.center())
    assert not window.session.doc.layer(layer_id).visible
    assert window.history_panel.labels()[-1] == "Layer visibility"

    panel.list.edit(index)  # the inline editor, as a double click opens it
    (editor,) = panel.list.viewport().findChildren(QLineEdit)
    editor.setText("Scratches")
    qtbot.keyClick(editor, Qt.Key.Key_Return)
    QApplication.processEvents()  # the delegate commits on Return through a queued call
    assert window.session.doc.layer(layer_id).name == "Scratches"
    assert window.history_panel.labels()[-1] == "Rename layer"
    assert rows_shown(panel) == rows_from_the_document(window.session.doc)
