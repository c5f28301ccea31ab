"""A small material library laid out as people download them, for batch tests and benchmarks.

Folder and file names follow each library's own naming (CONVENTIONS.md):
Poly Haven ``name_diff_1k``, ambientCG ``Name_1K-PNG_Color`` with a preview
image, Megascans ``id_2K_Albedo``, a MaterialX-style folder holding two
materials that share maps, and a set whose color map is corrupt. Pixels are
smooth random fields (real maps are not white noise), seeded per file.
"""

from __future__ import annotations

import zlib
from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter

from matshop.io.images import write_image

#: folder -> {file name: channels}
LAYOUT: dict[str, dict[str, int]] = {
    "polyhaven/rock_wall_02": {
        "rock_wall_02_diff_1k.png": 3,
        "rock_wall_02_nor_gl_1k.png": -3,  # negative: a normal map
        "rock_wall_02_rough_1k.png": 1,
    },
    "ambientcg/Bricks076": {
        "Bricks076_1K-PNG_Color.png": 3,
        "Bricks076_1K-PNG_NormalGL.png": -3,
        "Bricks076_1K-PNG_Roughness.png": 1,
        "Bricks076_1K-PNG_Metalness.png": 1,
        "Bricks076.png": 3,  # the library's preview render: not a map
    },
    "megascans/surfaces/Rock_sdhcy": {
        "sdhcy_2K_Albedo.png": 3,
        "sdhcy_2K_Normal.png": -3,
        "sdhcy_2K_Roughness.png": 1,
        "sdhcy_2K_AO.png": 1,
    },
    "materialx/chess_set": {  # two materials in one folder, sharing three maps
        "king_black_base_color.png": 3,
        "king_white_base_color.png": 3,
        "king_shared_metallic.png": 1,
        "king_shared_normal.png": -3,
        "king_shared_roughness.png": 1,
    },
    "ambientcg/Broken001": {
        "Broken001_1K-PNG_Color.png": 0,  # zero: a corrupt file
        "Broken001_1K-PNG_NormalGL.png": -3,
        "Broken001_1K-PNG_Roughness.png": 1,
    },
}

#: what each set's output folder is, relative to OUT (the library's folders mirrored)
GOOD_SETS = (
    "polyhaven/rock_wall_02",
    "ambientcg/Bricks076",
    "megascans/surfaces/Rock_sdhcy",
    "materialx/chess_set/king_black",
    "materialx/chess_set/king_white",
)
BROKEN_SET = "ambientcg/Broken001"


def _field(seed: int, size: int, channels: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    noise = rng.standard_normal((size, size, channels))
    smooth = gaussian_filter(noise, sigma=(size / 16, size / 16, 0), mode="wrap")
    smooth /= 4 * smooth.std() + 1e-9
    return np.clip(0.5 + smooth, 0.02, 0.98).astype(np.float32)


def _normal_map(seed: int, size: int) -> np.ndarray:
    tilt = (_field(seed, size, 2) - 0.5) * 1.2
    n = np.concatenate([tilt, np.ones((size, size, 1), np.float32)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return 0.5 * n + 0.5


def make_library(root: Path, size: int = 32, *, sets: int = 1) -> Path:
    """Write the library under ``root`` (``sets`` > 1: that many copies of it); return root."""
    for copy in range(sets):
        base = root if sets == 1 else root / f"copy{copy:03d}"
        for folder, files in LAYOUT.items():
            for name, channels in files.items():
                path = base / folder / name
                path.parent.mkdir(parents=True, exist_ok=True)
                seed = zlib.crc32(f"{copy}/{folder}/{name}".encode())
                if channels == 0:
                    path.write_bytes(b"\x89PNG\r\n\x1a\n" + b"\x00garbage" * 8)
                elif channels < 0:
                    write_image(path, _normal_map(seed, size))
                else:
                    write_image(path, _field(seed, size, channels))
    return root
