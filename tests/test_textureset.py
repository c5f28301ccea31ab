"""Texture-set detection from file names (names only: files may be empty)."""

from __future__ import annotations

from pathlib import Path

import pytest

from matshop.errors import MatshopError
from matshop.io.textureset import SLOTS, detect_texture_set, parse_map_name

CHESSBOARD = Path(__file__).resolve().parents[2] / "shared" / "data" / "chessboard"

NAMES = [
    # Poly Haven
    ("rock_wall_diff_2k.png", "base_color", "rock_wall", None),
    ("rock_wall_nor_gl_2k.exr", "normal", "rock_wall", "opengl"),
    ("rock_wall_nor_dx_2k.exr", "normal", "rock_wall", "directx"),
    ("rock_wall_rough_2k.png", "roughness", "rock_wall", None),
    ("rock_wall_arm_2k.png", "orm", "rock_wall", None),
    ("rock_wall_disp_4k.png", "height", "rock_wall", None),
    # ambientCG
    ("Bricks076C_2K-PNG_Color.png", "base_color", "Bricks076C", None),
    ("Bricks076C_2K-PNG_NormalGL.png", "normal", "Bricks076C", "opengl"),
    ("Bricks076C_2K-PNG_NormalDX.png", "normal", "Bricks076C", "directx"),
    ("Bricks076C_2K-PNG_Roughness.png", "roughness", "Bricks076C", None),
    ("Bricks076C_2K-PNG_AmbientOcclusion.png", "ao", "Bricks076C", None),
    ("Bricks076C_2K-PNG_Displacement.png", "height", "Bricks076C", None),
    # Substance / Unreal / Unity
    ("Mat_BaseColor.png", "base_color", "Mat", None),
    ("Mat_Base_Color.png", "base_color", "Mat", None),
    ("Mat_Normal.png", "normal", "Mat", None),
    ("Mat_Normal_OpenGL.png", "normal", "Mat", "opengl"),
    ("Mat_Normal_DirectX.png", "normal", "Mat", "directx"),
    ("Mat_OcclusionRoughnessMetallic.png", "orm", "Mat", None),
    ("Mat_MaskMap.png", "mask_map", "Mat", None),
    ("Mat_mask_map_2k.png", "mask_map", "Mat", None),
    ("brick_base_gray.jpg", "base_color", "brick", None),
    ("rock_normal_map.png", "normal", "rock", None),
    ("Mat_MetallicSmoothness.png", "metallic_smoothness", "Mat", None),
    ("Mat_AlbedoTransparency.png", "base_color", "Mat", None),
    ("Mat_metallicRoughness.png", "metallic_roughness", "Mat", None),
    ("Mat_Height.png", "height", "Mat", None),
    ("Mat_Emissive.png", "emissive", "Mat", None),
    ("T_Rock_ORM.tga", "orm", "T_Rock", None),
    ("rock_NormalMap.png", "normal", "rock", None),
    ("Aset_rock_4K_Normal_LOD0.jpg", "normal", "Aset_rock", None),
    ("matBaseColor.png", "base_color", "mat", None),
    # others
    ("wood_Glossiness.jpg", "gloss", "wood", None),
    ("wood_col_v2.png", "base_color", "wood", None),
    ("chessboard_base_color.jpg", "base_color", "chessboard", None),
    ("rock_normalgl.png", "normal", "rock", "opengl"),
    ("rock_bmp.png", "bump", "rock", None),
    ("Rock_AO.png", "ao", "Rock", None),
    ("rock wall #3 - roughness.png", "roughness", "rock wall #3", None),
    ("velvet_ndf.exr", "distribution", "velvet", None),
    ("skin_sss.exr", "profile", "skin", None),
    ("albedo.png", "base_color", "", None),
    ("rock_diff (1).png", "base_color", "rock", None),
    ("Holz_Oberfläche_Rauheit_roughness.png", "roughness", "Holz_Oberfläche_Rauheit", None),
    # ambiguous tokens inside material names: only the end counts
    ("spec_ops_crate_diff.png", "base_color", "spec_ops_crate", None),
    ("metal_plate_rough_4k.png", "roughness", "metal_plate", None),
    ("gas_mask_diff.png", "base_color", "gas_mask", None),
    ("tan_leather_nor.png", "normal", "tan_leather", None),
    ("col_stone_spec.png", "specular", "col_stone", None),
    ("leather_tan.png", "tangent", "leather", None),
]


