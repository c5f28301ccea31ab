"""The ``.matshop`` container: a zip of ``manifest.json`` and raw float32 members.

Writing goes through :func:`matshop.io.atomic.atomic_target` (temp file
beside the target, fsync, rename), so the previous file survives any failure,
a full disk or a killed process. Members are deflated at level 1: on imported
8-bit textures stored as float32 it shrinks the data ~6x at several hundred
MB/s (byte shuffling, tried, compressed worse). Entries carry a fixed date,
so the same document always gives the same bytes.

Reading checks, before building anything: that the file is a zip with sane
member names (no absolute paths, no ``..``, no duplicates, no encryption or
exotic compression), that the manifest is complete and consistent
(:func:`~matshop.io.project_format.parse_manifest`), that every referenced
member exists with exactly the declared size and all of them fit the memory
limit (so a zip bomb is refused before a byte is inflated), and that the
payloads pass their CRC and hold only finite values. The file is opened
read-only and never modified.
"""

from __future__ import annotations

import os
import struct
import zipfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MatshopError, naming
from ..finite import all_finite
from ..layers import Document, Layer
from ..layers.tiles import TileGrid, freeze
from ..memory import require_memory
from .atomic import atomic_target
from .guard import check_input_file
from .project_check import (
    ArraySpec,
    GridSpec,
    LayerSpec,
    ManifestSpec,
    bind_op_params,
    check_version,
    load_manifest_json,
    parse_manifest,
)
from .project_format import (
    ARRAY_DTYPES,
    MANIFEST_NAME,
    MAX_MANIFEST_BYTES,
    TILE_DTYPE,
    FormatProblem,
    Payload,
    dump_manifest,
    encode,
)

#: Default cap on the bytes a project may inflate to (the document's memory).
DEFAULT_MAX_BYTES = 16 << 30
MAX_MEMBERS = 100_000
_FIXED_DATE = (1980, 1, 1, 0, 0, 0)
_COMPRESSLEVEL = 1
#: What zipfile and zlib raise on damaged archives (never a bug of ours)
_ZIP_ERRORS = (
    zipfile.BadZipFile,
    zlib.error,
    EOFError,
    OSError,
    ValueError,
    NotImplementedError,
    RuntimeError,
    struct.error,
    OverflowError,
)


@dataclass
class Project:
    """A loaded project: the document and what the app saved beside it."""

    document: Document
    #: free-form JSON the app stored (view, active layer, brush, ...)
    settings: dict[str, Any] = field(default_factory=dict)
    format_version: int = 1
    #: the matshop version that wrote the file
    app_version: str = ""
    path: Path | None = None


# ----------------------------------------------------------------- writing


def write_project(
    document: Document, path: str | os.PathLike[str], settings: dict[str, Any] | None
) -> None:
    """Write ``document`` to ``path`` atomically (the old file survives any failure)."""
    try:
        manifest, payloads = encode(document, settings)
        text = dump_manifest(manifest)
        _check_loadable(manifest, text, payloads)
    except FormatProblem as exc:  # before the temp file exists: nothing to clean up
        raise MatshopError(f"cannot save: {exc}", path) from None
    with atomic_target(path) as tmp:
        with zipfile.ZipFile(tmp, "w", allowZip64=True) as archive:
            archive.writestr(_entry(MANIFEST_NAME, len(text)), text)
            for payload in payloads:
                _write_payload(archive, payload)


def _check_loadable(manifest: dict, text: bytes, payloads: list[Payload]) -> None:
    """Refuse to save what :func:`read_project` would refuse to load: the same checks
    (names, ids, counts, sizes) run on the manifest before a byte is written."""
    if len(text) > MAX_MANIFEST_BYTES:
        raise FormatProblem(f"{MANIFEST_NAME} would be {len(text)} bytes, over the limit")
    parse_manifest(manifest)
    total = sum(payload.nbytes for payload in payloads)
    if total > DEFAULT_MAX_BYTES:
        raise FormatProblem(
            f"its layers take {total / 2**30:.1f} GiB, more than a project may load "
            f"({DEFAULT_MAX_BYTES / 2**30:.1f} GiB)"
        )


def _entry(name: str, size: int) -> zipfile.ZipInfo:
    info = zipfile.ZipInfo(name, date_time=_FIXED_DATE)
    info.compress_type = zipfile.ZIP_DEFLATED
    info._compresslevel = _COMPRESSLEVEL  # type: ignore[attr-defined]  # no public setter
    info.external_attr = 0o644 << 16
    info.file_size = size  # lets zipfile choose zip64 up front for > 2 GiB members
    return info


