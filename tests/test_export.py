"""Export presets: every preset round-trips through files and the generic importer.

The truth a round trip is held to is independent of the exporter: the files
are read back by :func:`matshop.io.material_io.load_material` (texture-set
detection by name, ORM / mask-map unpacking, normal decoding) and compared
with the material that was exported, within what quantisation allows.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from matshop.errors import MatshopError
from matshop.export.core import export_material
from matshop.export.presets import builtin_preset_names, load_preset
from matshop.export.reimport import reimport
from matshop.export.resize import resize_material
from matshop.io.images import read_image
from matshop.io.material_io import load_material
from matshop.material import Material, Schema

ROOT = Path(__file__).resolve().parents[1]
CHESSBOARD = ROOT.parent / "shared" / "data" / "chessboard"
SAMPLE = ROOT / "resources" / "sample"

#: one 8-bit code; a normal whose three encoded components are each within a
#: code of the truth is within this angle of it (|dn| < sqrt(3) * 2 / 255)
CODE8 = 1 / 255
NORMAL_CODE8_DEG = np.degrees(np.sqrt(3) * 2 / 255)
ENGINE_PRESETS = ("unreal", "unity_urp", "unity_hdrp", "gltf", "godot")


@pytest.fixture(scope="module", params=["sample", "chessboard"])
def source(request) -> Material:
    """The bundled sample and the real chessboard set, resampled to 384 in edit
    space so their values are off the 8-bit grid: quantisation is exercised."""
    if request.param == "chessboard" and not CHESSBOARD.is_dir():
        pytest.skip(f"{CHESSBOARD} not present (the shared data folder)")
    material, _ = load_material(SAMPLE if request.param == "sample" else CHESSBOARD)
    resized = resize_material(material, (384, 384))
    for name in material.maps:  # the premise: off the grid
        codes = resized.maps[name] * 255
        assert np.abs(codes - np.rint(codes)).max() > 0.1, name
    return resized


@pytest.fixture(scope="module")
def sample() -> Material:
    """The bundled sample as loaded: 8-bit codes exactly, with occlusion."""
    return load_material(SAMPLE)[0]


def _angles_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # atan2 of |a x b| and a.b stays accurate for tiny angles (arccos does not)
    a, b = a[..., :3].astype(np.float64), b[..., :3].astype(np.float64)
    sine = np.linalg.norm(np.cross(a, b), axis=-1)
    return np.degrees(np.arctan2(sine, np.sum(a * b, axis=-1)))


def _worst(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a.astype(np.float64) - b.astype(np.float64)).max())


def test_builtin_presets_load_and_follow_engine_conventions() -> None:
    names = builtin_preset_names()
    assert set(ENGINE_PRESETS) | {"raw"} <= set(names)
    conventions = {n: load_preset(n).normal_convention for n in names}
    assert conventions["unreal"] == "directx"
    assert {conventions[n] for n in ("gltf", "godot", "unity_urp", "unity_hdrp")} == {"opengl"}
    orm = load_preset("unreal").output("ORM")
    assert [(c.dest, c.source) for c in orm.channels] == [
        (0, "ao"),
        (1, "roughness"),
        (2, "metallic"),
    ]
    mask = load_preset("unity_hdrp").output("MaskMap")
    assert mask.channels[3].source == "roughness" and mask.channels[3].transform == "invert"
    assert load_preset("unreal").output("BaseColor").color_space == "srgb"


@pytest.mark.parametrize("preset_name", ENGINE_PRESETS)
def test_engine_preset_round_trip_within_one_code(
    preset_name: str, source: Material, tmp_path: Path
) -> None:
    preset = load_preset(preset_name)
    summary = export_material(source, preset, tmp_path, name="mat")
    assert all(f.path.is_file() for f in summary.files)
    back, _ = load_material(tmp_path, normal_convention=preset.normal_convention)
    for name in ("base_color", "roughness", "metallic"):
        worst = _worst(source.maps[name], back.maps[name])
        assert worst < CODE8, f"{preset_name} {name}: off by {worst * 255:.3f} codes"
    angle = _angles_deg(source.maps["normal"], back.maps["normal"]).max()
    assert angle < NORMAL_CODE8_DEG, f"{preset_name} normal: {angle:.3f} deg"
    if "ao" in source.schema:
        assert _worst(source.maps["ao"], back.maps["ao"]) < CODE8
    else:  # filled with the engine default and said so
        assert np.all(back.maps["ao"] == 1.0)
        assert any("no ao" in w for w in summary.warnings)
    # the preset's own inverse reads the same numbers as the generic importer
    mine = reimport(tmp_path, preset, "mat")
    for name in ("base_color", "roughness", "metallic"):
        np.testing.assert_allclose(mine.maps[name], back.maps[name], atol=1e-6)


def test_directx_normals_have_green_flipped(source: Material, tmp_path: Path) -> None:
    export_material(source, "unreal", tmp_path / "dx", name="m")
    export_material(source, "gltf", tmp_path / "gl", name="m")
    dx, _ = read_image(tmp_path / "dx" / "m_Normal.png")
    gl, _ = read_image(tmp_path / "gl" / "m_normal.png")
    # rounding of a value that lands on a half code may go either way: one code
    assert _worst(dx[..., 1], 1.0 - gl[..., 1]) <= CODE8 + 1e-6
    assert _worst(dx[..., [0, 2]], gl[..., [0, 2]]) <= CODE8 + 1e-6
    # and the flip is real: the chessboard's normals are not flat in y
    assert np.abs(gl[..., 1] - 0.5).max() > 5 * CODE8


def test_raw_preset_round_trip_is_tighter(source: Material, tmp_path: Path) -> None:
    export_material(source, "raw", tmp_path, name="mat")
    back, _ = load_material(tmp_path, normal_convention="opengl")
    assert _worst(source.maps["base_color"], back.maps["base_color"]) <= 0.5 / 65535 + 1e-7
    for name in ("roughness", "metallic"):
        assert _worst(source.maps[name], back.maps[name]) == 0.0  # float EXR: exact
    assert _angles_deg(source.maps["normal"], back.maps["normal"]).max() < 0.01


def test_sixteen_bit_and_half_outputs_are_tighter_than_8bit(
    source: Material, tmp_path: Path
) -> None:
    user = tmp_path / "deep.toml"
    user.write_text(
        """
