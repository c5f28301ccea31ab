"""Pen pressure through the real editor: the tool panel's pressure curve (edited with the
mouse on its plot) and its size / opacity / flow switches, then synthetic tablet events on
the canvas. Truth: each dab's radius and opacity equal the brush's setting times the curve at
the pen's pressure, the curve computed here with scipy's PchipInterpolator on the points the
plot holds (not with matshop's curve table), the radius from the painted area."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import QEvent, QPointF, Qt  # noqa: E402
from PySide6.QtGui import QPointingDevice, QTabletEvent  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402
from scipy.interpolate import PchipInterpolator  # noqa: E402

from matshop.app.testing import click, shown_window  # noqa: E402
from matshop.layers import Rect  # noqa: E402
from matshop.tools.settings import BrushSettings  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = os.environ.get("MATSHOP_SHOTS")
RADIUS_PX = 20.0
OPACITY = 0.8


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    yield win
    win.prompts.save_answer = "discard"


def tablet(canvas, kind: QEvent.Type, texel: tuple[float, float], pressure: float) -> None:
    pos = canvas.to_widget(*texel)
    release = kind == QEvent.Type.TabletRelease
    held = Qt.MouseButton.NoButton if release else Qt.MouseButton.LeftButton
    event = QTabletEvent(
        kind,
        QPointingDevice.primaryPointingDevice(),
        pos,
        QPointF(canvas.mapToGlobal(pos)),
        pressure,
        *(0.0,) * 5,
        Qt.KeyboardModifier.NoModifier,
        Qt.MouseButton.LeftButton,
        held,
    )
    QApplication.sendEvent(canvas, event)
    assert event.isAccepted()


def pen_stroke(canvas, points: list[tuple[float, float]], pressure: float) -> None:
    kinds = [QEvent.Type.TabletPress] + [QEvent.Type.TabletMove] * (len(points) - 1)
    for kind, point in zip(kinds, points, strict=True):
        tablet(canvas, kind, point, pressure)
    tablet(canvas, QEvent.Type.TabletRelease, points[-1], pressure)


def coverage(window, cx: int, cy: int, half: int = 40) -> np.ndarray:
    layer = window.session.active_layer
    return layer.coverage(Rect(cx - half, cy - half, cx + half, cy + half))


def test_pressure_drives_size_and_opacity_through_the_curve_drawn_in_the_panel(window) -> None:
    assert window.open_path(SAMPLE)
    settings = window.brush_settings
    settings.set("radius_px", RADIUS_PX)
    settings.set("hardness", 1.0)
    settings.set("opacity", OPACITY)
    settings.set("flow", 1.0)
    panel = window.tool_panel.brush_panel.pressure
    assert panel.targets["size"].isChecked() and not panel.targets["opacity"].isChecked()
    panel.targets["opacity"].click()
    assert settings.pressure_targets == {"size": True, "opacity": True, "flow": False}
    # a point added with a click on the plot bends the curve: light pressure does less
    editor = panel.editor
    click(editor.viewport(), editor.to_widget(0.5, 0.2))
    points = settings.pressure_curve.points
    assert len(points) == 3 and abs(points[1][0] - 0.5) < 0.03 and abs(points[1][1] - 0.2) < 0.03
    curve = PchipInterpolator(*np.array(points).T)
    canvas = window.canvas
    for n, pressure in enumerate((0.45, 0.7, 0.95)):
        cx, cy = 60 + 120 * n, 260
        pen_stroke(canvas, [(cx + 0.5, cy + 0.5)], pressure)  # one dab
        cover = coverage(window, cx, cy)
        factor = float(curve(pressure))
        assert cover[40, 40] == pytest.approx(OPACITY * factor, abs=2e-3)  # opacity x curve
        # a hard dab covers the area of its disc: the radius from the painted area
        radius = np.sqrt(cover.sum() / (OPACITY * factor * np.pi))
        assert radius == pytest.approx(RADIUS_PX * factor, abs=0.05)  # size x curve
    # the curve and switches are tool settings: saved with the editor state, read back
    saved = json.loads(json.dumps(settings.to_json()))
    again = BrushSettings()
    again.load_json(saved)
    assert again.pressure_curve == settings.pressure_curve
    assert again.pressure_targets == settings.pressure_targets
    if SHOTS:
        window.tool_dock.grab().save(str(Path(SHOTS) / "pressure_panel.png"))
        canvas.flush()
        canvas.grab().save(str(Path(SHOTS) / "pressure_dabs.png"))


def test_opacity_caps_a_stroke_and_flow_builds_it_up(window) -> None:
    """Overlapping dabs of one stroke at one pressure: with opacity following the pen the
    stroke stays at opacity x curve(p); with flow following it, it builds past it."""
    assert window.open_path(SAMPLE)
    settings = window.brush_settings
    for name, value in (("radius_px", 12.0), ("hardness", 1.0), ("opacity", 1.0)):
        settings.set(name, value)
    settings.set("spacing", 0.05)
    settings.set_pressure_curve([(0.0, 0.0), (0.4, 0.15), (1.0, 1.0)])
    curve = PchipInterpolator([0.0, 0.4, 1.0], [0.0, 0.15, 1.0])
    panel = window.tool_panel.brush_panel.pressure
    assert panel.model.points == ((0.0, 0.0), (0.4, 0.15), (1.0, 1.0))  # the plot follows
    panel.targets["size"].click()  # off: every dab has the full size
    pressure = 0.5
    factor = float(curve(pressure))
    results = {}
    for n, target in enumerate(("opacity", "flow")):
        for name, check in panel.targets.items():
            if check.isChecked() != (name == target):
                check.click()
        cx, cy = 80 + 200 * n, 300
        pen_stroke(window.canvas, [(cx - 4.5, cy + 0.5), (cx + 5.5, cy + 0.5)], pressure)
        results[target] = coverage(window, cx, cy)[40, 40]
    assert results["opacity"] == pytest.approx(factor, abs=2e-3)
    # flow: about 40 dabs of alpha f overlap here; alpha-over gives 1 - (1 - f)^k > f
    assert results["flow"] > 3 * factor
