"""The layers panel per opacity change: rows and thumbnails it redoes, against rebuilding all.

    xvfb-run -a python benchmarks/layers_panel.py [--layers 12]

The editor opens the 2K chessboard (a synthetic 2K set when it is absent) and
gets ``--layers`` paint layers, each with a painted band, every other one with
a painted mask. Then one layer's opacity changes 20 times, as separate steps,
measured two ways in the same run:

- the panel as it is: the layer model repaints the changed row (no thumbnail
  is drawn: opacity changes no layer's content);
- the old way, every row rebuilt: each document change resets the model and
  forgets every thumbnail, as the panel's ``refresh()`` did before.

Printed per change: rows the view was told about, thumbnails drawn, the
panel's own time (the model's slots and the list's repaint) and the whole
change (edit, flatten scheduling, canvas and panels).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
from _common import CHESSBOARD

CHANGES = 20


def open_editor(layers: int):
    from PySide6.QtWidgets import QApplication

    from matshop.app.testing import make_window
    from matshop.layers import PaintTransaction, Rect
    from matshop.material import Material, Schema

    app = QApplication.instance() or QApplication([])
    window = make_window(Path(tempfile.mkdtemp()))
    window.resize(1560, 940)
    window.show()
    if CHESSBOARD.is_dir():
        assert window.open_path(CHESSBOARD)
    else:
        from matshop.layers import Document

        schema = Schema.from_names(["base_color", "roughness"])
        rng = np.random.default_rng(0)
        maps = {p.name: rng.random((2048, 2048, p.phys_channels), np.float32) for p in schema}
        window.session.set_document(Document.from_material(Material("synthetic", schema, maps)))
    session, commands = window.session, window.layer_commands
    doc = session.doc
    for number in range(layers):
        layer_id = commands.add_paint_layer()
        band = Rect(0, 150 * number % doc.height, doc.width, 150 * number % doc.height + 96)
        for target in ("pixels", "mask") if number % 2 else ("pixels",):
            if target == "mask":
                commands.add_mask()
            tx = PaintTransaction(doc, layer_id, target)
            value = np.full(doc.schema.edit_width, 0.3, np.float32) if target == "pixels" else 0.0
            tx.paint(band, value, np.ones((band.height, band.width), np.float32))
            session.push(tx.commit(), applied=True)
    app.processEvents()
    return app, window


def measure(app, window, layer_id: int, baseline: bool) -> dict[str, float]:
    import matshop.app.layer_model as layer_model

    panel = window.layers_panel
    model, doc = panel.model, window.session.doc
    counts = {"rows": 0, "thumbnails": 0}
    panel_s = 0.0

    def rows(first, last, *_roles) -> None:
        counts["rows"] += last.row() - first.row() + 1

    def reset() -> None:
        counts["rows"] += model.rowCount()

    real = layer_model.grid_thumbnail

    def drawn(*args, **kwargs):
        counts["thumbnails"] += 1
        return real(*args, **kwargs)

    def rebuild(*_args) -> None:  # the old refresh(): every row and thumbnail again
        nonlocal panel_s
        start = time.perf_counter()
        model._document_replaced()
        panel_s += time.perf_counter() - start

    model.dataChanged.connect(rows)
    model.modelReset.connect(reset)
    layer_model.grid_thumbnail = drawn
    if baseline:
        doc.events.layer.connect(rebuild)
    viewport = panel.list.viewport()
    total = time.perf_counter()
    for change in range(CHANGES):
        window.layer_commands.set_property(layer_id, "opacity", 0.9 - 0.02 * change)
        app.processEvents()
        start = time.perf_counter()
        viewport.repaint()
        panel_s += time.perf_counter() - start
    total = time.perf_counter() - total
    if baseline:
        doc.events.layer.disconnect(rebuild)
    layer_model.grid_thumbnail = real
    model.dataChanged.disconnect(rows)
    model.modelReset.disconnect(reset)
    return {
        "rows": counts["rows"] / CHANGES,
        "thumbnails": counts["thumbnails"] / CHANGES,
        "panel_ms": panel_s / CHANGES * 1e3,
        "total_ms": total / CHANGES * 1e3,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--layers", type=int, default=12)
    args = parser.parse_args()
    app, window = open_editor(args.layers)
    doc = window.session.doc
    target = doc.layers[len(doc.layers) // 2].id
    window.session.set_active_layer(target)
    app.processEvents()
    measure(app, window, target, baseline=False)  # warm-up
    rows = {
        "changed rows only": measure(app, window, target, baseline=False),
        "every row rebuilt": measure(app, window, target, baseline=True),
    }
    print(f"{doc.name}: {doc.width}x{doc.height}, {len(doc.layers)} layers; per opacity change:")
    for name, m in rows.items():
        print(
            f"  {name:18} rows {m['rows']:5.1f}  thumbnails {m['thumbnails']:5.1f}  "
            f"panel {m['panel_ms']:6.2f} ms  whole change {m['total_ms']:6.1f} ms"
        )
    new, old = rows["changed rows only"], rows["every row rebuilt"]
    print(f"panel time: rebuilding every row is {old['panel_ms'] / new['panel_ms']:.1f}x slower")
    window.prompts.save_answer = "discard"
    window.close()


if __name__ == "__main__":
    main()
