"""Variance kept (blur keep_variance=true, export --keep-variance) against closed forms.

The truth in each test is worked out by hand from the tilts the test builds
(a checkerboard of two tilts averaged to uniform has slope covariance
``(a - b)(a - b)^T / 4``); nothing here asks matshop for the expected value.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from matshop.cli import main
from matshop.io.images import read_image, write_image
from matshop.material import Schema
from matshop.ops import get_op
from matshop.ops.variance import lost_slope_covariance

SIZE = 32


def _tilted(theta_x: float, theta_y: float) -> np.ndarray:
    """Unit normal tilted by theta_x in the x-z plane and theta_y in the y-z plane (slopes
    ``-tan theta``)."""
    n = np.array([math.tan(theta_x), math.tan(theta_y), 1.0])
    return n / np.linalg.norm(n)


def _checker(a: np.ndarray, b: np.ndarray, size: int = SIZE) -> np.ndarray:
    rows, cols = np.mgrid[0:size, 0:size]
    return np.where(((rows + cols) % 2 == 0)[..., None], a, b).astype(np.float32)


def _edit(schema: Schema, **maps: np.ndarray) -> np.ndarray:
    parts = [schema[name].space.to_edit(maps[name]) for name in schema.names]
    return np.concatenate(parts, axis=2).astype(np.float32)


def _phys(schema: Schema, edit: np.ndarray, name: str) -> np.ndarray:
    return schema[name].space.from_edit(np.ascontiguousarray(edit[..., schema.edit_slices[name]]))


def _blur(schema: Schema, edit: np.ndarray, **values) -> np.ndarray:
    spec = get_op("blur")
    params = values.pop("params", None)
    return spec.function(edit, schema=schema, params=params, **spec.bind(values))


# two tilts: 0.25 rad along x and 0.1 rad along y; slopes (-tan a, -tan b) at each
TILT_A = (0.25, 0.0)
TILT_B = (0.0, 0.1)
# the averaged checkerboard's lost slope variance, by hand: |s_a - s_b|^2 / 4
HAND_TRACE = (math.tan(0.25) ** 2 + math.tan(0.1) ** 2) / 4


def test_constant_tilt_loses_no_variance_and_keeps_roughness_bits() -> None:
    schema = Schema.from_names(["base_color", "roughness", "normal"])
    rng = np.random.default_rng(1)
    normal = np.broadcast_to(_tilted(0.3, -0.2), (SIZE, SIZE, 3)).astype(np.float32)
    rough = rng.uniform(0.1, 0.9, (SIZE, SIZE, 1)).astype(np.float32)
    color = rng.uniform(0, 1, (SIZE, SIZE, 3)).astype(np.float32)
    edit = _edit(schema, base_color=color, roughness=rough, normal=normal)
    cov = lost_slope_covariance(normal, lambda a: a.mean(axis=(0, 1), keepdims=True))
    assert np.all(cov == 0.0)
    out = _blur(schema, edit, sigma_px=3.0, keep_variance=True, params="normal")
    assert np.array_equal(out, _blur(schema, edit, sigma_px=3.0, params="normal"))


@pytest.mark.parametrize("border", ["wrap", "clamp"])
def test_two_tilt_checkerboard_adds_exactly_their_variance_ggx(border: str) -> None:
    schema = Schema.from_names(["base_color", "roughness", "normal"])
    normal = _checker(_tilted(*TILT_A), _tilted(*TILT_B))
    r = 0.4
    rough = np.full((SIZE, SIZE, 1), r, np.float32)
    color = np.random.default_rng(2).uniform(0, 1, (SIZE, SIZE, 3)).astype(np.float32)
    edit = _edit(schema, base_color=color, roughness=rough, normal=normal)
    out = _blur(schema, edit, sigma_px=4.0, border=border, keep_variance=True, params="normal")
    # GGX alpha = r^2 and alpha'^2 = alpha^2 + lost slope variance
    expected_r = (r**4 + HAND_TRACE) ** 0.25
    got = _phys(schema, out, "roughness")
    # clamp border: the corner texels see a few more of one tilt, so the footprint is
    # not exactly half-half there; the interior is
    inner = got[8:-8, 8:-8] if border == "clamp" else got
    np.testing.assert_allclose(inner, expected_r, rtol=2e-4)
    # the colours are bit-identical to the input
    assert np.array_equal(out[..., :3], edit[..., :3])


@pytest.mark.parametrize(
    ("name", "value", "widened"),
    [
        # Beckmann: total slope variance m^2 (per axis m^2 / 2)
        ("beckmann_roughness", 0.2, lambda m, v: math.sqrt(m * m + v)),
        # Phong: m^2 = 2 / (n + 2) (Walter et al. 2007)
        ("phong_exponent", 200.0, lambda n, v: 2 / (2 / (n + 2) + v) - 2),
    ],
)
def test_two_tilt_checkerboard_other_families(name: str, value: float, widened) -> None:
    schema = Schema.from_names([name, "normal"])
    normal = _checker(_tilted(*TILT_A), _tilted(*TILT_B))
    lobe = np.full((SIZE, SIZE, 1), value, np.float32)
    out = _blur(
        schema,
        _edit(schema, **{name: lobe, "normal": normal}),
        sigma_px=4.0,
        keep_variance=True,
        params="normal",
    )
    np.testing.assert_allclose(_phys(schema, out, name), widened(value, HAND_TRACE), rtol=5e-4)


def test_anisotropic_exponents_take_the_variance_of_their_own_axis() -> None:
    # tilts only along x: nu (the x axis without a tangent) widens, nv stays
    schema = Schema.from_names(["anisotropic_exponents", "normal"])
    normal = _checker(_tilted(0.2, 0.0), _tilted(-0.2, 0.0))
    lobe = np.broadcast_to(np.float32([100.0, 300.0]), (SIZE, SIZE, 2))
    out = _blur(
        schema,
        _edit(schema, anisotropic_exponents=lobe, normal=normal),
        sigma_px=4.0,
        keep_variance=True,
        params="normal",
    )
    got = _phys(schema, out, "anisotropic_exponents")
    var_x = math.tan(0.2) ** 2  # two slopes +-tan(0.2), equally weighted
    np.testing.assert_allclose(got[..., 0], 1 / (1 / 102 + var_x) - 2, rtol=5e-4)
    np.testing.assert_allclose(got[..., 1], 300.0, rtol=1e-5)


def test_roughness_never_decreases_and_colours_stay_bit_identical() -> None:
    schema = Schema.from_names(["base_color", "roughness", "metallic", "normal"])
    rng = np.random.default_rng(3)
    tilt = rng.normal(0, 0.3, (SIZE, SIZE, 2))
    normal = np.concatenate([np.tan(tilt), np.ones((SIZE, SIZE, 1))], axis=2)
    normal = (normal / np.linalg.norm(normal, axis=2, keepdims=True)).astype(np.float32)
    maps = {
        "base_color": rng.uniform(0, 1, (SIZE, SIZE, 3)).astype(np.float32),
        "roughness": rng.uniform(0, 1, (SIZE, SIZE, 1)).astype(np.float32),
        "metallic": rng.uniform(0, 1, (SIZE, SIZE, 1)).astype(np.float32),
        "normal": normal,
    }
    edit = _edit(schema, **maps)
    mask = rng.uniform(0, 1, (SIZE, SIZE)).astype(np.float32)
    for params in ("normal", None):  # only the normals blurred, or everything
        kept = _blur(schema, edit, sigma_px=2.0, keep_variance=True, params=params)
        plain = _blur(schema, edit, sigma_px=2.0, params=params)
        for m in (None, mask):
            kept = get_op("blur").function(
                edit,
                schema=schema,
                params=params,
                mask=m,
                **get_op("blur").bind({"sigma_px": 2.0, "keep_variance": True}),
            )
            plain = get_op("blur").function(
                edit,
                schema=schema,
                params=params,
                mask=m,
                **get_op("blur").bind({"sigma_px": 2.0}),
            )
            r_kept, r_plain = _phys(schema, kept, "roughness"), _phys(schema, plain, "roughness")
            assert np.all(r_kept >= r_plain)
            assert np.mean(r_kept > r_plain) > 0.9  # random tilts: nearly every texel lost some
            rough = schema.edit_slices["roughness"]
            others = np.ones(edit.shape[2], bool)
            others[rough] = False
            assert np.array_equal(kept[..., others], plain[..., others])
        if params == "normal":
            assert np.all(_phys(schema, kept, "roughness") >= maps["roughness"])


def test_normals_not_blurred_lose_nothing() -> None:
    schema = Schema.from_names(["roughness", "normal"])
    normal = _checker(_tilted(*TILT_A), _tilted(*TILT_B))
    rough = np.full((SIZE, SIZE, 1), 0.5, np.float32)
    edit = _edit(schema, roughness=rough, normal=normal)
    out = _blur(schema, edit, sigma_px=4.0, keep_variance=True, params="roughness")
    assert np.array_equal(out, _blur(schema, edit, sigma_px=4.0, params="roughness"))


# --------------------------------------------------------------------------- real path


def _write_set(folder: Path, normal: np.ndarray, rough: float, size: int) -> None:
    folder.mkdir()
    rng = np.random.default_rng(4)
    write_image(folder / "v_basecolor.png", rng.uniform(0, 1, (size, size, 3)), bit_depth="uint16")
    write_image(folder / "v_roughness.png", np.full((size, size, 1), rough), bit_depth="uint16")
    write_image(folder / "v_normal_gl.png", 0.5 * normal + 0.5, bit_depth="uint16")


def test_apply_cli_blur_keep_variance_on_files(tmp_path: Path) -> None:
    normal = _checker(_tilted(*TILT_A), _tilted(*TILT_B))
    _write_set(tmp_path / "in", normal, 0.3, SIZE)
    out = tmp_path / "out"
    argv = [
        "apply",
        str(tmp_path / "in"),
        str(out),
        "--op",
        "blur",
        "sigma_px=4",
        "keep_variance=true",
        "--params",
        "normal",
    ]
    assert main(argv) == 0
    (rough_file,) = out.glob("*roughness*")
    got, _ = read_image(rough_file)
    # slopes from the 16-bit codes differ from the exact tilts by ~1e-5
    np.testing.assert_allclose(got, (0.3**4 + HAND_TRACE) ** 0.25, atol=2e-4)
    src, _ = read_image(tmp_path / "in" / "v_basecolor.png")
    (color_file,) = out.glob("*basecolor*")
    assert np.array_equal(read_image(color_file)[0], src)


def test_blur_handles_more_channels_than_opencv_takes() -> None:
    # a sampled lobe (128) beside colours: 134 channels; OpenCV 5 filters take 128
    rng = np.random.default_rng(5)
    image = rng.uniform(0, 1, (16, 16, 134)).astype(np.float32)
    out = get_op("blur").function(image, sigma_px=1.5, border="wrap")
    # channel by channel against a brute-force wrapped Gaussian (scipy, exact weights)
    from scipy.ndimage import gaussian_filter

    for k in (0, 127, 128, 133):
        ref = gaussian_filter(image[..., k].astype(np.float64), 1.5, mode="wrap", truncate=4.0)
        np.testing.assert_allclose(out[..., k], ref, atol=1e-5)


def test_kept_variance_looks_closer_from_afar_on_bumps() -> None:
    # fine isotropic bumps (tilts ~17 deg) under a GGX r = 0.3 lobe; the truth is the
    # full-resolution render averaged 4x4 (matshop.render.far_field), not the formula
    from scipy.ndimage import gaussian_filter

    from matshop.render.far_field import far_field_errors
    from matshop.render.materials import from_maps
    from matshop.spaces.frame import height_to_normal

    size = 128
    rng = np.random.default_rng(6)
    height = gaussian_filter(rng.normal(0.0, 1.0, (size, size)), 1.5, mode="wrap")
    maps = {
        "base_color": np.full((size, size, 3), 0.5, np.float32),
        "roughness": np.full((size, size, 1), 0.3, np.float32),
        "normal": height_to_normal((height / height.std()).astype(np.float32), strength=0.6),
    }
    (result,) = far_field_errors(from_maps(maps), (4,))
    print(f"4x: RMSE plain {result.rmse_plain:.4f}, kept {result.rmse_kept:.4f}")
    assert result.rmse_kept <= 0.8 * result.rmse_plain


def test_rotating_the_material_rotates_the_anisotropic_covariance() -> None:
    # tilts along x with the tangent along x, then the whole material turned 90 degrees
    # (tilts along y, tangent along y): nu widens by the same amount both times; tilts
    # along y under a tangent along x widen nv instead
    schema = Schema.from_names(["anisotropic_exponents", "normal"], {"normal": "normal_tangent"})
    lobe = np.broadcast_to(np.float32([100.0, 300.0]), (SIZE, SIZE, 2))
    var = math.tan(0.2) ** 2  # two slopes +-tan(0.2), equally weighted
    nu, nv = 1 / (1 / 102 + var) - 2, 1 / (1 / 302 + var) - 2
    cases = [
        ((0.2, 0.0), (1.0, 0.0, 0.0), (nu, 300.0)),
        ((0.0, 0.2), (0.0, 1.0, 0.0), (nu, 300.0)),
        ((0.0, 0.2), (1.0, 0.0, 0.0), (100.0, nv)),
    ]
    for tilt, tangent, expected in cases:
        normal = _checker(_tilted(*tilt), _tilted(-tilt[0], -tilt[1]))
        # the tangent made orthogonal to each normal (Gram-Schmidt), as a frame is
        t = np.broadcast_to(np.float32(tangent), normal.shape)
        t = t - np.sum(t * normal, axis=2, keepdims=True) * normal
        t = t / np.linalg.norm(t, axis=2, keepdims=True)
        frame = np.concatenate([normal, t], axis=2).astype(np.float32)
        edit = _edit(schema, anisotropic_exponents=lobe, normal=frame)
        out = _blur(schema, edit, sigma_px=4.0, keep_variance=True, params="normal")
        # averaging the log-rotations of frames turned 90 degrees leaves the blurred
        # tangent ~0.3 degrees off the axis, which leaks ~1e-6 of variance across
        np.testing.assert_allclose(
            _phys(schema, out, "anisotropic_exponents"),
            np.broadcast_to(np.float32(expected), lobe.shape),
            rtol=1e-3,
        )


def test_filter_layer_keeps_variance_through_a_project(tmp_path: Path) -> None:
    normal = _checker(_tilted(*TILT_A), _tilted(*TILT_B))
    _write_set(tmp_path / "in", normal, 0.3, SIZE)
    project = tmp_path / "p.matshop"
    assert main(["new", str(project), "--from", str(tmp_path / "in")]) == 0
    argv = [
        "layer",
        "add",
        str(project),
        "filter",
        "--op",
        "blur",
        "sigma_px=4",
        "keep_variance=true",
        "--params",
        "normal",
    ]
    assert main(argv) == 0
    assert main(["flatten", str(project), str(tmp_path / "out")]) == 0
    got, _ = read_image(next((tmp_path / "out").glob("*roughness*")))
    np.testing.assert_allclose(got, (0.3**4 + HAND_TRACE) ** 0.25, atol=2e-4)


def test_viewport_mips_widen_ggx_by_the_tilt_variance_they_average() -> None:
    """The GL viewport's mip chain with keep variance (``shading_maps.mip_chain``): a
    one-texel checkerboard of normals tilted +-theta about y has slopes -+tan(theta) along
    x, so each 2x2 average removes a slope variance tan^2(theta) (worked out here) and
    level 1's GGX alpha is sqrt(alpha^2 + tan^2 theta); level 0 and the plain chain keep
    alpha; colours are untouched."""
    from matshop.viewport.gl import shading_maps

    theta, r = 0.3, 0.4
    normal = _checker(_tilted(theta, 0.0), _tilted(-theta, 0.0))
    tilt = np.arctan2(-normal[0, 0, 0], normal[0, 0, 2])
    assert abs(abs(tilt) - theta) < 1e-6  # the tilt about y is theta
    size = normal.shape[0]
    schema = Schema.from_names(["base_color", "roughness", "normal"])
    maps = {
        "base_color": np.full((size, size, 3), 0.5, np.float32),
        "roughness": np.full((size, size, 1), r, np.float32),
        "normal": normal,
    }
    packed = shading_maps.pack(schema, maps)
    plain = shading_maps.mip_chain(packed, 2)
    kept = shading_maps.mip_chain(packed, 2, widen="ggx")
    alpha = r * r
    np.testing.assert_array_equal(kept["ks_lobe"][0], plain["ks_lobe"][0])
    np.testing.assert_allclose(plain["ks_lobe"][1][..., 3], alpha, rtol=1e-6)
    widened = math.sqrt(alpha**2 + math.tan(theta) ** 2)
    np.testing.assert_allclose(kept["ks_lobe"][1][..., 3], widened, rtol=1e-5)
    np.testing.assert_allclose(kept["ks_lobe"][2][..., 3], widened, rtol=1e-5)
    np.testing.assert_array_equal(kept["ks_lobe"][1][..., :3], plain["ks_lobe"][1][..., :3])
    np.testing.assert_array_equal(kept["kd_ao"][1], plain["kd_ao"][1])
