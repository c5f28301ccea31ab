"""The editor's 3D view dock: a split view, painting on the mesh, dirty-tile uploads.

Run under a display with OpenGL 3.3 core (``xvfb-run -a python -m pytest``;
Mesa llvmpipe is enough). The GL tests skip, saying why, only when no such
context can be created; the no-GL fallback is checked in a subprocess on
Qt's offscreen platform, which has no OpenGL. Expected texels come from the
viewport's own picking pass (its correctness against the analytic sphere is
``tests/test_viewport_gl_paint.py``'s business). A screenshot of the split
view goes to ``test-output/screenshots/``.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6.QtOpenGLWidgets", reason="PySide6 (extra 'gui') not installed")
pytest.importorskip("OpenGL.GL", reason="PyOpenGL (extra 'gui') not installed")
pytest.importorskip("pytestqt")

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = ROOT / "test-output" / "screenshots"
GEOMETRY = ROOT.parent / "shared" / "data" / "geometry"
SWATCH = {
    "base_color": (0.9, 0.3, 0.05),
    "metallic": (0.0,),
    "roughness": (0.35,),
    "normal": (0.0, 0.0, 1.0),
    "ao": (1.0,),
}

# the offscreen fallback runs in a subprocess: it needs no display of its own
_HAS_DISPLAY = bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
needs_display = pytest.mark.skipif(
    not _HAS_DISPLAY, reason="no display for an OpenGL context: run under xvfb-run"
)


@pytest.fixture
def window(qtbot, tmp_path):
    if not _HAS_DISPLAY:
        pytest.skip("no display for an OpenGL context: run under xvfb-run")
    from PySide6.QtWidgets import QApplication

    from matshop.app.testing import make_window
    from matshop.app.theme import apply_theme
    from matshop.app.view3d import gl_problem

    apply_theme(QApplication.instance())
    problem = gl_problem()
    if problem is not None:
        pytest.skip(f"no OpenGL 3.3 core context can be created here: {problem}")
    win = make_window(tmp_path)
    qtbot.addWidget(win)
    win.resize(1560, 940)
    win.show()
    qtbot.waitExposed(win)
    win.activateWindow()
    yield win
    win.prompts.save_answer = "discard"


def open_sample(win, qtbot):
    """The bundled sample, the swatch set, the 3D view shown (F3's action) and drawn once."""
    assert win.open_path(SAMPLE)
    for name, value in SWATCH.items():
        win.swatch_model.set_value(name, value)
    win.actions_by_name["view3d"].trigger()
    viewport = win.view3d.viewport
    assert viewport is not None and win.view3d.isVisible()
    qtbot.waitExposed(viewport)
    qtbot.waitUntil(lambda: viewport.renderer is not None and viewport.renderer.textures)
    win.canvas.flush()
    return win.session.doc, viewport


def shot(win, name: str) -> Path:
    from PySide6.QtWidgets import QApplication

    from matshop.app.testing import spin

    win.canvas.flush()
    QApplication.processEvents()
    viewport = win.view3d.viewport
    end = time.perf_counter() + 60.0
    while viewport is not None and viewport.drawing and time.perf_counter() < end:
        spin(5)  # software GL draws a frame in bands: the shot shows the whole one
    SHOTS.mkdir(parents=True, exist_ok=True)
    path = SHOTS / f"{name}.png"
    assert win.grab().save(str(path))
    return path


@needs_display
def test_a_stroke_on_the_sphere_paints_the_document_and_undoes_as_one_step(window, qtbot):
    from PySide6.QtCore import Qt

    from matshop.app.testing import drag
    from matshop.layers import PaintLayer

    doc, viewport = open_sample(window, qtbot)
    window.set_tool("brush")
    window.brush_settings.set("radius_px", 6.0)
    window.brush_settings.set("hardness", 1.0)
    before = doc.flatten_edit()
    steps = window.session.steps
    w, h = viewport.width(), viewport.height()
    cx, cy = w / 2, h / 2
    points = [(cx - 40 + 4 * i, cy - 10) for i in range(21)]
    # where the stroke must land: the viewport's own picking of those pixels
    texels = []
    for x, y in points:
        hit = viewport._hit(x, y)
        assert hit is not None, "the stroke must lie on the sphere"
        texels.append(hit.texel(doc.width, doc.height))

    drag(viewport, points)

    after = doc.flatten_edit()
    changed = np.any(after != before, axis=-1)
    for tx, ty in texels:
        assert changed[int(ty), int(tx)], f"texel {tx:.1f},{ty:.1f} under the stroke unchanged"
    # nothing far from the stroke: every changed texel is within the brush of the path
    rows, cols = np.nonzero(changed)
    path = np.array(texels)
    near = np.min(np.hypot(cols[:, None] + 0.5 - path[:, 0], rows[:, None] + 0.5 - path[:, 1]), 1)
    assert near.max() < 6.0 + 4.0  # radius + a dab's spacing and the sphere's stretch
    # a fill layer was active: a paint layer was added (its own step), then ONE stroke step
    assert isinstance(window.session.active_layer, PaintLayer)
    assert window.session.steps == steps + 2
    assert window.history_panel.labels()[-1] == "Paint"
    # the 2D canvas shows the stroke too (same document, same dirty tiles)
    window.canvas.flush()
    tx, ty = texels[len(texels) // 2]
    shown = window.canvas.cache.buffer[int(ty), int(tx), :3].astype(int)
    codes = np.round(255 * np.array(SWATCH["base_color"]))  # the swatch holds the file's codes
    np.testing.assert_allclose(shown, codes, atol=1)
    # ... and so does the 3D view: the texture it samples was re-uploaded
    image = viewport.render_image((w, h))
    x, y = points[len(points) // 2]
    red, green = image[int(y), int(x), :2].astype(int)
    assert red > green + 40, "the painted orange must show on the sphere"
    path_png = shot(window, "view3d_split_painted")
    print(f"screenshot: {path_png}")

    window.activateWindow()  # Qt recreated the window for OpenGL: shortcuts need it active
    qtbot.waitUntil(window.isActiveWindow)
    qtbot.keyClick(window.canvas, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert window.session.steps == steps + 1, "Ctrl+Z undid the stroke step"
    assert np.array_equal(doc.flatten_edit(), before)  # bit-identical


@needs_display
def test_a_2d_dab_re_uploads_only_its_dirty_tiles(window, qtbot):
    from matshop.app.testing import click

    doc, viewport = open_sample(window, qtbot)
    window.layer_commands.add_paint_layer()
    viewport.render_image(64)  # the frame that uploads whatever was pending
    textures = viewport.renderer.textures
    dirty: set = set()
    doc.events.dirty.connect(lambda region: dirty.update(region.keys))
    sent_before = textures.bytes_uploaded
    window.brush_settings.set("radius_px", 10.0)
    click(window.canvas, window.canvas.to_widget(128.0, 128.0))  # on a tile corner: 4 tiles
    viewport.render_image(64)
    sent = textures.bytes_uploaded - sent_before
    expected = sum(textures.tile_bytes(key) for key in dirty)
    whole = doc.width * doc.height * 8 * len(textures.names)
    print(f"one 2D dab: {len(dirty)} tiles, {sent} bytes uploaded (whole set {whole})")
    assert len(dirty) == 4
    assert sent == expected
    assert sent < whole / 8


@needs_display
def test_the_mesh_choice_and_a_user_mesh(window, qtbot):
    doc, viewport = open_sample(window, qtbot)
    dock = window.view3d
    labels = [dock.mesh_combo.itemText(i) for i in range(dock.mesh_combo.count())]
    if GEOMETRY.is_dir():
        assert labels == ["Sphere", "Cube", "Plane"]
    else:
        assert labels == ["Sphere"]
    target = GEOMETRY / "cube.obj"
    if not target.is_file():
        pytest.skip("the shared cube.obj is not present")
    window.prompts.mesh_path = target
    assert dock.open_mesh()
    assert viewport._mesh.triangle_count == 12
    assert viewport.uv_at(viewport.width() / 2, viewport.height() / 2) is not None
    not_a_mesh = SAMPLE / "tiles_basecolor.png"
    assert not_a_mesh.is_file()
    window.prompts.mesh_path = not_a_mesh
    assert not dock.open_mesh()  # not a mesh: one line, the cube stays
    assert window.prompts.kinds()[-1] == "error"
    assert viewport._mesh.triangle_count == 12


@needs_display
def test_floating_the_dock_and_docking_it_again_keeps_the_view_working(window, qtbot):
    from PySide6.QtWidgets import QApplication

    doc, viewport = open_sample(window, qtbot)
    viewport.camera_moved = True  # the same view throughout, whatever the dock's shape
    front = viewport.render_image(96)
    for floating in (True, False):  # each move gives the viewport a new GL context
        window.view3d.setFloating(floating)
        QApplication.processEvents()
        qtbot.waitExposed(viewport)
        again = viewport.render_image(96)
        assert np.abs(again.astype(int) - front.astype(int)).max() <= 1
        assert viewport.uv_at(viewport.width() / 2, viewport.height() / 2) is not None
    # F3 hides and shows it; the action follows the dock's close button too
    action = window.actions_by_name["view3d"]
    action.trigger()
    assert not window.view3d.isVisible() and not action.isChecked()
    window.view3d.show()
    assert action.isChecked()


@needs_display
def test_the_eyedropper_picks_the_swatch_under_the_cursor_on_the_mesh(window, qtbot):
    from matshop.app.testing import click
    from matshop.layers import Rect

    doc, viewport = open_sample(window, qtbot)
    window.set_tool("eyedropper")
    x, y = viewport.width() / 2 + 30, viewport.height() / 2 - 50
    tx, ty = (int(t) for t in viewport._hit(x, y).texel(doc.width, doc.height))
    steps = window.session.steps
    click(viewport, (x, y))
    picked = window.swatch_model.swatch().values["base_color"]
    expected = doc.physical(Rect(tx, ty, tx + 1, ty + 1))["base_color"][0, 0]
    np.testing.assert_allclose(picked, expected, atol=1e-5)
    assert picked != pytest.approx(SWATCH["base_color"], abs=0.05)
    assert window.session.steps == steps  # a pick is no edit


_OFFSCREEN = textwrap.dedent(
    """
    import sys, tempfile
    from pathlib import Path
    from PySide6.QtWidgets import QApplication
    app = QApplication(sys.argv)
    from matshop.app.testing import make_window, click
    win = make_window(Path(tempfile.mkdtemp()))
    win.show()
    assert win.open_path(sys.argv[1])
    win.actions_by_name["view3d"].trigger()
    app.processEvents()
    assert win.view3d.isVisible() and win.view3d.viewport is None
    print("NOTE", win.view3d.note.text())
    before = win.session.doc.flatten_edit()
    click(win.canvas, win.canvas.to_widget(100.0, 100.0))  # the 2D editor still paints
    print("PAINTED", bool((win.session.doc.flatten_edit() != before).any()))
    win.prompts.save_answer = "discard"
    win.close()
    """
)


def test_without_opengl_the_dock_shows_one_line_and_the_editor_works(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["QT_QPA_PLATFORM"] = "offscreen"
    done = subprocess.run(
        [sys.executable, "-c", _OFFSCREEN, str(SAMPLE)],
        env=env,
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    note = next(line for line in done.stdout.splitlines() if line.startswith("NOTE"))
    assert note.startswith("NOTE 3D view unavailable: ") and "\n" not in note
    assert "PAINTED True" in done.stdout


@needs_display
def test_keep_variance_in_the_3d_toolbar_reaches_the_mips(window, qtbot):
    """The toolbar's Keep Variance (the export option's words) switches the viewport's
    mips to widened lobes (the sample's GGX roughness) and back."""
    doc, viewport = open_sample(window, qtbot)
    action = window.view3d.keep_variance_action
    assert action.text() == "Keep Variance" and "--keep-variance" in action.toolTip()
    viewport.render_image(64)  # a frame uploads the document
    assert viewport.renderer.textures.widen is None
    for on, widen in ((True, "ggx"), (False, None)):
        action.trigger()
        assert action.isChecked() is on
        viewport.render_image(64)  # the next frame uploads the document again
        assert viewport.renderer.textures.widen == widen


@needs_display
def test_a_3d_stroke_takes_the_editors_tip_and_a_fresh_seed(window, qtbot):
    """Wiring: the editor's tip, dynamics and next stroke seed reach the 3D painter (the
    tip dab itself is checked against the tip's pixels in test_viewport_gl_tips.py)."""
    from matshop.app.testing import drag
    from matshop.viewport.gl.painting import SurfaceStroke

    doc, viewport = open_sample(window, qtbot)
    window.set_tool("brush")
    window.brush_settings.set("radius_px", 12.0)
    tips = window.brush_settings.tips
    tips.set_kind("spots")
    tips.set_rotation("random")
    seed = tips.stroke_seed
    x, y = viewport.width() / 2, viewport.height() / 2
    hit = viewport._hit(x, y)
    brush = window.host.brush()
    assert brush.tip is not None and brush.dynamics.rotation == "random"
    before = doc.flatten_edit()
    drag(viewport, [(x, y)])  # a click: one dab
    after = doc.flatten_edit()
    assert tips.stroke_seed == seed + 1, "the 3D stroke drew the next stroke seed"
    changed = np.any(after != before, axis=-1)
    # the spots tip has holes: the dab is not the round disc's filled footprint
    rows, cols = np.nonzero(changed)
    box = changed[rows.min() : rows.max() + 1, cols.min() : cols.max() + 1]
    assert 0.1 < box.mean() < 0.7, f"{box.mean():.2f} of the dab's box painted"
    # the same dab painted by the 3D painter directly from the editor's brush and that seed
    layer_id = window.session.active_layer.id
    window.undo()
    assert np.array_equal(doc.flatten_edit(), before)
    stroke = SurfaceStroke(
        doc, layer_id, brush, viewport.surface_map(), seed=seed, swatch=window.host.swatch()
    )
    stroke.add_hits([(hit, 1.0)])
    stroke.end()
    assert np.array_equal(doc.flatten_edit(), after)
