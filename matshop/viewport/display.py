"""Physical maps -> 8-bit display pixels, one parameter at a time.

Qt-free numpy so the conversion can be tested and timed on its own. The
canvas shows each parameter the way its file stores it, so a texel the
file holds as (198, 119, 99) is drawn (198, 119, 99):

- colors as the file's own (sRGB-encoded) codes: the physical values *are*
  the file's encoded values, so they are only quantised, never encoded again,
- normal frames as the file's encoding ``(n + 1) / 2`` in the file's
  convention (DirectX files flip green), the familiar blue normal map,
- microfacet exponents (Phong, Ashikhmin-Shirley) as the equivalent
  roughness ``sqrt(2 / (n + 2))`` so rough is bright like a roughness map
  (an exponent of 0..10000 has no useful 8-bit code of its own),
- scalars (roughness, metallic, ao, height...) as gray in [0, 1],
- wide parameters (sampled distributions, profiles) as the gray mean of
  their samples.

Output is RGBX8888 (R, G, B, 255 per texel), what the canvas' QImage wraps
without a copy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..material import Parameter, Schema

_F32 = np.float32


@dataclass(frozen=True)
class DisplayMode:
    """How one parameter is turned into display colors."""

    kind: str  # "color", "vector", "exponent", "scalar", "wide"
    note: str  # what the user is looking at, for the status bar / combo tooltip


def display_mode(param: Parameter) -> DisplayMode:
    """The display mode of a schema parameter (by its editing space and width)."""
    space = param.space.name
    if space in ("srgb", "gamma22"):
        return DisplayMode("color", "color as the file stores it (sRGB codes)")
    if space.startswith("normal"):
        return DisplayMode("vector", "normal as the file stores it: (n + 1) / 2")
    if space.startswith(("phong", "ashikhmin_shirley")):
        return DisplayMode("exponent", "exponent shown as equivalent roughness sqrt(2/(n+2))")
    if param.phys_channels <= 3 and param.phys_channels != 2:
        return DisplayMode("scalar", "linear value in [0, 1]")
    if param.phys_channels == 2:
        return DisplayMode("scalar", "two channels shown as red and green")
    return DisplayMode("wide", f"mean of {param.phys_channels} samples")


def _codes(values: np.ndarray) -> np.ndarray:
    """Float values in [0, 1] (clipped) -> the nearest 8-bit codes."""
    scaled = np.clip(values, _F32(0.0), _F32(1.0))  # a new array: scaled in place below
    scaled *= _F32(255.0)
    scaled += _F32(0.5)
    return scaled.astype(np.uint8)


def _normal_codes(normal: np.ndarray, convention: str) -> np.ndarray:
    """Unit OpenGL normals -> the file's codes ``(n + 1) / 2`` in ``convention``."""
    rgb = normal[..., :3] * _F32(0.5) + _F32(0.5)
    if convention == "directx":  # their +Y points down the image
        rgb[..., 1] = _F32(1.0) - rgb[..., 1]
    return _codes(rgb)


def to_display(
    param: Parameter,
    phys: np.ndarray,
    out: np.ndarray | None = None,
    *,
    normal_convention: str = "opengl",
) -> np.ndarray:
    """Physical values ``(h, w, P)`` of ``param`` -> RGBX ``(h, w, 4)`` uint8.

    ``out`` (e.g. a view into the canvas buffer) is filled and returned when
    given. ``normal_convention`` (``"opengl"`` or ``"directx"``) is the normal
    file's, so normals look as they do in that file.
    """
    height, width = phys.shape[:2]
    if out is None:
        out = np.empty((height, width, 4), dtype=np.uint8)
    mode = display_mode(param).kind
    phys = np.asarray(phys, dtype=np.float32)
    if mode == "color":
        rgb = _gray_or_rg(_codes(phys[..., :3]))
    elif mode == "vector":
        rgb = _normal_codes(phys, normal_convention)
    elif mode == "exponent":
        rough = np.sqrt(_F32(2.0) / (np.maximum(phys, _F32(0.0)) + _F32(2.0)))
        rgb = _gray_or_rg(_codes(rough))
    elif mode == "wide":
        rgb = _gray_or_rg(_codes(phys.mean(axis=-1, keepdims=True)))
    else:
        rgb = _gray_or_rg(_codes(phys))
    out[..., :3] = rgb
    out[..., 3] = 255
    return out


def _gray_or_rg(channels: np.ndarray) -> np.ndarray:
    """One channel -> gray; two -> red/green (blue 0); three -> as is."""
    if channels.shape[-1] == 1:
        return np.repeat(channels, 3, axis=-1)
    if channels.shape[-1] == 2:
        zeros = np.zeros(channels.shape[:-1] + (1,), dtype=np.uint8)
        return np.concatenate([channels, zeros], axis=-1)
    return channels[..., :3]


def format_values(schema: Schema, phys: dict[str, np.ndarray]) -> str:
    """One texel's physical values as a short readable line (status bar)."""
    parts = []
    for param in schema.parameters:
        values = np.asarray(phys[param.name]).reshape(-1)
        if values.size > 4:
            text = f"mean {values.mean():.3f}"
        else:
            text = " ".join(f"{v:.3f}" for v in values)
        parts.append(f"{param.label}: {text}")
    return "   ".join(parts)
