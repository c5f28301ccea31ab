"""Layer document: the cost of one brush dab against a full flatten, in one run.

    python benchmarks/document.py [--size 4096] [--layers 20] [--dabs 50] [--tile-size 64]
    python benchmarks/document.py --sweep 32,64,128,256   # choose the tile size

Data: the shared chessboard PBR set (base color, metallic, roughness,
normal: 8 edit channels), tiled 2x2 to 4096x4096, as the bottom fill layer;
synthetic values when it is absent. The stack has ``--layers`` layers: the
base, sparse paint layers in assorted blend modes (each with a few
64-px-radius dabs), a masked constant fill ("rust"), a Gaussian blur filter
layer (sigma 2 px) in the middle and a levels filter near the top.

Measured:

- full flatten: every cache dropped, then flatten to edit space and
  ``from_edit`` of every tile (what an export or the first display costs);
- dab update: one soft dab of radius 64 px on a paint layer, painted by the
  brush engine (a one-sample stroke of :class:`matshop.paint.StrokeSession`
  with a material swatch, one undo step), then the update of just the dirty
  tiles; p50/p95 over ``--dabs`` dabs, as a ratio to
  the full flatten (issue [C] asks for <= 1%), on a layer above the blur and
  on one below it (whose dab the blur spreads to neighbouring tiles);
- memory: bytes of an empty layer, of the layer payloads, caches and history,
  and the peak resident size of the process.
"""

from __future__ import annotations

import argparse
import gc
import resource
import time
import tracemalloc
from pathlib import Path

import numpy as np

from matshop.layers import (
    AddLayer,
    Document,
    History,
    PaintTransaction,
    Rect,
    SetMask,
    flatten_reference,
)
from matshop.material import EditMaterial, Schema
from matshop.paint import Brush, StrokeSample, StrokeSession, Swatch

CHESSBOARD = Path(__file__).resolve().parents[2] / "shared" / "data" / "chessboard"
RADIUS = 64
BLENDS = ("normal", "normal", "add", "multiply", "subtract", "detail", "normal")


