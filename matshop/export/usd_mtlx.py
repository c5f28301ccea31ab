"""A MaterialX document as UsdShade prims: the material's ``mtlx`` render context.

The translation follows usdMtlx (the plugin USD renderers such as Storm,
Karma and Omniverse read MaterialX through): every node becomes a
``UsdShade.Shader`` whose ``info:id`` is its MaterialX nodedef name
(``ND_image_color3``, ``ND_open_pbr_surface_surfaceshader``), a nodegraph a
``UsdShade.NodeGraph`` with its outputs, values and connections as typed
inputs, a ``colorspace`` as the attribute's ``colorSpace`` metadata, and the
surface shader drives the Material's ``outputs:mtlx:surface``. The document
is the very one the ``.mtlx`` file holds (:func:`.mtlx.build_document`), so
both routes describe one shading network.
"""

from __future__ import annotations

import MaterialX as mx
from pxr import Gf, Sdf, Tf, Usd, UsdShade

_T = Sdf.ValueTypeNames
#: MaterialX type -> USD value type (usdMtlx's mapping)
SDF_TYPES = {
    "float": _T.Float,
    "integer": _T.Int,
    "boolean": _T.Bool,
    "color3": _T.Color3f,
    "color4": _T.Color4f,
    "vector2": _T.Float2,
    "vector3": _T.Float3,
    "vector4": _T.Float4,
    "filename": _T.Asset,
    "string": _T.String,
    "surfaceshader": _T.Token,
}
_VECTORS = {
    "color3": Gf.Vec3f,
    "color4": Gf.Vec4f,
    "vector2": Gf.Vec2f,
    "vector3": Gf.Vec3f,
    "vector4": Gf.Vec4f,
}


def _value(port: mx.ValueElement) -> object:
    kind = port.getType()
    if kind == "filename":
        return Sdf.AssetPath(f"./{port.getValueString()}")
    value = port.getValue()
    if kind in _VECTORS:
        return _VECTORS[kind](*value.asTuple())
    return value


def _shader(stage: Usd.Stage, parent: Sdf.Path, node: mx.Node) -> UsdShade.Shader:
    nodedef = node.getNodeDef()
    if nodedef is None:  # our documents are validated first: a bug, not user input
        raise RuntimeError(f"MaterialX node {node.getName()} has no nodedef")
    path = parent.AppendChild(Tf.MakeValidIdentifier(node.getName()))
    shader = UsdShade.Shader.Define(stage, path)
    shader.CreateIdAttr(nodedef.getName())
    shader.CreateOutput("out", SDF_TYPES[node.getType()])
    return shader


def _set_inputs(shader: UsdShade.Shader, node: mx.Node, prims: dict[str, Usd.Prim]) -> None:
    """Values and connections of ``node``'s inputs (``prims``: node or graph name -> prim)."""
    for port in node.getInputs():
        usd_input = shader.CreateInput(port.getName(), SDF_TYPES[port.getType()])
        if port.getNodeName():
            source = UsdShade.ConnectableAPI(prims[port.getNodeName()])
            usd_input.ConnectToSource(source, "out")
        elif port.getNodeGraphString():
            graph = UsdShade.ConnectableAPI(prims[port.getNodeGraphString()])
            usd_input.ConnectToSource(graph, port.getOutputString())
        else:
            usd_input.Set(_value(port))
        if port.getColorSpace():
            usd_input.GetAttr().SetColorSpace(port.getColorSpace())


def add_materialx(
    stage: Usd.Stage, material: UsdShade.Material, doc: mx.Document
) -> UsdShade.Shader:
    """Author ``doc`` (one surfacematerial, validated) under ``material`` as the
    ``mtlx`` render context; return the surface shader."""
    base = material.GetPath()
    prims: dict[str, Usd.Prim] = {}
    own_graphs = [c for c in doc.getChildren() if isinstance(c, mx.NodeGraph)]  # not the library's
    for graph in own_graphs:
        path = base.AppendChild(Tf.MakeValidIdentifier(graph.getName()))
        usd_graph = UsdShade.NodeGraph.Define(stage, path)
        prims[graph.getName()] = usd_graph.GetPrim()
        nodes = {n.getName(): (n, _shader(stage, path, n)) for n in graph.getNodes()}
        inner = {name: shader.GetPrim() for name, (_, shader) in nodes.items()}
        for node, shader in nodes.values():
            _set_inputs(shader, node, inner)
        for out in graph.getOutputs():
            port = usd_graph.CreateOutput(out.getName(), SDF_TYPES[out.getType()])
            port.ConnectToSource(UsdShade.ConnectableAPI(inner[out.getNodeName()]), "out")
    (material_node,) = doc.getMaterialNodes()
    (surface_node,) = mx.getShaderNodes(material_node)
    surface = _shader(stage, base, surface_node)
    _set_inputs(surface, surface_node, prims)
    material.CreateSurfaceOutput("mtlx").ConnectToSource(surface.ConnectableAPI(), "out")
    return surface