@pytest.mark.parametrize(("name", "slot", "material", "convention"), NAMES)
def test_names(name, slot, material, convention):
    parsed = parse_map_name(name)
    assert parsed is not None, name
    assert (parsed.slot, parsed.material, parsed.convention) == (slot, material, convention)


@pytest.mark.parametrize(
    "name", ["Bricks076C.png", "notes.png", "rock_gl.png", "rock_2k.png", "1234.png", "_.png"]
)
def test_names_without_a_tag(name):
    assert parse_map_name(name) is None


def test_every_tag_in_the_table_finds_its_slot():
    for slot, spec in SLOTS.items():
        assert spec.description
        for tag in spec.tags:
            for name in (f"mat_{tag.replace(' ', '_')}.png", f"MAT-{tag.upper()}.exr"):
                parsed = parse_map_name(name)
                assert parsed is not None and parsed.slot == slot, (name, parsed)
                assert parsed.material.lower() == "mat"


def make_folder(root: Path, *names: str) -> Path:
    root.mkdir(parents=True, exist_ok=True)
    for name in names:
        (root / name).write_bytes(b"")
    return root


def test_poly_haven_folder(tmp_path):
    folder = make_folder(
        tmp_path / "ph",
        "rock_wall_diff_2k.png",
        "rock_wall_nor_gl_2k.exr",
        "rock_wall_nor_dx_2k.exr",
        "rock_wall_rough_2k.png",
        "rock_wall_arm_2k.png",
        "rock_wall.blend",
    )
    ts = detect_texture_set(folder)
    assert ts.name == "rock_wall" and ts.folder == folder
    assert {k: p.name for k, p in ts.maps.items()} == {
        "base_color": "rock_wall_diff_2k.png",
        "normal": "rock_wall_nor_gl_2k.exr",
        "roughness": "rock_wall_rough_2k.png",
        "orm": "rock_wall_arm_2k.png",
    }
    assert ts.hints == {"normal": {"convention": "opengl"}}
    assert [p.name for p in ts.alternates["normal"]] == ["rock_wall_nor_dx_2k.exr"]
    assert ts.unrecognised == []


def test_ambientcg_folder_with_preview(tmp_path):
    stem = "Bricks076C_2K-PNG"
    folder = make_folder(
        tmp_path / "acg",
        *(f"{stem}_{t}.png" for t in ("Color", "NormalGL", "NormalDX", "Roughness")),
        f"{stem}_AmbientOcclusion.png",
        f"{stem}_Displacement.png",
        "Bricks076C.png",
        f"{stem}.usdc",
        f"{stem}.mtlx",
    )
    ts = detect_texture_set(folder)
    assert ts.name == "Bricks076C"
    assert set(ts.maps) == {"base_color", "normal", "roughness", "ao", "height"}
    assert ts.maps["normal"].name.endswith("NormalGL.png")
    assert ts.unrecognised == []
    assert ts.not_used == {folder / "Bricks076C.png": "a preview image (named like the material)"}
    # one file of the set selects the same set
    one = detect_texture_set(folder / f"{stem}_Roughness.png")
    assert one.maps == ts.maps and one.name == ts.name


def test_substance_and_unity_names(tmp_path):
    folder = make_folder(
        tmp_path / "sub",
        "Mat_BaseColor.png",
        "Mat_Normal.png",
        "Mat_OcclusionRoughnessMetallic.png",
        "Mat_MaskMap.png",
        ".Mat_Height.tmp-1a2b.png",  # a temp file of an interrupted save
    )
    ts = detect_texture_set(folder)
    assert set(ts.maps) == {"base_color", "normal", "orm", "mask_map"} and ts.name == "Mat"
    assert ts.hints == {}


