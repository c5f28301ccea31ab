"""Export writing: all-or-nothing files, --force, --strict, bad folders, dithering, resizing."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

import matshop.io.fileset as writer
from matshop.errors import MatshopError
from matshop.export.core import export_material
from matshop.export.quantize import quantize
from matshop.export.resize import resampling_matrix, resize_array, target_size
from matshop.io.images import read_image
from matshop.io.material_io import load_material
from matshop.material import Material, Schema

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


@pytest.fixture(scope="module")
def small() -> Material:
    """The bundled sample without occlusion, at 128 texels (fast)."""
    material, _ = load_material(SAMPLE)
    maps = {n: a[::4, ::4].copy() for n, a in material.maps.items() if n != "ao"}
    names = [n for n in material.schema.names if n != "ao"]
    return Material("tiles", Schema.from_names(names), maps, material.sources)


def _listing(folder: Path) -> dict[str, bytes]:
    """Every entry (hidden ones too) with its bytes."""
    return {p.name: (p.read_bytes() if p.is_file() else b"<dir>") for p in folder.iterdir()}


def test_missing_parameter_is_filled_and_reported(small: Material, tmp_path: Path) -> None:
    summary = export_material(small, "unreal", tmp_path)
    assert summary.warnings == ["ORM: the material has no ao; filled with (1)"]
    orm, _ = read_image(summary.file("_ORM.png"))
    assert np.all(orm[..., 0] == 1.0)
    assert any("warning: ORM" in line for line in summary.lines())


def test_strict_refuses_missing_parameter_before_writing(small: Material, tmp_path: Path) -> None:
    out = tmp_path / "out"
    with pytest.raises(MatshopError, match="ORM needs ao.*strict") as caught:
        export_material(small, "unreal", out, strict=True)
    assert "\n" not in str(caught.value)
    assert not out.exists()


def test_existing_files_need_force(small: Material, tmp_path: Path) -> None:
    first = export_material(small, "gltf", tmp_path)
    before = _listing(tmp_path)
    brighter = dict(small.maps, base_color=np.clip(small.maps["base_color"] + 0.2, 0, 1))
    changed = Material(small.name, small.schema, brighter, small.sources)
    with pytest.raises(MatshopError, match="already exist.*--force"):
        export_material(changed, "gltf", tmp_path)
    assert _listing(tmp_path) == before
    export_material(changed, "gltf", tmp_path, force=True)
    after = _listing(tmp_path)
    assert set(after) == set(before)  # no staging folders or temp files left
    assert after[first.file("_baseColor.png").name] != before[first.file("_baseColor.png").name]


def test_failure_mid_write_leaves_nothing_half_written(
    small: Material, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "tiles_ORM.png").write_bytes(b"the previous export")
    before = _listing(tmp_path)
    real = writer.write_one
    calls = []

    def fail_after_first(pending: writer.PendingFile, path: Path) -> None:
        calls.append(pending.name)
        if len(calls) > 1:
            raise MatshopError("disk full (simulated)", path)
        real(pending, path)

    monkeypatch.setattr(writer, "write_one", fail_after_first)
    with pytest.raises(MatshopError, match="disk full"):
        export_material(small, "unreal", tmp_path, force=True)
    # the first file was written (into staging) before the failure; files go two at a
    # time, so a third may have started before the second failed
    assert 2 <= len(calls) <= 3
    assert _listing(tmp_path) == before


def test_failure_while_renaming_restores_previous_files(
    small: Material, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    export_material(small, "godot", tmp_path)
    before = _listing(tmp_path)
    real_replace = os.replace
    moved = []

    def flaky_replace(src: os.PathLike, dst: os.PathLike) -> None:
        if Path(dst).parent == tmp_path and not Path(dst).name.startswith("."):
            moved.append(dst)
            if len(moved) == 2:
                raise OSError(28, "No space left on device")
        real_replace(src, dst)

    monkeypatch.setattr(writer.os, "replace", flaky_replace)
    changed = Material(
        small.name, small.schema, dict(small.maps, metallic=1 - small.maps["metallic"])
    )
    with pytest.raises(MatshopError, match="No space left"):
        export_material(changed, "godot", tmp_path, force=True)
    monkeypatch.undo()
    assert _listing(tmp_path) == before


def test_unwritable_output_folder_is_a_clear_error(small: Material, tmp_path: Path) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    with pytest.raises(MatshopError, match="not a folder"):
        export_material(small, "gltf", blocker)
    with pytest.raises(MatshopError, match="cannot write here") as caught:
        export_material(small, "gltf", blocker / "sub")
    assert str(blocker / "sub") in str(caught.value)
    if os.geteuid() != 0:  # root writes anywhere: permissions cannot be tested as root
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        with pytest.raises(MatshopError, match="cannot write here"):
            export_material(small, "gltf", locked)


def _longest_run(row: np.ndarray) -> int:
    edges = np.flatnonzero(np.diff(row) != 0)
    bounds = np.concatenate([[-1], edges, [row.size - 1]])
    return int(np.diff(bounds).max())


def test_dithered_ramp_has_no_bands(tmp_path: Path) -> None:
    """A roughness ramp over ~25 codes across 1024 texels: plain rounding makes
    flat bands ~40 texels wide; dithered codes keep every region's mean."""
    width, rows = 1024, 64
    ramp = np.linspace(0.40, 0.50, width, dtype=np.float64)
    roughness = np.broadcast_to(ramp[None, :, None], (rows, width, 1)).astype(np.float32)
    material = Material("ramp", Schema.from_names(["roughness"]), {"roughness": roughness})
    summary = export_material(material, "gltf", tmp_path)
    orm, _ = read_image(summary.file("_occlusionRoughnessMetallic.png"))
    codes = np.rint(orm[..., 1] * 255)
    plain = np.rint(roughness[..., 0] * 255)

    band = _longest_run(plain[0])
    assert band >= 30  # the undithered step this test is about
    assert max(_longest_run(r) for r in codes) <= band / 2

    block = 8  # texels per region along the ramp (all rows): a fraction of a band
    truth = (ramp * 255).reshape(-1, block).mean(axis=1)
    dithered_means = codes.reshape(rows, -1, block).mean(axis=(0, 2))
    plain_means = plain.reshape(rows, -1, block).mean(axis=(0, 2))
    assert np.abs(dithered_means - truth).max() < 0.05  # codes
    assert np.abs(plain_means - truth).max() > 0.3  # rounding is biased per band
    assert np.abs(codes - roughness[..., 0] * 255).max() < 1.0  # still within a code


