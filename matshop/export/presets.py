"""Export presets: what files an engine wants and how each is packed.

A preset is data, never a code branch. Its shape follows Substance 3D
Painter's export presets (``maps``, each with a ``fileName`` template,
``fileFormat``, ``bitDepth`` and ``channels`` of ``destChannel`` /
``srcMapName`` / ``srcChannel``) so artists can read and write their own::

    {
      "name": "unreal",
      "description": "Unreal Engine 5: BaseColor, DirectX normal, packed ORM",
      "fileName": "{material}_{channel}.{ext}",
      "normalConvention": "directx",
      "maps": [
        {"channel": "BaseColor", "fileFormat": "png", "bitDepth": 8,
         "colorSpace": "srgb", "srcMapName": "base_color"},
        {"channel": "ORM", "fileFormat": "png", "bitDepth": 8, "channels": [
          {"destChannel": "R", "srcMapName": "ao"},
          {"destChannel": "G", "srcMapName": "roughness"},
          {"destChannel": "B", "srcMapName": "metallic"}]}
      ]
    }

A map either takes a whole parameter (``srcMapName`` on the map: all its
channels, e.g. base color RGB or a 128-channel distribution) or lists
``channels``. A channel reads ``srcChannel`` (R/G/B/A, X/Y/Z or an index) of
the parameter ``srcMapName``, optionally through ``"transform": "invert"``
(smoothness = 1 - roughness); ``"value"`` instead of a source writes a
constant; ``"default"`` overrides the engine default used when the material
lacks the parameter. ``srcMapName`` may also be ``tangent`` (the tangent of a
normal + tangent frame). A map with ``"optional": true`` is written only when
the material has at least one of its parameters (emissive, height).

``"keepVariance": true`` widens the roughness by the normal tilt variance a
reduction averages away whenever an export with the preset downsizes
(``--size N``; :mod:`matshop.ops.variance`); the command line's
``--keep-variance`` / ``--no-keep-variance`` overrides it. The built-in presets
say ``false``: the option is not closer to the far-field look on every material
(docs/variance.md), so it stays the user's choice.

``"pngLevel": N`` (0-9) is the zlib level of the preset's PNG files (default
:data:`~matshop.io.png_settings.PNG_LEVEL`, chosen by measurement; 9 for the
smallest files); the command line's ``--png-level`` overrides it.

``colorSpace`` applies to color parameters (base color, specular, emissive,
diffuse): ``srgb`` or ``linear``; other parameters are data and always linear.
Normals are encoded ``(n + 1) / 2`` in the preset's ``normalConvention``.
8-bit maps are dithered unless ``"dithering": false``; the built-in presets
turn it off for normal maps, whose decoded (renormalised) vectors sit just off
the code grid: rounding keeps them within half a code, dithering a full one.
"""

from __future__ import annotations

import json
import os
import re
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from ..errors import InvalidValue, MatshopError, naming
from ..io.guard import read_input_file
from ..io.jsonfile import MAX_JSON_BYTES, bounded_int
from ..io.safe_names import file_name_problem, safe_stem

#: pseudo-parameters a preset may read besides the material's own
PSEUDO_PARAMETERS = frozenset({"tangent"})

#: format -> (file extension, bit depths it can hold, channel counts it can hold)
FORMATS: dict[str, tuple[str, tuple[str, ...], tuple[int, ...] | None]] = {
    "png": ("png", ("uint8", "uint16"), (1, 2, 3, 4)),
    "tga": ("tga", ("uint8",), (1, 3, 4)),
    "jpg": ("jpg", ("uint8",), (1, 3)),
    "tif": ("tif", ("uint8", "uint16", "float"), None),
    "exr": ("exr", ("half", "float"), None),
}
_FORMAT_ALIASES = {"jpeg": "jpg", "tiff": "tif", "targa": "tga", "openexr": "exr"}
_BIT_DEPTHS = {
    "8": "uint8",
    "uint8": "uint8",
    "16": "uint16",
    "uint16": "uint16",
    "16f": "half",
    "half": "half",
    "32f": "float",
    "32": "float",
    "float": "float",
}
_CHANNEL_LETTERS = {"R": 0, "G": 1, "B": 2, "A": 3, "X": 0, "Y": 1, "Z": 2, "L": 0}
#: files one preset may write (engines use a handful)
MAX_MAPS = 64
_TEMPLATE_FIELDS = frozenset({"material", "channel", "ext", "preset"})
_TEMPLATE_TOKEN = re.compile(r"\{([^{}]*)\}")
_TRANSFORMS = ("none", "invert")
_CONVENTIONS = ("opengl", "directx")
_COLOR_SPACES = ("srgb", "linear")


