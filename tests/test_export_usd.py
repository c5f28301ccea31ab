"""USD export: USD's own validators, reading the stage back with pxr, and the
texture files it points at read independently with OpenImageIO.

Independent truths: the validators of ``pxr.UsdValidation`` (those behind
``usdchecker``), MaterialX's own node library, the source material's pixels,
the OBJ file's own ``v``/``vt`` records, and the sphere's closed-form tangent.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest
from pxr import Sdf, Usd, UsdGeom, UsdShade
from scipy.spatial import cKDTree

from matshop.cli import main
from matshop.errors import MatshopError
from matshop.export.core import export_material
from matshop.export.presets import builtin_preset_names, load_preset
from matshop.export.usd_check import materialx_id_problems, validate_usd
from matshop.io.material_io import load_material
from matshop.material import Material

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"
SPHERE = ROOT.parent / "shared" / "data" / "geometry" / "sphere.obj"
#: parameter fed to each UsdPreviewSurface input
SURFACE = {
    "diffuseColor": "base_color",
    "metallic": "metallic",
    "roughness": "roughness",
    "occlusion": "ao",
    "normal": "normal",
}


@pytest.fixture(scope="module")
def small() -> Material:
    material, _ = load_material(SAMPLE)
    maps = {n: a[::8, ::8].copy() for n, a in material.maps.items()}
    return Material("tiles", material.schema, maps, material.sources)


def read_texels(path: Path) -> np.ndarray:
    """The file's values in [0, 1] by OpenImageIO itself (alpha kept unassociated)."""
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)
    buf = oiio.ImageBuf(str(path), 0, 0, config)
    assert not buf.has_error, buf.geterror()
    return buf.get_pixels(oiio.FLOAT)


def texture_reading(surface: UsdShade.Shader, name: str) -> tuple[UsdShade.Shader, str]:
    """The UsdUVTexture feeding ``surface``'s input ``name`` and its output (r, g, b, a, rgb)."""
    source, output, _ = surface.GetInput(name).GetConnectedSource()
    texture = UsdShade.Shader(source.GetPrim())
    assert texture.GetIdAttr().Get() == "UsdUVTexture"
    return texture, output


def input_or(shader: UsdShade.Shader, name: str, fallback: tuple) -> np.ndarray:
    """An input's authored value, else the spec's fallback."""
    value = shader.GetInput(name)
    return np.asarray(value.Get() if value else fallback, dtype=np.float64)


def errors_and_warnings(path: Path) -> tuple[list[str], set[str]]:
    findings = validate_usd(path)
    return [str(f) for f in findings if f.severity == "Error"], {
        f.name for f in findings if f.severity == "Warn"
    }


@pytest.mark.parametrize("preset_name", builtin_preset_names())
def test_every_preset_validates_and_reads_back_the_source(
    preset_name: str, small: Material, tmp_path: Path
) -> None:
    preset = load_preset(preset_name)
    summary = export_material(small, preset, tmp_path, usdz=True)
    usda, usdz = summary.file(".usda"), summary.file(".usdz")
    for path in (usda, usdz):
        errors, warnings = errors_and_warnings(path)
        assert errors == [], path.name
        # the one warning: DirectX normals flip green through scale (2, -2, 2, 1)
        expected = {"NonCompliantScaleValues"} if preset.normal_convention == "directx" else set()
        assert warnings == expected, path.name

    stage = Usd.Stage.Open(str(usda))
    (mesh_prim,) = [p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]
    material, _ = UsdShade.MaterialBindingAPI(mesh_prim).ComputeBoundMaterial()
    surface = material.ComputeSurfaceSource()[0]
    assert surface.GetIdAttr().Get() == "UsdPreviewSurface"
    mtlx_surface = material.ComputeSurfaceSource("mtlx")[0]
    assert mtlx_surface.GetIdAttr().Get() == "ND_open_pbr_surface_surfaceshader"

    for name, param in SURFACE.items():
        texture, channel = texture_reading(surface, name)
        file = texture.GetInput("file").Get().path
        space = texture.GetInput("sourceColorSpace").Get()
        assert space == ("sRGB" if param == "base_color" else "raw"), (name, space)
        st_source = texture.GetInput("st").GetConnectedSource()[0]
        reader = UsdShade.Shader(st_source.GetPrim())
        assert reader.GetIdAttr().Get() == "UsdPrimvarReader_float2"
        assert reader.GetInput("varname").Get() == "st"
        scale = input_or(texture, "scale", (1, 1, 1, 1))
        bias = input_or(texture, "bias", (0, 0, 0, 0))
        texels = read_texels(tmp_path / file.removeprefix("./"))
        picks = [0, 1, 2] if channel == "rgb" else ["rgba".index(channel)]
        value = texels[..., picks] * scale[picks] + bias[picks]  # what the shader reads
        source = small.maps[param].astype(np.float64)
        if param == "normal":
            # an exported 8-bit normal keeps each component within a code of 2 / 255
            assert np.abs(value - source[..., :3]).max() < 2.5 / 255, name
        else:
            # dithered 8-bit, or finer: within one code
            assert np.abs(value - source[..., : len(picks)]).max() < 1.01 / 255, name

    # the round trip: both files re-import through load_material with the source's values
    for path in (usda, usdz):
        back, report = load_material(path)
        assert back.size == small.size and set(SURFACE.values()) <= set(back.schema.names)
        for param in SURFACE.values():
            error = np.abs(back.maps[param].astype(np.float64) - small.maps[param]).max()
            assert error < (2.5 if param == "normal" else 1.01) / 255, (path.name, param)
        convention = back.sources["normal"]["convention"]
        assert convention == preset.normal_convention