def base_material(size: int) -> tuple[EditMaterial, str]:
    """The real set in edit space, tiled up (or cropped) to ``size`` x ``size``."""
    if CHESSBOARD.is_dir():
        from matshop.io.material_io import load_material

        material, _ = load_material(CHESSBOARD)
        edit = material.to_edit()
        what = f"chessboard ({', '.join(material.schema.names)}), tiled to {size}"
        data = edit.data
        reps = -(-size // data.shape[0]), -(-size // data.shape[1]), 1
        data = np.ascontiguousarray(np.tile(data, reps)[:size, :size])
        return EditMaterial(edit.name, edit.schema, data), what
    schema = Schema.from_names(["base_color", "metallic", "roughness", "normal"])
    rng = np.random.default_rng(0)
    data = rng.random((size, size, schema.edit_width), dtype=np.float32) * 0.5
    return EditMaterial("synthetic", schema, data), "synthetic (chessboard absent)"


BRUSH = Brush(radius_px=RADIUS, hardness=0.5)


def swatch_of(schema: Schema, edit_vector: np.ndarray, name: str) -> Swatch:
    """The physical values of one edit vector, as a brush swatch."""
    values = {}
    for param in schema.parameters:
        edit = edit_vector[schema.edit_slices[param.name]].reshape(1, 1, -1)
        values[param.name] = param.space.from_edit(edit).reshape(-1)
    return Swatch(name, values)


def paint_dab(doc: Document, history: History, layer_id: int, x: int, y: int, swatch) -> None:
    stroke = StrokeSession(doc, layer_id, BRUSH, swatch=swatch, history=history, label="Dab")
    stroke.add([StrokeSample(x + 0.5, y + 0.5)])
    stroke.end()


def build(size: int, layers: int, tile: int, seed: int = 1):
    base, what = base_material(size)
    doc = Document(base.schema, size, size, tile_size=tile, name=base.name)
    history = History(doc)
    history.push(AddLayer(doc.new_fill_layer("base", source=base.data)))
    rng = np.random.default_rng(seed)
    picked = base.data[rng.integers(0, size, 32), rng.integers(0, size, 32)]
    swatches = [swatch_of(base.schema, vector, f"swatch {i}") for i, vector in enumerate(picked)]
    paint_ids = []
    fixed = 4  # base, rust fill, blur, levels
    blur_at = 1 + (layers - fixed) // 2
    for i in range(layers - fixed):
        if len(doc) == blur_at:
            blur = doc.new_filter_layer("blur", "soften", op_params={"sigma_px": 2.0})
            history.push(AddLayer(blur))
        layer = doc.new_paint_layer(f"paint {i}", blend=BLENDS[i % len(BLENDS)], opacity=0.8)
        history.push(AddLayer(layer))
        paint_ids.append(layer.id)
        for _ in range(6):
            x, y = rng.integers(0, size, 2)
            paint_dab(doc, history, layer.id, int(x), int(y), swatches[rng.integers(32)])
    rust = doc.new_fill_layer("rust", value=picked[0], opacity=0.4, parameters=["base_color"])
    history.push(AddLayer(rust))
    history.push(SetMask(rust.id, doc.new_mask(0.0)))
    tx = PaintTransaction(doc, rust.id, "mask")
    for _ in range(10):
        x, y = rng.integers(0, size - 4 * RADIUS, 2)
        tx.paint(
            Rect(x, y, x + 4 * RADIUS, y + 4 * RADIUS), 1.0, np.full((256, 256), 0.6, np.float32)
        )
    history.push(tx.commit(), applied=True)
    levels = doc.new_filter_layer(
        "levels", "tone", op_params={"gamma": 1.2}, parameters=["roughness"]
    )
    history.push(AddLayer(levels))
    below = [lid for lid in paint_ids if doc.index_of(lid) < doc.index_of(blur.id)]
    above = [lid for lid in paint_ids if doc.index_of(lid) > doc.index_of(blur.id)]
    return doc, history, swatches, below[-1], above[-1], what


def full_flatten(doc: Document) -> float:
    doc.invalidate_all()
    start = time.perf_counter()
    doc.update()
    return time.perf_counter() - start


def dab_updates(doc, history, layer_id, swatches, count: int, seed: int) -> tuple[list, list, list]:
    rng = np.random.default_rng(seed)
    paint_times, update_times, tiles = [], [], []
    for i in range(count):
        x, y = (int(v) for v in rng.integers(RADIUS, doc.width - RADIUS, 2))
        start = time.perf_counter()
        paint_dab(doc, history, layer_id, x, y, swatches[i % len(swatches)])
        middle = time.perf_counter()
        recomputed = doc.update()
        end = time.perf_counter()
        paint_times.append(middle - start)
        update_times.append(end - middle)
        tiles.append(int(recomputed.sum()))
    return paint_times, update_times, tiles


def empty_layer_bytes(doc: Document) -> tuple[int, int]:
    tracemalloc.start()
    before = tracemalloc.take_snapshot()
    layer = doc.new_paint_layer("empty")
    after = tracemalloc.take_snapshot()
    tracemalloc.stop()
    assert layer.pixels is not None
    # what matshop's lines allocated (numpy buffers included), not the snapshots
    stats = after.compare_to(before, "filename")
    return layer.pixels.footprint(), sum(
        s.size_diff for s in stats if "matshop" in s.traceback[0].filename
    )


def run(args, tile: int, check: bool) -> dict[str, float]:
    start = time.perf_counter()
    doc, history, swatches, below_id, above_id, what = build(args.size, args.layers, tile)
    setup = time.perf_counter() - start
    # warm up: numba compiles its kernels for each array layout on first use
    full_flatten(doc)
    for layer_id in (below_id, above_id):
        dab_updates(doc, history, layer_id, swatches, 3, seed=0)
    full = min(full_flatten(doc) for _ in range(args.repeat))
    results = {"tile": tile, "full": full, "setup": setup}
    print(f"\ntile {tile}: {doc}\n  data: {what}; setup {setup:.1f} s")
    count = doc.layout.rows * doc.layout.cols
    print(f"  full flatten (edit + from_edit, {count} tiles): {full:.2f} s")
    for label, layer_id, seed in (("above blur", above_id, 2), ("below blur", below_id, 3)):
        paint, update, tiles = dab_updates(doc, history, layer_id, swatches, args.dabs, seed)
        p50, p95 = np.percentile(update, [50, 95])
        results[f"p50 {label}"] = p50
        results[f"p95 {label}"] = p95
        print(
            f"  dab r={RADIUS} {label:10s}: update p50 {p50 * 1e3:6.1f} ms"
            f" ({p50 / full:6.2%} of full)"
            f"  p95 {p95 * 1e3:6.1f} ms ({p95 / full:6.2%})  tiles {int(np.median(tiles))}"
            f"  paint p50 {np.median(paint) * 1e3:5.1f} ms"
        )
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20
    print(f"  peak resident memory so far (data, stack, caches, history): {peak:.2f} GiB")
    if check:
        start = time.perf_counter()
        same = np.array_equal(doc.flatten_edit(copy=False), flatten_reference(doc))
        print(
            f"  cached flatten == uncached reference: {same} ({time.perf_counter() - start:.1f} s)"
        )
    footprint, allocated = empty_layer_bytes(doc)
    memory = doc.memory()
    print(
        f"  empty layer: {footprint} B (grid footprint), {allocated} B allocated in all"
        f"\n  layers {memory['layers'] / 2**20:.0f} MiB, caches {memory['caches'] / 2**20:.0f} MiB,"
        f" history {history.report()}"
    )
    results["memory"] = memory["total"]
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=4096)
    parser.add_argument("--layers", type=int, default=20)
    parser.add_argument("--dabs", type=int, default=50)
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--tile-size", type=int, default=64)
    parser.add_argument("--sweep", type=str, default="", help="comma-separated tile sizes")
    parser.add_argument("--no-check", action="store_true", help="skip the uncached comparison")
    args = parser.parse_args()
    tiles = [int(t) for t in args.sweep.split(",")] if args.sweep else [args.tile_size]
    rows = []
    for tile in tiles:
        rows.append(run(args, tile, check=not args.no_check and len(tiles) == 1))
        gc.collect()  # the document and its history form reference cycles
    if len(rows) > 1:
        print("\ntile  full s  p50 above  p95 above  p50 below  p95 below  (ms; % of full)")
        for r in rows:
            cells = "  ".join(
                f"{r[k] * 1e3:5.1f} {r[k] / r['full']:5.2%}"
                for k in ("p50 above blur", "p95 above blur", "p50 below blur", "p95 below blur")
            )
            print(f"{r['tile']:4d}  {r['full']:6.2f}  {cells}")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20
    print(f"\npeak resident memory of the process (all runs): {peak:.2f} GiB")


if __name__ == "__main__":
    main()