def test_quantize_keeps_grid_values_and_constants() -> None:
    codes = np.arange(256, dtype=np.float32).reshape(16, 16, 1) / 255
    smooth = 1.0 - (1.0 - codes)  # float32 arithmetic a few ulps off the grid
    assert np.array_equal(quantize(smooth, "uint8", dither=True), codes)
    flat = np.full((8, 8, 1), 0.3, dtype=np.float32)
    assert np.unique(quantize(flat, "uint8", dither=True)).size == 1
    again = quantize(np.linspace(0, 1, 999).reshape(1, -1, 1), "uint8", dither=True, seed=5)
    same = quantize(np.linspace(0, 1, 999).reshape(1, -1, 1), "uint8", dither=True, seed=5)
    assert np.array_equal(again, same)  # reproducible exports
    deep = quantize(np.linspace(0, 1, 999).reshape(1, -1, 1), "uint16", dither=True)
    assert np.abs(deep - np.linspace(0, 1, 999).reshape(1, -1, 1)).max() <= 0.5 / 65535 + 1e-7


def test_resampling_is_normalised_periodic_and_sizes_are_powers_of_two() -> None:
    weights = resampling_matrix(64, 16)
    np.testing.assert_allclose(np.asarray(weights.sum(axis=1)).ravel(), 1.0, atol=1e-12)
    x = np.arange(64)
    wave = np.sin(2 * np.pi * 3 * x / 64)[None, :, None] * np.ones((64, 1, 1))
    small = resize_array(wave.astype(np.float32), (16, 16))
    # a periodic wave well below the new Nyquist survives, seam included
    np.testing.assert_allclose(
        small[0, :, 0], np.sin(2 * np.pi * 3 * (np.arange(16) + 0.375) / 16), atol=0.05
    )
    # a wave above the new Nyquist is filtered out, not aliased
    fine = np.sin(2 * np.pi * 28 * x / 64)[None, :, None] * np.ones((64, 1, 1))
    assert np.abs(resize_array(fine.astype(np.float32), (16, 16))).max() < 0.05
    assert target_size((2048, 2048), 512) == (512, 512)
    assert target_size((1000, 2000), 1024) == (512, 1024)
    with pytest.raises(MatshopError, match="power of two"):
        target_size((512, 512), 300)