def _write_payload(archive: zipfile.ZipFile, payload: Payload) -> None:
    """Stream one member tile by tile (no whole-grid buffer)."""
    with archive.open(_entry(payload.member, payload.nbytes), "w") as out:
        for chunk in payload.chunks():
            out.write(chunk)


# ----------------------------------------------------------------- reading


def read_project(path: str | os.PathLike[str], max_bytes: int = DEFAULT_MAX_BYTES) -> Project:
    """Load and check a project; every problem is a :class:`MatshopError` naming ``path``."""
    target = Path(path)
    try:
        with _open_archive(target) as archive:
            spec = _read_manifest(archive)
            infos = _check_members(archive, spec, max_bytes)
            arrays = {s.member: _read_member(archive, infos[s.member], s) for s in spec.members()}
            for layer in spec.layers:
                if layer.kind == "filter":
                    layer.op_params = {
                        k: arrays[v.member] if isinstance(v, ArraySpec) else v
                        for k, v in layer.op_params.items()
                    }
                    bind_op_params(layer)
    except FormatProblem as exc:
        problem = str(exc) if exc.standalone else f"damaged or invalid project: {exc}"
        raise MatshopError(problem, target) from None
    except MemoryError:
        raise MatshopError("not enough memory to load this project", target) from None
    document = _build(spec, arrays, target)
    return Project(document, spec.settings, spec.format_version, spec.app_version, target)


def _open_archive(path: Path) -> zipfile.ZipFile:
    check_input_file(path, "project file")  # a FIFO or a device would block or never end
    try:
        archive = zipfile.ZipFile(path, "r")
    except zipfile.BadZipFile:
        problem = "not a matshop project (not a zip archive, or truncated)"
        raise MatshopError(problem, path) from None
    except PermissionError:
        raise MatshopError("cannot read: permission denied", path) from None
    except _ZIP_ERRORS as exc:
        raise MatshopError(f"not a matshop project (unreadable zip: {exc})", path) from None
    try:
        _check_names(archive)
    except BaseException:
        archive.close()
        raise
    return archive


def _check_names(archive: zipfile.ZipFile) -> None:
    infos = archive.infolist()
    if len(infos) > MAX_MEMBERS:
        raise FormatProblem(f"{len(infos)} members, more than {MAX_MEMBERS}")
    names = [info.filename for info in infos]
    for name in names:
        parts = name.replace("\\", "/").split("/")
        if (
            name.startswith(("/", "\\"))
            or "\\" in name
            or "\x00" in name
            or (len(name) > 1 and name[1] == ":")
            or ".." in parts
        ):
            raise FormatProblem(f"member {name[:80]!r} points outside the container")
    if len(set(names)) != len(names):
        raise FormatProblem("the archive holds two members with the same name")


def _usable(info: zipfile.ZipInfo) -> None:
    if info.flag_bits & 0x1:
        raise FormatProblem(f"member {info.filename} is encrypted")
    if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
        raise FormatProblem(f"member {info.filename} uses an unsupported compression")


def _read_manifest(archive: zipfile.ZipFile) -> ManifestSpec:
    try:
        info = archive.getinfo(MANIFEST_NAME)
    except KeyError:
        problem = f"not a matshop project (no {MANIFEST_NAME} inside)"
        raise FormatProblem(problem, standalone=True) from None
    _usable(info)
    if info.file_size > MAX_MANIFEST_BYTES:
        raise FormatProblem(f"{MANIFEST_NAME} is {info.file_size} bytes, over the limit")
    manifest = load_manifest_json(_read_bytes(archive, info))
    check_version(manifest)  # a newer format says so, whatever else it changed
    return parse_manifest(manifest)


def _read_bytes(archive: zipfile.ZipFile, info: zipfile.ZipInfo) -> bytes:
    return _read_array(archive, info).tobytes()


#: bytes decompressed at a time: zipfile joins what one read inflates into one
#: bytes object holding the GIL, so a whole 2K layer (64 MB) read at once held it
#: ~140 ms, a stall of the editor's event loop while a project reopens
_READ_CHUNK = 4 << 20


def _read_array(archive: zipfile.ZipFile, info: zipfile.ZipInfo) -> np.ndarray:
    """A member's bytes as a uint8 array, read a chunk at a time."""
    out = np.empty(info.file_size, dtype=np.uint8)
    filled = 0
    try:
        with archive.open(info) as member:
            while True:
                # one byte more than is left: a longer member shows itself
                chunk = member.read(min(_READ_CHUNK, info.file_size - filled + 1))
                if not chunk or filled + len(chunk) > info.file_size:
                    filled += len(chunk)
                    break
                out[filled : filled + len(chunk)] = np.frombuffer(chunk, dtype=np.uint8)
                filled += len(chunk)
    except _ZIP_ERRORS as exc:
        raise FormatProblem(f"member {info.filename} is damaged or truncated ({exc})") from None
    if filled != info.file_size:
        raise FormatProblem(f"member {info.filename} is damaged or truncated (wrong length)")
    return out


