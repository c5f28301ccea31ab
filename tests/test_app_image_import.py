"""Images as content in the real editor: Layer > Import Image (its file dialog and its
"use it as" question answered through Prompts) makes a paint layer whose base color is
the file's own codes (read with OpenImageIO), in one undo step; an image dropped on the
canvas asks what to make of it (opening it stays a choice) and can become the active
layer's mask, equal to the file's gray codes."""

from __future__ import annotations

import math
import os
import warnings
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import QMimeData, QPointF, Qt, QUrl  # noqa: E402
from PySide6.QtGui import QDragEnterEvent, QDropEvent  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop.app.image_import import OPEN_INSTEAD  # noqa: E402
from matshop.app.testing import shown_window  # noqa: E402
from matshop.layers import Rect  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = Path(os.environ["MATSHOP_SHOTS"]) if os.environ.get("MATSHOP_SHOTS") else None
SIZE = 512


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path)
    assert win.open_path(SAMPLE)
    win.canvas.actual_size()
    win.canvas.flush()
    yield win
    win.prompts.save_answer = "discard"  # teardown closes without asking a human


def write(path: Path, codes: np.ndarray) -> Path:
    codes = codes if codes.ndim == 3 else codes[..., None]
    spec = oiio.ImageSpec(codes.shape[1], codes.shape[0], codes.shape[2], "uint8")
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec) and out.write_image(codes) and out.close()
    return path


def read_codes(path: Path) -> np.ndarray:
    inp = oiio.ImageInput.open(str(path))
    spec = inp.spec()
    pixels = inp.read_image(0, 0, 0, spec.nchannels, "uint8")
    inp.close()
    return pixels.reshape(spec.height, spec.width, spec.nchannels).astype(np.float64)


def pick(label_start: str):
    def answer(labels: list[str]) -> str | None:
        return next(label for label in labels if label.startswith(label_start))

    return answer


def test_layer_import_image_makes_a_paint_layer_of_the_files_codes(window, tmp_path) -> None:
    doc = window.session.doc
    # stripes of strong colors: easy to see on the canvas, and every code differs
    x = np.arange(SIZE)
    rgb = np.stack(
        [(x[None, :] * 255 // (SIZE - 1)) * np.ones((SIZE, 1), int)]
        + [((x[:, None] // 32) % 2 * 200 + 30) * np.ones((1, SIZE), int)]
        + [np.full((SIZE, SIZE), 90)],
        axis=-1,
    ).astype(np.uint8)
    image = write(tmp_path / "stripes.png", rgb)
    window.prompts.image_path = image
    window.prompts.image_use = pick("Base color")
    steps = window.session.steps
    window.actions_by_name["import_image"].trigger()
    asked = dict(window.prompts.asked)
    assert "Normal from a height image" in asked["image_use"]
    assert "Mask of layer" in asked["image_use"]
    assert OPEN_INSTEAD not in asked["image_use"]  # the menu imports; only a drop may open
    layer = window.session.active_layer
    assert layer.kind == "paint" and layer.parameters == ("base_color",)
    assert window.session.steps == steps + 1
    physical = doc.physical()["base_color"]  # base color is held as file codes / 255
    np.testing.assert_allclose(physical * 255, read_codes(image), atol=0.51)
    window.canvas.flush()
    if SHOTS is not None:
        window.canvas.grab().save(str(SHOTS / "import_image_canvas.png"))
    window.undo()
    assert all(other.id != layer.id for other in doc.layers)


def drop_on_canvas(window, path: Path) -> None:
    canvas = window.canvas
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(path))])
    # sent to the canvas, which takes no drops itself: Qt hands them up to the window
    assert not canvas.acceptDrops() and window.acceptDrops()
    centre = canvas.rect().center()
    action, none = Qt.DropAction.CopyAction, Qt.MouseButton.NoButton
    mods = Qt.KeyboardModifier.NoModifier
    with warnings.catch_warnings():  # PySide marks the QPoint constructor deprecated
        warnings.simplefilter("ignore", DeprecationWarning)
        enter = QDragEnterEvent(centre, action, mime, none, mods)
    QApplication.sendEvent(canvas, enter)
    assert enter.isAccepted()
    drop = QDropEvent(QPointF(centre), action, mime, none, mods)
    QApplication.sendEvent(canvas, drop)
    assert drop.isAccepted()


def test_an_image_dropped_on_the_canvas_can_become_the_active_layers_mask(window, tmp_path) -> None:
    doc = window.session.doc
    yy, xx = np.mgrid[0:SIZE, 0:SIZE]
    gray = (127.5 + 127.5 * np.sin(xx / 23.0) * np.cos(yy / 31.0)).round().astype(np.uint8)
    image = write(tmp_path / "blotches.png", gray)
    window.actions_by_name["add_paint"].trigger()
    layer = window.session.active_layer
    window.prompts.image_use = pick("Mask of layer")
    drop_on_canvas(window, image)
    offered = dict(window.prompts.asked)["image_use"]
    assert offered.startswith(f"blotches.png: {OPEN_INSTEAD} | ")
    assert layer.mask is not None
    mask = np.asarray(layer.mask.read(Rect(0, 0, SIZE, SIZE))).reshape(SIZE, SIZE)
    np.testing.assert_allclose(mask * 255, read_codes(image)[..., 0], atol=1e-3)
    # and "open it" keeps what a drop always did
    window.prompts.image_use = lambda labels: OPEN_INSTEAD
    window.prompts.save_answer = "discard"
    drop_on_canvas(window, SAMPLE / "tiles_roughness.png")
    assert window.session.doc is not doc


def test_a_height_image_from_the_menu_tilts_the_normals_by_atan_slope(window, tmp_path) -> None:
    ramp = np.tile(np.arange(SIZE) * 255 // (SIZE - 1), (SIZE, 1)).astype(np.uint8)
    window.prompts.image_path = write(tmp_path / "ramp.png", ramp)
    window.prompts.image_use = pick("Normal from a height image")
    window.prompts.height_px = lambda default: 20.0  # the artist's answer, default offered
    window.actions_by_name["import_image"].trigger()
    assert dict(window.prompts.asked)["height_px"] == "ramp.png: 8"
    normal = window.session.doc.physical()["normal"][..., :3]
    codes = read_codes(window.prompts.image_path)[..., 0] / 255.0
    HEIGHT_PX = 20.0  # noqa: N806

    # central differences of the file's own (8-bit) codes, scaled to texels
    slope = HEIGHT_PX * (np.roll(codes, -1, axis=1) - np.roll(codes, 1, axis=1)) / 2
    expected_x = -np.sin(np.arctan(slope))
    np.testing.assert_allclose(normal[:, 1:-1, 0], expected_x[:, 1:-1], atol=2e-3)
    assert np.abs(normal[..., 1]).max() < 1e-3
    mean_tilt = math.degrees(math.atan(HEIGHT_PX / (SIZE - 1)))
    assert abs(np.degrees(np.arcsin(-normal[:, 1:-1, 0])).mean() - mean_tilt) < 0.05
