"""Images as layer content through the command line: the flattened project's exported maps
hold the imported image's own codes (read back with OpenImageIO) where the layer covers,
within 1 code; a height ramp becomes the constant tilt atan(slope); an image as a mask
reveals exactly where it is white; a wrong size is resampled with a note; a bad file is
one line naming it, exit 2, the project unchanged."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest

from matshop.cli import main

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"
SIZE = 512


def write(path: Path, codes: np.ndarray) -> Path:
    """Write integer codes (H, W[, C]) as a PNG with OpenImageIO (uint8 or uint16)."""
    codes = codes if codes.ndim == 3 else codes[..., None]
    spec = oiio.ImageSpec(codes.shape[1], codes.shape[0], codes.shape[2], str(codes.dtype))
    if codes.shape[2] == 4:
        spec.attribute("oiio:UnassociatedAlpha", 1)
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec) and out.write_image(codes) and out.close()
    return path


def read(path: Path) -> np.ndarray:
    """A file's codes as integers (H, W, C)."""
    inp = oiio.ImageInput.open(str(path))
    spec = inp.spec()
    fmt = "uint16" if spec.format == oiio.TypeDesc("uint16") else "uint8"
    pixels = inp.read_image(0, 0, 0, spec.nchannels, fmt)
    inp.close()
    return pixels.reshape(spec.height, spec.width, spec.nchannels).astype(np.int64)


def run(*argv: object) -> int:
    return main([str(a) for a in argv])


@pytest.fixture
def project(tmp_path: Path) -> Path:
    path = tmp_path / "p.matshop"
    assert run("new", path, "--from", SAMPLE) == 0
    return path


def flattened(project: Path, tmp_path: Path, name: str) -> np.ndarray:
    out = tmp_path / "out"
    assert run("flatten", project, out) == 0
    return read(next(out.glob(f"*_{name}*.png")))


