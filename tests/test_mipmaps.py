"""The canvas' mip levels against a brute-force box filter: each level-k texel is the mean
of the 2x2 level-(k-1) texels under it, rounded half up, odd edges repeating their last
texel; and a pyramid brought up to date piece by piece after changes equals one built
from scratch."""

from __future__ import annotations

import numpy as np
import pytest

from matshop.layers import Rect
from matshop.viewport.mipmaps import MipPyramid, level_for_zoom


def brute_half(picture: np.ndarray) -> np.ndarray:
    """Every output texel from its own (up to) 2x2 block, by Python loops over ints."""
    height, width, channels = picture.shape
    out = np.empty(((height + 1) // 2, (width + 1) // 2, channels), dtype=np.uint8)
    for y in range(out.shape[0]):
        for x in range(out.shape[1]):
            rows = [min(2 * y, height - 1), min(2 * y + 1, height - 1)]
            cols = [min(2 * x, width - 1), min(2 * x + 1, width - 1)]
            for c in range(channels):
                total = sum(int(picture[r, q, c]) for r in rows for q in cols)
                out[y, x, c] = (total + 2) // 4  # the mean, rounded half up
    return out


@pytest.mark.parametrize(
    ("height", "width", "channels"),
    [(32, 48, 4), (33, 17, 4), (1, 1, 4), (2, 5, 1), (9, 12, 3), (10, 7, 5), (6, 6, 8)],
)
def test_every_level_is_the_brute_force_box_mean(height, width, channels) -> None:
    rng = np.random.default_rng(height * 100 + width + channels)
    base = rng.integers(0, 256, (height, width, channels), dtype=np.uint8)
    pyramid = MipPyramid(base)
    expected = base
    for k in range(1, 6):
        expected = brute_half(expected)
        np.testing.assert_array_equal(pyramid.level(k), expected, err_msg=f"level {k}")


def test_the_rounding_is_half_up_at_every_residue() -> None:
    # blocks summing to 4n + r for r = 0..3: means n, n, n + 1 (half up), n + 1
    blocks = np.array([[10, 10, 10, 10], [10, 10, 10, 11], [10, 10, 11, 11], [10, 11, 11, 11]])
    base = np.zeros((2, 8, 4), dtype=np.uint8)
    for i, block in enumerate(blocks):
        base[:, 2 * i : 2 * i + 2, :] = block.reshape(2, 2, 1)
    assert MipPyramid(base).level(1)[0, :, 0].tolist() == [10, 10, 11, 11]


def test_marked_changes_update_to_what_a_fresh_pyramid_gives() -> None:
    rng = np.random.default_rng(7)
    base = rng.integers(0, 256, (200, 150, 4), dtype=np.uint8)
    pyramid = MipPyramid(base)
    pyramid.level(4)  # built whole once
    for x0, y0, x1, y1 in [(3, 5, 40, 21), (100, 150, 150, 200), (77, 0, 78, 1)]:
        base[y0:y1, x0:x1] = rng.integers(0, 256, (y1 - y0, x1 - x0, 4), dtype=np.uint8)
        pyramid.mark(Rect(x0, y0, x1, y1))
    fresh = MipPyramid(base.copy())
    for k in range(5):
        np.testing.assert_array_equal(pyramid.level(k), fresh.level(k), err_msg=f"level {k}")


def test_the_level_drawn_leaves_at_most_a_2x_reduction() -> None:
    assert [level_for_zoom(z) for z in (2.0, 1.0, 0.6, 0.5, 0.3, 0.25, 0.2, 0.1)] == [
        0,
        0,
        0,
        1,
        1,
        2,
        2,
        3,
    ]
