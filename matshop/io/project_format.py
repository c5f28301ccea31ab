"""The ``.matshop`` manifest: how a document becomes one, and how one is checked.

A project file is a zip archive (see :mod:`matshop.io.project_store`) holding
``manifest.json`` and binary members. The manifest (format 1) is::

    {
      "format": "matshop", "format_version": 1, "app_version": "0.1.0",
      "document": {"name": str, "height": int, "width": int, "tile_size": int,
                   "background": [float] * C,
                   "sources": {param: {"file": str, "slot": str, "convention": str, ...}}},
      "schema": [{"name": str, "space": str, "edit_channels": int}, ...],
      "layers": [                                  # bottom to top
        {"kind": "paint" | "fill" | "filter" | "group", "id": int, "name": str,
         "visible": bool, "opacity": float, "blend": str,
         "parameters": null | [str], "mask_inverted": bool,
         "parent": null | int,                     # id of the group it belongs to
         "mask": null | GRID,                      # one channel
         "mask_generator": {"kind": "cavity" | "edge" | "ao", "radius_px": float,
                            "level": float, "contrast": float, "blur_px": float,
                            "invert": bool},   # optional: the mask made of the layers below
         "pixels": GRID,                           # paint: C + 1 channels
         "value": null | [float] * C,              # fill: constant, and/or
         "source": null | ARRAY,                   # fill: (H, W, C) texture
         "op": str, "op_params": {name: JSON | {"$array": ARRAY}}},   # filter
        ...],
      "settings": {...}                            # the app's, free-form JSON
    }
    GRID  = {"member": str, "dtype": "<f4", "channels": int, "fill": [float],
             "tiles": [[row, col], ...]}
    ARRAY = {"member": str, "dtype": "<f4" | "<f8" | "|b1", "shape": [int]}

A GRID member holds its stored tiles one after another in the listed order,
each ``(h, w, channels)`` row-major little-endian float32, ``h, w`` from the
tile layout (edge tiles are short): only non-empty tiles exist, so an empty
layer is a few lines of JSON. Floats in the manifest are float32 or Python
floats written with ``repr``, which JSON reads back exactly; NaN is refused.

This module writes manifests (:func:`encode`); :mod:`.project_check` reads
and checks them.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from ..finite import all_finite
from ..layers import Document, FillLayer, FilterLayer, Layer, PaintLayer
from ..layers.tiles import TileGrid

FORMAT_NAME = "matshop"
#: The newest format this version writes and reads.
FORMAT_VERSION = 1
MANIFEST_NAME = "manifest.json"
TILE_DTYPE = "<f4"
#: dtypes an ARRAY member may have (filter parameters may be masks or polygons)
ARRAY_DTYPES = {"<f4": 4, "<f8": 8, "|b1": 1}
LAYER_KINDS = ("paint", "fill", "filter", "group")

# Limits against tampered files; far above anything the editor makes.
MAX_SIDE = 65536
MAX_TILE_SIZE = 4096
MAX_TILES = 1 << 20  # a 65536-texel square in 64-texel tiles
MAX_LAYERS = 10_000
MAX_GROUP_DEPTH = 32
MAX_PARAMETERS = 1024
MAX_CHANNELS = 1 << 16
MAX_STRING = 4096
MAX_LAYER_ID = 2**62
MAX_MANIFEST_BYTES = 64 << 20


class FormatProblem(Exception):
    """What is wrong with a manifest or a member, as one line (the caller adds the file).

    ``standalone`` problems read on their own ("made by a newer matshop");
    the others get "damaged or invalid project: " in front.
    """

    def __init__(self, problem: str, *, standalone: bool = False) -> None:
        super().__init__(problem)
        self.standalone = standalone


# ----------------------------------------------------------------- writing


@dataclass(frozen=True)
class Payload:
    """One binary member to write: its name, exact size and its bytes in chunks."""

    member: str
    nbytes: int
    chunks: Callable[[], Iterator[memoryview]]


def _f4(array: np.ndarray) -> memoryview:
    return memoryview(np.ascontiguousarray(array, dtype=TILE_DTYPE)).cast("B")


def _floats(vector: np.ndarray) -> list[float]:
    return [float(v) for v in np.asarray(vector, dtype=np.float32).reshape(-1)]


def layer_label(index: int, name: object) -> str:
    """How messages name a layer: its position and (cut short) name."""
    text = repr(name if isinstance(name, str) else "?")
    return f"layer {index} ({text[:40]})"


def encode(document: Document, settings: dict[str, Any] | None) -> tuple[dict, list[Payload]]:
    """The manifest and payloads of ``document``.

    Every array is captured here (tiles are immutable, so this costs no
    copy): edits made while the payloads are written, e.g. during an autosave
    in a worker thread, do not change what is saved. (The working tiles of a
    paint transaction still open are the exception: commit it first.)
    ``settings`` must be plain JSON; tuples come back as lists.
    """
    settings = {} if settings is None else settings
    if not isinstance(settings, dict):
        raise FormatProblem(f"settings must be a dict, got {type(settings).__name__}")
    _check_json(settings, "settings")
    _check_json(document.sources, "document sources")
    if not np.isfinite(document.background).all():
        raise FormatProblem("the document background holds NaN or infinite values")
    payloads: list[Payload] = []
    layers = []
    for index, layer in enumerate(list(document.layers)):
        layers.append(_encode_layer(layer, index, document, payloads))
    manifest = {
        "format": FORMAT_NAME,
        "format_version": FORMAT_VERSION,
        "app_version": __version__,
        "document": {
            "name": document.name,
            "height": document.height,
            "width": document.width,
            "tile_size": document.layout.tile_size,
            "background": _floats(document.background),
            "sources": document.sources,
        },
        "schema": [
            {"name": p.name, "space": p.space.name, "edit_channels": p.edit_channels}
            for p in document.schema.parameters
        ],
        "layers": layers,
        "settings": settings,
    }
    return manifest, payloads


def dump_manifest(manifest: dict) -> bytes:
    """The manifest as compact UTF-8 JSON (no NaN: the reader refuses it)."""
    try:
        text = json.dumps(manifest, separators=(",", ":"), allow_nan=False, ensure_ascii=False)
        return text.encode("utf-8")
    except UnicodeEncodeError:  # a lone surrogate, e.g. from a non-UTF-8 file name
        raise FormatProblem("the document holds a name that is not valid Unicode text") from None
    except (TypeError, ValueError) as exc:
        raise FormatProblem(f"the document holds a value JSON cannot store ({exc})") from None


def _check_json(value: Any, what: str) -> None:
    try:
        json.dumps(value, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise FormatProblem(f"{what} must be plain finite JSON values ({exc})") from None


def _encode_layer(layer: Layer, index: int, doc: Document, payloads: list[Payload]) -> dict:
    where = layer_label(index, layer.name)
    prefix = f"layers/{index:04d}"
    entry: dict[str, Any] = {
        "kind": layer.kind,
        "id": layer.id,
        "name": layer.name,
        "visible": layer.visible,
        "opacity": float(layer.opacity),
        "blend": layer.blend,
        "parameters": None if layer.parameters is None else list(layer.parameters),
        "mask_inverted": layer.mask_inverted,
        "parent": getattr(layer, "parent", None),
        "mask": None,
    }
    if layer.mask is not None:
        entry["mask"] = _encode_grid(layer.mask, f"{prefix}/mask.f32", f"{where} mask", payloads)
    if layer.mask_generator is not None:  # absent otherwise: older readers see nothing new
        entry["mask_generator"] = layer.mask_generator.to_json()
    if isinstance(layer, PaintLayer):
        assert layer.pixels is not None
        pixels = _encode_grid(layer.pixels, f"{prefix}/pixels.f32", f"{where} pixels", payloads)
        entry["pixels"] = pixels
    elif isinstance(layer, FillLayer):
        entry["value"] = None if layer.value is None else _floats(layer.value)
        entry["source"] = None
        if layer.value is not None and not np.isfinite(layer.value).all():
            raise FormatProblem(f"{where} fill value holds NaN or infinite values")
        if layer.source is not None:
            member = f"{prefix}/source.f32"
            entry["source"] = _encode_array(layer.source, member, f"{where} source", payloads)
    elif isinstance(layer, FilterLayer):
        entry["op"] = layer.op
        entry["op_params"] = {
            key: _encode_param(value, f"{prefix}/param-{n}.bin", f"{where} {key}", payloads)
            for n, (key, value) in enumerate(layer.op_params.items())
        }
    elif layer.kind != "group":  # a group has no content: its members say they belong
        raise FormatProblem(f"{where}: saving {layer.kind} layers is not supported yet")
    return entry


def _encode_grid(grid: TileGrid, member: str, what: str, payloads: list[Payload]) -> dict:
    keys = sorted(grid.keys())
    tiles = [grid.get(key) for key in keys]
    for tile in tiles:
        assert tile is not None
        if not all_finite(tile):
            raise FormatProblem(f"{what} hold NaN or infinite values")
    nbytes = sum(tile.size * 4 for tile in tiles if tile is not None)

    def chunks() -> Iterator[memoryview]:
        for tile in tiles:
            assert tile is not None
            yield _f4(tile)

    payloads.append(Payload(member, nbytes, chunks))
    return {
        "member": member,
        "dtype": TILE_DTYPE,
        "channels": grid.channels,
        "fill": _floats(grid.fill),
        "tiles": [list(key) for key in keys],
    }


def _encode_array(array: np.ndarray, member: str, what: str, payloads: list[Payload]) -> dict:
    if array.dtype == bool:
        dtype, data = "|b1", np.ascontiguousarray(array)
    elif array.dtype == np.float32:
        dtype, data = TILE_DTYPE, np.ascontiguousarray(array, dtype=TILE_DTYPE)
    elif array.dtype.kind in "fiu":  # float64 polygons; integers are exact in float64
        dtype, data = "<f8", np.ascontiguousarray(array, dtype="<f8")
    else:
        raise FormatProblem(f"{what}: cannot store an array of {array.dtype}")
    if dtype != "|b1" and not all_finite(data):
        raise FormatProblem(f"{what} holds NaN or infinite values")
    payloads.append(Payload(member, data.nbytes, lambda: iter([memoryview(data).cast("B")])))
    return {"member": member, "dtype": dtype, "shape": list(data.shape)}


def _encode_param(value: Any, member: str, what: str, payloads: list[Payload]) -> Any:
    if isinstance(value, np.ndarray):
        return {"$array": _encode_array(value, member, what, payloads)}
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, Path):
        raise FormatProblem(f"{what}: a project cannot refer to the outside file {value}")
    _check_json(value, what)
    return value
