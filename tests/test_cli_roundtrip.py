"""`matshop info` and `matshop convert` on the real chessboard set and the bundled sample."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from matshop.cli import main
from matshop.io.images import read_image, write_image
from matshop.io.material_io import load_material
from matshop.spaces.frame import decode_normal_map

ROOT = Path(__file__).resolve().parents[1]
CHESSBOARD = ROOT.parent / "shared" / "data" / "chessboard"
SAMPLE = ROOT / "resources" / "sample"

needs_chessboard = pytest.mark.skipif(
    not CHESSBOARD.is_dir(), reason="shared chessboard texture set not present"
)


@needs_chessboard
def test_info_describes_the_chessboard(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["info", str(CHESSBOARD)]) == 0
    out = capsys.readouterr().out
    assert "2048 x 2048" in out
    for name in ("base_color", "normal", "roughness", "metallic"):
        assert name in out
    assert "sRGB" in out and "opengl normals" in out
    assert "edit vector: 8 channels" in out


def _angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    cos = np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)
    return np.degrees(np.arccos(cos))


@needs_chessboard
def test_convert_round_trips_8bit_codes_exactly(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert main(["convert", str(CHESSBOARD), str(out)]) == 0
    original, _ = load_material(CHESSBOARD)
    for name, tag in (
        ("base_color", "basecolor"),
        ("roughness", "roughness"),
        ("metallic", "metallic"),
    ):
        written, info = read_image(out / f"chessboard_{tag}.png")
        assert info.bit_depth == "uint8"
        codes_in = np.rint(original.maps[name] * 255)
        codes_out = np.rint(written[..., : original.maps[name].shape[2]] * 255)
        worst = np.abs(codes_in - codes_out).max()
        assert worst == 0, f"{name}: 8-bit codes moved by {worst}"
    # normals: back to the same direction within one 8-bit quantisation step
    rgb, _ = read_image(out / "chessboard_normal_gl.png")
    back = decode_normal_map(rgb, convention="opengl")
    worst = _angle_deg(back, original.maps["normal"]).max()
    one_step_deg = np.degrees(2.0 / 255.0)  # 2/255 in [-1, 1] at the sphere's steepest
    print(f"chessboard normals: worst {worst:.3f} deg (one 8-bit step {one_step_deg:.3f})")
    assert worst <= one_step_deg


def _crop_of_chessboard(folder: Path, size: int = 256) -> Path:
    """A centre crop of every chessboard map (a full 2K x 128-channel set takes minutes)."""
    folder.mkdir()
    for path in sorted(CHESSBOARD.iterdir()):
        array, _ = read_image(path)
        r0 = (array.shape[0] - size) // 2
        c0 = (array.shape[1] - size) // 2
        write_image(folder / f"{path.stem}.png", array[r0 : r0 + size, c0 : c0 + size])
    return folder


@needs_chessboard
def test_sampled_distribution_from_real_roughness(tmp_path: Path) -> None:
    crop = _crop_of_chessboard(tmp_path / "crop")
    out = tmp_path / "sampled"
    assert main(["convert", str(crop), str(out), "--sampled-distribution"]) == 0
    d, info = read_image(out / "chessboard_distribution.exr")
    assert d.shape[2] == 128 and info.channel_names[0] == "d.000"
    edges = np.linspace(0, np.pi / 2, 129)
    bin_measure = 2 * np.pi * np.diff(np.sin(edges) ** 2) / 2
    mass = d.astype(np.float64) * bin_measure
    assert np.all(d >= 0)
    assert np.abs(mass.sum(axis=-1) - 1).max() < 1e-2, "every texel's lobe is normalised"
    # each lobe is GGX with alpha = r^2, whose median angle is atan(alpha) in closed form
    roughness, _ = read_image(crop / "chessboard_roughness.png")
    alpha = np.clip(roughness[..., 0].astype(np.float64) ** 2, 0.02, 1.0)
    rng = np.random.default_rng(0)
    for r, c in rng.integers(0, d.shape[0], size=(200, 2)):
        cdf = np.concatenate([[0.0], np.cumsum(mass[r, c])])
        median = np.interp(0.5 * cdf[-1], cdf, edges)
        assert abs(median - np.arctan(alpha[r, c])) < 0.5 * (edges[1] - edges[0])
    reloaded, _ = load_material(out)
    assert reloaded.schema.names == ("base_color", "metallic", "distribution", "normal")


def test_demo_runs_on_the_bundled_sample(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "matshop", "demo", str(SAMPLE), "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr
    assert "worst error" in result.stdout
    from oracle import file_codes

    # the round trip wrote the source's codes (OpenImageIO on both files)
    for tag in ("basecolor", "roughness", "metallic", "ao"):
        written = file_codes(tmp_path / "roundtrip" / f"tiles_{tag}.png")
        assert np.abs(written - file_codes(SAMPLE / f"tiles_{tag}.png")).max() <= 1, tag
    # the sampled set's tables are lobes: pi sum d (sin^2 b - sin^2 a) = 1 in every texel
    table = file_codes(tmp_path / "sampled" / "tiles_distribution.exr").astype(np.float64)
    assert table.shape[2] == 128
    edges = np.arange(129) * (np.pi / 2 / 128)
    mass = np.pi * table @ np.diff(np.sin(edges) ** 2)
    np.testing.assert_allclose(mass, 1.0, atol=2e-3)
    # the layered part: the project flattens to what the demo wrote
    from matshop.io.material_io import load_material
    from matshop.io.project import load_project

    doc = load_project(tmp_path / "layered.matshop").document
    assert [layer.name for layer in doc.layers] == ["Base", "Bronze", "Rust"]
    written, _ = load_material(tmp_path / "layered")
    for name, values in doc.physical().items():
        # one 8-bit code; normals store n = 2 v - 1 (two units per code) and are renormalised
        step = 2.5 / 255 if name == "normal" else 1 / 255 + 1e-6
        assert np.abs(written.maps[name] - values).max() <= step, name
    assert (tmp_path / "layered_ball.png").stat().st_size > 10_000
