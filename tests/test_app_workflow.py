"""An artist's session through the real widgets, start to finish, on the bundled sample and
(when present) the shared 2K chessboard: open, look at each parameter, paint a partial swatch,
mask and invert, a filter layer, export, save, reopen. Screenshots of every step go to
``test-output/screenshots/workflow_<set>_NN_<step>.png``; each step also checks what the user
would check by eye, against the files on disk."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")
oiio = pytest.importorskip("OpenImageIO")

from PySide6.QtCore import QEvent, Qt  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop.app.testing import drag, shown_window  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SHOTS = ROOT / "test-output" / "screenshots"
SETS = {
    "sample": ROOT / "resources" / "sample",
    "chessboard": ROOT.parent / "shared" / "data" / "chessboard",
}


def codes(path: Path) -> np.ndarray:
    buf = oiio.ImageBuf(str(path))
    spec = buf.spec()
    return np.asarray(buf.get_pixels(oiio.UINT8)).reshape(spec.height, spec.width, -1)


@pytest.mark.parametrize("name", list(SETS))
def test_an_artists_session_through_the_real_widgets(qtbot, tmp_path, name) -> None:
    folder = SETS[name]
    if not folder.is_dir():
        pytest.skip(f"the shared set is absent: {folder}")
    window = shown_window(qtbot, tmp_path)
    canvas = window.canvas
    step = iter(range(1, 100))

    def shot(what: str) -> None:
        canvas.flush()
        QApplication.sendEvent(canvas, QEvent(QEvent.Type.Leave))
        QApplication.processEvents()
        SHOTS.mkdir(parents=True, exist_ok=True)
        assert window.grab().save(str(SHOTS / f"workflow_{name}_{next(step):02d}_{what}.png"))

    def texels(points) -> list:
        return [canvas.to_widget(x, y) for x, y in points]

    assert window.open_path(folder)
    doc = window.session.doc
    shot("opened")
    for param in doc.schema.names:  # every parameter, as the file shows it
        window.show_parameter(param)
        shot(f"shows_{param}")
    window.show_parameter("base_color")

    # paint only base color and roughness into a new layer (Ctrl+Shift+N)
    qtbot.keyClick(
        canvas,
        Qt.Key.Key_N,
        Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier,
    )
    checks = window.tool_panel.swatch_editor.checks
    for param in doc.schema.names:
        if param not in ("base_color", "roughness"):
            checks[param].click()
    window.swatch_model.set_value("base_color", (0.2, 0.55, 0.85))
    assert "paints base color, roughness" in window.tool_label.text()
    size = min(doc.width, doc.height)
    window.brush_settings.set("radius_px", size / 25)
    canvas.fit()
    before = doc.flatten_edit()
    line = [(size * (0.2 + 0.03 * i), size * 0.3) for i in range(21)]
    drag(canvas, texels(line))
    after = doc.flatten_edit()
    untouched = [
        c
        for p in doc.schema.names
        if p not in ("base_color", "roughness")
        for c in range(*doc.schema.edit_slices[p].indices(doc.channels))
    ]
    assert np.array_equal(after[..., untouched], before[..., untouched])
    shot("painted_base_color_and_roughness")

    # mask, invert (all hidden), reveal a patch with the eraser on the mask
    window.actions_by_name["add_mask"].trigger()
    window.actions_by_name["invert_mask"].trigger()
    window.session.set_mask_target(True)
    window.set_tool("eraser")
    assert window.tool_label.text().startswith("Eraser: reveals")
    drag(canvas, texels(line[:8]))
    shot("mask_inverted_then_revealed")
    window.set_tool("brush")
    window.session.set_mask_target(False)

    # a blur filter layer, then export and compare the exported color with the canvas
    blur = next(
        a
        for a in window.actions_by_name["add_filter"].menu().actions()
        if a.text() == "Gaussian blur"
    )
    blur.trigger()
    assert window.background.wait(120)
    shot("blur_layer")
    window.prompts.folder = tmp_path / "export"
    window.prompts.preset = "raw"
    window.files.export()
    exported = next((tmp_path / "export").glob("*base*color*.png"))
    canvas.flush()
    shown = canvas.cache.buffer[..., :3].astype(int)
    assert np.abs(shown - codes(exported)[..., :3].astype(int)).max() <= 1
    shot("exported")

    # save, close, reopen: the same flatten
    flattened = doc.flatten_edit()
    project = tmp_path / f"{name}.matshop"
    assert window.files.save_to(project)
    window.session.set_document(None)
    assert window.open_path(project)
    assert window.background.wait(120)
    np.testing.assert_array_equal(window.session.doc.flatten_edit(), flattened)
    shot("reopened")
    window.prompts.save_answer = "discard"
