"""A filter layer's flatten, computed by the tiler with the op's declared reach, against the
op run once on the whole image (what a filter layer cost before ops declared a reach).

    python benchmarks/filter_tiles.py [--op bilateral] [--sigma 4] [--repeat 2]

On the 2K chessboard (a synthetic 2K set without it): best of ``--repeat`` full flattens
of a document holding the set and one filter layer (all caches dropped before each), and
best of the op itself on the set's edit array. The ratio is tiled / whole; slow (lattice)
ops are computed in blocks of at least 512 px and 16 reaches (``FilterLayer.block_tiles``),
so their margin costs at most ~1.27x.
"""

from __future__ import annotations

import argparse

from _common import CHESSBOARD, best_time

from matshop.layers import AddLayer, Document, History
from matshop.ops import get_op


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--op", default="bilateral")
    parser.add_argument("--sigma", type=float, default=4.0)
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    if CHESSBOARD.is_dir():
        from matshop.io.material_io import load_material

        edit = load_material(CHESSBOARD)[0].to_edit()
    else:
        import numpy as np

        from matshop.material import EditMaterial, Schema

        schema = Schema.from_names(["base_color", "roughness", "metallic"])
        data = np.random.default_rng(0).random((2048, 2048, schema.edit_width), np.float32)
        edit = EditMaterial("synthetic", schema, data)
    spec = get_op(args.op)
    values = spec.bind({"sigma_px": args.sigma})
    doc = Document.from_material(edit)
    layer = doc.new_filter_layer(args.op, op_params=values)
    History(doc).push(AddLayer(layer))
    reach = layer.reach(doc.layout, doc.schema)

    def tiled() -> None:
        doc.invalidate_all()
        doc.update()

    def whole() -> None:
        spec.function(edit.data, schema=edit.schema, **values)

    tiled_s = best_time(tiled, args.repeat)
    whole_s = best_time(whole, args.repeat)
    blocks = layer.block_tiles(doc.layout, reach) * doc.layout.tile_size if reach else "-"
    print(
        f"{edit.name} {edit.size[1]}x{edit.size[0]}, {args.op} sigma_px={args.sigma:g}: "
        f"reach {reach}, blocks {blocks} px"
    )
    print(
        f"  whole-image op {whole_s:.2f} s, tiled flatten {tiled_s:.2f} s, "
        f"ratio {tiled_s / whole_s:.2f}"
    )


if __name__ == "__main__":
    main()
