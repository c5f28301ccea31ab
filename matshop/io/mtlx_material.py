"""A material read from a MaterialX document (``.mtlx``).

The document's material node names a surface shader (``open_pbr_surface``,
``standard_surface`` or ``gltf_pbr``); each of its texture-fed inputs is
evaluated by following the graph back to the image it reads, through the
nodes a texture set needs and whose definitions are MaterialX's: ``image``
(the file, relative to the document; ``srgb_texture`` colorspace or raw),
``extract`` (one channel), ``invert`` (``amount - in``), ``convert``,
``multiply`` / ``add`` by a constant, ``dot`` (pass-through) and ``normalmap``
(``n = 2 v - 1``, tangent space). Any other node is refused in one line.

Colors are kept sRGB-coded as matshop holds them (a raw color image is
encoded); normals arrive as unit OpenGL tangent-space vectors, and the
convention the file itself uses is recorded (``directx`` when the graph flips
green before ``normalmap``).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import MatshopError
from ..material import PARAMETER_KINDS, Material, Schema
from ..spaces.color import linear_to_srgb
from ..spaces.frame import decode_normal_map
from .images import read_image

MTLX_SUFFIX = ".mtlx"
#: surface shader -> {input: matshop parameter}, per each model's nodedef
_MODELS = {
    "open_pbr_surface": {
        "base_color": "base_color",
        "base_metalness": "metallic",
        "specular_roughness": "roughness",
        "geometry_normal": "normal",
        "emission_color": "emissive",
        "geometry_opacity": "opacity",
    },
    "standard_surface": {
        "base_color": "base_color",
        "metalness": "metallic",
        "specular_roughness": "roughness",
        "normal": "normal",
        "emission_color": "emissive",
        "opacity": "opacity",
    },
    "gltf_pbr": {
        "base_color": "base_color",
        "metallic": "metallic",
        "roughness": "roughness",
        "occlusion": "ao",
        "normal": "normal",
        "emissive": "emissive",
        "alpha": "opacity",
    },
}
_COLORS = frozenset({"base_color", "emissive"})


class _Evaluator:
    """Evaluates the supported nodes over whole images, reading each file once."""

    def __init__(self, folder: Path, path: Path, limits: dict) -> None:
        self.folder = folder
        self.path = path
        self.limits = limits
        self.images: dict[str, tuple[np.ndarray, str]] = {}
        self.flipped_green = False
        self.srgb = False  #: the last image evaluated was sRGB-coded
        self.last_file = ""  #: and its file name

    def constant(self, port) -> np.ndarray:  # noqa: ANN001 - a MaterialX input
        value = port.getValue()
        values = value.asTuple() if hasattr(value, "asTuple") else (value,)
        return np.asarray(values, dtype=np.float32)

    def operand(self, node, name: str) -> np.ndarray:  # noqa: ANN001 - a MaterialX node
        port = node.getInput(name)
        if port is None:
            raise MatshopError(f"node {node.getName()} has no input {name!r}", self.path)
        upstream = port.getConnectedNode()
        return self.constant(port) if upstream is None else self.evaluate(upstream)

    def evaluate(self, node) -> np.ndarray:  # noqa: ANN001 - a MaterialX node
        category = node.getCategory()
        if category == "image":
            return self.image(node)
        if category == "extract":
            index = int(node.getInput("index").getValue())
            return self.operand(node, "in")[..., index : index + 1]
        if category == "invert":
            amount = node.getInput("amount")
            return (self.constant(amount) if amount else 1.0) - self.operand(node, "in")
        if category in ("convert", "dot"):
            values = self.operand(node, "in")
            width = {"float": 1, "color3": 3, "vector3": 3, "color4": 4}.get(node.getType(), 0)
            return np.repeat(values, width, axis=-1) if values.shape[-1] == 1 < width else values
        if category in ("multiply", "add"):
            left, right = self.operand(node, "in1"), self.operand(node, "in2")
            if category == "multiply" and right.ndim == 1 and right.size >= 2 and right[1] < 0:
                self.flipped_green = True
            return left * right if category == "multiply" else left + right
        if category == "normalmap":
            texels = self.operand(node, "in")
            return decode_normal_map(np.clip(texels, 0.0, 1.0))  # n = 2v - 1, renormalised
        raise MatshopError(f"cannot read node {node.getName()!r} ({category})", self.path)

    def image(self, node) -> np.ndarray:  # noqa: ANN001 - a MaterialX node
        port = node.getInput("file")
        name = port.getValueString()
        file = self.folder / name
        if name not in self.images:
            if not file.is_file():
                raise MatshopError(f"texture {name} is missing", self.path)
            pixels, info = read_image(file, **self.limits)
            self.images[name] = (pixels, info.bit_depth)
        pixels, _ = self.images[name]
        width = {"float": 1, "color3": 3, "vector3": 3, "color4": 4}[node.getType()]
        if pixels.shape[2] == 1 and width > 1:
            pixels = np.repeat(pixels, width, axis=2)
        self.srgb = port.getColorSpace() == "srgb_texture"
        self.last_file = name
        return pixels[..., :width]


def read_mtlx_material(
    path: str | os.PathLike,
    *,
    spaces: dict[str, str] | None = None,
    max_pixels: int | None = None,
) -> Material:
    """The material of the MaterialX document at ``path`` (``sources`` names the files);
    ``spaces`` and ``max_pixels`` as in ``load_material``."""
    import MaterialX as mx

    path = Path(path)
    doc = mx.createDocument()
    try:
        mx.readFromXmlFile(doc, str(path))
    except (mx.Exception, mx.ExceptionParseError, mx.ExceptionFileMissing, OSError) as exc:
        reason = str(exc).replace(str(path), "").strip() or type(exc).__name__
        raise MatshopError(f"not a MaterialX document: {reason}", path) from None
    materials = doc.getMaterialNodes()
    shaders = mx.getShaderNodes(materials[0]) if materials else []
    if not shaders or shaders[0].getCategory() not in _MODELS:
        known = ", ".join(_MODELS)
        raise MatshopError(f"no material with a {known} surface shader", path)
    shader = shaders[0]
    limits = {} if max_pixels is None else {"max_pixels": max_pixels}
    evaluator = _Evaluator(path.parent, path, limits)
    maps: dict[str, np.ndarray] = {}
    sources: dict[str, dict] = {}
    for input_name, param in _MODELS[shader.getCategory()].items():
        port = shader.getInput(input_name)
        if port is None or not port.getNodeGraphString():
            continue
        graph = doc.getNodeGraph(port.getNodeGraphString())
        output = graph.getOutput(port.getOutputString()) if graph else None
        node = output.getConnectedNode() if output else None
        if node is None:
            raise MatshopError(f"{input_name} reads a missing graph output", path)
        evaluator.flipped_green = False
        values = evaluator.evaluate(node)
        file = evaluator.last_file
        if param in _COLORS and not evaluator.srgb:
            values = linear_to_srgb(np.clip(values, 0.0, None))
        extra: dict[str, str] = {}
        if param == "normal":
            convention = "directx" if evaluator.flipped_green else "opengl"
            extra = {"convention": convention, "convention_source": "the MaterialX graph"}
        elif param not in _COLORS:
            values = values[..., :1]
        maps[param] = np.ascontiguousarray(values, dtype=np.float32)
        depth = evaluator.images[file][1]
        sources[param] = {"file": str(path.parent / file), "bit_depth": depth, **extra}
    if not maps:
        raise MatshopError(f"{shader.getName()} reads no texture", path)
    sizes = {m.shape[:2] for m in maps.values()}
    if len(sizes) > 1:
        raise MatshopError(f"its textures differ in size: {sorted(sizes)}", path)
    names = [n for n in PARAMETER_KINDS if n in maps]
    name = materials[0].getName().removeprefix("M_")
    return Material(name, Schema.from_names(names, spaces), maps, sources)
