"""The layers and history panels driven like a user would, the ``matshop open`` verb,
and a session on the real 2K chessboard set (skipped when the data is absent)."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop.app.testing import click, drag, shown_window  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
CHESSBOARD = ROOT.parent / "shared" / "data" / "chessboard"
SHOTS = ROOT / "test-output" / "screenshots"


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    yield win
    win.prompts.save_answer = "discard"


def test_rename_hide_blend_and_parameters_through_the_layers_panel(window) -> None:
    assert window.open_path(SAMPLE)
    doc = window.session.doc
    window.layer_commands.add_paint_layer()
    panel = window.layers_panel
    layer = window.session.active_layer
    row = panel.index_of(layer.id)
    panel.model.setData(row, "Scratches", Qt.ItemDataRole.EditRole)  # what the editor commits
    assert layer.name == "Scratches" and row.data() == "Scratches"
    row = panel.index_of(layer.id)
    panel.model.setData(row, Qt.CheckState.Unchecked, Qt.ItemDataRole.CheckStateRole)
    assert not layer.visible and row.data(Qt.ItemDataRole.CheckStateRole) == Qt.CheckState.Unchecked
    panel.blend.setCurrentIndex(panel.blend.findData("detail"))
    panel.blend.activated.emit(panel.blend.currentIndex())
    assert layer.blend == "detail" and panel.linear.text() == "linear"
    panel.param_buttons["roughness"].click()  # untick: every parameter but roughness
    assert layer.parameters == tuple(n for n in doc.schema.names if n != "roughness")
    labels = window.history_panel.labels()
    assert labels[-4:] == ["Rename layer", "Layer visibility", "Blend mode", "Layer parameters"]
    # one undo per change, in reverse
    for check in (
        lambda: layer.parameters is None,
        lambda: layer.blend == "normal",
        lambda: layer.visible,
        lambda: layer.name != "Scratches",
    ):
        window.session.undo()
        assert check()


def test_clicking_a_history_row_jumps_there_and_back(window) -> None:
    assert window.open_path(SAMPLE)
    doc = window.session.doc
    opened = doc.flatten_edit()
    canvas = window.canvas
    drag(canvas, [canvas.to_widget(50, 50), canvas.to_widget(300, 300)])
    window.layer_commands.add_filter_layer("blur", {"sigma_px": 2.0})
    final = doc.flatten_edit()
    history = window.history_panel.list
    assert history.count() == 4  # Open, add layer, paint, add filter
    history.setCurrentRow(0)
    assert np.array_equal(doc.flatten_edit(), opened) and window.session.steps == 0
    assert history.count() == 4  # undone steps stay listed for redo
    history.setCurrentRow(3)
    assert np.array_equal(doc.flatten_edit(), final)


def test_matshop_open_verb_parses_a_path_or_none() -> None:
    from matshop.cli import build_parser
    from matshop.cli.verbs import open as open_verb

    argv = ["open", str(SAMPLE)]
    args = build_parser(argv).parse_args(argv)
    assert args.run is open_verb.run and args.path == SAMPLE
    assert build_parser(["open"]).parse_args(["open"]).path is None


@pytest.mark.skipif(not CHESSBOARD.is_dir(), reason="../shared/data/chessboard is not present")
def test_a_session_on_the_2k_chessboard(window, qtbot, capsys) -> None:
    start = time.perf_counter()
    assert window.open_path(CHESSBOARD)
    opened_s = time.perf_counter() - start
    doc = window.session.doc
    assert doc.size == (2048, 2048)
    canvas = window.canvas
    canvas.flush()
    window.brush_settings.set("radius_px", 24.0)
    before = doc.flatten_edit()
    cache = canvas.cache
    start = time.perf_counter()
    click(canvas, canvas.to_widget(1000.0, 1000.0))  # new paint layer + one dab
    dab_s = time.perf_counter() - start
    stale = int(cache.pending.sum())
    start = time.perf_counter()
    converted = cache.refresh(budget_s=None)
    redraw_s = time.perf_counter() - start
    assert stale <= 4 and sum(rect.area for rect in converted) == stale * 64 * 64
    assert not np.array_equal(doc.flatten_edit(), before)
    # a filter slider tick on 2K: the canvas converts a budgeted slice, not all of it
    window.layer_commands.add_filter_layer("blur", {"sigma_px": 3.0})
    start = time.perf_counter()
    canvas._refresh_some()
    slice_s = time.perf_counter() - start
    assert cache.busy  # the rest is left for the next turns of the event loop
    canvas.flush()
    window.show_parameter("normal")
    canvas.flush()
    QApplication.processEvents()  # panels rebuilt for the new document show up
    SHOTS.mkdir(parents=True, exist_ok=True)
    window.grab().save(str(SHOTS / "08_chessboard_2k_normal.png"))
    qtbot.keyClick(canvas, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClick(canvas, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert np.array_equal(doc.flatten_edit(), before)
    with capsys.disabled():
        print(
            f"\n2K chessboard: open {opened_s * 1e3:.0f} ms, dab (incl. new layer) "
            f"{dab_s * 1e3:.1f} ms, redraw {stale} tile(s) {redraw_s * 1e3:.1f} ms, "
            f"first blur slice {slice_s * 1e3:.1f} ms"
        )


def _tablet(canvas, kind, texel, pressure: float) -> None:
    from PySide6.QtCore import QEvent, QPointF
    from PySide6.QtGui import QPointingDevice, QTabletEvent

    pos = canvas.to_widget(*texel)
    held = (
        Qt.MouseButton.NoButton if kind == QEvent.Type.TabletRelease else Qt.MouseButton.LeftButton
    )
    event = QTabletEvent(
        kind,
        QPointingDevice.primaryPointingDevice(),
        pos,
        QPointF(canvas.mapToGlobal(pos)),
        pressure,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        Qt.KeyboardModifier.NoModifier,
        Qt.MouseButton.LeftButton,
        held,
    )
    QApplication.sendEvent(canvas, event)
    assert event.isAccepted()  # accepted: Qt synthesises no mouse events on top


def test_pen_pressure_from_tablet_events_sets_the_dab_size(window) -> None:
    from PySide6.QtCore import QEvent

    assert window.open_path(SAMPLE)
    doc = window.session.doc
    window.brush_settings.set("radius_px", 20.0)
    window.brush_settings.set("hardness", 1.0)
    before = doc.flatten_edit()
    canvas = window.canvas
    for kind, x, pressure in (
        (QEvent.Type.TabletPress, 100, 1.0),
        (QEvent.Type.TabletMove, 200, 1.0),
        (QEvent.Type.TabletMove, 300, 0.25),
        (QEvent.Type.TabletRelease, 400, 0.25),
    ):
        _tablet(canvas, kind, (x + 0.5, 200.5), pressure)
    changed = np.any(doc.flatten_edit() != before, axis=-1)
    width_full = int(changed[:, 150].sum())
    width_light = int(changed[:, 390].sum())
    assert width_full >= 40 and width_light <= 16  # radius follows the pen pressure
    assert window.session.steps == 2  # the new paint layer, then the stroke
