"""Symmetric painting on a mesh across an object-space plane, and the plane shown.

Truths, none from the mirror code under test:
- a stroke painted with the X mirror equals the same stroke plus an independent
  second stroke through the mirrored points, computed here in closed form on
  the unit sphere (longitude -> -longitude), and that second stroke is the
  np.flip of the first (the sphere's UV layout is mirrored: u -> 1 - u);
- on a plane whose two halves map to two separate, *unmirrored* UV islands
  (built here), the mirrored dab lands in the other island, centred on the
  texel the layout formula gives for (-x, y);
- through the real widget, a mouse drag with the mirror equals the drag plus
  the drag mirrored about the view's centre column (the front camera looks
  down -z, so world x -> -x is screen column c -> W - 1 - c), one undo step;
- the rendered frame shows the plane: the pixels where the projected circle
  x = 0 of the sphere lies have the mirror colour, and none do without it.
Skips only where no OpenGL 3.3 core context can be created (run under xvfb-run).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from gl_testing import require_gl

require_gl()  # skips the module, saying why, without pytest-qt or an OpenGL 3.3 context

from gl_testing import release, shown_viewport  # noqa: E402
from PySide6.QtCore import QPointF  # noqa: E402

from matshop.layers import AddLayer, Document, History, Rect  # noqa: E402
from matshop.material import Material, Schema  # noqa: E402
from matshop.paint import Brush, Swatch  # noqa: E402
from matshop.viewport.gl.mesh_data import build  # noqa: E402
from matshop.viewport.gl.mirror import MeshMirror, MirrorPlane  # noqa: E402
from matshop.viewport.gl.picking import SurfaceHit  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SHOTS = Path(os.environ["MATSHOP_SHOTS"]) if os.environ.get("MATSHOP_SHOTS") else None
SCHEMA = Schema.from_names(["base_color", "roughness"])
RED = Swatch("red", {"base_color": (0.9, 0.05, 0.05), "roughness": (0.4,)})
BRUSH = Brush(radius_px=5.0, hardness=0.6, spacing=0.15, flow=0.8)
MIRROR_RGB = np.array([90, 200, 255])
PLANE_ALPHA = 0.22  # the fill's opacity (matshop.viewport.gl.mirror_gpu.PLANE_ALPHA)


def symmetric_sphere(segments: int = 100, rings: int = 50):
    """uv_sphere's sphere and layout, its quads split along mirrored diagonals on the two
    sides of x = 0 (uv_sphere splits them all one way, so its facets are not quite
    symmetric). 100 segments over 256 texels: few texel centres lie on a diagonal, where
    the bake's per-triangle texel size (a dab's world radius and spacing) is a tie."""
    u = np.arange(segments + 1) / segments
    v = np.arange(rings + 1) / rings
    phi = 2.0 * np.pi * (u[None, :] - 0.5)
    lat = np.pi * (v[:, None] - 0.5)
    n = np.stack(
        np.broadcast_arrays(np.sin(phi) * np.cos(lat), np.sin(lat), np.cos(phi) * np.cos(lat)),
        axis=-1,
    ).reshape(-1, 3)
    uvs = np.stack(np.broadcast_arrays(u[None, :], v[:, None]), axis=-1).reshape(-1, 2)
    row = segments + 1
    i, j = np.mgrid[0:rings, 0:segments]
    a = (i * row + j).ravel()
    b, c, d = a + 1, a + row + 1, a + row
    left = (j < segments // 2).ravel()  # u < 1/2 is x < 0: the diagonal a-c; else b-d
    tris = np.concatenate(
        [
            np.where(left[:, None], np.stack([a, b, c], 1), np.stack([a, b, d], 1)),
            np.where(left[:, None], np.stack([a, c, d], 1), np.stack([b, c, d], 1)),
        ]
    )
    return build(n, uvs, tris, normals=n, name="symmetric-sphere")


def make_doc(width: int, height: int) -> tuple[Document, History, int]:
    maps = {
        "base_color": np.full((height, width, 3), 0.5, np.float32),
        "roughness": np.full((height, width, 1), 0.5, np.float32),
    }
    doc = Document.from_material(Material("grey", SCHEMA, maps), tile_size=64)
    history = History(doc)
    layer = doc.new_paint_layer("paint")
    history.push(AddLayer(layer))
    return doc, history, layer.id


def coverage(doc: Document, layer_id: int) -> np.ndarray:
    return doc.layer(layer_id).coverage(Rect(0, 0, doc.width, doc.height))


def union(*images: np.ndarray) -> np.ndarray:
    return 1.0 - np.prod([1.0 - a for a in images], axis=0)


def sphere_hit(lon: float, lat: float) -> SurfaceHit:
    """The unit sphere's point, normal and uv at (longitude, latitude), as uv_sphere maps it."""
    p = np.array([np.sin(lon) * np.cos(lat), np.sin(lat), np.cos(lon) * np.cos(lat)])
    return SurfaceHit(p, p.copy(), np.array([0.5 + lon / (2 * np.pi), 0.5 + lat / np.pi]))


