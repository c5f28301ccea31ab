"""The canvas' lit display at 2K: how long a light move takes to reach the canvas.

    xvfb-run -a -s "-screen 0 1280x1024x24" python benchmarks/lit_display.py [--moves 8]

Needs an OpenGL 3.3 core context (under Xvfb: Mesa llvmpipe, the CPU); the
renderer string and the load average are printed first. Data: the shared 2K
chessboard when present, else a synthetic 2K set.

- **passes** (this thread's own context, :class:`SwatchRenderer`): one full
  2K pass (draw + ``glFinish`` + read back) and the coarse passes at mip
  levels 1-4, for a light move (the lights only) and after a material change
  (the base too), against two baselines measured in the same process: a memory
  copy of the 2K RGBA8 picture and a 2K RGBA8 texture upload (``glTexSubImage2D``
  + ``glFinish``);
- **light moves in the editor** (:class:`LitPreview` on a canvas, its GL
  thread): for ``--moves`` light positions, the time from the move to the
  first picture shown (coarse, marked "refining"), to the full 2K picture,
  and to the "refining" note (set before the move returns).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np
from _common import CHESSBOARD, best_time

from matshop.viewport.gl.context import install_default_format


def _document():
    from matshop.layers import Document
    from matshop.material import Material, Schema

    if CHESSBOARD.is_dir():
        from matshop.io.material_io import load_material

        material, _ = load_material(CHESSBOARD)
        return Document.from_material(material.to_edit()), "chessboard 2K"
    rng = np.random.default_rng(0)
    schema = Schema.from_names(["base_color", "roughness", "normal"])
    normal = rng.normal(0.0, 0.2, (2048, 2048, 3)).astype(np.float32)
    normal[..., 2] = 1.0
    normal /= np.linalg.norm(normal, axis=2, keepdims=True)
    maps = {
        "base_color": rng.random((2048, 2048, 3), dtype=np.float32),
        "roughness": rng.random((2048, 2048, 1), dtype=np.float32),
        "normal": normal,
    }
    return Document.from_material(Material("synthetic", schema, maps).to_edit()), "synthetic 2K"


def passes(doc, repeat: int) -> None:
    from OpenGL import GL

    from matshop.app import lit_scene
    from matshop.viewport.gl.context import OffscreenContext, renderer_string
    from matshop.viewport.gl.swatch import SwatchRenderer

    context = OffscreenContext()
    print(renderer_string())
    renderer = SwatchRenderer(tilt_deg=lit_scene.TILT_DEG)
    light = renderer.lighting
    light.samples, light.environment_scale = lit_scene.SAMPLES, lit_scene.ENVIRONMENT_SCALE
    light.lights = lit_scene.lights(lit_scene.light_direction(0.3, -0.4))
    renderer.set_document(doc)
    width, height = renderer.size(0)
    picture = np.zeros((height, width, 4), np.uint8)
    copy_s = best_time(lambda: picture.copy(), repeat)
    tex = GL.glGenTextures(1)
    GL.glBindTexture(GL.GL_TEXTURE_2D, tex)
    GL.glTexImage2D(
        GL.GL_TEXTURE_2D, 0, GL.GL_RGBA8, width, height, 0, GL.GL_RGBA, GL.GL_UNSIGNED_BYTE, None
    )

    def upload() -> None:
        GL.glBindTexture(GL.GL_TEXTURE_2D, tex)
        GL.glTexSubImage2D(
            GL.GL_TEXTURE_2D, 0, 0, 0, width, height, GL.GL_RGBA, GL.GL_UNSIGNED_BYTE, picture
        )
        GL.glFinish()

    upload_s = best_time(upload, repeat)
    print(
        f"baselines: memory copy of the {width}x{height} RGBA8 picture {copy_s * 1e3:.1f} ms, "
        f"its texture upload {upload_s * 1e3:.1f} ms"
    )
    for level in range(5):
        w, h = renderer.size(level)
        began = time.perf_counter()
        renderer.image(level)  # the material is new: its base (environment, emission) too
        changed_s = time.perf_counter() - began
        seconds = best_time(lambda level=level: renderer.image(level), repeat)  # lights only
        print(
            f"pass level {level} ({w}x{h}): light move {seconds * 1e3:.0f} ms = "
            f"{seconds / copy_s:.0f}x the copy, {seconds / upload_s:.1f}x the upload; "
            f"after a material change (with the base) {changed_s * 1e3:.0f} ms"
        )
    GL.glDeleteTextures([tex])
    renderer.delete()
    context.done_current()


def light_moves(doc, moves: int) -> None:
    from PySide6.QtCore import QEventLoop, QTimer

    from matshop.app.lit_preview import LitPreview
    from matshop.app.session import DocumentSession
    from matshop.viewport.canvas import TextureCanvas

    session = DocumentSession()
    canvas = TextureCanvas()
    canvas.resize(1000, 800)
    session.set_document(doc)
    canvas.set_document(doc)
    lit = LitPreview(session, canvas)
    lit.set_enabled(True)
    assert lit.gl is not None, lit.gl_problem
    assert lit.wait(600.0)
    shown: list[tuple[float, int]] = []
    lit.rendered.connect(lambda _s: shown.append((time.perf_counter(), canvas.overlay.width())))
    first, full, note = [], [], []
    for k in range(moves):
        shown.clear()
        began = time.perf_counter()
        lit.set_light_at(-0.8 + 1.6 * k / max(moves - 1, 1), 0.3 * (-1) ** k)
        note.append(time.perf_counter() - began if canvas.refining else float("inf"))
        while not lit.up_to_date():
            loop = QEventLoop()
            QTimer.singleShot(2, loop.quit)
            loop.exec()
        first.append(shown[0][0] - began)
        full.append(shown[-1][0] - began)
    levels = sorted({w for _, w in shown})
    ms = [f"{statistics.median(x) * 1e3:.0f} ms" for x in (note, first, full)]
    print(
        f"light move at 2K over {moves} moves (median): 'refining' shown after {ms[0]}, "
        f"first picture {ms[1]} (widths seen: {levels}), full 2K picture {ms[2]}"
    )
    lit.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--moves", type=int, default=8)
    args = parser.parse_args()
    install_default_format()
    from PySide6.QtWidgets import QApplication

    app = QApplication([])  # noqa: F841 - Qt needs it alive
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    doc, what = _document()
    print(f"data: {what}")
    passes(doc, args.repeat)
    light_moves(doc, args.moves)


if __name__ == "__main__":
    main()
