"""A ``.matshop`` project used as a look: its layers above the base, over another set.

Fill, filter and group layers carry over as they are; paint layers, fill
textures and masks are resampled to the set's size (in edit space, paint
premultiplied by its coverage so edges do not darken). Edit vectors are laid
out per parameter, so each layer keeps only the parameters the set shares
with the look's material (same editing space); a layer sharing none is left
out and said so.
"""

from __future__ import annotations

import os
from functools import lru_cache
from pathlib import Path

import numpy as np
from skimage.transform import resize

from ..errors import MatshopError
from ..layers import Document
from ..layers.layer import FillLayer, FilterLayer, GroupLayer, Layer, PaintLayer
from ..layers.tiles import TileGrid
from ..material import Material, Schema

_COMMON = ("visible", "opacity", "blend", "mask_inverted")


def check_look(path: str | os.PathLike[str]) -> None:
    """Refuse a project that cannot serve as a look (unreadable, nothing above its base)."""
    doc = _look(Path(path), os.stat(path).st_mtime_ns)
    if len(doc.layers) < 2:
        raise MatshopError("the look has no layers above its base: nothing to apply", path)


def apply_look(path: str | os.PathLike[str], material: Material) -> tuple[Material, list[str]]:
    """``material`` under the look's layers, flattened; and notes on layers left out."""
    look = _look(Path(path), os.stat(path).st_mtime_ns)
    target = Document.from_material(material)
    shared = [
        name
        for name in look.schema.names
        if name in target.schema and look.schema[name].space.name == target.schema[name].space.name
    ]
    notes: list[str] = []
    made: list[tuple[Layer, Layer]] = []
    for layer in look.layers[1:]:
        wanted = look.schema.names if layer.parameters is None else layer.parameters
        keep = tuple(p for p in wanted if p in shared)
        if not keep:
            notes.append(f"look layer {layer.name!r}: the set has none of its parameters")
            continue
        new = _copy_content(layer, look, target)
        for name in _COMMON:
            new.put(name, new.validate(name, getattr(layer, name), target.schema))
        new.put("parameters", new.validate("parameters", keep, target.schema))
        if layer.mask is not None:
            mask = _resampled(layer.mask.to_array(), target.size)[..., 0]
            new.put("mask", target.new_mask(array=mask))
        made.append((layer, new))
    ids = {old.id: new.id for old, new in made}
    for old, new in made:  # members sit below their group: link before inserting any
        new.put("parent", ids.get(old.parent) if old.parent is not None else None)
        target.insert_layer(new)
    return target.flatten_physical(), notes


@lru_cache(maxsize=2)
def _look(path: Path, mtime_ns: int) -> Document:
    """The look's document, read once per worker process while the file is unchanged."""
    from ..io.project import load_project

    return load_project(path).document


def _copy_content(layer: Layer, look: Document, target: Document) -> Layer:
    if isinstance(layer, FilterLayer):
        return target.new_layer("filter", layer.name, op=layer.op, op_params=dict(layer.op_params))
    if isinstance(layer, GroupLayer):
        return target.new_layer("group", layer.name)
    if isinstance(layer, FillLayer):
        if layer.source is None:
            value = _remap(layer.value, look.schema, target.schema)
            return target.new_layer("fill", layer.name, value=value)
        source = _resampled(_remap(layer.source, look.schema, target.schema), target.size)
        return target.new_layer("fill", layer.name, source=source)
    if isinstance(layer, PaintLayer):
        assert layer.pixels is not None
        pixels = layer.pixels.to_array()
        values, coverage = pixels[..., :-1], pixels[..., -1:]
        values = _remap(values, look.schema, target.schema)
        # premultiplied while resampling: uncovered texels' values must not bleed in
        both = _resampled(np.concatenate([values * coverage, coverage], axis=-1), target.size)
        covered = both[..., -1:]
        values = np.divide(both[..., :-1], covered, out=np.zeros_like(both[..., :-1]),
                           where=covered > 1e-6)  # fmt: skip
        pixels = TileGrid.from_array(np.concatenate([values, covered], -1), target.layout)
        return target.new_layer("paint", layer.name, pixels=pixels)
    raise MatshopError(f"look layer {layer.name!r}: a {layer.kind} layer cannot be carried over")


def _remap(values: np.ndarray, source: Schema, target: Schema) -> np.ndarray:
    """Edit values laid out for ``source`` re-laid for ``target`` (shared parameters; 0 else)."""
    out = np.zeros((*values.shape[:-1], target.edit_width), np.float32)
    for name, where in source.edit_slices.items():
        if name in target:
            out[..., target.edit_slices[name]] = values[..., where]
    return out


def _resampled(array: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """``(h, w, C)`` to ``size``: bilinear, box-filtered first when shrinking."""
    if array.shape[:2] == tuple(size):
        return np.ascontiguousarray(array, dtype=np.float32)
    shrinking = size[0] < array.shape[0] or size[1] < array.shape[1]
    out = resize(array, (*size, array.shape[2]), order=1, mode="wrap", anti_aliasing=shrinking)
    return out.astype(np.float32)
