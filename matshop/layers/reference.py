"""The whole-image flatten without caches or tiles: the oracle for the cached one.

Each layer is composited over the whole image in one call; a filter runs on
the whole composite below (a neighbourhood filter tile by tile from that
whole composite, as its definition in :func:`filter_by_tile` says).
It shares only the per-texel arithmetic with the compositor (layer alpha,
blend kernels, the layer's mean), so comparing the two checks the tiling,
the filter margins and, after edits, the cache invalidation. Slow and
memory-hungry by design; tests and benchmarks use it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .blend import get_blend_mode, mean_of, weighted_mean
from .compositor import blend_into, close_group, filter_by_tile, generated_mask
from .layer import FillLayer, FilterLayer, GroupLayer, PaintLayer

if TYPE_CHECKING:
    from .document import Document


def flatten_reference(doc: Document) -> np.ndarray:
    """The document flattened bottom-up in edit space, ``(H, W, C)`` float32, from scratch."""
    bounds = doc.layout.bounds
    schema = doc.schema
    image = np.tile(doc.background, (bounds.height, bounds.width, 1))
    # the composite under each group's lowest member, kept until the group closes
    group_inputs: dict[int, list[np.ndarray]] = {}
    starts = {}
    for index, layer in enumerate(doc.layers):
        if isinstance(layer, GroupLayer):  # brute force, apart from Document.group_starts
            below = [b for b in range(index) if doc.in_group(doc.layers[b], layer.id)]
            starts.setdefault(min(below, default=index), []).append(index)
    for index, layer in enumerate(doc.layers):
        for group_index in starts.get(index, ()):
            group_inputs[group_index] = image.copy()
        # a generated mask is made of the whole composite below, as it stands here
        shown = doc.shows(layer) or isinstance(layer, GroupLayer)
        generated = None
        if shown and layer.mask_generator is not None:
            generated = generated_mask(layer, schema, image)
        if isinstance(layer, GroupLayer):
            close_group(doc, layer, group_inputs.pop(index), image, bounds, generated)
            continue
        if not doc.shows(layer):
            continue
        uses_mean = get_blend_mode(layer.blend).uses_mean
        if isinstance(layer, FilterLayer):
            reach = layer.reach(doc.layout, schema)
            if reach:  # a neighbourhood op runs per tile (see filter_by_tile)
                grown = _continued(image, reach, layer.border)
                values = filter_by_tile(layer, schema, doc.layout, bounds, grown, reach)
            else:
                values = layer.run(image, schema)
            mean = mean_of(*weighted_mean(values)) if uses_mean else None
            alpha = layer.alpha(bounds, generated=generated)
        elif isinstance(layer, PaintLayer):
            values, coverage = layer.values(bounds)
            alpha = layer.alpha(bounds, coverage, generated)
            mean = layer.mean() if uses_mean else None
        elif isinstance(layer, FillLayer):
            values = layer.content(bounds)
            alpha = layer.alpha(bounds, generated=generated)
            mean = layer.mean() if uses_mean else None
        else:  # pragma: no cover
            raise TypeError(f"cannot flatten a {type(layer).__name__}")
        blend_into(layer, schema, image, values, alpha, mean)
    return image


def _continued(image: np.ndarray, reach: int, border: str) -> np.ndarray:
    """The image grown by ``reach`` on every side, periodically or by its edge texels."""
    height, width = image.shape[:2]
    rows = np.arange(-reach, height + reach)
    cols = np.arange(-reach, width + reach)
    if border == "wrap":
        rows, cols = rows % height, cols % width
    else:
        rows, cols = np.clip(rows, 0, height - 1), np.clip(cols, 0, width - 1)
    return image[rows][:, cols]
