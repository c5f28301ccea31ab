"""Variance kept: the footprint's share of its gain and the widening's (docs/variance.md).

``export --size N --keep-variance`` does two things to a reduced texel: its normal and
lobe become the area means over its own footprint (instead of Lanczos-3, which plain
exports keep), and its lobe is widened by the slopes' spread over that footprint. This
splits the two against the same far-field truth as benchmarks/variance.py (the full
render averaged over each small pixel): the plain export, the plain export with the
normal and lobe area-averaged (the footprint alone, not an option), and the shipped
``--keep-variance``. The ratios: kept/plain (what the option buys), area/plain (the
footprint's share) and kept/area (the widening's share).

    python benchmarks/variance_filters.py            # the 512^2 grooved crop and the bumps (~1 min)
    python benchmarks/variance_filters.py --whole    # the whole 2K chessboard too (~4 min)
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _common import CHESSBOARD  # noqa: E402
from variance import FIGURE_CROP, bumpy, chessboards  # noqa: E402

from matshop.export.resize import footprint_shading, resize_array, resize_material  # noqa: E402
from matshop.material import EditMaterial, Material  # noqa: E402
from matshop.render.far_field import box_average, swatch_radiance  # noqa: E402


def area_plain(material: Material, size: tuple[int, int]) -> Material:
    """The plain export with the normal and lobe area-averaged and no widening."""
    edit = material.to_edit()
    data = footprint_shading(edit, resize_array(edit.data, size), size)
    return EditMaterial(edit.name, edit.schema, data, edit.sources).to_physical()


def rmse(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a - b) ** 2)))


def run(material: Material, label: str, factors: tuple[int, ...]) -> None:
    full = swatch_radiance(material)
    h, w = material.size
    for factor in factors:
        size = (h // factor, w // factor)
        truth = box_average(full, factor)
        plain, area, kept = (
            rmse(swatch_radiance(reduced), truth)
            for reduced in (
                resize_material(material, size),
                area_plain(material, size),
                resize_material(material, size, keep_variance=True),
            )
        )
        print(
            f"{label:24s} {factor}x  plain {plain:.4f}  area {area:.4f}  kept {kept:.4f}  "
            f"kept/plain {kept / plain:.3f} = area/plain {area / plain:.3f} "
            f"x kept/area {kept / area:.3f}",
            flush=True,
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--whole", action="store_true", help="also the whole 2K chessboard")
    args = parser.parse_args()
    run(bumpy(), "bumps 512", (2, 4, 8))
    if not CHESSBOARD.is_dir():
        print("shared chessboard absent: synthetic material only")
        return
    for crop in (FIGURE_CROP, (512, 1536, 0)):
        material, normals = chessboards(crop)
        run(material, f"chessboard crop {crop[1]},{crop[2]}", (2, 4, 8))
        run(normals, "  normals only", (4,))
    if args.whole:
        whole, whole_normals = chessboards(None)
        run(whole, "chessboard", (2, 4, 8))
        run(whole_normals, "  normals only", (2, 4, 8))


if __name__ == "__main__":
    main()
