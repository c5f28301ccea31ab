"""Texture-set detection by file name.

A stem such as ``Bricks076C_2K-PNG_NormalGL`` or ``rock_wall_nor_gl_2k`` is
split on ``_ . - #``, spaces and camel case into lowercase tokens (pure digits
dropped, resolution-like tokens such as ``2k`` kept whole). Trailing noise
(resolution, version, LOD, format words, a ``map`` filler, ``gl``/``dx``
normal-convention hints) is skipped, then the longest tag from :data:`SLOTS`
(up to three tokens, compared glued together) must end the name; what comes
before it is the material name. Matching only at the end keeps material names
like ``metal_plate`` or ``spec_ops_crate`` from claiming slots.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import NamedTuple

from matshop.errors import MatshopError


class SlotSpec(NamedTuple):
    tags: tuple[str, ...]  #: multi-token tags are written with spaces
    description: str


#: slot -> tags and meaning (Blender Node Wrangler's tags plus ours).
SLOTS: dict[str, SlotSpec] = {
    "base_color": SlotSpec(
        (
            "diffuse",
            "diff",
            "albedo",
            "base",
            "col",
            "color",
            "basecolor",
            "base color",
            "albedo transparency",
        ),
        "base color / albedo, sRGB color (alpha may hold opacity)",
    ),
    "metallic": SlotSpec(("metallic", "metalness", "metal", "mtl"), "metalness, linear"),
    "specular": SlotSpec(("specularity", "specular", "spec", "spc"), "specular level or color"),
    "normal": SlotSpec(("normal", "nor", "nrm", "nrml", "norm"), "tangent-space normal map"),
    "bump": SlotSpec(("bump", "bmp"), "bump (height for shading only), linear"),
    "roughness": SlotSpec(("roughness", "rough", "rgh"), "perceptual roughness, linear"),
    "gloss": SlotSpec(
        ("gloss", "glossy", "glossiness", "smoothness"), "glossiness = 1 - roughness, linear"
    ),
    "height": SlotSpec(
        ("displacement", "displace", "disp", "dsp", "height", "heightmap"),
        "height / displacement, linear",
    ),
    "transmission": SlotSpec(("transmission", "transparency"), "transmission weight, linear"),
    "emissive": SlotSpec(("emission", "emissive", "emit"), "emitted color, sRGB color"),
    "opacity": SlotSpec(("alpha", "opacity"), "opacity (1 = opaque), linear"),
    "ao": SlotSpec(("ao", "ambient", "occlusion", "ambient occlusion"), "ambient occlusion"),
    "tangent": SlotSpec(("tangent", "tan"), "tangent / anisotropy direction map"),
    "orm": SlotSpec(
        ("orm", "arm", "occlusion roughness metallic"),
        "packed R occlusion, G roughness, B metallic (Unreal, Godot, Poly Haven arm)",
    ),
    "metallic_roughness": SlotSpec(
        ("metallic roughness",), "glTF metallicRoughness: G roughness, B metallic"
    ),
    "metallic_smoothness": SlotSpec(
        ("metallic smoothness",), "Unity metallic map: R metallic, A smoothness"
    ),
    "mask": SlotSpec(
        ("mask", "maskmap"), "Unity HDRP mask map: R metallic, G occlusion, B detail, A smoothness"
    ),
    "distribution": SlotSpec(("distribution", "ndf"), "matshop multi-channel EXR: microfacet NDF"),
    "profile": SlotSpec(("profile", "sss"), "matshop multi-channel EXR: subsurface profile"),
}

#: What each packed slot holds per channel (None: unused).
PACKED_CHANNELS: dict[str, tuple[str | None, ...]] = {
    "orm": ("ao", "roughness", "metallic"),
    "metallic_roughness": (None, "roughness", "metallic"),
    "metallic_smoothness": ("metallic", None, None, "smoothness"),
    "mask": ("metallic", "ao", "detail", "smoothness"),
}

IMAGE_EXTENSIONS = frozenset(
    ".png .jpg .jpeg .jpe .tif .tiff .exr .tga .hdr .bmp .webp .psd .dds .tx .jxl .jp2".split()
)

_CONVENTIONS = {"gl": "opengl", "ogl": "opengl", "opengl": "opengl"}
_CONVENTIONS |= {"dx": "directx", "directx": "directx"}
_FILLERS = frozenset({"map", "tex", "texture"})
_FORMAT_WORDS = frozenset("png jpg jpeg exr tif tiff tga hdr".split())  # not "bmp": a bump tag
_VARIANT_PART = re.compile(r"\d+k|\d+x\d+|v\d+|lod\d+|\d+bits?|udim", re.IGNORECASE)
_RESOLUTION = re.compile(r"\d+k|\d+x\d+")  # variants that tell sets apart (2k vs 4k)
_PROTECT = re.compile(r"opengl|directx", re.IGNORECASE)  # keep whole through camel split
_PART = re.compile(r"[^_.\-#\s]+")
_WORD = re.compile(r"[A-Z]+(?![a-z])|[A-Z]?[a-z]+|\d+|[^A-Za-z\d]+")
_MAX_TAG_TOKENS = 3


def _tag_table() -> dict[str, tuple[str, str | None]]:
    """Glued tag -> (slot, normal convention); also accepts ``<tag>map``, ``<normal>gl``."""
    table: dict[str, tuple[str, str | None]] = {}
    for slot, spec in SLOTS.items():
        for tag in spec.tags:
            glued = tag.replace(" ", "")
            table.setdefault(glued, (slot, None))
            table.setdefault(glued + "map", (slot, None))
            if slot == "normal":
                for word, convention in _CONVENTIONS.items():
                    table.setdefault(glued + word, (slot, convention))
    return table


_TAGS = _tag_table()


class _Token(NamedTuple):
    text: str  # lowercase
    start: int
    kind: str  # "word", "variant" (resolution, format...), "filler", "hint"


@dataclass(frozen=True)
class MapName:
    """What a file name says: which slot, whose material, which variant."""

    slot: str
    material: str  #: display name, e.g. "Bricks076C" for "Bricks076C_2K-PNG_Color"
    group: str  #: files of one set share this key (prefix + resolution)
    prefix: str  #: the name before the tag, as written
    convention: str | None = None  #: normal maps: "opengl" / "directx" from the name


@dataclass
class TextureSet:
    """The maps of one material found beside each other."""

    name: str  #: material name (the common prefix, else the folder's name)
    folder: Path
    maps: dict[str, Path]  #: slot -> file
    #: per-slot hints from file names, e.g. ``{"normal": {"convention": "opengl"}}``
    hints: dict[str, dict[str, str]] = field(default_factory=dict)
    #: image files beside the set whose names match no slot
    unrecognised: list[Path] = field(default_factory=list)
    #: recognised but not used, per slot (a DirectX normal when an OpenGL one exists)
    alternates: dict[str, list[Path]] = field(default_factory=dict)


def known_slots() -> list[str]:
    """Every slot a texture set may fill: single maps, then packed ones."""
    return [*SLOTS, *PACKED_CHANNELS]


def with_slot(ts: TextureSet, slot: str, file: str | os.PathLike[str] | None) -> TextureSet:
    """A copy of ``ts`` with ``slot`` read from ``file`` (None: the slot is left empty).

    For a user correcting what detection found. The file leaves any other
    slot, the unrecognised list and the alternates, so it is read once.
    """
    if slot not in known_slots():
        raise MatshopError(f"unknown map slot {slot!r} (known: {', '.join(known_slots())})")
    maps = {k: v for k, v in ts.maps.items() if k != slot}
    hints = {k: v for k, v in ts.hints.items() if k != slot}
    unrecognised = list(ts.unrecognised)
    alternates = {k: list(v) for k, v in ts.alternates.items()}
    if file is not None:
        path = Path(file)
        maps = {k: v for k, v in maps.items() if v != path}
        unrecognised = [f for f in unrecognised if f != path]
        alternates = {k: [f for f in v if f != path] for k, v in alternates.items()}
        maps[slot] = path
    return replace(
        ts,
        maps=maps,
        hints=hints,
        unrecognised=unrecognised,
        alternates={k: v for k, v in alternates.items() if v},
    )


def check_texture_set(ts: TextureSet) -> None:
    """Refuse a (user-edited) set that cannot be loaded: one line naming the problem."""
    if not ts.maps:
        raise MatshopError("the texture set has no maps", ts.folder)
    unknown = [slot for slot in ts.maps if slot not in known_slots()]
    if unknown:
        raise MatshopError(f"unknown map slot {unknown[0]!r}", ts.folder)
    seen: dict[Path, str] = {}
    for slot, path in ts.maps.items():
        if path in seen:
            raise MatshopError(f"used for both {seen[path]} and {slot}", path)
        seen[path] = slot
        if not path.is_file():
            raise MatshopError("file not found", path)


def _tokens(stem: str) -> list[_Token]:
    stem = _PROTECT.sub(lambda m: m.group().capitalize(), stem)  # same length
    tokens = []
    for part in _PART.finditer(stem):
        if _VARIANT_PART.fullmatch(part.group()):
            tokens.append(_Token(part.group().lower(), part.start(), "variant"))
            continue
        for word in _WORD.finditer(part.group()):
            text = word.group().lower()
            if text.isdigit() or not any(ch.isalnum() for ch in text):
                continue  # numbers, "(1)" of duplicate downloads
            kind = "word"
            if text in _CONVENTIONS:
                kind = "hint"
            elif text in _FILLERS:
                kind = "filler"
            elif text in _FORMAT_WORDS:
                kind = "variant"
            tokens.append(_Token(text, part.start() + word.start(), kind))
    return tokens


def parse_map_name(name: str | os.PathLike[str]) -> MapName | None:
    """Classify one file name (extension ignored); None when no tag ends it."""
    stem = Path(name).stem
    tokens = _tokens(stem)
    end, hint, variants = len(tokens), None, []
    while end and tokens[end - 1].kind != "word":
        end -= 1
        token = tokens[end]
        if token.kind == "hint":
            hint = hint or _CONVENTIONS[token.text]
        elif _RESOLUTION.fullmatch(token.text):
            variants.insert(0, token.text)
    for k in range(min(_MAX_TAG_TOKENS, end), 0, -1):
        if all(t.kind == "word" for t in tokens[end - k : end]):
            found = _TAGS.get("".join(t.text for t in tokens[end - k : end]))
            if found is not None:
                break
    else:
        return None
    slot, convention = found
    convention = (convention or hint) if slot == "normal" else None
    prefix = stem[: tokens[end - k].start].rstrip("_.-# ")
    group = "_".join([_key(prefix), *variants]).strip("_")
    material = prefix
    for token in reversed(_tokens(prefix)):  # "Bricks076C_2K-PNG" -> "Bricks076C"
        if token.kind != "variant":
            break
        material = prefix[: token.start].rstrip("_.-# ")
    return MapName(slot, material, group, prefix, convention)


def detect_texture_set(path: str | os.PathLike[str]) -> TextureSet:
    """Find the texture set in a folder, or the set a given file belongs to.

    Raises MatshopError when nothing is recognised, when a folder holds several
    materials (pass one file to choose), or when two files claim one slot.
    """
    path = Path(path)
    if not path.exists():
        raise MatshopError("not found", path)
    chosen: MapName | None = None
    if path.is_dir():
        folder = path
    else:
        if path.suffix.lower() not in IMAGE_EXTENSIONS:
            raise MatshopError("not an image file", path)
        folder = path.parent
        chosen = parse_map_name(path)
        if chosen is None:
            raise MatshopError(f"file name names no texture map; {_EXPECTED}", path)
    try:
        files = sorted(
            f
            for f in folder.iterdir()
            if f.suffix.lower() in IMAGE_EXTENSIONS and not f.name.startswith(".") and f.is_file()
        )
    except OSError as exc:
        raise MatshopError(f"cannot list folder: {exc.strerror or exc}", folder) from exc
    groups: dict[str, list[tuple[Path, MapName]]] = {}
    unrecognised = []
    parsed_files = [(f, parse_map_name(f)) for f in files]
    # A file named just like a material ("rusty_metal_02.png" beside
    # "rusty_metal_02_diff_2k.png") is a preview, not a map ending in "metal".
    prefixes = {_key(parsed.prefix) for _, parsed in parsed_files if parsed is not None}
    for f, parsed in parsed_files:
        if parsed is None or _key(f.stem) in prefixes:
            unrecognised.append(f)
        else:
            groups.setdefault(parsed.group, []).append((f, parsed))
    if chosen is None:
        if not groups:
            raise MatshopError(
                f"no texture maps recognised in {len(files)} image files; {_EXPECTED}", folder
            )
        if len(groups) > 1:
            names = ", ".join(sorted(_label(members) for members in groups.values()))
            raise MatshopError(
                f"several materials in one folder ({names}); pass one file of the set to choose",
                folder,
            )
        chosen = next(iter(groups.values()))[0][1]
    else:
        if path.name not in {f.name for f, _ in groups.get(chosen.group, [])}:
            raise MatshopError(f"file name names no texture map; {_EXPECTED}", path)
        prefix = chosen.material.lower()
        unrecognised = [f for f in unrecognised if f.name.lower().startswith(prefix)]
    name = chosen.material or folder.name
    return _assign(name, folder, groups[chosen.group], unrecognised)


def _key(name: str) -> str:
    return "_".join(_PART.findall(name.lower()))


_EXPECTED = (
    "expected names like <material>_basecolor.png, <material>_normal.png, <material>_roughness.png"
)


def _label(members: list[tuple[Path, MapName]]) -> str:
    first = members[0][0]
    return f"{members[0][1].material or first.stem} ({len(members)} maps, e.g. {first.name})"


def _assign(
    name: str, folder: Path, members: list[tuple[Path, MapName]], unrecognised: list[Path]
) -> TextureSet:
    """One file per slot; OpenGL beats DirectX when both normal flavours exist."""
    by_slot: dict[str, list[tuple[Path, MapName]]] = {}
    for member in members:
        by_slot.setdefault(member[1].slot, []).append(member)
    result = TextureSet(name, folder, {}, unrecognised=unrecognised)
    for slot, claims in by_slot.items():
        conventions = [parsed.convention for _, parsed in claims]
        if len(claims) > 1 and None not in conventions and len(set(conventions)) == len(claims):
            claims = sorted(claims, key=lambda c: c[1].convention != "opengl")
            result.alternates[slot] = [f for f, _ in claims[1:]]
        elif len(claims) > 1:
            names = " and ".join(f.name for f, _ in claims)
            raise MatshopError(f"{names} both claim the {slot} slot; remove or rename one", folder)
        path, parsed = claims[0]
        result.maps[slot] = path
        if parsed.convention:
            result.hints[slot] = {"convention": parsed.convention}
    return result
