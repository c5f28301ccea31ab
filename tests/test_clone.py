"""Seamless cloning by mean-value coordinates: exactness, smoothness, accuracy, regions, borders."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from matshop.ops.clone import CloneCoordinates, CloneError, clone, region_mask, seamless_clone

RNG = np.random.default_rng(7)


def disc(shape: tuple[int, int], cx: float, cy: float, r: float) -> np.ndarray:
    yy, xx = np.indices(shape)
    return (xx - cx) ** 2 + (yy - cy) ** 2 <= r * r


def smooth_field(shape: tuple[int, int], channels: int, sigma: float = 6.0) -> np.ndarray:
    noise = RNG.normal(size=(*shape, channels))
    field = ndimage.gaussian_filter(noise, (sigma, sigma, 0), mode="wrap")
    return (field / field.std()).astype(np.float32)


def texture(shape: tuple[int, int], channels: int) -> np.ndarray:
    return RNG.random((*shape, channels), dtype=np.float32)


def brute_force_membrane(boundary: np.ndarray, diffs: np.ndarray, points: np.ndarray):
    """Mean-value interpolation of ``diffs`` over the closed polygon ``boundary`` at ``points``.

    Textbook form, independent of the implementation: angles by atan2,
    ``w_i = (tan(a_(i-1)/2) + tan(a_i/2)) / r_i``, ``lambda = w / sum(w)``.
    """
    b = boundary.astype(np.float64)
    out = np.empty((len(points), diffs.shape[1]))
    for start in range(0, len(points), 256):
        x = points[start : start + 256, None, :].astype(np.float64)
        d = b[None] - x  # (P, N, 2)
        dn = np.roll(d, -1, axis=1)
        r = np.hypot(d[..., 0], d[..., 1])
        angle = np.arctan2(d[..., 0] * dn[..., 1] - d[..., 1] * dn[..., 0], (d * dn).sum(-1))
        half = np.tan(angle / 2)
        w = (half + np.roll(half, 1, axis=1)) / r
        lam = w / w.sum(axis=1, keepdims=True)
        out[start : start + 256] = lam @ diffs
    return out


def laplacian(image: np.ndarray) -> np.ndarray:
    """5-point Laplacian over the two image axes (wrapping), per channel."""
    return sum(np.roll(image, s, axis=a) for s in (1, -1) for a in (0, 1)) - 4 * image


def ring_distance(mask: np.ndarray) -> np.ndarray:
    """Distance (px) of each region pixel to the nearest pixel outside."""
    return ndimage.distance_transform_edt(np.pad(mask, 1))[1:-1, 1:-1]


# ---------------------------------------------------------------- exactness


def test_identical_source_and_target_is_a_no_op() -> None:
    image = texture((48, 64), 5)
    mask = disc(image.shape[:2], 30, 22, 14)
    out = seamless_clone(image, image, region=mask, offset=(0, 0))
    np.testing.assert_array_equal(out, image)
    assert out is not image


def test_boundary_is_target_and_interior_gradient_is_source() -> None:
    shape = (96, 96)
    target = smooth_field(shape, 3, sigma=8) + texture(shape, 3)
    source = 3.0 * smooth_field(shape, 3, sigma=10) + texture(shape, 3)
    mask = disc(shape, 40, 44, 26)
    coords = CloneCoordinates.from_region(mask, shape)
    dx, dy = 9, -6
    out = coords.clone(target, source, (dx, dy))

    bx, by = coords.boundary[:, 0], coords.boundary[:, 1]
    np.testing.assert_array_equal(out[by + dy, bx + dx], target[by + dy, bx + dx])
    outside = np.ones(shape, bool)
    outside[by + dy, bx + dx] = False
    outside[coords.interior[:, 1] + dy, coords.interior[:, 0] + dx] = False
    np.testing.assert_array_equal(out[outside], target[outside])

    # result - source (the membrane) is smooth inside, away from the seam: the
    # pasted detail (Laplacian) is the source's. Exact MVC gives a ratio of
    # ~0.003 here, the piecewise-linear mesh interpolation ~0.02.
    membrane = np.roll(out, (-dy, -dx), axis=(0, 1)) - source
    away = ring_distance(mask) >= 4
    lap_membrane = np.abs(laplacian(membrane)[away])
    lap_source = np.abs(laplacian(source)[away])
    assert lap_membrane.mean() < 0.04 * lap_source.mean()
    pasted = np.roll(out, (-dy, -dx), axis=(0, 1))
    assert np.abs(laplacian(pasted) - laplacian(source))[away].mean() < 0.04 * lap_source.mean()


def test_constant_difference_is_reproduced_exactly() -> None:
    source = texture((60, 70), 4)
    shift = np.array([0.25, -1.5, 3.0, 1e3], dtype=np.float32)
    target = np.roll(source, (5, 7), axis=(0, 1)) + shift
    mask = disc(source.shape[:2], 32, 28, 17)
    out = seamless_clone(target, source, region=mask, offset=(7, 5))
    # source + constant everywhere in the region: the result is the target
    np.testing.assert_allclose(out, target, rtol=2e-6, atol=2e-6 * np.abs(shift).max())


@pytest.mark.parametrize("channels", [1, 3, 10])
def test_linearity(channels: int) -> None:
    shape = (50, 58)
    t1, t2 = texture(shape, channels), smooth_field(shape, channels)
    s1, s2 = smooth_field(shape, channels), texture(shape, channels)
    coords = CloneCoordinates.from_region(disc(shape, 25, 26, 15), shape)
    a, b = 0.75, -2.5
    lhs = coords.clone(a * t1 + b * t2, a * s1 + b * s2, (6, -4))
    rhs = a * coords.clone(t1, s1, (6, -4)) + b * coords.clone(t2, s2, (6, -4))
    np.testing.assert_allclose(lhs, rhs, atol=1e-5)


def test_channels_are_independent_and_any_count_works() -> None:
    shape = (40, 44)
    target, source = texture(shape, 140), smooth_field(shape, 140)
    mask = disc(shape, 20, 21, 12)
    many = seamless_clone(target, source, region=mask, offset=(2, 3))
    few = seamless_clone(target[..., 60:63], source[..., 60:63], region=mask, offset=(2, 3))
    one = seamless_clone(target[..., 7], source[..., 7], region=mask, offset=(2, 3))
    np.testing.assert_allclose(many[..., 60:63], few, atol=1e-6)
    np.testing.assert_allclose(many[..., 7], one, atol=1e-6)


# ---------------------------------------------------------------- accuracy of the acceleration

#: max |accelerated - exact| membrane error as a fraction of the boundary
#: difference range (40 px disc; measured: noise ~0.020, smooth <= 0.007)
NOISE_BOUND = 0.03
SMOOTH_BOUND = 0.01


def test_membrane_matches_brute_force_mean_value_coordinates() -> None:
    shape = (56, 56)
    mask = disc(shape, 27.6, 28.3, 20)  # a 40 px disc
    coords = CloneCoordinates.from_region(mask, shape)
    boundary = coords.boundary

    # the boundary is the region's closed chain of border pixels
    border = mask & ~ndimage.binary_erosion(mask, border_value=0)
    assert {tuple(p) for p in boundary} == {tuple(p) for p in np.argwhere(border)[:, ::-1]}
    steps = np.abs(np.diff(np.vstack([boundary, boundary[:1]]), axis=0))
    assert steps.max() == 1
    interior = coords.interior
    assert len(interior) == mask.sum() - border.sum()

    bx, by = boundary[:, 0].astype(float), boundary[:, 1].astype(float)
    noise = RNG.random((len(boundary), 1))
    smooth = np.stack(
        [np.sin(bx / 7) + np.cos(by / 5), (bx / 56) ** 2, np.sin(bx / 20 + by / 13)], axis=1
    )
    for diffs, bound in ((noise, NOISE_BOUND), (smooth, SMOOTH_BOUND)):
        exact = brute_force_membrane(boundary, diffs, interior)
        fast = coords.membrane(diffs.astype(np.float32))
        error = np.abs(fast - exact).max(axis=0) / np.ptp(diffs, axis=0)
        assert error.max() < bound, error
        # and through the public function: result - source inside
        target = np.zeros((*shape, diffs.shape[1]), np.float32)
        target[by.astype(int), bx.astype(int)] = diffs
        out = seamless_clone(target, np.zeros_like(target), region=mask, offset=(0, 0))
        np.testing.assert_allclose(out[interior[:, 1], interior[:, 0]], fast, atol=1e-6)

    # the exact option is the brute force
    reference = CloneCoordinates.from_region(mask, shape, exact=True)
    np.testing.assert_allclose(
        reference.membrane(smooth.astype(np.float32)),
        brute_force_membrane(boundary, smooth, interior),
        atol=2e-6,
    )


def test_pixels_opencvs_triangles_miss_are_placed_in_qhulls(monkeypatch) -> None:
    """OpenCV's Delaunay (run beside the weights, on the clone's own thread) claims no
    pixel here; Qhull's triangles then place them all, and the membrane is still
    mean-value interpolation (against the brute force, as above)."""
    import threading

    from matshop.ops import clone as clone_module

    threads = []

    def no_triangles(points: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
        threads.append(threading.current_thread().name)
        return np.zeros((0, 3), dtype=np.int64)

    monkeypatch.setattr(clone_module, "_delaunay_cv2", no_triangles)
    shape = (128, 128)
    mask = disc(shape, 63.4, 64.2, 56)
    coords = CloneCoordinates.from_region(mask, shape)
    assert len(threads) == 1 and threads[0].startswith("matshop-delaunay")
    boundary, interior = coords.boundary, coords.interior
    # interpolated in triangles, not the exact coordinates (the last resort)
    assert coords.mesh_vertices < 0.5 * len(interior)
    bx, by = boundary[:, 0].astype(float), boundary[:, 1].astype(float)
    smooth = np.stack([np.sin(bx / 17) + np.cos(by / 11), (bx / 128) ** 2], axis=1)
    exact = brute_force_membrane(boundary, smooth, interior)
    fast = coords.membrane(smooth.astype(np.float32))
    error = np.abs(fast - exact).max(axis=0) / np.ptp(smooth, axis=0)
    assert error.max() < SMOOTH_BOUND, error


def test_accuracy_grows_with_the_settings() -> None:
    shape = (56, 56)
    mask = disc(shape, 27.6, 28.3, 20)
    coarse = CloneCoordinates.from_region(mask, shape, mesh_density=2, far=3)
    fine = CloneCoordinates.from_region(mask, shape, mesh_density=8, far=16)
    assert coarse.mesh_vertices < fine.mesh_vertices
    diffs = np.sin(coarse.boundary[:, :1] / 6.0)
    exact = brute_force_membrane(coarse.boundary, diffs, coarse.interior)
    err_coarse = np.abs(coarse.membrane(diffs.astype(np.float32)) - exact).max()
    err_fine = np.abs(fine.membrane(diffs.astype(np.float32)) - exact).max()
    assert err_fine < 0.5 * err_coarse


# ---------------------------------------------------------------- regions


@pytest.mark.parametrize(
    ("polygon", "make_mask"),
    [
        # a diamond: its edges run through pixel centres
        ([(30, 8), (52, 30), (30, 52), (8, 30)], lambda x, y: abs(x - 30) + abs(y - 30) <= 22),
        (
            [(10, 12), (49, 12), (49, 40), (10, 40)],
            lambda x, y: (10 <= x) & (x <= 49) & (12 <= y) & (y <= 40),
        ),
    ],
)
def test_polygon_and_mask_give_the_same_clone(polygon, make_mask) -> None:
    shape = (64, 60)
    yy, xx = np.indices(shape)
    mask = make_mask(xx, yy)
    np.testing.assert_array_equal(region_mask(np.array(polygon), shape), mask)
    target, source = texture(shape, 3), smooth_field(shape, 3)
    a = seamless_clone(target, source, region=np.array(polygon, float), offset=(3, -2))
    b = seamless_clone(target, source, region=mask, offset=(3, -2))
    np.testing.assert_array_equal(a, b)


def test_polygon_of_a_disc_is_rasterized_by_pixel_centres() -> None:
    shape = (70, 80)
    angles = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    polygon = np.stack([40.3 + 21 * np.cos(angles), 33.8 + 21 * np.sin(angles)], axis=1)
    mask = region_mask(polygon, shape)
    reference = disc(shape, 40.3, 33.8, 21)
    assert np.count_nonzero(mask != reference) <= 4  # polygon vs circle on the rim only
    target, source = texture(shape, 2), texture(shape, 2)
    np.testing.assert_array_equal(
        seamless_clone(target, source, region=polygon, offset=(1, 2)),
        seamless_clone(target, source, region=mask, offset=(1, 2)),
    )


def test_components_are_cloned_separately_and_holes_are_filled() -> None:
    shape = (60, 90)
    target, source = texture(shape, 3), 2 + smooth_field(shape, 3)
    left, right = disc(shape, 20, 30, 12), disc(shape, 65, 28, 15)
    both = seamless_clone(target, source, region=left | right, offset=(2, 1))
    one_by_one = seamless_clone(
        seamless_clone(target, source, region=left, offset=(2, 1)),
        source,
        region=right,
        offset=(2, 1),
    )
    np.testing.assert_allclose(both, one_by_one, atol=1e-6)

    ring = right & ~disc(shape, 65, 28, 6)
    np.testing.assert_array_equal(
        seamless_clone(target, source, region=ring, offset=(2, 1)),
        seamless_clone(target, source, region=right, offset=(2, 1)),
    )


def test_coordinates_are_reused_across_offsets() -> None:
    shape = (64, 64)
    image = texture(shape, 4)
    mask = disc(shape, 20, 20, 11)
    coords = CloneCoordinates.from_region(mask, shape)
    for offset in [(25, 3), (30, 31), (-5, 2)]:
        np.testing.assert_array_equal(
            seamless_clone(image, image, region=coords, offset=offset),
            seamless_clone(image, image, region=mask, offset=offset),
        )


def test_reclone_into_a_reused_buffer_and_the_op_form() -> None:
    shape = (40, 50)
    image = texture(shape, 3)
    mask = disc(shape, 15, 18, 9)
    coords = CloneCoordinates.from_region(mask, shape)
    expected = coords.clone(image, image, (20, 4))
    buffer = np.full_like(image, np.nan)
    assert coords.clone(image, image, (20, 4), out=buffer) is buffer
    np.testing.assert_array_equal(buffer, expected)
    with pytest.raises(ValueError, match="share memory"):
        coords.clone(image, image, (20, 4), out=image)
    # the registry form clones the edit array from itself by default
    np.testing.assert_array_equal(clone(image, region=coords, offset=(20, 4)), expected)
    half = clone(image, region=mask, offset=(20, 4), mask=np.full(shape, 0.5, np.float32))
    np.testing.assert_allclose(half, (image + expected) / 2, atol=1e-6)


# ---------------------------------------------------------------- borders


def test_wrap_pastes_across_the_image_edge() -> None:
    shape = (48, 56)
    target, source = texture(shape, 3), smooth_field(shape, 3)
    mask = disc(shape, 24, 22, 13)
    offset = (28, 30)  # lands on x 39..65, y 39..65: across both edges
    wrapped = seamless_clone(target, source, region=mask, offset=offset, border="wrap")

    # the same paste on a 2x2 tiling of the target, where it does not wrap
    tiled = np.tile(target, (2, 2, 1))
    source_big = np.zeros_like(tiled)
    source_big[: shape[0], : shape[1]] = source
    mask_big = np.zeros(tiled.shape[:2], bool)
    mask_big[: shape[0], : shape[1]] = mask
    big = seamless_clone(tiled, source_big, region=mask_big, offset=offset, border="error")
    folded = target.copy()
    yy, xx = np.nonzero(np.roll(mask_big, offset[::-1], axis=(0, 1)))
    folded[yy % shape[0], xx % shape[1]] = big[yy, xx]
    np.testing.assert_allclose(wrapped, folded, atol=1e-6)
    assert not np.allclose(wrapped[:5, :5], target[:5, :5])  # the corner got pasted


def test_clamp_drops_what_falls_outside() -> None:
    shape = (48, 56)
    target, source = texture(shape, 2), smooth_field(shape, 2)
    mask = disc(shape, 24, 22, 13)
    out = seamless_clone(target, source, region=mask, offset=(25, 0), border="clamp")
    np.testing.assert_array_equal(out[:, :30], target[:, :30])  # nothing wrapped to the left
    assert not np.allclose(out[15:30, 45:], target[15:30, 45:])
    with pytest.raises(CloneError, match="leaves"):
        seamless_clone(target, source, region=mask, offset=(25, 0), border="error")


# ---------------------------------------------------------------- bad input


def test_bad_input_errors() -> None:
    shape = (32, 40)
    target, source = texture(shape, 3), texture(shape, 3)
    mask = disc(shape, 15, 15, 8)
    with pytest.raises(ValueError, match="empty"):
        seamless_clone(target, source, region=np.zeros(shape, bool), offset=(0, 0))
    with pytest.raises(ValueError, match="entirely outside"):
        seamless_clone(target, source, region=mask, offset=(100, 0), border="clamp")
    with pytest.raises(ValueError, match="channels"):
        seamless_clone(target, texture(shape, 4), region=mask, offset=(0, 0))
    with pytest.raises(ValueError, match="region mask is 41x32"):
        seamless_clone(target, source, region=np.ones((32, 41), bool), offset=(0, 0))
    with pytest.raises(ValueError, match="3 or more vertices"):
        seamless_clone(target, source, region=np.array([[1, 1], [5, 5]]), offset=(0, 0))
    with pytest.raises(ValueError, match="border"):
        seamless_clone(target, source, region=mask, offset=(0, 0), border="mirror")
    with pytest.raises(ValueError, match="offset"):
        seamless_clone(target, source, region=mask, offset=(0.5, 0))
    with pytest.raises(ValueError, match="wraps onto itself"):
        seamless_clone(texture((10, 10), 3), source, region=mask, offset=(0, 0))
    coords = CloneCoordinates.from_region(mask, shape)
    with pytest.raises(ValueError, match="built for a 40x32 source"):
        coords.clone(target, texture((32, 41), 3), (0, 0))


def test_seamless_clone_writes_into_the_callers_buffer() -> None:
    rng = np.random.default_rng(3)
    image = rng.random((64, 80, 4), dtype=np.float32)
    mask = np.zeros((64, 80), dtype=bool)
    mask[20:40, 10:30] = True
    fresh = seamless_clone(image, image, region=mask, offset=(25, 5))
    buffer = np.full_like(image, np.nan)
    assert seamless_clone(image, image, region=mask, offset=(25, 5), out=buffer) is buffer
    assert np.array_equal(buffer, fresh)
