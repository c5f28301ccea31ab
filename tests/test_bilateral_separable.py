"""The separable bilateral against brute-force references (float64, numpy).

Two truths the kernel did not produce: a second, direct implementation of the
same separable filter (a 1-D bilateral along the rows, then along the columns,
both weighted by the original guide, cut at ceil(3 sigma)), over an image large
enough to cross the kernel's tiles; and the exact 2-D filter on images whose
guide varies along one axis only, where the separable filter is exact.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_bilateral import brute_force, voronoi_material

from matshop.ops.bilateral import bilateral_filter

RNG = np.random.default_rng(11)


def separable_reference(
    image: np.ndarray, sigma_s: float, sigma_r: float, weights: np.ndarray, border: str
) -> np.ndarray:
    """Row pass then column pass, each ``sum_t w_t v(x + t) / sum_t w_t``, in float64."""
    img = image.astype(np.float64)
    guide = img * weights / sigma_r
    radius = math.ceil(3 * sigma_s)
    mode = "wrap" if border == "wrap" else "edge"

    def one_pass(values: np.ndarray, axis: int) -> np.ndarray:
        pads = [(0, 0)] * 3
        pads[axis] = (radius, radius)
        padded_values = np.pad(values, pads, mode=mode)
        padded_guide = np.pad(guide, pads, mode=mode)
        num = np.zeros_like(values)
        den = np.zeros(values.shape[:2] + (1,))
        size = values.shape[axis]
        for t in range(-radius, radius + 1):
            window = np.arange(radius + t, radius + t + size)
            far = np.take(padded_values, window, axis=axis)
            dist2 = np.sum((np.take(padded_guide, window, axis=axis) - guide) ** 2, axis=-1)
            w = math.exp(-t * t / (2 * sigma_s**2)) * np.exp(-dist2 / 2)[..., None]
            num += w * far
            den += w
        return num / den

    return one_pass(one_pass(img, 1), 0)


@pytest.mark.parametrize("border", ["wrap", "clamp"])
@pytest.mark.parametrize("sigma_s", [1.5, 4.0])
def test_matches_a_direct_separable_filter_across_tiles(sigma_s, border) -> None:
    # 300 x 600: more than one tile each way (256 rows, 512 columns), and a last
    # tile narrower than the others; two passenger channels of uniform noise
    guide = voronoi_material(300, 3, noise=0.03, seed=12)[:, :300]
    guide = np.concatenate([guide, guide[:, ::-1]], axis=1)
    image = np.concatenate([guide, RNG.random((300, 600, 2), dtype=np.float32)], axis=2)
    weights = np.array([1.0, 0.5, 2.0, 0.0, 0.0])
    out = bilateral_filter(
        image,
        sigma_space_px=sigma_s,
        sigma_range=0.2,
        channel_weights=weights,
        border=border,
        method="separable",
    )
    ref = separable_reference(image, sigma_s, 0.2, weights, border)
    error = np.abs(out - ref)
    print(f"separable sigma {sigma_s} {border}: max error {error.max():.2e}")
    # the kernel's exp(-q) is within 2.6e-4 of the true one; float32 sums
    assert error.max() < 1e-3
    assert float(np.sqrt(np.mean(error**2))) < 1e-4


@pytest.mark.parametrize("axis", [0, 1])
def test_exact_when_the_guide_varies_along_one_axis(axis) -> None:
    """Steps and a ramp along one axis: the 2-D weights factor into the two passes."""
    size = 72
    steps = RNG.random(size // 8).repeat(8) + np.linspace(0, 0.3, size)
    guide = np.broadcast_to(steps[:, None] if axis == 0 else steps[None, :], (size, size))
    passenger = RNG.random((size, size), dtype=np.float32)  # varies both ways: not a guide
    image = np.stack([guide, passenger], axis=-1).astype(np.float32)
    weights = np.array([1.0, 0.0])
    for sigma_s in (2.0, 5.0):
        out = bilateral_filter(
            image,
            sigma_space_px=sigma_s,
            sigma_range=0.1,
            channel_weights=weights,
            method="separable",
        )
        exact = brute_force(image, sigma_s, 0.1, weights=weights)
        assert np.abs(out - exact).max() < 1e-3


def test_differs_from_the_exact_filter_on_oblique_edges() -> None:
    """Not exact in general: across a diagonal edge it counts neighbours the 2-D kernel does not."""
    size = 64
    yy, xx = np.mgrid[0:size, 0:size]
    guide = ((xx + yy) % 32 < 16).astype(np.float32)  # diagonal stripes, tileable
    passenger = RNG.random((size, size), dtype=np.float32)
    image = np.stack([guide, passenger], axis=-1)
    weights = np.array([1.0, 0.0])
    out = bilateral_filter(
        image, sigma_space_px=4.0, sigma_range=0.1, channel_weights=weights, method="separable"
    )
    exact = brute_force(image, 4.0, 0.1, weights=weights)
    # the guide itself is preserved either way; the passenger's averages differ
    assert np.abs(out[..., 0] - exact[..., 0]).max() < 1e-3
    assert np.abs(out[..., 1] - exact[..., 1]).max() > 1e-2
