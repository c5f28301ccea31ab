"""Brush tip dabs and stencils: speed as ratios to OpenCV's warpAffine, measured in one run.

    python benchmarks/tips.py [--repeat N]

A tip dab is the tip image scaled to the dab's diameter and turned, sampled
bilinearly at the texel centres of its block (``Brush.footprint``); the
baseline is ``cv2.warpAffine`` (fixed-point bilinear, SIMD) of the same tip
level onto the same block. A stencil mask of a dab's block (a 4K stencil at
half scale) is timed against the same warp of the stencil's matching level.
Also: a whole 600-texel stroke with a tip (dynamics on) against the round
dab, the cost tips add to painting. Ratios are paired runs (the machine is shared),
both sides on one thread.

Goals: a tip dab and a stencil mask within 5x of OpenCV's warp, which is SIMD
with 1/32-pixel fixed-point weights (ours is a scalar float loop, exact to
the tests' independent scipy warp); a stroke with a tip and dynamics within
1.5x of the round stroke (stamping into the layer dominates either way).
"""

from __future__ import annotations

import argparse
import math
import time

import cv2
import numpy as np
from _common import goal, paired_ratios

from matshop.layers import AddLayer, Document, History
from matshop.material import Material, Schema
from matshop.paint import (
    Brush,
    Dynamics,
    Stencil,
    StrokeSample,
    Swatch,
    paint_stroke,
    procedural_tip,
)


def warp(image: np.ndarray, size: int, scale: float, angle_deg: float) -> np.ndarray:
    t = math.radians(angle_deg)
    forward = scale * np.array([[math.cos(t), math.sin(t)], [-math.sin(t), math.cos(t)]])
    h, w = image.shape
    shift = np.array([size / 2 - 0.5, size / 2 - 0.5]) - forward @ np.array(
        [w / 2 - 0.5, h / 2 - 0.5]
    )
    return cv2.warpAffine(
        image, np.hstack([forward, shift[:, None]]), (size, size), flags=cv2.INTER_LINEAR
    )


def stroke_doc() -> tuple[Document, int]:
    schema = Schema.from_names(["base_color", "roughness"])
    maps = {
        "base_color": np.full((1024, 1024, 3), 0.5, np.float32),
        "roughness": np.full((1024, 1024, 1), 0.5, np.float32),
    }
    doc = Document.from_material(Material("b", schema, maps))
    layer = doc.new_paint_layer("p")
    History(doc).push(AddLayer(layer))
    return doc, layer.id


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    cv2.setNumThreads(1)  # one thread each: the dab kernel is single-threaded too
    tip = procedural_tip("noise", 1)
    for radius in (16.0, 64.0, 256.0):
        brush = Brush(radius_px=radius, tip=tip)
        x0, y0, alpha = brush.footprint(500.3, 500.7, radius, 30.0)
        scale = 2 * radius / 128
        level = tip.pyramid.level_for(scale)
        image = tip.pyramid.levels[level]
        size = alpha.shape[0]
        ratios = paired_ratios(
            lambda b=brush, r=radius: b.footprint(500.3, 500.7, r, 30.0),
            lambda i=image, s=size, sc=scale * (1 << level): warp(i, s, sc, 30.0),
            args.repeat,
            inner=max(1, int(2000 / radius)),
        )
        goal(f"tip dab r={radius:g} / cv2.warpAffine", ratios, 5.0)

    rng = np.random.default_rng(0)
    stencil = Stencil(rng.random((4096, 4096), dtype=np.float32), (500.0, 500.0), 0.5, 20.0)
    level = stencil._pyramid.level_for(0.5)  # type: ignore[union-attr]
    image = stencil._pyramid.levels[level]  # type: ignore[union-attr]
    ratios = paired_ratios(
        lambda: stencil.mask(400, 400, 200, 200),
        lambda: warp(image, 200, 0.5 * (1 << level), 20.0),
        args.repeat,
        inner=20,
    )
    goal("stencil mask 200^2 / cv2.warpAffine", ratios, 5.0)

    path = [StrokeSample(200 + 60 * i, 500 + 80 * math.sin(i / 2)) for i in range(11)]
    swatch = Swatch("s", {"base_color": (0.8, 0.2, 0.1)})
    tipped = Brush(
        radius_px=24.0,
        tip=procedural_tip("scratches", 2),
        dynamics=Dynamics(
            rotation="follow", size_jitter=0.3, angle_jitter_deg=15, scatter_across=0.3
        ),
    )
    plain = Brush(radius_px=24.0)

    def paint(brush: Brush) -> None:
        doc, layer = stroke_doc()
        paint_stroke(doc, layer, path, brush, swatch=swatch, seed=3)

    start = time.process_time()
    ratios = paired_ratios(lambda: paint(tipped), lambda: paint(plain), args.repeat)
    goal("stroke with a tip and dynamics / round stroke", ratios, 1.5)
    print(f"(process time of the whole run {time.process_time() - start:.1f} s)")


if __name__ == "__main__":
    main()
