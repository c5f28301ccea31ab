"""Reference-renderer speed: a 512x512 sphere thumbnail with image-based lighting.

    python benchmarks/render.py [--repeat N] [--size 512]

Data: the shared chessboard set (2K base color, metallic, roughness, normal)
when present, else the bundled 512^2 sample. Ours: ``render`` end to end
(geometry, material prefilter from the 2K maps, diffuse from the irradiance
map, filtered importance sampling of the GGX lobe, background), at 16 and 32
specular samples per pixel. Baseline: one plain numpy pass over the same
pixels, the cheapest shading there is (a Lambertian ``albedo * max(0, n.l)``
with the normals and albedo already in memory), measured in the same run.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from _common import CHESSBOARD, best_time

from matshop.io.material_io import load_material
from matshop.render.environment import studio
from matshop.render.render import render

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--size", type=int, default=512)
    args = parser.parse_args()
    source = CHESSBOARD if CHESSBOARD.is_dir() else SAMPLE
    material, _ = load_material(source)
    h, w = material.size
    print(f"data: {source.name} ({w}x{h}: {', '.join(material.schema.names)})")
    env = studio()
    size = args.size

    rng = np.random.default_rng(0)
    normals = rng.normal(size=(size * size, 3)).astype(np.float32)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    albedo = rng.random((size * size, 3), dtype=np.float32)
    light = np.array([0.3, 0.5, 0.8], dtype=np.float32)
    base = best_time(lambda: albedo * np.maximum(normals @ light, 0.0)[:, None], args.repeat)

    for samples in (16, 32):
        ours = best_time(
            lambda s=samples: render(material, size=size, environment=env, samples=s), args.repeat
        )
        print(
            f"sphere {size}x{size} IBL, {samples:2d} samples/px  ours {ours * 1e3:7.1f} ms  "
            f"numpy Lambert pass {base * 1e3:6.1f} ms  ratio {ours / base:6.1f}"
        )


if __name__ == "__main__":
    main()