@dataclass(frozen=True)
class ChannelSpec:
    """One destination channel of an output file."""

    dest: int
    #: parameter name (or ``tangent``); None for a constant ``value``
    source: str | None
    source_channel: int = 0
    transform: str = "none"
    #: the constant (no source), or the fill when the material lacks ``source``
    value: float | None = None


@dataclass(frozen=True)
class OutputSpec:
    """One file of a preset."""

    channel: str  #: the ``{channel}`` token, e.g. ``BaseColor``
    file_name: str  #: template, e.g. ``{material}_{channel}.{ext}``
    format: str  #: key of :data:`FORMATS`
    bit_depth: str  #: uint8, uint16, half, float
    color_space: str  #: srgb or linear (color parameters only)
    channels: tuple[ChannelSpec, ...] | None  #: None: the whole ``source`` parameter
    source: str | None = None
    optional: bool = False
    dithering: bool = True

    @property
    def extension(self) -> str:
        return FORMATS[self.format][0]

    @property
    def sources(self) -> tuple[str, ...]:
        """Every parameter this output reads, in order, without repeats."""
        if self.channels is None:
            return (self.source,) if self.source else ()
        names = [c.source for c in self.channels if c.source is not None]
        return tuple(dict.fromkeys(names))

    def file_for(self, material: str, preset: str) -> str:
        # the template was checked on load; every value put into it is a safe stem
        return self.file_name.format(
            material=safe_stem(material),
            channel=self.channel,
            ext=self.extension,
            preset=safe_stem(preset, "preset"),
        )


@dataclass(frozen=True)
class Preset:
    """A named table of outputs."""

    name: str
    description: str
    normal_convention: str
    outputs: tuple[OutputSpec, ...]
    origin: str  #: ``built-in`` or the file it came from
    #: widen the lobe by the normal variance a downsizing export removes
    keep_variance: bool = False
    #: zlib level of the PNG files (None: the writer's default)
    png_level: int | None = None

    def output(self, channel: str) -> OutputSpec:
        for out in self.outputs:
            if out.channel == channel:
                return out
        raise KeyError(f"preset {self.name!r} has no output {channel!r}")


def locate(outputs: Sequence[OutputSpec], param: str) -> tuple[OutputSpec, int | None, bool] | None:
    """Where ``param`` is written: (output, channel or None for the whole file,
    inverted), a whole-parameter file winning over a packed channel; None if nowhere."""
    for output in outputs:
        if output.channels is None and output.source == param:
            return output, None, False
    for output in outputs:
        for spec in output.channels or ():
            if spec.source == param:
                return output, spec.dest, spec.transform == "invert"
    return None


# ---------------------------------------------------------------------------
# loading


def builtin_preset_names() -> list[str]:
    """Names of the presets shipped in ``matshop/export/presets/``."""
    folder = resources.files(__package__).joinpath("presets")
    return sorted(p.name[: -len(".json")] for p in folder.iterdir() if p.name.endswith(".json"))


def load_preset(name: str | None = None, *, path: str | os.PathLike | None = None) -> Preset:
    """A built-in preset by ``name``, or the user's preset file at ``path``.

    User files are JSON (``.json``) or TOML (``.toml``). Every problem raises
    :class:`MatshopError` naming the file and the offending entry.
    """
    if path is not None:
        file = Path(path)
        text = read_input_file(file, "preset file", MAX_JSON_BYTES)
        return parse_preset(_decode(text, file), origin=str(file))
    if name is None:
        raise MatshopError("no preset given: use --preset NAME or --preset-file FILE")
    known = builtin_preset_names()
    if name not in known:
        raise MatshopError(f"unknown preset {name!r}; built-in presets: {', '.join(known)}")
    text = resources.files(__package__).joinpath("presets", f"{name}.json").read_bytes()
    return parse_preset(_decode(text, Path(f"{name}.json")), origin="built-in")


