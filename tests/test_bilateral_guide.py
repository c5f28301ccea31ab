"""The bilateral op's guide chosen by explained variance, against the exact filter.

``guide="auto"`` drops the trailing principal axes of the range guide whose
variance sums to at most ``MAX_RESIDUAL`` (in sigma_range^2). Checked here:
the axes kept follow from an eigen-decomposition done independently (numpy
on every texel), the result stays within 40 dB of the exact (brute-force)
filter on crops of real edit values, and ``guide="full"`` is the filter
with every axis.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_bilateral import brute_force, chessboard, crop, psnr

from matshop.material import Schema
from matshop.ops.bilateral import bilateral_filter, prepare_guide
from matshop.ops.bilateral_ops import MAX_RESIDUAL, bilateral

__all__ = ["chessboard"]  # the real edit values, a fixture shared with test_bilateral
SCHEMA = Schema.from_names(["base_color", "metallic", "roughness", "normal"])  # the chessboard's


def kept_axes(image: np.ndarray, weights: np.ndarray, sigma_range: float, residual: float) -> int:
    """Independent count: leading axes of the covariance of every texel, by dropped variance."""
    guide = image.reshape(-1, image.shape[2]).astype(np.float64) * weights / sigma_range
    variance = np.sort(np.linalg.eigvalsh(np.cov(guide.T, bias=True)))[::-1].clip(0)
    tails = np.cumsum(variance[::-1])[::-1]
    return int(np.count_nonzero(tails > residual))


def mixed_guide(size: int = 96) -> tuple[np.ndarray, np.ndarray]:
    """Six channels: two strong independent fields, one weak one, three combinations."""
    rng = np.random.default_rng(5)
    yy, xx = np.mgrid[0:size, 0:size] / size
    strong = np.stack([np.sin(6 * xx) > 0, np.cos(5 * yy) > 0], -1).astype(np.float64)
    weak = 0.02 * np.sin(9 * xx * yy)[..., None]
    mixed = strong @ rng.random((2, 3)) + weak
    image = np.concatenate([strong, weak, mixed], -1) + rng.normal(0, 0.003, (size, size, 6))
    return image.astype(np.float32), np.ones(6)


@pytest.mark.parametrize("residual", [1e-4, 1e-3, 0.01, 0.1, 1.0])
def test_kept_axes_follow_the_explained_variance(residual) -> None:
    image, weights = mixed_guide()
    guide = prepare_guide(image, weights, 0.1, None, residual)
    # the guide samples every texel of this small image, so the counts agree exactly
    assert guide.dims == max(1, kept_axes(image, weights, 0.1, residual))


@pytest.mark.parametrize("sigma_s", [4.0, 8.0])
def test_auto_guide_is_within_40_db_of_the_exact_filter_on_real_crops(chessboard, sigma_s) -> None:
    edit, weights = chessboard
    for row, col in [(0, 0), (700, 1300), (1024, 512)]:
        image = crop(edit, row, col)
        exact = brute_force(image, sigma_s, 0.1, weights=weights)
        auto = bilateral_filter(
            image,
            sigma_space_px=sigma_s,
            sigma_range=0.1,
            channel_weights=weights,
            max_residual=MAX_RESIDUAL,
        )
        full_dims = prepare_guide(image, weights.astype(np.float64), 0.1, None).dims
        auto_dims = prepare_guide(image, weights.astype(np.float64), 0.1, None, MAX_RESIDUAL).dims
        print(
            f"crop {row},{col} sigma {sigma_s}: axes {auto_dims} of {full_dims}, "
            f"{psnr(auto, exact):.1f} dB"
        )
        assert psnr(auto, exact) >= 40.0


def test_the_full_guide_is_the_filter_with_every_axis(chessboard) -> None:
    edit = np.ascontiguousarray(chessboard[0][:96, :96])
    full = bilateral(edit, sigma_px=4.0, schema=SCHEMA, guide="full")
    every = bilateral_filter(
        edit, sigma_space_px=4.0, sigma_range=0.1, channel_weights=chessboard[1]
    )
    assert np.array_equal(full, every)
    auto = bilateral(edit, sigma_px=4.0, schema=SCHEMA)
    assert not np.array_equal(auto, full)  # this crop has axes worth dropping
