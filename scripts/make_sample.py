"""Generate the bundled sample material ``resources/sample/tiles_*``.

A 4x4 grid of bevelled ceramic tiles in grout, one row of brushed gold
tiles, with per-tile color and roughness variation and fine noise. Every map
tiles seamlessly (all noise is periodic), so the sample exercises wrap-around
filtering. Deterministic: the same seed gives the same bytes.

    python scripts/make_sample.py [OUT_DIR]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter

from matshop.io.images import write_image
from matshop.spaces.color import linear_to_srgb
from matshop.spaces.frame import encode_normal_map, height_to_normal

SIZE = 512
TILES = 4
GROUT_PX = 6
BEVEL_PX = 10
SEED = 20261124


def periodic_noise(rng: np.random.Generator, sigma_px: float) -> np.ndarray:
    """Zero-mean, unit-std noise, smooth at ``sigma_px`` and periodic in both axes."""
    noise = gaussian_filter(rng.standard_normal((SIZE, SIZE)), sigma_px, mode="wrap")
    return (noise - noise.mean()) / noise.std()


def tile_layout() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-texel tile id, distance to the nearest tile edge in px, and a grout mask."""
    pitch = SIZE // TILES
    coords = np.arange(SIZE)
    local = coords % pitch
    edge_dist_1d = np.minimum(local, pitch - 1 - local).astype(np.float32) - GROUT_PX / 2
    edge_dist = np.minimum(edge_dist_1d[:, None], edge_dist_1d[None, :])
    tile_id = (coords[:, None] // pitch) * TILES + coords[None, :] // pitch
    grout = edge_dist < 0
    return tile_id, edge_dist, grout


def main(out_dir: Path) -> None:
    rng = np.random.default_rng(SEED)
    tile_id, edge_dist, grout = tile_layout()
    gold_row = tile_id // TILES == 2

    # height: a rounded bevel rising over BEVEL_PX, small per-tile tilt, fine bumps
    bevel = np.clip(edge_dist / BEVEL_PX, 0.0, 1.0)
    height = np.sin(0.5 * np.pi * bevel) * 4.0
    tilt = rng.normal(0.0, 0.01, size=(TILES * TILES, 2))
    rows, cols = np.mgrid[0:SIZE, 0:SIZE].astype(np.float32)
    height += np.where(grout, 0.0, tilt[tile_id, 0] * (rows % (SIZE // TILES)))
    height += np.where(grout, 0.0, tilt[tile_id, 1] * (cols % (SIZE // TILES)))
    height += 0.5 * periodic_noise(rng, 3.0) + np.where(grout, 0.5 * periodic_noise(rng, 2.0), 0)
    normal = height_to_normal(height[..., None].astype(np.float32), strength=1.0, wrap=True)

    # base color, built in linear reflectance then sRGB-encoded
    tile_tint = rng.uniform(0.85, 1.1, size=(TILES * TILES, 1))
    ceramic = np.array([0.55, 0.18, 0.12]) * tile_tint[tile_id]
    gold = np.array([0.95, 0.70, 0.30]) * np.ones((SIZE, SIZE, 1))
    grout_color = np.array([0.30, 0.29, 0.27]) * np.ones((SIZE, SIZE, 1))
    albedo = np.where(gold_row[..., None], gold, ceramic)
    albedo = np.where(grout[..., None], grout_color, albedo)
    albedo *= 1.0 + 0.06 * periodic_noise(rng, 3.0)[..., None]
    base_color = linear_to_srgb(np.clip(albedo, 0.0, 1.0).astype(np.float32))

    # roughness: glossy glaze, rough grout, brushed gold streaks along rows
    tile_rough = rng.uniform(0.18, 0.4, size=TILES * TILES)[tile_id]
    streaks = gaussian_filter(rng.standard_normal((SIZE, SIZE)), (0.5, 12.0), mode="wrap")
    streaks /= streaks.std()
    roughness = np.where(gold_row, 0.3 + 0.05 * streaks, tile_rough)
    roughness = np.where(grout, 0.85, roughness) + 0.03 * periodic_noise(rng, 2.5)
    metallic = np.where(gold_row & ~grout, 1.0, 0.0)
    occlusion = np.clip(0.55 + 0.45 * np.clip(edge_dist / (2 * BEVEL_PX) + 0.5, 0, 1), 0, 1)

    out_dir.mkdir(parents=True, exist_ok=True)
    write_image(out_dir / "tiles_basecolor.png", base_color, bit_depth="uint8")
    write_image(out_dir / "tiles_normal.png", encode_normal_map(normal), bit_depth="uint8")
    write_image(out_dir / "tiles_roughness.png", np.clip(roughness, 0, 1)[..., None])
    write_image(out_dir / "tiles_metallic.png", metallic[..., None].astype(np.float32))
    write_image(out_dir / "tiles_ao.png", occlusion[..., None].astype(np.float32))


if __name__ == "__main__":
    root = Path(__file__).resolve().parent.parent
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else root / "resources" / "sample")
