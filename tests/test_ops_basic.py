"""Scale, curves/levels, blur and compositing: meaning, linearity, selection, masks."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from matshop.material import Material, Schema
from matshop.ops import OpError, all_ops, get_op
from matshop.ops.blur import gaussian_blur
from matshop.ops.composite import composite
from matshop.ops.curves import curve_lut, curves, levels
from matshop.ops.scale import scale
from matshop.spaces.frame import height_to_normal

RNG = np.random.default_rng(42)


def random_material(height: int = 48, width: int = 40) -> Material:
    schema = Schema.from_names(["base_color", "roughness", "normal", "metallic"])
    normal = RNG.normal(size=(height, width, 3)) * [0.4, 0.4, 1] + [0, 0, 1]
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    maps = {
        "base_color": RNG.random((height, width, 3), dtype=np.float32),
        "roughness": RNG.uniform(0.05, 1, (height, width, 1)).astype(np.float32),
        "normal": normal.astype(np.float32),
        "metallic": RNG.random((height, width, 1), dtype=np.float32),
    }
    return Material("random", schema, maps)


def angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.degrees(np.arccos(np.clip(np.sum(a * b, axis=-1), -1, 1)))


# ---------------------------------------------------------------- registry and specs


def test_every_op_declares_its_parameters_once() -> None:
    for name, spec in all_ops().items():
        assert spec.name == name and spec.summary and spec.label
        for param in spec.params:
            assert param.doc
            if param.kind in ("float", "int"):
                lo, hi = param.hard_range
                assert lo <= param.default <= hi
                if param.ui_range:
                    assert lo <= param.ui_range[0] <= param.ui_range[1] <= hi


@pytest.mark.parametrize(
    ("op", "values", "match"),
    [
        ("blur", {"sigma_px": -1.0}, "outside"),
        ("blur", {"sigma_px": float("nan")}, "finite"),
        ("blur", {"border": "mirror"}, "choose one of"),
        ("blur", {"radius": 3}, "unknown parameter"),
        ("curves", {"points": [(0, 0)]}, "at least two"),
        ("curves", {"points": [(0.5, 0), (0.2, 1)]}, "increasing"),
        ("scale", {"factor": "big"}, "number"),
    ],
)
def test_bad_parameters_are_one_line_errors(op: str, values: dict, match: str) -> None:
    with pytest.raises(OpError, match=match) as err:
        get_op(op).bind(values)
    assert "\n" not in str(err.value) and op in str(err.value)


def test_unknown_op_and_parameter_names() -> None:
    with pytest.raises(OpError, match="unknown op 'sharpen'"):
        get_op("sharpen")
    edit = random_material().to_edit()
    with pytest.raises(OpError, match="no parameter 'sheen'"):
        scale(edit.data, factor=2, schema=edit.schema, params=["sheen"])
    with pytest.raises(OpError, match="mask is"):
        scale(edit.data, factor=2, mask=np.ones((3, 3), np.float32))


# ---------------------------------------------------------------- scale


def test_scaling_frames_scales_every_perturbation_angle() -> None:
    mat = random_material()
    edit = mat.to_edit()
    tilt = angle_deg(mat.maps["normal"], np.array([0, 0, 1.0]))
    for factor in (0.0, 0.5, 2.0):
        scaled = scale(edit.data, factor=factor, schema=edit.schema, params=["normal"])
        back = type(edit)(edit.name, edit.schema, scaled).to_physical()
        new_tilt = angle_deg(back.maps["normal"], np.array([0, 0, 1.0]))
        ok = tilt < 80 / max(factor, 1)  # doubling past 180 degrees wraps around
        assert np.abs(new_tilt[ok] - factor * tilt[ok]).max() < 1e-3
        # only the selected parameter moved
        others = [n for n in edit.schema.names if n != "normal"]
        idx = edit.schema.channel_indices(others)
        assert np.array_equal(scaled[..., idx], edit.data[..., idx])


def test_halving_linear_color_halves_reflectance_under_a_mask() -> None:
    edit = random_material().to_edit()
    mask = np.zeros(edit.size, np.float32)
    mask[:, : edit.size[1] // 2] = 1.0
    out = scale(edit.data, factor=0.5, schema=edit.schema, params="kd", mask=mask)
    color = edit.schema.edit_slices["base_color"]
    half = edit.size[1] // 2
    assert np.allclose(out[:, :half, color], 0.5 * edit.data[:, :half, color])
    assert np.array_equal(out[:, half:], edit.data[:, half:])


# ---------------------------------------------------------------- curves and levels


def test_identity_curve_is_an_exact_no_op() -> None:
    edit = random_material().to_edit()
    out = curves(edit.data, schema=edit.schema)
    assert np.array_equal(out, edit.data) and out is not edit.data


def test_two_point_curve_is_a_scale_and_matches_the_scale_op() -> None:
    # over the space's fixed range (0 at the origin) a straight curve through 0 is a scale
    edit = random_material().to_edit()
    out = curves(edit.data, points=[(0, 0), (1, 0.5)], schema=edit.schema, remap="space")
    assert np.allclose(out, scale(edit.data, factor=0.5), atol=1e-6)


def _data_range(values: np.ndarray, clip: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """remap="data" written out: the median at 0.5, the robust range inside [0, 1]."""
    low, median, high = np.percentile(values, [clip, 50.0, 100.0 - clip], axis=0)
    reach = np.maximum(median - low, high - median)
    return median - reach, 2.0 * reach


def test_curves_over_the_data_range_follow_its_percentiles() -> None:
    """remap="data": [0, 1] spans median -/+ the larger distance to the 0.5th/99.5th
    percentile, per channel (of |v| for a frame), and the curve continues with slope 1
    beyond; truth from numpy's percentiles and the curve's formula."""
    edit = random_material().to_edit()
    data = edit.data.astype(np.float64)
    out = curves(edit.data, points=[(0, 0), (1, 0.5)], schema=edit.schema)

    def halved(t: np.ndarray) -> np.ndarray:  # the curve t -> t / 2, slope 1 outside
        return np.where(t < 0, t, np.where(t > 1, 0.5 + (t - 1), 0.5 * t))

    color = edit.schema.edit_slices["base_color"]
    lo, span = _data_range(data[..., color].reshape(-1, 3))
    want = lo + span * halved((data[..., color] - lo) / span)
    np.testing.assert_allclose(out[..., color], want, atol=1e-5)
    frame = edit.schema.edit_slices["normal"]
    m = np.linalg.norm(data[..., frame], axis=-1)
    lo, span = _data_range(m.reshape(-1))
    want = np.maximum(lo + span * halved((m - lo) / span), 0.0)
    np.testing.assert_allclose(np.linalg.norm(out[..., frame], axis=-1), want, atol=1e-5)
    # the data's range differs from the space's: the two remaps really differ
    space = curves(edit.data, points=[(0, 0), (1, 0.5)], schema=edit.schema, remap="space")
    assert not np.allclose(out, space, atol=1e-3)


def test_curve_lut_follows_the_control_points_and_is_monotone() -> None:
    points = [(0, 0), (0.25, 0.5), (0.6, 0.7), (1, 1)]
    lut = curve_lut(points)
    t = np.linspace(0, 1, len(lut))
    for x, y in points:
        assert abs(np.interp(x, t, lut) - y) < 1e-3
    assert np.all(np.diff(lut) >= 0)


def test_vector_curves_keep_direction_and_remap_magnitude() -> None:
    edit = random_material().to_edit()
    frame = edit.schema.edit_slices["normal"]
    out = curves(
        edit.data,
        points=[(0, 0), (0.5, 0.25), (1, 0.5)],
        schema=edit.schema,
        params="normal",
        remap="space",
    )
    before, after = edit.data[..., frame], out[..., frame]
    # same direction: the cross product vanishes
    assert np.abs(np.cross(before, after)).max() < 1e-5
    # magnitude m (in [0, pi/2]) mapped through the curve: here m -> m / 2
    assert np.allclose(
        np.linalg.norm(after, axis=-1), 0.5 * np.linalg.norm(before, axis=-1), atol=1e-5
    )


def test_levels_match_the_formula_per_channel() -> None:
    edit = random_material().to_edit()
    kwargs = {"in_black": 0.1, "in_white": 0.8, "gamma": 2.0, "params": "metallic"}
    out = levels(edit.data, schema=edit.schema, remap="space", **kwargs)
    m = edit.schema.edit_slices["metallic"]
    x = np.clip((edit.data[..., m].astype(np.float64) - 0.1) / 0.7, 0, 1) ** 0.5
    assert np.abs(out[..., m] - x).max() < 1e-3
    # over the data's range (outliers: below the 2nd, above the 98th percentile)
    out = levels(edit.data, schema=edit.schema, clip_percent=2.0, **kwargs)
    v = edit.data[..., m].astype(np.float64)
    lo, span = _data_range(v.reshape(-1), 2.0)
    t = (v - lo) / span
    inside = lo + span * np.clip((t - 0.1) / 0.7, 0, 1) ** 0.5
    x = np.where(t < 0, lo + span * t, np.where(t > 1, lo + span * t, inside))
    # the 4096-entry table is coarse only at the black point, where x^0.5 is vertical
    assert np.abs(out[..., m] - x).max() < 5e-3
    assert np.abs(out[..., m] - x).mean() < 1e-4


# ---------------------------------------------------------------- blur


@pytest.mark.parametrize("sigma", [0.7, 3.0, 8.0, 30.0])  # seam bands, and full padding
@pytest.mark.parametrize("border", ["wrap", "clamp"])
def test_blur_matches_scipy_gaussian(border: str, sigma: float) -> None:
    image = RNG.random((64, 48, 5), dtype=np.float32)
    ours = gaussian_blur(image, sigma_px=sigma, border=border)
    mode = "wrap" if border == "wrap" else "nearest"
    reference = gaussian_filter(image, sigma=(sigma, sigma, 0), mode=mode, truncate=4.0)
    assert np.abs(ours - reference).max() < 1e-4


@pytest.mark.parametrize("sigma", [2.0, 6.0, 10.0])  # bands of the 2D blur; per-pass strips
def test_wrapped_blur_of_a_larger_image_matches_scipy(sigma: float) -> None:
    image = RNG.random((260, 230, 3), dtype=np.float32)
    ours = gaussian_blur(image, sigma_px=sigma, border="wrap")
    reference = gaussian_filter(image, sigma=(sigma, sigma, 0), mode="wrap", truncate=4.0)
    assert np.abs(ours - reference).max() < 1e-4


def test_blur_is_linear_and_wraps_like_a_tiling_texture() -> None:
    x = RNG.random((32, 32, 4), dtype=np.float32)
    y = RNG.random((32, 32, 4), dtype=np.float32)
    lhs = gaussian_blur(2 * x - 3 * y, sigma_px=2.5)
    rhs = 2 * gaussian_blur(x, sigma_px=2.5) - 3 * gaussian_blur(y, sigma_px=2.5)
    assert np.abs(lhs - rhs).max() < 1e-5
    rolled = gaussian_blur(np.roll(x, (5, -7), axis=(0, 1)), sigma_px=2.5)
    assert (
        np.abs(rolled - np.roll(gaussian_blur(x, sigma_px=2.5), (5, -7), axis=(0, 1))).max() < 1e-6
    )


def test_blurring_frames_keeps_a_tilted_plane_while_blurring_its_height_bends_it() -> None:
    """Fig. 2's point, measured: a tilted plane's normal map tiles, its height does not."""
    size, slope = 64, 0.3
    rows, cols = np.mgrid[0:size, 0:size].astype(np.float32)
    height = slope * cols + 0.05 * np.sin(2 * np.pi * rows / size)  # tilted, gently rippled
    normals = height_to_normal(height[..., None], wrap=False)
    schema = Schema.from_names(["normal"])
    mat = Material("plane", schema, {"normal": normals})
    edit = mat.to_edit()
    blurred = type(edit)("plane", schema, gaussian_blur(edit.data, sigma_px=4.0)).to_physical()
    n_edit = blurred.maps["normal"]
    # the other route: blur the height field and re-derive normals (both wrap: a tiling texture)
    h_blur = gaussian_blur(height[..., None].astype(np.float32), sigma_px=4.0)
    n_height = height_to_normal(h_blur, wrap=True)
    plane = normals.reshape(-1, 3).mean(axis=0)
    plane /= np.linalg.norm(plane)
    edit_err = angle_deg(n_edit, plane)
    height_err = angle_deg(n_height, plane)
    print(
        f"tilted plane, worst deviation: edit space {edit_err.max():.2f} deg, "
        f"height field {height_err.max():.2f} deg"
    )
    assert np.allclose(np.linalg.norm(n_edit, axis=-1), 1.0, atol=1e-5)
    assert edit_err.max() < 1.0
    assert height_err.max() > 30.0  # the seam's cliff spreads into the surface


# ---------------------------------------------------------------- compositing


def test_composite_is_alpha_over_and_linear() -> None:
    a, b, c, d = (RNG.random((16, 16, 6), dtype=np.float32) for _ in range(4))
    mask = RNG.random((16, 16), dtype=np.float32)
    out = composite(a, b, mask=mask, opacity=0.7)
    alpha = 0.7 * mask[..., None]
    assert np.allclose(out, (1 - alpha) * a + alpha * b, atol=1e-6)
    lhs = composite(2 * a + c, 2 * b + d, mask=mask)
    rhs = 2 * composite(a, b, mask=mask) + composite(c, d, mask=mask)
    assert np.abs(lhs - rhs).max() < 1e-5


def test_composite_only_touches_selected_parameters() -> None:
    steel = random_material().to_edit()
    rust = random_material().to_edit()
    out = composite(steel.data, rust.data, schema=steel.schema, params=["base_color", "roughness"])
    chosen = steel.schema.channel_indices(["base_color", "roughness"])
    rest = steel.schema.channel_indices(["normal", "metallic"])
    assert np.array_equal(out[..., chosen], rust.data[..., chosen])
    assert np.array_equal(out[..., rest], steel.data[..., rest])


def test_ops_never_modify_their_input() -> None:
    edit = random_material().to_edit()
    before = edit.data.copy()
    mask = RNG.random(edit.size, dtype=np.float32)
    scale(edit.data, factor=3, mask=mask)
    curves(edit.data, points=[(0, 0.1), (1, 0.9)], schema=edit.schema)
    gaussian_blur(edit.data, sigma_px=2, schema=edit.schema, params="normal", mask=mask)
    composite(edit.data, edit.data[::-1].copy(), mask=mask)
    assert np.array_equal(edit.data, before)


def test_per_channel_scale_of_a_frame_scales_one_axis_of_the_perturbation() -> None:
    material = random_material()
    edit = material.to_edit()
    normal = edit.schema.edit_slices["normal"]
    out = scale(edit.data, schema=edit.schema, params="normal", channel_factors=(0.0, 2.0, 1.0))
    expected = edit.data.copy()
    expected[..., normal] *= np.array([0.0, 2.0, 1.0], np.float32)
    assert np.array_equal(out, expected)
    # with a mask the per-channel result blends like any op
    mask = np.zeros(edit.size, np.float32)
    mask[:, :10] = 1.0
    masked = scale(
        edit.data, schema=edit.schema, params="normal", channel_factors=(0, 2, 1), mask=mask
    )
    assert np.array_equal(masked[:, :10], expected[:, :10])
    assert np.array_equal(masked[:, 10:], edit.data[:, 10:])
    with pytest.raises(OpError, match="has 2 values, the selection has 3"):
        scale(edit.data, schema=edit.schema, params="normal", channel_factors=(1.0, 2.0))
    spec = get_op("scale")
    parsed = spec.parse_args(["channel_factors=0,2,1"])
    assert spec.bind(parsed)["channel_factors"] == (0.0, 2.0, 1.0)
    with pytest.raises(OpError, match="finite"):
        spec.bind({"channel_factors": (1.0, float("nan"))})
