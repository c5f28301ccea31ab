"""The OpenGL viewport against closed forms, not against the reference renderer.

Three scenes whose answer needs no renderer (the textbook checks of a
shading model), each drawn by the real viewport and read back as 8-bit:

- white furnace: a white Lambertian sphere inside a uniform environment of
  radiance L reflects exactly L (energy conservation of the diffuse term);
- E cos / pi: lit by one directional light of irradiance E, the brightest
  point of a white Lambertian sphere (its normal facing the light) has
  radiance E / pi;
- mirror: a white metal (F0 = 1) of very low roughness in a uniform
  environment reflects L where it faces the camera.

The display transform is written out in the tests (exposure, the clip or Narkowicz's
ACES curve here, the exact sRGB encoding of CONVENTIONS.md in tests/oracle.py), not
imported from matshop.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from gl_testing import require_gl

require_gl()  # skips the module, saying why, without pytest-qt or an OpenGL 3.3 context

from gl_testing import release, shown_viewport  # noqa: E402
from oracle import srgb_encode as srgb  # noqa: E402

from matshop.layers import Document  # noqa: E402
from matshop.material import Material, Schema  # noqa: E402
from matshop.render.environment import uniform  # noqa: E402
from matshop.render.integrator import DirectionalLight  # noqa: E402
from matshop.viewport.gl import mesh_data  # noqa: E402

SIZE = 192


def narkowicz_aces(x: float) -> float:
    return min(max(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0), 1.0)


def code(display: float) -> int:
    return round(display * 255)


def white(*, metallic: float, roughness: float) -> Material:
    """Constant maps: base colour code 255 (linear 1), the given metal and roughness."""
    shape = (8, 8)
    maps = {
        "base_color": np.ones((*shape, 3), np.float32),
        "metallic": np.full((*shape, 1), metallic, np.float32),
        "roughness": np.full((*shape, 1), roughness, np.float32),
    }
    return Material("white", Schema.from_names(list(maps)), maps)


@pytest.fixture
def viewport(gl_context, qtbot):
    widget = shown_viewport(qtbot, SIZE)
    widget.set_mesh(mesh_data.uv_sphere())
    widget.lighting.background = (0.0, 0.0, 0.0)  # the sphere is what is not black
    widget.lighting.samples = 64
    yield widget
    release(widget)


def draw(viewport, material: Material, **lighting) -> np.ndarray:
    for name, value in lighting.items():
        setattr(viewport.lighting, name, value)
    viewport.set_document(Document.from_material(material))
    return viewport.render_image(SIZE)[..., :3].astype(int)


def sphere_interior(image: np.ndarray, keep: float = 0.8) -> np.ndarray:
    """Pixels well inside the sphere's silhouette (no edge antialiasing), as (N, 3)."""
    covered = image.max(axis=-1) > 0
    rows, cols = np.nonzero(covered)
    cy, cx = rows.mean(), cols.mean()
    radius = math.sqrt(covered.sum() / math.pi)
    yy, xx = np.mgrid[: image.shape[0], : image.shape[1]]
    inside = (yy - cy) ** 2 + (xx - cx) ** 2 <= (keep * radius) ** 2
    assert inside.sum() > 1000, "the sphere is too small to measure"
    return image[inside]


@pytest.mark.parametrize(("radiance", "tonemap"), [(0.5, "linear"), (2.0, "aces")])
def test_white_furnace_reflects_the_environment(viewport, radiance, tonemap) -> None:
    viewport.set_environment(uniform(radiance))
    image = draw(
        viewport,
        white(metallic=0.0, roughness=1.0),
        specular=False,
        lights=(),
        environment_scale=1.0,
        exposure=0.0,
        tonemap=tonemap,
    )
    curve = narkowicz_aces if tonemap == "aces" else (lambda x: min(max(x, 0.0), 1.0))
    expected = code(srgb(curve(radiance)))
    pixels = sphere_interior(image)
    assert np.abs(pixels - expected).max() <= 1, (expected, np.unique(pixels))


def test_a_directional_light_gives_e_over_pi_where_the_normal_faces_it(viewport) -> None:
    viewport.set_environment(uniform(0.0))
    irradiance = 0.8 * math.pi  # E / pi = 0.8: below the clip, far from the toe
    camera_side = (0.2, 0.3, 1.0)  # in front, so the facing point is seen
    image = draw(
        viewport,
        white(metallic=0.0, roughness=1.0),
        specular=False,
        lights=(DirectionalLight(camera_side, (irradiance,) * 3),),
        environment_scale=0.0,
        exposure=0.0,
        tonemap="linear",
    )
    brightest = image.max(axis=(0, 1))
    expected = code(srgb(irradiance / math.pi))  # cos = 1 at the facing point
    assert np.abs(brightest - expected).max() <= 1, (brightest, expected)
    # and everywhere it falls off as cos: E / pi max(n.l, 0) with n the surface normal
    # under the pixel (the picking pass's), on a grid of pixels across the sphere
    light = np.asarray(camera_side) / np.linalg.norm(camera_side)
    checked = 0
    for row in range(4, SIZE, 8):
        for col in range(4, SIZE, 8):
            hit = viewport._hit(col + 0.5, row + 0.5)
            if hit is None:
                continue  # off the sphere
            cosine = max(float(hit.normal @ light), 0.0)
            expected = code(srgb(irradiance / math.pi * cosine))
            assert abs(int(image[row, col, 1]) - expected) <= 1, (row, col, cosine)
            checked += 1
    print(f"cosine law checked at {checked} pixels")
    assert checked > 200


def test_a_white_mirror_reflects_the_environment_where_it_faces_the_camera(viewport) -> None:
    viewport.set_environment(uniform(0.5))
    image = draw(
        viewport,
        white(metallic=1.0, roughness=0.05),
        specular=True,
        lights=(),
        environment_scale=1.0,
        exposure=0.0,
        tonemap="linear",
    )
    centre = sphere_interior(image, keep=0.5)  # near normal incidence: F = 1, G ~ 1
    expected = code(srgb(0.5))
    assert np.abs(np.median(centre, axis=0) - expected).max() <= 1
    assert np.abs(centre - expected).max() <= 2, np.unique(centre)
