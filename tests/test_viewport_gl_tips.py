"""Brush tips in the 3D view: a tip dab on a plane facing the camera is the 2D tip dab.

Truth: the tip's own pixels, turned and scaled to the dab by a formula written
here (scipy's bilinear ``map_coordinates`` at each texel centre), at the texel
position of the uv picked under the cursor; and the 2D brush engine's stroke at
that texel position. The mesh is a square plane z = 0 with uv = (x + 1, y + 1) / 2
(texel size uniform), so the tangent-plane offsets of a 3D dab are texel offsets.
Mouse events go through Qt (pytest-qt) into the real widget.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from gl_testing import require_gl

require_gl()  # skips the module, saying why, without pytest-qt or an OpenGL 3.3 context

from PySide6.QtCore import QPoint, Qt  # noqa: E402
from scipy import ndimage  # noqa: E402

from matshop.io.material_io import load_material  # noqa: E402
from matshop.layers import AddLayer, Document, History  # noqa: E402
from matshop.paint import Brush, Swatch  # noqa: E402
from matshop.paint.dynamics import DabShaper, Dynamics  # noqa: E402
from matshop.paint.painter import StrokeSession  # noqa: E402
from matshop.paint.stroke import StrokeSample  # noqa: E402
from matshop.paint.tips import Tip  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SIZE = 256
RED = Swatch("red", {"base_color": (0.9, 0.05, 0.05)})


def _tip_image() -> np.ndarray:
    """24 x 16 pixels, no symmetry: a ramp across, a bar at the top, a dot at the right."""
    h, w = 16, 24
    image = np.tile(np.linspace(0.2, 0.8, w, dtype=np.float32), (h, 1))
    image[1:4, 2:20] = 1.0
    image[9:13, 19:23] = 0.0
    return image


TIP = Tip(_tip_image(), {"image": "test-tip.png"})


def _plane():
    from matshop.viewport.gl.mesh_data import build

    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float64)
    uvs = (positions[:, :2] + 1.0) / 2.0
    normals = np.tile([0.0, 0.0, 1.0], (4, 1))
    return build(positions, uvs, [[0, 1, 2], [0, 2, 3]], normals=normals, name="plane")


def _document():
    material, _ = load_material(SAMPLE)
    doc = Document.from_material(material)
    history = History(doc)
    layer = doc.new_paint_layer("paint")
    history.push(AddLayer(layer))
    return doc, layer, history


@pytest.fixture
def plane_view(gl_context, qtbot):
    from matshop.viewport.gl.view import MaterialViewport

    doc, layer, history = _document()
    widget = MaterialViewport()
    widget.resize(SIZE, SIZE)
    qtbot.addWidget(widget)
    widget.show()
    qtbot.waitExposed(widget)
    widget.set_mesh(_plane())
    widget.set_document(doc)
    return widget, doc, layer, history


def _expected_dab(shape, x: float, y: float, radius_px: float, angle_deg: float) -> np.ndarray:
    """The tip turned ``angle_deg`` (counter-clockwise on screen, texel y down), its longer
    side 2 * radius texels, centred at texel point (x, y), sampled at texel centres."""
    image = TIP.image
    h, w = image.shape
    scale = 2.0 * radius_px / max(h, w)
    rows, cols = np.mgrid[0 : shape[0], 0 : shape[1]]
    dx, dy = cols + 0.5 - x, rows + 0.5 - y
    a = math.radians(angle_deg)
    # on screen (y down) a counter-clockwise turn R: the texel offset d shows pixel R^-1 d
    px = (math.cos(a) * dx - math.sin(a) * dy) / scale + w / 2.0
    py = (math.sin(a) * dx + math.cos(a) * dy) / scale + h / 2.0
    return ndimage.map_coordinates(
        image, [py - 0.5, px - 0.5], order=1, mode="grid-constant", cval=0.0
    )


def _alpha(layer) -> np.ndarray:
    return layer.pixels.to_array()[..., -1]


def _click_texel(widget, doc, qtbot, ix: int, iy: int) -> tuple[float, float]:
    u, v = widget.uv_at(ix, iy)
    qtbot.mouseClick(widget, Qt.MouseButton.LeftButton, pos=QPoint(ix, iy))
    return u * doc.width, (1.0 - v) * doc.height


@pytest.mark.parametrize("angle_deg", [0.0, 30.0, 90.0])
def test_a_3d_tip_dab_on_a_plane_is_the_2d_tip_dab(plane_view, qtbot, angle_deg):
    widget, doc, layer, history = plane_view
    radius = 18.0
    brush = Brush(radius_px=radius, tip=TIP, dynamics=Dynamics(angle_deg=angle_deg))
    widget.set_brush(layer.id, brush, RED, history)
    x, y = _click_texel(widget, doc, qtbot, 121, 133)
    painted = _alpha(layer)
    expected = _expected_dab(painted.shape, x, y, radius, angle_deg)
    err = np.abs(painted - expected).max()
    print(
        f"angle {angle_deg}: dab at texel ({x:.3f}, {y:.3f}), {np.count_nonzero(painted)} "
        f"texels painted, max |3D - formula| {err:.2e}"
    )
    assert expected.max() == pytest.approx(1.0)
    assert err < 2e-3
    # the 2D brush engine painting the same dab at that texel point
    doc2, layer2, _ = _document()
    session = StrokeSession(doc2, layer2.id, brush, swatch=RED)
    session.add([StrokeSample(x, y)])
    session.end()
    assert np.abs(painted - _alpha(layer2)).max() < 2e-3


def test_random_rotation_and_size_jitter_follow_the_stroke_seed(plane_view, qtbot):
    widget, doc, layer, history = plane_view
    dynamics = Dynamics(rotation="random", size_jitter=0.5, angle_jitter_deg=20.0)
    brush = Brush(radius_px=16.0, tip=TIP, dynamics=dynamics)
    widget.set_brush(layer.id, brush, RED, history)
    x, y = _click_texel(widget, doc, qtbot, 140, 110)
    # the first dab of seed 0 (the 3D view's stroke seed), drawn here from the same dynamics
    placed = DabShaper(dynamics, 0).place(x, y, 16.0, None)
    assert placed.radius_px < 16.0 and placed.angle_deg % 90.0 != 0.0
    painted = _alpha(layer)
    expected = _expected_dab(painted.shape, placed.x, placed.y, placed.radius_px, placed.angle_deg)
    err = np.abs(painted - expected).max()
    assert painted.max() > 0.5 and expected.max() > 0.5
    print(f"random: radius {placed.radius_px:.2f} angle {placed.angle_deg:.1f}: max err {err:.2e}")
    assert err < 2e-3


def _drag(qtbot, widget, points) -> None:
    qtbot.mousePress(widget, Qt.MouseButton.LeftButton, pos=QPoint(*points[0]))
    for p in points[1:]:
        qtbot.mouseMove(widget, QPoint(*p))
    qtbot.mouseRelease(widget, Qt.MouseButton.LeftButton, pos=QPoint(*points[-1]))


STROKE = [(60, 128), (100, 128), (140, 128), (196, 128)]


@pytest.mark.parametrize("tip", [None, TIP], ids=["round", "tip"])
def test_a_stencil_on_the_3d_view_masks_strokes_in_screen_space(plane_view, qtbot, tip):
    from matshop.paint.stencil import Stencil

    widget, doc, layer, history = plane_view
    widget.set_brush(layer.id, Brush(radius_px=10.0, spacing=0.1, tip=tip), RED, history)
    _drag(qtbot, widget, STROKE)
    plain = _alpha(layer)
    assert plain.max() > 0.5
    history.undo()
    # a black stencil over the whole widget: nothing is painted
    widget.set_stencil(Stencil(np.zeros((8, 8), np.float32), (SIZE / 2, SIZE / 2), SIZE / 4))
    _drag(qtbot, widget, STROKE)
    assert not _alpha(layer).any()
    # its left half shut, its right half open, split at widget x = 128
    half = np.zeros((SIZE, SIZE), np.float32)  # one stencil pixel a widget pixel
    half[:, SIZE // 2 :] = 1.0
    widget.set_stencil(Stencil(half, (SIZE / 2, SIZE / 2), 1.0))
    _drag(qtbot, widget, STROKE)
    masked = _alpha(layer)
    # texel columns on screen: the plane's texel x maps to widget x linearly (a facing plane)
    cols = np.arange(doc.width) + 0.5
    world_x = 2.0 * cols / doc.width - 1.0
    screen_x = widget.camera.project(np.stack([world_x, 0 * world_x, 0 * world_x], -1), SIZE, SIZE)[
        :, 0
    ]
    shut, open_ = screen_x < 127.5 - 0.5, screen_x > 128.5 + 0.5  # a pixel's blend at the edge
    print(f"{np.count_nonzero(plain)} texels plain; masked {np.count_nonzero(masked)}")
    assert not masked[:, shut].any()
    np.testing.assert_allclose(masked[:, open_], plain[:, open_], atol=1e-6)
    assert masked[:, open_].max() > 0.5


def test_a_mirrored_3d_tip_dab_is_the_dab_reflected(plane_view, qtbot):
    from matshop.viewport.gl.mirror import MirrorPlane

    widget, doc, layer, history = plane_view
    brush = Brush(radius_px=14.0, tip=TIP, dynamics=Dynamics(angle_deg=30.0))
    widget.set_brush(layer.id, brush, RED, history)
    widget.set_mirror(MirrorPlane("x"))  # world x = 0: texel x -> width - x on this plane
    x, y = _click_texel(widget, doc, qtbot, 90, 120)
    painted = _alpha(layer)
    alone = _expected_dab(painted.shape, x, y, 14.0, 30.0)
    expected = np.maximum(alone, np.flip(alone, axis=1))  # the two dabs do not overlap
    err = np.abs(painted - expected).max()
    print(f"mirrored tip dab: max |3D - (dab + its flip)| {err:.2e}")
    assert not np.any((alone > 0) & (np.flip(alone, axis=1) > 0))
    assert err < 2e-3
