"""``export --size N --keep-variance``: each small texel stands for its own area.

With the option, a reduced texel's normal and lobe are the area means over the
input texels its extent covers and its lobe is widened by the slopes' spread over
that same area; without it every channel is Lanczos-3, as before the option
existed. The truth here is worked out by hand from the fields each test writes
(tilts in one plane average as angles; a two-tilt mixture's slope variance is
``p (1 - p) (s_a - s_b)^2``) or computed by a brute-force Lanczos-3 written in
this file, all from the source files' own pixels.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from test_variance import HAND_TRACE, TILT_A, TILT_B, _checker, _tilted

from matshop.cli import main
from matshop.export.resize import area_matrix
from matshop.io.images import read_image, write_image


def _write(folder: Path, normal: np.ndarray, rough: np.ndarray) -> Path:
    """A set of 16-bit PNGs: the normal (OpenGL), the roughness and a random colour."""
    folder.mkdir()
    size = normal.shape[0]
    rng = np.random.default_rng(4)
    write_image(folder / "v_basecolor.png", rng.uniform(0, 1, (size, size, 3)), bit_depth="uint16")
    write_image(folder / "v_roughness.png", rough, bit_depth="uint16")
    write_image(folder / "v_normal_gl.png", 0.5 * normal + 0.5, bit_depth="uint16")
    return folder


def _export(source: Path, out: Path, size: int, *flags: str) -> dict[str, np.ndarray]:
    """The raw preset's normal (decoded from ``0.5 n + 0.5``) and roughness as written."""
    argv = ["export", str(source), str(out), "--preset", "raw", "--size", str(size), *flags]
    assert main(argv) == 0
    normal, _ = read_image(next(out.glob("*normal*")))
    rough, _ = read_image(next(out.glob("*roughness*")))
    return {"normal": 2.0 * normal.astype(np.float64) - 1.0, "roughness": rough.astype(np.float64)}


def _source(folder: Path) -> dict[str, np.ndarray]:
    """The set's own pixels: unit normals decoded from their codes, roughness."""
    codes, _ = read_image(folder / "v_normal_gl.png")
    normal = 2.0 * codes.astype(np.float64) - 1.0
    rough, _ = read_image(folder / "v_roughness.png")
    return {
        "normal": normal / np.linalg.norm(normal, axis=-1, keepdims=True),
        "roughness": rough.astype(np.float64),
    }


def _x_tilt(normal: np.ndarray) -> np.ndarray:
    """The tilt angle of normals in the x-z plane (radians)."""
    return np.arctan2(normal[..., 0], normal[..., 2])


