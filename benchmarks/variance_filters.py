"""Variance kept: the footprint's share of its gain and the widening's (docs/variance.md).

``export --size N --keep-variance`` does two things to a reduced texel: its normal and
lobe become the area means over its own footprint (instead of Lanczos-3, which plain
exports keep), and its lobe is widened by the slopes' spread over that footprint. This
splits the two against the same far-field truth as benchmarks/variance.py (the full
render averaged over each small pixel): the plain export, the plain export with the
normal and lobe area-averaged (the footprint alone, not an option), and the shipped
``--keep-variance``. The ratios: kept/plain (what the option buys), area/plain (the
footprint's share) and kept/area (the widening's share); on the crops also split
between the small texels whose area holds a groove and the others.

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

from matshop.export.resize import (  # noqa: E402
    area_matrix,
    footprint_shading,
    resize_array,
    resize_material,
)
from matshop.material import EditMaterial, Material  # noqa: E402
from matshop.ops.variance import lost_slope_covariance  # noqa: E402
from matshop.render.far_field import box_average, swatch_radiance  # noqa: E402


def area_plain(material: Material, size: tuple[int, int]) -> Material:
    """The plain export with the normal and lobe area-averaged and no widening."""
    edit = material.to_edit()
    data = footprint_shading(edit, resize_array(edit.data, size), size)
    return EditMaterial(edit.name, edit.schema, data, edit.sources).to_physical()


#: a small texel "holds a groove" when its area loses more slope variance than this
GROOVE_VARIANCE = 1e-3


def groove_texels(material: Material, size: tuple[int, int]) -> np.ndarray:
    """``(H', W')`` bool: the small texels whose area loses more than :data:`GROOVE_VARIANCE`."""
    cov = lost_slope_covariance(
        material.maps["normal"][..., :3], lambda a: resize_array(a, size, weights=area_matrix)
    )
    return cov[..., 0] + cov[..., 2] > GROOVE_VARIANCE


def rmse(a: np.ndarray, b: np.ndarray, where: np.ndarray | None = None) -> float:
    squared = np.mean((a - b) ** 2, axis=-1)
    return float(np.sqrt(np.mean(squared if where is None else squared[where])))


def run(material: Material, label: str, factors: tuple[int, ...], split: bool = False) -> None:
    """Print the three errors per reduction; ``split``: also on the small texels whose area
    holds a groove (lost slope variance > :data:`GROOVE_VARIANCE`) and on the others."""
    full = swatch_radiance(material)
    h, w = material.size
    for factor in factors:
        size = (h // factor, w // factor)
        truth = box_average(full, factor)
        renders = [
            swatch_radiance(reduced)
            for reduced in (
                resize_material(material, size),
                area_plain(material, size),
                resize_material(material, size, keep_variance=True),
            )
        ]
        plain, area, kept = (rmse(image, truth) for image in renders)
        print(
            f"{label:24s} {factor}x  plain {plain:.4f}  area {area:.4f}  kept {kept:.4f}  "
            f"kept/plain {kept / plain:.3f} = area/plain {area / plain:.3f} "
            f"x kept/area {kept / area:.3f}",
            flush=True,
        )
        if split:
            groove = groove_texels(material, size)
            for name, where in (("groove texels", groove), ("other texels", ~groove)):
                errors = "  ".join(
                    f"{kind} {rmse(image, truth, where):.3f} (mean {image[where].mean():.2f})"
                    for kind, image in zip(("plain", "area", "kept"), renders, strict=True)
                )
                print(
                    f"  {name} ({where.mean():.0%}, truth mean {truth[where].mean():.2f}): "
                    + errors,
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
        run(material, f"chessboard crop {crop[1]},{crop[2]}", (2, 4, 8), split=True)
        run(normals, "  normals only", (4, 8), split=True)
    if args.whole:
        whole, whole_normals = chessboards(None)
        run(whole, "chessboard", (2, 4, 8))
        run(whole_normals, "  normals only", (2, 4, 8))


if __name__ == "__main__":
    main()
