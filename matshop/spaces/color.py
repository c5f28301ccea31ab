"""Color parameters (diffuse kd, specular ks, base color, emissive).

Files hold display-encoded values in [0, 1]; the edit space is linear
reflectance, where scaling by 0.5 halves the response. The default transfer
function is the exact piecewise sRGB curve (IEC 61966-2-1); the seed paper's
pure gamma 2.2 is offered as the ``gamma22`` space.
"""

from __future__ import annotations

import numpy as np

from ._kernels import POWER, SRGB_DECODE, SRGB_ENCODE, Step, transfer
from .base import EditRange, FusedSpace, Space

_GAMMA = 2.2


def _map(values: np.ndarray, out: np.ndarray | None, curve: int, **clamp: float) -> np.ndarray:
    """One fused kernel pass (:func:`._kernels.transfer`) into ``out`` or a new array."""
    v = np.asarray(values, dtype=np.float32)
    if out is None:
        out = np.empty(v.shape, dtype=np.float32)
    return transfer(v, out, curve, **clamp)


def srgb_to_linear(encoded: np.ndarray, *, out: np.ndarray | None = None) -> np.ndarray:
    """Exact sRGB decode, float32, any shape. Input is not clamped.

    ``v <= 0.04045 ? v / 12.92 : ((v + 0.055) / 1.055)^2.4``, odd-symmetric so
    out-of-range intermediates stay finite; computed in float64 (about half an
    ulp of float32), in one pass. ``out`` (float32, same shape) may be given.
    """
    return _map(encoded, out, SRGB_DECODE)


def linear_to_srgb(linear: np.ndarray, *, out: np.ndarray | None = None) -> np.ndarray:
    """Exact sRGB encode, float32, any shape. Input is not clamped.

    ``v <= 0.0031308 ? 12.92 v : 1.055 v^(1/2.4) - 0.055``, odd-symmetric; see
    :func:`srgb_to_linear`.
    """
    return _map(linear, out, SRGB_ENCODE)


class SRGBColorSpace(FusedSpace):
    """sRGB-encoded color <-> linear color with the exact piecewise curve."""

    name = "srgb"
    description = "color: exact sRGB transfer function <-> linear reflectance"
    edit_range = EditRange(0.0, 1.0)
    curve_mode = "channels"

    def __init__(self, channels: int = 3) -> None:
        self.phys_channels = channels
        self.edit_channels = channels

    def to_edit_step(self) -> Step:
        return Step(False, SRGB_DECODE)

    def from_edit_step(self) -> Step:
        return Step(False, SRGB_ENCODE, lo=0.0, hi=1.0)


class Gamma22ColorSpace(FusedSpace):
    """The seed paper's color space: ``p~ = p^2.2``, back ``p = p~^(1/2.2)``."""

    name = "gamma22"
    description = "color: pure gamma 2.2 (the seed paper) <-> linear reflectance"
    edit_range = EditRange(0.0, 1.0)
    curve_mode = "channels"

    def __init__(self, channels: int = 3) -> None:
        self.phys_channels = channels
        self.edit_channels = channels

    def to_edit_step(self) -> Step:
        return Step(False, POWER, lo=0.0, p=_GAMMA)

    def from_edit_step(self) -> Step:
        return Step(False, POWER, lo=0.0, hi=1.0, p=1.0 / _GAMMA)


SPACES: dict[str, Space] = {"srgb": SRGBColorSpace(), "gamma22": Gamma22ColorSpace()}
