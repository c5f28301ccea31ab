"""Checking a ``.matshop`` manifest (the format is described in :mod:`.project_format`).

Reading never trusts the file: :func:`parse_manifest` checks every type,
name, size and reference and returns plain specs (:class:`ManifestSpec`)
from which the store reads exactly the declared bytes. Problems raise
:class:`~.project_format.FormatProblem` (one line, no path); the store adds
the file name. Strings from the file are cut short in messages, so a
tampered name cannot flood one.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InvalidValue, MatshopError
from ..layers.geometry import TileKey, TileLayout
from ..layers.properties import check_property
from ..material import Parameter, Schema
from ..ops import get_op
from ..spaces import get_space
from .jsonfile import bounded_int
from .project_format import (
    ARRAY_DTYPES,
    FORMAT_NAME,
    FORMAT_VERSION,
    LAYER_KINDS,
    MANIFEST_NAME,
    MAX_CHANNELS,
    MAX_GROUP_DEPTH,
    MAX_LAYER_ID,
    MAX_LAYERS,
    MAX_PARAMETERS,
    MAX_SIDE,
    MAX_STRING,
    MAX_TILE_SIZE,
    MAX_TILES,
    TILE_DTYPE,
    FormatProblem,
    layer_label,
)

#: Member names the manifest may reference: relative, plain, no "..".
_MEMBER_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.\-]*(/[A-Za-z0-9_][A-Za-z0-9_.\-]*)*")


@dataclass(frozen=True)
class GridSpec:
    """A checked GRID reference: which tiles a member holds, and its exact size."""

    member: str
    what: str
    channels: int
    fill: np.ndarray
    keys: tuple[TileKey, ...]
    nbytes: int


@dataclass(frozen=True)
class ArraySpec:
    """A checked ARRAY reference."""

    member: str
    what: str
    dtype: str
    shape: tuple[int, ...]
    nbytes: int


@dataclass
class LayerSpec:
    """A checked layer entry: properties in their stored (normalised) form."""

    kind: str
    id: int
    props: dict[str, Any]
    where: str
    mask: GridSpec | None = None
    pixels: GridSpec | None = None
    value: np.ndarray | None = None
    source: ArraySpec | None = None
    op: str = ""
    op_params: dict[str, Any] = field(default_factory=dict)


@dataclass
class ManifestSpec:
    """A fully checked manifest: everything needed to read members and build the document."""

    format_version: int
    app_version: str
    name: str
    layout: TileLayout
    background: np.ndarray
    schema: Schema
    layers: list[LayerSpec]
    settings: dict[str, Any]
    sources: dict[str, dict] = field(default_factory=dict)

    def members(self) -> list[GridSpec | ArraySpec]:
        """Every member the manifest references, in order."""
        found: list[GridSpec | ArraySpec] = []
        for layer in self.layers:
            found += [s for s in (layer.mask, layer.pixels, layer.source) if s is not None]
            found += [v for v in layer.op_params.values() if isinstance(v, ArraySpec)]
        return found


def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    keys = [key for key, _ in pairs]
    if len(set(keys)) != len(keys):
        raise FormatProblem("manifest repeats a key in one object")
    return dict(pairs)


def _refuse_constant(name: str) -> Any:
    raise FormatProblem(f"manifest holds {name}, not a finite number")


def load_manifest_json(data: bytes) -> Any:
    """Parse manifest bytes (strict UTF-8 JSON, no NaN, no repeated keys)."""
    try:
        return json.loads(
            data.decode("utf-8"),
            object_pairs_hook=_no_duplicates,
            parse_constant=_refuse_constant,
            parse_int=bounded_int,
        )
    except (UnicodeDecodeError, ValueError) as exc:  # JSONDecodeError, absurd integers
        raise FormatProblem(f"manifest is not valid JSON ({exc})") from None
    except RecursionError:
        raise FormatProblem("manifest nests too deeply") from None


def _get(obj: dict, key: str, where: str) -> Any:
    if key not in obj:
        raise FormatProblem(f"{where}: missing {key!r}")
    return obj[key]


def _type_name(value: Any) -> str:
    return {dict: "an object", list: "a list", str: "a string", bool: "a boolean"}.get(
        type(value), "null" if value is None else "a number"
    )


def _dict(value: Any, where: str) -> dict:
    if not isinstance(value, dict):
        raise FormatProblem(f"{where} must be an object, got {_type_name(value)}")
    return value


def _list(value: Any, where: str, max_len: int) -> list:
    if not isinstance(value, list):
        raise FormatProblem(f"{where} must be a list, got {_type_name(value)}")
    if len(value) > max_len:
        raise FormatProblem(f"{where} has {len(value)} entries, more than {max_len}")
    return value


def _int(value: Any, where: str, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise FormatProblem(f"{where} must be a whole number, got {_type_name(value)}")
    if not lo <= value <= hi:
        raise FormatProblem(f"{where}={value} is outside [{lo}, {hi}]")
    return value


def _str(value: Any, where: str) -> str:
    if not isinstance(value, str):
        raise FormatProblem(f"{where} must be a string, got {_type_name(value)}")
    if len(value) > MAX_STRING:
        raise FormatProblem(f"{where} is longer than {MAX_STRING} characters")
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:  # a lone surrogate (JSON "\ud800"): no save could keep it
        raise FormatProblem(f"{where} is not valid Unicode text") from None
    return value


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise FormatProblem(f"{where} must be a number, got {_type_name(value)}")
    if not math.isfinite(value):
        raise FormatProblem(f"{where} must be finite")
    return float(value)


def _vector(value: Any, length: int, where: str) -> np.ndarray:
    items = _list(value, where, length)
    if len(items) != length:
        raise FormatProblem(f"{where} needs {length} values, got {len(items)}")
    numbers = [_number(v, f"{where}[{i}]") for i, v in enumerate(items)]
    with np.errstate(over="ignore"):
        vector = np.array(numbers, dtype=np.float32)
    if not np.isfinite(vector).all():
        raise FormatProblem(f"{where} holds values too large for float32")
    return vector


def _member(value: Any, where: str, seen: set[str]) -> str:
    name = _str(value, f"{where} member")
    if not _MEMBER_NAME.fullmatch(name) or ".." in name.split("/") or name == MANIFEST_NAME:
        raise FormatProblem(f"{where} refers to member {name[:80]!r}, not a plain name inside")
    if name in seen:
        raise FormatProblem(f"{where} refers to member {name!r} a second time")
    seen.add(name)
    return name


def check_version(manifest: Any) -> tuple[int, str]:
    """The format version and app version, after checking this version can read them."""
    manifest = _dict(manifest, "manifest")
    if manifest.get("format") != FORMAT_NAME:
        raise FormatProblem(
            "not a matshop project (the manifest's format is not 'matshop')", standalone=True
        )
    version = _int(_get(manifest, "format_version", "manifest"), "format_version", 1, 2**31)
    app = manifest.get("app_version")
    app = app[:40] if isinstance(app, str) else "unknown"
    if version > FORMAT_VERSION:
        raise FormatProblem(
            f"made by a newer matshop (format {version}, this version reads up to "
            f"{FORMAT_VERSION}; saved by matshop {app}): update matshop to open it",
            standalone=True,
        )
    return version, app


def parse_manifest(manifest: Any) -> ManifestSpec:
    """Check a parsed manifest completely; raise :class:`FormatProblem` at the first fault."""
    version, app = check_version(manifest)
    schema = _parse_schema(_get(manifest, "schema", "manifest"))
    doc = _dict(_get(manifest, "document", "manifest"), "document")
    name = _str(_get(doc, "name", "document"), "document name")
    height = _int(_get(doc, "height", "document"), "document height", 1, MAX_SIDE)
    width = _int(_get(doc, "width", "document"), "document width", 1, MAX_SIDE)
    tile = _int(_get(doc, "tile_size", "document"), "document tile_size", 1, MAX_TILE_SIZE)
    layout = TileLayout(height, width, tile)
    if layout.rows * layout.cols > MAX_TILES:
        raise FormatProblem(
            f"a {width}x{height} document in {tile}-texel tiles has {layout.rows * layout.cols} "
            f"tiles, more than {MAX_TILES}"
        )
    background = _vector(_get(doc, "background", "document"), schema.edit_width, "background")
    entries = _list(_get(manifest, "layers", "manifest"), "layers", MAX_LAYERS)
    seen: set[str] = set()
    layers = [_parse_layer(e, i, schema, layout, seen) for i, e in enumerate(entries)]
    ids = [layer.id for layer in layers]
    if len(set(ids)) != len(ids):
        raise FormatProblem("two layers have the same id")
    _check_nesting(layers)
    settings = _dict(manifest.get("settings", {}), "settings")
    sources = _parse_sources(doc.get("sources", {}))
    return ManifestSpec(version, app, name, layout, background, schema, layers, settings, sources)


def _parse_sources(value: Any) -> dict[str, dict[str, str | int | float | bool | None]]:
    """Where each parameter came from: {param: {key: scalar}} (older projects: none)."""
    sources = {}
    for param, entry in _dict(value, "document sources").items():
        where = f"document sources[{param[:40]!r}]"
        _str(param, "document sources key")
        entry = _dict(entry, where)
        if len(entry) > MAX_PARAMETERS:
            raise FormatProblem(f"{where} has more than {MAX_PARAMETERS} entries")
        for key, item in entry.items():
            _str(key, f"{where} key")
            if isinstance(item, str):
                _str(item, f"{where}[{key[:40]!r}]")
            elif item is not None and not isinstance(item, (bool, int, float)):
                raise FormatProblem(f"{where}[{key[:40]!r}] must be a string or a number")
        sources[param] = dict(entry)
    if len(sources) > MAX_PARAMETERS:
        raise FormatProblem(f"document sources name more than {MAX_PARAMETERS} parameters")
    return sources


def _check_nesting(layers: list[LayerSpec]) -> None:
    """Groups nest at most MAX_GROUP_DEPTH deep (flattening walks every level)."""
    parents = {layer.id: layer.props.get("parent") for layer in layers if layer.kind == "group"}
    for layer in layers:
        depth, parent, seen = 0, layer.props.get("parent"), set()
        while parent in parents and parent not in seen:  # a cycle reads as no deeper
            seen.add(parent)
            depth += 1
            if depth > MAX_GROUP_DEPTH:
                raise FormatProblem(
                    f"{layer.where} sits in groups nested more than {MAX_GROUP_DEPTH} deep"
                )
            parent = parents[parent]


def _parse_schema(value: Any) -> Schema:
    entries = _list(value, "schema", MAX_PARAMETERS)
    if not entries:
        raise FormatProblem("schema has no parameters")
    params = []
    for index, entry in enumerate(entries):
        where = f"schema[{index}]"
        entry = _dict(entry, where)
        name = _str(_get(entry, "name", where), f"{where} name")
        space_name = _str(_get(entry, "space", where), f"{where} space")
        try:
            space = get_space(space_name)
        except KeyError:
            raise FormatProblem(
                f"parameter {name!r} uses editing space {space_name[:40]!r}, "
                "which this matshop does not know"
            ) from None
        channels = _int(_get(entry, "edit_channels", where), f"{where} edit_channels", 1, 2**31)
        if channels != space.edit_channels:
            raise FormatProblem(
                f"parameter {name!r}: space {space_name} has {space.edit_channels} edit "
                f"channels here, the file was saved with {channels}"
            )
        params.append(Parameter(name, space))
    try:
        schema = Schema(params)
    except InvalidValue as exc:
        raise FormatProblem(f"schema: {exc}") from None
    if schema.edit_width >= MAX_CHANNELS:
        raise FormatProblem(f"schema has {schema.edit_width} edit channels, over {MAX_CHANNELS}")
    return schema


def _parse_layer(
    value: Any, index: int, schema: Schema, layout: TileLayout, seen: set[str]
) -> LayerSpec:
    entry = _dict(value, f"layer {index}")
    where = layer_label(index, entry.get("name"))
    kind = _str(_get(entry, "kind", where), f"{where} kind")
    if kind not in LAYER_KINDS:
        known = ", ".join(LAYER_KINDS)
        raise FormatProblem(f"{where}: unknown layer kind {kind[:40]!r} (known: {known})")
    props = {
        name: _property(kind, name, _get(entry, name, where), schema, where)
        for name in ("name", "visible", "opacity", "blend", "parameters", "mask_inverted")
    }
    generator = entry.get("mask_generator")
    if generator is not None:  # projects before generated masks have none
        generator = _dict(generator, f"{where} mask_generator")
        try:
            props["mask_generator"] = check_property(kind, "mask_generator", generator, schema)
        except InvalidValue as exc:
            raise FormatProblem(f"{where} mask_generator: {exc}") from None
    parent = entry.get("parent")
    if parent is not None:  # may name a group no longer in the stack, as in the document
        props["parent"] = _int(parent, f"{where} parent", 1, MAX_LAYER_ID)
    if kind == "group" and props["blend"] != "normal":
        raise FormatProblem(f"{where}: a group passes its layers through, its blend is normal")
    spec = LayerSpec(
        kind, _int(_get(entry, "id", where), f"{where} id", 1, MAX_LAYER_ID), props, where
    )
    mask = _get(entry, "mask", where)
    if mask is not None:
        spec.mask = _parse_grid(mask, 1, layout, f"{where} mask", seen)
    if kind == "paint":
        pixels = _get(entry, "pixels", where)
        spec.pixels = _parse_grid(pixels, schema.edit_width + 1, layout, f"{where} pixels", seen)
    elif kind == "fill":
        value, source = _get(entry, "value", where), _get(entry, "source", where)
        if value is None and source is None:
            raise FormatProblem(f"{where}: a fill layer needs a value or a source")
        if value is not None:
            spec.value = _vector(value, schema.edit_width, f"{where} value")
        if source is not None:
            shape = (layout.height, layout.width, schema.edit_width)
            spec.source = _parse_array(source, f"{where} source", seen, shape, (TILE_DTYPE,))
    elif kind == "filter":
        _parse_filter(entry, spec, seen)
    return spec


def _property(kind: str, name: str, value: Any, schema: Schema, where: str) -> Any:
    """A stored layer property, checked by the layer model's own table
    (:mod:`matshop.layers.properties`) after the file's own limits."""
    if isinstance(value, str):
        value = _str(value, f"{where} {name}")
    elif isinstance(value, list):
        value = [
            _str(v, f"{where} {name}") for v in _list(value, f"{where} {name}", MAX_PARAMETERS)
        ]
    try:
        return check_property(kind, name, value, schema)
    except InvalidValue as exc:
        raise FormatProblem(f"{where}: {exc.problem}") from None


