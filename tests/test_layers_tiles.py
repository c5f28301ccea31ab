"""Tile geometry and sparse copy-on-write tile storage."""

from __future__ import annotations

import sys
import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from matshop.layers.geometry import Rect, TileLayout, keys_of
from matshop.layers.tiles import TileGrid


@pytest.mark.parametrize(("height", "width", "tile"), [(64, 64, 64), (70, 90, 16), (5, 3, 8)])
def test_tiles_cover_the_image_once(height: int, width: int, tile: int) -> None:
    layout = TileLayout(height, width, tile)
    cover = np.zeros((height, width), dtype=int)
    for key in layout.keys_in(layout.bounds):
        cover[layout.tile_rect(key).slices] += 1
    assert (cover == 1).all()


@settings(max_examples=60, deadline=None)
@given(
    height=st.integers(1, 70),
    width=st.integers(1, 70),
    tile=st.sampled_from([4, 8, 16]),
    margin=st.integers(0, 40),
    border=st.sampled_from(["wrap", "clamp"]),
    data=st.data(),
)
def test_dilate_matches_brute_force(height, width, tile, margin, border, data) -> None:
    layout = TileLayout(height, width, tile)
    tiles = np.array(
        data.draw(
            st.lists(
                st.booleans(),
                min_size=layout.rows * layout.cols,
                max_size=layout.rows * layout.cols,
            )
        )
    ).reshape(layout.grid_shape)
    # brute force in texels: every texel within margin (Chebyshev) of a dirty texel
    dirty = np.zeros((height, width), dtype=bool)
    for key in keys_of(tiles):
        dirty[layout.tile_rect(key).slices] = True
    ys, xs = np.nonzero(dirty)
    reached = np.zeros_like(dirty)
    for y, x in zip(ys, xs, strict=True):
        rows = np.arange(y - margin, y + margin + 1)
        cols = np.arange(x - margin, x + margin + 1)
        if border == "wrap":
            rows, cols = rows % height, cols % width
        else:
            rows = rows[(rows >= 0) & (rows < height)]
            cols = cols[(cols >= 0) & (cols < width)]
        reached[np.ix_(rows, cols)] = True
    expected = np.zeros(layout.grid_shape, dtype=bool)
    for key in layout.keys_in(layout.bounds):
        expected[key] = reached[layout.tile_rect(key).slices].any()
    assert np.array_equal(layout.dilate(tiles, margin, border), expected)


@settings(max_examples=60, deadline=None)
@given(
    rows=st.integers(1, 9),
    cols=st.integers(1, 9),
    max_texels=st.sampled_from([None, 64, 200]),
    data=st.data(),
)
def test_rects_of_covers_exactly_the_tiles(rows, cols, max_texels, data) -> None:
    layout = TileLayout(rows * 8 - 3, cols * 8, 8)
    flags = data.draw(st.lists(st.booleans(), min_size=rows * cols, max_size=rows * cols))
    tiles = np.array(flags).reshape(rows, cols)
    cover = np.zeros((layout.height, layout.width), dtype=int)
    for rect in layout.rects_of(tiles, max_texels):
        assert layout.aligned(rect) == rect
        cover[rect.slices] += 1
    expected = np.zeros_like(cover)
    for key in keys_of(tiles):
        expected[layout.tile_rect(key).slices] = 1
    assert np.array_equal(cover, expected)


def test_read_write_round_trip_and_fill() -> None:
    layout = TileLayout(50, 37, 16)
    grid = TileGrid(layout, 3, fill=[0.5, -1.0, 2.0])
    assert np.array_equal(grid.read(Rect(3, 4, 20, 30)), np.broadcast_to(grid.fill, (26, 17, 3)))
    block = np.random.default_rng(0).random((20, 25, 3)).astype(np.float32)
    grid.write(Rect(10, 25, 35, 45), block)
    full = grid.to_array()
    assert np.array_equal(full[25:45, 10:35], block)
    outside = np.ones((50, 37), bool)
    outside[25:45, 10:35] = False
    assert (full[outside] == grid.fill).all()
    assert set(grid.keys()) == set(layout.keys_in(Rect(10, 25, 35, 45)))


def test_write_replaces_tiles_and_never_mutates_old_ones() -> None:
    layout = TileLayout(32, 32, 16)
    grid = TileGrid(layout, 2)
    grid.write(Rect(0, 0, 32, 32), np.ones((32, 32, 2), np.float32))
    before = {key: grid.get(key) for key in grid.keys()}
    snapshot = {key: tile.copy() for key, tile in before.items()}
    old = grid.write(Rect(8, 8, 24, 24), np.zeros((16, 16, 2), np.float32))
    assert old == before  # the replaced tile objects themselves
    for key, tile in before.items():
        assert not tile.flags.writeable
        assert np.array_equal(tile, snapshot[key])
        assert grid.get(key) is not tile
    grid.replace(old)  # undo is a swap
    assert all(grid.get(key) is tile for key, tile in before.items())


def test_copy_shares_tiles() -> None:
    layout = TileLayout(20, 20, 8)
    grid = TileGrid(layout, 1)
    grid.write(Rect(0, 0, 20, 20), np.full((20, 20, 1), 0.3, np.float32))
    twin = grid.copy()
    assert all(twin.get(key) is grid.get(key) for key in grid.keys())
    twin.write(Rect(0, 0, 4, 4), np.zeros((4, 4, 1), np.float32))
    assert grid.read(Rect(0, 0, 4, 4)).max() == pytest.approx(0.3)


def test_from_array_skips_fill_tiles() -> None:
    layout = TileLayout(40, 40, 16)
    array = np.zeros((40, 40), np.float32)
    array[35, 2] = 1.0
    grid = TileGrid.from_array(array, layout)
    assert set(grid.keys()) == {(2, 0)}
    assert np.array_equal(grid.to_array()[..., 0], array)


def test_an_empty_layer_on_a_4k_document_costs_under_1_kib() -> None:
    from matshop.layers import Document
    from matshop.material import Schema

    schema = Schema.from_names(["base_color", "metallic", "roughness", "normal"])
    doc = Document(schema, 4096, 4096)
    doc.new_paint_layer("warm-up")
    tracemalloc.start()
    start = tracemalloc.take_snapshot()
    layer = doc.new_paint_layer("empty")
    layer_done = tracemalloc.take_snapshot()
    mask = doc.new_mask()
    mask_done = tracemalloc.take_snapshot()
    tracemalloc.stop()

    def grown(after, before) -> int:
        # only what matshop's lines allocated (numpy buffers included), not
        # the snapshots' own bookkeeping
        stats = after.compare_to(before, "filename")
        return sum(s.size_diff for s in stats if "matshop" in s.traceback[0].filename)

    assert layer.pixels is not None
    assert layer.pixels.nbytes == 0 and mask.nbytes == 0 and len(layer.pixels) == 0
    assert layer.pixels.footprint() < 1024
    assert grown(layer_done, start) < 1024  # the layer object, its grid, dict and fill
    assert grown(mask_done, layer_done) < 1024
    assert sys.getsizeof(layer.pixels._tiles) < 100
