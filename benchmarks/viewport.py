"""OpenGL viewport speed: frames per second and dab-to-screen latency.

    xvfb-run -a python benchmarks/viewport.py [--repeat N] [--size 512] [--dabs 20]

Needs an OpenGL 3.3 core context (under Xvfb: Mesa llvmpipe, i.e. the CPU;
on a workstation: its GPU); the renderer string is printed first.

Data: the shared chessboard set (2K) when present, else the bundled 512^2
sample, on the reference sphere (uv scale 2 x 1), studio environment, 16
specular samples per pixel (and 4, an interactive setting), one directional light.

- **frame**: one frame drawn offscreen at ``size x size`` (``glFinish``), against
  the numpy reference renderer's image of the same view in the same process
  (``matshop.render.render``; the baseline).
- **dab to screen**: one 3D dab painted on the sphere through the brush engine
  (stamp into the paint layer, the document's dirty tiles flattened, packed and
  uploaded, one frame drawn and finished), median over ``--dabs`` dabs at
  different places; against re-uploading the whole material (what every dab
  would cost without dirty tiles) plus a frame.
- **dab to screen at 4K**: the same on a 4096^2 document (the 2K set tiled
  2 x 2; ``--no-4k`` skips it): bytes uploaded per dab against the whole
  4K texture set, and the latency. A dab covers the same texels at either
  size, so the bytes per dab should not grow with the texture; what does
  grow is the full upload a dab would cost without dirty tiles.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np
from _common import CHESSBOARD, best_time

from matshop.viewport.gl.context import install_default_format

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--dabs", type=int, default=20)
    parser.add_argument("--no-4k", dest="four_k", action="store_false", help="skip the 4K dabs")
    args = parser.parse_args()

    install_default_format()
    from OpenGL import GL
    from PySide6.QtGui import QGuiApplication

    from matshop.io.material_io import load_material
    from matshop.layers import AddLayer, Document, History
    from matshop.material import Material
    from matshop.render.integrator import DirectionalLight
    from matshop.render.render import render
    from matshop.viewport.gl.context import OffscreenContext, renderer_string
    from matshop.viewport.gl.fbo import Framebuffer
    from matshop.viewport.gl.renderer import MaterialRenderer

    app = QGuiApplication.instance() or QGuiApplication([])  # noqa: F841 (keeps Qt alive)
    context = OffscreenContext()  # noqa: F841
    print(f"renderer: {renderer_string()}")
    source = CHESSBOARD if CHESSBOARD.is_dir() else SAMPLE
    material, _ = load_material(source)
    h, w = material.size
    print(f"data: {source.name} ({w}x{h}: {', '.join(material.schema.names)})")
    size = args.size
    light = DirectionalLight((-0.5, 0.7, 0.6), (2.0, 2.0, 2.0))

    doc = Document.from_material(material)
    history = History(doc)
    layer = doc.new_paint_layer("paint")
    history.push(AddLayer(layer))
    renderer = MaterialRenderer()
    renderer.uv_scale = (2.0, 1.0)
    renderer.lighting.samples = 16
    renderer.lighting.lights = (light,)
    renderer.set_document(doc)
    fbo = Framebuffer(size, size)
    fbo.bind()

    def frame() -> None:
        renderer.draw(size, size)
        GL.glFinish()

    for samples in (4, 16):
        renderer.lighting.samples = samples
        gl_frame = best_time(frame, args.repeat)
        reference = best_time(
            lambda s=samples: render(material, size=size, samples=s, lights=(light,)),
            max(1, args.repeat // 2),
        )
        print(
            f"frame {size}x{size}, {samples:2d} samples/px   GL {gl_frame * 1e3:7.1f} ms "
            f"({1.0 / gl_frame:5.1f} fps)   numpy reference {reference * 1e3:7.1f} ms   "
            f"ratio {reference / gl_frame:5.1f}x"
        )

    fbo.delete()
    renderer.delete()
    dabs(doc, layer.id, history, light, size, args.dabs, f"{w}x{h}")
    if args.four_k:
        big = Material(
            material.name,
            material.schema,
            {k: np.tile(v, (2, 2, 1)) for k, v in material.maps.items()},
        )
        doc4 = Document.from_material(big)
        history4 = History(doc4)
        layer4 = doc4.new_paint_layer("paint")
        history4.push(AddLayer(layer4))
        label = f"{2 * w}x{2 * h} (the set tiled 2x2)"
        dabs(doc4, layer4.id, history4, light, size, args.dabs, label)


def dabs(doc, layer_id, history, light, size: int, count: int, label: str) -> None:
    """Paint ``count`` dabs on the sphere through the brush engine; print latency and bytes."""
    from OpenGL import GL

    from matshop.paint import Brush, Swatch
    from matshop.viewport.gl.fbo import Framebuffer
    from matshop.viewport.gl.mesh_data import uv_sphere
    from matshop.viewport.gl.painting import SurfaceStroke
    from matshop.viewport.gl.picking import PickBuffer
    from matshop.viewport.gl.renderer import MaterialRenderer
    from matshop.viewport.gl.surface_map import SurfaceMap

    renderer = MaterialRenderer()
    renderer.uv_scale = (2.0, 1.0)
    renderer.lighting.samples = 16
    renderer.lighting.lights = (light,)
    start = time.perf_counter()
    renderer.set_document(doc)
    GL.glFinish()
    full_upload = time.perf_counter() - start
    full_bytes = renderer.textures.bytes_uploaded
    doc.events.dirty.connect(lambda region: renderer.mark_dirty(region.keys))
    fbo = Framebuffer(size, size)
    fbo.bind()

    def frame() -> None:
        renderer.draw(size, size)
        GL.glFinish()

    gl_frame = best_time(frame, 3)
    # painting: the bake (once per mesh and document size), then dabs
    start = time.perf_counter()
    surface = SurfaceMap(uv_sphere(), doc.layout, uv_scale=renderer.uv_scale)
    bake = time.perf_counter() - start
    picks = PickBuffer(renderer)
    picks.update(size, size)
    fbo.bind()
    swatch = Swatch(
        "red",
        {
            "base_color": (0.9, 0.05, 0.05),
            "metallic": (0.0,),
            "roughness": (0.4,),
            "normal": (0.0, 0.0, 1.0),
        }
        | ({"ao": (1.0,)} if "ao" in doc.schema else {}),
    )
    brush = Brush(radius_px=16.0, hardness=0.6)
    stroke = SurfaceStroke(doc, layer_id, brush, surface, swatch=swatch, history=history)
    rng = np.random.default_rng(0)
    latencies, stamps, uploads, sent = [], [], [], []
    for _ in range(count):
        hit = None
        while hit is None:
            x, y = rng.uniform(0.3, 0.7, size=2) * size
            hit = picks.hit(x, y)
        t0 = time.perf_counter()
        stroke.stamp(hit, 1.0)
        t1 = time.perf_counter()
        sent.append(renderer.sync())
        t2 = time.perf_counter()
        frame()
        t3 = time.perf_counter()
        latencies.append(t3 - t0)
        stamps.append(t1 - t0)
        uploads.append(t2 - t1)
    stroke.end()
    latency = statistics.median(latencies)
    tile_bytes = renderer.textures.tile_bytes((0, 0))
    per_dab = statistics.median(sent)
    print(
        f"dab to screen, {label} (radius {brush.radius_px:g} texels)   median "
        f"{latency * 1e3:7.1f} ms (stamp {statistics.median(stamps) * 1e3:.1f}, flatten+upload "
        f"{statistics.median(uploads) * 1e3:.1f}, frame {gl_frame * 1e3:.1f})   "
        f"{per_dab / 1024:.0f} KiB uploaded per dab ({per_dab / tile_bytes:.1f} tiles of "
        f"{tile_bytes / 1024:.0f} KiB), {full_bytes / per_dab:.0f}x less than the whole set"
    )
    print(
        f"without dirty tiles: full re-upload {full_upload * 1e3:7.1f} ms "
        f"({full_bytes / 2**20:.0f} MiB) + frame   ratio "
        f"{(full_upload + gl_frame) / latency:5.1f}x slower than a dab;  "
        f"UV bake (once per mesh) {bake * 1e3:.0f} ms"
    )
    fbo.delete()
    picks.delete()
    renderer.delete()


if __name__ == "__main__":
    main()
