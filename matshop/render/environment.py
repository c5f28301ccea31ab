"""Equirectangular HDR environments: procedural ones, user files, prefiltered lookups.

Convention: world ``+y`` is up; the camera sits on ``+z`` looking at ``-z``.
Image column ``u`` in ``[0, 1)`` is the azimuth ``phi = 2 pi (u - 1/2)`` measured
from ``-z`` towards ``+x`` (so the middle of the image is what the camera looks
at); row ``v`` in ``[0, 1]`` is the polar angle ``theta = pi v`` from ``+y``.

How the environment lights a surface (see :mod:`matshop.render.integrator`):

- **diffuse**: an irradiance map ``E(n)`` on a 64 x 32 grid of normals, computed
  once per environment by direct quadrature of ``L(w) max(0, n.w) dw`` over a
  128 x 64 downsampling of the map (every texel weighted by its solid angle),
  then read bilinearly;
- **specular**: filtered importance sampling (Krivanek & Colbert 2008): each
  BRDF sample reads a box-filtered mip level of the map whose texel solid angle
  matches the sample's share of the lobe, ``1 / (N pdf)``, so a few samples
  give a smooth, nearly unbiased estimate.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field

import cv2
import numpy as np

from ..errors import MatshopError

#: irradiance map size (columns, rows) and the environment resolution it integrates
_IRR_SIZE = (64, 32)
_IRR_SOURCE = (128, 64)
_MIN_ROWS = 4


def direction_to_uv(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Equirect ``(u, v)`` in ``[0, 1]`` of unit directions (components broadcast)."""
    u = 0.5 + np.arctan2(x, -z) / (2.0 * np.pi)
    v = np.arccos(np.clip(y, -1.0, 1.0)) / np.pi
    return u, v


