"""Channel packing: a Material and one output spec -> the output's float array.

Pure functions over arrays; nothing here touches files. Values come out in
file encoding in ``[0, 1]`` (colors sRGB- or linear-encoded as the output
says, normals ``(n + 1) / 2`` in the preset's convention, data linear);
quantisation is :mod:`.quantize`'s job and writing :mod:`matshop.io.fileset`'s.

A parameter the material lacks is filled with the engine's default
(:data:`ENGINE_DEFAULTS`, or the channel's own ``default``) and reported in
the returned warnings; :func:`plan_missing` lists them before any pixel work so
``--strict`` can refuse early.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MatshopError
from ..material import COLOR_PARAMETERS, Material
from ..spaces.color import linear_to_srgb, srgb_to_linear
from ..spaces.frame import encode_normal_map
from .presets import OutputSpec, Preset

#: What engines assume when a map is absent (glTF spec defaults, Unreal's and
#: Unity's material defaults), in file encoding. A color's default is an sRGB
#: value. Normals: flat ``+z``; tangent: ``+x``.
ENGINE_DEFAULTS: dict[str, tuple[float, ...]] = {
    "ao": (1.0,),
    "metallic": (0.0,),
    "roughness": (0.5,),
    "opacity": (1.0,),
    "transmission": (0.0,),
    "height": (0.0,),
    "base_color": (0.5, 0.5, 0.5),
    "specular": (0.5, 0.5, 0.5),
    "emissive": (0.0, 0.0, 0.0),
    "normal": (0.0, 0.0, 1.0),
    "tangent": (1.0, 0.0, 0.0),
}


@dataclass(frozen=True)
class Missing:
    """A parameter an output reads that the material does not have."""

    output: str
    parameter: str
    fill: tuple[float, ...] | None  #: None: no default exists (cannot be filled)

    def message(self) -> str:
        if self.fill is None:
            return f"{self.output}: the material has no {self.parameter} and it has no default"
        values = ", ".join(f"{v:g}" for v in self.fill)
        return f"{self.output}: the material has no {self.parameter}; filled with ({values})"


def has_parameter(material: Material, name: str) -> bool:
    """Whether ``name`` (or the pseudo-parameter ``tangent``) is in ``material``."""
    if name == "tangent":
        return "normal" in material.schema and material.maps["normal"].shape[2] == 6
    return name in material.schema


def is_written(material: Material, output: OutputSpec) -> bool:
    """Optional outputs are written only when the material has one of their sources."""
    return not output.optional or any(has_parameter(material, s) for s in output.sources)


def plan_missing(material: Material, preset: Preset) -> list[Missing]:
    """Every (output, parameter) the export will have to fill, in preset order."""
    missing = []
    for output in preset.outputs:
        if not is_written(material, output):
            continue
        if output.channels is None:
            assert output.source is not None
            if not has_parameter(material, output.source):
                fill = ENGINE_DEFAULTS.get(output.source)
                missing.append(Missing(output.channel, output.source, fill))
            continue
        for spec in output.channels:
            if spec.source is None or has_parameter(material, spec.source):
                continue
            if spec.value is not None:
                fill: tuple[float, ...] | None = (spec.value,)
            else:
                default = ENGINE_DEFAULTS.get(spec.source)
                fill = None if default is None else (default[spec.source_channel % len(default)],)
            missing.append(Missing(output.channel, spec.source, fill))
    return missing


def source_values(
    material: Material, name: str, *, color_space: str, convention: str
) -> np.ndarray:
    """Parameter ``name`` of ``material`` in file encoding, float32 ``(H, W, C)``.

    Colors are sRGB-encoded (``color_space="srgb"``) or linear; normals and
    tangents are encoded ``(n + 1) / 2`` in ``convention``; data is as stored.
    """
    if name == "tangent":
        return encode_normal_map(material.maps["normal"][..., 3:6], convention=convention)
    values = material.maps[name]
    if name == "normal":
        return encode_normal_map(values[..., :3], convention=convention)
    if name not in COLOR_PARAMETERS:
        return values
    return _encode_color(values, material.schema[name].space.name, color_space)


def _encode_color(values: np.ndarray, space: str, color_space: str) -> np.ndarray:
    """Physical color (encoded as its editing space says) -> the file's encoding."""
    if space == "srgb" and color_space == "srgb":
        return values  # already exactly what the file wants: no round trip through linear
    if space == "srgb":
        linear = srgb_to_linear(values)
    elif space == "gamma22":
        linear = np.power(np.clip(values, 0.0, None), np.float32(2.2)).astype(np.float32)
    else:  # a linear-valued color space
        linear = np.asarray(values, dtype=np.float32)
    return linear_to_srgb(linear) if color_space == "srgb" else linear


def pack_output(material: Material, output: OutputSpec, preset: Preset) -> np.ndarray:
    """The float32 ``(H, W, C)`` array of one output, in file encoding.

    Missing parameters are filled with their default (see :func:`plan_missing`
    for the list); a parameter without any default raises ``MatshopError``.
    """
    height, width = material.size

    def values(name: str) -> np.ndarray:
        return source_values(
            material, name, color_space=output.color_space, convention=preset.normal_convention
        )

    if output.channels is None:
        assert output.source is not None
        if has_parameter(material, output.source):
            return np.ascontiguousarray(values(output.source), dtype=np.float32)
        return _constant(height, width, _default(output, output.source, preset))
    out = np.empty((height, width, len(output.channels)), dtype=np.float32)
    cache: dict[str, np.ndarray] = {}
    for spec in output.channels:
        if spec.source is None or not has_parameter(material, spec.source):
            fill = spec.value
            if fill is None:
                assert spec.source is not None
                default = _default(output, spec.source, preset)
                fill = default[spec.source_channel % len(default)]
            out[..., spec.dest] = fill  # constants are written as given, never inverted
            continue
        if spec.source not in cache:
            cache[spec.source] = values(spec.source)
        src = cache[spec.source]
        if spec.source_channel >= src.shape[2]:
            raise MatshopError(
                f"preset {preset.name!r}, map {output.channel}: {spec.source} has "
                f"{src.shape[2]} channel(s), channel {spec.source_channel} asked for"
            )
        channel = src[..., spec.source_channel]
        out[..., spec.dest] = 1.0 - channel if spec.transform == "invert" else channel
    return out


def _default(output: OutputSpec, name: str, preset: Preset) -> tuple[float, ...]:
    """The engine default of ``name`` in file encoding (normals encoded too)."""
    default = ENGINE_DEFAULTS.get(name)
    if default is None:
        raise MatshopError(
            f"map {output.channel} needs {name}, which the material lacks and no engine "
            "default exists for"
        )
    if name in ("normal", "tangent"):
        vector = np.asarray(default, dtype=np.float32)
        encoded = encode_normal_map(vector, convention=preset.normal_convention)
        return tuple(float(v) for v in encoded)
    return default


def _constant(height: int, width: int, value: tuple[float, ...]) -> np.ndarray:
    return np.broadcast_to(np.asarray(value, dtype=np.float32), (height, width, len(value))).copy()
