"""MaterialX documents for an export: a surface shader reading the files.

The document undoes the preset's packing with MaterialX's own nodes, so it
references exactly the textures the preset wrote, whatever the engine:
``image`` nodes (``srgb_texture`` for sRGB colors, raw for data), ``extract``
for a packed channel, ``invert`` for smoothness, a ``multiply``/``add`` pair
flipping green for DirectX normals, and ``normalmap``. One nodegraph holds the
reads; the surface shader and ``surfacematerial`` sit at the top, as in the
MaterialX repository's GltfPbr examples.

The shading model is a choice (:data:`SHADING_MODELS`): ``open_pbr_surface``
(OpenPBR Surface, MaterialX 1.39), ``standard_surface`` or ``gltf_pbr``. Each
is fed per its definition; the mapping is the one MaterialX's own translation
graphs use (``standard_surface_to_gltf_pbr``, ``open_pbr_to_standard_surface``):

- roughness is perceptual in all three (GGX ``alpha = r^2``): glTF's
  ``roughness`` = ``specular_roughness``; metallic = ``metalness`` /
  ``base_metalness``;
- base color feeds ``base_color`` at full weight (``standard_surface``'s
  ``base`` defaults to 0.8 and is set to 1; OpenPBR's ``base_weight`` is 1);
- the normal is the same ``normalmap`` output (green flipped first for DirectX
  maps), into ``normal`` / ``geometry_normal``;
- emission: glTF's ``emissive`` color feeds ``emission_color`` with
  ``emission`` / ``emission_luminance`` 1, as the translation graphs map them
  one to one (set only when the material has an emissive map: both default to 0);
- opacity: ``alpha`` / ``geometry_opacity``; ``standard_surface``'s ``opacity``
  is a color (the value through ``convert``);
- ambient occlusion has an input only in ``gltf_pbr``: the other two models
  have none (their renderers compute occlusion), so it is left out.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import MaterialX as mx

from ..material import COLOR_PARAMETERS
from .presets import OutputSpec, Preset, locate


@dataclass(frozen=True)
class ShadingModel:
    """A MaterialX surface shader: which input each parameter feeds, and constants."""

    #: (shader input, its type, the matshop parameter feeding it)
    inputs: tuple[tuple[str, str, str], ...]
    #: input -> value, set always
    constants: tuple[tuple[str, float], ...] = ()
    #: the weight input set to 1 when emission is wired (None: the color is enough)
    emission_weight: str | None = None


SHADING_MODELS = {
    "open_pbr_surface": ShadingModel(
        inputs=(
            ("base_color", "color3", "base_color"),
            ("base_metalness", "float", "metallic"),
            ("specular_roughness", "float", "roughness"),
            ("geometry_normal", "vector3", "normal"),
            ("emission_color", "color3", "emissive"),
            ("geometry_opacity", "float", "opacity"),
        ),
        constants=(("base_weight", 1.0),),
        emission_weight="emission_luminance",
    ),
    "standard_surface": ShadingModel(
        inputs=(
            ("base_color", "color3", "base_color"),
            ("metalness", "float", "metallic"),
            ("specular_roughness", "float", "roughness"),
            ("normal", "vector3", "normal"),
            ("emission_color", "color3", "emissive"),
            ("opacity", "color3", "opacity"),
        ),
        constants=(("base", 1.0),),
        emission_weight="emission",
    ),
    "gltf_pbr": ShadingModel(
        inputs=(
            ("base_color", "color3", "base_color"),
            ("metallic", "float", "metallic"),
            ("roughness", "float", "roughness"),
            ("occlusion", "float", "ao"),
            ("normal", "vector3", "normal"),
            ("emissive", "color3", "emissive"),
            ("alpha", "float", "opacity"),
        ),
    ),
}
DEFAULT_SHADING_MODEL = "open_pbr_surface"
_IMAGE_TYPES = {1: "float", 3: "color3", 4: "color4"}
_SCALARS = frozenset({"metallic", "roughness", "ao", "opacity"})


def build_document(
    preset: Preset,
    outputs: Sequence[OutputSpec],
    files: dict[str, str],
    name: str,
    shading_model: str = DEFAULT_SHADING_MODEL,
) -> mx.Document:
    """A MaterialX document for the written ``outputs`` (``files``: channel -> file name)."""
    model = SHADING_MODELS[shading_model]
    doc = mx.createDocument()
    name = mx.createValidName(name)  # element names allow fewer characters than file names
    graph = doc.addNodeGraph(f"NG_{name}")
    shader = doc.addNode(shading_model, f"SR_{name}", "surfaceshader")
    for constant, value in model.constants:
        shader.addInput(constant, "float").setValue(value)
    images: dict[tuple[str, str], mx.Node] = {}

    def image(output: OutputSpec, kind: str) -> mx.Node:
        key = (output.channel, kind)
        if key not in images:
            node = graph.addNode("image", mx.createValidName(f"{output.channel}_{kind}"), kind)
            file = node.addInput("file", "filename")
            file.setValueString(files[output.channel])
            if kind in ("color3", "color4") and output.color_space == "srgb" and _is_color(output):
                file.setColorSpace("srgb_texture")
            images[key] = node
        return images[key]

    for shader_input, kind, param in model.inputs:
        found = locate(outputs, param)
        if found is None:
            continue
        output, channel, inverted = found
        if param == "normal":
            node = _normal(graph, image(output, "vector3"), preset.normal_convention)
        elif channel is None:
            node = image(output, "float" if param in _SCALARS else kind)
        else:
            packed = image(output, _IMAGE_TYPES.get(len(output.channels or ()), "color4"))
            if packed.getType() == "float":
                node = packed
            else:
                node = graph.addNode(
                    "extract", mx.createValidName(f"{output.channel}_{'RGBA'[channel]}"), "float"
                )
                node.addInput("in", packed.getType()).setConnectedNode(packed)
                node.addInput("index", "integer").setValue(channel)
        if inverted:
            flip = graph.addNode("invert", f"{param}_from_smoothness", "float")
            flip.addInput("in", "float").setConnectedNode(node)
            node = flip
        if node.getType() != kind:  # a scalar into a color input (standard_surface opacity)
            convert = graph.addNode("convert", f"{param}_as_{kind}", kind)
            convert.addInput("in", node.getType()).setConnectedNode(node)
            node = convert
        if param == "emissive" and model.emission_weight:
            shader.addInput(model.emission_weight, "float").setValue(1.0)
        out = graph.addOutput(f"out_{shader_input}", kind)
        out.setConnectedNode(node)
        port = shader.addInput(shader_input, kind)
        port.setNodeGraphString(graph.getName())
        port.setOutputString(out.getName())
    material = doc.addMaterialNode(f"M_{name}", shader)
    material.setAttribute("doc", f"exported by matshop with preset {preset.name}")
    return doc


def _is_color(output: OutputSpec) -> bool:
    return output.source in COLOR_PARAMETERS


def _normal(graph: mx.NodeGraph, texels: mx.Node, convention: str) -> mx.Node:
    """Texels ``(n + 1) / 2`` -> a world normal through ``normalmap`` (OpenGL +Y)."""
    source = texels
    if convention == "directx":  # g' = 1 - g: multiply by (1, -1, 1), add (0, 1, 0)
        scale = graph.addNode("multiply", "normal_flip_green", "vector3")
        scale.addInput("in1", "vector3").setConnectedNode(texels)
        scale.addInput("in2", "vector3").setValueString("1, -1, 1")
        shift = graph.addNode("add", "normal_flip_green_offset", "vector3")
        shift.addInput("in1", "vector3").setConnectedNode(scale)
        shift.addInput("in2", "vector3").setValueString("0, 1, 0")
        source = shift
    node = graph.addNode("normalmap", "normalmap", "vector3")
    node.addInput("in", "vector3").setConnectedNode(source)
    return node


@functools.cache
def standard_library() -> mx.Document:
    """MaterialX's standard data libraries (loaded once; only read afterwards)."""
    library = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), library)
    return library


def validate(doc: mx.Document) -> tuple[bool, str]:
    """``doc.validate()`` against the standard data libraries."""
    doc.setDataLibrary(standard_library())
    return doc.validate()


def checked_document(
    preset: Preset,
    outputs: Sequence[OutputSpec],
    files: dict[str, str],
    name: str,
    shading_model: str = DEFAULT_SHADING_MODEL,
) -> mx.Document:
    """:func:`build_document`, validated (its data library stays set)."""
    doc = build_document(preset, outputs, files, name, shading_model)
    valid, message = validate(doc)
    if not valid:  # a bug, not a user error: our documents must always validate
        raise RuntimeError(f"generated MaterialX document is invalid: {message}")
    return doc


def mtlx_writer(doc: mx.Document) -> Callable[[Path], None]:
    """A writer (for :mod:`matshop.io.fileset`) of the ``.mtlx`` document."""

    def write(path: Path) -> None:
        path.write_text(mx.writeToXmlString(doc), encoding="utf-8")

    return write
