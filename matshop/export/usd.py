"""USD export: ``<name>.usda`` (and a packaged ``<name>.usdz``) of an export.

The stage (Y up, meters, like glTF and the OBJ meshes)::

    /<name>                 Xform, the default prim
        /Geom               Mesh: the --glb mesh (a user's OBJ or the UV sphere)
        /Looks/<name>       Material
            outputs:surface       -> UsdPreviewSurface reading the texture files
            outputs:mtlx:surface  -> the MaterialX document's surface shader

The mesh carries vertex ``normals``, ``primvars:st`` (USD's texture origin is
the lower-left corner, as OBJ's; the glTF mesh's ``v`` is flipped back) and
``primvars:tangents`` (float3, along ``+u``) with ``primvars:tangentSigns``
(+-1, the bitangent's handedness: ``B = sign * cross(N, T)``), the glTF
``TANGENT`` split into a float3 primvar and its sign (USD has no standard
tangent primvar; MikkTSpace's, :mod:`matshop.render.tangent_space`).
Textures are referenced relative to the layer (``./<file>``), so the folder
and the ``.usdz`` resolve the same way.

A ``.usdz`` is a zip of the ``.usda`` (first, as the format asks) and the
textures it references, written by ``Sdf.ZipFileWriter`` (64-byte aligned).
Its image formats are those of the usdz specification (PNG, JPEG, OpenEXR,
AVIF); a preset writing another is refused before anything is written.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import MaterialX as mx
import numpy as np
from pxr import Sdf, Tf, Usd, UsdGeom, UsdShade, Vt

from ..errors import MatshopError
from .obj import Mesh, tangents
from .presets import OutputSpec, Preset
from .usd_mtlx import add_materialx
from .usd_preview import add_preview_surface

#: image extensions a usdz package may hold (usdz specification, "Allowed file types")
USDZ_IMAGE_EXTENSIONS = frozenset({"png", "jpg", "jpeg", "exr", "avif"})


def prim_name(name: str) -> str:
    """``name`` as a valid USD prim name (``Tf.MakeValidIdentifier``)."""
    return Tf.MakeValidIdentifier(name)


def build_stage(
    name: str,
    mesh: Mesh,
    preset: Preset,
    outputs: Sequence[OutputSpec],
    files: dict[str, str],
    mtlx_doc: mx.Document,
) -> Usd.Stage:
    """The stage in memory: mesh, material with both render contexts, binding."""
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, UsdGeom.LinearUnits.meters)
    root = UsdGeom.Xform.Define(stage, Sdf.Path.absoluteRootPath.AppendChild(prim_name(name)))
    stage.SetDefaultPrim(root.GetPrim())
    geom = _mesh(stage, root.GetPath().AppendChild("Geom"), mesh)
    looks = UsdGeom.Scope.Define(stage, root.GetPath().AppendChild("Looks"))
    material = UsdShade.Material.Define(stage, looks.GetPath().AppendChild(prim_name(name)))
    add_preview_surface(stage, material, preset, outputs, files)
    add_materialx(stage, material, mtlx_doc)
    binding = UsdShade.MaterialBindingAPI.Apply(geom.GetPrim())
    binding.Bind(material)
    return stage


def _mesh(stage: Usd.Stage, path: Sdf.Path, mesh: Mesh) -> UsdGeom.Mesh:
    usd_mesh = UsdGeom.Mesh.Define(stage, path)
    points = Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(mesh.positions, dtype=np.float32))
    usd_mesh.CreatePointsAttr(points)
    usd_mesh.CreateExtentAttr(UsdGeom.PointBased.ComputeExtent(points))
    count = len(mesh.indices) // 3
    usd_mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(count, 3, dtype=np.int32)))
    usd_mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(mesh.indices.astype(np.int32)))
    usd_mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)  # a polygon mesh: normals as given
    usd_mesh.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(mesh.normals)))
    usd_mesh.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    primvars = UsdGeom.PrimvarsAPI(usd_mesh)
    st = np.stack([mesh.uvs[:, 0], 1.0 - mesh.uvs[:, 1]], axis=1).astype(np.float32)
    primvars.CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.vertex).Set(
        Vt.Vec2fArray.FromNumpy(st)
    )
    frame = tangents(mesh)
    primvars.CreatePrimvar("tangents", Sdf.ValueTypeNames.Float3Array, UsdGeom.Tokens.vertex).Set(
        Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(frame[:, :3]))
    )
    primvars.CreatePrimvar(
        "tangentSigns", Sdf.ValueTypeNames.FloatArray, UsdGeom.Tokens.vertex
    ).Set(Vt.FloatArray.FromNumpy(np.ascontiguousarray(frame[:, 3])))
    return usd_mesh


def referenced_files(stage: Usd.Stage) -> list[str]:
    """The texture files the stage's shaders read, in authoring order, without repeats."""
    found: dict[str, None] = {}
    for prim in stage.Traverse():
        shader = UsdShade.Shader(prim)
        if not shader:
            continue
        for shader_input in shader.GetInputs():
            value = shader_input.Get()
            if isinstance(value, Sdf.AssetPath) and value.path:
                found[value.path.removeprefix("./")] = None
    return list(found)


def check_usdz_files(files: Sequence[str]) -> None:
    """Refuse (one line) a texture a usdz package cannot hold."""
    for file in files:
        extension = file.rsplit(".", 1)[-1].lower()
        if extension not in USDZ_IMAGE_EXTENSIONS:
            allowed = ", ".join(sorted(USDZ_IMAGE_EXTENSIONS))
            raise MatshopError(
                f"--usdz: {file} is .{extension}, which a usdz package cannot hold "
                f"(allowed images: {allowed}); use a preset writing PNG or EXR"
            )


def usda_writer(stage: Usd.Stage) -> Callable[[Path], None]:
    """A writer (for :mod:`matshop.io.fileset`) of the stage as text ``.usda``."""

    def write(path: Path) -> None:
        if not stage.GetRootLayer().Export(str(path)):
            raise OSError(f"USD could not write {path.name}")

    return write


def usdz_writer(usda_name: str, textures: Sequence[str]) -> Callable[[Path], None]:
    """A writer of the ``.usdz`` package; it reads ``usda_name`` and ``textures``
    from the folder it writes into (the staging folder, where they were written first)."""

    def write(path: Path) -> None:
        folder = path.parent
        writer = Sdf.ZipFileWriter.CreateNew(str(path))
        try:
            for name in (usda_name, *textures):
                writer.AddFile(str(folder / name), name)
        except Exception:
            writer.Discard()
            raise
        writer.Save()

    return write
