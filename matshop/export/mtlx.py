"""MaterialX documents for an export: a ``gltf_pbr`` shader reading the files.

The document undoes the preset's packing with MaterialX's own nodes, so it
references exactly the textures the preset wrote, whatever the engine:
``image`` nodes (``srgb_texture`` for sRGB colors, raw for data), ``extract``
for a packed channel, ``invert`` for smoothness, a ``multiply``/``add`` pair
flipping green for DirectX normals, and ``normalmap``. One nodegraph holds the
reads; ``gltf_pbr`` and ``surfacematerial`` sit at the top, as in the
MaterialX repository's GltfPbr examples.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import MaterialX as mx

from .presets import OutputSpec, Preset, locate

#: gltf_pbr input, its type, and the matshop parameter feeding it
_SHADER_INPUTS = (
    ("base_color", "color3", "base_color"),
    ("metallic", "float", "metallic"),
    ("roughness", "float", "roughness"),
    ("occlusion", "float", "ao"),
    ("normal", "vector3", "normal"),
    ("emissive", "color3", "emissive"),
    ("alpha", "float", "opacity"),
)
_IMAGE_TYPES = {1: "float", 3: "color3", 4: "color4"}


def build_document(
    preset: Preset, outputs: Sequence[OutputSpec], files: dict[str, str], name: str
) -> mx.Document:
    """A MaterialX document for the written ``outputs`` (``files``: channel -> file name)."""
    doc = mx.createDocument()
    name = mx.createValidName(name)  # element names allow fewer characters than file names
    graph = doc.addNodeGraph(f"NG_{name}")
    shader = doc.addNode("gltf_pbr", f"SR_{name}", "surfaceshader")
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

    for shader_input, kind, param in _SHADER_INPUTS:
        found = locate(outputs, param)
        if found is None:
            continue
        output, channel, inverted = found
        if param == "normal":
            node = _normal(graph, image(output, "vector3"), preset.normal_convention)
        elif channel is None:
            node = image(output, kind)
        else:
            packed = image(output, _IMAGE_TYPES.get(len(output.channels or ()), "color4"))
            if packed.getType() == "float":
                node = packed
            else:
                node = graph.addNode("extract", f"{output.channel}_{'RGBA'[channel]}", "float")
                node.addInput("in", packed.getType()).setConnectedNode(packed)
                node.addInput("index", "integer").setValue(channel)
        if inverted:
            flip = graph.addNode("invert", f"{param}_from_smoothness", "float")
            flip.addInput("in", "float").setConnectedNode(node)
            node = flip
        out = graph.addOutput(f"out_{shader_input}", kind)
        out.setConnectedNode(node)
        port = shader.addInput(shader_input, kind)
        port.setNodeGraphString(graph.getName())
        port.setOutputString(out.getName())
    material = doc.addMaterialNode(f"M_{name}", shader)
    material.setAttribute("doc", f"exported by matshop with preset {preset.name}")
    return doc


def _is_color(output: OutputSpec) -> bool:
    return output.source in ("base_color", "emissive", "specular", "diffuse")


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


def validate(doc: mx.Document) -> tuple[bool, str]:
    """``doc.validate()`` against the standard data libraries."""
    library = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), library)
    doc.setDataLibrary(library)
    return doc.validate()


def checked_document(
    preset: Preset, outputs: Sequence[OutputSpec], files: dict[str, str], name: str
) -> mx.Document:
    """:func:`build_document`, validated (its data library stays set)."""
    doc = build_document(preset, outputs, files, name)
    valid, message = validate(doc)
    if not valid:  # a bug, not a user error: our documents must always validate
        raise RuntimeError(f"generated MaterialX document is invalid: {message}")
    return doc


def mtlx_writer(doc: mx.Document) -> Callable[[Path], None]:
    """A writer (for :mod:`matshop.io.fileset`) of the ``.mtlx`` document."""

    def write(path: Path) -> None:
        path.write_text(mx.writeToXmlString(doc), encoding="utf-8")

    return write
