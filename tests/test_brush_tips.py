"""Brush tips, dynamics and stencils in the brush engine.

Truths: a dab with a tip image is the tip resampled by an independent warp
(scipy.ndimage.affine_transform, and OpenCV's warpAffine) of the file's own
pixels (read with OpenCV) at the dab's scale and angle, times the stroke's
opacity and flow; a quarter turn is np.rot90; following the stroke turns the
tip by atan2 of the segment; a stroke's seed replays it exactly; a stencil
of zeros blocks everything and a half stencil paints exactly its open half;
symmetry mirrors tip dabs as np.flip.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from scipy import ndimage

from matshop.layers import AddLayer, Document, History, Rect
from matshop.material import Material, Schema
from matshop.paint import (
    Brush,
    Dynamics,
    Stencil,
    StrokeSample,
    Swatch,
    load_tip,
    paint_stroke,
    procedural_tip,
)
from matshop.paint.tip_shapes import SHAPES

SCHEMA = Schema.from_names(["base_color", "roughness"])
SIZE = 128
FULL = Rect(0, 0, SIZE, SIZE)
RED = Swatch("red", {"base_color": (0.8, 0.1, 0.1), "roughness": (0.4,)})


def make_doc() -> tuple[Document, int]:
    maps = {
        "base_color": np.full((SIZE, SIZE, 3), 0.5, np.float32),
        "roughness": np.full((SIZE, SIZE, 1), 0.5, np.float32),
    }
    doc = Document.from_material(Material("base", SCHEMA, maps), tile_size=32)
    layer = doc.new_paint_layer("paint")
    History(doc).push(AddLayer(layer))
    return doc, layer.id


def paint(brush: Brush, points: list[tuple[float, float]], **options) -> np.ndarray:
    doc, layer_id = make_doc()
    samples = [StrokeSample(x, y) for x, y in points]
    paint_stroke(doc, layer_id, samples, brush, swatch=RED, wrap=False, **options)
    return doc.layer(layer_id).coverage(FULL)


@pytest.fixture
def tip_file(tmp_path):
    """An asymmetric gray tip (a ramp, a bar and a dot) written by OpenCV; read back by it."""
    h, w = 40, 32
    rows, cols = np.mgrid[0:h, 0:w]
    image = (40 + 5 * cols + 2 * rows).clip(0, 255).astype(np.uint8)
    image[4:10, 3:28] = 255
    image[30:34, 22:26] = 0
    path = tmp_path / "tip.png"
    cv2.imwrite(str(path), image)
    return path, cv2.imread(str(path), cv2.IMREAD_UNCHANGED).astype(np.float64) / 255.0


def warped_scipy(tip: np.ndarray, x: float, y: float, scale: float, angle_deg: float) -> np.ndarray:
    """The tip placed with its centre at texel point (x, y), ``scale`` texels a pixel,
    turned counter-clockwise on screen, sampled bilinearly at texel centres (zero outside)."""
    h, w = tip.shape
    t = math.radians(angle_deg)
    # on screen (y down) a counter-clockwise turn by t takes a tip offset (dx, dy) to
    # (dx cos + dy sin, -dx sin + dy cos); a texel centre shows the tip at the inverse turn
    inverse = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]]) / scale
    # in (row, col) order: rows are y, cols are x
    rc = np.array([[inverse[1, 1], inverse[1, 0]], [inverse[0, 1], inverse[0, 0]]])
    centre = np.array([y - 0.5, x - 0.5])
    offset = np.array([h / 2 - 0.5, w / 2 - 0.5]) - rc @ centre
    return ndimage.affine_transform(
        tip, rc, offset=offset, output_shape=(SIZE, SIZE), order=1, mode="grid-constant", cval=0.0
    )


def warped_cv2(tip: np.ndarray, x: float, y: float, scale: float, angle_deg: float) -> np.ndarray:
    h, w = tip.shape
    t = math.radians(angle_deg)
    forward = scale * np.array([[math.cos(t), math.sin(t)], [-math.sin(t), math.cos(t)]])
    shift = np.array([x - 0.5, y - 0.5]) - forward @ np.array([w / 2 - 0.5, h / 2 - 0.5])
    matrix = np.hstack([forward, shift[:, None]])
    return cv2.warpAffine(
        tip.astype(np.float32),
        matrix,
        (SIZE, SIZE),
        flags=cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_CONSTANT,
        borderValue=0,
    )


@pytest.mark.parametrize(
    ("radius", "angle", "opacity", "flow"),
    [(20.0, 0.0, 0.8, 1.0), (33.0, 30.0, 1.0, 0.5), (26.5, -117.0, 0.6, 0.7)],
)
def test_a_tip_dab_is_the_tip_warped_to_its_size_and_angle(
    tip_file, radius, angle, opacity, flow
) -> None:
    path, pixels = tip_file
    brush = Brush(
        radius_px=radius,
        opacity=opacity,
        flow=flow,
        tip=load_tip(path),
        dynamics=Dynamics(angle_deg=angle),
    )
    x, y = 61.3, 66.8
    dab = paint(brush, [(x, y)])
    scale = 2 * radius / 40  # the tip's longer side spans the diameter
    expected = opacity * flow * warped_scipy(pixels, x, y, scale, angle)
    assert expected.max() > 0.3
    np.testing.assert_allclose(dab, expected, atol=2e-5, rtol=0)
    # OpenCV's warp (fixed-point weights, 1/32 of a pixel) agrees within its precision
    opencv = opacity * flow * warped_cv2(pixels, x, y, scale, angle)
    assert np.abs(dab - opencv).max() < 0.03


@pytest.mark.parametrize("outside", ["zero", "clamp"])
def test_skipping_the_columns_past_the_image_changes_no_value(outside) -> None:
    """A tip's dab skips each row's columns past a zero border; every value must equal the
    one the texel-by-texel loop (the stencils' path, which also returns ``inside``)
    gives: random placements, scales and levels, exact and near right angles (a step
    near 0 puts the columns' bounds past any integer)."""
    from matshop.paint._sample_kernel import sample_block
    from matshop.paint.sampling import Pyramid

    rng = np.random.default_rng(7)
    for _ in range(300):
        h, w = (int(n) for n in rng.integers(1, 90, 2))
        pyramid = Pyramid(rng.random((h, w), dtype=np.float32), outside=outside)
        # the coarsest levels half the time: their factor makes the step nearest 0
        top = len(pyramid.padded) - 1
        level = top if rng.random() < 0.5 else int(rng.integers(0, top + 1))
        scale = float(rng.uniform(0.05, 6.0))
        turn = math.radians(float(rng.choice([0, 90, 90 + 1e-12, 45, 1e-9, rng.uniform(0, 360)])))
        cos, sin = math.cos(turn), math.sin(turn)
        size = tuple(int(n) for n in rng.integers(1, 200, 2))
        args = (
            pyramid.padded[level],
            int(rng.integers(-50, 50)),
            int(rng.integers(-50, 50)),
            float(rng.uniform(-20, 120)),
            float(rng.uniform(-20, 120)),
            cos / scale, -sin / scale, sin / scale, cos / scale,
            w / 2.0, h / 2.0, float(1 << level), outside == "clamp",
        )  # fmt: skip
        every, inside = np.empty(size, np.float32), np.empty(size, np.bool_)
        sample_block(*args, every, inside)
        skipping = np.empty(size, np.float32)
        sample_block(*args, skipping, np.empty((0, 0), np.bool_))
        assert np.array_equal(skipping, every)


def test_a_tip_drawn_small_is_box_filtered_not_aliased(tmp_path) -> None:
    rng = np.random.default_rng(5)
    pixels = (rng.random((64, 64)) > 0.5).astype(np.uint8) * 255  # worst case: white noise
    path = tmp_path / "noise.png"
    cv2.imwrite(str(path), pixels)
    dab = paint(Brush(radius_px=8.0, tip=load_tip(path)), [(64.0, 64.0)])
    # 64 px on a 16-texel diameter: each texel averages a 4x4 block of the tip
    blocks = (pixels / 255.0).reshape(16, 4, 16, 4).mean(axis=(1, 3))
    np.testing.assert_allclose(dab, warped_scipy(blocks, 64.0, 64.0, 1.0, 0.0), atol=2e-5)


def test_a_quarter_turn_is_np_rot90_of_the_dab(tip_file) -> None:
    path, _ = tip_file
    tip = load_tip(path)
    x = y = 64.5  # the centre of texel 64: a quarter turn maps texel centres to texel centres

    def dab(angle: float) -> np.ndarray:
        brush = Brush(radius_px=22.0, tip=tip, dynamics=Dynamics(angle_deg=angle))
        return paint(brush, [(x, y)])[64 - 40 : 64 + 41, 64 - 40 : 64 + 41]

    upright = dab(0.0)
    assert not np.allclose(upright, np.rot90(upright), atol=0.05)  # the tip is not symmetric
    np.testing.assert_allclose(dab(90.0), np.rot90(upright), atol=1e-6)
    np.testing.assert_allclose(dab(180.0), np.rot90(upright, 2), atol=1e-6)
    np.testing.assert_allclose(dab(-90.0), np.rot90(upright, -1), atol=1e-6)


@pytest.mark.parametrize(("dx", "dy"), [(1.0, 0.0), (0.3, -1.0), (-1.0, 0.6), (-0.2, 0.9)])
def test_follow_turns_the_tip_by_atan2_of_the_segment(tip_file, dx, dy) -> None:
    path, _ = tip_file
    tip = load_tip(path)
    start = (60.25, 63.75)
    end = (start[0] + 4 * dx, start[1] + 4 * dy)  # shorter than a step: one dab, at the start
    follow = Brush(radius_px=18.0, spacing=1.0, tip=tip, dynamics=Dynamics(rotation="follow"))
    got = paint(follow, [start, end])
    # counter-clockwise on screen, where y points down
    angle = math.degrees(math.atan2(-(end[1] - start[1]), end[0] - start[0]))
    fixed = Brush(radius_px=18.0, spacing=1.0, tip=tip, dynamics=Dynamics(angle_deg=angle))
    np.testing.assert_allclose(got, paint(fixed, [start]), atol=1e-6)


def test_follow_waits_for_a_direction_and_a_click_still_paints(tip_file) -> None:
    path, _ = tip_file
    brush = Brush(radius_px=12.0, tip=load_tip(path), dynamics=Dynamics(rotation="follow"))
    doc, layer_id = make_doc()
    from matshop.paint import StrokeSession

    session = StrokeSession(doc, layer_id, brush, swatch=RED)
    assert session.add([StrokeSample(40.0, 40.0)]) == []  # held until the stroke moves
    session.add([StrokeSample(40.0, 40.0)])  # not a move either
    assert session.end() is not None  # a click: the dab at the fixed angle
    np.testing.assert_allclose(
        doc.layer(layer_id).coverage(FULL),
        paint(Brush(radius_px=12.0, tip=brush.tip), [(40.0, 40.0)]),
        atol=0,
    )


PATH = [(20.0 + 8 * i, 64.0 + 10 * math.sin(i / 2)) for i in range(12)]


def test_jitter_and_scatter_replay_from_the_seed() -> None:
    dynamics = Dynamics(
        rotation="random",
        size_jitter=0.6,
        angle_jitter_deg=40,
        scatter_along=0.5,
        scatter_across=1.0,
    )
    brush = Brush(radius_px=6.0, spacing=0.5, tip=procedural_tip("scratches", 3), dynamics=dynamics)
    first = paint(brush, PATH, seed=11)
    assert np.array_equal(first, paint(brush, PATH, seed=11))  # bit for bit
    assert not np.array_equal(first, paint(brush, PATH, seed=12))


def test_scatter_across_spreads_dabs_within_its_bound() -> None:
    straight = [(16.0 + 8 * i, 64.0) for i in range(13)]
    radius = 4.0
    plain = paint(Brush(radius_px=radius, hardness=1.0), straight, seed=1)
    rows = np.nonzero(plain.any(axis=1))[0]
    assert rows.min() >= 64 - radius - 1 and rows.max() <= 64 + radius
    scatter = 1.5  # dab diameters either way
    brush = Brush(radius_px=radius, hardness=1.0, dynamics=Dynamics(scatter_across=scatter))
    spread = paint(brush, straight, seed=1)
    rows = np.nonzero(spread.any(axis=1))[0]
    reach = scatter * 2 * radius + radius + 1
    assert rows.min() >= 64 - reach and rows.max() <= 64 + reach  # never past the bound
    assert rows.max() - rows.min() > 4 * radius  # and wider than the plain stroke
    assert np.nonzero(spread.any(axis=0))[0].max() <= 16 + 8 * 12 + radius + 1  # not along


def test_size_jitter_never_grows_a_dab() -> None:
    brush = Brush(radius_px=10.0, hardness=1.0, dynamics=Dynamics(size_jitter=0.8))
    sizes = []
    for seed in range(12):
        dab = paint(brush, [(64.0, 64.0)], seed=seed)
        sizes.append(float((dab > 0.5).sum()))
    full = math.pi * 10.0**2
    assert max(sizes) <= full + 4 and min(sizes) < 0.6 * full and len(set(sizes)) > 6


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_procedural_tips_come_from_their_seed(name) -> None:
    a = procedural_tip(name, 4).image
    assert a.shape == (128, 128) and a.dtype == np.float32
    assert 0.0 <= a.min() and a.max() <= 1.0 and a.max() > 0.4
    assert np.array_equal(a, procedural_tip(name, 4).image)
    assert not np.array_equal(a, procedural_tip(name, 5).image)


def half_stencil(angle: float = 0.0) -> Stencil:
    """A 100x100 stencil, black on its left half, white on its right, over the middle."""
    image = np.zeros((100, 100), np.float32)
    image[:, 50:] = 1.0
    return Stencil(image, centre=(64.0, 64.0), scale=1.0, angle_deg=angle)


def test_a_stencil_of_zeros_blocks_every_dab() -> None:
    stencil = Stencil(np.zeros((300, 300), np.float32), centre=(64.0, 64.0), scale=1.0)
    doc, layer_id = make_doc()
    samples = [StrokeSample(x, y) for x, y in PATH]
    edit = paint_stroke(doc, layer_id, samples, Brush(radius_px=9.0), swatch=RED, stencil=stencil)
    assert edit is None and not doc.layer(layer_id).coverage(FULL).any()


@pytest.mark.parametrize("angle", [0.0, 90.0])
def test_a_half_stencil_paints_exactly_its_open_half(angle) -> None:
    brush = Brush(radius_px=9.0, hardness=0.3)
    plain = paint(brush, PATH)
    got = paint(brush, PATH, stencil=half_stencil(angle))
    cols = np.arange(SIZE) + 0.5

    def within(lo: float, hi: float) -> np.ndarray:
        return (
            (cols[None, :] > lo)
            & (cols[None, :] < hi)
            & (cols[:, None] > lo)
            & (cols[:, None] < hi)
        )

    # the stencil spans texels 14..114 around 64; white right of x = 64 (turned: above y = 64)
    centres = cols[None, :] if angle == 0.0 else -cols[:, None]
    boundary = 64.0 if angle == 0.0 else -64.0
    inside = within(14, 114)
    open_ = centres > boundary + 1.0
    shut = centres < boundary - 1.0
    np.testing.assert_allclose(got[open_ & inside], plain[open_ & inside], atol=1e-6)
    assert not got[shut & inside].any()
    outside = ~within(13, 115)
    np.testing.assert_allclose(got[outside], plain[outside], atol=1e-6)  # no sheet: no mask
    assert plain[shut & inside].max() > 0.5 and plain[open_ & inside].max() > 0.5


def test_symmetry_mirrors_tip_dabs_as_flips() -> None:
    left = [(8.0 + 4 * i, 30.0 + 12 * math.sin(i / 3)) for i in range(10)]
    brush = Brush(
        radius_px=6.0,
        tip=procedural_tip("scratches", 2),
        dynamics=Dynamics(rotation="follow", size_jitter=0.4, scatter_across=0.3),
    )
    alone = paint(brush, left, seed=5)
    assert alone.max() > 0.3 and not alone[:, SIZE // 2 :].any()
    mirrored = paint(brush, left, seed=5, symmetry="x")
    np.testing.assert_allclose(mirrored, alone + np.flip(alone, axis=1), atol=1e-6)


def test_the_eraser_takes_tips_and_stencils() -> None:
    doc, layer_id = make_doc()
    everywhere = [StrokeSample(64.0, 64.0)]
    paint_stroke(doc, layer_id, everywhere, Brush(radius_px=120, hardness=1), swatch=RED)
    assert doc.layer(layer_id).coverage(FULL).min() == 1.0
    tip = procedural_tip("spots", 9)
    brush = Brush(radius_px=30.0, tip=tip)
    samples = [StrokeSample(x, y) for x, y in PATH]
    paint_stroke(doc, layer_id, samples, brush, mode="erase", stencil=half_stencil(), wrap=False)
    left = doc.layer(layer_id).coverage(FULL)
    # erased through the open (right) half of the stencil only, as the same stroke paints
    painted = paint(brush, PATH, stencil=half_stencil())
    np.testing.assert_allclose(left, 1.0 - painted, atol=1e-6)
    assert painted[:, 66:114].max() > 0.5 and not painted[14:114, 14:62].any()