def paint(doc, layer_id, surface, hits, mirror=None, history=None) -> None:
    from matshop.viewport.gl.painting import SurfaceStroke

    stroke = SurfaceStroke(
        doc, layer_id, BRUSH, surface, swatch=RED, mirror=mirror, history=history
    )
    stroke.add_hits([(hit, 1.0) for hit in hits])
    stroke.end()


def compare(name: str, got: np.ndarray, want: np.ndarray, atol: float) -> None:
    """Texel for texel within ``atol`` (the rasterisation tolerance), and as much paint.

    The tolerance: a 3D dab's radius and spacing are in texels of the bake's
    per-triangle texel size, looked up at the texel under the dab's uv; a dab and
    its mirror image can read the two sides of a triangle edge there. Measured:
    two strokes mirrored by hand differ from each other's np.flip by up to 0.047
    at an edge texel of the falloff through the widget, 1e-5 from closed-form hits.
    """
    error = np.abs(got - want)
    print(f"{name}: max |error| {error.max():.4f}, mean {error.mean():.2e}, ", end="")
    print(f"painted {np.count_nonzero(want > 0.01)} texels")
    assert error.max() <= atol and error.mean() < 2e-3
    assert got.sum() == pytest.approx(want.sum(), rel=0.01)


def test_a_mirrored_stroke_on_the_sphere_equals_a_second_stroke_at_the_mirror(gl_context):
    from matshop.viewport.gl.surface_map import SurfaceMap

    mesh = symmetric_sphere()
    doc, history, layer_id = make_doc(256, 128)
    surface = SurfaceMap(mesh, doc.layout)
    # a wiggle on the +x side, with its closed-form mirror on the -x side
    lons = np.radians(np.linspace(25.0, 70.0, 40))
    lats = np.radians(15.0 * np.sin(np.linspace(0.0, 3.0, 40)))
    hits = [sphere_hit(lon, lat) for lon, lat in zip(lons, lats, strict=True)]
    mirrored_hits = [sphere_hit(-lon, lat) for lon, lat in zip(lons, lats, strict=True)]

    steps = history.report().undo_steps
    mirror = MeshMirror(mesh, MirrorPlane("x"))
    paint(doc, layer_id, surface, hits, mirror=mirror, history=history)
    assert history.report().undo_steps == steps + 1  # one stroke, one step
    symmetric = coverage(doc, layer_id)

    alone_doc, _, alone_id = make_doc(256, 128)
    paint(alone_doc, alone_id, surface, hits)
    alone = coverage(alone_doc, alone_id)
    second_doc, _, second_id = make_doc(256, 128)
    paint(second_doc, second_id, surface, mirrored_hits)
    second = coverage(second_doc, second_id)
    assert alone.max() > 0.79 and not alone[:, :128].any()  # the +x half: u > 1/2

    compare("mirror vs second stroke", symmetric, union(alone, second), atol=0.03)
    compare("second stroke vs flip", second, np.flip(alone, axis=1), atol=0.03)
    history.undo()
    assert not coverage(doc, layer_id).any()


