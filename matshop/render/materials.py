"""Small synthetic materials for tests, figures and thumbnails.

Values are *physical*, as files hold them (colors sRGB-encoded, GGX
perceptual roughness, Phong exponents, tabulated lobes ...); see
:data:`matshop.material.PARAMETER_KINDS` for the names.
"""

from __future__ import annotations

import numpy as np

from ..material import Material, Schema


def constant(
    size: int | tuple[int, int] = 1,
    *,
    name: str = "constant",
    spaces: dict[str, str] | None = None,
    **values: float | tuple[float, ...] | np.ndarray,
) -> Material:
    """A material whose every parameter is one value everywhere.

    ``constant(base_color=(0.8, 0.8, 0.8), roughness=0.4)``; a 1-D array gives
    a multi-channel parameter (``distribution=d_from_ggx(0.2)``).
    """
    h, w = (size, size) if np.isscalar(size) else size
    schema = Schema.from_names(list(values), spaces)
    maps = {}
    for param in schema.parameters:
        value = np.atleast_1d(np.asarray(values[param.name], dtype=np.float32))
        if value.size == 1:
            value = np.repeat(value, param.phys_channels)
        maps[param.name] = np.ascontiguousarray(np.broadcast_to(value, (h, w, param.phys_channels)))
    return Material(name, schema, maps)


def from_maps(
    maps: dict[str, np.ndarray], *, name: str = "material", spaces: dict[str, str] | None = None
) -> Material:
    """A material from ``(H, W, C)`` physical maps (``(H, W)`` scalars are widened)."""
    maps = {k: (v[..., None] if v.ndim == 2 else v).astype(np.float32) for k, v in maps.items()}
    return Material(name, Schema.from_names(list(maps), spaces), maps)


def srgb_from_linear(linear: float | np.ndarray) -> np.ndarray:
    """Encode linear reflectance as a file's sRGB value (for building colors from albedos)."""
    x = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1.0 / 2.4) - 0.055)