def _block_mean(a: np.ndarray, factor: int) -> np.ndarray:
    h, w = a.shape[:2]
    return a.reshape(h // factor, factor, w // factor, factor, *a.shape[2:]).mean(axis=(1, 3))


def _lanczos3(line: np.ndarray, n_out: int) -> np.ndarray:
    """Periodic Lanczos-3 reduction of a 1-D signal, tap by tap: the kernel stretched by
    the factor, centres aligned, weights normalised to sum to one."""
    n_in = line.size
    scale = n_in / n_out
    out = np.empty(n_out)
    for j in range(n_out):
        centre = (j + 0.5) * scale - 0.5
        total = weight_sum = 0.0
        for i in range(math.floor(centre - 3 * scale), math.ceil(centre + 3 * scale) + 1):
            x = (i - centre) / scale
            if abs(x) >= 3:
                continue
            w = np.sinc(x) * np.sinc(x / 3)
            total += w * line[i % n_in]
            weight_sum += w
        out[j] = total / weight_sum
    return out


def test_a_constant_tilt_keeps_its_normal_and_its_area_mean_lobe(tmp_path: Path) -> None:
    # one tilt everywhere loses no variance: the normal is the source's, the lobe each
    # small texel's area mean in the GGX edit coordinate, the median angle atan(r^2)
    size, small = 32, 8
    normal = np.broadcast_to(_tilted(0.3, -0.2), (size, size, 3)).astype(np.float32)
    rough = np.random.default_rng(1).uniform(0.1, 0.7, (size, size, 1))
    source = _source(_write(tmp_path / "in", normal, rough))
    got = _export(tmp_path / "in", tmp_path / "out", small, "--keep-variance")
    assert got["normal"].shape == (small, small, 3)
    np.testing.assert_allclose(got["normal"], source["normal"][:small, :small], atol=3e-5)
    median = _block_mean(np.arctan(source["roughness"] ** 2), size // small)
    np.testing.assert_allclose(got["roughness"], np.sqrt(np.tan(median)), rtol=1e-5)


def test_two_tilts_reduced_to_one_texel_give_their_unit_mean_and_their_variance(
    tmp_path: Path,
) -> None:
    # a 2x2 checkerboard of tilts 0.1 and 0.5 rad in the x-z plane exported to one
    # texel: the unit mean of the two normals (tilt 0.3 rad) and a GGX alpha^2 grown by
    # their slope variance, half and half: (tan 0.5 - tan 0.1)^2 / 4
    normal = _checker(_tilted(0.1, 0.0), _tilted(0.5, 0.0), 2)
    source = _source(_write(tmp_path / "in", normal, np.full((2, 2, 1), 0.3)))
    got = _export(tmp_path / "in", tmp_path / "out", 1, "--keep-variance")
    mean = source["normal"].sum(axis=(0, 1))
    np.testing.assert_allclose(got["normal"][0, 0], mean / np.linalg.norm(mean), atol=3e-5)
    slopes = np.tan(_x_tilt(source["normal"]))
    lost = np.var(slopes)  # the population variance of the four, by hand (s_a - s_b)^2 / 4
    assert abs(lost - (math.tan(0.5) - math.tan(0.1)) ** 2 / 4) < 1e-4
    r4 = np.mean(source["roughness"] ** 2) ** 2
    np.testing.assert_allclose(got["roughness"][0, 0, 0], (r4 + lost) ** 0.25, rtol=1e-5)


def test_export_keep_variance_checkerboard_downsized(tmp_path: Path) -> None:
    normal = _checker(_tilted(*TILT_A), _tilted(*TILT_B), 64)
    folder = _write(tmp_path / "in", normal, np.full((64, 64, 1), 0.3))
    kept = _export(folder, tmp_path / "kept", 8, "--keep-variance")["roughness"]
    plain = _export(folder, tmp_path / "plain", 8)["roughness"]
    assert kept.shape[:2] == (8, 8)
    np.testing.assert_allclose(plain, 0.3, atol=1e-4)
    # each small texel's 8x8 area holds the two tilts half and half: the hand value
    # (up to the 16-bit normal codes)
    np.testing.assert_allclose(kept, (0.3**4 + HAND_TRACE) ** 0.25, rtol=2e-4)


def test_only_the_texels_whose_area_holds_a_groove_tilt_or_widen(tmp_path: Path) -> None:
    # one groove column tilted 0.4 rad in a flat 64^2 field, reduced 4x: the small
    # column whose 4-texel area holds it has a quarter of its area tilted, so its normal
    # is tilted 0.1 rad and it loses p (1 - p) tan(0.4)^2 with p = 1/4; its neighbours,
    # which Lanczos-3 reaches (and the plain export rings into), are flat with the
    # source's roughness
    size, groove = 64, 21  # column 21 lies in small column 5 (texels 20..23)
    normal = np.broadcast_to(_tilted(0.0, 0.0), (size, size, 3)).copy()
    normal[:, groove] = _tilted(0.4, 0.0)
    folder = _write(tmp_path / "in", normal, np.full((size, size, 1), 0.3))
    source = _source(folder)
    kept = _export(folder, tmp_path / "kept", 16, "--keep-variance")
    plain = _export(folder, tmp_path / "plain", 16)
    holds = np.zeros(16, bool)
    holds[groove // 4] = True
    # the source's own tilts (its flat texels' 16-bit codes are 1.5e-5 rad off flat)
    src_tilt = _x_tilt(source["normal"][0])
    tilt = _x_tilt(kept["normal"])
    np.testing.assert_allclose(tilt[:, holds], src_tilt[20:24].mean(), atol=3e-5)
    np.testing.assert_allclose(tilt[:, ~holds], src_tilt[0], atol=3e-6)
    groove_tilt = abs(src_tilt[groove])
    assert np.abs(_x_tilt(plain["normal"][:, ~holds])).max() > 1e-3  # Lanczos' ringing
    r = source["roughness"][0, 0, 0]
    np.testing.assert_allclose(kept["roughness"][:, ~holds], r, rtol=1e-6)
    lost = 0.25 * 0.75 * math.tan(groove_tilt) ** 2
    np.testing.assert_allclose(kept["roughness"][:, holds], (r**4 + lost) ** 0.25, rtol=2e-4)


def test_plain_export_is_lanczos3_and_the_option_the_area_mean(tmp_path: Path) -> None:
    # normals tilted in the x-z plane by an angle that varies along x, and a roughness
    # varying along x: in edit space (log-rotations, median angles) both are linear in the
    # angle and in the GGX median angle atan(r^2), so the plain export is a Lanczos-3 of
    # them (brute force here)
    # and, with the option, the area mean (plus the widening, absent where a small
    # texel's area is one tilt: here each run of 4 texels shares one)
    size, small = 64, 16
    x = np.arange(size)
    angle = 0.35 * np.sin(2 * np.pi * 3 * (x // 4) / 16) + 0.2 * ((x // 4) % 3 == 0)
    normal = np.stack([np.sin(angle), np.zeros(size), np.cos(angle)], axis=-1)
    normal = np.broadcast_to(normal[None], (size, size, 3)).astype(np.float32)
    rough = np.broadcast_to((0.2 + 0.5 * (x % 7) / 6)[None, :, None], (size, size, 1))
    source = _source(_write(tmp_path / "in", normal, rough))
    plain = _export(tmp_path / "in", tmp_path / "plain", small)
    kept = _export(tmp_path / "in", tmp_path / "kept", small, "--keep-variance")
    src_angle = _x_tilt(source["normal"][0])
    src_median = np.arctan(source["roughness"][0, :, 0] ** 2)
    np.testing.assert_allclose(_x_tilt(plain["normal"][0]), _lanczos3(src_angle, small), atol=3e-5)
    np.testing.assert_allclose(
        plain["roughness"][0, :, 0], np.sqrt(np.tan(_lanczos3(src_median, small))), rtol=2e-6
    )
    np.testing.assert_allclose(
        _x_tilt(kept["normal"][0]), src_angle.reshape(small, 4).mean(axis=1), atol=3e-5
    )
    area_median = src_median.reshape(small, 4).mean(axis=1)
    np.testing.assert_allclose(kept["roughness"][0, :, 0], np.sqrt(np.tan(area_median)), rtol=2e-6)


def test_area_weights_are_each_small_texels_share_of_its_own_extent() -> None:
    # 10 -> 4: each small texel spans 2.5 input texels (by hand)
    hand = np.zeros((4, 10))
    hand[0, [0, 1, 2]] = [0.4, 0.4, 0.2]
    hand[1, [2, 3, 4]] = [0.2, 0.4, 0.4]
    hand[2, [5, 6, 7]] = [0.4, 0.4, 0.2]
    hand[3, [7, 8, 9]] = [0.2, 0.4, 0.4]
    np.testing.assert_allclose(area_matrix(10, 4).toarray(), hand, atol=1e-12)
    # an integer factor is the block mean
    np.testing.assert_allclose(area_matrix(8, 2).toarray(), np.kron(np.eye(2), np.full(4, 0.25)))
