"""A preset's ``keepVariance`` against the command line's ``--keep-variance``.

The truth: the bytes ``matshop export --size N --keep-variance`` writes (the
flag, tested against closed forms in test_variance.py), and the plain
downsized export's own pixels read back with OpenImageIO: keeping the variance
may only raise roughness; colours, normals and the other packed channels stay
byte for byte what the plain export wrote.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from oracle import file_codes

from matshop.cli import main
from matshop.io.images import write_image

SIZE = 64
SMALL = "16"


def bumpy_set(folder: Path) -> Path:
    """A 64x64 texture set with bumps a few texels wide (tilts up to ~30 degrees)
    and varied roughness, as 16-bit PNGs."""
    folder.mkdir()
    rows, cols = np.mgrid[0:SIZE, 0:SIZE] * (2 * np.pi / SIZE)
    # slopes of a tiling height with periods of 4 and 8 texels
    sx = 0.4 * np.cos(16 * cols) + 0.2 * np.sin(8 * (rows + cols))
    sy = 0.4 * np.sin(16 * rows) + 0.2 * np.sin(8 * (rows + cols))
    normal = np.stack([-sx, -sy, np.ones_like(sx)], axis=-1)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    rng = np.random.default_rng(7)
    write_image(folder / "b_normal_gl.png", 0.5 * normal + 0.5, bit_depth="uint16")
    write_image(
        folder / "b_roughness.png", rng.uniform(0.15, 0.6, (SIZE, SIZE, 1)), bit_depth="uint16"
    )
    write_image(folder / "b_basecolor.png", rng.uniform(0, 1, (SIZE, SIZE, 3)), bit_depth="uint16")
    write_image(folder / "b_metallic.png", rng.uniform(0, 1, (SIZE, SIZE, 1)), bit_depth="uint16")
    return folder


def studio_preset(path: Path, keep_variance: object) -> Path:
    """An engine-like preset: packed 8-bit ORM (dithered), 8-bit colour and normal, and a
    float roughness file."""
    preset = {
        "name": "studio",
        "normalConvention": "opengl",
        "keepVariance": keep_variance,
        "maps": [
            {"channel": "BaseColor", "fileFormat": "png", "bitDepth": 8,
             "srcMapName": "base_color"},
            {"channel": "Normal", "fileFormat": "png", "bitDepth": 8, "srcMapName": "normal",
             "dithering": False},
            {"channel": "ORM", "fileFormat": "png", "bitDepth": 8, "channels": [
                {"destChannel": "R", "srcMapName": "ao"},
                {"destChannel": "G", "srcMapName": "roughness"},
                {"destChannel": "B", "srcMapName": "metallic"}]},
            {"channel": "Roughness", "fileFormat": "exr", "bitDepth": "float",
             "srcMapName": "roughness"},
        ],
    }  # fmt: skip
    path.write_text(json.dumps(preset))
    return path


def export(source: Path, out: Path, preset: Path, *flags: str) -> dict[str, object]:
    """What the export wrote: each PNG's bytes, each EXR's float pixels (an EXR's
    header holds its write time, ``capDate``, so its bytes differ from run to run)."""
    assert main(["export", str(source), str(out), "--preset-file", str(preset), *flags]) == 0
    return {
        p.name: file_codes(p).tobytes() if p.suffix == ".exr" else p.read_bytes()
        for p in sorted(out.iterdir())
    }


def test_preset_keep_variance_writes_what_the_flag_writes_and_only_widens(tmp_path: Path) -> None:
    source = bumpy_set(tmp_path / "in")
    keeps = studio_preset(tmp_path / "keeps.json", True)
    plain = studio_preset(tmp_path / "plain.json", False)

    by_preset = export(source, tmp_path / "a", keeps, "--size", SMALL)
    by_flag = export(source, tmp_path / "b", plain, "--size", SMALL, "--keep-variance")
    assert by_preset == by_flag
    # the flag overrides the preset both ways
    unkept = export(source, tmp_path / "c", keeps, "--size", SMALL, "--no-keep-variance")
    without = export(source, tmp_path / "d", plain, "--size", SMALL)
    assert unkept == without
    assert by_preset != without
    # not downsizing: nothing to keep, the preset's setting changes nothing
    assert export(source, tmp_path / "e", keeps) == export(source, tmp_path / "f", plain)

    def codes(folder: str, name: str) -> np.ndarray:
        return file_codes(tmp_path / folder / name)

    # colours: the very bytes of the plain downsized export
    assert by_preset["b_BaseColor.png"] == without["b_BaseColor.png"]
    # normals: each small texel's is the unit mean of the source's over its 4x4 area
    # (as log-rotations, within a code of the renormalised vector mean); the plain
    # export's Lanczos-3 is up to 3 codes off it
    normal = 2 * file_codes(source / "b_normal_gl.png") - 1  # 16-bit: floats in [0, 1]
    mean = normal.reshape(16, 4, 16, 4, 3).mean(axis=(1, 3))
    mean /= np.linalg.norm(mean, axis=-1, keepdims=True)
    assert np.abs(codes("a", "b_Normal.png") - np.round(127.5 * mean + 127.5)).max() <= 1
    kept_orm, plain_orm = codes("a", "b_ORM.png"), codes("d", "b_ORM.png")
    assert kept_orm.shape == (16, 16, 3)
    # occlusion and metallic untouched; the roughness never below its 4x4 area's mean
    # (the GGX edit coordinate, the median angle atan(r^2)), higher where bumps were lost
    assert np.array_equal(kept_orm[..., [0, 2]], plain_orm[..., [0, 2]])
    rough = file_codes(source / "b_roughness.png")[..., 0]
    area = np.sqrt(np.tan(np.arctan(rough**2).reshape(16, 4, 16, 4).mean(axis=(1, 3))))
    kept_r = codes("a", "b_Roughness.exr")[..., 0]
    assert np.all(kept_r >= area - 1e-6) and np.mean(kept_r > area + 1e-3) > 0.5
    assert np.all(kept_orm[..., 1] >= np.floor(255 * area))
    assert np.mean(kept_orm[..., 1] > np.round(255 * area) + 1) > 0.5


@pytest.mark.parametrize("value", ["maybe", 1, None])
def test_bad_keep_variance_in_a_preset_is_one_line(
    tmp_path: Path, capfd: pytest.CaptureFixture[str], value: object
) -> None:
    source = bumpy_set(tmp_path / "in")
    preset = studio_preset(tmp_path / "bad.json", value)
    capfd.readouterr()
    out = tmp_path / "out"
    argv = ["export", str(source), str(out), "--preset-file", str(preset), "--size", SMALL]
    assert main(argv) == 2
    err = capfd.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert "bad.json" in err[0] and "keepVariance" in err[0]
    assert not out.exists()


def test_builtin_presets_say_keep_variance_and_the_help_names_it(
    capfd: pytest.CaptureFixture[str],
) -> None:
    from matshop.export.presets import builtin_preset_names, load_preset

    for name in builtin_preset_names():
        text = (Path(__file__).parents[1] / "matshop/export/presets" / f"{name}.json").read_text()
        assert json.loads(text)["keepVariance"] is False
        assert load_preset(name).keep_variance is False
    with pytest.raises(SystemExit):
        main(["export", "--help"])
    assert "--no-keep-variance" in capfd.readouterr().out
