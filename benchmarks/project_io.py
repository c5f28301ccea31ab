"""Saving a project vs reopening it, on the 2K set with painted layers (same process).

Reopening must not take longer than saving (issue [I]: a 31 MB project took 15 s to reopen,
2.2 s to save). Prints both times and their ratio; the baseline is the save itself.

    python benchmarks/project_io.py [--layers 3] [--repeat 3]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
from _common import CHESSBOARD, best_time, goal, paired_ratios

from matshop.io.material_io import load_material
from matshop.io.project import load_project, save_project
from matshop.layers import AddLayer, Document, History
from matshop.material import Material, Schema
from matshop.paint import Brush, StrokeSample, StrokeSession, Swatch


def document(layers: int) -> tuple[Document, str]:
    if CHESSBOARD.is_dir():
        material, _ = load_material(CHESSBOARD)
        what = "chessboard 2K"
    else:
        rng = np.random.default_rng(0)
        schema = Schema.from_names(["base_color", "roughness"])
        maps = {
            "base_color": rng.random((2048, 2048, 3), dtype=np.float32),
            "roughness": rng.random((2048, 2048, 1), dtype=np.float32),
        }
        material, what = Material("synthetic", schema, maps), "synthetic 2K"
    doc = Document.from_material(material)
    history = History(doc)
    rng = np.random.default_rng(1)
    for number in range(layers):
        layer = doc.new_paint_layer(f"Paint {number}")
        history.push(AddLayer(layer))
        values = {p.name: material.maps[p.name][5, 5].tolist() for p in doc.schema.parameters}
        session = StrokeSession(
            doc, layer.id, Brush(radius_px=120), swatch=Swatch("s", values), history=history
        )
        points = rng.uniform(0, 2048, (12, 2))
        session.add([StrokeSample(float(x), float(y)) for x, y in points])
        session.end()
    return doc, f"{what}, {layers} painted layers"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--layers", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    doc, what = document(args.layers)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "bench.matshop"
        save_s = best_time(lambda: save_project(doc, path), args.repeat)
        size_mb = path.stat().st_size / 1e6
        load_s = best_time(lambda: load_project(path), args.repeat)
        print(f"{what}: project {size_mb:.1f} MB")
        ratio = load_s / save_s
        print(f"  save {save_s:.2f} s, reopen {load_s:.2f} s, reopen / save = {ratio:.2f}")
        ratios = paired_ratios(lambda: load_project(path), lambda: save_project(doc, path), 3)
    goal("project reopen / save", ratios, 1.0)


if __name__ == "__main__":
    main()