def _parse_grid(
    value: Any, channels: int, layout: TileLayout, where: str, seen: set[str]
) -> GridSpec:
    grid = _dict(value, where)
    member = _member(_get(grid, "member", where), where, seen)
    if _get(grid, "dtype", where) != TILE_DTYPE:
        raise FormatProblem(f"{where}: tiles must be {TILE_DTYPE} (little-endian float32)")
    got = _int(_get(grid, "channels", where), f"{where} channels", 1, MAX_CHANNELS)
    if got != channels:
        raise FormatProblem(f"{where} has {got} channels, the schema needs {channels}")
    fill = _vector(_get(grid, "fill", where), channels, f"{where} fill")
    rows, cols = layout.grid_shape
    entries = _list(_get(grid, "tiles", where), f"{where} tiles", rows * cols)
    keys: list[TileKey] = []
    texels = 0
    for entry in entries:
        pair = _list(entry, f"{where} tile key", 2)
        if len(pair) != 2:
            raise FormatProblem(f"{where}: a tile key is [row, col], got {len(pair)} numbers")
        row = _int(pair[0], f"{where} tile row", 0, rows - 1)
        col = _int(pair[1], f"{where} tile column", 0, cols - 1)
        keys.append((row, col))
        texels += layout.tile_rect((row, col)).area
    if len(set(keys)) != len(keys):
        raise FormatProblem(f"{where} lists a tile twice")
    return GridSpec(member, where, channels, fill, tuple(keys), texels * channels * 4)