@pytest.mark.parametrize("model", ["standard_surface", "gltf_pbr"])
def test_other_materialx_models_validate_as_the_mtlx_context(
    model: str, small: Material, tmp_path: Path
) -> None:
    summary = export_material(small, "unity_hdrp", tmp_path, usd=True, mtlx_shader=model)
    errors, warnings = errors_and_warnings(summary.file(".usda"))
    assert errors == [] and warnings == set()
    stage = Usd.Stage.Open(str(summary.file(".usda")))
    material = UsdShade.Material(stage.GetPrimAtPath("/tiles/Looks/tiles"))
    assert material.ComputeSurfaceSource("mtlx")[0].GetIdAttr().Get() == f"ND_{model}_surfaceshader"


def test_usdz_holds_the_usda_first_and_the_very_texture_files(
    small: Material, tmp_path: Path
) -> None:
    summary = export_material(small, "unity_urp", tmp_path, usdz=True)
    package = Sdf.ZipFile.Open(str(summary.file(".usdz")))
    names = list(package.GetFileNames())
    assert names[0] == "tiles.usda"
    stage = Usd.Stage.Open(str(summary.file(".usda")))
    read = {
        UsdShade.Shader(p).GetInput("file").Get().path.removeprefix("./")
        for p in stage.Traverse()
        if UsdShade.Shader(p) and UsdShade.Shader(p).GetIdAttr().Get() == "UsdUVTexture"
    }
    assert set(names[1:]) == read  # the textures the shaders read, nothing else
    for name in names:
        assert bytes(package.GetFile(name)) == (tmp_path / name).read_bytes(), name


def test_mesh_on_a_users_obj_matches_the_file(small: Material, tmp_path: Path) -> None:
    if not SPHERE.is_file():
        pytest.skip("shared geometry not present")
    summary = export_material(small, "gltf", tmp_path, usd=True, mesh=SPHERE)
    stage = Usd.Stage.Open(str(summary.file(".usda")))
    assert UsdGeom.GetStageUpAxis(stage) == "Y"
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/tiles/Geom"))
    points = np.asarray(mesh.GetPointsAttr().Get())
    st = np.asarray(UsdGeom.PrimvarsAPI(mesh).GetPrimvar("st").Get())
    normals = np.asarray(mesh.GetNormalsAttr().Get())
    assert UsdGeom.PrimvarsAPI(mesh).GetPrimvar("st").GetInterpolation() == "vertex"

    # every USD vertex is a corner of the OBJ file (position, uv with OBJ's = USD's v up,
    # normal), and every corner is a USD vertex
    v, vt, vn, corners = [], [], [], set()
    for line in SPHERE.read_text().splitlines():
        parts = line.split()
        if parts[:1] == ["v"]:
            v.append([float(x) for x in parts[1:4]])
        elif parts[:1] == ["vt"]:
            vt.append([float(x) for x in parts[1:3]])
        elif parts[:1] == ["vn"]:
            n = np.array([float(x) for x in parts[1:4]])
            vn.append(list(n / np.linalg.norm(n)))
        elif parts[:1] == ["f"]:
            for corner in parts[1:]:
                a, b, c = (int(i) - 1 for i in corner.split("/"))
                corners.add((a, b, c))
    obj = np.array([v[a] + vt[b] + vn[c] for a, b, c in corners])
    usd = np.concatenate([points, st, normals], axis=1)
    assert cKDTree(obj).query(usd)[0].max() < 1e-5
    assert cKDTree(usd).query(obj)[0].max() < 1e-5

    # counter-clockwise triangles facing their normals (USD's rightHanded default)
    triangles = np.asarray(mesh.GetFaceVertexIndicesAttr().Get()).reshape(-1, 3)
    corners_xyz = points[triangles]
    face = np.cross(corners_xyz[:, 1] - corners_xyz[:, 0], corners_xyz[:, 2] - corners_xyz[:, 0])
    facing = np.einsum("ij,ij->i", face, normals[triangles].mean(axis=1))
    assert (facing > 0).mean() > 0.99


