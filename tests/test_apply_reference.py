"""`matshop apply --op blur` writes what an independent computation of the same maths
gives: each parameter's closed-form editing transform in float64 numpy, OpenCV's Gaussian
blur of the wrapped image (the hand-written script of benchmarks/apply.py), the closed
form back, read and written with OpenCV rather than OpenImageIO. Within one 8-bit code
(float32 against float64 rounding), nearly everywhere exactly."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from matshop.cli import main

SIGMA_PX = 2.0
PAD = 16  # beyond OpenCV's 4 sigma reach


def _wrapped_blur(image: np.ndarray) -> np.ndarray:
    wide = cv2.copyMakeBorder(image, PAD, PAD, PAD, PAD, cv2.BORDER_WRAP)
    out = cv2.GaussianBlur(wide, (0, 0), SIGMA_PX)[PAD:-PAD, PAD:-PAD]
    return out.reshape(image.shape)


def _srgb_to_linear(v: np.ndarray) -> np.ndarray:
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def _linear_to_srgb(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def _normal_to_log(rgb: np.ndarray) -> np.ndarray:
    """Unit normal -> log of the shortest rotation taking +z to it: axis z x n, half angle."""
    n = 2.0 * rgb - 1.0
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    s = np.hypot(n[..., 0], n[..., 1])
    half = 0.5 * np.arctan2(s, n[..., 2])
    scale = np.where(s > 0, half / np.where(s > 0, s, 1.0), 0.5)
    return np.stack([-n[..., 1] * scale, n[..., 0] * scale, np.zeros_like(s)], axis=-1)


def _log_to_normal(e: np.ndarray) -> np.ndarray:
    """Rotation of +z by the angle 2|e| about the axis e (in the tangent plane)."""
    half = np.hypot(e[..., 0], e[..., 1])
    sinc = np.where(half > 0, np.sin(2 * half) / np.where(half > 0, half, 1.0), 2.0)
    return np.stack([e[..., 1] * sinc, -e[..., 0] * sinc, np.cos(2 * half)], axis=-1)


def _codes(v: np.ndarray) -> np.ndarray:
    return np.rint(np.clip(v, 0.0, 1.0) * 255.0).astype(np.uint8)


def _smooth_noise(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    return cv2.GaussianBlur(rng.random(shape), (0, 0), 3.0)


@pytest.fixture
def texture_set(tmp_path: Path) -> Path:
    rng = np.random.default_rng(4)
    h, w = 72, 96  # not square: rows and columns stay apart
    folder = tmp_path / "set"
    folder.mkdir()
    colour = np.clip(_smooth_noise(rng, (h, w, 3)) * 3 - 1, 0, 1)
    tilt = (_smooth_noise(rng, (h, w, 2)) - 0.5) * 3
    normal = np.dstack([tilt, np.ones((h, w))])
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    maps = {
        "basecolor": _codes(colour),
        "metallic": _codes(_smooth_noise(rng, (h, w))),
        "roughness": _codes(np.clip(_smooth_noise(rng, (h, w)) * 3 - 1, 0, 1)),
        "normal_gl": _codes(0.5 * normal + 0.5),
    }
    for tag, codes in maps.items():
        bgr = codes[..., ::-1] if codes.ndim == 3 else codes
        assert cv2.imwrite(str(folder / f"t_{tag}.png"), np.ascontiguousarray(bgr))
    return folder


def _read(path: Path) -> np.ndarray:
    codes = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    assert codes is not None and codes.dtype == np.uint8, path
    return codes[..., ::-1] if codes.ndim == 3 else codes


def test_a_blur_writes_the_closed_form_maths(texture_set: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert main(["apply", str(texture_set), str(out), "--op", "blur", f"sigma_px={SIGMA_PX}"]) == 0
    source = {
        tag: _read(texture_set / f"t_{tag}.png") / 255.0
        for tag in ("basecolor", "metallic", "roughness", "normal_gl")
    }
    linear = _wrapped_blur(_srgb_to_linear(source["basecolor"]))
    median = _wrapped_blur(np.arctan(source["roughness"] ** 2))  # GGX: atan(alpha), alpha = r^2
    expected = {
        "basecolor": _codes(_linear_to_srgb(linear)),
        "metallic": _codes(_wrapped_blur(source["metallic"])),
        "roughness": _codes(np.sqrt(np.clip(np.tan(np.clip(median, 0, np.pi / 4)), 0, 1))),
        "normal_gl": _codes(
            0.5 * _log_to_normal(_wrapped_blur(_normal_to_log(source["normal_gl"]))) + 0.5
        ),
    }
    assert sorted(p.name for p in out.iterdir()) == sorted(f"t_{t}.png" for t in expected)
    for tag, want in expected.items():
        got = _read(out / f"t_{tag}.png")
        diff = np.abs(got.astype(int) - want.astype(int))
        assert got.shape == want.shape and diff.max() <= 1, tag
        assert np.mean(diff == 0) > 0.99, tag
        # the blur did something: the files differ from the source
        assert np.mean(got != _codes(source[tag])) > 0.2, tag
