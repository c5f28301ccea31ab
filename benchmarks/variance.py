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
    python benchmarks/variance.py --figure-only         # only the figure (~30 s)
    python benchmarks/variance.py --truth lanczos       # the table against a Lanczos truth

Every run also writes docs/figures/variance_far_field.png (docs/figures.md): at
4x, the far-field truth, the plain downsized render and the one with variance
kept, side by side, for the bumpy material and the chessboard crop
:data:`FIGURE_CROP`, and prints the RMSE of each panel.
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

from matshop.figures.drawing import caption, grid, side_label  # noqa: E402
from matshop.material import Material  # noqa: E402
from matshop.render.far_field import far_field_errors, far_field_renders  # noqa: E402
from matshop.render.materials import from_maps  # noqa: E402
from matshop.render.tonemap import to_display, to_uint8  # noqa: E402
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


#: the figure's chessboard crop (size, row, column): the lower board's squares and grooves
FIGURE_CROP = (512, 900, 1400)
FIGURE_FACTOR = 4
FIGURE = Path(__file__).resolve().parents[1] / "docs" / "figures" / "variance_far_field.png"


def _tile(display: np.ndarray, lines: list[str]) -> np.ndarray:
    """A display image shown 2x larger (nearest), captioned."""
    tile = to_uint8(display)
    return caption(np.repeat(np.repeat(tile, 2, axis=0), 2, axis=1), lines)


def figure(materials: list[tuple[str, Material]], path: Path = FIGURE) -> None:
    """Truth / plain / kept at :data:`FIGURE_FACTOR`x, one row per material, each captioned
    with its RMSE against the truth, then the two errors (grey: ``|error|``, the mean of
    RGB in linear radiance, white at twice the plain render's RMSE)."""
    import cv2

    rows = []
    for label, material in materials:
        renders = far_field_renders(material, FIGURE_FACTOR)
        plain, kept = renders.rmse(renders.plain), renders.rmse(renders.kept)
        # one exposure per row, from the truth, so a bright material is not all white
        exposure = float(-np.log2(max(np.percentile(renders.truth, 99.0), 1e-6)))
        panels = (
            (renders.truth, ["far-field truth:", "full res averaged 4x"]),
            (renders.plain, ["downsized, plain", f"RMSE {plain:.4f}"]),
            (renders.kept, ["downsized, variance kept", f"RMSE {kept:.4f}"]),
        )
        tiles = [_tile(to_display(image, exposure=exposure), text) for image, text in panels]
        for name, image in (("plain", renders.plain), ("kept", renders.kept)):
            error = np.abs(image - renders.truth).mean(axis=2, keepdims=True) / (2 * plain)
            grey = np.repeat(np.clip(error, 0.0, 1.0), 3, axis=2)
            tiles.append(_tile(grey, [f"|{name} - truth|", f"white: {2 * plain:.2f}"]))
        h, w = material.size
        lines = [label, f"{w}x{h} -> {w // 4}x{h // 4}", f"kept/plain {kept / plain:.2f}"]
        rows.append(side_label(grid([tiles]), lines))
        print(
            f"figure {label:28s} {FIGURE_FACTOR}x: plain {plain:.4f} kept {kept:.4f} "
            f"ratio {kept / plain:.3f}"
        )
    image = grid([[row] for row in rows], gap=6)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(path), image[..., ::-1], [cv2.IMWRITE_PNG_COMPRESSION, 9]):
        raise SystemExit(f"cannot write {path}")
    print(f"wrote {path}")


def figure_materials() -> list[tuple[str, Material]]:
    materials = [("synthetic bumps", bumpy())]
    if CHESSBOARD.is_dir():
        size, row, col = FIGURE_CROP
        materials.append((f"chessboard {size} at ({row},{col})", chessboards(FIGURE_CROP)[0]))
    return materials


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--crop",
        type=int,
        nargs=3,
        metavar=("SIZE", "ROW", "COL"),
        help="a SIZE x SIZE crop of the chessboard at ROW, COL (default: the whole set)",
    )
    parser.add_argument(
        "--figure-only", action="store_true", help="only write the figure and its numbers"
    )
    parser.add_argument(
        "--truth",
        choices=("box", "lanczos"),
        default="box",
        help="the far-field truth: the full render averaged over each small pixel (box, "
        "default) or resampled by the export's Lanczos-3 (the table only)",
    )
    args = parser.parse_args()
    if args.truth == "box":
        figure(figure_materials())
    if args.figure_only:
        return
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
        for r in far_field_errors(material, (2, 4, 8), truth=args.truth):
            print(
                f"{material.name:22s} {w:4d}x{h:<4d} {r.factor:6d} {r.rmse_plain:8.4f} "
                f"{r.rmse_kept:8.4f} {r.ratio:10.3f}"
            )
        print(f"  ({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
