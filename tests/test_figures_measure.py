"""The figures' measurement helpers and synthetic materials, against closed-form truth."""

from __future__ import annotations

import numpy as np
import pytest

from matshop.figures import aniso as fig_aniso
from matshop.figures import steep as fig_steep
from matshop.figures.measure import (
    axis_difference_deg,
    highlight_shape,
    median_lobe_deg,
    steep_fraction,
    tilt_deg,
)
from matshop.figures.synthetic import (
    exponent_from_roughness,
    phong_tiles,
    steep_studs,
    with_anisotropy,
)
from matshop.render.materials import constant
from matshop.spaces.frame import height_to_normal


def _gaussian_ellipse(sx: float, sy: float, angle_deg: float, size: int = 161) -> np.ndarray:
    c = np.arange(size) - size // 2
    x, y = np.meshgrid(c, -c)  # +y up, as highlight_shape reads it
    a = np.radians(angle_deg)
    u = x * np.cos(a) + y * np.sin(a)
    v = -x * np.sin(a) + y * np.cos(a)
    return np.exp(-0.5 * ((u / sx) ** 2 + (v / sy) ** 2))


@pytest.mark.parametrize(("ratio", "angle"), [(1.0, 0.0), (3.0, 30.0), (2.0, 120.0)])
def test_highlight_shape_recovers_an_ellipse(ratio, angle):
    shape = highlight_shape(_gaussian_ellipse(10.0 * ratio, 10.0, angle), smooth_px=0.0)
    assert shape.aspect == pytest.approx(ratio, rel=0.03)
    if ratio > 1.0:
        assert axis_difference_deg(shape.angle_deg, angle) < 1.0
        # along the major axis the extent is the major one
        assert shape.extent_along(angle) == pytest.approx(shape.major_px, rel=1e-4)
        assert shape.extent_along(angle + 90.0) == pytest.approx(shape.minor_px, rel=1e-4)


def test_highlight_shape_ignores_a_second_separate_blob():
    image = _gaussian_ellipse(12.0, 4.0, 0.0) + 0.9 * np.roll(
        _gaussian_ellipse(4.0, 4.0, 0.0), 60, 0
    )
    assert highlight_shape(image, smooth_px=0.0).aspect == pytest.approx(3.0, rel=0.05)


def test_axis_difference_is_undirected():
    assert axis_difference_deg(179.0, 1.0) == pytest.approx(2.0)
    assert axis_difference_deg(10.0, 100.0) == pytest.approx(90.0)


def test_studs_walls_tilt_by_their_angle_and_tops_are_flat():
    normal = height_to_normal(steep_studs(128, period=64, top=10, foot=26, wall_deg=55.0))
    tilt = tilt_deg(normal)
    assert tilt[32, 32] == pytest.approx(0.0, abs=1e-4)  # a stud's top
    assert tilt[32, 32 + 18] == pytest.approx(55.0, abs=0.01)  # the middle of a wall
    assert steep_fraction(normal, 30.0) == pytest.approx((52**2 - 20**2) / 64**2, abs=0.02)


def test_median_lobe_angle_matches_the_phong_cdf():
    n = np.array([0.0, 40.0, 400.0])
    theta = np.radians(median_lobe_deg(n))
    np.testing.assert_allclose(1.0 - np.cos(theta) ** (n + 2.0), 0.5, atol=1e-12)


def test_exponent_from_roughness_keeps_the_ggx_median_angle():
    r = np.array([[0.1], [0.3], [0.6], [1.0]], np.float32)
    got = median_lobe_deg(exponent_from_roughness(r))
    np.testing.assert_allclose(got, np.degrees(np.arctan(r.astype(np.float64) ** 2)), atol=1e-3)


def test_with_anisotropy_adds_an_orthonormal_tangent_and_an_isotropic_lobe():
    base = constant(4, base_color=(0.5, 0.5, 0.5), roughness=0.4, normal=(0.3, 0.0, 0.954))
    aniso = with_anisotropy(base, tangent_deg=60.0)
    frame = aniso.maps["normal"]
    n, t = frame[..., :3], frame[..., 3:]
    np.testing.assert_allclose(np.sum(n * t, axis=-1), 0.0, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(t, axis=-1), 1.0, atol=1e-6)
    assert aniso.schema["normal"].space.name == "normal_tangent"
    assert "roughness" not in aniso.maps
    nu_nv = aniso.maps["anisotropic_exponents"]
    np.testing.assert_array_equal(nu_nv[..., 0], nu_nv[..., 1])
    flat = with_anisotropy(constant(2, roughness=0.4), tangent_deg=60.0).maps["normal"][0, 0, 3:]
    np.testing.assert_allclose(flat, [0.5, np.sqrt(0.75), 0.0], atol=1e-6)


def test_scaling_lobe_and_frame_edits_stretches_and_turns_the_highlight():
    # the figure's control ball: a constant material, where nothing but the edits shapes it
    control = constant(16, base_color=(0.2, 0.2, 0.2), roughness=0.27, normal=(0, 0, 1))
    shapes = [fig_aniso.measure(m, size=160)[0] for _, m, _ in fig_aniso.variants(control)]
    expected = [e for _, _, e in fig_aniso.variants(control)]
    assert shapes[1].aspect == pytest.approx(1.0, abs=0.05)  # AS with nu = nv is round
    for shape, angle in zip(shapes[2:], expected[2:], strict=True):
        assert shape.aspect == pytest.approx(fig_aniso.STRETCH, rel=0.1)
        assert axis_difference_deg(shape.angle_deg, angle) < 2.0


def test_steep_relief_blurred_as_height_field_stays_steeper():
    normal = height_to_normal(steep_studs(128, wall_deg=55.0))
    n_edit, n_height = fig_steep.relief_blur(normal, 10.0)
    t0, te, th = (float(tilt_deg(n).mean()) for n in (normal, n_edit, n_height))
    assert te < t0 and th < t0
    assert th > 1.2 * te
    assert steep_fraction(n_height, 30.0) > steep_fraction(n_edit, 30.0) + 0.2


def test_physical_unsharp_of_phong_exponents_blows_up_the_rough_side():
    material, tiles = phong_tiles(128)
    result, negative = fig_steep.physical_unsharp(material)
    a0 = median_lobe_deg(material.maps["phong_exponent"][..., 0])
    a1 = median_lobe_deg(result.maps["phong_exponent"][..., 0])
    assert negative > 0.1
    assert (a1 - a0)[~tiles].max() > 30.0  # grout next to tiles clamped to n = 0 (45 deg)
    assert (a0 - a1)[tiles].max() < 1.0
