"""Texture sets in real folders: which files make one material.

File names are classified by :mod:`matshop.io.map_names`. A folder may hold
one material or several, and libraries add more than maps, so detection:

- groups maps by the name before their tag (and resolution: ``2k`` and ``4k``
  are separate sets);
- lets a group lend its maps to the materials it names the stem of: a
  ``king_shared_metallic`` (or ``_common_``) fills the metallic slot of
  ``king_white`` and ``king_black`` when they have none, and so does a
  ``king_metallic`` beside ``king_white_*`` maps;
- lists several complete materials and asks for one (``material=``) instead
  of guessing;
- reports what it does not load (generic masks, previews, cavity maps, files
  whose names fit no slot, broken links) as "not used", never as an error;
- settles two files claiming one slot (``_normal.png`` and ``_normal.exr``)
  by reading their headers: the deeper one wins, then lossless over JPEG,
  then the one that states its normal convention; the choice is noted.

Explicit maps (:func:`resolve_texture_set` ``maps=``, the CLI's ``--map``,
the editor's texture-set dialog) add or override slots after detection.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from matshop.errors import MatshopError

from .map_names import (
    EXTRAS,
    IMAGE_EXTENSIONS,
    MIN_PACKED_CHANNELS,
    PACKED_CHANNELS,
    SLOTS,
    MapName,
    name_key,
    parse_map_name,
    slot_provides,
)

__all__ = [
    "PACKED_CHANNELS",
    "SLOTS",
    "NothingRecognised",
    "SeveralMaterials",
    "TextureSet",
    "check_texture_set",
    "detect_texture_set",
    "known_slots",
    "parse_map_name",
    "resolve_texture_set",
    "with_slot",
]

#: a last prefix word that marks maps shared by sibling materials
SHARING_WORDS = frozenset({"shared", "common", "all", "global"})


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
    #: other files beside the set that are not loaded, and why ("a generic mask")
    not_used: dict[Path, str] = field(default_factory=dict)
    #: decisions worth telling the user: shared maps taken, duplicates settled
    notes: list[str] = field(default_factory=list)
    #: the user's choice of normal-map convention (None: file name, confident guess, OpenGL)
    normal_convention: str | None = None

    def unloaded(self) -> list[tuple[Path, str, str | None]]:
        """Every file beside the set that is not loaded: ``(file, why, slot)``.

        ``slot`` names the map a file is an alternate of (None otherwise). In the
        order front ends list them: alternates, files set aside with a reason, then
        names that match no map.
        """
        rows: list[tuple[Path, str, str | None]] = [
            (path, f"the other {slot} convention", slot)
            for slot, paths in sorted(self.alternates.items())
            for path in paths
        ]
        rows += [(path, why, None) for path, why in self.not_used.items()]
        rows += [(path, "name matches no map", None) for path in self.unrecognised]
        return rows


class NothingRecognised(MatshopError):
    """No file in the folder names a map."""


class SeveralMaterials(MatshopError):
    """The folder holds several complete materials: ``choices`` names them."""

    def __init__(self, folder: Path, choices: list[str], labels: list[str]) -> None:
        self.choices = choices
        super().__init__(
            f"several materials in one folder ({', '.join(labels)}); "
            "choose one with --material NAME or pass one file of the set",
            folder,
        )


def known_slots() -> list[str]:
    """Every slot a texture set may fill: single maps, then packed ones."""
    return list(SLOTS)


def _convention_hint(path: Path) -> dict[str, str]:
    parsed = parse_map_name(path)
    return {"convention": parsed.convention} if parsed and parsed.convention else {}


def with_slot(ts: TextureSet, slot: str, file: str | os.PathLike[str] | None) -> TextureSet:
    """A copy of ``ts`` with ``slot`` read from ``file`` (None: the slot is left empty).

    For a user correcting what detection found. The file leaves any other
    slot and every "not used" list, so it is read once. A normal map's
    convention hint comes from the new file's name.
    """
    if slot not in known_slots():
        raise MatshopError(f"unknown map slot {slot!r} (known: {', '.join(known_slots())})")
    maps = {k: v for k, v in ts.maps.items() if k != slot}
    hints = {k: v for k, v in ts.hints.items() if k != slot}
    unrecognised = list(ts.unrecognised)
    alternates = {k: list(v) for k, v in ts.alternates.items()}
    not_used = dict(ts.not_used)
    if file is not None:
        path = Path(file)
        maps = {k: v for k, v in maps.items() if v != path}
        unrecognised = [f for f in unrecognised if f != path]
        alternates = {k: [f for f in v if f != path] for k, v in alternates.items()}
        not_used.pop(path, None)
        maps[slot] = path
        if slot in ("normal", "tangent") and _convention_hint(path):
            hints["normal"] = _convention_hint(path)
    return replace(
        ts,
        maps=maps,
        hints=hints,
        unrecognised=unrecognised,
        alternates={k: v for k, v in alternates.items() if v},
        not_used=not_used,
        notes=list(ts.notes),
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


_EXPECTED = (
    "expected names like <material>_basecolor.png, <material>_normal.png, <material>_roughness.png"
)


@dataclass
class _Group:
    """Maps that share a prefix and resolution: one material, or maps it lends."""

    key: str
    name: str
    words: tuple[str, ...]
    variants: tuple[str, ...]
    claims: dict[str, list[tuple[Path, MapName]]] = field(default_factory=dict)

    @property
    def shared(self) -> bool:
        return bool(self.words) and self.words[-1] in SHARING_WORDS

    @property
    def stem(self) -> tuple[str, ...]:
        """The prefix of the materials this group may lend to."""
        return self.words[:-1] if self.shared else self.words

    def label(self) -> str:
        count = len(self.claims)
        resolution = f" {' '.join(self.variants)}" if self.variants else ""
        return f"{self.name or '(unnamed)'}{resolution} ({count} map{'s' * (count != 1)})"

    def lends_to(self, other: _Group) -> bool:
        """Whether ``other`` may take this group's maps for the slots it lacks: a ``_shared_``
        group lends to the materials named after its stem; another group only when it is no
        material of its own (no base colour) and its name is the start of ``other``'s."""
        if other is self or self.variants not in ((), other.variants):
            return False
        if other.words[: len(self.stem)] != self.stem:
            return False
        if self.shared:
            return True
        return len(other.words) > len(self.words) and "base_color" not in self.claims


