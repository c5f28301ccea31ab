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