def split_plane() -> tuple:
    """A 2 x 1 plane in z = 0 whose halves map to two separate, unmirrored UV islands.

    Left half (x in [-1, 0]) -> u in [0.05, 0.45]; right half -> u in [0.55, 0.95],
    both increasing with x (translated, not flipped); v = 0.1 + 0.8 (y + 0.5).
    """
    xs = np.linspace(-1.0, 1.0, 9)
    ys = np.linspace(-0.5, 0.5, 5)
    positions, uvs, indices = [], [], []
    for side, (x0, x1) in enumerate(((-1.0, 0.0), (0.0, 1.0))):
        cols = xs[(xs >= x0) & (xs <= x1)]
        base = len(positions)
        for y in ys:
            for x in cols:
                positions.append((x, y, 0.0))
                uvs.append(island_uv(x, y, side))
        n = len(cols)
        for j in range(len(ys) - 1):
            for i in range(n - 1):
                a = base + j * n + i
                indices += [(a, a + 1, a + n + 1), (a, a + n + 1, a + n)]
    mesh = build(np.array(positions), np.array(uvs), np.array(indices), name="split-plane")
    return mesh


def island_uv(x: float, y: float, side: int) -> tuple[float, float]:
    u0 = 0.05 if side == 0 else 0.55
    return u0 + 0.4 * (x - (-1.0 if side == 0 else 0.0)), 0.1 + 0.8 * (y + 0.5)


@pytest.mark.parametrize("offset", [0.0, 0.1])
def test_the_mirrored_dab_paints_in_its_own_uv_island(gl_context, offset: float):
    from matshop.viewport.gl.surface_map import SurfaceMap

    mesh = split_plane()
    doc, _, layer_id = make_doc(256, 256)
    surface = SurfaceMap(mesh, doc.layout)
    point = np.array([0.55, 0.1, 0.0])
    hit = SurfaceHit(point, np.array([0.0, 0.0, 1.0]), np.array(island_uv(0.55, 0.1, 1)))
    mirror = MeshMirror(mesh, MirrorPlane("x", offset))
    paint(doc, layer_id, surface, [hit], mirror=mirror)
    alpha = coverage(doc, layer_id)
    # the plane x = offset (the box's centre is x = 0): the image at 2 offset - 0.55
    for side, x in ((1, 0.55), (0, 2 * offset - 0.55)):
        half = alpha[:, 128:] if side else alpha[:, :128]
        rows, cols = np.nonzero(half > 0)
        w = half[rows, cols]
        centre = np.array([np.average(cols + 0.5, weights=w), np.average(rows + 0.5, weights=w)])
        centre[0] += 128 * side
        u, v = island_uv(x, 0.1, side)
        expected = np.array([u * doc.width, (1.0 - v) * doc.height])
        print(f"island {side}: dab centroid {centre}, the layout's texel {expected}")
        assert np.abs(centre - expected).max() < 0.25
        assert half.max() == pytest.approx(BRUSH.flow, abs=1e-6)
    # the same dab in each island (same texel size; sampled at another sub-texel phase)
    assert alpha[:, :128].sum() == pytest.approx(alpha[:, 128:].sum(), rel=1e-2)


# ------------------------------------------------------------------ the widget


SIZE = 256


@pytest.fixture
def viewport(gl_context, qtbot):
    widget = shown_viewport(qtbot, SIZE)
    yield widget
    release(widget)


def drag_px(qtbot, widget, points) -> None:
    from matshop.app.testing import drag

    drag(widget, [QPointF(x, y) for x, y in points])


def test_a_mirrored_drag_equals_the_drag_and_its_mirror_image(viewport, qtbot):
    doc, history, layer_id = make_doc(256, 128)
    viewport.set_mesh(symmetric_sphere())
    viewport.set_document(doc)
    viewport.set_brush(layer_id, BRUSH, RED, history)
    # pixel centres right of the centre column, and the same pixels mirrored
    points = [(150.5 + 3 * i, 110.5 + 12 * np.sin(i / 3.0)) for i in range(14)]
    mirrored = [(SIZE - x, y) for x, y in points]

    viewport.set_mirror(MirrorPlane("x"))
    steps = history.report().undo_steps
    drag_px(qtbot, viewport, points)
    assert history.report().undo_steps == steps + 1
    symmetric = coverage(doc, layer_id)
    history.undo()
    assert not coverage(doc, layer_id).any()

    viewport.set_mirror(None)
    drag_px(qtbot, viewport, points)
    alone = coverage(doc, layer_id)
    history.undo()
    drag_px(qtbot, viewport, mirrored)
    second = coverage(doc, layer_id)
    assert alone.max() > 0.79 and not alone[:, :128].any()
    compare("widget: mirror vs two drags", symmetric, union(alone, second), atol=0.06)


