"""Texture sets on disk <-> :class:`~matshop.material.Material`.

Loading detects the set by file names (:mod:`matshop.io.textureset`), reads
each map through OpenImageIO (:mod:`matshop.io.images`), unpacks packed maps
(ORM, Unity mask maps), inverts gloss into roughness, decodes normal maps and
checks that every map has the same size. Saving writes one file per
parameter, named so that loading finds it again, into a staging folder that
is renamed into place only when every file has been written.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable
from contextlib import closing
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import MatshopError
from ..jit_setup import start_in_background
from ..material import PARAMETER_KINDS, Material, ProgressCallback, Schema
from ..spaces.frame import decode_normal_map, encode_normal_map, height_to_normal
from .fileset import PendingFile, write_all
from .images import ImageInfo, read_image, write_image
from .mtlx_material import MTLX_SUFFIX, read_mtlx_material
from .normal_convention import (
    CONVENTION_ATTRIBUTE,
    CONVENTION_TOKENS,
    DEFAULT_CONVENTION,
    decide_convention,
)
from .overlap import in_order
from .safe_names import safe_stem
from .textureset import PACKED_CHANNELS, TextureSet, check_texture_set, resolve_texture_set
from .usd_material import is_usd, read_usd_material

#: slots read as one parameter of the same name: RGB colors, first channels, wide maps
_COLOR_SLOTS, _SCALAR_SLOTS, _WIDE_SLOTS = (
    {name: name for name, kind in PARAMETER_KINDS.items() if kind.imported_as == how}
    for how in ("color", "scalar", "wide")
)
#: what a packed channel's meaning (textureset.PACKED_CHANNELS) feeds: (parameter, inverted)
_PACKED_MEANINGS: dict[str, tuple[str, bool]] = {
    "ao": ("ao", False),
    "roughness": ("roughness", False),
    "metallic": ("metallic", False),
    "smoothness": ("roughness", True),
}
#: parameter -> the tag of the file it is saved to
_SAVE_TAGS = {name: kind.file_tag for name, kind in PARAMETER_KINDS.items() if kind.file_tag}


@dataclass
class LoadReport:
    """What loading decided, for ``matshop info`` and the UI."""

    texture_set: TextureSet
    infos: dict[str, ImageInfo] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def _first_channel(array: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(array[..., :1])


def _as_rgb(array: np.ndarray, path: Path) -> np.ndarray:
    channels = array.shape[2]
    if channels in (1, 2):  # gray or gray+alpha: gray becomes RGB
        return np.repeat(array[..., :1], 3, axis=2)
    if channels >= 3:
        return np.ascontiguousarray(array[..., :3])
    raise MatshopError(f"expected a color image, got {channels} channels", path)


def _read_all(
    ts: TextureSet, max_pixels: int | None, progress: ProgressCallback | None = None
) -> tuple[dict, dict]:
    """Every map file of ``ts``; ``progress(files read, files)`` before the first and after
    each (a callback that raises stops the reading between files). Several files are
    read at once (:func:`~matshop.io.overlap.in_order`), their results taken in order."""
    arrays: dict[str, np.ndarray] = {}
    infos: dict[str, ImageInfo] = {}
    size: tuple[int, int] | None = None
    size_from: Path | None = None
    total = len(ts.maps)
    if progress is not None:
        progress(0, total)
    kwargs = {} if max_pixels is None else {"max_pixels": max_pixels}
    reads = [functools.partial(_read, path, kwargs) for path in ts.maps.values()]
    with closing(in_order(reads)) as results:
        files = zip(ts.maps.items(), results, strict=True)
        for done, ((slot, path), (array, info)) in enumerate(files, 1):
            if size is None:
                size, size_from = array.shape[:2], path
            elif array.shape[:2] != size:
                raise MatshopError(
                    f"size {array.shape[1]}x{array.shape[0]} differs from "
                    f"{size_from.name if size_from else '?'} ({size[1]}x{size[0]}); "
                    "all maps of a texture set must have the same resolution",
                    path,
                )
            arrays[slot], infos[slot] = array, info
            if progress is not None:
                progress(done, total)
    return arrays, infos


def _read(path: Path, kwargs: dict) -> tuple[np.ndarray, ImageInfo]:
    return read_image(path, **kwargs)  # the module's name, looked up per call (a test seam)


def load_material(
    path: str | os.PathLike | TextureSet,
    *,
    spaces: dict[str, str] | None = None,
    normal_convention: str | None = None,
    max_pixels: int | None = None,
    material: str | None = None,
    maps: dict[str, str | os.PathLike | None] | None = None,
    progress: ProgressCallback | None = None,
) -> tuple[Material, LoadReport]:
    """Load the texture set at ``path`` (a folder or one of its files).

    Parameters
    ----------
    path : folder or file of the set, or a :class:`TextureSet` (e.g. detected,
        then corrected by the user with :func:`~matshop.io.textureset.with_slot`).
    spaces : optional editing-space override per parameter (``{"roughness": "ggx_alpha"}``).
    normal_convention : ``"opengl"`` or ``"directx"``; default: the file-name hint
        (``_NormalGL``, ``_nor_dx``), else a confident guess from the normal map,
        else OpenGL (:func:`~matshop.io.normal_convention.decide_convention`).
    max_pixels : refuse images larger than this many texels.
    material : which material of a folder holding several (as detection lists them).
    maps : explicit files per slot, added or overriding detection (None: leave empty).
    progress : called with (map files read, map files) before the first file and after
        each; an exception it raises (a cancel) stops the loading between files.

    Raises
    ------
    MatshopError : one line naming the file and the problem.
    """
    if isinstance(path, TextureSet):
        ts = path
    elif is_usd(path) or Path(path).suffix.lower() == MTLX_SUFFIX:
        return _load_document(Path(path), spaces, max_pixels)
    else:
        ts = resolve_texture_set(path, material=material, maps=maps)
    check_texture_set(ts)
    start_in_background()  # numba's set-up while the files are read
    arrays, infos = _read_all(ts, max_pixels, progress)
    report = LoadReport(ts, infos, notes=list(ts.notes))
    maps: dict[str, np.ndarray] = {}
    sources: dict[str, dict] = {}

    def take(param: str, array: np.ndarray, slot: str, **extra: object) -> None:
        maps[param] = array.astype(np.float32, copy=False)
        info = infos[slot]
        sources[param] = {
            "file": str(ts.maps[slot]),
            "slot": slot,
            "bit_depth": info.bit_depth,
            **extra,
        }

    for slot, param in _COLOR_SLOTS.items():
        if slot in arrays:
            take(param, _as_rgb(arrays[slot], ts.maps[slot]), slot)
            has_alpha = arrays[slot].shape[2] in (2, 4)
            if slot == "base_color" and has_alpha and "opacity" not in ts.maps:
                take("opacity", np.ascontiguousarray(arrays[slot][..., -1:]), slot)
    for slot, param in _SCALAR_SLOTS.items():
        if slot in arrays:
            take(param, _first_channel(arrays[slot]), slot)
    if "gloss" in arrays and "roughness" not in maps:
        take("roughness", 1.0 - _first_channel(arrays["gloss"]), "gloss", inverted="gloss")
        report.notes.append(f"{ts.maps['gloss'].name}: gloss inverted into roughness")
    for slot, layout in PACKED_CHANNELS.items():
        if slot not in arrays:
            continue
        array = arrays[slot]
        for channel, meaning in enumerate(layout):
            if meaning not in _PACKED_MEANINGS:
                continue  # unused or not a material parameter (HDRP detail mask)
            param, invert = _PACKED_MEANINGS[meaning]
            if param in maps:
                continue  # a dedicated map wins over a packed one
            if channel >= array.shape[2]:
                raise MatshopError(
                    f"packed {slot} map needs channel {'RGBA'[channel]} for {meaning},"
                    f" the file has {array.shape[2]} channel(s)",
                    ts.maps[slot],
                )
            values = array[..., channel : channel + 1]
            take(param, 1.0 - values if invert else values, slot, packed=slot, channel=channel)
    for slot, param in _WIDE_SLOTS.items():
        if slot in arrays:
            take(param, arrays[slot], slot)

    _load_frame(ts, arrays, infos, maps, sources, report, normal_convention or ts.normal_convention)

    names = [n for n in PARAMETER_KINDS if n in maps]
    spaces = dict(spaces or {})
    if "normal" in maps and maps["normal"].shape[2] == 6:
        spaces.setdefault("normal", "normal_tangent")
    schema = Schema.from_names(names, spaces)
    for param in schema.parameters:
        got = maps[param.name].shape[2]
        if got != param.phys_channels:
            raise MatshopError(
                f"{param.name} map has {got} channel(s), the {param.space.name} space needs "
                f"{param.phys_channels}",
                sources[param.name]["file"],
            )
    return Material(ts.name, schema, maps, sources), report


def _load_document(
    path: Path, spaces: dict[str, str] | None, max_pixels: int | None
) -> tuple[Material, LoadReport]:
    """The material a USD file's UsdPreviewSurface (:mod:`.usd_material`) or a MaterialX
    document's surface shader (:mod:`.mtlx_material`) reads."""
    if is_usd(path):
        material = read_usd_material(path, spaces=spaces, max_pixels=max_pixels)
        note = f"read from {path.name}'s UsdPreviewSurface"
    else:
        material = read_mtlx_material(path, spaces=spaces, max_pixels=max_pixels)
        note = f"read from {path.name}'s MaterialX graph"
    files = {name: Path(source["file"]) for name, source in material.sources.items()}
    ts = TextureSet(material.name, path.parent, files)
    return material, LoadReport(ts, notes=[note])


