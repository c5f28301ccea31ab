"""Specular anti-aliasing in the GL viewport: mips that keep the normals' tilt variance.

A bumpy material seen from afar, judged by appearance, not by the formula: the truth is
the reference renderer's image of the full-resolution material at 4x the size, averaged
4x4 down (what the eye sees from that far). The viewport draws the same material at the
small size from mip level 2 with and without ``keep_variance``; the kept mips must be
closer to the truth (issue 18, item 3). Once with the GGX lobe, once with the same lobe
as a tabulated (sampled) distribution, which the mips widen by a Gaussian slope
convolution of their averaged tables (:mod:`matshop.ops.sampled_widening`). The four
images of each go to ``test-output/viewport_variance_<lobe>.png``: truth, plain, kept,
level 0.

Run under ``xvfb-run -a``; skips, saying why, only without an OpenGL 3.3 context.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from gl_testing import require_gl

require_gl()  # skips the module, saying why, without pytest-qt or an OpenGL 3.3 context

import cv2  # noqa: E402
from gl_testing import release, shown_viewport  # noqa: E402
from scipy.ndimage import binary_erosion, gaussian_filter  # noqa: E402

from matshop.figures.synthetic import with_lobe  # noqa: E402
from matshop.layers import Document  # noqa: E402
from matshop.material import Material  # noqa: E402
from matshop.render import scenes  # noqa: E402
from matshop.render.integrator import DirectionalLight  # noqa: E402
from matshop.render.materials import from_maps  # noqa: E402
from matshop.render.render import render  # noqa: E402
from matshop.render.surface import prefilter_factor  # noqa: E402
from matshop.render.tonemap import to_uint8  # noqa: E402
from matshop.spaces.frame import height_to_normal  # noqa: E402
from matshop.viewport.gl import mesh_data  # noqa: E402

VIEW = 128  # the far view; the truth is rendered at 4x and averaged down
REDUCTION = 4
SIZE = 1024  # texels: 4.4 per pixel of the far view, mip level 2
LIGHT = DirectionalLight((-0.5, 0.7, 0.6), (2.0, 2.0, 2.0))
OUT = Path(__file__).resolve().parents[1] / "test-output"


def bumpy_metal(size: int) -> Material:
    """Fine isotropic bumps (white noise blurred 1.5 texels, tilts ~17 deg) on a metal
    with GGX r = 0.3: all its light is specular, what keep variance is about."""
    rng = np.random.default_rng(0)
    height = gaussian_filter(rng.normal(0.0, 1.0, (size, size)), 1.5, mode="wrap")
    maps = {
        "base_color": np.full((size, size, 3), 0.5, np.float32),
        "metallic": np.ones((size, size, 1), np.float32),
        "roughness": np.full((size, size, 1), 0.3, np.float32),
        "normal": height_to_normal((height / height.std()).astype(np.float32), strength=0.6),
    }
    return from_maps(maps, name="bumpy metal")


@pytest.fixture
def viewport(gl_context, qtbot):
    widget = shown_viewport(qtbot, VIEW)
    yield widget
    release(widget)


def _gl(viewport, material: Material, levels: tuple[float, ...], keep: bool) -> list[np.ndarray]:
    """The viewport's images of ``material`` from each mip level of ``levels``."""
    if viewport.doc is None:  # the first call of a test
        viewport.set_document(Document.from_material(material))
    viewport.set_keep_variance(keep)  # the same document: reloaded into its textures
    viewport.set_uv_scale(2.0, 1.0)
    viewport.set_mesh(mesh_data.uv_sphere())
    viewport.lighting.samples = 16
    viewport.lighting.lights = (LIGHT,)
    images = []
    for level in levels:
        viewport.lighting.texture_lod = level
        images.append(viewport.render_image(VIEW)[..., :3].astype(int))
    return images


@pytest.mark.parametrize("lobe", ["ggx", "sampled"])
def test_kept_variance_mips_look_closer_to_the_far_field(viewport, lobe) -> None:
    material = with_lobe(bumpy_metal(SIZE), lobe)
    near = render(material, size=VIEW * REDUCTION, samples=16, lights=(LIGHT,))
    # the near render reads level 0, one texel a pixel or finer: it resolves the bumps
    assert prefilter_factor(material.size, scenes.sphere(VIEW * REDUCTION).uv_per_pixel) == 1
    far = near.radiance.reshape(VIEW, REDUCTION, VIEW, REDUCTION, 3).mean(axis=(1, 3))
    small = render(material, size=VIEW, samples=16, lights=(LIGHT,))  # its alpha and shape
    truth = to_uint8(dataclasses.replace(small, radiance=far).display()[..., :3]).astype(int)
    level = float(np.log2(prefilter_factor(material.size, scenes.sphere(VIEW).uv_per_pixel)))
    assert level == 2
    inside = binary_erosion(scenes.sphere(VIEW).mask, iterations=3)  # off the silhouette

    def rmse(image: np.ndarray) -> float:
        return float(np.sqrt(np.mean((image - truth)[inside] ** 2.0)))

    plain_image, plain_level0 = _gl(viewport, material, (level, 0.0), keep=False)
    kept_image, level0 = _gl(viewport, material, (level, 0.0), keep=True)
    assert viewport.renderer.textures.widen == lobe
    plain, kept = rmse(plain_image), rmse(kept_image)
    print(f"{lobe}: far field, 8-bit RMSE over the sphere: plain mips {plain:.2f}, kept {kept:.2f}")
    # level 0 averages nothing: keeping variance changes nothing there
    np.testing.assert_array_equal(level0, plain_level0)
    OUT.mkdir(exist_ok=True)
    strip = np.concatenate([truth, plain_image, kept_image, level0], axis=1).astype(np.uint8)
    cv2.imwrite(str(OUT / f"viewport_variance_{lobe}.png"), strip[..., ::-1])
    assert kept < 0.9 * plain