def test_unnamed_material_takes_folder_name(tmp_path):
    ts = detect_texture_set(make_folder(tmp_path / "oak", "albedo.png", "normal.png"))
    assert ts.name == "oak" and set(ts.maps) == {"base_color", "normal"}


def test_preview_named_like_material_is_not_a_map(tmp_path):
    folder = make_folder(
        tmp_path / "m",
        "rusty_metal_02_diff_2k.png",
        "rusty_metal_02_rough_2k.png",
        "rusty_metal_02.png",
    )
    ts = detect_texture_set(folder)
    assert set(ts.maps) == {"base_color", "roughness"}
    assert list(ts.not_used) == [folder / "rusty_metal_02.png"]


def test_several_materials_need_a_file_to_choose(tmp_path):
    folder = make_folder(
        tmp_path / "two",
        "rock_diff.png",
        "rock_nor.png",
        "wood_diff.png",
        "wood_rough.png",
        "wood_notes.png",
    )
    with pytest.raises(MatshopError, match="several materials") as err:
        detect_texture_set(folder)
    message = str(err.value)
    assert "\n" not in message and "rock" in message and "wood" in message
    ts = detect_texture_set(folder / "wood_rough.png")
    assert ts.name == "wood" and set(ts.maps) == {"base_color", "roughness"}
    assert [p.name for p in ts.unrecognised] == ["wood_notes.png"]


def test_resolutions_are_separate_sets(tmp_path):
    folder = make_folder(
        tmp_path / "res", "rock_diff_2k.png", "rock_rough_2k.png", "rock_diff_4k.png"
    )
    with pytest.raises(MatshopError, match="several materials"):
        detect_texture_set(folder)
    ts = detect_texture_set(folder / "rock_rough_2k.png")
    assert {p.name for p in ts.maps.values()} == {"rock_diff_2k.png", "rock_rough_2k.png"}


def write_maps(folder: Path, files: dict[str, tuple[int, str]]) -> Path:
    """Real 8x8 images: name -> (channels, bit depth), a ramp in every channel."""
    import numpy as np

    from matshop.io.images import write_image

    folder.mkdir(parents=True, exist_ok=True)
    for name, (channels, depth) in files.items():
        ramp = np.linspace(0.1, 0.9, 64, dtype=np.float32).reshape(8, 8, 1)
        write_image(folder / name, np.repeat(ramp, channels, axis=2), bit_depth=depth)
    return folder


@pytest.mark.parametrize(
    ("files", "slot", "winner", "reason"),
    [
        (
            {"rock_nor.png": (3, "uint8"), "rock_nor.exr": (3, "half")},
            "normal",
            "rock_nor.exr",
            "half over uint8, the deeper file wins",
        ),
        (
            {"rock_diff.png": (3, "uint16"), "rock_diff.tif": (3, "uint8")},
            "base_color",
            "rock_diff.png",
            "uint16 over uint8",
        ),
        (
            {"rock_diff.png": (3, "uint8"), "rock_diff.jpg": (3, "uint8")},
            "base_color",
            "rock_diff.png",
            "lossless over JPEG",
        ),
        (
            {"rock_nor.png": (3, "uint8"), "rock_nor_gl.png": (3, "uint8")},
            "normal",
            "rock_nor_gl.png",
            "its name states the normal convention",
        ),
        (
            {"rock_diff.png": (3, "uint8"), "rock_albedo.png": (3, "uint8")},
            "base_color",
            "rock_albedo.png",
            "alike; the first by name",
        ),
    ],
)
def test_two_files_for_one_slot_the_better_one_wins(tmp_path, files, slot, winner, reason):
    folder = write_maps(tmp_path / "c", files)
    ts = detect_texture_set(folder)
    assert ts.maps[slot].name == winner
    (loser,) = set(files) - {winner}
    assert reason in ts.not_used[folder / loser] and loser in " ".join(ts.notes)
    assert any(reason in note for note in ts.notes)


