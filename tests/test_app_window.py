"""Scripted sessions on the real main window: open, paint, undo/redo, filter layers,
sliders, save and reopen, bad files, menus and shortcuts. Screenshots of the main
states go to ``test-output/screenshots/``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import QPointF, Qt  # noqa: E402
from PySide6.QtWidgets import QApplication, QMessageBox  # noqa: E402

from matshop.app.testing import click, drag, make_window, shown_window  # noqa: E402
from matshop.io.material_io import load_material  # noqa: E402
from matshop.layers import AddLayer, Document, History, PaintLayer  # noqa: E402
from matshop.layers.layer import FilterLayer  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = ROOT / "test-output" / "screenshots"

SWATCH = {
    "base_color": (0.05, 0.35, 0.6),
    "metallic": (1.0,),
    "roughness": (0.2,),
    "normal": (0.0, 0.0, 1.0),
    "ao": (1.0,),
}


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    yield win
    win.prompts.save_answer = "discard"  # teardown closes without asking a human


def shot(win, name: str) -> Path:
    """Save a screenshot of the window (after converting every stale tile)."""
    win.canvas.flush()
    QApplication.processEvents()
    SHOTS.mkdir(parents=True, exist_ok=True)
    path = SHOTS / f"{name}.png"
    assert win.grab().save(str(path))
    return path


def open_sample(win) -> Document:
    assert win.open_path(SAMPLE)
    win.canvas.flush()
    for name, value in SWATCH.items():
        win.swatch_model.set_value(name, value)
    return win.session.doc


def stroke(win, texels, modifiers=Qt.KeyboardModifier.NoModifier) -> None:
    canvas = win.canvas
    drag(canvas, [canvas.to_widget(x, y) for x, y in texels], modifiers=modifiers)


def test_paint_a_stroke_undo_and_redo_with_the_keyboard(window, qtbot) -> None:
    doc = open_sample(window)
    shot(window, "01_opened_sample")
    before = doc.flatten_edit()
    window.brush_settings.set("radius_px", 12.0)
    window.brush_settings.set("hardness", 1.0)
    stroke(window, [(100 + 10 * i, 200) for i in range(21)])
    after = doc.flatten_edit()
    changed = np.any(after != before, axis=-1)
    assert changed[200, 100:300].all() and not changed[300:].any()
    # the stroke's centre line carries the swatch, every parameter of it
    phys = doc.physical()
    for name, value in SWATCH.items():
        np.testing.assert_allclose(
            phys[name][200, 150:250], np.broadcast_to(value, (100, len(value))), atol=2e-5
        )
    # the stroke went into a new paint layer: two steps, the stroke is the last
    assert isinstance(window.session.active_layer, PaintLayer)
    assert window.history_panel.labels()[-2:] == ["Add layer 'Paint 2'", "Paint"]
    assert window.actions_by_name["undo"].text() == "&Undo Paint"
    shot(window, "02_painted_stroke")

    qtbot.keyClick(window.canvas, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert np.array_equal(doc.flatten_edit(), before)  # bit-identical
    qtbot.keyClick(
        window.canvas,
        Qt.Key.Key_Z,
        Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier,
    )
    assert np.array_equal(doc.flatten_edit(), after)
    window.canvas.flush()
    # the canvas shows it too: a swatch color is the file's codes, shown as they are
    shown = window.canvas.cache.buffer[200, 150, :3].astype(int)
    codes = np.round(255 * np.array(SWATCH["base_color"]))
    np.testing.assert_allclose(shown, codes, atol=1)


def test_a_dab_redraws_only_its_tiles(window) -> None:
    doc = open_sample(window)
    window.layer_commands.add_paint_layer()
    window.canvas.flush()
    window.brush_settings.set("radius_px", 10.0)
    click(window.canvas, window.canvas.to_widget(128.0, 128.0))  # on a tile corner
    cache = window.canvas.cache
    assert int(cache.pending.sum()) == 4  # of 64 tiles
    converted = cache.refresh(budget_s=None)
    assert not cache.busy and sum(rect.area for rect in converted) == 4 * 64 * 64
    # the four tiles show the swatch's color codes under the dab, the rest what it was
    codes = np.round(255 * np.array(window.swatch_model.values["base_color"]))
    np.testing.assert_allclose(cache.buffer[128, 128, :3], codes, atol=1)
    assert doc.layers[-1].pixels is not None and len(doc.layers[-1].pixels) == 4


def test_blur_filter_layer_from_the_panel_matches_the_engine(window, qtbot) -> None:
    doc = open_sample(window)
    add_filter = window.actions_by_name["add_filter"].menu()
    blur = next(a for a in add_filter.actions() if a.text() == "Gaussian blur")
    blur.trigger()
    layer = window.session.active_layer
    assert isinstance(layer, FilterLayer) and layer.op == "blur"
    slider = window.properties_panel.controls["sigma_px"]
    steps = window.session.steps
    slider.box.setValue(6.0)  # typed value: one step
    assert layer.op_params["sigma_px"] == pytest.approx(6.0)
    assert window.session.steps == steps + 1
    shot(window, "03_blur_filter_layer")

    material, _ = load_material(SAMPLE)
    reference = Document.from_material(material)
    History(reference).push(
        AddLayer(reference.new_filter_layer("blur", op_params={"sigma_px": 6.0}))
    )
    assert np.array_equal(doc.flatten_edit(), reference.flatten_edit())


def test_an_opacity_slider_drag_is_one_undo_step(window) -> None:
    doc = open_sample(window)
    stroke(window, [(60, 60), (400, 400)])
    layer = window.session.active_layer
    painted = doc.flatten_edit()
    steps = window.session.steps
    slider = window.layers_panel.opacity.slider
    y = slider.height() // 2
    right = slider.width() - 7  # the handle sits at the right end (100 %)
    drag(slider, [(right, y), *[(right - 15 * i, y) for i in range(1, 9)]])
    assert layer.opacity < 0.8
    assert window.session.steps == steps + 1
    assert window.history_panel.labels()[-1] == "Layer opacity"
    shot(window, "04_opacity_drag")
    window.session.undo()
    assert layer.opacity == 1.0 and np.array_equal(doc.flatten_edit(), painted)


def test_save_project_and_reopen_gives_the_identical_flatten(window, tmp_path) -> None:
    doc = open_sample(window)
    stroke(window, [(30, 40), (200, 260), (420, 90)])
    window.layer_commands.add_filter_layer("blur", {"sigma_px": 3.0})
    window.show_parameter("roughness")
    expected = doc.flatten_edit()
    target = tmp_path / "work.matshop"
    window.prompts.save_path = target
    window.actions_by_name["save"].trigger()  # never saved: asks where (Save As)
    assert target.is_file() and not window.session.modified
    assert not window.isWindowModified() and "work.matshop" in window.windowTitle()
    assert window.open_path(target)
    reopened = window.session.doc
    assert reopened is not doc
    assert np.array_equal(reopened.flatten_edit(), expected)
    assert window.canvas.parameter == "roughness"  # editor state came back too
    assert [layer.kind for layer in reopened.layers] == ["fill", "paint", "filter"]
    shot(window, "05_reopened_project_roughness")


def test_a_failed_open_shows_one_line_and_keeps_the_document(qtbot, tmp_path, monkeypatch):
    from matshop.app.prompts import Prompts

    shown: list[str] = []
    monkeypatch.setattr(
        QMessageBox, "critical", staticmethod(lambda parent, title, text, *a: shown.append(text))
    )
    win = make_window(tmp_path)
    win.prompts = win.files.prompts = Prompts(win)
    qtbot.addWidget(win)
    doc = open_sample(win)
    stroke(win, [(10, 10), (90, 90)])
    before = doc.flatten_edit()
    steps = win.session.steps
    corrupt = tmp_path / "broken.matshop"
    corrupt.write_bytes(b"PK\x03\x04 this is not a zip archive at all")
    assert not win.open_path(corrupt)
    not_a_set = tmp_path / "empty_folder"
    not_a_set.mkdir()
    assert not win.open_path(not_a_set)
    assert len(shown) == 2 and all("\n" not in text for text in shown)
    assert "broken.matshop" in shown[0] and "Traceback" not in shown[0]
    assert win.session.doc is doc and win.session.steps == steps
    assert np.array_equal(doc.flatten_edit(), before)
    win.session.set_document(None)  # teardown: nothing to ask about


def test_menus_are_reachable_and_enabled_sensibly(window) -> None:
    a = window.actions_by_name
    menus = [action.menu() for action in window.menuBar().actions()]
    texts = {act.text() for menu in menus for act in menu.actions() if not act.isSeparator()}
    for name in ("open", "save", "save_as", "export", "undo", "redo", "add_paint", "fit"):
        assert a[name].text() in texts or a[name].text().startswith("&Undo")
    assert not any(a[n].isEnabled() for n in ("save", "export", "undo", "redo", "add_paint"))
    assert a["open"].isEnabled()
    shot(window, "00_empty_window")

    doc = open_sample(window)
    assert a["save"].isEnabled() and a["add_paint"].isEnabled()
    assert not a["undo"].isEnabled() and not a["delete"].isEnabled()  # one layer: keep it
    a["add_paint"].trigger()
    assert len(doc) == 2 and a["undo"].isEnabled() and a["delete"].isEnabled()
    assert not a["move_up"].isEnabled() and a["move_down"].isEnabled()
    a["move_down"].trigger()
    assert doc.layers[0].kind == "paint"
    a["move_up"].trigger()
    a["add_fill"].trigger()
    assert doc.layers[-1].kind == "fill" and doc.layers[-1].parameters is None
    a["delete"].trigger()
    assert len(doc) == 2
    view, canvas = window.canvas.view, window.canvas
    a["actual"].trigger()
    assert view.zoom == 1.0
    a["zoom_in"].trigger()
    assert view.zoom == pytest.approx(1.25)
    a["zoom_out"].trigger()
    assert view.zoom == pytest.approx(1.0)
    a["fit"].trigger()  # the whole texture inside the canvas, filling most of one side
    x0, y0 = view.to_widget(0, 0)
    x1, y1 = view.to_widget(doc.width, doc.height)
    assert x0 >= -0.5 and y0 >= -0.5 and x1 <= canvas.width() + 0.5 and y1 <= canvas.height() + 0.5
    assert max((x1 - x0) / canvas.width(), (y1 - y0) / canvas.height()) > 0.8
    layers = len(doc)
    a["undo"].trigger()  # the delete above comes back
    assert len(doc) == layers + 1
    a["redo"].trigger()
    assert len(doc) == layers
    asked = len(window.files.prompts.asked)
    window.files.prompts.folder = None
    a["export"].trigger()  # with no folder chosen it stops: no error, nothing else asked
    assert "error" not in [kind for kind, _ in window.files.prompts.asked[asked:]]
    for param in window.parameter_menu.actions():
        param.trigger()
        assert window.canvas.parameter == param.data()
    window.show_parameter("normal")
    shot(window, "06_normal_parameter")


def test_shortcuts_switch_tools_and_change_the_view(window, qtbot) -> None:
    open_sample(window)
    canvas = window.canvas
    for key, name in (
        (Qt.Key.Key_E, "eraser"),
        (Qt.Key.Key_S, "clone"),
        (Qt.Key.Key_I, "eyedropper"),
        (Qt.Key.Key_B, "brush"),
    ):
        qtbot.keyClick(canvas, key)
        assert window.tool.name == name
        assert window.actions_by_name[f"tool_{name}"].isChecked()
    radius = window.brush_settings.values["radius_px"]
    qtbot.keyClick(canvas, Qt.Key.Key_BracketRight)
    assert window.brush_settings.values["radius_px"] == pytest.approx(radius * 1.25)
    qtbot.keyClick(canvas, Qt.Key.Key_BracketLeft)
    assert window.brush_settings.values["radius_px"] == pytest.approx(radius)
    qtbot.keyClick(canvas, Qt.Key.Key_1)
    assert canvas.view.zoom == 1.0
    qtbot.keyClick(canvas, Qt.Key.Key_F)
    assert canvas.view.zoom != 1.0
    # the wheel zooms around the cursor: the texel under it stays put
    anchor = canvas.to_widget(200.0, 300.0)
    canvas.zoom_by(2.0, anchor)
    assert canvas.to_texel(anchor) == pytest.approx((200.0, 300.0))


def test_clone_stamp_and_eyedropper(window, qtbot) -> None:
    doc = open_sample(window)
    qtbot.keyClick(window.canvas, Qt.Key.Key_S)
    window.brush_settings.set("radius_px", 8.0)
    window.brush_settings.set("hardness", 1.0)
    stroke(window, [(300, 300)])
    assert "clone source" in window.statusBar().currentMessage()
    click(
        window.canvas,
        window.canvas.to_widget(40.5, 40.5),
        modifiers=Qt.KeyboardModifier.AltModifier,
    )
    stroke(window, [(300.5, 300.5), (340.5, 300.5)])
    flat = doc.flatten_edit()
    np.testing.assert_array_equal(flat[298:303, 300:341], flat[38:43, 40:81])
    shot(window, "07_clone_stamp")

    qtbot.keyClick(window.canvas, Qt.Key.Key_I)
    click(window.canvas, window.canvas.to_widget(470.5, 20.5))
    phys = doc.physical()
    for name, value in window.swatch_model.values.items():
        np.testing.assert_allclose(value, phys[name][20, 470], rtol=1e-6)


def test_autosave_and_restore_after_a_crash(qtbot, tmp_path) -> None:
    first = make_window(tmp_path)
    qtbot.addWidget(first)
    doc = open_sample(first)
    assert first.files.autosave() is None  # nothing changed yet
    stroke(first, [(50, 50), (250, 250)])
    recovery = first.files.autosave()
    assert recovery is not None and recovery.is_file()
    painted = doc.flatten_edit()
    first.session.set_document(None)  # "crash": no close, the recovery file stays

    second = make_window(tmp_path)
    qtbot.addWidget(second)
    second.prompts.restore_answer = True
    assert second.open_path(SAMPLE)
    assert second.prompts.kinds() == ["restore"]
    assert np.array_equal(second.session.doc.flatten_edit(), painted)
    assert second.session.modified  # restored work is not saved work
    second.prompts.save_answer = "discard"
    second.close()
    assert not recovery.exists()  # closed on purpose: nothing left to restore


def test_closing_with_unsaved_changes_asks(window) -> None:
    open_sample(window)
    window.close()  # unchanged: closes without a question
    assert "save_changes" not in window.prompts.kinds()
    window.show()
    open_sample(window)
    stroke(window, [(20, 20), (60, 20)])
    window.prompts.save_answer = "cancel"
    assert not window.close()
    assert window.isVisible() and window.session.doc is not None
    window.prompts.save_answer = "discard"
    assert window.close()
    assert window.prompts.kinds().count("save_changes") == 2


def test_closing_the_document_lets_go_of_the_memory_its_results_kept(window) -> None:
    """Results' memory is kept for reuse (``matshop.buffers``); a closed document's goes."""
    from matshop import buffers

    def pooled() -> int:
        return sum(b.nbytes for b in buffers._POOL._buffers)

    before = pooled()
    open_sample(window)
    stroke(window, [(20, 20), (60, 20)])
    window.canvas.flush()
    assert pooled() > before  # the sample's edit arrays came from the pool
    window.prompts.save_answer = "discard"
    assert window.files.close_document()
    assert window.session.doc is None
    assert pooled() <= before


def test_dropping_a_folder_opens_it(window) -> None:
    from PySide6.QtCore import QMimeData, QUrl
    from PySide6.QtGui import QDropEvent

    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(SAMPLE))])
    event = QDropEvent(
        QPointF(400, 300),
        Qt.DropAction.CopyAction,
        mime,
        Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
    )
    window.dropEvent(event)
    assert window.session.doc is not None and window.session.source_path == SAMPLE
    assert window.app_settings.recent_files()[0] == SAMPLE.resolve()


def test_undo_is_ignored_while_a_stroke_is_in_progress(window, qtbot) -> None:
    from PySide6.QtCore import QEvent

    from matshop.app.testing import _mouse

    open_sample(window)
    window.layer_commands.add_paint_layer()
    canvas = window.canvas
    left, none = Qt.MouseButton.LeftButton, Qt.MouseButton.NoButton
    plain = Qt.KeyboardModifier.NoModifier
    _mouse(canvas, QEvent.Type.MouseButtonPress, canvas.to_widget(50, 50), left, left, plain)
    _mouse(canvas, QEvent.Type.MouseMove, canvas.to_widget(90, 50), none, left, plain)
    qtbot.keyClick(canvas, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert window.tool.busy and window.session.steps == 1  # the paint layer is still there
    _mouse(canvas, QEvent.Type.MouseButtonRelease, canvas.to_widget(120, 50), left, none, plain)
    assert window.history_panel.labels()[-1] == "Paint" and window.session.steps == 2


def test_export_with_the_gltf_preset_writes_what_the_cli_writes(window, tmp_path) -> None:
    from matshop.cli import main

    doc = open_sample(window)
    stroke(window, [(30, 40), (200, 260), (420, 90)])
    window.layer_commands.add_filter_layer("blur", {"sigma_px": 2.0})
    window.prompts.save_path = tmp_path / "work.matshop"
    window.actions_by_name["save"].trigger()
    window.prompts.preset = "gltf"
    window.prompts.folder = tmp_path / "from_app"
    window.actions_by_name["export"].trigger()
    assert "preset" in window.prompts.kinds()  # the user was asked for a preset
    project, from_cli = tmp_path / "work.matshop", tmp_path / "from_cli"
    assert main(["export", str(project), str(from_cli), "--preset", "gltf"]) == 0
    app_files = {p.name: p.read_bytes() for p in sorted((tmp_path / "from_app").iterdir())}
    cli_files = {p.name: p.read_bytes() for p in sorted((tmp_path / "from_cli").iterdir())}
    assert app_files and app_files == cli_files
    assert any(name.endswith(".png") for name in app_files)
    assert len(doc) == 3


def test_the_tool_panel_scrolls_up_and_down_never_sideways(window) -> None:
    # a row wider than the dock (the mirror centre's boxes, the pressure curve) would hide
    # its right end behind a horizontal scroll bar
    area = window.tool_dock.widget()
    assert area.viewport().width() >= window.tool_panel.minimumSizeHint().width()
    assert area.horizontalScrollBar().maximum() == 0
