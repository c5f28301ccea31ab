"""The bilateral filter's two evaluations against the exact (brute-force) filter.

The permutohedral lattice approximates the Gaussian in feature space, the
separable filter the 2-D window by a row pass and a column pass, so the exact
filter is the reference: a vectorised sum over a (2R + 1)^2 window,
R = ceil(3 sigma), with the same borders. Accuracy is measured as PSNR over the
reference's data range; measured values are printed (``pytest -s``) and
asserted with some slack. Every accuracy test runs both methods.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter
from scipy.special import ndtri

from matshop.ops.bilateral import bilateral_filter, prepare_guide, run_lattice

CHESSBOARD = Path(__file__).resolve().parents[2] / "shared" / "data" / "chessboard"
RNG = np.random.default_rng(7)

#: accuracy target against the exact filter
MIN_PSNR = 35.0
METHODS = ("separable", "lattice")


# ---------------------------------------------------------------- references


def brute_force(
    image: np.ndarray,
    sigma_s: float,
    sigma_r: float,
    *,
    weights: np.ndarray | None = None,
    guide: np.ndarray | None = None,
    border: str = "wrap",
) -> np.ndarray:
    """The exact bilateral filter, window truncated at 3 sigma (float64)."""
    img = image.astype(np.float64)
    height, width, _ = img.shape
    if guide is None:
        guide = img * (1.0 if weights is None else np.asarray(weights, dtype=np.float64))
    guide = np.asarray(guide, dtype=np.float64)
    radius = math.ceil(3 * sigma_s)
    mode = "wrap" if border == "wrap" else "edge"
    pads = ((radius, radius), (radius, radius), (0, 0))
    padded_img = np.pad(img, pads, mode=mode)
    padded_guide = np.pad(guide, pads, mode=mode)
    num = np.zeros_like(img)
    den = np.zeros((height, width, 1))
    for dy in range(-radius, radius + 1):
        for dx in range(-radius, radius + 1):
            window = (
                slice(radius + dy, radius + dy + height),
                slice(radius + dx, radius + dx + width),
            )
            dist2 = np.sum((padded_guide[window] - guide) ** 2, axis=-1, keepdims=True)
            w = math.exp(-(dy * dy + dx * dx) / (2 * sigma_s**2)) * np.exp(
                -dist2 / (2 * sigma_r**2)
            )
            num += w * padded_img[window]
            den += w
    return num / den


def psnr(result: np.ndarray, reference: np.ndarray) -> float:
    peak = float(reference.max() - reference.min())
    mse = float(np.mean((result.astype(np.float64) - reference) ** 2))
    return 10 * math.log10(peak**2 / mse)


# ---------------------------------------------------------------- data


@pytest.fixture(scope="module")
def chessboard() -> tuple[np.ndarray, np.ndarray]:
    """Real edit values (base color, metallic, roughness, normal frame) and their weights."""
    if not CHESSBOARD.is_dir():
        pytest.skip("shared chessboard texture set not present")
    from matshop.io.material_io import load_material
    from matshop.ops.selection import Selection

    material, _ = load_material(CHESSBOARD)
    edit = material.to_edit().data
    weights = Selection(edit, schema=material.schema, params=None, mask=None, op="bilateral")
    return edit, weights.distance_weights()


def crop(edit: np.ndarray, row: int, col: int, size: int = 64) -> np.ndarray:
    return np.ascontiguousarray(edit[row : row + size, col : col + size])


def voronoi_material(size: int, channels: int, noise: float, seed: int = 0) -> np.ndarray:
    """Flat random materials in tileable Voronoi cells, a gentle gradient, additive noise."""
    rng = np.random.default_rng(seed)
    sites = rng.random((12, 2)) * size
    yy, xx = np.mgrid[0:size, 0:size].astype(np.float64)
    dist = []
    for sy, sx in sites:
        dy = np.abs(yy - sy)
        dx = np.abs(xx - sx)
        dist.append(np.minimum(dy, size - dy) ** 2 + np.minimum(dx, size - dx) ** 2)
    label = np.argmin(dist, axis=0)
    image = rng.random((len(sites), channels))[label]
    image += 0.05 * np.sin(2 * np.pi * xx / size)[..., None]
    image += rng.normal(0, noise, image.shape)
    return image.astype(np.float32)


def distribution_field(
    size: int, samples: int = 128, extra_modes: int = 0, seed: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """Inverse CDFs of normal lobes, sampled at ``samples`` quantiles, varying by region.

    ``extra_modes`` smooth shape variations (random per region) are added to
    the lobes, raising the rank of the field beyond the two of (mean, spread).
    Returns the (size, size, samples) edit values and the quadrature weights
    sqrt(dy), so the guide distance is the 2-Wasserstein distance.
    """
    rng = np.random.default_rng(seed)
    y = (np.arange(samples) + 0.5) / samples
    quantiles = ndtri(y)
    cells = voronoi_material(size, 2 + extra_modes, noise=0.0, seed=seed)
    mean = 0.2 + 0.6 * cells[..., :1] + rng.normal(0, 0.01, (size, size, 1))
    spread = 0.02 + 0.12 * cells[..., 1:2] + rng.normal(0, 0.005, (size, size, 1))
    icdf = mean + spread * quantiles + rng.normal(0, 0.005, (size, size, samples))
    for k in range(extra_modes):
        shape = np.sin((k + 1) * np.pi * y) * 0.15  # a smooth bump of the quantile function
        icdf += (cells[..., 2 + k : 3 + k] - 0.5) * shape
    weights = np.full(samples, math.sqrt(1.0 / samples))
    return icdf.astype(np.float32), weights


# ---------------------------------------------------------------- accuracy


@pytest.mark.parametrize("border", ["wrap", "clamp"])
@pytest.mark.parametrize("sigma_s", [2.0, 4.0, 8.0])
@pytest.mark.parametrize("sigma_r", [0.1, 0.3])
def test_psnr_on_real_edit_values(chessboard, sigma_s, sigma_r, border) -> None:
    edit, weights = chessboard
    worst = dict.fromkeys(METHODS, math.inf)
    for row, col in [(0, 0), (700, 1300), (1024, 512)]:
        image = crop(edit, row, col)
        ref = brute_force(image, sigma_s, sigma_r, weights=weights, border=border)
        for method in METHODS:
            out = bilateral_filter(
                image,
                sigma_space_px=sigma_s,
                sigma_range=sigma_r,
                channel_weights=weights,
                border=border,
                method=method,
            )
            worst[method] = min(worst[method], psnr(out, ref))
    shown = ", ".join(f"{method} {value:.1f}" for method, value in worst.items())
    print(f"chessboard sigma_s={sigma_s} sigma_r={sigma_r} {border}: worst PSNR (dB) {shown}")
    assert min(worst.values()) >= MIN_PSNR


@pytest.mark.parametrize("sigma_s", [2.0, 5.0])
def test_psnr_on_ten_synthetic_channels(sigma_s) -> None:
    image = voronoi_material(64, 10, noise=0.03, seed=1)
    ref = brute_force(image, sigma_s, 0.15)
    for method in METHODS:
        out = bilateral_filter(image, sigma_space_px=sigma_s, sigma_range=0.15, method=method)
        value = psnr(out, ref)
        print(f"10 channels (d = 12) sigma_s={sigma_s} {method}: PSNR {value:.1f} dB")
        assert value >= MIN_PSNR


@pytest.mark.parametrize("extra_modes", [0, 8])
def test_wide_guide_reduced_by_pca(extra_modes) -> None:
    """128 quantile samples, guide reduced to 6 principal components.

    The lattice error is measured against the exact filter with the same
    reduced guide, and the cost of the reduction itself as the exact filter
    with the reduced guide against the exact filter with the full one.
    """
    image, weights = distribution_field(64, extra_modes=extra_modes)
    sigma_s, sigma_r = 3.0, 0.05
    full = brute_force(image, sigma_s, sigma_r, weights=weights)
    guide = image.reshape(-1, image.shape[2]).astype(np.float64) * weights
    centred = guide - guide.mean(axis=0)
    _, _, axes = np.linalg.svd(centred, full_matrices=False)
    reduced = (centred @ axes[:6].T).reshape(64, 64, 6)
    reduced_ref = brute_force(image, sigma_s, sigma_r, guide=reduced)
    pca_cost = psnr(reduced_ref, full)
    for method in METHODS:
        out = bilateral_filter(
            image,
            sigma_space_px=sigma_s,
            sigma_range=sigma_r,
            channel_weights=weights,
            guide_dims=6,
            method=method,
        )
        method_error = psnr(out, reduced_ref)
        total = psnr(out, full)
        print(
            f"128 channels (+{extra_modes} modes), guide 6 PCA dims: {method} vs exact(reduced) "
            f"{method_error:.1f} dB, exact(reduced) vs exact(full) {pca_cost:.1f} dB, "
            f"{method} vs exact(full) {total:.1f} dB"
        )
        assert method_error >= MIN_PSNR
        assert total >= MIN_PSNR


def test_huge_sigma_range_is_a_gaussian_blur() -> None:
    """With an infinite range sigma only the spatial Gaussian remains.

    The lattice's kernel is Gaussian only approximately (its variance is
    calibrated, its shape is piecewise linear in the lattice), so the match
    is loose: measured 42-50 dB PSNR against scipy's exact Gaussian on this
    noisy image; asserted >= 38 dB and a max error below 5 % of the range.
    The separable filter is then a Gaussian blur cut at 3 sigma (scipy's at 4).
    """
    image = voronoi_material(96, 4, noise=0.05, seed=2)
    for sigma_s in (1.5, 3.0, 6.0):
        exact = gaussian_filter(image, sigma=(sigma_s, sigma_s, 0), mode="wrap")
        for method in METHODS:
            out = bilateral_filter(image, sigma_space_px=sigma_s, sigma_range=1e6, method=method)
            assert psnr(out, exact) >= 38.0
            assert np.abs(out - exact).max() <= 0.05 * (exact.max() - exact.min())


def test_no_guide_is_a_gaussian_blur() -> None:
    """All channel weights 0: the range kernel is 1 and the lattice is 2-D."""
    image = voronoi_material(96, 3, noise=0.05, seed=10)
    exact = gaussian_filter(image, sigma=(3.0, 3.0, 0), mode="wrap")
    for method in METHODS:
        out = bilateral_filter(
            image, sigma_space_px=3.0, sigma_range=0.1, channel_weights=np.zeros(3), method=method
        )
        assert psnr(out, exact) >= 38.0


# ---------------------------------------------------------------- behaviour


def test_constant_image_is_unchanged() -> None:
    image = np.broadcast_to(np.linspace(-1, 2, 9, dtype=np.float32), (40, 56, 9)).copy()
    for border in ("wrap", "clamp"):
        out = bilateral_filter(image, sigma_space_px=3.0, sigma_range=0.1, border=border)
        np.testing.assert_allclose(out, image, rtol=0, atol=1e-5)


def test_step_edge_is_preserved_while_noise_is_smoothed() -> None:
    height, width = 64, 96
    material_a = np.array([0.2, 0.5, 0.1, 0.0, 0.8, 0.3, -0.2, 0.0], dtype=np.float32)
    material_b = np.array([0.7, 0.3, 0.4, 1.0, 0.3, -0.1, 0.2, 0.0], dtype=np.float32)
    clean = np.empty((height, width, 8), dtype=np.float32)
    clean[:, : width // 2] = material_a
    clean[:, width // 2 :] = material_b
    noise_std = 0.02
    noisy = clean + RNG.normal(0, noise_std, clean.shape).astype(np.float32)
    out = bilateral_filter(noisy, sigma_space_px=4.0, sigma_range=0.15, border="clamp")
    error = out - clean
    # across the edge (8 columns each side) nothing leaks from the other material
    band = error[:, width // 2 - 8 : width // 2 + 8]
    assert np.abs(band).max() < 0.06
    assert np.sqrt(np.mean(band**2)) < 0.3 * noise_std
    # in the flat parts the noise is averaged away
    residual = float(np.std(error[:, 4 : width // 2 - 12]))
    print(f"step edge: noise std {noise_std} -> {residual:.4f}")
    assert residual < noise_std / 4
    # while a plain Gaussian blur of the same width smears the edge
    blurred = bilateral_filter(noisy, sigma_space_px=4.0, sigma_range=1e6, border="clamp")
    assert np.abs(blurred - clean)[:, width // 2 - 2 : width // 2 + 2].max() > 0.2


@pytest.mark.parametrize("method", METHODS)
def test_wrap_commutes_with_roll(method) -> None:
    """Rolling the texture rolls the result: the seam is not special.

    The lattice is fixed in pixel coordinates, so a shifted image meets it
    at another alignment; both results then differ by the lattice's
    approximation error (measured ~56 dB PSNR), not by a seam. The separable
    filter's sums are the same at every texel, up to float rounding.
    """
    image = voronoi_material(80, 8, noise=0.02, seed=3)
    shift = (37, -51)
    for sigma_s in (2.0, 5.0):
        rolled_first = bilateral_filter(
            np.roll(image, shift, axis=(0, 1)),
            sigma_space_px=sigma_s,
            sigma_range=0.2,
            method=method,
        )
        rolled_after = np.roll(
            bilateral_filter(image, sigma_space_px=sigma_s, sigma_range=0.2, method=method),
            shift,
            axis=(0, 1),
        )
        difference = np.abs(rolled_first - rolled_after).max()
        if method == "lattice":
            assert psnr(rolled_first, rolled_after) >= 45.0
            assert difference < 0.03
        else:
            assert difference < 1e-5


@pytest.mark.parametrize("method", METHODS)
def test_wrap_sees_across_the_seam_and_clamp_does_not(method) -> None:
    image = np.zeros((48, 48, 1), dtype=np.float32)
    image[:, :2] = 1.0  # a stripe on the left edge
    args = {"sigma_space_px": 3.0, "sigma_range": 1e6, "method": method}
    wrap = bilateral_filter(image, border="wrap", **args)
    clamp = bilateral_filter(image, border="clamp", **args)
    assert wrap[:, -1].mean() > 0.2  # the stripe bleeds over the seam to the right edge
    assert clamp[:, -1].max() < 1e-3


@pytest.mark.parametrize("method", METHODS)
def test_zero_weight_channels_do_not_steer_the_weights(method) -> None:
    guide = voronoi_material(48, 3, noise=0.02, seed=4)
    passenger = RNG.random((48, 48, 2), dtype=np.float32)
    image = np.concatenate([guide, passenger], axis=2)
    weights = np.array([1.0, 1.0, 1.0, 0.0, 0.0])
    args = {"sigma_space_px": 3.0, "sigma_range": 0.2, "method": method}
    out = bilateral_filter(image, channel_weights=weights, **args)
    alone = bilateral_filter(guide, **args)
    np.testing.assert_array_equal(out[..., :3], alone)
    # the passengers (uniform noise in [0, 1]) are averaged with the guide's weights: the
    # exact filter's for the lattice, the separable filter's (its own test) for it
    if method == "lattice":
        ref = brute_force(image, 3.0, 0.2, guide=guide)
        assert np.sqrt(np.mean((out[..., 3:] - ref[..., 3:]) ** 2)) < 0.01
    # and changing them changes nothing else
    other = image.copy()
    other[..., 3:] = 0.0
    out_other = bilateral_filter(other, channel_weights=weights, **args)
    np.testing.assert_array_equal(out_other[..., :3], out[..., :3])


def test_channel_weights_scale_the_range_distance() -> None:
    image = voronoi_material(48, 3, noise=0.02, seed=5)
    weights = np.array([2.0, 0.5, 1.0])
    out = bilateral_filter(image, sigma_space_px=2.0, sigma_range=0.4, channel_weights=weights)
    same = bilateral_filter(image * weights.astype(np.float32), sigma_space_px=2.0, sigma_range=0.4)
    # filtering the pre-scaled image gives the same weights, so the same result (scaled)
    np.testing.assert_allclose(out * weights, same, atol=1e-4)


def test_input_is_not_modified_and_output_is_new_float32() -> None:
    image = voronoi_material(40, 5, noise=0.02, seed=6)
    before = image.copy()
    out = bilateral_filter(image, sigma_space_px=2.0, sigma_range=0.2)
    np.testing.assert_array_equal(image, before)
    assert out.dtype == np.float32 and out.shape == image.shape
    assert not np.shares_memory(out, image)
    single = bilateral_filter(image[..., :1].copy(), sigma_space_px=2.0, sigma_range=0.2)
    assert single.shape == (40, 40, 1)


def test_tiles_do_not_show() -> None:
    """Tiles build pieces of one global lattice: tiny tiles give the one-tile result."""
    image = voronoi_material(96, 6, noise=0.02, seed=8)
    guide = prepare_guide(image, np.ones(6), 0.2, None)
    for sigma_s in (2.0, 4.0):
        whole = run_lattice(image, guide, sigma_s, "wrap", tile=96)
        tiled = run_lattice(image, guide, sigma_s, "wrap", tile=16)
        assert psnr(tiled, whole) >= 70.0


def test_duplicated_and_constant_channels_cost_nothing() -> None:
    base = voronoi_material(48, 3, noise=0.02, seed=9)
    wide = np.concatenate([base, base[..., :2], np.full((48, 48, 1), 0.5, np.float32)], axis=2)
    guide = prepare_guide(wide, np.ones(6), 0.2, None)
    assert guide.dims == 3  # the exact duplicates and the constant add no dimension
    out = bilateral_filter(wide, sigma_space_px=3.0, sigma_range=0.2)
    ref = brute_force(wide, 3.0, 0.2)
    assert psnr(out, ref) >= MIN_PSNR


# ---------------------------------------------------------------- validation


GOOD = np.zeros((16, 16, 3), dtype=np.float32)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"sigma_space_px": -1.0}, "sigma_space_px must be positive"),
        ({"sigma_space_px": 0.0}, "sigma_space_px must be positive"),
        ({"sigma_space_px": float("nan")}, "sigma_space_px must be finite"),
        ({"sigma_space_px": float("inf")}, "sigma_space_px must be finite"),
        ({"sigma_space_px": "wide"}, "sigma_space_px must be a number"),
        ({"sigma_space_px": 17.0}, "larger than the 16x16 image"),
        ({"sigma_range": -0.1}, "sigma_range must be positive"),
        ({"sigma_range": float("nan")}, "sigma_range must be finite"),
        ({"channel_weights": np.ones(2)}, "channel_weights must have shape"),
        ({"channel_weights": np.array([1.0, -1.0, 1.0])}, "finite and non-negative"),
        ({"channel_weights": np.array([1.0, np.nan, 1.0])}, "finite and non-negative"),
        ({"guide_dims": 0}, "guide_dims must be at least 1"),
        ({"guide_dims": 2.5}, "guide_dims must be an integer"),
        ({"border": "mirror"}, "border must be one of"),
    ],
)
def test_invalid_arguments_raise(kwargs, message) -> None:
    args = {"sigma_space_px": 2.0, "sigma_range": 0.1} | kwargs
    with pytest.raises(ValueError, match=message):
        bilateral_filter(GOOD, **args)


@pytest.mark.parametrize(
    ("image", "message"),
    [
        (np.zeros((16, 16), dtype=np.float32), r"expected an \(H, W, C\) image"),
        (np.zeros((16, 16, 0), dtype=np.float32), r"expected an \(H, W, C\) image"),
        (np.zeros((0, 16, 3), dtype=np.float32), r"expected an \(H, W, C\) image"),
        (np.full((16, 16, 3), np.nan, dtype=np.float32), "non-finite"),
        (np.array([[["a"]]]), "numeric image"),
    ],
)
def test_invalid_images_raise(image, message) -> None:
    with pytest.raises(ValueError, match=message):
        bilateral_filter(image, sigma_space_px=1.0, sigma_range=0.1)
