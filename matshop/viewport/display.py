"""Physical maps -> 8-bit display pixels, one parameter at a time.

Qt-free numpy so the conversion can be tested and timed on its own. Each
parameter family is shown the way artists expect to see its texture:

- colors (linear RGB) through the exact sRGB encode,
- normal frames as ``0.5 + 0.5 n`` (the familiar blue normal map),
- microfacet exponents (Phong, Ashikhmin-Shirley) as the equivalent
  roughness ``sqrt(2 / (n + 2))`` so rough is bright like a roughness map,
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

#: Entries of the sRGB encode table; 4096 levels keep 8-bit output exact to
#: within one code value while a table lookup is ~10x faster than pow().
_LUT_SIZE = 4096


def _srgb_table() -> np.ndarray:
    linear = np.linspace(0.0, 1.0, _LUT_SIZE, dtype=np.float64)
    encoded = np.where(
        linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(linear, 1 / 2.4) - 0.055
    )
    return np.round(encoded * 255.0).astype(np.uint8)


_SRGB = _srgb_table()
_LINEAR = np.round(np.linspace(0.0, 255.0, _LUT_SIZE)).astype(np.uint8)


@dataclass(frozen=True)
class DisplayMode:
    """How one parameter is turned into display colors."""

    kind: str  # "color", "vector", "exponent", "scalar", "wide"
    note: str  # what the user is looking at, for the status bar / combo tooltip


def display_mode(param: Parameter) -> DisplayMode:
    """The display mode of a schema parameter (by its editing space and width)."""
    space = param.space.name
    if space in ("srgb", "gamma22"):
        return DisplayMode("color", "linear color, shown sRGB-encoded")
    if space.startswith("normal"):
        return DisplayMode("vector", "normal shown as 0.5 + 0.5 n")
    if space.startswith(("phong", "ashikhmin_shirley")):
        return DisplayMode("exponent", "exponent shown as equivalent roughness sqrt(2/(n+2))")
    if param.phys_channels <= 3 and param.phys_channels != 2:
        return DisplayMode("scalar", "linear value in [0, 1]")
    if param.phys_channels == 2:
        return DisplayMode("scalar", "two channels shown as red and green")
    return DisplayMode("wide", f"mean of {param.phys_channels} samples")


def _encode(values: np.ndarray, table: np.ndarray) -> np.ndarray:
    """Float values (clipped to [0, 1]) -> uint8 through a lookup table."""
    index = np.clip(values, 0.0, 1.0)  # a new array: scaled in place below
    index *= _LUT_SIZE - 1
    return table[(index + 0.5).astype(np.intp)]


def to_display(param: Parameter, phys: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """Physical values ``(h, w, P)`` of ``param`` -> RGBX ``(h, w, 4)`` uint8.

    ``out`` (e.g. a view into the canvas buffer) is filled and returned when given.
    """
    height, width = phys.shape[:2]
    if out is None:
        out = np.empty((height, width, 4), dtype=np.uint8)
    mode = display_mode(param).kind
    phys = np.asarray(phys, dtype=np.float32)
    if mode == "color":
        rgb = _encode(phys[..., :3], _SRGB)
    elif mode == "vector":
        rgb = _encode(phys[..., :3] * np.float32(0.5) + np.float32(0.5), _LINEAR)
    elif mode == "exponent":
        rough = np.sqrt(np.float32(2.0) / (np.maximum(phys, 0.0) + np.float32(2.0)))
        rgb = _gray_or_rg(_encode(rough, _LINEAR))
    elif mode == "wide":
        rgb = _gray_or_rg(_encode(phys.mean(axis=-1, keepdims=True), _LINEAR))
    else:
        rgb = _gray_or_rg(_encode(phys, _LINEAR))
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