def _decode(text: bytes, file: Path) -> dict[str, Any]:
    try:
        if file.suffix.lower() == ".toml":
            data = tomllib.loads(text.decode("utf-8"))
        elif file.suffix.lower() == ".json":
            data = json.loads(text, parse_int=bounded_int)
        else:
            raise MatshopError("preset files must be .json or .toml", file)
    except (ValueError, UnicodeDecodeError) as exc:  # JSONDecodeError, TOMLDecodeError
        raise MatshopError(f"not a valid preset file: {exc}", file) from None
    except RecursionError:
        raise MatshopError("not a valid preset file: nested too deeply", file) from None
    if not isinstance(data, dict):
        raise MatshopError("a preset file must hold one table (a JSON object)", file)
    return data


def parse_preset(data: dict[str, Any], *, origin: str = "built-in") -> Preset:
    """Validate a decoded preset and build its :class:`Preset`."""
    with naming(None if origin == "built-in" else origin, what=f"preset {data.get('name', '?')!r}"):
        return _parse_preset(data, origin)


def _parse_preset(data: dict[str, Any], origin: str) -> Preset:
    name = data.get("name")
    if not isinstance(name, str) or not name:
        raise InvalidValue("needs a non-empty string 'name'")
    convention = str(data.get("normalConvention", "opengl")).lower()
    if convention not in _CONVENTIONS:
        raise InvalidValue(f"normalConvention must be opengl or directx, got {convention!r}")
    template = data.get("fileName", "{material}_{channel}.{ext}")
    maps = data.get("maps")
    if not isinstance(maps, list) or not maps:
        raise InvalidValue("needs a non-empty list 'maps'")
    if len(maps) > MAX_MAPS:  # each is a file to pack and write
        raise InvalidValue(f"has {len(maps)} maps, more than {MAX_MAPS}")
    outputs = []
    for index, entry in enumerate(maps):
        if not isinstance(entry, dict):
            raise InvalidValue(f"maps[{index}] must be a table")
        with naming(what=f"map {entry.get('channel', index)!r}"):
            outputs.append(_parse_output(entry, template))
    files = [o.file_for("m", name) for o in outputs]
    if len(set(files)) != len(files):
        raise InvalidValue("two maps would write the same file name")
    return Preset(
        name,
        str(data.get("description", "")),
        convention,
        tuple(outputs),
        origin,
        keep_variance=_flag(data, "keepVariance", False),
        png_level=_png_level(data),
    )


def _parse_output(entry: dict[str, Any], default_template: str) -> OutputSpec:
    channel = entry.get("channel")
    if not isinstance(channel, str) or not re.fullmatch(r"[A-Za-z0-9_\-][A-Za-z0-9_.\-]*", channel):
        raise InvalidValue("needs a 'channel' name of letters, digits, _ . - (not leading .)")
    template = str(entry.get("fileName", default_template))
    _check_template(template)
    fmt = str(entry.get("fileFormat", "png")).lower()
    fmt = _FORMAT_ALIASES.get(fmt, fmt)
    if fmt not in FORMATS:
        raise InvalidValue(f"fileFormat {fmt!r} is not one of {', '.join(FORMATS)}")
    _, depths, counts = FORMATS[fmt]
    depth = _BIT_DEPTHS.get(str(entry.get("bitDepth", depths[0])).lower())
    if depth not in depths:
        raise InvalidValue(f"{fmt} cannot hold bitDepth {entry.get('bitDepth')!r}; use {depths}")
    color_space = str(entry.get("colorSpace", "srgb")).lower()
    if color_space not in _COLOR_SPACES:
        raise InvalidValue(f"colorSpace must be srgb or linear, got {color_space!r}")
    whole = entry.get("srcMapName")
    raw_channels = entry.get("channels")
    if (whole is None) == (raw_channels is None):
        raise InvalidValue("give either 'srcMapName' (a whole parameter) or 'channels'")
    channels = None
    if raw_channels is not None:
        if not isinstance(raw_channels, list) or not raw_channels:
            raise InvalidValue("'channels' must be a non-empty list")
        channels = tuple(_parse_channel(c) for c in raw_channels)
        dests = sorted(c.dest for c in channels)
        if dests != list(range(len(dests))):
            raise InvalidValue(f"destChannel must fill R, G, B, A from R without gaps, got {dests}")
        if counts is not None and len(dests) not in counts:
            raise InvalidValue(f"{fmt} cannot hold {len(dests)} channels")
        channels = tuple(sorted(channels, key=lambda c: c.dest))
    elif not isinstance(whole, str) or not whole:
        raise InvalidValue("'srcMapName' must be a parameter name")
    return OutputSpec(
        channel=channel,
        file_name=template,
        format=fmt,
        bit_depth=depth,
        color_space=color_space,
        channels=channels,
        source=whole,
        optional=_flag(entry, "optional", False),
        dithering=_flag(entry, "dithering", True),
    )