def _check_members(
    archive: zipfile.ZipFile, spec: ManifestSpec, max_bytes: int
) -> dict[str, zipfile.ZipInfo]:
    refs = spec.members()
    total = sum(ref.nbytes for ref in refs)
    if total > max_bytes:
        raise FormatProblem(
            f"it would take {total / 2**30:.1f} GiB of memory, more than the limit of "
            f"{max_bytes / 2**30:.1f} GiB"
        )
    try:  # each member is read whole, then copied into tiles: about twice its size
        require_memory(2 * total, "loading its layers")
    except MatshopError as exc:
        raise FormatProblem(exc.problem, standalone=True) from None
    infos: dict[str, zipfile.ZipInfo] = {}
    for ref in refs:
        try:
            info = archive.getinfo(ref.member)
        except KeyError:
            raise FormatProblem(f"{ref.what}: member {ref.member} is missing") from None
        _usable(info)
        # the exact size: inflating can never produce more than the manifest declares
        if info.file_size != ref.nbytes:
            raise FormatProblem(
                f"{ref.what}: member {ref.member} holds {info.file_size} bytes, "
                f"its declared shape needs {ref.nbytes}"
            )
        infos[ref.member] = info
    return infos


def _read_member(
    archive: zipfile.ZipFile, info: zipfile.ZipInfo, ref: GridSpec | ArraySpec
) -> np.ndarray:
    """A member's values, checked: float32 tiles/arrays finite, booleans 0 or 1."""
    data = _read_array(archive, info)
    dtype = TILE_DTYPE if isinstance(ref, GridSpec) else ref.dtype
    if dtype == "|b1":
        if data.size and data.max() > 1:
            raise FormatProblem(f"{ref.what} holds values other than true and false")
        return data.view(bool).reshape(ref.shape)  # type: ignore[union-attr]
    values = data.view(dtype)
    assert values.itemsize == ARRAY_DTYPES[dtype]
    if not all_finite(values):
        raise FormatProblem(f"{ref.what} holds NaN or infinite values")
    if isinstance(ref, ArraySpec):
        return values.reshape(ref.shape).astype(np.dtype(dtype).newbyteorder("="), copy=False)
    return values


# ----------------------------------------------------------------- building


def _grid(doc: Document, ref: GridSpec, flat: np.ndarray) -> TileGrid:
    grid = TileGrid(doc.layout, ref.channels, ref.fill)
    tiles: dict = {}
    offset = 0
    for key in ref.keys:
        rect = doc.layout.tile_rect(key)
        count = rect.height * rect.width * ref.channels
        block = flat[offset : offset + count].reshape(rect.height, rect.width, ref.channels)
        # a copy per tile: tiles are replaced one by one later, and a view
        # would keep the whole member alive for as long as any tile of it
        tiles[key] = freeze(block.astype(np.float32))
        offset += count
    grid.replace(tiles)
    return grid


def _layer(doc: Document, spec: LayerSpec, arrays: dict[str, np.ndarray]) -> Layer:
    props = dict(spec.props)
    name = props.pop("name")
    if spec.kind == "paint":
        assert spec.pixels is not None
        props["pixels"] = _grid(doc, spec.pixels, arrays[spec.pixels.member])
    elif spec.kind == "fill" and spec.source is not None:
        source = arrays[spec.source.member].reshape(spec.source.shape)
        props["source"] = source.astype(np.float32, copy=False)
    elif spec.kind == "fill":
        props["value"] = spec.value
    elif spec.kind == "filter":
        props.update(op=spec.op, op_params=spec.op_params)
    if spec.mask is not None:
        props["mask"] = _grid(doc, spec.mask, arrays[spec.mask.member])
    layer = doc.new_layer(spec.kind, name, **props)
    if spec.kind == "fill" and spec.source is not None and spec.value is not None:
        layer.put("value", layer.validate("value", spec.value, doc.schema))  # kept beside it
    layer.id = spec.id
    return layer


def _build(spec: ManifestSpec, arrays: dict[str, np.ndarray], path: Path) -> Document:
    doc = Document(
        spec.schema,
        spec.layout.height,
        spec.layout.width,
        tile_size=spec.layout.tile_size,
        background=spec.background,
        name=spec.name,
        sources=spec.sources,
    )
    # checked above; this catches a layer rule the checks do not mirror
    with naming(path, what="damaged or invalid project"):
        layers = [_layer(doc, layer, arrays) for layer in spec.layers]
    for layer in layers:
        doc.insert_layer(layer)  # new layers made later get ids above the loaded ones
    return doc