def _load_frame(
    ts: TextureSet,
    arrays: dict[str, np.ndarray],
    infos: dict[str, ImageInfo],
    maps: dict[str, np.ndarray],
    sources: dict[str, dict],
    report: LoadReport,
    normal_convention: str | None,
) -> None:
    if "normal" in arrays:
        path = ts.maps["normal"]
        rgb = arrays["normal"]
        if rgb.shape[2] < 3:
            raise MatshopError(
                f"a normal map needs 3 channels (RGB), this file has {rgb.shape[2]}; "
                "if it is a height or bump map, name it *_height or *_bump",
                path,
            )
        convention, how, note = decide_convention(
            rgb[..., :3],
            given=normal_convention,
            from_name=ts.hints.get("normal", {}).get("convention"),
            from_metadata=infos["normal"].attributes.get(CONVENTION_ATTRIBUTE),
        )
        if note is not None:
            report.notes.append(f"{path.name}: {note}")
        # the file's pixels are not read again: decoded over themselves
        normal = decode_normal_map(rgb[..., :3], convention=convention, in_place=True)
        if "tangent" in arrays:
            tangent = decode_normal_map(arrays["tangent"][..., :3], convention=convention)
            normal = np.concatenate([normal, tangent], axis=2)
        maps["normal"] = normal
        sources["normal"] = {
            "file": str(path),
            "slot": "normal",
            "bit_depth": infos["normal"].bit_depth,
            "convention": convention,
            "convention_source": how,
            **({"convention_note": note} if note else {}),
        }
    elif "bump" in arrays:
        maps["normal"] = height_to_normal(_first_channel(arrays["bump"]), wrap=True)
        sources["normal"] = {
            "file": str(ts.maps["bump"]),
            "slot": "bump",
            "bit_depth": infos["bump"].bit_depth,
            "convention": "opengl",
            "convention_source": "derived from bump map",
        }
        report.notes.append(f"{ts.maps['bump'].name}: bump map converted to normals")


