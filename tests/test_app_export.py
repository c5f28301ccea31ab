"""File > Export lists the files it will write (existing ones marked) before writing."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import QTimer  # noqa: E402
from PySide6.QtWidgets import QApplication, QDialogButtonBox  # noqa: E402

from matshop.app.export_dialog import REPLACES, ExportChoices, ExportDialog  # noqa: E402
from matshop.app.prompts import Prompts  # noqa: E402
from matshop.app.testing import ScriptedPrompts, make_window  # noqa: E402
from matshop.app.theme import apply_theme  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SHOTS = ROOT / "test-output" / "screenshots"


@pytest.fixture
def window(qtbot, tmp_path):
    apply_theme(QApplication.instance())
    win = make_window(tmp_path)
    qtbot.addWidget(win)
    assert win.open_path(SAMPLE)
    yield win
    win.prompts.save_answer = "discard"


def _export(window, preset: str, folder: Path, answer: bool = True) -> list[str]:
    """Run File > Export; the names it listed, in order."""
    prompts = window.prompts
    prompts.preset, prompts.folder, prompts.export_answer = preset, folder, answer
    prompts.export_lines = []
    window.actions_by_name["export"].trigger()
    assert prompts.kinds()[-1] == "export" or "error" in prompts.kinds()
    return [line.split(": ", 1)[0] for line in prompts.export_lines]


@pytest.mark.parametrize("preset", ["gltf", "raw", "unity_urp"])
def test_listed_names_are_the_files_written(window, tmp_path, preset) -> None:
    folder = tmp_path / f"out_{preset}"
    listed = _export(window, preset, folder)
    written = sorted(p.name for p in folder.iterdir())
    assert listed and sorted(listed) == written
    assert all(name.startswith("tiles_") for name in listed)  # the document's name
    assert not any(REPLACES in line for line in window.prompts.export_lines)
    assert "error" not in window.prompts.kinds()


def test_optional_outputs_without_their_parameter_are_not_listed(window, tmp_path) -> None:
    listed = _export(window, "raw", tmp_path / "raw")
    lines = window.prompts.export_lines
    assert "tiles_roughness.exr" in listed and "tiles_basecolor.png" in listed
    assert not any("emissive" in name or "height" in name for name in listed)  # none in the set
    assert any(line.endswith("[exr float]") for line in lines)  # format and bit depth
    assert any(line.endswith("[png uint16]") for line in lines)


def test_cancel_writes_nothing(window, tmp_path) -> None:
    folder = tmp_path / "cancelled"
    listed = _export(window, "gltf", folder, answer=False)
    assert len(listed) == 3
    assert not folder.exists() or not any(folder.iterdir())


def test_existing_files_are_marked_and_replaced_only_when_confirmed(window, tmp_path) -> None:
    folder = tmp_path / "again"
    first = _export(window, "gltf", folder)
    stale = folder / first[0]
    stale.write_bytes(b"old")
    (folder / first[1]).unlink()

    listed = _export(window, "gltf", folder, answer=False)  # seen, declined: untouched
    lines = window.prompts.export_lines
    assert listed == first
    assert [line.endswith(REPLACES) for line in lines] == [True, False, True]
    assert stale.read_bytes() == b"old" and not (folder / first[1]).exists()

    assert _export(window, "gltf", folder) == first  # confirmed: replaced
    assert stale.read_bytes() != b"old" and (folder / first[1]).is_file()
    assert "error" not in window.prompts.kinds()


def test_the_dialog_lists_the_lines_and_names_the_replacement(qtbot, tmp_path) -> None:
    apply_theme(QApplication.instance())
    lines = [
        "tiles_baseColor.png: base_color (srgb) [png uint8]",
        f"tiles_normal.png: normal [png uint8] — {REPLACES}",
    ]
    dialog = ExportDialog(lines)
    qtbot.addWidget(dialog)
    dialog.show()
    qtbot.waitExposed(dialog)
    assert [dialog.list.item(i).text() for i in range(dialog.list.count())] == lines
    ok = dialog.findChild(QDialogButtonBox).button(QDialogButtonBox.StandardButton.Ok)
    assert ok.text() == "Replace and export"
    SHOTS.mkdir(parents=True, exist_ok=True)
    assert dialog.grab().save(str(SHOTS / "27_export_files.png"))

    # the real prompt: OK -> the extras chosen (none offered here), Cancel -> None
    prompts = Prompts(None)  # type: ignore[arg-type]
    for button, expected in (("accept", ExportChoices({})), ("reject", None)):
        give_up = time.monotonic() + 30.0  # a dialog that never shows ends the polling

        def answer(button: str = button, give_up: float = give_up) -> None:
            modal = QApplication.activeModalWidget()
            if isinstance(modal, ExportDialog):
                getattr(modal, button)()
            elif time.monotonic() < give_up:
                QTimer.singleShot(20, answer)

        QTimer.singleShot(0, answer)
        assert prompts.confirm_export(lines) == expected


def test_the_usd_checkbox_adds_its_files_to_the_list_and_the_export(
    window, qtbot, tmp_path
) -> None:
    lines = ["a.png: base_color [png uint8]"]
    usd_lines = ["a.usda: mesh [usd usda]", "a.usdz: package [usd usdz]"]
    dialog = ExportDialog(lines, extras={"usd": ("Also write USD", usd_lines)})
    qtbot.addWidget(dialog)

    def shown() -> list[str]:
        return [dialog.list.item(i).text() for i in range(dialog.list.count())]

    assert shown() == lines and dialog.chosen().extras == {"usd": False}
    assert "These 1 files" in dialog.summary.text()
    dialog.extras["usd"].setChecked(True)
    assert shown() == lines + usd_lines and dialog.chosen().extras == {"usd": True}
    assert "These 3 files" in dialog.summary.text()
    dialog.extras["usd"].setChecked(False)
    assert shown() == lines

    window.prompts.export_extras = {"usd"}
    folder = tmp_path / "usd"
    listed = _export(window, "unreal", folder)
    assert {"tiles.usda", "tiles.usdz"} <= set(listed)
    assert sorted(listed) == sorted(p.name for p in folder.iterdir())


def test_scripted_prompts_record_the_export_question() -> None:
    prompts = ScriptedPrompts()
    prompts.export_answer = False
    assert prompts.confirm_export(["a.png: x [png uint8]"]) is None
    assert prompts.asked[-1] == ("export", "a.png: x [png uint8]")
