"""Symmetric painting on a mesh: one mirrored stroke against painting its mirror by hand.

    xvfb-run -a python benchmarks/mirror3d.py [--repeat 11] [--size 512] [--radius 12]

Needs an OpenGL 3.3 core context for the surface bake (under Xvfb: Mesa llvmpipe).
On the built-in 65k-triangle sphere, a 40-point stroke of closed-form surface hits
is painted with the X mirror (each dab also at the surface point nearest its
reflection: a KD-tree query and the exact point-triangle test, then its ball)
and, the baseline, as two plain strokes: the same hits and the mirrored hits
computed in closed form (what an artist without symmetry paints). The mirror
should cost little beyond the second stroke's dabs themselves: goal <= 1.25x.
Wall-clock ratios are paired; single-thread CPU time (time.process_time) of each
side is printed too (run with NUMBA_NUM_THREADS=1 for the lead's table).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _common import goal, paired_ratios

from matshop.viewport.gl.context import install_default_format


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=11)
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--radius", type=float, default=12.0)
    args = parser.parse_args()

    install_default_format()
    from PySide6.QtGui import QGuiApplication

    from matshop.layers import AddLayer, Document, History
    from matshop.material import Material, Schema
    from matshop.paint import Brush, Swatch
    from matshop.viewport.gl.context import OffscreenContext, renderer_string
    from matshop.viewport.gl.mesh_data import uv_sphere
    from matshop.viewport.gl.mirror import MeshMirror, MirrorPlane
    from matshop.viewport.gl.painting import SurfaceStroke
    from matshop.viewport.gl.picking import SurfaceHit
    from matshop.viewport.gl.surface_map import SurfaceMap

    app = QGuiApplication.instance() or QGuiApplication([])  # noqa: F841 (kept alive)
    context = OffscreenContext()  # noqa: F841 (current while it lives)
    print(f"renderer: {renderer_string()}")
    size = args.size
    schema = Schema.from_names(["base_color", "roughness"])
    maps = {
        "base_color": np.full((size, size, 3), 0.5, np.float32),
        "roughness": np.full((size, size, 1), 0.5, np.float32),
    }
    mesh = uv_sphere()
    surface = SurfaceMap(mesh, Document.from_material(Material("g", schema, maps)).layout)
    mirror = MeshMirror(mesh, MirrorPlane("x"))
    brush = Brush(radius_px=args.radius, spacing=0.15)
    swatch = Swatch("red", {"base_color": (0.9, 0.1, 0.1)})

    def hit(lon: float, lat: float) -> tuple[SurfaceHit, float]:
        p = np.array([np.sin(lon) * np.cos(lat), np.sin(lat), np.cos(lon) * np.cos(lat)])
        uv = np.array([0.5 + lon / (2 * np.pi), 0.5 + lat / np.pi])
        return SurfaceHit(p, p.copy(), uv), 1.0

    lons = np.radians(np.linspace(20.0, 70.0, 40))
    lats = np.radians(15.0 * np.sin(np.linspace(0.0, 3.0, 40)))
    hits = [hit(lon, lat) for lon, lat in zip(lons, lats, strict=True)]
    mirrored = [hit(-lon, lat) for lon, lat in zip(lons, lats, strict=True)]

    def paint(strokes: list, with_mirror: bool) -> None:
        doc = Document.from_material(Material("g", schema, maps))
        layer = doc.new_paint_layer("p")
        History(doc).push(AddLayer(layer))
        for points in strokes:
            stroke = SurfaceStroke(
                doc,
                layer.id,
                brush,
                surface,
                swatch=swatch,
                mirror=mirror if with_mirror else None,
            )
            stroke.add_hits(points)
            stroke.end()

    def ours() -> None:
        paint([hits], True)

    def base() -> None:
        paint([hits, mirrored], False)

    def cpu_s(fn) -> float:
        """Best single-thread CPU time of three runs (other processes do not count)."""
        times = []
        for _ in range(3):
            start = time.process_time()
            fn()
            times.append(time.process_time() - start)
        return min(times)

    cpu = [cpu_s(ours) / cpu_s(base) for _ in range(args.repeat)]
    print(f"CPU-time ratios: median {np.median(cpu):.3f} ({min(cpu):.3f}..{max(cpu):.3f})")
    ratios = paired_ratios(ours, base, args.repeat, inner=3)
    goal("3D mirrored stroke / two plain strokes", ratios, 1.25)


if __name__ == "__main__":
    main()
