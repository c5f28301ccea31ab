"""What a texture file's name says: which map slot, whose material, which variant.

A stem such as ``Bricks076C_2K-PNG_NormalGL`` or ``rock_wall_nor_gl_2k`` is
split on ``_ . - #``, spaces and camel case into lowercase tokens (pure digits
dropped, resolution-like tokens such as ``2k`` kept whole). Trailing noise
(resolution, version, LOD, format words, a ``map`` filler, ``gl``/``dx``
normal-convention hints) is skipped, then the longest tag (up to three tokens,
compared glued together) must end the name; what comes before it is the
material name. Matching only at the end keeps material names like
``metal_plate`` or ``spec_ops_crate`` from claiming slots.

Tags come in two tables: :data:`SLOTS`, the maps a material loads, and
:data:`EXTRAS`, maps libraries ship that matshop recognises but does not
load (generic masks, previews, cavity...). An extra is reported as "not
used", never mistaken for a slot: a bare ``_mask`` is such an extra, only
``MaskMap`` / ``mask_map`` names Unity's packed map.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple


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
    "mask_map": SlotSpec(
        ("mask map", "maskmap"),
        "Unity HDRP mask map: R metallic, G occlusion, B detail, A smoothness",
    ),
    "distribution": SlotSpec(("distribution", "ndf"), "matshop multi-channel EXR: microfacet NDF"),
    "profile": SlotSpec(("profile", "sss"), "matshop multi-channel EXR: subsurface profile"),
}

#: Maps libraries ship that no matshop parameter takes: kind -> tags and meaning.
EXTRAS: dict[str, SlotSpec] = {
    "mask": SlotSpec(("mask", "masks"), "a generic mask"),
    "preview": SlotSpec(
        ("preview", "thumb", "thumbnail", "icon", "render", "swatch"), "a preview image"
    ),
    "cavity": SlotSpec(("cavity",), "a cavity map"),
    "curvature": SlotSpec(("curvature", "curv"), "a curvature map"),
    "translucency": SlotSpec(("translucency", "translucent"), "a translucency map"),
    "thickness": SlotSpec(("thickness",), "a thickness map"),
    "id": SlotSpec(("id", "matid", "material id"), "an ID map"),
    "sheen": SlotSpec(("sheen", "fuzz"), "a sheen map"),
    "scattering": SlotSpec(("scattering", "subsurface"), "a scattering map"),
    "position": SlotSpec(
        ("position", "world normal"), "a baked position or world-space normal map"
    ),
}

#: What each packed slot holds per channel (None: unused).
PACKED_CHANNELS: dict[str, tuple[str | None, ...]] = {
    "orm": ("ao", "roughness", "metallic"),
    "metallic_roughness": (None, "roughness", "metallic"),
    "metallic_smoothness": ("metallic", None, None, "smoothness"),
    "mask_map": ("metallic", "ao", "detail", "smoothness"),
}

#: Packed slots that need at least this many channels to be what their name says.
MIN_PACKED_CHANNELS = {"mask_map": 3}

#: slot -> the material parameters it provides
_PROVIDES: dict[str, frozenset[str]] = {
    "gloss": frozenset({"roughness"}),
    "bump": frozenset({"normal"}),
    "tangent": frozenset({"normal"}),
    **{
        slot: frozenset("roughness" if m == "smoothness" else m for m in layout if m != "detail")
        - {None}
        for slot, layout in PACKED_CHANNELS.items()
    },
}

IMAGE_EXTENSIONS = frozenset(
    ".png .jpg .jpeg .jpe .tif .tiff .exr .tga .hdr .bmp .webp .psd .dds .tx .jxl .jp2".split()
)

CONVENTION_WORDS = {"gl": "opengl", "ogl": "opengl", "opengl": "opengl"}
CONVENTION_WORDS |= {"dx": "directx", "directx": "directx"}
_FILLERS = frozenset({"map", "tex", "texture"})
_FORMAT_WORDS = frozenset("png jpg jpeg exr tif tiff tga hdr".split())  # not "bmp": a bump tag
_VARIANT_PART = re.compile(r"\d+k|\d+x\d+|v\d+|lod\d+|\d+bits?|udim", re.IGNORECASE)
_RESOLUTION = re.compile(r"\d+k|\d+x\d+")  # variants that tell sets apart (2k vs 4k)
_PROTECT = re.compile(r"opengl|directx", re.IGNORECASE)  # keep whole through camel split
_PART = re.compile(r"[^_.\-#\s]+")
_WORD = re.compile(r"[A-Z]+(?![a-z])|[A-Z]?[a-z]+|\d+|[^A-Za-z\d]+")
_MAX_TAG_TOKENS = 3
#: words that may follow a tag without being one: the tone of a base color
_QUALIFIERS = frozenset({"gray", "grey", "mono", "bw"})


def slot_provides(slot: str) -> frozenset[str]:
    """The material parameters a slot's file provides (``orm``: ao, roughness, metallic)."""
    return _PROVIDES.get(slot, frozenset({slot}))


