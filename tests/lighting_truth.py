"""Truth for the lighting-choice tests, written from the conventions alone (no matshop).

- The equirect convention of DESIGN/`matshop.render.environment`'s doc: column ``u`` in
  [0, 1) is the azimuth ``phi = 2 pi (u - 1/2)`` from -z towards +x, row ``v`` the polar
  angle ``theta = pi v`` from +y; a texel row band's solid angle is
  ``(2 pi / W)(cos theta0 - cos theta1)``.
- A turn of the environment by ``deg`` about +y carries azimuth ``phi`` to ``phi + deg``.
- A white Lambertian (kd = 1) reflects ``E(n) / pi``; in a uniform environment of
  radiance L, ``E = pi L`` so it reflects L; under a small bright patch of texels it
  reflects ``sum(L_i omega_i max(0, n.d_i)) / pi``.
- Display: Narkowicz's ACES fit of the radiance times ``2^stops``, then the exact sRGB
  encoding (CONVENTIONS.md), rounded to 8-bit codes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import OpenImageIO as oiio


def write_image(path: Path, pixels: np.ndarray) -> Path:
    """Write ``pixels`` (H, W, C) with OpenImageIO: float32 for .exr/.hdr, else 8-bit codes."""
    pixels = np.ascontiguousarray(pixels)
    fmt = "uint8" if pixels.dtype == np.uint8 else "float"
    spec = oiio.ImageSpec(pixels.shape[1], pixels.shape[0], pixels.shape[2], fmt)
    out = oiio.ImageOutput.create(str(path))
    assert out is not None, oiio.geterror()
    assert out.open(str(path), spec), out.geterror()
    assert out.write_image(pixels), out.geterror()
    out.close()
    return path


def white_lambertian_set(folder: Path, size: int = 16) -> Path:
    """A kd/ks texture set: diffuse code 255 (linear 1), specular code 0."""
    folder.mkdir(parents=True, exist_ok=True)
    write_image(folder / "white_diffuse.png", np.full((size, size, 3), 255, np.uint8))
    write_image(folder / "white_specular.png", np.zeros((size, size, 3), np.uint8))
    return folder


def direction(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Unit directions (..., 3) of equirect coordinates (the convention above)."""
    phi = 2.0 * np.pi * (np.asarray(u, dtype=np.float64) - 0.5)
    theta = np.pi * np.asarray(v, dtype=np.float64)
    return np.stack(
        np.broadcast_arrays(
            np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)
        ),
        axis=-1,
    )


class Spot:
    """A black equirect map with one bright block of texels (rows x cols) of radiance L."""

    def __init__(self, rows: int, row: int, col: int, size: int = 2, radiance: float = 300.0):
        self.rows, self.cols = rows, 2 * rows
        self.block = (slice(row, row + size), slice(col, col + size))
        self.radiance = radiance

    def pixels(self) -> np.ndarray:
        image = np.zeros((self.rows, self.cols, 3), np.float32)
        image[self.block] = self.radiance
        return image

    def write(self, path: Path) -> Path:
        return write_image(path, self.pixels())

    def texels(self, turn_deg: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Directions (N, 3) of the bright texels' centres after a turn, their solid angles."""
        rows, cols = np.mgrid[self.block]
        u = (cols.ravel() + 0.5) / self.cols + turn_deg / 360.0
        v = (rows.ravel() + 0.5) / self.rows
        edges = np.arange(self.rows + 1) * np.pi / self.rows
        band = (2.0 * np.pi / self.cols) * (np.cos(edges[:-1]) - np.cos(edges[1:]))
        return direction(u, v), band[rows.ravel()]

    def lambertian(self, normals: np.ndarray, turn_deg: float = 0.0) -> np.ndarray:
        """Radiance a white Lambertian with these unit normals (N, 3) reflects."""
        dirs, omega = self.texels(turn_deg)
        cosines = np.clip(normals @ dirs.T, 0.0, None)
        return cosines @ (self.radiance * omega) / np.pi

    def centre(self, turn_deg: float = 0.0) -> np.ndarray:
        dirs, omega = self.texels(turn_deg)
        mean = (dirs * omega[:, None]).sum(axis=0)
        return mean / np.linalg.norm(mean)


def aces(x: np.ndarray) -> np.ndarray:
    x = np.clip(np.asarray(x, dtype=np.float64), 0.0, None)
    return np.clip(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)


def srgb_encode(linear: np.ndarray) -> np.ndarray:
    x = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def display_code(radiance: np.ndarray, stops: float = 0.0) -> np.ndarray:
    """8-bit code of linear radiance at an exposure, through ACES and sRGB."""
    return np.round(srgb_encode(aces(np.asarray(radiance) * 2.0**stops)) * 255.0)


def linear_from_code(code: np.ndarray) -> np.ndarray:
    """The radiance (before the tone map) an 8-bit ACES+sRGB code shows, by bisection."""
    target = np.asarray(code, dtype=np.float64) / 255.0
    lo, hi = np.zeros_like(target), np.full_like(target, 64.0)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        below = srgb_encode(aces(mid)) < target
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return 0.5 * (lo + hi)


def artists_hdr(path: Path) -> Path:
    """An equirect HDR unlike the presets: warm horizon, blue zenith, two bright windows."""
    rows = 128
    v = (np.arange(rows) + 0.5) / rows
    sky = np.stack([0.4 + 0.6 * v, 0.5 + 0.2 * v, 1.2 - 0.8 * v], axis=-1).astype(np.float32)
    image = np.repeat(sky[:, None, :], 2 * rows, axis=1)
    image[30:40, 40:56] = (60.0, 55.0, 40.0)
    image[50:54, 180:200] = (5.0, 9.0, 20.0)
    return write_image(path, np.ascontiguousarray(image))
