"""What several figures share: the lit swatch tile, material resizing and the height-field blur."""

from __future__ import annotations

import cv2
import numpy as np

from ..material import Material, Schema
from ..ops import get_op
from ..ops.blur import gaussian
from ..render.integrator import DirectionalLight
from ..render.render import render
from .context import FigureContext, display

TILE = 224
#: a grazing key light brings out relief on the tilted swatch
RELIEF_LIGHT = DirectionalLight((-0.8, 0.7, 0.5), (2.5, 2.5, 2.5))


def swatch(ctx: FigureContext, material: Material, size: int = TILE) -> np.ndarray:
    image = render(
        material,
        scene="swatch",
        size=size,
        environment=ctx.environment,
        lights=(RELIEF_LIGHT,),
        samples=24,
    )
    return display(image)


def with_maps(material: Material, **maps: np.ndarray) -> Material:
    return Material(material.name, material.schema, {**material.maps, **maps}, material.sources)


def resized(material: Material, size: int) -> Material:
    h, w = material.size
    if max(h, w) <= size:
        return material
    maps = {}
    for name, arr in material.maps.items():
        out = cv2.resize(arr, (size, size), interpolation=cv2.INTER_AREA).reshape(size, size, -1)
        if name == "normal":
            out = out / np.linalg.norm(out[..., :3], axis=-1, keepdims=True)
        maps[name] = out.astype(np.float32)
    return Material(material.name, material.schema, maps, material.sources)


def height_blur(normal: np.ndarray, sigma: float) -> np.ndarray:
    nz = np.maximum(normal[..., 2:3], 1e-3)
    slopes = -normal[..., :2] / nz
    blurred = wrap_blur(slopes, sigma)
    n = np.concatenate([-blurred, np.ones_like(nz)], axis=-1)
    return (n / np.linalg.norm(n, axis=-1, keepdims=True)).astype(np.float32)


def wrap_blur(image: np.ndarray, sigma: float) -> np.ndarray:
    return gaussian(np.ascontiguousarray(image, dtype=np.float32), sigma, "wrap")


def detail_on_file_values(
    material: Material,
    *,
    amount: float,
    sigma_px: float,
    sigma_range: float,
    scale: dict[str, float] | None = None,
) -> dict[str, np.ndarray]:
    """The detail (unsharp) op run on the raw file values, each channel a linear scalar.

    What a physical-space editor does: ``scale`` divides a map first and multiplies
    it back after (e.g. a Phong exponent brought to [0, 1]). Not clipped: how far
    the result leaves the valid range is the figures' measurement.
    """
    names = material.schema.names
    scale = {n: (scale or {}).get(n, 1.0) for n in names}
    stack = np.concatenate([material.maps[n] / scale[n] for n in names], axis=2)
    chans = [f"c{k}" for k in range(stack.shape[2])]
    schema = Schema.from_names(chans, {c: "identity_unbounded" for c in chans})
    out = get_op("detail").function(
        stack,
        schema=schema,
        params=chans,
        mask=None,
        amount=amount,
        sigma_px=sigma_px,
        sigma_range=sigma_range,
        border="wrap",
    )
    maps, start = {}, 0
    for n in names:
        width = material.maps[n].shape[2]
        maps[n] = out[..., start : start + width] * scale[n]
        start += width
    return maps