@dataclass
class _Scan:
    folder: Path
    groups: dict[str, _Group]
    extras: list[tuple[Path, MapName]]
    unrecognised: list[Path]
    not_used: dict[Path, str]

    def materials(self) -> list[_Group]:
        """Groups that are materials, not just maps lent to siblings."""
        groups = list(self.groups.values())
        own = [g for g in groups if not g.shared]
        materials = [
            g
            for g in own
            if "base_color" in g.claims or not any(g.lends_to(other) for other in own)
        ]
        return materials or groups

    def lenders(self, material: _Group) -> list[_Group]:
        """Groups whose maps ``material`` may take, the most specific first."""
        found = [g for g in self.groups.values() if g.lends_to(material)]
        return sorted(found, key=lambda g: (-len(g.stem), g.key))


def _scan(folder: Path) -> _Scan:
    try:
        entries = sorted(folder.iterdir())
    except OSError as exc:
        raise MatshopError(f"cannot list folder: {exc.strerror or exc}", folder) from exc
    files, not_used = [], {}
    for entry in entries:
        if entry.suffix.lower() not in IMAGE_EXTENSIONS or entry.name.startswith("."):
            continue
        if entry.is_file():
            files.append(entry)
        elif entry.is_symlink() and not entry.exists():
            not_used[entry] = "a broken link"
        elif not entry.is_dir():
            not_used[entry] = "not a regular file"
    parsed_files = [(f, parse_map_name(f)) for f in files]
    # A file named just like a material ("rusty_metal_02.png" beside
    # "rusty_metal_02_diff_2k.png") is a preview, not a map ending in "metal".
    prefixes = {
        name_key(name)
        for _, p in parsed_files
        if p is not None and not p.extra
        for name in (p.prefix, p.material)
    }
    groups: dict[str, _Group] = {}
    extras, unrecognised = [], []
    for f, parsed in parsed_files:
        if name_key(f.stem) in prefixes:
            not_used[f] = "a preview image (named like the material)"
        elif parsed is None:
            unrecognised.append(f)
        elif parsed.extra:
            extras.append((f, parsed))
        else:
            group = groups.setdefault(
                parsed.group,
                _Group(parsed.group, parsed.material, parsed.prefix_words, parsed.variants),
            )
            group.claims.setdefault(parsed.slot, []).append((f, parsed))
    return _Scan(folder, groups, extras, unrecognised, not_used)


