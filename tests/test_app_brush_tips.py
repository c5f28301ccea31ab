"""Brush tips and stencils in the real editor (pytest-qt, Xvfb).

- The tool panel's Tip box picks a built-in tip, follow-stroke rotation and jitter; a drag
  on the canvas paints with them, and the stroke the brush tool records, written to a
  stroke file, replays through `matshop paint` to the editor's layer bytes exactly.
- A stencil loaded from the panel (the file dialog answered by script) is drawn over the
  canvas half transparent; Place + drag moves it, the wheel scales it, Shift+wheel turns
  it. A drag across a half-black stencil paints exactly the texels whose *screen* position
  is under its white half (read back from the document, against the same drag without
  it); a black stencil blocks every dab (no undo step).
- An unreadable tip file is one status-bar line; loading a 4K stencil never stalls the
  event loop past 250 ms of GUI-thread CPU.
"""

from __future__ import annotations

import gc
import json
import math
import os
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import QPoint, QPointF, Qt  # noqa: E402
from PySide6.QtGui import QWheelEvent  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop.app.testing import Heartbeat, drag, shown_window, spin  # noqa: E402
from matshop.cli import main  # noqa: E402
from matshop.io.project import load_project  # noqa: E402
from matshop.layers import Rect  # noqa: E402
from matshop.paint import Brush, StrokeSample, StrokeSession  # noqa: E402
from matshop.viewport.canvas import WHEEL_STEP  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = Path(os.environ["MATSHOP_SHOTS"]) if os.environ.get("MATSHOP_SHOTS") else None


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    assert win.open_path(SAMPLE)
    win.canvas.actual_size()
    win.canvas.flush()
    yield win
    win.prompts.save_answer = "discard"


def choose(qtbot, combo, label: str) -> None:
    """Pick ``label`` in a combo box with the keyboard, as a user can."""
    combo.setFocus()
    for _ in range(combo.count()):
        if combo.currentText() == label:
            return
        qtbot.keyClick(combo, Qt.Key.Key_Down)
    raise AssertionError(
        f"{label!r} not offered: {[combo.itemText(i) for i in range(combo.count())]}"
    )


def wheel(widget, pos: QPointF, notches: float, shift: bool = False) -> None:
    modifiers = Qt.KeyboardModifier.ShiftModifier if shift else Qt.KeyboardModifier.NoModifier
    event = QWheelEvent(
        pos,
        QPointF(widget.mapToGlobal(pos.toPoint())),
        QPoint(0, 0),
        QPoint(0, round(120 * notches)),
        Qt.MouseButton.NoButton,
        modifiers,
        Qt.ScrollPhase.NoScrollPhase,
        False,
    )
    QApplication.sendEvent(widget, event)


def layer_pixels(layer, doc) -> bytes:
    return layer.pixels.read(Rect(0, 0, doc.width, doc.height)).tobytes()


def wave(win, x0: float, y0: float, length: float, count: int = 16) -> list[QPointF]:
    return [
        win.canvas.to_widget(x0 + length * i / (count - 1), y0 + 18 * math.sin(i / 2.0))
        for i in range(count)
    ]


def test_a_tip_from_the_panel_paints_and_replays_through_the_cli(window, qtbot, tmp_path):
    panel = window.tool_panel.tip_panel
    choose(qtbot, panel.kind, "Scratches")
    choose(qtbot, panel.rotation, "Follow stroke")
    panel.sliders["size_jitter"].box.setValue(0.35)
    panel.sliders["angle_jitter_deg"].box.setValue(20)
    panel.sliders["scatter_across"].box.setValue(0.3)
    panel.seed.setValue(6)
    tips = window.brush_settings.tips
    assert (tips.kind, tips.rotation, tips.tip_seed) == ("scratches", "follow", 6)
    # the preview shows the tip: its mean gray is the tip image's
    shown = panel.preview.pixmap().toImage()
    gray = np.array(
        [
            [shown.pixelColor(x, y).red() for x in range(shown.width())]
            for y in range(shown.height())
        ]
    )
    assert abs(gray.mean() / 255 - tips.tip().image.mean()) < 0.03
    # saved with the project's editor state, restored into fresh settings
    from matshop.tools.settings import BrushSettings

    restored = BrushSettings()
    restored.load_json(json.loads(json.dumps(window.brush_settings.to_json())))
    assert restored.tips.to_json() == tips.to_json()
    assert restored.brush().tip.source == {"procedural": "scratches", "seed": 6}
    window.brush_settings.set("radius_px", 22.0)
    window.brush_settings.set("spacing", 0.3)
    window.swatch_model.set_value("base_color", (0.9, 0.8, 0.2))

    assert window.layer_commands.add_paint_layer() is not None
    project = tmp_path / "before.matshop"
    assert window.files.save_to(project)
    doc = window.session.doc
    layer = window.session.active_layer
    seed = tips.stroke_seed
    drag(window.canvas, wave(window, 60, 150, 380))
    record = window.tools["brush"].last_stroke
    assert record is not None and record["seed"] == seed and tips.stroke_seed == seed + 1
    assert record["brush"]["tip"] == {"procedural": "scratches", "seed": 6}
    assert record["brush"]["rotation"] == "follow" and record["layer"] == layer.name
    painted = layer_pixels(layer, doc)
    coverage = layer.coverage(Rect(0, 0, doc.width, doc.height))
    assert coverage.max() > 0.5

    # the same samples with the round dab paint something else: the tip is in the pixels
    round_brush = Brush(
        radius_px=22.0, spacing=0.3, hardness=window.brush_settings.values["hardness"]
    )
    plain = load_project(project).document
    plain_layer = next(x for x in plain.layers if x.name == layer.name)
    session = StrokeSession(plain, plain_layer.id, round_brush, swatch=window.swatch_model.swatch())
    session.add([StrokeSample(*p) for p in record["points"]])
    session.end()
    assert np.abs(plain_layer.coverage(Rect(0, 0, doc.width, doc.height)) - coverage).max() > 0.3

    strokes = tmp_path / "stroke.json"
    strokes.write_text(json.dumps(record))
    assert main(["paint", str(project), "--stroke", str(strokes)]) == 0
    replayed = load_project(project).document
    again = next(x for x in replayed.layers if x.name == layer.name)
    assert layer_pixels(again, replayed) == painted  # byte for byte
    if SHOTS is not None:
        window.canvas.flush()
        window.canvas.grab().save(str(SHOTS / "tips_canvas.png"))
        window.tool_panel.grab().save(str(SHOTS / "tips_panel.png"))


