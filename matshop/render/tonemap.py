"""Linear radiance to display pixels: exposure, a filmic curve, sRGB encoding.

``display = srgb_encode(curve(radiance * 2^exposure))`` with ``curve`` one of

- ``"aces"``: Narkowicz's fit of the ACES reference rendering transform
  (``x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)``), a filmic shoulder that
  keeps bright highlights from clipping abruptly;
- ``"linear"``: clip to [0, 1] (what the paper shows: linear radiance displayed at
  a gamma, for figures whose point is linearity).
"""

from __future__ import annotations

import numpy as np

from ..errors import InvalidValue

TONEMAPS = ("aces", "linear")


def aces(x: np.ndarray) -> np.ndarray:
    """Narkowicz 2015 ACES filmic fit, ``[0, inf) -> [0, 1)``."""
    x = np.clip(x, 0.0, None)
    return np.clip(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)


def srgb_encode(linear: np.ndarray) -> np.ndarray:
    """IEC 61966-2-1 encoding of linear values clipped to [0, 1]."""
    x = np.clip(linear, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def to_display(radiance: np.ndarray, *, exposure: float = 0.0, tonemap: str = "aces") -> np.ndarray:
    """Display-encoded float32 in [0, 1], same shape as ``radiance``."""
    if tonemap not in TONEMAPS:
        raise InvalidValue(f"unknown tone map {tonemap!r} (use one of {', '.join(TONEMAPS)})")
    scaled = np.asarray(radiance, dtype=np.float32) * np.float32(2.0**exposure)
    mapped = aces(scaled) if tonemap == "aces" else np.clip(scaled, 0.0, 1.0)
    return srgb_encode(mapped).astype(np.float32)


def to_uint8(display: np.ndarray) -> np.ndarray:
    """Round display values to 8-bit codes."""
    return np.round(np.clip(display, 0.0, 1.0) * 255.0).astype(np.uint8)