def test_a_color_image_with_alpha_gives_its_own_codes_where_it_covers(
    project: Path, tmp_path: Path
) -> None:
    rng = np.random.default_rng(7)
    rgba = rng.integers(0, 256, (SIZE, SIZE, 4)).astype(np.uint8)
    rgba[..., 3] = 0
    rgba[:, : SIZE // 2, 3] = 255  # the left half covers, the right half is transparent
    image = write(tmp_path / "decal.png", rgba)
    assert run("layer", "add", project, "image", image, "--params", "base_color") == 0
    base = flattened(project, tmp_path, "basecolor")
    original = read(SAMPLE / "tiles_basecolor.png")
    codes = read(image)
    assert np.abs(base[:, : SIZE // 2] - codes[:, : SIZE // 2, :3]).max() <= 1
    assert np.abs(base[:, SIZE // 2 :] - original[:, SIZE // 2 :]).max() <= 1  # uncovered
    # only base color changed
    roughness = flattened(project, tmp_path / "again", "roughness")
    assert np.array_equal(roughness, read(SAMPLE / "tiles_roughness.png"))


def test_a_gray_image_is_roughness_and_a_color_image_its_luminance(
    project: Path, tmp_path: Path
) -> None:
    ramp = np.tile(np.arange(SIZE) * 65535 // (SIZE - 1), (SIZE, 1)).astype(np.uint16)
    gray = write(tmp_path / "rough.png", ramp)
    assert run("layer", "add", project, "image", gray, "--params", "roughness") == 0
    roughness = flattened(project, tmp_path, "roughness")[..., 0]
    # the export writes 8 bits: the 16-bit codes scaled, within 1 code
    assert np.abs(roughness - np.round(read(gray)[..., 0] * 255 / 65535)).max() <= 1
    rng = np.random.default_rng(2)
    rgb = rng.integers(0, 256, (SIZE, SIZE, 3)).astype(np.uint8)
    color = write(tmp_path / "metal.png", rgb)
    assert run("layer", "add", project, "image", color, "--params", "metallic") == 0
    metallic = flattened(project, tmp_path / "m", "metallic")[..., 0]
    luma = read(color) @ np.array([0.2126, 0.7152, 0.0722])  # Rec. 709, on the codes
    assert np.abs(metallic - luma).max() <= 1


@pytest.mark.parametrize("height_px", [40.0, 150.0])
def test_a_height_ramp_becomes_a_constant_tilt_of_atan_slope(
    height_px: float, project: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    # height rises to the right by 1/(SIZE-1) of its range per texel (16-bit codes)
    ramp = np.tile(np.arange(SIZE) * 65535 // (SIZE - 1), (SIZE, 1)).astype(np.uint16)
    image = write(tmp_path / "height.png", ramp)
    argv = ["layer", "add", project, "image", image, "--as-height", "--height-px", height_px]
    assert run(*argv) == 0
    normal = flattened(project, tmp_path, "normal")
    tilt = math.atan(height_px / (SIZE - 1))  # away from the uphill side: -x
    expected = np.array([-math.sin(tilt), 0.0, math.cos(tilt)])
    codes = np.round((expected + 1) / 2 * 255)
    inside = normal[:, 2:-2]  # the texture tiles: the ramp's wrap-around seam is a cliff
    assert np.abs(inside - codes).max() <= 1
    assert abs(math.degrees(tilt)) > 4  # a visible tilt, not the flat normal


def test_an_image_as_mask_reveals_where_it_is_white(project: Path, tmp_path: Path) -> None:
    assert run("layer", "add", project, "fill", "--value", "roughness=0.9", "--name", "R") == 0
    mask = np.zeros((SIZE, SIZE), np.uint8)
    mask[: SIZE // 4] = 255
    image = write(tmp_path / "mask.png", mask)
    assert run("layer", "add", project, "image", image, "--as-mask", "--layer", "R") == 0
    roughness = flattened(project, tmp_path, "roughness")[..., 0]
    assert np.abs(roughness[: SIZE // 4] - round(0.9 * 255)).max() <= 1
    original = read(SAMPLE / "tiles_roughness.png")[..., 0]
    assert np.array_equal(roughness[SIZE // 4 :], original[SIZE // 4 :])


def test_a_larger_image_is_resampled_with_a_note(
    project: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    rng = np.random.default_rng(4)
    blocks = rng.integers(0, 256, (SIZE, SIZE, 3)).astype(np.uint8)
    big = np.repeat(np.repeat(blocks, 2, axis=0), 2, axis=1)  # each code on 2x2 texels
    image = write(tmp_path / "big.png", big)
    capfd.readouterr()
    assert run("layer", "add", project, "image", image, "--params", "base_color") == 0
    out = capfd.readouterr().out
    assert "big.png is 1024x1024, the project 512x512: resampled" in out
    base = flattened(project, tmp_path, "basecolor")
    assert np.abs(base - blocks).max() <= 1  # area averaging of equal texels


@pytest.mark.parametrize(
    ("content", "argv", "expected"),
    [
        (None, ["--params", "roughness"], "missing.png: file not found"),
        (b"not a png", ["--params", "roughness"], "bad.png: not a readable image"),
        (b"", ["--params", "sheen"], "not sheen"),
        (b"", [], "needs --params"),
        (b"", ["--as-height", "--params", "roughness"], "pick the normal parameter"),
        (b"", ["--as-mask", "--params", "roughness"], "--params does not apply with --as-mask"),
    ],
)
def test_bad_image_requests_are_one_line_and_leave_the_project_alone(
    content: bytes | None,
    argv: list[str],
    expected: str,
    project: Path,
    tmp_path: Path,
    capfd: pytest.CaptureFixture[str],
) -> None:
    if content is None:
        image = tmp_path / "missing.png"
    elif content:
        image = tmp_path / "bad.png"
        image.write_bytes(content)
    else:
        image = write(tmp_path / "fine.png", np.full((8, 8), 128, np.uint8))
    before = project.read_bytes()
    capfd.readouterr()
    assert run("layer", "add", project, "image", image, *argv) == 2
    err = capfd.readouterr().err.strip().splitlines()
    assert len(err) == 1 and expected in err[0], err
    assert project.read_bytes() == before
