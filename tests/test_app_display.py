"""The 2D canvas shows each parameter as its file stores it: real sets opened from disk in
the real editor window, the canvas grabbed, compared with the source files' own pixels read
independently with OpenImageIO (colors as their sRGB codes, normals as their file encodes
them, scalars as gray), a constant Phong map with the closed form sqrt(2 / (n + 2)), an
edited canvas with the exported file, and zoomed-out drawing with the mean of the texels it
covers (no aliasing). Screenshots go to ``test-output/screenshots/``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")
oiio = pytest.importorskip("OpenImageIO")

from PySide6.QtCore import QEvent, Qt  # noqa: E402
from PySide6.QtGui import QColor, QImage  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop.app.testing import drag, shown_window  # noqa: E402
from matshop.tools.widgets import ColorButton  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
CHESSBOARD = ROOT.parent / "shared" / "data" / "chessboard"
SHOTS = ROOT / "test-output" / "screenshots"


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    yield win
    win.prompts.save_answer = "discard"  # teardown closes without asking a human


def file_codes(path: Path) -> np.ndarray:
    """The file's 8-bit codes ``(H, W, C)``, read with OpenImageIO (not matshop's reader)."""
    buf = oiio.ImageBuf(str(path))
    pixels = buf.get_pixels(oiio.UINT8)
    assert pixels is not None, buf.geterror()
    return np.asarray(pixels).reshape(buf.spec().height, buf.spec().width, -1)


def grab_canvas(win, name: str | None = None) -> np.ndarray:
    """What the canvas widget shows, as ``(H, W, 3)`` uint8 (the real paint path)."""
    win.canvas.flush()
    QApplication.sendEvent(win.canvas, QEvent(QEvent.Type.Leave))  # no brush ring drawn
    image = win.canvas.grab().toImage().convertToFormat(QImage.Format.Format_RGB888)
    if name is not None:
        SHOTS.mkdir(parents=True, exist_ok=True)
        image.save(str(SHOTS / f"{name}.png"))
    width, height = image.width(), image.height()
    rows = np.frombuffer(image.constBits(), np.uint8).reshape(height, image.bytesPerLine())
    return rows[:, : width * 3].reshape(height, width, 3).copy()


def shown_texels(win, name: str | None = None) -> tuple[np.ndarray, tuple[slice, slice]]:
    """At 1:1: the grabbed texels and the ``(rows, cols)`` of the document they show."""
    canvas = win.canvas
    canvas.actual_size()
    assert canvas.view.zoom == 1.0
    pixels = grab_canvas(win, name)
    ox, oy = int(canvas.view.offset_x), int(canvas.view.offset_y)
    doc = win.session.doc
    x0, y0 = max(0, -ox), max(0, -oy)
    x1 = min(doc.width, canvas.width() - ox)
    y1 = min(doc.height, canvas.height() - oy)
    assert x1 - x0 >= min(doc.width, 256) and y1 - y0 >= min(doc.height, 200), "too little shown"
    crop = pixels[y0 + oy : y1 + oy, x0 + ox : x1 + ox]
    return crop, (slice(y0, y1), slice(x0, x1))


def unit_normal_codes(codes: np.ndarray, green_up: bool) -> np.ndarray:
    """A normal file's codes as unit vectors re-encoded (what a unit-normal editor can hold).

    Written out here, not taken from matshop: ``n = 2 c / 255 - 1`` renormalised,
    back to ``255 (n + 1) / 2``; the convention only decides which way green
    points, and re-encoding in the same convention undoes it.
    """
    n = 2.0 * codes[..., :3].astype(np.float64) / 255.0 - 1.0
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    del green_up  # renormalising is the same in either convention
    return np.round(255.0 * (n + 1.0) / 2.0)


def assert_shows_file(win, folder: Path, tag: str, name: str, shot: str) -> None:
    """Canvas at 1:1 == the file's own codes (gray files: every channel the file's first)."""
    win.show_parameter(name)
    crop, (rows, cols) = shown_texels(win, shot)
    path = next(folder.glob(f"*_{tag}.*"))
    codes = file_codes(path)[rows, cols]
    expected = codes[..., :3] if codes.shape[2] >= 3 else np.repeat(codes[..., :1], 3, axis=2)
    diff = np.abs(crop.astype(int) - expected.astype(int))
    assert diff.max() <= 1, f"{name}: canvas differs from {path.name} by up to {diff.max()} codes"


def test_the_sample_is_shown_as_its_files_store_it(window) -> None:
    assert window.open_path(SAMPLE)
    for tag, name in (
        ("basecolor", "base_color"),
        ("roughness", "roughness"),
        ("metallic", "metallic"),
        ("ao", "ao"),
    ):
        assert_shows_file(window, SAMPLE, tag, name, f"display_sample_{name}")
    window.show_parameter("normal")
    crop, (rows, cols) = shown_texels(window, "display_sample_normal")
    codes = file_codes(SAMPLE / "tiles_normal.png")[rows, cols]
    # the sample's normals are unit vectors to within a code: the raw codes must match
    assert np.abs(crop.astype(int) - codes[..., :3].astype(int)).max() <= 1


@pytest.mark.skipif(not CHESSBOARD.is_dir(), reason=f"the shared 2K set is absent: {CHESSBOARD}")
def test_the_shared_2k_jpeg_set_is_shown_as_its_files_store_it(window) -> None:
    assert window.open_path(CHESSBOARD)
    doc = window.session.doc
    assert doc.size == (2048, 2048)
    for tag, name in (("base_color", "base_color"), ("roughness", "roughness")):
        assert_shows_file(window, CHESSBOARD, tag, name, f"display_chessboard_{name}")
    window.show_parameter("normal")
    crop, (rows, cols) = shown_texels(window, "display_chessboard_normal")
    codes = file_codes(CHESSBOARD / "chessboard_normal.jpg")[rows, cols]
    # JPEG normals are not quite unit length; the editor holds unit normals, so the
    # canvas shows the file's vectors renormalised (1 code), and the raw codes at the 99th
    # percentile of texels
    unit = unit_normal_codes(codes, doc.normal_convention == "opengl")
    assert np.abs(crop - unit).max() <= 1
    raw = np.abs(crop.astype(int) - codes[..., :3].astype(int))
    assert np.percentile(raw, 99) <= 1


def test_a_dark_tilted_and_directx_normal_map_is_shown_in_its_own_convention(
    window, tmp_path
) -> None:
    """A DirectX file (named so) is shown with its own green, not OpenGL's."""
    rng = np.random.default_rng(7)
    n = rng.normal(size=(96, 128, 3))
    n[..., 2] = np.abs(n[..., 2]) + 1.5
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    codes = np.round(255 * (n + 1) / 2).astype(np.uint8)
    folder = tmp_path / "dx"
    folder.mkdir()
    color = rng.integers(0, 256, size=(96, 128, 3), dtype=np.uint8)
    for name, pixels in (("bricks_normal_dx.png", codes), ("bricks_basecolor.png", color)):
        out = oiio.ImageOutput.create(str(folder / name))
        out.open(str(folder / name), oiio.ImageSpec(128, 96, 3, oiio.UINT8))
        out.write_image(pixels)
        out.close()
    assert window.open_path(folder)
    assert window.session.doc.normal_convention == "directx"
    window.show_parameter("normal")
    crop, (rows, cols) = shown_texels(window, "display_directx_normal")
    assert np.abs(crop - unit_normal_codes(codes, green_up=False)[rows, cols]).max() <= 1
    assert_shows_file(window, folder, "basecolor", "base_color", "display_random_color")