def _parse_array(
    value: Any,
    where: str,
    seen: set[str],
    shape: tuple[int, ...] | None,
    dtypes: tuple[str, ...] = tuple(ARRAY_DTYPES),
) -> ArraySpec:
    array = _dict(value, where)
    member = _member(_get(array, "member", where), where, seen)
    dtype = _get(array, "dtype", where)
    if dtype not in dtypes:
        raise FormatProblem(f"{where}: dtype {str(dtype)[:20]!r} is not one of {list(dtypes)}")
    dims = _list(_get(array, "shape", where), f"{where} shape", 4)
    got = tuple(_int(d, f"{where} shape", 0, MAX_CHANNELS * MAX_SIDE) for d in dims)
    if shape is not None and got != shape:
        raise FormatProblem(f"{where} is {list(got)}, the document needs {list(shape)}")
    return ArraySpec(member, where, dtype, got, math.prod(got) * ARRAY_DTYPES[dtype])


def _parse_filter(entry: dict, spec: LayerSpec, seen: set[str]) -> None:
    where = spec.where
    spec.op = _str(_get(entry, "op", where), f"{where} op")
    try:
        op = get_op(spec.op)
    except MatshopError as exc:
        raise FormatProblem(f"{where}: {exc.problem}") from None
    if op.inputs:
        raise FormatProblem(f"{where}: op {spec.op} cannot be a filter layer")
    params = _dict(_get(entry, "op_params", where), f"{where} op_params")
    for key, value in params.items():
        try:
            kind = op.param(key).kind
        except MatshopError as exc:
            raise FormatProblem(f"{where}: {exc.problem}") from None
        if isinstance(value, dict):
            array = _get(value, "$array", f"{where} {key}")
            spec.op_params[key] = _parse_array(array, f"{where} {key}", seen, None)
        elif kind in ("region", "path") and value is not None:
            # a string here would name a file outside the project: never read it
            raise FormatProblem(f"{where} {key}: only an array stored in the project is allowed")
        else:
            spec.op_params[key] = value
    for param in op.params:  # saved before the parameter existed: keep the old behaviour
        if param.name not in params and param.missing is not None:
            spec.op_params[param.name] = param.missing
    # values are bound (validated) by the op once the arrays are read


def bind_op_params(spec: LayerSpec) -> None:
    """Validate a filter layer's parameters with its op (arrays already read in)."""
    from ..layers.filters import bind_filter

    try:
        spec.op_params = bind_filter(spec.op, spec.op_params)[1]
    except MatshopError as exc:
        raise FormatProblem(f"{spec.where}: {exc.problem}") from None
    except (TypeError, ValueError) as exc:
        raise FormatProblem(f"{spec.where}: bad filter parameters ({exc})") from None