def detect_texture_set(path: str | os.PathLike[str], *, material: str | None = None) -> TextureSet:
    """Find the texture set in a folder, or the set a given file belongs to.

    ``material`` chooses one of several materials in a folder by name (as
    :class:`SeveralMaterials` lists them). Raises :class:`NothingRecognised`,
    :class:`SeveralMaterials` or MatshopError (one line each).
    """
    path = Path(path)
    if not path.exists():
        raise MatshopError("not found", path)
    if path.is_dir():
        folder, chosen_file = path, None
    else:
        if path.suffix.lower() not in IMAGE_EXTENSIONS:
            raise MatshopError("not an image file", path)
        folder, chosen_file = path.parent, path
    scan = _scan(folder)
    materials = scan.materials()
    if chosen_file is not None:
        group = _group_of(scan, materials, chosen_file)
    elif material is not None:
        group = _group_named(scan, materials, material)
    elif not materials:
        count = len(scan.unrecognised) + len(scan.extras) + len(scan.not_used)
        raise NothingRecognised(
            f"no texture maps recognised in {count} image files; {_EXPECTED}", folder
        )
    elif len(materials) > 1:
        labels = sorted(g.label() for g in materials)
        raise SeveralMaterials(folder, sorted(g.key for g in materials), labels)
    else:
        group = materials[0]
    return _assemble(scan, group, single=len(materials) == 1)


def list_materials(folder: str | os.PathLike[str]) -> list[str]:
    """The names :func:`detect_texture_set` accepts as ``material`` for ``folder``."""
    return sorted(g.key for g in _scan(Path(folder)).materials())


def _group_of(scan: _Scan, materials: list[_Group], file: Path) -> _Group:
    parsed = parse_map_name(file)
    if parsed is not None and parsed.extra and file not in scan.not_used:
        raise MatshopError(
            f"is {EXTRAS[parsed.slot].description}, not a material map; "
            "pass one of the material's maps or its folder",
            file,
        )
    group = scan.groups.get(parsed.group) if parsed is not None else None
    if group is None or file in scan.not_used:
        raise MatshopError(f"file name names no texture map; {_EXPECTED}", file)
    if group in materials:
        return group
    borrowers = [m for m in materials if group.lends_to(m)]
    if len(borrowers) == 1:
        return borrowers[0]
    labels = sorted(g.label() for g in borrowers)
    raise SeveralMaterials(scan.folder, sorted(g.key for g in borrowers), labels)


def _group_named(scan: _Scan, materials: list[_Group], wanted: str) -> _Group:
    key = name_key(wanted)
    for exact in (True, False):
        found = [g for g in materials if (g.key == key if exact else name_key(g.name) == key)]
        if len(found) == 1:
            return found[0]
    names = ", ".join(sorted(g.key for g in materials)) or "none"
    raise MatshopError(f"no material {wanted!r} here (materials: {names})", scan.folder)


def _belongs(words: tuple[str, ...], group: _Group) -> bool:
    return words[: len(group.words)] == group.words


def _assemble(scan: _Scan, group: _Group, *, single: bool) -> TextureSet:
    result = TextureSet(group.name or scan.folder.name, scan.folder, {})
    provided: set[str] = set()
    for slot, claims in sorted(group.claims.items()):
        _take(result, slot, claims, provided)
    lenders = scan.lenders(group)
    for lender in lenders:
        for slot, claims in sorted(lender.claims.items()):
            if slot in result.maps or slot_provides(slot) <= provided:
                continue
            if _take(result, slot, claims, provided):
                siblings = "_".join(lender.stem) + "_*" if lender.stem else "every material"
                result.notes.append(
                    f"{slot}: {result.maps[slot].name}, shared with {siblings} in the folder"
                )
    taken = set(result.maps.values())
    for lender in lenders:  # the lenders' maps this material does not take
        for slot, claims in lender.claims.items():
            for f, _ in claims:
                if f not in taken:
                    result.not_used[f] = f"a {slot} map this material has already"
    for f, parsed in scan.extras:
        if single or _belongs(parsed.prefix_words, group):
            result.not_used[f] = EXTRAS[parsed.slot].description
    if single:
        result.unrecognised = list(scan.unrecognised)
        result.not_used.update(scan.not_used)
    else:
        result.unrecognised = [f for f in scan.unrecognised if _belongs(_words(f), group)]
        result.not_used.update(
            {f: why for f, why in scan.not_used.items() if _belongs(_words(f), group)}
        )
    result.not_used = dict(sorted(result.not_used.items()))
    return result


def _words(path: Path) -> tuple[str, ...]:
    return tuple(name_key(path.stem).split("_"))