def test_an_unreadable_duplicate_loses(tmp_path):
    folder = write_maps(tmp_path / "u", {"rock_nor.png": (3, "uint8")})
    (folder / "rock_nor.exr").write_bytes(b"not an exr")
    ts = detect_texture_set(folder)
    assert ts.maps["normal"].name == "rock_nor.png"
    assert "rock_nor.exr cannot be read" in ts.not_used[folder / "rock_nor.exr"]


@pytest.mark.parametrize("names", [(), ("readme.txt",), ("photo.png", "notes.jpg")])
def test_nothing_recognised(tmp_path, names):
    folder = make_folder(tmp_path / "none", *names)
    with pytest.raises(MatshopError, match="no texture maps recognised") as err:
        detect_texture_set(folder)
    message = str(err.value)
    assert "\n" not in message and str(folder) in message and "_basecolor.png" in message


def test_bad_paths(tmp_path):
    with pytest.raises(MatshopError, match="not found"):
        detect_texture_set(tmp_path / "nowhere")
    folder = make_folder(tmp_path / "f", "rock_diff.png", "rock.txt", "Bricks.png")
    with pytest.raises(MatshopError, match="not an image file"):
        detect_texture_set(folder / "rock.txt")
    with pytest.raises(MatshopError, match="names no texture map") as err:
        detect_texture_set(folder / "Bricks.png")
    assert "Bricks.png" in str(err.value)


@pytest.mark.skipif(not CHESSBOARD.is_dir(), reason=f"{CHESSBOARD} not present")
def test_real_chessboard_folder():
    ts = detect_texture_set(CHESSBOARD)
    assert ts.name == "chessboard"
    assert set(ts.maps) == {"base_color", "metallic", "normal", "roughness"}
    assert detect_texture_set(CHESSBOARD / "chessboard_normal.jpg").maps == ts.maps


def test_a_user_corrected_set_loads_what_the_user_chose(tmp_path: Path) -> None:
    import numpy as np

    from matshop.io.images import write_image
    from matshop.io.material_io import load_material
    from matshop.io.textureset import check_texture_set, with_slot

    rough = np.linspace(0, 1, 16, dtype=np.float32)[None, :, None].repeat(8, axis=0)
    write_image(tmp_path / "rock_basecolor.png", np.full((8, 16, 3), 0.5, np.float32))
    write_image(tmp_path / "rock_r.png", rough)  # a name no tag matches
    ts = detect_texture_set(tmp_path)
    assert "roughness" not in ts.maps and tmp_path / "rock_r.png" in ts.unrecognised
    fixed = with_slot(ts, "roughness", tmp_path / "rock_r.png")
    assert fixed.maps["roughness"] == tmp_path / "rock_r.png" and not fixed.unrecognised
    assert "roughness" not in ts.maps  # the detected set is not changed
    material, report = load_material(fixed)
    assert np.allclose(material.maps["roughness"][..., 0], rough[..., 0], atol=1 / 255)
    assert report.texture_set is fixed
    dropped = with_slot(fixed, "base_color", None)
    assert set(load_material(dropped)[0].maps) == {"roughness"}
    # the same file in two slots, a missing file, an unknown slot: one line each
    twice = with_slot(fixed, "metallic", tmp_path / "rock_r.png")
    assert "roughness" not in twice.maps  # moving a file takes it out of its old slot
    bad = {**fixed.maps, "metallic": tmp_path / "rock_r.png"}
    with pytest.raises(MatshopError, match="used for both"):
        check_texture_set(type(fixed)(fixed.name, fixed.folder, bad))
    with pytest.raises(MatshopError, match="file not found"):
        load_material(with_slot(fixed, "ao", tmp_path / "gone.png"))
    with pytest.raises(MatshopError, match="unknown map slot 'sheen'"):
        with_slot(fixed, "sheen", tmp_path / "rock_r.png")
