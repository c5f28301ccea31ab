"""A UsdPreviewSurface network reading an export's texture files.

Like the MaterialX document (:mod:`.mtlx`), the network undoes the preset's
packing, so it references exactly the files the preset wrote, whatever the
engine. Every conversion is one of UsdUVTexture's own inputs, per channel:

- ``sourceColorSpace``: ``sRGB`` for color parameters stored sRGB-encoded,
  ``raw`` for everything else (data, normals, linear colors). A file holding
  both gets one texture node per reading (the same file, twice);
- a packed channel is read through ``outputs:r/g/b/a`` of its file's node;
- ``value = texel * scale + bias``: normals ``(2, 2, 2, 1)`` / ``(-1, -1, -1, 0)``
  (``n = 2v - 1``); DirectX normals ``(2, -2, 2, 1)`` / ``(-1, 1, -1, 0)``, which
  also flips green (USD's tangent space is OpenGL's: ``+v`` up). USD's
  ``NormalMapTextureValidator`` *warns* about that non-standard scale for 8-bit
  maps; it is exactly what the UsdUVTexture spec defines scale and bias for,
  and the alternative (a second, OpenGL copy of the normal map) would make the
  USD disagree with the files the engine gets. An inverted channel (Unity's
  smoothness) gets ``scale -1, bias 1`` on that channel: ``1 - a`` is roughness.

``st`` comes from one ``UsdPrimvarReader_float2`` reading the mesh's ``st``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from pxr import Gf, Sdf, Tf, Usd, UsdShade

from ..material import COLOR_PARAMETERS
from .presets import OutputSpec, Preset, locate

_T = Sdf.ValueTypeNames
#: UsdPreviewSurface input, its type, the matshop parameter feeding it
SURFACE_INPUTS = (
    ("diffuseColor", _T.Color3f, "base_color"),
    ("metallic", _T.Float, "metallic"),
    ("roughness", _T.Float, "roughness"),
    ("occlusion", _T.Float, "ao"),
    ("normal", _T.Normal3f, "normal"),
    ("emissiveColor", _T.Color3f, "emissive"),
    ("opacity", _T.Float, "opacity"),
)
_RGBA = "rgba"
#: texel -> value per convention: scale, bias (n = 2v - 1; DirectX flips green)
NORMAL_SCALE_BIAS = {
    "opengl": ((2.0, 2.0, 2.0, 1.0), (-1.0, -1.0, -1.0, 0.0)),
    "directx": ((2.0, -2.0, 2.0, 1.0), (-1.0, 1.0, -1.0, 0.0)),
}


@dataclass
class _Reading:
    """One UsdUVTexture node: a file read in one color space."""

    shader: UsdShade.Shader
    scale: list[float]
    bias: list[float]


def source_color_space(output: OutputSpec, param: str) -> str:
    """``sRGB`` when ``param`` sits in ``output`` sRGB-encoded, else ``raw``."""
    return "sRGB" if param in COLOR_PARAMETERS and output.color_space == "srgb" else "raw"


def add_preview_surface(
    stage: Usd.Stage,
    material: UsdShade.Material,
    preset: Preset,
    outputs: Sequence[OutputSpec],
    files: dict[str, str],
) -> UsdShade.Shader:
    """Author the network under ``material`` and connect its ``outputs:surface``."""
    base = material.GetPath()
    surface = UsdShade.Shader.Define(stage, base.AppendChild("PreviewSurface"))
    surface.CreateIdAttr("UsdPreviewSurface")
    reader = UsdShade.Shader.Define(stage, base.AppendChild("TexCoordReader"))
    reader.CreateIdAttr("UsdPrimvarReader_float2")
    reader.CreateInput("varname", _T.String).Set("st")
    st = reader.CreateOutput("result", _T.Float2)
    readings: dict[tuple[str, str], _Reading] = {}

    def reading(output: OutputSpec, color_space: str) -> _Reading:
        key = (output.channel, color_space)
        if key not in readings:
            suffix = "_sRGB" if color_space == "sRGB" and output.channels else ""
            node_name = Tf.MakeValidIdentifier(f"Tex_{output.channel}{suffix}")
            node = UsdShade.Shader.Define(stage, base.AppendChild(node_name))
            node.CreateIdAttr("UsdUVTexture")
            node.CreateInput("file", _T.Asset).Set(Sdf.AssetPath(f"./{files[output.channel]}"))
            node.CreateInput("sourceColorSpace", _T.Token).Set(color_space)
            node.CreateInput("wrapS", _T.Token).Set("repeat")
            node.CreateInput("wrapT", _T.Token).Set("repeat")
            node.CreateInput("st", _T.Float2).ConnectToSource(st)
            readings[key] = _Reading(node, [1.0] * 4, [0.0] * 4)
        return readings[key]

    for name, value_type, param in SURFACE_INPUTS:
        found = locate(outputs, param)
        if found is None:
            continue
        output, channel, inverted = found
        read = reading(output, source_color_space(output, param))
        if param == "normal":
            scale, bias = NORMAL_SCALE_BIAS[preset.normal_convention]
            read.scale[:3], read.bias[:3] = scale[:3], bias[:3]
            port = read.shader.CreateOutput("rgb", _T.Float3)
        elif value_type == _T.Float:
            letter = "r" if channel is None else _RGBA[channel]
            if inverted:  # smoothness -> roughness: 1 - a
                read.scale[_RGBA.index(letter)], read.bias[_RGBA.index(letter)] = -1.0, 1.0
            port = read.shader.CreateOutput(letter, _T.Float)
        else:
            port = read.shader.CreateOutput("rgb", _T.Float3)
        surface.CreateInput(name, value_type).ConnectToSource(port)
    for read in readings.values():
        if read.scale != [1.0] * 4 or read.bias != [0.0] * 4:
            read.shader.CreateInput("scale", _T.Float4).Set(Gf.Vec4f(*read.scale))
            read.shader.CreateInput("bias", _T.Float4).Set(Gf.Vec4f(*read.bias))
    material.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")
    return surface
