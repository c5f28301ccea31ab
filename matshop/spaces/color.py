"""Color parameters (diffuse kd, specular ks, base color, emissive).

Files hold display-encoded values in [0, 1]; the edit space is linear
reflectance, where scaling by 0.5 halves the response. The default transfer
function is the exact piecewise sRGB curve (IEC 61966-2-1); the seed paper's
pure gamma 2.2 is offered as the ``gamma22`` space.
"""

from __future__ import annotations

import numpy as np

from .base import EditRange, Space, as_channels

_SRGB_DECODE_KNEE = 0.04045
_SRGB_ENCODE_KNEE = 0.0031308


def srgb_to_linear(encoded: np.ndarray) -> np.ndarray:
    """Exact sRGB decode, float32, any shape. Input is not clamped."""
    v = np.asarray(encoded, dtype=np.float32)
    # abs/sign keep the curve odd-symmetric so out-of-range intermediates stay finite
    mag = np.abs(v)
    out = np.where(
        mag <= _SRGB_DECODE_KNEE,
        mag / np.float32(12.92),
        ((mag + np.float32(0.055)) / np.float32(1.055)) ** np.float32(2.4),
    )
    return np.copysign(out, v).astype(np.float32, copy=False)


def linear_to_srgb(linear: np.ndarray) -> np.ndarray:
    """Exact sRGB encode, float32, any shape. Input is not clamped."""
    v = np.asarray(linear, dtype=np.float32)
    mag = np.abs(v)
    out = np.where(
        mag <= _SRGB_ENCODE_KNEE,
        mag * np.float32(12.92),
        np.float32(1.055) * mag ** np.float32(1.0 / 2.4) - np.float32(0.055),
    )
    return np.copysign(out, v).astype(np.float32, copy=False)


class SRGBColorSpace(Space):
    """sRGB-encoded color <-> linear color with the exact piecewise curve."""

    name = "srgb"
    description = "color: exact sRGB transfer function <-> linear reflectance"
    edit_range = EditRange(0.0, 1.0)
    curve_mode = "channels"

    def __init__(self, channels: int = 3) -> None:
        self.phys_channels = channels
        self.edit_channels = channels

    def to_edit(self, phys: np.ndarray) -> np.ndarray:
        return srgb_to_linear(as_channels(phys, self.phys_channels, self.name))

    def from_edit(self, edit: np.ndarray) -> np.ndarray:
        clamped = np.clip(as_channels(edit, self.edit_channels, self.name), 0.0, 1.0)
        return linear_to_srgb(clamped)


class Gamma22ColorSpace(Space):
    """The seed paper's color space: ``p~ = p^2.2``, back ``p = p~^(1/2.2)``."""

    name = "gamma22"
    description = "color: pure gamma 2.2 (the seed paper) <-> linear reflectance"
    edit_range = EditRange(0.0, 1.0)
    curve_mode = "channels"

    def __init__(self, channels: int = 3) -> None:
        self.phys_channels = channels
        self.edit_channels = channels

    def to_edit(self, phys: np.ndarray) -> np.ndarray:
        v = np.clip(as_channels(phys, self.phys_channels, self.name), 0.0, None)
        return (v ** np.float32(2.2)).astype(np.float32, copy=False)

    def from_edit(self, edit: np.ndarray) -> np.ndarray:
        v = np.clip(as_channels(edit, self.edit_channels, self.name), 0.0, 1.0)
        return (v ** np.float32(1.0 / 2.2)).astype(np.float32, copy=False)


SPACES: dict[str, Space] = {"srgb": SRGBColorSpace(), "gamma22": Gamma22ColorSpace()}
