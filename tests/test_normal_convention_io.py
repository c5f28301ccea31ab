"""Normal-map conventions from the file on disk to every file matshop writes.

The truth here is the source file's own codes, decoded by hand in this test
(``n = 2c - 1``, green negated for DirectX), and read back with OpenImageIO
directly: never matshop's decoder, never a reload told the convention.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest
from oracle import file_codes as codes

from matshop.cli import main
from matshop.io.material_io import load_material
from matshop.io.project import load_project
from matshop.spaces.frame import CONFIDENT_GUESS, guess_normal_convention

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


def unit(codes_rgb: np.ndarray, *, directx: bool, scale: float = 255.0) -> np.ndarray:
    n = 2.0 * codes_rgb[..., :3].astype(np.float64) / scale - 1.0
    if directx:
        n[..., 1] = -n[..., 1]
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.degrees(np.arccos(np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)))


@pytest.fixture
def dx_set(tmp_path: Path) -> Path:
    """The sample with its (OpenGL) normal map re-encoded as DirectX, named ``_nor_dx``."""
    folder = tmp_path / "dx_set"
    folder.mkdir()
    for path in SAMPLE.iterdir():
        if path.name != "tiles_normal.png":
            shutil.copy(path, folder / path.name)
    gl = codes(SAMPLE / "tiles_normal.png")
    dx = gl.copy()
    dx[..., 1] = 255 - gl[..., 1]
    out = oiio.ImageOutput.create(str(folder / "tiles_nor_dx.png"))
    out.open(str(folder / "tiles_nor_dx.png"), oiio.ImageSpec(dx.shape[1], dx.shape[0], 3, "uint8"))
    out.write_image(dx.astype(np.uint8))
    out.close()
    return folder


def _truth() -> np.ndarray:
    return unit(codes(SAMPLE / "tiles_normal.png"), directx=False)


def _read_back(folder: Path, expected_convention: str, how: tuple[str, ...]) -> None:
    material, _ = load_material(folder)
    source = material.sources["normal"]
    assert source["convention"] == expected_convention
    assert source["convention_source"] in how, source  # never guessed, never defaulted
    worst = angle_deg(material.maps["normal"][..., :3].astype(np.float64), _truth()).max()
    assert worst < 0.9, f"normals moved by {worst:.2f} deg"  # 8-bit steps, twice


def test_convert_keeps_the_source_convention_in_name_and_values(dx_set, tmp_path) -> None:
    out = tmp_path / "out"
    assert main(["convert", str(dx_set), str(out)]) == 0
    written = out / "tiles_normal_dx.png"
    assert written.is_file()
    # the written codes are the DirectX source's codes (the convention is kept)
    assert np.abs(codes(written).astype(int) - codes(dx_set / "tiles_nor_dx.png")).max() <= 1
    _read_back(out, "directx", ("file name",))


def test_apply_and_flatten_read_back_without_a_guess(dx_set, tmp_path) -> None:
    applied = tmp_path / "applied"
    args = ["apply", str(dx_set), str(applied), "--op", "blur", "sigma_px=1", "--params", "ao"]
    assert main(args) == 0
    assert (applied / "tiles_normal_dx.png").is_file()
    _read_back(applied, "directx", ("file name",))

    project = tmp_path / "p.matshop"
    assert main(["new", str(project), "--from", str(dx_set)]) == 0
    assert main(["flatten", str(project), str(tmp_path / "flat")]) == 0
    assert (tmp_path / "flat" / "tiles_normal_dx.png").is_file()
    _read_back(tmp_path / "flat", "directx", ("file name",))


@pytest.mark.parametrize(
    ("preset", "file", "convention", "how"),
    [
        ("raw", "tiles_normal_gl.exr", "opengl", ("file name",)),
        ("gltf", "tiles_normal.png", "opengl", ("file metadata",)),
        ("unreal", "tiles_Normal.png", "directx", ("file metadata",)),
        ("godot", "tiles_normal.png", "opengl", ("file metadata",)),
    ],
)
def test_exports_read_back_without_a_guess(dx_set, tmp_path, preset, file, convention, how):
    out = tmp_path / preset
    assert main(["export", str(dx_set), str(out), "--preset", preset]) == 0
    assert (out / file).is_file(), sorted(p.name for p in out.iterdir())
    if preset != "raw":  # only the normal map: engines want their own names for the rest
        for other in out.iterdir():
            if other.name != file:
                other.unlink()
    _read_back(out, convention, how)


def test_exported_normal_codes_against_the_source_file(dx_set, tmp_path) -> None:
    """glTF's file holds the OpenGL codes of the source; Unreal's green is 255 minus them."""
    source_gl = codes(SAMPLE / "tiles_normal.png").astype(int)
    assert main(["export", str(dx_set), str(tmp_path / "g"), "--preset", "gltf"]) == 0
    assert main(["export", str(dx_set), str(tmp_path / "u"), "--preset", "unreal"]) == 0
    gltf = codes(tmp_path / "g" / "tiles_normal.png").astype(int)
    unreal = codes(tmp_path / "u" / "tiles_Normal.png").astype(int)
    assert np.abs(gltf[..., :3] - source_gl[..., :3]).max() <= 1
    assert np.abs(unreal[..., 1] - (255 - source_gl[..., 1])).max() <= 1
    assert np.abs(unreal[..., [0, 2]] - source_gl[..., [0, 2]]).max() <= 1
    assert np.corrcoef(gltf[..., 1].ravel(), source_gl[..., 1].ravel())[0, 1] > 0.99


def _noise_normals(folder: Path) -> Path:
    """A normal map of white noise: its curl tells neither convention."""
    folder.mkdir()
    rng = np.random.default_rng(7)
    slope = rng.normal(0.0, 0.3, (64, 64, 2))
    n = np.dstack([slope, np.ones((64, 64))])
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    rgb = np.rint((n + 1.0) / 2.0 * 255).astype(np.uint8)
    out = oiio.ImageOutput.create(str(folder / "noise_normal.png"))
    out.open(str(folder / "noise_normal.png"), oiio.ImageSpec(64, 64, 3, "uint8"))
    out.write_image(rgb)
    out.close()
    return folder


def test_an_unconfident_guess_reads_opengl_and_says_so(tmp_path, capsys) -> None:
    folder = _noise_normals(tmp_path / "noise")
    _, confidence = guess_normal_convention(codes(folder / "noise_normal.png"))
    assert confidence < CONFIDENT_GUESS  # the premise: noise cannot tell
    material, report = load_material(folder)
    assert material.sources["normal"]["convention"] == "opengl"
    assert material.sources["normal"]["convention_source"] == "default"
    assert main(["info", str(folder)]) == 0
    printed = capsys.readouterr().out
    assert "opengl normals (default)" in printed
    assert "read as opengl normals by default" in printed and "--normal-convention" in printed
    assert main(["info", str(folder), "--normal-convention", "directx"]) == 0
    assert "directx normals (given)" in capsys.readouterr().out


def test_a_project_remembers_files_slots_and_the_chosen_convention(tmp_path) -> None:
    folder = _noise_normals(tmp_path / "noise")
    project = tmp_path / "n.matshop"
    args = ["new", str(project), "--from", str(folder), "--normal-convention", "directx"]
    assert main(args) == 0
    sources = load_project(project).document.sources
    assert sources["normal"]["convention"] == "directx"
    assert sources["normal"]["convention_source"] == "given"
    assert sources["normal"]["slot"] == "normal"
    assert Path(sources["normal"]["file"]) == folder / "noise_normal.png"
    assert main(["flatten", str(project), str(tmp_path / "flat")]) == 0
    written = codes(tmp_path / "flat" / "noise_normal_dx.png").astype(int)
    assert np.abs(written - codes(folder / "noise_normal.png").astype(int)).max() <= 1
