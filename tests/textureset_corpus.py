"""Folders laid out as texture libraries ship them, each with the set it must produce.

Every file is a real small image (or, where the case says so, a corrupt file
or a broken link), so detection, header reads and loading all run for real.
The expected sets are written by hand from how each library names its maps
(CONVENTIONS.md), not derived from matshop's own tables.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from matshop.io.images import write_image

SIZE = 8
#: file spec: (channels, bit depth) for an image, or one of these words
CORRUPT, BROKEN_LINK, OTHER_SIZE = "corrupt", "broken link", "other size"


@dataclass
class Case:
    name: str
    files: dict[str, tuple[int, str] | str]
    maps: dict[str, str]  #: slot -> file the set must use (empty when detection refuses)
    not_used: dict[str, str] = field(default_factory=dict)  #: file -> words its reason holds
    material: str | None = None  #: chosen with material=
    several: tuple[str, ...] = ()  #: without a choice: the materials listed
    notes: tuple[str, ...] = ()  #: words the detection notes must hold
    unrecognised: tuple[str, ...] = ()


def _rgb(n: int = 3, depth: str = "uint8") -> tuple[int, str]:
    return (n, depth)


GRAY, RGB, RGBA = _rgb(1), _rgb(3), _rgb(4)
CHESS = {
    "chessboard_base_color.jpg": RGB,
    "chessboard_metallic.jpg": GRAY,
    "chessboard_normal.jpg": RGB,
    "chessboard_roughness.jpg": GRAY,
    "king_black_base_color.jpg": RGB,
    "king_white_base_color.jpg": RGB,
    "king_shared_metallic.jpg": GRAY,
    "king_shared_normal.jpg": RGB,
    "king_shared_roughness.jpg": GRAY,
    "chess_set.png": RGB,  # the library's render of the whole set
}

CASES = [
    Case(
        "materialx_variant_with_shared_metallic",
        {
            "king_white_base_color.jpg": RGB,
            "king_white_normal.jpg": RGB,
            "king_white_roughness.jpg": GRAY,
            "king_shared_metallic.jpg": GRAY,
        },
        {
            "base_color": "king_white_base_color.jpg",
            "normal": "king_white_normal.jpg",
            "roughness": "king_white_roughness.jpg",
            "metallic": "king_shared_metallic.jpg",
        },
        notes=("king_shared_metallic.jpg, shared with king_*",),
    ),
    Case(
        "materialx_chess_set_several_materials",
        CHESS,
        {},
        several=("chessboard", "king_black", "king_white"),
        unrecognised=("chess_set.png",),
    ),
    Case(
        "materialx_chess_set_one_chosen",
        CHESS,
        {
            "base_color": "king_black_base_color.jpg",
            "metallic": "king_shared_metallic.jpg",
            "normal": "king_shared_normal.jpg",
            "roughness": "king_shared_roughness.jpg",
        },
        material="King_Black",
        notes=("king_shared_normal.jpg", "king_shared_roughness.jpg"),
    ),
    Case(
        "materialx_brick_with_masks",
        {
            "brick_base_gray.jpg": GRAY,
            "brick_dirt_gray.jpg": GRAY,
            "brick_normal.jpg": RGB,
            "brick_roughness.jpg": GRAY,
            "brick_mask.jpg": GRAY,
            "brick_dirt_mask.jpg": GRAY,
            "brick_variation_mask.jpg": GRAY,
        },
        {
            "base_color": "brick_base_gray.jpg",
            "normal": "brick_normal.jpg",
            "roughness": "brick_roughness.jpg",
        },
        not_used={
            "brick_mask.jpg": "generic mask",
            "brick_dirt_mask.jpg": "generic mask",
            "brick_variation_mask.jpg": "generic mask",
        },
        unrecognised=("brick_dirt_gray.jpg",),
    ),
    Case(
        "poly_haven_with_preview_and_both_normals",
        {
            "rock_wall_diff_2k.jpg": RGB,
            "rock_wall_nor_gl_2k.exr": _rgb(3, "half"),
            "rock_wall_nor_dx_2k.exr": _rgb(3, "half"),
            "rock_wall_rough_2k.jpg": GRAY,
            "rock_wall_arm_2k.jpg": RGB,
            "rock_wall_disp_2k.png": _rgb(1, "uint16"),
            "rock_wall.png": RGB,
        },
        {
            "base_color": "rock_wall_diff_2k.jpg",
            "normal": "rock_wall_nor_gl_2k.exr",
            "roughness": "rock_wall_rough_2k.jpg",
            "orm": "rock_wall_arm_2k.jpg",
            "height": "rock_wall_disp_2k.png",
        },
        not_used={"rock_wall.png": "preview"},
    ),
    Case(
        "ambientcg_with_preview",
        {
            "Bricks076C_2K-JPG_Color.jpg": RGB,
            "Bricks076C_2K-JPG_NormalGL.jpg": RGB,
            "Bricks076C_2K-JPG_NormalDX.jpg": RGB,
            "Bricks076C_2K-JPG_Roughness.jpg": GRAY,
            "Bricks076C_2K-JPG_AmbientOcclusion.jpg": GRAY,
            "Bricks076C_2K-JPG_Displacement.jpg": GRAY,
            "Bricks076C.png": RGB,
        },
        {
            "base_color": "Bricks076C_2K-JPG_Color.jpg",
            "normal": "Bricks076C_2K-JPG_NormalGL.jpg",
            "roughness": "Bricks076C_2K-JPG_Roughness.jpg",
            "ao": "Bricks076C_2K-JPG_AmbientOcclusion.jpg",
            "height": "Bricks076C_2K-JPG_Displacement.jpg",
        },
        not_used={"Bricks076C.png": "preview"},
    ),
    Case(
        "megascans_with_cavity_and_translucency",
        {
            "vdqhbbfn_2K_Albedo.jpg": RGB,
            "vdqhbbfn_2K_Normal_LOD0.jpg": RGB,
            "vdqhbbfn_2K_Roughness.jpg": GRAY,
            "vdqhbbfn_2K_AO.jpg": GRAY,
            "vdqhbbfn_2K_Cavity.jpg": GRAY,
            "vdqhbbfn_2K_Translucency.jpg": RGB,
            "vdqhbbfn_2K_Displacement.exr": _rgb(1, "float"),
            "vdqhbbfn_Preview.png": RGB,
        },
        {
            "base_color": "vdqhbbfn_2K_Albedo.jpg",
            "normal": "vdqhbbfn_2K_Normal_LOD0.jpg",
            "roughness": "vdqhbbfn_2K_Roughness.jpg",
            "ao": "vdqhbbfn_2K_AO.jpg",
            "height": "vdqhbbfn_2K_Displacement.exr",
        },
        not_used={
            "vdqhbbfn_2K_Cavity.jpg": "cavity",
            "vdqhbbfn_2K_Translucency.jpg": "translucency",
            "vdqhbbfn_Preview.png": "preview",
        },
    ),
    Case(
        "substance_export_with_a_mask",
        {
            "Crate_Wood_BaseColor.png": RGB,
            "Crate_Wood_Normal.png": RGB,
            "Crate_Wood_OcclusionRoughnessMetallic.png": RGB,
            "Crate_Wood_Height.png": _rgb(1, "uint16"),
            "Crate_Wood_Emissive.png": RGB,
            "Crate_Wood_Mask.png": GRAY,
        },
        {
            "base_color": "Crate_Wood_BaseColor.png",
            "normal": "Crate_Wood_Normal.png",
            "orm": "Crate_Wood_OcclusionRoughnessMetallic.png",
            "height": "Crate_Wood_Height.png",
            "emissive": "Crate_Wood_Emissive.png",
        },
        not_used={"Crate_Wood_Mask.png": "generic mask"},
    ),
    Case(
        "unity_hdrp_mask_map",
        {"Rock_BaseMap.png": RGBA, "Rock_Normal.png": RGB, "Rock_MaskMap.png": RGBA},
        {
            "base_color": "Rock_BaseMap.png",
            "normal": "Rock_Normal.png",
            "mask_map": "Rock_MaskMap.png",
        },
    ),
    Case(
        "a_one_channel_mask_map_is_a_mask",
        {"Rock_BaseMap.png": RGB, "Rock_Normal.png": RGB, "Rock_MaskMap.png": GRAY},
        {"base_color": "Rock_BaseMap.png", "normal": "Rock_Normal.png"},
        not_used={"Rock_MaskMap.png": "1 channel(s): a generic mask"},
    ),
    Case(
        "duplicates_by_format_and_depth",
        {
            "stone_albedo.png": RGB,
            "stone_albedo.jpg": RGB,
            "stone_normal.png": RGB,
            "stone_normal.exr": _rgb(3, "half"),
            "stone_roughness.png": _rgb(1, "uint16"),
            "stone_roughness.tif": GRAY,
        },
        {
            "base_color": "stone_albedo.png",
            "normal": "stone_normal.exr",
            "roughness": "stone_roughness.png",
        },
        not_used={
            "stone_albedo.jpg": "lossless over JPEG",
            "stone_normal.png": "half over uint8",
            "stone_roughness.tif": "uint16 over uint8",
        },
        notes=("the deeper file wins",),
    ),
    Case(
        "two_resolutions_need_a_choice",
        {"rock_diff_2k.png": RGB, "rock_rough_2k.png": GRAY, "rock_diff_4k.png": RGB},
        {},
        several=("rock_2k", "rock_4k"),
    ),
    Case(
        "two_resolutions_one_chosen",
        {"rock_diff_2k.png": RGB, "rock_rough_2k.png": GRAY, "rock_diff_4k.png": RGB},
        {"base_color": "rock_diff_4k.png"},
        material="rock_4k",
    ),
    Case(
        "common_maps_and_mixed_case_prefixes",
        {
            "Crate_Red_Diffuse.png": RGB,
            "crate_blue_diffuse.png": RGB,
            "crate_common_normal.png": RGB,
            "CRATE_COMMON_ROUGHNESS.png": GRAY,
        },
        {
            "base_color": "Crate_Red_Diffuse.png",
            "normal": "crate_common_normal.png",
            "roughness": "CRATE_COMMON_ROUGHNESS.png",
        },
        material="crate_red",
        notes=("shared with crate_*",),
    ),
    Case(
        "stray_unreadable_files_and_broken_links",
        {
            "oak_diff.png": RGB,
            "oak_nor_gl.png": RGB,
            "oak_dirt_mask.png": CORRUPT,
            "oak_notes.png": CORRUPT,
            "oak_spec.png": BROKEN_LINK,
        },
        {"base_color": "oak_diff.png", "normal": "oak_nor_gl.png"},
        not_used={"oak_dirt_mask.png": "generic mask", "oak_spec.png": "broken link"},
        unrecognised=("oak_notes.png",),
    ),
    Case(
        "a_material_named_like_the_start_of_another_lends_nothing",
        {
            "rock_wall_diff_2k.png": RGB,
            "rock_wall_nor_gl_2k.png": RGB,
            "rock_wall_02_diff_2k.png": RGB,
        },
        {"base_color": "rock_wall_02_diff_2k.png"},
        material="rock_wall_02_2k",
    ),
    Case(
        "a_base_map_under_a_parent_prefix",
        {
            "table_top_base_color.png": RGB,
            "table_top_normal.png": RGB,
            "table_metallic.png": GRAY,
        },
        {
            "base_color": "table_top_base_color.png",
            "normal": "table_top_normal.png",
            "metallic": "table_metallic.png",
        },
        notes=("table_metallic.png, shared with table_*",),
    ),
]


def build(case: Case, root: Path) -> Path:
    """Write the case's folder under ``root``; return it."""
    folder = root / case.name
    folder.mkdir(parents=True)
    rng = np.random.default_rng(len(case.name))
    for name, spec in case.files.items():
        path = folder / name
        if spec == CORRUPT:
            path.write_bytes(b"\x89PNG\r\n\x1a\n truncated")
        elif spec == BROKEN_LINK:
            os.symlink(folder / "gone.png", path)
        elif spec == OTHER_SIZE:
            write_image(path, rng.random((SIZE * 2, SIZE, 3), dtype=np.float32))
        else:
            channels, depth = spec
            values = rng.random((SIZE, SIZE, channels), dtype=np.float32)
            write_image(path, values, bit_depth=depth)
    return folder
