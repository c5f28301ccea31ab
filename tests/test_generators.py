"""Generator masks against closed forms: heights, a sphere cap's curvature, a groove, AO.

Normals are built here from analytic gradients (numpy), not by matshop.
"""

from __future__ import annotations

import numpy as np
import pytest

from matshop.ops.generators import (
    ambient_occlusion,
    convexity,
    generate_mask,
    integrate_height,
    shape_mask,
)

N = 128


def normals_from_gradient(dh_dx: np.ndarray, dh_dy: np.ndarray) -> np.ndarray:
    """OpenGL tangent-space normals of a height with these derivatives (x right, y down)."""
    dh_dv = -dh_dy  # v runs up the image
    n = np.dstack([-dh_dx, -dh_dv, np.ones_like(dh_dx)])
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def periodic_height() -> tuple[np.ndarray, np.ndarray]:
    """A tiling height (texel units) and its normals from the central differences of it."""
    y, x = np.mgrid[0:N, 0:N].astype(np.float64)
    h = 3.0 * np.sin(2 * np.pi * 3 * x / N) * np.cos(2 * np.pi * 2 * y / N) + 2.0 * np.sin(
        2 * np.pi * (x + 2 * y) / N
    )
    dh_dx = (np.roll(h, -1, axis=1) - np.roll(h, 1, axis=1)) / 2
    dh_dy = (np.roll(h, -1, axis=0) - np.roll(h, 1, axis=0)) / 2
    return h, normals_from_gradient(dh_dx, dh_dy)


def test_integration_recovers_a_tiling_height_up_to_its_mean() -> None:
    h, normals = periodic_height()
    back = integrate_height(normals)
    assert np.abs((back - back.mean()) - (h - h.mean())).max() < 1e-9


def test_integration_reads_green_as_up() -> None:
    """A ramp rising up the image (towards row 0) has normals leaning down (n_y < 0)."""
    y = np.mgrid[0:N, 0:N][0].astype(np.float64)
    h = 4.0 * np.sin(2 * np.pi * y / N)  # periodic, so Frankot-Chellappa holds exactly
    dh_dy = (np.roll(h, -1, axis=0) - np.roll(h, 1, axis=0)) / 2
    normals = normals_from_gradient(np.zeros_like(h), dh_dy)
    back = integrate_height(normals)
    assert np.corrcoef(back.ravel(), h.ravel())[0, 1] > 0.999


def test_a_sphere_caps_convexity_is_radius_squared_over_r() -> None:
    """For h = -r^2 / (2R) (a sphere cap near its top) a Gaussian of sigma s averages
    r^2 to r^2 + 2 s^2, so h - blur(h) = s^2 / R exactly, wherever the blur sees the cap."""
    big_r, sigma = 400.0, 3.0
    y, x = np.mgrid[0:N, 0:N].astype(np.float64) - N / 2
    h = -(x**2 + y**2) / (2 * big_r)
    got = convexity(h, sigma)
    inner = slice(N // 4, 3 * N // 4)  # away from the wrapped border
    np.testing.assert_allclose(got[inner, inner], sigma**2 / big_r, rtol=1e-3)


def test_a_groove_is_cavity_in_its_bottom_and_edge_on_its_lips() -> None:
    x = np.arange(N, dtype=np.float64)
    width = 3.0
    profile = -6.0 * np.exp(-((x - N / 2) ** 2) / (2 * width**2))  # a valley along y
    dh_dx = np.gradient(profile)[None, :].repeat(N, axis=0)
    normals = normals_from_gradient(dh_dx, np.zeros((N, N)))
    cavity = generate_mask(normals, "cavity", radius_px=4.0)
    edge = generate_mask(normals, "edge", radius_px=4.0)
    centre = N // 2
    assert cavity[:, centre].min() > 0.9 and edge[:, centre].max() == 0.0
    assert cavity[:, 5].max() < 0.05 and edge[:, 5].max() < 0.05  # flat far away
    lips = np.argmax(edge[N // 2])
    assert 3 <= abs(lips - centre) <= 12  # beside the valley, where the walls turn flat
    assert ((cavity >= 0) & (cavity <= 1) & (edge >= 0) & (edge <= 1)).all()


def test_ao_sees_the_whole_sky_on_a_flat_plane_and_less_in_a_pit() -> None:
    assert np.allclose(ambient_occlusion(np.zeros((32, 32)), 4.0), 1.0)
    # a square pit 6 deep and 4 wide: at its centre the walls rise 6 over 2 texels
    h = np.zeros((32, 32))
    h[14:18, 14:18] = -6.0
    ao = ambient_occlusion(h, 6.0)
    # along an axis the wall is 2 texels away and 6 high: sky fraction 1 - sin(atan(3))
    axis_value = 1.0 - np.sin(np.arctan(6.0 / 2.0))
    assert ao[15, 15] < 0.5 and ao[15, 15] == pytest.approx(axis_value, abs=0.15)
    assert ao[2, 2] == pytest.approx(1.0)


def test_controls_level_contrast_invert() -> None:
    ramp = np.linspace(0, 1, 11)
    assert np.allclose(shape_mask(ramp), ramp)  # defaults change nothing
    assert np.allclose(shape_mask(ramp, invert=True), 1 - ramp)
    steep = shape_mask(ramp, level=0.3, contrast=4.0)
    assert steep[3] == pytest.approx(0.5) and steep[0] == 0.0 and steep[6] == 1.0


def test_unknown_generator_and_bad_radius_are_refused() -> None:
    _, normals = periodic_height()
    with pytest.raises(ValueError, match="unknown mask generator 'dirt'"):
        generate_mask(normals, "dirt")
    with pytest.raises(ValueError, match="radius_px"):
        generate_mask(normals, "ao", radius_px=0)


def test_layer_add_takes_a_generated_mask_from_the_projects_normals(tmp_path) -> None:
    from matshop.cli import main
    from matshop.io.images import write_image
    from matshop.io.project import load_project

    x = np.arange(64, dtype=np.float64)
    profile = -6.0 * np.exp(-((x - 32) ** 2) / (2 * 3.0**2))
    normals = normals_from_gradient(np.gradient(profile)[None, :].repeat(64, 0), np.zeros((64, 64)))
    folder = tmp_path / "groove"
    folder.mkdir()
    write_image(folder / "groove_normal_gl.png", (normals + 1) / 2, bit_depth="uint16")
    write_image(folder / "groove_basecolor.png", np.full((64, 64, 3), 0.5, np.float32))
    project = tmp_path / "g.matshop"
    assert main(["new", str(project), "--from", str(folder)]) == 0
    args = ["layer", "add", str(project), "paint", "--name", "Dirt"]
    assert main([*args, "--mask-generator", "cavity", "radius_px=4"]) == 0
    doc = load_project(project).document
    mask = doc.generated_mask(doc.layers[-1].id)
    assert mask[:, 32].min() > 0.9 and mask[:, 4].max() < 0.05  # in the groove, not on flat
    # bad options are one line, exit 2, the project unchanged
    before = project.read_bytes()
    for bad in (["dirt"], ["ao", "radius_px=0"], ["ao", "blur_px=1e9"], ["edge", "sharp=2"]):
        assert main([*args, "--mask-generator", *bad]) == 2
    assert project.read_bytes() == before