def test_a_constant_phong_map_is_shown_as_its_equivalent_roughness(window, tmp_path) -> None:
    """A Phong exponent has no 8-bit code: the canvas shows sqrt(2 / (n + 2))."""
    from matshop.io.project import save_project
    from matshop.layers import Document
    from matshop.material import Material, Schema

    exponents = np.array([2.0, 30.0, 98.0, 700.0], np.float32)
    field = np.repeat(np.repeat(exponents[None, :], 200, axis=0), 100, axis=1)[..., None]
    schema = Schema.from_names(["phong_exponent"])
    material = Material("phong", schema, {"phong_exponent": field})
    path = tmp_path / "phong.matshop"
    save_project(Document.from_material(material), path)
    assert window.open_path(path)
    window.show_parameter("phong_exponent")
    crop, (rows, cols) = shown_texels(window, "display_phong")
    expected = np.round(255.0 * np.sqrt(2.0 / (field[rows, cols, 0] + 2.0)))
    assert np.abs(crop.astype(float) - expected[..., None]).max() <= 1


def test_an_edited_canvas_shows_what_export_writes(window, qtbot, tmp_path) -> None:
    """After a stroke, the canvas equals the exported base color file (raw preset, 8-bit)."""
    assert window.open_path(SAMPLE)
    # the color picked in the swatch editor's dialog is the color painted and shown
    editor = window.tool_panel.swatch_editor
    editor.pick_color = lambda initial, parent: QColor(51, 140, 217)
    button = editor.findChildren(ColorButton)[0]
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
    assert button.color().getRgb()[:3] == (51, 140, 217)
    window.brush_settings.set("radius_px", 14.0)
    canvas = window.canvas
    canvas.actual_size()
    drag(canvas, [canvas.to_widget(60 + 8 * i, 90 + 3 * i) for i in range(30)])
    window.prompts.folder = tmp_path / "out"
    window.prompts.preset = "raw"
    window.files.export()
    written = next((tmp_path / "out").glob("*base*color*.png"))
    window.show_parameter("base_color")
    crop, (rows, cols) = shown_texels(window, "display_after_stroke")
    exported = file_codes(written)[rows, cols, :3]
    assert np.abs(crop.astype(int) - exported.astype(int)).max() <= 1
    centre = crop[int(np.round(90 + 3 * 15)) - rows.start, 60 + 8 * 15 - cols.start]
    assert np.abs(centre.astype(int) - [51, 140, 217]).max() <= 1


