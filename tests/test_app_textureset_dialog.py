"""The texture-set review shown by File > Open: what was detected, Open or Cancel."""

from __future__ import annotations

import os

if not os.environ.get("DISPLAY"):
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import shutil
from pathlib import Path

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtWidgets import QApplication  # noqa: E402

from matshop.app.testing import make_window  # noqa: E402
from matshop.app.textureset_dialog import TextureSetDialog, texture_set_rows  # noqa: E402
from matshop.app.theme import apply_theme  # noqa: E402
from matshop.io.textureset import detect_texture_set  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = ROOT / "test-output" / "screenshots"


@pytest.fixture
def messy_set(tmp_path) -> Path:
    """The sample with both normal flavours and a stray preview image."""
    folder = tmp_path / "set"
    folder.mkdir()
    for path in SAMPLE.iterdir():
        if path.name != "tiles_normal.png":
            shutil.copy(path, folder / path.name)
    shutil.copy(SAMPLE / "tiles_normal.png", folder / "tiles_normal_gl.png")
    shutil.copy(SAMPLE / "tiles_normal.png", folder / "tiles_normal_dx.png")
    shutil.copy(SAMPLE / "tiles_ao.png", folder / "preview.png")
    return folder


def test_rows_list_maps_alternates_and_unrecognised(messy_set) -> None:
    rows = texture_set_rows(detect_texture_set(messy_set))
    by_file = {row[1]: row for row in rows}
    assert by_file["tiles_roughness.png"][0] == "roughness"
    assert by_file["tiles_normal_gl.png"][0] == "normal"
    assert "convention: opengl" in by_file["tiles_normal_gl.png"][3]
    assert by_file["tiles_normal_dx.png"][3] == "alternate normal: not loaded"
    assert "not loaded" in by_file["preview.png"][3]
    assert by_file["tiles_ao.png"][2].startswith("512x512 ")  # from the header


def test_open_dialog_reviews_the_set_and_cancel_keeps_the_document(qtbot, tmp_path, messy_set):
    apply_theme(QApplication.instance())
    window = make_window(tmp_path)
    qtbot.addWidget(window)
    prompts = window.prompts
    assert window.open_path(SAMPLE) and "texture_set" not in prompts.kinds()  # scripts: direct
    doc = window.session.doc

    prompts.folder = messy_set
    prompts.open_texture_set = False
    window.actions_by_name["open_folder"].trigger()
    assert prompts.kinds()[-1] == "texture_set" and window.session.doc is doc  # declined

    prompts.open_texture_set = True
    window.actions_by_name["open_folder"].trigger()
    assert window.session.doc is not doc and window.session.source_path == messy_set

    dialog = TextureSetDialog(detect_texture_set(messy_set))
    qtbot.addWidget(dialog)
    dialog.show()
    qtbot.waitExposed(dialog)
    assert dialog.table.topLevelItemCount() == 7
    SHOTS.mkdir(parents=True, exist_ok=True)
    assert dialog.grab().save(str(SHOTS / "23_texture_set_dialog.png"))
    window.prompts.save_answer = "discard"
