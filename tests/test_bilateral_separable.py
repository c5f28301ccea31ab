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


# The kernel has loops specialised by guide width (1, 2, 3 range dimensions, and
# a general one beyond), takes taps four at a time with single taps for the rest
# and channels two at a time with an odd one out: every case against the direct
# filter, on both borders, across the tiles.
@pytest.mark.parametrize("border", ["wrap", "clamp"])
@pytest.mark.parametrize(
    ("guide_channels", "passengers", "sigma_s"),
    [
        (1, 1, 1.5),  # 11 taps: two sweeps of four and three single ones
        (2, 2, 0.3),  # 3 taps: single ones only
        (3, 0, 1.0),  # 7 taps; 3 + 1 channels with the weight sum
        (4, 1, 2.0),
        (5, 2, 1.5),
        (0, 3, 1.5),  # no guide: a Gaussian blur
    ],
)
def test_every_guide_width_tap_and_channel_count_matches_the_direct_filter(
    guide_channels, passengers, sigma_s, border
) -> None:
    height, width = 260, 530  # two tiles each way, the second ones narrow
    image = RNG.random((height, width, guide_channels + passengers), dtype=np.float32)
    # independent random channels (and steps, so some weights are near 0):
    # every guide channel is a principal axis that the guide keeps
    image[..., :guide_channels] = np.floor(image[..., :guide_channels] * 4) / 4
    image[..., :guide_channels] += RNG.normal(0, 0.02, (height, width, guide_channels))
    weights = np.array([1.0, 0.7, 1.3, 0.9, 1.1][:guide_channels] + [0.0] * passengers)
    out = bilateral_filter(
        image,
        sigma_space_px=sigma_s,
        sigma_range=0.3,
        channel_weights=weights,
        border=border,
        method="separable",
    )
    ref = separable_reference(image, sigma_s, 0.3, weights, border)
    error = np.abs(out - ref)
    rms = float(np.sqrt(np.mean(error**2)))
    print(f"{guide_channels} guide + {passengers} {sigma_s}: max {error.max():.2e} rms {rms:.2e}")
    # the kernel's exp(-q) is within 2.6e-4 of the true one; steps of 0.25 at
    # sigma_range 0.3 put many weights where its error peaks (q ~ 2): measured
    # max 4-6e-4, rms up to 1.5e-4 (4 guide channels), as for one tap per sweep
    assert error.max() < 1e-3
    assert rms < 2e-4


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize(("row", "column", "channel"), [(0, 0, 4), (299, 599, 0), (150, 512, 3)])
def test_a_non_finite_texel_anywhere_is_refused(bad, row, column, channel) -> None:
    """One bad value (a corner, a tile edge, a passenger channel) is caught, not filtered.

    300 x 600 texels: more than the guide's sample, so the kernel's own check
    has to find it.
    """
    image = RNG.random((300, 600, 5), dtype=np.float32)
    image[row, column, channel] = bad
    weights = np.array([1.0, 1.0, 1.0, 0.0, 0.0])
    for border in ("wrap", "clamp"):
        with pytest.raises(ValueError, match="bilateral: the image has non-finite values"):
            bilateral_filter(
                image,
                sigma_space_px=2.0,
                sigma_range=0.2,
                channel_weights=weights,
                border=border,
                method="separable",
            )
