"""A material read from USD (``.usda``, ``.usdc``, ``.usd``, ``.usdz``).

The reader follows the UsdPreviewSurface and UsdUVTexture specifications, not
matshop's writer: the Material bound to the first mesh (else the first
Material), its universal surface (a ``UsdPreviewSurface``), and for each
texture-fed input the file, the output read (``r``, ``g``, ``b``, ``a``,
``rgb``), ``value = texel * scale + bias`` and ``sourceColorSpace``. So it
reads any USD material of that shape, and reading back matshop's own export
checks the writer against the specification.

Colors are kept as matshop holds them, sRGB-coded (a ``raw`` color texture is
encoded); normals arrive in USD's tangent space (OpenGL's, ``+v`` up) whatever
the file's convention, which is recorded from the sign of the green scale.
Textures inside a ``.usdz`` are read through USD's asset resolver.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import MatshopError
from ..material import PARAMETER_KINDS, Material, Schema
from ..spaces.color import linear_to_srgb
from ..spaces.frame import decode_normal_map
from .images import read_image

if TYPE_CHECKING:  # pxr loads only when a USD file is read
    from pxr import Sdf, Usd, UsdShade

USD_SUFFIXES = frozenset({".usda", ".usdc", ".usd", ".usdz"})
#: UsdPreviewSurface input -> matshop parameter
_INPUTS = {
    "diffuseColor": "base_color",
    "emissiveColor": "emissive",
    "metallic": "metallic",
    "roughness": "roughness",
    "occlusion": "ao",
    "opacity": "opacity",
    "normal": "normal",
}
_COLORS = frozenset({"base_color", "emissive"})
_CHANNELS = {"r": [0], "g": [1], "b": [2], "a": [3], "rgb": [0, 1, 2], "rgba": [0, 1, 2, 3]}


def is_usd(path: str | os.PathLike) -> bool:
    return Path(path).suffix.lower() in USD_SUFFIXES


def _bound_material(stage: Usd.Stage, path: Path) -> UsdShade.Material:
    from pxr import UsdGeom, UsdShade

    for prim in stage.Traverse():
        if prim.IsA(UsdGeom.Mesh):
            material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
            if material:
                return material
    for prim in stage.Traverse():
        if prim.IsA(UsdShade.Material):
            return UsdShade.Material(prim)
    raise MatshopError("no Material in this USD file", path)


def _texels(asset: Sdf.AssetPath, path: Path, limits: dict) -> tuple[np.ndarray, str]:
    """The pixels of a texture (a file, or a file inside a package) and its bit depth."""
    from pxr import Ar

    resolved = asset.resolvedPath
    if not resolved:
        raise MatshopError(f"texture {asset.path} is missing", path)
    if os.path.isfile(resolved):
        pixels, info = read_image(resolved, **limits)
        return pixels, info.bit_depth
    asset = Ar.GetResolver().OpenAsset(Ar.ResolvedPath(resolved))
    if asset is None:
        raise MatshopError(f"cannot open texture {asset.path}", path)
    suffix = Path(resolved.rstrip("]")).suffix
    with tempfile.TemporaryDirectory(prefix="matshop-usd-") as scratch:
        copy = Path(scratch) / f"texture{suffix}"
        copy.write_bytes(bytes(asset.GetBuffer()))
        pixels, info = read_image(copy, **limits)
    return pixels, info.bit_depth


def read_usd_material(
    path: str | os.PathLike,
    *,
    spaces: dict[str, str] | None = None,
    max_pixels: int | None = None,
) -> Material:
    """The material of the USD file at ``path`` (``sources`` says where each parameter
    came from); ``spaces`` and ``max_pixels`` as in ``load_material``.

    Raises :class:`MatshopError` (one line, naming the file) when the file has no
    UsdPreviewSurface material reading textures.
    """
    from pxr import Usd, UsdShade

    path = Path(path)
    stage = Usd.Stage.Open(str(path)) if path.is_file() else None
    if stage is None:
        raise MatshopError("USD cannot open this file", path)
    material = _bound_material(stage, path)
    surface = material.ComputeSurfaceSource()[0]
    if not surface or surface.GetIdAttr().Get() != "UsdPreviewSurface":
        raise MatshopError(f"{material.GetPath()} has no UsdPreviewSurface", path)
    maps: dict[str, np.ndarray] = {}
    sources: dict[str, dict] = {}
    limits = {} if max_pixels is None else {"max_pixels": max_pixels}
    for name, param in _INPUTS.items():
        port = surface.GetInput(name)
        if not port or not port.HasConnectedSource():
            continue
        source, output, _ = port.GetConnectedSource()
        texture = UsdShade.Shader(source.GetPrim())
        if texture.GetIdAttr().Get() != "UsdUVTexture" or output not in _CHANNELS:
            raise MatshopError(f"{name} is not read from a UsdUVTexture", path)
        asset = texture.GetInput("file").Get()
        pixels, depth = _texels(asset, path, limits)
        picks = _CHANNELS[output]
        packed = pixels.shape[2] > 1 and len(picks) == 1
        if pixels.shape[2] == 1:  # one channel: every output reads it
            pixels = np.repeat(pixels, 4, axis=2)
        if max(picks) >= pixels.shape[2]:
            raise MatshopError(f"{asset.path} has no channel {output} for {name}", path)
        scale = _float4(texture, "scale", (1.0, 1.0, 1.0, 1.0))
        bias = _float4(texture, "bias", (0.0, 0.0, 0.0, 0.0))
        values = pixels[..., picks] * scale[picks] + bias[picks]
        space = texture.GetInput("sourceColorSpace")
        space = space.Get() if space else "auto"
        if param == "normal":
            values = decode_normal_map(np.clip((values + 1.0) / 2.0, 0.0, 1.0))
            convention = "directx" if scale[1] < 0 else "opengl"
            extra = {"convention": convention, "convention_source": "USD scale and bias"}
        elif param in _COLORS:
            raw = space == "raw" or (space == "auto" and depth not in ("uint8",))
            values = linear_to_srgb(values) if raw else values
            extra = {}
        else:
            extra = {"packed": Path(asset.path).name, "channel": picks[0]} if packed else {}
        maps[param] = np.ascontiguousarray(values, dtype=np.float32)
        sources[param] = {"file": asset.resolvedPath, "bit_depth": depth, **extra}
    if not maps:
        raise MatshopError(f"{material.GetPath()} reads no texture", path)
    sizes = {m.shape[:2] for m in maps.values()}
    if len(sizes) > 1:
        raise MatshopError(f"its textures differ in size: {sorted(sizes)}", path)
    names = [n for n in PARAMETER_KINDS if n in maps]
    schema = Schema.from_names(names, spaces)
    return Material(material.GetPrim().GetName(), schema, maps, sources)


def _float4(texture: UsdShade.Shader, name: str, fallback: tuple[float, ...]) -> np.ndarray:
    value = texture.GetInput(name)
    return np.asarray(value.Get() if value else fallback, dtype=np.float32)