def test_sphere_tangents_follow_u_and_st_puts_the_image_top_up(
    small: Material, tmp_path: Path
) -> None:
    summary = export_material(small, "gltf", tmp_path, usd=True)  # the built-in UV sphere
    stage = Usd.Stage.Open(str(summary.file(".usda")))
    primvars = UsdGeom.PrimvarsAPI(stage.GetPrimAtPath("/tiles/Geom"))
    points = np.asarray(UsdGeom.Mesh(primvars.GetPrim()).GetPointsAttr().Get())
    st = np.asarray(primvars.GetPrimvar("st").Get())
    tangent = np.asarray(primvars.GetPrimvar("tangents").Get())
    signs = np.asarray(primvars.GetPrimvar("tangentSigns").Get())
    # USD's st origin is the image's lower-left: the north pole (y = 1) is the image top
    north = points[:, 1] > 0.999
    assert north.any() and np.all(st[north, 1] > 0.99)
    # closed form: u runs with the azimuth phi, d/dphi (sin t cos p, cos t, -sin t sin p)
    side = np.abs(points[:, 1]) < 0.9
    phi = 2 * np.pi * st[side, 0]
    expected = np.stack([-np.sin(phi), np.zeros_like(phi), -np.cos(phi)], axis=1)
    assert np.abs(tangent[side] - expected).max() < 0.05
    assert set(np.unique(signs)) <= {-1.0, 1.0}


def test_validators_catch_what_they_should(small: Material, tmp_path: Path) -> None:
    """The checks above can fail: a package with a TGA, and a MaterialX input of the wrong type."""
    summary = export_material(small, "gltf", tmp_path, usd=True)
    bad = tmp_path / "bad.usdz"
    writer = Sdf.ZipFileWriter.CreateNew(str(bad))
    writer.AddFile(str(summary.file(".usda")), "tiles.usda")
    tga = tmp_path / "x.tga"
    buf = oiio.ImageBuf(oiio.ImageSpec(4, 4, 3, "uint8"))
    assert buf.write(str(tga))
    writer.AddFile(str(tga), "x.tga")
    writer.Save()
    errors, _ = errors_and_warnings(bad)
    assert any("FileExtension" in e or "tga" in e for e in errors), errors

    stage = Usd.Stage.Open(str(summary.file(".usda")))
    (image,) = [
        UsdShade.Shader(p)
        for p in stage.Traverse()
        if UsdShade.Shader(p) and p.GetName() == "baseColor_color3"
    ]
    assert materialx_id_problems(image) == []
    image.GetPrim().RemoveProperty("inputs:file")
    image.CreateInput("file", Sdf.ValueTypeNames.String)  # MaterialX's is a filename: an asset
    image.CreateInput("gain", Sdf.ValueTypeNames.Float)  # no such input
    problems = materialx_id_problems(image)
    assert len(problems) == 2 and "'file'" in problems[0] and "'gain'" in problems[1]


def test_usdz_refuses_images_it_cannot_hold(small: Material, tmp_path: Path) -> None:
    preset = tmp_path / "tga.json"
    preset.write_text(
        '{"name": "tga", "maps": [{"channel": "color", "fileFormat": "tga",'
        ' "srcMapName": "base_color"}]}'
    )
    out = tmp_path / "out"
    with pytest.raises(MatshopError, match="usdz package cannot hold"):
        export_material(small, load_preset(path=preset), out, usdz=True)
    assert not out.exists()


def test_cli_writes_usd(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    out = tmp_path / "out"
    args = ["export", str(SAMPLE), str(out), "--preset", "unreal", "--size", "64", "--usdz"]
    assert main([*args, "--mtlx", "--mtlx-shader", "standard_surface"]) == 0
    printed = capsys.readouterr().out
    for name in ("tiles.usda", "tiles.usdz", "tiles_ORM.png", "tiles.mtlx"):
        assert name in printed and (out / name).is_file()
    assert "MaterialX standard_surface" in printed
    assert "<standard_surface" in (out / "tiles.mtlx").read_text()
    assert main(["info", str(out / "tiles.usdz")]) == 0
    info = capsys.readouterr().out
    assert "tiles.usdz[tiles_ORM.png]" in info and "directx normals" in info
    empty = tmp_path / "empty.usda"
    empty.write_text('#usda 1.0\ndef Xform "x"\n{\n}\n')
    assert main(["info", str(empty)]) == 2
    err = capsys.readouterr().err.strip()
    assert "no Material" in err and "empty.usda" in err and "\n" not in err
    assert (
        main(
            [
                "export",
                str(SAMPLE),
                str(tmp_path / "o2"),
                "--preset",
                "gltf",
                "--mesh",
                str(tmp_path / "m.obj"),
            ]
        )
        == 2
    )
    assert "--mesh is only used with" in capsys.readouterr().err


def test_a_usd_missing_its_texture_is_refused_in_one_line(small: Material, tmp_path: Path) -> None:
    summary = export_material(small, "gltf", tmp_path, usd=True)
    with pytest.raises(MatshopError, match="larger than|pixels"):
        load_material(summary.file(".usda"), max_pixels=16)  # the limit reaches the textures
    summary.file("_normal.png").unlink()
    with pytest.raises(MatshopError, match="tiles_normal.png is missing"):
        load_material(summary.file(".usda"))
