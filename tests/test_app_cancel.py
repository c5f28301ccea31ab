"""Cancel while a texture set opens or an export writes: the work stops between files.

Opening reports per-file progress (the panel's bar counts the set's map files) and its
Cancel stops before the files not yet started (files are read and written two at a time,
:mod:`matshop.io.overlap`: the ones in flight finish); export's Cancel stops the same way
and, all-or-nothing, leaves no output folder, no partial files and no staging folder behind
(an existing folder keeps exactly what it held). Each file is slowed through the engine's
own seams (``read_image``, ``fileset.write_one``) so the click lands mid-way on any machine.
"""

from __future__ import annotations

import time
from pathlib import Path

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

from PySide6.QtCore import Qt, QTimer  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402
from PySide6.QtWidgets import QFrame  # noqa: E402

from matshop.app.testing import shown_window  # noqa: E402
from matshop.export import export_material  # noqa: E402
from matshop.io import fileset, material_io  # noqa: E402
from matshop.io.material_io import load_material  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
#: the sample's map files, counted from the folder (one map per file)
SAMPLE_FILES = sorted(p.name for p in SAMPLE.iterdir() if p.suffix == ".png")
PER_FILE_S = 0.4


@pytest.fixture
def window(qtbot, tmp_path):
    win = shown_window(qtbot, tmp_path, size=(1200, 900))
    assert win.open_path(SAMPLE)
    yield win
    win.prompts.save_answer = "discard"


def _slowed(monkeypatch, module, name: str) -> list[str]:
    """``module.name`` made to take PER_FILE_S longer; returns the calls' first arguments."""
    real = getattr(module, name)
    calls: list[str] = []

    def slow(first, *args, **kwargs):
        calls.append(str(first))
        time.sleep(PER_FILE_S)
        return real(first, *args, **kwargs)

    monkeypatch.setattr(module, name, slow)
    return calls


def _cancel_when(window, label: str, files_done: int, seen: list[tuple[int, int]]) -> None:
    """Click the progress panel's Cancel once its bar shows ``files_done`` files of the
    work labelled ``label...`` (polling; records the bar's (value, maximum) seen)."""

    def look() -> None:
        panels = [p for p in window.findChildren(QFrame, "progressPanel") if p.isVisible()]
        if panels and panels[0].label.text().startswith(label):
            bar = panels[0].bar
            seen.append((bar.value(), bar.maximum()))
            if bar.value() >= files_done and panels[0].cancel is not None:
                QTest.mouseClick(panels[0].cancel, Qt.MouseButton.LeftButton)
                return
        QTimer.singleShot(20, look)

    QTimer.singleShot(20, look)


def test_the_engine_reports_one_step_per_file() -> None:
    steps: list[tuple[int, int]] = []
    load_material(SAMPLE, progress=lambda done, total: steps.append((done, total)))
    n = len(SAMPLE_FILES)
    assert steps == [(k, n) for k in range(n + 1)]


def test_export_reports_one_step_per_file(tmp_path) -> None:
    material, _ = load_material(SAMPLE)
    steps: list[tuple[int, int]] = []
    out = tmp_path / "out"
    export_material(material, "gltf", out, progress=lambda d, t: steps.append((d, t)))
    n = len(list(out.iterdir()))
    assert n >= 3 and steps == [(k, n) for k in range(n + 1)]


def test_cancel_while_a_set_opens_stops_between_files(window, monkeypatch) -> None:
    doc = window.session.doc
    reads = _slowed(monkeypatch, material_io, "read_image")
    seen: list[tuple[int, int]] = []
    _cancel_when(window, "Opening", 1, seen)
    assert not window.open_path(SAMPLE)
    n = len(SAMPLE_FILES)
    assert (1, n) in seen  # the bar counted the set's files
    # stopped between files, before the last: the click lands after file 1 (or 2), and
    # only the two files in flight then (at most 3 and 4 of 5) still run
    assert 2 <= len(reads) < n
    assert window.session.doc is doc
    assert "Did not open" in window.statusBar().currentMessage()


@pytest.mark.parametrize("existing", [False, True], ids=["new-folder", "existing-folder"])
def test_cancel_while_exporting_writes_nothing(window, monkeypatch, tmp_path, existing) -> None:
    folder = tmp_path / "export"
    before: dict[str, bytes] = {}
    if existing:  # a folder with an unrelated file and an older export the user replaces
        folder.mkdir()
        (folder / "notes.txt").write_bytes(b"mine")
        (folder / "tiles_baseColor.png").write_bytes(b"old export")
        before = {p.name: p.read_bytes() for p in folder.iterdir()}
    writes = _slowed(monkeypatch, fileset, "write_one")
    prompts = window.prompts
    prompts.preset, prompts.folder, prompts.export_answer = "gltf", folder, True
    seen: list[tuple[int, int]] = []
    _cancel_when(window, "Exporting", 0, seen)  # while the first files are written
    window.files.export()
    assert seen and seen[-1][1] >= 3  # the bar counted the files to write
    assert 1 <= len(writes) < seen[-1][1]  # stopped between files: the 2 in flight finished
    if existing:
        assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
    else:
        assert not folder.exists()
    assert not list(tmp_path.rglob(".matshop-staging*"))
    assert "Export cancelled" in window.statusBar().currentMessage()