def _png_level(data: dict[str, Any]) -> int | None:
    value = data.get("pngLevel")
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 9:
        raise InvalidValue(f"'pngLevel' must be a whole number 0 to 9, got {str(value)[:40]!r}")
    return value


def _flag(entry: dict[str, Any], key: str, default: bool) -> bool:
    """A true/false setting; the string "false" is not true (JSON and TOML have booleans)."""
    value = entry.get(key, default)
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.strip().lower() in ("true", "false"):
        return value.strip().lower() == "true"
    raise InvalidValue(f"{key!r} must be true or false, got {str(value)[:40]!r}")


def _parse_channel(entry: Any) -> ChannelSpec:
    if not isinstance(entry, dict):
        raise InvalidValue("each channel must be a table")
    dest = _channel_index(entry.get("destChannel"), "destChannel")
    source = entry.get("srcMapName")
    value = entry.get("value", entry.get("default"))
    if value is not None and (isinstance(value, bool) or not isinstance(value, int | float)):
        raise InvalidValue(f"value/default must be a number, got {value!r}")
    if source is None and "value" not in entry:
        raise InvalidValue(f"channel {entry.get('destChannel')}: give 'srcMapName' or 'value'")
    transform = str(entry.get("transform", "none")).lower()
    if transform not in _TRANSFORMS:
        raise InvalidValue(f"transform must be one of {_TRANSFORMS}, got {transform!r}")
    return ChannelSpec(
        dest=dest,
        source=None if source is None else str(source),
        source_channel=_channel_index(entry.get("srcChannel", 0), "srcChannel"),
        transform=transform,
        value=None if value is None else float(value),
    )


def _channel_index(value: Any, what: str) -> int:
    if isinstance(value, int) and not isinstance(value, bool) and value >= 0:
        return value
    if isinstance(value, str) and value.upper() in _CHANNEL_LETTERS:
        return _CHANNEL_LETTERS[value.upper()]
    raise InvalidValue(f"{what} must be R, G, B, A (or an index), got {value!r}")


def _check_template(template: str) -> None:
    unknown = set(_TEMPLATE_TOKEN.findall(template)) - _TEMPLATE_FIELDS
    if unknown:
        raise InvalidValue(
            f"fileName {template!r} uses unknown fields {sorted(unknown)}; "
            f"known: {', '.join('{' + f + '}' for f in sorted(_TEMPLATE_FIELDS))}"
        )
    try:
        example = template.format(material="m", channel="c", ext="png", preset="p")
    except (ValueError, IndexError, KeyError, AttributeError) as exc:
        raise InvalidValue(f"fileName {template[:60]!r} is not a valid template ({exc})") from None
    problem = file_name_problem(example)
    if problem is not None or example.startswith("."):
        raise InvalidValue(f"fileName {template[:60]!r} must make a plain file name")
    if "{ext}" not in template and not re.search(r"\.[A-Za-z]+$", template):
        raise InvalidValue(f"fileName {template!r} needs an extension or {{ext}}")
