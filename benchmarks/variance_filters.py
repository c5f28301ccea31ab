"""Which reduction filter for the normal and the lobe? A far-field experiment (docs/variance.md).

``export --size`` resamples every parameter with Lanczos-3 in edit space. For the normal
and the lobe, whose effect on the image is far from linear, its negative lobes ring:
tilts and widths next to a groove that no texel of the footprint has. This compares,
against the same far-field truth as benchmarks/variance.py (the full render averaged
over each small pixel), the export as it is (Lanczos-3 for everything, with and without
``keep_variance``) with the same export whose normal and lobe channels are area-averaged
instead (colours still Lanczos-3), with and without the widening.

    python benchmarks/variance_filters.py            # the 512^2 grooved crop and the bumps (~1 min)
    python benchmarks/variance_filters.py --whole    # the whole 2K chessboard too (~4 min)

Not a shipped option: switching the filter changes plain exports as well.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _common import CHESSBOARD  # noqa: E402
from variance import FIGURE_CROP, bumpy, chessboards  # noqa: E402

from matshop.export.resize import area_matrix, resize_array  # noqa: E402
from matshop.material import EditMaterial, Material  # noqa: E402
from matshop.ops.variance import lost_slope_covariance, widen_lobes  # noqa: E402
from matshop.render.far_field import box_average, swatch_radiance  # noqa: E402

#: edit channels area-averaged in the "area" variants
SHADING = ("normal", "roughness")


def reduce(material: Material, size: tuple[int, int], *, area: bool, keep: bool) -> Material:
    """``material`` at ``size``: Lanczos-3 everywhere, or area-averaged normal and lobe."""
    edit = material.to_edit()
    data = resize_array(edit.data, size)
    if area:
        by_area = resize_array(edit.data, size, weights=area_matrix)
        for name in SHADING:
            data[..., edit.schema.edit_slices[name]] = by_area[..., edit.schema.edit_slices[name]]
    if keep:
        normal = material.maps["normal"][..., :3]
        cov = lost_slope_covariance(normal, lambda a: resize_array(a, size, weights=area_matrix))
        data = widen_lobes(data, edit.schema, cov)
    return EditMaterial(edit.name, edit.schema, data, edit.sources).to_physical()


def rmse(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a - b) ** 2)))


def run(material: Material, label: str, factors: tuple[int, ...]) -> None:
    full = swatch_radiance(material)
    h, w = material.size
    for factor in factors:
        size = (h // factor, w // factor)
        truth = box_average(full, factor)
        err = {
            (area, keep): rmse(swatch_radiance(reduce(material, size, area=area, keep=keep)), truth)
            for area in (False, True)
            for keep in (False, True)
        }
        base = err[False, False]
        print(
            f"{label:22s} {factor}x  Lanczos plain {base:.4f} kept {err[False, True]:.4f} "
            f"({err[False, True] / base:.2f}x) | area normal+lobe plain {err[True, False]:.4f} "
            f"({err[True, False] / base:.2f}x) kept {err[True, True]:.4f} "
            f"({err[True, True] / base:.2f}x, {err[True, True] / err[True, False]:.2f}x of "
            "its plain)",
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
    crop, crop_normals = chessboards(FIGURE_CROP)
    run(crop, "chessboard crop", (2, 4, 8))
    run(crop_normals, "chessboard crop normals", (4,))
    if args.whole:
        whole, whole_normals = chessboards(None)
        run(whole, "chessboard", (2, 4, 8))
        run(whole_normals, "chessboard normals", (4,))


if __name__ == "__main__":
    main()
