"""The README's picture of brush tips and a stencil: docs/editor/tips_and_stencil.png.

Run under a display (``xvfb-run -a python scripts/tips_picture.py``): the real
editor opens the sample, lays a lettered stencil over the canvas, paints
spots through it and scratches that follow the stroke below it, then grabs
the canvas.
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
from PySide6.QtWidgets import QApplication

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from matshop.app.brush_images import choose_stencil  # noqa: E402
from matshop.app.testing import drag, make_window, spin  # noqa: E402


def main() -> None:
    app = QApplication.instance() or QApplication([])
    folder = Path(tempfile.mkdtemp())
    window = make_window(folder)
    window.resize(1500, 900)
    window.show()
    assert window.open_path(ROOT / "resources" / "sample")
    canvas = window.canvas
    canvas.actual_size()
    stencil = np.zeros((150, 520), np.uint8)
    cv2.putText(stencil, "matshop", (14, 112), cv2.FONT_HERSHEY_DUPLEX, 3.6, 255, 14)
    path = folder / "letters.png"
    cv2.imwrite(str(path), stencil)
    assert choose_stencil(window, path)
    settings = window.brush_settings.stencil
    centre = canvas.to_widget(256, 190)
    settings.set_image(settings.stencil, (centre.x(), centre.y()), 0.85 * canvas.view.zoom)

    tips, brush = window.brush_settings.tips, window.brush_settings
    tips.set_kind("spots")
    tips.set_rotation("random")
    tips.set("scatter_across", 0.3)
    brush.set("radius_px", 32.0)
    brush.set("spacing", 0.2)
    window.swatch_model.set_value("base_color", (0.12, 0.45, 0.75))
    for y in (172, 208):  # spots through the letters, all on the sheet
        drag(canvas, [canvas.to_widget(70 + 38 * i, y + 5 * math.sin(i)) for i in range(11)])
    settings.clear()

    tips.set_kind("scratches")
    tips.set_rotation("follow")
    tips.set("scatter_across", 0.0)
    tips.set("size_jitter", 0.3)
    tips.set("angle_jitter_deg", 8.0)
    brush.set("radius_px", 36.0)
    brush.set("spacing", 0.2)
    window.swatch_model.set_value("base_color", (0.95, 0.9, 0.7))
    points = [canvas.to_widget(40 + 36 * i, 400 + 40 * math.sin(i / 2.2)) for i in range(13)]
    drag(canvas, points)
    # the stencil again, where it lay, to show it over the result
    assert choose_stencil(window, path)
    settings.set_image(settings.stencil, (centre.x(), centre.y()), 0.85 * canvas.view.zoom)
    canvas.flush()
    spin(100)
    image = canvas.grab()
    top_left = canvas.to_widget(0, 0)
    size = round(512 * canvas.view.zoom)
    margin = 24
    image = image.copy(
        round(top_left.x()) - margin,
        round(top_left.y()) - margin,
        size + 2 * margin,
        size + 2 * margin,
    )
    out = ROOT / "docs" / "editor" / "tips_and_stencil.png"
    image.save(str(out))
    print(f"wrote {out} ({image.width()}x{image.height()})")
    window.prompts.save_answer = "discard"
    window.close()
    app.processEvents()


if __name__ == "__main__":
    main()
