"""The canvas' lit display: rendered off the GUI thread, the light moved by a right-drag.

Where OpenGL is available the editor draws it with the GL pass (``test_app_lit_gl.py``
checks that one at full resolution on the sample and the 2K set); these tests run the
reference-renderer fallback's progressive passes, and the cosine-law check with both.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop.app.lit_preview import QUICK_SIZE, light_direction  # noqa: E402
from matshop.app.testing import drag, make_window  # noqa: E402
from matshop.app.theme import apply_theme  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = ROOT / "test-output" / "screenshots"


def _pixels(image) -> np.ndarray:
    image = image.convertToFormat(image.Format.Format_RGBA8888)
    data = np.frombuffer(image.constBits(), dtype=np.uint8)
    return data.reshape(image.height(), image.bytesPerLine() // 4, 4)[:, : image.width()].copy()


def test_the_reference_fallback_renders_progressively_and_follows_the_light(
    qtbot, tmp_path
) -> None:
    apply_theme(QApplication.instance())
    window = make_window(tmp_path)
    qtbot.addWidget(window)
    window.resize(1560, 940)
    window.show()
    qtbot.waitExposed(window)
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow, timeout=3000)  # window shortcuts need the active window
    assert window.open_path(SAMPLE)
    lit, canvas = window.lit_preview, window.canvas
    lit.prefer_gl = False  # the fallback where no OpenGL context can be made
    qtbot.keyClick(canvas, Qt.Key.Key_L)  # the View menu's shortcut
    assert lit.enabled and window.actions_by_name["lit"].isChecked()
    assert lit.wait() and canvas.overlay is not None
    assert lit.gl is None and canvas.lit_label == "Lit (reference renderer)"
    first = _pixels(canvas.overlay)
    assert first.shape[:2] == (512, 512) and first[..., :3].std() > 5  # an image, not a fill
    canvas.flush()
    SHOTS.mkdir(parents=True, exist_ok=True)
    assert window.grab().save(str(SHOTS / "25_lit_preview.png"))

    # a right-drag to the lower right moves the light there: a different picture
    drag(
        canvas,
        [canvas.to_widget(300, 300), canvas.to_widget(500, 500)],
        button=Qt.MouseButton.RightButton,
    )
    assert lit.light == pytest.approx(light_direction(500 / 256 - 1, 500 / 256 - 1))
    assert canvas.refining  # the picture shown is the old light's: the note says so
    shown: list[tuple[int, bool]] = []
    lit.rendered.connect(lambda _s: shown.append((canvas.overlay.width(), canvas.refining)))
    assert lit.wait()
    # a quick picture first (the light follows at once), then the sharp one
    assert shown[0] == (QUICK_SIZE, True) and shown[-1] == (512, False), shown
    moved = _pixels(canvas.overlay)
    assert np.abs(moved.astype(int) - first.astype(int)).mean() > 2
    assert window.session.steps == 0  # moving the light is no edit

    qtbot.keyClick(canvas, Qt.Key.Key_L)
    assert not lit.enabled and canvas.overlay is None and not canvas.lit
    window.prompts.save_answer = "discard"


def _write(path: Path, pixels: np.ndarray) -> None:
    import OpenImageIO as oiio

    out = oiio.ImageOutput.create(str(path))
    height, width, channels = pixels.shape
    out.open(str(path), oiio.ImageSpec(width, height, channels, oiio.UINT8))
    out.write_image(np.ascontiguousarray(pixels))
    out.close()


@pytest.mark.parametrize("renderer", ["opengl", "reference"])
def test_lit_display_equals_render_and_a_tilted_normal_brightens_towards_the_light(
    qtbot, tmp_path, renderer
) -> None:
    """A 64x64 set whose normals lean 35 degrees towards +u: lit from +u (a right-drag to the
    right edge) it is brighter than lit from -u, by the cosine law's margin; and the shown
    image is the reference renderer's ``render()`` of the same flattened material and light."""
    from matshop.render.integrator import DirectionalLight
    from matshop.render.render import render

    folder = tmp_path / "tilted"
    folder.mkdir()
    tilt = np.radians(35.0)
    normal = np.array([np.sin(tilt), 0.0, np.cos(tilt)])
    codes = np.round(255 * (normal + 1) / 2).astype(np.uint8)
    _write(folder / "lean_normal_gl.png", np.broadcast_to(codes, (64, 64, 3)))
    _write(folder / "lean_basecolor.png", np.full((64, 64, 3), 160, np.uint8))
    _write(folder / "lean_roughness.png", np.full((64, 64, 1), 220, np.uint8))
    window = make_window(tmp_path)
    qtbot.addWidget(window)
    window.resize(1200, 900)
    window.show()
    qtbot.waitExposed(window)
    assert window.open_path(folder)
    lit, canvas = window.lit_preview, window.canvas
    lit.prefer_gl = renderer == "opengl"
    lit.set_enabled(True)
    if renderer == "opengl" and lit.gl is None:
        pytest.skip(f"no OpenGL here: {lit.gl_problem}")
    means = {}
    for side, x in (("towards", 63.5), ("away", 0.5)):
        drag(
            canvas,
            [canvas.to_widget(32, 32), canvas.to_widget(x, 32)],
            button=Qt.MouseButton.RightButton,
        )
        assert lit.wait(60.0)
        shown = _pixels(canvas.overlay)[..., :3].astype(float)
        means[side] = shown[8:-8, 8:-8].mean()
    # cos(angle to the light): the light leans 0.85 * 0.98 of the way over in x
    light_x = 0.85 * (63.5 / 32 - 1)
    light = np.array([light_x, 0.0, np.sqrt(1 - light_x**2)])
    towards, away = normal @ light, normal @ (light * [-1, 1, 1])
    assert towards > 2 * away  # the closed form says the lean matters...
    assert means["towards"] > means["away"] + 20  # ...and the display shows it
    # the last picture is render() of the same material and light, with the lit
    # display's settings written out here
    expected = render(
        window.session.doc.flatten_physical(),
        scene="swatch",
        size=64,
        lights=(DirectionalLight(lit.light, (3.0, 3.0, 3.0)),),
        environment_scale=0.25,
        samples=4,
        background=(0.12, 0.12, 0.13),
    )
    reference = np.clip(expected.display() * 255.0 + 0.5, 0, 255).astype(np.uint8)[..., :3]
    shown = _pixels(canvas.overlay)[..., :3]
    assert np.abs(shown.astype(int) - reference.astype(int)).max() <= 1
    window.prompts.save_answer = "discard"
