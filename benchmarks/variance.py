"""Variance kept, measured by appearance (docs/variance.md).

For each material: render it at full resolution (swatch scene, one pixel per
texel, two directional lights, no environment noise), average the image down
by 2, 4 and 8 (what the eye sees from that much farther away), and compare
with the material downsized by ``matshop export --size`` without and with
``--keep-variance``, rendered at the small size. Prints RMSE of linear
radiance and the ratio kept / plain (goal: <= 0.8 at 4x).

Materials: the shared chessboard (whole 2K set; it takes ~1 min), the same
normals with a constant base colour and roughness (isolates what the normals
contribute), and a synthetic bumpy material (Gaussian-filtered white-noise
height, mean tilt ~17 deg, GGX r = 0.3).

    python benchmarks/variance.py                       # ~2 min on 2 cores
    python benchmarks/variance.py --crop 512 512 1536   # a 512 crop at row 512, column 1536
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _common import CHESSBOARD  # noqa: E402

from matshop.material import Material  # noqa: E402
from matshop.render.far_field import far_field_errors  # noqa: E402
from matshop.render.materials import from_maps  # noqa: E402
from matshop.spaces.frame import height_to_normal  # noqa: E402


def bumpy(size: int = 512, *, bump_px: float = 1.5, strength: float = 0.6) -> Material:
    """Fine isotropic bumps (tiling): white noise blurred by ``bump_px``, unit variance."""
    rng = np.random.default_rng(0)
    height = gaussian_filter(rng.normal(0.0, 1.0, (size, size)), bump_px, mode="wrap")
    height = (height / height.std()).astype(np.float32)
    maps = {
        "base_color": np.full((size, size, 3), 0.5, np.float32),
        "roughness": np.full((size, size, 1), 0.3, np.float32),
        "normal": height_to_normal(height, strength=strength),
    }
    return from_maps(maps, name="bumpy")


def chessboards(crop: tuple[int, int, int] | None) -> list[Material]:
    from matshop.io.material_io import load_material

    material, _ = load_material(CHESSBOARD)
    maps = material.maps
    if crop:
        size, row, col = crop
        maps = {
            k: np.ascontiguousarray(v[row : row + size, col : col + size]) for k, v in maps.items()
        }
    h, w = maps["normal"].shape[:2]
    normals_only = {
        "base_color": np.full((h, w, 3), 0.5, np.float32),
        "roughness": np.full((h, w, 1), 0.28, np.float32),
        "normal": maps["normal"],
    }
    return [from_maps(maps, name="chessboard"), from_maps(normals_only, name="chessboard normals")]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--crop",
        type=int,
        nargs=3,
        metavar=("SIZE", "ROW", "COL"),
        help="a SIZE x SIZE crop of the chessboard at ROW, COL (default: the whole set)",
    )
    args = parser.parse_args()
    materials = [bumpy()]
    if CHESSBOARD.is_dir():
        materials = chessboards(args.crop) + materials
    else:
        print("shared chessboard absent: synthetic material only")
    header = ("material", "size", "factor", "plain", "kept", "kept/plain")
    print("{:22s} {:>9s} {:>6s} {:>8s} {:>8s} {:>10s}".format(*header))
    for material in materials:
        start = time.perf_counter()
        h, w = material.size
        for r in far_field_errors(material, (2, 4, 8)):
            print(
                f"{material.name:22s} {w:4d}x{h:<4d} {r.factor:6d} {r.rmse_plain:8.4f} "
                f"{r.rmse_kept:8.4f} {r.ratio:10.3f}"
            )
        print(f"  ({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