def mirror_pixels(image: np.ndarray, points_px: np.ndarray) -> np.ndarray:
    """Whether each projected point has a pixel of the mirror colour within one pixel."""
    found = []
    for x, y in points_px:
        c, r = int(x), int(y)
        block = image[max(r - 1, 0) : r + 2, max(c - 1, 0) : c + 2, :3].astype(int)
        found.append((np.abs(block - MIRROR_RGB).max(axis=-1) < 40).any())
    return np.array(found)


@pytest.mark.parametrize(("yaw", "offset"), [(0.0, 0.0), (35.0, 0.0), (0.0, 0.3)])
def test_the_plane_is_drawn_where_it_cuts_the_sphere(viewport, yaw, offset):
    doc, _, _ = make_doc(256, 128)
    viewport.set_mesh(symmetric_sphere())
    viewport.set_document(doc)
    viewport.camera.yaw = yaw
    # the plane x = offset meets the unit sphere in the circle of radius sqrt(1 - offset^2)
    t = np.linspace(-np.pi, np.pi, 721)
    r = np.sqrt(1.0 - offset**2)
    circle = np.stack([offset + 0 * t, r * np.sin(t), r * np.cos(t)], axis=1)
    eye = viewport.camera.eye()
    visible = np.sum(circle * (eye - circle), axis=1) > 0.05
    pixels = viewport.camera.project(circle[visible], SIZE, SIZE)
    inside = (pixels.min(axis=1) >= 2) & (pixels.max(axis=1) < SIZE - 2)
    pixels = pixels[inside]
    assert len(pixels) > 100

    plain = viewport.render_image(SIZE)
    assert mirror_pixels(plain, pixels).mean() < 0.02  # a grey sphere: no such colour
    viewport.set_mirror(MirrorPlane("x", offset))
    shown = viewport.render_image(SIZE)
    on_line = mirror_pixels(shown, pixels)
    print(f"yaw {yaw}: {on_line.mean():.3f} of {len(pixels)} points of the cut show the colour")
    assert on_line.mean() > 0.97
    if SHOTS is not None:
        import cv2

        SHOTS.mkdir(parents=True, exist_ok=True)
        name = f"mirror_plane_yaw{int(yaw)}_offset{offset:g}.png"
        cv2.imwrite(str(SHOTS / name), shown[..., 2::-1])
    if yaw:  # seen at an angle, the translucent quad lays its colour over the backdrop
        grid = np.linspace(-1.0, 1.0, 41)  # inside the quad (the box's half size 1 x 1.15)
        y, z = np.meshgrid(grid, grid)
        on_plane = np.stack([0 * y, y, z], axis=-1).reshape(-1, 3)
        cam = viewport.camera
        eye = cam.eye()
        rays = on_plane - eye
        rays /= np.linalg.norm(rays, axis=1, keepdims=True)
        along = -(eye @ rays.T)  # the ray's closest approach to the sphere's centre
        missed = np.linalg.norm(eye + along[:, None] * rays, axis=1) > 1.03
        px = cam.project(on_plane[missed], SIZE, SIZE)
        inside = (px.min(axis=1) >= 1) & (px.max(axis=1) < SIZE - 1)
        cols, rows = px[inside].astype(int).T
        assert len(cols) > 50
        want = (1 - PLANE_ALPHA) * plain[rows, cols, :3] + PLANE_ALPHA * MIRROR_RGB
        got = shown[rows, cols, :3].astype(float)
        print(f"plane fill: {len(cols)} backdrop pixels, max |error| {np.abs(got - want).max()}")
        np.testing.assert_allclose(got, want, atol=2.0)
