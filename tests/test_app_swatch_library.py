"""The swatch library panel: add the current swatch, apply one, and the JSON round trip."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop.app.testing import make_window  # noqa: E402
from matshop.app.theme import apply_theme  # noqa: E402
from matshop.paint import load_swatches  # noqa: E402
from matshop.tools.swatch_library import SwatchLibrary  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = ROOT / "test-output" / "screenshots"
BRONZE = {"base_color": (0.45, 0.25, 0.08), "metallic": (1.0,), "roughness": (0.35,)}


def test_add_apply_and_reload_the_library(qtbot, tmp_path) -> None:
    apply_theme(QApplication.instance())
    window = make_window(tmp_path)
    qtbot.addWidget(window)
    window.resize(1560, 940)
    window.show()
    qtbot.waitExposed(window)
    assert window.open_path(SAMPLE)
    model, panel = window.swatch_model, window.tool_panel.library_panel
    assert panel is not None and panel.isEnabled()  # the brush is the current tool
    for name, value in BRONZE.items():
        model.set_value(name, value)
    for name in ("normal", "ao"):
        model.set_enabled(name, False)
    qtbot.keyClicks(panel.name, "Bronze")
    qtbot.mouseClick(panel.add_button, Qt.MouseButton.LeftButton)
    qtbot.mouseClick(panel.add_button, Qt.MouseButton.LeftButton)  # same name: renamed
    assert [panel.list.item(i).text() for i in range(panel.list.count())] == [
        "Bronze",
        "Swatch",
    ]
    path = tmp_path / "swatches.json"
    saved = load_swatches(path)  # written at once, in the engine's format
    assert saved[0].name == "Bronze" and set(saved[0].parameters) == set(BRONZE)
    assert saved[0].values["roughness"] == pytest.approx((0.35,))
    SHOTS.mkdir(parents=True, exist_ok=True)
    window.canvas.flush()
    QApplication.processEvents()
    assert window.grab().save(str(SHOTS / "24_swatch_library.png"))

    # paint something else, then apply the saved bronze back
    model.set_value("roughness", (0.9,))
    model.set_enabled("normal", True)
    panel.list.setCurrentRow(0)
    qtbot.mouseClick(panel.apply_button, Qt.MouseButton.LeftButton)
    assert model.values["roughness"] == pytest.approx((0.35,))
    assert set(model.enabled) == set(BRONZE) and model.swatch().name == "Bronze"

    # a new window (a new run) reads the same file
    again = SwatchLibrary(path)
    assert [s.name for s in again.swatches] == ["Bronze", "Swatch"]
    assert again.swatches[0].values == saved[0].values
    qtbot.mouseClick(panel.remove_button, Qt.MouseButton.LeftButton)
    assert [s.name for s in load_swatches(path)] == ["Swatch"]
    window.prompts.save_answer = "discard"


def test_a_broken_library_file_is_reported_not_overwritten(tmp_path) -> None:
    path = tmp_path / "swatches.json"
    path.write_text("{not json", encoding="utf-8")
    library = SwatchLibrary(path)
    assert library.swatches == [] and "swatches.json" in library.error
    assert path.read_text(encoding="utf-8") == "{not json"
