"""Reading an export back into a Material by inverting its preset.

The generic importer (:func:`matshop.io.material_io.load_material`) finds
sets by file-name conventions; a user's preset may name and pack files any
way it likes, so this module undoes exactly what the preset did instead:
every parameter is taken from the first output that holds it (a whole-map
output wins over a packed channel), inverted channels are inverted back,
colors are re-encoded to sRGB and normals decoded from the preset's
convention. It is the round-trip check of every preset, built-in or not.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import MatshopError
from ..io.images import read_image
from ..material import COLOR_PARAMETERS, PARAMETER_KINDS, Material, Schema
from ..spaces.color import linear_to_srgb
from ..spaces.frame import decode_normal_map
from .pack import is_written
from .presets import OutputSpec, Preset, load_preset, locate


def _locations(preset: Preset) -> dict[str, tuple[OutputSpec, int | None, bool]]:
    """parameter -> (output, channel or None for the whole file, inverted)."""
    params = dict.fromkeys(p for output in preset.outputs for p in output.sources)
    return {p: found for p in params if (found := locate(preset.outputs, p)) is not None}


def reimport(
    out_dir: str | os.PathLike,
    preset: Preset | str,
    name: str,
    *,
    parameters: tuple[str, ...] | None = None,
) -> Material:
    """Load what ``preset`` wrote for material ``name`` in ``out_dir``.

    ``parameters`` limits which parameters are read (default: every one whose
    file exists). Raises :class:`MatshopError` when a file is missing.
    """
    if isinstance(preset, str):
        preset = load_preset(preset)
    folder = Path(out_dir)
    cache: dict[str, np.ndarray] = {}
    maps: dict[str, np.ndarray] = {}
    sources: dict[str, dict] = {}
    for param, (output, channel, inverted) in _locations(preset).items():
        if parameters is not None and param not in parameters:
            continue
        path = folder / output.file_for(name, preset.name)
        if not path.exists():
            if parameters is not None:
                raise MatshopError(f"{param} should be in this file, which is missing", path)
            continue
        if path.name not in cache:
            cache[path.name] = read_image(path)[0]
        pixels = cache[path.name]
        values = pixels if channel is None else pixels[..., channel : channel + 1]
        if inverted:
            values = 1.0 - values
        if param in ("normal", "tangent"):
            values = decode_normal_map(values[..., :3], convention=preset.normal_convention)
        elif param in COLOR_PARAMETERS:
            values = values[..., :3]
            if output.color_space == "linear":
                values = linear_to_srgb(values)
        maps[param] = np.ascontiguousarray(values, dtype=np.float32)
        sources[param] = {"file": str(path), "convention": preset.normal_convention}
    if "tangent" in maps:
        tangent = maps.pop("tangent")
        sources.pop("tangent")
        if "normal" in maps:
            maps["normal"] = np.concatenate([maps["normal"], tangent], axis=2)
    if not maps:
        raise MatshopError(f"no file of preset {preset.name!r} for {name!r} found", folder)
    names = [n for n in PARAMETER_KINDS if n in maps]
    frame = "normal" in maps and maps["normal"].shape[2] == 6
    spaces = {"normal": "normal_tangent"} if frame else {}
    return Material(name, Schema.from_names(names, spaces), maps, sources)


def written_parameters(material: Material, preset: Preset) -> list[str]:
    """The material's parameters that ``preset`` stores somewhere."""
    locations = _locations(preset)
    return [
        n for n in material.schema.names if n in locations and is_written(material, locations[n][0])
    ]