name = "deep"
normalConvention = "opengl"
[[maps]]
channel = "basecolor"
fileFormat = "png"
bitDepth = 16
srcMapName = "base_color"
[[maps]]
channel = "orm"
fileFormat = "png"
bitDepth = 16
channels = [
  {destChannel = "R", srcMapName = "ao"},
  {destChannel = "G", srcMapName = "roughness"},
  {destChannel = "B", srcMapName = "metallic"},
]
[[maps]]
channel = "normal"
fileFormat = "exr"
bitDepth = "half"
srcMapName = "normal"
"""
    )
    preset = load_preset(path=user)
    export_material(source, preset, tmp_path / "out", name="mat")
    back, _ = load_material(tmp_path / "out", normal_convention="opengl")
    for name in ("base_color", "roughness", "metallic"):
        assert _worst(source.maps[name], back.maps[name]) <= 0.5 / 65535 + 1e-7
    # half floats near 1 have a spacing of 2^-11: far below an 8-bit code
    assert _angles_deg(source.maps["normal"], back.maps["normal"]).max() < NORMAL_CODE8_DEG / 4


@pytest.mark.parametrize("preset_name", ("unity_urp", "unity_hdrp"))
def test_smoothness_in_alpha_survives_exactly(
    preset_name: str, sample: Material, tmp_path: Path
) -> None:
    # smoothness 0 (roughness 1) in a quarter of the map: premultiplied alpha
    # would wipe metallic (and occlusion) there
    roughness = sample.maps["roughness"].copy()
    roughness[:128, :128] = 1.0
    metallic = sample.maps["metallic"].copy()
    metallic[:128, :128] = 200 / 255
    maps = dict(sample.maps, roughness=roughness, metallic=metallic)
    material = Material("m", sample.schema, maps, sample.sources)
    export_material(material, preset_name, tmp_path, name="m")
    back, _ = load_material(tmp_path, normal_convention="opengl")
    for name in ("roughness", "metallic", "ao"):
        codes_in = np.rint(material.maps[name] * 255)
        codes_out = np.rint(back.maps[name] * 255)
        assert np.array_equal(codes_in, codes_out), f"{name} changed"
    packed = next(tmp_path.glob("m_M*.png"))
    rgba, info = read_image(packed)
    assert info.channels == 4
    assert np.all(rgba[:128, :128, 3] == 0.0) and np.all(rgba[:128, :128, 0] == 200 / 255)


def test_user_preset_in_json_with_constants_and_defaults(sample: Material, tmp_path: Path) -> None:
    user = tmp_path / "studio.json"
    user.write_text(
        """{"name": "studio", "fileName": "T_{material}_{channel}.{ext}",
        "maps": [{"channel": "RMA", "fileFormat": "tga", "bitDepth": 8, "channels": [
            {"destChannel": "R", "srcMapName": "roughness"},
            {"destChannel": "G", "srcMapName": "metallic"},
            {"destChannel": "B", "srcMapName": "height", "default": 0.25}]}]}"""
    )
    summary = export_material(sample, load_preset(path=user), tmp_path / "out")
    (written,) = summary.files
    assert written.path.name == "T_tiles_RMA.tga"
    pixels, _ = read_image(written.path)
    assert np.array_equal(
        np.rint(pixels[..., 0] * 255), np.rint(sample.maps["roughness"][..., 0] * 255)
    )
    assert np.all(np.rint(pixels[..., 2] * 255) == np.rint(0.25 * 255))
    assert summary.warnings == ["RMA: the material has no height; filled with (0.25)"]


@pytest.mark.parametrize(
    ("text", "complaint"),
    [
        ("{not json", "not a valid preset file"),
        ('{"name": "x", "maps": []}', "non-empty list 'maps'"),
        (
            '{"name": "x", "maps": [{"channel": "a", "fileFormat": "bmp", "srcMapName": "ao"}]}',
            "fileFormat",
        ),
        (
            '{"name": "x", "maps": [{"channel": "a", "fileFormat": "exr", "bitDepth": 8, '
            '"srcMapName": "ao"}]}',
            "cannot hold bitDepth",
        ),
        (
            '{"name": "x", "maps": [{"channel": "a", "channels": [{"destChannel": "G", '
            '"srcMapName": "ao"}]}]}',
            "without gaps",
        ),
        (
            '{"name": "x", "fileName": "{material}_{chanel}.{ext}", "maps": [{"channel": "a", '
            '"srcMapName": "ao"}]}',
            "unknown fields",
        ),
    ],
)
def test_bad_user_presets_are_one_line_errors(text: str, complaint: str, tmp_path: Path) -> None:
    user = tmp_path / "bad.json"
    user.write_text(text)
    with pytest.raises(MatshopError, match=complaint) as caught:
        load_preset(path=user)
    assert str(user) in str(caught.value) and "\n" not in str(caught.value)


def test_unknown_preset_names_the_known_ones() -> None:
    with pytest.raises(MatshopError, match="unknown preset 'cryengine'.*unreal"):
        load_preset("cryengine")


def test_export_resizes_to_power_of_two(sample: Material, tmp_path: Path) -> None:
    summary = export_material(sample, "godot", tmp_path, size=128)
    assert summary.size == (128, 128)
    for written in summary.files:
        pixels, _ = read_image(written.path)
        assert pixels.shape[:2] == (128, 128)
    with pytest.raises(MatshopError, match="power of two"):
        export_material(sample, "godot", tmp_path / "x", size=100)


def test_materials_built_in_memory_export_too(tmp_path: Path) -> None:
    """Any Material works (a flattened document, say), not only loaded sets."""
    rng = np.random.default_rng(1)
    schema = Schema.from_names(["base_color", "roughness", "emissive"])
    maps = {
        "base_color": rng.random((64, 64, 3), dtype=np.float32),
        "roughness": rng.random((64, 64, 1), dtype=np.float32),
        "emissive": rng.random((64, 64, 3), dtype=np.float32),
    }
    summary = export_material(Material("made", schema, maps), "unreal", tmp_path)
    names = sorted(f.path.name for f in summary.files)
    assert names == ["made_BaseColor.png", "made_Emissive.png", "made_Normal.png", "made_ORM.png"]
    assert sorted(summary.warnings) == [
        "Normal: the material has no normal; filled with (0, 0, 1)",
        "ORM: the material has no ao; filled with (1)",
        "ORM: the material has no metallic; filled with (0)",
    ]
    back = reimport(tmp_path, "unreal", "made")
    assert _worst(back.maps["emissive"], maps["emissive"]) < CODE8
    assert _angles_deg(back.maps["normal"], np.array([0, 0, 1.0])).max() < NORMAL_CODE8_DEG


def test_raw_preset_keeps_sampled_distributions_and_warns_about_clipping(
    sample: Material, tmp_path: Path
) -> None:
    from matshop.derive import with_sampled_distribution

    small = Material("d", sample.schema, {n: a[:16, :16].copy() for n, a in sample.maps.items()})
    material = with_sampled_distribution(small)
    summary = export_material(material, "raw", tmp_path / "raw")
    back, _ = load_material(tmp_path / "raw", normal_convention="opengl")
    assert back.maps["distribution"].shape[2] == material.maps["distribution"].shape[2] > 4
    assert _worst(back.maps["distribution"], material.maps["distribution"]) == 0.0
    assert summary.warnings == []
    # height outside [0, 1] cannot go into a 16-bit PNG: clipped, and said so
    schema = Schema.from_names(["height"])
    height = np.linspace(-0.5, 1.5, 64, dtype=np.float32).reshape(8, 8, 1)
    summary = export_material(Material("h", schema, {"height": height}), "godot", tmp_path / "g")
    assert any("h_height.png: 32 value(s) outside [0, 1] clipped" in w for w in summary.warnings)
