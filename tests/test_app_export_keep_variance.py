"""File > Export's size and keep-variance option write what the command line writes.

The real dialog is driven (combo box and checkbox clicked); the truth is the
files ``matshop export SET OUT --preset gltf --size 16 --keep-variance`` writes
from the same texture folder, compared byte for byte.
"""

from __future__ import annotations

import time
from pathlib import Path

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import Qt, QTimer  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402
from test_export_keep_variance import bumpy_set  # noqa: E402

from matshop.app.export_dialog import KEEP_VARIANCE_LABEL, ExportDialog  # noqa: E402
from matshop.app.prompts import Prompts  # noqa: E402
from matshop.app.testing import ScriptedPrompts, make_window  # noqa: E402
from matshop.app.theme import apply_theme  # noqa: E402
from matshop.cli import main  # noqa: E402

SHOTS = Path(__file__).resolve().parents[1] / "test-output" / "screenshots"


class DialogPrompts(ScriptedPrompts):
    """Scripted preset and folder; the export dialog is the real one."""

    confirm_export = Prompts.confirm_export


def files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def test_dialog_keep_variance_writes_what_the_command_line_writes(qtbot, tmp_path) -> None:
    apply_theme(QApplication.instance())
    source = bumpy_set(tmp_path / "bumps")
    window = make_window(tmp_path, DialogPrompts())
    qtbot.addWidget(window)
    assert window.open_path(source)
    window.prompts.preset, window.prompts.folder = "gltf", tmp_path / "editor"
    seen: dict[str, object] = {}
    give_up = time.monotonic() + 60.0  # a dialog that never shows ends the polling

    def drive() -> None:
        dialog = QApplication.activeModalWidget()
        if not isinstance(dialog, ExportDialog):
            if time.monotonic() < give_up:
                QTimer.singleShot(20, drive)
            return
        box = dialog.keep_variance
        seen["label"] = box.text()
        seen["enabled at full size"] = box.isEnabled()
        dialog.size.setCurrentIndex(dialog.size.findData(16))
        seen["enabled at 16"] = box.isEnabled()
        qtbot.mouseClick(box, Qt.MouseButton.LeftButton)
        seen["checked"] = box.isChecked()
        SHOTS.mkdir(parents=True, exist_ok=True)
        dialog.grab().save(str(SHOTS / "28_export_keep_variance.png"))
        qtbot.mouseClick(dialog.ok, Qt.MouseButton.LeftButton)

    QTimer.singleShot(0, drive)
    window.actions_by_name["export"].trigger()
    assert seen == {
        "label": KEEP_VARIANCE_LABEL,
        "enabled at full size": False,
        "enabled at 16": True,
        "checked": True,
    }
    assert "error" not in window.prompts.kinds()

    common = [str(source), "--preset", "gltf", "--size", "16"]
    assert main(["export", common[0], str(tmp_path / "cli"), *common[1:], "--keep-variance"]) == 0
    assert main(["export", common[0], str(tmp_path / "plain"), *common[1:]]) == 0
    written = files(tmp_path / "editor")
    assert written == files(tmp_path / "cli")
    assert written != files(tmp_path / "plain")  # the option changed the roughness file
    window.prompts.save_answer = "discard"


def test_the_dialog_says_the_option_in_the_command_lines_words(
    qtbot, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit):
        main(["export", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert f"--no-keep-variance {KEEP_VARIANCE_LABEL.lower()} (with --size N)" in help_text
    # a material of 16 texels has no smaller size to offer: the option stays off
    dialog = ExportDialog(["a.png: x [png uint8]"], size_hw=(16, 16), keep_variance=True)
    qtbot.addWidget(dialog)
    assert dialog.size.count() == 1 and not dialog.keep_variance.isEnabled()
    assert dialog.chosen().keep_variance is False and dialog.chosen().size is None