def write_half_stencil(path: Path) -> None:
    image = np.zeros((200, 240), np.uint8)
    image[:, 120:] = 255  # white (paint passes) on the right half
    cv2.imwrite(str(path), image)


def load_stencil_from_panel(window, qtbot, path: Path) -> None:
    window.prompts.image_path = path
    qtbot.mouseClick(window.tool_panel.stencil_panel.load, Qt.MouseButton.LeftButton)
    assert window.brush_settings.stencil.stencil is not None


def test_a_half_stencil_placed_on_screen_paints_exactly_its_open_half(window, qtbot, tmp_path):
    canvas, doc = window.canvas, window.session.doc
    window.brush_settings.set("radius_px", 12.0)
    window.brush_settings.set("hardness", 0.4)
    window.swatch_model.set_value("base_color", (0.2, 0.5, 0.9))
    before = canvas.grab().toImage()
    path = tmp_path / "half.png"
    write_half_stencil(path)
    load_stencil_from_panel(window, qtbot, path)
    settings = window.brush_settings.stencil
    assert window.tool_panel.stencil_panel.name.text() == "half.png"
    assert window.tool_label.text().endswith(", through the stencil")  # the status bar

    # drawn half transparent: the black half darkens the texture, the white half does not
    spin(50)
    after = canvas.grab().toImage()
    cx, cy = settings.centre
    half_w = 120 * settings.scale
    left = QPoint(round(cx - half_w / 2), round(cy))
    right = QPoint(round(cx + half_w / 2), round(cy))
    darker = before.pixelColor(left).lightness() - after.pixelColor(left).lightness()
    assert darker > 40, darker
    assert abs(before.pixelColor(right).lightness() - after.pixelColor(right).lightness()) < 6

    # placing: Place on, drag moves it, the wheel scales, Shift+wheel turns (and back)
    panel = window.tool_panel.stencil_panel
    qtbot.mouseClick(panel.place, Qt.MouseButton.LeftButton)
    assert settings.placing
    steps = window.session.steps
    drag(canvas, [QPointF(cx, cy), QPointF(cx + 20, cy + 10), QPointF(cx + 37, cy + 21)])
    assert settings.centre == pytest.approx((cx + 37, cy + 21))
    assert window.session.steps == steps  # placing paints nothing
    scale = settings.scale
    wheel(canvas, QPointF(cx, cy), 1)
    assert settings.scale == pytest.approx(scale * WHEEL_STEP**120)
    wheel(canvas, QPointF(cx, cy), 2, shift=True)
    assert settings.angle_deg == pytest.approx(30.0)
    assert panel.angle.box.value() == pytest.approx(30.0)
    panel.angle.box.setValue(0.0)
    assert settings.angle_deg == 0.0
    qtbot.mouseClick(panel.place, Qt.MouseButton.LeftButton)
    assert not settings.placing
    if SHOTS is not None:
        canvas.grab().save(str(SHOTS / "stencil_placed.png"))

    # a stroke across it, then the same drag without the stencil
    points = wave(window, 90, 200, 330)
    window.layer_commands.add_paint_layer()
    layer = window.session.active_layer
    drag(canvas, points)
    full = Rect(0, 0, doc.width, doc.height)
    stenciled = layer.coverage(full)
    if SHOTS is not None:
        canvas.flush()
        canvas.grab().save(str(SHOTS / "stencil_stroke.png"))
    qtbot.mouseClick(panel.clear, Qt.MouseButton.LeftButton)
    assert settings.stencil is None and "stencil" not in window.tool_label.text()
    qtbot.keyClick(canvas, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert not layer.coverage(full).any()
    drag(canvas, points)
    plain = layer.coverage(full)

    # where each texel centre is on the screen, and where the stencil's halves lie there
    ys, xs = np.mgrid[0 : doc.height, 0 : doc.width] + 0.5
    zoom = canvas.view.zoom
    sx = canvas.view.offset_x + xs * zoom
    sy = canvas.view.offset_y + ys * zoom
    cx, cy = settings.centre
    w, h = 240 * settings.scale, 200 * settings.scale
    on_sheet = (np.abs(sx - cx) < w / 2 - 2) & (np.abs(sy - cy) < h / 2 - 2)
    margin = 1.5 * zoom + settings.scale  # the bilinear seam, one texel and one stencil pixel
    open_ = on_sheet & (sx > cx + margin)
    shut = on_sheet & (sx < cx - margin)
    assert plain[open_].max() > 0.9 and plain[shut].max() > 0.9  # the drag crosses both
    assert not stenciled[shut].any()
    np.testing.assert_allclose(stenciled[open_], plain[open_], atol=1e-6, rtol=0)
    off_sheet = ~((np.abs(sx - cx) <= w / 2 + 2) & (np.abs(sy - cy) <= h / 2 + 2))
    np.testing.assert_allclose(stenciled[off_sheet], plain[off_sheet], atol=1e-6, rtol=0)


def test_a_black_stencil_blocks_every_dab(window, qtbot, tmp_path):
    path = tmp_path / "black.png"
    cv2.imwrite(str(path), np.zeros((64, 64), np.uint8))
    load_stencil_from_panel(window, qtbot, path)
    window.layer_commands.add_paint_layer()
    layer, doc = window.session.active_layer, window.session.doc
    cx, cy = window.brush_settings.stencil.centre
    steps = window.session.steps
    drag(window.canvas, [QPointF(cx - 60 + 8 * i, cy + 5 * math.sin(i)) for i in range(16)])
    assert window.session.steps == steps  # nothing painted: no undo step
    assert not layer.coverage(Rect(0, 0, doc.width, doc.height)).any()


def test_an_unreadable_tip_is_one_status_line(window, qtbot, tmp_path):
    bad = tmp_path / "broken.png"
    bad.write_text("not a png")
    window.prompts.image_path = bad
    qtbot.mouseClick(window.tool_panel.tip_panel.load, Qt.MouseButton.LeftButton)
    message = window.statusBar().currentMessage()
    assert "broken.png" in message and "\n" not in message, message
    assert window.brush_settings.tips.kind == "round"  # the brush as it was


def timed(obj, names) -> dict[str, list[float]]:
    """Wrap ``obj``'s methods ``names`` to record each call's GUI-thread CPU time."""
    spent: dict[str, list[float]] = {}
    for name in names:
        method = getattr(obj, name)
        spent[name] = []

        def wrapper(*args, _method=method, _into=spent[name], **kwargs):
            start = time.thread_time()
            try:
                return _method(*args, **kwargs)
            finally:
                _into.append(time.thread_time() - start)

        setattr(obj, name, wrapper)
    return spent


@pytest.mark.serial
def test_loading_a_4k_stencil_and_painting_a_big_tip_never_stall(
    warm_kernels, window, qtbot, tmp_path
):
    rng = np.random.default_rng(0)
    big = tmp_path / "big.png"
    cv2.imwrite(str(big), (rng.random((4096, 4096)) * 255).astype(np.uint8))
    window.prompts.image_path = big
    beat = Heartbeat()
    panel = window.tool_panel.stencil_panel
    _, wall, cpu = beat.measure(
        lambda: qtbot.mouseClick(panel.load, Qt.MouseButton.LeftButton),
        lambda: window.brush_settings.stencil.stencil is not None,
    )
    print(f"4K stencil: longest stall {wall * 1000:.0f} ms wall, {cpu * 1000:.0f} ms CPU")
    assert cpu < 0.25
    window.brush_settings.set("radius_px", 200.0)
    choose(qtbot, window.tool_panel.tip_panel.kind, "Noise")
    choose(qtbot, window.tool_panel.tip_panel.rotation, "Random")
    # pointer events arrive one by one (the event loop runs between them); the heap a long
    # test session leaves behind is frozen first, so a full garbage collection of it (a
    # second in the full suite, nothing an editor session has) does not count as painting
    points = wave(window, 60, 200, 400, 12)
    spent = timed(window.tools["brush"], ("press", "move", "release"))
    spent.update(timed(window.canvas, ("paintEvent",)))
    gc.collect()
    gc.freeze()
    try:
        _, wall, cpu = beat.measure(lambda: drag(window.canvas, points, pause_ms=20), lambda: True)
    finally:
        gc.unfreeze()
    where = ", ".join(f"{name} {max(t, default=0) * 1000:.0f}" for name, t in spent.items())
    report = (
        f"r=200 tip stroke over a 4K stencil: {wall * 1000:.0f} ms wall, {cpu * 1000:.0f} ms "
        f"CPU; longest GUI-thread CPU per call (ms): {where}; load {os.getloadavg()[0]:.1f}"
    )
    print(report)
    assert cpu < 0.25, report
