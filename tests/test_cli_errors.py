"""Bad input through the real command: one line naming the file, exit 2, nothing written."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_images import make_bad, oiio_write

from matshop.cli import main
from matshop.errors import MatshopError
from matshop.io.images import read_image, write_image

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


@pytest.fixture
def good_set(tmp_path: Path) -> Path:
    folder = tmp_path / "set"
    shutil.copytree(SAMPLE, folder)
    return folder


def _replace(folder: Path, name: str, source: Path) -> Path:
    for old in folder.glob(f"tiles_{name}.*"):
        old.unlink()
    target = folder / f"tiles_{name}{source.suffix}"
    shutil.move(source, target)
    return target


def _break(kind: str, folder: Path, scratch: Path) -> Path:
    """Damage the set in one way; return the file the error must name."""
    scratch.mkdir()
    if kind == "missing":
        return folder / "nothing_here"
    if kind in ("truncated-png", "text", "huge-png-100000", "nan-inf"):
        bad = make_bad(kind, scratch)
        slot = "height" if kind == "nan-inf" else "basecolor"
        return _replace(folder, slot, bad)
    if kind == "mismatched-size":
        small = scratch / "small.png"
        write_image(small, np.zeros((64, 64, 1), np.float32))
        return _replace(folder, "roughness", small)
    if kind == "one-channel-normal":
        gray = scratch / "gray.png"
        oiio_write(gray, np.full((512, 512, 1), 128, np.uint8), "uint8")
        return _replace(folder, "normal", gray)
    if kind == "unknown-names":
        for number, path in enumerate(sorted(folder.iterdir())):
            path.rename(folder / f"holiday_photo_{number}.png")
        return folder
    raise AssertionError(kind)


KINDS = [
    "missing",
    "truncated-png",
    "text",
    "huge-png-100000",
    "nan-inf",
    "mismatched-size",
    "one-channel-normal",
    "unknown-names",
]


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("verb", ["info", "convert"])
def test_bad_set_is_one_line_exit_2_nothing_written(
    kind: str, verb: str, good_set: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    named = _break(kind, good_set, tmp_path / "scratch")
    out = tmp_path / "out"
    argv = ["info", str(good_set)] if verb == "info" else ["convert", str(good_set), str(out)]
    if kind == "missing":
        argv[1] = str(named)
    assert main(argv) == 2
    captured = capfd.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith("matshop: error: ")
    assert named.name in lines[0]
    assert "Traceback" not in captured.err + captured.out
    assert not out.exists(), "a failed command must leave no output behind"


def test_exit_status_and_message_from_the_installed_entry_point(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "matshop", "info", str(tmp_path / "nope_basecolor.png")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "nope_basecolor.png" in result.stderr


def test_convert_refuses_to_overwrite_without_force(good_set: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert main(["convert", str(good_set), str(out)]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    assert main(["convert", str(good_set), str(out)]) == 2
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert main(["convert", str(good_set), str(out), "--force"]) == 0


def test_failed_write_leaves_previous_export_intact(
    good_set: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "out"
    assert main(["convert", str(good_set), str(out)]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    from matshop.io import material_io

    calls = []

    def failing_write(path, array, **kwargs):  # the third file fails mid-export
        calls.append(path)
        if len(calls) == 3:
            raise OSError(28, "No space left on device")
        write_image(path, array, **kwargs)

    monkeypatch.setattr(material_io, "write_image", failing_write)
    with pytest.raises(MatshopError, match="No space left on device"):
        material_io.save_material(material_io.load_material(good_set)[0], out, overwrite=True)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert read_image(out / "tiles_basecolor.png")[0].shape == (512, 512, 3)
