"""glTF binary and MaterialX documents written by the export, and the CLI verb.

The .glb files are checked by the Khronos glTF validator (npm package
``gltf-validator``, run through ``tools/gltf-validate.mjs``) and read back
with pygltflib; the .mtlx documents by MaterialX's own ``validate()``.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import MaterialX as mx
import MaterialX.PyMaterialXGenGlsl as mx_gen_glsl
import MaterialX.PyMaterialXGenShader as mx_gen_shader
import numpy as np
import pygltflib
import pytest

from matshop.cli import main
from matshop.export.core import export_material
from matshop.export.mtlx import validate
from matshop.export.presets import builtin_preset_names, load_preset
from matshop.io.images import read_image
from matshop.io.material_io import load_material
from matshop.material import Material, Schema

ROOT = Path(__file__).resolve().parents[1]
TOOLS = ROOT / "tools"
SPHERE = ROOT.parent / "shared" / "data" / "geometry" / "sphere.obj"
SAMPLE = ROOT / "resources" / "sample"


@pytest.fixture(scope="module")
def small() -> Material:
    material, _ = load_material(SAMPLE)
    maps = {n: a[::4, ::4].copy() for n, a in material.maps.items()}
    return Material("tiles", material.schema, maps, material.sources)


def validate_gltf(path: Path) -> dict:
    """The validator's report for ``path``; skip (or fail in CI) when it is absent."""
    node = shutil.which("node")
    problem = None
    if node is None:
        problem = "node is not installed"
    elif not (TOOLS / "node_modules" / "gltf-validator").is_dir():
        problem = "gltf-validator is not installed (run: npm install --prefix tools)"
    if problem:
        if os.environ.get("MATSHOP_REQUIRE_GLTF_VALIDATOR") == "1":
            pytest.fail(f"{problem}, and MATSHOP_REQUIRE_GLTF_VALIDATOR=1")
        pytest.skip(problem)
    run = subprocess.run(
        [node, str(TOOLS / "gltf-validate.mjs"), str(path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.stdout, run.stderr
    return json.loads(run.stdout.splitlines()[0])


def _embedded_image(doc: pygltflib.GLTF2, index: int, scratch: Path) -> np.ndarray:
    image = doc.images[index]
    view = doc.bufferViews[image.bufferView]
    blob = doc.binary_blob()
    scratch.write_bytes(blob[view.byteOffset : view.byteOffset + view.byteLength])
    return read_image(scratch)[0]


@pytest.mark.parametrize("mesh_name", ["built-in sphere", "shared sphere.obj"])
def test_glb_on_a_sphere_validates_and_reads_back(
    small: Material, tmp_path: Path, mesh_name: str
) -> None:
    mesh = None  # the built-in UV sphere
    if mesh_name.startswith("shared"):
        if not SPHERE.is_file():
            pytest.skip(f"{SPHERE} not present (the shared data folder)")
        mesh = SPHERE
    summary = export_material(small, "gltf", tmp_path, glb=True, mesh=mesh)
    glb = summary.file(".glb")
    report = validate_gltf(glb)
    assert report["numErrors"] == 0 and report["numWarnings"] == 0, report["messages"]

    doc = pygltflib.GLTF2.load(str(glb))
    (material,) = doc.materials
    pbr = material.pbrMetallicRoughness
    orm = pbr.metallicRoughnessTexture.index
    assert material.occlusionTexture.index == orm  # one ORM file serves both slots
    assert material.normalTexture is not None
    primitive = doc.meshes[0].primitives[0]
    assert primitive.attributes.TANGENT is not None  # a normal map: the mesh's tangents
    assert doc.accessors[primitive.indices].count % 3 == 0
    # the embedded textures are the very pixels of the exported files
    for texture_index, suffix in (
        (pbr.baseColorTexture.index, "_baseColor.png"),
        (orm, "_occlusionRoughnessMetallic.png"),
        (material.normalTexture.index, "_normal.png"),
    ):
        source = doc.textures[texture_index].source
        assert doc.images[source].mimeType == "image/png"
        embedded = _embedded_image(doc, source, tmp_path / f"embedded{suffix}")
        written, _ = read_image(summary.file(suffix))
        assert np.array_equal(embedded, written), suffix


def test_glb_holds_only_images_its_material_reads(small: Material, tmp_path: Path) -> None:
    """No normal map: no flat normal image, no tangents; the validator reports nothing."""
    names = [n for n in small.schema.names if n != "normal"]
    plain = Material(
        "plain", Schema.from_names(names), {n: small.maps[n] for n in names}, small.sources
    )
    glb = export_material(plain, "gltf", tmp_path, glb=True).file(".glb")
    doc = pygltflib.GLTF2.load(str(glb))
    (material,) = doc.materials
    assert material.normalTexture is None
    assert doc.meshes[0].primitives[0].attributes.TANGENT is None
    used = {
        material.pbrMetallicRoughness.baseColorTexture.index,
        material.pbrMetallicRoughness.metallicRoughnessTexture.index,
        material.occlusionTexture.index,
    }
    assert {doc.textures[i].source for i in used} == set(range(len(doc.images)))
    report = validate_gltf(glb)
    assert report["numErrors"] == 0 and report["numWarnings"] == 0, report["messages"]
    assert not any(m["code"] == "UNUSED_OBJECT" for m in report["messages"]), report["messages"]


def test_anisotropic_material_gets_tangents_and_khr_anisotropy(tmp_path: Path) -> None:
    size = 16
    angle = np.deg2rad(30.0)
    frame = np.zeros((size, size, 6), dtype=np.float32)
    frame[..., 2] = 1.0  # flat normal
    frame[..., 3], frame[..., 4] = np.cos(angle), np.sin(angle)  # rotated tangent
    exponents = np.empty((size, size, 2), dtype=np.float32)
    exponents[:, : size // 2] = (100.0, 10.0)  # wider lobe across the tangent
    exponents[:, size // 2 :] = (50.0, 50.0)  # isotropic
    schema = Schema.from_names(
        ["base_color", "anisotropic_exponents", "normal"], {"normal": "normal_tangent"}
    )
    base = np.full((size, size, 3), 0.5, dtype=np.float32)
    maps = {"base_color": base, "anisotropic_exponents": exponents, "normal": frame}
    summary = export_material(Material("brushed", schema, maps), "gltf", tmp_path, glb=True)
    glb = summary.file(".glb")
    report = validate_gltf(glb)
    assert report["numErrors"] == 0, report["messages"]

    doc = pygltflib.GLTF2.load(str(glb))
    assert "KHR_materials_anisotropy" in doc.extensionsUsed
    assert doc.meshes[0].primitives[0].attributes.TANGENT is not None
    extension = doc.materials[0].extensions["KHR_materials_anisotropy"]
    texels = _embedded_image(
        doc, doc.textures[extension["anisotropyTexture"]["index"]].source, tmp_path / "a.png"
    )
    direction = texels[..., :2] * 2 - 1
    strength = texels[..., 2]
    # isotropic half: no anisotropy
    assert np.all(strength[:, size // 2 :] == 0.0)
    # anisotropic half: stretched across the tangent (nv < nu), as glTF defines
    # alpha_t = mix(alpha_b, 1, strength^2) with alpha = sqrt(2 / (n + 2))
    aniso_dir = direction[:, : size // 2]
    across = np.array([-np.sin(angle), np.cos(angle)])
    assert np.abs(aniso_dir @ across - 1).max() < 0.02
    alpha_t, alpha_b = np.sqrt(2 / 12), np.sqrt(2 / 102)
    s = strength[:, : size // 2]
    np.testing.assert_allclose(alpha_b + (1 - alpha_b) * s**2, alpha_t, atol=0.01)


#: each model's inputs for (base color, metallic, roughness, normal, emission), per its nodedef
MODEL_INPUTS = {
    "open_pbr_surface": (
        "base_color",
        "base_metalness",
        "specular_roughness",
        "geometry_normal",
        "emission_color",
    ),
    "standard_surface": (
        "base_color",
        "metalness",
        "specular_roughness",
        "normal",
        "emission_color",
    ),
    "gltf_pbr": ("base_color", "metallic", "roughness", "normal", "emissive"),
}
#: the parameters those inputs read, and where each preset stores them
PARAMETERS = ("base_color", "metallic", "roughness", "normal", "emissive")


def _feeding(doc: mx.Document, shader: mx.Node, name: str) -> mx.Node:
    port = shader.getInput(name)
    graph = doc.getNodeGraph(port.getNodeGraphString())
    return graph.getOutput(port.getOutputString()).getConnectedNode()


def _image_of(node: mx.Node) -> tuple[mx.Node, list[str]]:
    """The image node upstream of ``node`` through single-input nodes, and their categories."""
    path = []
    while node.getCategory() != "image":
        path.append(node.getCategory())
        node = next(i for i in node.getInputs() if i.getConnectedNode() is not None)
        node = node.getConnectedNode()
    return node, path


def glsl_pixel_shader(doc: mx.Document) -> mx_gen_shader.Shader:
    """MaterialX's GLSL generator on the document's material (raises if it cannot)."""
    generator = mx_gen_glsl.GlslShaderGenerator.create()
    context = mx_gen_shader.GenContext(generator)
    context.registerSourceCodeSearchPath(mx.getDefaultDataSearchPath())
    (renderable,) = mx_gen_shader.findRenderableElements(doc)
    return generator.generate(renderable.getName(), renderable, context)


@pytest.mark.parametrize(
    ("preset_name", "model"),
    [(p, "open_pbr_surface") for p in builtin_preset_names()]
    + [(p, m) for p in ("unreal", "unity_urp") for m in ("standard_surface", "gltf_pbr")],
)
def test_materialx_document_validates_compiles_and_reads_the_exported_files(
    preset_name: str, model: str, small: Material, tmp_path: Path
) -> None:
    emissive = Material(
        small.name,
        Schema.from_names([*small.schema.names, "emissive"]),
        {**small.maps, "emissive": small.maps["base_color"] * 0.5},
        small.sources,
    )
    summary = export_material(emissive, preset_name, tmp_path, mtlx=True, mtlx_shader=model)
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(summary.file(".mtlx")))
    valid, message = validate(doc)
    assert valid, message
    files = {
        node.getInput("file").getValueString()
        for node in doc.traverseTree()
        if isinstance(node, mx.Node) and node.getCategory() == "image"
    }
    written = {f.path.name for f in summary.files if f.kind == "texture"}
    assert files and files <= written
    (shader,) = [n for n in doc.getNodes() if n.getCategory() == model]
    preset = load_preset(preset_name)
    for name, param in zip(MODEL_INPUTS[model], PARAMETERS, strict=True):
        image, path = _image_of(_feeding(doc, shader, name))
        # the file and channel the preset put the parameter in (the preset's own table)
        holder = next(o for o in preset.outputs if param in o.sources)
        assert image.getInput("file").getValueString() == holder.file_for("tiles", preset_name)
        srgb = image.getInput("file").getColorSpace() == "srgb_texture"
        assert srgb == (param in ("base_color", "emissive") and holder.color_space == "srgb")
        if param == "roughness":  # Unity stores smoothness: the document inverts it back
            assert ("invert" in path) == preset_name.startswith("unity")
        if param == "normal":  # DirectX green is flipped before normalmap
            assert path[0] == "normalmap"
            assert ("multiply" in path) == (preset.normal_convention == "directx")
    weights = {"open_pbr_surface": "emission_luminance", "standard_surface": "emission"}
    if model in weights:  # both default to 0: no emission unless set
        assert shader.getInput(weights[model]).getValue() == 1.0
    base = {"open_pbr_surface": "base_weight", "standard_surface": "base"}
    if model in base:
        assert shader.getInput(base[model]).getValue() == 1.0
    assert (shader.getInput("occlusion") is not None) == (model == "gltf_pbr")

    # the round trip: the document re-imports with the source's values (8 bits: within a code)
    back, _ = load_material(summary.file(".mtlx"))
    expected = set(PARAMETERS) | ({"ao"} if model == "gltf_pbr" else set())
    assert expected <= set(back.schema.names)
    for param in back.schema.names:
        error = np.abs(back.maps[param].astype(np.float64) - emissive.maps[param]).max()
        assert error < (2.5 if param == "normal" else 1.01) / 255, param
    assert back.sources["normal"]["convention"] == preset.normal_convention

    generated = glsl_pixel_shader(doc)
    pixel = generated.getStage(mx_gen_shader.PIXEL_STAGE)
    assert "void main" in pixel.getSourceCode()
    textures = {
        port.getValue().getValueString()
        for block in pixel.getUniformBlocks().values()
        for port in (block[i] for i in range(block.size()))
        if port.getType().getName() == "filename" and port.getValue() is not None
    }
    assert textures == files  # every texture the document reads is a sampler of the shader


def test_cli_export_writes_and_summarises(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    out = tmp_path / "out"
    args = ["export", str(SAMPLE), str(out), "--preset", "unreal", "--size", "128"]
    assert main([*args, "--glb", "--mtlx"]) == 0
    printed = capsys.readouterr().out
    for name in ("tiles_BaseColor.png", "tiles_Normal.png", "tiles_ORM.png", "tiles.glb"):
        assert name in printed and (out / name).is_file()
    assert "128x128" in printed
    assert main(args) == 2  # exists: needs --force
    assert "--force" in capsys.readouterr().err
    assert main([*args, "--force"]) == 0


def test_cli_offers_every_shading_model() -> None:
    from matshop.cli.verbs.export import SHADING_MODEL_NAMES
    from matshop.export.mtlx import DEFAULT_SHADING_MODEL, SHADING_MODELS

    assert set(SHADING_MODEL_NAMES) == set(SHADING_MODELS)
    assert SHADING_MODEL_NAMES[0] == DEFAULT_SHADING_MODEL


def test_info_reads_a_mtlx_and_refuses_what_it_cannot(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    out = tmp_path / "out"
    args = ["export", str(SAMPLE), str(out), "--preset", "unreal", "--size", "64", "--mtlx"]
    assert main(args) == 0
    capsys.readouterr()
    assert main(["info", str(out / "tiles.mtlx")]) == 0
    info = capsys.readouterr().out
    assert "tiles_ORM.png" in info and "directx normals (the MaterialX graph)" in info
    text = (out / "tiles.mtlx").read_text()
    odd = text.replace("<extract ", "<noise3d ").replace("</extract>", "</noise3d>")
    (out / "odd.mtlx").write_text(odd)
    (out / "cut.mtlx").write_text(text[: len(text) // 2])
    for name, problem in (("odd.mtlx", "cannot read node"), ("cut.mtlx", "not a MaterialX")):
        assert main(["info", str(out / name)]) == 2
        err = capsys.readouterr().err.strip()
        assert problem in err and name in err and "\n" not in err, err


def test_cli_errors_are_one_line(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    assert main(["export", str(SAMPLE), str(tmp_path), "--preset", "frostbite"]) == 2
    err = capsys.readouterr().err.strip()
    assert "unknown preset 'frostbite'" in err and "\n" not in err
    strict = tmp_path / "strict.json"
    strict.write_text(
        '{"name": "disp", "maps": [{"channel": "height", "bitDepth": 16, "srcMapName": "height"}]}'
    )
    args = ["export", str(SAMPLE), str(tmp_path / "o"), "--preset-file", str(strict)]
    assert main([*args, "--strict"]) == 2
    assert "height" in capsys.readouterr().err
    assert main(args) == 0
    assert "warning: height: the material has no height" in capsys.readouterr().out


def test_cli_lists_presets(capsys: pytest.CaptureFixture) -> None:
    assert main(["export", "--list-presets"]) == 0
    listed = capsys.readouterr().out
    for name in builtin_preset_names():
        assert name in listed


def test_bad_mesh_is_refused_before_anything_is_written(small: Material, tmp_path: Path) -> None:
    from matshop.errors import MatshopError

    flat = tmp_path / "no_uvs.obj"
    flat.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    out = tmp_path / "out"
    with pytest.raises(MatshopError, match="texture coordinates"):
        export_material(small, "gltf", out, glb=True, mesh=flat)
    garbled = tmp_path / "garbled.obj"
    garbled.write_text("v 0 0 0\nvt 0 0\nf 1/1 2/1 9/1\n")
    with pytest.raises(MatshopError, match="line 3"):
        export_material(small, "gltf", out, glb=True, mesh=garbled)
    assert not out.exists()
