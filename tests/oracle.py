"""Truth written once for the oracle tests: a file's own codes, the sRGB transfer function.

Both are independent of matshop: the codes come from OpenImageIO itself
(unassociated alpha, so data in alpha is what the file holds), the transfer
function from IEC 61966-2-1 as CONVENTIONS.md states it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import OpenImageIO as oiio


def file_codes(path: Path) -> np.ndarray:
    """``(H, W, C)`` integer codes of an 8-bit file (float values of other depths)."""
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)
    image = oiio.ImageInput.open(str(path), config)
    assert image is not None, oiio.geterror()
    spec = image.spec()
    integer = spec.format == "uint8"
    pixels = np.asarray(image.read_image(0, 0, 0, spec.nchannels, "uint8" if integer else "float"))
    image.close()
    pixels = pixels.reshape(spec.height, spec.width, spec.nchannels)
    return pixels.astype(int) if integer else pixels


def srgb_decode(encoded: np.ndarray) -> np.ndarray:
    v = np.asarray(encoded, dtype=np.float64)
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def srgb_encode(linear: np.ndarray) -> np.ndarray:
    x = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def lit_swatch(
    base: np.ndarray,
    metallic: np.ndarray,
    roughness: np.ndarray,
    normal: np.ndarray,
    light: tuple[float, float, float],
    irradiance: float,
    tilt_deg: float = 30.0,
) -> np.ndarray:
    """Radiance ``(H, W, 3)`` of texels given by their 8-bit codes, on the reference
    renderer's flat swatch (tilted ``tilt_deg`` towards +y, seen along +z) under one
    directional light, written from DESIGN.md's BRDF alone:
    ``(kd / pi + F D G / (4 n.i n.o)) E n.i``, the metallic workflow (``kd = base (1 - m)``,
    ``ks = 0.04 (1 - m) + base m``), Schlick F, GGX D with ``alpha = r^2``, Cook-Torrance G,
    OpenGL tangent-space normals ``2 c / 255 - 1``. NaN where the view is within 0.01 of
    a texel's shading horizon or below it (renderers lift it to the horizon there, their
    own choice, not the BRDF's)."""
    t = np.radians(tilt_deg)
    frame = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(t), -np.sin(t)], [0.0, np.sin(t), np.cos(t)]])
    local = normal.astype(np.float64) / 255.0 * 2.0 - 1.0
    n = local @ frame
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    i = np.asarray(light, dtype=np.float64) / np.linalg.norm(light)
    o = np.array([0.0, 0.0, 1.0])
    h = (i + o) / np.linalg.norm(i + o)
    n_i, n_o, n_h, o_h = n @ i, n @ o, n @ h, float(o @ h)
    base = srgb_decode(base / 255.0)
    m = (metallic.astype(np.float64) / 255.0)[..., None]
    kd = base * (1.0 - m)
    ks = 0.04 * (1.0 - m) + base * m
    alpha2 = (np.clip((roughness.astype(np.float64) / 255.0) ** 2, 1e-3, 1.0)) ** 2
    d = alpha2 / (np.pi * (alpha2 * n_h**2 + (1.0 - n_h**2)) ** 2)
    g = np.clip(np.minimum(2.0 * n_h * n_o / o_h, 2.0 * n_h * n_i / o_h), 0.0, 1.0)
    f = ks + (1.0 - ks) * (1.0 - o_h) ** 5
    lit = (n_i > 0) & (n_o > 0)
    specular = np.where(lit, d * g / (4.0 * np.maximum(n_i, 1e-9) * np.maximum(n_o, 1e-9)), 0.0)
    rho = np.where(lit[..., None], kd / np.pi + f * specular[..., None], 0.0)
    radiance = rho * np.clip(n_i, 0.0, None)[..., None] * irradiance
    return np.where((n_o > 0.01)[..., None], radiance, np.nan)
