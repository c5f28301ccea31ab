"""The 3D view's object-space mirror in the real editor: the dock's Mirror box turns the
X plane on, the widget shows the plane where it cuts the mesh (pixels along the cut's
projection, computed here from the camera, have the mirror colour), a drag paints both
sides as one undo step, and what it paints equals the drag plus the same drag mirrored
about the view's centre column with the mirror off (two independent strokes).

Run under a display with OpenGL 3.3 core (xvfb-run; Mesa llvmpipe is enough).
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("PySide6.QtOpenGLWidgets", reason="PySide6 (extra 'gui') not installed")
pytest.importorskip("OpenGL.GL", reason="PyOpenGL (extra 'gui') not installed")
pytest.importorskip("pytestqt")

from test_app_view3d import needs_display, open_sample, shot, window  # noqa: E402, F401

MIRROR_RGB = np.array([90, 200, 255])


def framebuffer(viewport) -> np.ndarray:
    """What the widget shows, ``(h, w, 3)`` uint8 (its own framebuffer, not a re-render)."""
    from PySide6.QtGui import QImage

    image = viewport.grabFramebuffer().convertToFormat(QImage.Format.Format_RGB888)
    w, h = image.width(), image.height()
    rows = np.frombuffer(image.constBits(), np.uint8).reshape(h, image.bytesPerLine())
    return rows[:, : 3 * w].reshape(h, w, 3).copy()


def cut_pixels(viewport) -> np.ndarray:
    """Widget pixels of the visible part of the circle where x = 0 cuts the unit sphere."""
    t = np.linspace(-np.pi, np.pi, 1441)
    circle = np.stack([0 * t, np.sin(t), np.cos(t)], axis=1)
    visible = np.sum(circle * (viewport.camera.eye() - circle), axis=1) > 0.05
    w, h = viewport.width(), viewport.height()
    pixels = viewport.camera.project(circle[visible], w, h)
    keep = (pixels.min(axis=1) >= 2) & (pixels[:, 0] < w - 2) & (pixels[:, 1] < h - 2)
    return pixels[keep]


def colour_near(image: np.ndarray, pixels: np.ndarray) -> float:
    """Share of ``pixels`` with a mirror-coloured pixel within one pixel."""
    hits = 0
    for x, y in pixels:
        c, r = int(x), int(y)
        block = image[max(r - 1, 0) : r + 2, max(c - 1, 0) : c + 2].astype(int)
        hits += bool((np.abs(block - MIRROR_RGB).max(axis=-1) < 40).any())
    return hits / len(pixels)


@needs_display
def test_the_3d_mirror_paints_both_sides_in_one_step_and_shows_its_plane(window, qtbot):  # noqa: F811
    from PySide6.QtCore import Qt

    from matshop.app.testing import drag
    from matshop.layers import Rect
    from matshop.viewport.gl.mirror import MirrorPlane

    doc, viewport = open_sample(window, qtbot)
    dock = window.view3d
    window.set_tool("brush")
    window.brush_settings.set("radius_px", 6.0)
    window.brush_settings.set("hardness", 0.8)
    window.layer_commands.add_paint_layer()  # strokes go here: one step each
    layer = window.session.active_layer
    full = Rect(0, 0, doc.width, doc.height)

    pixels = cut_pixels(viewport)
    assert len(pixels) > 100
    assert colour_near(framebuffer(viewport), pixels) < 0.05  # no plane yet
    assert not dock.mirror_offset.isEnabled()
    dock.mirror_combo.setCurrentIndex(dock.mirror_combo.findData("x"))
    assert viewport.mirror_plane == MirrorPlane("x") and dock.mirror_offset.isEnabled()
    viewport.repaint()
    shown = colour_near(framebuffer(viewport), pixels)
    print(f"{shown:.3f} of {len(pixels)} pixels along the cut show the mirror colour")
    assert shown > 0.97

    qtbot.wait(100)  # the dock settles its width (its toolbar grew): then the view stays
    viewport.camera_moved = True  # as if the user had framed it: no refit on resize
    w, h = viewport.width(), viewport.height()
    cx, cy = w // 2, h // 2
    points = [(cx + 18.5 + 3 * i, cy - 20.5 + 14 * np.sin(i / 3.0)) for i in range(14)]
    mirrored = [(w - x, y) for x, y in points]  # pixel column c -> w - 1 - c
    steps = window.session.steps
    drag(viewport, points)
    assert window.session.steps == steps + 1
    assert window.history_panel.labels()[-1] == "Paint"
    symmetric = layer.coverage(full)
    viewport.camera.yaw = 30.0  # the picture: the plane at an angle, both halves of the stroke
    print(f"screenshot: {shot(window, 'view3d_mirror')}")
    viewport.camera.yaw = 0.0
    assert (viewport.width(), viewport.height()) == (w, h)  # the mirrored points still are

    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    qtbot.keyClick(window.canvas, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert window.session.steps == steps and not layer.coverage(full).any()  # both halves

    saved = window.editor_state()  # what a project keeps: the plane, chosen again on open
    assert saved["view3d_mirror"] == {"axis": "x", "offset": 0.0}
    dock.mirror_combo.setCurrentIndex(dock.mirror_combo.findData(None))
    assert viewport.mirror_plane is None
    window.apply_editor_state({**saved, "view3d_mirror": {"axis": "z", "offset": 0.25}})
    assert viewport.mirror_plane == MirrorPlane("z", 0.25)
    window.apply_editor_state({**saved, "view3d_mirror": {"axis": "w", "offset": "far"}})
    assert viewport.mirror_plane is None and dock.mirror_offset.value() == 0.0
    drag(viewport, points)
    alone = layer.coverage(full)
    window.session.history.undo()
    drag(viewport, mirrored)
    second = layer.coverage(full)
    assert (viewport.width(), viewport.height()) == (w, h)
    # the mesh shown is mirror-symmetric with a mirrored layout: the vertex at (-x, y, z)
    # has u -> 1 - u, so texel column j mirrors to W - 1 - j (checked here, not assumed)
    mesh = viewport._mesh
    twins, found = mirror_twins(mesh.positions)
    assert found.mean() > 0.99
    # (the u = 0 / 1 seam and the poles hold several uvs at one point: left out)
    seam = (mesh.uvs[:, 0] < 1e-6) | (mesh.uvs[:, 0] > 1 - 1e-6)
    plain = found & ~seam & (np.abs(mesh.positions[:, 1]) < 0.99)
    # most vertices are checked: 0.90 of the built-in sphere (shown without the shared
    # meshes), more of the shared sphere.obj
    assert plain.mean() > 0.85
    assert np.abs(mesh.uvs[twins, 0] - (1.0 - mesh.uvs[:, 0]))[plain].max() < 1e-5

    def union(a, b):
        return 1.0 - (1.0 - a) * (1.0 - b)

    assert alone.max() > 0.79 and second.max() > 0.79
    flip = np.abs(symmetric - union(alone, np.flip(alone, axis=1)))
    print(f"mirror vs the stroke and its flip: max {flip.max():.4f}, mean {flip.mean():.1e}")
    assert flip.max() < 0.06  # the rasterisation tolerance of tests/test_viewport_gl_mirror.py
    # the independent drag at the mirrored pixels: the same paint, texel for texel except
    # at the stroke's far end, where its own dab walk ends up to one step off (its texel
    # sizes come from the other side's triangles, not quite mirror images on this mesh)
    error = np.abs(symmetric - union(alone, second))
    print(f"mirror vs two drags: max |error| {error.max():.4f}, mean {error.mean():.2e}")
    assert error.mean() < 2e-4 and np.count_nonzero(error > 0.06) < 100
    assert symmetric.sum() == pytest.approx(alone.sum() + second.sum(), rel=0.02)


def mirror_twins(positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For every vertex, the index of the vertex at its mirror image (-x, y, z), and whether
    there is one (within 1e-5)."""
    from scipy.spatial import cKDTree

    distance, index = cKDTree(positions).query(positions * np.array([-1.0, 1.0, 1.0]))
    return index, distance < 1e-5