def _take(
    result: TextureSet, slot: str, claims: list[tuple[Path, MapName]], provided: set[str]
) -> bool:
    """Settle the claims on ``slot`` into ``result``; False when none is usable."""
    usable = []
    for f, parsed in claims:
        channels = _channels(f) if slot in MIN_PACKED_CHANNELS else None
        if channels is not None and channels < MIN_PACKED_CHANNELS[slot]:
            result.not_used[f] = (
                f"{channels} channel(s): a generic mask, not a packed {slot.replace('_', ' ')}"
            )
        else:
            usable.append((f, parsed))
    if not usable:
        return False
    conventions = [parsed.convention for _, parsed in usable]
    if len(usable) > 1 and None not in conventions and len(set(conventions)) == len(usable):
        ranked = sorted(usable, key=lambda c: c[1].convention != "opengl")  # OpenGL first
        result.alternates[slot] = [f for f, _ in ranked[1:]]
    elif len(usable) > 1:
        ranked, reason = _rank(usable)
        for f, _ in ranked[1:]:
            result.not_used[f] = f"another {slot} map; {ranked[0][0].name} is used ({reason})"
        result.notes.append(
            f"{slot}: {ranked[0][0].name} over "
            f"{', '.join(f.name for f, _ in ranked[1:])} ({reason})"
        )
    else:
        ranked = usable
    path, parsed = ranked[0]
    result.maps[slot] = path
    provided.update(slot_provides(slot))
    if parsed.convention:
        result.hints[slot] = {"convention": parsed.convention}
    return True


#: bit depths by precision, for choosing between two files of one slot
_DEPTH_RANK = {"uint8": 1, "int8": 1, "uint16": 2, "int16": 2, "half": 3, "float": 4}
_LOSSY = frozenset({".jpg", ".jpeg", ".jpe", ".webp"})


def _header(path: Path) -> tuple[str, int] | None:
    """(bit depth, channels) from the file header; None when it cannot be read."""
    from .images import probe_image  # OpenImageIO only when two files compete

    try:
        info = probe_image(path)
    except (MatshopError, OSError):
        return None
    return info.bit_depth, info.channels


def _channels(path: Path) -> int | None:
    header = _header(path)
    return None if header is None else header[1]


def _rank(claims: list[tuple[Path, MapName]]) -> tuple[list[tuple[Path, MapName]], str]:
    """Best claim first, and the reason in words."""
    headers = {f: _header(f) for f, _ in claims}

    def quality(claim: tuple[Path, MapName]) -> tuple[bool, int, bool, bool]:
        f, parsed = claim
        header = headers[f]
        return (
            header is not None,
            _DEPTH_RANK.get(header[0], 1) if header else 0,
            f.suffix.lower() not in _LOSSY,
            parsed.convention is not None,
        )

    ranked = sorted(claims, key=lambda c: (tuple(-int(q) for q in quality(c)), c[0].name))
    (first, _), (second, _) = ranked[:2]
    best, runner = quality(ranked[0]), quality(ranked[1])
    differs = next((i for i in range(len(best)) if best[i] != runner[i]), None)
    if differs == 0:
        reason = f"{second.name} cannot be read"
    elif differs == 1:
        reason = f"{headers[first][0]} over {headers[second][0]}, the deeper file wins"  # type: ignore[index]
    elif differs == 2:
        reason = "lossless over JPEG"
    elif differs == 3:
        reason = "its name states the normal convention"
    else:
        reason = "alike; the first by name"
    return ranked, reason


def resolve_texture_set(
    path: str | os.PathLike[str],
    *,
    material: str | None = None,
    maps: Mapping[str, str | os.PathLike[str] | None] | None = None,
) -> TextureSet:
    """Detect the set at ``path``, then apply explicit ``maps`` (slot -> file, None: empty).

    Explicit maps add or override slots; with them a folder whose names
    match nothing still loads. A missing file or an unknown slot is one line.
    """
    maps = dict(maps or {})
    try:
        ts = detect_texture_set(path, material=material)
    except NothingRecognised:
        if not maps:
            raise
        folder = Path(path) if Path(path).is_dir() else Path(path).parent
        ts = TextureSet(folder.name, folder, {})
    for slot, file in maps.items():
        if slot not in known_slots():
            raise MatshopError(
                f"--map {slot}=...: unknown map slot (known: {', '.join(known_slots())})"
            )
        if file is not None and not Path(file).is_file():
            raise MatshopError(f"--map {slot}: file not found", file)
        ts = with_slot(ts, slot, file)
        ts.notes.append(
            f"{slot}: {Path(file).name} (given explicitly)" if file else f"{slot}: left empty"
        )
    return ts
