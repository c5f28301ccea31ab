"""An image as layer content: a paint layer's values for the parameters picked, or a mask.

What each parameter takes from the image (its codes as read, 8/16-bit divided
by their maximum; the image's alpha, if any, is the layer's coverage):

- a color (base color, diffuse, specular, emissive): the RGB codes as they
  are, sRGB file codes like the maps a texture set holds (gray repeated);
- a scalar (roughness, metallic, occlusion, height...): the gray, or the
  Rec. 709 luminance of a color image (as masks read it);
- the normal: a normal map decoded in the document's convention, or with
  ``as_height``, a height image made into normals by the engine's own
  :func:`~matshop.spaces.frame.height_to_normal`, its full range (0 to 1)
  spanning ``height_px`` texel widths of displacement (the texture tiles).

An image of another size than the document is resampled to it (area-averaged
down, bilinear up), and the returned notes say so; masks go through the one
mask reader, :func:`matshop.api.load_mask`, with the same resampling.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .api import load_mask
from .errors import InvalidValue, MatshopError
from .finite import all_finite
from .io.images import luminance, probe_image, read_image, resample_image
from .layers import Document
from .layers.layer import PaintLayer
from .layers.tiles import TileGrid
from .material import Parameter
from .spaces.frame import decode_normal_map, height_to_normal

PathLike = str | os.PathLike[str]

#: texel widths of displacement a height image's full range spans, unless told
HEIGHT_PX = 8.0


def _resample_note(path: Path, width: int, height: int, doc: Document) -> list[str]:
    if (height, width) == doc.size:
        return []
    how = "area-averaged" if width * height > doc.width * doc.height else "bilinear"
    return [
        f"{path.name} is {width}x{height}, the project {doc.width}x{doc.height}: "
        f"resampled to fit ({how})"
    ]


def _physical(
    param: Parameter,
    rgb: np.ndarray,
    gray: np.ndarray,
    *,
    as_height: bool,
    height_px: float,
    convention: str,
) -> np.ndarray:
    """The physical values ``(H, W, phys_channels)`` parameter ``param`` takes from the image."""
    if param.name == "normal" and param.phys_channels == 3:
        if as_height:
            return height_to_normal(gray * np.float32(height_px), wrap=True)
        return decode_normal_map(np.clip(rgb, 0.0, 1.0), convention=convention)  # type: ignore[arg-type]
    if as_height:
        raise InvalidValue("a height image makes normals: pick the normal parameter")
    if param.phys_channels == 3:
        return rgb
    if param.phys_channels == 1:
        return gray[..., None]
    raise InvalidValue(
        f"{param.name} ({param.phys_channels} values a texel) cannot be read from an image"
    )


def image_values(
    doc: Document,
    path: PathLike,
    parameters: tuple[str, ...] | list[str],
    *,
    as_height: bool = False,
    height_px: float = HEIGHT_PX,
) -> tuple[np.ndarray, list[str]]:
    """``(paint-layer pixels (H, W, channels + 1): edit values, then coverage, notes)``.

    Channels of parameters not picked hold the document's background.
    Raises :class:`MatshopError` (one line naming the file) for a file that
    cannot be read or values a parameter cannot take.
    """
    path = Path(path)
    unknown = [p for p in parameters if p not in doc.schema]
    if not parameters or unknown:
        raise MatshopError(
            f"pick parameters of the project ({', '.join(doc.schema.names)})"
            + (f", not {', '.join(unknown)}" if unknown else "")
        )
    if as_height and tuple(parameters) != ("normal",):
        raise MatshopError("a height image makes normals: pick the normal parameter only")
    if not (np.isfinite(height_px) and 0.0 < height_px <= 1e4):
        raise MatshopError(f"height_px must lie in (0, 10000], got {height_px:g}")
    pixels, info = read_image(path)
    notes = _resample_note(path, info.width, info.height, doc)
    pixels = resample_image(pixels, doc.size)
    if pixels.ndim == 2:
        pixels = pixels[..., None]
    alpha = info.alpha_channel
    coverage = np.clip(pixels[..., alpha], 0.0, 1.0) if alpha >= 0 else None
    color = np.delete(pixels, alpha, axis=2) if alpha >= 0 else pixels
    rgb = np.repeat(color[..., :1], 3, axis=2) if color.shape[2] < 3 else color[..., :3]
    gray = luminance(color)
    out = np.empty((*doc.size, doc.channels + 1), np.float32)
    out[..., :-1] = doc.background
    out[..., -1] = 1.0 if coverage is None else coverage
    for name in parameters:
        param = doc.schema[name]
        try:
            phys = _physical(
                param,
                rgb,
                gray,
                as_height=as_height,
                height_px=height_px,
                convention=doc.normal_convention,
            )
            with np.errstate(all="ignore"):
                edit = param.space.to_edit(np.ascontiguousarray(phys, dtype=np.float32))
        except (InvalidValue, ValueError) as exc:
            raise MatshopError(str(exc), path) from None
        if not all_finite(edit):
            raise MatshopError(f"its values are out of range for {name}", path)
        out[..., doc.schema.edit_slices[name]] = edit
    return out, notes


def image_layer(
    doc: Document,
    path: PathLike,
    parameters: tuple[str, ...] | list[str],
    *,
    name: str | None = None,
    as_height: bool = False,
    height_px: float = HEIGHT_PX,
    **props: object,
) -> tuple[PaintLayer, list[str]]:
    """A new paint layer (not yet in the stack) holding the image's values for ``parameters``
    and affecting only those; paint and erase on it as on any paint layer. ``props``: other
    layer properties (opacity, blend, visible)."""
    values, notes = image_values(doc, path, parameters, as_height=as_height, height_px=height_px)
    picked = tuple(p for p in doc.schema.names if p in parameters)
    limit = None if len(picked) == len(doc.schema.names) else picked
    layer = doc.new_paint_layer(name or Path(path).stem, parameters=limit, **props)
    layer.pixels = TileGrid.from_array(values, doc.layout, 0.0)
    return layer, notes


def image_mask(doc: Document, path: PathLike) -> tuple[TileGrid, list[str]]:
    """A mask grid from a gray image (or a color image's luminance), resampled to fit."""
    path = Path(path)
    info = probe_image(path)
    mask = doc.new_mask(array=load_mask(path, doc.size, resample=True))
    return mask, _resample_note(path, info.width, info.height, doc)