def _bit_depth_for(material: Material, name: str) -> str:
    """Keep the source's precision: 16-bit stays 16-bit, float stays float."""
    source_depth = material.sources.get(name, {}).get("bit_depth", "uint8")
    return source_depth if source_depth in ("uint8", "uint16", "half", "float") else "uint8"


def _file_plan(
    material: Material,
) -> list[tuple[str, np.ndarray | Callable[[], np.ndarray], str, dict]]:
    """(file name, its array or how to make it, bit depth, attributes) for every file a
    material saves to; normal maps are encoded when written, on the writing thread."""
    plan = []
    for param in material.schema.parameters:
        name = param.name
        array = material.maps[name]
        tag = _SAVE_TAGS.get(name)
        if tag is None:
            raise MatshopError(f"saving parameter {name!r} to files is not supported yet")
        depth = _bit_depth_for(material, name)
        attrs = {"matshop:space": param.space.name}
        if name == "normal":
            convention = material.sources.get(name, {}).get("convention", DEFAULT_CONVENTION)
            attrs = {**attrs, CONVENTION_ATTRIBUTE: convention}
            encode = functools.partial(encode_normal_map, convention=convention)
            plan.append(
                (
                    f"{tag}_{CONVENTION_TOKENS[convention]}.png",  # read back without a guess
                    functools.partial(encode, array[..., :3]),
                    depth if depth in ("uint8", "uint16") else "uint16",
                    attrs,
                )
            )
            if array.shape[2] == 6:
                tangent = functools.partial(encode, array[..., 3:])
                plan.append(("tangent.png", tangent, "uint16", attrs))
            continue
        if name in _WIDE_SLOTS:
            plan.append((f"{tag}.exr", array, "half" if depth == "half" else "float", attrs))
            continue
        ext = "exr" if depth in ("half", "float") else "png"
        plan.append((f"{tag}.{ext}", array, depth, attrs))
    return plan


def save_material(
    material: Material,
    out_dir: str | os.PathLike,
    *,
    overwrite: bool = False,
    progress: ProgressCallback | None = None,
    png_level: int | None = None,
) -> list[Path]:
    """Write ``material`` as ``<out_dir>/<name>_<tag>.<ext>`` files; return their paths.

    All or nothing (:func:`matshop.io.fileset.write_all`): a failure leaves
    no partial set behind and never loses an existing file. Existing files
    are replaced only with ``overwrite``. ``png_level``: zlib level of the PNGs
    (default :data:`~matshop.io.images.PNG_LEVEL`).
    """
    files = [
        PendingFile(
            f"{safe_stem(material.name)}_{suffix}",
            functools.partial(
                _write_map, array=array, depth=depth, attrs=attrs, png_level=png_level
            ),
        )
        for suffix, array, depth, attrs in _file_plan(material)
    ]
    return write_all(out_dir, files, force=overwrite, progress=progress)


def _write_map(
    path: Path,
    *,
    array: np.ndarray | Callable[[], np.ndarray],
    depth: str,
    attrs: dict,
    png_level: int | None,
) -> None:
    pixels = array() if callable(array) else array
    write_image(path, pixels, bit_depth=depth, attributes=attrs, png_level=png_level)
