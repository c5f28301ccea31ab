"""Measure export round trips: every built-in preset, written and read back.

usage: python tools/export_roundtrip.py [TEXTURE_SET] [--size N]

Exports the set (default: ../shared/data/chessboard, else the bundled sample)
with each preset into a temporary folder, re-imports it with the generic
importer and prints the worst error per parameter: scalars and colors in
8-bit codes, normals in degrees. With --size the set is first resampled in
edit space (values off the 8-bit grid, so quantisation shows).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from matshop.export.core import export_material
from matshop.export.presets import builtin_preset_names, load_preset
from matshop.export.resize import resize_material
from matshop.io.material_io import load_material

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default = ROOT.parent / "shared" / "data" / "chessboard"
    parser.add_argument("set", nargs="?", type=Path, default=None)
    parser.add_argument("--size", type=int, default=None)
    args = parser.parse_args()
    source = args.set or (default if default.is_dir() else ROOT / "resources" / "sample")
    material, _ = load_material(source)
    if args.size:
        material = resize_material(material, (args.size, args.size))
    height, width = material.size
    print(f"{source} at {width}x{height}")
    for name in builtin_preset_names():
        preset = load_preset(name)
        with tempfile.TemporaryDirectory() as out:
            start = time.perf_counter()
            export_material(material, preset, out)
            seconds = time.perf_counter() - start
            back, _ = load_material(out, normal_convention=preset.normal_convention)
        cells = []
        for param in material.schema.names:
            a = material.maps[param].astype(np.float64)
            b = back.maps[param].astype(np.float64)
            if param == "normal":
                sine = np.linalg.norm(np.cross(a[..., :3], b[..., :3]), axis=-1)
                angle = np.degrees(np.arctan2(sine, np.sum(a[..., :3] * b[..., :3], axis=-1)))
                cells.append(f"normal {angle.max():.3f} deg")
            else:
                cells.append(f"{param} {255 * np.abs(a - b).max():.4f}")
        print(f"  {name:11s} {seconds:5.2f} s  " + ", ".join(cells))


if __name__ == "__main__":
    main()