def uv_to_direction(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Unit directions ``(..., 3)`` of equirect coordinates."""
    phi = 2.0 * np.pi * (np.asarray(u) - 0.5)
    theta = np.pi * np.asarray(v)
    s = np.sin(theta)
    parts = np.broadcast_arrays(s * np.sin(phi), np.cos(theta), -s * np.cos(phi))
    return np.stack(parts, axis=-1)


def texel_directions(height: int, width: int) -> tuple[np.ndarray, np.ndarray]:
    """Directions ``(H, W, 3)`` of texel centres and their solid angles ``(H, 1)``."""
    v = (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    dirs = uv_to_direction(u[None, :], v[:, None])
    # exact solid angle of a latitude band cell: (2 pi / W) (cos t0 - cos t1)
    edges = np.arange(height + 1) * (np.pi / height)
    omega = (2.0 * np.pi / width) * (np.cos(edges[:-1]) - np.cos(edges[1:]))
    return dirs, omega[:, None]


def _downsample(image: np.ndarray) -> np.ndarray:
    h, w = image.shape[:2]
    return cv2.resize(image, (max(1, w // 2), max(1, h // 2)), interpolation=cv2.INTER_AREA)


@dataclass
class Environment:
    """An equirectangular radiance map (linear RGB, float32 ``(H, W, 3)``) with its prefilters."""

    radiance: np.ndarray
    name: str = "environment"
    levels: list[np.ndarray] = field(init=False, repr=False)
    irradiance_map: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        rad = np.ascontiguousarray(self.radiance, dtype=np.float32)
        if rad.ndim != 3 or rad.shape[2] != 3 or rad.shape[1] != 2 * rad.shape[0]:
            raise ValueError(f"an environment is (H, 2H, 3) equirect RGB, got {rad.shape}")
        self.radiance = rad
        self.levels = [rad]
        while self.levels[-1].shape[0] > _MIN_ROWS:
            self.levels.append(_downsample(self.levels[-1]))
        self._pack()
        self.irradiance_map = self._irradiance()

    # ------------------------------------------------------------------ lookups

    def _pack(self) -> None:
        """All mip levels in one flat array so a lookup is one gather per tap."""
        self._heights = np.array([lv.shape[0] for lv in self.levels], dtype=np.int64)
        self._widths = np.array([lv.shape[1] for lv in self.levels], dtype=np.int64)
        sizes = self._heights * self._widths
        self._offsets = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        self._flat = np.concatenate([lv.reshape(-1, 3) for lv in self.levels])

    @property
    def max_level(self) -> int:
        return len(self.levels) - 1

    def texel_solid_angle(self) -> float:
        """Mean solid angle of a level-0 texel, ``4 pi / (H W)``."""
        h, w = self.radiance.shape[:2]
        return 4.0 * np.pi / (h * w)

    def _bilinear(self, level: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        h = self._heights[level]
        w = self._widths[level]
        x = u * w - 0.5
        y = np.clip(v * h - 0.5, 0.0, h - 1.0)
        x0 = np.floor(x)
        y0 = np.minimum(np.floor(y), h - 2)
        fx = (x - x0)[..., None]
        fy = (y - y0)[..., None]
        x0 = x0.astype(np.int64) % w
        x1 = (x0 + 1) % w
        y0 = y0.astype(np.int64)
        base = self._offsets[level]
        row0 = base + y0 * w
        row1 = row0 + w
        f = self._flat
        top = f[row0 + x0] * (1.0 - fx) + f[row0 + x1] * fx
        bottom = f[row1 + x0] * (1.0 - fx) + f[row1 + x1] * fx
        return top * (1.0 - fy) + bottom * fy

    def lookup(self, x: np.ndarray, y: np.ndarray, z: np.ndarray, lod: np.ndarray | float = 0.0):
        """Radiance ``(..., 3)`` float32 along unit directions, trilinear in the mip level ``lod``.

        Runs the numba kernel; :meth:`lookup_reference` is the same in numpy.
        """
        from ._kernels import lookup

        return lookup(self._flat, self._offsets, self._heights, self._widths, x, y, z, lod)

    def lookup_reference(
        self, x: np.ndarray, y: np.ndarray, z: np.ndarray, lod: np.ndarray | float = 0.0
    ) -> np.ndarray:
        """:meth:`lookup` in plain numpy (the specification the kernel is tested against)."""
        u, v = direction_to_uv(x, y, z)
        lod = np.clip(np.broadcast_to(lod, u.shape), 0.0, self.max_level)
        l0 = np.minimum(np.floor(lod).astype(np.int64), max(self.max_level - 1, 0))
        frac = (lod - l0)[..., None]
        first = self._bilinear(l0, u, v)
        if self.max_level == 0:
            return first
        second = self._bilinear(l0 + 1, u, v)
        return (first + frac * (second - first)).astype(np.float32)

    def _irradiance(self) -> np.ndarray:
        cols, rows = _IRR_SOURCE
        source = cv2.resize(self.radiance, (cols, rows), interpolation=cv2.INTER_AREA)
        dirs, omega = texel_directions(rows, cols)
        weighted = (source * omega[..., None].astype(np.float32)).reshape(-1, 3).astype(np.float64)
        out_cols, out_rows = _IRR_SIZE
        normals, _ = texel_directions(out_rows, out_cols)
        cosines = normals.reshape(-1, 3) @ dirs.reshape(-1, 3).T
        # in place: np.clip on these 2048 x 8192 cosines took 0.8 of a 1.1 s prefilter
        np.maximum(cosines, 0.0, out=cosines)
        return (cosines @ weighted).reshape(out_rows, out_cols, 3).astype(np.float32)

    def irradiance(self, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Irradiance ``E(n) = integral L(w) max(0, n.w) dw`` ``(..., 3)`` for unit normals."""
        u, v = direction_to_uv(x, y, z)
        h, w = self.irradiance_map.shape[:2]
        px = u * w - 0.5
        py = np.clip(v * h - 0.5, 0.0, h - 1.0)
        x0 = np.floor(px)
        y0 = np.minimum(np.floor(py), h - 2)
        fx = (px - x0)[..., None]
        fy = (py - y0)[..., None]
        x0 = x0.astype(np.int64) % w
        x1 = (x0 + 1) % w
        y0 = y0.astype(np.int64)
        m = self.irradiance_map
        top = m[y0, x0] * (1.0 - fx) + m[y0, x1] * fx
        bottom = m[y0 + 1, x0] * (1.0 - fx) + m[y0 + 1, x1] * fx
        return (top * (1.0 - fy) + bottom * fy).astype(np.float32)

    def rotated(self, degrees: float) -> Environment:
        """The environment turned about ``+y`` by ``degrees`` (whole texels)."""
        w = self.radiance.shape[1]
        shift = int(round(degrees / 360.0 * w))
        return Environment(np.roll(self.radiance, shift, axis=1), f"{self.name}@{degrees:g}")


# ---------------------------------------------------------------------- makers


def uniform(radiance: float | tuple[float, float, float] = 1.0, rows: int = 16) -> Environment:
    """Constant radiance in every direction (the furnace test)."""
    rgb = np.broadcast_to(np.asarray(radiance, dtype=np.float32), (3,))
    return Environment(np.tile(rgb, (rows, 2 * rows, 1)), "uniform")


def _soft_light(dirs: np.ndarray, centre, radius_deg: float, power: float) -> np.ndarray:
    c = np.asarray(centre, dtype=np.float64)
    c = c / np.linalg.norm(c)
    angle = np.degrees(np.arccos(np.clip(dirs @ c, -1.0, 1.0)))
    # a flat disc with a smooth 30% rim: soft-box looking highlights
    edge = np.clip((radius_deg - angle) / (0.3 * radius_deg), 0.0, 1.0)
    return power * edge * edge * (3.0 - 2.0 * edge)


def studio(rows: int = 256) -> Environment:
    """A photo studio: dim graded walls, a floor, a large key soft box, a fill and a rim strip.

    Generated in code (no file to ship); deterministic. Radiance is in
    arbitrary linear units chosen so that exposure 0 shows a mid-grey diffuse
    ball at about middle grey.
    """
    dirs, _ = texel_directions(rows, 2 * rows)
    up = dirs[..., 1]
    walls = 0.18 + 0.12 * np.clip(up, 0.0, 1.0)
    floor = 0.10 + 0.05 * np.clip(-up, 0.0, 1.0) ** 0.5
    base = np.where(up >= 0.0, walls, floor)
    rgb = np.stack([base, base * 0.98, base * 0.95], axis=-1)
    # camera at +z: key light up-left-front, fill right, rim strip behind-above
    key = _soft_light(dirs, (-0.6, 0.6, 0.55), 16.0, 14.0)
    fill = _soft_light(dirs, (0.9, 0.15, 0.45), 22.0, 2.5)
    rim = _soft_light(dirs, (0.25, 0.5, -0.85), 9.0, 10.0)
    top = _soft_light(dirs, (0.0, 1.0, 0.0), 20.0, 3.0)
    light = key + fill + rim + top
    rgb = rgb + np.stack([light, light * 0.97, light * 0.92], axis=-1)
    return Environment(rgb.astype(np.float32), "studio")


def sky(
    rows: int = 256, sun_elevation_deg: float = 35.0, sun_azimuth_deg: float = -40.0
) -> Environment:
    """A clear sky with a soft sun over a grey-brown ground (procedural, deterministic).

    The sun azimuth is measured from the camera (``+z``) towards ``+x``; the
    default puts it up-left behind the camera's shoulder.
    """
    dirs, _ = texel_directions(rows, 2 * rows)
    up = dirs[..., 1]
    t = np.clip(up, 0.0, 1.0)
    zenith = np.array([0.25, 0.45, 0.95])
    horizon = np.array([0.95, 1.0, 1.05])
    sky_rgb = horizon + (zenith - horizon) * (t[..., None] ** 0.5)
    ground = np.array([0.22, 0.19, 0.16]) * (0.6 + 0.4 * np.clip(-up, 0.0, 1.0)[..., None])
    rgb = np.where((up >= 0.0)[..., None], sky_rgb, ground)
    el, az = np.radians(sun_elevation_deg), np.radians(sun_azimuth_deg)
    sun_dir = np.array([np.cos(el) * np.sin(az), np.sin(el), np.cos(el) * np.cos(az)])
    cosine = np.clip(dirs @ sun_dir, -1.0, 1.0)
    angle = np.degrees(np.arccos(cosine))
    disc = np.where(angle < 2.0, 400.0, 0.0)
    glow = 3.0 * np.exp(-((angle / 8.0) ** 2))
    rgb = rgb + (disc + glow)[..., None] * np.array([1.0, 0.93, 0.8])
    return Environment(rgb.astype(np.float32), "sky")


PROCEDURAL = {"studio": studio, "sky": sky}

#: a loaded file is area-averaged down to at most this many rows (2:1, so 2048 columns):
#: a 0.18 degree texel, finer than any lobe the viewport shows, and a 25 MB upload
#: instead of 400 MB for an 8K HDR (both renderers light with the same reduced map)
MAX_ROWS = 1024

#: the steps :func:`load_environment` reports: read, checked and reduced, prefiltered
LOAD_STEPS = 3


def uniform_radiance(text: str) -> float | None:
    """The radiance of ``"uniform"`` (1) or ``"uniform:L"``; None for any other text."""
    name, sep, value = text.partition(":")
    if name != "uniform":
        return None
    if not sep:
        return 1.0
    try:
        radiance = float(value)
    except ValueError:
        radiance = float("nan")
    if not (np.isfinite(radiance) and 0.0 <= radiance <= 1e6):
        raise MatshopError(f"uniform:L needs a radiance L from 0 to 1e6, got {value!r}")
    return radiance


def load_environment(
    spec: str | os.PathLike[str] | None,
    *,
    progress: Callable[[int, int], None] | None = None,
    max_rows: int = MAX_ROWS,
) -> Environment:
    """``"studio"``, ``"sky"``, ``"uniform"`` (radiance 1), ``"uniform:L"``, or an
    equirect .hdr/.exr (resized to 2:1, area-averaged down to ``max_rows`` rows).

    ``progress(done, LOAD_STEPS)`` is called before the work and after each step.
    """
    report = progress or (lambda done, total: None)
    report(0, LOAD_STEPS)
    text = "studio" if spec is None else os.fspath(spec)
    radiance = uniform_radiance(text)
    if radiance is not None:
        env = uniform(radiance)
    elif text in PROCEDURAL:
        env = PROCEDURAL[text]()
    else:
        pixels = _read_equirect(text, report, max_rows)
        env = Environment(pixels, os.path.basename(text))
    report(LOAD_STEPS, LOAD_STEPS)
    return env


def _read_equirect(text: str, report: Callable[[int, int], None], max_rows: int) -> np.ndarray:
    from ..io.images import read_image

    pixels, info = read_image(text)
    report(1, LOAD_STEPS)
    if info.is_integer:
        # an 8/16-bit image is display-encoded: decode to linear radiance
        pixels = np.where(pixels <= 0.04045, pixels / 12.92, ((pixels + 0.055) / 1.055) ** 2.4)
    if pixels.shape[2] < 3:
        pixels = np.repeat(pixels[..., :1], 3, axis=2)
    pixels = np.ascontiguousarray(pixels[..., :3], dtype=np.float32)
    h, w = pixels.shape[:2]
    if abs(w - 2 * h) > 1:
        raise MatshopError(
            f"an environment must be an equirectangular (2:1) image, got {w}x{h}", text
        )
    if not np.all(np.isfinite(pixels)) or pixels.min() < 0.0:
        raise MatshopError("environment has negative or non-finite radiance", text)
    rows = min(h, max_rows)
    if (w, h) != (2 * rows, rows):
        pixels = cv2.resize(pixels, (2 * rows, rows), interpolation=cv2.INTER_AREA)
    report(2, LOAD_STEPS)
    return pixels