def _checkerboard_set(folder: Path, size: int = 512) -> Path:
    """A roughness map of alternating black and white texels: its mean is 127.5."""
    folder.mkdir()
    yy, xx = np.mgrid[0:size, 0:size]
    pixels = (((xx + yy) % 2) * 255).astype(np.uint8)[..., None]
    path = folder / "checks_roughness.png"
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(size, size, 1, oiio.UINT8))
    out.write_image(pixels)
    out.close()
    return folder


@pytest.mark.parametrize("zoom", [0.5, 0.3, 0.25, 0.13])
def test_zoomed_out_the_canvas_shows_the_mean_not_aliased_texels(window, tmp_path, zoom) -> None:
    """Each screen pixel covers several texels of a 1-texel checkerboard: all gray (127.5).

    Plain bilinear sampling reads 4 texels of the many a pixel covers and shows
    black, white or moire stripes depending on the zoom and the pan.
    """
    assert window.open_path(_checkerboard_set(tmp_path / "checks"))
    canvas = window.canvas
    for pan in (0.0, 0.37):
        canvas.view.zoom = zoom
        canvas.view.offset_x = 40.0 + pan
        canvas.view.offset_y = 30.0 + pan
        pixels = grab_canvas(window, f"display_zoom_{zoom}_{pan}").astype(float)
        side = int(512 * zoom)
        inner = pixels[32 : 30 + side - 2, 42 : 40 + side - 2]  # away from the border pixels
        assert abs(inner.mean() - 127.5) < 3, f"zoom {zoom}: mean {inner.mean():.1f}"
        assert inner.std() < 6, f"zoom {zoom}, pan {pan}: aliasing, std {inner.std():.1f}"
