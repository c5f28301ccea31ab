"""Picking and painting on the mesh in the OpenGL viewport.

Truth: the analytic unit sphere of the reference scene (ray-sphere
intersection and its longitude/latitude texture coordinates, computed here
with numpy), not the picking pass under test. Mouse events go through Qt
(pytest-qt) into the widget, the brush engine and the layer document.
Skips only when no OpenGL 3.3 core context can be created (run under xvfb-run).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from gl_testing import require_gl

require_gl()  # skips the module, saying why, without pytest-qt or an OpenGL 3.3 context

from PySide6.QtCore import QPoint, Qt  # noqa: E402

from matshop.io.material_io import load_material  # noqa: E402
from matshop.layers import AddLayer, Document, History  # noqa: E402
from matshop.paint import Brush, Swatch  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
OUT = ROOT / "test-output"
SIZE = 256
RED = Swatch(
    "red",
    {
        "base_color": (0.9, 0.05, 0.05),
        "metallic": (0.0,),
        "roughness": (0.5,),
        "normal": (0.0, 0.0, 1.0),
        "ao": (1.0,),
    },
)


@pytest.fixture
def painted(gl_context, qtbot):
    """A viewport on the bundled sample (512^2) with an empty paint layer and a red brush."""
    from matshop.viewport.gl.view import MaterialViewport

    material, _ = load_material(SAMPLE)
    doc = Document.from_material(material)
    history = History(doc)
    layer = doc.new_paint_layer("paint")
    history.push(AddLayer(layer))
    widget = MaterialViewport()
    widget.resize(SIZE, SIZE)
    qtbot.addWidget(widget)
    widget.show()
    qtbot.waitExposed(widget)
    widget.set_document(doc)
    widget.set_brush(layer.id, Brush(radius_px=6.0, hardness=0.9, spacing=0.1), RED, history)
    return widget, doc, layer, history


def _sphere_uv(camera, x: float, y: float) -> np.ndarray:
    """Texture coordinates where the ray through widget point (x, y) meets the unit sphere."""
    origin = camera.eye()
    d = camera.ray(x, y, SIZE, SIZE)
    b = d @ origin
    t = -b - np.sqrt(b * b - (origin @ origin - 1.0))
    n = origin + t * d
    return np.array([0.5 + np.arctan2(n[0], n[2]) / (2 * np.pi), 0.5 + np.arcsin(n[1]) / np.pi])


def _alpha(doc, layer) -> np.ndarray:
    return layer.pixels.to_array()[..., -1]


def test_click_at_a_known_surface_point_paints_at_its_uv(painted, qtbot):
    widget, doc, layer, history = painted
    lon, lat = np.radians(-25.0), np.radians(20.0)
    point = np.array([np.sin(lon) * np.cos(lat), np.sin(lat), np.cos(lon) * np.cos(lat)])
    x, y = widget.camera.project(point, SIZE, SIZE)
    ix, iy = int(x), int(y)
    # the pick reads the pixel whose centre is (ix + 1/2, iy + 1/2)
    expected = _sphere_uv(widget.camera, ix + 0.5, iy + 0.5)
    known = np.array([0.5 + lon / (2 * np.pi), 0.5 + lat / np.pi])
    picked = np.array(widget.uv_at(ix, iy))
    print(f"picked uv {picked}, ray-sphere {expected}, the known point {known}")
    assert picked == pytest.approx(expected, abs=1e-3)  # 1e-3 = half a texel at 512
    assert picked == pytest.approx(known, abs=4e-3)  # within the pixel's footprint

    qtbot.mouseClick(widget, Qt.MouseButton.LeftButton, pos=QPoint(ix, iy))
    alpha = _alpha(doc, layer)
    rows, cols = np.nonzero(alpha > 0)
    weights = alpha[rows, cols]
    centre = np.array(
        [np.average(cols + 0.5, weights=weights), np.average(rows + 0.5, weights=weights)]
    )
    target = np.array([expected[0] * doc.width, (1.0 - expected[1]) * doc.height])
    print(f"dab centroid {centre} texels, expected {target}; {rows.size} texels painted")
    assert np.abs(centre - target).max() < 1.0
    assert alpha.max() == pytest.approx(1.0)
    # the flattened document shows the swatch there, and one undo takes it all back
    flat = doc.physical(doc.layout.bounds)["base_color"]
    assert flat[int(target[1]), int(target[0])] == pytest.approx(RED.values["base_color"], abs=1e-3)
    history.undo()
    assert not _alpha(doc, layer).any()


def test_a_stroke_across_the_uv_seam_leaves_no_gap(painted, qtbot):
    import cv2

    widget, doc, layer, history = painted
    widget.camera.yaw = 180.0  # look at the back: the u = 0 / 1 seam runs down the middle
    y = SIZE // 2
    x0, x1 = SIZE // 2 - 40, SIZE // 2 + 40
    start, end = widget.uv_at(x0, y), widget.uv_at(x1, y)
    assert start[0] > 0.9 and end[0] < 0.1  # the stroke really crosses the seam
    qtbot.mousePress(widget, Qt.MouseButton.LeftButton, pos=QPoint(x0, y))
    for x in range(x0 + 4, x1 + 1, 4):
        qtbot.mouseMove(widget, QPoint(x, y))
    qtbot.mouseRelease(widget, Qt.MouseButton.LeftButton, pos=QPoint(x1, y))
    alpha = _alpha(doc, layer)
    # texture space: the row of the stroke is painted all the way from start to end
    row = int((1.0 - 0.5 * (start[1] + end[1])) * doc.height)
    first, last = int(start[0] * doc.width), int(end[0] * doc.width)
    span = np.concatenate([alpha[row, first:], alpha[row, : last + 1]])
    print(f"row {row}: {span.size} texels across the seam, min alpha {span.min():.3f}")
    assert span.size > 20 and span.min() > 0.99
    # screen: every pixel along the stroke shows the red swatch, seam included
    image = widget.render_image(SIZE)[..., :3].astype(np.int16)
    OUT.mkdir(exist_ok=True)
    cv2.imwrite(str(OUT / "viewport_gl_seam_stroke.png"), image[..., ::-1].astype(np.uint8))
    line = image[y, x0 + 3 : x1 - 3]
    redness = line[:, 0] - line[:, 1]
    print(f"screen: min red - green along the stroke {redness.min()}")
    assert redness.min() > 60


def test_dabs_are_balls_on_the_surface_across_the_seam(painted):
    """One dab centred on the seam paints the same extent on both sides of it."""
    widget, doc, layer, history = painted
    widget.camera.yaw = 180.0
    # step right from the centre until the seam is crossed (u falls from ~1 to ~0)
    steps = np.arange(SIZE / 2, SIZE, 0.25)
    x = next((x for x in steps if widget.uv_at(x, SIZE / 2)[0] <= 0.5), None)
    assert x is not None, "no seam right of the centre"
    widget.painter.press(x - 0.25, SIZE / 2)
    widget.painter.release()
    alpha = _alpha(doc, layer)
    painted_cols = np.nonzero(alpha.any(axis=0))[0]
    left = np.sum(painted_cols >= doc.width // 2)
    right = np.sum(painted_cols < doc.width // 2)
    print(f"dab on the seam: {left} columns before u = 1, {right} after u = 0")
    assert left > 3 and right > 3 and abs(left - right) <= 2


def test_without_a_brush_the_left_button_orbits_and_the_wheel_zooms(painted, qtbot):
    widget, doc, layer, history = painted
    widget.set_brush(None)
    qtbot.mousePress(widget, Qt.MouseButton.LeftButton, pos=QPoint(100, 128))
    qtbot.mouseMove(widget, QPoint(150, 128))
    qtbot.mouseRelease(widget, Qt.MouseButton.LeftButton, pos=QPoint(150, 128))
    assert widget.camera.yaw == pytest.approx(360.0 - 50 * 0.4)
    assert not _alpha(doc, layer).any()  # nothing painted
    before = widget.camera.distance
    from PySide6.QtCore import QPointF
    from PySide6.QtGui import QWheelEvent

    event = QWheelEvent(
        QPointF(128, 128),
        QPointF(128, 128),
        QPoint(0, 0),
        QPoint(0, 120),
        Qt.MouseButton.NoButton,
        Qt.KeyboardModifier.NoModifier,
        Qt.ScrollPhase.NoScrollPhase,
        False,
    )
    widget.wheelEvent(event)
    assert widget.camera.distance == pytest.approx(before / 1.1)
