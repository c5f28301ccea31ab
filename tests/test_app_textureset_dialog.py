"""The texture-set review shown by File > Open: what was detected, corrected, Open or Cancel."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

import numpy as np  # noqa: E402
from PySide6.QtCore import QTimer  # noqa: E402
from PySide6.QtWidgets import QApplication, QComboBox  # noqa: E402

from matshop.app.prompts import Prompts  # noqa: E402
from matshop.app.testing import ScriptedPrompts, make_window  # noqa: E402
from matshop.app.textureset_dialog import (  # noqa: E402
    NOT_LOADED,
    TextureSetDialog,
    texture_set_rows,
)
from matshop.app.theme import apply_theme  # noqa: E402
from matshop.io.material_io import load_material  # noqa: E402
from matshop.io.textureset import detect_texture_set, known_slots  # noqa: E402

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
    assert by_file["preview.png"][3] == "not loaded: a preview image"
    assert by_file["tiles_ao.png"][2].startswith("512x512 ")  # from the header


def test_open_dialog_reviews_the_set_and_cancel_keeps_the_document(qtbot, tmp_path, messy_set):
    apply_theme(QApplication.instance())
    window = make_window(tmp_path)
    qtbot.addWidget(window)
    prompts = window.prompts
    assert window.open_path(SAMPLE) and "texture_set" not in prompts.kinds()  # scripts: direct
    doc = window.session.doc

    prompts.folder = messy_set
    prompts.texture_set_fix = lambda ts: None
    window.actions_by_name["open_folder"].trigger()
    assert prompts.kinds()[-1] == "texture_set" and window.session.doc is doc  # declined

    prompts.texture_set_fix = lambda ts: ts
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


@pytest.fixture
def rock_set(tmp_path) -> Path:
    """The sample renamed ``rock_*``, its roughness as ``rock_r.png`` (no slot's name)."""
    folder = tmp_path / "rock"
    folder.mkdir()
    for path in SAMPLE.iterdir():
        tag = path.stem.split("_", 1)[1]
        shutil.copy(path, folder / ("rock_r.png" if tag == "roughness" else f"rock_{tag}.png"))
    return folder


class DialogPrompts(ScriptedPrompts):
    """Scripted answers, except that the texture set is reviewed in the real dialog."""

    review_texture_set = Prompts.review_texture_set


def _in_dialog(qtbot, act, deadline_s: float = 30.0) -> list[TextureSetDialog]:
    """Run ``act(dialog)`` on the texture-set dialog once it is shown modally.

    Polls until the dialog shows, for ``deadline_s`` at most: a dialog that
    never comes leaves ``seen`` empty (the caller asserts it), not a timer
    polling forever.
    """
    seen: list[TextureSetDialog] = []
    give_up = time.monotonic() + deadline_s

    def poll() -> None:
        dialog = QApplication.activeModalWidget()
        if not isinstance(dialog, TextureSetDialog):
            if time.monotonic() < give_up:
                QTimer.singleShot(20, poll)
            return
        seen.append(dialog)
        act(dialog)

    QTimer.singleShot(0, poll)
    return seen


def test_every_row_has_a_slot_combo_with_not_loaded_and_the_known_slots(qtbot, messy_set):
    dialog = TextureSetDialog(detect_texture_set(messy_set))
    qtbot.addWidget(dialog)
    assert dialog.table.topLevelItemCount() == len(dialog.combos) == 7
    for index in range(dialog.table.topLevelItemCount()):
        combo = dialog.table.itemWidget(dialog.table.topLevelItem(index), 0)
        assert isinstance(combo, QComboBox)
        assert [combo.itemText(i) for i in range(combo.count())] == [NOT_LOADED, *known_slots()]
    chosen = {path.name: slot for path, slot in dialog.choices().items()}
    assert chosen["tiles_roughness.png"] == "roughness"
    assert chosen["tiles_normal_gl.png"] == "normal"
    assert chosen["tiles_normal_dx.png"] is None and chosen["preview.png"] is None

    # swap the normal flavours, drop the ao: the corrected set says so
    dialog.set_choice("tiles_normal_gl.png", None)
    dialog.set_choice("tiles_normal_dx.png", "normal")
    dialog.set_choice("tiles_ao.png", None)
    dialog.accept()
    fixed = dialog.texture_set
    assert fixed is not None and dialog.result() == dialog.DialogCode.Accepted
    assert fixed.maps["normal"].name == "tiles_normal_dx.png" and "ao" not in fixed.maps
    assert all(p.name != "tiles_ao.png" for p in fixed.maps.values())


def test_assigning_an_unrecognised_file_to_roughness_opens_it_as_roughness(
    qtbot, tmp_path, rock_set
):
    apply_theme(QApplication.instance())
    window = make_window(tmp_path, DialogPrompts())
    qtbot.addWidget(window)
    prompts = window.prompts
    assert "roughness" not in detect_texture_set(rock_set).maps

    def fix(dialog: TextureSetDialog) -> None:
        rows = {path.name: combo for path, combo in dialog.combos.items()}
        combo = rows["rock_r.png"]
        assert combo.currentText() == NOT_LOADED  # unrecognised: not loaded
        combo.setCurrentIndex(combo.findText("roughness"))
        dialog.show()
        SHOTS.mkdir(parents=True, exist_ok=True)
        assert dialog.grab().save(str(SHOTS / "26_texture_set_fix.png"))
        dialog.accept()

    prompts.folder = rock_set
    seen = _in_dialog(qtbot, fix)
    window.actions_by_name["open_folder"].trigger()
    assert seen and prompts.kinds()[-1] == "open_folder"  # the real dialog was shown
    doc = window.session.doc
    assert doc is not None and window.session.source_path == rock_set
    assert "roughness" in doc.schema.names
    expected, _ = load_material(SAMPLE)
    opened = doc.flatten_physical()
    np.testing.assert_allclose(opened.maps["roughness"], expected.maps["roughness"], atol=1e-6)
    window.prompts.save_answer = "discard"


def test_cancel_keeps_the_document_and_a_slot_chosen_twice_is_refused(qtbot, tmp_path, rock_set):
    window = make_window(tmp_path, DialogPrompts())
    qtbot.addWidget(window)
    prompts = window.prompts
    assert window.open_path(SAMPLE)
    doc = window.session.doc
    prompts.folder = rock_set

    seen = _in_dialog(qtbot, lambda dialog: dialog.reject())
    window.actions_by_name["open_folder"].trigger()
    assert seen and window.session.doc is doc  # cancelled: nothing replaced

    errors: list[str] = []

    def conflict(dialog: TextureSetDialog) -> None:
        dialog.set_choice("rock_r.png", "ao")  # rock_ao.png is the ao already
        dialog.accept()
        errors.append(dialog.error.text())
        still_open = dialog.isVisible() and dialog.texture_set is None
        errors.append(str(still_open))
        dialog.reject()

    seen = _in_dialog(qtbot, conflict)
    window.actions_by_name["open_folder"].trigger()
    assert seen and window.session.doc is doc
    message, still_open = errors
    assert still_open == "True"
    assert "ao is chosen for both" in message and "\n" not in message
    assert "rock_ao.png" in message and "rock_r.png" in message
    assert "error" not in prompts.kinds()  # shown in the dialog, not as a message box
    window.prompts.save_answer = "discard"


def test_a_set_with_every_file_dropped_is_refused_in_one_line(qtbot, rock_set):
    dialog = TextureSetDialog(detect_texture_set(rock_set))
    qtbot.addWidget(dialog)
    for path in dialog.combos:
        dialog.set_choice(path.name, None)
    dialog.accept()
    assert dialog.texture_set is None and dialog.result() != dialog.DialogCode.Accepted
    assert "no maps" in dialog.error.text() and "\n" not in dialog.error.text()


@pytest.fixture
def chess_like(tmp_path) -> Path:
    """Two materials sharing maps (MaterialX's layout), made of the sample's files."""
    folder = tmp_path / "chess"
    folder.mkdir()
    for tag, name in (
        ("basecolor", "king_white_base_color.png"),
        ("ao", "king_black_base_color.png"),
        ("normal", "king_shared_normal.png"),
        ("roughness", "king_shared_roughness.png"),
    ):
        shutil.copy(SAMPLE / f"tiles_{tag}.png", folder / name)
    shutil.copy(SAMPLE / "tiles_metallic.png", tmp_path / "metal_for_king.png")  # elsewhere
    return folder


def test_a_folder_of_several_materials_asks_which_then_reviews_it(qtbot, tmp_path, chess_like):
    window = make_window(tmp_path, DialogPrompts())
    qtbot.addWidget(window)
    prompts = window.prompts
    prompts.folder = chess_like
    prompts.material_answer = lambda names: "king_white" if "king_white" in names else None

    def review(dialog: TextureSetDialog) -> None:
        try:
            check(dialog)
        finally:  # a failed check must not leave a modal dialog blocking the test
            if dialog.isVisible():
                dialog.reject()

    def check(dialog: TextureSetDialog) -> None:
        rows = {path.name: combo for path, combo in dialog.combos.items()}
        assert rows["king_shared_normal.png"].currentText() == "normal"  # a shared map
        assert "king_black_base_color.png" not in rows  # the other material's own map
        # Add file... through the real button, the file dialog answered by the test
        dialog.choose_file = lambda: tmp_path / "metal_for_king.png"
        dialog.add_button.click()
        added = dialog.combos[tmp_path / "metal_for_king.png"]
        assert added.currentText() == NOT_LOADED  # its name suggests no free slot
        added.setCurrentIndex(added.findText("metallic"))
        # and read the normal map as DirectX
        control = dialog.normal_convention
        control.setCurrentIndex(control.findData("directx"))
        dialog.show()
        SHOTS.mkdir(parents=True, exist_ok=True)
        assert dialog.grab().save(str(SHOTS / "27_texture_set_add_file.png"))
        dialog.accept()

    seen = _in_dialog(qtbot, review)
    window.actions_by_name["open_folder"].trigger()
    assert seen and ("material", "king_black, king_white") in prompts.asked
    doc = window.session.doc
    assert doc is not None and set(doc.schema.names) == {
        "base_color",
        "metallic",
        "normal",
        "roughness",
    }
    assert Path(doc.sources["metallic"]["file"]) == tmp_path / "metal_for_king.png"
    assert doc.sources["normal"]["convention"] == "directx"
    # the file's own pixels: metallic equals the added file's codes
    from matshop.io.images import read_image

    expected, _ = read_image(SAMPLE / "tiles_metallic.png")
    np.testing.assert_allclose(
        doc.flatten_physical().maps["metallic"][..., 0], expected[..., 0], atol=1e-6
    )
    # and the normal map was decoded as DirectX: green negated against the file's codes
    normal_codes, _ = read_image(SAMPLE / "tiles_normal.png")
    n_y = doc.flatten_physical().maps["normal"][..., 1]
    raw_y = 2.0 * normal_codes[..., 1] - 1.0
    assert np.corrcoef(n_y.ravel(), raw_y.ravel())[0, 1] < -0.99
    window.prompts.save_answer = "discard"


def test_declining_the_material_list_opens_nothing(qtbot, tmp_path, chess_like):
    window = make_window(tmp_path)
    qtbot.addWidget(window)
    prompts = window.prompts
    assert window.open_path(SAMPLE)
    doc = window.session.doc
    prompts.material_answer = lambda names: None
    assert not window.open_path(chess_like)
    assert window.session.doc is doc and "error" not in prompts.kinds()
    window.prompts.save_answer = "discard"