class _Tag(NamedTuple):
    slot: str
    convention: str | None
    extra: bool


def _tag_table() -> dict[str, _Tag]:
    """Glued tag -> what it names; also accepts ``<tag>map``, ``<normal>gl``."""
    table: dict[str, _Tag] = {}
    for tags, extra in ((SLOTS, False), (EXTRAS, True)):
        for slot, spec in tags.items():
            for tag in spec.tags:
                glued = tag.replace(" ", "")
                table.setdefault(glued, _Tag(slot, None, extra))
                table.setdefault(glued + "map", _Tag(slot, None, extra))
                if slot == "normal":
                    for word, convention in CONVENTION_WORDS.items():
                        table.setdefault(glued + word, _Tag(slot, convention, extra))
    return table


_TAGS = _tag_table()


class _Token(NamedTuple):
    text: str  # lowercase
    start: int
    kind: str  # "word", "variant" (resolution, format...), "filler", "hint"


@dataclass(frozen=True)
class MapName:
    """What a file name says: which slot, whose material, which variant."""

    slot: str  #: a key of SLOTS, or of EXTRAS when ``extra``
    material: str  #: display name, e.g. "Bricks076C" for "Bricks076C_2K-PNG_Color"
    group: str  #: files of one set share this key (prefix + resolution)
    prefix: str  #: the name before the tag, as written
    convention: str | None = None  #: normal maps: "opengl" / "directx" from the name
    extra: bool = False  #: a recognised map no parameter takes (mask, preview...)
    variants: tuple[str, ...] = ()  #: resolution tokens ("2k")

    @property
    def prefix_words(self) -> tuple[str, ...]:
        """The prefix as lowercase parts: ``king_white`` -> ("king", "white")."""
        return tuple(name_key(self.prefix).split("_")) if self.prefix else ()


def name_key(name: str) -> str:
    """Case- and separator-insensitive key of a name: ``Rock-Wall 02`` -> ``rock_wall_02``."""
    return "_".join(_PART.findall(name.lower()))


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
            if text in CONVENTION_WORDS:
                kind = "hint"
            elif text in _FILLERS:
                kind = "filler"
            elif text in _FORMAT_WORDS:
                kind = "variant"
            tokens.append(_Token(text, part.start() + word.start(), kind))
    return tokens


def _match_tag(tokens: list[_Token], end: int) -> tuple[_Tag, int] | None:
    """The longest tag ending at token ``end`` (exclusive) and its first token."""
    for k in range(min(_MAX_TAG_TOKENS, end), 0, -1):
        window = tokens[end - k : end]
        if window[0].kind == "word" and all(t.kind in ("word", "filler") for t in window):
            found = _TAGS.get("".join(t.text for t in window))
            if found is not None:
                return found, end - k
    return None


def parse_map_name(name: str | os.PathLike[str]) -> MapName | None:
    """Classify one file name (extension ignored); None when no tag ends it."""
    stem = Path(name).stem
    tokens = _tokens(stem)
    end, hint, variants = len(tokens), None, []
    with_filler = None  # where the name ends if a trailing filler belongs to the tag
    while end and tokens[end - 1].kind != "word":
        if tokens[end - 1].kind == "filler" and with_filler is None:
            with_filler = end
        end -= 1
        token = tokens[end]
        if token.kind == "hint":
            hint = hint or CONVENTION_WORDS[token.text]
        elif _RESOLUTION.fullmatch(token.text):
            variants.insert(0, token.text)
    # "mask_map" is a tag of its own, "normal_map" a normal map: try the filler first
    match = (_match_tag(tokens, with_filler) if with_filler else None) or _match_tag(tokens, end)
    if match is None and end > 1 and tokens[end - 1].text in _QUALIFIERS:
        match = _match_tag(tokens, end - 1)  # MaterialX's "brick_base_gray"
    if match is None:
        return None
    (slot, convention, extra), first = match
    convention = (convention or hint) if slot == "normal" else None
    prefix = stem[: tokens[first].start].rstrip("_.-# ")
    group = "_".join([name_key(prefix), *variants]).strip("_")
    material = prefix
    for token in reversed(_tokens(prefix)):  # "Bricks076C_2K-PNG" -> "Bricks076C"
        if token.kind != "variant":
            break
        material = prefix[: token.start].rstrip("_.-# ")
    return MapName(slot, material, group, prefix, convention, extra, tuple(variants))
