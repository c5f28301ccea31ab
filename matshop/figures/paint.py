"""Fig. 9: a scripted painting session, replayed through the brush engine.

The paper's Fig. 9 shows materials painted interactively. Here the session is
a stroke file (:mod:`matshop.paint.strokefile`, the format ``matshop paint``
reads), written next to the figure as ``fig9_strokes.json`` and replayed
stroke by stroke into a paint layer over the data set (reduced to 512^2):

1. a bronze band (base color, low roughness, metallic) along a wave, pressure
   rising from 0.3 to 1 (the radius follows it);
2. soft dark grime (rough, dark, no metal) at low flow across the band;
3. a clone-stamp stroke copying part of the board sideways.

After each stroke the flattened material is rendered on the shared sphere
mesh (the procedural sphere if the mesh is absent): one frame per stroke.
Measured: the dabs each stroke laid down and the engine's time per dab
(``StrokeSession.add`` + ``end``, i.e. stamping, compositing into the layer
and recording the undo step; not the rendering).
"""

from __future__ import annotations

import json
import time

import numpy as np

from ..io.material_io import load_material
from ..layers import Document
from ..paint.painter import StrokeSession
from ..paint.strokefile import load_strokes
from ..render.render import render
from . import drawing
from .common import resized
from .context import ROOT, FigureContext, FigureResult, display

SIZE = 512
MESH = ROOT.parent / "shared" / "data" / "geometry" / "sphere.obj"
#: the parameters the paint layer holds (the swatches set all of them)
PAINTED = ("base_color", "roughness", "metallic")


def stroke_file(size: int = SIZE) -> dict:
    """The session's strokes as stroke-file JSON (texel coordinates on a ``size`` image)."""
    t = np.linspace(0.0, 1.0, 160)
    wave = [
        [
            round(size * (0.08 + 0.84 * u), 2),
            round(size * (0.3 + 0.08 * np.sin(3 * np.pi * u)), 2),
            round(0.3 + 0.7 * u, 3),
        ]
        for u in t
    ]
    grime = [[round(size * (0.2 + 0.6 * u), 2), round(size * (0.15 + 0.35 * u), 2), 1.0] for u in t]
    clone = [[round(size * 0.25, 2), round(size * (0.45 + 0.3 * u), 2), 1.0] for u in t]
    return {
        "strokes": [
            {
                "brush": {
                    "radius_px": 0.045 * size,
                    "hardness": 0.7,
                    "spacing": 0.1,
                    "size_pressure": [[0, 0.3], [1, 1]],
                },
                "swatch": {
                    "name": "bronze",
                    "values": {
                        "base_color": [0.8, 0.55, 0.3],
                        "roughness": [0.3],
                        "metallic": [1.0],
                    },
                },
                "points": wave,
            },
            {
                "brush": {
                    "radius_px": 0.06 * size,
                    "hardness": 0.1,
                    "spacing": 0.1,
                    "flow": 0.25,
                    "opacity": 0.8,
                },
                "swatch": {
                    "name": "grime",
                    "values": {
                        "base_color": [0.12, 0.1, 0.08],
                        "roughness": [0.9],
                        "metallic": [0.0],
                    },
                },
                "points": grime,
            },
            {
                "mode": "clone",
                "clone_offset": [round(0.45 * size), 0],
                "brush": {"radius_px": 0.05 * size, "hardness": 0.6, "spacing": 0.1},
                "points": clone,
            },
        ]
    }


def _frame(material, size: int) -> np.ndarray:
    scene = MESH if MESH.is_file() else "sphere"
    return display(render(material, scene=scene, size=size, samples=16))


def fig9(ctx: FigureContext) -> FigureResult:
    material, _ = load_material(ctx.data)
    material = resized(material, SIZE)
    path = ctx.outdir / "fig9_strokes.json"
    path.write_text(json.dumps(stroke_file(SIZE)))
    strokes = load_strokes(path)
    doc = Document.from_material(material)
    layer = doc.new_paint_layer("Paint", parameters=PAINTED)
    doc.insert_layer(layer)
    frames = [
        drawing.caption(_frame(doc.flatten_physical(), 200), ["start", "no strokes"], scale=0.4)
    ]
    values: dict[str, float] = {}
    total_dabs, total_s = 0, 0.0
    for number, stroke in enumerate(strokes, 1):
        start = time.perf_counter()
        session = StrokeSession(doc, layer.id, stroke.brush, **stroke.options)
        session.add(stroke.samples)
        session.end()
        elapsed = time.perf_counter() - start
        name = stroke.options.get("swatch").name if "swatch" in stroke.options else "clone"
        values[f"stroke{number}_dabs"] = float(session.dabs)
        values[f"stroke{number}_ms_per_dab"] = 1e3 * elapsed / max(session.dabs, 1)
        total_dabs += session.dabs
        total_s += elapsed
        label = f"{number}. {name}: {session.dabs} dabs"
        timing = f"{values[f'stroke{number}_ms_per_dab']:.2f} ms/dab"
        frames.append(
            drawing.caption(_frame(doc.flatten_physical(), 200), [label, timing], scale=0.4)
        )
    values["ms_per_dab"] = 1e3 * total_s / max(total_dabs, 1)
    image = drawing.caption(
        drawing.grid([frames], gap=3),
        [
            f"Fig. 9: a scripted painting session (fig9_strokes.json) replayed through the brush"
            f" engine on '{material.name}' ({SIZE}x{SIZE}),",
            f"one frame per stroke on the sphere mesh; {total_dabs} dabs,"
            f" {values['ms_per_dab']:.2f} ms per dab (stamp + composite + undo record).",
        ],
    )
    text = "; ".join(f"{k} {v:.3g}" for k, v in values.items())
    return FigureResult("fig9", ctx.save("fig9_painting", image), text, values)
